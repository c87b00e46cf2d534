//! Validation errors, each naming the offending item.

use super::Dof;

/// Why a model is not valid.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// No nodes or no fibers.
    #[error("the model is empty: it has no {0}")]
    Empty(&'static str),
    /// Two nodes share an id.
    #[error("node id {0} is defined twice")]
    DuplicateNode(u64),
    /// Two fibers share an id.
    #[error("fiber id {0} is defined twice")]
    DuplicateFiber(u64),
    /// Two materials share a name.
    #[error("material \"{0}\" is defined twice")]
    DuplicateMaterial(String),
    /// A coordinate is NaN, infinite or beyond [`MAX_COORDINATE`](crate::model::MAX_COORDINATE).
    #[error("node {node} has the coordinates [{:e}, {:e}, {:e}]: each must be finite and within ±{:e} m (lengths and stiffnesses computed from larger ones overflow)", coordinate[0], coordinate[1], coordinate[2], crate::model::MAX_COORDINATE)]
    NonFiniteCoordinate {
        /// Node id.
        node: u64,
        /// The coordinates as given.
        coordinate: [f64; 3],
    },
    /// A reference to a node that does not exist.
    #[error("{referrer} refers to unknown node {node}")]
    UnknownNode {
        /// Missing node id.
        node: u64,
        /// Who refers to it, e.g. "fiber 3".
        referrer: String,
    },
    /// A fiber refers to an unknown material.
    #[error("fiber {fiber} refers to unknown material \"{material}\"")]
    UnknownMaterial {
        /// Fiber id.
        fiber: u64,
        /// Material name.
        material: String,
    },
    /// A fiber with fewer than two nodes.
    #[error("fiber {0} has fewer than two nodes")]
    FiberTooShort(u64),
    /// Two consecutive fiber nodes at the same place.
    #[error("fiber {fiber} has a zero-length element between nodes {node_a} and {node_b}")]
    ZeroLengthElement {
        /// Fiber id.
        fiber: u64,
        /// First node id.
        node_a: u64,
        /// Second node id.
        node_b: u64,
    },
    /// The same node pair joined by two elements.
    #[error("element {node_a}–{node_b} appears twice (fibers {fiber_a} and {fiber_b})")]
    DuplicateElement {
        /// First node id.
        node_a: u64,
        /// Second node id.
        node_b: u64,
        /// Fiber of the first occurrence.
        fiber_a: u64,
        /// Fiber of the second occurrence.
        fiber_b: u64,
    },
    /// r ≤ 0, not finite, or so large that the section stiffness E·πr⁴/4 overflows.
    #[error("fiber {fiber} has an invalid radius {radius:e} m (must be finite and > 0, and its section stiffness E·πr⁴/4 finite)")]
    InvalidRadius {
        /// Fiber id.
        fiber: u64,
        /// The radius.
        radius: f64,
    },
    /// A material constant out of range.
    #[error("material \"{material}\": {what} = {value} is invalid ({rule})")]
    InvalidMaterial {
        /// Material name.
        material: String,
        /// "young", "poisson" or "shear".
        what: &'static str,
        /// The value.
        value: f64,
        /// The rule it breaks.
        rule: &'static str,
    },
    /// Neither or both of ν and G given.
    #[error("material \"{0}\" needs exactly one of poisson and shear")]
    MaterialUnderdetermined(String),
    /// A node that no fiber uses.
    #[error("node {0} belongs to no fiber")]
    UnusedNode(u64),
    /// A NaN, infinite or absurdly large (beyond ±1e100) load or prescribed value.
    #[error("{what} at node {node} is not finite or beyond ±1e100 (its norms and the displacements it causes would overflow)")]
    NonFiniteValue {
        /// Node id.
        node: u64,
        /// "load" or "prescribed value".
        what: &'static str,
    },
    /// The same DOF prescribed twice with different values.
    #[error("node {node} DOF {dof} is prescribed twice with different values")]
    ConflictingSupport {
        /// Node id.
        node: u64,
        /// The DOF.
        dof: Dof,
    },
    /// Invalid contact settings or explicit contact pair.
    #[error("{item}: {message}")]
    InvalidContact {
        /// "\[contact\]" or "contact pair 3".
        item: String,
        /// What is wrong.
        message: String,
    },
    /// Invalid `[cell]` settings.
    #[error("[cell]: {0}")]
    InvalidCell(String),
}
