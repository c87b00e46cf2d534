//! The penalty limit across twelve decades: the elastic A11 of the small generated non-woven
//! (`fixtures/cells/nonwoven_small.toml`, 274 bonded contacts) with every contact's penalties
//! scaled by s = 10⁰ … 10¹² (`[contact] penalty_scale`).
//!
//! The contacts are springs in series with the fibers, so A(s) = A∞ − C/(s + a) exactly for a
//! single spring and asymptotically for many: the error falls like 1/s. Measured (N/m):
//! 190.392 (s = 1), 199.405, 201.495, 201.767, 201.803, 201.793 (s = 10⁵); the fit through
//! s = 10, 10², 10³ gives A∞ = 201.798, a = 3.07, C = 31.3, and predicts s = 10⁴ and 10⁵ to
//! 4·10⁻⁵ and 2.6·10⁻⁵ — the round-off level (the penalty error there is C/s = 1.5·10⁻⁶ of
//! A∞ at 10⁵: round-off has taken over). From s = 10⁶ on, the stiffest contacts make pivots of
//! 10⁻¹² of their scaled diagonals and below (exactly zero from 10⁹): the Cholesky backend
//! refuses the matrix with `Error::Singular`, naming the node, DOF and fiber, instead of
//! returning garbage. `fibercell check` reports where that happens (`tests/check.rs`).

use fibercell::homogenize::elastic_abd;
use fibercell::io::read_description;
use fibercell::solve::SolveOptions;
use fibercell::Error;

fn a11(s: f64) -> Result<f64, Error> {
    let mut desc = read_description(std::path::Path::new("fixtures/cells/nonwoven_small.toml"))
        .expect("fixture reads");
    desc.contact.as_mut().expect("contact").penalty_scale = Some(s);
    let model = fibercell::Model::from_description(&desc).expect("model");
    elastic_abd(&model, &SolveOptions::default()).map(|a| a[0][0])
}

/// A∞, C and a of A(s) = A∞ − C/(s + a) through three points (a by bisection on the ratio of
/// the two differences, which decreases monotonically in a).
fn series_fit(s: [f64; 3], v: [f64; 3]) -> (f64, f64, f64) {
    let ratio = (v[1] - v[0]) / (v[2] - v[1]);
    let model_ratio =
        |a: f64| (1.0 / (s[0] + a) - 1.0 / (s[1] + a)) / (1.0 / (s[1] + a) - 1.0 / (s[2] + a));
    let (mut lo, mut hi) = (-0.9 * s[0], 1e3 * s[2]);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (model_ratio(lo) - ratio) * (model_ratio(mid) - ratio) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let a = 0.5 * (lo + hi);
    let c = (v[1] - v[0]) / (1.0 / (s[0] + a) - 1.0 / (s[1] + a));
    (v[0] + c / (s[0] + a), c, a)
}

#[test]
fn abd_converges_like_one_over_the_penalty_until_round_off_then_is_refused() {
    let a: Vec<(f64, Result<f64, Error>)> = (0..=12)
        .map(|k| (10f64.powi(k), a11(10f64.powi(k))))
        .collect();
    let ok = |k: usize| *a[k].1.as_ref().expect("solved below 10⁶");
    // Stiffer contacts, stiffer cell, up to 10³ (beyond, the steps are below round-off).
    for k in 0..3 {
        assert!(ok(k + 1) > ok(k), "A11 not increasing at s = 1e{k}");
    }
    let (limit, c, shift) = series_fit([1e1, 1e2, 1e3], [ok(1), ok(2), ok(3)]);
    // The fit is a series spring: positive compliance term and a shift of order one.
    assert!(
        c > 0.0 && shift > 0.0 && shift < 100.0,
        "C = {c}, a = {shift}"
    );
    // 1/s: the differences of successive decades shrink towards 10 (7.7 measured).
    let ratio = (ok(2) - ok(1)) / (ok(3) - ok(2));
    assert!((5.0..=10.0).contains(&ratio), "ratio {ratio}");
    // The limit is reached at 10⁴ and 10⁵ to the round-off, 10⁻⁴ (measured 4·10⁻⁵).
    for k in [4, 5] {
        let err = (ok(k) - limit).abs() / limit;
        assert!(err <= 1e-4, "s = 1e{k}: {err:e} from the limit {limit}");
    }
    // At s = 1 the contacts are still compliant: 5.7 % below the limit.
    let at_model = (limit - ok(0)) / limit;
    assert!((0.03..0.1).contains(&at_model), "{at_model}");
    // Beyond, either still within 1 % of the limit (near the pivot threshold) or refused
    // with a typed error naming the node and fibers — from 10⁹ on (zero pivots) always.
    for (k, (s, r)) in a.iter().enumerate().skip(6) {
        match r {
            Ok(v) => assert!(
                k < 9 && ((v - limit) / limit).abs() <= 1e-2,
                "s = {s:e}: {v} against the limit {limit}"
            ),
            Err(Error::Singular { fibers, .. }) => assert!(!fibers.is_empty()),
            Err(e) => panic!("s = {s:e}: {e}"),
        }
    }
}
