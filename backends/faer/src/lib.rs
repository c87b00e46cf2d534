//! faer sparse backends for the fibercell solver layer: supernodal/simplicial Cholesky
//! ([`FaerCholesky`], LLᵀ or LDLᵀ, symbolic analysis reused) and LU ([`FaerLu`], for the
//! nonsymmetric systems of Coulomb sliding). No system packages needed.

mod block_kernels;
mod block_solve;
mod block_tree;
mod cholesky;
mod column_layout;
mod dense_forward;
mod lu;
mod permute;
mod pivots;
mod prefetch;
mod sparse_forward;
#[cfg(test)]
mod test_matrices;
mod top_columns;

pub use cholesky::{CholeskyVariant, FaerCholesky};
pub use lu::FaerLu;
