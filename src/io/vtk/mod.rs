//! VTK XML files for ParaView: the fiber network as poly lines (`.vtp`, one line per fiber,
//! which the *Tube* filter takes directly, or `.vtu` with poly-line cells), the contact points
//! as vertices, and `.pvd` collections. Points are always the reference coordinates, with the
//! `displacement` as point data: *Warp By Vector* with it shows the deformed network (a
//! comment at the top of each file says so). DataArrays are written as text or, for large
//! cells, base64-encoded binary ([`VtkEncoding`]).

mod contacts;
mod document;
mod network;
mod series;

pub use contacts::contacts_vtp;
pub use document::VtkEncoding;
pub use network::{network_vtk, NetworkFormat};
pub use series::{model_vtk, series_pvd, step_file};
