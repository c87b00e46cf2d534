//! Committing a converged increment: the slip history, the dissipated and stored energy, the
//! forces with their equilibrium residual and reactions, and the increment's records.

use super::increment::Increment;
use super::options::CHATTER_SWITCHES;
use super::records::{ContactRecord, EnergyBalance, IncrementRecord, LowRankSizes};
use super::return_mapping::{gather, Trial};
use super::stabilizer::stabilizer_force;
use super::StickSlip;
use crate::constraints::{support_reactions, Discretization};
use crate::contact::{ContactPair, ContactState};
use fibercell_solver::SolveReport;
use nalgebra::{Vector2, Vector3};
use rayon::prelude::*;

/// What the energy balance carries from one increment to the next.
#[derive(Clone, Default)]
pub(super) struct EnergyHistory {
    /// Energy dissipated by sliding since the start.
    pub dissipated: f64,
    /// W_ext so far.
    pub external_work: f64,
    /// The generalized forces and displacements of the last increment.
    pub previous: (Vec<f64>, Vec<f64>),
    /// The largest (Σ_e ‖K_e q_e‖²)^½ of any increment so far: the scale of the reported
    /// equilibrium residual, which on an unloading path stays that of the peak load.
    pub force_scale: f64,
    /// The largest ‖K q‖ (every generalized DOF) so far: the scale of the stricter residual
    /// test by which an increment whose forces lag may stop (`classify_settled`).
    pub nodal_scale: f64,
    /// The largest |W_ext| so far: the scale of the energy balance (unloaded, an elastic
    /// cell has W_ext ≈ E_el ≈ 0 and its imbalance would be roundoff against nothing).
    pub work_scale: f64,
}

/// One contact's share of the commit.
struct CommittedContact {
    /// The new slip (None: it keeps its slip, stuck).
    slip: Option<Vector2<f64>>,
    dissipation: f64,
    /// Its generalized forces on its block's nodes.
    forces: crate::contact::BlockVector,
    record: ContactRecord,
    /// The elastic energy of its springs and of its stabilizer.
    energy: (f64, f64),
}

impl StickSlip<'_, '_, '_> {
    /// Commits the converged increment `inc` with the trials of its last classification.
    pub(super) fn commit(
        &mut self,
        mut inc: Increment,
        iterations: usize,
        trials: &[Trial],
        report: Option<SolveReport>,
    ) {
        let StickSlip {
            setup,
            contacts,
            factors,
            q,
            energy,
            out,
            ..
        } = self;
        let (model, disc, alpha) = (&setup.model, &setup.disc, inc.alpha);
        let internal = setup.elastic.internal_with_scale(model, q);
        // The scale of the residual: the forces the elements carry, (Σ_e ‖K_e q_e‖²)^½ (at a
        // node their sum cancels: ‖K q‖ measured a woven cell's shear, its yarns turning
        // nearly rigidly, against 10⁻³ of them and its roundoff as a 2·10⁻⁸ residual), the
        // largest of the run so far (unloaded to zero strain, a cell is nearly free of
        // stress, and the contact forces' roundoff would be measured against nothing).
        energy.force_scale = energy.force_scale.max(internal.element_norm);
        energy.nodal_scale = energy.nodal_scale.max(norm(&internal.forces));
        let mut forces = internal.forces;
        let mut stored: f64 = 0.5 * q.iter().zip(&forces).map(|(a, b)| a * b).sum::<f64>();
        let mut stabilization_energy = 0.0;
        // Per contact, in parallel: its new slip, dissipation, generalized forces and record;
        // then applied in contact order (the same sums as one pass).
        let committed: Vec<CommittedContact> = setup
            .pairs
            .par_iter()
            .with_min_len(256)
            .zip(trials)
            .zip(&contacts.slips)
            .map(|((pair, t), slip)| commit_contact(pair, t, slip, q, setup.stabilization))
            .collect();
        let mut records = Vec::with_capacity(setup.pairs.len());
        for (i, c) in committed.into_iter().enumerate() {
            if let Some(new) = c.slip {
                contacts.slips[i] = new;
            }
            energy.dissipated += c.dissipation;
            stored += c.energy.0;
            stabilization_energy += c.energy.1;
            add_block(&mut forces, &setup.pairs[i].jump.nodes, &c.forces);
            records.push(c.record);
        }
        // W_ext by the trapezoidal rule over this increment.
        energy.external_work += 0.5
            * forces
                .iter()
                .zip(&energy.previous.0)
                .zip(q.iter().zip(&energy.previous.1))
                .map(|((f, f0), (x, x0))| (f + f0) * (x - x0))
                .sum::<f64>();
        let (external_work, dissipated) = (energy.external_work, energy.dissipated);
        energy.work_scale = energy.work_scale.max(external_work.abs());
        let balance = EnergyBalance {
            external_work,
            stored,
            stabilization: stabilization_energy,
            relative_error: if energy.work_scale > 0.0 {
                (external_work - stored - stabilization_energy - dissipated).abs()
                    / energy.work_scale
            } else {
                0.0
            },
        };
        energy.previous = (forces.clone(), q.clone());
        let equilibrium_residual = relative_residual(
            disc,
            &forces,
            (&setup.applied_free, alpha),
            energy.force_scale,
        );
        let (reaction, reactions) = support_reactions(model, &forces, alpha);
        let macro_reaction = disc
            .driver()
            .map(|d| [0, 1, 2, 3, 4, 5].map(|k| forces[6 * d + k]));
        let count = |s: ContactState| records.iter().filter(|r| r.state == s).count();
        let (backend, bwd) = report.map_or(("none", 0.0), |r| (r.backend, r.backward_error));
        inc.lap(|t| &mut t.commit);
        out.increments.push(IncrementRecord {
            step: inc.step,
            alpha,
            iterations,
            factorizations: inc.factorizations,
            open: count(ContactState::Open),
            stick: count(ContactState::Stick),
            slip: count(ContactState::Slip),
            applied_load: setup.applied_full.map(|v| alpha * v),
            reaction,
            macro_reaction,
            dissipated,
            factor_reuses: inc.factor_reuses,
            reuse_iterations: inc.reuse_iterations,
            held: contacts
                .switches
                .iter()
                .filter(|&&n| n >= CHATTER_SWITCHES)
                .count(),
            backend: backend.to_string(),
            seconds: inc.started.elapsed().as_secs_f64(),
            timings: inc.timings,
            low_rank: LowRankSizes {
                largest_order: inc.low_rank_order,
                largest_bytes: inc.low_rank_bytes.max(factors.low_rank.memory_bytes()),
                columns: factors.low_rank.len(),
                crossover_order: factors.cost.crossover(),
            },
            cutbacks: 0,
            backward_error: bwd,
            equilibrium_residual,
            energy: balance,
        });
        if !setup.opts.history.keeps_all() {
            // Only the last increment keeps its full outputs: free the one before.
            if let (Some(r), Some(d)) =
                (out.contact_results.last_mut(), out.displacements.last_mut())
            {
                *r = Vec::new();
                *d = Vec::new();
            }
        }
        out.contact_states
            .push(records.iter().map(|r| r.state).collect());
        out.contact_results.push(records);
        out.displacements.push(disc.physical(q));
        out.reactions = reactions;
    }
}

/// Contact `pair`'s new slip, dissipation, forces, record and spring energies for its trial
/// `t` at displacements `q`, committed slip `slip`.
fn commit_contact(
    pair: &ContactPair,
    t: &Trial,
    slip: &Vector2<f64>,
    q: &[f64],
    stabilization: f64,
) -> CommittedContact {
    let (new_slip, dissipation) = match t.state {
        ContactState::Open => (Some(t.relative), 0.0),
        ContactState::Slip => {
            let new = t.relative - t.tangential / pair.penalty_tangent;
            (Some(new), t.tangential.dot(&(new - slip)))
        }
        ContactState::Stick => (None, 0.0),
    };
    let ft: Vector3<f64> = pair.tangents[0] * t.tangential[0] + pair.tangents[1] * t.tangential[1];
    let force = pair.normal * t.normal_force + ft;
    let mut fq = pair.jump.b.transpose() * force;
    let q_block = gather(q, &pair.jump.nodes);
    // The springs' elastic energy: normal, tangential, rotational; the stabilizer's.
    let mut energy = (0.0, 0.0);
    if t.state != ContactState::Open {
        let rotation = pair.jump.r.transpose() * pair.rotation_moment(&q_block);
        energy.0 = 0.5 * t.normal_force * t.normal_force / pair.penalty_normal
            + 0.5 * t.tangential.norm_squared() / pair.penalty_tangent
            + 0.5 * q_block.dot(&rotation);
        fq += rotation;
    }
    if stabilization > 0.0 && t.state != ContactState::Stick {
        let f = stabilizer_force(pair, t.state, &q_block) * stabilization;
        energy.1 = 0.5 * q_block.dot(&f);
        fq += f;
    }
    let record = ContactRecord {
        state: t.state,
        gap: -t.penetration,
        normal_force: t.normal_force,
        tangential_force: [ft[0], ft[1], ft[2]],
        tangential_magnitude: ft.norm(),
        friction_bound: t.bound,
        relative_tangential: {
            let g = pair.tangents[0] * t.relative[0] + pair.tangents[1] * t.relative[1];
            [g[0], g[1], g[2]]
        },
    };
    CommittedContact {
        slip: new_slip,
        dissipation,
        forces: fq,
        record,
        energy,
    }
}

impl StickSlip<'_, '_, '_> {
    /// The equilibrium residual the increment to load factor `alpha` would commit with the
    /// law's forces of `trials` at the current displacements, against the elements' nodal
    /// forces ‖K q‖ (the largest so far): stricter than the reported one (see
    /// [`StickSlip::commit`]), whose scale, the forces the elements carry, is 3–4 times
    /// larger on the non-wovens and would let the increments stop on less converged sliding
    /// forces (faer LU and Cholesky then differ by 6·10⁻⁸ on the knit's resultants).
    pub(super) fn equilibrium_residual(&self, alpha: f64, trials: &[Trial]) -> f64 {
        let (setup, q) = (&self.setup, &self.q[..]);
        let mut forces = setup.elastic.internal(&setup.model, q);
        let scale = self.energy.nodal_scale.max(norm(&forces));
        let contact_forces: Vec<_> = setup
            .pairs
            .par_iter()
            .with_min_len(256)
            .zip(trials)
            .zip(&self.contacts.slips)
            .map(|((pair, t), slip)| commit_contact(pair, t, slip, q, setup.stabilization).forces)
            .collect();
        for (pair, f) in setup.pairs.iter().zip(&contact_forces) {
            add_block(&mut forces, &pair.jump.nodes, f);
        }
        relative_residual(&setup.disc, &forces, (&setup.applied_free, alpha), scale)
    }
}

/// The Euclidean norm of `v`.
fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Adds a contact's generalized forces `f` on its block's nodes `nodes` to `forces`.
fn add_block(forces: &mut [f64], nodes: &[usize], f: &crate::contact::BlockVector) {
    for (k, &n) in nodes.iter().enumerate() {
        for d in 0..6 {
            forces[6 * n + d] += f[6 * k + d];
        }
    }
}

/// ‖R‖/(`scale` + ‖α F‖): R = f − α F on the free DOFs (see [`free_norm`]), `scale` the
/// elements' forces.
fn relative_residual(
    disc: &Discretization,
    forces: &[f64],
    (load, alpha): (&[f64], f64),
    scale: f64,
) -> f64 {
    let load_norm = alpha * load.iter().map(|v| v * v).sum::<f64>().sqrt();
    free_norm(disc, forces, (load, alpha)) / (scale + load_norm).max(f64::MIN_POSITIVE)
}

/// ‖f − α F‖₂ over the free DOFs of the generalized force vector `forces` (F given on the
/// free DOFs).
fn free_norm(disc: &Discretization, forces: &[f64], (load, alpha): (&[f64], f64)) -> f64 {
    forces
        .iter()
        .enumerate()
        .filter_map(|(g, f)| {
            let r = disc.reduced(g)?;
            Some(f - alpha * load[r])
        })
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
}
