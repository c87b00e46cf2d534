//! The solver layer on input an outside crate may hand it: one triangle of a symmetric matrix
//! (a symmetric Matrix Market file, `scipy.sparse.tril`), a non-square matrix, out-of-range
//! indices. Every ordering and every backend answers with a typed error at once — before these
//! guards the nested-dissection orderings hung inside METIS and AMD returned a solve with a
//! residual of 1.36 as a success — and a triangle expanded explicitly solves like the full
//! matrix.

use fibercell::solve::{SolverConfig, SolverKind};
use fibercell::solver::{
    compute_ordering, solve_checked, CscMatrix, CscRef, FillOrdering, LinearSolver, SolverError,
};

/// A symmetric positive definite 1D Laplacian of order `n` with a coupling two apart, both
/// triangles stored.
fn full(n: usize) -> CscMatrix {
    let mut t = Vec::new();
    for i in 0..n {
        t.push((i, i, 6.0));
        for (d, v) in [(1, -1.0), (2, -0.5)] {
            if i + d < n {
                t.push((i, i + d, v));
                t.push((i + d, i, v));
            }
        }
    }
    CscMatrix::from_triplets(n, n, &t).expect("matrix")
}

/// The lower (`lower`) or upper triangle of `a`, diagonal included.
fn triangle(a: &CscMatrix, lower: bool) -> CscMatrix {
    let a = a.as_ref();
    let mut t = Vec::new();
    for j in 0..a.ncols() {
        let (rows, vals) = a.col(j);
        for (&i, &v) in rows.iter().zip(vals) {
            if (lower && i >= j) || (!lower && i <= j) {
                t.push((i, j, v));
            }
        }
    }
    CscMatrix::from_triplets(a.nrows(), a.ncols(), &t).expect("triangle")
}

fn orderings() -> Vec<FillOrdering> {
    vec![
        FillOrdering::Auto,
        FillOrdering::Amd,
        FillOrdering::NestedDissection,
        FillOrdering::Natural,
    ]
}

/// Every symmetric backend of this build with every ordering.
fn symmetric_solvers() -> Vec<(String, Box<dyn LinearSolver>)> {
    let mut out = Vec::new();
    for kind in SolverKind::ALL {
        if !kind.is_available() || kind == SolverKind::FaerLu {
            continue;
        }
        for ordering in orderings() {
            let config = SolverConfig {
                kind,
                ordering: ordering.clone(),
                ..SolverConfig::default()
            };
            out.push((
                format!("{kind} {}", ordering.name()),
                config.build().expect("backend"),
            ));
        }
    }
    out
}

#[test]
fn one_triangle_is_refused_by_every_ordering_and_symmetric_backend() {
    let a = full(400);
    for lower in [true, false] {
        let t = triangle(&a, lower);
        for o in [
            FillOrdering::Amd,
            FillOrdering::NestedDissection,
            FillOrdering::Auto,
        ] {
            let e = compute_ordering(t.as_ref(), &o).expect_err("a triangle is refused");
            assert!(
                matches!(e, SolverError::NotStructurallySymmetric { .. }),
                "{o:?}: {e}"
            );
        }
        for (name, mut s) in symmetric_solvers() {
            let e = s.analyze(t.as_ref()).expect_err("a triangle is refused");
            assert!(
                matches!(e, SolverError::NotStructurallySymmetric { .. }),
                "{name}: {e}"
            );
            assert!(e.to_string().contains("both triangles"), "{name}: {e}");
        }
    }
}

/// faer LU takes a triangle as the nonsymmetric (triangular) matrix it is and solves it.
#[test]
fn lu_solves_a_triangle_as_the_triangular_matrix_it_is() {
    let t = triangle(&full(300), true);
    let mut lu = SolverConfig::new(SolverKind::FaerLu).build().expect("lu");
    lu.analyze(t.as_ref()).expect("analyze");
    lu.factorize(t.as_ref()).expect("factorize");
    let b: Vec<f64> = (0..300).map(|i| (i as f64 * 0.37).sin()).collect();
    let (_, report) = solve_checked(lu.as_mut(), t.as_ref(), &b, 1).expect("solve");
    assert!(report.backward_error <= 1e-15, "{}", report.backward_error);
}

#[test]
fn an_expanded_triangle_solves_like_the_full_matrix() {
    let a = full(200);
    let b: Vec<f64> = (0..200).map(|i| 1.0 + (i % 7) as f64).collect();
    for lower in [true, false] {
        let expanded =
            CscMatrix::symmetric_from_triangle(triangle(&a, lower).as_ref()).expect("expand");
        assert_eq!(expanded, a, "lower = {lower}");
    }
    let e = CscMatrix::symmetric_from_triangle(
        CscMatrix::from_triplets(2, 2, &[(0, 1, 1.0), (1, 0, 2.0)])
            .expect("matrix")
            .as_ref(),
    );
    assert!(matches!(e, Err(SolverError::InvalidMatrix(_))), "{e:?}");
    for (name, mut s) in symmetric_solvers() {
        s.analyze(a.as_ref()).expect("analyze");
        s.factorize(a.as_ref()).expect("factorize");
        let (_, report) = solve_checked(s.as_mut(), a.as_ref(), &b, 1).expect("solve");
        // CG stops at ‖r‖/‖b‖ ≤ 1e-12 on this well-conditioned matrix.
        let tol = if name.starts_with("cg") { 1e-11 } else { 1e-14 };
        assert!(
            report.backward_error <= tol,
            "{name}: {}",
            report.backward_error
        );
    }
}

#[test]
fn a_non_square_matrix_is_refused_everywhere() {
    // 3 × 2: rows 0..3, columns 0..2.
    let m = CscMatrix::from_triplets(3, 2, &[(0, 0, 1.0), (2, 1, 1.0)]).expect("matrix");
    for o in orderings() {
        let e = compute_ordering(m.as_ref(), &o).expect_err("refused");
        assert!(matches!(e, SolverError::DimensionMismatch(_)), "{o:?}: {e}");
    }
    for (name, mut s) in symmetric_solvers() {
        let e = s.analyze(m.as_ref()).expect_err("refused");
        assert!(
            matches!(e, SolverError::DimensionMismatch(_)),
            "{name}: {e}"
        );
    }
    let mut lu = SolverConfig::new(SolverKind::FaerLu).build().expect("lu");
    let e = lu.analyze(m.as_ref()).expect_err("refused");
    assert!(
        matches!(e, SolverError::DimensionMismatch(_)),
        "faer-lu: {e}"
    );
}

#[test]
fn out_of_range_and_unsorted_indices_never_reach_a_backend() {
    let e = CscRef::new(3, 3, &[0, 1, 2, 3], &[0, 5, 2], &[1.0; 3]).expect_err("row 5 of 3");
    assert!(matches!(e, SolverError::InvalidMatrix(_)) && e.to_string().contains("out of range"));
    let e = CscMatrix::new(3, 3, vec![0, 1, 2, 7], vec![0, 1, 2], vec![1.0; 3])
        .expect_err("pointer past the end");
    assert!(matches!(e, SolverError::InvalidMatrix(_)), "{e}");
    let e = CscMatrix::from_triplets(3, 3, &[(0, 0, 1.0), (3, 1, 1.0)]).expect_err("row 3 of 3");
    assert!(matches!(e, SolverError::InvalidMatrix(_)), "{e}");
}
