//! Model generators.

mod grid;
mod woven;

pub use grid::{clamped_grid, crossing_grid};
pub use woven::{plain_weave, PlainWeave};
