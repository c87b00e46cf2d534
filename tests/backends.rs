//! The solver layer on its own and through the mechanics: every backend and ordering agrees on
//! the same systems (≤ 1e-8), sprs matrices are accepted, symbolic analysis is reused, and each
//! failure is a typed error.

mod common;
use common::*;
use fibercell::solve::{solve_static, ReducedSystem, SolveOptions, SolverConfig, SolverKind};
use fibercell::solver::{
    solve_checked, CscMatrix, CscRef, FillOrdering, LinearSolver, SolverError, StopReason,
};
use fibercell::{io, Error};
use fibercell_cg::ConjugateGradient;
use fibercell_faer::{CholeskyVariant, FaerCholesky, FaerLu};
use std::path::Path;

fn direct_solvers() -> Vec<(String, Box<dyn LinearSolver>)> {
    let mut v: Vec<(String, Box<dyn LinearSolver>)> = Vec::new();
    for o in [
        FillOrdering::Auto,
        FillOrdering::Natural,
        FillOrdering::Amd,
        FillOrdering::NestedDissection,
    ] {
        for var in [CholeskyVariant::Llt, CholeskyVariant::Ldlt] {
            v.push((
                format!("faer {var:?} {}", o.name()),
                Box::new(FaerCholesky::new(var, o.clone())),
            ));
        }
        #[cfg(feature = "cholmod")]
        v.push((
            format!("cholmod {}", o.name()),
            Box::new(fibercell_cholmod::Cholmod::new(o.clone())),
        ));
    }
    v.push(("faer lu".into(), Box::new(FaerLu::new())));
    v.push(("cg".into(), Box::new(ConjugateGradient::new())));
    v
}

fn systems() -> Vec<(String, ReducedSystem)> {
    let frame = io::load_model(Path::new("fixtures/ok_frame3d.toml")).unwrap();
    let grid = build(&grid(8, 3, 0.01, 3e-4));
    vec![
        (
            "frame".into(),
            ReducedSystem::assemble(&frame, Default::default()).unwrap(),
        ),
        (
            "grid".into(),
            ReducedSystem::assemble(&grid, Default::default()).unwrap(),
        ),
    ]
}

fn reference(a: CscRef<'_>, b: &[f64]) -> Vec<f64> {
    let mut s = FaerCholesky::default();
    s.analyze(a).unwrap();
    s.factorize(a).unwrap();
    solve_checked(&mut s, a, b, 1).unwrap().0
}

#[test]
fn every_backend_and_ordering_agrees() {
    for (name, sys) in systems() {
        let a = sys.matrix().unwrap();
        let want = reference(a, &sys.rhs);
        let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut solvers = direct_solvers();
        let p = fibercell::solver::compute_ordering(a, &FillOrdering::NestedDissection).unwrap();
        solvers.push((
            "faer given".into(),
            Box::new(FaerCholesky::new(
                CholeskyVariant::Llt,
                FillOrdering::Given(p.fwd),
            )),
        ));
        solvers.push((
            "cg node blocks".into(),
            Box::new(ConjugateGradient::new().with_blocks(sys.dofs.node_block_starts())),
        ));
        for (sname, mut s) in solvers {
            s.analyze(a)
                .unwrap_or_else(|e| panic!("{sname} on {name}: {e}"));
            s.factorize(a)
                .unwrap_or_else(|e| panic!("{sname} on {name}: {e}"));
            let (x, report) = solve_checked(s.as_mut(), a, &sys.rhs, 1).unwrap();
            // The backward error, not ‖r‖/‖b‖: CG stops at a backward error of 1e-16, where
            // on the stiff grid ‖r‖/‖b‖ is still 2e-9 (its floor ε‖A‖‖x‖/‖b‖).
            assert!(
                report.backward_error < 1e-13,
                "{sname} on {name}: backward error {} (relative residual {})",
                report.backward_error,
                report.relative_residual
            );
            for (p, q) in x.iter().zip(&want) {
                assert!(
                    (p - q).abs() <= 1e-8 * scale,
                    "{sname} on {name}: {p} vs {q}"
                );
            }
        }
    }
}

/// The optional half and sparse forward solves: where a backend offers them, Wᵀ W equals
/// Bᵀ A⁻¹ B from its own full solves and lower-then-upper equals a solve (1e-10 of the scale,
/// on the frame and grid systems); elsewhere they are `Unavailable`. faer's LLᵀ must offer
/// them.
#[test]
fn half_and_sparse_forward_solves_agree_with_full_solves_or_are_unavailable() {
    for (name, sys) in systems() {
        let a = sys.matrix().unwrap();
        let n = a.ncols();
        let columns: Vec<Vec<(usize, f64)>> = vec![
            vec![(0, 1.0), (n / 2, -0.5)],
            vec![(n - 1, 2.0)],
            vec![(n / 3, 1.0), (n / 3 + 1, 1.0), (2 * n / 3, -1.0)],
        ];
        for (sname, mut s) in direct_solvers() {
            s.analyze(a).unwrap();
            s.factorize(a).unwrap();
            let must = sname.starts_with("faer Llt");
            let w = match s.forward_solve_sparse(&columns) {
                Ok(w) => w,
                Err(SolverError::Unavailable { .. }) if !must => continue,
                Err(e) => panic!("{sname} on {name}: {e}"),
            };
            let k = columns.len();
            let mut x = vec![0.0; n * k];
            for (j, col) in columns.iter().enumerate() {
                col.iter().for_each(|&(i, v)| x[j * n + i] = v);
            }
            s.solve_in_place(&mut x, k).unwrap();
            let gram = w.gram();
            let scale = gram.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for j in 0..k {
                for (i, col) in columns.iter().enumerate() {
                    let want: f64 = col.iter().map(|&(r, v)| v * x[j * n + r]).sum();
                    let got = gram[j * k + i];
                    assert!(
                        (got - want).abs() <= 1e-10 * scale,
                        "{sname} on {name}: ({i}, {j}) {got} vs {want}"
                    );
                }
            }
            let mut half = sys.rhs.clone();
            s.solve_lower_in_place(&mut half).unwrap();
            s.solve_upper_in_place(&mut half).unwrap();
            let mut full = sys.rhs.clone();
            s.solve_in_place(&mut full, 1).unwrap();
            let scale = full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (p, q) in half.iter().zip(&full) {
                assert!(
                    (p - q).abs() <= 1e-10 * scale,
                    "{sname} on {name}: {p} vs {q}"
                );
            }
        }
    }
}

#[test]
fn every_backend_through_the_mechanics() {
    let m = io::load_model(Path::new("fixtures/ok_frame3d.toml")).unwrap();
    let want = solve_static(&m, &SolveOptions::default())
        .unwrap()
        .displacements;
    for kind in SolverKind::ALL {
        let opts = SolveOptions {
            solver: kind,
            ..SolveOptions::default()
        };
        match solve_static(&m, &opts) {
            Ok(sol) => {
                assert!(kind.is_available());
                assert!(sol.summary.relative_residual < 1e-9);
                for (u, w) in sol.displacements.iter().zip(&want) {
                    for k in 0..6 {
                        assert!((u[k] - w[k]).abs() <= 1e-8 * 0.02, "{kind}");
                    }
                }
            }
            Err(Error::Solver(SolverError::Unavailable { backend, .. })) => {
                assert!(!kind.is_available());
                assert_eq!(backend, "cholmod");
            }
            Err(e) => panic!("{kind}: {e}"),
        }
    }
}

#[test]
fn sprs_matrices_are_accepted_without_fibercell() {
    let sys = &systems()[1].1;
    let a = sys.matrix().unwrap();
    let want = reference(a, &sys.rhs);
    let sp = a.to_owned().to_sprs();
    // Borrowed, zero-copy (CSC) …
    let view = sp.view();
    let borrowed = CscRef::try_from_sprs(&view).unwrap();
    // … and copied from CSR.
    let from_csr = CscMatrix::from_sprs(sp.to_csr().view()).unwrap();
    for m in [borrowed, from_csr.as_ref()] {
        let mut s = FaerCholesky::default();
        s.analyze(m).unwrap();
        s.factorize(m).unwrap();
        let (x, _) = solve_checked(&mut s, m, &sys.rhs, 1).unwrap();
        for (p, q) in x.iter().zip(&want) {
            assert!((p - q).abs() <= 1e-12 * q.abs().max(1e-9));
        }
    }
}

#[test]
fn symbolic_analysis_is_reused_and_many_rhs_solve_at_once() {
    let sys = &systems()[1].1;
    let a = sys.matrix().unwrap();
    let n = a.ncols();
    let mut s = FaerCholesky::default();
    s.analyze(a).unwrap();
    s.factorize(a).unwrap();
    let x1 = solve_checked(&mut s, a, &sys.rhs, 1).unwrap().0;
    // Same pattern, doubled values: refactorize without analyze, solution halves.
    let doubled: Vec<f64> = a.values().iter().map(|v| 2.0 * v).collect();
    let a2 = CscRef::new(n, n, a.col_ptr(), a.row_idx(), &doubled).unwrap();
    s.factorize(a2).unwrap();
    let mut b3 = Vec::new();
    for k in 1..=3 {
        b3.extend(sys.rhs.iter().map(|v| v * k as f64));
    }
    let (x3, report) = solve_checked(&mut s, a2, &b3, 3).unwrap();
    assert!(report.relative_residual < 1e-10);
    let scale = x1.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for k in 1..=3 {
        for i in 0..n {
            let want = x1[i] * k as f64 / 2.0;
            assert!((x3[(k - 1) * n + i] - want).abs() <= 1e-10 * scale * k as f64);
        }
    }
    // A different pattern is refused until analyze runs again.
    let other =
        CscMatrix::from_triplets(n, n, &(0..n).map(|i| (i, i, 1.0)).collect::<Vec<_>>()).unwrap();
    assert_eq!(
        s.factorize(other.as_ref()),
        Err(SolverError::PatternChanged)
    );
    let mut fresh = FaerCholesky::default();
    assert!(matches!(
        fresh.factorize(a),
        Err(SolverError::OutOfOrder(..))
    ));
    assert!(matches!(
        fresh.solve_in_place(&mut vec![0.0; n], 1),
        Err(SolverError::OutOfOrder(..))
    ));
}

fn block_diag_with_singular_block(blocks: usize, size: usize, bad: usize) -> CscMatrix {
    let mut t = Vec::new();
    for b in 0..blocks {
        for i in 0..size {
            for j in 0..size {
                let (gi, gj) = (b * size + i, b * size + j);
                let v = if b == bad {
                    // Rank one: v vᵀ with v = (1, 2, …): positive diagonal, singular.
                    ((i + 1) * (j + 1)) as f64
                } else if i == j {
                    size as f64 + 1.0
                } else {
                    1.0 / (1.0 + (i as f64 - j as f64).abs())
                };
                t.push((gi, gj, v));
            }
        }
    }
    CscMatrix::from_triplets(blocks * size, blocks * size, &t).unwrap()
}

#[test]
fn not_positive_definite_is_reported_at_the_right_column() {
    // Diagonal with one negative entry: column 2, whatever the ordering.
    let a = CscMatrix::from_triplets(4, 4, &[(0, 0, 1.0), (1, 1, 2.0), (2, 2, -3.0), (3, 3, 4.0)])
        .unwrap();
    #[allow(unused_mut)] // pushed to with the cholmod feature
    let mut solvers: Vec<Box<dyn LinearSolver>> = vec![
        Box::new(FaerCholesky::new(
            CholeskyVariant::Llt,
            FillOrdering::Natural,
        )),
        Box::new(FaerCholesky::new(CholeskyVariant::Ldlt, FillOrdering::Amd)),
    ];
    #[cfg(feature = "cholmod")]
    solvers.push(Box::new(fibercell_cholmod::Cholmod::new(
        FillOrdering::Natural,
    )));
    for mut s in solvers {
        s.analyze(a.as_ref()).unwrap();
        match s.factorize(a.as_ref()) {
            Err(SolverError::NotPositiveDefinite { column, .. }) => {
                assert_eq!(column, 2, "{}", s.name())
            }
            other => panic!("{}: {other:?}", s.name()),
        }
    }
    // A singular block inside larger dense blocks (simplicial and supernodal factorizations):
    // the column reported lies in the singular block.
    for (blocks, size) in [(3, 4), (6, 40)] {
        let bad = blocks / 2;
        let a = block_diag_with_singular_block(blocks, size, bad);
        for o in [FillOrdering::Natural, FillOrdering::Amd] {
            for var in [CholeskyVariant::Llt, CholeskyVariant::Ldlt] {
                let mut s = FaerCholesky::new(var, o.clone());
                s.analyze(a.as_ref()).unwrap();
                match s.factorize(a.as_ref()) {
                    Err(SolverError::NotPositiveDefinite { column, pivot }) => {
                        assert!(
                            (bad * size..(bad + 1) * size).contains(&column),
                            "{var:?} {o:?}: column {column}"
                        );
                        assert!(pivot < 1e-12);
                    }
                    other => panic!("{var:?} {o:?}: {other:?}"),
                }
            }
        }
        #[cfg(feature = "cholmod")]
        {
            let mut s = fibercell_cholmod::Cholmod::new(FillOrdering::Auto);
            s.analyze(a.as_ref()).unwrap();
            assert!(matches!(
                s.factorize(a.as_ref()),
                Err(SolverError::NotPositiveDefinite { .. } | SolverError::Singular { .. })
            ));
        }
    }
}

#[test]
fn lu_solves_nonsymmetric_systems_and_flags_zero_pivots() {
    // Nonsymmetric 3×3 with known solution x = (1, −2, 3).
    let a = CscMatrix::from_triplets(
        3,
        3,
        &[
            (0, 0, 4.0),
            (0, 1, 1.0),
            (1, 0, -2.0),
            (1, 1, 5.0),
            (1, 2, 1.0),
            (2, 1, 3.0),
            (2, 2, 6.0),
            (0, 2, 0.5),
        ],
    )
    .unwrap();
    let x = [1.0, -2.0, 3.0];
    let mut b = vec![0.0; 3];
    a.as_ref().mul_vec(&x, &mut b);
    let mut lu = FaerLu::new();
    assert!(!lu.capabilities().symmetric_only);
    lu.analyze(a.as_ref()).unwrap();
    lu.factorize(a.as_ref()).unwrap();
    let (got, report) = solve_checked(&mut lu, a.as_ref(), &b, 1).unwrap();
    assert!(report.relative_residual < 1e-14);
    for k in 0..3 {
        assert!((got[k] - x[k]).abs() < 1e-13);
    }
    // Numerically singular (row 2 = 2 · row 1): an error, not a solution.
    let s = CscMatrix::from_triplets(
        3,
        3,
        &[
            (0, 0, 1.0),
            (0, 1, 2.0),
            (1, 0, 2.0),
            (1, 1, 4.0),
            (2, 2, 1.0),
        ],
    )
    .unwrap();
    let mut lu = FaerLu::new();
    lu.analyze(s.as_ref()).unwrap();
    assert!(matches!(
        lu.factorize(s.as_ref()),
        Err(SolverError::Singular { .. })
    ));
}

#[test]
fn cg_reports_iterations_and_why_it_stopped() {
    let sys = &systems()[1].1;
    let a = sys.matrix().unwrap();
    let mut cg = ConjugateGradient::new().with_blocks(sys.dofs.node_block_starts());
    cg.analyze(a).unwrap();
    cg.factorize(a).unwrap();
    let (_, report) = solve_checked(&mut cg, a, &sys.rhs, 1).unwrap();
    assert_eq!(report.info.stop, Some(StopReason::Converged));
    assert!(report.info.iterations.unwrap() > 0);
    // The reported residual is the true one, recomputed after the recursion converged (at the
    // roundoff floor, summation order alone changes it by O(1), hence the factor 10).
    let est = report.info.residual_estimate.unwrap();
    assert!(
        est <= 10.0 * report.relative_residual && report.relative_residual <= 10.0 * est,
        "{est} vs {}",
        report.relative_residual
    );
    assert!(
        report.backward_error <= 1e-14,
        "backward error {}",
        report.backward_error
    );
    let mut short = ConjugateGradient::new().with_max_iterations(3);
    short.analyze(a).unwrap();
    short.factorize(a).unwrap();
    match short.solve_in_place(&mut sys.rhs.clone(), 1) {
        Err(SolverError::NoConvergence {
            iterations,
            residual,
            reason,
            ..
        }) => {
            assert_eq!(iterations, 3);
            assert!(residual > 0.0 && residual.is_finite());
            assert_eq!(reason, StopReason::MaxIterations);
        }
        other => panic!("{other:?}"),
    }
    // Indefinite with positive diagonal blocks: CG breaks down.
    let ind = CscMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (0, 1, 2.0), (1, 0, 2.0), (1, 1, 1.0)])
        .unwrap();
    let mut cg = ConjugateGradient::new().with_block_size(1);
    cg.analyze(ind.as_ref()).unwrap();
    cg.factorize(ind.as_ref()).unwrap();
    match cg.solve_in_place(&mut [1.0, -1.0], 1) {
        Err(SolverError::NoConvergence {
            reason: StopReason::Breakdown,
            ..
        }) => {}
        other => panic!("{other:?}"),
    }
}

#[test]
fn non_finite_inputs_are_errors() {
    let a = CscMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 1, f64::NAN)]).unwrap();
    let mut s = FaerCholesky::default();
    assert!(matches!(
        s.analyze(a.as_ref()),
        Err(SolverError::NonFinite {
            what: "matrix",
            index: 1
        })
    ));
    let a = CscMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 1, 1.0)]).unwrap();
    s.analyze(a.as_ref()).unwrap();
    s.factorize(a.as_ref()).unwrap();
    assert!(matches!(
        solve_checked(&mut s, a.as_ref(), &[1.0, f64::INFINITY], 1),
        Err(SolverError::NonFinite {
            what: "right-hand side",
            index: 1
        })
    ));
    assert!(matches!(
        solve_checked(&mut s, a.as_ref(), &[1.0], 1),
        Err(SolverError::DimensionMismatch(_))
    ));
}

#[test]
fn unavailable_backend_is_an_error_not_a_panic() {
    let r = SolverConfig::new(SolverKind::Cholmod).build();
    assert_eq!(r.is_ok(), cfg!(feature = "cholmod"));
    assert_eq!("cholmod".parse::<SolverKind>(), Ok(SolverKind::Cholmod));
    assert!("umfpack"
        .parse::<SolverKind>()
        .unwrap_err()
        .contains("umfpack"));
}

/// W: three sparse columns over rows of `a`, each entry half the square root of the diagonal.
fn low_rank(a: CscRef<'_>) -> CscMatrix {
    let n = a.nrows();
    let diag = |r: usize| {
        let (rows, vals) = a.col(r);
        rows.iter()
            .zip(vals)
            .find(|(&i, _)| i == r)
            .map_or(0.0, |(_, v)| *v)
    };
    let columns = [vec![0, n / 2], vec![5, 6], vec![n - 1]];
    let mut triplets = Vec::new();
    for (j, rows) in columns.iter().enumerate() {
        for &r in rows {
            triplets.push((r, j, 0.5 * diag(r).sqrt()));
        }
    }
    CscMatrix::from_triplets(n, columns.len(), &triplets).unwrap()
}

/// A + sign · W Wᵀ assembled explicitly.
#[cfg_attr(not(feature = "cholmod"), allow(dead_code))]
fn plus_outer(a: CscRef<'_>, w: CscRef<'_>, sign: f64) -> CscMatrix {
    let mut triplets = Vec::new();
    for j in 0..a.ncols() {
        let (rows, vals) = a.col(j);
        triplets.extend(rows.iter().zip(vals).map(|(&i, &v)| (i, j, v)));
    }
    for k in 0..w.ncols() {
        let (rows, vals) = w.col(k);
        for (&i, &u) in rows.iter().zip(vals) {
            for (&j, &v) in rows.iter().zip(vals) {
                triplets.push((i, j, sign * u * v));
            }
        }
    }
    CscMatrix::from_triplets(a.nrows(), a.ncols(), &triplets).unwrap()
}

/// A factor updated by W Wᵀ, then downdated back, solves as the refactorized matrices do
/// (1e-9 relative); a backend without the capability says so.
#[test]
fn low_rank_update_and_downdate_match_a_refactorization() {
    let (_, sys) = systems().pop().unwrap();
    let a = sys.matrix().unwrap();
    let w = low_rank(a);
    let mut faer = FaerCholesky::default();
    faer.analyze(a).unwrap();
    faer.factorize(a).unwrap();
    assert!(matches!(
        faer.update_factor(w.as_ref(), true),
        Err(SolverError::Unavailable { .. })
    ));
    #[cfg(feature = "cholmod")]
    for o in [FillOrdering::Auto, FillOrdering::NestedDissection] {
        let n = a.nrows();
        let b: Vec<f64> = (0..n).map(|i| ((i % 7) as f64 - 3.0) * 1e-3).collect();
        let updated = plus_outer(a, w.as_ref(), 1.0);
        let close = |x: &[f64], y: &[f64]| {
            let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-9 * scale)
        };
        let mut s = fibercell_cholmod::Cholmod::new(o.clone());
        s.analyze(a).unwrap();
        s.factorize(a).unwrap();
        s.update_factor(w.as_ref(), true).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&mut x, 1).unwrap();
        assert!(
            close(&x, &reference(updated.as_ref(), &b)),
            "update {}",
            o.name()
        );
        s.update_factor(w.as_ref(), false).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&mut x, 1).unwrap();
        assert!(close(&x, &reference(a, &b)), "downdate {}", o.name());
        // A new factorization drops the modification.
        s.update_factor(w.as_ref(), true).unwrap();
        s.factorize(a).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&mut x, 1).unwrap();
        assert!(close(&x, &reference(a, &b)), "refactorized {}", o.name());
        // Downdating past positive definiteness is a typed error.
        let mut big = w.clone();
        big.values_mut().iter_mut().for_each(|v| *v *= 10.0);
        let r = s.update_factor(big.as_ref(), false);
        assert!(matches!(r, Err(SolverError::NotPositiveDefinite { .. })));
        assert!(matches!(
            s.solve_in_place(&mut x, 1),
            Err(SolverError::OutOfOrder(..))
        ));
    }
}
