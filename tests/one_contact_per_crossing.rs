//! One crossing, one contact, however the fibers are cut into pieces.
//!
//! A crossing on the periodic seam. Two straight periodic strands — A along y at
//! x = 0.3 L, X along the diagonal (1, 1) — cross once per cell, A resting on X. A strand
//! written as pieces ends on a cell face and goes on from the periodic twin of its end node on
//! the opposite face, or ends at a node the next piece starts from. Cut so that the crossing
//! lies on the seam y = 0 ≡ L, the search sees it on every piece there: X's first and last
//! pieces and A's two pieces (split at y = L/2), directly and through the periodic images. The
//! same cell shifted by L/2 in y holds the crossing inside single pieces. Both hold the same
//! beams, so they must give one contact each and the same ABD to roundoff (1e-9 of the
//! diagonal); so must a third cut that splits A exactly at the crossing. Counting the seam
//! crossing once per piece pair gave four springs on one crossing (the chatter of issue 28).
//!
//! A fiber across a junction. Two yarns P (along x) and Q (along y) share a node J, and a
//! diagonal strand V rests on J. Written with P and Q whole, or split at J into pieces (J then
//! ends two or four fibers: a junction, not a continuation), it is one contact with the same ABD
//! to 1e-9; counted once per yarn, it was two to four springs on one point.

use fibercell::homogenize::homogenize_elastic;
use fibercell::model::{
    CellSpec, ContactSpec, FiberSpec, FrictionSpec, MaterialSpec, ModelDescription, NodeSpec,
};
use fibercell::solve::SolveOptions;
use fibercell::Model;

const L: f64 = 1e-3;
const R: f64 = 2e-5;
const N: usize = 20;

/// Adds a periodic strand of N equal steps from `start` (on a cell face) back to its periodic
/// twin, as pieces: a new piece wherever a point lies on a face (the piece ends on the far face,
/// the next starts on the near one) and at the points listed in `splits` (a shared node).
fn strand(m: &mut ModelDescription, start: [f64; 3], step: [f64; 3], splits: &[usize]) {
    // A point where a node already is (a junction with another strand) is that node.
    let mut node = |x: [f64; 3]| {
        let same = |y: &[f64; 3]| (0..3).all(|i| (x[i] - y[i]).abs() < 1e-12 * L);
        if let Some(n) = m.nodes.iter().find(|n| same(&n.x)) {
            return n.id;
        }
        let id = m.nodes.len() as u64 + 1;
        m.nodes.push(NodeSpec { id, x });
        id
    };
    let on_face = |v: f64| (v / L - (v / L).round()).abs() < 1e-9;
    let mut pieces: Vec<Vec<u64>> = vec![Vec::new()];
    let mut origin = [0.0; 2];
    for k in 0..=N {
        let raw: [f64; 3] = std::array::from_fn(|i| start[i] + k as f64 * step[i]);
        let at = |origin: [f64; 2]| [raw[0] - origin[0], raw[1] - origin[1], raw[2]];
        let crossed: Vec<usize> = (0..2)
            .filter(|&i| k > 0 && step[i] != 0.0 && on_face(raw[i]))
            .collect();
        let id = node(at(origin));
        pieces.last_mut().unwrap().push(id);
        if k == N {
            break;
        }
        if !crossed.is_empty() {
            for i in crossed {
                origin[i] += L;
            }
            let twin = node(at(origin));
            pieces.push(vec![twin]);
        } else if splits.contains(&k) {
            pieces.push(vec![id]);
        }
    }
    for nodes in pieces {
        let id = m.fibers.len() as u64 + 1;
        m.fibers.push(FiberSpec {
            id,
            nodes,
            radius: R,
            material: "fiber".into(),
        });
    }
}

/// An empty square cell with contact search and Tresca friction.
fn empty_cell() -> ModelDescription {
    ModelDescription {
        materials: vec![MaterialSpec {
            name: "fiber".into(),
            young: 2e9,
            poisson: Some(0.35),
            shear: None,
        }],
        cell: Some(CellSpec {
            size: [L, L],
            origin: Some([0.0, 0.0]),
            thickness: Some(6.0 * R),
            tolerance: None,
        }),
        contact: Some(ContactSpec {
            search: true,
            friction: FrictionSpec::Tresca { bound: 1.0 },
            ..Default::default()
        }),
        ..Default::default()
    }
}

/// The cell with the crossing at height `y`; A split at the steps `a_splits`.
fn cell(y: f64, a_splits: &[usize]) -> Model {
    let mut m = empty_cell();
    let h = L / N as f64;
    // X starts on the face y = 0 at the point whose diagonal passes the crossing (0.3 L, y).
    let x0 = (0.3 * L - y).rem_euclid(L);
    strand(&mut m, [x0, 0.0, 0.0], [h, h, 0.0], &[]);
    // A, a hair under two radii above X (closed; the overlap is adjusted to 0).
    let z = 2.0 * R * (1.0 - 1e-9);
    strand(&mut m, [0.3 * L, 0.0, z], [0.0, h, 0.0], a_splits);
    Model::from_description(&m).unwrap()
}

#[test]
fn a_crossing_on_the_seam_is_one_contact_with_the_abd_of_an_interior_one() {
    let interior = cell(0.5 * L, &[]);
    // X: two pieces (the crossing inside the longer one); A: one.
    assert_eq!(interior.fibers.len(), 3);
    let seam = cell(0.0, &[N / 2]);
    // X: two pieces meeting at the crossing on the seam; A: two, one of them from it.
    assert_eq!(seam.fibers.len(), 4);
    let split = cell(0.5 * L, &[N / 2]);
    let reference = homogenize_elastic(&interior, &SolveOptions::default()).unwrap();
    assert_eq!(reference.contacts, 1);
    assert!(reference.abd[0][0] > 0.0 && reference.asymmetry < 1e-10);
    for (name, model) in [("seam", &seam), ("split at the crossing", &split)] {
        assert_same_abd(name, &reference, model);
    }
}

/// One contact, and the ABD of `reference` to 1e-9 of √(ABD_ii ABD_jj).
fn assert_same_abd(name: &str, reference: &fibercell::homogenize::Homogenized, model: &Model) {
    let got = homogenize_elastic(model, &SolveOptions::default()).unwrap();
    assert_eq!(got.contacts, 1, "{name}: contacts");
    for i in 0..6 {
        for j in 0..6 {
            let (a, b) = (reference.abd[i][j], got.abd[i][j]);
            // |ABD_ij| ≤ √(ABD_ii ABD_jj) for a positive semi-definite ABD.
            let block = (reference.abd[i][i] * reference.abd[j][j]).abs().sqrt();
            assert!(
                (a - b).abs() <= 1e-9 * block,
                "{name}: ABD[{i}][{j}] {b} against {a}"
            );
        }
    }
}

/// P along x at y = 0.3 L and Q along y at x = 0.6 L, joined at J = (0.6 L, 0.3 L), split at J
/// as `splits` says; V along the diagonal through J, resting on it.
fn junction_cell(splits: [bool; 2]) -> Model {
    let mut m = empty_cell();
    let h = L / N as f64;
    let at = |split: bool, k: usize| if split { vec![k] } else { vec![] };
    strand(
        &mut m,
        [0.0, 0.3 * L, 0.0],
        [h, 0.0, 0.0],
        &at(splits[0], 12),
    );
    strand(
        &mut m,
        [0.6 * L, 0.0, 0.0],
        [0.0, h, 0.0],
        &at(splits[1], 6),
    );
    let z = 2.0 * R * (1.0 - 1e-9);
    strand(&mut m, [0.3 * L, 0.0, z], [h, h, 0.0], &[]);
    Model::from_description(&m).unwrap()
}

#[test]
fn a_fiber_across_a_junction_of_two_yarns_is_one_contact() {
    let whole = junction_cell([false, false]);
    let reference = homogenize_elastic(&whole, &SolveOptions::default()).unwrap();
    assert_eq!(reference.contacts, 1);
    assert!(reference.abd[0][0] > 0.0 && reference.asymmetry < 1e-10);
    for (name, splits) in [
        ("P split at J", [true, false]),
        ("both split", [true, true]),
    ] {
        let model = junction_cell(splits);
        // P, Q and V's two pieces (it leaves through x = L), and a piece more per split.
        assert_eq!(
            model.fibers.len(),
            4 + splits.iter().filter(|&&s| s).count()
        );
        assert_same_abd(name, &reference, &model);
    }
}
