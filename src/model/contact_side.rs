//! Where a contact acts on a fiber: a node, or a point along an element.

/// One side of a contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactSide {
    /// The translation of a node.
    Node(usize),
    /// The centerline point of an element at ξ ∈ [0, 1] (first → second node).
    Point {
        /// Element index.
        element: usize,
        /// Parameter along it.
        xi: f64,
    },
}
