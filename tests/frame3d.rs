//! 3D frames: an L-frame against Castigliano's closed form, the fixture frame (members along
//! x, y, z and oblique ones, mixed supports, forces and moments) against an independent dense
//! derivation, and the same model read from TOML, JSON and Abaqus .inp.

mod common;
use common::*;
use fibercell::model::{DofSet, FiberSpec, LoadSpec, ModelDescription, NodeSpec, SupportSpec};
use fibercell::solve::{solve_static, SolveOptions, StaticSolution};
use fibercell::{io, Model};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use std::f64::consts::PI;
use std::path::Path;

fn solve(m: &Model) -> StaticSolution {
    solve_static(m, &SolveOptions::default()).expect("solves")
}

#[test]
fn l_frame_out_of_plane_load_matches_castigliano() {
    // Column along z (length a) clamped at the base, beam along x (length b), tip load P along y.
    // δ_y = P b³/(3EI) + P a³/(3EI) + P b² a/(GJ)   (bending of both members + torsion of the
    // column by the moment P·b).
    let (a, b, r, p) = (0.8, 0.6, 0.01, 5.0);
    let d = ModelDescription {
        name: None,
        materials: vec![steel()],
        nodes: vec![
            NodeSpec {
                id: 1,
                x: [0.0, 0.0, 0.0],
            },
            NodeSpec {
                id: 2,
                x: [0.0, 0.0, a / 2.0],
            },
            NodeSpec {
                id: 3,
                x: [0.0, 0.0, a],
            },
            NodeSpec {
                id: 4,
                x: [b, 0.0, a],
            },
        ],
        fibers: vec![
            FiberSpec {
                id: 1,
                nodes: vec![1, 2, 3],
                radius: r,
                material: "steel".into(),
            },
            FiberSpec {
                id: 2,
                nodes: vec![3, 4],
                radius: r,
                material: "steel".into(),
            },
        ],
        supports: vec![SupportSpec {
            node: 1,
            dofs: vec![DofSet::All],
            value: 0.0,
        }],
        loads: vec![LoadSpec {
            node: 4,
            force: [0.0, p, 0.0],
            moment: [0.0; 3],
        }],
        ..Default::default()
    };
    let sol = solve(&build(&d));
    let ei = E * PI * r.powi(4) / 4.0;
    let gj = E / (2.0 * (1.0 + NU)) * PI * r.powi(4) / 2.0;
    let want = p * b.powi(3) / (3.0 * ei) + p * a.powi(3) / (3.0 * ei) + p * b * b * a / gj;
    let got = sol.displacements[3][1];
    assert!(
        rel(got, want, 0.0) <= 1e-10,
        "δy = {got:e}, closed form {want:e}"
    );
    // Column top: torsion φz = P b a / (GJ).
    let phi = sol.displacements[2][5];
    assert!(rel(phi, p * b * a / gj, 0.0) <= 1e-10);
    // The clamp reaction balances the load along y.
    let fy: f64 = sol
        .reactions
        .iter()
        .filter(|r| r.dof.index() == 1)
        .map(|r| r.value)
        .sum();
    assert!(rel(fy, -p, 0.0) <= 1e-9);
}

/// Independent derivation: quadrature element matrices, a local frame built differently
/// (e2 from a fixed skew vector), dense assembly, supports eliminated, dense Cholesky.
fn independent_solution(m: &Model) -> Vec<f64> {
    let n = 6 * m.nodes.len();
    let mut k = DMatrix::<f64>::zeros(n, n);
    for el in m.elements() {
        let f = &m.fibers[el.fiber];
        let mat = &m.materials[f.material];
        let r = f.section.radius;
        let (a, i, j) = (PI * r * r, PI * r.powi(4) / 4.0, PI * r.powi(4) / 2.0);
        let (x1, x2) = (m.nodes[el.nodes[0]].x, m.nodes[el.nodes[1]].x);
        let d = Vector3::new(x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]);
        let l = d.norm();
        let e1 = d / l;
        let skew = Vector3::new(0.267, -0.534, 0.802);
        let e2 = e1.cross(&skew).normalize();
        let e3 = e1.cross(&e2);
        let rot = Matrix3::from_rows(&[e1.transpose(), e2.transpose(), e3.transpose()]);
        let kl = quadrature_local_stiffness(
            mat.young * a,
            mat.young * i,
            mat.young * i,
            mat.shear * j,
            l,
        );
        let mut t = DMatrix::<f64>::zeros(12, 12);
        for b in 0..4 {
            t.view_mut((3 * b, 3 * b), (3, 3)).copy_from(&rot);
        }
        let kg = t.transpose() * kl * t;
        for r in 0..12 {
            for c in 0..12 {
                k[(6 * el.nodes[r / 6] + r % 6, 6 * el.nodes[c / 6] + c % 6)] += kg[(r, c)];
            }
        }
    }
    let mut f = DVector::<f64>::zeros(n);
    for l in &m.loads {
        f[6 * l.node + l.dof.index()] += l.value;
    }
    let mut fixed = vec![None; n];
    for s in &m.supports {
        fixed[6 * s.node + s.dof.index()] = Some(s.value);
    }
    let free: Vec<usize> = (0..n).filter(|&g| fixed[g].is_none()).collect();
    let uc = DVector::from_iterator(n, (0..n).map(|g| fixed[g].unwrap_or(0.0)));
    let rhs_full = &f - &k * &uc;
    let kff = DMatrix::from_fn(free.len(), free.len(), |a, b| k[(free[a], free[b])]);
    let rhs = DVector::from_iterator(free.len(), free.iter().map(|&g| rhs_full[g]));
    let uf = kff.cholesky().expect("SPD").solve(&rhs);
    let mut u = uc.as_slice().to_vec();
    for (a, &g) in free.iter().enumerate() {
        u[g] = uf[a];
    }
    u
}

#[test]
fn fixture_frame_matches_independent_dense_derivation() {
    let m = io::load_model(Path::new("fixtures/ok_frame3d.toml")).unwrap();
    let sol = solve(&m);
    let want = independent_solution(&m);
    let scale = want.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for (node, u) in sol.displacements.iter().enumerate() {
        for d in 0..6 {
            let w = want[6 * node + d];
            assert!(
                (u[d] - w).abs() <= 1e-9 * scale,
                "node {} dof {d}: {} vs {}",
                m.nodes[node].id,
                u[d],
                w
            );
        }
    }
    // Equilibrium of the whole frame: reactions + loads sum to zero force.
    for k in 0..3 {
        let r: f64 = sol
            .reactions
            .iter()
            .filter(|r| r.dof.index() == k)
            .map(|r| r.value)
            .sum();
        let l: f64 = m
            .loads
            .iter()
            .filter(|l| l.dof.index() == k)
            .map(|l| l.value)
            .sum();
        assert!(
            (r + l).abs() <= 1e-8 * 300.0,
            "force balance along {k}: {r} + {l}"
        );
    }
}

#[test]
fn prescribed_displacement_matches_independent_derivation() {
    let mut d = io::read_description(Path::new("fixtures/ok_frame3d.toml")).unwrap();
    d.supports.push(SupportSpec {
        node: 6,
        dofs: vec![DofSet::Rz],
        value: 0.003,
    });
    d.supports.push(SupportSpec {
        node: 5,
        dofs: vec![DofSet::Rx],
        value: -0.002,
    });
    d.supports[2].value = 0.0;
    let m = build(&d);
    let sol = solve(&m);
    let want = independent_solution(&m);
    let scale = want.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for (node, u) in sol.displacements.iter().enumerate() {
        for dof in 0..6 {
            assert!((u[dof] - want[6 * node + dof]).abs() <= 1e-9 * scale);
        }
    }
    assert_eq!(sol.displacements[m.node_index(6).unwrap()][5], 0.003);
}

#[test]
fn toml_json_and_abaqus_give_the_same_result() {
    let load = |f: &str| {
        let m = io::load_model(Path::new(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        let s = solve(&m);
        let mut by_id: Vec<(u64, [f64; 6])> =
            m.nodes.iter().map(|n| n.id).zip(s.displacements).collect();
        by_id.sort_by_key(|p| p.0);
        by_id
    };
    let t = load("fixtures/ok_frame3d.toml");
    let j = load("fixtures/ok_frame3d.json");
    let a = load("fixtures/ok_frame3d.inp");
    assert_eq!(
        t, j,
        "TOML and JSON are the same schema: bit-identical results"
    );
    let scale = t
        .iter()
        .flat_map(|p| p.1)
        .fold(0.0f64, |m, v| m.max(v.abs()));
    for ((ia, ua), (ib, ub)) in t.iter().zip(&a) {
        assert_eq!(ia, ib);
        for k in 0..6 {
            assert!((ua[k] - ub[k]).abs() <= 1e-12 * scale, "node {ia}");
        }
    }
}
