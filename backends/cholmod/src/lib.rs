//! SuiteSparse CHOLMOD through `suitesparse_sys`, as a fibercell [`LinearSolver`].
//!
//! Needs Debian's `libsuitesparse-dev` (and `libclang-dev` for the bindings). All C memory is
//! owned by RAII wrappers and freed in `Drop`. CHOLMOD reports a non-positive-definite matrix as
//! a *warning* (`status = CHOLMOD_NOT_POSDEF`, `L->minor < n`) while returning success: both are
//! checked after every factorization.
//!
//! ```
//! use fibercell_cholmod::Cholmod;
//! use fibercell_solver::{CscMatrix, LinearSolver};
//!
//! let t = [(0, 0, 4.0), (1, 1, 4.0), (2, 2, 4.0), (0, 1, -1.0), (1, 0, -1.0), (1, 2, -1.0), (2, 1, -1.0)];
//! let a = CscMatrix::from_triplets(3, 3, &t)?;
//! let mut cholmod = Cholmod::default();
//! cholmod.analyze(a.as_ref())?;
//! cholmod.factorize(a.as_ref())?;
//! let mut x = vec![3.0, 2.0, 3.0];
//! cholmod.solve_in_place(&mut x, 1)?;
//! assert!(x.iter().all(|v| (v - 1.0).abs() < 1e-14));
//! # Ok::<(), fibercell_solver::SolverError>(())
//! ```

#![warn(missing_docs)]

mod common;

use common::Common;
use fibercell_solver::{
    compute_ordering, AnalyzeInfo, Capabilities, CscRef, FillOrdering, LinearSolver, LowerTriangle,
    PatternFingerprint, SolveInfo, SolverError,
};
use std::os::raw::{c_int, c_long, c_void};
use suitesparse_sys as ss;

/// CHOLMOD sparse Cholesky (supernodal or simplicial, CHOLMOD's choice).
pub struct Cholmod {
    ordering: FillOrdering,
    pivot_tolerance: f64,
    common: Option<Common>,
    state: Option<State>,
}

struct State {
    n: usize,
    fingerprint: PatternFingerprint,
    lower: LowerTriangle,
    col_ptr: Vec<c_long>,
    row_idx: Vec<c_long>,
    values: Vec<f64>,
    scale: Vec<f64>,
    factor: *mut ss::cholmod_factor,
    /// A copy of `factor` modified by `update_factor` (a simplicial LDLᵀ), used by the solves
    /// until the next factorization; null when none. The supernodal `factor` is kept for the
    /// next numeric factorization.
    modified: *mut ss::cholmod_factor,
    factorized: bool,
}

// SAFETY: the CHOLMOD objects are plain heap memory not tied to a thread; `Cholmod` owns them
// exclusively and every access goes through `&mut self`.
unsafe impl Send for Cholmod {}

impl Default for Cholmod {
    fn default() -> Self {
        Self::new(FillOrdering::Auto)
    }
}

impl Cholmod {
    /// A solver with the given ordering ([`FillOrdering::Auto`]: CHOLMOD's default strategy).
    pub fn new(ordering: FillOrdering) -> Self {
        Cholmod {
            ordering,
            pivot_tolerance: 1e-12,
            common: None,
            state: None,
        }
    }

    /// Reciprocal condition estimates (of the diagonally scaled matrix) below this are
    /// rejected as singular (default 1e-12).
    pub fn with_pivot_tolerance(mut self, tol: f64) -> Self {
        self.pivot_tolerance = tol;
        self
    }

    fn free_modified(&mut self) {
        if let (Some(c), Some(s)) = (self.common.as_mut(), self.state.as_mut()) {
            if !s.modified.is_null() {
                // SAFETY: `modified` came from cholmod_l_copy_factor with this common.
                unsafe { ss::cholmod_l_free_factor(&mut s.modified, c.as_mut_ptr()) };
                s.modified = std::ptr::null_mut();
            }
        }
    }

    fn free_factor(&mut self) {
        self.free_modified();
        if let (Some(c), Some(s)) = (self.common.as_mut(), self.state.as_mut()) {
            if !s.factor.is_null() {
                // SAFETY: `factor` came from cholmod_l_analyze_p with this common.
                unsafe { ss::cholmod_l_free_factor(&mut s.factor, c.as_mut_ptr()) };
                s.factor = std::ptr::null_mut();
            }
        }
    }
}

impl Drop for Cholmod {
    fn drop(&mut self) {
        self.free_factor();
        // `Common` finishes itself in its own Drop, after the factor is gone.
    }
}

impl State {
    /// A CHOLMOD header over our own lower-triangle arrays (never freed by CHOLMOD).
    fn header(&mut self) -> ss::cholmod_sparse {
        ss::cholmod_sparse {
            nrow: self.n,
            ncol: self.n,
            nzmax: self.row_idx.len(),
            p: self.col_ptr.as_mut_ptr() as *mut c_void,
            i: self.row_idx.as_mut_ptr() as *mut c_void,
            nz: std::ptr::null_mut(),
            x: self.values.as_mut_ptr() as *mut c_void,
            z: std::ptr::null_mut(),
            stype: -1,
            itype: ss::CHOLMOD_LONG as c_int,
            xtype: ss::CHOLMOD_REAL as c_int,
            dtype: ss::CHOLMOD_DOUBLE as c_int,
            sorted: 1,
            packed: 1,
        }
    }
}

fn backend_error(code: c_int, what: &str) -> SolverError {
    if code == ss::CHOLMOD_OUT_OF_MEMORY {
        return SolverError::OutOfMemory;
    }
    SolverError::Backend {
        backend: "cholmod",
        code: code as i64,
        message: format!("{what} failed (CHOLMOD status {code})"),
    }
}

impl LinearSolver for Cholmod {
    fn name(&self) -> &'static str {
        "cholmod"
    }

    fn capabilities(&self) -> Capabilities {
        Capabilities::DIRECT_SPD
    }

    fn analyze(&mut self, a: CscRef<'_>) -> Result<AnalyzeInfo, SolverError> {
        <dyn LinearSolver>::check_symmetric_matrix(a)?;
        self.free_factor();
        self.state = None;
        if self.common.is_none() {
            self.common = Some(Common::start()?);
        }
        let n = a.ncols();
        let too_big = || SolverError::InvalidMatrix("index does not fit CHOLMOD's long".into());
        let lower = LowerTriangle::of(a);
        let to_long = |v: &[usize]| -> Result<Vec<c_long>, SolverError> {
            v.iter()
                .map(|&x| c_long::try_from(x).map_err(|_| too_big()))
                .collect()
        };
        let col_ptr = to_long(&lower.col_ptr)?;
        let row_idx = to_long(&lower.row_idx)?;
        let mut perm: Option<Vec<c_long>> = None;
        let (nmethods, method, name) = match &self.ordering {
            FillOrdering::Auto => (0, ss::CHOLMOD_AMD, "cholmod-default"),
            FillOrdering::Natural => (1, ss::CHOLMOD_NATURAL, "natural"),
            FillOrdering::Amd => (1, ss::CHOLMOD_AMD, "amd"),
            o @ (FillOrdering::NestedDissection | FillOrdering::Given(_)) => {
                let p = compute_ordering(a, o)?;
                perm = Some(p.fwd.iter().map(|&x| x as c_long).collect());
                (1, ss::CHOLMOD_GIVEN, o.name())
            }
        };
        let nnz = lower.nnz();
        let mut state = State {
            n,
            fingerprint: a.fingerprint(),
            lower,
            col_ptr,
            row_idx,
            values: vec![0.0; nnz],
            scale: vec![1.0; n],
            factor: std::ptr::null_mut(),
            modified: std::ptr::null_mut(),
            factorized: false,
        };
        let common = self
            .common
            .as_mut()
            .ok_or(SolverError::OutOfOrder("analyze", "start"))?;
        let c = common.as_mut_ptr();
        let mut header = state.header();
        // SAFETY: `c` is a started common; the header points to live arrays of the declared
        // sizes; `perm` (if any) has n entries.
        let (factor, status, lnz, fl, stored) = unsafe {
            (*c).nmethods = nmethods;
            (*c).method[0].ordering = method as c_int;
            (*c).postorder = 1;
            let pp = perm
                .as_mut()
                .map_or(std::ptr::null_mut(), |p| p.as_mut_ptr());
            let f = ss::cholmod_l_analyze_p(&mut header, pp, std::ptr::null_mut(), 0, c);
            // A supernodal symbolic factor knows its values' size (relaxed zeros included);
            // a simplicial one stores its structure.
            let stored = match f.as_ref() {
                Some(l) if l.is_super != 0 => l.xsize,
                _ => (*c).lnz as usize,
            };
            (f, (*c).status, (*c).lnz, (*c).fl, stored)
        };
        if factor.is_null() || status < 0 {
            return Err(backend_error(status, "cholmod_l_analyze_p"));
        }
        state.factor = factor;
        self.state = Some(state);
        Ok(AnalyzeInfo {
            n,
            nnz_a: a.nnz(),
            nnz_factor: Some(lnz as usize),
            factor_bytes: Some(8 * stored),
            flops: Some(fl),
            ordering: name.to_string(),
        })
    }

    fn factorize(&mut self, a: CscRef<'_>) -> Result<(), SolverError> {
        self.free_modified();
        let tol = self.pivot_tolerance;
        let (common, s) = match (self.common.as_mut(), self.state.as_mut()) {
            (Some(c), Some(s)) => (c, s),
            _ => return Err(SolverError::OutOfOrder("factorize", "analyze")),
        };
        <dyn LinearSolver>::check_matrix(a, Some(s.n))?;
        if a.fingerprint() != s.fingerprint {
            return Err(SolverError::PatternChanged);
        }
        s.factorized = false;
        s.lower.scaled_values(a, &mut s.scale, &mut s.values)?;
        let c = common.as_mut_ptr();
        let mut header = s.header();
        // SAFETY: factor and common are live and belong together; header points to live arrays.
        let (ok, status, minor, rcond) = unsafe {
            let ok = ss::cholmod_l_factorize(&mut header, s.factor, c);
            let rcond = ss::cholmod_l_rcond(s.factor, c);
            (ok, (*c).status, (*s.factor).minor, rcond)
        };
        if ok == 0 || status < 0 {
            return Err(backend_error(status, "cholmod_l_factorize"));
        }
        if status == ss::CHOLMOD_NOT_POSDEF as c_int || minor < s.n {
            // SAFETY: after analyze, Perm holds n longs (`minor` < n is a factor position).
            let column = unsafe {
                let perm = (*s.factor).Perm as *const c_long;
                if perm.is_null() || minor >= s.n {
                    minor.min(s.n.saturating_sub(1))
                } else {
                    *perm.add(minor) as usize
                }
            };
            return Err(SolverError::NotPositiveDefinite { column, pivot: 0.0 });
        }
        if !(rcond > tol) {
            return Err(SolverError::Singular {
                column: None,
                detail: format!(
                    "CHOLMOD reciprocal condition estimate {rcond:.3e} of the scaled matrix"
                ),
            });
        }
        s.factorized = true;
        Ok(())
    }

    fn solve_in_place(&mut self, rhs: &mut [f64], nrhs: usize) -> Result<SolveInfo, SolverError> {
        let (common, s) = match (self.common.as_mut(), self.state.as_mut()) {
            (Some(c), Some(s)) if s.factorized => (c, s),
            _ => return Err(SolverError::OutOfOrder("solve", "factorize")),
        };
        let n = s.n;
        <dyn LinearSolver>::check_rhs(n, rhs, nrhs)?;
        if n == 0 || nrhs == 0 {
            return Ok(SolveInfo::default());
        }
        for col in rhs.chunks_mut(n) {
            col.iter_mut().zip(&s.scale).for_each(|(x, d)| *x *= d);
        }
        let mut b = ss::cholmod_dense {
            nrow: n,
            ncol: nrhs,
            nzmax: n * nrhs,
            d: n,
            x: rhs.as_mut_ptr() as *mut c_void,
            z: std::ptr::null_mut(),
            xtype: ss::CHOLMOD_REAL as c_int,
            dtype: ss::CHOLMOD_DOUBLE as c_int,
        };
        let c = common.as_mut_ptr();
        // SAFETY: `b` describes `rhs` (n × nrhs, leading dimension n); the result is a new
        // dense matrix that we copy out of and free with the same common.
        unsafe {
            let factor = if s.modified.is_null() {
                s.factor
            } else {
                s.modified
            };
            let mut x = ss::cholmod_l_solve(ss::CHOLMOD_A as c_int, factor, &mut b, c);
            if x.is_null() {
                return Err(backend_error((*c).status, "cholmod_l_solve"));
            }
            let src = std::slice::from_raw_parts((*x).x as *const f64, n * nrhs);
            rhs.copy_from_slice(src);
            ss::cholmod_l_free_dense(&mut x, c);
        }
        for col in rhs.chunks_mut(n) {
            col.iter_mut().zip(&s.scale).for_each(|(x, d)| *x *= d);
        }
        Ok(SolveInfo::default())
    }

    /// cholmod_l_updown on a copy of the factor (CHOLMOD converts it to a simplicial LDLᵀ;
    /// the supernodal original stays for the next `factorize`), with W scaled like A and
    /// permuted to L's order, as CHOLMOD requires.
    fn update_factor(&mut self, w: CscRef<'_>, update: bool) -> Result<(), SolverError> {
        let (common, s) = match (self.common.as_mut(), self.state.as_mut()) {
            (Some(c), Some(s)) if s.factorized => (c, s),
            _ => return Err(SolverError::OutOfOrder("update_factor", "factorize")),
        };
        let n = s.n;
        if w.nrows() != n {
            return Err(SolverError::DimensionMismatch(format!(
                "W has {} rows, the factor {n}",
                w.nrows()
            )));
        }
        if let Some(i) = w.values().iter().position(|v| !v.is_finite()) {
            return Err(SolverError::NonFinite {
                what: "update column",
                index: i,
            });
        }
        if w.ncols() == 0 || n == 0 {
            return Ok(());
        }
        let c = common.as_mut_ptr();
        // SAFETY: after analyze, Perm holds the n entries of the fill-reducing permutation.
        let perm = unsafe {
            let p = (*s.factor).Perm as *const c_long;
            if p.is_null() {
                return Err(SolverError::OutOfOrder("update_factor", "analyze"));
            }
            std::slice::from_raw_parts(p, n)
        };
        let mut inverse = vec![0usize; n];
        for (k, &p) in perm.iter().enumerate() {
            inverse[p as usize] = k;
        }
        // Cnew = P S W, columns sorted by the permuted row.
        let mut col_ptr: Vec<c_long> = Vec::with_capacity(w.ncols() + 1);
        let mut row_idx: Vec<c_long> = Vec::with_capacity(w.nnz());
        let mut values: Vec<f64> = Vec::with_capacity(w.nnz());
        col_ptr.push(0);
        let mut column: Vec<(usize, f64)> = Vec::new();
        for j in 0..w.ncols() {
            let (rows, vals) = w.col(j);
            column.clear();
            column.extend(
                rows.iter()
                    .zip(vals)
                    .map(|(&r, &v)| (inverse[r], v * s.scale[r])),
            );
            column.sort_unstable_by_key(|e| e.0);
            for &(r, v) in &column {
                row_idx.push(r as c_long);
                values.push(v);
            }
            col_ptr.push(row_idx.len() as c_long);
        }
        let mut header = ss::cholmod_sparse {
            nrow: n,
            ncol: w.ncols(),
            nzmax: row_idx.len(),
            p: col_ptr.as_mut_ptr() as *mut c_void,
            i: row_idx.as_mut_ptr() as *mut c_void,
            nz: std::ptr::null_mut(),
            x: values.as_mut_ptr() as *mut c_void,
            z: std::ptr::null_mut(),
            stype: 0,
            itype: ss::CHOLMOD_LONG as c_int,
            xtype: ss::CHOLMOD_REAL as c_int,
            dtype: ss::CHOLMOD_DOUBLE as c_int,
            sorted: 1,
            packed: 1,
        };
        // SAFETY: factor, modified and common belong together; the header points to live
        // arrays of the declared sizes.
        let (ok, status, minor) = unsafe {
            if s.modified.is_null() {
                s.modified = ss::cholmod_l_copy_factor(s.factor, c);
                if s.modified.is_null() {
                    return Err(backend_error((*c).status, "cholmod_l_copy_factor"));
                }
            }
            let ok = ss::cholmod_l_updown(c_int::from(update), &mut header, s.modified, c);
            (ok, (*c).status, (*s.modified).minor)
        };
        if ok == 0 || status < 0 {
            // The modified factor may be left symbolic: no solve until the next factorize.
            s.factorized = false;
            return Err(backend_error(status, "cholmod_l_updown"));
        }
        // A downdate past positive definiteness leaves a non-positive D in the LDLᵀ factor
        // without an error from CHOLMOD: look at D (the first entry of each column).
        // SAFETY: after a successful updown, `modified` is a simplicial LDLᵀ of order n whose
        // column j starts at p[j] with its diagonal entry.
        let bad = unsafe {
            let (p, x) = (
                (*s.modified).p as *const c_long,
                (*s.modified).x as *const f64,
            );
            (0..n)
                .map(|j| (j, *x.add(*p.add(j) as usize)))
                .find(|&(_, d)| !(d > 0.0))
        };
        let not_definite = status == ss::CHOLMOD_NOT_POSDEF as c_int || minor < n;
        if not_definite || bad.is_some() {
            s.factorized = false;
            let (k, pivot) = bad.unwrap_or((minor.min(n - 1), 0.0));
            return Err(SolverError::NotPositiveDefinite {
                column: perm[k] as usize,
                pivot,
            });
        }
        Ok(())
    }
}
