//! The stateful cell (the FE² kernel): a sequence of updates is the curve, states are
//! independent (also updated in parallel), a trial commits nothing, and a path that turns in
//! the all-stick range follows the elastic ABD.

use fibercell::homogenize::{elasto_plastic_curve, CurveOptions};
use fibercell::io::load_model;
use fibercell::solve::IncrementalOptions;
use fibercell::{Cell, CellResponse, CellState, Error, Model};
use rayon::prelude::*;

fn fixture() -> Model {
    load_model(std::path::Path::new("fixtures/cells/nonwoven_small.toml")).expect("fixture loads")
}

/// The cell without tangents (each costs a factorization), for the tests that do not read them.
fn cell() -> Cell {
    Cell::new(&fixture(), &IncrementalOptions::default())
        .expect("the cell sets up")
        .without_tangent()
}

fn cell_with_tangent() -> Cell {
    Cell::new(&fixture(), &IncrementalOptions::default()).expect("the cell sets up")
}

/// ε11 = 2⁻⁷ in 2⁵ increments: every strain n·2⁻¹² is exact whether written α E or
/// E₀ + α ΔE, so the updates' arithmetic is the curve's.
const E11: f64 = 1.0 / 128.0;
const STEPS: usize = 32;

fn e11(v: f64) -> [f64; 6] {
    [v, 0.0, 0.0, 0.0, 0.0, 0.0]
}

/// Updates by E/N reproduce `curve --strain e11=2⁻⁷ --steps 32` bit for bit: strains,
/// resultants, dissipation, contact counts and state iterations of every increment (the
/// curve's contacts slide from about its fifth increment on, so this covers sliding).
#[test]
fn a_sequence_of_updates_is_the_curve() {
    let model = fixture();
    let curve = elasto_plastic_curve(
        &model,
        &CurveOptions {
            strain: e11(E11),
            steps: STEPS,
            unload: false,
            incremental: IncrementalOptions::default(),
        },
    )
    .expect("the curve runs");
    let cell = Cell::new(&model, &IncrementalOptions::default()).expect("cell");
    let mut state = cell.new_state();
    for p in &curve.points {
        let r = cell
            .update(&mut state, &e11(E11 / STEPS as f64))
            .expect("update");
        assert_eq!(r.strain, p.strain, "step {}", p.step);
        assert_eq!(r.resultant, p.resultant, "step {}", p.step);
        assert_eq!(r.dissipated, p.dissipated, "step {}", p.step);
        assert_eq!((r.open, r.stick, r.slip), (p.open, p.stick, p.slip));
        assert_eq!(r.iterations, p.iterations, "step {}", p.step);
    }
    assert!(curve.points.last().is_some_and(|p| p.slip > 0));
    assert_eq!(state.updates(), STEPS);
}

/// Four states on four directions, updated in turn, in parallel and each alone, give the
/// same responses bit for bit: a state's history is its own.
#[test]
fn states_are_independent_and_update_in_parallel() {
    let cell = cell();
    let directions: Vec<[f64; 6]> = (0..4)
        .map(|k| {
            let mut d = [0.0; 6];
            d[k % 3] = if k == 3 { -1e-3 } else { 1e-3 };
            d
        })
        .collect();
    let run = |states: &mut [CellState],
               directions: &[[f64; 6]],
               parallel: bool|
     -> Vec<Vec<CellResponse>> {
        let mut out = vec![Vec::new(); states.len()];
        for _ in 0..4 {
            let step: Vec<CellResponse> = if parallel {
                states
                    .par_iter_mut()
                    .zip(directions)
                    .map(|(s, d)| cell.update(s, d).expect("update"))
                    .collect()
            } else {
                states
                    .iter_mut()
                    .zip(directions)
                    .map(|(s, d)| cell.update(s, d).expect("update"))
                    .collect()
            };
            out.iter_mut().zip(step).for_each(|(o, r)| o.push(r));
        }
        out
    };
    let mut serial: Vec<CellState> = (0..4).map(|_| cell.new_state()).collect();
    let mut parallel = serial.clone();
    let interleaved = run(&mut serial, &directions, false);
    assert_eq!(run(&mut parallel, &directions, true), interleaved);
    for (k, d) in directions.iter().enumerate() {
        let own = run(&mut [cell.new_state()], &[*d], false);
        assert_eq!(own[0], interleaved[k], "state {k}");
    }
    assert!(interleaved
        .iter()
        .any(|rs| rs.last().is_some_and(|r| r.slip > 0)));
}

/// A trial leaves the committed state as it was: the same increment committed afterwards
/// gives the trial's response to the solver's tolerances (its factorization caches differ),
/// and a failed update (a non-finite strain) changes nothing.
#[test]
fn a_trial_commits_nothing() {
    let cell = cell();
    let mut state = cell.new_state();
    for _ in 0..3 {
        cell.update(&mut state, &e11(1e-3)).expect("update");
    }
    let before = state.strain();
    let tried = cell
        .trial(&mut state, &[1e-3, 5e-4, 2e-4, 0.0, 0.0, 0.0])
        .expect("trial");
    assert_eq!(state.strain(), before);
    assert_eq!(state.updates(), 3);
    assert!(cell
        .update(&mut state, &[f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0])
        .is_err());
    assert_eq!((state.strain(), state.updates()), (before, 3));
    let done = cell
        .update(&mut state, &[1e-3, 5e-4, 2e-4, 0.0, 0.0, 0.0])
        .expect("update");
    assert_eq!(done.strain, tried.strain);
    let scale = done.resultant.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for k in 0..6 {
        let d = (done.resultant[k] - tried.resultant[k]).abs();
        assert!(d <= 1e-7 * scale, "N{k}: {d:e} of {scale:e}");
    }
    assert!(tried.slip > 0, "the trial slides: {tried:?}");
}

/// In the all-stick range the response is linear whatever the path: after e11, then e22, then
/// g12 and κ11 increments (each a new path), N = A^elas E to 1e-8 of the largest resultant,
/// A^elas from the six elastic cell problems; nothing slides or dissipates.
#[test]
fn a_turning_path_in_the_stick_range_follows_the_abd() {
    let cell = cell();
    let abd = cell.elastic().expect("elastic").abd;
    let mut state = cell.new_state();
    let mut last = None;
    for inc in [
        [2e-6, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 1e-6, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 1e-6, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 1e-3, 0.0, 0.0],
        [1e-6, 1e-6, 0.0, 0.0, 0.0, 0.0],
    ] {
        last = Some(cell.update(&mut state, &inc).expect("update"));
    }
    let r = last.expect("updates ran");
    assert_eq!(r.slip, 0);
    assert_eq!(r.dissipated, 0.0);
    let expected: Vec<f64> = (0..6)
        .map(|i| (0..6).map(|j| abd[i][j] * r.strain[j]).sum())
        .collect();
    let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (i, (got, want)) in r.resultant.iter().zip(&expected).enumerate() {
        assert!((got - want).abs() <= 1e-8 * scale, "N{i}: {got} vs {want}");
    }
}

/// A copy continues like the original to the solver's tolerances.
#[test]
fn a_clone_continues_like_the_original() {
    let cell = cell();
    let mut state = cell.new_state();
    for _ in 0..4 {
        cell.update(&mut state, &e11(1e-3)).expect("update");
    }
    let mut copy = state.clone();
    let a = cell.update(&mut state, &e11(1e-3)).expect("update");
    let b = cell.update(&mut copy, &e11(1e-3)).expect("update");
    assert_eq!(a.strain, b.strain);
    let d = (a.resultant[0] - b.resultant[0]).abs();
    assert!(d <= 1e-7 * a.resultant[0].abs(), "{d:e}");
    assert_eq!(a.slip, b.slip);
}

/// A cell with nodal loads is refused (it is driven by its strain alone).
#[test]
fn a_cell_with_loads_is_refused() {
    let mut model = fixture();
    model.loads.push(fibercell::model::Load {
        node: 0,
        dof: fibercell::model::Dof::Ux,
        value: 1.0,
    });
    let e = Cell::new(&model, &IncrementalOptions::default()).err();
    assert!(
        matches!(&e, Some(Error::InvalidOption(m)) if m.contains("[[loads]]")),
        "{e:?}"
    );
}

#[test]
fn the_cell_is_shared_across_threads() {
    fn sync<T: Sync + Send>() {}
    fn send<T: Send>() {}
    sync::<Cell>();
    send::<CellState>();
}

/// All stuck, the tangent is the elastic ABD of the six cell problems (the same matrix), to
/// 1e-8 of its largest entry: the cell's κ₁ is ≈ 1.1·10¹¹ (`fibercell check`), and the
/// elastic ABD alone moves by 1·10⁻⁹ of its largest entry between two fill-reducing orderings
/// (A11 190.3907009 with chains eliminated before METIS, 190.3907011 with the fill rule), so
/// two computations of it agree to no better than that.
#[test]
fn the_stick_tangent_is_the_elastic_abd() {
    let cell = cell_with_tangent();
    let abd = cell.elastic().expect("elastic").abd;
    let mut state = cell.new_state();
    let r = cell.update(&mut state, &e11(1e-6)).expect("update");
    assert_eq!(r.slip, 0);
    let t = r.tangent.expect("tangent");
    let scale = abd.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for (j, (tr, ar)) in t.iter().zip(&abd).enumerate() {
        for (k, (tv, av)) in tr.iter().zip(ar).enumerate() {
            assert!((tv - av).abs() <= 1e-8 * scale, "[{j}][{k}] {tv} vs {av}");
        }
    }
}

/// Sliding, the tangent is the derivative of the trial response with respect to the
/// increment: central differences with h = 10⁻⁵ in each of the six components, from a state
/// at ε11 = 3·10⁻³ (contacts sliding) and an increment (10⁻³, 2·10⁻⁴, 10⁻⁴, 0, 0, 0), agree
/// to 10⁻⁶ of the largest entry. The trials carry the state iteration's equilibrium residual
/// (1.5–9·10⁻¹⁰), which the difference amplifies by 1/h: at h = 10⁻⁶ one trial at 9·10⁻¹⁰
/// put ε11's entry 1.25·10⁻⁶ off while h = 10⁻⁷ and 10⁻⁵ gave 6·10⁻⁸; at 10⁻⁵ that noise is
/// ten times smaller and the h² terms stay below it. No contact may switch between the
/// trials, or the difference is not a derivative. Without the Coulomb slope μ p_N d nᵀ of the sliding contacts (the run's
/// fixed-point matrix) the error is 4.9·10⁻⁴; with it the tangent is nonsymmetric by
/// 1.8·10⁻⁴ of its largest entry.
#[test]
fn the_sliding_tangent_is_the_derivative_of_the_response() {
    let cell = cell_with_tangent();
    let mut state = cell.new_state();
    for _ in 0..3 {
        cell.update(&mut state, &e11(1e-3)).expect("update");
    }
    let increment = [1e-3, 2e-4, 1e-4, 0.0, 0.0, 0.0];
    let centre = cell.trial(&mut state, &increment).expect("trial");
    assert!(centre.slip > 0, "{centre:?}");
    let t = centre.tangent.expect("tangent");
    let scale = t.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let h = 1e-5;
    let mut worst = 0.0f64;
    for k in 0..6 {
        let mut plus = increment;
        let mut minus = increment;
        plus[k] += h;
        minus[k] -= h;
        let p = cell.trial(&mut state, &plus).expect("trial +h");
        let m = cell.trial(&mut state, &minus).expect("trial −h");
        assert_eq!(
            (p.open, p.stick, p.slip),
            (m.open, m.stick, m.slip),
            "a contact switched in direction {k}"
        );
        for (j, row) in t.iter().enumerate() {
            let fd = (p.resultant[j] - m.resultant[j]) / (2.0 * h);
            worst = worst.max((fd - row[k]).abs() / scale);
        }
    }
    assert!(worst <= 1e-6, "worst {worst:e}");
    let asymmetry = (0..6)
        .flat_map(|j| (0..6).map(move |k| (j, k)))
        .map(|(j, k)| (t[j][k] - t[k][j]).abs() / scale)
        .fold(0.0f64, f64::max);
    println!("tangent FD error {worst:e}, asymmetry {asymmetry:e}");
}

/// A state whose caches were released continues like one that kept them, to the solver's
/// tolerances (its next update factorizes anew), and its committed strain is unchanged.
#[test]
fn a_state_without_caches_continues_like_one_with_them() {
    let cell = cell();
    let mut kept = cell.new_state();
    for _ in 0..4 {
        cell.update(&mut kept, &e11(1e-3)).expect("update");
    }
    let mut released = kept.clone();
    released.release_caches();
    assert_eq!(released.strain(), kept.strain());
    let a = cell.update(&mut kept, &e11(1e-3)).expect("update");
    let b = cell.update(&mut released, &e11(1e-3)).expect("update");
    let d = (a.resultant[0] - b.resultant[0]).abs();
    assert!(d <= 1e-7 * a.resultant[0].abs(), "{d:e}");
    assert_eq!((a.slip, a.stick), (b.slip, b.stick));
    released.release_caches();
    let c = cell.update(&mut released, &e11(1e-3)).expect("update");
    assert!(c.resultant[0] > b.resultant[0]);
}

/// The cell's factorization at rest is every state's: a state's first update makes none of
/// its own, and a state without caches past rest (a clone) continues on it, its sliding
/// contacts a low-rank correction, like the original to the solver's tolerances. (A bound
/// on the capacitance order makes the choice between correcting and factorizing independent
/// of the machine's timings.) Without the sharing each of them factorizes once.
#[test]
fn states_solve_on_the_cells_factorization_at_rest() {
    let first = cell()
        .update(&mut cell().new_state(), &e11(1e-4))
        .expect("update");
    assert_eq!(first.factorizations, 0);
    let options = IncrementalOptions {
        max_capacitance_order: Some(100_000),
        ..IncrementalOptions::default()
    };
    let cell = Cell::new(&fixture(), &options)
        .expect("cell")
        .without_tangent();
    let mut original = cell.new_state();
    for _ in 0..4 {
        cell.update(&mut original, &e11(1e-3)).expect("update");
    }
    let mut copy = original.clone();
    let a = cell.update(&mut original, &e11(1e-3)).expect("update");
    let b = cell.update(&mut copy, &e11(1e-3)).expect("update");
    assert!(b.slip > 0, "the copy's contacts slide");
    assert_eq!(b.factorizations, 0);
    let d = (a.resultant[0] - b.resultant[0]).abs();
    assert!(d <= 1e-7 * a.resultant[0].abs(), "{d:e}");
    assert_eq!((a.slip, a.stick), (b.slip, b.stick));
}
