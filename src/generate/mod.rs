//! Model generators.

mod grid;

pub use grid::{clamped_grid, crossing_grid};
