//! Circular cross-sections.

use std::f64::consts::PI;

/// A solid circular cross-section of radius r.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    /// Radius r (m).
    pub radius: f64,
}

impl Section {
    /// Area A = π r².
    pub fn area(&self) -> f64 {
        PI * self.radius.powi(2)
    }
    /// Second moment of area about either principal axis, I2 = I3 = π r⁴ / 4.
    pub fn second_moment(&self) -> f64 {
        PI * self.radius.powi(4) / 4.0
    }
    /// Torsion constant of the circle, J = π r⁴ / 2 (the polar moment).
    pub fn torsion_constant(&self) -> f64 {
        PI * self.radius.powi(4) / 2.0
    }
}
