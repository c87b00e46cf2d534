//! The benchmark report as Markdown tables: printed by `fibercell bench` and pasted into the
//! performance page (`docs/performance.md`).

use super::BenchReport;
use std::fmt::Write;

fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map_or("–".into(), |v| v.to_string())
}

fn ms(s: f64) -> String {
    if s >= 10.0 {
        format!("{s:.1} s")
    } else if s >= 1.0 {
        format!("{s:.2} s")
    } else {
        format!("{:.1} ms", s * 1e3)
    }
}

fn mb(bytes: usize) -> String {
    let mb = bytes as f64 / 1e6;
    if mb >= 10.0 {
        format!("{mb:.0} MB")
    } else {
        format!("{mb:.2} MB")
    }
}

fn per_second(v: f64) -> String {
    format!("{:.2e}/s", v)
}

/// A table cell of the curve `pick` chooses: `f` of it, or a dash.
fn curve_cell<'a>(
    pick: fn(&super::CellBench) -> Option<&super::CurveBench>,
    f: &'a dyn Fn(&super::CurveBench) -> String,
) -> impl Fn(&super::CellBench) -> String + 'a {
    move |c| pick(c).map_or("–".into(), f)
}

/// The whole report as Markdown.
pub fn markdown(r: &BenchReport) -> String {
    let m = &r.machine;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Machine: {}, {} threads, {} GiB. DGEMM {:.1} GFLOP/s on one thread, {:.1} on {}; \
         STREAM triad {:.1} GB/s. fibercell {}, seed {}, medians of {} runs.\n",
        m.cpu,
        m.threads,
        opt(m.memory_gib.map(|g| format!("{g:.0}"))),
        m.dgemm_gflops_1,
        m.dgemm_gflops_all,
        m.threads,
        m.bandwidth_gbs,
        r.version,
        r.seed,
        r.repeats
    );
    let _ = writeln!(
        s,
        "| stage | {} |",
        r.cells
            .iter()
            .map(|c| c.cell.as_str())
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let _ = writeln!(s, "|---|{}", "---:|".repeat(r.cells.len()));
    let mut row = |name: &str, f: &dyn Fn(&super::CellBench) -> String| {
        let cols: Vec<String> = r.cells.iter().map(f).collect();
        let _ = writeln!(s, "| {name} | {} |", cols.join(" | "));
    };
    row("fibers / elements", &|c| {
        format!("{} / {}", c.fibers, c.elements)
    });
    row("closed contacts", &|c| c.contacts.to_string());
    row("free DOFs / nnz(K)", &|c| {
        format!("{} / {:.2e}", c.dofs, c.nnz_k as f64)
    });
    row("generation", &|c| ms(c.generation));
    row("contact search (segments/s)", &|c| {
        format!(
            "{} ({})",
            ms(c.contact_search),
            per_second(c.segments_per_second)
        )
    });
    row("contact set (merge, kinematics)", &|c| ms(c.contact_set));
    row("pattern", &|c| ms(c.pattern));
    row("value fill, elements (elements/s)", &|c| {
        format!(
            "{} ({})",
            ms(c.fill_elements),
            per_second(c.elements_per_second)
        )
    });
    row("value fill, contacts (pairs/s)", &|c| {
        format!(
            "{} ({})",
            ms(c.fill_contacts),
            per_second(c.pairs_per_second)
        )
    });
    row("value fill: fraction of bandwidth", &|c| {
        format!("{:.1} %", 100.0 * c.fill_fraction_of_bandwidth)
    });
    row("six cell problems (+ Θ), end to end", &|c| {
        ms(c.six_cell_problems)
    });
    row(
        "… setup / fill / analyze / factorize / Θ load / 7 solves",
        &|c| {
            c.six_cell_problem_stages.stages()[..6]
                .iter()
                .map(|&t| ms(t))
                .collect::<Vec<_>>()
                .join(" / ")
        },
    );
    type Pick = fn(&super::CellBench) -> Option<&super::CurveBench>;
    let curves: [(&str, Pick); 2] = [
        ("curve", |c| c.curve.as_ref()),
        ("mild curve", |c| c.mild_curve.as_ref()),
    ];
    for (label, pick) in curves {
        if !r.cells.iter().any(|c| pick(c).is_some()) {
            continue;
        }
        row(
            &format!("{label}: physics, ε11 at the end"),
            &curve_cell(pick, &|k| format!("{}; {}", k.physics, k.strain)),
        );
        row(
            &format!("{label}: increments, total"),
            &curve_cell(pick, &|k| match &k.error {
                Some(e) => format!("failed: {e}"),
                None if k.completed < k.steps => format!(
                    "{} of {} in {} (time limit), projected {}",
                    k.completed,
                    k.steps,
                    ms(k.total),
                    ms(k.projected_total)
                ),
                None => format!("{}, {}", k.steps, ms(k.total)),
            }),
        );
        row(
            &format!("{label}: one increment (median / max)"),
            &curve_cell(pick, &|k| {
                format!("{} / {}", ms(k.increment_median), ms(k.increment_max))
            }),
        );
        row(
            &format!(
                "{label}: state iterations / factorizations / low-rank solves (correction steps)"
            ),
            &curve_cell(pick, &|k| {
                format!(
                    "{} / {} / {} ({})",
                    k.state_iterations, k.factorizations, k.factor_reuses, k.correction_steps
                )
            }),
        );
        row(
            &format!("{label}: low rank: largest order / most columns / crossover order"),
            &curve_cell(pick, &|k| {
                format!(
                    "{} / {} / {}",
                    k.low_rank_largest_order,
                    k.low_rank_most_columns,
                    opt(k.crossover_order)
                )
            }),
        );
        row(
            &format!(
                "… {}",
                fibercell::solve::IncrementTimings::NAMES.join(" / ")
            ),
            &curve_cell(pick, &|k| {
                k.stages.map_or("–".into(), |s| {
                    s.iter().map(|&t| ms(t)).collect::<Vec<_>>().join(" / ")
                })
            }),
        );
        if r.cells
            .iter()
            .any(|c| pick(c).is_some_and(|k| k.output_bytes.is_some()))
        {
            row(
                &format!("{label}: memory: low-rank correction (peak) / outputs at the end"),
                &curve_cell(pick, &|k| {
                    format!(
                        "{} / {}",
                        opt(k.low_rank_bytes.map(mb)),
                        opt(k.output_bytes.map(mb))
                    )
                }),
            );
        }
        row(
            &format!("{label}: sliding at end / held / max residual / stabilization work"),
            &curve_cell(pick, &|k| {
                format!(
                    "{} / {} / {:.1e} / {:.1e} of dissipation",
                    k.sliding_at_end, k.held, k.max_equilibrium_residual, k.stabilization_share
                )
            }),
        );
    }
    if r.cells.iter().any(|c| c.memory.is_some()) {
        row(
            "memory: pattern / values of K / faer's factor, 8·nnz(L) (stored)",
            &|c| {
                c.memory.as_ref().map_or("–".into(), |m| {
                    let stored = m
                        .factor_stored
                        .map_or(String::new(), |b| format!(" ({})", mb(b)));
                    format!(
                        "{} / {} / {}{stored}",
                        mb(m.pattern),
                        mb(m.values),
                        mb(m.factor)
                    )
                })
            },
        );
    }
    row("peak memory", &|c| {
        opt(c.peak_memory.map(|b| format!("{:.2} GB", b as f64 / 1e9)))
    });
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "| cell | backend | ordering | analyze | factorize | solve | nnz(L) | GFLOP/s | of DGEMM | solve of bandwidth |"
    );
    let _ = writeln!(s, "|---|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for c in &r.cells {
        for b in &c.backends {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                c.cell,
                b.name,
                b.ordering,
                ms(b.analyze),
                ms(b.factorize),
                ms(b.solve),
                opt(b.nnz_l.map(|v| format!("{:.3e}", v as f64))),
                opt(b.gflops.map(|v| format!("{v:.1}"))),
                opt(b.fraction_of_dgemm.map(|v| format!("{:.0} %", 100.0 * v))),
                opt(b
                    .solve_fraction_of_bandwidth
                    .map(|v| format!("{:.0} %", 100.0 * v))),
            );
        }
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "| cell | contacts switched | fraction | refactorization + solve, faer / CHOLMOD | \
         CG on the old factor: iterations | seconds | \
         of a refactorization | low-rank on faer's factor, first / next | first: columns / \
         capacitance / solve | of a refactorization (first / next) | backward error | CHOLMOD downdate + solve, first | next | of CHOLMOD's \
         refactorization (first / next) | backward error |"
    );
    let _ = writeln!(
        s,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for c in &r.cells {
        for u in &c.reuse {
            let _ = writeln!(
                s,
                "| {} | {} | {:.1} % | {} | {}{} | {} | {:.2} | {} | {} | {} | {} | {} | {} | {} | {} |",
                c.cell,
                u.switched,
                100.0 * u.fraction,
                match (u.refactorization_seconds, u.cholmod_refactorization_seconds) {
                    (Some(a), Some(b)) => format!("{} / {}", ms(a), ms(b)),
                    (Some(a), None) => ms(a),
                    _ => "–".into(),
                },
                u.iterations,
                if u.converged { "" } else { " (not converged)" },
                ms(u.seconds),
                u.ratio_to_refactorization,
                match (u.low_rank_seconds, u.low_rank_next_seconds) {
                    (Some(a), Some(b)) => format!("{} / {}", ms(a), ms(b)),
                    _ => "–".into(),
                },
                opt(u
                    .low_rank_stages
                    .map(|[c, f, s]| format!("{} / {} / {}", ms(c), ms(f), ms(s)))),
                opt(u.low_rank_ratios.map(|[a, b]| format!("{a:.2} / {b:.2}"))),
                opt(u.low_rank_backward_error.map(|x| format!("{x:.1e}"))),
                opt(u.updown_seconds.map(ms)),
                opt(u.updown_next_seconds.map(ms)),
                match (u.updown_ratio, u.updown_next_ratio) {
                    (Some(a), Some(b)) => format!("{a:.2} / {b:.2}"),
                    _ => "–".into(),
                },
                opt(u.updown_backward_error.map(|x| format!("{x:.1e}"))),
            );
        }
    }
    s
}

/// Where `fibercell bench --readme` expects the report to be committed.
pub const REPORT_PATH: &str = "benches/results/bench.json";

/// The `fibercell bench` command that measures `r` again (cells, repeats, seed, curve steps and
/// time limit, the CHOLMOD feature when a CHOLMOD backend ran).
pub fn reproduce_command(r: &BenchReport) -> String {
    let cells: Vec<&str> = r.cells.iter().map(|c| c.cell.as_str()).collect();
    let cholmod = r
        .cells
        .iter()
        .flat_map(|c| &c.backends)
        .any(|b| b.name.contains("cholmod"));
    let steps = r
        .cells
        .iter()
        .find_map(|c| c.curve.as_ref())
        .map_or(0, |k| k.steps);
    let limit = r
        .curve_time_limit
        .map_or(String::new(), |s| format!(" --curve-time-limit {s}"));
    format!(
        "cargo run --release{} -- bench --cells {} --repeats {} --seed {} --curve-steps {steps}\
         {limit} --json {REPORT_PATH} --readme docs/performance.md",
        if cholmod { " --features cholmod" } else { "" },
        cells.join(","),
        r.repeats,
        r.seed
    )
}

/// The marker lines between which [`splice_readme`] puts the tables.
pub const README_MARKERS: [&str; 2] = ["<!-- bench:start -->", "<!-- bench:end -->"];

/// Replaces the text between the two [`README_MARKERS`] lines of `readme` (each alone on its
/// line; mentions inside other text do not count) by `tables` and the command that reproduces
/// them; None when a marker line is missing or they are out of order.
pub fn splice_readme(readme: &str, tables: &str, command: &str) -> Option<String> {
    let line_at = |marker: &str, from: usize| -> Option<usize> {
        let mut pos = from;
        for line in readme[from..].split_inclusive('\n') {
            if line.trim_end() == marker {
                return Some(pos);
            }
            pos += line.len();
        }
        None
    };
    let start = line_at(README_MARKERS[0], 0)?;
    let body = start + README_MARKERS[0].len();
    let end = line_at(README_MARKERS[1], body)?;
    Some(format!(
        "{}\n\nReproduce: `{command}`\n\n{}\n{}",
        &readme[..body],
        tables.trim_end(),
        &readme[end..]
    ))
}
