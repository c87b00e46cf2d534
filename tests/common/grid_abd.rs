//! The beam-theory ABD of a rectangular grid with fixed junctions (derived in
//! `tests/homogenize_lattice.rs`) and a block-scaled ABD comparison.

use std::f64::consts::PI;

/// Grid of fibers of radius `r` (E, ν): x-fibers `sy` apart, y-fibers `sx` apart.
pub fn grid_abd(young: f64, poisson: f64, r: f64, sx: f64, sy: f64) -> [[f64; 6]; 6] {
    let (a, i, j) = (PI * r * r, PI * r.powi(4) / 4.0, PI * r.powi(4) / 2.0);
    let g = young / (2.0 * (1.0 + poisson));
    let mut abd = [[0.0; 6]; 6];
    abd[0][0] = young * a / sy;
    abd[1][1] = young * a / sx;
    abd[2][2] = 12.0 * young * i / ((sx + sy) * sx * sy);
    abd[3][3] = young * i / sy;
    abd[4][4] = young * i / sx;
    abd[5][5] = g * j * (sx + sy) / (4.0 * sx * sy);
    abd
}

/// Every entry within `tol` × √(want_rr want_cc): A ~ EA/L and D ~ EI/L are orders of
/// magnitude apart, so each block is judged on its own scale.
pub fn assert_abd(got: &[[f64; 6]; 6], want: &[[f64; 6]; 6], tol: f64) {
    for r in 0..6 {
        for c in 0..6 {
            let scale = (want[r][r].abs() * want[c][c].abs()).sqrt();
            assert!(
                (got[r][c] - want[r][c]).abs() <= tol * scale,
                "ABD[{r}][{c}] = {:e}, want {:e}",
                got[r][c],
                want[r][c]
            );
        }
    }
}

/// The elastic ABD of a cell with the default solver.
pub fn elastic_abd(d: &fibercell::model::ModelDescription) -> [[f64; 6]; 6] {
    fibercell::homogenize::homogenize_elastic(
        &fibercell::Model::from_description(d).expect("valid cell"),
        &fibercell::solve::SolveOptions::default(),
    )
    .expect("homogenizes")
    .abd
}
