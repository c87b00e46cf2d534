//! The periodic cell: boundary nodes paired across opposite faces, the plate kinematics of the
//! six macroscopic quantities (ε11, ε22, γ12, κ11, κ22, κ12), and the percolation check.

mod macro_field;
mod pairing;
mod percolation;
mod strands;

pub use macro_field::{macro_matrix, parse_macro_strain, MacroStrain, MACRO_NAMES};
pub(crate) use pairing::independent_node;
pub use pairing::{anchor_node, pair_boundary_nodes, CellError, CellGeometry, Periodicity};
pub use percolation::check_percolation;
pub(crate) use strands::strand_of_fibers;
