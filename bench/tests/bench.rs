//! The throughput benchmark's library entry point on the small preset: every stage is measured
//! and consistent with the others (same matrix for every backend, the factor-reuse solve
//! converges after one switch, the curve runs), and bad options are typed errors.

use fibercell::Error;
use fibercell_bench::{markdown, reproduce_command, run_bench, splice_readme, BenchOptions};

#[test]
fn the_small_cell_runs_every_stage() {
    let opts = BenchOptions {
        cells: vec!["S".into()],
        repeats: 1,
        curve_steps: 2,
        // Stops the curve after its first increment; the second is projected.
        curve_time_limit: Some(1e-6),
        ..BenchOptions::default()
    };
    let mut log = Vec::new();
    let r = run_bench(&opts, &mut |s| log.push(s.to_string())).expect("bench");
    assert!(r.machine.dgemm_gflops_1 > 0.0 && r.machine.dgemm_gflops_all > 0.0);
    assert!(r.machine.bandwidth_gbs > 0.0);
    let c = &r.cells[0];
    assert_eq!(c.cell, "S");
    assert!(
        c.fibers >= 150 && c.contacts > 500,
        "{} fibers, {} contacts",
        c.fibers,
        c.contacts
    );
    // Entries of K: at least the 12×12 element blocks' distinct couplings of 6×6 node blocks.
    assert!(c.nnz_k >= 36 * (c.dofs / 6));
    for t in [
        c.generation,
        c.contact_search,
        c.pattern,
        c.fill_elements,
        c.fill_contacts,
    ] {
        assert!(t > 0.0 && t.is_finite());
    }
    assert!(!c.backends.is_empty());
    for b in &c.backends {
        let l = b.nnz_l.expect("direct backends report nnz(L)");
        // L holds at least the lower triangle of K.
        assert!(l >= (c.nnz_k + c.dofs) / 2, "{}: nnz(L) {l}", b.name);
        assert!(b.factorize > 0.0 && b.solve > 0.0);
    }
    let one = &c.reuse[0];
    assert_eq!(one.switched, 1);
    assert!(one.converged && one.iterations >= 1, "{one:?}");
    // The ratios divide by the reported steady-state refactorization.
    let refactor = one.refactorization_seconds.expect("faer's refactorization");
    assert!(refactor > 0.0);
    assert!((one.ratio_to_refactorization * refactor - one.seconds).abs() <= 1e-9 * one.seconds);
    let [first, _] = one.low_rank_ratios.expect("low-rank ratios");
    let low_rank = one.low_rank_seconds.expect("low-rank seconds");
    assert!((first * refactor - low_rank).abs() <= 1e-9 * low_rank);
    // Its stages (columns, capacitance, solve) make up the first low-rank solve.
    let stages = one.low_rank_stages.expect("low-rank stages");
    assert!(stages.iter().all(|&t| t >= 0.0), "{stages:?}");
    assert!((stages.iter().sum::<f64>() - low_rank).abs() <= 1e-9 * low_rank);
    let curve = c.curve.as_ref().expect("curve ran");
    assert_eq!(curve.error, None);
    assert!(curve.factorizations >= 1);
    assert_eq!((curve.completed, curve.steps), (1, 2));
    assert!(curve.projected_total > curve.total, "{curve:?}");
    // The default curve is the generated cell as it is, to 1 %; the mild Tresca curve of
    // earlier reports follows it.
    assert_eq!((curve.name.as_str(), curve.strain), ("default", 0.01));
    assert!(
        curve.physics.starts_with("Coulomb μ = 0.3"),
        "{}",
        curve.physics
    );
    let mild = c.mild_curve.as_ref().expect("mild curve ran");
    assert_eq!(
        (mild.name.as_str(), mild.strain, mild.error.as_deref()),
        ("mild", 2e-3, None)
    );
    assert!(mild.physics.starts_with("Tresca"), "{}", mild.physics);
    assert!(curve.max_equilibrium_residual <= 1e-8, "{curve:?}");
    // Memory of the large structures: K's values are nnz(K) doubles, its pattern at least a
    // row index (usize) per entry and an element's slot map (u32: a start per column and an
    // offset per column node and row, 12 + 24 per element);
    // the factor's values 8 · nnz(L), and as stored at least that (faer's supernodes hold
    // L's entries plus square diagonal blocks and relaxed zeros); the curve's outputs at least a contact record per
    // contact and increment and six doubles per node and increment.
    let m = c.memory.as_ref().expect("memory measured");
    assert_eq!(m.values, 8 * c.nnz_k);
    assert!(m.pattern >= 8 * c.nnz_k + 4 * 36 * c.elements, "{m:?}");
    assert_eq!(m.factor, 8 * c.backends[0].nnz_l.unwrap());
    assert_eq!(m.factor_stored, c.backends[0].factor_bytes);
    assert!(
        m.factor_stored.expect("stored bytes reported") >= m.factor,
        "{m:?}"
    );
    let record = size_of::<fibercell::solve::ContactRecord>();
    let per_increment = c.contacts * record + c.dofs / 6 * 48;
    let outputs = curve.output_bytes.expect("curve outputs measured");
    assert!(outputs >= curve.completed * per_increment, "{outputs} B");
    // The all-stick start needs no low-rank solve; the mild curve's sizes are reported too.
    assert!(curve.low_rank_bytes.is_some() && mild.low_rank_bytes.is_some());
    let text = markdown(&r);
    assert!(
        text.contains("| memory: pattern / values of K / faer's factor, 8·nnz(L) (stored) |"),
        "{text}"
    );
    assert!(
        text.contains("| curve: memory: low-rank correction (peak)"),
        "{text}"
    );
    assert!(text.contains("| mild curve: increments, total"), "{text}");
    assert!(text.contains("| curve: low rank: largest order"), "{text}");
    assert!(text.contains("| six cell problems"));
    assert!(text.contains("1 of 2 in"), "{text}");
    let command = reproduce_command(&r);
    for part in [
        "--cells S ",
        "--repeats 1 ",
        "--curve-steps 2 ",
        "--curve-time-limit 0.000001 ",
    ] {
        assert!(command.contains(part), "{command}");
    }
    assert!(log.iter().any(|l| l.contains("S: six cell problems")));
}

#[test]
fn unknown_cells_and_bad_options_are_typed_errors() {
    let bad_cell = BenchOptions {
        cells: vec!["XXL".into()],
        curve_steps: 0,
        ..BenchOptions::default()
    };
    let err = run_bench(&bad_cell, &mut |_| {}).unwrap_err();
    assert!(err.to_string().contains("XXL"), "{err}");
    let no_repeats = BenchOptions {
        repeats: 0,
        ..BenchOptions::default()
    };
    assert!(matches!(
        run_bench(&no_repeats, &mut |_| {}),
        Err(Error::InvalidOption(_))
    ));
}

#[test]
fn the_readme_tables_are_spliced_between_the_markers_only() {
    let readme = "# T\n\nbefore\n<!-- bench:start -->\nold table\n<!-- bench:end -->\nafter\n";
    let new = splice_readme(readme, "| a | b |\n", "fibercell bench").expect("markers");
    assert_eq!(
        new,
        "# T\n\nbefore\n<!-- bench:start -->\n\nReproduce: `fibercell bench`\n\n| a | b |\n\
         <!-- bench:end -->\nafter\n"
    );
    // Splicing again replaces, it does not accumulate.
    assert_eq!(
        splice_readme(&new, "| a | b |\n", "fibercell bench"),
        Some(new.clone())
    );
    assert_eq!(splice_readme("no markers", "x", "c"), None);
    let reversed = "<!-- bench:end -->\n<!-- bench:start -->\n";
    assert_eq!(splice_readme(reversed, "x", "c"), None);
    // A marker quoted inside a sentence is not a marker line.
    let quoted = format!("See `<!-- bench:start -->` below.\n{readme}");
    let spliced = splice_readme(&quoted, "| a | b |\n", "fibercell bench").expect("markers");
    assert!(spliced.starts_with("See `<!-- bench:start -->` below.\n# T\n"));
    assert!(spliced.contains("<!-- bench:start -->\n\nReproduce"));
}

/// docs/performance.md's tables are generated from the committed report: rendering
/// `benches/results/bench.json` again into the page changes nothing (after a new run, write both
/// with `--json benches/results/bench.json --readme docs/performance.md`).
#[test]
fn the_performance_page_is_the_rendering_of_the_committed_report() {
    let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let json = std::fs::read_to_string(root.join("benches/results/bench.json")).expect("report");
    let report: fibercell_bench::BenchReport = serde_json::from_str(&json).expect("a bench report");
    let page = std::fs::read_to_string(root.join("docs/performance.md")).expect("page");
    let rendered = splice_readme(&page, &markdown(&report), &reproduce_command(&report))
        .expect("the page has the bench markers");
    assert!(
        rendered == page,
        "docs/performance.md differs from the rendering of benches/results/bench.json"
    );
}
