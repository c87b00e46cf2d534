//! Ensembles: statistics against the realizations computed one by one, failed realizations
//! reported with their seed while the others complete, and a restart that gives the
//! uninterrupted result (the killed CLI run: `cli/tests/ensemble.rs`).

use fibercell::ensemble::{run_ensemble, EnsembleOptions};
use fibercell::generate::{CellParams, FiberAmount};
use fibercell::homogenize::homogenize_elastic;
use fibercell::io::read_cell_params;
use fibercell::solve::SolveOptions;
use fibercell::Model;
use std::path::Path;

/// The small non-woven of the fixture catalog with `fibers` fibers: at 30 some seeds do not
/// percolate (2 and 4 of 1–4), at 50 all of 1–6 do.
fn small_nonwoven(fibers: usize) -> CellParams {
    let mut p = read_cell_params(Path::new("fixtures/cells/nonwoven_small.params.toml")).unwrap();
    let CellParams::Nonwoven(n) = &mut p else {
        panic!("not a non-woven")
    };
    n.amount = FiberAmount::Count { fibers };
    p
}

fn options(params: CellParams, realizations: usize) -> EnsembleOptions {
    EnsembleOptions {
        params,
        realizations,
        first_seed: 1,
        solve: SolveOptions::default(),
        curve: None,
    }
}

#[test]
fn failed_realizations_are_reported_and_the_others_give_the_statistics() {
    let params = small_nonwoven(30);
    let e = run_ensemble(&options(params.clone(), 4), None, None).unwrap();
    let failed = e.failed();
    assert_eq!(failed.iter().map(|f| f.0).collect::<Vec<_>>(), [2, 4]);
    assert!(
        failed.iter().all(|f| f.1.contains("percolate")),
        "{failed:?}"
    );
    // The ABD of seeds 1 and 3, computed directly.
    let abd = |seed: u64| {
        let d = params.with_seed(seed).generate().unwrap();
        homogenize_elastic(
            &Model::from_description(&d).unwrap(),
            &SolveOptions::default(),
        )
        .unwrap()
        .abd
    };
    let (a, b) = (abd(1), abd(3));
    // Two values: mean (a + b)/2, s = |a − b|/√2, ci95 = t₀.₉₇₅,₁ s/√2 with t = 12.706.
    for i in 0..6 {
        for j in 0..6 {
            let x = &e.abd[i][j];
            let scale = a[i][j].abs().max(b[i][j].abs());
            assert_eq!(x.n, 2);
            assert!((x.mean - 0.5 * (a[i][j] + b[i][j])).abs() <= 1e-12 * scale);
            let s = (a[i][j] - b[i][j]).abs() / 2f64.sqrt();
            assert!((x.std - s).abs() <= 1e-12 * scale);
            assert!((x.ci95 - 12.706 * s / 2f64.sqrt()).abs() <= 1e-4 * x.ci95.max(1e-300));
        }
    }
    assert_eq!(e.convergence.len(), 1);
}

#[test]
fn a_restarted_ensemble_reuses_the_stored_realizations_and_equals_a_fresh_one() {
    let dir = tempfile::tempdir().unwrap();
    let params = small_nonwoven(50);
    let first = run_ensemble(&options(params.clone(), 2), Some(dir.path()), None).unwrap();
    assert_eq!(first.reused, 0);
    let resumed = run_ensemble(&options(params.clone(), 4), Some(dir.path()), None).unwrap();
    assert_eq!(resumed.reused, 2);
    assert_eq!(resumed.realizations[..2], first.realizations[..]);
    // Realizations of other parameters are not reused.
    let other = run_ensemble(&options(small_nonwoven(60), 4), Some(dir.path()), None);
    let err = other.unwrap_err().to_string();
    assert!(err.contains("other generator parameters"), "{err}");
    let fresh = run_ensemble(&options(params, 4), None, None).unwrap();
    let abd = |e: &fibercell::ensemble::Ensemble| -> Vec<_> {
        e.realizations.iter().map(|r| r.abd).collect()
    };
    assert_eq!(abd(&resumed), abd(&fresh));
    assert_eq!(resumed.abd, fresh.abd);
    assert_eq!(resumed.convergence, fresh.convergence);
}

/// Curves in an ensemble: per point the statistics of the realizations' own curves, each as
/// the `curve` computation gives it for that seed; a store of another path is not reused.
#[test]
fn an_ensemble_with_curves_gives_per_point_statistics_of_the_realizations_curves() {
    use fibercell::ensemble::CurvePath;
    use fibercell::homogenize::{elasto_plastic_curve, CurveOptions};
    use fibercell::solve::IncrementalOptions;
    let params = small_nonwoven(50);
    let path = CurvePath {
        strain: [0.05, 0.0, 0.0, 0.0, 0.0, 0.0],
        steps: 5,
        unload: true,
    };
    let dir = tempfile::tempdir().unwrap();
    let opts = EnsembleOptions {
        curve: Some(path.clone()),
        ..options(params.clone(), 3)
    };
    let e = run_ensemble(&opts, Some(dir.path()), None).unwrap();
    assert!(e.failed().is_empty(), "{:?}", e.failed());
    let stats = e.curve.as_ref().unwrap();
    assert_eq!(
        (stats.curves, stats.points.len(), stats.component),
        (3, 15, 0)
    );
    // Each seed's curve computed directly.
    let direct: Vec<Vec<[f64; 6]>> = (1..=3)
        .map(|seed| {
            let d = params.with_seed(seed).generate().unwrap();
            let model = Model::from_description(&d).unwrap();
            let c = elasto_plastic_curve(
                &model,
                &CurveOptions {
                    strain: path.strain,
                    steps: path.steps,
                    unload: path.unload,
                    incremental: IncrementalOptions::default(),
                },
            )
            .unwrap();
            c.points.iter().map(|p| p.resultant).collect()
        })
        .collect();
    // Three values: ci95 = t₀.₉₇₅,₂ s/√3 with t = 4.303 (Abramowitz & Stegun table 26.10).
    // Two runs of one curve agree to their equilibrium residuals (≤ 1e-8), not bitwise: the
    // choice between a low-rank solve and a refactorization uses measured times.
    for (k, p) in stats.points.iter().enumerate() {
        assert_eq!(p.step, k + 1);
        // Load 1..5, unload 4..0, reload 1..5 fifths.
        let t = k as f64;
        let alpha = match t {
            _ if t < 5.0 => t + 1.0,
            _ if t < 10.0 => 9.0 - t,
            _ => t - 9.0,
        } / 5.0;
        assert!(
            (p.strain[0] - 0.05 * alpha).abs() < 1e-15,
            "{k}: {:?}",
            p.strain
        );
        for m in 0..6 {
            let v: Vec<f64> = direct.iter().map(|c| c[k][m]).collect();
            let scale = direct
                .iter()
                .flatten()
                .map(|r| r[m].abs())
                .fold(0.0, f64::max);
            let mean = v.iter().sum::<f64>() / 3.0;
            let s = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
            let x = &p.resultant[m];
            assert_eq!(x.n, 3);
            assert!(
                (x.mean - mean).abs() <= 1e-7 * scale,
                "{k} {m}: {} vs {mean}",
                x.mean
            );
            assert!(
                (x.std - s).abs() <= 1e-7 * scale,
                "{k} {m}: {} vs {s}",
                x.std
            );
            assert!((x.ci95 - 4.303 * x.std / 3f64.sqrt()).abs() <= 1e-4 * x.ci95.max(1e-300));
        }
    }
    // Sliding happened (this cell's bonds hold to ε11 ≈ 1 %): the mean's secant at the peak
    // is below the elastic slope A11, and the dissipation only grows.
    let peak = stats.points[4].resultant[0].mean;
    assert!(peak < 0.9 * e.abd[0][0].mean * 0.05, "{peak}");
    let dissipated: Vec<f64> = stats.points.iter().map(|p| p.dissipated.mean).collect();
    assert!(dissipated[4] > 0.0 && dissipated.windows(2).all(|w| w[1] >= w[0]));
    assert_eq!(stats.convergence.len(), 2);
    // The files: one row per point, one per realization and point, and the plot.
    let files = tempfile::tempdir().unwrap();
    fibercell::io::write_ensemble_files(files.path(), &e, "small").unwrap();
    let read = |name: &str| std::fs::read_to_string(files.path().join(name)).unwrap();
    let points = read("ensemble-curve.csv");
    assert_eq!(points.lines().count(), 16);
    assert!(points.starts_with("step,e11,e22,g12,k11,k22,k12,N11_mean,N11_std,N11_ci95,"));
    let curves = read("curves.csv");
    assert_eq!(curves.lines().count(), 46);
    let row: Vec<f64> = curves
        .lines()
        .nth(31)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!((row[0], row[1]), (3.0, 1.0));
    let stored = e.realizations[2].curve.as_ref().unwrap()[0];
    assert_eq!((row[2], row[8]), (stored.strain[0], stored.resultant[0]));
    assert!(read("ensemble-curve.svg").contains("95 % interval of the mean"));
    // A rerun reuses the curves; a store of another path is refused.
    let again = run_ensemble(&opts, Some(dir.path()), None).unwrap();
    assert_eq!((again.reused, &again.curve), (3, &e.curve));
    let other = EnsembleOptions {
        curve: Some(CurvePath {
            steps: 20,
            ..path.clone()
        }),
        ..options(params, 3)
    };
    let err = run_ensemble(&other, Some(dir.path()), None).unwrap_err();
    assert!(err.to_string().contains("another curve path"), "{err}");
}

/// The RVE study: at each size the ensemble of the non-woven with its fibers per unit area
/// kept, the representative size read off the intervals, a rerun that reuses every
/// realization, and sizes a fiber cannot fit refused before anything runs.
#[test]
fn an_rve_study_is_an_ensemble_per_size_at_constant_density() {
    use fibercell::ensemble::{run_rve_study, RveStudyOptions, MAIN_MODULI};
    use fibercell::generate::NonWoven;
    let CellParams::Nonwoven(base) = small_nonwoven(50) else {
        unreachable!()
    };
    let study_opts = |tolerance: f64| RveStudyOptions {
        params: base.clone(),
        sizes: vec![0.005, 0.006],
        realizations: 3,
        first_seed: 1,
        tolerance,
        solve: SolveOptions::default(),
    };
    let dir = tempfile::tempdir().unwrap();
    let study = run_rve_study(&study_opts(0.05), Some(dir.path()), None).unwrap();
    // 50 fibers on 5 × 5 mm², so 72 on 6 × 6 mm².
    let fibers = |p: &NonWoven| match p.amount {
        FiberAmount::Count { fibers } => fibers,
        _ => unreachable!(),
    };
    assert_eq!(fibers(&study.sizes[0].params), 50);
    assert_eq!(fibers(&study.sizes[1].params), 72);
    assert_eq!(study.sizes[1].params.size, [0.006, 0.006]);
    for z in &study.sizes {
        let direct = run_ensemble(
            &options(CellParams::Nonwoven(z.params.clone()), 3),
            None,
            None,
        )
        .unwrap();
        assert_eq!(z.moduli, MAIN_MODULI.map(|k| direct.abd[k][k]));
    }
    // The representative size: the smallest from which every interval is within tolerance.
    let worst = |z: usize| {
        (0..6)
            .map(|m| study.sizes[z].moduli[m].relative_ci95())
            .fold(0.0, f64::max)
    };
    let loose = run_rve_study(
        &study_opts(1.01 * worst(0).max(worst(1))),
        Some(dir.path()),
        None,
    )
    .unwrap();
    assert_eq!(loose.representative_all, Some(0.005));
    let between = 0.5 * (worst(0) + worst(1));
    let expected = (worst(1) < worst(0)).then_some(0.006);
    let mid = run_rve_study(&study_opts(between), Some(dir.path()), None).unwrap();
    assert_eq!(mid.representative_all, expected);
    assert_eq!(study.representative_all, None, "{:?}", study.representative);
    // Reruns reuse every realization of every size.
    assert!(mid.sizes.iter().all(|z| z.ensemble.reused == 3));
    let mut small = study_opts(0.05);
    small.sizes = vec![0.004, 0.006];
    let err = run_rve_study(&small, None, None).unwrap_err().to_string();
    assert!(
        err.contains("cell size 0.004 m") && err.contains("half the smaller period"),
        "{err}"
    );
    small.sizes = vec![0.006, 0.005];
    let err = run_rve_study(&small, None, None).unwrap_err().to_string();
    assert!(err.contains("increasing order"), "{err}");
}
