//! A contact switching from stick to sliding is a rank-2 change of the cell matrix: K_ff with
//! contact i stuck minus K_ff with it sliding is w₁w₁ᵀ + w₂w₂ᵀ with the columns of
//! `PeriodicSystem::stick_spring_columns` (1e-12 of the largest entry: the same products summed
//! in another order), and with the cholmod feature a CHOLMOD factor downdated by those columns
//! solves the switched system backward-stably (normwise backward error ≤ 1e-13; these cells
//! are ill-conditioned, so forward errors of two stable solves differ by ~1e-8).

mod common;
use common::small_nonwoven;
use fibercell::homogenize::{ContactStiffness, PeriodicSystem};
use fibercell::Model;

fn cell() -> (Model, PeriodicSystem) {
    let model = Model::from_description(&small_nonwoven()).unwrap();
    let sys = PeriodicSystem::new(&model).unwrap();
    (model, sys)
}

fn values(model: &Model, sys: &PeriodicSystem, sliding: &[usize]) -> Vec<f64> {
    let mut v = sys.zero_values();
    sys.add_elements(model, &mut v);
    sys.add_contacts(&mut v, |i| {
        if sliding.contains(&i) {
            ContactStiffness::Sliding
        } else {
            ContactStiffness::Stick
        }
    });
    v.values
}

#[test]
fn switching_a_contact_to_sliding_removes_its_two_stick_columns() {
    let (model, sys) = cell();
    let n = sys.n_contacts();
    assert!(n >= 10, "{n} contacts");
    let stick = values(&model, &sys, &[]);
    let scale = stick.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let a = sys.pattern.matrix(&stick).unwrap();
    for i in [0, n / 3, n - 1] {
        let sliding = values(&model, &sys, &[i]);
        let columns = sys.stick_spring_columns(i);
        assert!(columns.iter().all(|c| !c.is_empty()));
        let w = |k: usize, r: usize| columns[k].iter().find(|e| e.0 == r).map_or(0.0, |e| e.1);
        let mut changed = 0;
        for col in 0..a.ncols() {
            let (rows, _) = a.col(col);
            let start = sys.pattern.col_ptr()[col];
            for (k, &row) in rows.iter().enumerate() {
                let slot = start + k;
                let diff = stick[slot] - sliding[slot];
                let expected = w(0, row) * w(0, col) + w(1, row) * w(1, col);
                assert!(
                    (diff - expected).abs() <= 1e-12 * scale,
                    "contact {i} ({row}, {col}): {diff} vs {expected}"
                );
                changed += usize::from(expected != 0.0);
            }
        }
        assert!(changed > 0);
    }
}

#[cfg(feature = "cholmod")]
#[test]
fn a_cholmod_downdate_by_the_stick_columns_solves_the_switched_system() {
    use fibercell::solver::{backward_error, FillOrdering, LinearSolver};
    let (model, sys) = cell();
    let n = sys.n_contacts();
    let switched = [1, n / 2, n - 2];
    let stick = values(&model, &sys, &[]);
    let sliding = values(&model, &sys, &switched);
    let a0 = sys.pattern.matrix(&stick).unwrap();
    let a = sys.pattern.matrix(&sliding).unwrap();
    let w = sys.stick_spring_matrix(&switched).unwrap();
    let b: Vec<f64> = (0..sys.n_free())
        .map(|i| ((i % 5) as f64 - 2.0) * 1e-3)
        .collect();
    let solve = |s: &mut dyn LinearSolver| {
        let mut x = b.clone();
        s.solve_in_place(&mut x, 1).unwrap();
        x
    };
    let mut modified = fibercell_cholmod::Cholmod::new(FillOrdering::Auto);
    modified.analyze(a0).unwrap();
    modified.factorize(a0).unwrap();
    modified.update_factor(w.as_ref(), false).unwrap();
    let got = solve(&mut modified);
    // A backward-stable solve of the switched matrix, and not one of the unswitched.
    let on_switched = backward_error(a, &got, &b);
    let on_original = backward_error(a0, &got, &b);
    assert!(on_switched <= 1e-13, "{on_switched:e}");
    assert!(on_original >= 1e-8, "{on_original:e}");
}
