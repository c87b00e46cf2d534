//! The supernodal structure of L that this crate's LLᵀ kernel and block solves read, and how
//! it is made from the node elimination tree without a scalar analysis.
//!
//! faer's `factorize_supernodal_symbolic_cholesky` makes the same structure from the scalar
//! elimination tree: it walks every scalar column (six per beam node), and then builds a
//! row-major copy of the supernodal pattern and a postorder that only faer's own kernels read.
//! On the L non-woven that step took 0.06–0.12 s warm and 0.2–0.36 s inside `homogenize`, where
//! its fresh arrays fault. Here every step runs on nodes (positions of the node order):
//!
//! 1. *Fundamental supernodes.* Inside a node each column is the only child of the next, whose
//!    count is one less, so a fundamental supernode is a run of whole nodes: position p joins
//!    p − 1 when p is p − 1's parent and only child and below(p − 1) = w(p) + below(p) (the
//!    counts of p − 1's last column and p's first differ by one).
//! 2. *Relaxed amalgamation*, faer's rule with faer's thresholds: a supernode is merged into
//!    the next one when it is that one's child and the explicit zeros the merge stores stay
//!    under the threshold of the merged size.
//! 3. *Rows.* Node k's columns are rows of exactly the supernodes on the tree paths from its
//!    lower neighbours up to k's own (George & Liu's row subtree); walking them for k in order
//!    writes every supernode's rows ascending.
//!
//! The result is faer's structure array for array (tested), so the factor is the same value for
//! value; only faer's kernels, which need faer's own type, do not read it.

use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::linalg::SymbolicSupernodalParams;
use fibercell_solver::{NodeGraph, NodeTree, SolverError};

/// No supernode (the parent of a root).
const NONE: usize = usize::MAX;

/// A supernodal structure of L, in the factor's order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Supernodes {
    /// First column of each supernode, n at the end.
    begin: Vec<usize>,
    /// Where each supernode's rows below its diagonal block start in `row_idx`, and the end.
    col_ptr_for_row_idx: Vec<usize>,
    /// Where each supernode's values (rows × width, column-major) start, and the end.
    col_ptr_for_val: Vec<usize>,
    row_idx: Vec<usize>,
}

/// A borrowed supernodal structure: this crate's [`Supernodes`] or faer's own.
#[derive(Clone, Copy)]
pub(crate) struct SupernodesRef<'a> {
    n: usize,
    begin: &'a [usize],
    end: &'a [usize],
    col_ptr_for_row_idx: &'a [usize],
    col_ptr_for_val: &'a [usize],
    row_idx: &'a [usize],
}

impl<'a> SupernodesRef<'a> {
    /// faer's structure, borrowed.
    pub(crate) fn of_faer(f: &'a SymbolicSupernodalCholesky<usize>) -> Self {
        SupernodesRef {
            n: f.nrows(),
            begin: f.supernode_begin(),
            end: f.supernode_end(),
            col_ptr_for_row_idx: f.col_ptr_for_row_idx(),
            col_ptr_for_val: f.col_ptr_for_val(),
            row_idx: f.row_idx(),
        }
    }

    /// Order of the matrix.
    pub(crate) fn nrows(self) -> usize {
        self.n
    }

    pub(crate) fn n_supernodes(self) -> usize {
        self.begin.len()
    }

    /// First column of each supernode.
    pub(crate) fn supernode_begin(self) -> &'a [usize] {
        self.begin
    }

    /// One past the last column of each supernode.
    pub(crate) fn supernode_end(self) -> &'a [usize] {
        self.end
    }

    /// Start of each supernode's rows in [`SupernodesRef::row_idx`], and the end.
    pub(crate) fn col_ptr_for_row_idx(self) -> &'a [usize] {
        self.col_ptr_for_row_idx
    }

    /// Start of each supernode's values, and the end.
    pub(crate) fn col_ptr_for_val(self) -> &'a [usize] {
        self.col_ptr_for_val
    }

    /// The rows below every supernode's diagonal block.
    pub(crate) fn row_idx(self) -> &'a [usize] {
        self.row_idx
    }

    /// The rows below supernode `s`'s diagonal block, ascending.
    pub(crate) fn pattern(self, s: usize) -> &'a [usize] {
        &self.row_idx[self.col_ptr_for_row_idx[s]..self.col_ptr_for_row_idx[s + 1]]
    }

    /// Stored values of L (square diagonal blocks and relaxed zeros included).
    pub(crate) fn len_val(self) -> usize {
        self.col_ptr_for_val[self.n_supernodes()]
    }
}

impl Supernodes {
    pub(crate) fn as_ref(&self) -> SupernodesRef<'_> {
        let ns = self.begin.len() - 1;
        SupernodesRef {
            n: self.begin[ns],
            begin: &self.begin[..ns],
            end: &self.begin[1..],
            col_ptr_for_row_idx: &self.col_ptr_for_row_idx,
            col_ptr_for_val: &self.col_ptr_for_val,
            row_idx: &self.row_idx,
        }
    }

    /// The supernodes of the matrix permuted by `tree`'s order (`graph.expand(tree.nodes())`),
    /// as faer's supernodal analysis with its default relaxation makes them. O(nodes + node
    /// edges + stored row indices).
    pub(crate) fn of_node_tree(graph: &NodeGraph, tree: &NodeTree) -> Result<Self, SolverError> {
        let starts = tree.column_starts(graph);
        let width: Vec<usize> = starts.windows(2).map(|w| w[1] - w[0]).collect();
        let (parent, below) = (tree.parents(), tree.below());
        let m = width.len();
        if m == 0 {
            return Ok(Supernodes::shaped(&[0], &[0], &[]));
        }
        let postordered = parent.len() == m
            && below.len() == m
            && parent
                .iter()
                .enumerate()
                .all(|(j, &p)| p == j || (j < p && p < m));
        if !postordered {
            return Err(inconsistent("is not a postordered elimination tree"));
        }
        let fundamental = fundamental_supernodes(&width, parent, below);
        let relaxed = relaxed_supernodes(&fundamental, &width, parent, below);
        let mut s = Supernodes::shaped(&relaxed, &starts, below);
        s.row_idx = rows(graph, tree, &relaxed, &starts, &s.col_ptr_for_row_idx)?;
        Ok(s)
    }

    /// Columns and value layout of supernodes of positions `first[r]..first[r + 1]`, with no
    /// rows yet.
    fn shaped(first: &[usize], starts: &[usize], below: &[usize]) -> Self {
        let ns = first.len() - 1;
        let mut s = Supernodes {
            begin: Vec::with_capacity(ns + 1),
            col_ptr_for_row_idx: Vec::with_capacity(ns + 1),
            col_ptr_for_val: Vec::with_capacity(ns + 1),
            row_idx: Vec::new(),
        };
        let (mut rows, mut values) = (0, 0);
        for w in first.windows(2) {
            let (cols, degree) = (starts[w[1]] - starts[w[0]], below[w[1] - 1]);
            s.begin.push(starts[w[0]]);
            s.col_ptr_for_row_idx.push(rows);
            s.col_ptr_for_val.push(values);
            rows += degree;
            values += (cols + degree) * cols;
        }
        s.begin.push(starts[starts.len() - 1]);
        s.col_ptr_for_row_idx.push(rows);
        s.col_ptr_for_val.push(values);
        s
    }
}

/// The fundamental supernodes as runs of positions: their first positions, m at the end.
fn fundamental_supernodes(width: &[usize], parent: &[usize], below: &[usize]) -> Vec<usize> {
    let m = width.len();
    let mut children = vec![0u32; m];
    for (j, &p) in parent.iter().enumerate() {
        if p != j {
            children[p] += 1;
        }
    }
    let mut first = vec![0];
    for p in 1..m {
        let joins = parent[p - 1] == p && children[p] == 1 && below[p - 1] == width[p] + below[p];
        if !joins {
            first.push(p);
        }
    }
    first.push(m);
    first
}

/// faer's relaxed amalgamation of the fundamental supernodes `fundamental` (first positions, m
/// at the end): the relaxed supernodes' first positions, m at the end.
///
/// faer visits each supernode as a parent in ascending order and merges into it the child
/// numbered just before it, if any, while the zeros stay below its thresholds; a merged child
/// has absorbed its own predecessor already, so the relaxed supernodes are runs of fundamental
/// ones. The zeros of a merge: the child's columns hold (parent width + parent degree − child
/// degree) zeros each, on top of the zeros both held already.
fn relaxed_supernodes(
    fundamental: &[usize],
    width: &[usize],
    parent: &[usize],
    below: &[usize],
) -> Vec<usize> {
    let nf = fundamental.len() - 1;
    let relax = SymbolicSupernodalParams::default().relax.unwrap_or(&[]);
    let last = |f: usize| fundamental[f + 1] - 1;
    let mut size: Vec<usize> = (0..nf)
        .map(|f| width[fundamental[f]..fundamental[f + 1]].iter().sum())
        .collect();
    let degree: Vec<usize> = (0..nf).map(|f| below[last(f)]).collect();
    let mut zeros = vec![0usize; nf];
    for p in 1..nf {
        let c = p - 1;
        // The child's last node's parent is the first node of p.
        if parent[last(c)] != fundamental[p] {
            continue;
        }
        let (ps, cs) = (size[p], size[c]);
        let new_zeros = (ps + degree[p]).saturating_sub(degree[c]) * cs;
        let merged = if new_zeros == 0 {
            zeros[p] + zeros[c]
        } else {
            let total = new_zeros + zeros[p] + zeros[c];
            let cols = cs + ps;
            let expanded = (cols * (cols + 1) / 2 + degree[p] * cols) as f64;
            let within = relax.iter().any(|&(max_cols, fraction)| {
                max_cols >= cols && expanded * fraction >= total as f64
            });
            if !within {
                continue;
            }
            total
        };
        size[p] += cs;
        size[c] = 0;
        zeros[p] = merged;
    }
    let mut first = vec![0];
    first.extend((0..nf).filter(|&f| size[f] > 0).map(|f| fundamental[f + 1]));
    first
}

/// The rows below every supernode (of positions `first[r]..first[r + 1]`), laid out at
/// `col_ptr[r]`: for each position k ascending, its columns go to every supernode on the
/// tree paths from k's lower neighbours up to k's own.
fn rows(
    graph: &NodeGraph,
    tree: &NodeTree,
    first: &[usize],
    starts: &[usize],
    col_ptr: &[usize],
) -> Result<Vec<usize>, SolverError> {
    let (nodes, parent) = (tree.nodes(), tree.parents());
    let (m, ns) = (nodes.len(), first.len() - 1);
    let mut supernode_of = vec![0usize; m];
    for r in 0..ns {
        supernode_of[first[r]..first[r + 1]].fill(r);
    }
    let super_parent: Vec<usize> = (0..ns)
        .map(|r| {
            let last = first[r + 1] - 1;
            if parent[last] == last {
                NONE
            } else {
                supernode_of[parent[last]]
            }
        })
        .collect();
    let mut position = vec![0usize; m];
    for (new, &old) in nodes.iter().enumerate() {
        position[old] = new;
    }
    let mut row_idx = vec![0usize; col_ptr[ns]];
    let mut next = col_ptr[..ns].to_vec();
    let mut visited = vec![NONE; ns];
    let broken = || inconsistent("gives supernodes that miss a row of L");
    for k in 0..m {
        let cols = starts[k]..starts[k + 1];
        visited[supernode_of[k]] = k;
        for &h in graph.neighbours(nodes[k]) {
            let i = position[h];
            if i >= k {
                continue;
            }
            let mut r = supernode_of[i];
            while visited[r] != k {
                let (at, to) = (next[r], next[r] + cols.len());
                if to > col_ptr[r + 1] {
                    return Err(broken());
                }
                row_idx[at..to]
                    .iter_mut()
                    .zip(cols.clone())
                    .for_each(|(o, c)| *o = c);
                next[r] = to;
                visited[r] = k;
                r = *super_parent
                    .get(r)
                    .filter(|&&p| p != NONE)
                    .ok_or_else(broken)?;
            }
        }
    }
    if next.iter().zip(&col_ptr[1..]).any(|(a, b)| a != b) {
        return Err(broken());
    }
    Ok(row_idx)
}

/// An internal error: the node tree is not what its order's analysis made.
fn inconsistent(what: &str) -> SolverError {
    SolverError::Backend {
        backend: "faer-cholesky",
        code: -4,
        message: format!("the node tree {what} (an internal error)"),
    }
}

/// Asserts that two structures are the same, array for array (tests).
#[cfg(test)]
pub(crate) fn assert_same_supernodes(
    ours: SupernodesRef<'_>,
    theirs: SupernodesRef<'_>,
    what: &str,
) {
    assert_eq!(ours.nrows(), theirs.nrows(), "{what}");
    assert_eq!(ours.supernode_begin(), theirs.supernode_begin(), "{what}");
    assert_eq!(ours.supernode_end(), theirs.supernode_end(), "{what}");
    assert_eq!(
        ours.col_ptr_for_row_idx(),
        theirs.col_ptr_for_row_idx(),
        "{what}"
    );
    assert_eq!(ours.col_ptr_for_val(), theirs.col_ptr_for_val(), "{what}");
    assert_eq!(ours.row_idx(), theirs.row_idx(), "{what}");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_matrices::{blocked_network, grid, structure_cases};
    use faer::perm::PermRef;
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
        SymmetricOrdering,
    };
    use faer::sparse::linalg::SupernodalThreshold;
    use faer::sparse::SymbolicSparseColMatRef;
    use faer::Side;
    use fibercell_solver::{CscMatrix, FillOrdering};

    /// faer's own analysis of `a` under `fwd`/`inv`, supernodal whatever its flops.
    fn faers(a: &CscMatrix, fwd: &[usize], inv: &[usize]) -> SymbolicCholesky<usize> {
        let a = a.as_ref();
        let n = a.ncols();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx());
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let p = PermRef::new_checked(fwd, inv, n);
        factorize_symbolic_cholesky(pattern, Side::Lower, SymmetricOrdering::Custom(p), params)
            .unwrap()
    }

    /// `a` and `b` side by side, unconnected (the node tree is a forest of two trees).
    fn beside(a: &CscMatrix, b: &CscMatrix) -> CscMatrix {
        let (a, b) = (a.as_ref(), b.as_ref());
        let mut t = Vec::new();
        for (m, offset) in [(a, 0), (b, a.ncols())] {
            for j in 0..m.ncols() {
                let (rows, values) = m.col(j);
                t.extend(
                    rows.iter()
                        .zip(values)
                        .map(|(&i, &v)| (i + offset, j + offset, v)),
                );
            }
        }
        let n = a.ncols() + b.ncols();
        CscMatrix::from_triplets(n, n, &t).unwrap()
    }

    /// The supernodes made on the node tree are faer's, array for array, for every ordering:
    /// on networks of mixed node widths (relaxed supernodes with explicit zeros among them),
    /// on scalar grids, on a forest and on one node.
    #[test]
    fn the_node_tree_gives_faers_supernodes() {
        let mut cases = structure_cases();
        cases.push(("forest", beside(&blocked_network(300), &grid(7))));
        let mut relaxed_zeros = 0;
        for (name, a) in &cases {
            let g = NodeGraph::of(a.as_ref()).unwrap();
            for o in [
                FillOrdering::Amd,
                FillOrdering::NestedDissection,
                FillOrdering::Auto,
            ] {
                let what = format!("{name}, {}", o.name());
                let ordered = g.ordered(&o).unwrap();
                let p = &ordered.permutation;
                let ours = Supernodes::of_node_tree(&g, &ordered.tree).unwrap();
                let faer = faers(a, &p.fwd, &p.inv);
                let SymbolicCholeskyRaw::Supernodal(theirs) = faer.raw() else {
                    panic!("{what}: forced supernodal");
                };
                let (ours, theirs) = (ours.as_ref(), SupernodesRef::of_faer(theirs));
                assert_same_supernodes(ours, theirs, &what);
                // Entries of the lower trapezoids against the structure's nnz(L).
                let stored: usize = (0..ours.n_supernodes())
                    .map(|s| {
                        let w = ours.supernode_end()[s] - ours.supernode_begin()[s];
                        w * (w + 1) / 2 + w * ours.pattern(s).len()
                    })
                    .sum();
                assert!(stored >= ordered.fill.nnz_l, "{what}");
                relaxed_zeros += usize::from(stored > ordered.fill.nnz_l);
            }
        }
        assert!(relaxed_zeros >= 6, "only {relaxed_zeros} cases relaxed");
    }

    /// An empty matrix has no supernodes.
    #[test]
    fn an_empty_tree_has_no_supernodes() {
        let a = CscMatrix::from_triplets(0, 0, &[]).unwrap();
        let g = NodeGraph::of(a.as_ref()).unwrap();
        let ordered = g.ordered(&FillOrdering::Amd).unwrap();
        let s = Supernodes::of_node_tree(&g, &ordered.tree).unwrap();
        assert_eq!((s.as_ref().n_supernodes(), s.as_ref().len_val()), (0, 0));
        assert_eq!(s.as_ref().nrows(), 0);
    }
}
