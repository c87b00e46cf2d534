//! `fibercell bench`: the benchmark report of the `fibercell-bench` crate.

use crate::output::write;
use fibercell::{io, Error};
use std::path::Path;

pub(crate) fn bench(
    opts: fibercell_bench::BenchOptions,
    from_json: Option<&Path>,
    [json, markdown, readme]: [Option<&Path>; 3],
) -> Result<(), Error> {
    use fibercell_bench as bench;
    let report: bench::BenchReport = match from_json {
        Some(p) => {
            let text = io::read_text(p)?;
            serde_json::from_str(&text).map_err(|e| {
                Error::InvalidOption(format!("{}: not a bench report: {e}", p.display()))
            })?
        }
        None => bench::run_bench(&opts, &mut |what| eprintln!("bench: {what}"))?,
    };
    let text = bench::markdown(&report);
    println!("{text}");
    if let Some(p) = readme {
        let old = io::read_text(p)?;
        let command = bench::reproduce_command(&report);
        let new = bench::splice_readme(&old, &text, &command).ok_or_else(|| {
            Error::InvalidOption(format!(
                "{}: no {} … {} markers",
                p.display(),
                bench::README_MARKERS[0],
                bench::README_MARKERS[1]
            ))
        })?;
        write(p, &new)?;
    }
    if let Some(p) = json {
        let doc = serde_json::to_string_pretty(&report)
            .map_err(|e| Error::InvalidOption(format!("cannot serialize the report: {e}")))?;
        write(p, &doc)?;
    }
    if let Some(p) = markdown {
        write(p, &text)?;
    }
    Ok(())
}
