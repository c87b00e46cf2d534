//! The model as written in files (TOML, JSON, or imported from Abaqus): ids and names, not yet
//! validated. [`crate::Model::from_description`] checks it.

use super::DofSet;
use serde::{Deserialize, Serialize};

/// A whole model file. TOML and JSON use this same schema (see the README).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelDescription {
    /// Optional title.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Materials, referred to by name.
    #[serde(default)]
    pub materials: Vec<MaterialSpec>,
    /// Nodes with ids and coordinates.
    #[serde(default)]
    pub nodes: Vec<NodeSpec>,
    /// Fibers: polylines of node ids with a radius and a material.
    #[serde(default)]
    pub fibers: Vec<FiberSpec>,
    /// Fixed or prescribed DOFs.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub supports: Vec<SupportSpec>,
    /// Nodal forces and moments.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub loads: Vec<LoadSpec>,
    /// Contact settings; a model without them has no contact.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<ContactSpec>,
    /// Explicit contact pairs.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<ContactPairSpec>,
    /// Periodic cell; a model without it is an ordinary structure.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cell: Option<CellSpec>,
}

/// `[[materials]]`: E with exactly one of ν and G.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Name.
    pub name: String,
    /// Young's modulus E (Pa).
    pub young: f64,
    /// Poisson's ratio ν, −1 < ν < 0.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson: Option<f64>,
    /// Shear modulus G (Pa).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear: Option<f64>,
}

/// `[[nodes]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeSpec {
    /// Node id (any unsigned integer, unique).
    pub id: u64,
    /// Coordinates x, y, z (m).
    #[serde(deserialize_with = "super::fixed_array::exactly")]
    pub x: [f64; 3],
}

/// `[[fibers]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FiberSpec {
    /// Fiber id (unique).
    pub id: u64,
    /// Node ids along the fiber; each consecutive pair is one frame element. Fibers that share a
    /// node are rigidly joined there.
    pub nodes: Vec<u64>,
    /// Radius of the circular cross-section (m).
    pub radius: f64,
    /// Material name.
    pub material: String,
}

/// `[[supports]]`: the listed DOFs of a node are prescribed to `value` (0 by default: fixed).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupportSpec {
    /// Node id.
    pub node: u64,
    /// DOFs: ux uy uz rx ry rz, or translations, rotations, all.
    pub dofs: Vec<DofSet>,
    /// Prescribed displacement (m) or rotation (rad).
    #[serde(default)]
    pub value: f64,
}

/// `[[loads]]`: a nodal force and moment.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Node id.
    pub node: u64,
    /// Force (N).
    #[serde(default, deserialize_with = "super::fixed_array::exactly")]
    pub force: [f64; 3],
    /// Moment (N·m).
    #[serde(default, deserialize_with = "super::fixed_array::exactly")]
    pub moment: [f64; 3],
}

/// `[contact]`: how fibers touch. Without it a model has no contact.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Search for contacts between all fibers (default true); explicit `[[contacts]]` are
    /// always used.
    #[serde(default = "yes")]
    pub search: bool,
    /// Surfaces closer than this count as candidate pairs (m; default: the largest radius).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Normal penalty p_N (N/m); default 1000 × the largest transverse element stiffness
    /// 12EI/L³ of the two elements in contact.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penalty_normal: Option<f64>,
    /// Tangential penalty p_T (N/m); default equal to the normal penalty.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penalty_tangent: Option<f64>,
    /// Rolling and twisting resistance p_R of a closed contact (N·m/rad, ≥ 0; 0: the thesis's
    /// point contact); default p_N a²/4 with a half the smaller fiber radius.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penalty_rotation: Option<f64>,
    /// Factor s > 0 on every contact's penalties p_N, p_T and p_R, default or given (default
    /// 1): a penalty study (s = 1, 10, 100 …) keeps each contact's share of the defaults.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penalty_scale: Option<f64>,
    /// Friction law.
    #[serde(default)]
    pub friction: FrictionSpec,
    /// Initially penetrating pairs: "adjust" (strain-free: their gap is set to 0, default) or
    /// "resolve" (pushed apart over the increments).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_penetration: Option<PenetrationSpec>,
    /// Bonded contacts (default false): initially closed contacts never open (the normal
    /// spring is bilateral) and open ones never close; only stick and slip evolve. A bonded or
    /// consolidated mat, such as the generated non-wovens.
    #[serde(default, skip_serializing_if = "is_false")]
    pub bonded: bool,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_false(v: &bool) -> bool {
    !*v
}

fn yes() -> bool {
    true
}

/// `friction = { law = "coulomb", mu = 0.3 }` (with an optional `cohesion = c`, N),
/// `{ law = "tresca", bound = 0.5 }` or `{ law = "none" }`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "lowercase", deny_unknown_fields)]
pub enum FrictionSpec {
    /// Frictionless.
    #[default]
    None,
    /// Coulomb friction coefficient μ ≥ 0, with cohesion c ≥ 0: |F_t| ≤ c + μ max(N, 0)
    /// (Mohr–Coulomb; c = 0 is the thesis's law).
    Coulomb {
        /// μ.
        mu: f64,
        /// c (N; default 0): the tangential force a contact resists at zero normal force,
        /// e.g. a bonded crossing's bond strength.
        #[serde(default, skip_serializing_if = "is_zero")]
        cohesion: f64,
    },
    /// Tresca friction bound G ≥ 0 (N).
    Tresca {
        /// G.
        bound: f64,
    },
}

/// How initially penetrating pairs are treated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PenetrationSpec {
    /// Set their gap to zero: touching, stress free.
    Adjust,
    /// Keep the negative gap: the penalty pushes them apart as the load is applied.
    Resolve,
}

/// `[[contacts]]`: an explicit contact pair between two nodes or points on fibers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactPairSpec {
    /// Side I.
    pub a: SideSpec,
    /// Side II.
    pub b: SideSpec,
    /// Unit normal from I to II (default: from the position of I to that of II).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::fixed_array::optional"
    )]
    pub normal: Option<[f64; 3]>,
    /// Initial gap ḡ (m; default 0: touching).
    #[serde(default)]
    pub gap: f64,
    /// Normal penalty for this pair (N/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penalty_normal: Option<f64>,
    /// Tangential penalty for this pair (N/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penalty_tangent: Option<f64>,
    /// Rolling resistance for this pair (N·m/rad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penalty_rotation: Option<f64>,
}

/// A contact side: `{ node = 3 }` or `{ fiber = 2, segment = 0, xi = 0.5 }` (the point at
/// parameter ξ ∈ [0, 1] of the fiber's segment, counted from 0).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged, deny_unknown_fields)]
pub enum SideSpec {
    /// A node.
    Node {
        /// Node id.
        node: u64,
    },
    /// A point on a fiber segment.
    Point {
        /// Fiber id.
        fiber: u64,
        /// Segment index along the fiber (0-based).
        segment: usize,
        /// Parameter along the segment.
        xi: f64,
    },
}

/// `[cell]`: the model is a periodic cell of a fabric, periodic in x and y with free top and
/// bottom faces.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellSpec {
    /// Periods L_x, L_y (m).
    #[serde(deserialize_with = "super::fixed_array::exactly")]
    pub size: [f64; 2],
    /// Lower-left corner (x₀, y₀) of the cell (m; default: the smallest node coordinates).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::fixed_array::optional"
    )]
    pub origin: Option<[f64; 2]>,
    /// Thickness h used to turn stress resultants into moduli in Pa (m; default: the z extent
    /// of the fiber surfaces).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// Distance within which boundary nodes are paired (m; default 1e-6 × the smaller period).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
}
