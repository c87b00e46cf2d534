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
    #[serde(default)]
    pub force: [f64; 3],
    /// Moment (N·m).
    #[serde(default)]
    pub moment: [f64; 3],
}
