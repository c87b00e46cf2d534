//! Stochastic ensembles: the scatter of a random cell's effective stiffness from seed to seed.
//! N realizations of a generator with consecutive seeds, the six cell problems of each (and
//! optionally a curve along a strain path), and per ABD entry and curve point the mean,
//! standard deviation and 95 % confidence interval of the mean, with the interval's
//! convergence as N grows; and the RVE-size study, ensembles at growing cell sizes. Each
//! realization is stored as it finishes, so a killed run restarts without losing finished work.

mod curve_statistics;
#[cfg(feature = "mpi")]
mod mpi_run;
mod realization;
mod run;
mod rve_study;
mod statistics;

pub use curve_statistics::{CurveConvergencePoint, CurvePointSummary, CurveStatistics};
#[cfg(feature = "mpi")]
pub use mpi_run::run_ensemble_mpi;
pub use realization::{run_realization, CurvePath, CurveSample, Realization, RealizationStore};
pub use run::{
    run_ensemble, ConvergencePoint, Ensemble, EnsembleOptions, EnsembleProgress, MAIN_MODULI,
};
pub use rve_study::{
    representative_size, run_rve_study, scaled_nonwoven, RveProgress, RveSize, RveStudy,
    RveStudyOptions,
};
pub use statistics::{summarize, SampleSummary};
