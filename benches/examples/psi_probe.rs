//! Where the N model's conductance time goes: the mechanics and the ψ table
//! of the N model on the paper's conducting scene (29 summits, 20 steps), CPU time of
//! this process (best of 5).
//! Run: `cargo run --release -p strata-benches --features probes --example psi_probe`.
use std::path::PathBuf;
use std::time::Instant;

use strata::engine::{EngineOptions, Quiet, solve};
use strata::scene::{ModelKind, Scene};
use strata::spots::SpotSum;
use strata_benches::cpu_seconds;

fn main() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/paper-E2E1-5-conductance.toml");
    let mut scene = Scene::from_file(&path).expect("scene");
    let spec = scene.conductance.expect("[conductance]");
    scene.conductance = None;
    scene.model.kind = ModelKind::Independent;
    let opts = EngineOptions {
        ..Default::default()
    };
    let sol = solve(&scene, None, &opts, &mut Quiet).expect("solve");
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
    for k_max in [50.0, 100.0] {
        interacting_split(k_max);
    }
}

/// The I model's conductance split on the paper scene with k_max = `k_max`: ψ table,
/// kernel table, and the per-step spot networks (fill and dense LU), wall time.
pub fn interacting_split(k_max: f64) {
    use strata::scene::SurfaceSource;
    use strata_runtime::conduction::ConductionCompliance;
    use strata_runtime::rough::conductance::{Body, Interactions, Kernel};
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/paper-E2E1-5-conductance.toml");
    let mut scene = Scene::from_file(&path).expect("scene");
    let spec = scene.conductance.expect("[conductance]");
    scene.conductance = None;
    scene.model.kind = ModelKind::Interacting;
    if let SurfaceSource::Generate(g) = &mut scene.surface.source {
        g.k_max = k_max;
    }
    let opts = EngineOptions {
        ..Default::default()
    };
    let sol = solve(&scene, None, &opts, &mut Quiet).expect("solve");
    let surface =
        strata::engine::load_surface(&scene, &strata_runtime::resources::MemoryLimit::default())
            .expect("surface");
    let law = strata_runtime::law::Homogeneous { e_star: 1.0 };
    let rc = strata_runtime::rough::RoughContact::from_surface(&law, &surface).expect("rc");
    let t = Instant::now();
    let sum = SpotSum::new(&scene, &spec).expect("spots");
    let g = sum.spot_conductances(&sol.steps).expect("psi");
    let t_psi = t.elapsed().as_secs_f64();
    let comp = ConductionCompliance::new(&scene.bodies.first, spec.kind).expect("comp");
    let t = Instant::now();
    let kernel = Kernel::periodic(
        Body::Layered(&comp),
        Body::HalfSpace(45.0),
        rc.extent(),
        &strata_runtime::resources::MemoryLimit::default(),
    )
    .expect("kernel");
    let t_kernel = t.elapsed().as_secs_f64();
    // the engine's way: the interactions of every summit that touches, filled once
    let t = Instant::now();
    let touching: Vec<usize> = (0..rc.summits().len())
        .filter(|&k| g.iter().any(|gs| gs[k] > 0.0))
        .collect();
    let points: Vec<(f64, f64)> = touching
        .iter()
        .map(|&k| (rc.summits()[k].x, rc.summits()[k].y))
        .collect();
    let net = Interactions::new(
        &kernel,
        &points,
        &strata_runtime::resources::MemoryLimit::default(),
    )
    .expect("interactions");
    let t_fill = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut most = 0;
    for gs in &g {
        let spots: Vec<(usize, f64)> = touching
            .iter()
            .enumerate()
            .filter(|(_, k)| gs[**k] > 0.0)
            .map(|(r, &k)| (r, gs[k]))
            .collect();
        most = most.max(spots.len());
        std::hint::black_box(net.network(&spots, rc.area()).expect("network"));
    }
    let t_net = t.elapsed().as_secs_f64();
    println!(
        "I model k_max = {k_max} ({} summits, ≤ {most} spots): mechanics {:.3} s, ψ table {:.4} s, kernel table {:.4} s, interactions of {} summits {:.4} s, {} networks {:.3} s",
        rc.summits().len(),
        sol.seconds,
        t_psi,
        t_kernel,
        touching.len(),
        t_fill,
        g.len(),
        t_net
    );
}
