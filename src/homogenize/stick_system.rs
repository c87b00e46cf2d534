//! The linear system with every closed contact in stick on one discretization: the blocks of
//! the elements (Tᵀ K T) and of the closed contacts (K_N + K_T^st + K_R) on the free DOFs, with
//! a periodic cell's couplings to its drivers. One assembler for the cell problems, the
//! property checks and the free model's rigid modes.

use crate::assembly::{
    color_blocks, BlockSlots, ContactColumns, ElementBlocks, Pattern, SharedMut, NO_SLOT,
};
use crate::cell::MacroStrain;
use crate::constraints::Discretization;
use crate::contact::{ContactOrigin, ContactPair, ContactSet};
use crate::model::{Dof, Model};
use crate::solve::DriverCouplings;
use crate::Error;
use fibercell_solver::{CscMatrix, SolverError};
use nalgebra::SMatrix;
use rayon::prelude::*;

/// The assembled values of a [`StickSystem`]: K_ff, and for a periodic cell its couplings to
/// the drivers (zero without a driver).
#[derive(Clone, Debug)]
pub struct PeriodicValues {
    /// Values of K_ff on the pattern.
    pub values: Vec<f64>,
    /// K_fE and K_EE.
    pub couplings: DriverCouplings,
}

type Matrix6 = SMatrix<f64, 6, 6>;

/// Where the blocks of one color write: K_ff through the pattern, K_fE by free DOF; blocks of
/// a color share no generalized node but the driver, so their writes are disjoint.
struct Sink<'a> {
    disc: &'a Discretization,
    driver: usize,
    values: SharedMut<'a, f64>,
    coupling: SharedMut<'a, [f64; 6]>,
}

impl Sink<'_> {
    /// Adds the m × m block `k(row, column)` on generalized nodes `gnodes` (m = 6 per node)
    /// through its row-major pattern `slots`; returns its driver–driver part, if any.
    fn add(
        &self,
        gnodes: &[usize],
        k: impl Fn(usize, usize) -> f64,
        slots: BlockSlots<'_>,
    ) -> Option<Matrix6> {
        let m = 6 * gnodes.len();
        if !gnodes.contains(&self.driver) {
            // No driver node (all blocks but a few): every entry goes to its slot, a node's six
            // rows of a column as one run when they are adjacent slots (`Pattern::row_run`).
            for c in 0..m {
                for r0 in (0..m).step_by(6) {
                    if let Some(first) = slots.row_run(r0, c) {
                        // SAFETY: as below, the slots couple two nodes of this block only.
                        let run = unsafe { self.values.run::<6>(first as usize) };
                        for (d, v) in run.iter_mut().enumerate() {
                            *v += k(r0 + d, c);
                        }
                        continue;
                    }
                    for r in r0..r0 + 6 {
                        let s = slots.get(r, c);
                        if s != NO_SLOT {
                            // SAFETY: as below, the slot couples two nodes of this block only.
                            unsafe { *self.values.get(s as usize) += k(r, c) };
                        }
                    }
                }
            }
            return None;
        }
        let mut k_ee: Option<Matrix6> = None;
        let driver = |r: usize| gnodes[r / 6] == self.driver;
        let mut put = |r: usize, c: usize, v: f64| match (driver(r), driver(c)) {
            (true, true) => k_ee.get_or_insert_with(Matrix6::zeros)[(r % 6, c % 6)] += v,
            (false, true) => {
                if let Some(i) = self.disc.reduced(6 * gnodes[r / 6] + r % 6) {
                    // SAFETY: row r's node is not the driver and belongs to this block only
                    // within its color (see `PeriodicSystem::element_colors`).
                    unsafe { self.coupling.get(i)[c % 6] += v };
                }
            }
            (_, false) => {
                let s = slots.get(r, c);
                if s != NO_SLOT {
                    // SAFETY: the slot couples two non-driver nodes of this block, which no
                    // other block of its color holds.
                    unsafe { *self.values.get(s as usize) += v };
                }
            }
        };
        // Column by column: a column's entries of one node are adjacent in K.
        for c in 0..m {
            for r in 0..m {
                put(r, c, k(r, c));
            }
        }
        k_ee
    }
}

/// The tangential state a closed contact enters the cell matrix with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactStiffness {
    /// K_N + K_T^st + K_R (the elastic moduli A^elas).
    Stick,
    /// K_N + K_R: no tangential stiffness (a contact sliding under a Tresca bound).
    Sliding,
}

/// Numbering, pattern and block maps of the system with every closed contact in stick: the
/// elements and the closed contacts (gap ≤ 0) on the free DOFs of a discretization — a
/// periodic cell's ([`super::PeriodicSystem`] holds one), or a supported or free model's
/// ([`StickSystem::supported`]).
#[derive(Clone, Debug)]
pub struct StickSystem {
    /// Unknowns and constraint maps (a cell's drivers prescribed to zero).
    pub discretization: Discretization,
    /// Sparsity pattern of K_ff: elements, then closed contacts.
    pub pattern: Pattern,
    /// Every element's block on the generalized nodes.
    elements: ElementBlocks,
    pub(crate) contacts: Vec<ContactPair>,
    /// Where each closed contact came from (its sides and fibers), in the order of `contacts`.
    pub contact_origins: Vec<ContactOrigin>,
    /// The index of each closed contact in the model's contact set (how `fibercell contacts`
    /// and the curve's switches number them), in the order of `contacts`.
    pub contact_indices: Vec<usize>,
    /// Elements by color: no two of a color share a generalized node other than the driver.
    element_colors: Vec<Vec<usize>>,
    /// Closed contacts by the nodes whose columns they fill.
    pub(crate) contact_columns: ContactColumns,
}

/// Seconds [`StickSystem::build`] spent on the blocks and on the pattern.
pub(crate) struct BuildTimings {
    pub blocks: f64,
    pub pattern: f64,
}

impl StickSystem {
    /// The system of a model with supports (or none: a free model, whose matrix is singular
    /// with the rigid modes of each connected piece as its null space): its contacts searched
    /// without periodic images, the closed ones in stick.
    pub fn supported(model: &Model) -> Result<Self, Error> {
        let set = ContactSet::build(model)?;
        Ok(Self::build(model, Discretization::supported(model), &set)?.0)
    }

    /// Numbers the blocks of the elements and of the closed contacts of `set` on
    /// `discretization` and builds the pattern.
    pub(crate) fn build(
        model: &Model,
        discretization: Discretization,
        set: &ContactSet,
    ) -> Result<(Self, BuildTimings), Error> {
        let clock = std::time::Instant::now();
        let closed: Vec<usize> = (0..set.pairs.len())
            .filter(|&i| set.pairs[i].gap <= 0.0)
            .collect();
        let elements = ElementBlocks::new(model, &discretization);
        let contacts: Vec<ContactPair> = closed
            .par_iter()
            .map(|&i| discretization.contact_pair(&set.pairs[i]))
            .collect();
        let contact_origins = closed.iter().map(|&i| set.origins[i].clone()).collect();
        let n_elements = model.elements().len();
        let blocks: Vec<&[usize]> = (0..n_elements)
            .map(|e| elements.gnodes_of(model, e))
            .chain(contacts.iter().map(|c| &c.jump.nodes[..]))
            .collect();
        let (driver, n_gnodes) = (discretization.driver(), discretization.n_gnodes());
        let element_colors = color_blocks(n_gnodes, blocks[..n_elements].iter().copied(), driver);
        let blocks_seconds = clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        let pattern = Pattern::from_blocks(
            discretization.reduced_indices(),
            discretization.n_free(),
            &blocks,
            n_elements,
        )?;
        let contact_columns = ContactColumns::new(n_gnodes, driver, &contacts, &pattern);
        let timings = BuildTimings {
            blocks: blocks_seconds,
            pattern: clock.elapsed().as_secs_f64(),
        };
        let system = StickSystem {
            discretization,
            pattern,
            elements,
            contacts,
            contact_origins,
            contact_indices: closed,
            element_colors,
            contact_columns,
        };
        Ok((system, timings))
    }

    /// Number of unknowns.
    pub fn n_free(&self) -> usize {
        self.discretization.n_free()
    }

    /// (node, DOF) of a free unknown.
    pub fn node_dof(&self, k: usize) -> (usize, Dof) {
        self.discretization.node_dof(k)
    }

    /// A solver error with its column mapped to node, DOF and fibers of `model` where it
    /// names one.
    pub(crate) fn locate(&self, model: &Model, e: SolverError) -> Error {
        self.discretization.locate(model, e)
    }

    /// Number of closed contacts included as stick springs.
    pub fn n_contacts(&self) -> usize {
        self.contacts.len()
    }

    /// The columns w₁, w₂ with K_T^st = p_T Bᵀ(t₁t₁ᵀ + t₂t₂ᵀ)B = w₁w₁ᵀ + w₂w₂ᵀ (4.58) of
    /// closed contact `i` on the free DOFs, as (row of K_ff, value) sorted by row: switching
    /// the contact from stick to sliding is the rank-2 downdate K_ff − w₁w₁ᵀ − w₂w₂ᵀ.
    pub fn stick_spring_columns(&self, i: usize) -> [Vec<(usize, f64)>; 2] {
        let pair = &self.contacts[i];
        let root = pair.penalty_tangent.sqrt();
        pair.tangents.map(|t| {
            let mut column: Vec<(usize, f64)> = (0..pair.size())
                .filter_map(|r| {
                    let g = 6 * pair.jump.nodes[r / 6] + r % 6;
                    let row = self.discretization.reduced(g)?;
                    Some((row, root * pair.jump.b.column(r).dot(&t)))
                })
                .collect();
            column.sort_unstable_by_key(|e| e.0);
            column.dedup_by(|next, kept| {
                let same = next.0 == kept.0;
                if same {
                    kept.1 += next.1;
                }
                same
            });
            column
        })
    }

    /// The n × 2k matrix W of the stick springs of the closed contacts `switched` (columns 2j,
    /// 2j + 1 from [`StickSystem::stick_spring_columns`] of the j-th): K_ff with them stuck
    /// minus K_ff with them sliding is W Wᵀ, the argument of a factor downdate
    /// (`LinearSolver::update_factor`).
    pub fn stick_spring_matrix(&self, switched: &[usize]) -> Result<CscMatrix, Error> {
        let mut triplets = Vec::new();
        for (k, &i) in switched.iter().enumerate() {
            for (j, column) in self.stick_spring_columns(i).into_iter().enumerate() {
                triplets.extend(column.into_iter().map(|(r, v)| (r, 2 * k + j, v)));
            }
        }
        Ok(CscMatrix::from_triplets(
            self.n_free(),
            2 * switched.len(),
            &triplets,
        )?)
    }

    /// Assembles K_ff, K_fE and K_EE (elements and closed contacts in stick).
    pub fn assemble(&self, model: &Model) -> PeriodicValues {
        let mut out = self.zero_values();
        self.add_elements(model, &mut out);
        self.add_contacts(&mut out, |_| ContactStiffness::Stick);
        out
    }

    /// All values zero.
    pub fn zero_values(&self) -> PeriodicValues {
        PeriodicValues {
            values: self.pattern.zero_values(),
            couplings: DriverCouplings {
                coupling: vec![[0.0; 6]; self.discretization.n_free()],
                k_ee: SMatrix::zeros(),
            },
        }
    }

    /// Adds Tᵀ K T of every element: the colors one after another, the elements of a color in
    /// parallel, each writing its own entries (the sums do not depend on the number of threads).
    pub fn add_elements(&self, model: &Model, out: &mut PeriodicValues) {
        self.add_colored(out, &self.element_colors, |e, sink| {
            let slots = self.pattern.element_slots(e);
            self.elements
                .with_block(model, e, |gnodes, k| sink.add(gnodes, k, slots))
        });
    }

    /// Adds the closed contacts, contact i with the stiffness `which(i)`: node by node in
    /// parallel, each node's task filling its own columns (see `ContactColumns`), so the sums do
    /// not depend on the number of threads.
    pub fn add_contacts(
        &self,
        out: &mut PeriodicValues,
        which: impl Fn(usize) -> ContactStiffness + Sync,
    ) {
        out.couplings.k_ee += self.contact_columns.add(
            &self.contacts,
            &self.pattern,
            &self.discretization,
            &mut out.values,
            Some(&mut out.couplings.coupling),
            |i| self.contacts[i].closed_block(which(i) == ContactStiffness::Stick),
        );
    }

    /// Runs `block(i, sink)` for the blocks of each color in parallel, colors in order; the
    /// driver–driver parts they return are summed in block order.
    fn add_colored(
        &self,
        out: &mut PeriodicValues,
        colors: &[Vec<usize>],
        block: impl Fn(usize, &Sink<'_>) -> Option<Matrix6> + Sync,
    ) {
        let sink = Sink {
            disc: &self.discretization,
            driver: self.discretization.driver().unwrap_or(usize::MAX),
            values: SharedMut::new(&mut out.values),
            coupling: SharedMut::new(&mut out.couplings.coupling),
        };
        for color in colors {
            let driver_blocks: Vec<Option<Matrix6>> = color
                .par_iter()
                .with_min_len(32)
                .map(|&i| block(i, &sink))
                .collect();
            for m in driver_blocks.into_iter().flatten() {
                out.couplings.k_ee += m;
            }
        }
    }

    /// Nodal displacements and rotations of every node for the unknowns `x` and the drivers `e`.
    pub fn expand(&self, x: &[f64], e: &MacroStrain) -> Vec<[f64; 6]> {
        let disc = &self.discretization;
        let mut q = disc.generalized(x, 0.0);
        if let Some(d) = disc.driver() {
            q[6 * d..6 * d + 6].copy_from_slice(e);
        }
        disc.physical(&q)
    }
}
