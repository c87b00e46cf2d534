//! The `fibercell` command line: a thin shell over the library.

use clap::{Args, Parser, Subcommand};
use fibercell::io::NetworkFormat;
use fibercell::solve::{
    solve_incremental, solve_static, IncrementalOptions, SolveOptions, SolverKind,
};
use fibercell::solver::FillOrdering;
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

/// The linear solver of every command that solves.
#[derive(clap::Args, Clone, Debug)]
struct SolverArgs {
    /// Linear solver backend (cholmod needs a build with `--features cholmod`); it solves
    /// every system, as Coulomb sliding is solved on symmetric ones (a fixed point on the
    /// friction bounds).
    #[arg(long, default_value = "faer-cholesky", value_parser = solver_parser())]
    solver: SolverKind,
    /// Fill-reducing ordering of the Cholesky backends: auto (the better of amd and nd by
    /// predicted flops), amd, nd (nested dissection, METIS) or natural.
    #[arg(long, default_value = "auto", value_parser = ordering_parser())]
    ordering: FillOrdering,
}

impl SolverArgs {
    /// The library's options for these flags.
    fn options(&self) -> SolveOptions {
        SolveOptions {
            solver: self.solver,
            ordering: self.ordering.clone(),
            ..SolveOptions::default()
        }
    }
}

/// The random cells of `ensemble` and `rve-study`: a generator and the seeds of its realizations.
#[derive(clap::Args, Clone, Debug)]
struct GeneratorArgs {
    /// Non-woven preset (S, M, L or XL) as the generator.
    #[arg(long, conflicts_with = "params", required_unless_present = "params")]
    preset: Option<String>,
    /// Generator parameter file (`family = "nonwoven"` etc., as `fixtures/cells/*.params.toml`).
    #[arg(long)]
    params: Option<PathBuf>,
    /// Number of realizations N (per cell size in `rve-study`).
    #[arg(short = 'n', long)]
    realizations: usize,
    /// Seed of the first realization; the others follow it (at every size in `rve-study`).
    #[arg(long, default_value_t = 1)]
    first_seed: u64,
}

impl GeneratorArgs {
    /// The generator's parameters (a preset's for the first seed) and its name for titles.
    fn cell_params(&self) -> Result<(fibercell::generate::CellParams, String), Error> {
        use fibercell::generate::{nonwoven_preset, CellParams};
        match (&self.preset, &self.params) {
            (Some(p), _) => Ok((
                CellParams::Nonwoven(nonwoven_preset(p, self.first_seed)?),
                format!("non-woven {p}"),
            )),
            (None, Some(path)) => Ok((io::read_cell_params(path)?, path.display().to_string())),
            (None, None) => Err(Error::InvalidOption(
                "give the generator: --preset S|M|L|XL or --params FILE".into(),
            )),
        }
    }
}

/// `-d DIR`: the directory of a command's result files (`-o` still accepted).
#[derive(Args, Clone)]
struct OutDir {
    /// Directory for the result files (CSV, JSON, VTK, plots); created if missing.
    #[arg(
        short = 'd',
        long = "out-dir",
        value_name = "DIR",
        default_value = "fibercell-results",
        short_alias = 'o',
        alias = "output"
    )]
    dir: PathBuf,
}

/// `--vtk`: how VTK files are encoded.
#[derive(Args, Clone, Copy)]
struct VtkArgs {
    /// Encoding of the VTK files: auto (text up to 20,000 points, base64 binary above), ascii
    /// or binary.
    #[arg(long = "vtk", value_name = "ENCODING", default_value = "auto", value_parser = vtk_parser())]
    encoding: io::VtkEncoding,
}

#[derive(Subcommand)]
enum Command {
    /// Solve the linear static problem of a model (supports and nodal loads from the file).
    Solve {
        /// Model file: .toml, .json or Abaqus .inp.
        model: PathBuf,
        #[command(flatten)]
        solver: SolverArgs,
        /// Print one JSON document (displacements, reactions, solver report) to stdout.
        #[arg(long)]
        json: bool,
        /// Load increments of the stick/slip solver (models with contact).
        #[arg(long, default_value_t = 10)]
        steps: usize,
        /// Slide along the directions of a frictionless pre-run (thesis Remark 4.38) instead of
        /// the per-contact return mapping.
        #[arg(long)]
        fixed_slip_direction: bool,
        /// Print one line per increment on stderr (models with contact): state iterations,
        /// factorizations, low-rank solves and their sizes, cutbacks, contact states, time.
        #[arg(long)]
        log: bool,
        #[command(flatten)]
        output: OutDir,
        #[command(flatten)]
        vtk: VtkArgs,
    },
    /// Effective stiffness of a periodic cell: ABD per unit area, the thesis's moduli and the
    /// orthotropic constants.
    Homogenize {
        /// Model file with a [cell] section.
        model: PathBuf,
        #[command(flatten)]
        solver: SolverArgs,
        /// Print one JSON document instead of the table.
        #[arg(long)]
        json: bool,
        /// Also write homogenized.json and the cell-problem solutions (case_*.vtp) to this
        /// directory; created if missing.
        #[arg(
            short = 'd',
            long = "out-dir",
            value_name = "DIR",
            short_alias = 'o',
            alias = "output"
        )]
        output: Option<PathBuf>,
        #[command(flatten)]
        vtk: VtkArgs,
    },
    /// The friction-driven elasto-plastic curve of a periodic cell with contacts: ramp a
    /// macroscopic strain (e.g. --strain e11=0.02 or --strain g12=0.01,k11=2) over --steps.
    Curve {
        /// Model file with [cell] and [contact].
        model: PathBuf,
        /// Target macroscopic strain: comma-separated name=value with names e11 e22 g12 k11 k22 k12.
        #[arg(long, value_parser = parse_strain)]
        strain: fibercell::cell::MacroStrain,
        /// Increments of the loading branch.
        #[arg(long, default_value_t = 100)]
        steps: usize,
        /// Unload to zero and reload (hysteresis).
        #[arg(long)]
        unload: bool,
        #[command(flatten)]
        solver: SolverArgs,
        /// Print one JSON document.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        output: OutDir,
        /// Bonded contacts: closed ones never open, open ones never close; only stick and
        /// slip evolve. The same as `bonded = true` in the model's [contact], which the
        /// generated non-wovens set.
        #[arg(long)]
        bonded: bool,
        /// Relative stiffness of stabilizing springs on open and sliding contacts (e.g. 1e-8),
        /// so fibers that lose their hold do not make the system singular.
        #[arg(long, default_value_t = 0.0)]
        stabilization: f64,
        /// Print one line per increment on stderr: state iterations, factorizations, low-rank
        /// solves and their sizes, cutbacks, contact states, time.
        #[arg(long)]
        log: bool,
    },
    /// Generate a periodic fabric cell and print its statistics.
    Generate {
        #[command(subcommand)]
        kind: GenerateKind,
    },
    /// The scatter of a random cell's effective stiffness: N realizations of a generator with
    /// consecutive seeds, the six cell problems of each, and per ABD entry the mean, standard
    /// deviation and 95 % confidence interval, with the interval's convergence as N grows.
    /// Each realization is stored in DIR/realizations as it finishes; a rerun with the same DIR
    /// reuses them (a killed run loses no finished work).
    Ensemble {
        #[command(flatten)]
        generator: GeneratorArgs,
        /// Also the elasto-plastic curve of each realization to this macroscopic strain (as
        /// `curve --strain`), with per point the mean and 95 % interval of the resultants.
        #[arg(long, value_parser = parse_strain)]
        strain: Option<fibercell::cell::MacroStrain>,
        /// Increments of the curves' loading branch.
        #[arg(long, default_value_t = 100, requires = "strain")]
        steps: usize,
        /// Unload the curves to zero and reload.
        #[arg(long, requires = "strain")]
        unload: bool,
        #[command(flatten)]
        solver: SolverArgs,
        /// Print one JSON document instead of the table.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        out: OutDir,
    },
    /// The representative volume of a non-woven: an ensemble at each cell size (fibers per
    /// unit area kept), the main moduli's mean and scatter against size, and the size from
    /// which their relative 95 % interval stays within the tolerance. Each size keeps its
    /// realizations in DIR/size-<L>; a rerun reuses them.
    RveStudy {
        #[command(flatten)]
        generator: GeneratorArgs,
        /// Cell sides L in m, comma-separated and increasing (square cells L × L).
        #[arg(long, value_delimiter = ',', required = true)]
        sizes: Vec<f64>,
        /// Largest relative 95 % interval of a main modulus's mean at a representative size.
        #[arg(long, default_value_t = 0.05)]
        tolerance: f64,
        #[command(flatten)]
        solver: SolverArgs,
        /// Print one JSON document instead of the table.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        out: OutDir,
    },
    /// Statistics of a model: fibers, length, volume fraction, orientation tensor, contacts.
    Stats {
        /// Model file.
        model: PathBuf,
        /// Print one JSON document.
        #[arg(long)]
        json: bool,
        /// Also draw the orientation rose (18 bins of 10°) to PREFIX.svg and PREFIX.png.
        #[arg(long, value_name = "PREFIX")]
        rose: Option<PathBuf>,
    },
    /// Convert a model between formats: .toml, .json, .inp (Abaqus) in and out; .vtp, .vtu and
    /// .pvd (ParaView) out.
    Convert {
        /// Input model (.toml, .json or .inp).
        input: PathBuf,
        /// Output file (.toml, .json, .inp, .vtp, .vtu or .pvd).
        output: PathBuf,
        #[command(flatten)]
        vtk: VtkArgs,
        /// The solver a .inp file is for: abaqus (two-node B31 beams, read back exactly) or
        /// calculix (ccx: B32 beams with midside nodes, and a cell step applying --cell-strain).
        #[arg(long, value_name = "SOLVER", default_value = "abaqus", value_parser = flavour_parser())]
        flavour: io::InpFlavour,
        /// Membrane strain of a cell's CalculiX step, e.g. e11=0.001 or g12=0.002.
        #[arg(long, value_parser = parse_strain, default_value = "e11=0.001")]
        cell_strain: fibercell::cell::MacroStrain,
    },
    /// Throughput benchmark on generated non-woven cells: every stage timed, against the
    /// machine's measured DGEMM and memory bandwidth (see docs/performance.md).
    Bench {
        /// Presets to run, comma-separated: S, M, L.
        #[arg(long, default_value = "S,M", value_delimiter = ',')]
        cells: Vec<String>,
        /// Write the full report as JSON here.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Write the Markdown tables here too.
        #[arg(long)]
        markdown: Option<PathBuf>,
        /// Repeats of each stage (medians are reported; contact search and value fills at
        /// least 15).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Generator seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Increments of the elasto-plastic curve (0: skip it).
        #[arg(long, default_value_t = 100)]
        curve_steps: usize,
        /// Wall-clock limit of one curve in seconds: it stops there and the rest is projected.
        #[arg(long, default_value_t = fibercell_bench::DEFAULT_CURVE_TIME_LIMIT)]
        curve_time_limit: f64,
        /// Do not run: render the report of an earlier --json file.
        #[arg(long)]
        from_json: Option<PathBuf>,
        /// Replace the performance tables of this Markdown file (docs/performance.md; between
        /// its bench:start and bench:end markers) with this report.
        #[arg(long)]
        readme: Option<PathBuf>,
    },
    /// Solve A x = b for a matrix in Matrix Market form (coordinate real/integer, general or
    /// symmetric) with any backend, and report the phases' times, nnz(L), flops and the
    /// residual: the solver layer on matrices from anywhere.
    SolveMatrix {
        /// Matrix Market file of A.
        matrix: PathBuf,
        /// Matrix Market `array` file of b (default: b = A·1, whose solution is all ones).
        #[arg(long)]
        rhs: Option<PathBuf>,
        #[command(flatten)]
        solver: SolverArgs,
        /// Run the analysis and the factorization this many times and report their medians
        /// (the factorizations reuse the last analysis).
        #[arg(long, default_value_t = 1)]
        repeats: usize,
        /// Print one JSON document.
        #[arg(long)]
        json: bool,
    },
    /// Write the matrix a model's job solves in Matrix Market form (symmetric, lower triangle):
    /// a cell's six elastic cell problems, or a supported model's reduced K. Beside it,
    /// OUT_rhs.mtx holds the right-hand sides and OUT_dofs.csv the node and DOF of every row.
    ExportMatrix {
        /// Model file.
        model: PathBuf,
        /// Output .mtx file.
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
    },
    /// Property checks of a model: symmetry, definiteness and conditioning of the system its
    /// job solves (closed contacts in stick), a cell's null space before its anchor (the three
    /// translations) or a free model's (six rigid modes per piece), the contacts' penetration
    /// at the solution relative to the radii and, for a cell with contacts, the penalty study
    /// of its moduli (ABD at p, 10p, 100p, the limit p → ∞ and the penalty an accuracy
    /// needs). Exit code 1 when a check fails.
    Check {
        /// Model file.
        model: PathBuf,
        #[command(flatten)]
        solver: SolverArgs,
        /// Print one JSON document instead of the table.
        #[arg(long)]
        json: bool,
        /// Relative accuracy required of the moduli: a larger penalty error at the model's
        /// penalties fails the check (without it the study reports the penalty for 1 %).
        #[arg(long)]
        accuracy: Option<f64>,
        /// Skip the penalty study (three more homogenizations).
        #[arg(long)]
        no_penalty_study: bool,
        /// Cells: the macroscopic strain the contact penetration is measured at (each of
        /// ε11, ε22, γ12 alone; curvatures 2ε/h).
        #[arg(long, default_value_t = 1e-2)]
        penetration_strain: f64,
        /// Largest accepted contact penetration, relative to the smaller radius of the two
        /// fibers.
        #[arg(long, default_value_t = fibercell::check::DEFAULT_MAX_PENETRATION)]
        max_penetration: f64,
    },
}

#[derive(Subcommand)]
enum GenerateKind {
    /// A stochastic non-woven: fibers deposited one on another (see docs/generators.md).
    Nonwoven {
        /// All parameters from a TOML file (the fields of `generate::NonWoven`); the flags
        /// below override it.
        #[arg(long, conflicts_with = "preset")]
        params: Option<PathBuf>,
        /// Start from a benchmark cell: S, M, L or XL (see docs/generators.md).
        #[arg(long)]
        preset: Option<String>,
        /// Cell periods Lx,Ly (m).
        #[arg(long, value_parser = parse_pair)]
        size: Option<[f64; 2]>,
        /// Number of fibers.
        #[arg(long, conflicts_with = "volume_fraction")]
        fibers: Option<usize>,
        /// Solid volume fraction with --thickness instead of --fibers.
        #[arg(long, requires = "thickness")]
        volume_fraction: Option<f64>,
        /// Nominal thickness (m) for --volume-fraction.
        #[arg(long)]
        thickness: Option<f64>,
        /// Mean fiber length (m).
        #[arg(long)]
        length: Option<f64>,
        /// Coefficient of variation of the (log-normal) length; 0: all equal.
        #[arg(long)]
        length_cv: Option<f64>,
        /// Fiber radius (m).
        #[arg(long)]
        radius: Option<f64>,
        /// isotropic, tensor:A11,A12 or vonmises:ANGLE,KAPPA (angle in degrees).
        #[arg(long, value_parser = parse_orientation)]
        orientation: Option<fibercell::generate::Orientation>,
        /// Largest out-of-plane tilt (degrees).
        #[arg(long)]
        tilt: Option<f64>,
        /// In-plane curvature of the fibers (1/m).
        #[arg(long)]
        curl: Option<f64>,
        /// Largest element length (m).
        #[arg(long)]
        element_length: Option<f64>,
        /// Random seed.
        #[arg(long)]
        seed: Option<u64>,
        /// Output model file (.toml or .json).
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
    },
    /// A plain or twill weave (see docs/generators.md).
    Woven {
        /// All parameters from a TOML file (the fields of `generate::Weave`).
        #[arg(long)]
        params: Option<PathBuf>,
        /// plain, or twill:OVER/UNDER (e.g. twill:2/1).
        #[arg(long, value_parser = parse_weave_pattern)]
        pattern: Option<fibercell::generate::WeavePattern>,
        /// Cell size Lx,Ly (m): one repeat of the pattern.
        #[arg(long, value_parser = parse_pair)]
        size: Option<[f64; 2]>,
        /// Yarn radius (m).
        #[arg(long)]
        radius: Option<f64>,
        /// Output model file (.toml or .json).
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
    },
    /// A geotextile: families of straight fibers with fixed junctions, in layers.
    Geotextile {
        /// All parameters from a TOML file (the fields of `generate::Geotextile`).
        #[arg(long)]
        params: Option<PathBuf>,
        /// Cell periods Lx,Ly (m).
        #[arg(long, value_parser = parse_pair)]
        size: Option<[f64; 2]>,
        /// A fiber family ANGLE_DEG,SPACING,RADIUS[,LAYER]; repeat for each family.
        #[arg(long = "family", value_parser = parse_family)]
        families: Vec<fibercell::generate::FiberFamily>,
        /// Layers touch with Coulomb friction MU instead of connector beams.
        #[arg(long)]
        contact_mu: Option<f64>,
        /// Largest element length (m).
        #[arg(long)]
        element_length: Option<f64>,
        /// Output model file (.toml or .json).
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
    },
    /// Any family from a catalog parameter file (`family = "woven"|"geotextile"|"knitted"|
    /// "nonwoven"` and the generator's fields, as in fixtures/cells/*.params.toml).
    From {
        /// Parameter file (TOML).
        params: PathBuf,
        /// Output model file (.toml or .json).
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
    },
    /// A plain-jersey knit of interlocked loops.
    Knitted {
        /// All parameters from a TOML file (the fields of `generate::Knit`).
        #[arg(long)]
        params: Option<PathBuf>,
        /// Loops per course in the cell.
        #[arg(long)]
        wales: Option<usize>,
        /// Courses in the cell.
        #[arg(long)]
        courses: Option<usize>,
        /// Yarn radius (m).
        #[arg(long)]
        radius: Option<f64>,
        /// Output model file (.toml or .json).
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
    },
}

fn parse_weave_pattern(s: &str) -> Result<fibercell::generate::WeavePattern, String> {
    use fibercell::generate::WeavePattern;
    if s == "plain" {
        return Ok(WeavePattern::Plain);
    }
    let floats = s
        .strip_prefix("twill:")
        .and_then(|f| f.split_once('/'))
        .ok_or_else(|| format!("\"{s}\" is not plain or twill:OVER/UNDER"))?;
    let num = |v: &str| {
        v.trim()
            .parse::<usize>()
            .map_err(|_| format!("\"{v}\" is not a whole number"))
    };
    Ok(WeavePattern::Twill {
        over: num(floats.0)?,
        under: num(floats.1)?,
    })
}

fn parse_family(s: &str) -> Result<fibercell::generate::FiberFamily, String> {
    let v: Vec<&str> = s.split(',').collect();
    if !(3..=4).contains(&v.len()) {
        return Err(format!("\"{s}\" is not ANGLE_DEG,SPACING,RADIUS[,LAYER]"));
    }
    let num = |x: &str| {
        x.trim()
            .parse::<f64>()
            .map_err(|_| format!("\"{x}\" is not a number"))
    };
    let layer = match v.get(3) {
        Some(l) => l
            .trim()
            .parse::<usize>()
            .map_err(|_| format!("layer \"{l}\" is not a whole number"))?,
        None => 0,
    };
    Ok(fibercell::generate::FiberFamily {
        angle_degrees: num(v[0])?,
        spacing: num(v[1])?,
        radius: num(v[2])?,
        offset: None,
        layer,
    })
}

fn parse_pair(s: &str) -> Result<[f64; 2], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| {
            p.trim()
                .parse::<f64>()
                .map_err(|_| format!("\"{p}\" is not a number"))
        })
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [a, b] => Ok([*a, *b]),
        _ => Err(format!("\"{s}\" is not two comma-separated numbers")),
    }
}

fn parse_orientation(s: &str) -> Result<fibercell::generate::Orientation, String> {
    use fibercell::generate::Orientation;
    match s.split_once(':') {
        None if s == "isotropic" => Ok(Orientation::Isotropic),
        Some(("tensor", v)) => {
            let [a11, a12] = parse_pair(v)?;
            Ok(Orientation::Tensor { a11, a12 })
        }
        Some(("vonmises", v)) => {
            let [angle, kappa] = parse_pair(v)?;
            Ok(Orientation::VonMises {
                mean_angle_degrees: angle,
                concentration: kappa,
            })
        }
        _ => Err(format!(
            "unknown orientation \"{s}\" (use isotropic, tensor:A11,A12 or vonmises:ANGLE,KAPPA)"
        )),
    }
}

/// `--solver`: the backends' names, listed in `--help`.
fn solver_parser() -> impl clap::builder::TypedValueParser<Value = SolverKind> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(SolverKind::ALL.map(SolverKind::name))
        .try_map(|s| s.parse::<SolverKind>())
}

/// `--vtk`: the encodings' names, listed in `--help`.
fn flavour_parser() -> impl clap::builder::TypedValueParser<Value = io::InpFlavour> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(["abaqus", "calculix"]).map(|s| {
        if s == "calculix" {
            io::InpFlavour::CalculiX
        } else {
            io::InpFlavour::Abaqus
        }
    })
}

fn vtk_parser() -> impl clap::builder::TypedValueParser<Value = io::VtkEncoding> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(["auto", "ascii", "binary"]).map(|s| {
        match s.as_str() {
            "ascii" => io::VtkEncoding::Ascii,
            "binary" => io::VtkEncoding::Binary,
            _ => io::VtkEncoding::Auto,
        }
    })
}

/// `--ordering`: the orderings' names, listed in `--help`.
fn ordering_parser() -> impl clap::builder::TypedValueParser<Value = FillOrdering> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(FillOrdering::NAMES)
        .try_map(|s| FillOrdering::parse(&s))
}

fn parse_strain(s: &str) -> Result<fibercell::cell::MacroStrain, String> {
    fibercell::cell::parse_macro_strain(s)
}

fn bench(
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

fn write(path: &Path, contents: &str) -> Result<(), Error> {
    io::write_atomic(path, contents.as_bytes())
}

/// A progress bar on stderr for runs of many increments (hidden when stderr is not a terminal);
/// with `log`, also one line per increment: its iterations, factorizations, low-rank solves
/// and their largest capacitance order, the crossover order, cutbacks, sliding contacts, time.
fn progress_bar(what: &str, log: bool) -> (indicatif::ProgressBar, fibercell::solve::Progress) {
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

fn to_pretty<T: serde::Serialize>(doc: &T) -> Result<String, Error> {
    serde_json::to_string_pretty(doc).map_err(|e| Error::Output {
        path: "json".into(),
        message: e.to_string(),
    })
}

fn solve(
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

fn largest(d: &[[f64; 6]]) -> f64 {
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

fn homogenize(
    model_path: &Path,
    options: SolveOptions,
    json: bool,
    (out, vtk): (Option<&Path>, io::VtkEncoding),
) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    let h = fibercell::homogenize::homogenize_elastic(&model, &options)?;
    let pretty = to_pretty(&h)?;
    if let Some(out) = out {
        // homogenized.json is written last: a folder that holds it is complete.
        io::begin_results(out, "homogenized.json")?;
        for (k, case) in h.cases.iter().enumerate() {
            let name = format!("case_{}.vtp", fibercell::cell::MACRO_NAMES[k]);
            write(
                &out.join(name),
                &io::network_vtk(&model, case, NetworkFormat::PolyData, vtk),
            )?;
        }
        write(
            &out.join("case_pressure.vtp"),
            &io::network_vtk(
                &model,
                &h.pressure.displacements,
                NetworkFormat::PolyData,
                vtk,
            ),
        )?;
        write(&out.join("homogenized.json"), &pretty)?;
    }
    if json {
        println!("{pretty}");
        return Ok(());
    }
    println!(
        "{}: cell {:.4e} m² ({} free DOFs, {} paired boundary nodes), thickness {:.4e} m, backend {}",
        model_path.display(),
        h.area,
        h.free_dofs,
        h.paired_nodes,
        h.thickness,
        h.backend
    );
    println!(
        "ABD per unit area (rows/columns e11 e22 g12 k11 k22 k12; A in N/m, B in N, D in N·m):"
    );
    for row in &h.abd {
        println!(
            "  {}",
            row.iter()
                .map(|v| format!("{v:>13.5e}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    println!("asymmetry max|ABD − ABDᵀ|/max|ABD| = {:.2e}", h.asymmetry);
    println!(
        "solves: backward error {:.2e}, relative residual {:.2e} (largest of the seven)",
        h.backward_error, h.relative_residual
    );
    let m = &h.moduli;
    println!(
        "moduli: a11_11 {:.5e}  a22_22 {:.5e}  a12_12 {:.5e}  a22_11 {:.5e} N/m;  c1111 {:.5e}  c1122 {:.5e}  c2222 {:.5e} N·m",
        m.a11_11, m.a22_22, m.a12_12, m.a22_11, m.c1111, m.c1122, m.c2222
    );
    let o = &h.orthotropic;
    println!(
        "orthotropic: E1 {:.5e} N/m ({:.5e} Pa)  E2 {:.5e} N/m ({:.5e} Pa)  G12 {:.5e} N/m ({:.5e} Pa)\n  nu12 {:.5} (-e22/e11 under N11 = A12/A22, the thesis's nu21)  nu21 {:.5} (-e11/e22 under N22 = A12/A11, the thesis's nu12)",
        o.e1, o.e1_pa, o.e2, o.e2_pa, o.g12, o.g12_pa, o.nu12, o.nu21
    );
    let b = &h.pressure.b_hom;
    println!(
        "pressure (1 Pa down on the {:.1} % of the cell seen from above, balanced by a body force): B_hom N11 {:.5e} N22 {:.5e} N12 {:.5e} m;  M11 {:.5e} M22 {:.5e} M12 {:.5e} m²",
        100.0 * h.pressure.coverage,
        b[0], b[1], b[2], b[3], b[4], b[5]
    );
    let t = &h.timings;
    println!(
        "time (s): setup {:.3}  assembly {:.3}  analysis {:.3}  factorization {:.3}  pressure load {:.3}  7 solves {:.3}  post {:.3}  total {:.3}",
        t.setup, t.assembly, t.analysis, t.factorization, t.pressure_load, t.solve, t.post, t.total
    );
    Ok(())
}

fn curve(
    model_path: &Path,
    (strain, steps, unload): (fibercell::cell::MacroStrain, usize, bool),
    (solve, bonded, stabilization): (SolveOptions, bool, f64),
    (json, log): (bool, bool),
    out: &Path,
) -> Result<(), Error> {
    use fibercell::homogenize::{elasto_plastic_curve, CurveOptions};
    let model = io::load_model(model_path)?;
    // curve.json is written last: a folder that holds it is complete.
    io::begin_results(out, "curve.json")?;
    let (bar, progress) = progress_bar("curve", log);
    let incremental = IncrementalOptions {
        progress: Some(progress),
        bonded,
        stabilization,
        solve,
        ..IncrementalOptions::default()
    };
    let c = elasto_plastic_curve(
        &model,
        &CurveOptions {
            strain,
            steps,
            unload,
            incremental,
        },
    );
    bar.finish_and_clear();
    let c = c?;
    let title = format!(
        "{}: elasto-plastic curve ({} switches to slip)",
        model_path.display(),
        c.switches.iter().filter(|s| s.to == "slip").count()
    );
    io::write_curve_files(out, &c, &title)?;
    if json {
        println!("{}", to_pretty(&c)?);
        return Ok(());
    }
    let k = io::dominant_component(&strain);
    let last = c.points.last();
    println!(
        "{}: {} increments, {} switches, {} linear segments; final {} = {:.4e} {}, dissipated {:.4e} J/m²; results in {}",
        model_path.display(),
        c.points.len(),
        c.switches.len(),
        c.segments.len(),
        io::RESULTANT_NAMES[k],
        last.map_or(0.0, |p| p.resultant[k]),
        io::RESULTANT_UNITS[k],
        last.map_or(0.0, |p| p.dissipated),
        out.display()
    );
    for s in c.switches.iter().take(20) {
        println!(
            "  contact {} {} → {} at {} = {:.6e} (increment {})",
            s.contact,
            s.from,
            s.to,
            fibercell::cell::MACRO_NAMES[k],
            s.estimated_strain[k],
            s.step
        );
    }
    if c.switches.len() > 20 {
        println!("  … {} switches in all (switches.csv)", c.switches.len());
    }
    Ok(())
}

fn ensemble(
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

fn rve_study(
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

fn generate(kind: GenerateKind) -> Result<(), Error> {
    use fibercell::generate::{CellParams, FiberAmount, LengthDistribution, NonWoven};
    match kind {
        GenerateKind::Nonwoven {
            params,
            preset,
            size,
            fibers,
            volume_fraction,
            thickness,
            length,
            length_cv,
            radius,
            orientation,
            tilt,
            curl,
            element_length,
            seed,
            output,
        } => {
            let mut p = match params {
                Some(path) => io::read_toml_file::<NonWoven>(&path)?,
                None => match preset {
                    Some(name) => fibercell::generate::nonwoven_preset(&name, 1)?,
                    None => NonWoven::default(),
                },
            };
            if let Some(v) = size {
                p.size = v;
            }
            if let Some(fibers) = fibers {
                p.amount = FiberAmount::Count { fibers };
            }
            if let (Some(fraction), Some(thickness)) = (volume_fraction, thickness) {
                p.amount = FiberAmount::VolumeFraction {
                    fraction,
                    thickness,
                };
            }
            if length.is_some() || length_cv.is_some() {
                let mean = length.unwrap_or(match p.length {
                    LengthDistribution::Fixed { length } => length,
                    LengthDistribution::LogNormal { mean, .. } => mean,
                });
                // A cv of 0 is a fixed length; any other (NaN and negative ones too) goes to
                // the generator's validation, like the parameter file's.
                p.length = match length_cv {
                    Some(cv) if cv != 0.0 => LengthDistribution::LogNormal { mean, cv },
                    _ => LengthDistribution::Fixed { length: mean },
                };
            }
            if let Some(v) = radius {
                p.radius = v;
            }
            if let Some(v) = orientation {
                p.orientation = v;
            }
            if let Some(v) = tilt {
                p.tilt_degrees = v;
            }
            if let Some(v) = curl {
                p.curl = v;
            }
            if let Some(v) = element_length {
                p.element_length = v;
            }
            if let Some(v) = seed {
                p.seed = v;
            }
            let t = std::time::Instant::now();
            let cell = fibercell::generate::nonwoven(&p)?;
            let r = &cell.report;
            let label = format!(
                "non-woven (seed {}): {} fibers deposited, {} dropped (touching nothing), {} supports",
                p.seed, r.deposited, r.dropped, r.supports
            );
            finish_generated(&label, t, &cell.description, &output)
        }
        GenerateKind::Woven {
            params,
            pattern,
            size,
            radius,
            output,
        } => {
            let mut p: fibercell::generate::Weave = params_or_default(params.as_deref())?;
            if let Some(v) = pattern {
                p.pattern = v;
            }
            if let Some(v) = size {
                p.size = v;
            }
            if let Some(v) = radius {
                p.radius = v;
            }
            generate_cell(CellParams::Woven(p), &output)
        }
        GenerateKind::Geotextile {
            params,
            size,
            families,
            contact_mu,
            element_length,
            output,
        } => {
            let mut p: fibercell::generate::Geotextile = params_or_default(params.as_deref())?;
            if let Some(v) = size {
                p.size = v;
            }
            if !families.is_empty() {
                p.families = families;
            }
            if let Some(mu) = contact_mu {
                p.layer_junction = fibercell::generate::LayerJunction::Contact { mu };
            }
            if let Some(v) = element_length {
                p.element_length = v;
            }
            generate_cell(CellParams::Geotextile(p), &output)
        }
        GenerateKind::From { params, output } => {
            generate_cell(fibercell::io::read_cell_params(&params)?, &output)
        }
        GenerateKind::Knitted {
            params,
            wales,
            courses,
            radius,
            output,
        } => {
            let mut p: fibercell::generate::Knit = params_or_default(params.as_deref())?;
            if let Some(v) = wales {
                p.wales = v;
            }
            if let Some(v) = courses {
                p.courses = v;
            }
            if let Some(v) = radius {
                p.radius = v;
            }
            generate_cell(CellParams::Knitted(p), &output)
        }
    }
}

/// Generator parameters from a TOML file, or the generator's defaults.
fn params_or_default<T: serde::de::DeserializeOwned + Default>(
    path: Option<&Path>,
) -> Result<T, Error> {
    match path {
        Some(path) => io::read_toml_file(path),
        None => Ok(T::default()),
    }
}

/// Generates a cell of any family, writes it and prints its statistics.
fn generate_cell(params: fibercell::generate::CellParams, output: &Path) -> Result<(), Error> {
    let t = std::time::Instant::now();
    let d = params.generate()?;
    let label = match &params {
        fibercell::generate::CellParams::Geotextile(g) => {
            format!("geotextile ({} families)", g.families.len())
        }
        _ => d.name.clone().unwrap_or_default(),
    };
    finish_generated(&label, t, &d, output)
}

/// Writes a generated cell and prints its statistics.
fn finish_generated(
    label: &str,
    started: std::time::Instant,
    d: &fibercell::model::ModelDescription,
    output: &Path,
) -> Result<(), Error> {
    let elapsed = started.elapsed().as_secs_f64();
    let model = fibercell::Model::from_description(d)?;
    let stats = fibercell::stats::network_stats(&model)?;
    io::write_description(output, d)?;
    println!(
        "{label}: generated in {elapsed:.2} s, written to {}",
        output.display()
    );
    println!("{}", stats.summary());
    Ok(())
}

fn stats(model_path: &Path, json: bool, rose: Option<&Path>) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    let s = fibercell::stats::network_stats(&model)?;
    if let Some(prefix) = rose {
        let fractions = fibercell::stats::orientation_histogram(&model, 18);
        let title = format!(
            "{}: fiber orientation (length-weighted)",
            model_path.display()
        );
        let plot = io::RosePlot {
            title: &title,
            fractions: &fractions,
        };
        let (svg, png) = (plot.svg()?, plot.png()?);
        io::write_atomic(&prefix.with_extension("svg"), svg.as_bytes())?;
        io::write_atomic(&prefix.with_extension("png"), &png)?;
    }
    if json {
        println!("{}", to_pretty(&s)?);
    } else {
        println!("{}: {}", model_path.display(), s.summary());
    }
    Ok(())
}

fn convert(input: &Path, output: &Path, opts: &io::WriteOptions) -> Result<(), Error> {
    let d = io::read_description(input)?;
    let written = io::write_model(output, &d, opts)?;
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    println!("{} → {}", input.display(), names.join(", "));
    Ok(())
}

fn read_text(path: &Path) -> Result<String, Error> {
    std::fs::read_to_string(path).map_err(|e| {
        Error::Input(io::InputError::Read {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    })
}

fn solve_matrix(
    matrix: &Path,
    rhs: Option<&Path>,
    solver: &SolverArgs,
    repeats: usize,
    json: bool,
) -> Result<(), Error> {
    let in_file = |path: &Path, e: fibercell::solver::SolverError| {
        Error::Input(io::InputError::Read {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    };
    let a = fibercell::solver::read_matrix_market(&read_text(matrix)?)
        .map_err(|e| in_file(matrix, e))?;
    let b = match rhs {
        Some(path) => {
            let (n, k, values) = fibercell::solver::read_matrix_market_dense(&read_text(path)?)
                .map_err(|e| in_file(path, e))?;
            if k != 1 || n != a.as_ref().nrows() {
                return Err(Error::InvalidOption(format!(
                    "{}: b is {n} × {k}, the matrix needs one column of {}",
                    path.display(),
                    a.as_ref().nrows()
                )));
            }
            Some(values)
        }
        None => None,
    };
    let config = solver.options().solver_config(Vec::new());
    let (_, r) = fibercell::solve::solve_matrix(a.as_ref(), b.as_deref(), &config, repeats)?;
    if json {
        println!("{}", to_pretty(&r)?);
        return Ok(());
    }
    println!(
        "{}: n {}, nnz(A) {}, backend {} (ordering {})",
        matrix.display(),
        r.n,
        r.nnz,
        r.backend,
        r.ordering
    );
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3e}"));
    println!(
        "nnz(L) {}, flops {}, iterations {}",
        r.nnz_factor.map_or("-".to_string(), |v| v.to_string()),
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

fn export_matrix(model_path: &Path, out: &Path) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    let job = io::job_system(&model)?;
    io::write_job_system(&job, model_path, out).map(|_| ())
}

fn check(
    model_path: &Path,
    options: &fibercell::check::CheckOptions,
    json: bool,
) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    let report = fibercell::check::check_model(&model, options)?;
    if json {
        println!("{}", to_pretty(&report)?);
    } else {
        print_check(model_path, &report);
    }
    let failed: Vec<String> = report
        .checks
        .iter()
        .filter(|c| !c.passed)
        .map(|c| format!("{}: {}", c.name, c.value))
        .collect();
    if failed.is_empty() {
        Ok(())
    } else {
        Err(Error::ChecksFailed { failed })
    }
}

fn print_check(model_path: &Path, r: &fibercell::check::CheckReport) {
    println!(
        "{}: {} (n = {}, nnz = {})",
        model_path.display(),
        r.system,
        r.matrix.n,
        r.matrix.nnz
    );
    if let Some(p) = &r.penalty {
        println!(
            "penalty study (penalty_scale {} × 1, 10, 100; limit: A∞ − C/(s + a) through the three):",
            p.model_scale
        );
        println!(
            "  {:<4} {:>12} {:>12} {:>12} {:>12} {:>9} {:>7} {:>9}",
            "", "×1", "×10", "×100", "limit", "±", "ratio", "error ×1"
        );
        for e in &p.entries {
            println!(
                "  {:<4} {:>12.5e} {:>12.5e} {:>12.5e} {:>12.5e} {:>9.1e} {:>7.2} {:>9.2e}",
                e.name,
                e.values[0],
                e.values[1],
                e.values[2],
                e.limit,
                e.limit_error,
                e.convergence_ratio,
                e.error_at_model
            );
        }
        println!(
            "  {:<4} {:>12.1e} {:>12.1e} {:>12.1e}   (round-off: ABD's asymmetry)",
            "rnd", p.roundoff[0], p.roundoff[1], p.roundoff[2]
        );
        if let Some(r) = p.recommended_penalty_scale {
            println!(
                "  for a relative error of {:.0e}: penalty_scale = {r:.3e} in [contact]",
                p.accuracy
            );
        }
        for w in &p.warnings {
            println!("  warning: {w}");
        }
    }
    for c in &r.checks {
        println!(
            "{} {:<28} {}   [{}]",
            if c.passed { "ok  " } else { "FAIL" },
            c.name,
            c.value,
            c.limit
        );
    }
}

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
        } => solve(
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
        } => homogenize(
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
        } => curve(
            &model,
            (strain, steps, unload),
            (solver.options(), bonded, stabilization),
            (json, log),
            &output.dir,
        ),
        Command::Generate { kind } => generate(kind),
        Command::Ensemble {
            generator,
            strain,
            steps,
            unload,
            solver,
            json,
            out,
        } => ensemble(
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
        } => rve_study(
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
        Command::Stats { model, json, rose } => stats(&model, json, rose.as_deref()),
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
            convert(&input, &output, &opts)
        }
        Command::ExportMatrix { model, output } => export_matrix(&model, &output),
        Command::Check {
            model,
            solver,
            json,
            accuracy,
            no_penalty_study,
            penetration_strain,
            max_penetration,
        } => check(
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
            solver,
            repeats,
            json,
        } => solve_matrix(&matrix, rhs.as_deref(), &solver, repeats, json),
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
        } => bench(
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
