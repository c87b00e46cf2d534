//! Where the wall-clock time of one load increment went.

use std::time::Instant;

/// Seconds of one increment per stage, summed over its state iterations.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IncrementTimings {
    /// Contact blocks and right-hand side for the current states, added to the elastic values.
    pub assemble: f64,
    /// Numeric factorizations (and the one symbolic analysis of the run, in the first increment).
    pub factorize: f64,
    /// Solves on an earlier factorization with a low-rank correction (new columns of S, the
    /// capacitance LU, the solves), failed attempts included.
    pub factor_reuse: f64,
    /// Direct solves with the current factorization, with their backward-error check.
    pub solve: f64,
    /// Return mapping of every contact.
    pub classify: f64,
    /// Committing the slip history, forces, reactions and records of the increment.
    pub commit: f64,
}

impl IncrementTimings {
    /// The stages in the order of the fields.
    pub fn stages(&self) -> [f64; 6] {
        [
            self.assemble,
            self.factorize,
            self.factor_reuse,
            self.solve,
            self.classify,
            self.commit,
        ]
    }

    /// Names of [`IncrementTimings::stages`].
    pub const NAMES: [&'static str; 6] = [
        "assemble",
        "factorize",
        "factor reuse",
        "solve",
        "classify",
        "commit",
    ];

    /// Adds the time since `since` to the stage `field` and restarts the clock.
    pub(crate) fn lap(field: &mut f64, since: &mut Instant) {
        let now = Instant::now();
        *field += (now - *since).as_secs_f64();
        *since = now;
    }

    /// Stage-wise sum.
    pub fn add(&mut self, other: &IncrementTimings) {
        self.assemble += other.assemble;
        self.factorize += other.factorize;
        self.factor_reuse += other.factor_reuse;
        self.solve += other.solve;
        self.classify += other.classify;
        self.commit += other.commit;
    }
}
