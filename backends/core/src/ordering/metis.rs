//! Nested dissection by METIS (`METIS_NodeND`) on a matrix's node graph (feature `metis`).

use super::NodeGraph;
use crate::SolverError;

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
const SEPARATORS_TRIED: metis_sys::idx_t = 2;

/// Held while METIS orders (see `nested_dissection`).
static METIS_TURN: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// The node order (`[new] = old node`) of METIS `METIS_NodeND` on `graph`, nodes weighted by
/// their unknowns.
pub(super) fn node_nested_dissection(graph: &NodeGraph) -> Result<Vec<usize>, SolverError> {
    let m = graph.nodes();
    if m <= 1 {
        return Ok((0..m).collect());
    }
    let too_big = || SolverError::Backend {
        backend: "metis",
        code: -2,
        message: "graph too large for 32-bit METIS indices".into(),
    };
    let idx = |v: usize| metis_sys::idx_t::try_from(v).map_err(|_| too_big());
    let mut xadj: Vec<metis_sys::idx_t> = Vec::with_capacity(m + 1);
    let mut adjncy: Vec<metis_sys::idx_t> = Vec::with_capacity(graph.edges());
    let mut vwgt: Vec<metis_sys::idx_t> = Vec::with_capacity(m);
    xadj.push(0);
    for g in 0..m {
        vwgt.push(idx(graph.weight(g))?);
        for &h in graph.neighbours(g) {
            adjncy.push(idx(h)?);
        }
        xadj.push(idx(adjncy.len())?);
    }
    let mut nvtxs = idx(m)?;
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
        // Two separators tried at each level, the smaller kept. On the L non-woven's whole
        // node graph (155,781 nodes, before its chains went first): nnz(L) 7.84e7 and 5.28e10 flops against 8.00e7 / 5.73e10 with one and
        // 7.69e7 / 5.06e10 with five (CHOLMOD's default ordering: 7.83e7 / 5.31e10), for
        // 1.3 s of ordering against 1.0 s and 3.0 s: five save ≈ 0.06 s per factorization
        // and ≈ 1 ms per solve, so they pay for their 1.7 s after thousands of solves only.
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
    Ok(perm.iter().map(|&g| g as usize).collect())
}
