//! Fill-reducing orderings: approximate minimum degree (faer's AMD), nested dissection (METIS
//! `METIS_NodeND`), natural, or a permutation given by the caller.

use crate::{CscRef, SolverError};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SymbolicSparseColMatRef;

/// Which fill-reducing ordering a direct solver uses.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Ordering {
    /// The backend's choice (faer: the better of AMD and nested dissection by predicted fill;
    /// CHOLMOD: its own default strategy).
    #[default]
    Auto,
    /// No reordering.
    Natural,
    /// Approximate minimum degree.
    Amd,
    /// Nested dissection through METIS `METIS_NodeND` (the best of five separators at each
    /// level), on the graph compressed to supervariables (consecutive columns with identical
    /// patterns, e.g. the six DOFs of a node).
    NestedDissection,
    /// A caller's permutation: `perm[new] = old`.
    Given(Vec<usize>),
}

impl Ordering {
    /// A short name for reports.
    pub fn name(&self) -> &'static str {
        match self {
            Ordering::Auto => "auto",
            Ordering::Natural => "natural",
            Ordering::Amd => "amd",
            Ordering::NestedDissection => "nested-dissection",
            Ordering::Given(_) => "given",
        }
    }

    /// The names [`Ordering::parse`] takes, as the CLI's `--ordering` lists them.
    pub const NAMES: [&'static str; 4] = ["auto", "amd", "nd", "natural"];

    /// The ordering called `name` (one of [`Ordering::NAMES`]; `nested-dissection` too).
    pub fn parse(name: &str) -> Result<Ordering, String> {
        match name {
            "auto" => Ok(Ordering::Auto),
            "amd" => Ok(Ordering::Amd),
            "nd" | "nested-dissection" => Ok(Ordering::NestedDissection),
            "natural" => Ok(Ordering::Natural),
            _ => Err(format!(
                "unknown ordering \"{name}\" (use auto, amd, nd or natural)"
            )),
        }
    }
}

/// A permutation with its inverse: `fwd[new] = old`, `inv[old] = new`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Permutation {
    /// New position → old index.
    pub fwd: Vec<usize>,
    /// Old index → new position.
    pub inv: Vec<usize>,
}

impl Permutation {
    /// Checks that `fwd` is a permutation of 0..n and builds the inverse.
    pub fn from_fwd(fwd: Vec<usize>, n: usize) -> Result<Self, SolverError> {
        if fwd.len() != n {
            return Err(SolverError::DimensionMismatch(format!(
                "permutation has {} entries for a matrix of order {n}",
                fwd.len()
            )));
        }
        let mut inv = vec![usize::MAX; n];
        for (new, &old) in fwd.iter().enumerate() {
            if old >= n || inv[old] != usize::MAX {
                return Err(SolverError::InvalidMatrix(format!(
                    "given ordering is not a permutation of 0..{n} (entry {new} = {old})"
                )));
            }
            inv[old] = new;
        }
        Ok(Permutation { fwd, inv })
    }

    /// The identity of order n.
    pub fn identity(n: usize) -> Self {
        Permutation {
            fwd: (0..n).collect(),
            inv: (0..n).collect(),
        }
    }
}

/// Computes the permutation for a concrete ordering from the pattern of the square,
/// structurally symmetric matrix `a` (checked: AMD and METIS need a symmetric graph and hang or
/// return nonsense on one triangle). [`Ordering::Auto`] is resolved by the backends; here it
/// means AMD.
pub fn compute_ordering(a: CscRef<'_>, ordering: &Ordering) -> Result<Permutation, SolverError> {
    let n = a.ncols();
    if a.nrows() != n {
        return Err(SolverError::DimensionMismatch(format!(
            "matrix is {}×{n}, not square",
            a.nrows()
        )));
    }
    if !matches!(ordering, Ordering::Given(_) | Ordering::Natural) {
        a.check_structurally_symmetric()?;
    }
    match ordering {
        Ordering::Natural => Ok(Permutation::identity(n)),
        Ordering::Given(p) => Permutation::from_fwd(p.clone(), n),
        Ordering::Auto | Ordering::Amd => amd_ordering(a),
        Ordering::NestedDissection => nested_dissection(a),
    }
}

fn amd_ordering(a: CscRef<'_>) -> Result<Permutation, SolverError> {
    let n = a.ncols();
    let mut fwd = vec![0usize; n];
    let mut inv = vec![0usize; n];
    let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx());
    let req = amd::order_scratch::<usize>(n, a.nnz());
    let mut buf = MemBuffer::try_new(req).map_err(|_| SolverError::OutOfMemory)?;
    amd::order(
        &mut fwd,
        &mut inv,
        pattern,
        amd::Control::default(),
        MemStack::new(&mut buf),
    )
    .map_err(|e| SolverError::Backend {
        backend: "amd",
        code: -1,
        message: format!("{e:?}"),
    })?;
    Ok(Permutation { fwd, inv })
}

/// Groups consecutive columns with identical patterns; returns the group of every column and
/// the first column of every group.
fn supervariables(a: CscRef<'_>) -> (Vec<usize>, Vec<usize>) {
    let n = a.ncols();
    let mut group = vec![0usize; n];
    let mut starts = Vec::new();
    for (j, g) in group.iter_mut().enumerate() {
        let same = j > 0 && a.col(j).0 == a.col(j - 1).0;
        if !same {
            starts.push(j);
        }
        *g = starts.len() - 1;
    }
    (group, starts)
}

/// The typed error of a METIS return code other than METIS_OK.
fn metis_error(status: metis_sys::rstatus_et) -> SolverError {
    #[allow(non_upper_case_globals)]
    match status {
        metis_sys::rstatus_et_METIS_ERROR_MEMORY => SolverError::OutOfMemory,
        metis_sys::rstatus_et_METIS_ERROR_INPUT => SolverError::InvalidMatrix(
            "METIS_NodeND rejected the graph of the matrix (METIS_ERROR_INPUT)".into(),
        ),
        code => SolverError::Backend {
            backend: "metis",
            code: code as i64,
            message: "METIS_NodeND failed (METIS_ERROR)".into(),
        },
    }
}

/// METIS_OPTION_NSEPS of the nested dissection.
const SEPARATORS_TRIED: metis_sys::idx_t = 5;

/// Held while METIS orders (see `nested_dissection`).
static METIS_TURN: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn nested_dissection(a: CscRef<'_>) -> Result<Permutation, SolverError> {
    let n = a.ncols();
    if n <= 1 {
        return Ok(Permutation::identity(n));
    }
    let (group, starts) = supervariables(a);
    let m = starts.len();
    let too_big = || SolverError::Backend {
        backend: "metis",
        code: -2,
        message: "graph too large for 32-bit METIS indices".into(),
    };
    // Compressed graph without self loops; weights = supervariable sizes.
    let mut xadj: Vec<metis_sys::idx_t> = Vec::with_capacity(m + 1);
    let mut adjncy: Vec<metis_sys::idx_t> = Vec::new();
    let mut vwgt: Vec<metis_sys::idx_t> = Vec::with_capacity(m);
    xadj.push(0);
    for (g, &j) in starts.iter().enumerate() {
        let end = starts.get(g + 1).copied().unwrap_or(n);
        vwgt.push(metis_sys::idx_t::try_from(end - j).map_err(|_| too_big())?);
        let mut last = usize::MAX;
        for &r in a.col(j).0 {
            let h = group[r];
            if h != g && h != last {
                adjncy.push(metis_sys::idx_t::try_from(h).map_err(|_| too_big())?);
                last = h;
            }
        }
        xadj.push(metis_sys::idx_t::try_from(adjncy.len()).map_err(|_| too_big())?);
    }
    let mut nvtxs = metis_sys::idx_t::try_from(m).map_err(|_| too_big())?;
    let mut options = [0 as metis_sys::idx_t; metis_sys::METIS_NOPTIONS as usize];
    let mut perm = vec![0 as metis_sys::idx_t; m];
    let mut iperm = vec![0 as metis_sys::idx_t; m];
    // METIS draws from one process-wide random state: concurrent calls race on it (and order
    // differently from run to run), so they take turns.
    let _turn = METIS_TURN
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    // SAFETY: all arrays have the sizes METIS documents (xadj m+1, adjncy xadj[m], vwgt m,
    // options METIS_NOPTIONS, perm/iperm m) and live across the calls.
    let status = unsafe {
        metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
        options[metis_sys::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
        // Five separators tried at each level, the smallest kept: on the non-woven cells nnz(L)
        // drops 3-4 % below the single-separator default (M: 1.190e7 -> 1.134e7, L: 8.05e7 ->
        // 7.74e7, below CHOLMOD's default ordering) for about twice the ordering time.
        options[metis_sys::moptions_et_METIS_OPTION_NSEPS as usize] = SEPARATORS_TRIED;
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            vwgt.as_mut_ptr(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return Err(metis_error(status));
    }
    // Expand: supervariables in METIS order, their columns consecutively.
    let mut fwd = Vec::with_capacity(n);
    for &g in &perm {
        let g = g as usize;
        let end = starts.get(g + 1).copied().unwrap_or(n);
        fwd.extend(starts[g]..end);
    }
    Permutation::from_fwd(fwd, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CscMatrix;

    fn grid_laplacian(k: usize, dofs: usize) -> CscMatrix {
        let idx = |i: usize, j: usize| i * k + j;
        let mut t = Vec::new();
        for i in 0..k {
            for j in 0..k {
                let mut nb = vec![idx(i, j)];
                if i + 1 < k {
                    nb.push(idx(i + 1, j));
                }
                if j + 1 < k {
                    nb.push(idx(i, j + 1));
                }
                for &p in &nb {
                    for &q in &nb {
                        for a in 0..dofs {
                            for b in 0..dofs {
                                let v = if p == q && a == b { 8.0 } else { -0.1 };
                                t.push((p * dofs + a, q * dofs + b, v));
                            }
                        }
                    }
                }
            }
        }
        CscMatrix::from_triplets(k * k * dofs, k * k * dofs, &t).unwrap()
    }

    /// Nested dissection gives the same permutation when several threads order at once
    /// (METIS draws from one process-wide random state).
    #[test]
    fn nested_dissection_is_the_same_on_concurrent_threads() {
        let a = grid_laplacian(30, 3);
        let want = compute_ordering(a.as_ref(), &Ordering::NestedDissection).unwrap();
        std::thread::scope(|scope| {
            let runs: Vec<_> = (0..4)
                .map(|_| {
                    scope.spawn(|| {
                        (0..20)
                            .map(|_| compute_ordering(a.as_ref(), &Ordering::NestedDissection))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            for run in runs {
                for p in run.join().unwrap() {
                    assert_eq!(p.unwrap().fwd, want.fwd);
                }
            }
        });
    }

    #[test]
    fn every_ordering_is_a_permutation() {
        let a = grid_laplacian(12, 3);
        for o in [Ordering::Natural, Ordering::Amd, Ordering::NestedDissection] {
            let p = compute_ordering(a.as_ref(), &o).unwrap();
            let mut seen = p.fwd.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..a.as_ref().ncols()).collect::<Vec<_>>());
            for (new, &old) in p.fwd.iter().enumerate() {
                assert_eq!(p.inv[old], new);
            }
        }
    }

    #[test]
    fn nested_dissection_keeps_supervariables_together() {
        let a = grid_laplacian(10, 6);
        let p = compute_ordering(a.as_ref(), &Ordering::NestedDissection).unwrap();
        for chunk in p.fwd.chunks(6) {
            assert_eq!(chunk[0] % 6, 0);
            for (k, &c) in chunk.iter().enumerate() {
                assert_eq!(c, chunk[0] + k);
            }
        }
    }

    #[test]
    fn given_ordering_is_checked() {
        let a = grid_laplacian(3, 1);
        let e = compute_ordering(
            a.as_ref(),
            &Ordering::Given(vec![0, 1, 1, 3, 4, 5, 6, 7, 8]),
        );
        assert!(matches!(e, Err(SolverError::InvalidMatrix(_))));
        let e = compute_ordering(a.as_ref(), &Ordering::Given(vec![0]));
        assert!(matches!(e, Err(SolverError::DimensionMismatch(_))));
    }
}
