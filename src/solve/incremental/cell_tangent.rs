//! The consistent tangent of a converged stick/slip state for a macro-scale Newton iteration
//! (FE²): dN/dE · area = K_EE − K_Ef K_ff⁻¹ K_fE (thesis 5.5) on the tangent matrix of the
//! state — its contacts' states, slip directions and k⊥ held, and a Coulomb contact sliding in
//! compression with its bound's slope, μ p_N d nᵀ (the bound c + μ N follows the normal force;
//! the run's fixed point on the bounds leaves that term out of its matrices). The six cell
//! problems on it are solved on the state's reference factorization with the tangent's blocks
//! as a low-rank correction (a nonsymmetric one while Coulomb contacts slide), checked by the
//! residual of the tangent matrix; without a reference, or when that correction would cost
//! more than a factorization, the tangent matrix is factorized itself (by LU when
//! nonsymmetric).

use super::driver_couplings::DriverCouplings;
use super::factor_reuse::{low_rank_column, refine_low_rank, ResidualCheck};
use super::factors::TangentSolver;
use super::options::REUSE_ACCURACY;
use super::run_state::RunState;
use super::setup::Setup;
use crate::contact::{BlockCoefficients, ContactState, Friction};
use crate::solve::low_rank::ContactChange;
use crate::solve::static_solve::{backward_tolerance, check_backward_error};
use crate::solve::{SolverConfig, SolverKind};
use crate::Error;
use fibercell_solver::{solve_checked, CscRef, SolverError};
use nalgebra::Vector6;

/// dN/dE times the cell area: rows N11, N22, N12, M11, M22, M12; columns the strains.
pub(crate) type Tangent = [[f64; 6]; 6];

impl RunState {
    /// The consistent tangent (times the area) at the state's converged contact states.
    pub fn tangent(&mut self, setup: &Setup<'_>) -> Result<Tangent, Error> {
        let blocks: Vec<BlockCoefficients> = (0..setup.pairs.len())
            .map(|i| {
                setup.pairs[i].block_coefficients(
                    &self.contacts.consistent_block(i),
                    self.tangent_friction(setup, i),
                    setup.stabilization,
                )
            })
            .collect();
        let nonsymmetric = blocks.iter().any(|d| *d != d.transpose());
        let (pairs, disc) = (&setup.pairs, &setup.disc);
        let mut values = Vec::new();
        setup.elastic_values(&mut values)?;
        setup
            .contact_columns
            .add(pairs, &setup.pattern, disc, &mut values, None, |i| {
                pairs[i].block_of(&blocks[i])
            });
        let columns = DriverCouplings::with_blocks(setup, |i| pairs[i].block_of(&blocks[i]))
            .ok_or(Error::InvalidOption(
                "the cell has no macroscopic driver".into(),
            ))?;
        let rows =
            DriverCouplings::with_blocks(setup, |i| pairs[i].block_of(&blocks[i].transpose()))
                .ok_or(Error::InvalidOption(
                    "the cell has no macroscopic driver".into(),
                ))?;
        let a = setup.pattern.matrix(&values)?;
        let n = disc.n_free();
        let rhs: Vec<f64> = (0..6)
            .flat_map(|k| columns.coupling.iter().map(move |c| -c[k]))
            .collect();
        let mut x = vec![0.0; 6 * n];
        if n > 0 {
            if let Some(solved) = self.tangent_low_rank(setup, &blocks, a, nonsymmetric, &rhs)? {
                x = solved;
            } else {
                x = self.tangent_direct(setup, a, nonsymmetric, &rhs)?;
            }
        }
        Ok(std::array::from_fn(|j| {
            std::array::from_fn(|k| {
                let schur: f64 = (0..n).map(|i| rows.coupling[i][j] * x[k * n + i]).sum();
                columns.k_ee[(j, k)] + schur
            })
        }))
    }

    /// The six cell problems on the tangent matrix `a` solved on the state's reference
    /// factorization, the tangent's blocks as a low-rank correction of it (on a copy of the
    /// state's columns, so that its increments are not changed), each solution corrected
    /// with the residual of `a` to the reuse accuracy; None without a reference, or when the
    /// correction is too large or misses its accuracy.
    fn tangent_low_rank(
        &mut self,
        setup: &Setup<'_>,
        blocks: &[BlockCoefficients],
        a: CscRef<'_>,
        nonsymmetric: bool,
        rhs: &[f64],
    ) -> Result<Option<Vec<f64>>, Error> {
        let factors = &mut self.factors;
        let (Some(reference), Some(a0)) = (
            factors.reference.as_deref(),
            factors.backends.reference.as_mut(),
        ) else {
            return Ok(None);
        };
        let changes: Vec<ContactChange> = blocks
            .iter()
            .zip(reference)
            .enumerate()
            .map(|(contact, (d, r))| ContactChange {
                contact,
                stiffness: d - r.stiffness,
                load: Vector6::zeros(),
            })
            .filter(ContactChange::is_change)
            .collect();
        let mut low_rank = factors.low_rank.clone();
        let (order, new) = low_rank.size_of(&changes);
        if low_rank.len() + new > setup.opts.max_low_rank_columns || !factors.cost.worth(order) {
            return Ok(None);
        }
        let locate = |e| setup.locate(e);
        let column = |c: usize, k: usize| low_rank_column(&setup.pairs[c], &setup.disc, k);
        low_rank
            .extend(a0.as_mut(), &changes, column)
            .map_err(locate)?;
        let cap = low_rank.capacitance(&changes);
        let n = setup.n_free();
        let mut x = Vec::with_capacity(6 * n);
        for b in rhs.chunks(n) {
            let first = low_rank.solve(a0.as_mut(), &cap, b);
            let check = ResidualCheck {
                a,
                symmetric: !nonsymmetric,
                b,
                target: REUSE_ACCURACY * backward_tolerance(&setup.opts.solve),
                tolerance: REUSE_ACCURACY * backward_tolerance(&setup.opts.solve),
            };
            match refine_low_rank(&low_rank, a0.as_mut(), &cap, &check, first).map_err(locate)? {
                Some(solved) => x.extend(solved.x),
                None => return Ok(None),
            }
        }
        Ok(Some(x))
    }

    /// The six cell problems on a factorization of the tangent matrix `a` itself.
    fn tangent_direct(
        &mut self,
        setup: &Setup<'_>,
        a: CscRef<'_>,
        nonsymmetric: bool,
        rhs: &[f64],
    ) -> Result<Vec<f64>, Error> {
        let tangent = self.tangent_solver(setup, nonsymmetric)?;
        let locate = |e| setup.locate(e);
        if !tangent.analyzed {
            tangent.solver.analyze(a).map_err(locate)?;
            tangent.analyzed = true;
        }
        tangent.solver.factorize(a).map_err(locate)?;
        let (x, report) = solve_checked(tangent.solver.as_mut(), a, rhs, 6).map_err(locate)?;
        check_backward_error(
            &setup.opts.solve,
            report.backward_error,
            "the cell's tangent",
        )?;
        Ok(x)
    }

    /// The friction contact i's tangent block is built with: a Coulomb contact sliding in
    /// compression (its bound above the cohesion) as Coulomb, one in tension at its cohesion
    /// (Tresca), other laws as they are.
    fn tangent_friction(&self, setup: &Setup<'_>, i: usize) -> Friction {
        match setup.friction() {
            Friction::Coulomb { cohesion, .. }
                if self.contacts.states[i] == ContactState::Slip
                    && !self.contacts.in_compression(i) =>
            {
                Friction::Tresca { bound: cohesion }
            }
            friction => friction,
        }
    }

    /// The tangent's solver: LU when `nonsymmetric`, else the run's symmetric backend; kept
    /// (analyzed once) while the symmetry stays.
    fn tangent_solver(
        &mut self,
        setup: &Setup<'_>,
        nonsymmetric: bool,
    ) -> Result<&mut TangentSolver, Error> {
        let slot = &mut self.factors.backends.tangent;
        if slot.as_ref().is_none_or(|t| t.nonsymmetric != nonsymmetric) {
            let kind = if nonsymmetric {
                SolverKind::FaerLu
            } else {
                setup.opts.solve.solver
            };
            let solver = SolverConfig {
                kind,
                ..setup.solver_config.clone()
            }
            .build()?;
            *slot = Some(TangentSolver {
                nonsymmetric,
                solver,
                analyzed: false,
            });
        }
        slot.as_mut()
            .ok_or(Error::Solver(SolverError::OutOfOrder("solve", "analyze")))
    }
}
