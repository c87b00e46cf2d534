//! Compressed sparse column matrices: an owned [`CscMatrix`] and a borrowed [`CscRef`].

use crate::SolverError;
use rayon::prelude::*;
#[cfg(feature = "sprs")]
use sprs::{CompressedStorage, CsMatView};

/// Rows of a symmetric product of several columns ([`CscRef::fold_many_symmetric_par`]) go
/// to the threads in chunks of this many.
pub(crate) const PRODUCT_CHUNK: usize = 1024;

/// A borrowed CSC matrix: `col_ptr` (len ncols + 1), `row_idx` and `values` (len nnz).
///
/// Row indices are strictly increasing inside each column. Symmetric matrices store both
/// triangles.
#[derive(Clone, Copy, Debug)]
pub struct CscRef<'a> {
    nrows: usize,
    ncols: usize,
    col_ptr: &'a [usize],
    row_idx: &'a [usize],
    values: &'a [f64],
}

/// An owned CSC matrix with the same invariants as [`CscRef`].
#[derive(Clone, Debug, PartialEq, Default)]
pub struct CscMatrix {
    nrows: usize,
    ncols: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
}

/// A cheap fingerprint of a sparsity pattern, to detect a changed pattern between analyze and
/// factorize without keeping a copy of the indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PatternFingerprint {
    n: usize,
    nnz: usize,
    hash: u64,
}

fn check_structure(
    nrows: usize,
    ncols: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
    nvalues: usize,
) -> Result<(), SolverError> {
    let bad = |m: String| Err(SolverError::InvalidMatrix(m));
    if col_ptr.len() != ncols + 1 {
        return bad(format!(
            "col_ptr has {} entries, expected ncols + 1 = {}",
            col_ptr.len(),
            ncols + 1
        ));
    }
    if col_ptr[0] != 0 {
        return bad("col_ptr[0] must be 0".into());
    }
    let nnz = col_ptr[ncols];
    if row_idx.len() != nnz || nvalues != nnz {
        return bad(format!(
            "col_ptr says {nnz} entries but row_idx has {} and values {nvalues}",
            row_idx.len()
        ));
    }
    // Column by column, on all threads for a large pattern (L's cell matrix, 2.6·10⁷
    // entries: 33–36 → 19–21 ms); the lowest failing column is the one reported, as one pass
    // would find it.
    let column = |j: usize| -> Option<String> {
        let (start, end) = (col_ptr[j], col_ptr[j + 1]);
        if end < start || end > nnz {
            return Some(format!("col_ptr is not non-decreasing at column {j}"));
        }
        let rows = &row_idx[start..end];
        for (k, &r) in rows.iter().enumerate() {
            if r >= nrows {
                return Some(format!("row index {r} out of range in column {j}"));
            }
            if k > 0 && rows[k - 1] >= r {
                return Some(format!("row indices not strictly increasing in column {j}"));
            }
        }
        None
    };
    let first = if nnz >= PARALLEL_CHECK_ENTRIES {
        (0..ncols)
            .into_par_iter()
            .with_min_len(COLUMNS_PER_TASK)
            .find_map_first(column)
    } else {
        (0..ncols).find_map(column)
    };
    first.map_or(Ok(()), bad)
}

/// Patterns with at least this many entries are checked on all threads, in tasks of at least
/// [`COLUMNS_PER_TASK`] columns.
const PARALLEL_CHECK_ENTRIES: usize = 1 << 20;
const COLUMNS_PER_TASK: usize = 1 << 14;

impl<'a> CscRef<'a> {
    /// Checks the arrays (sizes, bounds, sorted unique rows) and wraps them.
    pub fn new(
        nrows: usize,
        ncols: usize,
        col_ptr: &'a [usize],
        row_idx: &'a [usize],
        values: &'a [f64],
    ) -> Result<Self, SolverError> {
        check_structure(nrows, ncols, col_ptr, row_idx, values.len())?;
        // SAFETY: the pattern was checked just above.
        unsafe { Self::new_unchecked(nrows, ncols, col_ptr, row_idx, values) }
    }

    /// Checks a pattern (sizes, bounds, sorted unique rows) once, for
    /// [`CscRef::new_unchecked`] with many value arrays.
    pub fn check_pattern(
        nrows: usize,
        ncols: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
    ) -> Result<(), SolverError> {
        check_structure(nrows, ncols, col_ptr, row_idx, row_idx.len())
    }

    /// Wraps the arrays checking only their sizes (O(1)): for a pattern reused with new values
    /// in a loop.
    ///
    /// # Safety
    ///
    /// The pattern must have passed [`CscRef::check_pattern`] (or [`CscRef::new`]): backends
    /// hand the row indices to foreign code (CHOLMOD) that does not check them.
    pub unsafe fn new_unchecked(
        nrows: usize,
        ncols: usize,
        col_ptr: &'a [usize],
        row_idx: &'a [usize],
        values: &'a [f64],
    ) -> Result<Self, SolverError> {
        if col_ptr.len() != ncols + 1 || values.len() != row_idx.len() {
            return Err(SolverError::InvalidMatrix(format!(
                "{} column pointers and {} values for {ncols} columns and {} entries",
                col_ptr.len(),
                values.len(),
                row_idx.len()
            )));
        }
        Ok(CscRef {
            nrows,
            ncols,
            col_ptr,
            row_idx,
            values,
        })
    }

    #[cfg(feature = "sprs")]
    /// Borrows an sprs matrix without copying. It must be stored CSC with a plain (unsliced)
    /// index pointer; use [`CscMatrix::from_sprs`] for any other sprs matrix.
    pub fn try_from_sprs(m: &'a CsMatView<'_, f64>) -> Result<Self, SolverError> {
        if m.storage() != CompressedStorage::CSC {
            return Err(SolverError::InvalidMatrix(
                "sprs matrix is stored CSR; convert it with CscMatrix::from_sprs".into(),
            ));
        }
        let col_ptr = match m.proper_indptr() {
            std::borrow::Cow::Borrowed(p) => p,
            std::borrow::Cow::Owned(_) => {
                return Err(SolverError::InvalidMatrix(
                    "sprs matrix has an offset index pointer; use CscMatrix::from_sprs".into(),
                ))
            }
        };
        Self::new(m.rows(), m.cols(), col_ptr, m.indices(), m.data())
    }

    /// Number of rows.
    pub fn nrows(&self) -> usize {
        self.nrows
    }
    /// Number of columns.
    pub fn ncols(&self) -> usize {
        self.ncols
    }
    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
    /// Column pointers.
    pub fn col_ptr(&self) -> &'a [usize] {
        self.col_ptr
    }
    /// Row indices.
    pub fn row_idx(&self) -> &'a [usize] {
        self.row_idx
    }
    /// Values.
    pub fn values(&self) -> &'a [f64] {
        self.values
    }
    /// Row indices and values of column `j`.
    pub fn col(&self, j: usize) -> (&'a [usize], &'a [f64]) {
        let r = self.col_ptr[j]..self.col_ptr[j + 1];
        (&self.row_idx[r.clone()], &self.values[r])
    }

    /// The diagonal (zero where not stored).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.ncols.min(self.nrows))
            .map(|j| {
                let (rows, vals) = self.col(j);
                rows.binary_search(&j).map(|k| vals[k]).unwrap_or(0.0)
            })
            .collect()
    }

    /// The fingerprint of the pattern.
    pub fn fingerprint(&self) -> PatternFingerprint {
        // FNV-1a over the indices in chunks of a fixed size on all threads, then over the
        // chunks' hashes in order: the same value on any number of threads. Within a chunk
        // four interleaved streams (index k to stream k mod 4), so that the multiplications
        // do not wait on one another: 17 → 6.6 ms on L's pattern (2.7·10⁷ indices), called
        // by every factorization.
        const CHUNK: usize = 1 << 16;
        const BASIS: u64 = 0xcbf2_9ce4_8422_2325;
        let fnv = |h: u64, x: u64| (h ^ x).wrapping_mul(0x0100_0000_01b3);
        let chunk_hash = |c: &[usize]| {
            let mut lanes = [BASIS, BASIS ^ 1, BASIS ^ 2, BASIS ^ 3];
            let quads = c.chunks_exact(4);
            let rest = quads.remainder();
            for q in quads {
                for (h, &x) in lanes.iter_mut().zip(q) {
                    *h = fnv(*h, x as u64);
                }
            }
            let h = rest.iter().fold(lanes[0], |h, &x| fnv(h, x as u64));
            lanes[1..].iter().fold(h, |h, &x| fnv(h, x))
        };
        let chunks: Vec<u64> = self
            .col_ptr
            .par_chunks(CHUNK)
            .chain(self.row_idx.par_chunks(CHUNK))
            .map(chunk_hash)
            .collect();
        PatternFingerprint {
            n: self.ncols,
            nnz: self.nnz(),
            hash: chunks.iter().fold(BASIS, |h, &x| fnv(h, x)),
        }
    }

    /// Returns the first value index holding a NaN or infinity.
    pub fn first_non_finite(&self) -> Option<usize> {
        const CHUNK: usize = 1 << 16;
        let bad = |v: &f64| !v.is_finite();
        let chunk = self
            .values
            .par_chunks(CHUNK)
            .position_first(|c| c.iter().any(bad))?;
        let within = self.values[chunk * CHUNK..].iter().position(bad)?;
        Some(chunk * CHUNK + within)
    }

    /// The first stored entry (row, column) whose mirror (column, row) is not stored, in
    /// column order; `None` for a structurally symmetric square matrix. Columns are checked
    /// in parallel by binary search, O(nnz log(nnz per column)): first only the strictly
    /// lower entries — if each has its mirror and there are as many strictly upper ones, the
    /// mirroring is one-to-one and the pattern symmetric — and all entries when that fails.
    pub fn structural_asymmetry(&self) -> Option<(usize, usize)> {
        if self.nrows != self.ncols {
            return Some((self.nrows.min(self.ncols), 0));
        }
        let below_diagonal = |j: usize| {
            let rows = self.col(j).0;
            &rows[rows.partition_point(|&i| i <= j)..]
        };
        let lower_mirrored = (0..self.ncols).into_par_iter().with_min_len(1024).all(|j| {
            below_diagonal(j)
                .iter()
                .all(|&i| self.col(i).0.binary_search(&j).is_ok())
        });
        if lower_mirrored {
            let (lower, diagonal): (usize, usize) = (0..self.ncols)
                .into_par_iter()
                .with_min_len(1024)
                .map(|j| {
                    let below = below_diagonal(j).len();
                    let on = usize::from(self.col(j).0.binary_search(&j).is_ok());
                    (below, on)
                })
                .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
            if 2 * lower + diagonal == self.nnz() {
                return None;
            }
        }
        (0..self.ncols)
            .into_par_iter()
            .with_min_len(1024)
            .find_map_first(|j| {
                self.col(j)
                    .0
                    .iter()
                    .find(|&&i| self.col(i).0.binary_search(&j).is_err())
                    .map(|&i| (i, j))
            })
    }

    /// Checks that the matrix is square with a symmetric pattern (what symmetric backends and
    /// the fill-reducing orderings need).
    pub fn check_structurally_symmetric(&self) -> Result<(), SolverError> {
        if self.nrows != self.ncols {
            return Err(SolverError::DimensionMismatch(format!(
                "matrix is {}×{}, not square",
                self.nrows, self.ncols
            )));
        }
        match self.structural_asymmetry() {
            None => Ok(()),
            Some((row, column)) => Err(SolverError::NotStructurallySymmetric { row, column }),
        }
    }

    /// Whether `|a_ij − a_ji| ≤ tol · max|a|` for all entries (pattern must be symmetric too).
    pub fn is_symmetric(&self, tol: f64) -> bool {
        if self.nrows != self.ncols {
            return false;
        }
        let scale = self.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        (0..self.ncols).all(|j| {
            let (rows, vals) = self.col(j);
            rows.iter().zip(vals).all(|(&i, &v)| {
                let (ri, vi) = self.col(i);
                match ri.binary_search(&j) {
                    Ok(k) => (vi[k] - v).abs() <= tol * scale,
                    Err(_) => v.abs() <= tol * scale,
                }
            })
        })
    }

    /// y = A x, serial.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for (j, &xj) in x.iter().enumerate().take(self.ncols) {
            let (rows, vals) = self.col(j);
            for (&i, &v) in rows.iter().zip(vals) {
                y[i] += v * xj;
            }
        }
    }

    /// y = A x for a **symmetric** A, in parallel: each column is read as a row (A = Aᵀ), so
    /// every output entry is written by one task and the result does not depend on threads.
    pub fn mul_vec_symmetric_par(&self, x: &[f64], y: &mut [f64]) {
        const CHUNK: usize = 2048;
        y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
            for (k, yi) in out.iter_mut().enumerate() {
                let (rows, vals) = self.col(c * CHUNK + k);
                *yi = rows.iter().zip(vals).map(|(&r, &v)| v * x[r]).sum();
            }
        });
    }

    /// y = A x and ‖A‖∞ for a **symmetric** A in one pass over its entries (the column's
    /// absolute sum beside its product; see [`CscRef::mul_vec_symmetric_par`]).
    pub fn mul_vec_symmetric_norm_par(&self, x: &[f64], y: &mut [f64]) -> f64 {
        const CHUNK: usize = 2048;
        y.par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, out)| {
                let mut norm = 0.0f64;
                for (k, yi) in out.iter_mut().enumerate() {
                    let (rows, vals) = self.col(c * CHUNK + k);
                    let (mut sum, mut abs) = (0.0, 0.0);
                    for (&r, &v) in rows.iter().zip(vals) {
                        sum += v * x[r];
                        abs += v.abs();
                    }
                    *yi = sum;
                    norm = norm.max(abs);
                }
                norm
            })
            .reduce(|| 0.0, f64::max)
    }

    /// Y = A X for a **symmetric** A and the `k` columns of `x` (length n each, stacked), with
    /// ‖A‖∞, in one pass over A (`CscRef::fold_many_symmetric_par`). Each entry of Y is the
    /// sum [`CscRef::mul_vec_symmetric_par`] forms, by one task: the result does not depend on
    /// the threads.
    pub fn mul_many_symmetric_norm_par(&self, x: &[f64], k: usize, y: &mut [f64]) -> f64 {
        let n = self.ncols;
        assert!(
            x.len() == n * k && y.len() == n * k,
            "X and Y must be n × k"
        );
        if n == 0 || k == 0 {
            return 0.0;
        }
        if k == 1 {
            // The same sums; the one-column loop is a third faster than a group of one.
            return self.mul_vec_symmetric_norm_par(x, y);
        }
        // Per chunk of rows: its piece of every column of Y.
        let mut pieces: Vec<Vec<&mut [f64]>> = (0..n.div_ceil(PRODUCT_CHUNK))
            .map(|_| Vec::with_capacity(k))
            .collect();
        for column in y.chunks_mut(n) {
            for (piece, rows) in pieces.iter_mut().zip(column.chunks_mut(PRODUCT_CHUNK)) {
                piece.push(rows);
            }
        }
        let (norm, _) = self.fold_many_symmetric_par(x, k, pieces, |columns, i, c0, sums| {
            for (column, &s) in columns[c0..].iter_mut().zip(sums) {
                column[i % PRODUCT_CHUNK] = s;
            }
        });
        norm
    }

    /// A X for a **symmetric** A and the `k` columns of `x` (length n each, stacked), handed
    /// to `visit` as it is formed, and ‖A‖∞, in one pass over A: the rows go in chunks of
    /// 1,024 to the threads, each column of A read as a row (A = Aᵀ) once for up
    /// to eight right-hand sides, its entries' products summed in registers.
    /// `visit(state, i, c0, sums)` receives the entries (i, c0), (i, c0 + 1), … of A X with
    /// the state of row i's chunk (`states` holds one per chunk, returned in chunk order).
    pub(crate) fn fold_many_symmetric_par<T: Send>(
        &self,
        x: &[f64],
        k: usize,
        states: Vec<T>,
        visit: impl Fn(&mut T, usize, usize, &[f64]) + Sync,
    ) -> (f64, Vec<T>) {
        const GROUP: usize = 8;
        let n = self.ncols;
        assert!(x.len() == n * k, "X must be n × k");
        assert_eq!(
            states.len(),
            n.div_ceil(PRODUCT_CHUNK),
            "one state per chunk"
        );
        if k == 0 {
            return (0.0, states);
        }
        // Each group of up to eight columns of X interleaved and padded to eight (row r's
        // values side by side): an entry's products are one vector operation, where the
        // columns apart took a load each. The seven residuals of L's cell problems: 0.108–0.113
        // → 0.078–0.087 s, the interleaved copy included.
        let groups: Vec<Vec<[f64; GROUP]>> = (0..k)
            .step_by(GROUP)
            .map(|c0| {
                let m = GROUP.min(k - c0);
                let row = |r: usize| {
                    std::array::from_fn(|c| if c < m { x[(c0 + c) * n + r] } else { 0.0 })
                };
                (0..n).into_par_iter().map(row).collect()
            })
            .collect();
        let folded: Vec<(f64, T)> = states
            .into_par_iter()
            .enumerate()
            .map(|(chunk, mut state)| {
                let rows_of_chunk = chunk * PRODUCT_CHUNK..n.min((chunk + 1) * PRODUCT_CHUNK);
                let mut norm = 0.0f64;
                for (g, c0) in (0..k).step_by(GROUP).enumerate() {
                    let m = GROUP.min(k - c0);
                    let xg = &groups[g];
                    for i in rows_of_chunk.clone() {
                        let (rows, vals) = self.col(i);
                        let sums = row_products(rows, vals, xg);
                        visit(&mut state, i, c0, &sums[..m]);
                        if c0 == 0 {
                            norm = norm.max(vals.iter().map(|v| v.abs()).sum());
                        }
                    }
                }
                (norm, state)
            })
            .collect();
        let norm = folded.iter().fold(0.0f64, |m, (v, _)| m.max(*v));
        (norm, folded.into_iter().map(|(_, t)| t).collect())
    }

    /// Copies into an owned matrix.
    pub fn to_owned(&self) -> CscMatrix {
        CscMatrix {
            nrows: self.nrows,
            ncols: self.ncols,
            col_ptr: self.col_ptr.to_vec(),
            row_idx: self.row_idx.to_vec(),
            values: self.values.to_vec(),
        }
    }
}

/// Σ_k v_k X[r_k] over a column's entries (`rows`, `vals`) for eight interleaved columns,
/// summed in entry order (the same sums as one column at a time), with the machine's widest
/// vectors (checked at run time).
fn row_products(rows: &[usize], vals: &[f64], x: &[[f64; 8]]) -> [f64; 8] {
    #[inline(always)]
    fn sums(rows: &[usize], vals: &[f64], x: &[[f64; 8]]) -> [f64; 8] {
        let mut s = [0.0; 8];
        for (&r, &v) in rows.iter().zip(vals) {
            for (sc, xc) in s.iter_mut().zip(&x[r]) {
                *sc += v * xc;
            }
        }
        s
    }
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx512f")]
        unsafe fn wide(rows: &[usize], vals: &[f64], x: &[[f64; 8]]) -> [f64; 8] {
            sums(rows, vals, x)
        }
        #[target_feature(enable = "avx")]
        unsafe fn avx(rows: &[usize], vals: &[f64], x: &[[f64; 8]]) -> [f64; 8] {
            sums(rows, vals, x)
        }
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F, checked above.
            return unsafe { wide(rows, vals, x) };
        }
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX, checked above.
            return unsafe { avx(rows, vals, x) };
        }
    }
    sums(rows, vals, x)
}

impl CscMatrix {
    /// Checks and takes ownership of the arrays.
    pub fn new(
        nrows: usize,
        ncols: usize,
        col_ptr: Vec<usize>,
        row_idx: Vec<usize>,
        values: Vec<f64>,
    ) -> Result<Self, SolverError> {
        check_structure(nrows, ncols, &col_ptr, &row_idx, values.len())?;
        Ok(CscMatrix {
            nrows,
            ncols,
            col_ptr,
            row_idx,
            values,
        })
    }

    /// Builds a matrix from (row, col, value) triplets; duplicates are summed.
    pub fn from_triplets(
        nrows: usize,
        ncols: usize,
        triplets: &[(usize, usize, f64)],
    ) -> Result<Self, SolverError> {
        let mut t: Vec<_> = triplets.to_vec();
        if let Some(&(i, j, _)) = t.iter().find(|&&(i, j, _)| i >= nrows || j >= ncols) {
            return Err(SolverError::InvalidMatrix(format!(
                "triplet ({i}, {j}) outside a {nrows}×{ncols} matrix"
            )));
        }
        t.sort_by_key(|&(i, j, _)| (j, i));
        let mut col_ptr = vec![0usize; ncols + 1];
        let mut row_idx = Vec::with_capacity(t.len());
        let mut values: Vec<f64> = Vec::with_capacity(t.len());
        let mut last: Option<(usize, usize)> = None;
        for (i, j, v) in t {
            if last == Some((i, j)) {
                if let Some(x) = values.last_mut() {
                    *x += v;
                }
                continue;
            }
            last = Some((i, j));
            row_idx.push(i);
            values.push(v);
            col_ptr[j + 1] += 1;
        }
        for j in 0..ncols {
            col_ptr[j + 1] += col_ptr[j];
        }
        Self::new(nrows, ncols, col_ptr, row_idx, values)
    }

    /// The full symmetric matrix A + Aᵀ − diag(A) of a matrix that stores one triangle of it
    /// (lower or upper, with its diagonal): what a symmetric Matrix Market file or
    /// `scipy.sparse.tril` gives. A matrix with entries in both strict triangles is refused
    /// ([`SolverError::InvalidMatrix`]): it is not a triangle.
    pub fn symmetric_from_triangle(a: CscRef<'_>) -> Result<Self, SolverError> {
        if a.nrows() != a.ncols() {
            return Err(SolverError::DimensionMismatch(format!(
                "matrix is {}×{}, not square",
                a.nrows(),
                a.ncols()
            )));
        }
        let (mut lower, mut upper) = (false, false);
        let mut t = Vec::with_capacity(2 * a.nnz());
        for j in 0..a.ncols() {
            let (rows, vals) = a.col(j);
            for (&i, &v) in rows.iter().zip(vals) {
                lower |= i > j;
                upper |= i < j;
                t.push((i, j, v));
                if i != j {
                    t.push((j, i, v));
                }
            }
        }
        if lower && upper {
            return Err(SolverError::InvalidMatrix(
                "entries in both strict triangles: not a single triangle of a symmetric matrix"
                    .into(),
            ));
        }
        Self::from_triplets(a.nrows(), a.ncols(), &t)
    }

    #[cfg(feature = "sprs")]
    /// Copies any sprs matrix (CSR or CSC, sliced or not) into CSC form.
    pub fn from_sprs(m: CsMatView<'_, f64>) -> Result<Self, SolverError> {
        let csc = if m.is_csc() { m.to_owned() } else { m.to_csc() };
        let col_ptr = csc.indptr().to_proper().into_owned();
        let base = col_ptr.first().copied().unwrap_or(0);
        let col_ptr: Vec<usize> = col_ptr.iter().map(|p| p - base).collect();
        let mut out = CscMatrix {
            nrows: csc.rows(),
            ncols: csc.cols(),
            col_ptr,
            row_idx: csc.indices().to_vec(),
            values: csc.data().to_vec(),
        };
        // sprs allows unsorted indices in principle; sort each column to our invariant.
        for j in 0..out.ncols {
            let r = out.col_ptr[j]..out.col_ptr[j + 1];
            let mut pairs: Vec<(usize, f64)> = out.row_idx[r.clone()]
                .iter()
                .copied()
                .zip(out.values[r.clone()].iter().copied())
                .collect();
            pairs.sort_by_key(|p| p.0);
            for (k, (i, v)) in r.zip(pairs) {
                out.row_idx[k] = i;
                out.values[k] = v;
            }
        }
        check_structure(
            out.nrows,
            out.ncols,
            &out.col_ptr,
            &out.row_idx,
            out.values.len(),
        )?;
        Ok(out)
    }

    #[cfg(feature = "sprs")]
    /// Converts to an sprs CSC matrix (for tools that work with sprs).
    pub fn to_sprs(&self) -> sprs::CsMat<f64> {
        sprs::CsMat::new_csc(
            (self.nrows, self.ncols),
            self.col_ptr.clone(),
            self.row_idx.clone(),
            self.values.clone(),
        )
    }

    /// Borrows as a [`CscRef`].
    pub fn as_ref(&self) -> CscRef<'_> {
        CscRef {
            nrows: self.nrows,
            ncols: self.ncols,
            col_ptr: &self.col_ptr,
            row_idx: &self.row_idx,
            values: &self.values,
        }
    }

    /// Mutable access to the values (the pattern stays fixed).
    pub fn values_mut(&mut self) -> &mut [f64] {
        &mut self.values
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `first_non_finite` gives the first bad value's index across the parallel chunks: a NaN
    /// late in the second chunk and an infinity later still give the NaN's index; none, `None`.
    #[test]
    fn the_first_non_finite_value_is_found_across_chunks() {
        let n = 200_000;
        let diagonal = |values: Vec<f64>| {
            CscMatrix::new(n, n, (0..=n).collect(), (0..n).collect(), values).unwrap()
        };
        let mut v = vec![1.0; n];
        assert_eq!(diagonal(v.clone()).as_ref().first_non_finite(), None);
        v[131_000] = f64::NAN;
        v[190_000] = f64::INFINITY;
        v[3] = 2.0;
        assert_eq!(diagonal(v).as_ref().first_non_finite(), Some(131_000));
    }

    /// The fingerprint tells apart patterns of one order and entry count — one column's
    /// off-diagonal row moved, or two neighbouring columns' (in different streams) — and is
    /// the same on one thread and on several (200,001 pointers and 400,000 rows: 10 chunks).
    #[test]
    fn the_fingerprint_sees_moved_entries_and_not_the_threads() {
        let n = 200_000;
        // Two entries per column: the diagonal and row (j + shift) mod n.
        let pattern = |shift: &dyn Fn(usize) -> usize| {
            let rows: Vec<usize> = (0..n)
                .flat_map(|j| {
                    let (a, b) = (j, (j + shift(j)) % n);
                    [a.min(b), a.max(b)]
                })
                .collect();
            CscMatrix::new(
                n,
                n,
                (0..=n).map(|j| 2 * j).collect(),
                rows,
                vec![1.0; 2 * n],
            )
            .unwrap()
        };
        let base = pattern(&|_| 1);
        let moved = pattern(&|j| if j == 150_001 { 2 } else { 1 });
        let swapped = pattern(&|j| match j {
            7 => 2,
            8 => 1_000,
            _ => 1,
        });
        let f = base.as_ref().fingerprint();
        assert_ne!(f, moved.as_ref().fingerprint());
        assert_ne!(f, swapped.as_ref().fingerprint());
        let one_thread = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        assert_eq!(one_thread.install(|| base.as_ref().fingerprint()), f);
    }

    /// `structural_asymmetry` names the first entry in column order whose mirror is missing,
    /// as a scan of every entry does, on random patterns of order 1 to 9 — symmetric ones,
    /// ones with an entry dropped or added, with and without diagonals (the shortcut through
    /// the strictly lower entries and the counts must not miss an unmirrored upper entry).
    #[test]
    fn structural_asymmetry_is_the_first_unmirrored_entry() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |m: u64| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) % m
        };
        let (mut symmetric, mut asymmetric) = (0, 0);
        for case in 0..3000 {
            let n = 1 + next(9) as usize;
            let mut entries = std::collections::BTreeSet::new();
            for _ in 0..next(3 * n as u64 + 1) {
                let (i, j) = (next(n as u64) as usize, next(n as u64) as usize);
                entries.insert((j, i));
                entries.insert((i, j));
            }
            match case % 3 {
                0 => {}
                1 => {
                    let (i, j) = (next(n as u64) as usize, next(n as u64) as usize);
                    entries.insert((j, i)); // (column, row): one entry, maybe unmirrored
                }
                _ => {
                    if let Some(&e) = entries.iter().nth(next(entries.len() as u64 + 1) as usize) {
                        entries.remove(&e);
                    }
                }
            }
            let triplets: Vec<(usize, usize, f64)> =
                entries.iter().map(|&(j, i)| (i, j, 1.0)).collect();
            let a = CscMatrix::from_triplets(n, n, &triplets).unwrap();
            let a = a.as_ref();
            let want = (0..n).find_map(|j| {
                a.col(j)
                    .0
                    .iter()
                    .find(|&&i| !a.col(i).0.contains(&j))
                    .map(|&i| (i, j))
            });
            assert_eq!(a.structural_asymmetry(), want, "case {case}: {entries:?}");
            if want.is_some() {
                asymmetric += 1;
            } else {
                symmetric += 1;
            }
        }
        assert!(
            symmetric > 1000 && asymmetric > 500,
            "{symmetric} / {asymmetric}"
        );
    }

    /// A symmetric matrix of order n with a varying diagonal and the given off-diagonals.
    fn banded_symmetric(n: usize, offsets: &[usize]) -> CscMatrix {
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, 4.0 + (i % 7) as f64));
            for &off in offsets.iter().filter(|&&off| i + off < n) {
                let v = -1.0 - (i % 5) as f64 * 0.25;
                t.push((i, i + off, v));
                t.push((i + off, i, v));
            }
        }
        CscMatrix::from_triplets(n, n, &t).unwrap()
    }

    /// The fused product and norm equal `mul_vec` and `norm_inf` on a symmetric matrix larger
    /// than one parallel chunk (to rounding of the sums, 1e-14).
    #[test]
    fn fused_symmetric_product_and_norm_match_the_separate_ones() {
        let n = 5000;
        let a = banded_symmetric(n, &[3]);
        let x: Vec<f64> = (0..n).map(|i| ((i * 17) % 13) as f64 - 6.0).collect();
        let (mut y1, mut y2) = (vec![0.0; n], vec![0.0; n]);
        a.as_ref().mul_vec(&x, &mut y1);
        let norm = a.as_ref().mul_vec_symmetric_norm_par(&x, &mut y2);
        assert!((norm - crate::norm_inf(a.as_ref())).abs() <= 1e-14 * norm);
        for (p, q) in y1.iter().zip(&y2) {
            assert!((p - q).abs() <= 1e-14 * (1.0 + p.abs()), "{p} vs {q}");
        }
    }

    /// The k-column product and norm equal `mul_vec` per column and `norm_inf` on a symmetric
    /// matrix of several chunks (to rounding of the sums, 1e-14), on one and three threads.
    #[test]
    fn several_column_symmetric_product_matches_one_column_at_a_time() {
        let n = 3001;
        let a = banded_symmetric(n, &[3, 1100]);
        let k = 11;
        let x: Vec<f64> = (0..n * k).map(|i| ((i * 17) % 13) as f64 - 6.0).collect();
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut y = vec![f64::NAN; n * k];
            let norm = pool.install(|| a.as_ref().mul_many_symmetric_norm_par(&x, k, &mut y));
            assert!((norm - crate::norm_inf(a.as_ref())).abs() <= 1e-14 * norm);
            for c in 0..k {
                let mut want = vec![0.0; n];
                a.as_ref().mul_vec(&x[c * n..(c + 1) * n], &mut want);
                for (p, q) in want.iter().zip(&y[c * n..(c + 1) * n]) {
                    assert!((p - q).abs() <= 1e-14 * (1.0 + p.abs()), "{p} vs {q}");
                }
            }
        }
    }

    /// A pattern checked once, then wrapped with values checking sizes only.
    #[test]
    fn checked_pattern_then_unchecked_views_check_sizes() {
        assert!(CscRef::check_pattern(2, 2, &[0, 2, 3], &[1, 0, 1]).is_err());
        assert!(CscRef::check_pattern(2, 2, &[0, 2, 3], &[0, 1, 1]).is_ok());
        // SAFETY: the pattern was checked just above.
        let a = unsafe { CscRef::new_unchecked(2, 2, &[0, 2, 3], &[0, 1, 1], &[1.0, 2.0, 3.0]) };
        assert_eq!(a.map(|a| a.nnz()).ok(), Some(3));
        // SAFETY: as above.
        let e = unsafe { CscRef::new_unchecked(2, 2, &[0, 2, 3], &[0, 1, 1], &[1.0]) };
        assert!(matches!(e, Err(SolverError::InvalidMatrix(_))));
    }

    #[test]
    fn rejects_unsorted_rows_and_bad_pointers() {
        let e = CscRef::new(2, 2, &[0, 2, 3], &[1, 0, 1], &[1.0, 2.0, 3.0]).unwrap_err();
        assert!(
            e.to_string().contains("strictly increasing in column 0"),
            "{e}"
        );
        let e = CscRef::new(2, 2, &[0, 2], &[0, 1], &[1.0, 2.0]).unwrap_err();
        assert!(e.to_string().contains("ncols + 1"), "{e}");
        let e = CscRef::new(2, 2, &[0, 1, 2], &[0, 5], &[1.0, 2.0]).unwrap_err();
        assert!(e.to_string().contains("out of range"), "{e}");
    }

    /// A pattern large enough to be checked on all threads reports its lowest bad column,
    /// whichever thread meets a later one first, and passes when it has none.
    #[test]
    fn a_large_pattern_reports_its_first_bad_column() {
        let n = 300_000;
        let col_ptr: Vec<usize> = (0..=n).map(|j| 4 * j).collect();
        let mut rows: Vec<usize> = (0..n)
            .flat_map(|j| (0..4).map(move |k| (j + k) % n))
            .collect();
        // Column j holds j, j + 1, j + 2, j + 3 (mod n), sorted.
        for c in rows.chunks_mut(4) {
            c.sort_unstable();
        }
        assert!(rows.len() >= PARALLEL_CHECK_ENTRIES);
        CscRef::check_pattern(n, n, &col_ptr, &rows).unwrap();
        let mut bad = rows.clone();
        bad.swap(4 * 200_000, 4 * 200_000 + 1);
        bad[4 * 250_000 + 2] = n + 7;
        bad[4 * 299_999] = n;
        let e = CscRef::check_pattern(n, n, &col_ptr, &bad).unwrap_err();
        assert!(
            e.to_string()
                .contains("strictly increasing in column 200000"),
            "{e}"
        );
        bad.swap(4 * 200_000, 4 * 200_000 + 1);
        let e = CscRef::check_pattern(n, n, &col_ptr, &bad).unwrap_err();
        assert!(
            e.to_string().contains(&format!(
                "row index {} out of range in column 250000",
                n + 7
            )),
            "{e}"
        );
    }

    #[cfg(feature = "sprs")]
    #[test]
    fn sprs_round_trip_csr_and_csc() {
        let a = CscMatrix::from_triplets(
            3,
            3,
            &[
                (0, 0, 4.0),
                (1, 0, 1.0),
                (0, 1, 1.0),
                (1, 1, 3.0),
                (2, 2, 2.0),
                (2, 2, 0.5),
            ],
        )
        .unwrap();
        let s = a.to_sprs();
        let back = CscMatrix::from_sprs(s.view()).unwrap();
        assert_eq!(back, a);
        let csr = s.to_csr();
        assert_eq!(CscMatrix::from_sprs(csr.view()).unwrap(), a);
        assert!(CscRef::try_from_sprs(&csr.view()).is_err());
        let sv = s.view();
        let borrowed = CscRef::try_from_sprs(&sv).unwrap();
        assert_eq!(borrowed.values(), a.as_ref().values());
        assert_eq!(a.as_ref().diagonal(), vec![4.0, 3.0, 2.5]);
    }

    #[test]
    fn parallel_symmetric_spmv_matches_serial() {
        let n = 5000;
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, 4.0 + i as f64 * 1e-3));
            if i + 7 < n {
                t.push((i, i + 7, -1.0));
                t.push((i + 7, i, -1.0));
            }
        }
        let a = CscMatrix::from_triplets(n, n, &t).unwrap();
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let (mut y1, mut y2) = (vec![0.0; n], vec![0.0; n]);
        a.as_ref().mul_vec(&x, &mut y1);
        a.as_ref().mul_vec_symmetric_par(&x, &mut y2);
        for (p, q) in y1.iter().zip(&y2) {
            assert!((p - q).abs() <= 1e-14 * p.abs().max(1.0));
        }
        assert!(a.as_ref().is_symmetric(0.0));
    }
}
