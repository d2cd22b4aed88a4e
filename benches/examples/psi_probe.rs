//! Where the N model's conductance time goes (issue 34): the mechanics and the ψ table
//! of the N model on the paper's conducting scene (29 summits, 20 steps), CPU time of
//! this process (best of 5).
//! Run: `cargo run --release -p strata-benches --features probes --example psi_probe`.
use std::path::PathBuf;
use std::time::Instant;

use strata::engine::{EngineOptions, solve_scene};
use strata::scene::{ModelKind, Scene};
use strata::spots::SpotSum;
use strata_benches::cpu_seconds;

fn main() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/paper-E2E1-5-conductance.toml");
    let mut scene = Scene::from_file(&path).expect("scene");
    let spec = scene.conductance.clone().expect("[conductance]");
    scene.conductance = None;
    scene.model.kind = ModelKind::Independent;
    let opts = EngineOptions {
        quiet: true,
        ..Default::default()
    };
    let sol = solve_scene(&scene, &path, &opts).expect("solve");
    let radii: Vec<f64> = sol
        .steps
        .iter()
        .flat_map(|s| s.radii.iter().copied())
        .filter(|&a| a > 0.0)
        .collect();
    let lo = radii.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = radii.iter().copied().fold(0.0, f64::max);
    println!(
        "{} radii in contact over {} steps, {lo:e} … {hi:e} m ({:.2} decades); mechanics {:.2} ms wall",
        radii.len(),
        sol.steps.len(),
        (hi / lo).log10(),
        1e3 * sol.seconds
    );
    // repeated for ≥ 1 s of wall time: the CPU clock ticks at 10 ms
    let (t, c) = (Instant::now(), cpu_seconds());
    let mut runs = 0;
    while runs < 5 || t.elapsed().as_secs_f64() < 1.0 {
        let sum = SpotSum::new(&scene, &spec).expect("spots");
        let h = sum.conductances(&sol.steps, 1e-6).expect("h");
        std::hint::black_box(h);
        runs += 1;
    }
    let wall = t.elapsed().as_secs_f64() / runs as f64;
    let cpu = (cpu_seconds() - c) / runs as f64;
    println!(
        "N model's conductance (ψ table and the sum): {:.2} ms wall, {:.1} ms CPU",
        1e3 * wall,
        1e3 * cpu
    );
}
