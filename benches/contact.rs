//! Contact search throughput (segments/s; the pairs found are printed) and one stick/slip
//! increment on generated two-layer grids of crossing fibers.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use fibercell::contact::{find_candidates, ContactSet};
use fibercell::generate::crossing_grid;
use fibercell::solve::{solve_incremental, IncrementalOptions};
use fibercell::Model;
use std::hint::black_box;

fn contact(c: &mut Criterion) {
    let mut g = c.benchmark_group("contact");
    g.sample_size(10);
    for k in [30, 100] {
        let model = Model::from_description(&crossing_grid(k, 4, 5e-3, 2e-4)).expect("grid");
        let segments = model.elements().len();
        let tolerance = model.contact.as_ref().map_or(0.0, |s| s.tolerance);
        let found = find_candidates(&model, tolerance, None).len();
        let pairs = ContactSet::build(&model).expect("contacts").pairs.len();
        eprintln!("crossing grid {k}×{k}: {segments} segments, {found} candidate element pairs, {pairs} contacts");
        g.throughput(Throughput::Elements(segments as u64));
        g.bench_function(format!("search/{segments}-segments"), |b| {
            b.iter(|| black_box(find_candidates(black_box(&model), tolerance, None).len()))
        });
    }
    let model = Model::from_description(&crossing_grid(20, 4, 5e-3, 2e-4)).expect("grid");
    let opts = IncrementalOptions {
        steps: 1,
        ..Default::default()
    };
    g.throughput(Throughput::Elements(400));
    g.bench_function("increment/grid20-400-contacts", |b| {
        b.iter(|| {
            black_box(
                solve_incremental(black_box(&model), &opts)
                    .expect("solves")
                    .increments
                    .len(),
            )
        })
    });
    g.finish();
}

criterion_group!(benches, contact);
criterion_main!(benches);
