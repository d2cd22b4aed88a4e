//! FFT-BEM benches. Run: `cargo bench -p strata-benches --bench bem` (add `-- --quick`
//! for a short run; a filter such as `-- floor` runs one part).
//!
//! * `bem_floor` (printed table, one run): per grid n = 256, 512, 1024, 2048 the time of
//!   one real-to-complex 2-D FFT pair with the kernel multiply (`RealFft2::convolve`,
//!   the floor of an iteration) and the time per constrained-CG iteration of a solve,
//!   plain (Polonsky–Keer) and preconditioned (the default; two convolutions per
//!   iteration), with the convolutions each spent per iteration (paper-like surface,
//!   L = 1 mm, D_f = 2.4, k = 2…10, RMS 3.4 µm, seed 20240611, generated at n; two-layer
//!   stack E2/E1 = 1 on a rigid base; approach 5 µm, tolerance 1e-10, warm-started from
//!   the solution at 4.75 µm as along a load curve), timed alternately in one run (best
//!   of the repetitions of each, with the load average), and the ratios; then the wall
//!   time of the 20-step 512² E2/E1 = 5 curve (best of 3), preconditioned and plain.
//!   The table also times a state pass (read and write p, u, t, r, read z: the memory
//!   traffic any Polonsky–Keer iteration has besides its convolution) and gives
//!   (pair + state pass) / pair, the floor of an iteration where the fields outgrow
//!   the cache, and the fused floor (`FusedPass`: the pair with a clean iteration's
//!   least row work fused into its row passes) over the pair. The last column is the
//!   preconditioned solve's time over 1.5 pairs × the plain solve's iterations: the
//!   step time of the default solver against what a plain iteration at 1.5 pairs
//!   would give.
//!   All on all cores (rayon).
//! * `bem_fft_pair/n`, `bem_iteration/n`: the same two quantities under criterion.
//! * `bem_512`: one load step at n = 512 on the shared paper-like surface
//!   (`tests/reference/surface_km10.npy`) from a cold start: half-space at mean gap
//!   0.5·(z_M − z̄) (tolerances 1e-8, 1e-10); the two-layer stack at approach 5 µm.
//! * `bem_curve_512`: the 20-step load curve at 512² on the paper's E2/E1 = 5 stack
//!   (the `fig15-18-E2E1-5` scene's surface, approaches 1.3…9.8 µm), warm-started.
//! * `bem_plastic_512` (printed): one 512² step elastic and capped by a hardness, side by
//!   side (`plastic_table`).
//! * `bem_vs_tamaas` (printed, with `STRATA_TAMAAS_DIR`): per n = 512, 2048 writes the
//!   generated surface to `DIR/surface_n.npy`, times one cold load step under mean-
//!   pressure (p̄ = 0.005 E*) and mean-gap (0.5·(z_M − z̄)) control on the half-space
//!   (E = 4 GPa, ν = 0.15) at tolerance 1e-8 and writes `DIR/strata_speed.csv`;
//!   `tests/python/run.sh --speed` runs it and Tamaas 2.9 on the same files and loads.
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use strata_bem::{Array2, BemLoad, BemOptions, BemSolver, read_heights_npy};
use strata_benches::{curve_approaches, filter_matches, paper_surface};
use strata_runtime::Stack;
use strata_runtime::fft::RealFft2;
use strata_runtime::surface::Surface;

/// Median of `reps` timings of `f` (s).
fn median(reps: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[reps / 2]
}

/// One timing of `f` (s).
fn once(f: impl FnOnce()) -> f64 {
    let t0 = Instant::now();
    f();
    t0.elapsed().as_secs_f64()
}

/// An FFT pair with the kernel multiply on an n×n grid, ready to time.
struct Pair {
    plan: RealFft2,
    work: strata_runtime::fft::Fft2Work,
    input: Vec<f64>,
    kernel: Vec<f64>,
    out: Vec<f64>,
}

impl Pair {
    fn new(n: usize) -> Self {
        let plan = RealFft2::new(n, n).expect("plan");
        let work = plan.work();
        let input: Vec<f64> = (0..n * n).map(|i| (i as f64 * 0.37).sin()).collect();
        let kernel: Vec<f64> = (0..plan.spectrum_len())
            .map(|i| 1.0 / (1.0 + i as f64))
            .collect();
        Pair {
            plan,
            work,
            input,
            kernel,
            out: vec![0.0; n * n],
        }
    }

    fn run(&mut self) {
        self.plan
            .convolve(
                &self.input,
                &mut self.out,
                &self.kernel,
                0.0,
                &mut self.work,
            )
            .expect("convolve");
        black_box(&self.out);
    }
}

/// The state pass: one parallel pass that reads and writes four n×n f64 fields and
/// reads a fifth — p, u, t, r and z, the least any Polonsky–Keer iteration moves
/// through memory besides its convolution (each of the four is updated once per
/// iteration, z is read to form the gap). Its time added to the pair's is the floor of
/// an iteration at grids whose fields do not fit in cache.
struct StatePass {
    p: Vec<f64>,
    u: Vec<f64>,
    t: Vec<f64>,
    r: Vec<f64>,
    z: Vec<f64>,
}

impl StatePass {
    fn new(n: usize) -> Self {
        let f = |s: f64| {
            (0..n * n)
                .map(|i| (i as f64 * s).sin())
                .collect::<Vec<f64>>()
        };
        StatePass {
            p: f(0.1),
            u: f(0.2),
            t: f(0.3),
            r: f(0.4),
            z: f(0.5),
        }
    }

    fn run(&mut self) {
        use rayon::prelude::*;
        const CHUNK: usize = 1 << 15;
        let (a, b) = (1e-3, 0.5);
        self.p
            .par_chunks_mut(CHUNK)
            .zip(self.u.par_chunks_mut(CHUNK))
            .zip(self.t.par_chunks_mut(CHUNK))
            .zip(self.r.par_chunks_mut(CHUNK))
            .zip(self.z.par_chunks(CHUNK))
            .for_each(|((((p, u), t), r), z)| {
                for k in 0..p.len() {
                    p[k] = (p[k] - a * t[k]).max(0.0);
                    u[k] -= a * r[k];
                    t[k] = u[k] - z[k] + b * t[k];
                    r[k] *= b;
                }
            });
        black_box(&self.p);
    }
}

/// The fused floor: one convolution with a clean Polonsky–Keer iteration's row work
/// fused into its two row passes and nothing else (no sums, no contact-set checks):
/// the fill applies the step (p ← max(p − a t, 0), u ← u − a r) and forms the gap
/// g = u − z + b on the set as the transform's input; the drain forms t ← g + b t and
/// r ← q + b r from the product q. The least a fused iteration can cost (its fields move
/// through memory once, beside the FFT's own traffic).
struct FusedPass {
    plan: RealFft2,
    work: strata_runtime::fft::Fft2Work,
    kernel: Vec<f64>,
    fields: [Vec<f64>; 6],
}

impl FusedPass {
    fn new(n: usize) -> Self {
        let plan = RealFft2::new(n, n).expect("plan");
        let work = plan.work();
        let kernel: Vec<f64> = (0..plan.spectrum_len())
            .map(|i| 1.0 / (1.0 + i as f64))
            .collect();
        let f = |s: f64| {
            (0..n * n)
                .map(|i| (i as f64 * s).sin())
                .collect::<Vec<f64>>()
        };
        FusedPass {
            plan,
            work,
            kernel,
            fields: [f(0.1), f(0.2), f(0.3), f(0.4), f(0.5), vec![0.0; n * n]],
        }
    }

    fn run(&mut self) {
        use strata_runtime::fft::Fields;
        let (a, b) = (1e-3, 0.5);
        let [p, u, t, r, z, g] = &mut self.fields;
        self.plan
            .convolve_fields(
                Fields {
                    fields: [
                        &mut p[..],
                        &mut u[..],
                        &mut t[..],
                        &mut r[..],
                        &mut z[..],
                        &mut g[..],
                    ],
                    kernel: (&self.kernel).into(),
                    dc: 0.0,
                },
                &mut self.work,
                |_, [p, u, t, r, z, g], input: &mut [f64]| {
                    for k in 0..input.len() {
                        let pn = (p[k] - a * t[k]).max(0.0);
                        let un = u[k] - a * r[k];
                        let gn = if pn > 0.0 { un - z[k] + b } else { 0.0 };
                        p[k] = pn;
                        u[k] = un;
                        g[k] = gn;
                        input[k] = gn;
                    }
                },
                |_| Some(b),
                |&b, _, [_, _, t, r, _, g], q: &[f64]| {
                    for k in 0..q.len() {
                        t[k] = g[k] + b * t[k];
                        r[k] = q[k] + b * r[k];
                    }
                },
            )
            .expect("convolve");
        black_box(&self.fields);
    }
}

/// The floor table's solve at n: a warm-started load step (the approach 5 µm from the
/// solution at 4.75 µm), ready to time.
struct Step {
    solver: BemSolver,
    init: Vec<f64>,
}

impl Step {
    fn new(n: usize, preconditioner: bool) -> Self {
        let z = paper_surface(n);
        let stack = Stack::paper_two_layer(1.0).expect("stack");
        let opts = BemOptions {
            preconditioner,
            ..Default::default()
        };
        let solver = BemSolver::new(&z, 1e-3, &stack, opts).expect("solver");
        let prev = solver.solve(BemLoad::Approach(4.75e-6)).expect("solve");
        let init = prev.pressure.iter().copied().collect();
        Step { solver, init }
    }

    /// Iterations and convolutions of one solve.
    fn run(&self) -> (usize, usize) {
        let s = self
            .solver
            .solve_from(BemLoad::Approach(5e-6), Some(&self.init))
            .expect("solve");
        black_box(&s);
        (s.iterations.max(1), s.products)
    }
}

/// CPU time of this process so far (ns): the sum over its threads of the scheduler's
/// run time (/proc/self/task/*/schedstat), which a loaded machine does not inflate
/// the way it inflates wall time; 0 where unavailable.
fn cpu_ns() -> u64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    tasks
        .filter_map(|t| t.ok())
        .filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum()
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "?".into())
}

/// The 20-step 512² load curve on the paper's E2/E1 = 5 stack (approaches 1.3…9.8 µm).
fn curve_loads() -> Vec<BemLoad> {
    curve_approaches()
        .into_iter()
        .map(BemLoad::Approach)
        .collect()
}

fn floor_table(_c: &mut Criterion) {
    if !filter_matches("floor") {
        return;
    }
    println!(
        "\nbem_floor: time per CG iteration vs one realfft 2-D pair (same run, {} threads; \
         pair and solve timed alternately, best of the repetitions of each, so that the \
         load of a shared machine hits both alike)",
        rayon::current_num_threads()
    );
    println!(
        "| n | FFT pair (ms) | state pass (ms) | (pair + state pass) / pair | fused floor / pair | iteration (ms): plain / preconditioned | iteration / pair: plain / preconditioned | convolutions per iteration: plain / preconditioned | iterations: plain / preconditioned | CPU ratio: plain / preconditioned | preconditioned step / (1.5 pair × plain iterations) | load average |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    // STRATA_FLOOR_GRIDS (e.g. "512,2048") limits the grids; "0" skips the table.
    let grids: Vec<usize> = std::env::var("STRATA_FLOOR_GRIDS")
        .ok()
        .map(|v| v.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![256, 512, 1024, 2048]);
    for n in grids.into_iter().filter(|&n| n > 0) {
        let mut pair = Pair::new(n);
        let mut state = StatePass::new(n);
        let mut fused = FusedPass::new(n);
        let steps = [Step::new(n, false), Step::new(n, true)];
        let (rounds, pairs) = if n >= 2048 { (4, 3) } else { (8, 9) };
        let mut best_pair = f64::INFINITY;
        let mut best_state = f64::INFINITY;
        let mut best_fused = f64::INFINITY;
        let (mut cpu_pair, mut n_pair) = (0u64, 0usize);
        // Per solver: best time per iteration, CPU ns, iterations timed, last counts.
        let mut best = [f64::INFINITY; 2];
        let mut cpu = [0u64; 2];
        let mut timed = [0usize; 2];
        let mut counts = [(0usize, 0usize); 2];
        for _ in 0..rounds {
            let c0 = cpu_ns();
            for _ in 0..pairs {
                best_pair = best_pair.min(once(|| pair.run()));
            }
            cpu_pair += cpu_ns() - c0;
            n_pair += pairs;
            for _ in 0..pairs {
                best_state = best_state.min(once(|| state.run()));
            }
            for _ in 0..pairs {
                best_fused = best_fused.min(once(|| fused.run()));
            }
            for (k, step) in steps.iter().enumerate() {
                let c1 = cpu_ns();
                let t = once(|| counts[k] = step.run());
                cpu[k] += cpu_ns() - c1;
                timed[k] += counts[k].0;
                best[k] = best[k].min(t / counts[k].0 as f64);
            }
        }
        let cp = cpu_pair as f64 / n_pair as f64;
        let ci = |k: usize| cpu[k] as f64 / timed[k] as f64;
        let per = |k: usize| counts[k].1 as f64 / counts[k].0 as f64;
        println!(
            "| {n} | {:.3} | {:.3} | {:.2} | {:.2} | {:.3} / {:.3} | {:.2} / {:.2} | {:.2} / {:.2} | {} / {} | {:.2} / {:.2} | {:.2} | {} |",
            best_pair * 1e3,
            best_state * 1e3,
            (best_pair + best_state) / best_pair,
            best_fused / best_pair,
            best[0] * 1e3,
            best[1] * 1e3,
            best[0] / best_pair,
            best[1] / best_pair,
            per(0),
            per(1),
            counts[0].0,
            counts[1].0,
            ci(0) / cp,
            ci(1) / cp,
            best[1] * counts[1].0 as f64 / (1.5 * best_pair * counts[0].0 as f64),
            load_average()
        );
    }
    let z = paper_surface(512);
    let stack = Stack::paper_two_layer(5.0).expect("stack");
    let loads = curve_loads();
    for preconditioner in [true, false] {
        let opts = BemOptions {
            preconditioner,
            ..Default::default()
        };
        let mut best = f64::INFINITY;
        let mut iters = 0;
        let c0 = cpu_ns();
        for _ in 0..3 {
            let t = once(|| {
                let solver = BemSolver::new(&z, 1e-3, &stack, opts).expect("solver");
                let out = solver.solve_curve(&loads).expect("curve");
                iters = out.iter().map(|s| s.iterations).sum();
            });
            best = best.min(t);
        }
        let cpu = (cpu_ns() - c0) as f64 * 1e-9 / 3.0;
        println!(
            "bem_curve ({}): 20-step 512² curve, E2/E1 = 5, approaches 1.3…9.8 µm, tolerance \
             1e-10: {best:.3} s wall (best of 3, solver set-up included), {cpu:.3} s CPU (mean, \
             all threads), {iters} iterations, load average {}",
            if preconditioner {
                "preconditioned"
            } else {
                "plain"
            },
            load_average()
        );
    }
}

/// Whether the command line's filter (if any) selects `name`.
fn fft_and_iteration(c: &mut Criterion) {
    let mut g = c.benchmark_group("bem_fft_pair");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_secs(3));
    for n in [256usize, 512, 1024, 2048] {
        let plan = RealFft2::new(n, n).expect("plan");
        let mut w = plan.work();
        let input: Vec<f64> = (0..n * n).map(|i| (i as f64 * 0.37).sin()).collect();
        let kernel = vec![1.0; plan.spectrum_len()];
        let mut out = vec![0.0; n * n];
        g.throughput(Throughput::Elements((n * n) as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                plan.convolve(&input, &mut out, &kernel, 0.0, &mut w)
                    .expect("convolve")
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("bem_iteration");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_secs(3));
    for n in [256usize, 512] {
        let z = paper_surface(n);
        let stack = Stack::paper_two_layer(1.0).expect("stack");
        let solver = BemSolver::new(&z, 1e-3, &stack, BemOptions::default()).expect("solver");
        let prev = solver.solve(BemLoad::Approach(4.75e-6)).expect("solve");
        let init: Vec<f64> = prev.pressure.iter().copied().collect();
        g.throughput(Throughput::Elements((n * n) as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let t = Instant::now();
                    let s = black_box(
                        solver
                            .solve_from(BemLoad::Approach(5e-6), Some(&init))
                            .expect("solve"),
                    );
                    total += t.elapsed() / s.iterations.max(1) as u32;
                }
                total
            })
        });
    }
    g.finish();
}

fn steps(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/reference");
    let z =
        read_heights_npy(&dir.join("surface_km10.npy")).expect("tests/reference/surface_km10.npy");
    let layered =
        Stack::from_toml_file(&dir.join("stack_h100um_E2E1_1.toml")).expect("reference stack");
    let half = Stack::half_space(4e9, 0.15).expect("stack");
    let mut g = c.benchmark_group("bem_512");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_secs(5));
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
    let mut g = c.benchmark_group("bem_curve_512");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_secs(10));
    let z = paper_surface(512);
    let stack = Stack::paper_two_layer(5.0).expect("stack");
    let loads = curve_loads();
    g.bench_function("E2E1_5_20_steps", |b| {
        b.iter(|| {
            let solver = BemSolver::new(&z, 1e-3, &stack, BemOptions::default()).expect("solver");
            black_box(solver.solve_curve(&loads).expect("curve"))
        })
    });
    g.finish();
}

/// Writes an n×n f64 .npy (format 1.0, little-endian, C order).
fn write_npy(path: &Path, z: &Array2<f64>) {
    let (r, c) = z.dim();
    Surface::new(z.iter().copied().collect(), r, c, 1e-3, true)
        .and_then(|s| s.write_npy(path))
        .expect("write surface");
}

fn vs_tamaas(_c: &mut Criterion) {
    let Some(dir) = std::env::var_os("STRATA_TAMAAS_DIR").map(PathBuf::from) else {
        return;
    };
    std::fs::create_dir_all(&dir).expect("dir");
    let half = Stack::half_space(4e9, 0.15).expect("stack");
    let es = half.top_plane_strain_modulus();
    let tol = 1e-8;
    let mut csv = std::fs::File::create(dir.join("strata_speed.csv")).expect("csv");
    writeln!(csv, "# strata BemSolver, half-space E=4e9 nu=0.15, tolerance {tol:e}, one cold load step, median of runs, {} threads", rayon::current_num_threads()).expect("csv");
    writeln!(
        csv,
        "n,control,load,seconds,iterations,pressure_ratio,area_fraction"
    )
    .expect("csv");
    // STRATA_SPEED_GRIDS (e.g. "512") limits the grids; default 512 and 2048.
    let grids: Vec<usize> = std::env::var("STRATA_SPEED_GRIDS")
        .ok()
        .map(|v| v.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![512, 2048]);
    for n in grids {
        let z = paper_surface(n);
        write_npy(&dir.join(format!("surface_{n}.npy")), &z);
        let opts = BemOptions {
            tolerance: tol,
            ..Default::default()
        };
        let solver = BemSolver::new(&z, 1e-3, &half, opts).expect("solver");
        for (control, load) in [
            ("pressure", BemLoad::MeanPressure(0.005 * es)),
            ("gap", BemLoad::MeanGap(0.5 * solver.max_separation())),
        ] {
            let mut last = None;
            let reps = if n >= 2048 { 3 } else { 7 };
            let t = median(reps, || last = Some(solver.solve(load).expect("solve")));
            let s = last.expect("solved");
            let value = match load {
                BemLoad::MeanPressure(p) => p,
                BemLoad::MeanGap(g) => g,
                _ => f64::NAN,
            };
            println!(
                "strata n={n} {control} {value:e}: {t:.4} s, {} iterations, p/E* {:.8e}, A/A0 {:.5e}",
                s.iterations, s.pressure_ratio, s.area_fraction
            );
            writeln!(
                csv,
                "{n},{control},{value:e},{t},{},{},{}",
                s.iterations, s.pressure_ratio, s.area_fraction
            )
            .expect("csv");
        }
    }
}

/// `bem_plastic_512` (printed, one run): one 512² load step on the shared surface
/// (`tests/reference/surface_km10.npy`) on the half-space (E = 4 GPa, ν = 0.15) at
/// mean gap 0.5·(z_M − z̄), elastic (the default preconditioned iteration) and capped at
/// H = 0.2 and 0.05 GPa (a fresh `PlasticPath`: active-set steps on the elastic
/// iteration, then the bounded MPRGP check), timed alternately (best of 5 each), with
/// the plastic fraction, the operator products and the ratio plastic/elastic.
fn plastic_table(_: &mut Criterion) {
    if !filter_matches("plastic") {
        return;
    }
    let dir_ref = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/reference");
    let z = read_heights_npy(&dir_ref.join("surface_km10.npy"))
        .expect("tests/reference/surface_km10.npy");
    let half = Stack::half_space(4e9, 0.15).expect("stack");
    let solver = BemSolver::new(&z, 1e-3, &half, BemOptions::default()).expect("solver");
    let load = BemLoad::MeanGap(0.5 * solver.max_separation());
    let best = |f: &mut dyn FnMut() -> (f64, usize, f64)| {
        let mut t = f64::INFINITY;
        let mut out = (0.0, 0, 0.0);
        for _ in 0..5 {
            let t0 = Instant::now();
            out = f();
            t = t.min(t0.elapsed().as_secs_f64());
        }
        (t, out)
    };
    println!(
        "| H (GPa) | elastic (s) | plastic (s) | plastic / elastic | plastic area / contact area | products elastic / plastic |"
    );
    println!("|---|---|---|---|---|---|");
    // STRATA_CM_PLASTIC_DIR: also write the surface and the capped steps at the elastic
    // solution's approach (offset control, as ContactMechanics' plastic system takes
    // it) for `tests/python/run.sh --speed`, which times ContactMechanics beside.
    let cm_dir = std::env::var_os("STRATA_CM_PLASTIC_DIR").map(PathBuf::from);
    let mut cm_rows = Vec::new();
    for h in [0.2e9, 0.05e9] {
        let (te, (_, pe, _)) = best(&mut || {
            let s = solver.solve(load).expect("elastic");
            (s.area_fraction, s.products, 0.0)
        });
        let (tp, (a, pp, frac)) = best(&mut || {
            let mut path = strata_bem::PlasticPath::new(&solver, h).expect("path");
            let (s, info) = path.step(load).expect("plastic");
            (s.area_fraction, s.products, info.plastic_area_fraction)
        });
        println!(
            "| {:.2} | {te:.3} | {tp:.3} | {:.1} | {:.1} % | {pe} / {pp} |",
            h / 1e9,
            tp / te,
            100.0 * frac / a.max(f64::MIN_POSITIVE)
        );
        if cm_dir.is_some() {
            let delta = solver.solve(load).expect("elastic").approach;
            let mut out = None;
            let (t, _) = best(&mut || {
                let mut path = strata_bem::PlasticPath::new(&solver, h).expect("path");
                out = Some(path.step(BemLoad::Approach(delta)).expect("plastic"));
                (0.0, 0, 0.0)
            });
            let (s, info) = out.expect("solved");
            cm_rows.push(format!(
                "{h:e},{delta:e},{t},{},{},{},{}",
                s.mean_pressure, s.area_fraction, info.plastic_area_fraction, s.products
            ));
        }
    }
    if let Some(dir) = cm_dir {
        std::fs::create_dir_all(&dir).expect("dir");
        std::fs::copy(dir_ref.join("surface_km10.npy"), dir.join("surface.npy")).expect("copy");
        let mut csv = std::fs::File::create(dir.join("strata_plastic_speed.csv")).expect("csv");
        writeln!(
            csv,
            "# strata PlasticPath, one capped step from the undeformed surface, half-space E=4e9 nu=0.15, tolerance 1e-10 (KKT on the gap / sigma_z), best of 5, {} threads\nhardness,approach,seconds,mean_pressure,area_fraction,plastic_area_fraction,products",
            rayon::current_num_threads()
        )
        .expect("csv");
        for r in cm_rows {
            writeln!(csv, "{r}").expect("csv");
        }
    }
}

criterion_group!(
    benches,
    floor_table,
    vs_tamaas,
    fft_and_iteration,
    steps,
    plastic_table
);
criterion_main!(benches);
