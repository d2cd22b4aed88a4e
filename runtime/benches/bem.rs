//! FFT-BEM time per load step at n = 512 on the shared paper-like surface
//! (`../shared/reference/surface_km10.npy`), cold start, for comparison with Tamaas
//! (`tests/python/run.sh --speed` runs both side by side and prints the ratio).
//!
//! Cases: homogeneous half-space (E = 4 GPa, ν = 0.15) at mean gap 0.5·(z_M − z̄), at
//! tolerances 1e-8 and 1e-10; the paper's two-layer stack on a rigid base (E2/E1 = 1)
//! at approach 5 µm.
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;
use strata_runtime::Stack;
use strata_runtime::bem::{BemLoad, BemOptions, BemSolver, read_heights_npy};

fn bench(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/reference");
    let z = read_heights_npy(&dir.join("surface_km10.npy")).expect("shared reference surface");
    let layered =
        Stack::from_toml_file(&dir.join("stack_h100um_E2E1_1.toml")).expect("reference stack");
    let half = Stack::half_space(4e9, 0.15).expect("stack");
    let mut g = c.benchmark_group("bem_512");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_secs(10));
    for tol in [1e-8, 1e-10] {
        let opts = BemOptions {
            tolerance: tol,
            ..Default::default()
        };
        let solver = BemSolver::new(&z, 1e-3, &half, opts).expect("solver");
        let gap = 0.5 * solver.max_separation();
        g.bench_function(format!("halfspace_mean_gap_tol{tol:e}"), |b| {
            b.iter(|| black_box(solver.solve(BemLoad::MeanGap(gap)).expect("solve")))
        });
    }
    let solver = BemSolver::new(&z, 1e-3, &layered, BemOptions::default()).expect("solver");
    g.bench_function("two_layer_rigid_approach_5um_tol1e-10", |b| {
        b.iter(|| black_box(solver.solve(BemLoad::Approach(5e-6)).expect("solve")))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
