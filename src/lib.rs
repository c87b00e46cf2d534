//! # fibercell
//!
//! Effective mechanical properties of textiles from their fiber microstructure. A fabric cell
//! is a network of 3D Euler–Bernoulli frame elements (thesis §4.2–4.3); this crate builds the
//! model ([`model`]), the element matrices ([`element`]), the reduced sparse system
//! ([`assembly`], [`constraints`]) and solves it through a pluggable sparse solver layer
//! ([`fibercell_solver`], re-exported as [`solver`]) with faer, CG or CHOLMOD backends
//! ([`solve`]). Files are handled in [`io`].
//!
//! The whole static analysis from Rust:
//!
//! ```no_run
//! use fibercell::{io, solve};
//! let model = io::load_model(std::path::Path::new("fixtures/ok_frame3d.toml"))?;
//! let solution = solve::solve_static(&model, &solve::SolveOptions::default())?;
//! println!("tip: {:?}", solution.displacements[0]);
//! # Ok::<(), fibercell::Error>(())
//! ```
//!
//! Units are SI throughout (m, N, Pa, rad). DOFs per node: ux, uy, uz, rx, ry, rz.

pub mod assembly;
pub mod cell;
pub mod check;
pub mod constraints;
pub mod contact;
pub mod element;
pub mod ensemble;
mod error;
pub mod free_memory;
pub mod generate;
pub mod homogenize;
mod input_error;
pub mod io;
pub mod model;
pub mod solve;
pub mod stats;

pub use error::Error;
pub use fibercell_solver as solver;
pub use homogenize::{Cell, CellResponse, CellState};
pub use model::Model;

/// The Rust examples of the README and of `docs/`, compiled and run as doctests.
#[cfg(doctest)]
mod doc_examples {
    #[doc = include_str!("../README.md")]
    struct Readme;
    #[doc = include_str!("../docs/architecture.md")]
    struct Architecture;
    #[doc = include_str!("../docs/cli.md")]
    struct Cli;
    #[doc = include_str!("../docs/contact.md")]
    struct Contact;
    #[doc = include_str!("../docs/generators.md")]
    struct Generators;
    #[doc = include_str!("../docs/homogenization.md")]
    struct Homogenization;
    #[doc = include_str!("../docs/library.md")]
    struct Library;
    #[doc = include_str!("../docs/model-format.md")]
    struct ModelFormat;
    #[doc = include_str!("../docs/performance.md")]
    struct Performance;
    #[doc = include_str!("../docs/testing.md")]
    struct Testing;
    #[doc = include_str!("../docs/theory.md")]
    struct Theory;
}
