//! Conductance benches (issue 34). Run: `cargo bench -p strata-benches --bench conductance`.
//!
//! Printed, one run, on the paper's conducting scene against steel
//! (`scenes/paper-E2E1-5-conductance.toml`: 512², 20 approaches 1.3…9.8 µm):
//! * BEM: the whole 20-step curve with `[conductance]` and without, timed alternately
//!   (best of [`REPS`] each, wall and CPU time of the process), and their ratio;
//! * N and I models: the curve with `[conductance]` (best of [`REPS`]), the mechanics'
//!   time and the conductance's own time of the same runs (curve.json's `seconds` and
//!   `conductance.seconds`), and the share the conductance adds.
//!
//! Wall times include surface generation and table loading for every model (the
//! engine's `solve_scene`), the same with and without conductance.

use std::path::PathBuf;
use std::time::Instant;

use strata::engine::{EngineOptions, solve_scene};
use strata::scene::{ModelKind, Scene};

/// Repetitions of each timing (best of).
const REPS: usize = 3;

/// CPU time of this process so far (user + system, s), from /proc/self/stat.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = after.split_whitespace().collect();
    let tick = 100.0;
    let v = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    // fields 14 and 15 (utime, stime) are at 11 and 12 after the command name
    (v(11) + v(12)) / tick
}

/// (wall s, CPU s, mechanics s, conductance s) of one solve.
fn run(scene: &Scene, path: &std::path::Path) -> (f64, f64, f64, f64) {
    let opts = EngineOptions {
        quiet: true,
        ..Default::default()
    };
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let sol = solve_scene(scene, path, &opts).expect("the scene solves");
    let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
    let hc = sol.meta["conductance"]["seconds"].as_f64().unwrap_or(0.0);
    (wall, cpu, sol.seconds - hc, hc)
}

fn best(v: &[(f64, f64, f64, f64)]) -> (f64, f64, f64, f64) {
    let pick = |f: fn(&(f64, f64, f64, f64)) -> f64| v.iter().map(f).fold(f64::INFINITY, f64::min);
    (pick(|x| x.0), pick(|x| x.1), pick(|x| x.2), pick(|x| x.3))
}

fn main() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/paper-E2E1-5-conductance.toml");
    let with = Scene::from_file(&path).expect("the paper's conducting scene reads");
    let mut without = with.clone();
    without.conductance = None;
    println!(
        "conductance bench: {} (512², 20 steps), best of {REPS}",
        path.display()
    );
    for kind in [
        ModelKind::Bem,
        ModelKind::Independent,
        ModelKind::Interacting,
    ] {
        let (mut a, mut b) = (with.clone(), without.clone());
        a.model.kind = kind;
        b.model.kind = kind;
        // warm the table cache and the allocator
        run(&a, &path);
        let (mut tw, mut tn) = (Vec::new(), Vec::new());
        for _ in 0..REPS {
            tw.push(run(&a, &path));
            tn.push(run(&b, &path));
        }
        let (w, n) = (best(&tw), best(&tn));
        println!(
            "{kind:?}: with conductance wall {:.3} s (CPU {:.3} s), without {:.3} s (CPU {:.3} s): ratio wall {:.3}, CPU {:.3}; \
             in the runs with it: mechanics {:.3} s, conductance {:.3} s (+{:.1} %)",
            w.0,
            w.1,
            n.0,
            n.1,
            w.0 / n.0,
            w.1 / n.1,
            w.2,
            w.3,
            100.0 * w.3 / w.2
        );
    }
}
