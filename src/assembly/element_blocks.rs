//! The element blocks of any discretization — the one place element stiffnesses become
//! blocks on unknowns: Tᵀ K T on each element's generalized nodes (K itself on its own nodes
//! where no node is constrained, the common case), their fill into a pattern, the right-hand
//! side F_f − K_fc u_c, and the internal forces K q.
//!
//! With K split into free (f) and prescribed (c) DOFs, K_ff u_f = F_f − K_fc u_c; the reduced
//! matrix K_ff is a principal submatrix of the symmetric K and stays symmetric.

use super::{element_stiffness, Assembler, FillMode, Pattern, NO_SLOT};
use crate::constraints::Discretization;
use crate::model::Model;
use crate::Error;
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Every element's block on the generalized nodes of a discretization.
#[derive(Debug)]
pub struct ElementBlocks {
    /// Generalized nodes and T of every element (None: the element's own nodes, T = I).
    maps: Vec<Option<(Vec<usize>, DMatrix<f64>)>>,
    /// The discretization is the identity (a supported structure).
    identity: bool,
    /// Every element's Tᵀ K T, kept after first use when they take at most
    /// [`ELEMENT_CACHE_BYTES`] (the internal forces of every increment's commit need them).
    cache: OnceLock<Option<Vec<DMatrix<f64>>>>,
}

impl Clone for ElementBlocks {
    /// The maps; the cache is rebuilt on first use.
    fn clone(&self) -> Self {
        ElementBlocks {
            maps: self.maps.clone(),
            identity: self.identity,
            cache: OnceLock::new(),
        }
    }
}

/// Largest memory the element matrices are kept in.
const ELEMENT_CACHE_BYTES: usize = 512 << 20;

/// Elements a thread takes at least in [`ElementBlocks::internal_with_scale`]: a product with
/// a 12 × 12 block takes tens of nanoseconds, handing work to another thread microseconds,
/// so a cell of fewer elements runs on the calling thread alone (a small cell's update was
/// mostly thread wake-ups).
const ELEMENTS_PER_THREAD: usize = 1024;

impl ElementBlocks {
    /// The blocks of `model`'s elements on `disc`.
    pub fn new(model: &Model, disc: &Discretization) -> Self {
        let identity = disc.is_identity();
        ElementBlocks {
            maps: model
                .elements()
                .par_iter()
                .map(|e| {
                    if identity {
                        None
                    } else {
                        disc.non_identity_block(&e.nodes)
                    }
                })
                .collect(),
            identity,
            cache: OnceLock::new(),
        }
    }

    /// The generalized nodes of element e's block.
    pub fn gnodes_of<'a>(&'a self, model: &'a Model, e: usize) -> &'a [usize] {
        match &self.maps[e] {
            Some((g, _)) => g,
            None => &model.elements()[e].nodes,
        }
    }

    /// Tᵀ K T of element e on its generalized nodes.
    pub fn matrix(&self, model: &Model, e: usize) -> DMatrix<f64> {
        let k = element_stiffness(model, e);
        let k = DMatrix::from_fn(12, 12, |r, c| k[(r, c)]);
        match &self.maps[e] {
            Some((_, t)) => t.transpose() * k * t,
            None => k,
        }
    }

    /// `f(generalized nodes, entry)` of element e's block: K itself where T = I (no copy),
    /// else Tᵀ K T.
    pub fn with_block<R>(
        &self,
        model: &Model,
        e: usize,
        f: impl FnOnce(&[usize], &dyn Fn(usize, usize) -> f64) -> R,
    ) -> R {
        let k = element_stiffness(model, e);
        match &self.maps[e] {
            None => f(&model.elements()[e].nodes, &|r, c| k[(r, c)]),
            Some((g, t)) => {
                let tkt = t.transpose() * DMatrix::from_fn(12, 12, |r, c| k[(r, c)]) * t;
                f(g, &|r, c| tkt[(r, c)])
            }
        }
    }

    /// Every element's Tᵀ K T when they fit in [`ELEMENT_CACHE_BYTES`].
    fn cached(&self, model: &Model) -> Option<&[DMatrix<f64>]> {
        self.cache
            .get_or_init(|| {
                let bytes: usize = (0..self.maps.len())
                    .map(|e| 8 * (6 * self.gnodes_of(model, e).len()).pow(2))
                    .sum();
                (bytes <= ELEMENT_CACHE_BYTES)
                    .then(|| self.matrices(model).map(|(_, k)| k).collect())
            })
            .as_deref()
    }

    /// `f(e, Tᵀ K T)` for every element in order, from the cache when it fits.
    fn for_each_matrix(&self, model: &Model, mut f: impl FnMut(usize, &DMatrix<f64>)) {
        match self.cached(model) {
            Some(all) => all.iter().enumerate().for_each(|(e, k)| f(e, k)),
            None => self.matrices(model).for_each(|(e, k)| f(e, &k)),
        }
    }

    /// (element, Tᵀ K T) of every element in order, computed in parallel chunks.
    fn matrices<'a>(
        &'a self,
        model: &'a Model,
    ) -> impl Iterator<Item = (usize, DMatrix<f64>)> + 'a {
        const CHUNK: usize = 4096;
        (0..self.maps.len()).step_by(CHUNK).flat_map(move |start| {
            let end = (start + CHUNK).min(self.maps.len());
            let mats: Vec<DMatrix<f64>> = (start..end)
                .into_par_iter()
                .map(|e| self.matrix(model, e))
                .collect();
            (start..end).zip(mats)
        })
    }

    /// Overwrites `values` (length `pattern.nnz()`, element slots on these blocks) with K_ff.
    pub fn fill(
        &self,
        model: &Model,
        pattern: &Pattern,
        values: &mut [f64],
        mode: FillMode,
    ) -> Result<(), Error> {
        if self.identity {
            Assembler::new(model).fill(model, pattern, values, mode)?;
            return Ok(());
        }
        pattern.check_values(values)?;
        values.iter_mut().for_each(|v| *v = 0.0);
        self.for_each_matrix(model, |e, k| {
            let m = k.nrows();
            let slots = pattern.element_slots(e);
            for r in 0..m {
                for c in 0..m {
                    let s = slots.get(r, c);
                    if s != NO_SLOT {
                        values[s as usize] += k[(r, c)];
                    }
                }
            }
        });
        Ok(())
    }

    /// The nodal loads F of the model on the free DOFs (α = 1).
    pub fn applied(model: &Model, disc: &Discretization) -> Vec<f64> {
        let mut rhs = vec![0.0; disc.n_free()];
        for l in &model.loads {
            let (gnodes, t) = disc.block(&[l.node]);
            for c in 0..t.ncols() {
                if let Some(r) = disc.reduced(6 * gnodes[c / 6] + c % 6) {
                    rhs[r] += t[(l.dof.index(), c)] * l.value;
                }
            }
        }
        rhs
    }

    /// The right-hand side F_f − K_fc u_c for α = 1: the nodal loads and the products of the
    /// elements with the prescribed DOFs. The one right-hand side of every job.
    pub fn rhs(&self, model: &Model, disc: &Discretization) -> Vec<f64> {
        let mut rhs = Self::applied(model, disc);
        if disc.has_nonzero_prescribed() {
            self.subtract_prescribed(model, disc, &|g| disc.prescribed_value(g), &mut rhs);
        }
        rhs
    }

    /// −K_fc u_c for the values `u_c` per generalized DOF (read on prescribed DOFs only).
    pub fn prescribed_load(&self, model: &Model, disc: &Discretization, u_c: &[f64]) -> Vec<f64> {
        let mut rhs = vec![0.0; disc.n_free()];
        self.subtract_prescribed(model, disc, &|g| u_c[g], &mut rhs);
        rhs
    }

    /// rhs −= K_fc u_c, `value` giving u_c per generalized DOF.
    fn subtract_prescribed(
        &self,
        model: &Model,
        disc: &Discretization,
        value: &dyn Fn(usize) -> f64,
        rhs: &mut [f64],
    ) {
        for e in 0..self.maps.len() {
            let gnodes = self.gnodes_of(model, e);
            let prescribed = |c: usize| {
                let g = 6 * gnodes[c / 6] + c % 6;
                disc.reduced(g)
                    .is_none()
                    .then(|| value(g))
                    .filter(|v| *v != 0.0)
            };
            if !(0..6 * gnodes.len()).any(|c| prescribed(c).is_some()) {
                continue;
            }
            self.with_block(model, e, |gnodes, k| {
                for r in 0..6 * gnodes.len() {
                    if let Some(i) = disc.reduced(6 * gnodes[r / 6] + r % 6) {
                        for c in 0..6 * gnodes.len() {
                            if let Some(v) = prescribed(c) {
                                rhs[i] -= k(r, c) * v;
                            }
                        }
                    }
                }
            });
        }
    }

    /// Generalized internal forces K q for the full generalized vector q.
    pub fn internal(&self, model: &Model, q: &[f64]) -> Vec<f64> {
        self.internal_with_scale(model, q).forces
    }

    /// Generalized internal forces K q and the forces the elements carry, (Σ_e ‖K_e q_e‖²)^½:
    /// the scale of an equilibrium residual. Unlike ‖K q‖, which vanishes at an unloaded
    /// node where the elements' forces balance, it measures what the sums cancel, and unlike
    /// ‖|K| |q|‖ it is blind to rigid motions (K_e q_e = 0 for a rigid motion of element e).
    pub fn internal_with_scale(&self, model: &Model, q: &[f64]) -> InternalForces {
        if self.identity {
            return identity_internal(model, &q[..6 * model.nodes.len()]);
        }
        // K_e q_e into `y`, column by column; then a node's six rows at a time into `out`.
        let add = |out: &mut [f64], y: &mut Vec<f64>, e: usize, k: &DMatrix<f64>| -> f64 {
            let gnodes = self.gnodes_of(model, e);
            y.clear();
            y.resize(k.nrows(), 0.0);
            for (c, column) in k.as_slice().chunks_exact(k.nrows()).enumerate() {
                let qc = q[6 * gnodes[c / 6] + c % 6];
                if qc != 0.0 {
                    y.iter_mut().zip(column).for_each(|(o, v)| *o += v * qc);
                }
            }
            for (&g, rows) in gnodes.iter().zip(y.chunks_exact(6)) {
                out[6 * g..6 * g + 6]
                    .iter_mut()
                    .zip(rows)
                    .for_each(|(o, v)| *o += v);
            }
            y.iter().map(|v| v * v).sum()
        };
        match self.cached(model) {
            // One slice of the elements per thread, each into its own vector, summed.
            Some(all) => {
                let threads = rayon::current_num_threads().min(all.len() / ELEMENTS_PER_THREAD);
                let chunk = all.len().div_ceil(threads.max(1)).max(1);
                let part = |(p, ks): (usize, &[DMatrix<f64>])| {
                    let (mut out, mut y) = (vec![0.0; q.len()], Vec::new());
                    let squares = ks
                        .iter()
                        .enumerate()
                        .map(|(i, k)| add(&mut out, &mut y, p * chunk + i, k))
                        .sum::<f64>();
                    (out, squares)
                };
                let parts: Vec<(Vec<f64>, f64)> = if threads > 1 {
                    all.par_chunks(chunk).enumerate().map(part).collect()
                } else {
                    all.chunks(chunk).enumerate().map(part).collect()
                };
                let mut parts = parts.into_iter();
                let (mut out, mut squares) =
                    parts.next().unwrap_or_else(|| (vec![0.0; q.len()], 0.0));
                for (part, s) in parts {
                    out.iter_mut().zip(&part).for_each(|(o, v)| *o += v);
                    squares += s;
                }
                InternalForces::new(out, squares)
            }
            None => {
                let (mut out, mut y, mut squares) = (vec![0.0; q.len()], Vec::new(), 0.0);
                self.matrices(model)
                    .for_each(|(e, k)| squares += add(&mut out, &mut y, e, &k));
                InternalForces::new(out, squares)
            }
        }
    }
}

/// Generalized internal forces and the scale of the forces the elements carry
/// (see [`ElementBlocks::internal_with_scale`]).
#[derive(Clone, Debug)]
pub struct InternalForces {
    /// K q on every generalized DOF.
    pub forces: Vec<f64>,
    /// (Σ_e ‖K_e q_e‖²)^½.
    pub element_norm: f64,
}

impl InternalForces {
    fn new(forces: Vec<f64>, squares: f64) -> Self {
        Self {
            forces,
            element_norm: squares.sqrt(),
        }
    }
}

/// K u over all global DOFs of a supported structure, element by element (u: 6 per node).
fn identity_internal(model: &Model, u: &[f64]) -> InternalForces {
    let contributions: Vec<(usize, [f64; 12])> = (0..model.elements().len())
        .into_par_iter()
        .map(|e| {
            let k = element_stiffness(model, e);
            let nodes = model.elements()[e].nodes;
            let mut ue = [0.0; 12];
            for (a, &nd) in nodes.iter().enumerate() {
                ue[6 * a..6 * a + 6].copy_from_slice(&u[6 * nd..6 * nd + 6]);
            }
            let mut fe = [0.0; 12];
            for (r, f) in fe.iter_mut().enumerate() {
                *f = (0..12).map(|c| k[(r, c)] * ue[c]).sum();
            }
            (e, fe)
        })
        .collect();
    let mut out = vec![0.0; u.len()];
    let mut squares = 0.0;
    for (e, fe) in contributions {
        squares += fe.iter().map(|v| v * v).sum::<f64>();
        for (a, &nd) in model.elements()[e].nodes.iter().enumerate() {
            for d in 0..6 {
                out[6 * nd + d] += fe[6 * a + d];
            }
        }
    }
    InternalForces::new(out, squares)
}
