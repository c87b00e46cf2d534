//! Argument groups several commands share, and the parsers of option values.

use crate::command::Command;
use clap::{Args, Parser};
use fibercell::solve::{SolveOptions, SolverKind};
use fibercell::solver::FillOrdering;
use fibercell::{io, Error};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "fibercell",
    version,
    about = "Effective mechanical properties of textiles from fiber-network cells"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

/// The linear solver of every command that solves.
#[derive(clap::Args, Clone, Debug)]
pub(crate) struct SolverArgs {
    /// Linear solver backend (cholmod needs a build with `--features cholmod`); it solves
    /// every system, as Coulomb sliding is solved on symmetric ones (a fixed point on the
    /// friction bounds).
    #[arg(long, default_value = "faer-cholesky", value_parser = solver_parser())]
    pub(crate) solver: SolverKind,
    /// Fill-reducing ordering of the Cholesky backends: auto (the better of amd and nd by
    /// predicted flops), amd, nd (nested dissection, METIS) or natural.
    #[arg(long, default_value = "auto", value_parser = ordering_parser())]
    pub(crate) ordering: FillOrdering,
}

impl SolverArgs {
    /// The library's options for these flags.
    pub(crate) fn options(&self) -> SolveOptions {
        SolveOptions {
            solver: self.solver,
            ordering: self.ordering.clone(),
            ..SolveOptions::default()
        }
    }
}

/// The random cells of `ensemble` and `rve-study`: a generator and the seeds of its realizations.
#[derive(clap::Args, Clone, Debug)]
pub(crate) struct GeneratorArgs {
    /// Non-woven preset (S, M, L or XL) as the generator.
    #[arg(long, conflicts_with = "params", required_unless_present = "params")]
    pub(crate) preset: Option<String>,
    /// Generator parameter file (`family = "nonwoven"` etc., as `fixtures/cells/*.params.toml`).
    #[arg(long)]
    pub(crate) params: Option<PathBuf>,
    /// Number of realizations N (per cell size in `rve-study`).
    #[arg(short = 'n', long)]
    pub(crate) realizations: usize,
    /// Seed of the first realization; the others follow it (at every size in `rve-study`).
    #[arg(long, default_value_t = 1)]
    pub(crate) first_seed: u64,
}

impl GeneratorArgs {
    /// The generator's parameters (a preset's for the first seed) and its name for titles.
    pub(crate) fn cell_params(&self) -> Result<(fibercell::generate::CellParams, String), Error> {
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
pub(crate) struct OutDir {
    /// Directory for the result files (CSV, JSON, VTK, plots); created if missing.
    #[arg(
        short = 'd',
        long = "out-dir",
        value_name = "DIR",
        default_value = "fibercell-results",
        short_alias = 'o',
        alias = "output"
    )]
    pub(crate) dir: PathBuf,
}

/// `--vtk`: how VTK files are encoded.
#[derive(Args, Clone, Copy)]
pub(crate) struct VtkArgs {
    /// Encoding of the VTK files: auto (text up to 20,000 points, base64 binary above), ascii
    /// or binary.
    #[arg(long = "vtk", value_name = "ENCODING", default_value = "auto", value_parser = vtk_parser())]
    pub(crate) encoding: io::VtkEncoding,
}

pub(crate) fn parse_weave_pattern(s: &str) -> Result<fibercell::generate::WeavePattern, String> {
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

pub(crate) fn parse_family(s: &str) -> Result<fibercell::generate::FiberFamily, String> {
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

pub(crate) fn parse_pair(s: &str) -> Result<[f64; 2], String> {
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

pub(crate) fn parse_orientation(s: &str) -> Result<fibercell::generate::Orientation, String> {
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
pub(crate) fn flavour_parser() -> impl clap::builder::TypedValueParser<Value = io::InpFlavour> {
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

pub(crate) fn parse_strain(s: &str) -> Result<fibercell::cell::MacroStrain, String> {
    fibercell::cell::parse_macro_strain(s)
}
