//! The fiber network: nodes, fibers (polylines of 2-node frame elements), circular sections,
//! materials, supports and nodal loads — validated on construction.

mod contact_settings;
mod contact_side;
mod description;
mod dof;
mod error;
pub(crate) mod fixed_array;
mod friction;
mod material;
mod network;
mod section;

pub use contact_settings::{ContactSettings, ExplicitContact};
pub use contact_side::ContactSide;
pub use description::{
    CellSpec, ContactPairSpec, ContactSpec, FiberSpec, FrictionSpec, LoadSpec, MaterialSpec,
    ModelDescription, NodeSpec, PenetrationSpec, SideSpec, SupportSpec,
};
pub use dof::{Dof, DofSet};
pub use error::ModelError;
pub use friction::Friction;
pub use material::Material;
pub use network::{Element, Fiber, Load, Model, Node, Support, MAX_COORDINATE, MAX_LOAD};
pub use section::Section;
