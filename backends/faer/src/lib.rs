//! faer sparse backends for the fibercell solver layer: supernodal/simplicial Cholesky
//! ([`FaerCholesky`], LLᵀ or LDLᵀ, symbolic analysis reused) and LU ([`FaerLu`], for the
//! nonsymmetric systems of Coulomb sliding). No system packages needed.
//!
//! ```
//! use fibercell_faer::{FaerCholesky, FaerLu};
//! use fibercell_solver::{solve_checked, CscMatrix, LinearSolver};
//!
//! // A symmetric positive definite tridiagonal matrix, both triangles stored.
//! let t = [(0, 0, 4.0), (1, 1, 4.0), (2, 2, 4.0), (0, 1, -1.0), (1, 0, -1.0), (1, 2, -1.0), (2, 1, -1.0)];
//! let a = CscMatrix::from_triplets(3, 3, &t)?;
//! let mut cholesky = FaerCholesky::default(); // LLᵀ, the better of AMD and nested dissection
//! let info = cholesky.analyze(a.as_ref())?; // once per pattern
//! cholesky.factorize(a.as_ref())?; // whenever the values change
//! let (x, report) = solve_checked(&mut cholesky, a.as_ref(), &[3.0, 2.0, 3.0], 1)?;
//! assert!(x.iter().all(|v| (v - 1.0).abs() < 1e-14) && report.relative_residual < 1e-15);
//! assert_eq!(info.n, 3);
//!
//! // A nonsymmetric matrix goes to LU.
//! let b = CscMatrix::from_triplets(2, 2, &[(0, 0, 2.0), (0, 1, 1.0), (1, 1, 3.0)])?;
//! let mut lu = FaerLu::new();
//! lu.analyze(b.as_ref())?;
//! lu.factorize(b.as_ref())?;
//! let mut x = vec![3.0, 3.0];
//! lu.solve_in_place(&mut x, 1)?;
//! assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
//! # Ok::<(), fibercell_solver::SolverError>(())
//! ```

#![warn(missing_docs)]

mod block_kernels;
mod block_solve;
mod block_solve_many;
mod block_tree;
mod cholesky;
mod column_layout;
mod dense_forward;
mod dense_llt;
mod lu;
mod permute;
mod pivots;
mod prefault;
mod prefetch;
mod sparse_forward;
mod supernodal_llt;
mod supernodes;
mod symbolic;
#[cfg(test)]
mod test_matrices;
mod top_columns;

pub use cholesky::{CholeskyVariant, FaerCholesky};

/// The code blocks of `backends/README.md` (the solver layer on its own, and a minimal
/// backend) run as this crate's doc-tests.
#[doc = include_str!("../../README.md")]
#[cfg(doctest)]
pub struct BackendsReadme;
pub use lu::FaerLu;
