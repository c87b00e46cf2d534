//! Linear elastic, isotropic fiber materials.

/// Young's modulus E and shear modulus G (Pa); ν when it was given.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name used by fibers to refer to it.
    pub name: String,
    /// Young's modulus E (Pa).
    pub young: f64,
    /// Shear modulus G (Pa); G = E / (2(1 + ν)) when ν was given.
    pub shear: f64,
    /// Poisson's ratio, when given.
    pub poisson: Option<f64>,
}
