//! The sparsity pattern of the reduced stiffness (both triangles) and the slot map that sends
//! every entry of every element matrix to its place in the value array — built once, so value
//! fills never search or sort.

use super::DofMap;
use crate::model::Model;
use fibercell_solver::{CscRef, SolverError};

/// Slot of an element-matrix entry that touches a prescribed DOF.
pub const NO_SLOT: u32 = u32::MAX;

/// CSC pattern of the reduced system plus, per element, the value slot of each of its 144
/// entries (row-major, `NO_SLOT` for prescribed rows or columns).
#[derive(Clone, Debug)]
pub struct Pattern {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    element_slots: Vec<[u32; 144]>,
}

/// Errors of pattern construction.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("the stiffness pattern has {0} entries, more than the 32-bit slot map holds")]
pub struct PatternTooLargeError(pub usize);

impl Pattern {
    /// Builds the pattern of the frame elements of `model` under `dofs`.
    pub fn new(model: &Model, dofs: &DofMap) -> Result<Self, PatternTooLargeError> {
        let n_nodes = model.nodes.len();
        let mut adjacency: Vec<Vec<usize>> = (0..n_nodes).map(|i| vec![i]).collect();
        for e in model.elements() {
            let [a, b] = e.nodes;
            adjacency[a].push(b);
            adjacency[b].push(a);
        }
        for adj in &mut adjacency {
            adj.sort_unstable();
            adj.dedup();
        }
        let red = dofs.reduced_indices();
        let n = dofs.n_free();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for node in 0..n_nodes {
            for d in 0..6 {
                if red[6 * node + d] == usize::MAX {
                    continue;
                }
                for &nb in &adjacency[node] {
                    row_idx.extend(red[6 * nb..6 * nb + 6].iter().filter(|&&r| r != usize::MAX));
                }
                col_ptr.push(row_idx.len());
            }
        }
        if row_idx.len() >= NO_SLOT as usize {
            return Err(PatternTooLargeError(row_idx.len()));
        }
        let mut element_slots = Vec::with_capacity(model.elements().len());
        for e in model.elements() {
            let globals: Vec<usize> = e
                .nodes
                .iter()
                .flat_map(|&nd| (0..6).map(move |d| 6 * nd + d))
                .collect();
            let mut slots = [NO_SLOT; 144];
            for (c, &gc) in globals.iter().enumerate() {
                let Some(jc) = dofs.reduced(gc) else { continue };
                let rows = &row_idx[col_ptr[jc]..col_ptr[jc + 1]];
                for (r, &gr) in globals.iter().enumerate() {
                    let Some(ir) = dofs.reduced(gr) else { continue };
                    if let Ok(k) = rows.binary_search(&ir) {
                        slots[r * 12 + c] = (col_ptr[jc] + k) as u32;
                    }
                }
            }
            element_slots.push(slots);
        }
        Ok(Pattern {
            n,
            col_ptr,
            row_idx,
            element_slots,
        })
    }

    /// Order of the reduced system.
    pub fn n(&self) -> usize {
        self.n
    }
    /// Stored entries (both triangles).
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
    /// Column pointers.
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }
    /// Row indices.
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }
    /// Slot map of element `e` (row-major 12×12).
    pub fn element_slots(&self, e: usize) -> &[u32; 144] {
        &self.element_slots[e]
    }
    /// A matrix view with these values.
    pub fn matrix<'a>(&'a self, values: &'a [f64]) -> Result<CscRef<'a>, SolverError> {
        CscRef::new(self.n, self.n, &self.col_ptr, &self.row_idx, values)
    }
}
