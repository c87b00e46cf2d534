//! The commands and their flags (the `--help` text is their doc comments).

use crate::args::{
    flavour_parser, parse_family, parse_orientation, parse_pair, parse_strain, parse_weave_pattern,
    GeneratorArgs, OutDir, SolverArgs, VtkArgs,
};
use clap::Subcommand;
use fibercell::io;
use std::path::PathBuf;

#[derive(Subcommand)]
pub(crate) enum Command {
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
        /// Matrix Market `array` file of B, one or more columns (default: b = A·1, whose
        /// solution is all ones), e.g. the OUT_rhs.mtx of `export-matrix`.
        #[arg(long)]
        rhs: Option<PathBuf>,
        /// Write the solution X (Matrix Market `array`, a column per right-hand side).
        #[arg(short, long, value_name = "FILE")]
        output: Option<PathBuf>,
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
pub(crate) enum GenerateKind {
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
