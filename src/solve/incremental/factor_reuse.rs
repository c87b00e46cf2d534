//! Solving a state iteration on the reference factorization A₀ with the changed contacts as a
//! low-rank correction U E Uᵀ (Sherman–Morrison–Woodbury, see `low_rank.rs`), checked and
//! corrected with the residual of the assembled matrix.

use super::assemble::System;
use super::factors::ReferenceSolve;
use super::increment::Increment;
use super::matrix_values::MatrixValues;
use super::options::{LOW_RANK_MATCH, MAX_REFINEMENTS, REUSE_ACCURACY};
use super::setup::Setup;
use super::StickSlip;
use crate::constraints::Discretization;
use crate::contact::ContactPair;
use crate::solve::low_rank::{Capacitance, ContactChange, LowRankCorrection, SparseColumn};
use crate::solve::static_solve::{backward_tolerance, check_backward_error};
use crate::Error;
use fibercell_solver::{
    backward_from_product, norm_inf, relative_from_product, CscRef, LinearSolver, SolveInfo,
    SolveReport, SolverError,
};
use nalgebra::Vector6;

/// A low-rank solve that reached the check's `tolerance`: the solution, its backward error,
/// its relative residual ‖b − Ax‖₂/‖b‖₂, the correction steps it took, and whether it stopped
/// short of the check's `target`.
pub(super) struct LowRankSolve {
    pub x: Vec<f64>,
    pub backward_error: f64,
    pub relative_residual: f64,
    pub refinements: usize,
    pub short_of_target: bool,
}

/// The solve report of a checked low-rank solution.
pub(super) fn low_rank_report(r: &LowRankSolve) -> SolveReport {
    SolveReport {
        backend: "low-rank",
        relative_residual: r.relative_residual,
        backward_error: r.backward_error,
        info: SolveInfo {
            iterations: Some(r.refinements),
            ..SolveInfo::default()
        },
    }
}

/// What a low-rank solution of one state iteration is checked against: the assembled matrix A
/// and load b, the backward error to reach (`target`) and the largest one accepted
/// (`tolerance`).
pub(super) struct ResidualCheck<'a> {
    pub a: CscRef<'a>,
    pub symmetric: bool,
    pub b: &'a [f64],
    pub target: f64,
    pub tolerance: f64,
}

/// Corrects `first`, a solution of A x = b by the low-rank correction `cap` of the reference
/// factorization `a0`, with the residual of the assembled A until the backward error is at
/// most the check's target, or [`MAX_REFINEMENTS`] steps were taken; `None` when it is then
/// above the check's tolerance (or the capacitance matrix is singular).
pub(super) fn refine_low_rank(
    low_rank: &LowRankCorrection,
    a0: &mut dyn LinearSolver,
    cap: &Capacitance,
    check: &ResidualCheck<'_>,
    first: Result<Vec<f64>, SolverError>,
) -> Result<Option<LowRankSolve>, SolverError> {
    let ResidualCheck {
        a,
        symmetric,
        b,
        target,
        tolerance,
    } = *check;
    let Ok(mut x) = first else {
        return Ok(None);
    };
    let mut ax = vec![0.0; b.len()];
    let mut norm_a = None;
    for refinements in 0..=MAX_REFINEMENTS {
        let norm_a = *norm_a.get_or_insert_with(|| {
            if symmetric {
                a.mul_vec_symmetric_norm_par(&x, &mut ax)
            } else {
                a.mul_vec(&x, &mut ax);
                norm_inf(a)
            }
        });
        if refinements > 0 {
            if symmetric {
                a.mul_vec_symmetric_par(&x, &mut ax);
            } else {
                a.mul_vec(&x, &mut ax);
            }
        }
        let backward_error = backward_from_product(norm_a, &ax, &x, b);
        if !backward_error.is_finite() {
            return Ok(None);
        }
        let last = refinements == MAX_REFINEMENTS;
        if backward_error <= target || (last && backward_error <= tolerance) {
            return Ok(Some(LowRankSolve {
                relative_residual: relative_from_product(&ax, b),
                x,
                backward_error,
                refinements,
                short_of_target: backward_error > target,
            }));
        }
        if last {
            break;
        }
        let r: Vec<f64> = b.iter().zip(&ax).map(|(p, q)| p - q).collect();
        let Ok(dx) = low_rank.solve(a0, cap, &r) else {
            return Ok(None);
        };
        x.iter_mut().zip(&dx).for_each(|(xi, d)| *xi += d);
    }
    Ok(None)
}

/// The rows of `pair`'s block on free DOFs: (row in the block, free DOF).
pub(super) fn free_rows<'a>(
    pair: &'a ContactPair,
    disc: &'a Discretization,
) -> impl Iterator<Item = (usize, usize)> + 'a {
    (0..pair.size()).filter_map(move |r| {
        disc.reduced(6 * pair.jump.nodes[r / 6] + r % 6)
            .map(|i| (r, i))
    })
}

/// The column of U for basis row `k` of `pair`'s jump basis in the free DOFs.
pub(super) fn low_rank_column(pair: &ContactPair, disc: &Discretization, k: usize) -> SparseColumn {
    let g = pair.jump_basis()[k];
    let mut col: SparseColumn = free_rows(pair, disc).map(|(r, i)| (i, g[r])).collect();
    col.sort_unstable_by_key(|e| e.0);
    col.dedup_by(|b, a| {
        if a.0 == b.0 {
            a.1 += b.1;
            true
        } else {
            false
        }
    });
    col.retain(|e| e.1 != 0.0);
    col
}

impl StickSlip<'_, '_, '_> {
    /// Solves `system` on the reference factorization with the changed contacts as a low-rank
    /// correction, when there is a reference and the correction is predicted cheaper than a
    /// factorization (see [`super::factors::LowRankCost`]); `None` when it is not tried or
    /// misses its accuracy (the next factorization then becomes the reference). The solution
    /// comes with its capacitance while unchecked: not in the last iteration allowed, the
    /// residual check waits until the contact states are consistent with the solution (the
    /// states in between only steer the iteration; see [`StickSlip::confirm`]).
    ///
    /// The contacts whose load alone changed are columns of U while they fit in the bound on
    /// the columns; past it, only the contacts whose block changed are, and the assembled load
    /// is solved for instead (a forward half more per solve). Once the reference has sliding
    /// contacts, their blocks mostly stay (see `contact_states::FrozenTangent`) while their
    /// loads change in every iteration: as columns they would fill the bound at once.
    pub(super) fn solve_low_rank(
        &mut self,
        inc: &mut Increment,
        system: &mut System,
        iteration: usize,
    ) -> Result<Option<(LowRankSolve, Option<Capacitance>)>, Error> {
        let StickSlip {
            setup,
            factors,
            matrix,
            ..
        } = self;
        let opts = &setup.opts;
        let (Some(all_changes), Some(a0), true) = (
            system.changes.as_deref(),
            factors.backends.reference.as_mut(),
            setup.n_free() > 0 && !factors.refresh_reference,
        ) else {
            return Ok(None);
        };
        let low_rank = &mut factors.low_rank;
        let fits = |changes: &[ContactChange]| {
            let (order, new) = low_rank.size_of(changes);
            (low_rank.len() + new <= opts.max_low_rank_columns).then_some(order)
        };
        let block_changes: Vec<ContactChange>;
        let (changes, order, assembled_load) = match fits(all_changes) {
            Some(order) => (all_changes, order, false),
            None => {
                block_changes = all_changes
                    .iter()
                    .filter(|c| c.changes_block())
                    .map(|c| ContactChange {
                        load: Vector6::zeros(),
                        ..*c
                    })
                    .collect();
                let Some(order) = fits(&block_changes) else {
                    factors.refresh_reference = true;
                    return Ok(None);
                };
                (&block_changes[..], order, true)
            }
        };
        let affordable = match opts.max_capacitance_order {
            Some(max) => order <= max,
            None => factors.cost.worth(order),
        };
        if !affordable {
            return Ok(None);
        }
        let locate = |e| setup.locate(e);
        let column = |c: usize, k: usize| low_rank_column(&setup.pairs[c], &setup.disc, k);
        let x0 = match factors.reference_solution.take() {
            kept if assembled_load => {
                factors.reference_solution = kept;
                low_rank
                    .extend(a0.as_mut(), changes, column)
                    .map_err(locate)?;
                None
            }
            Some(x0) => {
                low_rank
                    .extend(a0.as_mut(), changes, column)
                    .map_err(locate)?;
                Some(x0)
            }
            // b₀ = b − U Δχ, the load with every contact as in the reference: from the
            // references of two earlier increments when affine in α, else its forward half
            // along with the new columns' forward solves.
            None => {
                let (alpha, affine, rhs) = (inc.alpha, &mut factors.affine, &system.rhs);
                let mut solved_b0 = None;
                let x0 = low_rank
                    .extend_with_reference(
                        a0.as_mut(),
                        changes,
                        column,
                        |low_rank| {
                            let load = low_rank.active_load(changes);
                            let shift = low_rank.spread(changes, &load);
                            rhs.iter().zip(&shift).map(|(b, s)| b - s).collect()
                        },
                        |low_rank, b0| {
                            let known = affine.predict(alpha, b0, low_rank);
                            if known.is_none() {
                                solved_b0 = Some(b0.to_vec());
                            }
                            known
                        },
                    )
                    .map_err(locate)?;
                if let Some(b0) = solved_b0 {
                    affine.record(alpha, b0, &x0);
                }
                Some(x0)
            }
        };
        inc.low_rank_order = inc.low_rank_order.max(order);
        let started = std::time::Instant::now();
        let cap = low_rank.capacitance(changes);
        if order > 0 {
            factors.cost.lu_rate = (2.0 / 3.0 * (order as f64).powi(3)
                / started.elapsed().as_secs_f64().max(1e-9))
            .max(1e8);
        }
        inc.low_rank_bytes = inc
            .low_rank_bytes
            .max(low_rank.memory_bytes() + cap.memory_bytes());
        let first = match x0 {
            Some(x0) => {
                let load = low_rank.active_load(changes);
                let first = low_rank.solve_from(a0.as_mut(), &cap, &x0, &load);
                factors.reference_solution = Some(x0);
                first
            }
            None => low_rank.solve(a0.as_mut(), &cap, &system.rhs),
        };
        let solved = match first {
            Ok(x) if iteration < opts.max_state_iterations && x.iter().all(|v| v.is_finite()) => {
                Some((
                    LowRankSolve {
                        x,
                        backward_error: f64::NAN,
                        relative_residual: f64::NAN,
                        refinements: 0,
                        short_of_target: false,
                    },
                    Some(cap),
                ))
            }
            first => {
                let check = residual_check(setup, factors.reference_solve, matrix, system)?;
                refine_low_rank(&factors.low_rank, a0.as_mut(), &cap, &check, first)
                    .map_err(locate)?
                    .map(|r| (r, None))
            }
        };
        factors.refresh_reference = solved.as_ref().is_none_or(|(r, _)| r.short_of_target);
        inc.lap(|t| &mut t.factor_reuse);
        Ok(solved)
    }

    /// Checks an unchecked low-rank solution `x` of `system` with capacitance `cap` against
    /// the assembled matrix and corrects it; its report, `None` when it misses the accuracy
    /// (the same states are then solved again on a new reference). A corrected solution
    /// replaces the run's displacements.
    pub(super) fn confirm(
        &mut self,
        inc: &mut Increment,
        system: &mut System,
        cap: &Capacitance,
        x: Vec<f64>,
    ) -> Result<Option<(SolveReport, bool)>, Error> {
        let StickSlip {
            setup,
            factors,
            matrix,
            q,
            path,
            ..
        } = self;
        let a0 = factors
            .backends
            .reference
            .as_mut()
            .ok_or(Error::Solver(SolverError::OutOfOrder("solve", "factorize")))?;
        let check = residual_check(setup, factors.reference_solve, matrix, system)?;
        let checked = refine_low_rank(&factors.low_rank, a0.as_mut(), cap, &check, Ok(x))
            .map_err(|e| setup.locate(e))?;
        inc.lap(|t| &mut t.factor_reuse);
        let Some(r) = checked else {
            factors.refresh_reference = true;
            return Ok(None);
        };
        // Short of the reference's accuracy: the correction has drifted from a reference of
        // an earlier increment, and the same states are solved again on a new one; a reference
        // of this increment that cannot be matched is as good as its matrix allows.
        if r.short_of_target && factors.reference_solve.map(|r| r.step) != Some(inc.step) {
            factors.refresh_reference = true;
            return Ok(None);
        }
        inc.reuse_iterations += r.refinements;
        check_backward_error(&setup.opts.solve, r.backward_error, &inc.name())?;
        let refined = r.refinements > 0;
        if refined {
            *q = path.generalized(&setup.disc, &r.x, inc.alpha);
        }
        Ok(Some((low_rank_report(&r), refined)))
    }
}

/// The residual check of a low-rank solution of `system`: its assembled matrix (the values
/// brought up to date first) and load, and the accuracy of a direct solve.
fn residual_check<'s>(
    setup: &'s Setup<'_>,
    reference: Option<ReferenceSolve>,
    matrix: &'s mut MatrixValues,
    system: &'s mut System,
) -> Result<ResidualCheck<'s>, Error> {
    matrix.catch_up(
        &mut system.values_behind,
        &setup.pattern,
        &setup.pairs,
        system.changes.as_deref(),
    );
    let direct = backward_tolerance(&setup.opts.solve);
    Ok(ResidualCheck {
        a: setup.pattern.matrix(&matrix.values)?,
        symmetric: !system.nonsymmetric,
        b: &system.rhs,
        target: low_rank_target(direct, reference.map(|r| r.backward_error)),
        tolerance: REUSE_ACCURACY * direct,
    })
}

/// The backward error a low-rank solve aims at: [`LOW_RANK_MATCH`] times that of the
/// reference's own direct solve `reference`, at least ε/256 (a reference solve of a zero load
/// is exact), at most [`REUSE_ACCURACY`] times the accepted backward error of a direct solve,
/// `direct` (the most a low-rank solve may keep).
pub(super) fn low_rank_target(direct: f64, reference: Option<f64>) -> f64 {
    let loosest = REUSE_ACCURACY * direct;
    reference.map_or(loosest, |r| {
        (LOW_RANK_MATCH * r).max(f64::EPSILON / 256.0).min(loosest)
    })
}

#[cfg(test)]
mod tests {
    use super::low_rank_target;

    /// A low-rank solve aims at ten times the reference's own backward error (the L
    /// non-woven's Cholesky reached 2·10⁻¹⁹, its low-rank solves had been accepted at up to
    /// 1.4·10⁻¹⁶), at ε/256 after a reference solve of a zero load, and never at less than
    /// it may keep (10⁻⁵ of the accepted direct backward error).
    #[test]
    fn a_low_rank_solve_aims_at_its_references_accuracy() {
        let direct = 1e-10;
        assert_eq!(low_rank_target(direct, Some(2e-19)), 10.0 * 2e-19);
        assert_eq!(low_rank_target(direct, Some(0.0)), f64::EPSILON / 256.0);
        assert_eq!(low_rank_target(direct, Some(1e-15)), 1e-5 * direct);
        assert_eq!(low_rank_target(direct, None), 1e-5 * direct);
        assert!(low_rank_target(direct, Some(2e-19)) < 5e-17);
    }
}
