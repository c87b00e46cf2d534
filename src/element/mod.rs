//! The 3D Euler–Bernoulli frame element (thesis §4.2–4.3, Appendix A.1 corrected).

mod local_frame;
mod shape;
mod stiffness;

pub use local_frame::local_frame;
pub use shape::{hermite, hermite_d2, linear, linear_d1};
pub use stiffness::{global_stiffness, local_stiffness, FrameStiffness, Matrix12};
