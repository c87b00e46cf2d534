//! The stateful cell through the C ABI: `FcCell` (set up once, shared by any number of
//! states and threads) and `FcCellState` (one material point), advanced by `fc_cell_update`
//! and tried by `fc_cell_trial`.

use crate::{guard, invalid, solve_options, Failure, FcModel, FcSolveOptions, FcStatus};
use fibercell::solve::IncrementalOptions;
use fibercell::{Cell, CellResponse, CellState};
use std::sync::atomic::{AtomicU64, Ordering};

/// A periodic cell set up once (pairing, contacts, pattern, elastic values) for any number of
/// `FcCellState`s. Read-only after it is made: calls with different states may run on
/// different threads at once.
pub struct FcCell {
    inner: Cell,
    id: u64,
}

/// One material point of an `FcCell` (contact states, slips, energies, its factorizations).
/// One call at a time per state.
pub struct FcCellState {
    inner: CellState,
    /// The `FcCell` it belongs to.
    cell: u64,
}

/// A state's response to a strain increment.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FcCellResponse {
    /// The macroscopic strain reached: e11, e22, g12, k11, k22, k12.
    pub strain: [f64; 6],
    /// Averaged stress resultants N11, N22, N12 (N/m), M11, M22, M12 (N).
    pub resultant: [f64; 6],
    /// The consistent tangent dN/dE, row-major (rows N11 … M12, columns e11 … k12); zeros
    /// unless `has_tangent`.
    pub tangent: [f64; 36],
    /// Whether `tangent` was computed (the cell was made with `tangent` true).
    pub has_tangent: bool,
    /// Dissipated energy per unit cell area since the state's start (J/m²).
    pub dissipated: f64,
    /// Elastic energy stored per unit area (J/m²).
    pub stored_energy: f64,
    /// Contacts open, stuck and sliding.
    pub open: usize,
    /// Contacts stuck.
    pub stick: usize,
    /// Contacts sliding.
    pub slip: usize,
    /// State iterations of the increment.
    pub iterations: usize,
    /// Times the increment was halved.
    pub cutbacks: usize,
    /// Factorizations the state made itself (none on the cell's shared one at rest).
    pub factorizations: usize,
    /// Contacts held in their state after chattering.
    pub held: usize,
    /// The increment's equilibrium residual ‖R‖/‖F‖.
    pub equilibrium_residual: f64,
    /// The energy balance's relative error.
    pub energy_error: f64,
}

impl From<&CellResponse> for FcCellResponse {
    fn from(r: &CellResponse) -> Self {
        let mut tangent = [0.0; 36];
        if let Some(t) = &r.tangent {
            for (k, v) in tangent.iter_mut().enumerate() {
                *v = t[k / 6][k % 6];
            }
        }
        FcCellResponse {
            strain: r.strain,
            resultant: r.resultant,
            tangent,
            has_tangent: r.tangent.is_some(),
            dissipated: r.dissipated,
            stored_energy: r.stored_energy,
            open: r.open,
            stick: r.stick,
            slip: r.slip,
            iterations: r.iterations,
            cutbacks: r.cutbacks,
            factorizations: r.factorizations,
            held: r.held,
            equilibrium_residual: r.equilibrium_residual,
            energy_error: r.energy_error,
        }
    }
}

static NEXT_CELL: AtomicU64 = AtomicU64::new(1);

/// Sets up the cell `model` (a periodic cell without supports or loads) with the solver
/// `opts` (NULL: the defaults); with `tangent`, responses carry the consistent tangent (one
/// factorization each).
///
/// # Safety
/// `model` is a valid handle; `opts` is NULL or valid; `out` is valid for a write.
#[no_mangle]
pub unsafe extern "C" fn fc_cell_new(
    model: *const FcModel,
    opts: *const FcSolveOptions,
    tangent: bool,
    out: *mut *mut FcCell,
) -> FcStatus {
    guard(|| {
        // SAFETY: the caller's contract.
        let m = unsafe { model.as_ref() }.ok_or_else(|| invalid("model is NULL"))?;
        if out.is_null() {
            return Err(invalid("out is NULL"));
        }
        // SAFETY: the caller's contract.
        let solve = unsafe { solve_options(opts)? };
        let options = IncrementalOptions {
            solve,
            ..IncrementalOptions::default()
        };
        let mut inner = Cell::new(&m.model, &options)?;
        if !tangent {
            inner = inner.without_tangent();
        }
        let id = NEXT_CELL.fetch_add(1, Ordering::Relaxed);
        // SAFETY: `out` is valid for a write.
        unsafe { *out = Box::into_raw(Box::new(FcCell { inner, id })) };
        Ok(())
    })
}

/// Releases a cell (NULL: nothing); its states stay valid handles but no call accepts them.
///
/// # Safety
/// `cell` is NULL or a handle from this library, not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn fc_cell_free(cell: *mut FcCell) {
    if !cell.is_null() {
        // SAFETY: made by Box::into_raw in `fc_cell_new`, released once.
        drop(unsafe { Box::from_raw(cell) });
    }
}

/// A state of `cell` at rest (zero strain, closed contacts stuck), in `*out`.
///
/// # Safety
/// `cell` is a valid handle; `out` is valid for a write.
#[no_mangle]
pub unsafe extern "C" fn fc_cell_state_new(
    cell: *const FcCell,
    out: *mut *mut FcCellState,
) -> FcStatus {
    guard(|| {
        // SAFETY: the caller's contract.
        let c = unsafe { cell.as_ref() }.ok_or_else(|| invalid("cell is NULL"))?;
        let state = FcCellState {
            inner: c.inner.new_state(),
            cell: c.id,
        };
        // SAFETY: the caller's contract.
        unsafe { give_state(out, state) }
    })
}

/// A copy of `state` in `*out` (its first update factorizes anew).
///
/// # Safety
/// `state` is a valid handle; `out` is valid for a write.
#[no_mangle]
pub unsafe extern "C" fn fc_cell_state_clone(
    state: *const FcCellState,
    out: *mut *mut FcCellState,
) -> FcStatus {
    guard(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { state.as_ref() }.ok_or_else(|| invalid("state is NULL"))?;
        let copy = FcCellState {
            inner: s.inner.clone(),
            cell: s.cell,
        };
        // SAFETY: the caller's contract.
        unsafe { give_state(out, copy) }
    })
}

/// Releases a state (NULL: nothing).
///
/// # Safety
/// `state` is NULL or a handle from this library, not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn fc_cell_state_free(state: *mut FcCellState) {
    if !state.is_null() {
        // SAFETY: made by Box::into_raw in `give_state`, released once.
        drop(unsafe { Box::from_raw(state) });
    }
}

/// Drops the state's factorizations and matrix values until its next update, which then
/// factorizes anew: for many material points, whose caches would not fit in memory together.
///
/// # Safety
/// `state` is a valid handle.
#[no_mangle]
pub unsafe extern "C" fn fc_cell_state_release_caches(state: *mut FcCellState) -> FcStatus {
    guard(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { state.as_mut() }.ok_or_else(|| invalid("state is NULL"))?;
        s.inner.release_caches();
        Ok(())
    })
}

/// The strain `state` is at (6 values: e11, e22, g12, k11, k22, k12) into `strain`.
///
/// # Safety
/// `state` is a valid handle; `strain` holds 6 doubles.
#[no_mangle]
pub unsafe extern "C" fn fc_cell_state_strain(
    state: *const FcCellState,
    strain: *mut f64,
) -> FcStatus {
    guard(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { state.as_ref() }.ok_or_else(|| invalid("state is NULL"))?;
        if strain.is_null() {
            return Err(invalid("strain is NULL"));
        }
        // SAFETY: `strain` holds 6 doubles.
        unsafe { std::ptr::copy_nonoverlapping(s.inner.strain().as_ptr(), strain, 6) };
        Ok(())
    })
}

/// Advances `state` by the strain `increment` (6 values) and commits it; the response in
/// `*response`. On an error the state is as it was.
///
/// # Safety
/// `cell` and `state` are valid handles; `increment` holds 6 doubles; `response` is valid for
/// a write.
#[no_mangle]
pub unsafe extern "C" fn fc_cell_update(
    cell: *const FcCell,
    state: *mut FcCellState,
    increment: *const f64,
    response: *mut FcCellResponse,
) -> FcStatus {
    // SAFETY: the caller's contract.
    guard(|| unsafe { step(cell, state, increment, response, true) })
}

/// The response `fc_cell_update` would give, without committing it: `state` stays.
///
/// # Safety
/// As `fc_cell_update`.
#[no_mangle]
pub unsafe extern "C" fn fc_cell_trial(
    cell: *const FcCell,
    state: *mut FcCellState,
    increment: *const f64,
    response: *mut FcCellResponse,
) -> FcStatus {
    // SAFETY: the caller's contract.
    guard(|| unsafe { step(cell, state, increment, response, false) })
}

/// An update (`commit`) or trial.
///
/// # Safety
/// As `fc_cell_update`.
unsafe fn step(
    cell: *const FcCell,
    state: *mut FcCellState,
    increment: *const f64,
    response: *mut FcCellResponse,
    commit: bool,
) -> Result<(), Failure> {
    // SAFETY: the caller's contract.
    let (c, s) = unsafe { (cell.as_ref(), state.as_mut()) };
    let c = c.ok_or_else(|| invalid("cell is NULL"))?;
    let s = s.ok_or_else(|| invalid("state is NULL"))?;
    if s.cell != c.id {
        return Err(invalid(
            "state belongs to another cell: make it with fc_cell_state_new of this cell",
        ));
    }
    if increment.is_null() || response.is_null() {
        return Err(invalid("increment or response is NULL"));
    }
    let mut inc = [0.0; 6];
    // SAFETY: `increment` holds 6 doubles.
    unsafe { std::ptr::copy_nonoverlapping(increment, inc.as_mut_ptr(), 6) };
    let r = if commit {
        c.inner.update(&mut s.inner, &inc)?
    } else {
        c.inner.trial(&mut s.inner, &inc)?
    };
    // SAFETY: `response` is valid for a write.
    unsafe { *response = FcCellResponse::from(&r) };
    Ok(())
}

/// Stores a new state in `*out`.
///
/// # Safety
/// `out` is NULL or valid for a write.
unsafe fn give_state(out: *mut *mut FcCellState, state: FcCellState) -> Result<(), Failure> {
    if out.is_null() {
        return Err(invalid("out is NULL"));
    }
    // SAFETY: `out` is valid for a write (caller's contract).
    unsafe { *out = Box::into_raw(Box::new(state)) };
    Ok(())
}
