//! Model generators.

mod grid;
mod nonwoven;
mod orientation;
mod segment_grid;
mod woven;

pub use grid::{clamped_grid, crossing_grid};
pub use nonwoven::{
    nonwoven, nonwoven_preset, DepositionReport, FiberAmount, GeneratedCell, LengthDistribution,
    NonWoven,
};
pub use orientation::{bessel_ratio, concentration_for, sample_angle, Orientation};
pub use woven::{plain_weave, PlainWeave};
