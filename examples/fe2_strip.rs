//! FE²: a fabric strip pulled between two grips, discretized by bilinear membrane elements
//! whose 2 × 2 integration points each hold a state of one fabric cell (`fibercell::Cell`).
//! Each load step is solved by Newton's method on the macro nodal displacements with the
//! cells' consistent tangents: every iteration *tries* each point's strain increment from its
//! committed state (`Cell::trial`), and the converged increment is committed (`Cell::update`).
//!
//! ```text
//! cargo run --release --example fe2_strip [CELL.toml]   # default: the non-woven fixture
//! ```
//!
//! Membrane only: the macro strain (ε11, ε22, γ12) of a point is its cell's, curvatures zero,
//! and the resultants (N11, N22, N12) are the membrane forces per unit width.

use fibercell::{Cell, CellResponse, CellState, Error, Model};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// The macro mesh: `nx × ny` bilinear quadrilaterals on [0, length] × [0, width].
#[derive(Clone, Copy, Debug)]
pub struct Strip {
    pub nx: usize,
    pub ny: usize,
    pub length: f64,
    pub width: f64,
}

/// How the strip is held.
#[derive(Clone, Copy, Debug)]
pub enum Grips {
    /// Left edge fixed, right edge moved by (δ, 0): clamped grips restrain the lateral
    /// contraction near them, so the strain is not uniform.
    Clamped,
    /// Every boundary node moved affinely, u = E x with E = (ε11, ε22, γ12) scaled like δ:
    /// the strain is uniform, E, at every point.
    Affine([f64; 3]),
}

/// The state of the macro problem: displacements, one cell state per integration point.
pub struct Fe2 {
    pub strip: Strip,
    pub grips: Grips,
    cell: Cell,
    /// Per integration point (element-major, 4 per element).
    pub states: Vec<CellState>,
    /// Nodal displacements (u, v) per node, node (i, j) at 2 (j (nx + 1) + i).
    pub u: Vec<f64>,
    /// Newton: relative residual to reach and most iterations per step.
    pub tolerance: f64,
    pub max_iterations: usize,
}

/// One converged load step.
#[derive(Clone, Debug)]
pub struct Step {
    /// The grip displacement δ (Clamped) or load factor (Affine).
    pub load: f64,
    /// Reaction force on the right grip along x (N), Σ of the internal forces there.
    pub reaction: f64,
    /// ‖R_free‖ / ‖f_int‖ after each Newton iteration (the first before any correction).
    pub residuals: Vec<f64>,
    /// Per iteration: each point's (open, stick, slip) counts, to see contacts switching.
    pub counts: Vec<Vec<(usize, usize, usize)>>,
    /// Each point's committed response.
    pub responses: Vec<CellResponse>,
}

const GAUSS: [f64; 2] = [-0.577_350_269_189_625_8, 0.577_350_269_189_625_8];

impl Fe2 {
    pub fn new(model: &Model, strip: Strip, grips: Grips) -> Result<Self, Error> {
        let cell = Cell::new(model, &fibercell::solve::IncrementalOptions::default())?;
        let points = 4 * strip.nx * strip.ny;
        Ok(Fe2 {
            states: (0..points).map(|_| cell.new_state()).collect(),
            u: vec![0.0; 2 * (strip.nx + 1) * (strip.ny + 1)],
            cell,
            strip,
            grips,
            tolerance: 1e-9,
            max_iterations: 20,
        })
    }

    fn node(&self, i: usize, j: usize) -> usize {
        j * (self.strip.nx + 1) + i
    }

    fn position(&self, n: usize) -> [f64; 2] {
        let s = &self.strip;
        let (i, j) = (n % (s.nx + 1), n / (s.nx + 1));
        [
            s.length * i as f64 / s.nx as f64,
            s.width * j as f64 / s.ny as f64,
        ]
    }

    /// The prescribed value of DOF d at `load`, None where free.
    fn prescribed(&self, d: usize, load: f64) -> Option<f64> {
        let s = &self.strip;
        let n = d / 2;
        let (i, j) = (n % (s.nx + 1), n / (s.nx + 1));
        let x = self.position(n);
        match self.grips {
            Grips::Clamped if i == 0 => Some(0.0),
            Grips::Clamped if i == s.nx => Some(if d.is_multiple_of(2) { load } else { 0.0 }),
            Grips::Clamped => None,
            Grips::Affine(e) => {
                let boundary = i == 0 || i == s.nx || j == 0 || j == s.ny;
                boundary.then(|| {
                    load * if d.is_multiple_of(2) {
                        e[0] * x[0] + 0.5 * e[2] * x[1]
                    } else {
                        0.5 * e[2] * x[0] + e[1] * x[1]
                    }
                })
            }
        }
    }

    /// Element e's nodes (counter-clockwise) and, per integration point, the strain matrix B
    /// (3 × 8: ε11, ε22, γ12 from u1, v1, …, u4, v4) and weight × det J.
    fn element(&self, e: usize) -> ([usize; 4], Vec<(DMatrix<f64>, f64)>) {
        let s = &self.strip;
        let (i, j) = (e % s.nx, e / s.nx);
        let nodes = [
            self.node(i, j),
            self.node(i + 1, j),
            self.node(i + 1, j + 1),
            self.node(i, j + 1),
        ];
        let (a, b) = (s.length / s.nx as f64, s.width / s.ny as f64);
        let signs = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        let mut points = Vec::with_capacity(4);
        for &eta in &GAUSS {
            for &xi in &GAUSS {
                let mut bm = DMatrix::zeros(3, 8);
                for (k, &(sx, sy)) in signs.iter().enumerate() {
                    let dx = 0.25 * sx * (1.0 + sy * eta) * 2.0 / a;
                    let dy = 0.25 * sy * (1.0 + sx * xi) * 2.0 / b;
                    bm[(0, 2 * k)] = dx;
                    bm[(1, 2 * k + 1)] = dy;
                    bm[(2, 2 * k)] = dy;
                    bm[(2, 2 * k + 1)] = dx;
                }
                points.push((bm, 0.25 * a * b));
            }
        }
        (nodes, points)
    }

    /// The strain of every integration point for displacements `u`.
    fn strains(&self, u: &[f64]) -> Vec<[f64; 3]> {
        let mut out = Vec::with_capacity(self.states.len());
        for e in 0..self.strip.nx * self.strip.ny {
            let (nodes, points) = self.element(e);
            let ue =
                DVector::from_iterator(8, nodes.iter().flat_map(|&n| [u[2 * n], u[2 * n + 1]]));
            for (bm, _) in &points {
                let eps = bm * &ue;
                out.push([eps[0], eps[1], eps[2]]);
            }
        }
        out
    }

    /// Every point's response to its strain under `u` (in parallel) from its committed state:
    /// tried, or with `commit` committed.
    fn respond(&mut self, u: &[f64], commit: bool) -> Result<Vec<CellResponse>, Error> {
        let strains = self.strains(u);
        let cell = &self.cell;
        self.states
            .par_iter_mut()
            .zip(&strains)
            .map(|(s, eps)| {
                let now = s.strain();
                let inc = [
                    eps[0] - now[0],
                    eps[1] - now[1],
                    eps[2] - now[2],
                    0.0,
                    0.0,
                    0.0,
                ];
                if commit {
                    cell.update(s, &inc)
                } else {
                    cell.trial(s, &inc)
                }
            })
            .collect()
    }

    /// Internal forces and tangent stiffness of the responses `r` (one per point).
    fn assemble(&self, r: &[CellResponse]) -> Result<(DVector<f64>, DMatrix<f64>), Error> {
        let n = self.u.len();
        let (mut f, mut k) = (DVector::zeros(n), DMatrix::zeros(n, n));
        for e in 0..self.strip.nx * self.strip.ny {
            let (nodes, points) = self.element(e);
            let dofs: Vec<usize> = nodes.iter().flat_map(|&n| [2 * n, 2 * n + 1]).collect();
            for (g, (bm, w)) in points.iter().enumerate() {
                let resp = &r[4 * e + g];
                let t = resp
                    .tangent
                    .ok_or(Error::InvalidOption("no tangent".into()))?;
                let stress = DVector::from_row_slice(&resp.resultant[..3]);
                let c = DMatrix::from_fn(3, 3, |a, b| t[a][b]);
                let fe = bm.transpose() * stress * *w;
                let ke = bm.transpose() * c * bm * *w;
                for (a, &da) in dofs.iter().enumerate() {
                    f[da] += fe[a];
                    for (b, &db) in dofs.iter().enumerate() {
                        k[(da, db)] += ke[(a, b)];
                    }
                }
            }
        }
        Ok((f, k))
    }

    /// One load step to `load`: Newton on the free displacements, then every point commits.
    pub fn step(&mut self, load: f64) -> Result<Step, Error> {
        let n = self.u.len();
        let fixed: Vec<Option<f64>> = (0..n).map(|d| self.prescribed(d, load)).collect();
        let free: Vec<usize> = (0..n).filter(|&d| fixed[d].is_none()).collect();
        let mut u = self.u.clone();
        // The grips move; the free DOFs follow at first by the last tangent (none yet: stay).
        for (d, v) in fixed.iter().enumerate() {
            if let Some(v) = v {
                u[d] = *v;
            }
        }
        let mut residuals = Vec::new();
        let mut counts = Vec::new();
        for _ in 0..=self.max_iterations {
            let responses = self.respond(&u, false)?;
            let (f, k) = self.assemble(&responses)?;
            counts.push(
                responses
                    .iter()
                    .map(|r| (r.open, r.stick, r.slip))
                    .collect(),
            );
            let r_free = DVector::from_iterator(free.len(), free.iter().map(|&d| f[d]));
            let relative = r_free.norm() / f.norm().max(f64::MIN_POSITIVE);
            residuals.push(relative);
            if relative <= self.tolerance || free.is_empty() {
                return self.commit(load, u, &f, residuals, counts);
            }
            let k_ff = DMatrix::from_fn(free.len(), free.len(), |a, b| k[(free[a], free[b])]);
            let du = k_ff
                .lu()
                .solve(&(-r_free))
                .ok_or(Error::InvalidOption("the macro tangent is singular".into()))?;
            for (a, &d) in free.iter().enumerate() {
                u[d] += du[a];
            }
        }
        Err(Error::InvalidOption(format!(
            "Newton did not converge in {} iterations at load {load}: residuals {residuals:?}",
            self.max_iterations
        )))
    }

    /// Commits every point at `u` and records the step.
    fn commit(
        &mut self,
        load: f64,
        u: Vec<f64>,
        f: &DVector<f64>,
        residuals: Vec<f64>,
        counts: Vec<Vec<(usize, usize, usize)>>,
    ) -> Result<Step, Error> {
        let responses = self.respond(&u, true)?;
        self.u = u;
        let s = &self.strip;
        let reaction = (0..=s.ny).map(|j| f[2 * self.node(s.nx, j)]).sum();
        Ok(Step {
            load,
            reaction,
            residuals,
            counts,
            responses,
        })
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "fixtures/cells/nonwoven_small.toml".into());
    let model = fibercell::io::load_model(std::path::Path::new(&path))?;
    let strip = Strip {
        nx: 4,
        ny: 2,
        length: 0.1,
        width: 0.05,
    };
    let mut fe2 = Fe2::new(&model, strip, Grips::Clamped)?;
    println!("grip δ [m], reaction [N], Newton residuals, sliding contacts (all points)");
    for k in 1..=10 {
        let step = fe2.step(k as f64 * 1e-4)?;
        let sliding: usize = step.responses.iter().map(|r| r.slip).sum();
        let res: Vec<String> = step.residuals.iter().map(|r| format!("{r:.1e}")).collect();
        println!(
            "{:.1e}  {:.5e}  [{}]  {sliding}",
            step.load,
            step.reaction,
            res.join(", ")
        );
    }
    Ok(())
}
