//! Matrix Market `coordinate real symmetric` output (lower triangle, 1-based).

use fibercell_solver::CscRef;
use std::fmt::Write;

/// `columns` dense columns of length `n` (stored column after column) in Matrix Market
/// `array real general` form.
pub fn write_matrix_market_dense(
    n: usize,
    columns: usize,
    values: &[f64],
    comment: &str,
) -> String {
    let mut s = String::with_capacity(values.len() * 26 + 200);
    s.push_str("%%MatrixMarket matrix array real general\n");
    for line in comment.lines() {
        let _ = writeln!(s, "% {line}");
    }
    let _ = writeln!(s, "{n} {columns}");
    for v in values {
        let _ = writeln!(s, "{v:.17e}");
    }
    s
}

/// The lower triangle of a symmetric matrix in Matrix Market form.
pub fn write_matrix_market(a: CscRef<'_>, comment: &str) -> String {
    let lower: usize = (0..a.ncols())
        .map(|j| a.col(j).0.iter().filter(|&&i| i >= j).count())
        .sum();
    let mut s = String::with_capacity(lower * 40 + 200);
    s.push_str("%%MatrixMarket matrix coordinate real symmetric\n");
    for line in comment.lines() {
        let _ = writeln!(s, "% {line}");
    }
    let _ = writeln!(s, "{} {} {}", a.nrows(), a.ncols(), lower);
    for j in 0..a.ncols() {
        let (rows, vals) = a.col(j);
        for (&i, &v) in rows.iter().zip(vals) {
            if i >= j {
                let _ = writeln!(s, "{} {} {:.17e}", i + 1, j + 1, v);
            }
        }
    }
    s
}
