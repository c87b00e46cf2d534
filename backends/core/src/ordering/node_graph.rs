//! The graph of a structurally symmetric matrix compressed to its nodes (supervariables:
//! consecutive columns with identical patterns, e.g. the six DOFs of a beam node), the
//! orderings computed on it, and the fill they predict for the scalar matrix.
//!
//! A fiber network's matrix is 6×6-blocked by node, so its node graph has 36× fewer edges than
//! the scalar one: AMD and nested dissection run on it and the node order is expanded, each
//! node's columns kept together. Because the blocks between nodes are full (below), the scalar
//! factor's pattern is the node factor's pattern expanded, so nnz(L) and the flops of a
//! candidate follow exactly from the node graph's elimination tree, without a scalar symbolic
//! factorization.

use super::node_tree::NodeTree;
#[cfg(feature = "metis")]
use super::pre_elimination::pre_eliminated;
use super::{FillOrdering, Permutation};
use crate::{CscRef, SolverError};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SymbolicSparseColMatRef;
use rayon::prelude::*;

/// Columns one task of [`NodeGraph::with_groups`] compares at least, and nodes whose
/// adjacency lists it makes.
const NODES_PER_TASK: usize = 4096;

/// A structurally symmetric matrix's graph on its supervariables. Blocks between two
/// supervariables are full or empty: if column j of group g holds row r of group h, every
/// column of h (same pattern as r) holds j, so by symmetry every column of g holds all of h.
#[derive(Clone, Debug)]
pub struct NodeGraph {
    /// First column of each node, and n at the end (`starts[g]..starts[g + 1]`).
    starts: Vec<usize>,
    /// Adjacency (other nodes, ascending, no self loop) in CSR form.
    xadj: Vec<usize>,
    adj: Vec<usize>,
}

/// A node order (`nodes[new] = old node`), its elimination tree and unknowns below each node's
/// block ([`NodeGraph::tree_and_counts`]), and its fill.
struct Candidate {
    nodes: Vec<usize>,
    tree: (Vec<usize>, Vec<usize>),
    fill: FillEstimate,
}

/// A node graph's ordering: the scalar permutation, its fill, the ordering chosen and the
/// node order's elimination tree ([`NodeGraph::ordered`]).
#[derive(Clone, Debug)]
pub struct OrderedNodes {
    pub permutation: Permutation,
    pub fill: FillEstimate,
    pub chosen: FillOrdering,
    pub tree: NodeTree,
}

/// The fill a node ordering predicts for the scalar matrix's Cholesky factor (exact for the
/// pattern; faer's relaxed supernodes may store a few explicit zeros more).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FillEstimate {
    /// Entries of L, diagonal included.
    pub nnz_l: usize,
    /// Σ c_j² over the factor's column counts c_j (a left-looking Cholesky's flops).
    pub flops: f64,
}

/// Graphs of at least this many nodes count their factor's entries on two threads (on L's
/// 155,781 nodes 14 ms on one).
const PARALLEL_COUNT_NODES: usize = 1 << 14;

impl NodeGraph {
    /// The node graph of `a`, whose pattern must be square and symmetric (checked: AMD and
    /// METIS hang or return nonsense on one triangle). The check runs on the nodes while
    /// they are made (see `NodeGraph::with_groups` and `NodeGraph::is_mirrored`: one
    /// comparison per entry of a node's first column and one lookup per node edge); only a
    /// refused pattern goes through [`CscRef::check_structurally_symmetric`], for the first
    /// entry without its mirror.
    ///
    /// The grouped pattern is symmetric exactly when (i) every node's pattern is made of whole
    /// nodes (it holds all rows of a node or none) and (ii) the node adjacency is symmetric.
    /// If: take an entry (i, j), j in node g and i in node h. Column j's pattern is g's, which
    /// holds i, so all of h by (i); then h = g, or h is g's neighbour and by (ii) g is h's,
    /// so h's pattern holds a row of g and by (i) all of g, j among them: column i holds j.
    /// Only if: with a symmetric pattern row i's pattern is column i's, the same for all
    /// columns of h, so a column holds all rows of h or none (i); (ii) follows.
    pub fn of(a: CscRef<'_>) -> Result<Self, SolverError> {
        if a.nrows() != a.ncols() {
            a.check_structurally_symmetric()?;
        }
        let (graph, whole_nodes) = Self::with_groups(a);
        if !(whole_nodes && graph.is_mirrored()) {
            a.check_structurally_symmetric()?;
        }
        Ok(graph)
    }

    /// Whether the node adjacency is symmetric: every node is in the list of each of its
    /// neighbours.
    fn is_mirrored(&self) -> bool {
        (0..self.nodes())
            .into_par_iter()
            .with_min_len(1024)
            .all(|g| {
                self.neighbours(g)
                    .iter()
                    .all(|&h| self.neighbours(h).binary_search(&g).is_ok())
            })
    }

    /// [`NodeGraph::of`] for a pattern the caller has checked with
    /// [`CscRef::check_structurally_symmetric`] (on an asymmetric pattern the orderings may
    /// hang or return nonsense).
    pub fn of_checked(a: CscRef<'_>) -> Self {
        Self::with_groups(a).0
    }

    /// The graph of `a`'s pattern as [`NodeGraph::of_checked`] makes it, and whether every
    /// node's pattern is made of whole nodes (each run of a node's rows in its first column
    /// holds all of them). The columns' comparisons
    /// and the nodes' lists are made on the threads.
    fn with_groups(a: CscRef<'_>) -> (Self, bool) {
        let n = a.ncols();
        let opens: Vec<bool> = (0..n)
            .into_par_iter()
            .with_min_len(NODES_PER_TASK)
            .map(|j| j == 0 || a.col(j).0 != a.col(j - 1).0)
            .collect();
        let mut starts = Vec::new();
        let mut group = vec![0usize; n];
        for (j, g) in group.iter_mut().enumerate() {
            if opens[j] {
                starts.push(j);
            }
            *g = starts.len() - 1;
        }
        let m = starts.len();
        starts.push(n);
        // Node g's neighbours: the nodes of its first column's rows (ascending), but g.
        let weight = |h: usize| starts[h + 1] - starts[h];
        let lists: Vec<(Vec<usize>, Vec<usize>, bool)> = starts[..m]
            .par_chunks(NODES_PER_TASK)
            .enumerate()
            .map(|(c, firsts)| {
                let (mut ends, mut adj) = (Vec::with_capacity(firsts.len()), Vec::new());
                let mut whole = true;
                for (g, &first) in (c * NODES_PER_TASK..).zip(firsts) {
                    // The rows strictly ascend, so each node's rows are one run, all of
                    // the node when the run is as long as the node is wide.
                    let (mut last, mut run) = (usize::MAX, 0);
                    for &r in a.col(first).0 {
                        let h = group[r];
                        if h != last {
                            whole &= last == usize::MAX || run == weight(last);
                            if h != g {
                                adj.push(h);
                            }
                            (last, run) = (h, 0);
                        }
                        run += 1;
                    }
                    whole &= last == usize::MAX || run == weight(last);
                    ends.push(adj.len());
                }
                (ends, adj, whole)
            })
            .collect();
        let mut xadj = Vec::with_capacity(m + 1);
        let mut adj = Vec::with_capacity(lists.iter().map(|l| l.1.len()).sum());
        let mut whole_nodes = true;
        xadj.push(0);
        for (ends, part, whole) in lists {
            let offset = adj.len();
            xadj.extend(ends.iter().map(|&e| offset + e));
            adj.extend(part);
            whole_nodes &= whole;
        }
        (NodeGraph { starts, xadj, adj }, whole_nodes)
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.starts.len() - 1
    }

    /// Order of the scalar matrix.
    pub fn order_of_matrix(&self) -> usize {
        *self.starts.last().unwrap_or(&0)
    }

    /// Columns (unknowns) of node g.
    pub fn weight(&self, g: usize) -> usize {
        self.starts[g + 1] - self.starts[g]
    }

    /// Neighbours of node g (ascending, without g).
    pub fn neighbours(&self, g: usize) -> &[usize] {
        &self.adj[self.xadj[g]..self.xadj[g + 1]]
    }

    /// Stored adjacency entries (each edge twice).
    pub fn edges(&self) -> usize {
        self.adj.len()
    }

    /// The scalar permutation of `ordering` (AMD or nested dissection; [`FillOrdering::Auto`]
    /// is the one of the two with fewer predicted flops, AMD on a tie) with its predicted fill
    /// and the concrete ordering used.
    pub fn order(
        &self,
        ordering: &FillOrdering,
    ) -> Result<(Permutation, FillEstimate, FillOrdering), SolverError> {
        self.ordered(ordering)
            .map(|o| (o.permutation, o.fill, o.chosen))
    }

    /// [`NodeGraph::order`] with the node order's elimination tree (postordered).
    pub fn ordered(&self, ordering: &FillOrdering) -> Result<OrderedNodes, SolverError> {
        let (best, chosen) = match ordering {
            FillOrdering::Amd => (self.candidate(self.amd()?), FillOrdering::Amd),
            FillOrdering::NestedDissection => (
                self.candidate(self.nested_dissection()?),
                FillOrdering::NestedDissection,
            ),
            FillOrdering::Auto => self.better_of_amd_and_nested_dissection()?,
            FillOrdering::Natural | FillOrdering::Given(_) => {
                return Err(SolverError::InvalidMatrix(format!(
                    "the {} ordering is not computed on the node graph",
                    ordering.name()
                )))
            }
        };
        let tree = self.postordered_of(&best.nodes, &best.tree);
        Ok(OrderedNodes {
            permutation: self.expand(tree.nodes())?,
            fill: best.fill,
            chosen,
            tree,
        })
    }

    /// Both candidates side by side (METIS and AMD are sequential); without METIS (the
    /// `metis` feature) AMD alone.
    fn better_of_amd_and_nested_dissection(
        &self,
    ) -> Result<(Candidate, FillOrdering), SolverError> {
        // AMD is the faster: its tree and fill are made on its thread while METIS runs.
        let (amd, nd) = rayon::join(
            || self.amd().map(|o| self.candidate(o)),
            || self.nested_dissection(),
        );
        let amd = amd?;
        Ok(match nd {
            Err(SolverError::Unavailable { .. }) => (amd, FillOrdering::Amd),
            nd => {
                let nd = self.candidate(nd?);
                if nd.fill.flops < amd.fill.flops {
                    (nd, FillOrdering::NestedDissection)
                } else {
                    (amd, FillOrdering::Amd)
                }
            }
        })
    }

    /// The scalar permutation of a node order (`nodes[new] = old node`): each node's columns
    /// consecutively, in their own order.
    pub fn expand(&self, nodes: &[usize]) -> Result<Permutation, SolverError> {
        let n = self.order_of_matrix();
        let mut fwd = Vec::with_capacity(n);
        for &g in nodes {
            fwd.extend(self.starts[g]..self.starts[g + 1]);
        }
        Permutation::from_fwd(fwd, n)
    }

    /// AMD (faer's) on the node graph; its node order.
    fn amd(&self) -> Result<Vec<usize>, SolverError> {
        let m = self.nodes();
        let mut fwd = vec![0usize; m];
        let mut inv = vec![0usize; m];
        let pattern = SymbolicSparseColMatRef::new_checked(m, m, &self.xadj, None, &self.adj);
        let req = amd::order_scratch::<usize>(m, self.adj.len());
        let mut buf = MemBuffer::try_new(req).map_err(|_| SolverError::OutOfMemory)?;
        amd::order(
            &mut fwd,
            &mut inv,
            pattern,
            amd::Control::default(),
            MemStack::new(&mut buf),
        )
        .map_err(|e| SolverError::Backend {
            backend: "amd",
            code: -1,
            message: format!("{e:?}"),
        })?;
        Ok(fwd)
    }

    /// Nested dissection by METIS on the node graph, weighted by node size, after the nodes
    /// whose elimination removes more edges than it adds ([`pre_eliminated`]): METIS orders
    /// the rest.
    #[cfg(feature = "metis")]
    fn nested_dissection(&self) -> Result<Vec<usize>, SolverError> {
        let first = pre_eliminated(self);
        let rest = super::metis::node_nested_dissection(&first.graph)?;
        let mut order = first.eliminated;
        order.extend(rest.iter().map(|&k| first.kept[k]));
        Ok(order)
    }

    /// A graph from its parts: node starts (n at the end) and sorted adjacency in CSR form.
    pub(super) fn from_parts(starts: Vec<usize>, xadj: Vec<usize>, adj: Vec<usize>) -> Self {
        NodeGraph { starts, xadj, adj }
    }

    /// Without the `metis` feature there is no nested dissection.
    #[cfg(not(feature = "metis"))]
    fn nested_dissection(&self) -> Result<Vec<usize>, SolverError> {
        Err(SolverError::Unavailable {
            backend: "metis",
            reason: "fibercell-solver was built without its `metis` feature".into(),
        })
    }

    /// A node order with its elimination tree and fill.
    fn candidate(&self, nodes: Vec<usize>) -> Candidate {
        let tree = self.tree_and_counts(&nodes);
        let fill = self.fill_of(&nodes, &tree.1);
        Candidate { nodes, tree, fill }
    }

    /// The scalar factor's fill under a node order (`nodes[new] = old node`), from the node
    /// graph's elimination tree: for each node i, the nodes of its row of L are the etree
    /// paths from its lower neighbours up to i (George & Liu's row subtrees), so node j's
    /// column below its diagonal block holds the weights of every i whose row subtree passes
    /// j. Node j of width w with b unknowns below its block then has scalar column counts
    /// w + b, w − 1 + b, …, 1 + b. O(nnz of the node factor).
    pub fn fill(&self, nodes: &[usize]) -> FillEstimate {
        self.fill_of(nodes, &self.tree_and_counts(nodes).1)
    }

    /// [`NodeGraph::fill`] from the order's unknowns below each node's block.
    fn fill_of(&self, nodes: &[usize], below: &[usize]) -> FillEstimate {
        let mut fill = FillEstimate {
            nnz_l: 0,
            flops: 0.0,
        };
        for (j, &old) in nodes.iter().enumerate() {
            let b = below[j];
            for k in 1..=self.weight(old) {
                let c = k + b;
                fill.nnz_l += c;
                fill.flops += (c as f64) * (c as f64);
            }
        }
        fill
    }

    /// The elimination tree of the permuted node graph (`parent`, a root its own parent) and
    /// each node's unknowns below its diagonal block in L (`below`), by position.
    fn tree_and_counts(&self, nodes: &[usize]) -> (Vec<usize>, Vec<usize>) {
        let m = self.nodes();
        let mut position = vec![0usize; m];
        for (new, &old) in nodes.iter().enumerate() {
            position[old] = new;
        }
        let parent = self.elimination_tree(nodes, &position);
        // Each row's walk is independent of the others': on a large graph the rows are dealt
        // alternately to two threads, each with its own marks and counts, summed after.
        let below = if m >= PARALLEL_COUNT_NODES {
            let count = |first| self.row_subtree_counts(nodes, &position, &parent, first, 2);
            let (even, odd) = rayon::join(|| count(0), || count(1));
            even.iter().zip(&odd).map(|(a, b)| a + b).collect()
        } else {
            self.row_subtree_counts(nodes, &position, &parent, 0, 1)
        };
        (parent, below)
    }

    /// The unknowns that the rows `first`, `first + step`, … of the node factor put below
    /// each node's diagonal block (by position): row i's nodes are the tree paths from its
    /// lower neighbours up to i (its row subtree), each path walked until a node already
    /// marked for row i.
    fn row_subtree_counts(
        &self,
        nodes: &[usize],
        position: &[usize],
        parent: &[usize],
        first: usize,
        step: usize,
    ) -> Vec<usize> {
        let m = self.nodes();
        let mut below = vec![0usize; m];
        let mut mark = vec![usize::MAX; m];
        for i in (first..m).step_by(step) {
            let old = nodes[i];
            mark[i] = i;
            let w = self.weight(old);
            for &k in self.neighbours(old) {
                let mut r = position[k];
                if r > i {
                    continue;
                }
                while mark[r] != i {
                    mark[r] = i;
                    below[r] += w;
                    r = parent[r];
                }
            }
        }
        below
    }

    /// An equivalent node order (same elimination tree, same fill): the tree's postorder with
    /// each node's children by ascending column count, so the child with the longest column
    /// comes right before its parent (CHOLMOD's weighted postorder). A supernode can absorb
    /// only the supernode numbered right before it, so this is the order in which relaxed
    /// amalgamation merges the most.
    pub fn postordered(&self, nodes: &[usize]) -> Vec<usize> {
        self.postordered_of(nodes, &self.tree_and_counts(nodes))
            .nodes
    }

    /// [`NodeGraph::postordered`] from the order's tree and counts, with the tree renumbered
    /// to the postorder.
    fn postordered_of(
        &self,
        nodes: &[usize],
        (parent, below): &(Vec<usize>, Vec<usize>),
    ) -> NodeTree {
        let m = nodes.len();
        let count = |j: usize| below[j] + self.weight(nodes[j]);
        // Children lists in CSR form, each by ascending count and then position (the
        // positions go in ascending, and a stable sort of each list keeps that among equal
        // counts; most lists hold one child).
        let mut first_child = vec![0usize; m + 1];
        for j in 0..m {
            if parent[j] != j {
                first_child[parent[j] + 1] += 1;
            }
        }
        for j in 0..m {
            first_child[j + 1] += first_child[j];
        }
        let mut children = vec![0usize; first_child[m]];
        let mut next = first_child.clone();
        for j in 0..m {
            if parent[j] != j {
                children[next[parent[j]]] = j;
                next[parent[j]] += 1;
            }
        }
        for j in 0..m {
            let list = &mut children[first_child[j]..first_child[j + 1]];
            if list.len() > 1 {
                list.sort_by_key(|&c| count(c));
            }
        }
        // `next[j]`: j's next child to visit.
        next.copy_from_slice(&first_child);
        // `post[j]`: the new position of position j.
        let mut post = vec![0usize; m];
        let mut out = Vec::with_capacity(m);
        let mut stack = Vec::new();
        for root in (0..m).filter(|&j| parent[j] == j) {
            stack.push(root);
            while let Some(&j) = stack.last() {
                if next[j] == first_child[j + 1] {
                    post[j] = out.len();
                    out.push(nodes[j]);
                    stack.pop();
                } else {
                    stack.push(children[next[j]]);
                    next[j] += 1;
                }
            }
        }
        let mut tree = NodeTree {
            nodes: out,
            parent: vec![0; m],
            below: vec![0; m],
        };
        for j in 0..m {
            tree.parent[post[j]] = post[parent[j]];
            tree.below[post[j]] = below[j];
        }
        tree
    }

    /// Parent of each node in the elimination tree of the permuted node graph (Liu's algorithm
    /// with path compression); a root's parent is itself.
    fn elimination_tree(&self, nodes: &[usize], position: &[usize]) -> Vec<usize> {
        let m = nodes.len();
        let mut parent: Vec<usize> = (0..m).collect();
        let mut ancestor = vec![usize::MAX; m];
        for (i, &old) in nodes.iter().enumerate() {
            for &k in self.neighbours(old) {
                let mut r = position[k];
                if r > i {
                    continue;
                }
                while ancestor[r] != usize::MAX && ancestor[r] != i {
                    let next = ancestor[r];
                    ancestor[r] = i;
                    r = next;
                }
                if ancestor[r] == usize::MAX {
                    ancestor[r] = i;
                    parent[r] = i;
                }
            }
        }
        parent
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CscMatrix;
    use faer::sparse::linalg::cholesky::simplicial::prefactorize_symbolic_cholesky;

    /// A symmetric matrix on `widths.len()` nodes of the given widths, full blocks on the
    /// diagonal and between the nodes of each edge.
    fn blocked(widths: &[usize], edges: &[(usize, usize)]) -> CscMatrix {
        let mut start = vec![0];
        for w in widths {
            start.push(start.last().unwrap() + w);
        }
        let mut t = Vec::new();
        let block = |t: &mut Vec<(usize, usize, f64)>, g: usize, h: usize| {
            for r in start[g]..start[g + 1] {
                for c in start[h]..start[h + 1] {
                    t.push((r, c, if r == c { 10.0 } else { -0.1 }));
                }
            }
        };
        for g in 0..widths.len() {
            block(&mut t, g, g);
        }
        for &(g, h) in edges {
            block(&mut t, g, h);
            block(&mut t, h, g);
        }
        let n = *start.last().unwrap();
        CscMatrix::from_triplets(n, n, &t).unwrap()
    }

    /// A scattered graph: a ring of `m` nodes with chords from a fixed-seed LCG, widths 1–6.
    fn scattered(m: usize) -> CscMatrix {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as usize
        };
        let widths: Vec<usize> = (0..m).map(|_| 1 + next() % 6).collect();
        let mut edges: Vec<(usize, usize)> = (0..m).map(|g| (g, (g + 1) % m)).collect();
        for _ in 0..m {
            let (g, h) = (next() % m, next() % m);
            if g != h {
                edges.push((g, h));
            }
        }
        blocked(&widths, &edges)
    }

    /// faer's elimination tree and column counts of the scalar matrix under `p`.
    fn scalar_tree(a: &CscMatrix, p: &Permutation) -> (Vec<isize>, Vec<usize>) {
        let a = a.as_ref();
        let n = a.ncols();
        let mut t = Vec::new();
        for j in 0..n {
            for &i in a.col(j).0 {
                let (pi, pj) = (p.inv[i], p.inv[j]);
                if pi <= pj {
                    t.push((pi, pj, 1.0));
                }
            }
        }
        let upper = CscMatrix::from_triplets(n, n, &t).unwrap();
        let u = upper.as_ref();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, u.col_ptr(), None, u.row_idx());
        let mut etree = vec![0isize; n];
        let mut counts = vec![0usize; n];
        let mut buf = MemBuffer::new(faer::dyn_stack::StackReq::new::<usize>(n));
        prefactorize_symbolic_cholesky(&mut etree, &mut counts, pattern, MemStack::new(&mut buf));
        (etree, counts)
    }

    /// nnz(L) and Σ c² of the scalar factor under `p`, by faer's own column counts.
    fn scalar_fill(a: &CscMatrix, p: &Permutation) -> FillEstimate {
        let (_, counts) = scalar_tree(a, p);
        FillEstimate {
            nnz_l: counts.iter().sum(),
            flops: counts.iter().map(|&c| (c * c) as f64).sum(),
        }
    }

    #[test]
    fn nodes_are_the_blocks() {
        let a = blocked(&[6, 3, 6, 1], &[(0, 1), (1, 2), (2, 3)]);
        let g = NodeGraph::of(a.as_ref()).unwrap();
        assert_eq!(g.nodes(), 4);
        assert_eq!(
            (0..4).map(|k| g.weight(k)).collect::<Vec<_>>(),
            [6, 3, 6, 1]
        );
        assert_eq!(g.neighbours(1), [0, 2]);
        assert_eq!(g.edges(), 6);
    }

    /// Across several tasks of [`NodeGraph::with_groups`] (a ring with chords, widths 1–3):
    /// every node's weight, and its list the sorted distinct ends of its edges.
    #[test]
    fn nodes_and_lists_across_tasks_are_the_blocks_and_edges() {
        let m = 3 * NODES_PER_TASK + 17;
        let widths: Vec<usize> = (0..m).map(|g| 1 + g % 3).collect();
        let mut edges: Vec<(usize, usize)> = (0..m).map(|g| (g, (g + 1) % m)).collect();
        edges.extend((0..m).step_by(5).map(|g| (g, (g * 7919 + 11) % m)));
        edges.retain(|&(g, h)| g != h);
        let mut want = vec![Vec::new(); m];
        for &(g, h) in &edges {
            want[g].push(h);
            want[h].push(g);
        }
        let g = NodeGraph::of(blocked(&widths, &edges).as_ref()).unwrap();
        assert_eq!(g.nodes(), m);
        for (k, mut list) in want.into_iter().enumerate() {
            list.sort_unstable();
            list.dedup();
            assert_eq!(g.weight(k), widths[k], "node {k}");
            assert_eq!(g.neighbours(k), list, "node {k}");
        }
    }

    /// The fill predicted on the node graph is faer's scalar column count exactly, for node
    /// orders from AMD, nested dissection, the identity and its reverse.
    #[test]
    fn predicted_fill_is_the_scalar_factors() {
        for m in [1, 2, 17, 200] {
            let a = scattered(m);
            let g = NodeGraph::of(a.as_ref()).unwrap();
            let k = g.nodes();
            let mut orders = vec![(0..k).collect::<Vec<_>>(), (0..k).rev().collect()];
            orders.push(g.amd().unwrap());
            if cfg!(feature = "metis") {
                orders.push(g.nested_dissection().unwrap());
            }
            for nodes in orders {
                let p = g.expand(&nodes).unwrap();
                assert_eq!(g.fill(&nodes), scalar_fill(&a, &p), "m = {m}");
            }
        }
    }

    /// A path's nodes all have degree ≤ 2: they go first, from one end, with no fill — node j
    /// of width w then has w unknowns below its block but the last, so nnz(L) is
    /// m·w(w+1)/2 + (m−1)·w².
    #[test]
    fn a_path_is_eliminated_from_its_end_without_fill() {
        let (m, w) = (9, 6);
        let edges: Vec<(usize, usize)> = (1..m).map(|j| (j - 1, j)).collect();
        let a = blocked(&vec![w; m], &edges);
        let g = NodeGraph::of(a.as_ref()).unwrap();
        let first = super::super::pre_elimination::pre_eliminated(&g);
        assert_eq!(first.eliminated, (0..m).collect::<Vec<_>>());
        assert_eq!(first.graph.nodes(), 0);
        let expected = m * w * (w + 1) / 2 + (m - 1) * w * w;
        assert_eq!(g.fill(&first.eliminated).nnz_l, expected);
        let p = g.expand(&first.eliminated).unwrap();
        assert_eq!(scalar_fill(&a, &p).nnz_l, expected);
    }

    /// On a graph of PARALLEL_COUNT_NODES nodes and more the rows are counted on two threads;
    /// the fill is still the scalar factor's, under the natural order and AMD's.
    #[test]
    fn the_counts_on_two_threads_are_the_scalar_factors() {
        let k = 130;
        let widths: Vec<usize> = (0..k * k).map(|g| 1 + g % 3).collect();
        let mut edges = Vec::new();
        for i in 0..k {
            for j in 0..k {
                if i + 1 < k {
                    edges.push((i * k + j, (i + 1) * k + j));
                }
                if j + 1 < k {
                    edges.push((i * k + j, i * k + j + 1));
                }
            }
        }
        let a = blocked(&widths, &edges);
        let g = NodeGraph::of(a.as_ref()).unwrap();
        assert!(g.nodes() >= PARALLEL_COUNT_NODES);
        for nodes in [(0..g.nodes()).collect::<Vec<_>>(), g.amd().unwrap()] {
            let p = g.expand(&nodes).unwrap();
            assert_eq!(g.fill(&nodes), scalar_fill(&a, &p));
        }
    }

    /// Auto is the candidate with fewer predicted flops, its fill the prediction.
    #[test]
    fn auto_takes_the_cheaper_candidate() {
        let a = scattered(300);
        let g = NodeGraph::of(a.as_ref()).unwrap();
        let (p, fill, chosen) = g.order(&FillOrdering::Auto).unwrap();
        let amd = g.order(&FillOrdering::Amd).unwrap().1;
        let mut best = amd.flops;
        if cfg!(feature = "metis") {
            best = best.min(g.order(&FillOrdering::NestedDissection).unwrap().1.flops);
        } else {
            assert_eq!(chosen, FillOrdering::Amd);
        }
        assert_eq!(fill.flops, best);
        assert_eq!(scalar_fill(&a, &p), fill);
    }

    /// The postorder is an equivalent order (same fill, by faer's scalar column counts) in
    /// which every subtree is contiguous and ends at its root, and the child right before
    /// each parent has the longest column of its siblings (so faer's relaxed amalgamation,
    /// which merges only that child, can merge the widest one).
    #[test]
    fn the_postorder_keeps_the_fill_and_puts_the_longest_child_last() {
        for m in [1, 17, 200] {
            let a = scattered(m);
            let g = NodeGraph::of(a.as_ref()).unwrap();
            let k = g.nodes();
            for nodes in [(0..k).collect::<Vec<_>>(), g.amd().unwrap()] {
                let post = g.postordered(&nodes);
                let p = g.expand(&post).unwrap();
                assert_eq!(scalar_fill(&a, &p), g.fill(&nodes), "m = {m}");
                let (parent, below) = g.tree_and_counts(&post);
                let count = |j: usize| below[j] + g.weight(post[j]);
                let mut size = vec![1usize; k];
                let mut longest_child = vec![None::<usize>; k];
                for j in 0..k {
                    let q = parent[j];
                    if q == j {
                        continue;
                    }
                    assert!(q > j, "m = {m}: parent before child");
                    size[q] += size[j];
                    if longest_child[q].is_none_or(|c| count(c) <= count(j)) {
                        longest_child[q] = Some(j);
                    }
                }
                for j in 0..k {
                    // Subtree of j: the size[j] positions ending at j.
                    let first = j + 1 - size[j];
                    for d in first..j {
                        let mut r = d;
                        while parent[r] != r && r < j {
                            r = parent[r];
                        }
                        assert_eq!(r, j, "m = {m}: position {d} outside the subtree of {j}");
                    }
                    if j > 0 && parent[j - 1] == j {
                        let c = longest_child[j].unwrap();
                        assert_eq!(count(j - 1), count(c), "m = {m}: a longer child not last");
                    } else {
                        assert!(
                            longest_child[j].is_none(),
                            "m = {m}: child not right before"
                        );
                    }
                }
            }
        }
    }

    /// The node tree expanded is faer's scalar elimination tree and column counts of the
    /// permuted matrix, entry for entry, for every ordering and on graphs of mixed widths.
    #[test]
    fn the_expanded_node_tree_is_the_scalar_tree() {
        for m in [1, 2, 17, 200] {
            let a = scattered(m);
            let g = NodeGraph::of(a.as_ref()).unwrap();
            let mut orderings = vec![FillOrdering::Amd, FillOrdering::Auto];
            if cfg!(feature = "metis") {
                orderings.push(FillOrdering::NestedDissection);
            }
            for o in orderings {
                let ordered = g.ordered(&o).unwrap();
                let t = ordered.tree.scalar_tree(&g);
                let (parent, counts) = scalar_tree(&a, &ordered.permutation);
                assert_eq!(t.parent, parent, "m = {m}, {}", o.name());
                assert_eq!(t.counts, counts, "m = {m}, {}", o.name());
                assert_eq!(t.counts.iter().sum::<usize>(), ordered.fill.nnz_l);
            }
        }
    }

    /// The reach pattern holds, in each column, the first column of every neighbour node
    /// ordered before its own, and nothing else.
    #[test]
    fn the_reach_pattern_has_one_entry_per_earlier_neighbour() {
        // Widths 2, 1, 3 on a path 0–1–2 ordered 2, 0, 1: columns 0..3 node 2, 3..5 node 0,
        // 5 node 1.
        let a = blocked(&[2, 1, 3], &[(0, 1), (1, 2)]);
        let g = NodeGraph::of(a.as_ref()).unwrap();
        let (parent, below) = g.tree_and_counts(&[2, 0, 1]);
        let tree = NodeTree {
            nodes: vec![2, 0, 1],
            parent,
            below,
        };
        let r = tree.reach_pattern(&g);
        assert_eq!(r.col_ptr, [0, 0, 0, 0, 0, 0, 2]);
        assert_eq!(r.row_idx, [0, 3]);
        let t = tree.scalar_tree(&g);
        // Node 1 (position 2) joins both: the root; nodes 2 and 0 have it as parent.
        assert_eq!(t.parent, [1, 2, 5, 4, 5, -1]);
        assert_eq!(t.counts, [4, 3, 2, 3, 2, 1]);
    }

    /// The matrix of `a` without the stored entries at `drop` (value indices).
    fn without(a: &CscMatrix, drop: &[usize]) -> CscMatrix {
        let a = a.as_ref();
        let mut t = Vec::new();
        for j in 0..a.ncols() {
            let (rows, values) = a.col(j);
            for (k, (&i, &v)) in rows.iter().zip(values).enumerate() {
                if !drop.contains(&(a.col_ptr()[j] + k)) {
                    t.push((i, j, v));
                }
            }
        }
        CscMatrix::from_triplets(a.nrows(), a.ncols(), &t).unwrap()
    }

    /// The check on the nodes accepts exactly what the scalar check accepts and refuses with
    /// its entry: one entry dropped (asymmetric off the diagonal; symmetric on it, and the
    /// node of that column splits), a mirrored pair dropped (symmetric, nodes split), and
    /// one block of a pair dropped (the nodes stay whole, their adjacency is one-sided).
    #[test]
    fn the_node_check_agrees_with_the_scalar_check() {
        let a = scattered(40);
        let r = a.as_ref();
        let symmetric = |b: CscRef<'_>| {
            let (g, whole_nodes) = NodeGraph::with_groups(b);
            whole_nodes && g.is_mirrored()
        };
        assert!(symmetric(r));
        let position = |i: usize, j: usize| {
            let rows = r.col(j).0;
            r.col_ptr()[j] + rows.binary_search(&i).unwrap()
        };
        let mut cases: Vec<Vec<usize>> = (0..r.nnz()).step_by(5).map(|k| vec![k]).collect();
        let (mut accepted, mut refused) = (0, 0);
        for j in (0..r.ncols()).step_by(3) {
            for &i in r.col(j).0.iter().filter(|&&i| i > j).take(2) {
                cases.push(vec![position(i, j), position(j, i)]);
            }
        }
        // One side of the block between the first node and its first neighbour.
        let g = NodeGraph::of_checked(r);
        let h = g.neighbours(0)[0];
        let block: Vec<usize> = (g.starts[h]..g.starts[h + 1])
            .flat_map(|i| (g.starts[0]..g.starts[1]).map(move |j| (i, j)))
            .map(|(i, j)| position(i, j))
            .collect();
        cases.push(block);
        for drop in &cases {
            let b = without(&a, drop);
            let scalar = b.as_ref().check_structurally_symmetric();
            let nodes = symmetric(b.as_ref());
            assert_eq!(nodes, scalar.is_ok(), "dropped {drop:?}");
            assert_eq!(
                NodeGraph::of(b.as_ref()).map(|_| ()),
                scalar,
                "dropped {drop:?}"
            );
            if nodes {
                accepted += 1;
            } else {
                refused += 1;
            }
        }
        assert!(
            accepted >= 20 && refused >= 20,
            "{accepted} accepted, {refused} refused"
        );
    }

    #[test]
    fn an_asymmetric_pattern_is_refused() {
        let a = CscMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 1, 1.0), (1, 0, 1.0)]).unwrap();
        assert!(matches!(
            NodeGraph::of(a.as_ref()),
            Err(SolverError::NotStructurallySymmetric { .. })
        ));
    }
}
