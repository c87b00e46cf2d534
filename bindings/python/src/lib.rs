//! The Python extension `fibercell._fibercell`: models, the generators, `homogenize`, `curve`,
//! `ensemble`, the stateful cell (`Cell`, `CellState`) and the sparse solver layer. Results cross as the JSON the CLI prints (the same serializer,
//! so the same digits); the Python package (`python/fibercell/__init__.py`) turns them into
//! dictionaries with NumPy arrays. Every call that computes releases the GIL; every error is a
//! `fibercell.FibercellError` (a `ValueError`) with the library's message, the text the CLI
//! prints after `error:`.

mod cell;

use fibercell::homogenize::{elasto_plastic_curve, homogenize_elastic, CurveOptions};
use fibercell::io;
use fibercell::model::ModelDescription;
use fibercell::solve::{IncrementalOptions, MatrixSolver, SolveOptions, SolverConfig};
use fibercell_solver::CscMatrix;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::Mutex;

pyo3::create_exception!(
    _fibercell,
    FibercellError,
    PyValueError,
    "An error of fibercell: malformed or invalid input, a singular system, a failed solve."
);

/// The library's error as a Python exception, its message as the CLI prints it.
fn error(e: impl std::fmt::Display) -> PyErr {
    FibercellError::new_err(e.to_string())
}

/// The solver options of a backend and ordering given by name.
fn solve_options(solver: &str, ordering: &str) -> PyResult<SolveOptions> {
    SolveOptions::by_name(solver, ordering).map_err(error)
}

fn to_json<T: serde::Serialize>(value: &T) -> PyResult<String> {
    serde_json::to_string(value).map_err(error)
}

/// A validated model: fibers, nodes, materials, contacts, and a periodic cell or supports.
#[pyclass(frozen, module = "fibercell")]
struct Model {
    description: ModelDescription,
    model: fibercell::Model,
}

impl Model {
    fn new(description: ModelDescription) -> PyResult<Self> {
        let model = fibercell::Model::from_description(&description).map_err(error)?;
        Ok(Model { description, model })
    }
}

#[pymethods]
impl Model {
    /// Reads a model file: .toml, .json or Abaqus .inp.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let d = py.detach(|| io::read_description(&path)).map_err(error)?;
        Model::new(d)
    }

    /// A model from the text of a TOML model file.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Self> {
        Model::new(io::parse_toml(text, "<toml string>").map_err(error)?)
    }

    /// A model from the text of a JSON model file (also what `fibercell.Model.from_dict`
    /// passes).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Model::new(io::parse_json(text, "<json string>").map_err(error)?)
    }

    /// A model from the text of an Abaqus input file.
    #[staticmethod]
    fn from_inp(text: &str) -> PyResult<Self> {
        Model::new(io::parse_abaqus(text, "<inp string>").map_err(error)?)
    }

    /// The model as the text of a JSON model file.
    fn to_json(&self) -> PyResult<String> {
        io::to_json(&self.description).map_err(error)
    }

    /// The model as the text of a TOML model file.
    fn to_toml(&self) -> PyResult<String> {
        io::to_toml(&self.description).map_err(error)
    }

    /// Writes the model in the format of the path's extension (.toml, .json, .inp, .vtp,
    /// .vtu, .pvd), atomically.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let d = &self.description;
        py.detach(|| io::write_model(&path, d, &io::WriteOptions::default()))
            .map(|_| ())
            .map_err(error)
    }

    /// Number of nodes.
    #[getter]
    fn nodes(&self) -> usize {
        self.model.nodes.len()
    }

    /// Number of fibers.
    #[getter]
    fn fibers(&self) -> usize {
        self.model.fibers.len()
    }

    /// Number of beam elements.
    #[getter]
    fn elements(&self) -> usize {
        self.model.elements().len()
    }

    /// Whether the model is a periodic cell.
    #[getter]
    fn is_cell(&self) -> bool {
        self.model.cell.is_some()
    }

    fn __repr__(&self) -> String {
        format!(
            "fibercell.Model({:?}: {} fibers, {} elements{})",
            self.description.name.as_deref().unwrap_or(""),
            self.model.fibers.len(),
            self.model.elements().len(),
            if self.model.cell.is_some() {
                ", periodic cell"
            } else {
                ""
            }
        )
    }
}

/// A generated cell from the JSON of a parameter set tagged by `family` (woven, geotextile,
/// knitted, nonwoven), as in `fixtures/cells/*.params.toml`; the fields not given keep the
/// generator's defaults.
#[pyfunction]
fn generate_json(py: Python<'_>, params: &str) -> PyResult<Model> {
    let params = fibercell::generate::CellParams::from_json_with_defaults(params).map_err(error)?;
    let d = py.detach(|| params.generate()).map_err(error)?;
    Model::new(d)
}

/// `homogenize`: the elastic ABD of a cell and its moduli, as the JSON the CLI prints.
#[pyfunction]
#[pyo3(signature = (model, solver = "faer-cholesky", ordering = "auto"))]
fn homogenize_json(
    py: Python<'_>,
    model: &Model,
    solver: &str,
    ordering: &str,
) -> PyResult<String> {
    let options = solve_options(solver, ordering)?;
    let m = &model.model;
    let h = py
        .detach(|| homogenize_elastic(m, &options))
        .map_err(error)?;
    to_json(&h)
}

/// `curve`: the elasto-plastic curve of a cell under `strain` ("e11=0.01,g12=0.002"), as the
/// JSON the CLI prints.
#[pyfunction]
#[pyo3(signature = (model, strain, steps = 100, unload = false, solver = "faer-cholesky",
                    ordering = "auto", bonded = false, stabilization = 0.0))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments
fn curve_json(
    py: Python<'_>,
    model: &Model,
    strain: &str,
    steps: usize,
    unload: bool,
    solver: &str,
    ordering: &str,
    bonded: bool,
    stabilization: f64,
) -> PyResult<String> {
    let strain = fibercell::cell::parse_macro_strain(strain).map_err(error)?;
    let opts = CurveOptions {
        strain,
        steps,
        unload,
        incremental: IncrementalOptions {
            solve: solve_options(solver, ordering)?,
            bonded,
            stabilization,
            ..IncrementalOptions::default()
        },
    };
    let m = &model.model;
    let c = py
        .detach(|| elasto_plastic_curve(m, &opts))
        .map_err(error)?;
    to_json(&c)
}

/// `ensemble`: N realizations of the generator of `params` (JSON tagged by `family`, as for
/// `generate_json`) from seed `first_seed`, their ABD and, with `strain`, their curves, with
/// the statistics, as the JSON `fibercell ensemble --json` prints. With `directory` each
/// realization is stored there as it finishes and a rerun reuses them.
#[pyfunction]
#[pyo3(signature = (params, realizations, first_seed = 1, strain = None, steps = 100,
                    unload = false, directory = None, solver = "faer-cholesky",
                    ordering = "auto"))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments
fn ensemble_json(
    py: Python<'_>,
    params: &str,
    realizations: usize,
    first_seed: u64,
    strain: Option<&str>,
    steps: usize,
    unload: bool,
    directory: Option<PathBuf>,
    solver: &str,
    ordering: &str,
) -> PyResult<String> {
    use fibercell::ensemble::{run_ensemble, CurvePath, EnsembleOptions};
    let curve = strain
        .map(|s| {
            fibercell::cell::parse_macro_strain(s).map(|strain| CurvePath {
                strain,
                steps,
                unload,
            })
        })
        .transpose()
        .map_err(error)?;
    let opts = EnsembleOptions {
        params: fibercell::generate::CellParams::from_json_with_defaults(params).map_err(error)?,
        realizations,
        first_seed,
        solve: solve_options(solver, ordering)?,
        curve,
    };
    let e = py
        .detach(|| run_ensemble(&opts, directory.as_deref(), None))
        .map_err(error)?;
    to_json(&e)
}

/// `check`: the property checks of a model, as the JSON `fibercell check --json` prints.
#[pyfunction]
#[pyo3(signature = (model, accuracy = None, penalty_study = true, max_penetration = 0.1,
                    penetration_strain = 0.01, solver = "faer-cholesky", ordering = "auto"))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments
fn check_json(
    py: Python<'_>,
    model: &Model,
    accuracy: Option<f64>,
    penalty_study: bool,
    max_penetration: f64,
    penetration_strain: f64,
    solver: &str,
    ordering: &str,
) -> PyResult<String> {
    let options = fibercell::check::CheckOptions {
        solve: solve_options(solver, ordering)?,
        penalty_study,
        accuracy: accuracy.unwrap_or(1e-2),
        require_accuracy: accuracy.is_some(),
        penetration_strain,
        max_penetration,
    };
    let m = &model.model;
    let report = py
        .detach(|| fibercell::check::check_model(m, &options))
        .map_err(error)?;
    to_json(&report)
}

/// A square CSC matrix from NumPy arrays (both triangles of a symmetric matrix).
fn csc(
    n: usize,
    indptr: &PyReadonlyArray1<'_, i64>,
    indices: &PyReadonlyArray1<'_, i64>,
    data: &PyReadonlyArray1<'_, f64>,
) -> PyResult<CscMatrix> {
    let index = |v: &i64, what: &str| {
        usize::try_from(*v).map_err(|_| error(format!("negative {what} {v} in the CSC arrays")))
    };
    let col_ptr = indptr
        .as_slice()?
        .iter()
        .map(|v| index(v, "column pointer"))
        .collect::<PyResult<Vec<usize>>>()?;
    let row_idx = indices
        .as_slice()?
        .iter()
        .map(|v| index(v, "row index"))
        .collect::<PyResult<Vec<usize>>>()?;
    CscMatrix::new(n, n, col_ptr, row_idx, data.as_slice()?.to_vec()).map_err(error)
}

/// The sparse solver layer: one backend (faer-cholesky, faer-lu, cg, cholmod) with one
/// ordering (auto, amd, nd, natural); `factorize` analyzes first when the pattern is new.
#[pyclass(module = "fibercell")]
struct SparseSolver {
    inner: Mutex<MatrixSolver>,
}

#[pymethods]
impl SparseSolver {
    #[new]
    #[pyo3(signature = (solver = "faer-cholesky", ordering = "auto"))]
    fn new(solver: &str, ordering: &str) -> PyResult<Self> {
        let options = solve_options(solver, ordering)?;
        let config = SolverConfig {
            kind: options.solver,
            ordering: options.ordering,
            ..SolverConfig::default()
        };
        Ok(SparseSolver {
            inner: Mutex::new(MatrixSolver::new(&config).map_err(error)?),
        })
    }

    /// Analyzes (when the pattern is new) and factorizes the n × n CSC matrix given by its
    /// arrays.
    fn factorize(
        &self,
        py: Python<'_>,
        n: usize,
        indptr: PyReadonlyArray1<'_, i64>,
        indices: PyReadonlyArray1<'_, i64>,
        data: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<()> {
        let a = csc(n, &indptr, &indices, &data)?;
        let mut solver = self.inner.lock().map_err(error)?;
        let solver = &mut *solver;
        py.detach(|| solver.factorize(a)).map_err(error)
    }

    /// x with A x = b for the factorized A, checked by its backward error; returns (x, the
    /// backward error).
    fn solve<'py>(
        &self,
        py: Python<'py>,
        b: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, f64)> {
        let b = b.as_slice()?.to_vec();
        let mut solver = self.inner.lock().map_err(error)?;
        let solver = &mut *solver;
        let (x, backward) = py.detach(|| solver.solve(&b)).map_err(error)?;
        Ok((PyArray1::from_vec(py, x), backward))
    }

    /// The backend's name.
    #[getter]
    fn backend(&self) -> PyResult<&'static str> {
        Ok(self.inner.lock().map_err(error)?.backend())
    }
}

#[pymodule]
fn _fibercell(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("FibercellError", m.py().get_type::<FibercellError>())?;
    m.add_class::<Model>()?;
    m.add_class::<SparseSolver>()?;
    m.add_class::<cell::Cell>()?;
    m.add_class::<cell::CellState>()?;
    m.add_function(wrap_pyfunction!(generate_json, m)?)?;
    m.add_function(wrap_pyfunction!(homogenize_json, m)?)?;
    m.add_function(wrap_pyfunction!(curve_json, m)?)?;
    m.add_function(wrap_pyfunction!(ensemble_json, m)?)?;
    m.add_function(wrap_pyfunction!(check_json, m)?)?;
    Ok(())
}
