//! Rough-contact solver speed (issue 5 targets, 2 cores): a 20-step load curve on the
//! paper's k_M = 10 surface (n = 512) with the I model < 0.5 s, k_M = 40 < 3 s, and the
//! N model < 20 ms. The material law is the homogeneous one by default; set
//! `STRATA_BENCH_TABLE=/path/to/table.strata` and `STRATA_BENCH_STACK=/path/stack.toml`
//! to time a layered law from a surrogate table as well.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::rough::{Images, Model, RoughContact};
use strata_runtime::surface::{GenerateParams, Surface};

fn surface(k_max: f64) -> Surface {
    Surface::generate(&GenerateParams {
        size: 1e-3,
        grid: 512,
        fractal_dimension: 2.4,
        k_min: 2.0,
        k_max,
        rms: 3.4e-6,
        seed: 20240611,
    })
    .expect("surface")
}

fn curve(c: &mut Criterion, name: &str, law: &dyn AsperityLaw, s: &Surface) {
    let rc = RoughContact::from_surface(law, s).expect("summits");
    // 20 approaches up to g_n ≈ 0.13 (z_M − z̄), as in the paper's curves
    let top = rc.top_to_mean();
    let deltas: Vec<f64> = (1..=20).map(|i| 0.87 * top * i as f64 / 20.0).collect();
    for (label, model) in [
        ("N", Model::Independent),
        ("I-isolated", Model::Interacting(Images::Isolated)),
        ("I-periodic5x5", Model::Interacting(Images::Periodic(2))),
    ] {
        c.bench_function(&format!("{name}/{label}/20 steps"), |b| {
            b.iter(|| black_box(rc.curve(model, black_box(&deltas)).expect("solve")))
        });
    }
}

fn benches(c: &mut Criterion) {
    let hom = Homogeneous { e_star: 4.092e9 };
    let s10 = surface(10.0);
    let s40 = surface(40.0);
    curve(c, "km10-homogeneous", &hom, &s10);
    curve(c, "km40-homogeneous", &hom, &s40);
    if let (Ok(t), Ok(st)) = (
        std::env::var("STRATA_BENCH_TABLE"),
        std::env::var("STRATA_BENCH_STACK"),
    ) {
        let table = strata_runtime::table::Table::load(std::path::Path::new(&t)).expect("table");
        let stack =
            strata_runtime::Stack::from_toml_file(std::path::Path::new(&st)).expect("stack");
        let law = table.law_for(&stack).expect("law");
        curve(c, "km10-table", &law, &s10);
        curve(c, "km40-table", &law, &s40);
    }
}

criterion_group! {
    name = rough;
    config = Criterion::default().sample_size(10);
    targets = benches
}
criterion_main!(rough);
