//! Assembly of one state iteration's system K + K_N + K_T, α F + F_N + F_T for the current
//! contact states: once a symmetric factorization is the reference, as its matrix plus the
//! blocks of the contacts changed since (G ΔD Gᵀ, a low-rank change); before that, element and
//! contact blocks anew.

use super::contact_states::ContactStates;
use super::increment::Increment;
use super::load_path::LoadPath;
use super::setup::Setup;
use super::StickSlip;
use crate::assembly::SharedMut;
use crate::contact::{BlockState, BlockVector, ContactBlock, ContactState};
use crate::solve::check_supported_with;
use crate::solve::kept_contact_loads::KeptContactLoads;
use crate::solve::low_rank::ContactChange;
use crate::Error;
use nalgebra::Vector2;
use rayon::prelude::*;

/// The system of one state iteration.
pub(super) struct System {
    /// The contacts whose block or load differs from the reference factorization's (None: no
    /// reference yet, `values` assembled anew).
    pub changes: Option<Vec<ContactChange>>,
    /// The matrix values do not include `changes` yet (see `MatrixValues::catch_up`).
    pub values_behind: bool,
    /// The load.
    pub rhs: Vec<f64>,
    /// A Coulomb-sliding contact with the consistent tangent makes it nonsymmetric.
    pub nonsymmetric: bool,
}

impl StickSlip<'_, '_, '_> {
    /// Assembles the system of the current contact states.
    pub(super) fn assemble(&mut self, inc: &mut Increment) -> Result<System, Error> {
        let StickSlip {
            setup,
            contacts,
            factors,
            matrix,
            kept_loads,
            path,
            ..
        } = self;
        let changes = factors
            .reference
            .as_deref()
            .map(|reference| contact_changes(setup, contacts, reference, inc));
        if changes.is_none() {
            matrix.drop_reference();
            setup.elastic_values(&mut matrix.values)?;
            assembled_values(setup, contacts, &mut matrix.values);
        }
        let mut rhs = path.rhs(inc.alpha);
        let scatter = Scatter {
            setup,
            contacts,
            path,
            alpha: inc.alpha,
        };
        if changes.is_none() {
            // The contact loads for the current states.
            scatter.by_colors(&|i| Some(contacts.states[i]), &mut rhs);
        } else {
            scatter.loads(inc, kept_loads, &mut rhs);
        }
        if setup.disc.is_identity() {
            let closed: Vec<&[usize]> = (0..setup.pairs.len())
                .filter(|&i| contacts.states[i] != ContactState::Open)
                .map(|i| &setup.set.pairs[i].jump.nodes[..])
                .collect();
            check_supported_with(&setup.model, &closed)?;
        }
        let nonsymmetric = contacts.consistent_coulomb()
            && !contacts.symmetric_step
            && contacts.states.contains(&ContactState::Slip);
        inc.lap(|t| &mut t.assemble);
        Ok(System {
            // With a reference, the values follow the changes only where the matrix is read
            // (a residual check or a factorization).
            values_behind: changes.is_some(),
            changes,
            rhs,
            nonsymmetric,
        })
    }
}

/// Adds every contact's block in its current state to the element values `values`.
pub(super) fn assembled_values(setup: &Setup<'_>, contacts: &ContactStates, values: &mut [f64]) {
    setup.contact_columns.add(
        &setup.pairs,
        &setup.pattern,
        &setup.disc,
        values,
        None,
        |i| contact_block(setup, contacts, i),
    );
}

/// Contact i's block in its current state (see [`ContactPair::block_coefficients`]).
pub(super) fn contact_block(setup: &Setup<'_>, contacts: &ContactStates, i: usize) -> ContactBlock {
    let pair = &setup.pairs[i];
    pair.block_of(&pair.block_coefficients(
        &contacts.block(i),
        contacts.friction_of(i),
        setup.stabilization,
    ))
}

/// The contacts whose block coefficients or load differ from the reference's.
fn contact_changes(
    setup: &Setup<'_>,
    contacts: &ContactStates,
    reference: &[super::factors::ReferenceBlock],
    inc: &Increment,
) -> Vec<ContactChange> {
    let pairs = &setup.pairs;
    (0..pairs.len())
        .into_par_iter()
        .with_min_len(256)
        .filter_map(|i| {
            let current = contacts.block(i);
            let r = &reference[i];
            let friction = contacts.friction_of(i);
            let stiffness =
                pairs[i].block_coefficients(&current, friction, setup.stabilization) - r.stiffness;
            let load = contacts.load_coefficients(&pairs[i], i, &current)
                - r.load(&pairs[i])
                - stiffness * inc.prescribed_jump[i];
            let change = ContactChange {
                contact: i,
                stiffness,
                load,
            };
            change.is_change().then_some(change)
        })
        .collect()
}

/// Scatters contact blocks and loads into a system.
struct Scatter<'s, 'a> {
    setup: &'s Setup<'a>,
    contacts: &'s ContactStates,
    path: &'s LoadPath,
    alpha: f64,
}

impl Scatter<'_, '_> {
    /// Contact i's load in `state` (G φ, see [`ContactPair::load_coefficients`]) minus its
    /// block's products with the prescribed DOFs at α, times `sign`, into `rhs`: the caller
    /// keeps concurrent calls on distinct nodes.
    fn contact_into(&self, i: usize, state: ContactState, sign: f64, rhs: &SharedMut<f64>) {
        let (setup, contacts, alpha) = (self.setup, self.contacts, self.alpha);
        let disc = &setup.disc;
        let pair = &setup.pairs[i];
        let block_state = BlockState {
            state,
            ..contacts.block(i)
        };
        let friction = contacts.friction_of(i);
        let mut f = pair.load_of(&contacts.load_coefficients(pair, i, &block_state));
        let gdof = |r: usize| 6 * pair.jump.nodes[r / 6] + r % 6;
        let mut prescribed = BlockVector::zeros();
        for &c in &setup.prescribed[i] {
            prescribed[c] = self.path.value(gdof(c), alpha);
        }
        if prescribed.iter().any(|v| *v != 0.0) {
            let d = pair.block_coefficients(&block_state, friction, setup.stabilization);
            f -= pair.apply_block(&pair.block_of(&d), &prescribed);
        }
        for r in 0..pair.size() {
            if let Some(ir) = disc.reduced(gdof(r)) {
                // SAFETY: row r is a free DOF of a node no concurrent call holds.
                unsafe { *rhs.get(ir) += sign * f[r] };
            }
        }
    }

    /// Every contact in the state `state` gives it (None: left out), color by color in
    /// parallel (sums independent of the number of threads).
    fn by_colors(&self, state: &(dyn Fn(usize) -> Option<ContactState> + Sync), rhs: &mut [f64]) {
        let shared_rhs = SharedMut::new(rhs);
        for color in &self.setup.contact_colors {
            color.par_iter().with_min_len(16).for_each(|&i| {
                if let Some(state) = state(i) {
                    self.contact_into(i, state, 1.0, &shared_rhs)
                }
            });
        }
    }

    /// Only the load: once per increment every contact stuck, or open if it is open now (α
    /// and the slips are fixed within it), then the contacts in another state swapped in.
    fn loads(&self, inc: &mut Increment, kept: &mut Option<KeptContactLoads>, rhs: &mut [f64]) {
        let (setup, contacts) = (self.setup, self.contacts);
        let pairs = &setup.pairs;
        let (base_states, base) = inc
            .base_load
            .get_or_insert_with(|| self.base_load(kept, rhs));
        rhs.copy_from_slice(base);
        let shared_rhs = SharedMut::new(rhs);
        for i in (0..pairs.len()).filter(|&i| contacts.states[i] != base_states[i]) {
            if !setup.prescribed[i].is_empty() {
                self.contact_into(i, base_states[i], -1.0, &shared_rhs);
                self.contact_into(i, contacts.states[i], 1.0, &shared_rhs);
                continue;
            }
            let base_state = BlockState {
                state: base_states[i],
                direction: Vector2::zeros(),
                k_perp: 0.0,
            };
            // No prescribed DOFs: the load alone, G (φ − φ_base) (see
            // ContactPair::load_coefficients), without the block.
            let pair = &pairs[i];
            let phi = contacts.load_coefficients(pair, i, &contacts.block(i))
                - contacts.load_coefficients(pair, i, &base_state);
            let mut f = BlockVector::zeros();
            for (ga, pa) in pair.jump_basis().iter().zip(phi.iter()) {
                f += ga * *pa;
            }
            for (r, ir) in super::factor_reuse::free_rows(pair, &setup.disc) {
                // SAFETY: one contact at a time.
                unsafe { *shared_rhs.get(ir) += f[r] };
            }
        }
    }

    /// The base states of this increment (open as open, the others stuck) and α F (`rhs`)
    /// plus their loads.
    fn base_load(
        &self,
        kept: &mut Option<KeptContactLoads>,
        rhs: &[f64],
    ) -> (Vec<ContactState>, Vec<f64>) {
        let (setup, contacts) = (self.setup, self.contacts);
        let states: Vec<ContactState> = contacts
            .states
            .iter()
            .map(|&s| match s {
                ContactState::Open => ContactState::Open,
                _ => ContactState::Stick,
            })
            .collect();
        // The contacts without prescribed DOFs: their kept sum, updated where the base state
        // or the slip changed (an open contact's load is zero, a stuck one's its stick load).
        let free = |i: usize| setup.prescribed[i].is_empty();
        let kept = kept.get_or_insert_with(|| {
            let mut sum = vec![0.0; rhs.len()];
            self.by_colors(&|i| free(i).then_some(states[i]), &mut sum);
            KeptContactLoads::new(&states, &contacts.slips, sum)
        });
        kept.update(
            &states,
            &contacts.slips,
            free,
            |i, state, slip, sign, out| {
                if state != ContactState::Stick {
                    return;
                }
                // The stick load as `contact_into` sums it (G φ), so updates cancel exactly.
                let pair = &setup.pairs[i];
                let stick = BlockState {
                    state,
                    direction: Vector2::zeros(),
                    k_perp: 0.0,
                };
                let phi = pair.load_coefficients(&stick, &Vector2::zeros(), slip, setup.friction());
                let f = pair.load_of(&phi);
                for (r, ir) in super::factor_reuse::free_rows(&setup.pairs[i], &setup.disc) {
                    out[ir] += sign * f[r];
                }
            },
        );
        let mut base: Vec<f64> = rhs.iter().zip(kept.sum()).map(|(r, k)| r + k).collect();
        // The contacts on prescribed DOFs, whose loads follow α.
        self.by_colors(&|i| (!free(i)).then_some(states[i]), &mut base);
        (states, base)
    }
}
