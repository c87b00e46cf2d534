//! The load path of a run: the prescribed values u_c(α) = u₀ + α Δu on the prescribed DOFs and
//! the elastic right-hand side b(α) = b₀ + α Δb (the nodal loads α F and the elements'
//! products −K_fc u_c(α)). A run from rest has u₀ = 0 and b₀ = 0, and every value is α times
//! the discretization's own, exactly; a [`crate::Cell`] state turning to a new macroscopic
//! strain direction starts a new path at its current values ([`LoadPath::turn`]).

use super::setup::Setup;
use crate::constraints::Discretization;

/// Prescribed values and elastic load, affine in α.
#[derive(Clone, Debug)]
pub(crate) struct LoadPath {
    /// u₀ per generalized DOF (0 on free ones).
    base: Vec<f64>,
    /// Δu per generalized DOF.
    direction: Vec<f64>,
    /// b₀ on the free DOFs.
    rhs_base: Vec<f64>,
    /// Δb on the free DOFs.
    rhs_direction: Vec<f64>,
}

impl LoadPath {
    /// The path from rest along the discretization's prescribed values and loads.
    pub fn new(setup: &Setup<'_>) -> Self {
        let disc = &setup.disc;
        LoadPath {
            base: vec![0.0; 6 * disc.n_gnodes()],
            direction: (0..6 * disc.n_gnodes())
                .map(|g| disc.prescribed_value(g))
                .collect(),
            rhs_base: vec![0.0; disc.n_free()],
            rhs_direction: setup.rhs_full.clone(),
        }
    }

    /// u_c(α) of generalized DOF `g`.
    pub fn value(&self, g: usize, alpha: f64) -> f64 {
        self.base[g] + alpha * self.direction[g]
    }

    /// b(α).
    pub fn rhs(&self, alpha: f64) -> Vec<f64> {
        self.rhs_base
            .iter()
            .zip(&self.rhs_direction)
            .map(|(b, d)| b + alpha * d)
            .collect()
    }

    /// The full generalized vector for unknowns `x` at `alpha`.
    pub fn generalized(&self, disc: &Discretization, x: &[f64], alpha: f64) -> Vec<f64> {
        (0..self.base.len())
            .map(|g| match disc.reduced(g) {
                Some(r) => x[r],
                None => self.value(g, alpha),
            })
            .collect()
    }

    /// A new path from the values at `alpha` of this one, changing by `direction` (per
    /// generalized DOF, zero on free ones) per unit α: its α = 0 is this one's `alpha`. The
    /// elastic load changes by the elements' products with `direction` only (a cell has no
    /// nodal loads).
    pub fn turn(&mut self, setup: &Setup<'_>, alpha: f64, direction: Vec<f64>) {
        for (b, d) in self.base.iter_mut().zip(&self.direction) {
            *b += alpha * d;
        }
        for (b, d) in self.rhs_base.iter_mut().zip(&self.rhs_direction) {
            *b += alpha * d;
        }
        self.rhs_direction = setup
            .elastic
            .prescribed_load(&setup.model, &setup.disc, &direction);
        self.direction = direction;
    }
}
