//! `fibercell ensemble` and `fibercell rve-study`: many realizations of a random cell.

use crate::args::GeneratorArgs;
use crate::output::to_pretty;
use fibercell::solve::SolveOptions;
use fibercell::{io, Error};
use std::path::Path;

pub(crate) fn ensemble(
    generator: &GeneratorArgs,
    solve: SolveOptions,
    curve: Option<fibercell::ensemble::CurvePath>,
    json: bool,
    out: &Path,
) -> Result<(), Error> {
    use fibercell::ensemble::{EnsembleOptions, MAIN_MODULI};
    let (params, name) = generator.cell_params()?;
    let GeneratorArgs {
        realizations,
        first_seed,
        ..
    } = *generator;
    let opts = EnsembleOptions {
        params,
        realizations,
        first_seed,
        solve,
        curve,
    };
    let mut report = |r: &fibercell::ensemble::Realization, reused: bool| {
        eprintln!("seed {}: {}", r.seed, realization_outcome(r, reused));
    };
    let Some(e) = ensemble_on_ranks(&opts, out, &mut report)? else {
        return Ok(()); // a rank of an MPI job other than 0: rank 0 reports
    };
    let title = format!("{name}: {} realizations", e.realizations.len());
    io::write_ensemble_files(out, &e, &title)?;
    if json {
        println!("{}", to_pretty(&e)?);
        return Ok(());
    }
    let failed = e.failed();
    println!(
        "{title} (seeds {first_seed}–{}), {} failed, {} reused; results in {}",
        first_seed + realizations as u64 - 1,
        failed.len(),
        e.reused,
        out.display()
    );
    for k in MAIN_MODULI {
        let x = &e.abd[k][k];
        println!(
            "  {}  mean {:.5e}  std {:.3e}  95 % interval ± {:.3e} ({:.2} %)",
            io::abd_entry_name(k, k),
            x.mean,
            x.std,
            x.ci95,
            100.0 * x.relative_ci95()
        );
    }
    if let Some(c) = &e.curve {
        let k = c.component;
        if let Some(peak) = c.points.get(c.path.steps.saturating_sub(1)) {
            let x = &peak.resultant[k];
            println!(
                "  curves: {} of {} complete; at {} = {:.4e}: {}  mean {:.5e} {}  std {:.3e}  \
                 95 % interval ± {:.3e} ({:.2} %)",
                c.curves,
                e.realizations.len(),
                fibercell::cell::MACRO_NAMES[k],
                peak.strain[k],
                io::RESULTANT_NAMES[k],
                x.mean,
                io::RESULTANT_UNITS[k],
                x.std,
                x.ci95,
                100.0 * x.relative_ci95()
            );
        }
    }
    for (seed, err) in &failed {
        println!("  seed {seed} failed: {err}");
    }
    Ok(())
}

/// Runs the ensemble — over the ranks of an MPI job when started by `mpirun` with more than
/// one rank (feature `mpi`), else in this process — and returns it on the rank that reports
/// (`None` on the others). `ensemble.json` is written last: a folder that holds it is complete.
fn ensemble_on_ranks(
    opts: &fibercell::ensemble::EnsembleOptions,
    out: &Path,
    report: fibercell::ensemble::EnsembleProgress<'_>,
) -> Result<Option<fibercell::ensemble::Ensemble>, Error> {
    #[cfg(feature = "mpi")]
    {
        use mpi::traits::Communicator;
        let universe = mpi::initialize();
        if let Some(world) = universe
            .as_ref()
            .map(|u| u.world())
            .filter(|w| w.size() > 1)
        {
            let root = world.rank() == 0;
            let began = if root {
                io::begin_results(out, "ensemble.json")
            } else {
                Ok(())
            };
            let run = began.and_then(|()| {
                let store = root.then_some(out);
                fibercell::ensemble::run_ensemble_mpi(&world, opts, store, Some(report))
            });
            return match run {
                Err(e) if root => {
                    // The other ranks may wait for rank 0: end the whole job.
                    eprintln!("error: {e}");
                    world.abort(1)
                }
                other => other,
            };
        }
    }
    io::begin_results(out, "ensemble.json")?;
    fibercell::ensemble::run_ensemble(opts, Some(out), Some(report)).map(Some)
}

/// How a realization ended, for the progress lines of `ensemble` and `rve-study`.
fn realization_outcome(r: &fibercell::ensemble::Realization, reused: bool) -> String {
    match (&r.error, reused) {
        (Some(e), _) => format!("failed: {e}"),
        (None, true) => "reused".into(),
        (None, false) => format!("{:.2} s", r.seconds),
    }
}

pub(crate) fn rve_study(
    generator: &GeneratorArgs,
    mut opts: fibercell::ensemble::RveStudyOptions,
    json: bool,
    out: &Path,
) -> Result<(), Error> {
    use fibercell::ensemble::{run_rve_study, MAIN_MODULI};
    use fibercell::generate::CellParams;
    let (params, name) = generator.cell_params()?;
    let CellParams::Nonwoven(base) = params else {
        return Err(Error::InvalidOption(format!(
            "{name}: an RVE study needs a random cell (family = \"nonwoven\"); the woven, \
             knitted and geotextile generators give one cell per size"
        )));
    };
    opts.params = base;
    let mut report = |size: f64, r: &fibercell::ensemble::Realization, reused: bool| {
        let what = realization_outcome(r, reused);
        eprintln!("L = {size:e} m, seed {}: {what}", r.seed);
    };
    // rve.json is written last: a folder that holds it is complete.
    io::begin_results(out, "rve.json")?;
    let study = run_rve_study(&opts, Some(out), Some(&mut report))?;
    let title = format!(
        "{name}: RVE study, {} realizations per size",
        opts.realizations
    );
    io::write_rve_files(out, &study, &title)?;
    if json {
        println!("{}", to_pretty(&study)?);
        return Ok(());
    }
    println!("{title}; results in {}", out.display());
    for z in &study.sizes {
        let row: Vec<String> = MAIN_MODULI
            .iter()
            .zip(&z.moduli)
            .map(|(&k, x)| {
                format!(
                    "{} {:.4e} ± {:.1} %",
                    io::abd_entry_name(k, k),
                    x.mean,
                    100.0 * x.relative_ci95()
                )
            })
            .collect();
        let failed = z.ensemble.failed();
        let moduli = match failed.first() {
            Some((seed, e)) if z.moduli[0].n == 0 => format!("all failed (seed {seed}: {e})"),
            _ => row.join(", "),
        };
        println!(
            "  L = {:.4e} m, {} of {} realizations: {moduli}",
            z.size,
            z.moduli[0].n,
            z.ensemble.realizations.len(),
        );
    }
    let size = |s: Option<f64>| s.map_or("beyond the sizes studied".into(), |l| format!("{l:e} m"));
    println!(
        "  representative (every main modulus within ± {:.1} %): {}",
        100.0 * study.tolerance,
        size(study.representative_all)
    );
    for (&k, r) in MAIN_MODULI.iter().zip(&study.representative) {
        println!("    {}: {}", io::abd_entry_name(k, k), size(*r));
    }
    Ok(())
}
