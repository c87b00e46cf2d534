//! What a stick/slip run reports: per increment, per contact, and the whole solution.

use super::super::IncrementTimings;
use crate::constraints::Reaction;
use crate::contact::{ContactSet, ContactState};
use serde::Serialize;
use std::sync::Arc;

/// One increment.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct IncrementRecord {
    /// Increment n (1-based).
    pub step: usize,
    /// Load factor α = n/N.
    pub alpha: f64,
    /// State iterations needed.
    pub iterations: usize,
    /// Numeric factorizations done in this increment.
    pub factorizations: usize,
    /// Solves done on an earlier factorization with the changed contacts as a low-rank
    /// correction instead of a new factorization (see [`IncrementalOptions::reuse_factor`](super::IncrementalOptions::reuse_factor)).
    pub factor_reuses: usize,
    /// Residual correction steps of those solves.
    pub reuse_iterations: usize,
    /// Contacts open, stuck and sliding at the end of the increment.
    pub open: usize,
    /// Stuck contacts.
    pub stick: usize,
    /// Sliding contacts.
    pub slip: usize,
    /// Applied nodal loads summed per DOF (Fx, Fy, Fz, Mx, My, Mz), times α.
    pub applied_load: [f64; 6],
    /// Support reactions summed per DOF.
    pub reaction: [f64; 6],
    /// For a periodic cell: the reactions of the six macroscopic drivers (stress resultants
    /// times the cell area).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub macro_reaction: Option<[f64; 6]>,
    /// Energy dissipated by sliding since the start, Σ F_t · Δs (J).
    pub dissipated: f64,
    /// Contacts that chattered (changed state or slip direction 4 times in this increment: the
    /// discrete penalty problem can have no consistent state for them) and were then held in
    /// their state for the rest of it (of a halved increment: the most either half held).
    pub held: usize,
    /// Backend of the last solve.
    pub backend: String,
    /// Wall-clock seconds of the increment (not serialized: results files stay reproducible).
    #[serde(skip)]
    pub seconds: f64,
    /// Those seconds per stage (not serialized).
    #[serde(skip)]
    pub timings: IncrementTimings,
    /// The sizes of the low-rank corrections (not serialized: they follow measured times).
    #[serde(skip)]
    pub low_rank: LowRankSizes,
    /// Times the increment was halved because it ended with contacts held off equilibrium
    /// (its halves' records are merged into this one: iterations and factorizations summed,
    /// the attempts' included, the state at its end, the larger residual); 0: solved whole.
    pub cutbacks: usize,
    /// Backward error of the last solve.
    pub backward_error: f64,
    /// Equilibrium residual ‖R‖₂ / (s + ‖α F‖₂) at the converged state, R on the free DOFs:
    /// R = α F − K q − f_c(q), the contact forces f_c those of the contact law itself (the
    /// return mapping's normal force, stick force or bound c + μ max(N, 0) along the slip
    /// direction, not the linearization the last system was assembled with), s = (Σ_e ‖K_e
    /// q_e‖²)^½ the forces the elements carry, the largest of the run so far (on an unloading
    /// path, the peak load's). About the solves' accuracy and the bounds' fixed-point tolerance; with
    /// held contacts, how far their state is from equilibrium (an error above
    /// [`MAX_HELD_RESIDUAL`](crate::solve::MAX_HELD_RESIDUAL)).
    pub equilibrium_residual: f64,
    /// The energy of the increment's state (J): the work of the external forces so far, the
    /// elastic energy stored in the elements and contact springs, the energy of the
    /// stabilizing springs, and [`IncrementRecord::dissipated`].
    pub energy: EnergyBalance,
}

/// The low-rank corrections of an increment (see
/// [`IncrementalOptions::reuse_factor`](super::IncrementalOptions::reuse_factor)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LowRankSizes {
    /// Largest capacitance order (columns of U in play) of the increment's low-rank solves
    /// (0: none).
    pub largest_order: usize,
    /// The most memory the correction held in the increment (bytes): the columns of U, their
    /// forward solves, S = Uᵀ A₀⁻¹ U and a capacitance factorization.
    pub largest_bytes: usize,
    /// Columns of U kept on the reference factorization at the end of the increment.
    pub columns: usize,
    /// The order at which a capacitance factorization is predicted to cost as much as a
    /// factorization of the matrix, from the run's measured times: above it the solver
    /// refactorizes (None before the first timed factorization).
    pub crossover_order: Option<usize>,
}

/// The energy balance of a stick/slip path: W_ext = E_el + E_stab + D up to the quadrature
/// of W_ext (the trapezoidal rule on each increment, exact where the response is linear in it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct EnergyBalance {
    /// Work of the external forces (loads and reactions, the macroscopic resultants of a cell)
    /// so far, by the trapezoidal rule over the increments: Σ ½ (f_{n−1} + f_n)·(q_n − q_{n−1}),
    /// f the generalized forces K q + f_c (at equilibrium the external ones).
    pub external_work: f64,
    /// Elastic energy: ½ qᵀ K q of the elements, and per closed contact ½ N²/p_N + ½ |F_t|²/p_T
    /// + ½ qᵀ K_R q of its springs.
    pub stored: f64,
    /// Energy of the stabilizing springs (0 without stabilization).
    pub stabilization: f64,
    /// |W_ext − E_el − E_stab − D| / max |W_ext| so far (0 when no work was done): the
    /// quadrature error of the increments, first order in their size while contacts slide
    /// (the dissipation F_t·Δs takes each increment's end force, W_ext the trapezoidal rule:
    /// per sliding contact and increment they differ by ½ ΔF_t·Δs, ½ μ ΔN |Δs| as the bound
    /// rises), roundoff while all stick.
    pub relative_error: f64,
}

/// One contact at the end of an increment.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ContactRecord {
    /// open, stick or slip.
    #[serde(serialize_with = "state_name")]
    pub state: ContactState,
    /// Current gap ḡ − nᵀ\[u\] (m; negative: penetration, which the penalty allows).
    pub gap: f64,
    /// Normal force N ≥ 0 (N).
    pub normal_force: f64,
    /// Tangential force vector in global coordinates (N).
    pub tangential_force: [f64; 3],
    /// Its magnitude (N).
    pub tangential_magnitude: f64,
    /// The friction bound μN or G at this state (N).
    pub friction_bound: f64,
    /// Tangential relative displacement of the contact points, global (m).
    pub relative_tangential: [f64; 3],
}

fn state_name<S: serde::Serializer>(s: &ContactState, ser: S) -> Result<S::Ok, S::Error> {
    ser.serialize_str(s.name())
}

/// Results of every increment.
#[derive(Clone, Debug)]
pub struct IncrementalSolution {
    /// The contact pairs (shared with the run's setup: a cell's states hold one copy).
    pub contacts: Arc<ContactSet>,
    /// Per-increment summary.
    pub increments: Vec<IncrementRecord>,
    /// Per increment, every contact (empty for the increments before the last when the run
    /// kept only the last: [`IncrementalOptions::history`](super::IncrementalOptions::history)).
    pub contact_results: Vec<Vec<ContactRecord>>,
    /// Per increment, every contact's state (kept for every increment).
    pub contact_states: Vec<Vec<ContactState>>,
    /// Per increment, [ux, uy, uz, rx, ry, rz] of every node (empty like `contact_results`).
    pub displacements: Vec<Vec<[f64; 6]>>,
    /// Reactions at the end.
    pub reactions: Vec<Reaction>,
}

impl IncrementalSolution {
    /// Keeps the first `n` increments' records (a cutback going back).
    pub(super) fn truncate(&mut self, n: usize) {
        self.increments.truncate(n);
        self.contact_results.truncate(n);
        self.contact_states.truncate(n);
        self.displacements.truncate(n);
    }

    /// Removes increment `k`'s records and returns its summary.
    pub(super) fn remove(&mut self, k: usize) -> IncrementRecord {
        self.contact_results.remove(k);
        self.contact_states.remove(k);
        self.displacements.remove(k);
        self.increments.remove(k)
    }

    /// Drops the records of every increment but the last.
    pub(super) fn keep_last(&mut self) {
        let earlier = self.increments.len().saturating_sub(1);
        self.increments.drain(..earlier);
        self.contact_results.drain(..earlier);
        self.contact_states.drain(..earlier);
        self.displacements.drain(..earlier);
    }

    /// Bytes its per-increment outputs hold: every increment's displacements of every node
    /// and record of every contact, and the increments' summaries.
    pub fn memory_bytes(&self) -> usize {
        let displacements: usize = self
            .displacements
            .iter()
            .map(|d| d.capacity() * size_of::<[f64; 6]>())
            .sum();
        let records: usize = self
            .contact_results
            .iter()
            .map(|r| r.capacity() * size_of::<ContactRecord>())
            .sum();
        let states: usize = self
            .contact_states
            .iter()
            .map(|s| s.capacity() * size_of::<ContactState>())
            .sum();
        displacements + records + states + self.increments.capacity() * size_of::<IncrementRecord>()
    }
}
