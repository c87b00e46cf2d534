//! analyze / factorize / solve per backend on the reduced stiffness of the grid fixture
//! (36,018 DOFs). CG, which needs tens of thousands of iterations on this slender-fiber system,
//! is timed on a smaller grid so the suite stays short.

use criterion::{criterion_group, criterion_main, Criterion};
use fibercell::solve::ReducedSystem;
use fibercell::solver::{FillOrdering, LinearSolver};
use fibercell_faer::{CholeskyVariant, FaerCholesky, FaerLu};
use std::hint::black_box;
use std::path::Path;

type Make = Box<dyn Fn() -> Box<dyn LinearSolver>>;

fn backends() -> Vec<(&'static str, Make)> {
    #[allow(unused_mut)] // extended with the cholmod feature
    let mut v: Vec<(&'static str, Make)> = vec![
        (
            "faer-llt-amd",
            Box::new(|| Box::new(FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::Amd))),
        ),
        (
            "faer-llt-nd",
            Box::new(|| {
                Box::new(FaerCholesky::new(
                    CholeskyVariant::Llt,
                    FillOrdering::NestedDissection,
                ))
            }),
        ),
        (
            "faer-ldlt-amd",
            Box::new(|| Box::new(FaerCholesky::new(CholeskyVariant::Ldlt, FillOrdering::Amd))),
        ),
        ("faer-lu", Box::new(|| Box::new(FaerLu::new()))),
    ];
    #[cfg(feature = "cholmod")]
    {
        v.push((
            "cholmod-default",
            Box::new(|| Box::new(fibercell_cholmod::Cholmod::new(FillOrdering::Auto))),
        ));
        v.push((
            "cholmod-amd",
            Box::new(|| Box::new(fibercell_cholmod::Cholmod::new(FillOrdering::Amd))),
        ));
        v.push((
            "cholmod-nd",
            Box::new(|| {
                Box::new(fibercell_cholmod::Cholmod::new(
                    FillOrdering::NestedDissection,
                ))
            }),
        ));
    }
    v
}

fn bench_backend(
    c: &mut Criterion,
    group: &str,
    name: &str,
    make: &dyn Fn() -> Box<dyn LinearSolver>,
    sys: &ReducedSystem,
) {
    let a = sys.matrix().expect("matrix");
    let mut g = c.benchmark_group(format!("{group}/{name}"));
    g.sample_size(10);
    g.bench_function("analyze", |b| {
        b.iter(|| {
            let mut s = make();
            black_box(s.analyze(a).expect("analyze"))
        })
    });
    let mut s = make();
    s.analyze(a).expect("analyze");
    g.bench_function("factorize", |b| {
        b.iter(|| s.factorize(black_box(a)).expect("factorize"))
    });
    s.factorize(a).expect("factorize");
    let mut x = sys.rhs.clone();
    g.bench_function("solve", |b| {
        b.iter(|| {
            x.copy_from_slice(&sys.rhs);
            s.solve_in_place(black_box(&mut x), 1).expect("solve")
        })
    });
    // The optional halves (LLᵀ backends): 64 unit columns spread over the matrix by sparse
    // forward solves, and the forward and backward halves of one solve.
    let n = a.ncols();
    let columns: Vec<Vec<(usize, f64)>> = (0..64).map(|j| vec![(j * n / 64, 1.0)]).collect();
    if s.forward_solve_sparse(&columns).is_ok() {
        g.bench_function("forward_sparse_64", |b| {
            b.iter(|| {
                s.forward_solve_sparse(black_box(&columns))
                    .expect("forward")
            })
        });
        g.bench_function("solve_lower", |b| {
            b.iter(|| {
                x.copy_from_slice(&sys.rhs);
                s.solve_lower_in_place(black_box(&mut x)).expect("lower")
            })
        });
        g.bench_function("solve_upper", |b| {
            b.iter(|| {
                x.copy_from_slice(&sys.rhs);
                s.solve_upper_in_place(black_box(&mut x)).expect("upper")
            })
        });
    }
    g.finish();
}

fn solvers(c: &mut Criterion) {
    let model = fibercell::io::load_model(Path::new("fixtures/ok_grid30.json")).expect("fixture");
    let sys = ReducedSystem::assemble(&model, Default::default()).expect("assemble");
    for (name, make) in backends() {
        bench_backend(c, "solvers/grid30", name, make.as_ref(), &sys);
    }
    let small =
        fibercell::Model::from_description(&fibercell::generate::clamped_grid(10, 2, 5e-3, 2e-4))
            .expect("grid");
    let sys = ReducedSystem::assemble(&small, Default::default()).expect("assemble");
    let blocks = sys.dofs.node_block_starts();
    let make = move || -> Box<dyn LinearSolver> {
        Box::new(fibercell_cg::ConjugateGradient::new().with_blocks(blocks.clone()))
    };
    bench_backend(c, "solvers/grid10", "cg", &make, &sys);
    bench_backend(
        c,
        "solvers/grid10",
        "faer-llt-amd",
        &|| Box::new(FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::Amd)),
        &sys,
    );
}

criterion_group!(benches, solvers);
criterion_main!(benches);
