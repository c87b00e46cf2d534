//! What one load increment keeps across its state iterations: its load factor, the jumps of
//! the prescribed DOFs, the base load of its assemblies, and its counters and clocks.

use super::load_path::LoadPath;
use super::setup::Setup;
use crate::contact::ContactState;
use crate::solve::IncrementTimings;
use nalgebra::Vector6;
use std::time::Instant;

/// One increment n with load factor α_n, while its state iterations run.
pub(super) struct Increment {
    /// n (1-based).
    pub step: usize,
    pub alpha: f64,
    /// Per contact γ = Gᵀ α ū on its prescribed DOFs: its block's products with them are the
    /// load −G D γ.
    pub prescribed_jump: Vec<Vector6<f64>>,
    /// The contacts' states (open as open, all others as stuck) at the first load-only
    /// assembly of this increment, and α F + their loads.
    pub base_load: Option<(Vec<ContactState>, Vec<f64>)>,
    pub factorizations: usize,
    pub factor_reuses: usize,
    /// Residual correction steps of the low-rank solves.
    pub reuse_iterations: usize,
    /// Largest capacitance order of the low-rank solves.
    pub low_rank_order: usize,
    /// The most bytes the low-rank correction held with a capacitance factorization.
    pub low_rank_bytes: usize,
    pub timings: IncrementTimings,
    pub started: Instant,
    clock: Instant,
}

impl Increment {
    pub fn new(setup: &Setup<'_>, path: &LoadPath, step: usize, alpha: f64) -> Self {
        let started = Instant::now();
        let prescribed_jump = setup
            .pairs
            .iter()
            .zip(&setup.prescribed)
            .map(|(p, cols)| {
                if cols.is_empty() {
                    return Vector6::zeros();
                }
                let g = p.jump_basis();
                Vector6::from_fn(|b, _| {
                    cols.iter()
                        .map(|&c| {
                            let gdof = 6 * p.jump.nodes[c / 6] + c % 6;
                            g[b][c] * path.value(gdof, alpha)
                        })
                        .sum()
                })
            })
            .collect();
        Increment {
            step,
            alpha,
            prescribed_jump,
            base_load: None,
            factorizations: 0,
            factor_reuses: 0,
            reuse_iterations: 0,
            low_rank_order: 0,
            low_rank_bytes: 0,
            timings: IncrementTimings::default(),
            started,
            clock: started,
        }
    }

    /// Adds the time since the last lap to the stage `stage` picks.
    pub fn lap(&mut self, stage: impl FnOnce(&mut IncrementTimings) -> &mut f64) {
        IncrementTimings::lap(stage(&mut self.timings), &mut self.clock);
    }

    /// The error context of this increment.
    pub fn name(&self) -> String {
        format!("increment {}", self.step)
    }
}
