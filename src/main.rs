//! The `fibercell` command line: a thin shell over the library.

use clap::{Parser, Subcommand};
use fibercell::solve::{solve_static, SolveOptions, SolverKind};
use fibercell::solver::Ordering;
use fibercell::{io, Error};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "fibercell",
    version,
    about = "Effective mechanical properties of textiles from fiber-network cells"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve the linear static problem of a model (supports and nodal loads from the file).
    Solve {
        /// Model file: .toml, .json or Abaqus .inp.
        model: PathBuf,
        /// Linear solver backend.
        #[arg(long, default_value = "faer-cholesky", value_parser = parse_solver)]
        solver: SolverKind,
        /// Fill-reducing ordering: auto, amd, nd (nested dissection, METIS) or natural.
        #[arg(long, default_value = "auto", value_parser = parse_ordering)]
        ordering: Ordering,
        /// Print one JSON document (displacements, reactions, solver report) to stdout.
        #[arg(long)]
        json: bool,
        /// Directory for displacements.csv, displacements.json and deformed.vtu.
        #[arg(short, long, default_value = "fibercell-results")]
        output: PathBuf,
    },
    /// Write the reduced stiffness matrix in Matrix Market form (symmetric, lower triangle).
    ExportMatrix {
        /// Model file.
        model: PathBuf,
        /// Output .mtx file.
        #[arg(short, long)]
        output: PathBuf,
    },
}

fn parse_solver(s: &str) -> Result<SolverKind, String> {
    s.parse()
}

fn parse_ordering(s: &str) -> Result<Ordering, String> {
    match s {
        "auto" => Ok(Ordering::Auto),
        "amd" => Ok(Ordering::Amd),
        "nd" | "nested-dissection" | "metis" => Ok(Ordering::NestedDissection),
        "natural" => Ok(Ordering::Natural),
        _ => Err(format!(
            "unknown ordering \"{s}\" (use auto, amd, nd or natural)"
        )),
    }
}

fn solve(
    model_path: &Path,
    solver: SolverKind,
    ordering: Ordering,
    json: bool,
    out: &Path,
) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    let options = SolveOptions {
        solver,
        ordering,
        ..SolveOptions::default()
    };
    let sol = solve_static(&model, &options)?;
    let doc = io::solution_json(&model, &sol);
    let pretty = serde_json::to_string_pretty(&doc).map_err(|e| Error::Output {
        path: "stdout".into(),
        message: e.to_string(),
    })?;
    std::fs::create_dir_all(out).map_err(|e| Error::Output {
        path: out.display().to_string(),
        message: e.to_string(),
    })?;
    io::write_atomic(
        &out.join("displacements.csv"),
        io::displacements_csv(&model, &sol).as_bytes(),
    )?;
    io::write_atomic(&out.join("displacements.json"), pretty.as_bytes())?;
    io::write_atomic(
        &out.join("deformed.vtu"),
        io::deformed_vtu(&model, &sol).as_bytes(),
    )?;
    if json {
        println!("{pretty}");
    } else {
        let s = &sol.summary;
        let max_u = sol
            .displacements
            .iter()
            .map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt())
            .fold(0.0, f64::max);
        println!(
            "{}: {} nodes, {} fibers, {} elements, {} free DOFs",
            model_path.display(),
            model.nodes.len(),
            model.fibers.len(),
            model.elements().len(),
            s.free_dofs
        );
        println!(
            "solver {} (ordering {}): nnz(K) {}, nnz(L) {}, relative residual {:.2e}, backward error {:.2e}",
            s.backend,
            s.ordering,
            s.nnz,
            s.nnz_factor.map_or("-".into(), |v| v.to_string()),
            s.relative_residual,
            s.backward_error
        );
        println!(
            "time: pattern {:.3} s, fill {:.3} s, analyze {:.3} s, factorize {:.3} s, solve {:.3} s",
            s.timings.pattern, s.timings.fill, s.timings.analyze, s.timings.factorize, s.timings.solve
        );
        println!(
            "largest displacement {max_u:.6e} m; results in {}",
            out.display()
        );
    }
    Ok(())
}

fn export_matrix(model_path: &Path, out: &Path) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    let sys = fibercell::solve::ReducedSystem::assemble(&model, Default::default())?;
    let comment = format!(
        "reduced stiffness of {} ({} free DOFs, SI units); row/column k = k-th free DOF, node by node in ux uy uz rx ry rz order",
        model_path.display(),
        sys.dofs.n_free()
    );
    io::write_atomic(
        out,
        io::write_matrix_market(sys.matrix()?, &comment).as_bytes(),
    )
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let r = match cli.command {
        Command::Solve {
            model,
            solver,
            ordering,
            json,
            output,
        } => solve(&model, solver, ordering, json, &output),
        Command::ExportMatrix { model, output } => export_matrix(&model, &output),
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
