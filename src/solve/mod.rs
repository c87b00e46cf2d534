//! Choosing a backend and solving the static problem K u = F.

mod affine_reference;
mod backend;
mod connectivity;
mod dense_lu;
mod gram;
mod increment_timings;
mod incremental;
mod kept_contact_loads;
mod low_rank;
mod matrix_solve;
mod reduced;
mod static_solve;

pub use backend::{SolverConfig, SolverKind};
pub(crate) use connectivity::node_roots;
pub use connectivity::{check_supported, check_supported_with};
pub use increment_timings::IncrementTimings;
pub(crate) use incremental::{gather, run_incremental, Advanced, OnAllStick, RunState, Setup};
pub use incremental::{
    solve_incremental, ContactRecord, DriverCouplings, EnergyBalance, History, IncrementRecord,
    IncrementalOptions, IncrementalSolution, LowRankSizes, Progress, ProgressFn, BOUND_TOLERANCE,
    EQUILIBRIUM_TOLERANCE, MAX_CONTACT_RECORDS, MAX_CUTBACKS, MAX_HELD_RESIDUAL, MAX_INCREMENTS,
    MAX_LOW_RANK_COLUMNS, MAX_SETTLED_RESIDUAL, STALLED_EQUILIBRIUM_TOLERANCE,
};
pub(crate) use low_rank::ContactChange;
/// The low-rank correction's internals, for `fibercell-bench`'s measurement of the solve after
/// contact switches (feature `bench-internals`): not part of the API, they change without notice.
#[cfg(feature = "bench-internals")]
#[doc(hidden)]
pub mod bench_internals {
    pub use super::low_rank::{
        Capacitance, ContactChange, LowRankCorrection, Reference, SparseColumn,
    };
}
pub use matrix_solve::{
    solve_matrix, MatrixSolveReport, MatrixSolver, MATRIX_SOLVE_BACKWARD_ERROR,
};
pub use reduced::ReducedSystem;
pub(crate) use static_solve::check_backward_error;
pub use static_solve::{solve_static, SolveOptions, SolveSummary, StaticSolution, Timings};
