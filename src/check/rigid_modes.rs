//! The null space of a free model's system (no supports, no cell): the six rigid modes of each
//! connected piece.
//!
//! A rigid motion of a piece — a translation, or a small rotation θ about its centroid c, which
//! moves node i by θ × (xᵢ − c) and turns it by θ — strains no element and changes no contact
//! jump, so K r = 0 for its six modes. Together with the matrix being positive definite once
//! one node of every piece is held (six DOFs each), this makes the null space exactly these
//! 6 × pieces modes: holding 6 × pieces DOFs removes at most that many dimensions.

use crate::homogenize::StickSystem;
use crate::model::{Dof, Support};
use crate::solve::{node_roots, SolveOptions, SolverKind};
use crate::solver::SolverError;
use crate::{Error, Model};
use serde::Serialize;

/// ‖K r‖∞ / (‖K‖∞ ‖r‖∞) of a free model's matrix for the rigid modes of its pieces.
#[derive(Clone, Debug, Serialize)]
pub struct RigidModes {
    /// Connected pieces (nodes joined by elements and closed contacts).
    pub pieces: usize,
    /// Per mode (translations along x, y, z, rotations about x, y, z through each piece's
    /// centroid), the worst piece.
    pub relative: [f64; 6],
    /// Whether the matrix with one node of every piece held is positive definite.
    pub held_positive_definite: bool,
    /// Unknowns of the free system.
    pub n: usize,
}

/// The connected piece of every node (0-based, in order of first node) and their count.
fn pieces(model: &Model, sys: &StickSystem) -> (Vec<usize>, usize) {
    let links: Vec<&[usize]> = sys.contacts.iter().map(|c| &c.jump.nodes[..]).collect();
    let roots = node_roots(model, &links);
    let mut label = vec![usize::MAX; roots.len()];
    let mut count = 0;
    let piece = roots
        .iter()
        .map(|&r| {
            if label[r] == usize::MAX {
                label[r] = count;
                count += 1;
            }
            label[r]
        })
        .collect();
    (piece, count)
}

/// The rigid mode `mode` (0–2 translations, 3–5 rotations) of every piece at once, on the
/// free DOFs of `sys`, each piece's rotation about its own centroid.
fn mode_vector(
    model: &Model,
    sys: &StickSystem,
    piece: &[usize],
    count: usize,
    mode: usize,
) -> Vec<f64> {
    let mut centroid = vec![[0.0; 3]; count];
    let mut nodes = vec![0usize; count];
    for (i, node) in model.nodes.iter().enumerate() {
        let c = &mut centroid[piece[i]];
        c.iter_mut().zip(node.x).for_each(|(c, x)| *c += x);
        nodes[piece[i]] += 1;
    }
    for (c, &m) in centroid.iter_mut().zip(&nodes) {
        c.iter_mut().for_each(|v| *v /= m.max(1) as f64);
    }
    let mut r = vec![0.0; sys.n_free()];
    for (k, v) in r.iter_mut().enumerate() {
        let (node, dof) = sys.node_dof(k);
        let d = dof.index();
        // A translation moves the displacements, a rotation turns the rotations by e_a and
        // moves the displacements by e_a × (x − c).
        *v = if mode < 3 || d >= 3 {
            f64::from(u8::from(d == mode))
        } else {
            // (e_a × (x − c))_d with a = mode − 3.
            let c = centroid[piece[node]];
            let x = model.nodes[node].x;
            let rel = [x[0] - c[0], x[1] - c[1], x[2] - c[2]];
            let a = mode - 3;
            let (b, e) = ((a + 1) % 3, (a + 2) % 3);
            if d == e {
                rel[b]
            } else if d == b {
                -rel[e]
            } else {
                0.0
            }
        };
    }
    r
}

/// The free model's matrix (elements and closed contacts in stick) applied to the rigid modes
/// of its pieces, and the definiteness of the matrix with one node of each piece held.
pub fn rigid_mode_residuals(model: &Model, solve: &SolveOptions) -> Result<RigidModes, Error> {
    let sys = StickSystem::supported(model)?;
    let values = sys.assemble(model);
    let a = sys.pattern.matrix(&values.values)?;
    let (piece, count) = pieces(model, &sys);
    let norm = fibercell_solver::norm1(a);
    let mut relative = [0.0; 6];
    for (mode, rel) in relative.iter_mut().enumerate() {
        let r = mode_vector(model, &sys, &piece, count, mode);
        let mut kr = vec![0.0; r.len()];
        a.mul_vec(&r, &mut kr);
        let worst = kr.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let scale = norm * r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        *rel = if scale > 0.0 { worst / scale } else { 0.0 };
    }
    Ok(RigidModes {
        pieces: count,
        relative,
        held_positive_definite: held_definite(model, &piece, count, solve)?,
        n: sys.n_free(),
    })
}

/// Whether the model with the first node of every piece held (all six DOFs) has a positive
/// definite matrix.
fn held_definite(
    model: &Model,
    piece: &[usize],
    count: usize,
    solve: &SolveOptions,
) -> Result<bool, Error> {
    let mut held = model.clone();
    let mut seen = vec![false; count];
    for (node, &p) in piece.iter().enumerate() {
        if !std::mem::replace(&mut seen[p], true) {
            held.supports.extend(Dof::ALL.map(|dof| Support {
                node,
                dof,
                value: 0.0,
            }));
        }
    }
    let sys = StickSystem::supported(&held)?;
    let values = sys.assemble(&held);
    let a = sys.pattern.matrix(&values.values)?;
    let mut options = solve.clone();
    if options.solver != SolverKind::Cholmod {
        options.solver = SolverKind::FaerCholesky;
    }
    let mut solver = options
        .solver_config(sys.discretization.node_block_starts())
        .build()?;
    match solver.analyze(a).and_then(|_| solver.factorize(a)) {
        Ok(()) => Ok(true),
        Err(SolverError::NotPositiveDefinite { .. }) => Ok(false),
        Err(e) => Err(sys.locate(&held, e)),
    }
}
