//! Model generators.

mod catalog;
mod check;
mod geotextile;
mod grid;
mod knitted;
mod nonwoven;
mod orientation;
mod segment_grid;
mod woven;
mod wrap;

pub use catalog::CellParams;
pub use geotextile::{geotextile, FiberFamily, Geotextile, LayerJunction};
pub use grid::{clamped_grid, crossing_grid};
pub use knitted::{knitted, Knit};
pub use nonwoven::{
    nonwoven, nonwoven_preset, DepositionReport, FiberAmount, GeneratedCell, LengthDistribution,
    NonWoven, MAX_ELEMENTS, MAX_TILT_DEGREES, MAX_VOLUME_FRACTION,
};
pub use orientation::{bessel_ratio, concentration_for, sample_angle, Orientation};
pub use woven::{weave, Weave, WeavePattern};
