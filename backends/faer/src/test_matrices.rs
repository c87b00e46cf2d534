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

/// A fiber-like network: a ring of `m` nodes of widths 1–6 with chords from hashes of the node number,
/// every node's and every edge's block dense, diagonally dominant (SPD).
pub(crate) fn blocked_network(m: usize) -> CscMatrix {
    // Hashes of the node number stand in for random widths and chords.
    let hash = |g: usize, salt: u64| {
        let x = (g as u64 ^ (salt << 32)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        ((x ^ (x >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9) >> 32) as usize
    };
    let widths: Vec<usize> = (0..m).map(|g| 1 + hash(g, 11) % 6).collect();
    let mut start = vec![0];
    for w in &widths {
        start.push(start.last().unwrap() + w);
    }
    let mut edges: Vec<(usize, usize)> = (0..m).map(|g| (g, (g + 1) % m)).collect();
    edges.extend((0..m).map(|g| (hash(g, 23) % m, hash(g, 47) % m)));
    edges.retain(|&(g, h)| g != h);
    let n = start[m];
    let mut t = Vec::new();
    let mut diag = vec![1.0; n];
    for g in 0..m {
        // The node's own block: the pairs within it.
        for i in start[g]..start[g + 1] {
            for j in start[g]..i {
                let v = 0.05;
                t.push((i, j, v));
                t.push((j, i, v));
                diag[i] += v;
                diag[j] += v;
            }
        }
    }
    for &(g, h) in &edges {
        for i in start[g]..start[g + 1] {
            for j in start[h]..start[h + 1] {
                let v = -0.1 - ((i * 31 + j * 17) % 11) as f64 / 20.0;
                t.push((i, j, v));
                t.push((j, i, v));
                diag[i] += v.abs();
                diag[j] += v.abs();
            }
        }
    }
    for (i, d) in diag.iter().enumerate() {
        t.push((i, i, *d));
    }
    CscMatrix::from_triplets(n, n, &t).unwrap()
}

/// Networks of mixed node widths (1 to 3000 nodes) and scalar grids (3³ to 20³): the cases of
/// the structure tests.
pub(crate) fn structure_cases() -> Vec<(&'static str, CscMatrix)> {
    vec![
        ("network 1", blocked_network(1)),
        ("network 3", blocked_network(3)),
        ("network 40", blocked_network(40)),
        ("network 400", blocked_network(400)),
        ("network 3000", blocked_network(3000)),
        ("grid 3", grid(3)),
        ("grid 12", grid(12)),
        ("grid 20", grid(20)),
    ]
}
