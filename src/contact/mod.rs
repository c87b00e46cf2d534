//! Beam-to-beam frictional contact with the penalty method (thesis §4.3): search, kinematics of
//! the contact points, normal and tangential contributions, and the contact set with its
//! stick/slip states.

mod coefficients;
mod duplicates;
mod geometry;
mod kinematics;
mod law;
mod search;
mod set;

pub use crate::model::{ContactSide, Friction};
pub use coefficients::{BlockCoefficients, BlockState, ContactBlock};
pub use geometry::{closest_points, ClosestPoints};
pub use kinematics::{centerline_interpolation, jump_operator, Jump, JumpMatrix};
pub use law::{tangent_basis, BlockMatrix, BlockVector, ContactPair, ContactState, PairKinematics};
pub use search::{find_candidates, find_candidates_brute_force, Candidate};
pub use set::{default_penalty, ContactOrigin, ContactSet, PenetrationReport};
