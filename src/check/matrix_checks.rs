//! Properties of one assembled system matrix: symmetry, positive definiteness (a Cholesky
//! factorization), and its 1-norm condition number estimated on that factorization.

use crate::solver::{inverse_norm1_estimate, CscRef, LinearSolver, SolverError};
use serde::Serialize;

/// What [`matrix_checks`] found.
#[derive(Clone, Debug, Serialize)]
pub struct MatrixChecks {
    /// Order of the matrix.
    pub n: usize,
    /// Stored entries.
    pub nnz: usize,
    /// max |a_ij − a_ji| / max |a_ij|.
    pub asymmetry: f64,
    /// Whether the Cholesky factorization succeeded (every pivot above 1e-12 of its scaled
    /// diagonal): the matrix is positive definite.
    pub positive_definite: bool,
    /// Where it failed, when it did (node, DOF and fibers of the pivot).
    pub definiteness_error: Option<String>,
    /// Estimate of κ₁(SAS) = ‖SAS‖₁ ‖(SAS)⁻¹‖₁ with S = diag(A)^-1/2 — the matrix the
    /// Cholesky backends factorize, so the conditioning the solve sees (Hager–Higham; a lower
    /// bound, usually within a factor of 3), when positive definite. Unscaled, a fiber
    /// network's κ mixes units (translations, rotations) and says little.
    pub condition_estimate: Option<f64>,
    /// Normwise backward error of a solve A x = A·1 on the factorization.
    pub backward_error: Option<f64>,
}

/// max |a_ij − a_ji| / max |a_ij| (an entry without its mirror counts whole).
pub fn asymmetry(a: CscRef<'_>) -> f64 {
    let scale = a.values().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 {
        return 0.0;
    }
    let mut worst = 0.0f64;
    for j in 0..a.ncols() {
        let (rows, vals) = a.col(j);
        for (&i, &v) in rows.iter().zip(vals) {
            let (ri, vi) = a.col(i);
            let mirror = ri.binary_search(&j).map(|k| vi[k]).unwrap_or(0.0);
            worst = worst.max((v - mirror).abs());
        }
    }
    worst / scale
}

/// Symmetry, definiteness and conditioning of `a` on `solver` (a Cholesky backend, analyzed
/// and factorized here). `locate` turns a pivot's column into the model's words.
pub fn matrix_checks(
    a: CscRef<'_>,
    solver: &mut dyn LinearSolver,
    locate: &dyn Fn(SolverError) -> crate::Error,
) -> Result<MatrixChecks, crate::Error> {
    let mut out = MatrixChecks {
        n: a.ncols(),
        nnz: a.nnz(),
        asymmetry: asymmetry(a),
        positive_definite: false,
        definiteness_error: None,
        condition_estimate: None,
        backward_error: None,
    };
    let factored = solver.analyze(a).and_then(|_| solver.factorize(a));
    match factored {
        Ok(()) => out.positive_definite = true,
        Err(e @ SolverError::NotPositiveDefinite { .. }) => {
            out.definiteness_error = Some(locate(e).to_string());
            return Ok(out);
        }
        Err(e) => return Err(locate(e)),
    }
    let ones = vec![1.0; a.ncols()];
    let mut b = vec![0.0; a.ncols()];
    a.mul_vec(&ones, &mut b);
    let (_, report) = crate::solver::solve_checked(solver, a, &b, 1).map_err(locate)?;
    out.backward_error = Some(report.backward_error);
    out.condition_estimate = Some(scaled_condition(a, solver).map_err(locate)?);
    Ok(out)
}

/// κ₁(SAS), S = diag(A)^-1/2, on the factorization of A: (SAS)⁻¹ = S⁻¹A⁻¹S⁻¹, symmetric.
fn scaled_condition(a: CscRef<'_>, solver: &mut dyn LinearSolver) -> Result<f64, SolverError> {
    let n = a.ncols();
    let mut root = vec![0.0; n];
    for (j, r) in root.iter_mut().enumerate() {
        let (rows, vals) = a.col(j);
        let d = rows.binary_search(&j).map(|k| vals[k]).unwrap_or(0.0);
        *r = d.max(0.0).sqrt();
    }
    let norm = (0..n)
        .map(|j| {
            let (rows, vals) = a.col(j);
            rows.iter()
                .zip(vals)
                .map(|(&i, v)| v.abs() / (root[i] * root[j]))
                .sum::<f64>()
        })
        .fold(0.0, f64::max);
    let inverse = inverse_norm1_estimate(n, &mut |x, _| {
        x.iter_mut().zip(&root).for_each(|(v, r)| *v *= r);
        solver.solve_in_place(x, 1)?;
        x.iter_mut().zip(&root).for_each(|(v, r)| *v *= r);
        Ok(())
    })?;
    Ok(norm * inverse)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::CscMatrix;

    /// A diagonal matrix is perfectly conditioned once scaled, however its entries differ
    /// (κ₁(SAS) = 1 for diag(1, …, 10⁻⁶, …, 1)): the scaling takes the units out.
    #[test]
    fn a_diagonal_matrix_scales_to_condition_one() {
        let n = 50;
        let t: Vec<_> = (0..n)
            .map(|i| (i, i, if i == 17 { 1e-6 } else { 1.0 }))
            .collect();
        let a = CscMatrix::from_triplets(n, n, &t).unwrap();
        let mut s = crate::solve::SolverConfig::new(crate::solve::SolverKind::FaerCholesky)
            .build()
            .unwrap();
        let c = matrix_checks(a.as_ref(), s.as_mut(), &|e| e.into()).unwrap();
        assert!(c.positive_definite);
        let k = c.condition_estimate.unwrap();
        assert!((k - 1.0).abs() <= 1e-12, "{k}");
        assert_eq!(c.asymmetry, 0.0);
    }

    /// κ₁ of the 1D Laplacian tridiag(−1, 2, −1) of order n (a constant diagonal, so SAS =
    /// A/2 and κ is unchanged): ‖A‖₁ = 4 and ‖A⁻¹‖₁ is the largest column sum of
    /// (A⁻¹)_ij = min(i,j)(n+1−max(i,j))/(n+1) (1-based), i.e. of the middle column,
    /// (n+1)²/8 for odd n. The estimate is within 1 %.
    #[test]
    fn condition_of_the_laplacian() {
        let n = 101;
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, 2.0));
            if i + 1 < n {
                t.push((i, i + 1, -1.0));
                t.push((i + 1, i, -1.0));
            }
        }
        let a = CscMatrix::from_triplets(n, n, &t).unwrap();
        let mut s = crate::solve::SolverConfig::new(crate::solve::SolverKind::FaerCholesky)
            .build()
            .unwrap();
        let c = matrix_checks(a.as_ref(), s.as_mut(), &|e| e.into()).unwrap();
        let want = 4.0 * ((n + 1) as f64).powi(2) / 8.0;
        let k = c.condition_estimate.unwrap();
        assert!((k - want).abs() <= 0.01 * want, "{k} against {want}");
    }

    /// An indefinite matrix is reported, not an error; an asymmetric one measured.
    #[test]
    fn indefinite_and_asymmetric() {
        let a = CscMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 1, -1.0)]).unwrap();
        let mut s = crate::solve::SolverConfig::new(crate::solve::SolverKind::FaerCholesky)
            .build()
            .unwrap();
        let c = matrix_checks(a.as_ref(), s.as_mut(), &|e| e.into()).unwrap();
        assert!(!c.positive_definite);
        assert!(c.definiteness_error.is_some());
        let b = CscMatrix::from_triplets(
            2,
            2,
            &[(0, 0, 4.0), (1, 1, 4.0), (0, 1, 1.0), (1, 0, 1.0 + 4e-12)],
        )
        .unwrap();
        assert!((asymmetry(b.as_ref()) - 1e-12).abs() < 1e-15);
    }
}
