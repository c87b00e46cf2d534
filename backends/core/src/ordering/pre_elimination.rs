//! The nodes eliminated before nested dissection: those whose elimination leaves the graph
//! with fewer edges than before, taken lowest degree first.
//!
//! Eliminating a node of degree d removes its d edges and joins its neighbours pairwise,
//! adding f edges (the fill: the neighbour pairs not yet adjacent). Where f < d the elimination
//! graph shrinks in nodes and edges, and the node's neighbourhood is nearly a clique — a
//! simplicial node (f = 0) can go first in a minimum-fill order at no loss, and f < d extends
//! this to the nodes a separator could gain little from. On a fiber network these are a
//! fiber's free ends and its nodes between contacts (degree ≤ 2, f ≤ 1), and then the nodes
//! at contacts whose neighbours the chains already joined. METIS orders the rest.
//!
//! Measured with `solve-matrix --ordering nd` on the exported cell matrices, mean of METIS
//! seeds 1–3, degree ≤ 2 only against this rule: L seed 1 nnz(L) 7.89 → 7.59·10⁷ and flops
//! 5.52 → 4.98·10¹⁰ (METIS orders 107,520 → 55,805 nodes), L seed 2 7.68 → 7.49·10⁷ and
//! 4.87 → 4.77·10¹⁰, M 1.141 → 1.127·10⁷ and 4.02 → 4.07·10⁹. METIS takes ≈ 30 % less time
//! on L, about what the rule's test costs (0.15–0.2 s): the gain is the factor, not the ordering
//! time. Eliminating every node of degree ≤ 4 instead was worse on M and L seed 2 (+7 %, +3 %
//! flops), every node of degree ≤ 6 worse everywhere (+33 % on L).
#![cfg_attr(not(feature = "metis"), allow(dead_code))]

use super::NodeGraph;
use rustc_hash::FxHashSet;

/// Degree above which a node is not tested (the test looks up its d(d − 1)/2 neighbour
/// pairs). The rule itself seldom passes near it: in a first version of this code, caps 8
/// and 16 kept the same 55,684 of L's nodes (this one keeps 55,805 at cap 8).
const LARGEST_DEGREE_TESTED: usize = 8;

/// Adjacency lists up to this length are scanned (each holds the node's own and fill edges,
/// with eliminated nodes until pruned); longer ones are looked up.
const SCANNED_LIST: usize = 32;

/// [`pre_eliminated`]: the nodes eliminated first in their order, the others ascending, and the
/// graph of the others with the edges the eliminations added (node k of it is `kept[k]`, with
/// its weight).
pub(super) struct PreElimination {
    pub(super) eliminated: Vec<usize>,
    pub(super) kept: Vec<usize>,
    pub(super) graph: NodeGraph,
}

/// The elimination graph as nodes go, for lookups in long lists with the graph's own edges
/// (sorted, bisected) and a set of the fill edges. Each node's list of its own and fill edges
/// (holding eliminated nodes until it is next read) lies in one shared array with room to
/// grow: a candidate reads its neighbours' lists, so they are kept dense (32-bit entries,
/// no allocation of their own) for the sake of the cache.
struct EliminationGraph<'g> {
    graph: &'g NodeGraph,
    lists: Vec<u32>,
    slot: Vec<Slot>,
    /// FxHash: the keys are node pairs of one matrix, and SipHash took 5 of the 68 ms on L.
    fill: FxHashSet<(usize, usize)>,
    alive: Vec<bool>,
    degree: Vec<usize>,
}

/// A node's list in [`EliminationGraph::lists`]: `len` entries from `start`, room for `room`.
#[derive(Clone, Copy)]
struct Slot {
    start: usize,
    len: u32,
    room: u32,
}

/// Room for fill edges each list starts with (it moves to the end of the array, with twice
/// its room, when full).
const ROOM_FOR_FILL: usize = 2;

impl<'g> EliminationGraph<'g> {
    /// The graph as it is, or None if its nodes do not fit the lists' 32-bit entries.
    fn new(graph: &'g NodeGraph) -> Option<Self> {
        let m = graph.nodes();
        u32::try_from(m).ok()?;
        let mut lists = Vec::with_capacity(graph.edges() + m * ROOM_FOR_FILL);
        let mut slot = Vec::with_capacity(m);
        for g in 0..m {
            let own = graph.neighbours(g);
            slot.push(Slot {
                start: lists.len(),
                len: own.len() as u32,
                room: (own.len() + ROOM_FOR_FILL) as u32,
            });
            // Entries are node numbers below m, which fits (checked above).
            lists.extend(own.iter().map(|&u| u as u32));
            lists.extend([u32::MAX; ROOM_FOR_FILL]);
        }
        Some(EliminationGraph {
            graph,
            lists,
            slot,
            fill: FxHashSet::default(),
            alive: vec![true; m],
            degree: (0..m).map(|g| graph.neighbours(g).len()).collect(),
        })
    }

    /// Whether live nodes `a` and `b` are adjacent: a scan of the shorter list where it is
    /// short, else a bisection of the graph's own edges and a lookup of the fill.
    fn joined(&self, a: usize, b: usize) -> bool {
        let (sa, sb) = (self.slot[a], self.slot[b]);
        let (short, other) = if sa.len <= sb.len { (sa, b) } else { (sb, a) };
        if short.len as usize <= SCANNED_LIST {
            let list = &self.lists[short.start..short.start + short.len as usize];
            return list.contains(&(other as u32));
        }
        self.graph.neighbours(a).binary_search(&b).is_ok()
            || self.fill.contains(&(a.min(b), a.max(b)))
    }

    /// The live neighbours of `v` (its list pruned of eliminated nodes, once per node each).
    fn neighbours(&mut self, v: usize) -> &[u32] {
        let Slot { start, len, .. } = self.slot[v];
        let list = &mut self.lists[start..start + len as usize];
        let mut live = 0;
        for k in 0..list.len() {
            if self.alive[list[k] as usize] {
                list[live] = list[k];
                live += 1;
            }
        }
        self.slot[v].len = live as u32;
        &self.lists[start..start + live]
    }

    /// Appends `u` to `v`'s list: after pruning it if it is full, and at the end of the array
    /// with twice its room if it is still full.
    fn push(&mut self, v: usize, u: usize) {
        if self.slot[v].len == self.slot[v].room {
            self.neighbours(v);
        }
        let s = self.slot[v];
        if s.len == s.room {
            let start = self.lists.len();
            self.lists
                .extend_from_within(s.start..s.start + s.len as usize);
            self.lists.resize(start + 2 * s.room as usize, u32::MAX);
            self.slot[v] = Slot {
                start,
                len: s.len,
                room: 2 * s.room,
            };
        }
        let s = &mut self.slot[v];
        self.lists[s.start + s.len as usize] = u as u32;
        s.len += 1;
    }

    /// The neighbour pairs of `around` not yet adjacent, into `missing`, or None once there
    /// are `limit` of them.
    fn missing_pairs<'m>(
        &self,
        around: &[usize],
        limit: usize,
        missing: &'m mut Vec<(usize, usize)>,
    ) -> Option<&'m [(usize, usize)]> {
        missing.clear();
        for (i, &a) in around.iter().enumerate() {
            for &b in &around[i + 1..] {
                if !self.joined(a, b) {
                    if missing.len() + 1 >= limit {
                        return None;
                    }
                    missing.push((a, b));
                }
            }
        }
        Some(missing)
    }

    /// Eliminates `v` (live neighbours `around`, of which the pairs `missing` are not yet
    /// adjacent): the neighbours lose it and are joined pairwise.
    fn eliminate(&mut self, v: usize, around: &[usize], missing: &[(usize, usize)]) {
        self.alive[v] = false;
        for &u in around {
            self.degree[u] -= 1;
        }
        for &(a, b) in missing {
            self.fill.insert((a.min(b), a.max(b)));
            self.push(a, b);
            self.push(b, a);
            self.degree[a] += 1;
            self.degree[b] += 1;
        }
    }
}

/// The nodes of `graph` eliminated first (see the module): repeatedly a node of least degree
/// d ≤ [`LARGEST_DEGREE_TESTED`] whose fill f is below max(d, 1), as long as there is one; and
/// the graph of the others. Each node's list is pruned once per read and each tested pair is
/// a bisection or a hash lookup, so a node joined to every other costs no quadratic search.
pub(super) fn pre_eliminated(graph: &NodeGraph) -> PreElimination {
    let m = graph.nodes();
    let Some(mut g) = EliminationGraph::new(graph) else {
        return PreElimination {
            eliminated: Vec::new(),
            kept: (0..m).collect(),
            graph: graph.clone(),
        };
    };
    // Lowest degree first; a node is queued again at its new degree when that changes, and a
    // stale entry (eliminated, or at another degree now) is passed over. Within a degree the
    // latest queued goes first, so a tail is eliminated from its free end without fill.
    let mut queues: Vec<Vec<usize>> = vec![Vec::new(); LARGEST_DEGREE_TESTED + 1];
    for v in (0..m).rev() {
        if let Some(q) = queues.get_mut(g.degree[v]) {
            q.push(v);
        }
    }
    let mut eliminated = Vec::new();
    let mut missing = Vec::new();
    while let Some((d, v)) = queues
        .iter_mut()
        .enumerate()
        .find_map(|(d, q)| q.pop().map(|v| (d, v)))
    {
        if !g.alive[v] || g.degree[v] != d {
            continue;
        }
        let mut around = [0usize; LARGEST_DEGREE_TESTED];
        let live = g.neighbours(v);
        debug_assert_eq!(live.len(), d, "node {v}'s degree");
        let around = &mut around[..live.len()];
        for (a, &u) in around.iter_mut().zip(live) {
            *a = u as usize;
        }
        let Some(missing) = g.missing_pairs(around, around.len().max(1), &mut missing) else {
            continue;
        };
        g.eliminate(v, around, missing);
        eliminated.push(v);
        for &u in around.iter() {
            if let Some(q) = queues.get_mut(g.degree[u]) {
                q.push(u);
            }
        }
    }
    let kept: Vec<usize> = (0..m).filter(|&v| g.alive[v]).collect();
    let mut index = vec![usize::MAX; m];
    for (k, &v) in kept.iter().enumerate() {
        index[v] = k;
    }
    let mut starts = Vec::with_capacity(kept.len() + 1);
    let mut xadj = Vec::with_capacity(kept.len() + 1);
    let mut edges = Vec::new();
    starts.push(0);
    xadj.push(0);
    for &v in &kept {
        starts.push(starts.last().copied().unwrap_or(0) + graph.weight(v));
        let first = edges.len();
        edges.extend(g.neighbours(v).iter().map(|&u| index[u as usize]));
        edges[first..].sort_unstable();
        xadj.push(edges.len());
    }
    PreElimination {
        eliminated,
        kept,
        graph: NodeGraph::from_parts(starts, xadj, edges),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The graph on `m` nodes of six unknowns with `edges` (each once, either way round).
    fn graph(m: usize, edges: &[(usize, usize)]) -> NodeGraph {
        let mut lists = vec![Vec::new(); m];
        for &(a, b) in edges {
            lists[a].push(b);
            lists[b].push(a);
        }
        let (mut xadj, mut adj) = (vec![0], Vec::new());
        for mut l in lists {
            l.sort_unstable();
            l.dedup();
            adj.extend(l);
            xadj.push(adj.len());
        }
        NodeGraph::from_parts((0..=m).map(|g| 6 * g).collect(), xadj, adj)
    }

    fn clique(nodes: std::ops::Range<usize>) -> Vec<(usize, usize)> {
        let all: Vec<usize> = nodes.collect();
        let mut e = Vec::new();
        for (i, &a) in all.iter().enumerate() {
            e.extend(all[i + 1..].iter().map(|&b| (a, b)));
        }
        e
    }

    /// The cube's nodes have degree 3 and no two neighbours adjacent: eliminating one would
    /// add 3 edges for its 3, so all stay. A tail on node 0 goes from its free end.
    #[test]
    fn a_cube_stays_and_a_tail_goes_from_its_free_end() {
        let mut edges: Vec<(usize, usize)> = (0..8)
            .flat_map(|i| [1, 2, 4].map(|b| (i, i ^ b)))
            .filter(|&(i, j)| i < j)
            .collect();
        edges.extend([(0, 8), (8, 9), (9, 10)]);
        let first = pre_eliminated(&graph(11, &edges));
        assert_eq!(first.eliminated, [10, 9, 8]);
        assert_eq!(first.kept, (0..8).collect::<Vec<_>>());
        for i in 0..8 {
            let mut cube = [i ^ 1, i ^ 2, i ^ 4];
            cube.sort_unstable();
            assert_eq!(first.graph.neighbours(i), cube);
            assert_eq!(first.graph.weight(i), 6);
        }
    }

    /// Node 30 joins 0 and 1 (adjacent, in one clique) and 20 (another): eliminating it adds
    /// the 2 edges 0–20 and 1–20 for its 3, so it goes. Node 31 joins three cliques: 3 edges
    /// for its 3, so it stays. The cliques' nodes have degree 11, above the nodes tested.
    #[test]
    fn a_node_whose_elimination_removes_edges_goes_and_joins_its_neighbours() {
        let mut edges = clique(0..12);
        edges.extend(
            clique(20..32)
                .iter()
                .map(|&(a, b)| (a - 20 + 12, b - 20 + 12)),
        );
        edges.extend(
            clique(40..52)
                .iter()
                .map(|&(a, b)| (a - 40 + 24, b - 40 + 24)),
        );
        // Cliques on 0–11, 12–23, 24–35; node 36 on 0, 1, 12; node 37 on 2, 13, 24.
        edges.extend([(36, 0), (36, 1), (36, 12), (37, 2), (37, 13), (37, 24)]);
        let g = graph(38, &edges);
        let first = pre_eliminated(&g);
        assert_eq!(first.eliminated, [36]);
        assert_eq!(first.kept, (0..36).chain([37]).collect::<Vec<_>>());
        let kept = &first.graph;
        assert_eq!(kept.edges(), g.edges() - 2 * 3 + 2 * 2);
        assert!(kept.neighbours(12).starts_with(&[0, 1, 13]));
        assert_eq!(kept.neighbours(36), [2, 13, 24]);
    }

    /// On scattered graphs (a ring with long chords and triangles), replayed on a dense
    /// adjacency matrix: every node eliminated was live with degree ≤ the largest tested and
    /// fill below max(degree, 1); the graph left is the elimination graph, and none of its
    /// nodes has degree ≤ 2 (those always qualify).
    #[test]
    fn the_eliminations_follow_the_rule_and_leave_the_elimination_graph() {
        for (m, chords, seed) in [(60, 40, 1u64), (200, 150, 7), (400, 500, 11)] {
            let mut x = seed;
            let mut next = |k: usize| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (x >> 33) as usize % k
            };
            let mut edges: Vec<(usize, usize)> = (0..m).map(|i| (i, (i + 1) % m)).collect();
            // Long chords, and short ones closing triangles on the ring.
            edges.extend(
                (0..chords)
                    .map(|_| (next(m), next(m)))
                    .filter(|(a, b)| a != b),
            );
            edges.extend((0..chords).map(|_| next(m)).map(|i| (i, (i + 2) % m)));
            // Tails hung on some nodes.
            let mut n = m;
            for _ in 0..m / 10 {
                let on = next(m);
                edges.extend([(on, n), (n, n + 1)]);
                n += 2;
            }
            let g = graph(n, &edges);
            let first = pre_eliminated(&g);
            let mut dense = vec![vec![false; n]; n];
            for &(a, b) in &edges {
                dense[a][b] = true;
                dense[b][a] = true;
            }
            let mut alive = vec![true; n];
            let mut beyond_chains = 0;
            for &v in &first.eliminated {
                assert!(alive[v], "m = {m}: {v} eliminated twice");
                let around: Vec<usize> = (0..n).filter(|&u| alive[u] && dense[v][u]).collect();
                let mut fill = 0;
                for (i, &a) in around.iter().enumerate() {
                    for &b in &around[i + 1..] {
                        if !dense[a][b] {
                            fill += 1;
                            dense[a][b] = true;
                            dense[b][a] = true;
                        }
                    }
                }
                let d = around.len();
                assert!(
                    d <= LARGEST_DEGREE_TESTED && fill < d.max(1),
                    "m = {m}: {v}"
                );
                beyond_chains += usize::from(d > 2);
                alive[v] = false;
            }
            let kept: Vec<usize> = (0..n).filter(|&v| alive[v]).collect();
            assert_eq!(first.kept, kept, "m = {m}");
            assert!(first.eliminated.len() + kept.len() == n);
            assert!(beyond_chains > 0, "m = {m}: no node of degree > 2 went");
            for (k, &v) in kept.iter().enumerate() {
                let want: Vec<usize> = (0..kept.len()).filter(|&j| dense[v][kept[j]]).collect();
                assert_eq!(first.graph.neighbours(k), want, "m = {m}: node {v}");
                assert!(want.len() > 2, "m = {m}: node {v} of degree {}", want.len());
            }
        }
    }
}
