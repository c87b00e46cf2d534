//! The sparse linear solver layer of fibercell, usable on its own.
//!
//! It knows nothing about fibers: it takes square sparse matrices in compressed sparse column
//! (CSC) form — its own [`CscRef`] views, or sprs matrices through `CscMatrix::from_sprs` /
//! `CscRef::try_from_sprs` (feature `sprs`) — and offers
//!
//! * the [`LinearSolver`] trait with separate *analyze* (ordering + symbolic factorization, once
//!   per sparsity pattern), *factorize* (numeric, whenever values change) and *solve* (any number of
//!   right-hand sides) phases;
//! * fill-reducing [`FillOrdering`]s: approximate minimum degree, nested dissection (METIS
//!   `METIS_NodeND`, feature `metis`), natural or a given permutation;
//! * typed [`SolverError`]s and [`solve_checked`], which reports the relative residual
//!   ‖Ax − b‖/‖b‖ of every solve and never returns a non-finite solution.
//!
//! Backends live in their own crates (`fibercell-faer`, `fibercell-cg`, `fibercell-cholmod`).
//! Symmetric matrices are always passed with **both triangles stored**; Cholesky backends read
//! the lower one.
//!
//! Features (both on by default): `metis` (nested dissection; without it that ordering is
//! [`SolverError::Unavailable`] and a backend's automatic choice is AMD) and `sprs` (the
//! conversions to and from sprs matrices).

mod condition;
mod csc;
mod error;
mod factor_pcg;
mod forward;
mod lower;
mod matrix_market;
mod median;
mod ordering;
mod residual;
mod solver;
mod zeros;

pub use condition::{inverse_norm1_estimate, norm1, SolveWith};
pub use csc::{CscMatrix, CscRef, PatternFingerprint};
pub use error::{SolverError, StopReason};
pub use factor_pcg::{pcg_with_factor, FactorPcg};
pub use forward::{ForwardBlock, ForwardColumns};
pub use lower::{permuted_diagonal_scale, DiagonalEntries, LowerTriangle};
pub use matrix_market::{read_matrix_market, read_matrix_market_dense};
pub use median::median;
pub use ordering::{
    compute_ordering, FillEstimate, FillOrdering, NodeGraph, NodeTree, OrderedNodes, Permutation,
    ReachPattern, ScalarTree,
};
pub use residual::{
    backward_error, backward_from_product, norm_inf, norm_inf_symmetric_par, relative_from_product,
    relative_residual, solve_checked, solve_checked_into, vector_norm_inf, SolveReport,
};
pub use solver::{AnalyzeInfo, Capabilities, LinearSolver, SolveInfo};
pub use zeros::{extend_with_zeros, extend_with_zeros_par, populate_par};
