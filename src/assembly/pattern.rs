//! The sparsity pattern of the reduced stiffness (both triangles) and the slot map that sends
//! every entry of every block matrix — the 12×12 frame elements, then any extra node blocks such
//! as the 24×24 contact blocks coupling four nodes (thesis 4.69–4.70) — to its place in the value
//! array. Built once per set of blocks, so value fills never search or sort.

pub use crate::error::PatternTooLargeError;
use crate::model::Model;
use fibercell_solver::{CscRef, SolverError};
use rayon::prelude::*;

/// Slot of a block-matrix entry that touches a prescribed DOF.
pub const NO_SLOT: u32 = u32::MAX;

/// CSC pattern of the reduced system plus, per block, the value slot of each entry of its dense
/// (6k × 6k, row-major) matrix, k = number of nodes of the block, as a [`BlockSlots`].
#[derive(Clone, Debug)]
pub struct Pattern {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    n_elements: usize,
    block_offsets: Vec<usize>,
    slots: Vec<u32>,
    /// Whether the CSC pattern passed [`CscRef::check_pattern`] (then [`Pattern::matrix`]
    /// checks only sizes).
    checked: bool,
}

impl Pattern {
    /// The pattern of the frame elements of `model` over the numbering `reduced` of `n_free`
    /// unknowns (`Discretization::reduced_indices`, `Discretization::n_free`).
    pub fn new(
        model: &Model,
        reduced: &[usize],
        n_free: usize,
    ) -> Result<Self, PatternTooLargeError> {
        let elements: Vec<[usize; 2]> = model.elements().iter().map(|e| e.nodes).collect();
        let blocks: Vec<&[usize]> = elements.iter().map(|e| &e[..]).collect();
        Self::from_blocks(reduced, n_free, &blocks, elements.len())
    }

    /// The pattern of arbitrary node blocks over a numbering `reduced` (6 entries per node: the
    /// reduced index of each DOF, `usize::MAX` when it is not an unknown). The first
    /// `n_elements` blocks are reachable through [`Pattern::element_slots`], the rest through
    /// [`Pattern::extra_slots`].
    pub fn from_blocks(
        reduced: &[usize],
        n_free: usize,
        blocks: &[&[usize]],
        n_elements: usize,
    ) -> Result<Self, PatternTooLargeError> {
        let n_nodes = reduced.len() / 6;
        let red = reduced;
        let n = n_free;
        let adjacency = NodeAdjacency::of(n_nodes, blocks);
        let free = |node: usize| {
            red[6 * node..6 * node + 6]
                .iter()
                .filter(|&&r| r != usize::MAX)
        };
        // Every free DOF of a node has the same rows: its neighbours' free DOFs, ascending.
        let rows_of_node: Vec<usize> = (0..n_nodes)
            .into_par_iter()
            .map(|node| {
                adjacency
                    .of_node(node)
                    .iter()
                    .map(|&nb| free(nb).count())
                    .sum()
            })
            .collect();
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        for (node, &rows) in rows_of_node.iter().enumerate() {
            for _ in free(node) {
                col_ptr.push(col_ptr[col_ptr.len() - 1] + rows);
            }
        }
        let nnz = col_ptr[col_ptr.len() - 1];
        if nnz >= NO_SLOT as usize {
            return Err(PatternTooLargeError(nnz));
        }
        // Zeros the allocator maps lazily, mapped here in one request per 256 KiB before the
        // tasks write them (L: 210 MB, 51,000 pages that faulted one by one).
        let mut row_idx = vec![0usize; nnz];
        fibercell_solver::populate_par(&mut row_idx);
        let node_entries = (0..n_nodes).map(|node| free(node).count() * rows_of_node[node]);
        split_by_lengths(&mut row_idx, node_entries)
            .into_par_iter()
            .enumerate()
            .for_each(|(node, out)| {
                let adj = adjacency.of_node(node);
                let mut k = 0;
                while k < out.len() {
                    for &nb in adj {
                        for &r in free(nb) {
                            out[k] = r;
                            k += 1;
                        }
                    }
                }
            });
        drop(adjacency);
        let reduced_of = |g: usize| (red[g] != usize::MAX).then_some(red[g]);
        let mut block_offsets = Vec::with_capacity(blocks.len() + 1);
        block_offsets.push(0);
        for b in blocks {
            block_offsets
                .push(block_offsets[block_offsets.len() - 1] + BlockSlots::stored(b.len()));
        }
        // Zeroed pages from the allocator, each block's slots set to NO_SLOT by its task (a
        // sequential fill of L's 40 MB took 10–15 ms).
        let mut slots = vec![0; block_offsets[blocks.len()]];
        fibercell_solver::populate_par(&mut slots);
        let block_lengths = blocks.iter().map(|b| BlockSlots::stored(b.len()));
        split_by_lengths(&mut slots, block_lengths)
            .into_par_iter()
            .zip(blocks)
            .for_each(|(slots, b)| {
                slots.fill(NO_SLOT);
                block_slots_of(b, &reduced_of, &col_ptr, &row_idx, slots);
            });
        let checked = CscRef::check_pattern(n, n, &col_ptr, &row_idx).is_ok();
        Ok(Pattern {
            checked,
            n,
            col_ptr,
            row_idx,
            n_elements,
            block_offsets,
            slots,
        })
    }

    /// Order of the reduced system.
    pub fn n(&self) -> usize {
        self.n
    }
    /// `values` must hold one value per slot of this pattern.
    pub fn check_values(&self, values: &[f64]) -> Result<(), fibercell_solver::SolverError> {
        if values.len() == self.nnz() {
            return Ok(());
        }
        Err(fibercell_solver::SolverError::DimensionMismatch(format!(
            "{} values for a pattern of {} entries",
            values.len(),
            self.nnz()
        )))
    }

    /// Bytes it holds: the CSC structure and the element blocks' slot maps.
    pub fn memory_bytes(&self) -> usize {
        let usizes =
            self.col_ptr.capacity() + self.row_idx.capacity() + self.block_offsets.capacity();
        usizes * size_of::<usize>() + self.slots.capacity() * size_of::<u32>()
    }

    /// Stored entries (both triangles).
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// A zero for every stored entry, written on all threads so that the writes map the pages,
    /// one fault each ([`fibercell_solver::extend_with_zeros_par`]). Zeros from the allocator
    /// alone are mapped by a fill's first `+=`: its read maps the shared zero page and its
    /// write replaces it, two faults and a TLB shootdown on every core per page (measured:
    /// 10 % of `homogenize` on the L cell).
    pub fn zero_values(&self) -> Vec<f64> {
        let mut values = Vec::new();
        fibercell_solver::extend_with_zeros_par(&mut values, self.nnz());
        values
    }
    /// Column pointers.
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }
    /// Row indices.
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }
    /// Number of blocks (elements first, then the extra blocks).
    pub fn n_blocks(&self) -> usize {
        self.block_offsets.len() - 1
    }
    /// Slot map of element `e` (12×12).
    pub fn element_slots(&self, e: usize) -> BlockSlots<'_> {
        self.block_slots(e)
    }
    /// Slot map of extra block `b` (6k × 6k).
    pub fn extra_slots(&self, b: usize) -> BlockSlots<'_> {
        self.block_slots(self.n_elements + b)
    }
    fn block_slots(&self, b: usize) -> BlockSlots<'_> {
        BlockSlots::of(&self.slots[self.block_offsets[b]..self.block_offsets[b + 1]])
    }
    /// A matrix view with these values.
    pub fn matrix<'a>(&'a self, values: &'a [f64]) -> Result<CscRef<'a>, SolverError> {
        if self.checked {
            // SAFETY: the pattern passed `check_pattern` at construction and never changes.
            unsafe { CscRef::new_unchecked(self.n, self.n, &self.col_ptr, &self.row_idx, values) }
        } else {
            CscRef::new(self.n, self.n, &self.col_ptr, &self.row_idx, values)
        }
    }
}

/// The slot map of the block on nodes `b` ([`BlockSlots`]'s layout; `slots` holds NO_SLOT on
/// entry) in the pattern (`col_ptr`, `row_idx`). The free DOFs of a node all have the same
/// rows, and a neighbour's free rows lie together in them in DOF order: so one search per
/// pair of nodes places all their entries.
fn block_slots_of(
    b: &[usize],
    reduced_of: &impl Fn(usize) -> Option<usize>,
    col_ptr: &[usize],
    row_idx: &[usize],
    slots: &mut [u32],
) {
    let m = 6 * b.len();
    let (starts, offsets) = slots.split_at_mut(m);
    for (pc, &a) in b.iter().enumerate() {
        let mut columns = (0..6).filter_map(|d| reduced_of(6 * a + d).map(|j| (d, j)));
        let Some((_, j0)) = columns.next() else {
            continue;
        };
        for (d, j) in (0..6).filter_map(|d| reduced_of(6 * a + d).map(|j| (d, j))) {
            starts[6 * pc + d] = col_ptr[j] as u32;
        }
        let rows = &row_idx[col_ptr[j0]..col_ptr[j0 + 1]];
        let offsets = &mut offsets[pc * m..(pc + 1) * m];
        for (pr, &nb) in b.iter().enumerate() {
            let Some(first) = (0..6).find_map(|d| reduced_of(6 * nb + d)) else {
                continue;
            };
            let Ok(k0) = rows.binary_search(&first) else {
                continue;
            };
            let free_rows = (0..6).filter(|&d| reduced_of(6 * nb + d).is_some());
            for (k, dr) in free_rows.enumerate() {
                offsets[6 * pr + dr] = (k0 + k) as u32;
            }
        }
    }
}

/// Where the entries of a block's dense 6k × 6k matrix (k nodes) go in the value array: entry
/// (r, c) at `start[c] + offset[c / 6][r]`, NO_SLOT where its row or column is not an unknown.
/// The columns of a node share their rows, so one offset per (column node, row) serves its six
/// columns: 6k + 6k² numbers per block instead of 36k² (on the L cell 4× less, ≈ 40 MB).
#[derive(Clone, Copy, Debug)]
pub struct BlockSlots<'a> {
    m: usize,
    /// Per column: the first value slot of its column of the matrix, or NO_SLOT.
    starts: &'a [u32],
    /// Per column node and row: the row's position in that node's columns, or NO_SLOT.
    offsets: &'a [u32],
}

impl<'a> BlockSlots<'a> {
    /// Numbers stored for a block of `k` nodes.
    fn stored(k: usize) -> usize {
        6 * k * (k + 1)
    }

    /// The map stored in `stored` (length [`BlockSlots::stored`]).
    fn of(stored: &'a [u32]) -> Self {
        let k = (0..=stored.len())
            .find(|&k| Self::stored(k) >= stored.len())
            .unwrap_or(0);
        let m = 6 * k;
        let (starts, offsets) = stored.split_at(m);
        BlockSlots { m, starts, offsets }
    }

    /// The block's order 6k.
    pub fn size(&self) -> usize {
        self.m
    }

    /// Entries of the block, m².
    pub fn len(&self) -> usize {
        self.m * self.m
    }

    /// Whether the block is empty.
    pub fn is_empty(&self) -> bool {
        self.m == 0
    }

    /// The slot of entry (r, c), NO_SLOT when it touches a prescribed DOF.
    #[inline]
    pub fn get(&self, r: usize, c: usize) -> u32 {
        let start = self.starts[c];
        let offset = self.offsets[(c / 6) * self.m + r];
        if start == NO_SLOT || offset == NO_SLOT {
            NO_SLOT
        } else {
            start + offset
        }
    }

    /// The slots row by row.
    pub fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.m).flat_map(move |r| (0..self.m).map(move |c| self.get(r, c)))
    }

    /// The slot of the first of rows `r0..r0 + 6` (one node's six DOFs) in column `c`, when
    /// the six are adjacent slots — all six DOFs free: rows are sorted, so the last is then
    /// exactly the first + 5 — otherwise `None`.
    #[inline]
    pub fn row_run(&self, r0: usize, c: usize) -> Option<u32> {
        let first = self.get(r0, c);
        (first != NO_SLOT && self.get(r0 + 5, c) == first + 5).then_some(first)
    }
}

/// Each node's neighbours through the blocks (itself included), ascending and unique: node
/// p's are `list[start[p]..start[p] + len[p]]`. One array filled in one pass, then sorted per
/// node on all threads (a vector per node, grown block by block, took 40 ms on L's 155,781
/// nodes and 10 ms more to free).
struct NodeAdjacency {
    start: Vec<usize>,
    len: Vec<usize>,
    list: Vec<usize>,
}

impl NodeAdjacency {
    fn of(n_nodes: usize, blocks: &[&[usize]]) -> Self {
        // Room per node: itself and every block it is in, whole.
        let mut room = vec![1usize; n_nodes];
        for b in blocks {
            for &p in b.iter() {
                room[p] += b.len();
            }
        }
        let mut start = Vec::with_capacity(n_nodes + 1);
        start.push(0);
        for r in &room {
            start.push(start[start.len() - 1] + r);
        }
        let mut list = vec![0usize; start[n_nodes]];
        let mut next = start[..n_nodes].to_vec();
        for (p, at) in next.iter_mut().enumerate() {
            list[*at] = p;
            *at += 1;
        }
        for b in blocks {
            for &p in b.iter() {
                list[next[p]..next[p] + b.len()].copy_from_slice(b);
                next[p] += b.len();
            }
        }
        let len = split_by_lengths(&mut list, room.into_iter())
            .into_par_iter()
            .map(|nodes| {
                nodes.sort_unstable();
                let mut unique = usize::from(!nodes.is_empty());
                for k in 1..nodes.len() {
                    if nodes[k] != nodes[unique - 1] {
                        nodes[unique] = nodes[k];
                        unique += 1;
                    }
                }
                unique
            })
            .collect();
        NodeAdjacency { start, len, list }
    }

    /// Node p's neighbours.
    fn of_node(&self, p: usize) -> &[usize] {
        &self.list[self.start[p]..self.start[p] + self.len[p]]
    }
}

/// `v` cut into consecutive pieces of the given lengths (which must add up to at most its
/// length), for filling them on several threads.
fn split_by_lengths<T>(mut v: &mut [T], lengths: impl Iterator<Item = usize>) -> Vec<&mut [T]> {
    let mut pieces = Vec::new();
    for len in lengths {
        let (piece, rest) = std::mem::take(&mut v).split_at_mut(len);
        pieces.push(piece);
        v = rest;
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each node's list holds itself and every node it shares a block with, ascending, once:
    /// blocks that repeat, overlap and leave a node out.
    #[test]
    fn the_node_adjacency_is_each_nodes_sorted_unique_neighbours() {
        let blocks: [&[usize]; 4] = [&[3, 1], &[1, 3], &[0, 4, 1], &[4, 0]];
        let adjacency = NodeAdjacency::of(6, &blocks);
        let want: [&[usize]; 6] = [&[0, 1, 4], &[0, 1, 3, 4], &[2], &[1, 3], &[0, 1, 4], &[5]];
        for (p, want) in want.iter().enumerate() {
            assert_eq!(adjacency.of_node(p), *want, "node {p}");
        }
    }

    /// Every block entry's slot is where its row sits in its column (found here by a linear
    /// scan), NO_SLOT where the row or the column is not an unknown: on node blocks of one,
    /// two and four nodes, one with a node twice, over nodes with some, all or none of their
    /// DOFs eliminated.
    #[test]
    fn block_slots_are_the_entries_positions() {
        let nodes = 7;
        let mut reduced = vec![usize::MAX; 6 * nodes];
        let mut next = 0;
        for (g, r) in reduced.iter_mut().enumerate() {
            let (node, d) = (g / 6, g % 6);
            // node 2 has no unknowns, node 4 only rotations, node 6 every other DOF.
            let free = match node {
                2 => false,
                4 => d >= 3,
                6 => d % 2 == 0,
                _ => true,
            };
            if free {
                *r = next;
                next += 1;
            }
        }
        let blocks: Vec<Vec<usize>> = vec![
            vec![0, 1],
            vec![1, 2],
            vec![2, 3],
            vec![3, 4],
            vec![4, 5, 6, 0],
            vec![5, 5],
            vec![6],
        ];
        let refs: Vec<&[usize]> = blocks.iter().map(|b| &b[..]).collect();
        let p = Pattern::from_blocks(&reduced, next, &refs, 4).unwrap();
        let mut checked = 0;
        for (i, b) in blocks.iter().enumerate() {
            let slots = if i < 4 {
                p.element_slots(i)
            } else {
                p.extra_slots(i - 4)
            };
            let m = 6 * b.len();
            assert_eq!(slots.len(), m * m);
            for r in 0..m {
                for c in 0..m {
                    let (gr, gc) = (6 * b[r / 6] + r % 6, 6 * b[c / 6] + c % 6);
                    let want = match (reduced[gr], reduced[gc]) {
                        (usize::MAX, _) | (_, usize::MAX) => NO_SLOT,
                        (ir, jc) => {
                            let k = (p.col_ptr[jc]..p.col_ptr[jc + 1])
                                .find(|&k| p.row_idx[k] == ir)
                                .expect("a block's entries are in the pattern");
                            checked += 1;
                            k as u32
                        }
                    };
                    assert_eq!(slots.get(r, c), want, "block {i}, entry ({r}, {c})");
                }
            }
        }
        assert!(checked > 500, "{checked} entries with a slot");
    }
}
