//! Nested dissection by METIS (`METIS_NodeND`) on the compressed graph of a matrix (feature
//! `metis`).

use super::Permutation;
use crate::{CscRef, SolverError};

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

pub(super) fn nested_dissection(a: CscRef<'_>) -> Result<Permutation, SolverError> {
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
