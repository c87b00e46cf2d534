//! Nested dissection by METIS on a matrix's node graph (feature `metis`).
//!
//! A large graph is split first: `METIS_ComputeVertexSeparator` finds the top separator, and
//! `METIS_NodeND` orders the two halves side by side, separator last — the first step of
//! METIS's own recursion (`MlevelNestedDissection`), with its second and later steps on two
//! threads. The vendored METIS draws from a thread-local random state and sets no process-wide
//! signal handlers (`vendor/metis-sys/PATCHES.md`), so the order is the same whatever runs
//! beside it and whatever the number of threads.

use super::NodeGraph;
use crate::SolverError;
use metis_sys::idx_t;

/// Graphs of at least this many nodes are split at a top separator first. Measured with
/// `solve-matrix --ordering nd`, METIS seeds 1–15 on L (55,805 nodes left to METIS): METIS
/// 0.36 → 0.21–0.25 s, flops 4.94 → 5.02·10¹⁰ (mean; ±0.19 between seeds). On M (9,395
/// nodes), seeds 1–8: 48 → 31–45 ms for +3 % flops, a wash, so M stays whole.
const SPLIT_NODES: usize = 16_384;

/// METIS_OPTION_NSEPS: separators tried at each level, the smaller kept.
const SEPARATORS_TRIED: idx_t = 2;

/// METIS_OPTION_UFACTOR of the top separator: its sides' weights may differ from even by
/// 1 + 1/1000 (METIS's default for nested dissection, 200, lets them differ by 1.2, and on
/// L seed 1 the larger half took 0.23 s against 0.19). Measured with `solve-matrix` on L seed
/// 1's node graph, METIS seeds 1–5: ordering 0.433 → 0.386 s (mean), flops 5.14 → 5.05·10¹⁰
/// (mean; ±0.25 between seeds).
const TOP_IMBALANCE: idx_t = 1;

/// A graph in METIS's arrays: CSR adjacency without self loops, node weights.
struct MetisGraph {
    xadj: Vec<idx_t>,
    adjncy: Vec<idx_t>,
    vwgt: Vec<idx_t>,
}

/// The typed error of a METIS return code other than METIS_OK.
fn metis_error(call: &str, status: std::os::raw::c_int) -> SolverError {
    #[allow(non_upper_case_globals)]
    match status {
        metis_sys::rstatus_et_METIS_ERROR_MEMORY => SolverError::OutOfMemory,
        metis_sys::rstatus_et_METIS_ERROR_INPUT => SolverError::InvalidMatrix(format!(
            "{call} rejected the graph of the matrix (METIS_ERROR_INPUT)"
        )),
        code => SolverError::Backend {
            backend: "metis",
            code: code as i64,
            message: format!("{call} failed (METIS_ERROR)"),
        },
    }
}

/// METIS's default options, 0-based numbering and [`SEPARATORS_TRIED`] separators.
fn options() -> [idx_t; metis_sys::METIS_NOPTIONS as usize] {
    let mut options = [0; metis_sys::METIS_NOPTIONS as usize];
    // SAFETY: the array holds METIS_NOPTIONS entries, as METIS_SetDefaultOptions writes.
    unsafe { metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr()) };
    options[metis_sys::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
    // On the L non-woven's whole node graph (155,781 nodes, before the pre-elimination):
    // nnz(L) 7.84e7 and 5.28e10 flops against 8.00e7 / 5.73e10 with one and 7.69e7 / 5.06e10
    // with five (CHOLMOD's default ordering: 7.83e7 / 5.31e10), for 1.3 s of ordering against
    // 1.0 s and 3.0 s: five save ≈ 0.06 s per factorization and ≈ 1 ms per solve, so they pay
    // for their 1.7 s after thousands of solves only.
    options[metis_sys::moptions_et_METIS_OPTION_NSEPS as usize] = SEPARATORS_TRIED;
    options
}

impl MetisGraph {
    /// `graph` in METIS's arrays, nodes weighted by their unknowns.
    fn of(graph: &NodeGraph) -> Result<Self, SolverError> {
        let too_big = || SolverError::Backend {
            backend: "metis",
            code: -2,
            message: "graph too large for 32-bit METIS indices".into(),
        };
        let idx = |v: usize| idx_t::try_from(v).map_err(|_| too_big());
        let m = graph.nodes();
        let mut g = MetisGraph {
            xadj: Vec::with_capacity(m + 1),
            adjncy: Vec::with_capacity(graph.edges()),
            vwgt: Vec::with_capacity(m),
        };
        // Node numbers below m and list ends up to the edges: both fit once these do.
        idx(m)?;
        idx(graph.edges())?;
        g.xadj.push(0);
        for v in 0..m {
            g.vwgt.push(idx(graph.weight(v))?);
            g.adjncy
                .extend(graph.neighbours(v).iter().map(|&h| h as idx_t));
            g.xadj.push(g.adjncy.len() as idx_t);
        }
        Ok(g)
    }

    fn nodes(&self) -> usize {
        self.vwgt.len()
    }

    /// The nodes of `side` (0 or 1 of a separator's `part`), ascending, and their graph.
    fn side(&self, part: &[idx_t], side: idx_t) -> (Vec<usize>, MetisGraph) {
        let nodes: Vec<usize> = (0..self.nodes()).filter(|&v| part[v] == side).collect();
        let mut local = vec![0 as idx_t; self.nodes()];
        for (k, &v) in nodes.iter().enumerate() {
            local[v] = k as idx_t;
        }
        let mut g = MetisGraph {
            xadj: Vec::with_capacity(nodes.len() + 1),
            adjncy: Vec::new(),
            vwgt: nodes.iter().map(|&v| self.vwgt[v]).collect(),
        };
        g.xadj.push(0);
        for &v in &nodes {
            let list = &self.adjncy[self.xadj[v] as usize..self.xadj[v + 1] as usize];
            g.adjncy.extend(
                list.iter()
                    .filter(|&&h| part[h as usize] == side)
                    .map(|&h| local[h as usize]),
            );
            g.xadj.push(g.adjncy.len() as idx_t);
        }
        (nodes, g)
    }

    /// METIS_NodeND's order (`[new] = old`).
    fn nested_dissection(mut self) -> Result<Vec<usize>, SolverError> {
        let m = self.nodes();
        if m <= 1 {
            return Ok((0..m).collect());
        }
        let mut nvtxs = m as idx_t;
        let mut options = options();
        let (mut perm, mut iperm) = (vec![0 as idx_t; m], vec![0 as idx_t; m]);
        // SAFETY: the arrays have the sizes METIS documents (xadj m + 1, adjncy xadj[m], vwgt
        // m, options METIS_NOPTIONS, perm and iperm m) and live across the call; the indices
        // in xadj and adjncy are in range (made so by `of` and `side`).
        let status = unsafe {
            metis_sys::METIS_NodeND(
                &mut nvtxs,
                self.xadj.as_mut_ptr(),
                self.adjncy.as_mut_ptr(),
                self.vwgt.as_mut_ptr(),
                options.as_mut_ptr(),
                perm.as_mut_ptr(),
                iperm.as_mut_ptr(),
            )
        };
        if status != metis_sys::rstatus_et_METIS_OK {
            return Err(metis_error("METIS_NodeND", status));
        }
        Ok(perm.iter().map(|&g| g as usize).collect())
    }

    /// METIS_ComputeVertexSeparator's part of each node: 0 or 1 for the two sides, 2 for the
    /// separator.
    fn separator(&mut self) -> Result<Vec<idx_t>, SolverError> {
        let m = self.nodes();
        let mut nvtxs = m as idx_t;
        let mut options = options();
        options[metis_sys::moptions_et_METIS_OPTION_UFACTOR as usize] = TOP_IMBALANCE;
        let (mut part, mut separator_weight) = (vec![0 as idx_t; m], 0 as idx_t);
        // SAFETY: as in `nested_dissection`, with part of size m.
        let status = unsafe {
            metis_sys::METIS_ComputeVertexSeparator(
                &mut nvtxs,
                self.xadj.as_mut_ptr(),
                self.adjncy.as_mut_ptr(),
                self.vwgt.as_mut_ptr(),
                options.as_mut_ptr(),
                &mut separator_weight,
                part.as_mut_ptr(),
            )
        };
        if status != metis_sys::rstatus_et_METIS_OK {
            return Err(metis_error("METIS_ComputeVertexSeparator", status));
        }
        if part.iter().any(|&p| !(0..=2).contains(&p)) {
            return Err(SolverError::Backend {
                backend: "metis",
                code: -4,
                message: "METIS_ComputeVertexSeparator returned a part other than 0, 1, 2".into(),
            });
        }
        Ok(part)
    }

    /// The top separator's two sides ordered on two threads, then the separator.
    fn split_nested_dissection(mut self) -> Result<Vec<usize>, SolverError> {
        let part = self.separator()?;
        let order_side = |side| {
            let (nodes, g) = self.side(&part, side);
            g.nested_dissection()
                .map(|order| order.iter().map(|&k| nodes[k]).collect::<Vec<_>>())
        };
        let (first, second) = rayon::join(|| order_side(0), || order_side(1));
        let mut order = first?;
        order.extend(second?);
        order.extend((0..self.nodes()).filter(|&v| part[v] == 2));
        Ok(order)
    }
}

/// The node order (`[new] = old node`) of METIS's nested dissection of `graph`, nodes weighted
/// by their unknowns; graphs of [`SPLIT_NODES`] nodes and more split at a top separator first.
pub(super) fn node_nested_dissection(graph: &NodeGraph) -> Result<Vec<usize>, SolverError> {
    let g = MetisGraph::of(graph)?;
    if g.nodes() >= SPLIT_NODES {
        g.split_nested_dissection()
    } else {
        g.nested_dissection()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The k × k grid's graph, node (i, j) of weight 1 + (i + j) mod 3.
    fn grid(k: usize) -> NodeGraph {
        let mut starts = vec![0];
        let (mut xadj, mut adj) = (vec![0], Vec::new());
        for i in 0..k {
            for j in 0..k {
                starts.push(starts[starts.len() - 1] + 1 + (i + j) % 3);
                let v = i * k + j;
                let mut nb = Vec::new();
                if i > 0 {
                    nb.push(v - k);
                }
                if j > 0 {
                    nb.push(v - 1);
                }
                if j + 1 < k {
                    nb.push(v + 1);
                }
                if i + 1 < k {
                    nb.push(v + k);
                }
                adj.extend(nb);
                xadj.push(adj.len());
            }
        }
        NodeGraph::from_parts(starts, xadj, adj)
    }

    fn is_permutation(order: &[usize]) -> bool {
        let mut seen = vec![false; order.len()];
        order
            .iter()
            .all(|&v| v < seen.len() && !std::mem::replace(&mut seen[v], true))
    }

    /// A graph of SPLIT_NODES nodes and more is ordered as the first step of METIS's recursion:
    /// the separator's two sides, which share no edge and weigh alike, each ordered whole,
    /// then the separator.
    #[test]
    fn a_split_order_holds_one_side_the_other_and_the_separator() {
        let k = 130;
        let g = grid(k);
        assert!(g.nodes() >= SPLIT_NODES);
        let order = node_nested_dissection(&g).unwrap();
        assert!(is_permutation(&order));
        // The same separator as the order's (each METIS call seeds its own state).
        let part = MetisGraph::of(&g).unwrap().separator().unwrap();
        for v in 0..g.nodes() {
            for &h in g.neighbours(v) {
                assert!(part[v] + part[h] != 1, "edge {v}–{h} joins the two sides");
            }
        }
        let count = |p| part.iter().filter(|&&x| x == p).count();
        let (first, second, separator) = (count(0), count(1), count(2));
        // The two threads get even halves: 16,772 and 16,856 unknowns here (13,837 and 19,809
        // at METIS's default imbalance for nested dissection).
        let weight = |p| {
            (0..g.nodes())
                .filter(|&v| part[v] == p)
                .map(|v| g.weight(v))
                .sum::<usize>()
        };
        let (light, heavy) = (weight(0).min(weight(1)), weight(0).max(weight(1)));
        assert!(
            heavy as f64 <= 1.02 * light as f64,
            "sides of {light} and {heavy}"
        );
        // A grid's separator is about one line of it, and its sides hold a third at least.
        assert!(separator <= 2 * k, "separator of {separator} nodes");
        assert!(first.min(second) > g.nodes() / 3, "sides {first}, {second}");
        let parts: Vec<idx_t> = order.iter().map(|&v| part[v]).collect();
        assert!(parts[..first].iter().all(|&p| p == 0));
        assert!(parts[first..first + second].iter().all(|&p| p == 1));
        assert!(parts[first + second..].iter().all(|&p| p == 2));
        // The split costs little fill against METIS's own recursion: 0.7 % more on this grid;
        // more than 10 % would mean a worse top separator than METIS's own.
        let whole = MetisGraph::of(&g).unwrap().nested_dissection().unwrap();
        let (split, whole) = (g.fill(&order).nnz_l, g.fill(&whole).nnz_l);
        assert!(
            (split as f64) < 1.1 * whole as f64,
            "nnz(L) {split} split, {whole} whole"
        );
    }

    /// The split order, its halves on two threads, is the same on every run while other
    /// threads order at once (each METIS call draws from its own thread's seeded state).
    #[test]
    fn the_split_order_is_the_same_beside_other_orderings() {
        let g = grid(130);
        let want = node_nested_dissection(&g).unwrap();
        std::thread::scope(|scope| {
            let runs: Vec<_> = (0..3)
                .map(|_| {
                    scope.spawn(|| {
                        (0..3)
                            .map(|_| node_nested_dissection(&g))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            for run in runs {
                for order in run.join().unwrap() {
                    assert_eq!(order.unwrap(), want);
                }
            }
        });
    }
}
