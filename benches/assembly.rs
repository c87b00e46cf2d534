//! Assembly throughput on the committed grid fixture: pattern + slot map (once per pattern) and
//! value fills (serial and parallel), in elements per second.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use fibercell::assembly::{Assembler, FillMode, Pattern};
use fibercell::constraints::Discretization;
use std::hint::black_box;
use std::path::Path;

fn assembly(c: &mut Criterion) {
    let model = fibercell::io::load_model(Path::new("fixtures/ok_grid30.json")).expect("fixture");
    let n_el = model.elements().len() as u64;
    let dofs = Discretization::supported(&model);
    let pattern = Pattern::new(&model, dofs.reduced_indices(), dofs.n_free()).expect("pattern");
    let assembler = Assembler::new(&model);
    let mut values = vec![0.0; pattern.nnz()];
    let mut g = c.benchmark_group("assembly/grid30");
    g.throughput(Throughput::Elements(n_el));
    g.sample_size(20);
    g.bench_function("pattern", |b| {
        b.iter(|| {
            let d = Discretization::supported(black_box(&model));
            let p = Pattern::new(&model, d.reduced_indices(), d.n_free()).expect("pattern");
            let a = Assembler::new(&model);
            black_box((p.nnz(), a.n_colors()))
        })
    });
    for (name, mode) in [
        ("fill-serial", FillMode::Serial),
        ("fill-parallel", FillMode::Parallel),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                assembler
                    .fill(black_box(&model), &pattern, &mut values, mode)
                    .expect("fill");
                black_box(values[0])
            })
        });
    }
    g.finish();
}

criterion_group!(benches, assembly);
criterion_main!(benches);
