//! Asymptotic homogenization of a periodic cell (thesis §3.1.4, §5.1): the six elastic cell
//! problems driven by unit macroscopic strains, the ABD stiffness per unit cell area, the
//! thesis's moduli and the orthotropic constants of §5.1.2, and the out-of-plane pressure problem
//! Θ with its B^hom (§3.2, 5.2, 5.4).

mod curve;
mod elastic;
mod orthotropic;
mod pressure;
mod segments;
mod stateful_cell;
mod stick_system;
pub(crate) mod system;

pub use curve::{
    check_curve_path, elasto_plastic_curve, Curve, CurveOptions, CurvePoint, SwitchEvent,
    MAX_MACRO_STRAIN,
};
pub(crate) use elastic::{abd_asymmetry, abd_of, cell_rhs};
pub use elastic::{
    cell_problem, elastic_abd, homogenize_elastic, HomogenizeTimings, Homogenized, LinearSystem,
    PressureResponse,
};
pub use orthotropic::{Orthotropic, ThesisModuli};
pub use pressure::{default_pixel, pressure_load, PressureLoad};
pub use segments::{segment_starting_at, Segment};
pub use stateful_cell::{Cell, CellResponse, CellState};
pub use stick_system::{ContactStiffness, PeriodicValues, StickSystem};
pub use system::{PeriodicSystem, SetupTimings};
