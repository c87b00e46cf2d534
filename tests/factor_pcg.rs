//! CG preconditioned by the factorization of a nearby matrix (`solver::pcg_with_factor`): after
//! a rank-k change of a symmetric positive definite matrix it converges in at most k + 1
//! iterations in exact arithmetic (a few more in floating point), and it reports, rather than
//! hides, a budget too small to converge.

use fibercell::solver::{backward_error, pcg_with_factor, CscMatrix, FillOrdering, LinearSolver};
use fibercell_faer::{CholeskyVariant, FaerCholesky};

/// The 5-point Laplacian of an m × m grid plus `shift` on the diagonal, with `bumps` added to
/// the diagonal entries listed (each a rank-one change).
fn grid(m: usize, bumps: &[(usize, f64)]) -> CscMatrix {
    let n = m * m;
    let mut t = Vec::new();
    for i in 0..m {
        for j in 0..m {
            let k = i * m + j;
            t.push((k, k, 4.1));
            if i + 1 < m {
                t.push((k, k + m, -1.0));
                t.push((k + m, k, -1.0));
            }
            if j + 1 < m {
                t.push((k, k + 1, -1.0));
                t.push((k + 1, k, -1.0));
            }
        }
    }
    t.extend(bumps.iter().map(|&(k, v)| (k, k, v)));
    CscMatrix::from_triplets(n, n, &t).expect("valid triplets")
}

#[test]
fn a_rank_k_change_converges_in_k_plus_one_iterations() {
    let m = 40;
    let a0 = grid(m, &[]);
    let mut factor = FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::Amd);
    factor.analyze(a0.as_ref()).expect("analyze");
    factor.factorize(a0.as_ref()).expect("factorize");
    let b: Vec<f64> = (0..m * m).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
    for k in [0usize, 1, 3, 8] {
        // k well-separated diagonal changes: both stiffer and softer springs.
        let bumps: Vec<(usize, f64)> = (0..k)
            .map(|i| (37 + 191 * i, if i % 2 == 0 { 50.0 } else { -2.0 }))
            .collect();
        let a = grid(m, &bumps);
        let r = pcg_with_factor(&mut factor, a.as_ref(), &b, 1e-13, 100).expect("pcg");
        assert!(
            r.converged,
            "k = {k}: backward error {:e}",
            r.backward_error
        );
        // k + 1 in exact arithmetic; loss of orthogonality in floating point costs a few more
        // (measured: 0, 1, 3, 12 for k = 0, 1, 3, 8).
        assert!(
            r.iterations <= k + 1 + k / 2,
            "k = {k}: {} iterations, expected about k + 1",
            r.iterations
        );
        assert!(backward_error(a.as_ref(), &r.x, &b) <= 1e-13);
    }
}

#[test]
fn a_budget_too_small_is_reported_not_hidden() {
    let m = 30;
    let a0 = grid(m, &[]);
    let mut factor = FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::Amd);
    factor.analyze(a0.as_ref()).expect("analyze");
    factor.factorize(a0.as_ref()).expect("factorize");
    let bumps: Vec<(usize, f64)> = (0..20).map(|i| (5 + 41 * i, 30.0)).collect();
    let a = grid(m, &bumps);
    let b = vec![1.0; m * m];
    let r = pcg_with_factor(&mut factor, a.as_ref(), &b, 1e-14, 3).expect("pcg");
    assert!(!r.converged);
    assert_eq!(r.iterations, 3);
    assert!(r.backward_error > 1e-14);
    assert_eq!(r.backward_error, backward_error(a.as_ref(), &r.x, &b));
}
