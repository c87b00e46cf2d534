//! Choosing a backend and solving the static problem K u = F.

mod backend;
mod connectivity;
mod reduced;
mod static_solve;

pub use backend::{make_solver, SolverKind};
pub use connectivity::check_supported;
pub use reduced::ReducedSystem;
pub use static_solve::{solve_static, SolveOptions, SolveSummary, StaticSolution, Timings};
