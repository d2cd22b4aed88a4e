//! Conductance benches. Run: `cargo bench -p strata-benches --bench conductance`
//! (`-- bem` for the BEM item alone, `-- spots` for the N and I models alone).
//!
//! Printed, one run, on the paper's conducting scene against steel
//! (`scenes/paper-E2E1-5-conductance.toml`: 512², 20 approaches 1.3…9.8 µm, k = 2…10,
//! 29 summits):
//! * BEM: the whole 20-step curve with `[conductance]` and without, timed alternately,
//!   and their ratio;
//! * N and I models: the curve with `[conductance]` and without, and, in the runs with
//!   it, the mechanics' time and the conductance's own time (curve.json's `seconds` and
//!   `conductance.seconds`) and the share the conductance adds;
//!
//! then the N and I models on the same scene with realistic summit counts: the surface's
//! spectrum to k_max = 50 and 100 (698 and 2406 summits), where the conductance's fixed
//! cost (the I model's kernel table) is shared by more spots.
//!
//! Each item runs on a fresh table cache: its first run (not in the means) solves the
//! layered stack's ψ table and keeps it there, as a user's first run per stack does; the
//! conductance time of that run is printed as `first run`. The timed runs read it.
//!
//! Each item: wall and process CPU time (user + system of all threads, /proc/self/stat),
//! the mean over runs repeated for at least [`MIN_SECONDS`] and [`MIN_RUNS`] runs (the
//! CPU clock ticks at 10 ms), with and without conductance alternating. Wall times
//! include surface generation and table loading (the engine's `solve`), the same
//! with and without conductance. On a shared machine the CPU times are the steadier.

use std::path::{Path, PathBuf};
use std::time::Instant;

use strata::engine::{EngineOptions, Quiet, solve};
use strata::scene::{ModelKind, Scene, SurfaceSource};
use strata_benches::cpu_seconds;

/// Runs of each item: at least this many (the BEM [`BEM_RUNS`]) …
const MIN_RUNS: usize = 3;
/// … of the BEM curve, whose mechanics alone varies by ~10 % between runs on a shared
/// machine.
const BEM_RUNS: usize = 8;
/// … and at least this much wall time (s) per item.
const MIN_SECONDS: f64 = 1.0;

/// Means of one item: wall s, CPU s, mechanics s, conductance s (engine's clocks).
#[derive(Debug, Clone, Copy, Default)]
struct Times {
    wall: f64,
    cpu: f64,
    mechanics: f64,
    conductance: f64,
    runs: usize,
}

/// One solve with the table cache `cache`: (wall, CPU, mechanics, conductance, summits)
/// in s.
fn run(scene: &Scene, cache: &Path) -> (Times, usize) {
    let opts = EngineOptions {
        cache_dir: Some(cache.to_path_buf()),
        ..Default::default()
    };
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let sol = solve(scene, None, &opts, &mut Quiet).expect("the scene solves");
    let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
    let hc = sol.summary.conductance.as_ref().map_or(0.0, |c| c.seconds);
    let summits = sol.summary.summits.unwrap_or(0);
    (
        Times {
            wall,
            cpu,
            mechanics: sol.seconds - hc,
            conductance: hc,
            runs: 1,
        },
        summits,
    )
}

fn add(a: &mut Times, b: Times) {
    a.wall += b.wall;
    a.cpu += b.cpu;
    a.mechanics += b.mechanics;
    a.conductance += b.conductance;
    a.runs += 1;
}

fn mean(t: Times) -> Times {
    let n = t.runs.max(1) as f64;
    Times {
        wall: t.wall / n,
        cpu: t.cpu / n,
        mechanics: t.mechanics / n,
        conductance: t.conductance / n,
        runs: t.runs,
    }
}

/// The scene with and without conductance, alternating: (with, without, summits, the
/// first run's conductance seconds).
fn measure(with: &Scene, without: &Scene, min_runs: usize) -> (Times, Times, usize, f64) {
    // a fresh table cache (the mechanics table comes from the shared one: copied in)
    let cache =
        std::env::temp_dir().join(format!("strata-bench-conductance-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&cache);
    let (shared, _) = strata::cache::dir(None);
    std::fs::create_dir_all(&cache).expect("a temporary table cache");
    for e in std::fs::read_dir(&shared).into_iter().flatten().flatten() {
        if e.file_name().to_string_lossy().starts_with("stack-") {
            let _ = std::fs::copy(e.path(), cache.join(e.file_name()));
        }
    }
    // warm the allocator and the mechanics table; solve the ψ table into the cache
    let _ = run(without, &cache);
    let (first, summits) = run(with, &cache);
    let (mut w, mut n) = (Times::default(), Times::default());
    let t0 = Instant::now();
    while w.runs < min_runs || t0.elapsed().as_secs_f64() < 2.0 * MIN_SECONDS {
        add(&mut w, run(with, &cache).0);
        add(&mut n, run(without, &cache).0);
    }
    let _ = std::fs::remove_dir_all(&cache);
    (mean(w), mean(n), summits, first.conductance)
}

fn print(label: &str, (w, n, first): (Times, Times, f64)) {
    println!(
        "{label}: with conductance wall {:.4} s (CPU {:.4} s), without {:.4} s (CPU {:.4} s): \
         ratio wall {:.3}, CPU {:.3}; in the runs with it: mechanics {:.4} s, conductance {:.4} s \
         (+{:.1} %); {} runs each; first run (ψ table solved into the cache): conductance {:.4} s",
        w.wall,
        w.cpu,
        n.wall,
        n.cpu,
        w.wall / n.wall,
        w.cpu / n.cpu,
        w.mechanics,
        w.conductance,
        100.0 * w.conductance / w.mechanics,
        w.runs,
        first
    );
}

fn main() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/paper-E2E1-5-conductance.toml");
    let with = Scene::from_file(&path).expect("the paper's conducting scene reads");
    let mut without = with.clone();
    without.conductance = None;
    println!(
        "conductance bench: {} (512², 20 steps); means over ≥ {MIN_RUNS} runs and ≥ {MIN_SECONDS} s each",
        path.display()
    );
    // `-- bem` or `-- spots`: only the BEM item, or only the N and I models
    let args: Vec<String> = std::env::args().skip(1).collect();
    let only = |w: &str| args.iter().any(|a| a == w);
    let (bem, spots) = match (only("bem"), only("spots")) {
        (false, false) => (true, true),
        other => other,
    };
    let kinds = [
        ModelKind::Bem,
        ModelKind::Independent,
        ModelKind::Interacting,
    ];
    for kind in kinds
        .into_iter()
        .filter(|k| if *k == ModelKind::Bem { bem } else { spots })
    {
        let (mut a, mut b) = (with.clone(), without.clone());
        a.model.kind = kind;
        b.model.kind = kind;
        let runs = if kind == ModelKind::Bem {
            BEM_RUNS
        } else {
            MIN_RUNS
        };
        let (w, n, summits, first) = measure(&a, &b, runs);
        print(
            &format!("k_max = 10 ({summits} summits), {kind:?}"),
            (w, n, first),
        );
    }
    for k_max in [50.0, 100.0].into_iter().filter(|_| spots) {
        for kind in [ModelKind::Independent, ModelKind::Interacting] {
            let (mut a, mut b) = (with.clone(), without.clone());
            for s in [&mut a, &mut b] {
                s.model.kind = kind;
                if let SurfaceSource::Generate(g) = &mut s.surface.source {
                    g.k_max = k_max;
                }
            }
            let (w, n, summits, first) = measure(&a, &b, MIN_RUNS);
            print(
                &format!("k_max = {k_max} ({summits} summits), {kind:?}"),
                (w, n, first),
            );
        }
    }
}
