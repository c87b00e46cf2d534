//! Elastic homogenization of periodic grids with fixed junctions against beam-theory closed
//! forms, independence of where the cell boundary cuts the fibers and of the number of periods,
//! the 90° rotation swap, ABD symmetry, and bad cells.
//!
//! Rectangular grid, x-fibers Ly apart and y-fibers Lx apart, rigidly joined, radius r:
//! * stretching: A11 = EA/Ly, A22 = EA/Lx, A12 = 0 (the families do not interact);
//! * in-plane shear γ: each fiber segment between joints (length L) has a chord rotation ±γ/2
//!   and both ends at the joint rotation θ; its energy is 6EI(θ − ψ)²/L. Minimizing
//!   6EI[(θ − γ/2)²/Lx + (θ + γ/2)²/Ly] over θ gives U = 6EIγ²/(Lx + Ly), so
//!   A66 = 2U/(γ² Lx Ly) = 12EI / ((Lx + Ly) Lx Ly);
//! * bending: D11 = EI/Ly, D22 = EI/Lx, D12 = 0;
//! * twist κ12 (w = −½κ12 xy): every fiber twists at the rate κ12/2 without bending, so
//!   D66 = GJ (Lx + Ly) / (4 Lx Ly);
//! * B = 0 (all fibers in the mid-surface).

mod common;
use common::grid_abd::{assert_abd, grid_abd};
use common::GridCell;
use fibercell::homogenize::{homogenize_elastic, Homogenized};
use fibercell::model::ModelDescription;
use fibercell::solve::SolveOptions;
use fibercell::{Error, Model};

const E: f64 = 1.0e9;
const NU: f64 = 0.3;
const R: f64 = 2e-4;

fn grid_cell(
    lx: f64,
    ly: f64,
    jx: f64,
    jy: f64,
    nx: usize,
    ny: usize,
    sub: usize,
) -> ModelDescription {
    GridCell {
        young: E,
        poisson: NU,
        radius: R,
        size: [lx, ly],
        joint: [jx, jy],
        periods: [nx, ny],
        sub,
    }
    .build()
}

fn homogenize(d: &ModelDescription) -> Homogenized {
    homogenize_elastic(
        &Model::from_description(d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap()
}

fn closed_form(lx: f64, ly: f64) -> [[f64; 6]; 6] {
    grid_abd(E, NU, R, lx, ly)
}

#[test]
fn square_and_rectangular_grids_match_beam_theory() {
    for (lx, ly) in [(5e-3, 5e-3), (4e-3, 7e-3)] {
        let h = homogenize(&grid_cell(lx, ly, 0.5 * lx, 0.5 * ly, 1, 1, 2));
        assert_abd(&h.abd, &closed_form(lx, ly), 1e-9);
        assert!(h.asymmetry <= 1e-10, "asymmetry {}", h.asymmetry);
        // Orthotropic constants of §5.1.2 (A12 = 0: E1 = A11, E2 = A22, ν = 0).
        assert!((h.orthotropic.e1 - h.abd[0][0]).abs() <= 1e-12 * h.abd[0][0]);
        assert!(h.orthotropic.nu12.abs() <= 1e-9);
        assert!(
            (h.orthotropic.e1_pa - h.abd[0][0] / (2.0 * R)).abs() <= 1e-9 * h.orthotropic.e1_pa
        );
    }
}

#[test]
fn result_does_not_depend_on_where_the_boundary_cuts_the_fibers() {
    let (lx, ly) = (4e-3, 7e-3);
    let centred = homogenize(&grid_cell(lx, ly, 0.5 * lx, 0.5 * ly, 1, 1, 3));
    let shifted = homogenize(&grid_cell(lx, ly, 0.3 * lx, 0.85 * ly, 1, 1, 3));
    assert_abd(&shifted.abd, &centred.abd, 1e-9);
}

#[test]
fn result_does_not_depend_on_the_number_of_periods() {
    let (lx, ly) = (4e-3, 7e-3);
    let one = homogenize(&grid_cell(lx, ly, 0.4 * lx, 0.6 * ly, 1, 1, 2));
    let six = homogenize(&grid_cell(lx, ly, 0.4 * lx, 0.6 * ly, 2, 3, 2));
    assert_abd(&six.abd, &one.abd, 1e-9);
    assert!(six.paired_nodes > one.paired_nodes);
}

#[test]
fn rotating_the_geometry_by_90_degrees_swaps_the_directions() {
    let (lx, ly) = (4e-3, 7e-3);
    let h = homogenize(&grid_cell(lx, ly, 0.5 * lx, 0.5 * ly, 1, 1, 2));
    // (x, y) → (y', x') with y' = Lx... : the rotated cell is the grid with the periods swapped,
    // built by rotating every node by 90° about the origin and shifting back into the box.
    let mut d = grid_cell(lx, ly, 0.5 * lx, 0.5 * ly, 1, 1, 2);
    for n in &mut d.nodes {
        n.x = [ly - n.x[1], n.x[0], n.x[2]];
    }
    d.cell.as_mut().unwrap().size = [ly, lx];
    let r = homogenize(&d);
    for (a, b) in [(0, 1), (3, 4)] {
        assert!((r.abd[a][a] - h.abd[b][b]).abs() <= 1e-9 * h.abd[b][b]);
        assert!((r.abd[b][b] - h.abd[a][a]).abs() <= 1e-9 * h.abd[a][a]);
    }
    assert!((r.abd[2][2] - h.abd[2][2]).abs() <= 1e-9 * h.abd[2][2]);
    assert!((r.abd[5][5] - h.abd[5][5]).abs() <= 1e-9 * h.abd[5][5]);
}

#[test]
fn bad_cells_are_reported() {
    let (lx, ly) = (4e-3, 7e-3);
    // A fiber end without a partner: drop the last node of the first x-fiber.
    let mut d = grid_cell(lx, ly, 0.5 * lx, 0.5 * ly, 1, 1, 1);
    let removed = d.fibers[0].nodes.pop().unwrap();
    d.nodes.retain(|n| n.id != removed);
    let e = homogenize_elastic(
        &Model::from_description(&d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::Cell(fibercell::cell::CellError::Unpaired { .. })),
        "{e}"
    );
    assert!(e.to_string().contains("no partner"), "{e}");
    // Only x-fibers: no load path in y.
    let mut d = grid_cell(lx, ly, 0.5 * lx, 0.5 * ly, 1, 1, 2);
    let y_fiber = d.fibers.pop().unwrap();
    let keep: std::collections::HashSet<u64> =
        d.fibers.iter().flat_map(|f| f.nodes.clone()).collect();
    d.nodes
        .retain(|n| keep.contains(&n.id) || !y_fiber.nodes.contains(&n.id));
    let e = homogenize_elastic(
        &Model::from_description(&d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("do not percolate in y"), "{e}");
    // A node outside the box.
    let mut d = grid_cell(lx, ly, 0.5 * lx, 0.5 * ly, 1, 1, 2);
    d.nodes[3].x[0] += lx;
    let e = homogenize_elastic(
        &Model::from_description(&d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("outside the cell"), "{e}");
    // Invalid sizes.
    let mut d = grid_cell(lx, ly, 0.5 * lx, 0.5 * ly, 1, 1, 2);
    d.cell.as_mut().unwrap().size[1] = f64::NAN;
    assert!(Model::from_description(&d)
        .unwrap_err()
        .to_string()
        .contains("size[1]"));
    // A model without [cell].
    let mut d = grid_cell(lx, ly, 0.5 * lx, 0.5 * ly, 1, 1, 2);
    d.cell = None;
    let e = homogenize_elastic(
        &Model::from_description(&d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("no [cell]"), "{e}");
}
