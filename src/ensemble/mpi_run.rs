//! An ensemble over the ranks of an MPI job (feature `mpi`, rsmpi): rank 0 reads the store and
//! broadcasts the seeds still to run; rank r runs the r-th, (r + K)-th, … of them (round robin
//! over K ranks) and sends each realization to rank 0 as JSON; rank 0 runs its own share,
//! stores every realization as it arrives and computes the statistics. A realization is the
//! same computation as in a single-process run ([`run_realization`]).

use super::realization::{run_realization, Realization, RealizationStore};
use super::run::{seeds, Ensemble, EnsembleOptions, EnsembleProgress};
use crate::Error;
use mpi::traits::*;
use std::collections::HashMap;
use std::path::Path;

/// Tag of the messages that carry a realization.
const REALIZATION: mpi::Tag = 1;

/// Marks a failed set-up in the broadcast of the seeds' count.
const FAILED: u64 = u64::MAX;

/// Runs the ensemble of `opts` on the ranks of `world`: `Some(ensemble)` on rank 0, `None` on
/// the others. `store` and `progress` are rank 0's (see [`super::run_ensemble`]). An error
/// of rank 0 before the work is shared ends every rank (the others return `None`).
pub fn run_ensemble_mpi<C: Communicator>(
    world: &C,
    opts: &EnsembleOptions,
    store: Option<&Path>,
    progress: Option<EnsembleProgress<'_>>,
) -> Result<Option<Ensemble>, Error> {
    let root = world.process_at_rank(0);
    if world.rank() != 0 {
        let mut count = 0u64;
        root.broadcast_into(&mut count);
        if count == FAILED {
            return Ok(None);
        }
        let mut todo = vec![0u64; count as usize];
        root.broadcast_into(&mut todo[..]);
        for seed in own_share(&todo, world) {
            let r = run_realization(&opts.params, seed, &opts.solve, opts.curve.as_ref());
            // Rank 0 waits for every realization: one that cannot be sent ends the job
            // rather than leave it waiting (serde_json fails only on maps without string keys,
            // which a realization has none of).
            let Ok(bytes) = serde_json::to_vec(&r) else {
                eprintln!("error: the realization of seed {seed} cannot be serialized");
                world.abort(1)
            };
            root.send_with_tag(&bytes[..], REALIZATION);
        }
        return Ok(None);
    }
    let set_up = (|| {
        let seeds = seeds(opts)?;
        let store = store
            .map(|dir| RealizationStore::open(dir, &opts.params, opts.curve.as_ref()))
            .transpose()?;
        let mut stored = HashMap::new();
        for seed in seeds.clone() {
            if let Some(r) = store.as_ref().map(|s| s.load(seed)).transpose()?.flatten() {
                stored.insert(seed, r);
            }
        }
        Ok::<_, Error>((seeds, store, stored))
    })();
    let (seeds, store, stored) = match set_up {
        Ok(s) => s,
        Err(e) => {
            let mut failed = FAILED;
            root.broadcast_into(&mut failed);
            return Err(e);
        }
    };
    let mut todo: Vec<u64> = seeds.clone().filter(|s| !stored.contains_key(s)).collect();
    root.broadcast_into(&mut (todo.len() as u64));
    root.broadcast_into(&mut todo[..]);
    let mut root_work = RootWork {
        store: store.as_ref(),
        progress,
        done: HashMap::new(),
    };
    for seed in seeds.clone() {
        if let Some(r) = stored.get(&seed) {
            root_work.hear(r, true);
        }
    }
    for seed in own_share(&todo, world) {
        let r = run_realization(&opts.params, seed, &opts.solve, opts.curve.as_ref());
        root_work.keep(r)?;
        // What arrived meanwhile is stored now, not at the end.
        while world
            .any_process()
            .immediate_probe_with_tag(REALIZATION)
            .is_some()
        {
            root_work.receive(world)?;
        }
    }
    while root_work.done.len() < todo.len() {
        root_work.receive(world)?;
    }
    let reused = stored.len();
    let mut all = stored;
    all.extend(root_work.done);
    let realizations = seeds.filter_map(|s| all.remove(&s)).collect();
    Ok(Some(Ensemble::from_realizations(
        realizations,
        reused,
        opts.curve.as_ref(),
    )))
}

/// The seeds of `todo` that rank `world.rank()` runs: every K-th from its rank on.
fn own_share<'t, C: Communicator>(todo: &'t [u64], world: &C) -> impl Iterator<Item = u64> + 't {
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    todo.iter().copied().skip(rank).step_by(size.max(1))
}

/// Rank 0's side: realizations stored as they arrive.
struct RootWork<'s, 'p> {
    store: Option<&'s RealizationStore>,
    progress: Option<EnsembleProgress<'p>>,
    done: HashMap<u64, Realization>,
}

impl RootWork<'_, '_> {
    fn hear(&mut self, r: &Realization, reused: bool) {
        if let Some(p) = self.progress.as_mut() {
            p(r, reused);
        }
    }

    /// Stores a new realization and reports it.
    fn keep(&mut self, r: Realization) -> Result<(), Error> {
        if let Some(s) = self.store {
            s.save(&r)?;
        }
        self.hear(&r, false);
        self.done.insert(r.seed, r);
        Ok(())
    }

    /// Receives one realization from another rank.
    fn receive<C: Communicator>(&mut self, world: &C) -> Result<(), Error> {
        let (bytes, status) = world.any_process().receive_vec_with_tag::<u8>(REALIZATION);
        let r: Realization = serde_json::from_slice(&bytes).map_err(|e| Error::Output {
            path: format!("message of rank {}", status.source_rank()),
            message: e.to_string(),
        })?;
        self.keep(r)
    }
}
