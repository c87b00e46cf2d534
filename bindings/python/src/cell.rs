//! The stateful cell in Python: `Cell` (set up once, shared by threads) and `CellState` (one
//! material point), advanced by `Cell.update` and tried by `Cell.trial`.

use crate::{error, solve_options, Model};
use fibercell::solve::IncrementalOptions;
use fibercell::CellResponse;
use numpy::{PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

static NEXT_CELL: AtomicU64 = AtomicU64::new(1);

/// A periodic cell set up once (pairing, contacts, pattern, elastic values) for any number of
/// states; calls with different states may run on different threads at once (the GIL is
/// released while they compute).
#[pyclass(frozen, module = "fibercell")]
pub(crate) struct Cell {
    inner: fibercell::Cell,
    id: u64,
}

/// One material point of a `Cell`: contact states, slips, energies and its factorizations.
#[pyclass(module = "fibercell")]
pub(crate) struct CellState {
    inner: Mutex<fibercell::CellState>,
    cell: u64,
}

#[pymethods]
impl Cell {
    #[new]
    #[pyo3(signature = (model, solver = "faer-cholesky", ordering = "auto", tangent = true))]
    fn new(
        py: Python<'_>,
        model: &Model,
        solver: &str,
        ordering: &str,
        tangent: bool,
    ) -> PyResult<Self> {
        let options = IncrementalOptions {
            solve: solve_options(solver, ordering)?,
            ..IncrementalOptions::default()
        };
        let m = &model.model;
        let mut inner = py
            .detach(|| fibercell::Cell::new(m, &options))
            .map_err(error)?;
        if !tangent {
            inner = inner.without_tangent();
        }
        Ok(Cell {
            inner,
            id: NEXT_CELL.fetch_add(1, Ordering::Relaxed),
        })
    }

    /// A state at rest: zero strain, closed contacts stuck.
    fn new_state(&self) -> CellState {
        CellState {
            inner: Mutex::new(self.inner.new_state()),
            cell: self.id,
        }
    }

    /// Advances `state` by the strain `increment` (6 values: e11, e22, g12, k11, k22, k12) and
    /// commits it; on an error the state is as it was.
    fn update<'py>(
        &self,
        py: Python<'py>,
        state: &CellState,
        increment: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        self.step(py, state, increment, true)
    }

    /// `update`, and the seconds the library call took inside it (without the Python layer):
    /// for measuring the binding's overhead.
    fn timed_update<'py>(
        &self,
        py: Python<'py>,
        state: &CellState,
        increment: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(Bound<'py, PyDict>, f64)> {
        let mut seconds = 0.0;
        let r = self.step_timed(py, state, increment, true, &mut seconds)?;
        Ok((r, seconds))
    }

    /// The response `update` would give, without committing it.
    fn trial<'py>(
        &self,
        py: Python<'py>,
        state: &CellState,
        increment: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        self.step(py, state, increment, false)
    }

    /// Contact pairs of the cell.
    #[getter]
    fn contacts(&self) -> usize {
        self.inner.contacts()
    }

    /// Cell area L_x L_y (m²).
    #[getter]
    fn area(&self) -> f64 {
        self.inner.area()
    }
}

impl Cell {
    fn step<'py>(
        &self,
        py: Python<'py>,
        state: &CellState,
        increment: PyReadonlyArray1<'py, f64>,
        commit: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        self.step_timed(py, state, increment, commit, &mut 0.0)
    }

    /// `step`, the library call's seconds in `seconds`.
    fn step_timed<'py>(
        &self,
        py: Python<'py>,
        state: &CellState,
        increment: PyReadonlyArray1<'py, f64>,
        commit: bool,
        seconds: &mut f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        if state.cell != self.id {
            return Err(error(
                "state belongs to another cell: make it with new_state() of this cell",
            ));
        }
        let inc: [f64; 6] = increment.as_slice()?.try_into().map_err(|_| {
            error(format!(
                "the increment has {} values: give 6 (e11, e22, g12, k11, k22, k12)",
                increment.len().unwrap_or(0)
            ))
        })?;
        let mut guard = state.inner.lock().map_err(error)?;
        let s = &mut *guard;
        let cell = &self.inner;
        let r = py
            .detach(|| {
                let started = std::time::Instant::now();
                let r = if commit {
                    cell.update(s, &inc)
                } else {
                    cell.trial(s, &inc)
                };
                *seconds = started.elapsed().as_secs_f64();
                r
            })
            .map_err(error)?;
        response(py, &r)
    }
}

/// The response as a dict with NumPy arrays.
fn response<'py>(py: Python<'py>, r: &CellResponse) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("strain", PyArray1::from_slice(py, &r.strain))?;
    d.set_item("resultant", PyArray1::from_slice(py, &r.resultant))?;
    match &r.tangent {
        Some(t) => {
            let rows: Vec<Vec<f64>> = t.iter().map(|row| row.to_vec()).collect();
            d.set_item("tangent", PyArray2::from_vec2(py, &rows)?)?
        }
        None => d.set_item("tangent", py.None())?,
    }
    d.set_item("dissipated", r.dissipated)?;
    d.set_item("stored_energy", r.stored_energy)?;
    d.set_item("open", r.open)?;
    d.set_item("stick", r.stick)?;
    d.set_item("slip", r.slip)?;
    d.set_item("iterations", r.iterations)?;
    d.set_item("cutbacks", r.cutbacks)?;
    d.set_item("factorizations", r.factorizations)?;
    d.set_item("held", r.held)?;
    d.set_item("equilibrium_residual", r.equilibrium_residual)?;
    d.set_item("energy_error", r.energy_error)?;
    Ok(d)
}

#[pymethods]
impl CellState {
    /// The macroscopic strain the state is at (e11, e22, g12, k11, k22, k12).
    #[getter]
    fn strain<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let s = self.inner.lock().map_err(error)?;
        Ok(PyArray1::from_slice(py, &s.strain()))
    }

    /// Updates committed so far.
    #[getter]
    fn updates(&self) -> PyResult<usize> {
        Ok(self.inner.lock().map_err(error)?.updates())
    }

    /// A copy of the committed state (its first update factorizes anew).
    fn copy(&self) -> PyResult<CellState> {
        let s = self.inner.lock().map_err(error)?;
        Ok(CellState {
            inner: Mutex::new(s.clone()),
            cell: self.cell,
        })
    }

    /// Drops the state's factorizations and matrix values until its next update, which then
    /// factorizes anew: for many material points, whose caches would not fit in memory.
    fn release_caches(&self) -> PyResult<()> {
        self.inner.lock().map_err(error)?.release_caches();
        Ok(())
    }

    fn __copy__(&self) -> PyResult<CellState> {
        self.copy()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> PyResult<CellState> {
        self.copy()
    }
}
