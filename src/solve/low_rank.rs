//! Solves after contact changes on one fixed factorization (Sherman–Morrison–Woodbury).
//!
//! With A₀ the factorized matrix, a contact whose block coefficients changed by ΔD_c adds
//! U_c ΔD_c U_cᵀ, U_c its jump rows in the free DOFs (see
//! [`ContactPair::jump_basis`](crate::contact::ContactPair)); all changes together are
//! A = A₀ + U E Uᵀ with E block diagonal, and
//!
//! x = A₀⁻¹ b − A₀⁻¹ U z,  (I + E S) z = E Uᵀ A₀⁻¹ b,  S = Uᵀ A₀⁻¹ U:
//!
//! two solves with A₀ and one dense LU of order R (the changed contacts' columns). S is kept:
//! a contact's columns are solved for once (many right-hand sides at a time) and serve every
//! later solve on the same A₀, whatever its state or slip direction then. E may be
//! nonsymmetric (Coulomb sliding) while A₀ is a symmetric factorization.

use super::dense_lu::DenseLu;
use super::gram::new_gram_columns;
use crate::contact::BlockCoefficients;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Accum, Mat, MatMut, MatRef, Par};
use fibercell_solver::{ForwardColumns, LinearSolver, SolverError};
use nalgebra::Vector6;
use rayon::prelude::*;
use std::cell::RefCell;
use std::collections::HashMap;

/// The order in which a contact's jump rows become columns of U: the two tangents first (all a
/// switch between stick and slip or a new slip direction needs), then the normal (Coulomb
/// sliding, opening), then the three rotations.
const ORDER: [usize; 6] = [1, 2, 0, 3, 4, 5];

/// Bytes of right-hand sides solved for at once when columns are added.
const BATCH_BYTES: usize = 256 << 20;

/// Columns forward-solved at once (their values lie on elimination-tree paths only). A batch is
/// one pass over the top separators with wide panels: L's 764 columns at 1 % took 266 ms in
/// three batches of 256 and 206 ms in one (medians of nine, side by side); the bound keeps a
/// batch's dense values near the top blocks (3,240 rows × 1,024 columns on L, 27 MB) small.
const FORWARD_BATCH: usize = 1024;

/// The order S's storage is reserved for when it first grows (see
/// [`LowRankCorrection::grow_s`]): the default bound on the columns kept on one factorization,
/// 128 MiB of address space.
const S_RESERVED_ORDER: usize = super::MAX_LOW_RANK_COLUMNS;

/// Products Wᵀ W of one block below this many multiply-adds run single-threaded.
const PARALLEL_PRODUCT: usize = 1 << 20;

/// One contact's change since the reference: of its block coefficients (ΔD) and of its load
/// coefficients (Δχ, the load G χ including the products of the block with prescribed DOFs).
#[derive(Clone, Copy, Debug)]
pub struct ContactChange {
    pub contact: usize,
    pub stiffness: BlockCoefficients,
    pub load: Vector6<f64>,
}

impl ContactChange {
    /// Whether anything changed.
    pub(crate) fn is_change(&self) -> bool {
        self.columns_needed() > 0
    }

    /// Whether the block changed (not only the load): the contact is then a row of the
    /// capacitance matrix.
    pub(crate) fn changes_block(&self) -> bool {
        self.stiffness.iter().any(|&v| v != 0.0)
    }

    /// How many leading entries of the column order the change needs (0: none).
    fn columns_needed(&self) -> usize {
        columns_needed(&self.stiffness, &self.load)
    }

    /// The rank of the block's change as `RankFactors` keeps it (its needed columns are its
    /// only nonzero ones, so the 6 × 6 matrix's rank is theirs): singular values only, on
    /// the stack.
    fn rank(&self) -> usize {
        let s = self.stiffness.singular_values();
        let largest = s.max();
        s.iter()
            .filter(|&&v| kept_singular_value(v, largest))
            .count()
    }
}

/// Whether a singular value `v` of a block whose largest is `largest` counts for its rank:
/// above 10⁻¹³ of the largest.
fn kept_singular_value(v: f64, largest: f64) -> bool {
    largest > 0.0 && v > 1e-13 * largest
}

/// How many leading entries of the column order a change `e` of block coefficients and `f` of
/// load coefficients need (0: none).
fn columns_needed(e: &BlockCoefficients, f: &Vector6<f64>) -> usize {
    let touches = |i: usize| f[i] != 0.0 || (0..6).any(|j| e[(i, j)] != 0.0 || e[(j, i)] != 0.0);
    if (3..6).any(touches) {
        6
    } else if touches(0) {
        3
    } else if touches(1) || touches(2) {
        2
    } else {
        0
    }
}

/// A sparse column of U: (free DOF, value), DOFs distinct.
pub type SparseColumn = Vec<(usize, f64)>;

fn dot(column: &SparseColumn, x: &[f64]) -> f64 {
    column.iter().map(|&(i, v)| v * x[i]).sum()
}

/// The columns U and S = Uᵀ A₀⁻¹ U accumulated on one factorization A₀.
#[derive(Clone)]
pub struct LowRankCorrection {
    n: usize,
    columns: Vec<SparseColumn>,
    /// Per contact: indices of its columns, in [`ORDER`].
    owned: Vec<Vec<usize>>,
    /// S = Uᵀ A₀⁻¹ U (order `columns.len()`).
    s: Mat<f64>,
    /// How the columns of S are computed on this A₀.
    mode: ColumnMode,
}

/// How S's columns are computed.
#[derive(Clone)]
enum ColumnMode {
    /// Not known yet (no columns).
    Unknown,
    /// S = Wᵀ W from the backend's sparse forward solves W = L⁻¹ P Ŝ U, kept block by block
    /// (block of L → its rows, the columns reaching it, their values).
    Forward(HashMap<usize, StoredBlock>),
    /// Full solves A₀⁻¹ U, many right-hand sides at a time.
    Solves,
}

/// The rows of W in one block of L, for every column so far that reaches it.
#[derive(Clone)]
struct StoredBlock {
    first_row: usize,
    rows: usize,
    columns: Vec<usize>,
    values: Vec<f64>,
}

impl StoredBlock {
    /// Its values as a `rows × columns` matrix.
    fn matrix(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.values, self.rows, self.columns.len())
    }

    /// The threads of a product with one vector (see [`one_vector_par`]).
    fn par(&self) -> Par {
        one_vector_par(self.values.len())
    }
}

/// The threads of a product or triangular solve with one vector over a matrix of `values`
/// entries: all of them from [`PARALLEL_PRODUCT`] on (the matrix is read once,
/// bandwidth-bound on one core), else one.
fn one_vector_par(values: usize) -> Par {
    if values >= PARALLEL_PRODUCT {
        Par::rayon(0)
    } else {
        Par::Seq
    }
}

/// The factorized capacitance matrix I + E S of one set of changes: of the contacts whose
/// block changed; those whose load changed alone (E = 0, e.g. a stuck contact with a new
/// slip) only add their U Δχ.
pub struct Capacitance {
    /// Per contact whose block changed: its columns and its E (row-major, in column order).
    blocks: Vec<(Vec<usize>, Vec<f64>)>,
    /// Their columns, block after block: the rows of the capacitance matrix.
    active: Vec<usize>,
    /// Every changed contact's columns, in the order of their load
    /// ([`LowRankCorrection::active_load`]).
    loaded: Vec<usize>,
    factor: CapacitanceFactor,
}

/// How the capacitance system is solved.
enum CapacitanceFactor {
    /// Every E_c = −C_c C_cᵀ (symmetric, negative semi-definite: contacts that lost springs,
    /// stick → slip with Tresca or no friction, closed → open): the symmetric positive
    /// definite I − Cᵀ S C by Cholesky, half the flops of an LU. C_c row-major per block.
    Cholesky {
        c: Vec<Vec<f64>>,
        /// The factor L, column-major, order [`Capacitance::order`] (its lower triangle; above
        /// it zeros, or within a contact's diagonal block the matrix's entries, unused).
        l: Vec<f64>,
    },
    /// Otherwise each E_c = X_c Y_cᵀ of its rank r_c (a nonsymmetric Coulomb-sliding block
    /// relative to stick has rank 2 in its three translational columns), and
    /// I + Yᵀ S X, of order Σ r_c, by LU with partial pivoting.
    Lu {
        factors: Vec<RankFactors>,
        lu: DenseLu,
    },
}

/// E = X Yᵀ for a k × k block E: X = U_r Σ_r and Y = V_r of its singular value decomposition,
/// without the singular values below 10⁻¹³ of the largest. Row-major k × r.
struct RankFactors {
    x: Vec<f64>,
    y: Vec<f64>,
    rank: usize,
}

impl RankFactors {
    fn of(e: &[f64], k: usize) -> Self {
        let svd = nalgebra::DMatrix::from_row_slice(k, k, e).svd(true, true);
        let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
            unreachable!("both singular vector sets were requested")
        };
        let largest = svd.singular_values.iter().fold(0.0f64, |m, &v| m.max(v));
        let kept: Vec<usize> = (0..k)
            .filter(|&a| kept_singular_value(svd.singular_values[a], largest))
            .collect();
        let rank = kept.len();
        let mut x = vec![0.0; k * rank];
        let mut y = vec![0.0; k * rank];
        for (b, &a) in kept.iter().enumerate() {
            for i in 0..k {
                x[i * rank + b] = u[(i, a)] * svd.singular_values[a];
                y[i * rank + b] = v_t[(a, i)];
            }
        }
        RankFactors { x, y, rank }
    }
}

/// C with C Cᵀ = −E for a symmetric negative semi-definite k × k block `e` (row-major), to
/// rounding; `None` otherwise.
fn negative_square_root(e: &[f64], k: usize) -> Option<Vec<f64>> {
    let scale = e.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let tol = 1e-12 * scale;
    let symmetric = (0..k).all(|i| (0..k).all(|l| (e[i * k + l] - e[l * k + i]).abs() <= tol));
    if !symmetric {
        return None;
    }
    let f = nalgebra::DMatrix::from_fn(k, k, |i, l| -0.5 * (e[i * k + l] + e[l * k + i]));
    let eig = nalgebra::SymmetricEigen::new(f);
    if eig.eigenvalues.iter().any(|&l| l < -tol) {
        return None;
    }
    let mut c = vec![0.0; k * k];
    for a in 0..k {
        let root = eig.eigenvalues[a].max(0.0).sqrt();
        for i in 0..k {
            c[i * k + a] = eig.eigenvectors[(i, a)] * root;
        }
    }
    Some(c)
}

impl Capacitance {
    /// Its order R: the changed blocks' columns (Cholesky) or ranks (LU).
    pub fn order(&self) -> usize {
        match &self.factor {
            CapacitanceFactor::Cholesky { .. } => self.active.len(),
            CapacitanceFactor::Lu { factors, .. } => factors.iter().map(|f| f.rank).sum(),
        }
    }

    /// The number of load coefficients it goes with (every changed contact's columns).
    pub fn loads(&self) -> usize {
        self.loaded.len()
    }

    /// Bytes it holds: the factorized matrix of order R and its blocks' factors.
    pub(crate) fn memory_bytes(&self) -> usize {
        let f64s = |v: &Vec<f64>| v.capacity() * size_of::<f64>();
        let usizes = |v: &Vec<usize>| v.capacity() * size_of::<usize>();
        let blocks: usize = self.blocks.iter().map(|(c, e)| usizes(c) + f64s(e)).sum();
        let factor = match &self.factor {
            CapacitanceFactor::Cholesky { c, l } => c.iter().map(f64s).sum::<usize>() + f64s(l),
            CapacitanceFactor::Lu { factors, lu } => {
                let ranks: usize = factors.iter().map(|f| f64s(&f.x) + f64s(&f.y)).sum();
                lu.memory_bytes() + ranks
            }
        };
        blocks + usizes(&self.active) + usizes(&self.loaded) + factor
    }
}

impl LowRankCorrection {
    /// No columns, for `contacts` contacts and `n` free DOFs.
    pub fn new(n: usize, contacts: usize) -> Self {
        LowRankCorrection {
            n,
            columns: Vec::new(),
            owned: vec![Vec::new(); contacts],
            s: Mat::zeros(0, 0),
            mode: ColumnMode::Unknown,
        }
    }

    /// Right-hand sides solved for at once.
    fn batch(&self) -> usize {
        (BATCH_BYTES / (8 * self.n.max(1))).clamp(2, 256)
    }

    /// Forgets all columns (A₀ was refactorized).
    pub(crate) fn reset(&mut self) {
        self.columns.clear();
        self.owned.iter_mut().for_each(Vec::clear);
        self.s = Mat::zeros(0, 0);
        self.mode = ColumnMode::Unknown;
    }

    /// Unknowns and contacts it was made for.
    pub(crate) fn sizes(&self) -> (usize, usize) {
        (self.n, self.owned.len())
    }

    /// Columns of U so far.
    pub(crate) fn len(&self) -> usize {
        self.columns.len()
    }

    /// Bytes it holds: the columns of U, their forward solves (block by block) and S.
    pub(crate) fn memory_bytes(&self) -> usize {
        let entry = size_of::<(usize, f64)>();
        let columns: usize = self.columns.iter().map(|c| c.capacity() * entry).sum();
        let owned: usize = self.owned.iter().map(|o| o.capacity()).sum::<usize>() * 8;
        // The written rows of each column: the reserved rest is not resident.
        let s = self.s.nrows() * self.s.ncols() * 8;
        let forward: usize = match &self.mode {
            ColumnMode::Forward(blocks) => blocks
                .values()
                .map(|b| (b.values.capacity() + b.columns.capacity()) * 8)
                .sum(),
            ColumnMode::Unknown | ColumnMode::Solves => 0,
        };
        columns + owned + s + forward
    }

    /// The order of the capacitance matrix of `changes` (the ranks of their blocks) and how
    /// many of its columns are new.
    pub(crate) fn size_of(&self, changes: &[ContactChange]) -> (usize, usize) {
        changes.iter().fold((0, 0), |(order, new), ch| {
            let have = self.owned[ch.contact].len();
            let need = ch.columns_needed().max(have);
            let rows = if ch.changes_block() { ch.rank() } else { 0 };
            (order + rows, new + need - have)
        })
    }

    /// Adds the columns `changes` need, `column(contact, basis row)` giving one (basis rows as
    /// in [`BlockCoefficients`]), and extends S by solving with the factorization `a0`.
    pub(crate) fn extend(
        &mut self,
        a0: &mut dyn LinearSolver,
        changes: &[ContactChange],
        column: impl Fn(usize, usize) -> SparseColumn + Sync,
    ) -> Result<(), SolverError> {
        let first = self.add_columns(changes, column);
        self.solve_columns(a0, first, None).map(|_| ())
    }

    /// [`LowRankCorrection::extend`], and the [`Reference`] of the right-hand side `b0(self)`
    /// (called once the new columns are there, e.g. to take U Δχ off the load): with S from
    /// forward solves, b₀'s forward half goes through the factor along with the first new
    /// columns, each block of L read once for both.
    ///
    /// `known(b₀)`, when it gives the reference without a solve (see
    /// [`super::affine_reference::AffineReferences`]), is taken instead, and the new columns
    /// are solved for alone.
    pub fn extend_with_reference(
        &mut self,
        a0: &mut dyn LinearSolver,
        changes: &[ContactChange],
        column: impl Fn(usize, usize) -> SparseColumn + Sync,
        b0: impl FnOnce(&Self) -> Vec<f64>,
        known: impl FnOnce(&Self, &[f64]) -> Option<Reference>,
    ) -> Result<Reference, SolverError> {
        let first = self.add_columns(changes, column);
        let mut b = b0(self);
        if let Some(reference) = known(self, &b) {
            self.solve_columns(a0, first, None)?;
            return Ok(reference);
        }
        if self.solve_columns(a0, first, Some(&mut b))? {
            Ok(Reference::forward(b))
        } else {
            self.reference(a0, b)
        }
    }

    /// Adds the columns `changes` need (see [`LowRankCorrection::extend`]); the index of the
    /// first new one.
    fn add_columns(
        &mut self,
        changes: &[ContactChange],
        column: impl Fn(usize, usize) -> SparseColumn + Sync,
    ) -> usize {
        let first = self.columns.len();
        let wanted: Vec<(usize, usize)> = changes
            .iter()
            .flat_map(|ch| {
                let (c, have) = (ch.contact, self.owned[ch.contact].len());
                (have..ch.columns_needed().max(have)).map(move |k| (c, ORDER[k]))
            })
            .collect();
        let new: Vec<SparseColumn> = wanted.par_iter().map(|&(c, k)| column(c, k)).collect();
        for (j, &(c, _)) in wanted.iter().enumerate() {
            self.owned[c].push(first + j);
        }
        self.columns.extend(new);
        first
    }

    /// Extends S by the columns `first..`; with `rhs`, also its forward half in place when
    /// it could go along with the columns' forward solves (then `true`).
    fn solve_columns(
        &mut self,
        a0: &mut dyn LinearSolver,
        first: usize,
        mut rhs: Option<&mut Vec<f64>>,
    ) -> Result<bool, SolverError> {
        let total = self.columns.len();
        if first == total {
            return Ok(false);
        }
        let batch = self.batch();
        let n = self.n;
        self.grow_s(total);
        let mut fused = false;
        if !matches!(self.mode, ColumnMode::Solves) {
            for start in (first..total).step_by(FORWARD_BATCH) {
                let end = (start + FORWARD_BATCH).min(total);
                let columns = &self.columns[start..end];
                let w = match rhs.take() {
                    // A backend that cannot go along falls back to the columns alone.
                    Some(x) => match a0.forward_solve_sparse_and_lower(columns, x) {
                        Err(SolverError::Unavailable { .. }) => a0.forward_solve_sparse(columns),
                        w => {
                            fused = w.is_ok();
                            w
                        }
                    },
                    None => a0.forward_solve_sparse(columns),
                };
                match w {
                    Ok(w) => self.add_forward(start, w),
                    Err(SolverError::Unavailable { .. })
                        if matches!(self.mode, ColumnMode::Unknown) =>
                    {
                        self.mode = ColumnMode::Solves;
                        break;
                    }
                    Err(e) => return Err(e),
                }
            }
            if !matches!(self.mode, ColumnMode::Solves) {
                return Ok(fused);
            }
        }
        for start in (first..total).step_by(batch) {
            let end = (start + batch).min(total);
            let k = end - start;
            let mut z = vec![0.0; n * k];
            for (j, col) in self.columns[start..end].iter().enumerate() {
                for &(i, v) in col {
                    z[j * n + i] += v;
                }
            }
            a0.solve_in_place(&mut z, k)?;
            let columns = &self.columns;
            let products: Vec<Vec<f64>> = z
                .par_chunks(n)
                .map(|zj| columns.iter().map(|u| dot(u, zj)).collect())
                .collect();
            for (j, p) in products.iter().enumerate() {
                let c = start + j;
                for (row, &v) in p.iter().enumerate() {
                    self.s[(row, c)] = v;
                    if row < start {
                        // S is symmetric for a symmetric A₀.
                        self.s[(c, row)] = v;
                    }
                }
            }
        }
        Ok(false)
    }

    /// Grows S to order `total`, in place within the storage reserved when it first grows
    /// past its capacity: for the order of [`S_RESERVED_ORDER`] columns or of all the contacts'
    /// columns, whichever is smaller. Growing faer's matrix past its capacity copies it into a
    /// new allocation, both resident at once: 0.39 + 0.46 GB at 7,600 columns on the L curve,
    /// at every growth. The reservation is address space: only the pages written are resident
    /// (8 bytes × order², rounded up to pages per column); where it cannot be had, S grows
    /// by copies as before.
    fn grow_s(&mut self, total: usize) {
        if self.s.col_stride().unsigned_abs() < total {
            let order = S_RESERVED_ORDER
                .min(ORDER.len() * self.owned.len())
                .max(total);
            // Columns a multiple of 4 KiB apart would map a row's entries to one cache set.
            // (faer rounds the rows up to its SIMD alignment, at most 16 doubles.)
            let rows = order.next_multiple_of(16);
            let rows = if rows.is_multiple_of(512) {
                rows + 16
            } else {
                rows
            };
            // A failed reservation leaves the matrix as it was.
            let _ = self.s.try_reserve(rows, order);
        }
        self.s.resize_with(total, total, |_, _| 0.0);
    }

    /// Adds S's entries for the columns `start..` from their forward solves `w`:
    /// S = Wᵀ W block by block of L, each block's new columns against all its columns (the
    /// blocks' products in parallel, the large ones split further).
    fn add_forward(&mut self, start: usize, w: ForwardColumns) {
        if matches!(self.mode, ColumnMode::Unknown) {
            self.mode = ColumnMode::Forward(HashMap::new());
        }
        let ColumnMode::Forward(store) = &mut self.mode else {
            return;
        };
        let end = start + w.ncols;
        // Each block's new columns appended (a new block takes the solved values as they are).
        let mut updated = Vec::with_capacity(w.blocks.len());
        for blk in w.blocks {
            let stored = store.entry(blk.block).or_insert_with(|| StoredBlock {
                first_row: blk.first_row,
                rows: blk.rows,
                columns: Vec::new(),
                values: Vec::new(),
            });
            let old = stored.columns.len();
            stored.columns.extend(blk.columns.iter().map(|c| start + c));
            if stored.values.is_empty() {
                stored.values = blk.values;
            } else {
                stored.values.extend(blk.values);
            }
            updated.push((blk.block, old));
        }
        let store = &*store;
        // The updated blocks, each looked up once.
        let updated: Vec<(&StoredBlock, usize)> = updated
            .into_iter()
            .map(|(block, old)| (&store[&block], old))
            .collect();
        let products: Vec<Vec<f64>> = updated
            .par_iter()
            .map(|&(stored, old)| {
                let (rows, all) = (stored.rows, stored.columns.len());
                let w_all = MatRef::from_column_major_slice(&stored.values, rows, all);
                let threads = if rows * all * (all - old) > PARALLEL_PRODUCT {
                    rayon::current_num_threads()
                } else {
                    1
                };
                new_gram_columns(w_all, old, threads)
            })
            .collect();
        // The new columns of S summed on the threads, one column each: the products' columns
        // that add to it, in block order.
        let mut parts: Vec<Vec<(usize, usize)>> = vec![Vec::new(); end - start];
        for (i, &(stored, old)) in updated.iter().enumerate() {
            for (b, &col) in stored.columns[old..].iter().enumerate() {
                parts[col - start].push((i, b));
            }
        }
        let r = self.s.nrows();
        let mut fresh = vec![0.0; r * (end - start)];
        fresh
            .par_chunks_mut(r)
            .zip(&parts)
            .for_each(|(out, parts)| {
                for &(i, b) in parts {
                    let columns = &updated[i].0.columns;
                    let all = columns.len();
                    for (&row, &v) in columns.iter().zip(&products[i][b * all..(b + 1) * all]) {
                        out[row] += v;
                    }
                }
            });
        // Nothing was in the new columns before; their rows of the older columns mirror them.
        for (c, column) in (start..end).zip(fresh.chunks(r)) {
            self.s.col_as_slice_mut(c).copy_from_slice(column);
        }
        for c in start..end {
            for row in 0..start {
                self.s[(c, row)] = self.s[(row, c)];
            }
        }
    }

    /// Factorizes I + E S for `changes` (each contact's columns must be there: see
    /// [`LowRankCorrection::extend`]).
    pub fn capacitance(&self, changes: &[ContactChange]) -> Capacitance {
        let loaded: Vec<usize> = changes
            .iter()
            .flat_map(|ch| self.owned[ch.contact].iter().copied())
            .collect();
        let blocks: Vec<(Vec<usize>, Vec<f64>)> = changes
            .iter()
            .filter(|ch| ch.changes_block())
            .map(|ch| {
                let e = &ch.stiffness;
                let cols = self.owned[ch.contact].clone();
                let k = cols.len();
                let mut block = vec![0.0; k * k];
                for i in 0..k {
                    for l in 0..k {
                        block[i * k + l] = e[(ORDER[i], ORDER[l])];
                    }
                }
                (cols, block)
            })
            .collect();
        let active: Vec<usize> = blocks.iter().flat_map(|(c, _)| c.clone()).collect();
        let roots: Option<Vec<Vec<f64>>> = blocks
            .iter()
            .map(|(cols, e)| negative_square_root(e, cols.len()))
            .collect();
        if let Some(c) = roots {
            if let Some(l) = self.symmetric_capacitance(&blocks, &active, &c) {
                return Capacitance {
                    blocks,
                    active,
                    loaded,
                    factor: CapacitanceFactor::Cholesky { c, l },
                };
            }
        }
        let factors: Vec<RankFactors> = blocks
            .iter()
            .map(|(cols, e)| RankFactors::of(e, cols.len()))
            .collect();
        let lu = self.rank_capacitance(&blocks, &active, &factors);
        Capacitance {
            blocks,
            active,
            loaded,
            factor: CapacitanceFactor::Lu { factors, lu },
        }
    }

    /// The LU factorization of I + Yᵀ S X (X, Y block diagonal with `factors` per block of
    /// `blocks`), built a column at a time: the column β of block c′ is Yᵀ (S X_c′ e_β) on the
    /// active rows.
    fn rank_capacitance(
        &self,
        blocks: &[(Vec<usize>, Vec<f64>)],
        active: &[usize],
        factors: &[RankFactors],
    ) -> DenseLu {
        // (block, its first active row, its first rank row) per column of the matrix.
        let mut columns = Vec::new();
        let (mut at, mut rank_at) = (0, 0);
        let mut starts = Vec::with_capacity(blocks.len());
        for (b, ((cols, _), f)) in blocks.iter().zip(factors).enumerate() {
            starts.push((at, rank_at));
            columns.extend((0..f.rank).map(|beta| (b, beta)));
            at += cols.len();
            rank_at += f.rank;
        }
        let r = rank_at;
        let mut data = vec![0.0; r * r];
        data.par_chunks_mut(r.max(1))
            .zip(&columns)
            .enumerate()
            .for_each(|(j, (out, &(b, beta)))| {
                let (cols_b, f_b) = (&blocks[b].0, &factors[b]);
                let mut v = vec![0.0; active.len()];
                for (m, &col) in cols_b.iter().enumerate() {
                    let weight = f_b.x[m * f_b.rank + beta];
                    if weight != 0.0 {
                        let s_col = self.s.col_as_slice(col);
                        for (vi, &row) in v.iter_mut().zip(active) {
                            *vi += weight * s_col[row];
                        }
                    }
                }
                for (((cols, _), f), &(at, rank_at)) in blocks.iter().zip(factors).zip(&starts) {
                    for a in 0..f.rank {
                        out[rank_at + a] = (0..cols.len())
                            .map(|i| f.y[i * f.rank + a] * v[at + i])
                            .sum();
                    }
                }
                out[j] += 1.0;
            });
        DenseLu::new(data, r)
    }

    /// The Cholesky factor of I − Cᵀ S C (C block diagonal, `c` per block of `blocks`), factorized
    /// in place where the matrix is built (its lower triangle, column-major), or `None` when it is
    /// not numerically positive definite.
    fn symmetric_capacitance(
        &self,
        blocks: &[(Vec<usize>, Vec<f64>)],
        active: &[usize],
        c: &[Vec<f64>],
    ) -> Option<Vec<f64>> {
        let r = active.len();
        let mut data = vec![0.0; r * r];
        // Each block's columns of the matrix, and where its rows begin.
        let mut pieces: Vec<(&mut [f64], usize)> = Vec::with_capacity(blocks.len());
        let (mut rest, mut start) = (&mut data[..], 0);
        for (cols, _) in blocks {
            let (now, next) = std::mem::take(&mut rest).split_at_mut(cols.len() * r);
            pieces.push((now, start));
            (rest, start) = (next, start + cols.len());
        }
        // The lower triangle, a block's columns at a time: S C_b on the active rows from the
        // block's own on (S's columns of the block read once, gathered in the active order),
        // then C_b1ᵀ of each row block b1 and the identity.
        pieces
            .into_par_iter()
            .zip(blocks)
            .zip(c)
            .enumerate()
            .for_each(|(b, (((out, start), (cols_b, _)), c_b))| {
                let kb = cols_b.len();
                let rows = &active[start..];
                let mut sc = vec![0.0; rows.len() * kb];
                let mut gathered = vec![0.0; rows.len()];
                for (m, &col) in cols_b.iter().enumerate() {
                    let s_col = self.s.col_as_slice(col);
                    for (g, &row) in gathered.iter_mut().zip(rows) {
                        *g = s_col[row];
                    }
                    for a in 0..kb {
                        let weight = c_b[m * kb + a];
                        let sc_a = &mut sc[a * rows.len()..(a + 1) * rows.len()];
                        for (x, g) in sc_a.iter_mut().zip(&gathered) {
                            *x += weight * g;
                        }
                    }
                }
                let mut offset = start;
                for (b1, (cols, _)) in blocks.iter().enumerate().skip(b) {
                    let k = cols.len();
                    for a in 0..kb {
                        let sc_a = &sc[a * rows.len() + offset - start..];
                        let column = &mut out[a * r..(a + 1) * r];
                        for a1 in 0..k {
                            column[offset + a1] =
                                -(0..k).map(|i| c[b1][i * k + a1] * sc_a[i]).sum::<f64>();
                        }
                    }
                    offset += k;
                }
                for a in 0..kb {
                    out[a * r + start + a] += 1.0;
                }
            });
        let par = Par::rayon(0);
        let mut scratch =
            MemBuffer::new(cholesky_in_place_scratch::<f64>(r, par, Default::default()));
        cholesky_in_place(
            MatMut::from_column_major_slice_mut(&mut data, r, r),
            Default::default(),
            par,
            MemStack::new(&mut scratch),
            Default::default(),
        )
        .ok()?;
        Some(data)
    }

    /// The load changes Δχ of `changes` on the columns of `cap` (same order).
    pub(crate) fn active_load(&self, changes: &[ContactChange]) -> Vec<f64> {
        changes
            .iter()
            .flat_map(|ch| (0..self.owned[ch.contact].len()).map(|k| ch.load[ORDER[k]]))
            .collect()
    }

    /// U v for `v` on the columns of `changes` (in the order of
    /// [`LowRankCorrection::active_load`] and of their capacitance).
    pub(crate) fn spread(&self, changes: &[ContactChange], v: &[f64]) -> Vec<f64> {
        let mut w = vec![0.0; self.n];
        let active = changes.iter().flat_map(|ch| &self.owned[ch.contact]);
        for (&col, vj) in active.zip(v) {
            for &(i, u) in &self.columns[col] {
                w[i] += u * vj;
            }
        }
        w
    }

    /// x = (A₀ + U E Uᵀ)⁻¹ b for the changes factorized in `cap`, `a0` the factorization of A₀:
    /// two solves with A₀, or — when S came from forward solves W = L⁻¹ P Ŝ U — one forward
    /// and one backward half: f = L⁻¹ P Ŝ b, Uᵀ A₀⁻¹ b = Wᵀ f, x = Ŝ Pᵀ L⁻ᵀ (f − W z).
    pub(crate) fn solve(
        &self,
        a0: &mut dyn LinearSolver,
        cap: &Capacitance,
        b: &[f64],
    ) -> Result<Vec<f64>, SolverError> {
        let reference = self.reference(a0, b.to_vec())?;
        self.solve_from_taken(a0, cap, reference, &vec![0.0; cap.loads()])
    }

    /// [`LowRankCorrection::solve_from`] when `reference` is not needed afterwards: a forward
    /// half is taken, and the backward half runs in place on it.
    pub fn solve_from_taken(
        &self,
        a0: &mut dyn LinearSolver,
        cap: &Capacitance,
        reference: Reference,
        load: &[f64],
    ) -> Result<Vec<f64>, SolverError> {
        let v = self.coefficients(cap, &reference, load)?;
        match reference {
            Reference::Forward(f, _) => self.backward_from(a0, f, &v),
            full => self.finish(a0, &full, &v),
        }
    }

    /// A₀⁻¹ b₀ for later [`LowRankCorrection::solve_from`]: its forward half when S comes from
    /// forward solves, else the full solution.
    pub fn reference(
        &self,
        a0: &mut dyn LinearSolver,
        mut b0: Vec<f64>,
    ) -> Result<Reference, SolverError> {
        if matches!(self.mode, ColumnMode::Forward(_)) {
            a0.solve_lower_in_place(&mut b0)?;
            Ok(Reference::forward(b0))
        } else {
            a0.solve_in_place(&mut b0, 1)?;
            Ok(Reference::Full(b0))
        }
    }

    /// x = (A₀ + U E Uᵀ)⁻¹ b for b = b₀ + U Δχ, from A₀⁻¹ b₀ (`reference`) and the load change
    /// `load` on the columns of `cap` ([`LowRankCorrection::active_load`]): one solve with A₀
    /// (one backward half from a forward reference), as A₀⁻¹ b = A₀⁻¹ b₀ + A₀⁻¹ U Δχ and
    /// Uᵀ A₀⁻¹ b = Uᵀ A₀⁻¹ b₀ + S Δχ.
    pub fn solve_from(
        &self,
        a0: &mut dyn LinearSolver,
        cap: &Capacitance,
        reference: &Reference,
        load: &[f64],
    ) -> Result<Vec<f64>, SolverError> {
        let v = self.coefficients(cap, reference, load)?;
        self.finish(a0, reference, &v)
    }

    /// The coefficients v = Δχ − z of U's columns in the solution of
    /// [`LowRankCorrection::solve_from`], z from the capacitance system.
    fn coefficients(
        &self,
        cap: &Capacitance,
        reference: &Reference,
        load: &[f64],
    ) -> Result<Vec<f64>, SolverError> {
        let projected: Vec<f64> = match reference {
            Reference::Full(x0) => cap
                .active
                .iter()
                .map(|&c| dot(&self.columns[c], x0))
                .collect(),
            Reference::Forward(_, projection) => {
                self.project(reference);
                let projection = projection.borrow();
                cap.active.iter().map(|&c| projection[c]).collect()
            }
        };
        let y: Vec<f64> = cap
            .active
            .iter()
            .zip(projected)
            .map(|(&c, p)| {
                p + cap
                    .loaded
                    .iter()
                    .zip(load)
                    .map(|(&l, v)| self.s[(c, l)] * v)
                    .sum::<f64>()
            })
            .collect();
        let z = cap.solve(y)?;
        // v = Δχ − z (z on the capacitance's columns), as a coefficient of every column of U.
        let mut v = vec![0.0; self.columns.len()];
        for (&c, l) in cap.loaded.iter().zip(load) {
            v[c] += l;
        }
        for (&c, zj) in cap.active.iter().zip(&z) {
            v[c] -= zj;
        }
        Ok(v)
    }

    /// x = Ŝ Pᵀ L⁻ᵀ (f + W v) from the forward half f = L⁻¹ P Ŝ b₀ (taken) and the
    /// coefficients `v` of U's columns.
    fn backward_from(
        &self,
        a0: &mut dyn LinearSolver,
        mut f: Vec<f64>,
        v: &[f64],
    ) -> Result<Vec<f64>, SolverError> {
        self.forward_spread(v, &mut f);
        a0.solve_upper_in_place(&mut f)?;
        Ok(f)
    }

    /// x = A₀⁻¹ b₀ + A₀⁻¹ U v from `reference` (A₀⁻¹ b₀ or its forward half) and the
    /// coefficients `v` of U's columns.
    fn finish(
        &self,
        a0: &mut dyn LinearSolver,
        reference: &Reference,
        v: &[f64],
    ) -> Result<Vec<f64>, SolverError> {
        match (reference, &self.mode) {
            (Reference::Forward(f0, _), _) => self.backward_from(a0, f0.clone(), v),
            (Reference::Full(x0), ColumnMode::Forward(_)) => {
                let mut w = vec![0.0; self.n];
                self.forward_spread(v, &mut w);
                a0.solve_upper_in_place(&mut w)?;
                Ok(x0.iter().zip(&w).map(|(x, w)| x + w).collect())
            }
            (Reference::Full(x0), _) => {
                let mut w = vec![0.0; self.n];
                for (col, &vj) in self.columns.iter().zip(v) {
                    if vj != 0.0 {
                        col.iter().for_each(|&(i, u)| w[i] += u * vj);
                    }
                }
                a0.solve_in_place(&mut w, 1)?;
                Ok(x0.iter().zip(&w).map(|(x, w)| x + w).collect())
            }
        }
    }

    /// Extends a forward reference's Wᵀ f (f in the factor's row order), kept for the columns
    /// before its length, to every column: the products of each block's columns added since,
    /// which come after its older ones. Zeros without forward solves; nothing for a full
    /// reference.
    pub(crate) fn project(&self, reference: &Reference) {
        let Reference::Forward(f, projection) = reference else {
            return;
        };
        let mut projection = projection.borrow_mut();
        if projection.len() > self.columns.len() {
            // Not from these columns (they were reset): anew.
            projection.clear();
        }
        let known = projection.len();
        projection.resize(self.columns.len(), 0.0);
        if let ColumnMode::Forward(store) = &self.mode {
            // The blocks' products on the threads, summed per column after in the order of
            // the blocks' keys (the map's own order changes from run to run, and with it the
            // last bits of the sums).
            let mut products: Vec<(usize, &[usize], Vec<f64>)> = store
                .par_iter()
                .filter_map(|(&key, blk)| {
                    let new = blk.columns.partition_point(|&c| c < known);
                    debug_assert!(blk.columns[new..].iter().all(|&c| c >= known));
                    if new == blk.columns.len() {
                        return None;
                    }
                    let rows = &f[blk.first_row..blk.first_row + blk.rows];
                    let w = blk.matrix().subcols(new, blk.columns.len() - new);
                    let mut products = vec![0.0; w.ncols()];
                    matmul(
                        MatMut::from_column_major_slice_mut(&mut products, w.ncols(), 1),
                        Accum::Replace,
                        w.transpose(),
                        MatRef::from_column_major_slice(rows, blk.rows, 1),
                        1.0,
                        blk.par(),
                    );
                    Some((key, &blk.columns[new..], products))
                })
                .collect();
            products.sort_unstable_by_key(|p| p.0);
            for (_, columns, products) in products {
                for (&c, p) in columns.iter().zip(&products) {
                    projection[c] += p;
                }
            }
        }
    }

    /// out += W v (factor row order), `v` a coefficient per column; nothing without forward
    /// solves.
    fn forward_spread(&self, v: &[f64], out: &mut [f64]) {
        if let ColumnMode::Forward(store) = &self.mode {
            // The blocks' rows are disjoint: split `out` by them, the products on the threads.
            let mut blocks: Vec<&StoredBlock> = store.values().collect();
            blocks.sort_unstable_by_key(|blk| blk.first_row);
            let mut pieces = Vec::with_capacity(blocks.len());
            let (mut rest, mut at) = (out, 0);
            for blk in blocks {
                let (_, tail) = std::mem::take(&mut rest).split_at_mut(blk.first_row - at);
                let (rows, tail) = tail.split_at_mut(blk.rows);
                pieces.push((blk, rows));
                (rest, at) = (tail, blk.first_row + blk.rows);
            }
            pieces.into_par_iter().for_each(|(blk, rows)| {
                let coefficients: Vec<f64> = blk.columns.iter().map(|&c| v[c]).collect();
                if coefficients.iter().all(|&x| x == 0.0) {
                    return;
                }
                matmul(
                    MatMut::from_column_major_slice_mut(rows, blk.rows, 1),
                    Accum::Add,
                    blk.matrix(),
                    MatRef::from_column_major_slice(&coefficients, blk.columns.len(), 1),
                    1.0,
                    blk.par(),
                );
            });
        }
    }
}

/// A₀⁻¹ b₀ as [`LowRankCorrection::solve_from`] starts from it.
#[derive(Clone, Debug)]
pub enum Reference {
    /// The solution.
    Full(Vec<f64>),
    /// Its forward half f = L⁻¹ P Ŝ b₀ (factor row order), and Wᵀ f for the columns so far:
    /// kept across the solves from it and extended to the columns added in between.
    Forward(Vec<f64>, RefCell<Vec<f64>>),
}

impl Reference {
    /// The reference of the forward half `f`.
    fn forward(f: Vec<f64>) -> Self {
        Reference::Forward(f, RefCell::new(Vec::new()))
    }

    /// (1 − t) `a` + t `b`: the reference of (1 − t) b₀ₐ + t b₀ᵦ, as A₀⁻¹ and its halves are
    /// linear (Wᵀ f too, for the columns both have); `None` when they are not of one kind.
    pub(crate) fn combine(a: &Reference, b: &Reference, t: f64) -> Option<Reference> {
        let mix = |u: &[f64], v: &[f64]| -> Vec<f64> {
            u.iter().zip(v).map(|(u, v)| u + t * (v - u)).collect()
        };
        match (a, b) {
            (Reference::Full(x), Reference::Full(y)) => Some(Reference::Full(mix(x, y))),
            (Reference::Forward(f, p), Reference::Forward(g, q)) => {
                let (p, q) = (p.borrow(), q.borrow());
                let known = p.len().min(q.len());
                Some(Reference::Forward(
                    mix(f, g),
                    RefCell::new(mix(&p[..known], &q[..known])),
                ))
            }
            _ => None,
        }
    }
}

impl Capacitance {
    /// z with (I + E S) z = E y.
    fn solve(&self, y: Vec<f64>) -> Result<Vec<f64>, SolverError> {
        let r = self.order();
        let mut z = Vec::with_capacity(self.active.len());
        match &self.factor {
            CapacitanceFactor::Lu { factors, lu } => {
                // E = X Yᵀ: z = X t with (I + Yᵀ S X) t = Yᵀ y.
                let mut t = Vec::with_capacity(r);
                let mut offset = 0;
                for ((cols, _), f) in self.blocks.iter().zip(factors) {
                    let u = &y[offset..offset + cols.len()];
                    t.extend((0..f.rank).map(|a| {
                        (0..cols.len())
                            .map(|i| f.y[i * f.rank + a] * u[i])
                            .sum::<f64>()
                    }));
                    offset += cols.len();
                }
                lu.solve_in_place(&mut t);
                let mut offset = 0;
                for ((cols, _), f) in self.blocks.iter().zip(factors) {
                    let tb = &t[offset..offset + f.rank];
                    z.extend((0..cols.len()).map(|i| {
                        (0..f.rank)
                            .map(|a| f.x[i * f.rank + a] * tb[a])
                            .sum::<f64>()
                    }));
                    offset += f.rank;
                }
            }
            CapacitanceFactor::Cholesky { c, l } => {
                // E = −C Cᵀ: z = −C t with (I − Cᵀ S C) t = Cᵀ y.
                let mut t = Vec::with_capacity(r);
                let mut offset = 0;
                for (b, (cols, _)) in self.blocks.iter().enumerate() {
                    let k = cols.len();
                    let u = &y[offset..offset + k];
                    t.extend((0..k).map(|a| (0..k).map(|i| c[b][i * k + a] * u[i]).sum::<f64>()));
                    offset += k;
                }
                let l = MatRef::from_column_major_slice(l, r, r);
                let mut t_mat = MatMut::from_column_major_slice_mut(&mut t, r, 1);
                let par = one_vector_par(r * r);
                solve_lower_triangular_in_place(l, t_mat.as_mut(), par);
                solve_upper_triangular_in_place(l.transpose(), t_mat, par);
                let mut offset = 0;
                for (b, (cols, _)) in self.blocks.iter().enumerate() {
                    let k = cols.len();
                    let tb = &t[offset..offset + k];
                    z.extend((0..k).map(|i| -(0..k).map(|a| c[b][i * k + a] * tb[a]).sum::<f64>()));
                    offset += k;
                }
            }
        }
        if let Some(i) = z.iter().position(|v| !v.is_finite()) {
            return Err(SolverError::NonFinite {
                what: "capacitance solution",
                index: i,
            });
        }
        Ok(z)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::solve::{SolverConfig, SolverKind};
    use fibercell_solver::CscMatrix;
    use nalgebra::{DMatrix, DVector};

    /// The Woodbury solve equals a dense solve of A₀ + U E Uᵀ (a path-graph Laplacian plus a
    /// diagonal as A₀, contacts of 2, 3 and 6 columns on random DOFs, E nonsymmetric and
    /// indefinite as a stick → slip change is) to 1e-10, and S grown in two steps equals
    /// Uᵀ A₀⁻¹ U computed at once: with S from sparse forward solves (faer Cholesky) and from
    /// full solves (faer LU, which has no forward solve).
    #[test]
    fn woodbury_solve_matches_a_dense_solve_of_the_modified_matrix() {
        for (kind, forward) in [
            (SolverKind::FaerCholesky, true),
            (SolverKind::FaerLu, false),
        ] {
            woodbury_solve_with(kind, forward);
        }
    }

    /// S grows in place within its reservation: after three growths its storage has not
    /// moved and the entries written before are where they were (faer's exact growth copied
    /// S into a new allocation each time); the bytes counted are the written entries only.
    #[test]
    fn s_grows_in_place_and_counts_what_is_written() {
        let mut low_rank = LowRankCorrection::new(10, 4);
        low_rank.grow_s(3);
        let at = low_rank.s.as_ptr();
        low_rank.s[(2, 1)] = 7.0;
        for order in [6, 12, 24] {
            low_rank.grow_s(order);
            assert_eq!(low_rank.s.as_ptr(), at, "order {order}");
            assert_eq!(low_rank.s[(2, 1)], 7.0);
            assert_eq!(low_rank.s[(order - 1, order - 1)], 0.0);
        }
        assert_eq!(low_rank.memory_bytes(), 24 * 24 * 8);
    }

    /// The default reservation (4,096 columns) is not laid out 32 KiB apart: columns a multiple
    /// of 4 KiB apart map a row's entries to one cache set, and the M curve's S-products by
    /// rows took 20.6–23.5 s against 18.2–20.2 s with the stride off the power of two (three
    /// alternating runs each).
    #[test]
    fn s_columns_are_not_a_multiple_of_a_page_apart() {
        let mut low_rank = LowRankCorrection::new(10, 2000);
        low_rank.grow_s(3);
        let stride = low_rank.s.col_stride().unsigned_abs();
        assert!(stride >= S_RESERVED_ORDER, "reserved {stride}");
        assert!(!stride.is_multiple_of(512), "stride {stride}");
    }

    /// Entries (row, column, value) of a sparse test matrix.
    type Triplets = Vec<(usize, usize, f64)>;

    /// A path-graph Laplacian of order `n` plus a diagonal (its triplets), and its
    /// factorization by `kind`.
    pub(in crate::solve) fn path_graph_factor(
        n: usize,
        kind: SolverKind,
    ) -> (Triplets, Box<dyn LinearSolver>) {
        let mut triplets = Vec::new();
        for i in 0..n {
            triplets.push((i, i, 3.0 + (i % 7) as f64 * 0.1));
            if i + 1 < n {
                triplets.push((i, i + 1, -1.0));
                triplets.push((i + 1, i, -1.0));
            }
        }
        let a0 = CscMatrix::from_triplets(n, n, &triplets).expect("matrix");
        let mut solver = SolverConfig::new(kind).build().expect("solver");
        solver.analyze(a0.as_ref()).expect("analyze");
        solver.factorize(a0.as_ref()).expect("factorize");
        (triplets, solver)
    }

    fn woodbury_solve_with(kind: SolverKind, forward: bool) {
        let n = 60;
        let (triplets, mut solver) = path_graph_factor(n, kind);
        // A pseudo-random but fixed column for (contact, basis row).
        let column = |c: usize, k: usize| -> SparseColumn {
            (0..4)
                .map(|j| {
                    (
                        (7 * c + 13 * k + 17 * j) % n,
                        1.0 + ((c + k + j) % 5) as f64 * 0.3,
                    )
                })
                .fold(Vec::<(usize, f64)>::new(), |mut v, (i, x)| {
                    match v.iter_mut().find(|e| e.0 == i) {
                        Some(e) => e.1 += x,
                        None => v.push((i, x)),
                    }
                    v
                })
        };
        let change = |c: usize, level: usize| {
            let mut e = BlockCoefficients::zeros();
            for &i in &ORDER[..level] {
                for &j in &ORDER[..level] {
                    e[(i, j)] = 0.2 * ((3 * i + 5 * j + c) % 7) as f64 - 0.6;
                }
            }
            e
        };
        let ch = |c: usize, level: usize| ContactChange {
            contact: c,
            stiffness: change(c, level),
            load: Vector6::from_fn(|i, _| {
                if ORDER[..level].contains(&i) {
                    0.5 - 0.1 * (i + c) as f64
                } else {
                    0.0
                }
            }),
        };
        let mut low_rank = LowRankCorrection::new(n, 4);
        let first = vec![ch(0, 2), ch(2, 3)];
        low_rank
            .extend(solver.as_mut(), &first, column)
            .expect("extend");
        let b: Vec<f64> = (0..n).map(|i| ((i * 31) % 11) as f64 - 5.0).collect();
        // A reference taken on the first columns and solved from once (its projection kept
        // for them), used again below once the other columns are there.
        let early = low_rank
            .reference(solver.as_mut(), b.clone())
            .expect("solve");
        let cap = low_rank.capacitance(&first);
        low_rank
            .solve_from(solver.as_mut(), &cap, &early, &low_rank.active_load(&first))
            .expect("solve");
        let changes = vec![ch(0, 2), ch(1, 6), ch(2, 3)];
        // Orders are ranks: contact 2's 3 × 3 block has rank 2 (in column order its third
        // row is −1.5 times the first minus the second), so 2 + 6 + 2 rows; 6 new columns.
        assert_eq!(low_rank.size_of(&changes), (10, 6));
        low_rank
            .extend(solver.as_mut(), &changes, column)
            .expect("extend");
        assert_eq!(low_rank.len(), 11);
        // Its memory: S of order 11 and the columns' entries (16 bytes each), plus with forward
        // solves their rows of W (at most n doubles and a column index per column and block).
        let entries: usize = low_rank.columns.iter().map(Vec::len).sum();
        let least = 8 * 11 * 11 + 16 * entries;
        let bytes = low_rank.memory_bytes();
        assert!(
            least <= bytes && bytes <= 2 * least + 16 * n * 11 + 1024,
            "{bytes} B, {least} B at least"
        );
        let cap = low_rank.capacitance(&changes);
        assert!(cap.memory_bytes() >= 8 * cap.order() * cap.order());
        assert_eq!(
            matches!(low_rank.mode, ColumnMode::Forward(_)),
            forward,
            "{kind:?}"
        );
        // Dense A = A₀ + Σ U_c E_c U_cᵀ.
        let mut dense = DMatrix::<f64>::zeros(n, n);
        for &(i, j, v) in &triplets {
            dense[(i, j)] += v;
        }
        let basis = |c: usize, k: usize| {
            let mut v = DVector::<f64>::zeros(n);
            for (i, x) in column(c, k) {
                v[i] += x;
            }
            v
        };
        // A + Σ U_c E_c U_cᵀ, densely.
        let add_changes = |dense: &mut DMatrix<f64>, changes: &[ContactChange]| {
            for change in changes {
                let (c, e) = (change.contact, &change.stiffness);
                for p in 0..6 {
                    for q in 0..6 {
                        if e[(p, q)] != 0.0 {
                            *dense += basis(c, p) * basis(c, q).transpose() * e[(p, q)];
                        }
                    }
                }
            }
        };
        add_changes(&mut dense, &changes);
        // S against Uᵀ A₀⁻¹ U.
        let a0_dense = DMatrix::from_fn(n, n, |i, j| {
            triplets
                .iter()
                .filter(|t| t.0 == i && t.1 == j)
                .map(|t| t.2)
                .sum::<f64>()
        });
        let inv = a0_dense.clone().try_inverse().expect("invertible");
        let owned: Vec<(usize, usize)> = [(0, 2), (2, 3), (1, 6)]
            .iter()
            .flat_map(|&(c, l)| ORDER[..l].iter().map(move |&k| (c, k)))
            .collect();
        for (r, &(c1, k1)) in owned.iter().enumerate() {
            for (s, &(c2, k2)) in owned.iter().enumerate() {
                let expected = (basis(c1, k1).transpose() * &inv * basis(c2, k2))[(0, 0)];
                assert!((low_rank.s[(r, s)] - expected).abs() <= 1e-12 * expected.abs().max(1.0));
            }
        }
        let cap = low_rank.capacitance(&changes);
        assert!(matches!(cap.factor, CapacitanceFactor::Lu { .. }));
        let x = low_rank.solve(solver.as_mut(), &cap, &b).expect("solve");
        let expected = dense
            .clone()
            .lu()
            .solve(&DVector::from_vec(b.clone()))
            .expect("nonsingular");
        let err = (DVector::from_vec(x) - &expected).amax() / expected.amax();
        assert!(err <= 1e-10, "relative error {err}");
        // From x₀ = A₀⁻¹ b₀ and b = b₀ + U Δχ with one solve.
        let load = low_rank.active_load(&changes);
        assert_eq!(load.len(), 11);
        let spread = low_rank.spread(&changes, &load);
        let b1: Vec<f64> = b.iter().zip(&spread).map(|(p, q)| p + q).collect();
        let mut x0 = b.clone();
        solver.solve_in_place(&mut x0, 1).expect("solve");
        let expected = dense
            .lu()
            .solve(&DVector::from_vec(b1))
            .expect("nonsingular");
        // From the full x₀ and from the reference the correction keeps (its forward half
        // when S came from forward solves).
        let kept = low_rank
            .reference(solver.as_mut(), b.clone())
            .expect("solve");
        assert_eq!(matches!(kept, Reference::Forward(..)), forward);
        // The same columns with b₀'s reference taken along (fused with the forward solves
        // where S comes from them): the same S and reference, to 1e-12.
        let mut along = LowRankCorrection::new(n, 4);
        along
            .extend(solver.as_mut(), &first, column)
            .expect("extend");
        let taken = along
            .extend_with_reference(
                solver.as_mut(),
                &changes,
                column,
                |lr| {
                    assert_eq!(lr.len(), 11, "the new columns are there");
                    b.clone()
                },
                |_, _| None,
            )
            .expect("extend");
        let scale = low_rank.s.norm_max();
        assert!((&along.s - &low_rank.s).norm_max() <= 1e-12 * scale);
        match (&taken, &kept) {
            (Reference::Forward(p, _), Reference::Forward(q, _))
            | (Reference::Full(p), Reference::Full(q)) => {
                let big = q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                assert!(p.iter().zip(q).all(|(x, y)| (x - y).abs() <= 1e-12 * big));
            }
            _ => panic!("{kind:?}: references of different kinds"),
        }
        for reference in [Reference::Full(x0), kept, early] {
            let x1 = low_rank
                .solve_from(solver.as_mut(), &cap, &reference, &load)
                .expect("solve");
            let err = (DVector::from_vec(x1) - &expected).amax() / expected.amax();
            assert!(err <= 1e-10, "relative error from x₀: {err}");
        }
        // Springs removed (E = −F, F symmetric positive semi-definite, of rank 1 for contact 0)
        // keep A positive definite: the Cholesky capacitance, the same result as a dense solve.
        let removed: Vec<ContactChange> = [(0usize, 2usize), (1, 6), (2, 3)]
            .iter()
            .map(|&(c, level)| {
                let mut e = BlockCoefficients::zeros();
                for (p, &i) in ORDER[..level].iter().enumerate() {
                    for (q, &j) in ORDER[..level].iter().enumerate() {
                        e[(i, j)] = if c == 0 || p == q { -0.02 } else { 0.0 };
                    }
                }
                ContactChange {
                    contact: c,
                    stiffness: e,
                    load: Vector6::zeros(),
                }
            })
            .collect();
        let cap = low_rank.capacitance(&removed);
        assert!(matches!(cap.factor, CapacitanceFactor::Cholesky { .. }));
        let x = low_rank.solve(solver.as_mut(), &cap, &b).expect("solve");
        let mut dense = a0_dense.clone();
        add_changes(&mut dense, &removed);
        let expected = dense
            .lu()
            .solve(&DVector::from_vec(b.clone()))
            .expect("nonsingular");
        let err = (DVector::from_vec(x) - &expected).amax() / expected.amax();
        assert!(
            err <= 1e-10,
            "relative error with the Cholesky capacitance: {err}"
        );
        // Contact 1's load changes alone (E = 0): it is no row of the capacitance, whose order
        // is the other two contacts' ranks 2 + 2, and its U Δχ still reaches the solution.
        let mut mixed = changes.clone();
        mixed[1].stiffness = BlockCoefficients::zeros();
        assert_eq!(low_rank.size_of(&mixed), (4, 0));
        let cap = low_rank.capacitance(&mixed);
        assert_eq!((cap.order(), cap.loads()), (4, 11));
        let load = low_rank.active_load(&mixed);
        let spread = low_rank.spread(&mixed, &load);
        let b1: Vec<f64> = b.iter().zip(&spread).map(|(p, q)| p + q).collect();
        let mut dense = a0_dense;
        add_changes(&mut dense, &mixed);
        let expected = dense
            .lu()
            .solve(&DVector::from_vec(b1))
            .expect("nonsingular");
        let mut x0 = b.clone();
        solver.solve_in_place(&mut x0, 1).expect("solve");
        let x1 = low_rank
            .solve_from(solver.as_mut(), &cap, &Reference::Full(x0), &load)
            .expect("solve");
        let err = (DVector::from_vec(x1) - &expected).amax() / expected.amax();
        assert!(
            err <= 1e-10,
            "relative error with a load-only change: {err}"
        );
    }
}
