//! The unknowns of a problem and how the physical nodal DOFs depend on them.
//!
//! Every physical node's six DOFs are a combination of *generalized nodes*: itself (an
//! independent node), or — for a slave of a periodic cell — its master plus the macro jump
//! (M(x_slave) − M(x_master)) E of the driver node E (index n_nodes). A generalized DOF is free,
//! or prescribed to a value that the load factor α scales (supports, macroscopic strains).
//! Element and contact matrices on physical nodes become Tᵀ K T on generalized nodes, which keeps
//! the reduced system symmetric (thesis 4.42 with the periodic constraints folded in).

use crate::cell::{macro_matrix, MacroStrain, Periodicity};
use crate::contact::{ContactPair, Jump, JumpMatrix};
use crate::model::{Dof, Model};
use nalgebra::{DMatrix, SMatrix};

type Matrix6 = SMatrix<f64, 6, 6>;

/// Numbering and constraint maps of a problem.
#[derive(Clone, Debug)]
pub struct Discretization {
    n_nodes: usize,
    n_gnodes: usize,
    reduced: Vec<usize>,
    prescribed: Vec<f64>,
    free: Vec<(usize, Dof)>,
    /// Per physical node: the generalized nodes it depends on, with 6×6 blocks (None: itself).
    maps: Vec<Option<Vec<(usize, Matrix6)>>>,
    /// A periodic cell's periods and every node's position relative to its origin and
    /// mid-surface (for the images of nodes shifted by whole periods).
    cell: Option<([f64; 2], Vec<[f64; 3]>)>,
}

impl Discretization {
    /// An ordinary structure: supports prescribe DOFs, every node is independent.
    pub fn supported(model: &Model) -> Self {
        let n = model.nodes.len();
        let mut prescribed = vec![0.0; 6 * n];
        let mut fixed = vec![false; 6 * n];
        for s in &model.supports {
            let g = 6 * s.node + s.dof.index();
            fixed[g] = true;
            prescribed[g] = s.value;
        }
        Self::number(n, n, fixed, prescribed, vec![None; n], None)
    }

    /// A periodic cell driven by the macroscopic strain `target` (reached at α = 1); the
    /// translations of `anchor` are fixed (without one the system keeps the three rigid
    /// translations as its null space: `fibercell check` verifies that).
    pub fn periodic(
        model: &Model,
        p: &Periodicity,
        target: &MacroStrain,
        anchor: Option<usize>,
    ) -> Self {
        let n = model.nodes.len();
        let g = &p.geometry;
        let mut fixed = vec![false; 6 * (n + 1)];
        let mut prescribed = vec![0.0; 6 * (n + 1)];
        let mut maps = vec![None; n];
        for i in 0..n {
            if let Some((m, _)) = p.master[i] {
                let xs = g.relative(&model.nodes[i].x);
                let xm = g.relative(&model.nodes[m].x);
                let jump = macro_matrix(xs[0], xs[1], xs[2]) - macro_matrix(xm[0], xm[1], xm[2]);
                maps[i] = Some(vec![(m, Matrix6::identity()), (n, jump)]);
                fixed[6 * i..6 * i + 6].iter_mut().for_each(|f| *f = true);
            }
        }
        for d in 0..3 {
            if let Some(a) = anchor {
                fixed[6 * a + d] = true;
            }
        }
        for k in 0..6 {
            fixed[6 * n + k] = true;
            prescribed[6 * n + k] = target[k];
        }
        let relative = model.nodes.iter().map(|p| g.relative(&p.x)).collect();
        Self::number(n, n + 1, fixed, prescribed, maps, Some((g.size, relative)))
    }

    fn number(
        n_nodes: usize,
        n_gnodes: usize,
        fixed: Vec<bool>,
        prescribed: Vec<f64>,
        maps: Vec<Option<Vec<(usize, Matrix6)>>>,
        cell: Option<([f64; 2], Vec<[f64; 3]>)>,
    ) -> Self {
        let mut reduced = vec![usize::MAX; 6 * n_gnodes];
        let mut free = Vec::new();
        for g in 0..6 * n_gnodes {
            // Slave nodes have no DOFs of their own.
            let slave = g / 6 < n_nodes && maps[g / 6].is_some();
            if !fixed[g] && !slave {
                reduced[g] = free.len();
                free.push((g / 6, Dof::ALL[g % 6]));
            }
        }
        Discretization {
            n_nodes,
            n_gnodes,
            reduced,
            prescribed,
            free,
            maps,
            cell,
        }
    }

    /// Number of unknowns.
    pub fn n_free(&self) -> usize {
        self.free.len()
    }
    /// Number of generalized DOFs (6 per generalized node).
    pub fn n_global(&self) -> usize {
        6 * self.n_gnodes
    }
    /// The generalized DOF of (node, dof): 6 · node + dof.
    pub fn global(node: usize, dof: Dof) -> usize {
        6 * node + dof.index()
    }
    /// Whether any prescribed value is non-zero.
    pub fn has_nonzero_prescribed(&self) -> bool {
        self.prescribed.iter().any(|v| *v != 0.0)
    }
    /// Number of generalized nodes (physical nodes, plus the driver node of a cell).
    pub fn n_gnodes(&self) -> usize {
        self.n_gnodes
    }
    /// Number of physical nodes.
    pub fn n_nodes(&self) -> usize {
        self.n_nodes
    }
    /// The driver node of a periodic cell.
    pub fn driver(&self) -> Option<usize> {
        (self.n_gnodes > self.n_nodes).then_some(self.n_nodes)
    }
    /// Reduced index of every generalized DOF (`usize::MAX` when not an unknown).
    pub fn reduced_indices(&self) -> &[usize] {
        &self.reduced
    }
    /// Reduced index of a generalized DOF.
    pub fn reduced(&self, g: usize) -> Option<usize> {
        (self.reduced[g] != usize::MAX).then_some(self.reduced[g])
    }
    /// Prescribed value of a generalized DOF at α = 1 (0 when free).
    pub fn prescribed_value(&self, g: usize) -> f64 {
        self.prescribed[g]
    }
    /// A solver error with its column mapped to node, DOF and fibers of `model` where it names
    /// one (an unknown of a physical node).
    pub(crate) fn locate(&self, model: &Model, e: fibercell_solver::SolverError) -> crate::Error {
        let n = self.n_free();
        super::locate(e, model, &|c: usize| (c < n).then(|| self.node_dof(c)))
    }
    /// (generalized node, DOF) of an unknown; the node is physical unless it is the driver.
    pub fn node_dof(&self, k: usize) -> (usize, Dof) {
        self.free[k]
    }
    /// First unknown of every generalized node that has unknowns (block-Jacobi blocks).
    pub fn node_block_starts(&self) -> Vec<usize> {
        block_starts(self.free.iter().map(|&(node, _)| node))
    }

    /// The generalized nodes of a block of physical nodes and T (6·nodes × 6·gnodes) with
    /// q_physical = T q_generalized.
    pub fn block(&self, nodes: &[usize]) -> (Vec<usize>, DMatrix<f64>) {
        self.block_of_images(nodes, &vec![[0, 0]; nodes.len()])
    }

    /// The block of an element's `nodes`, or None when it is the identity (no node is a
    /// slave: the element acts on its own nodes' DOFs) — the common case, which then needs no
    /// Tᵀ K T.
    pub fn non_identity_block(&self, nodes: &[usize]) -> Option<(Vec<usize>, DMatrix<f64>)> {
        if self.are_own_nodes(nodes) {
            return None;
        }
        Some(self.block(nodes))
    }

    /// Whether `nodes` are their own generalized nodes: none a slave, none repeated (T = I).
    fn are_own_nodes(&self, nodes: &[usize]) -> bool {
        nodes.iter().all(|&n| self.maps[n].is_none())
            && nodes
                .iter()
                .enumerate()
                .all(|(k, n)| !nodes[..k].contains(n))
    }

    /// As [`Discretization::block`] for periodic images of the nodes, shifted by `shifts`
    /// periods: the image of x moves by u(x) + (M(x + sL) − M(x)) E.
    ///
    /// # Panics
    /// If a shift is non-zero outside a periodic cell (a contact set searched with images
    /// belongs to the cell's discretization).
    pub fn block_of_images(
        &self,
        nodes: &[usize],
        shifts: &[[i32; 2]],
    ) -> (Vec<usize>, DMatrix<f64>) {
        let mut gnodes: Vec<usize> = Vec::with_capacity(nodes.len() + 1);
        let mut parts: Vec<(usize, usize, Matrix6)> = Vec::new();
        for (k, (&n, &s)) in nodes.iter().zip(shifts).enumerate() {
            let mut deps: Vec<(usize, Matrix6)> = match &self.maps[n] {
                None => vec![(n, Matrix6::identity())],
                Some(v) => v.clone(),
            };
            if s != [0, 0] {
                let Some((size, relative)) = &self.cell else {
                    panic!("a periodic image outside a periodic cell");
                };
                let x = relative[n];
                let shifted = macro_matrix(
                    x[0] + f64::from(s[0]) * size[0],
                    x[1] + f64::from(s[1]) * size[1],
                    x[2],
                );
                deps.push((self.n_nodes, shifted - macro_matrix(x[0], x[1], x[2])));
            }
            for (gn, m) in deps {
                let c = match gnodes.iter().position(|&x| x == gn) {
                    Some(c) => c,
                    None => {
                        gnodes.push(gn);
                        gnodes.len() - 1
                    }
                };
                parts.push((k, c, m));
            }
        }
        let mut t = DMatrix::<f64>::zeros(6 * nodes.len(), 6 * gnodes.len());
        for (k, c, m) in parts {
            let mut v = t.view_mut((6 * k, 6 * c), (6, 6));
            v += m;
        }
        (gnodes, t)
    }

    /// Whether the block of these node images is the identity: no node is a slave or
    /// repeated, no image shifted — then the generalized nodes are `nodes` themselves and T = I,
    /// with no need to form them ([`Discretization::block_of_images`] gives the same).
    pub fn is_identity_block(&self, nodes: &[usize], shifts: &[[i32; 2]]) -> bool {
        shifts.iter().all(|s| *s == [0, 0]) && self.are_own_nodes(nodes)
    }

    /// Whether every node is its own generalized node (no periodic maps).
    pub fn is_identity(&self) -> bool {
        self.maps.iter().all(|m| m.is_none())
    }

    /// The full generalized vector for unknowns `x` at load factor `alpha`.
    pub fn generalized(&self, x: &[f64], alpha: f64) -> Vec<f64> {
        (0..6 * self.n_gnodes)
            .map(|g| match self.reduced(g) {
                Some(r) => x[r],
                None => alpha * self.prescribed[g],
            })
            .collect()
    }

    /// Physical [ux, uy, uz, rx, ry, rz] of every node from a full generalized vector.
    pub fn physical(&self, q: &[f64]) -> Vec<[f64; 6]> {
        (0..self.n_nodes)
            .map(|i| match &self.maps[i] {
                None => [0, 1, 2, 3, 4, 5].map(|d| q[6 * i + d]),
                Some(deps) => {
                    let mut u = [0.0; 6];
                    for (gn, m) in deps {
                        for (r, ur) in u.iter_mut().enumerate() {
                            *ur += (0..6).map(|c| m[(r, c)] * q[6 * gn + c]).sum::<f64>();
                        }
                    }
                    u
                }
            })
            .collect()
    }

    /// A contact pair with its jumps moved onto generalized nodes (B T and R T).
    pub fn contact_pair(&self, pair: &ContactPair) -> ContactPair {
        if self.is_identity_block(&pair.jump.nodes, &pair.jump.shifts) {
            return pair.clone();
        }
        let k = pair.jump.nodes.len();
        let (gnodes, t) = self.block_of_images(&pair.jump.nodes, &pair.jump.shifts);
        let moved = |m: &JumpMatrix| {
            let product = DMatrix::from_fn(3, 6 * k, |r, c| m[(r, c)]) * &t;
            let mut padded = JumpMatrix::zeros();
            padded
                .view_mut((0, 0), (3, product.ncols()))
                .copy_from(&product);
            padded
        };
        ContactPair {
            jump: Jump {
                shifts: vec![[0, 0]; gnodes.len()],
                nodes: gnodes,
                b: moved(&pair.jump.b),
                r: moved(&pair.jump.r),
            },
            ..pair.clone()
        }
    }
}

/// Positions where the node of consecutive unknowns changes: the first unknown of every node
/// block (block-Jacobi preconditioner blocks).
fn block_starts(nodes: impl Iterator<Item = usize>) -> Vec<usize> {
    let mut starts = Vec::new();
    let mut last = usize::MAX;
    for (k, node) in nodes.enumerate() {
        if node != last {
            starts.push(k);
            last = node;
        }
    }
    starts
}
