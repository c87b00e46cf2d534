//! The elastic part of a stick/slip system on a discretization: the element blocks on
//! generalized nodes, their load with prescribed DOFs, and their internal forces.

use crate::assembly::{element_stiffness, Assembler, Pattern, NO_SLOT};
use crate::constraints::{internal_forces, Discretization};
use crate::model::Model;
use crate::Error;
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::sync::OnceLock;

/// The elastic part on a discretization: element blocks on generalized nodes.
pub(super) struct Elastic {
    /// Generalized nodes and T of every element (None: the element's own nodes, T = I).
    maps: Vec<Option<(Vec<usize>, DMatrix<f64>)>>,
    /// The discretization is the identity (a supported structure).
    identity: bool,
    /// Every element's Tᵀ K T, kept after first use when they take at most
    /// [`ELEMENT_CACHE_BYTES`] (the internal forces of every increment's commit need them).
    cache: OnceLock<Option<Vec<DMatrix<f64>>>>,
}

/// Largest memory the element matrices of the commit are kept in.
const ELEMENT_CACHE_BYTES: usize = 512 << 20;

impl Elastic {
    pub(super) fn new(model: &Model, disc: &Discretization) -> Self {
        let identity = disc.is_identity();
        Elastic {
            maps: model
                .elements()
                .iter()
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

    /// Every element's Tᵀ K T when they fit in [`ELEMENT_CACHE_BYTES`].
    fn cached(&self, model: &Model) -> Option<&[DMatrix<f64>]> {
        self.cache
            .get_or_init(|| {
                let bytes: usize = (0..self.maps.len())
                    .map(|e| 8 * (6 * self.block_nodes(model, e)).pow(2))
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

    /// Nodes of element e's block.
    fn block_nodes(&self, model: &Model, e: usize) -> usize {
        match &self.maps[e] {
            Some((g, _)) => g.len(),
            None => model.elements()[e].nodes.len(),
        }
    }

    /// The generalized nodes of element e's block.
    pub(super) fn gnodes_of<'a>(&'a self, model: &'a Model, e: usize) -> &'a [usize] {
        match &self.maps[e] {
            Some((g, _)) => g,
            None => &model.elements()[e].nodes,
        }
    }

    /// Tᵀ K T of element e on its generalized nodes.
    pub(super) fn matrix(&self, model: &Model, e: usize) -> DMatrix<f64> {
        let k = element_stiffness(model, e);
        let k = DMatrix::from_fn(12, 12, |r, c| k[(r, c)]);
        match &self.maps[e] {
            Some((_, t)) => t.transpose() * k * t,
            None => k,
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

    pub(super) fn fill(
        &self,
        model: &Model,
        pattern: &Pattern,
        values: &mut [f64],
        mode: crate::assembly::FillMode,
    ) -> Result<(), Error> {
        if self.identity {
            Assembler::new(model).fill(model, pattern, values, mode)?;
            return Ok(());
        }
        values.iter_mut().for_each(|v| *v = 0.0);
        self.for_each_matrix(model, |e, k| {
            let m = k.nrows();
            let slots = pattern.element_slots(e);
            for r in 0..m {
                for c in 0..m {
                    let s = slots[r * m + c];
                    if s != NO_SLOT {
                        values[s as usize] += k[(r, c)];
                    }
                }
            }
        });
        Ok(())
    }

    /// The nodal loads F of the model on the free DOFs (α = 1).
    pub(super) fn applied(model: &Model, disc: &Discretization) -> Vec<f64> {
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

    /// The load of the linear system for α = 1: F and the products of the elements with the
    /// prescribed DOFs.
    pub(super) fn rhs(&self, model: &Model, disc: &Discretization) -> Vec<f64> {
        let mut rhs = Self::applied(model, disc);
        for e in 0..self.maps.len() {
            let gnodes = self.gnodes_of(model, e);
            let prescribed = |c: usize| {
                let g = 6 * gnodes[c / 6] + c % 6;
                disc.reduced(g)
                    .is_none()
                    .then(|| disc.prescribed_value(g))
                    .filter(|v| *v != 0.0)
            };
            if !(0..6 * gnodes.len()).any(|c| prescribed(c).is_some()) {
                continue;
            }
            let k = self.matrix(model, e);
            for r in 0..k.nrows() {
                if let Some(i) = disc.reduced(6 * gnodes[r / 6] + r % 6) {
                    for c in 0..k.ncols() {
                        if let Some(v) = prescribed(c) {
                            rhs[i] -= k[(r, c)] * v;
                        }
                    }
                }
            }
        }
        rhs
    }

    /// Generalized internal forces K q for the full generalized vector q.
    pub(super) fn internal(&self, model: &Model, q: &[f64]) -> Vec<f64> {
        if self.identity {
            return internal_forces(model, &q[..6 * model.nodes.len()]);
        }
        // Column by column, a node's six rows at a time (contiguous in K and in `out`).
        let add = |out: &mut [f64], e: usize, k: &DMatrix<f64>| {
            let gnodes = self.gnodes_of(model, e);
            for (c, column) in k.as_slice().chunks_exact(k.nrows()).enumerate() {
                let qc = q[6 * gnodes[c / 6] + c % 6];
                if qc == 0.0 {
                    continue;
                }
                for (&g, rows) in gnodes.iter().zip(column.chunks_exact(6)) {
                    for (o, v) in out[6 * g..6 * g + 6].iter_mut().zip(rows) {
                        *o += v * qc;
                    }
                }
            }
        };
        match self.cached(model) {
            // One slice of the elements per thread, each into its own vector, summed.
            Some(all) => {
                let chunk = all.len().div_ceil(rayon::current_num_threads()).max(1);
                let parts: Vec<Vec<f64>> = all
                    .par_chunks(chunk)
                    .enumerate()
                    .map(|(p, ks)| {
                        let mut out = vec![0.0; q.len()];
                        for (i, k) in ks.iter().enumerate() {
                            add(&mut out, p * chunk + i, k);
                        }
                        out
                    })
                    .collect();
                let mut parts = parts.into_iter();
                let mut out = parts.next().unwrap_or_else(|| vec![0.0; q.len()]);
                for part in parts {
                    out.iter_mut().zip(&part).for_each(|(o, v)| *o += v);
                }
                out
            }
            None => {
                let mut out = vec![0.0; q.len()];
                self.matrices(model).for_each(|(e, k)| add(&mut out, e, &k));
                out
            }
        }
    }
}
