//! Non-woven generation of the S, M and L benchmark cells (fibers/s), and the statistics of
//! the M cell (pairing, contact search with periodic images, contact set).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use fibercell::generate::{nonwoven, nonwoven_preset};
use fibercell::stats::network_stats;
use fibercell::Model;
use std::hint::black_box;

fn generate(c: &mut Criterion) {
    let mut g = c.benchmark_group("generate");
    g.sample_size(10);
    for size in ["S", "M", "L"] {
        let p = nonwoven_preset(size, 1).expect("preset");
        let cell = nonwoven(&p).expect("cell");
        let model = Model::from_description(&cell.description).expect("model");
        let s = network_stats(&model).expect("stats");
        eprintln!(
            "{size}: {} fibers, {} elements, {} nodes ({} DOFs), {} contacts",
            s.fibers,
            s.elements,
            s.nodes,
            6 * s.nodes,
            s.contacts
        );
        g.throughput(Throughput::Elements(s.fibers as u64));
        g.bench_function(format!("nonwoven/{size}"), |b| {
            b.iter(|| black_box(nonwoven(black_box(&p)).expect("cell").report.pieces))
        });
        if size == "M" {
            g.throughput(Throughput::Elements(s.elements as u64));
            g.bench_function("stats/M", |b| {
                b.iter(|| black_box(network_stats(black_box(&model)).expect("stats").contacts))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, generate);
criterion_main!(benches);
