//! Six DOFs per node (ux, uy, uz, rx, ry, rz); prescribed DOFs are eliminated and the free ones
//! numbered node by node, so each node's free DOFs are consecutive in the reduced system.

use crate::model::{Dof, Model};

/// The numbering of the reduced (free) system.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    n_nodes: usize,
    /// Reduced index of every global DOF 6·node + dof, or `usize::MAX` if prescribed.
    reduced: Vec<usize>,
    /// Global DOF of every reduced index.
    free: Vec<usize>,
    /// Prescribed value of every global DOF (0 for free ones).
    prescribed: Vec<f64>,
}

impl DofMap {
    /// Numbers the free DOFs of `model`; prescribed DOFs come from its supports.
    pub fn new(model: &Model) -> Self {
        let n_nodes = model.nodes.len();
        let mut is_prescribed = vec![false; 6 * n_nodes];
        let mut prescribed = vec![0.0; 6 * n_nodes];
        for s in &model.supports {
            let g = 6 * s.node + s.dof.index();
            is_prescribed[g] = true;
            prescribed[g] = s.value;
        }
        let mut reduced = vec![usize::MAX; 6 * n_nodes];
        let mut free = Vec::with_capacity(6 * n_nodes);
        for g in 0..6 * n_nodes {
            if !is_prescribed[g] {
                reduced[g] = free.len();
                free.push(g);
            }
        }
        DofMap {
            n_nodes,
            reduced,
            free,
            prescribed,
        }
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.n_nodes
    }
    /// Number of global DOFs (6 per node).
    pub fn n_global(&self) -> usize {
        6 * self.n_nodes
    }
    /// Number of free DOFs (order of the reduced system).
    pub fn n_free(&self) -> usize {
        self.free.len()
    }
    /// Global DOF index of (node, dof).
    pub fn global(node: usize, dof: Dof) -> usize {
        6 * node + dof.index()
    }
    /// Reduced index of a global DOF, `None` if prescribed.
    pub fn reduced(&self, global: usize) -> Option<usize> {
        let r = self.reduced[global];
        (r != usize::MAX).then_some(r)
    }
    /// Reduced indices of all global DOFs (`usize::MAX` for prescribed ones).
    pub fn reduced_indices(&self) -> &[usize] {
        &self.reduced
    }
    /// (node, dof) of a reduced index.
    pub fn node_dof(&self, reduced: usize) -> (usize, Dof) {
        let g = self.free[reduced];
        (g / 6, Dof::ALL[g % 6])
    }
    /// Prescribed value of a global DOF (0 when free).
    pub fn prescribed_value(&self, global: usize) -> f64 {
        self.prescribed[global]
    }
    /// Whether any prescribed value is non-zero.
    pub fn has_nonzero_prescribed(&self) -> bool {
        self.prescribed.iter().any(|v| *v != 0.0)
    }
    /// First reduced index of every node that has free DOFs (node blocks for block
    /// preconditioners).
    pub fn node_block_starts(&self) -> Vec<usize> {
        block_starts(self.free.iter().map(|&g| g / 6))
    }
    /// Expands a reduced solution to all global DOFs, filling in prescribed values.
    pub fn expand(&self, reduced: &[f64]) -> Vec<f64> {
        (0..self.n_global())
            .map(|g| match self.reduced(g) {
                Some(r) => reduced[r],
                None => self.prescribed[g],
            })
            .collect()
    }
}

/// Positions where the node of consecutive unknowns changes: the first unknown of every node
/// block (block-Jacobi preconditioner blocks).
pub fn block_starts(nodes: impl Iterator<Item = usize>) -> Vec<usize> {
    let mut starts = Vec::new();
    let mut last = usize::MAX;
    for (k, node) in nodes.enumerate() {
        if node != last {
            starts.push(k);
            last = node;
        }
    }
    starts
}
