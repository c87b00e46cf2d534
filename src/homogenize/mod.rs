//! Asymptotic homogenization of a periodic cell (thesis §3.1.4, §5.1): the six elastic cell
//! problems driven by unit macroscopic strains, the ABD stiffness per unit cell area, the
//! thesis's moduli and the orthotropic constants of §5.1.2.

mod curve;
mod elastic;
mod orthotropic;
pub(crate) mod system;

pub use curve::{elasto_plastic_curve, Curve, CurveOptions, CurvePoint, Segment, SwitchEvent};
pub use elastic::{homogenize_elastic, Homogenized};
pub use orthotropic::{Orthotropic, ThesisModuli};
pub use system::PeriodicSystem;
