//! Solving a state iteration directly: a factorization of the assembled matrix (unless the
//! same states were factorized last), which becomes the reference of the low-rank solves when
//! the first symmetric one or when the correction outgrew its columns or accuracy.

use super::assemble::System;
use super::contact_states::ContactStates;
use super::driver_couplings::DriverCouplings;
use super::factors::{ReferenceBlock, ReferenceSolve};
use super::increment::Increment;
use super::options::MAX_BESIDE_FACTOR_BYTES;
use super::StickSlip;
use crate::contact::Friction;
use crate::solve::low_rank::Reference;
use crate::solve::{SolverConfig, SolverKind};
use crate::Error;
use fibercell_solver::{solve_checked, SolveReport, SolverError};

impl StickSlip<'_, '_, '_> {
    /// Factorizes `system` if needed and solves it: the solution and its report (none without
    /// unknowns).
    pub(super) fn solve_direct(
        &mut self,
        inc: &mut Increment,
        system: &mut System,
    ) -> Result<(Vec<f64>, Option<SolveReport>), Error> {
        let StickSlip {
            setup,
            contacts,
            factors,
            matrix,
            on_all_stick,
            ..
        } = self;
        let locate = |e| setup.locate(e);
        let n_free = setup.n_free();
        matrix.catch_up(
            &mut system.values_behind,
            &setup.pattern,
            &setup.pairs,
            system.changes.as_deref(),
        );
        let a = setup.pattern.matrix(&matrix.values)?;
        let nonsymmetric = system.nonsymmetric;
        // The first symmetric factorization, or the next after the correction outgrew its
        // columns or its accuracy, becomes the reference (in its own solver); so does any
        // other when a second factor beside the reference is not worth its memory.
        let beside_allowed = factors.low_rank.len() > 0
            && factors
                .factor_bytes
                .is_none_or(|b| b <= MAX_BESIDE_FACTOR_BYTES);
        let make_reference = !nonsymmetric
            && setup.low_rank_possible
            && n_free > 0
            && (factors.reference.is_none() || factors.refresh_reference || !beside_allowed);
        let backends = &mut factors.backends;
        if make_reference {
            // The old reference's correction and a factor beside it go before the new
            // factorization allocates.
            backends.symmetric = None;
            if factors.factorized.as_ref().is_some_and(|key| !key.0) {
                factors.factorized = None;
            }
            factors.low_rank.reset();
            factors.affine.clear();
            factors.reference_solution = None;
        }
        // A direct symmetric solver beside the reference works on the reference's analysis
        // (the pattern is the same): no second ordering, symbolic factor or lower pattern.
        let beside_reference = (!nonsymmetric && !make_reference && backends.symmetric.is_none())
            .then(|| backends.reference.as_ref().and_then(|r| r.share()))
            .flatten();
        let (slot, kind) = if nonsymmetric {
            (&mut backends.general, SolverKind::FaerLu)
        } else if make_reference {
            (&mut backends.reference, setup.opts.solve.solver)
        } else {
            (&mut backends.symmetric, setup.opts.solve.solver)
        };
        if slot.is_none() && !nonsymmetric {
            // The cell's shared analysis, when there is one.
            let shared = setup.shared.as_ref();
            *slot = shared.and_then(|s| s.solver()).or(beside_reference);
            if factors.factor_bytes.is_none() {
                factors.factor_bytes = shared.and_then(|s| s.factor_bytes());
            }
        }
        if slot.is_none() {
            let mut s = SolverConfig {
                kind,
                ..setup.solver_config.clone()
            }
            .build()?;
            let info = s.analyze(a).map_err(locate)?;
            // The ordering's and symbolic factorization's workspace.
            crate::free_memory::release_free_memory();
            if !nonsymmetric {
                factors.factor_bytes = info.factor_bytes;
            }
            *slot = Some(s);
        }
        let solver = slot
            .as_mut()
            .ok_or(Error::Solver(SolverError::OutOfOrder("solve", "analyze")))?;
        let (directions, k_perp) = (0..contacts.states.len())
            .map(|i| {
                let b = contacts.block(i);
                (b.direction, b.k_perp)
            })
            .unzip();
        let key = (nonsymmetric, contacts.states.clone(), directions, k_perp);
        inc.lap(|t| &mut t.factorize);
        let mut refactorized = false;
        if make_reference || factors.factorized.as_ref() != Some(&key) {
            let started = std::time::Instant::now();
            // A reference at rest is the cell's shared factorization (the same values).
            let shared = setup
                .shared
                .as_ref()
                .filter(|s| make_reference && s.is_of(&matrix.values));
            match shared.and_then(|s| Some((s.solver()?, s.factorize_seconds()))) {
                Some((rest, seconds)) => {
                    *solver = rest;
                    factors.cost.factorize = Some(seconds);
                }
                None => {
                    solver.factorize(a).map_err(locate)?;
                    inc.factorizations += 1;
                    if !nonsymmetric {
                        factors.cost.factorize = Some(started.elapsed().as_secs_f64());
                    }
                }
            }
            if !make_reference {
                factors.factorized = Some(key);
            } else {
                factors.refresh_reference = false;
                factors.reference = Some(reference_blocks(setup, contacts));
                refactorized = true;
            }
            // The initial states are all-stick unless frictionless (sliding).
            let friction = setup.friction();
            if !nonsymmetric
                && friction != Friction::None
                && contacts
                    .states
                    .iter()
                    .zip(&setup.pairs)
                    .all(|(s, p)| *s == ContactStates::initial(p, friction))
            {
                if let Some(hook) = on_all_stick.take() {
                    let couplings = DriverCouplings::of(setup, contacts);
                    hook(solver.as_mut(), a, couplings.as_ref())?;
                }
            }
            inc.lap(|t| &mut t.factorize);
        }
        if n_free == 0 {
            return Ok((Vec::new(), None));
        }
        let (x, r) = solve_checked(solver.as_mut(), a, &system.rhs, 1).map_err(locate)?;
        if refactorized {
            matrix.set_reference();
            // The reference's own load: A₀⁻¹ b₀ of this increment.
            factors.reference_solution = Some(Reference::Full(x.clone()));
            factors.reference_solve = Some(ReferenceSolve {
                step: inc.step,
                backward_error: r.backward_error,
            });
        }
        Ok((x, Some(r)))
    }
}

/// Every contact's block as the reference factorization has it.
pub(super) fn reference_blocks(
    setup: &super::setup::Setup<'_>,
    contacts: &ContactStates,
) -> Vec<ReferenceBlock> {
    (0..setup.pairs.len())
        .map(|i| {
            let state = contacts.block(i);
            ReferenceBlock {
                stiffness: setup.pairs[i].block_coefficients(
                    &state,
                    contacts.friction_of(i),
                    setup.stabilization,
                ),
                state,
                friction: contacts.friction_of(i),
                anchor: contacts.perpendicular[i].1,
                slip: contacts.slips[i],
                offset: contacts.frozen_offset(i),
            }
        })
        .collect()
}
