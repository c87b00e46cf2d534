//! Block-Jacobi preconditioner: the inverses of the diagonal blocks, applied block by block.

use fibercell_solver::{CscRef, SolverError};

/// Inverted diagonal blocks of a symmetric positive definite matrix, each stored as a dense
/// Cholesky factor.
pub struct BlockJacobi {
    starts: Vec<usize>,
    /// Lower Cholesky factor of each block, row-major b×b, concatenated.
    factors: Vec<f64>,
    offsets: Vec<usize>,
}

impl BlockJacobi {
    /// Factorizes the diagonal blocks `starts[k]..starts[k + 1]` of `a`.
    pub fn new(a: CscRef<'_>, starts: &[usize]) -> Result<Self, SolverError> {
        let n = a.ncols();
        let mut factors = Vec::new();
        let mut offsets = Vec::with_capacity(starts.len() + 1);
        for (k, &s) in starts.iter().enumerate() {
            let e = starts.get(k + 1).copied().unwrap_or(n);
            let b = e - s;
            offsets.push(factors.len());
            let mut m = vec![0.0; b * b];
            for j in s..e {
                let (rows, vals) = a.col(j);
                for (&i, &v) in rows.iter().zip(vals) {
                    if (s..e).contains(&i) {
                        m[(i - s) * b + (j - s)] = v;
                    }
                }
            }
            // In-place dense Cholesky, lower triangle.
            for c in 0..b {
                let mut d = m[c * b + c];
                for q in 0..c {
                    d -= m[c * b + q] * m[c * b + q];
                }
                if !(d > 0.0) {
                    return Err(SolverError::NotPositiveDefinite {
                        column: s + c,
                        pivot: d / m[c * b + c].abs().max(f64::MIN_POSITIVE),
                    });
                }
                let d = d.sqrt();
                m[c * b + c] = d;
                for r in c + 1..b {
                    let mut v = m[r * b + c];
                    for q in 0..c {
                        v -= m[r * b + q] * m[c * b + q];
                    }
                    m[r * b + c] = v / d;
                }
            }
            factors.extend_from_slice(&m);
        }
        offsets.push(factors.len());
        Ok(BlockJacobi {
            starts: starts.to_vec(),
            factors,
            offsets,
        })
    }

    /// z = M⁻¹ r, blocks in parallel (recursive halving at block boundaries, no allocation).
    pub fn apply(&self, r: &[f64], z: &mut [f64]) {
        self.apply_range(0, self.starts.len(), r, z);
    }

    fn block_end(&self, k: usize, n: usize) -> usize {
        self.starts.get(k + 1).copied().unwrap_or(n)
    }

    /// Applies blocks lo..hi; `z` covers exactly their rows.
    fn apply_range(&self, lo: usize, hi: usize, r: &[f64], z: &mut [f64]) {
        if hi - lo > 256 {
            let mid = (lo + hi) / 2;
            let (za, zb) = z.split_at_mut(self.starts[mid] - self.starts[lo]);
            rayon::join(
                || self.apply_range(lo, mid, r, za),
                || self.apply_range(mid, hi, r, zb),
            );
            return;
        }
        let base = self.starts.get(lo).copied().unwrap_or(0);
        let n = r.len();
        for k in lo..hi {
            let (s, e) = (self.starts[k], self.block_end(k, n));
            let b = e - s;
            let l = &self.factors[self.offsets[k]..self.offsets[k + 1]];
            let zk = &mut z[s - base..e - base];
            // Forward then backward substitution with L and Lᵀ.
            for i in 0..b {
                let mut v = r[s + i];
                for q in 0..i {
                    v -= l[i * b + q] * zk[q];
                }
                zk[i] = v / l[i * b + i];
            }
            for i in (0..b).rev() {
                let mut v = zk[i];
                for q in i + 1..b {
                    v -= l[q * b + i] * zk[q];
                }
                zk[i] = v / l[i * b + i];
            }
        }
    }
}
