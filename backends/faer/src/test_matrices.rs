//! Test matrices of the solve modules' unit tests (below every one of them).

use crate::{CholeskyVariant, FaerCholesky};
use fibercell_solver::{CscMatrix, FillOrdering, LinearSolver};

/// The order, the matrix and the supernodal nested-dissection LLᵀ factor of `grid(k)`.
pub(crate) fn grid_factor(k: usize) -> (usize, CscMatrix, FaerCholesky) {
    let a = grid(k);
    let mut s = FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::NestedDissection);
    s.analyze(a.as_ref()).unwrap();
    s.factorize(a.as_ref()).unwrap();
    (k * k * k, a, s)
}

/// A k³ grid Laplacian with edge weights and diagonal scales spread over four decades.
pub(crate) fn grid(k: usize) -> CscMatrix {
    let id = |x: usize, y: usize, z: usize| (x * k + y) * k + z;
    let weight = |a: usize, b: usize| 1.0 + ((a * 7919 + b * 104_729) % 97) as f64 / 10.0;
    let scale = |a: usize| 10f64.powi((a % 5) as i32 - 2);
    let mut t = Vec::new();
    let mut diag = vec![0.1; k * k * k];
    for x in 0..k {
        for y in 0..k {
            for z in 0..k {
                let a = id(x, y, z);
                for b in [
                    (x + 1 < k).then(|| id(x + 1, y, z)),
                    (y + 1 < k).then(|| id(x, y + 1, z)),
                    (z + 1 < k).then(|| id(x, y, z + 1)),
                ]
                .into_iter()
                .flatten()
                {
                    let w = weight(a, b);
                    t.push((a, b, -w * scale(a) * scale(b)));
                    t.push((b, a, -w * scale(a) * scale(b)));
                    diag[a] += w;
                    diag[b] += w;
                }
            }
        }
    }
    for (a, d) in diag.iter().enumerate() {
        t.push((a, a, d * scale(a) * scale(a)));
    }
    CscMatrix::from_triplets(k * k * k, k * k * k, &t).unwrap()
}
