//! Matrix Market `coordinate real symmetric` output (lower triangle, 1-based).

use super::write_atomic;
use crate::Error;
use fibercell_solver::CscRef;
use std::fmt::Write;
use std::path::{Path, PathBuf};

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

/// Writes `job` ([`super::job_system`] of the model at `source`) to `out` (Matrix
/// Market, symmetric, lower triangle), its right-hand sides to `OUT_rhs.mtx` and the node and
/// DOF of every row to `OUT_dofs.csv`, each file atomically; the header of both matrices says
/// which problem it is and where the rows are described. Returns the three paths.
pub fn write_job_system(
    job: &super::JobSystem,
    source: &Path,
    out: &Path,
) -> Result<[PathBuf; 3], Error> {
    let system = &job.system;
    let n = system.dofs.len();
    let stem = out.with_extension("");
    let sibling = |suffix: &str| PathBuf::from(format!("{}{suffix}", stem.display()));
    let (rhs_path, dofs_path) = (sibling("_rhs.mtx"), sibling("_dofs.csv"));
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::Output {
            path: dir.display().to_string(),
            message: e.to_string(),
        })?;
    }
    let comment = format!(
        "{} of {} ({n} unknowns, SI units); row k is the unknown in row k of {}",
        job.description,
        source.display(),
        dofs_path.display()
    );
    let mut map = String::from("row,node,dof\n");
    for (k, (node, dof)) in system.dofs.iter().enumerate() {
        map.push_str(&format!("{},{node},{}\n", k + 1, dof.name()));
    }
    let rhs = write_matrix_market_dense(n, system.columns, &system.rhs, &comment);
    write_atomic(&rhs_path, rhs.as_bytes())?;
    write_atomic(&dofs_path, map.as_bytes())?;
    write_atomic(
        out,
        write_matrix_market(system.matrix.as_ref(), &comment).as_bytes(),
    )?;
    Ok([out.to_path_buf(), rhs_path, dofs_path])
}
