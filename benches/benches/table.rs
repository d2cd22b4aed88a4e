//! Lookup cost of a table-backed asperity law: χ/ζ (target < 50 ns), g (< 200 ns).
//! Uses the shipped family table `tables/paper-two-layer.strata` (a member stack
//! with E2/E1 = 5, off the family grid).
//!
//! Side by side in one run: the runtime's hand-written C¹ cubic Hermite
//! (`interp::Pair1`) against the `splines` crate holding the same interpolant exactly
//! (cubic Bézier keys with mirrored tangents p_k ± m_k/3) on the χ nodes of that
//! member; the setup asserts the two agree to 1e-13. The figures are quoted in the
//! runtime's `table` module docs.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use strata_runtime::Stack;
use strata_runtime::law::AsperityLaw;
use strata_runtime::table::Table;
use strata_runtime::table::interp::{Pair1, node_slopes, slice_leading};

fn bench(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let table = Table::load(&root.join("tables/paper-two-layer.strata")).expect("shipped table");
    let stack =
        Stack::from_toml_file(&root.join("tables/stacks/paper-two-layer.toml")).expect("stack");
    let law = table.law_for(&stack).expect("member");
    let radii: Vec<f64> = (0..64).map(|i| 1e-6 * (1.0 + 0.37 * i as f64)).collect();
    let mut k = 0;
    // The same χ interpolant, hand-written and as a `splines` Bézier spline.
    let h = &table.header;
    let fam = h.family.expect("shipped table is a family");
    let coord = table.family_coordinate(&stack).expect("member");
    let chi = slice_leading(&fam.ratio, &table.chi, h.x.n, coord);
    let slopes = node_slopes(h.x.n, |i| chi[i]);
    let pair = Pair1::new(h.x, &chi, &chi);
    let keys: Vec<splines::Key<f64, f64>> = (0..h.x.n)
        .map(|i| {
            let ctrl = chi[i] + slopes[i] / 3.0;
            splines::Key::new(h.x.node(i), chi[i], splines::Interpolation::Bezier(ctrl))
        })
        .collect();
    let spline = splines::Spline::from_vec(keys);
    let h1 = stack.layers()[0].thickness;
    let coords: Vec<f64> = radii.iter().map(|a| (a / h1).ln()).collect();
    let worst = (0..=1000)
        .map(|i| h.x.lo + (h.x.hi - h.x.lo) * i as f64 / 1000.0)
        .filter_map(|c| {
            spline
                .sample(c)
                .map(|v| (v - pair.first(c)).abs() / v.abs())
        })
        .fold(0.0_f64, f64::max);
    assert!(worst < 1e-13, "splines vs hand-written: {worst:e}");
    eprintln!("splines Bezier keys reproduce the hand-written chi to {worst:.1e} (relative)");
    c.bench_function("chi interpolant: hand-written Pair1", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            pair.first(black_box(coords[k]))
        })
    });
    c.bench_function("chi interpolant: splines Bezier", |b| {
        b.iter(|| {
            k = (k + 1) & 63;
            spline.sample(black_box(coords[k]))
        })
    });
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
