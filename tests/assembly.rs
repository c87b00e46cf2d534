//! Assembly: serial and parallel fills agree, the pattern is symmetric and complete, and the
//! assembled stiffness is invariant under a rigid rotation of the whole model.

mod common;
use common::*;
use fibercell::assembly::{element_stiffness, Assembler, FillMode, Pattern};
use fibercell::constraints::Discretization;
use fibercell::model::ModelDescription;
use nalgebra::{DMatrix, Rotation3, Vector3};

fn assemble(d: &ModelDescription, mode: FillMode) -> (Discretization, Pattern, Vec<f64>) {
    let model = build(d);
    let dofs = Discretization::supported(&model);
    let pattern = Pattern::new(&model, dofs.reduced_indices(), dofs.n_free()).unwrap();
    let mut values = vec![f64::NAN; pattern.nnz()];
    Assembler::new(&model)
        .fill(&model, &pattern, &mut values, mode)
        .unwrap();
    (dofs, pattern, values)
}

fn dense(p: &Pattern, v: &[f64]) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(p.n(), p.n());
    for j in 0..p.n() {
        for k in p.col_ptr()[j]..p.col_ptr()[j + 1] {
            m[(p.row_idx()[k], j)] = v[k];
        }
    }
    m
}

#[test]
fn parallel_fill_equals_serial_fill() {
    let d = grid(12, 3, 0.01, 2e-4);
    let (_, p, serial) = assemble(&d, FillMode::Serial);
    let (_, _, parallel) = assemble(&d, FillMode::Parallel);
    let max = serial.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (a, b) in serial.iter().zip(&parallel) {
        assert!((a - b).abs() <= 1e-14 * max, "{a} vs {b}");
    }
    assert!(p.matrix(&serial).unwrap().is_symmetric(1e-14));
}

#[test]
fn fill_equals_dense_sum_of_element_matrices() {
    let d = grid(3, 2, 0.01, 2e-4);
    let model = build(&d);
    let (dofs, p, v) = assemble(&d, FillMode::Parallel);
    let mut full = DMatrix::<f64>::zeros(dofs.n_global(), dofs.n_global());
    for (e, el) in model.elements().iter().enumerate() {
        let k = element_stiffness(&model, e);
        for r in 0..12 {
            for c in 0..12 {
                let gr = 6 * el.nodes[r / 6] + r % 6;
                let gc = 6 * el.nodes[c / 6] + c % 6;
                full[(gr, gc)] += k[(r, c)];
            }
        }
    }
    let reduced = dense(&p, &v);
    let free: Vec<usize> = (0..dofs.n_global())
        .filter(|&g| dofs.reduced(g).is_some())
        .collect();
    let max = full.amax();
    for (i, &gi) in free.iter().enumerate() {
        for (j, &gj) in free.iter().enumerate() {
            assert!((reduced[(i, j)] - full[(gi, gj)]).abs() <= 1e-13 * max);
        }
    }
}

#[test]
fn stiffness_is_invariant_under_rigid_rotation() {
    let d = grid(4, 2, 0.02, 5e-4);
    let q = Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vector3::new(0.3, -1.2, 0.7)),
        1.1,
    );
    let mut rotated = d.clone();
    for n in &mut rotated.nodes {
        let x = q * Vector3::new(n.x[0], n.x[1], n.x[2]) + Vector3::new(0.5, -0.25, 2.0);
        n.x = [x[0], x[1], x[2]];
    }
    let (dofs, p, v) = assemble(&d, FillMode::Parallel);
    let (dofs_r, p_r, v_r) = assemble(&rotated, FillMode::Parallel);
    assert_eq!(dofs.n_free(), dofs_r.n_free());
    let (k, k_r) = (dense(&p, &v), dense(&p_r, &v_r));
    // Every node is either fully clamped or fully free, so T = diag(Q, Q, …) per free node.
    let n = dofs.n_free();
    let mut t = DMatrix::<f64>::zeros(n, n);
    for b in (0..n).step_by(3) {
        t.view_mut((b, b), (3, 3)).copy_from(q.matrix());
    }
    let expected = &t * k * t.transpose();
    let err = (&expected - &k_r).amax();
    assert!(
        err <= 1e-12 * k_r.amax(),
        "rotated stiffness differs by {err:e}"
    );
}
