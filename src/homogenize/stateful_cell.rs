//! A stateful cell, the kernel a macro-scale code calls at its integration points (FE²): the
//! periodic cell set up once — pairing, contact set, percolation check, pattern and elastic
//! values — and any number of independent states, each a material point's contact states,
//! slips and energies, advanced by macroscopic strain increments with the stick/slip solver
//! of [`super::elasto_plastic_curve`] (thesis §4.3, §5.1.2).
//!
//! A state follows a straight strain path E(α) = E₀ + α D: an increment along the path's
//! direction continues it (the solver's predictors and reference loads stay valid), any
//! other one starts a new path at the current strain. The cell's factorization at rest is
//! shared by all states (read-only); what a state factorizes later is its own: states are
//! independent and may be updated in parallel.

use super::curve::check_small_strain;
use super::elastic::homogenize_elastic;
use super::Homogenized;
use crate::cell::MacroStrain;
use crate::constraints::Discretization;
use crate::model::Model;
use crate::solve::{Advanced, IncrementalOptions, RunState, Setup};
use crate::Error;
use std::borrow::Cow;

/// A periodic cell with contacts, set up once for any number of [`CellState`]s.
pub struct Cell {
    setup: Setup<'static>,
    /// Cell area L_x L_y (m²): resultants and energies are per unit area.
    area: f64,
    /// Whether updates and trials compute the consistent tangent.
    tangent: bool,
}

/// One material point of a [`Cell`]: its contact states, slips, displacements and energies,
/// its strain path, and its own factorizations.
///
/// `clone` copies the committed state without the factorizations: the copy's next update
/// solves on the cell's factorization at rest (or factorizes anew), and its results equal the
/// original's to the solver's tolerances (not bit for bit).
#[derive(Clone)]
pub struct CellState {
    run: RunState,
    /// E₀ of the current path.
    base: MacroStrain,
    /// D of the current path (zero before the first update).
    direction: MacroStrain,
}

impl CellState {
    /// The macroscopic strain the state is at, E = (ε11, ε22, γ12, κ11, κ22, κ12).
    pub fn strain(&self) -> MacroStrain {
        std::array::from_fn(|k| self.base[k] + self.run.alpha * self.direction[k])
    }

    /// Updates committed so far.
    pub fn updates(&self) -> usize {
        self.run.step
    }

    /// Drops the state's factorizations, low-rank columns and matrix values until its next
    /// update, which then solves on the cell's factorization at rest (or factorizes anew):
    /// for many material points whose caches would not fit in memory together. The committed
    /// state is unchanged.
    pub fn release_caches(&mut self) {
        self.run.release_caches();
    }
}

/// The response of a cell state to a strain increment.
#[derive(Clone, Debug, PartialEq)]
pub struct CellResponse {
    /// The macroscopic strain reached.
    pub strain: MacroStrain,
    /// Averaged stress resultants (N11, N22, N12 in N/m; M11, M22, M12 in N).
    pub resultant: [f64; 6],
    /// Dissipated energy per unit cell area since the state's start (J/m²).
    pub dissipated: f64,
    /// Elastic energy stored in the fibers and contact springs per unit area (J/m²).
    pub stored_energy: f64,
    /// Contacts open.
    pub open: usize,
    /// Contacts stuck.
    pub stick: usize,
    /// Contacts sliding.
    pub slip: usize,
    /// State iterations of the increment.
    pub iterations: usize,
    /// Times the increment was halved.
    pub cutbacks: usize,
    /// Factorizations the state made itself in the increment: none where it solved on the
    /// cell's shared factorization at rest (see [`Cell::new`]) or on its own earlier one,
    /// corrected by the contacts changed since (a consistent tangent's own is not counted).
    pub factorizations: usize,
    /// Contacts held in their state after chattering.
    pub held: usize,
    /// The increment's equilibrium residual (see [`crate::solve::IncrementRecord::equilibrium_residual`]).
    pub equilibrium_residual: f64,
    /// The energy balance's relative error (see [`crate::solve::EnergyBalance`]).
    pub energy_error: f64,
    /// The consistent tangent dN/dE for a macro Newton iteration (rows N11 … M12, columns
    /// ε11 … κ12; N/m, N, N·m as in the ABD): the derivative of this response with respect
    /// to the increment, contacts' states held (a Coulomb contact sliding in compression with
    /// its bound's slope μ p_N, which makes it nonsymmetric). None when the cell was built
    /// [`Cell::without_tangent`].
    pub tangent: Option<[[f64; 6]; 6]>,
}

impl Cell {
    /// Sets up the periodic cell `model` (no supports, no nodal loads: it is driven by its
    /// macroscopic strain) with the stick/slip settings `options` (`steps`, `path` and
    /// `deadline` are not used: each update is one increment, halved where needed).
    ///
    /// With a backend that can share a factorization (faer Cholesky, the default), the
    /// all-stick matrix at rest is analyzed and factorized here, once, for every state: a
    /// state at rest solves on it (bit for bit as if it had factorized it), and a state without
    /// caches (cloned, released) solves on it with its contacts changed since rest as a
    /// low-rank correction while that is cheaper than factorizing its own.
    pub fn new(model: &Model, options: &IncrementalOptions) -> Result<Self, Error> {
        // The cell first (a model without [cell] is told so, not asked to drop its loads).
        let (periodicity, set, anchor) = super::system::prepare_cell(model, true)?;
        if !model.loads.is_empty() {
            return Err(Error::InvalidOption(
                "a stateful cell is driven by its macroscopic strain alone: remove its [[loads]]"
                    .into(),
            ));
        }
        let disc = Discretization::periodic(model, &periodicity, &[0.0; 6], Some(anchor));
        let options = IncrementalOptions {
            steps: 1,
            path: None,
            deadline: None,
            progress: None,
            ..options.clone()
        };
        let mut setup = Setup::new(
            Cow::Owned(model.clone()),
            Cow::Owned(disc),
            set,
            Cow::Owned(options),
        )?;
        setup.share_rest_factorization()?;
        Ok(Cell {
            area: periodicity.geometry.area(),
            setup,
            tangent: true,
        })
    }

    /// The cell without the consistent tangent in its responses (each costs a factorization
    /// of the tangent matrix: skip it where the caller does not use it).
    pub fn without_tangent(self) -> Self {
        Cell {
            tangent: false,
            ..self
        }
    }

    /// A state at rest: zero strain, every closed contact in stick.
    pub fn new_state(&self) -> CellState {
        CellState {
            run: RunState::start(&self.setup),
            base: [0.0; 6],
            direction: [0.0; 6],
        }
    }

    /// The cell's elastic homogenization: the all-stick ABD, the orthotropic constants and
    /// B^hom (see [`homogenize_elastic`]).
    pub fn elastic(&self) -> Result<Homogenized, Error> {
        homogenize_elastic(&self.setup.model, &self.setup.opts.solve)
    }

    /// Cell area L_x L_y (m²).
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Contact pairs of the cell.
    pub fn contacts(&self) -> usize {
        self.setup.pairs.len()
    }

    /// Advances `state` by the macroscopic strain `increment` and commits it. On an error the
    /// state stays as it was.
    pub fn update(
        &self,
        state: &mut CellState,
        increment: &MacroStrain,
    ) -> Result<CellResponse, Error> {
        let (turn, alpha) = self.path_to(state, increment)?;
        let (before, turned) = (state.strain(), turn.is_some());
        let advanced = state.run.advance(&self.setup, turn, alpha, self.tangent)?;
        if turned {
            (state.base, state.direction) = (before, *increment);
        }
        Ok(self.response(state.strain(), &advanced))
    }

    /// The response [`Cell::update`] would give, without committing it: `state` stays at its
    /// committed values (a macro Newton iteration tries several strains per converged step).
    pub fn trial(
        &self,
        state: &mut CellState,
        increment: &MacroStrain,
    ) -> Result<CellResponse, Error> {
        let (turn, alpha) = self.path_to(state, increment)?;
        let strain = match turn {
            Some(_) => std::array::from_fn(|k| state.strain()[k] + increment[k]),
            None => std::array::from_fn(|k| state.base[k] + alpha * state.direction[k]),
        };
        let advanced = state.run.trial(&self.setup, turn, alpha, self.tangent)?;
        Ok(self.response(strain, &advanced))
    }

    /// How `state` reaches its strain plus `increment`: along its path to a load factor, or
    /// on a new path (its direction per generalized DOF) to α = 1.
    fn path_to(
        &self,
        state: &CellState,
        increment: &MacroStrain,
    ) -> Result<(Option<Vec<f64>>, f64), Error> {
        if let Some(v) = increment.iter().find(|v| !v.is_finite()) {
            return Err(Error::InvalidOption(format!(
                "macroscopic strain increment component {v} is not finite"
            )));
        }
        let now = state.strain();
        check_small_strain(
            &self.setup.model,
            &std::array::from_fn(|k| now[k] + increment[k]),
        )?;
        if let Some(s) = along(&state.direction, increment) {
            return Ok((None, state.run.alpha + s));
        }
        let disc = &self.setup.disc;
        let driver = disc.driver().ok_or(Error::InvalidOption(
            "the cell has no macroscopic driver".into(),
        ))?;
        let mut direction = vec![0.0; 6 * disc.n_gnodes()];
        direction[6 * driver..6 * driver + 6].copy_from_slice(increment);
        Ok((Some(direction), 1.0))
    }

    fn response(&self, strain: MacroStrain, advanced: &Advanced) -> CellResponse {
        let (r, area) = (&advanced.record, self.area);
        CellResponse {
            strain,
            resultant: r.macro_reaction.unwrap_or([0.0; 6]).map(|v| v / area),
            dissipated: r.dissipated / area,
            stored_energy: r.energy.stored / area,
            open: r.open,
            stick: r.stick,
            slip: r.slip,
            iterations: r.iterations,
            cutbacks: r.cutbacks,
            factorizations: r.factorizations,
            held: r.held,
            equilibrium_residual: r.equilibrium_residual,
            energy_error: r.energy.relative_error,
            tangent: advanced.tangent.map(|t| t.map(|row| row.map(|v| v / area))),
        }
    }
}

/// s with `increment` = s `direction` to rounding (None: another direction, or no path yet).
fn along(direction: &MacroStrain, increment: &MacroStrain) -> Option<f64> {
    let k = (0..6).max_by(|&a, &b| direction[a].abs().total_cmp(&direction[b].abs()))?;
    if direction[k] == 0.0 {
        return None;
    }
    let s = increment[k] / direction[k];
    let scale = increment.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    (0..6)
        .all(|j| (increment[j] - s * direction[j]).abs() <= 1e-14 * scale)
        .then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// A state on the cell's shared rest factorization counts that factor's size in its
    /// memory rule (a second factor beside the reference only while it is at most
    /// `MAX_BESIDE_FACTOR_BYTES`): after its first update at rest (it solves on the shared
    /// factor), and after its caches were released (it adopts the shared factor).
    #[test]
    fn states_count_the_shared_factors_size() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/cells/nonwoven_small.toml");
        let model = crate::io::load_model(&path).expect("fixture loads");
        let cell = Cell::new(&model, &IncrementalOptions::default()).expect("the cell sets up");
        let shared = cell.setup.shared_factor_bytes();
        assert!(shared.is_some_and(|b| b > 0), "{shared:?}");
        let mut state = cell.new_state();
        let step = [1e-4, 0.0, 0.0, 0.0, 0.0, 0.0];
        cell.update(&mut state, &step).expect("update at rest");
        assert_eq!(state.run.factor_bytes(), shared);
        state.release_caches();
        cell.update(&mut state, &step)
            .expect("update after the release");
        assert_eq!(state.run.factor_bytes(), shared);
    }
}
