//! `fibercell solve-matrix` and `fibercell export-matrix`: a cell problem's matrix on its own.

use crate::args::SolverArgs;
use crate::output::{read_text, to_pretty};
use fibercell::{io, Error};
use std::path::Path;

/// What `solve-matrix` was asked for.
pub(crate) struct SolveMatrixRequest<'a> {
    pub matrix: &'a Path,
    pub rhs: Option<&'a Path>,
    pub output: Option<&'a Path>,
    pub solver: &'a SolverArgs,
    pub repeats: usize,
    pub json: bool,
}

pub(crate) fn solve_matrix(req: SolveMatrixRequest<'_>) -> Result<(), Error> {
    let matrix = req.matrix;
    let in_file = |path: &Path, e: fibercell::solver::SolverError| {
        Error::Input(io::InputError::Read {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    };
    let a = fibercell::solver::read_matrix_market(&read_text(matrix)?)
        .map_err(|e| in_file(matrix, e))?;
    let b = match req.rhs {
        Some(path) => {
            let (n, k, values) = fibercell::solver::read_matrix_market_dense(&read_text(path)?)
                .map_err(|e| in_file(path, e))?;
            if k == 0 || n != a.as_ref().nrows() {
                return Err(Error::InvalidOption(format!(
                    "{}: b is {n} × {k}, the matrix needs one or more columns of {}",
                    path.display(),
                    a.as_ref().nrows()
                )));
            }
            Some(values)
        }
        None => None,
    };
    let config = req.solver.options().solver_config(Vec::new());
    let (x, r) = fibercell::solve::solve_matrix(a.as_ref(), b.as_deref(), &config, req.repeats)?;
    if let Some(out) = req.output {
        let comment = format!(
            "fibercell solve-matrix: X of A X = B for {}",
            matrix.display()
        );
        let text = io::write_matrix_market_dense(r.n, r.columns, &x, &comment);
        io::write_atomic(out, text.as_bytes())?;
    }
    if req.json {
        println!("{}", to_pretty(&r)?);
        return Ok(());
    }
    println!(
        "{}: n {}, nnz(A) {}, {} right-hand side{}, backend {} (ordering {})",
        matrix.display(),
        r.n,
        r.nnz,
        r.columns,
        if r.columns == 1 { "" } else { "s" },
        r.backend,
        r.ordering
    );
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3e}"));
    println!(
        "nnz(L) {}{}, flops {}, iterations {}",
        r.nnz_factor.map_or("-".to_string(), |v| v.to_string()),
        r.factor_bytes.map_or(String::new(), |b| format!(
            " ({:.1} MB stored)",
            b as f64 / 1e6
        )),
        opt(r.flops),
        r.iterations.map_or("-".to_string(), |v| v.to_string())
    );
    println!(
        "time (s): analyze {:.4}  factorize {:.4}  solve {:.4}{}",
        r.analyze_seconds,
        r.factorize_seconds,
        r.solve_seconds,
        if r.repeats > 1 {
            format!(" (medians of {} runs)", r.repeats)
        } else {
            String::new()
        }
    );
    println!(
        "relative residual {:.2e}, backward error {:.2e}, max |x − 1| {}",
        r.relative_residual,
        r.backward_error,
        opt(r.error_against_ones)
    );
    Ok(())
}

pub(crate) fn export_matrix(model_path: &Path, out: &Path) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    let job = io::job_system(&model)?;
    io::write_job_system(&job, model_path, out).map(|_| ())
}
