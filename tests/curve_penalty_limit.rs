//! The penalty limit of the friction curve: with every contact's penalties scaled by s
//! (`[contact] penalty_scale`), the resultant at ε11 = 1 % of the small generated non-woven
//! converges to the rigid-contact limit as the penalties grow, its error falling like 1/s.
//!
//! Measured (50 increments, N11 in N/m): s = 1, 2, 4, 8, 16, 32, 64, 128 give 1.43209,
//! 1.45118, 1.46487, 1.47420, 1.48006, 1.48339, 1.48522, 1.48616. The differences between
//! successive doublings shrink by 1.39, 1.47, 1.59, 1.76, 1.82, 1.95: an error ∝ 1/s halves
//! with each doubling (ratio 2), one ∝ s^(−1/2) would shrink by 1.41. So the asymptotic 1/s
//! range starts near s = 8; at the default penalties (s = 1: p_N = 1000 × 12EI/L³ of the
//! elements in contact) the contacts are still compliant against the fibers' axial stiffness
//! (EA/L ≈ L²/(3r²) × 12EI/L³ ≈ 120 × 12EI/L³ here), and N11 lies 3.7 % below the
//! Richardson-extrapolated limit 1.4871. The elastic A11 behaves alike (190.4 at s = 1, limit
//! 201.8).

use fibercell::homogenize::{elasto_plastic_curve, CurveOptions};
use fibercell::io::read_description;
use fibercell::solve::IncrementalOptions;

/// N11 at ε11 = 1 % (50 increments) with the penalties scaled by `s`.
fn n11_at_one_percent(s: f64) -> f64 {
    let mut desc = read_description(std::path::Path::new("fixtures/cells/nonwoven_small.toml"))
        .expect("fixture reads");
    desc.contact.as_mut().expect("contact").penalty_scale = Some(s);
    let model = fibercell::Model::from_description(&desc).expect("model");
    let c = elasto_plastic_curve(
        &model,
        &CurveOptions {
            strain: [0.01, 0.0, 0.0, 0.0, 0.0, 0.0],
            steps: 50,
            unload: false,
            incremental: IncrementalOptions::default(),
        },
    )
    .expect("the curve runs");
    let last = c.points.last().expect("points");
    assert!(last.slip > 100, "s = {s}: {} sliding", last.slip);
    last.resultant[0]
}

#[test]
fn the_stress_converges_like_one_over_the_penalty() {
    let scales = [8.0, 16.0, 32.0, 64.0];
    let n: Vec<f64> = scales.iter().map(|&s| n11_at_one_percent(s)).collect();
    // Stiffer contacts, stiffer mat: N11 grows toward the limit.
    assert!(n.windows(2).all(|w| w[1] > w[0]), "{n:?}");
    let d: Vec<f64> = n.windows(2).map(|w| w[1] - w[0]).collect();
    let ratios: Vec<f64> = d.windows(2).map(|w| w[0] / w[1]).collect();
    // 1/s: each doubling halves the error (measured 1.76 and 1.82, rising toward 2); an error
    // ∝ s^(−1/2) would give 1.41, ∝ s^(−2) 4.
    for r in &ratios {
        assert!((1.6..=2.3).contains(r), "ratios {ratios:?} of {n:?}");
    }
    assert!(
        ratios[1] >= ratios[0],
        "ratios {ratios:?} approach 2 from below"
    );
    // Richardson with the last ratio: the limit, and the error at s = 64 against it.
    let r = ratios[1];
    let limit = n[3] + d[2] / (r - 1.0);
    assert!(
        (limit - n[3]) / limit < 3e-3,
        "limit {limit}, N11(64) {}",
        n[3]
    );
    assert!(
        (limit - n[0]) / limit < 1.5e-2,
        "limit {limit}, N11(8) {}",
        n[0]
    );
}

/// `penalty_scale` multiplies every contact's default penalties: s = 2 doubles p_N, p_T and
/// p_R of each pair exactly, and a non-positive or non-finite scale is a typed error naming it.
#[test]
fn the_penalty_scale_multiplies_every_penalty() {
    let path = std::path::Path::new("fixtures/cells/nonwoven_small.toml");
    let desc = read_description(path).expect("fixture reads");
    let pairs = |s: Option<f64>| {
        let mut d = desc.clone();
        d.contact.as_mut().expect("contact").penalty_scale = s;
        let model = fibercell::Model::from_description(&d).expect("model");
        fibercell::contact::ContactSet::build(&model)
            .expect("set")
            .pairs
    };
    let (one, two) = (pairs(None), pairs(Some(2.0)));
    assert!(!one.is_empty());
    for (a, b) in one.iter().zip(&two) {
        assert_eq!(2.0 * a.penalty_normal, b.penalty_normal);
        assert_eq!(2.0 * a.penalty_tangent, b.penalty_tangent);
        assert_eq!(2.0 * a.penalty_rotation, b.penalty_rotation);
    }
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let mut d = desc.clone();
        d.contact.as_mut().expect("contact").penalty_scale = Some(bad);
        let e = fibercell::Model::from_description(&d).expect_err("rejected");
        assert!(e.to_string().contains("penalty_scale"), "{e}");
    }
}
