//! The periodic cell as a linear system. Slave nodes (on the faces x = x₀ + L_x, y = y₀ + L_y)
//! are eliminated master–slave: u_slave = u_master + (M(x_slave) − M(x_master)) E, with M the
//! plate kinematics of [`crate::cell::macro_matrix`] and E the six macroscopic quantities, which
//! become a seventh "node" of six driver DOFs. Every element matrix is transformed, Tᵀ K T, so
//! the reduced system stays symmetric positive definite; the reactions of the driver DOFs are
//! the stress resultants times the cell area. One independent node has its translations fixed
//! to remove the rigid translations (the only rigid motions the periodicity leaves), which does
//! not over-constrain anything.

use crate::assembly::{element_stiffness, Pattern, NO_SLOT};
use crate::cell::{check_percolation, macro_matrix, pair_boundary_nodes, MacroStrain, Periodicity};
use crate::model::{Dof, Model};
use crate::Error;
use nalgebra::{SMatrix, SVector};

/// How the 12 DOFs of an element map onto its generalized nodes (independent nodes and the
/// driver node): q_element = T q_generalized.
#[derive(Clone, Debug)]
struct ElementMap {
    gnodes: Vec<usize>,
    t: SMatrix<f64, 12, 18>,
}

/// The assembled values of a periodic cell problem.
#[derive(Clone, Debug)]
pub struct PeriodicValues {
    /// Values of K_ff on the pattern.
    pub values: Vec<f64>,
    /// K_fE: for every free DOF, its coupling to the six drivers.
    pub coupling: Vec<[f64; 6]>,
    /// K_EE.
    pub k_ee: SMatrix<f64, 6, 6>,
}

/// Numbering, pattern and element maps of a periodic cell.
#[derive(Clone, Debug)]
pub struct PeriodicSystem {
    /// Pairing and geometry.
    pub periodicity: Periodicity,
    n_nodes: usize,
    reduced: Vec<usize>,
    /// (node, DOF) of every free unknown.
    free: Vec<(usize, Dof)>,
    /// Sparsity pattern of K_ff with element slot maps.
    pub pattern: Pattern,
    maps: Vec<ElementMap>,
    /// The node whose translations are fixed.
    pub anchor: usize,
}

impl PeriodicSystem {
    /// Pairs the boundary, checks percolation, numbers the unknowns and builds the pattern.
    pub fn new(model: &Model) -> Result<Self, Error> {
        let periodicity = pair_boundary_nodes(model)?;
        check_percolation(model, &periodicity)?;
        if !model.supports.is_empty() {
            return Err(Error::InvalidOption(
                "a periodic cell is driven by macroscopic strains: remove its [[supports]]".into(),
            ));
        }
        let g = &periodicity.geometry;
        let n = model.nodes.len();
        let driver = n;
        let centre = [g.origin[0] + 0.5 * g.size[0], g.origin[1] + 0.5 * g.size[1]];
        let anchor = (0..n)
            .filter(|&i| periodicity.master[i].is_none())
            .min_by(|&a, &b| {
                let d = |i: usize| {
                    (model.nodes[i].x[0] - centre[0]).powi(2)
                        + (model.nodes[i].x[1] - centre[1]).powi(2)
                };
                d(a).total_cmp(&d(b))
            })
            .ok_or(crate::cell::CellError::NotACell)?;
        let mut reduced = vec![usize::MAX; 6 * (n + 1)];
        let mut free = Vec::new();
        for i in 0..n {
            if periodicity.master[i].is_some() {
                continue;
            }
            for d in 0..6 {
                if i == anchor && d < 3 {
                    continue;
                }
                reduced[6 * i + d] = free.len();
                free.push((i, Dof::ALL[d]));
            }
        }
        let mut maps = Vec::with_capacity(model.elements().len());
        for e in model.elements() {
            let mut gnodes: Vec<usize> = Vec::with_capacity(3);
            let mut t = SMatrix::<f64, 12, 18>::zeros();
            let column = |gnodes: &mut Vec<usize>, gnode: usize| match gnodes
                .iter()
                .position(|&x| x == gnode)
            {
                Some(k) => k,
                None => {
                    gnodes.push(gnode);
                    gnodes.len() - 1
                }
            };
            for (k, &node) in e.nodes.iter().enumerate() {
                match periodicity.master[node] {
                    None => {
                        let c = column(&mut gnodes, node);
                        t.fixed_view_mut::<6, 6>(6 * k, 6 * c)
                            .copy_from(&SMatrix::<f64, 6, 6>::identity());
                    }
                    Some((m, _)) => {
                        let c = column(&mut gnodes, m);
                        let mut block = t.fixed_view_mut::<6, 6>(6 * k, 6 * c);
                        block += SMatrix::<f64, 6, 6>::identity();
                        let xs = g.relative(&model.nodes[node].x);
                        let xm = g.relative(&model.nodes[m].x);
                        let jump =
                            macro_matrix(xs[0], xs[1], xs[2]) - macro_matrix(xm[0], xm[1], xm[2]);
                        let c = column(&mut gnodes, driver);
                        let mut block = t.fixed_view_mut::<6, 6>(6 * k, 6 * c);
                        block += jump;
                    }
                }
            }
            maps.push(ElementMap { gnodes, t });
        }
        let blocks: Vec<&[usize]> = maps.iter().map(|m| &m.gnodes[..]).collect();
        let pattern = Pattern::from_blocks(&reduced, free.len(), &blocks, blocks.len())?;
        Ok(PeriodicSystem {
            periodicity,
            n_nodes: n,
            reduced,
            free,
            pattern,
            maps,
            anchor,
        })
    }

    /// Number of unknowns.
    pub fn n_free(&self) -> usize {
        self.free.len()
    }

    /// (node, DOF) of a free unknown.
    pub fn node_dof(&self, k: usize) -> (usize, Dof) {
        self.free[k]
    }

    /// Assembles K_ff, K_fE and K_EE.
    pub fn assemble(&self, model: &Model) -> PeriodicValues {
        let mut out = PeriodicValues {
            values: vec![0.0; self.pattern.nnz()],
            coupling: vec![[0.0; 6]; self.free.len()],
            k_ee: SMatrix::zeros(),
        };
        for (e, map) in self.maps.iter().enumerate() {
            let k = element_stiffness(model, e);
            let m = 6 * map.gnodes.len();
            let kt: SMatrix<f64, 18, 18> = map.t.transpose() * k * map.t;
            let slots = self.pattern.element_slots(e);
            let gdof = |r: usize| 6 * map.gnodes[r / 6] + r % 6;
            for r in 0..m {
                let driver_r = map.gnodes[r / 6] == self.n_nodes;
                for c in 0..m {
                    let v = kt[(r, c)];
                    let driver_c = map.gnodes[c / 6] == self.n_nodes;
                    match (driver_r, driver_c) {
                        (true, true) => out.k_ee[(r % 6, c % 6)] += v,
                        (false, true) => {
                            if let Some(&i) =
                                Some(&self.reduced[gdof(r)]).filter(|&&i| i != usize::MAX)
                            {
                                out.coupling[i][c % 6] += v;
                            }
                        }
                        (_, false) => {
                            let s = slots[r * m + c];
                            if s != NO_SLOT {
                                out.values[s as usize] += v;
                            }
                        }
                    }
                }
            }
        }
        out
    }

    /// Nodal displacements and rotations of every node for the unknowns `x` and the drivers `e`.
    pub fn expand(&self, model: &Model, x: &[f64], e: &MacroStrain) -> Vec<[f64; 6]> {
        let g = &self.periodicity.geometry;
        let own = |i: usize| {
            let mut u = [0.0; 6];
            for (d, v) in u.iter_mut().enumerate() {
                let r = self.reduced[6 * i + d];
                if r != usize::MAX {
                    *v = x[r];
                }
            }
            u
        };
        let es = SVector::<f64, 6>::from(*e);
        (0..self.n_nodes)
            .map(|i| match self.periodicity.master[i] {
                None => own(i),
                Some((m, _)) => {
                    let xs = g.relative(&model.nodes[i].x);
                    let xm = g.relative(&model.nodes[m].x);
                    let jump = (macro_matrix(xs[0], xs[1], xs[2])
                        - macro_matrix(xm[0], xm[1], xm[2]))
                        * es;
                    let um = own(m);
                    [0, 1, 2, 3, 4, 5].map(|d| um[d] + jump[d])
                }
            })
            .collect()
    }
}
