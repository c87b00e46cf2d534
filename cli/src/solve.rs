//! `fibercell solve`: a model's static problem, incremental when it has contacts.

use crate::output::{progress_bar, to_pretty, write};
use fibercell::io::NetworkFormat;
use fibercell::solve::{solve_incremental, solve_static, IncrementalOptions, SolveOptions};
use fibercell::{io, Error};
use std::path::Path;

pub(crate) fn solve(
    model_path: &Path,
    options: SolveOptions,
    incremental: (usize, bool, bool),
    json: bool,
    (out, vtk): (&Path, io::VtkEncoding),
) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    // displacements.json is written last: a folder that holds it is complete.
    io::begin_results(out, "displacements.json")?;
    if model.has_contact() {
        return solve_with_contact(model_path, &model, options, incremental, json, (out, vtk));
    }
    let sol = solve_static(&model, &options)?;
    let pretty = to_pretty(&io::solution_json(&model, &sol))?;
    write(
        &out.join("displacements.csv"),
        &io::displacements_csv(&model, &sol.displacements),
    )?;
    write(
        &out.join("network.vtp"),
        &io::network_vtk(&model, &sol.displacements, NetworkFormat::PolyData, vtk),
    )?;
    write(&out.join("displacements.json"), &pretty)?;
    if json {
        println!("{pretty}");
        return Ok(());
    }
    let s = &sol.summary;
    print_model_line(model_path, &model, s.free_dofs);
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
        "largest displacement {:.6e} m; results in {}",
        largest(&sol.displacements),
        out.display()
    );
    Ok(())
}

fn print_model_line(path: &Path, model: &fibercell::Model, free: usize) {
    println!(
        "{}: {} nodes, {} fibers, {} elements, {} free DOFs",
        path.display(),
        model.nodes.len(),
        model.fibers.len(),
        model.elements().len(),
        free
    );
}

pub(crate) fn largest(d: &[[f64; 6]]) -> f64 {
    d.iter()
        .map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt())
        .fold(0.0, f64::max)
}

fn solve_with_contact(
    model_path: &Path,
    model: &fibercell::Model,
    solve: SolveOptions,
    (steps, fixed_slip_direction, log): (usize, bool, bool),
    json: bool,
    (out, vtk): (&Path, io::VtkEncoding),
) -> Result<(), Error> {
    let (bar, progress) = progress_bar("stick/slip", log);
    let opts = IncrementalOptions {
        steps,
        solve,
        fixed_slip_direction,
        progress: Some(progress),
        ..IncrementalOptions::default()
    };
    let sol = solve_incremental(model, &opts);
    bar.finish_and_clear();
    let sol = sol?;
    let pretty = to_pretty(&io::incremental_json(model, &sol))?;
    let final_u = sol.displacements.last().map(|d| &d[..]).unwrap_or(&[]);
    write(
        &out.join("displacements.csv"),
        &io::displacements_csv(model, final_u),
    )?;
    write(&out.join("increments.csv"), &io::increments_csv(&sol))?;
    write(&out.join("contacts.csv"), &io::contacts_csv(&sol))?;
    for (k, rec) in sol.increments.iter().enumerate() {
        write(
            &out.join(io::step_file("step", rec.step)),
            &io::network_vtk(model, &sol.displacements[k], NetworkFormat::PolyData, vtk),
        )?;
        write(
            &out.join(io::step_file("contacts", rec.step)),
            &io::contacts_vtp(&sol, k, vtk),
        )?;
    }
    write(&out.join("solution.pvd"), &io::series_pvd(&sol))?;
    write(&out.join("displacements.json"), &pretty)?;
    if json {
        println!("{pretty}");
        return Ok(());
    }
    print_model_line(
        model_path,
        model,
        6 * model.nodes.len() - model.supports.len(),
    );
    let p = sol.contacts.penetration;
    println!("{} contact pairs", sol.contacts.pairs.len());
    if p.count > 0 {
        println!(
            "{} pairs start penetrating (worst overlap {:.3e} m): {}",
            p.count,
            p.worst_overlap,
            if p.adjusted {
                "gaps set to zero (strain-free)"
            } else {
                "resolved by the penalty over the increments"
            }
        );
    }
    println!(
        "{:>5} {:>8} {:>5} {:>6} {:>6} {:>6}",
        "step", "alpha", "iter", "open", "stick", "slip"
    );
    for r in &sol.increments {
        println!(
            "{:>5} {:>8.4} {:>5} {:>6} {:>6} {:>6}",
            r.step, r.alpha, r.iterations, r.open, r.stick, r.slip
        );
    }
    println!(
        "largest displacement {:.6e} m; results in {}",
        largest(final_u),
        out.display()
    );
    Ok(())
}
