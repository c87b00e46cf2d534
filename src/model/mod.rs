//! The fiber network: nodes, fibers (polylines of 2-node frame elements), circular sections,
//! materials, supports and nodal loads — validated on construction.

mod description;
mod dof;
mod error;
mod material;
mod network;
mod section;

pub use description::{FiberSpec, LoadSpec, MaterialSpec, ModelDescription, NodeSpec, SupportSpec};
pub use dof::{Dof, DofSet};
pub use error::ModelError;
pub use material::Material;
pub use network::{Element, Fiber, Load, Model, Node, Support};
pub use section::Section;
