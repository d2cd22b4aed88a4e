//! Lookup cost of a table-backed asperity law: χ/ζ (target < 50 ns), g (< 200 ns).
//! Uses the shipped family table `tables/paper-two-layer.strata` (a member stack
//! with E2/E1 = 5, off the family grid).

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use strata_runtime::Stack;
use strata_runtime::law::AsperityLaw;
use strata_runtime::table::Table;

fn bench(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let table = Table::load(&root.join("tables/paper-two-layer.strata")).expect("shipped table");
    let stack =
        Stack::from_toml_file(&root.join("tables/stacks/paper-two-layer.toml")).expect("stack");
    let law = table.law_for(&stack).expect("member");
    let radii: Vec<f64> = (0..64).map(|i| 1e-6 * (1.0 + 0.37 * i as f64)).collect();
    let mut k = 0;
    c.bench_function("table chi lookup", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            law.chi(black_box(radii[k]))
        })
    });
    c.bench_function("table chi+zeta lookup", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            let a = black_box(radii[k]);
            (law.chi(a), law.zeta(a))
        })
    });
    c.bench_function("table chi_zeta_derivs", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            law.chi_zeta_derivs(black_box(radii[k]))
        })
    });
    c.bench_function("table g lookup", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            let a = black_box(radii[k]);
            law.g(a, black_box(3.1 * a + 2e-5))
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
