//! Time per full asperity solve (paraboloid at a given contact radius: kernel
//! quadrature, matrix assembly, LU, two right-hand sides) against node count, for the
//! paper's two-layer stack (h₁ = 100 µm, E2/E1 = 5, rigid base at 1 mm).
//!
//! Run: `cargo bench -p strata-tablegen --bench fredholm -- --quick`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use strata_tablegen::asperity::{Asperity, Method, Options};
use strata_tablegen::fredholm::Discretisation;
use strata_tablegen::runtime::Stack;

fn stack() -> Stack {
    Stack::paper_two_layer(5.0).expect("valid stack")
}

fn solver(d: Discretisation) -> Asperity {
    Asperity::new(
        &stack(),
        Options {
            method: Method::Fixed(d),
            ..Options::default()
        },
    )
    .expect("valid options")
}

fn bench(c: &mut Criterion) {
    let st = stack();
    let mut g = c.benchmark_group("nystrom_a_over_h_1");
    for n in [32usize, 64, 128] {
        let s = solver(Discretisation::Nystrom { nodes: n });
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                s.paraboloid_at_radius(black_box(1e-4), 1e-4)
                    .expect("solve")
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("product_a_over_h_30");
    g.sample_size(10);
    for n in [128usize, 256, 512, 1024] {
        let s = solver(Discretisation::Product {
            intervals: n,
            richardson: true,
        });
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                s.paraboloid_at_radius(black_box(3e-3), 1e-2)
                    .expect("solve")
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("default_at_delta");
    g.sample_size(10);
    let s = Asperity::new(&st, Options::default()).expect("valid");
    g.bench_function("reference_delta_2um", |b| {
        b.iter(|| s.paraboloid_at_delta(black_box(2e-6), 1e-4).expect("solve"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
