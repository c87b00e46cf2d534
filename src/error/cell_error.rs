//! Why a model is not a valid periodic cell (reported by [`crate::cell`]).

use super::list;

/// Why a model is not a valid periodic cell.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CellError {
    /// The model has no `[cell]` section.
    #[error("the model has no [cell] section")]
    NotACell,
    /// Nodes outside the cell box.
    #[error("node{} {} lie{} outside the cell [{x0}, {x1}] × [{y0}, {y1}]", plural(nodes), list(nodes), if nodes.len() == 1 { "s" } else { "" })]
    Outside {
        /// Node ids.
        nodes: Vec<u64>,
        /// Cell bounds.
        x0: f64,
        /// Cell bounds.
        x1: f64,
        /// Cell bounds.
        y0: f64,
        /// Cell bounds.
        y1: f64,
    },
    /// Boundary nodes without a partner on the opposite face.
    #[error("the cell is not periodic: boundary node{} {} on the {face} face ha{} no partner on the opposite face (a fiber leaves the cell without re-entering)", plural(nodes), list(nodes), if nodes.len() == 1 { "s" } else { "ve" })]
    Unpaired {
        /// Node ids.
        nodes: Vec<u64>,
        /// "x = x0", "x = x0 + Lx", …
        face: String,
    },
    /// A boundary node with several candidate partners.
    #[error(
        "boundary node {node} has several partners ({candidates:?}) within the pairing tolerance"
    )]
    Ambiguous {
        /// Node id.
        node: u64,
        /// Candidate ids.
        candidates: Vec<u64>,
    },
    /// No load path across the cell in a direction.
    #[error("the fibers do not percolate in {direction}: no chain of fibers crosses the cell from one {direction} face to the other, so the cell has no stiffness in that direction")]
    NoPercolation {
        /// "x" or "y".
        direction: &'static str,
    },
    /// Fibers not connected to the rest of the cell.
    #[error("fiber{} {} {} not connected to the rest of the cell (held by nothing)", plural(fibers), list(fibers), if fibers.len() == 1 { "is" } else { "are" })]
    Disconnected {
        /// Fiber ids.
        fibers: Vec<u64>,
    },
}

fn plural<T>(v: &[T]) -> &'static str {
    if v.len() == 1 {
        ""
    } else {
        "s"
    }
}
