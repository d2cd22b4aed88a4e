//! FFT-BEM benches.
//!
//! `bem_512`: time per load step at n = 512 on the shared paper-like surface
//! (`tests/reference/surface_km10.npy`), cold start, for comparison with Tamaas
//! (`tests/python/run.sh --speed` runs both side by side and prints the ratio).
//! Cases: homogeneous half-space (E = 4 GPa, ν = 0.15) at mean gap 0.5·(z_M − z̄), at
//! tolerances 1e-8 and 1e-10; the paper's two-layer stack on a rigid base (E2/E1 = 1)
//! at approach 5 µm.
//!
//! `bem_iteration/n`: time per constrained-conjugate-gradient iteration (two kernel
//! products, i.e. two forward and two inverse 2-D FFTs, plus the projections) on the
//! paper scene's generated surface (L = 1 mm, k = 2…10, RMS 3.4 µm, seed 20240611)
//! resampled spectrally to n × n, two-layer stack E2/E1 = 1 on a rigid base, approach
//! 5 µm, default tolerance: the wall time of a cold solve divided by its iteration
//! count (set-up of the initial guess included, amortised). Throughput is in grid
//! points per second.
//!
//! Run: `cargo bench -p strata-runtime --bench bem` (add `-- --quick` for a short run).
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};
use strata_bem::{Array2, BemLoad, BemOptions, BemSolver, read_heights_npy, resample_spectral};
use strata_runtime::Stack;
use strata_runtime::surface::{GenerateParams, Surface};

fn bench(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/reference");
    let z =
        read_heights_npy(&dir.join("surface_km10.npy")).expect("tests/reference/surface_km10.npy");
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

fn per_iteration(c: &mut Criterion) {
    let s = Surface::generate(&GenerateParams {
        size: 1e-3,
        grid: 512,
        fractal_dimension: 2.4,
        k_min: 2.0,
        k_max: 10.0,
        rms: 3.4e-6,
        seed: 20240611,
    })
    .expect("surface");
    let z512 = Array2::from_shape_vec((512, 512), s.heights().to_vec()).expect("heights");
    let stack = Stack::paper_two_layer(1.0).expect("stack");
    let mut g = c.benchmark_group("bem_iteration");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_secs(3));
    for n in [64usize, 128, 256, 512] {
        let z = resample_spectral(&z512, n).expect("resample");
        let solver = BemSolver::new(&z, 1e-3, &stack, BemOptions::default()).expect("solver");
        g.throughput(Throughput::Elements((n * n) as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let t = Instant::now();
                    let sol = black_box(solver.solve(BemLoad::Approach(5e-6)).expect("solve"));
                    let elapsed = t.elapsed();
                    total += elapsed / sol.iterations.max(1) as u32;
                }
                total
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench, per_iteration);
criterion_main!(benches);
