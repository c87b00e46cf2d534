//! The one value fill of contact blocks, Bᵀ S B + ρ RᵀR (see [`ContactBlock`]): the cell
//! problems' closed contacts, the stick/slip system in any states and its changes since the
//! reference factorization. Node-owned: the task of a generalized node adds, for every contact
//! the node belongs to, the contact's six columns of that node. A task writes only its own
//! node's columns of K_ff and its own rows of K_fE, so no coloring is needed, the writes sweep
//! the value array column by column instead of jumping between the column blocks of a contact,
//! and every entry's sum runs in contact order whatever the number of threads. The six columns
//! are computed as one small product, Bᵀ (S B_a) + Rᵀ (ρ R_a), whose rows the compiler
//! vectorizes.

use crate::assembly::{prefetch, BlockSlots, Pattern, SharedMut, NO_SLOT};
use crate::constraints::Discretization;
use crate::contact::{ContactBlock, ContactPair};
use nalgebra::SMatrix;
use rayon::prelude::*;

/// Most generalized nodes of a contact block (four nodes of two elements and the driver).
const MAX_NODES: usize = 5;

/// Contact `contact` seen from one of its nodes, at `position` in its block.
#[derive(Clone, Debug)]
struct Incidence {
    contact: u32,
    position: u8,
    /// `runs[d][b]`: the slot of the first of the six rows of block node b in the node's column
    /// d, when the six are adjacent slots; otherwise [`NO_SLOT`] and the rows go entry by entry
    /// through the slot map.
    runs: [[u32; MAX_NODES]; 6],
}

/// The contacts listed by the generalized nodes whose columns they write.
#[derive(Clone, Debug)]
pub struct ContactColumns {
    /// Incidences of node g: `incidences[node_ptr[g]..node_ptr[g + 1]]`, by contact; the
    /// driver node has none.
    node_ptr: Vec<usize>,
    incidences: Vec<Incidence>,
    /// The contacts that hold the driver, with its position in their block.
    with_driver: Vec<(usize, usize)>,
}

impl ContactColumns {
    /// The incidences of `contacts` on the `n_gnodes` generalized nodes but the `driver`;
    /// contact i's block entries are at `pattern.extra_slots(i)`.
    pub fn new(
        n_gnodes: usize,
        driver: Option<usize>,
        contacts: &[ContactPair],
        pattern: &Pattern,
    ) -> Self {
        let owner = |g: usize| Some(g) != driver;
        let mut node_ptr = vec![0usize; n_gnodes + 1];
        for pair in contacts {
            assert!(
                pair.jump.nodes.len() <= MAX_NODES,
                "a contact block of > 5 nodes"
            );
            for &g in pair.jump.nodes.iter().filter(|&&g| owner(g)) {
                node_ptr[g + 1] += 1;
            }
        }
        for g in 0..n_gnodes {
            node_ptr[g + 1] += node_ptr[g];
        }
        let mut next = node_ptr.clone();
        let mut incidences = vec![
            Incidence {
                contact: 0,
                position: 0,
                runs: [[NO_SLOT; MAX_NODES]; 6],
            };
            node_ptr[n_gnodes]
        ];
        let mut with_driver = Vec::new();
        for (i, pair) in contacts.iter().enumerate() {
            let m = pair.size();
            let slots = pattern.extra_slots(i);
            for (a, &g) in pair.jump.nodes.iter().enumerate() {
                if !owner(g) {
                    with_driver.push((i, a));
                    continue;
                }
                let mut runs = [[NO_SLOT; MAX_NODES]; 6];
                for (d, column) in runs.iter_mut().enumerate() {
                    let c = 6 * a + d;
                    for (b, run) in column.iter_mut().take(m / 6).enumerate() {
                        *run = slots.row_run(6 * b, c).unwrap_or(NO_SLOT);
                    }
                }
                incidences[next[g]] = Incidence {
                    contact: i as u32,
                    position: a as u8,
                    runs,
                };
                next[g] += 1;
            }
        }
        ContactColumns {
            node_ptr,
            incidences,
            with_driver,
        }
    }

    /// Adds the blocks of `contacts` (the ones of [`ContactColumns::new`]), contact i's
    /// `block(i)`: K_ff to `values`, K_fE to `coupling` (row by free DOF; by symmetry, from
    /// the driver's rows: symmetric blocks only), nodes in parallel; returns the K_EE part,
    /// summed in contact order.
    pub fn add(
        &self,
        contacts: &[ContactPair],
        pattern: &Pattern,
        disc: &Discretization,
        values: &mut [f64],
        coupling: Option<&mut [[f64; 6]]>,
        block: impl Fn(usize) -> ContactBlock + Sync,
    ) -> SMatrix<f64, 6, 6> {
        let values = SharedMut::new(values);
        let coupling = coupling.map(SharedMut::new);
        let n_gnodes = self.node_ptr.len() - 1;
        (0..n_gnodes)
            .into_par_iter()
            .with_min_len(256)
            .for_each(|g| {
                let (from, to) = (self.node_ptr[g], self.node_ptr[g + 1]);
                for (k, inc) in self.incidences[from..to].iter().enumerate() {
                    // The runs of the next incidence, wherever its slots lie.
                    if let Some(next) = self.incidences.get(from + k + 1) {
                        for &slot in next.runs.iter().flatten() {
                            values.prefetch(slot as usize);
                            values.prefetch(slot as usize + 5);
                        }
                        let pair = &contacts[next.contact as usize];
                        prefetch(&pair.normal);
                        for j in (0..3 * pair.size()).step_by(8) {
                            prefetch(&pair.jump.b.as_slice()[j]);
                            prefetch(&pair.jump.r.as_slice()[j]);
                        }
                    }
                    let i = inc.contact as usize;
                    let pair = &contacts[i];
                    let s = block(i);
                    let position = inc.position as usize;
                    with_node_columns(pair, &s, position, |d, column| {
                        let Some(free) = disc.reduced(6 * g + d) else {
                            return;
                        };
                        let c = 6 * position + d;
                        for (b, &first) in inc.runs[d].iter().take(column.len() / 6).enumerate() {
                            let rows = &column[6 * b..6 * b + 6];
                            if first != NO_SLOT {
                                // SAFETY: the slots of column c of this block lie in node g's
                                // columns, which only this task writes.
                                let run = unsafe { values.run::<6>(first as usize) };
                                for (v, k) in run.iter_mut().zip(rows) {
                                    *v += k;
                                }
                            } else if disc.driver() == Some(pair.jump.nodes[b]) {
                                // Driver rows of column c: by symmetry K_fE's row c.
                                if let Some(coupling) = &coupling {
                                    // SAFETY: row `free` is node g's, which only this task
                                    // writes.
                                    let row = unsafe { coupling.get(free) };
                                    for (v, k) in row.iter_mut().zip(rows) {
                                        *v += k;
                                    }
                                }
                            } else {
                                let slots = pattern.extra_slots(i);
                                for (r, k) in (6 * b..6 * b + 6).zip(rows) {
                                    let slot = slots.get(r, c);
                                    if slot != NO_SLOT {
                                        // SAFETY: as above.
                                        unsafe { *values.get(slot as usize) += k };
                                    }
                                }
                            }
                        }
                    });
                }
            });
        let mut k_ee = SMatrix::<f64, 6, 6>::zeros();
        for &(i, p) in &self.with_driver {
            let s = block(i);
            with_node_columns(&contacts[i], &s, p, |d, column| {
                for e in 0..6 {
                    k_ee[(e, d)] += column[6 * p + e];
                }
            });
        }
        k_ee
    }
}

impl ContactColumns {
    /// Adds the driver's columns of the blocks of `contacts` that hold it, contact i's
    /// `block(i)`: K_fE (rows of free DOFs) to `coupling`, and returns K_EE (no symmetry
    /// assumed).
    pub fn add_driver_columns(
        &self,
        contacts: &[ContactPair],
        disc: &Discretization,
        coupling: &mut [[f64; 6]],
        block: impl Fn(usize) -> ContactBlock,
    ) -> SMatrix<f64, 6, 6> {
        let mut k_ee = SMatrix::<f64, 6, 6>::zeros();
        for &(i, p) in &self.with_driver {
            let pair = &contacts[i];
            with_node_columns(pair, &block(i), p, |e, column| {
                for (r, k) in column.iter().enumerate() {
                    let g = pair.jump.nodes[r / 6];
                    if Some(g) == disc.driver() {
                        k_ee[(r % 6, e)] += k;
                    } else if let Some(f) = disc.reduced(6 * g + r % 6) {
                        coupling[f][e] += k;
                    }
                }
            });
        }
        k_ee
    }
}

/// Adds `block` of contact `pair` to `values` through its row-major slots `slots` (entries
/// without a slot, on prescribed DOFs, left out): one contact's share of
/// [`ContactColumns::add`], the same entries (for the few blocks that change between state
/// iterations).
pub fn add_contact_block(
    pair: &ContactPair,
    block: &ContactBlock,
    slots: BlockSlots<'_>,
    values: &mut [f64],
) {
    for a in 0..pair.jump.nodes.len() {
        with_node_columns(pair, block, a, |d, column| {
            let c = 6 * a + d;
            for (r, k) in column.iter().enumerate() {
                let slot = slots.get(r, c);
                if slot != NO_SLOT {
                    values[slot as usize] += k;
                }
            }
        });
    }
}

/// Calls `column(d, k)` with the six columns k = Bᵀ S b_c + ρ Rᵀ r_c, c = 6 `position` + d, of
/// a contact's block (S, ρ of `block`), for the block's size.
fn with_node_columns(
    pair: &ContactPair,
    block: &ContactBlock,
    position: usize,
    column: impl FnMut(usize, &[f64]),
) {
    match pair.jump.nodes.len() {
        1 => node_columns::<6>(pair, block, position, column),
        2 => node_columns::<12>(pair, block, position, column),
        3 => node_columns::<18>(pair, block, position, column),
        4 => node_columns::<24>(pair, block, position, column),
        _ => node_columns::<30>(pair, block, position, column),
    }
}

/// [`with_node_columns`] for a block of M = 6k rows, with the AVX2 kernel where the CPU has it
/// (the same operations in the same order, so the same sums).
#[inline(always)]
fn node_columns<const M: usize>(
    pair: &ContactPair,
    block: &ContactBlock,
    position: usize,
    mut column: impl FnMut(usize, &[f64]),
) {
    let (b, r) = (pair.jump.b.as_slice(), pair.jump.r.as_slice());
    let (b_a, r_a) = (&b[18 * position..], &r[18 * position..]);
    let (s, p_r) = (&block.jump, block.rotation);
    // Column d: (S b_c, p_R r_c), c = 6 position + d.
    let sr: [[f64; 6]; 6] = std::array::from_fn(|d| {
        let (bc, rc) = (&b_a[3 * d..3 * d + 3], &r_a[3 * d..3 * d + 3]);
        let sb = |i: usize| s[(i, 0)] * bc[0] + s[(i, 1)] * bc[1] + s[(i, 2)] * bc[2];
        [sb(0), sb(1), sb(2), p_r * rc[0], p_r * rc[1], p_r * rc[2]]
    });
    #[cfg(target_arch = "x86_64")]
    let block = if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        unsafe { node_block_avx2::<M>(b, r, &sr) }
    } else {
        node_block::<M>(b, r, &sr)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let block = node_block::<M>(b, r, &sr);
    for (d, out) in block.iter().enumerate() {
        column(d, out);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn node_block_avx2<const M: usize>(b: &[f64], r: &[f64], sr: &[[f64; 6]; 6]) -> [[f64; M]; 6] {
    node_block::<M>(b, r, sr)
}

/// The six columns Bᵀ (S b_c) + Rᵀ (p_R r_c) from B and R (3 × M, column-major) and
/// `sr[d]` = (S b_c, p_R r_c): Bᵀ and Rᵀ copied component by component, so each column is six
/// multiply-adds of M-vectors.
#[inline(always)]
fn node_block<const M: usize>(b: &[f64], r: &[f64], sr: &[[f64; 6]; 6]) -> [[f64; M]; 6] {
    let mut bt = [[0.0; M]; 3];
    let mut rt = [[0.0; M]; 3];
    for j in 0..M {
        for k in 0..3 {
            bt[k][j] = b[3 * j + k];
            rt[k][j] = r[3 * j + k];
        }
    }
    let mut block = [[0.0; M]; 6];
    for (out, c) in block.iter_mut().zip(sr) {
        for (j, o) in out.iter_mut().enumerate() {
            *o = (bt[0][j] * c[0] + bt[1][j] * c[1] + bt[2][j] * c[2])
                + (rt[0][j] * c[3] + rt[1][j] * c[4] + rt[2][j] * c[5]);
        }
    }
    block
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::generate::{nonwoven, FiberAmount, LengthDistribution, NonWoven};
    use crate::homogenize::{ContactStiffness, PeriodicSystem, PeriodicValues};
    use crate::model::Model;

    /// Every third contact sliding, the others stuck.
    fn which(i: usize) -> ContactStiffness {
        if i.is_multiple_of(3) {
            ContactStiffness::Sliding
        } else {
            ContactStiffness::Stick
        }
    }

    /// A periodic non-woven cell of 60 fibers, with contacts across its boundary (also the
    /// stick/slip matrix values' test cell).
    pub(crate) fn system() -> PeriodicSystem {
        let description = nonwoven(&NonWoven {
            size: [3e-3, 3e-3],
            amount: FiberAmount::Count { fibers: 60 },
            length: LengthDistribution::Fixed { length: 1.2e-3 },
            element_length: 2.5e-4,
            seed: 7,
            ..NonWoven::default()
        })
        .unwrap()
        .description;
        PeriodicSystem::new(&Model::from_description(&description).unwrap()).unwrap()
    }

    /// The contacts entry by entry from `closed_stiffness`, serially: K_ff through the slot
    /// map, K_fE from the rows of free DOFs in the driver's columns, K_EE from its block.
    fn reference(sys: &PeriodicSystem) -> PeriodicValues {
        let mut out = sys.zero_values();
        let disc = &sys.discretization;
        for (i, pair) in sys.contacts.iter().enumerate() {
            let k = pair.closed_stiffness(which(i) == ContactStiffness::Stick);
            let (m, slots) = (pair.size(), sys.pattern.extra_slots(i));
            let node = |r: usize| pair.jump.nodes[r / 6];
            let is_driver = |r: usize| disc.driver() == Some(node(r));
            for r in 0..m {
                for c in 0..m {
                    match (is_driver(r), is_driver(c)) {
                        (true, true) => out.couplings.k_ee[(r % 6, c % 6)] += k(r, c),
                        (false, true) => {
                            if let Some(f) = disc.reduced(6 * node(r) + r % 6) {
                                out.couplings.coupling[f][c % 6] += k(r, c);
                            }
                        }
                        (_, false) => {
                            if slots.get(r, c) != NO_SLOT {
                                out.values[slots.get(r, c) as usize] += k(r, c);
                            }
                        }
                    }
                }
            }
        }
        out
    }

    fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(f)
    }

    #[test]
    fn node_owned_fill_matches_the_entrywise_blocks_on_any_number_of_threads() {
        let sys = system();
        let columns = &sys.contact_columns;
        // The paths the test covers: contacts with the driver (K_fE, K_EE) and rows that are
        // not six adjacent slots (the anchor's fixed translations, the driver's rows).
        let with_driver = columns.with_driver.len();
        let split_rows = columns
            .incidences
            .iter()
            .filter(|inc| {
                let pair = &sys.contacts[inc.contact as usize];
                inc.runs.iter().any(|runs| {
                    (0..pair.jump.nodes.len()).any(|b| {
                        runs[b] == NO_SLOT
                            && sys.discretization.driver() != Some(pair.jump.nodes[b])
                    })
                })
            })
            .count();
        assert!(with_driver > 0, "no contact holds the driver");
        assert!(split_rows > 0, "every row block is a run");

        let expected = reference(&sys);
        let fill = || {
            let mut out = sys.zero_values();
            sys.add_contacts(&mut out, which);
            out
        };
        let one = in_pool(1, fill);
        let scale = expected.values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * scale;
        for (k, (a, b)) in one.values.iter().zip(&expected.values).enumerate() {
            assert!(close(*a, *b), "K_ff slot {k}: {a} against {b}");
        }
        for (f, (a, b)) in one
            .couplings
            .coupling
            .iter()
            .zip(&expected.couplings.coupling)
            .enumerate()
        {
            for e in 0..6 {
                assert!(
                    close(a[e], b[e]),
                    "K_fE row {f}, driver {e}: {} against {}",
                    a[e],
                    b[e]
                );
            }
        }
        assert!(expected
            .couplings
            .coupling
            .iter()
            .flatten()
            .any(|v| *v != 0.0));
        assert!((one.couplings.k_ee - expected.couplings.k_ee).abs().max() <= 1e-12 * scale);
        assert!(expected.couplings.k_ee.abs().max() > 0.0);
        // Sums in a fixed order: bit for bit the same on three threads.
        let three = in_pool(3, fill);
        assert_eq!(one.values, three.values);
        assert_eq!(one.couplings.coupling, three.couplings.coupling);
        assert_eq!(one.couplings.k_ee, three.couplings.k_ee);
    }
}
