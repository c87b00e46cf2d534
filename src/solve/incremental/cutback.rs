//! Increment cutback: an increment that ends with contacts held off equilibrium (their states
//! chattered or their Coulomb bounds still moved after the state iterations allowed) is redone
//! from its start as two halves, each of which may be halved again, down to
//! 1/2^[`IncrementalOptions::max_cutbacks`](super::IncrementalOptions::max_cutbacks) of it. A large increment can switch thousands of contacts at once (an
//! avalanche of sliding), after which the fixed point on the states converges slowly or not
//! at all; on smaller increments fewer contacts switch at a time. The halves' records are
//! merged into the increment's one record, so a run keeps one record per requested load factor.

use super::commit::EnergyHistory;
use super::contact_states::ContactStates;
use super::options::EQUILIBRIUM_TOLERANCE;
use super::records::IncrementRecord;
use super::StickSlip;
use crate::constraints::Reaction;
use crate::solve::kept_contact_loads::KeptContactLoads;
use crate::Error;

/// What an increment changes, as it was at its start.
struct Snapshot {
    contacts: ContactStates,
    kept_loads: Option<KeptContactLoads>,
    q: Vec<f64>,
    energy: EnergyHistory,
    reactions: Vec<Reaction>,
    records: usize,
}

impl StickSlip<'_, '_, '_> {
    /// Increment `step` from load factor `from` to `alpha`, halved where it ends with contacts
    /// held off equilibrium (residual above [`EQUILIBRIUM_TOLERANCE`]) or without equilibrium
    /// ([`Error::NoEquilibrium`]), `depth` halvings deep so far.
    pub(super) fn advance(
        &mut self,
        step: usize,
        (from, alpha): (f64, f64),
        depth: usize,
    ) -> Result<(), Error> {
        let snapshot = (depth < self.setup.opts.max_cutbacks).then(|| self.snapshot());
        let result = self.increment(step, alpha);
        let Some(snapshot) = snapshot else {
            return result;
        };
        match result {
            Ok(()) if !self.held_off_equilibrium() => return Ok(()),
            Ok(()) | Err(Error::NoEquilibrium { .. }) => {}
            Err(e) => return Err(e),
        }
        // The attempt's state iterations and factorizations count in the increment's record.
        let attempt = self.out.increments.last().cloned();
        self.restore(snapshot);
        let middle = 0.5 * (from + alpha);
        self.advance(step, (from, middle), depth + 1)?;
        self.advance(step, (middle, alpha), depth + 1)?;
        self.merge_last_two(attempt);
        Ok(())
    }

    /// The last increment held contacts and its residual is above the equilibrium tolerance.
    fn held_off_equilibrium(&self) -> bool {
        self.out
            .increments
            .last()
            .is_some_and(|r| r.held > 0 && r.equilibrium_residual > EQUILIBRIUM_TOLERANCE)
    }

    fn snapshot(&self) -> Snapshot {
        Snapshot {
            contacts: self.contacts.clone(),
            kept_loads: self.kept_loads.clone(),
            q: self.q.clone(),
            energy: self.energy.clone(),
            reactions: self.out.reactions.clone(),
            records: self.out.increments.len(),
        }
    }

    fn restore(&mut self, s: Snapshot) {
        self.contacts = s.contacts;
        self.kept_loads = s.kept_loads;
        self.q = s.q;
        self.energy = s.energy;
        self.out.reactions = s.reactions;
        self.out.truncate(s.records);
    }

    /// Merges the records of the two halves (and the `attempt` on the whole) into the second
    /// half's (see [`merge_halves`]).
    fn merge_last_two(&mut self, attempt: Option<IncrementRecord>) {
        let out = &mut self.out;
        let n = out.increments.len();
        if n < 2 {
            return;
        }
        let first = out.remove(n - 2);
        if let Some(last) = out.increments.last_mut() {
            merge_halves(last, &first, attempt.as_ref());
        }
    }
}

/// The record of a halved increment from its halves' (`first`, `last`) and the `attempt` on
/// the whole, into `last`: the state at the end, the work of all, the larger residual and held
/// count of the halves (a record saying "nothing held" beside a residual that holding left in
/// the first half would hide its cause).
fn merge_halves(
    last: &mut IncrementRecord,
    first: &IncrementRecord,
    attempt: Option<&IncrementRecord>,
) {
    for r in std::iter::once(first).chain(attempt) {
        last.iterations += r.iterations;
        last.factorizations += r.factorizations;
        last.factor_reuses += r.factor_reuses;
        last.reuse_iterations += r.reuse_iterations;
        last.seconds += r.seconds;
        last.timings.add(&r.timings);
        last.low_rank.largest_order = last.low_rank.largest_order.max(r.low_rank.largest_order);
    }
    last.cutbacks += first.cutbacks + 1;
    last.equilibrium_residual = last.equilibrium_residual.max(first.equilibrium_residual);
    last.held = last.held.max(first.held);
}

#[cfg(test)]
mod tests {
    use super::{merge_halves, IncrementRecord};

    /// As L seed 3 under e22 at α = 0.45: a first half that ended with 3 contacts held at
    /// residual 8·10⁻⁵ and a second that settled. The merged record reports both the residual
    /// and the held contacts (before: "held 0" beside 8·10⁻⁵), sums the work of the halves and
    /// the failed attempt, and counts the halving.
    #[test]
    fn the_merged_record_keeps_the_held_contacts_of_the_worse_half() {
        let record = |iterations, held, residual| IncrementRecord {
            iterations,
            held,
            equilibrium_residual: residual,
            ..IncrementRecord::default()
        };
        let first = record(40, 3, 8e-5);
        let attempt = record(50, 120, 2e-4);
        let mut last = record(6, 0, 1e-10);
        merge_halves(&mut last, &first, Some(&attempt));
        assert_eq!(last.held, 3);
        assert_eq!(last.equilibrium_residual, 8e-5);
        assert_eq!(last.iterations, 96);
        assert_eq!(last.cutbacks, 1);

        let mut settled = record(6, 0, 1e-10);
        merge_halves(&mut settled, &record(5, 0, 2e-10), None);
        assert_eq!((settled.held, settled.equilibrium_residual), (0, 2e-10));
    }
}
