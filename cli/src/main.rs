//! The `fibercell` command line: a thin shell over the library. One module per command (or
//! pair of related commands); `main` parses the flags and hands them to it.

mod args;
mod bench;
mod check;
mod command;
mod curve;
mod ensemble;
mod generate;
mod homogenize;
mod matrix;
mod model_files;
mod output;
mod solve;

use args::Cli;
use clap::Parser;
use command::Command;
use fibercell::io;
use std::process::ExitCode;

fn main() -> ExitCode {
    // Output piped into `head` and closed early ends the program quietly, as for any Unix
    // tool, instead of a panic in println!.
    #[cfg(unix)]
    // SAFETY: called before any other thread exists; SIG_DFL is a valid disposition.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // Interrupted (Ctrl-C, SIGTERM, SIGHUP), remove the temporary files of outputs under way;
    // every output is renamed into place whole, so none is left half written.
    let _ = ctrlc::set_handler(|| {
        let removed = io::remove_unfinished_outputs();
        eprintln!("interrupted; {removed} unfinished output file(s) removed");
        std::process::exit(130);
    });
    let cli = Cli::parse();
    let r = match cli.command {
        Command::Solve {
            model,
            solver,
            steps,
            fixed_slip_direction,
            log,
            json,
            output,
            vtk,
        } => solve::solve(
            &model,
            solver.options(),
            (steps, fixed_slip_direction, log),
            json,
            (&output.dir, vtk.encoding),
        ),
        Command::Homogenize {
            model,
            solver,
            json,
            output,
            vtk,
        } => homogenize::homogenize(
            &model,
            solver.options(),
            json,
            (output.as_deref(), vtk.encoding),
        ),
        Command::Curve {
            model,
            strain,
            steps,
            unload,
            solver,
            json,
            output,
            bonded,
            stabilization,
            log,
        } => curve::curve(
            &model,
            (strain, steps, unload),
            (solver.options(), bonded, stabilization),
            (json, log),
            &output.dir,
        ),
        Command::Generate { kind } => generate::generate(kind),
        Command::Ensemble {
            generator,
            strain,
            steps,
            unload,
            solver,
            json,
            out,
        } => ensemble::ensemble(
            &generator,
            solver.options(),
            strain.map(|strain| fibercell::ensemble::CurvePath {
                strain,
                steps,
                unload,
            }),
            json,
            &out.dir,
        ),
        Command::RveStudy {
            generator,
            sizes,
            tolerance,
            solver,
            json,
            out,
        } => ensemble::rve_study(
            &generator,
            fibercell::ensemble::RveStudyOptions {
                params: fibercell::generate::NonWoven::default(),
                sizes,
                realizations: generator.realizations,
                first_seed: generator.first_seed,
                tolerance,
                solve: solver.options(),
            },
            json,
            &out.dir,
        ),
        Command::Stats { model, json, rose } => model_files::stats(&model, json, rose.as_deref()),
        Command::Convert {
            input,
            output,
            vtk,
            flavour,
            cell_strain,
        } => {
            let opts = io::WriteOptions {
                vtk: vtk.encoding,
                inp: io::InpOptions {
                    flavour,
                    cell_strain,
                },
            };
            model_files::convert(&input, &output, &opts)
        }
        Command::ExportMatrix { model, output } => matrix::export_matrix(&model, &output),
        Command::Check {
            model,
            solver,
            json,
            accuracy,
            no_penalty_study,
            penetration_strain,
            max_penetration,
        } => check::check(
            &model,
            &fibercell::check::CheckOptions {
                solve: solver.options(),
                penalty_study: !no_penalty_study,
                accuracy: accuracy.unwrap_or(1e-2),
                require_accuracy: accuracy.is_some(),
                penetration_strain,
                max_penetration,
            },
            json,
        ),
        Command::SolveMatrix {
            matrix,
            rhs,
            output,
            solver,
            repeats,
            json,
        } => matrix::solve_matrix(matrix::SolveMatrixRequest {
            matrix: &matrix,
            rhs: rhs.as_deref(),
            output: output.as_deref(),
            solver: &solver,
            repeats,
            json,
        }),
        Command::Bench {
            cells,
            json,
            markdown,
            repeats,
            seed,
            curve_steps,
            curve_time_limit,
            from_json,
            readme,
        } => bench::bench(
            fibercell_bench::BenchOptions {
                cells,
                seed,
                repeats,
                curve_steps,
                curve_time_limit: Some(curve_time_limit),
                ..Default::default()
            },
            from_json.as_deref(),
            [json.as_deref(), markdown.as_deref(), readme.as_deref()],
        ),
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
