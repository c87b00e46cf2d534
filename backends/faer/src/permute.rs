//! Right-hand sides into and out of the factor's row order, with the scaling Ŝ: gathers
//! (sequential writes, random reads), split over the threads for large factors.

use rayon::prelude::*;

/// Rows per parallel piece.
const CHUNK: usize = 1 << 14;

/// Applies `row(i)` to every row `i` of `out`, in pieces on the threads when `parallel`.
fn gather(out: &mut [f64], parallel: bool, row: impl Fn(usize) -> f64 + Sync) {
    let fill = |(k, piece): (usize, &mut [f64])| {
        let start = k * CHUNK;
        piece
            .iter_mut()
            .enumerate()
            .for_each(|(i, o)| *o = row(start + i));
    };
    if parallel {
        out.par_chunks_mut(CHUNK).enumerate().for_each(fill);
    } else {
        out.chunks_mut(CHUNK).enumerate().for_each(fill);
    }
}

/// out[new] = x[fwd[new]] · scale[fwd[new]]: `x` (original order) into the factor's order,
/// scaled (`fwd[new] = old`).
pub(crate) fn into_factor_order(
    x: &[f64],
    scale: &[f64],
    fwd: &[usize],
    out: &mut [f64],
    parallel: bool,
) {
    gather(out, parallel, |new| {
        let old = fwd[new];
        x[old] * scale[old]
    });
}

/// out[old] = y[inv[old]] · scale[old]: `y` (the factor's order) back to the original order,
/// scaled (`inv[old] = new`).
pub(crate) fn from_factor_order(
    y: &[f64],
    scale: &[f64],
    inv: &[usize],
    out: &mut [f64],
    parallel: bool,
) {
    gather(out, parallel, |old| y[inv[old]] * scale[old]);
}

/// out = x, in pieces on the threads when `parallel`.
pub(crate) fn copy(x: &[f64], out: &mut [f64], parallel: bool) {
    gather(out, parallel, |i| x[i]);
}

/// out[new·k + c] = x[c·n + fwd[new]] · scale[fwd[new]]: the k columns of `x` (original order,
/// column after column) into the factor's order, scaled and interleaved.
pub(crate) fn many_into_factor_order(
    x: &[f64],
    k: usize,
    scale: &[f64],
    fwd: &[usize],
    out: &mut [f64],
) {
    let n = fwd.len();
    out.par_chunks_mut(CHUNK * k)
        .enumerate()
        .for_each(|(piece, rows)| {
            for (i, row) in rows.chunks_mut(k).enumerate() {
                let old = fwd[piece * CHUNK + i];
                for (c, o) in row.iter_mut().enumerate() {
                    *o = x[c * n + old] * scale[old];
                }
            }
        });
}

/// out[c·n + old] = y[inv[old]·k + c] · scale[old]: k interleaved columns in the factor's order
/// back to the original order, column after column, scaled (`inv[old] = new`); one pass, each
/// row's k values read together.
pub(crate) fn many_from_factor_order(
    y: &[f64],
    k: usize,
    scale: &[f64],
    inv: &[usize],
    out: &mut [f64],
) {
    let n = inv.len();
    let mut pieces: Vec<Vec<&mut [f64]>> = Vec::new();
    for column in out.chunks_mut(n.max(1)).take(k) {
        for (p, piece) in column.chunks_mut(CHUNK).enumerate() {
            if p == pieces.len() {
                pieces.push(Vec::with_capacity(k));
            }
            pieces[p].push(piece);
        }
    }
    pieces
        .into_par_iter()
        .enumerate()
        .for_each(|(p, mut columns)| {
            let rows = columns.first().map_or(0, |c| c.len());
            for i in 0..rows {
                let old = p * CHUNK + i;
                let row = &y[inv[old] * k..(inv[old] + 1) * k];
                for (column, &v) in columns.iter_mut().zip(row) {
                    column[i] = v * scale[old];
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Into and out of a permuted order with a scaling, sequential and parallel (several
    /// pieces), against the definitions; the round trip scales twice.
    #[test]
    fn into_and_out_of_the_factor_order_follow_the_definitions() {
        let n = 3 * CHUNK + 17;
        let fwd: Vec<usize> = (0..n).map(|i| (i * 7919) % n).collect();
        let mut inv = vec![0; n];
        fwd.iter()
            .enumerate()
            .for_each(|(new, &old)| inv[old] = new);
        let x: Vec<f64> = (0..n).map(|i| i as f64 - 5.0).collect();
        let scale: Vec<f64> = (0..n).map(|i| 1.0 + (i % 3) as f64).collect();
        for parallel in [false, true] {
            let mut y = vec![0.0; n];
            into_factor_order(&x, &scale, &fwd, &mut y, parallel);
            for new in 0..n {
                assert_eq!(y[new], x[fwd[new]] * scale[fwd[new]]);
            }
            let mut back = vec![0.0; n];
            from_factor_order(&y, &scale, &inv, &mut back, parallel);
            for old in 0..n {
                assert_eq!(back[old], x[old] * scale[old] * scale[old]);
            }
            let mut same = vec![0.0; n];
            copy(&back, &mut same, parallel);
            assert_eq!(same, back);
        }
        // Three columns at once, interleaved in the factor's order and back.
        let k = 3;
        let xs: Vec<f64> = (0..k * n).map(|i| (i % 1013) as f64 - 7.0).collect();
        let mut y = vec![0.0; k * n];
        many_into_factor_order(&xs, k, &scale, &fwd, &mut y);
        for new in 0..n {
            for c in 0..k {
                assert_eq!(y[new * k + c], xs[c * n + fwd[new]] * scale[fwd[new]]);
            }
        }
        let mut back = vec![0.0; k * n];
        many_from_factor_order(&y, k, &scale, &inv, &mut back);
        for old in 0..n {
            for c in 0..k {
                assert_eq!(back[c * n + old], xs[c * n + old] * scale[old] * scale[old]);
            }
        }
    }
}
