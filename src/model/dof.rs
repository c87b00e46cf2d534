//! Nodal degrees of freedom: ux, uy, uz, rx, ry, rz (in this order, 6 per node).

use serde::{Deserialize, Serialize};
use std::fmt;

/// One nodal degree of freedom.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Dof {
    /// Displacement along x.
    Ux,
    /// Displacement along y.
    Uy,
    /// Displacement along z.
    Uz,
    /// Rotation about x.
    Rx,
    /// Rotation about y.
    Ry,
    /// Rotation about z.
    Rz,
}

impl Dof {
    /// All six, in DOF order.
    pub const ALL: [Dof; 6] = [Dof::Ux, Dof::Uy, Dof::Uz, Dof::Rx, Dof::Ry, Dof::Rz];

    /// Position 0..6 within the node.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The DOF at position `i` (0..6).
    pub fn from_index(i: usize) -> Option<Dof> {
        Self::ALL.get(i).copied()
    }

    /// Lower-case name, as in model files.
    pub fn name(self) -> &'static str {
        ["ux", "uy", "uz", "rx", "ry", "rz"][self.index()]
    }
}

impl fmt::Display for Dof {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A DOF or a named group of DOFs, as written in `supports`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DofSet {
    /// Displacement along x.
    Ux,
    /// Displacement along y.
    Uy,
    /// Displacement along z.
    Uz,
    /// Rotation about x.
    Rx,
    /// Rotation about y.
    Ry,
    /// Rotation about z.
    Rz,
    /// ux, uy, uz.
    Translations,
    /// rx, ry, rz.
    Rotations,
    /// All six (a clamp).
    All,
}

impl DofSet {
    /// The DOFs of the set.
    pub fn dofs(self) -> &'static [Dof] {
        match self {
            DofSet::Ux => &Dof::ALL[0..1],
            DofSet::Uy => &Dof::ALL[1..2],
            DofSet::Uz => &Dof::ALL[2..3],
            DofSet::Rx => &Dof::ALL[3..4],
            DofSet::Ry => &Dof::ALL[4..5],
            DofSet::Rz => &Dof::ALL[5..6],
            DofSet::Translations => &Dof::ALL[0..3],
            DofSet::Rotations => &Dof::ALL[3..6],
            DofSet::All => &Dof::ALL,
        }
    }
}
