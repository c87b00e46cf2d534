//! From the model to the reduced sparse system: the sparsity pattern with its
//! slot map (built once), and the value fill (serial or parallel, refilled in place).

mod coloring;
mod contact_columns;
mod element_blocks;
mod fill;
mod pattern;
mod shared;

pub use coloring::{color_blocks, color_elements};
pub use contact_columns::{add_contact_block, ContactColumns};
pub use element_blocks::{ElementBlocks, InternalForces};
pub use fill::{element_stiffness, fiber_stiffness, Assembler, FillMode};
pub use pattern::{BlockSlots, Pattern, PatternTooLargeError, NO_SLOT};
pub(crate) use shared::{prefetch, SharedMut};

/// A small periodic cell with contacts, for the unit tests of the assembled values.
#[cfg(test)]
pub(crate) use contact_columns::tests::system as test_system;
