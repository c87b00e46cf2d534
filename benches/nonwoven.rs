//! The stages of `fibercell bench` under criterion, on the non-woven cells S and M: contact
//! search with periodic images (segments/s), value fill of the elements and of the closed
//! contacts of the periodic cell system (elements/s, pairs/s), numeric factorization with the
//! pattern analyzed once (faer, and CHOLMOD with the feature), and the solve after one contact
//! switch by CG on the previous factor (and, with the feature, by a rank-2 downdate of
//! CHOLMOD's factor). `fibercell bench` runs the same stages (and the cell
//! problems, the curve, L) with the machine's limits alongside.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use fibercell::cell::pair_boundary_nodes;
use fibercell::contact::find_candidates;
use fibercell::generate::{nonwoven, nonwoven_preset};
use fibercell::homogenize::{ContactStiffness, PeriodicSystem};
use fibercell::solve::{SolverConfig, SolverKind};
use fibercell::Model;
use fibercell_solver::pcg_with_factor;
use std::hint::black_box;

fn stages(c: &mut Criterion) {
    let mut g = c.benchmark_group("nonwoven");
    g.sample_size(10);
    for size in ["S", "M"] {
        let p = nonwoven_preset(size, 1).expect("preset");
        let cell = nonwoven(&p).expect("cell");
        let model = Model::from_description(&cell.description).expect("model");
        let periodicity = pair_boundary_nodes(&model).expect("pairing");
        let tolerance = model.contact.as_ref().map_or(0.0, |c| c.tolerance);
        let elements = model.elements().len();
        g.throughput(Throughput::Elements(elements as u64));
        g.bench_function(format!("contact search/{size}"), |b| {
            b.iter(|| black_box(find_candidates(&model, tolerance, Some(&periodicity)).len()))
        });

        let sys = PeriodicSystem::new(&model).expect("cell system");
        let mut values = sys.zero_values();
        g.bench_function(format!("fill elements/{size}"), |b| {
            b.iter(|| {
                values.values.fill(0.0);
                sys.add_elements(&model, &mut values);
                black_box(values.values[0])
            })
        });
        g.throughput(Throughput::Elements(sys.n_contacts() as u64));
        g.bench_function(format!("fill contacts/{size}"), |b| {
            b.iter(|| {
                values.values.fill(0.0);
                sys.add_contacts(&mut values, |_| ContactStiffness::Stick);
                black_box(values.values[0])
            })
        });

        let stick = sys.assemble(&model);
        let a = sys.pattern.matrix(&stick.values).expect("matrix");
        let rhs: Vec<f64> = stick.couplings.coupling.iter().map(|c| -c[0]).collect();
        g.throughput(Throughput::Elements(1));
        let mut kinds = vec![("faer", SolverKind::FaerCholesky)];
        if cfg!(feature = "cholmod") {
            kinds.push(("cholmod", SolverKind::Cholmod));
        }
        for (name, kind) in kinds {
            let mut solver = SolverConfig::new(kind).build().expect("backend");
            solver.analyze(a).expect("analysis");
            g.bench_function(format!("factorize {name}/{size}"), |b| {
                b.iter(|| solver.factorize(a).expect("factorization"))
            });
        }

        let mut factor = SolverConfig::new(SolverKind::FaerCholesky)
            .build()
            .expect("faer");
        factor.analyze(a).expect("analysis");
        factor.factorize(a).expect("factorization");
        let mut switched = sys.zero_values();
        sys.add_elements(&model, &mut switched);
        sys.add_contacts(&mut switched, |i| {
            if i == 0 {
                ContactStiffness::Sliding
            } else {
                ContactStiffness::Stick
            }
        });
        let a1 = sys.pattern.matrix(&switched.values).expect("matrix");
        g.bench_function(format!("solve after one switch/{size}"), |b| {
            b.iter(|| {
                let r = pcg_with_factor(factor.as_mut(), a1, &rhs, 1e-13, 500).expect("pcg");
                assert!(r.converged);
                black_box(r.iterations)
            })
        });
        if let Ok(mut chol) = SolverConfig::new(SolverKind::Cholmod).build() {
            // The switch as a rank-2 downdate of CHOLMOD's factor, a solve, and the update
            // back (the factor stays simplicial after the first modification).
            let w = sys.stick_spring_matrix(&[0]).expect("columns");
            chol.analyze(a).expect("analysis");
            chol.factorize(a).expect("factorization");
            g.bench_function(format!("downdate, solve, update cholmod/{size}"), |b| {
                b.iter(|| {
                    chol.update_factor(w.as_ref(), false).expect("downdate");
                    let mut x = rhs.clone();
                    chol.solve_in_place(&mut x, 1).expect("solve");
                    chol.update_factor(w.as_ref(), true).expect("update");
                    black_box(x[0])
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, stages);
criterion_main!(benches);
