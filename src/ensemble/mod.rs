//! Stochastic ensembles: the scatter of a random cell's effective stiffness from seed to seed.
//! N realizations of a generator with consecutive seeds, the six cell problems of each, and per
//! ABD entry the mean, standard deviation and 95 % confidence interval of the mean, with the
//! interval's convergence as N grows. Each realization is stored as it finishes, so a killed run
//! restarts without losing finished work.

mod realization;
mod run;
mod statistics;

pub use realization::{run_realization, Realization, RealizationStore};
pub use run::{
    run_ensemble, ConvergencePoint, Ensemble, EnsembleOptions, EnsembleProgress, MAIN_MODULI,
};
pub use statistics::{summarize, SampleSummary};
