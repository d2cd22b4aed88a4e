//! Time per S(ρ) evaluation for 1, 10 and 100 layers.
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use strata_runtime::{Base, Compliance, Layer, Stack};

fn graded(n: usize) -> Stack {
    let total = 1e-3;
    let layers = (0..n)
        .map(|i| Layer {
            thickness: total / n as f64,
            young: 4e9 * (1.0 + 4.0 * i as f64 / n as f64),
            poisson: 0.15 + 0.2 * i as f64 / n as f64,
        })
        .collect();
    Stack::new(
        layers,
        Base::Elastic {
            young: 2e10,
            poisson: 0.35,
        },
    )
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("compliance_S");
    for n in [1usize, 10, 100] {
        let comp = Compliance::new(&graded(n));
        let h1 = 1e-3 / n as f64;
        g.bench_function(format!("{n}_layers"), |b| {
            b.iter(|| comp.s(black_box(1.0 / h1)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
