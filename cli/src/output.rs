//! What every command shares for its output: atomic writes, JSON, the progress bar and increment log.

use fibercell::{io, Error};
use std::path::Path;

pub(crate) fn write(path: &Path, contents: &str) -> Result<(), Error> {
    io::write_atomic(path, contents.as_bytes())
}

/// A progress bar on stderr for runs of many increments (hidden when stderr is not a terminal);
/// with `log`, also one line per increment: its iterations, factorizations, low-rank solves
/// and their largest capacitance order, the crossover order, cutbacks, sliding contacts, time.
pub(crate) fn progress_bar(
    what: &str,
    log: bool,
) -> (indicatif::ProgressBar, fibercell::solve::Progress) {
    let bar = indicatif::ProgressBar::new(0);
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} increments ({eta})")
    {
        bar.set_style(style);
    }
    bar.set_message(what.to_string());
    let b = bar.clone();
    let report = fibercell::solve::Progress(std::sync::Arc::new(move |done, total, r| {
        b.set_length(total as u64);
        b.set_position(done as u64);
        if log {
            let line = increment_log_line(done, total, r);
            if b.is_hidden() {
                eprintln!("{line}");
            } else {
                b.println(line);
            }
        }
    }));
    (bar, report)
}

/// One increment in the `--log` of `curve` and `solve`.
fn increment_log_line(done: usize, total: usize, r: &fibercell::solve::IncrementRecord) -> String {
    let crossover = r
        .low_rank
        .crossover_order
        .map_or_else(|| "-".to_string(), |c| c.to_string());
    format!(
        "increment {done}/{total} α={:.4}: {} iterations, {} factorizations, {} low-rank solves \
         (largest order {}, crossover {crossover}, {} columns kept), {} cutbacks, \
         open/stick/slip {}/{}/{}, held {}, residual {:.1e}, {:.2} s",
        r.alpha,
        r.iterations,
        r.factorizations,
        r.factor_reuses,
        r.low_rank.largest_order,
        r.low_rank.columns,
        r.cutbacks,
        r.open,
        r.stick,
        r.slip,
        r.held,
        r.equilibrium_residual,
        r.seconds
    )
}

pub(crate) fn to_pretty<T: serde::Serialize>(doc: &T) -> Result<String, Error> {
    serde_json::to_string_pretty(doc).map_err(|e| Error::Output {
        path: "json".into(),
        message: e.to_string(),
    })
}

pub(crate) fn read_text(path: &Path) -> Result<String, Error> {
    std::fs::read_to_string(path).map_err(|e| {
        Error::Input(io::InputError::Read {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    })
}
