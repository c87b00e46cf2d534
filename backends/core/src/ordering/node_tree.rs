//! The elimination tree of a node order, and what it gives the scalar factor without a scalar
//! analysis: its elimination tree and column counts, and a small pattern with the same
//! elimination reach as the permuted matrix.
//!
//! Each node's columns are consecutive in the order and its blocks are full
//! ([`NodeGraph`]), so the scalar factor is the node factor expanded: inside a node of width
//! w, column i's parent is column i + 1 and the node's last column's parent is the first
//! column of the parent node; column i of a node with b unknowns below its block holds
//! w − i + b entries.

use super::NodeGraph;

/// A node order (`nodes[new] = old node`) with its elimination tree, by position.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NodeTree {
    pub(super) nodes: Vec<usize>,
    /// Parent position of each position; a root is its own parent.
    pub(super) parent: Vec<usize>,
    /// Unknowns below each node's diagonal block in L.
    pub(super) below: Vec<usize>,
}

/// The scalar factor's elimination tree and column counts, as faer's
/// `prefactorize_symbolic_cholesky` returns them for the permuted matrix.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScalarTree {
    /// Parent column of each column, −1 at a root.
    pub parent: Vec<isize>,
    /// Entries of each column of L, diagonal included.
    pub counts: Vec<usize>,
}

/// A pattern in compressed columns (ascending rows in each column).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReachPattern {
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
}

impl NodeTree {
    /// The node order: `nodes()[new] = old node`.
    pub fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    /// Each position's parent position; a root is its own parent. A parent comes after its
    /// children (the order is postordered).
    pub fn parents(&self) -> &[usize] {
        &self.parent
    }

    /// Unknowns below each position's diagonal block in L.
    pub fn below(&self) -> &[usize] {
        &self.below
    }

    /// The first scalar column of each position, and n at the end.
    pub fn column_starts(&self, graph: &NodeGraph) -> Vec<usize> {
        let mut starts = Vec::with_capacity(self.nodes.len() + 1);
        starts.push(0);
        for &g in &self.nodes {
            starts.push(starts[starts.len() - 1] + graph.weight(g));
        }
        starts
    }

    /// The scalar elimination tree and column counts of the permuted matrix
    /// (`graph.expand(self.nodes())`). O(n).
    pub fn scalar_tree(&self, graph: &NodeGraph) -> ScalarTree {
        let starts = self.column_starts(graph);
        let n = starts[starts.len() - 1];
        let mut parent = Vec::with_capacity(n);
        let mut counts = Vec::with_capacity(n);
        for (j, cols) in starts.windows(2).enumerate() {
            let w = cols[1] - cols[0];
            let p = self.parent[j];
            let last = if p == j { -1 } else { starts[p] as isize };
            parent.extend((cols[0] + 1..cols[1]).map(|c| c as isize));
            parent.push(last);
            counts.extend((0..w).map(|i| w - i + self.below[j]));
        }
        ScalarTree { parent, counts }
    }

    /// A pattern whose strict upper triangle reaches what the permuted matrix's does in the
    /// elimination tree: in every column of a node, the first column of each neighbour
    /// numbered before it. A supernodal symbolic factorization that walks the tree from each
    /// entry (faer's `ereach_super`) and never splits a node then finds the same row
    /// structure from one entry per neighbour instead of one per neighbouring column.
    /// O(n · upper node degree).
    pub fn reach_pattern(&self, graph: &NodeGraph) -> ReachPattern {
        let starts = self.column_starts(graph);
        let n = starts[starts.len() - 1];
        let mut position = vec![0usize; self.nodes.len()];
        for (new, &old) in self.nodes.iter().enumerate() {
            position[old] = new;
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        let mut rows = Vec::new();
        col_ptr.push(0);
        for (j, &old) in self.nodes.iter().enumerate() {
            rows.clear();
            rows.extend(
                graph
                    .neighbours(old)
                    .iter()
                    .map(|&h| position[h])
                    .filter(|&q| q < j)
                    .map(|q| starts[q]),
            );
            rows.sort_unstable();
            for _ in 0..graph.weight(old) {
                row_idx.extend_from_slice(&rows);
                col_ptr.push(row_idx.len());
            }
        }
        ReachPattern { col_ptr, row_idx }
    }
}
