//! A crossing on the periodic seam is one contact. Two straight periodic strands — A along y at
//! x = 0.3 L, X along the diagonal (1, 1) — cross once per cell, A resting on X. A strand
//! written as pieces ends on a cell face and goes on from the periodic twin of its end node on
//! the opposite face, or ends at a node the next piece starts from. Cut so that the crossing
//! lies on the seam y = 0 ≡ L, the search sees it on every piece there: X's first and last
//! pieces and A's two pieces (split at y = L/2), directly and through the periodic images. The
//! same cell shifted by L/2 in y holds the crossing inside single pieces. Both hold the same
//! beams, so they must give one contact each and the same ABD to roundoff (1e-9 of the
//! diagonal); so must a third cut that splits A exactly at the crossing. Counting the seam
//! crossing once per piece pair gave four springs on one crossing (the chatter of issue 28).

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
    let mut node = |x: [f64; 3]| {
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

/// The cell with the crossing at height `y`; A split at the steps `a_splits`.
fn cell(y: f64, a_splits: &[usize]) -> Model {
    let mut m = ModelDescription {
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
    };
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
    let opts = SolveOptions::default();
    let interior = cell(0.5 * L, &[]);
    // X: two pieces (the crossing inside the longer one); A: one.
    assert_eq!(interior.fibers.len(), 3);
    let seam = cell(0.0, &[N / 2]);
    // X: two pieces meeting at the crossing on the seam; A: two, one of them from it.
    assert_eq!(seam.fibers.len(), 4);
    let split = cell(0.5 * L, &[N / 2]);
    let reference = homogenize_elastic(&interior, &opts).unwrap();
    assert_eq!(reference.contacts, 1);
    assert!(reference.abd[0][0] > 0.0 && reference.asymmetry < 1e-10);
    for (name, model) in [("seam", &seam), ("split at the crossing", &split)] {
        let got = homogenize_elastic(model, &opts).unwrap();
        assert_eq!(got.contacts, 1, "{name}: contacts");
        for i in 0..6 {
            for j in 0..6 {
                let (a, b) = (reference.abd[i][j], got.abd[i][j]);
                // |ABD_ij| ≤ √(ABD_ii ABD_jj) for a positive semi-definite ABD.
                let block = (reference.abd[i][i] * reference.abd[j][j]).abs().sqrt();
                assert!(
                    (a - b).abs() <= 1e-9 * block,
                    "{name}: ABD[{i}][{j}] {b} against {a} with the crossing inside"
                );
            }
        }
    }
}
