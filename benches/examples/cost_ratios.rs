//! Two cost ratios of `docs/performance.md`, counted and timed:
//!
//! * **spots**: the N model's conductance against its mechanical curve, on every shipped
//!   scene with `[conductance]` (run with `model.kind = "independent"`) at its own
//!   spectrum and at k_max = 50 and 100 (more summits): the whole curve through the
//!   engine with `[conductance]` and without, alternating, means over the runs; in the
//!   runs with it the engine's own clocks of the mechanics and of the conductance. Each
//!   scene starts from a fresh table cache (its mechanics tables copied in from the
//!   shared one): the first run solves the stack's ψ table into it (`psi-<hex>.strata`,
//!   the run's ψ Fredholm node solves counted), the timed runs read it (0 solves).
//! * **bem**: a force-controlled capped BEM step against the elastic step at the same
//!   mean pressure, on the half-space (E = 4 GPa, ν = 0.15) and the shared 512² surface
//!   (`tests/reference/surface_km10.npy`; `--grid N` another size, the benches' paper-like
//!   surface), H = 0.2 and 0.05 GPa, the mean pressure that of the capped solution at
//!   mean gap 0.5·(z_M − z̄) (the rows of `bem_plastic_512`): a fresh path's step (the
//!   elastic solve, then the capped iteration with the load held in it) and a step at
//!   1.25× that load on the flattened surface, each against the elastic step at its
//!   load. Counted: the operator products (K and the preconditioner) of each; timed:
//!   best of the runs.
//!
//! ```text
//! cargo run --release -p strata-benches --features probes --example cost_ratios -- [spots|bem] [--runs R] [--grid N]
//! ```
//!
//! Defaults: both parts, R = 5, the 512² surface. The products do not depend on the
//! machine; the times do: run it on a quiet machine.
use std::path::{Path, PathBuf};
use std::time::Instant;

use strata::engine::{EngineOptions, Quiet, solve};
use strata::scene::{ModelKind, Scene, SurfaceSource};
use strata_bem::{BemLoad, BemOptions, BemSolver, PlasticPath, read_heights_npy};
use strata_benches::{cpu_seconds, paper_surface};
use strata_runtime::Stack;

/// Wall and CPU seconds, and the engine's clocks of the mechanics and the conductance.
#[derive(Debug, Clone, Copy, Default)]
struct Times {
    wall: f64,
    cpu: f64,
    mechanics: f64,
    conductance: f64,
    runs: usize,
}

impl Times {
    fn add(&mut self, b: Times) {
        self.wall += b.wall;
        self.cpu += b.cpu;
        self.mechanics += b.mechanics;
        self.conductance += b.conductance;
        self.runs += 1;
    }

    fn mean(self) -> Times {
        let n = self.runs.max(1) as f64;
        Times {
            wall: self.wall / n,
            cpu: self.cpu / n,
            mechanics: self.mechanics / n,
            conductance: self.conductance / n,
            runs: self.runs,
        }
    }
}

/// One solve of `scene` with the table cache `cache`: its times and summits.
fn run(scene: &Scene, cache: &Path) -> (Times, usize) {
    let opts = EngineOptions {
        cache_dir: Some(cache.to_path_buf()),
        ..Default::default()
    };
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let sol = solve(scene, None, &opts, &mut Quiet).expect("the scene solves");
    let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
    let hc = sol.summary.conductance.as_ref().map_or(0.0, |c| c.seconds);
    let times = Times {
        wall,
        cpu,
        mechanics: sol.seconds - hc,
        conductance: hc,
        runs: 1,
    };
    (times, sol.summary.summits.unwrap_or(0))
}

/// The ψ table files in `cache`: their node values (the Fredholm node solves of the
/// tables held).
fn psi_nodes(cache: &Path) -> usize {
    std::fs::read_dir(cache)
        .into_iter()
        .flatten()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with("psi-"))
        .filter_map(|e| std::fs::read(e.path()).ok())
        .filter_map(|b| strata_runtime::constriction::PsiTable::from_bytes(&b).ok())
        .map(|t| t.nodes().len())
        .sum()
}

/// The N model with and without conductance on one scene (see the module docs).
fn spots_item(label: &str, with: &Scene, runs: usize) {
    let mut without = with.clone();
    without.conductance = None;
    let cache = std::env::temp_dir().join(format!("strata-cost-ratios-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&cache);
    std::fs::create_dir_all(&cache).expect("a temporary table cache");
    let (shared, _) = strata::cache::dir(None);
    for e in std::fs::read_dir(&shared).into_iter().flatten().flatten() {
        if e.file_name().to_string_lossy().starts_with("stack-") {
            let _ = std::fs::copy(e.path(), cache.join(e.file_name()));
        }
    }
    let _ = run(&without, &cache);
    let before = psi_nodes(&cache);
    let (first, summits) = run(with, &cache);
    let solved = psi_nodes(&cache) - before;
    let (mut w, mut n) = (Times::default(), Times::default());
    let held = psi_nodes(&cache);
    for _ in 0..runs {
        w.add(run(with, &cache).0);
        n.add(run(&without, &cache).0);
    }
    assert_eq!(psi_nodes(&cache), held, "a timed run solved ψ nodes");
    let _ = std::fs::remove_dir_all(&cache);
    let (w, n) = (w.mean(), n.mean());
    println!(
        "| {label} | {summits} | {solved} / 0 | {:.4} / {:.4} | {:.4} / {:.4} | {:.3} / {:.3} | {:.4}, {:.5} (+{:.1} %) | {:.4} |",
        w.wall,
        w.cpu,
        n.wall,
        n.cpu,
        w.wall / n.wall,
        w.cpu / n.cpu,
        w.mechanics,
        w.conductance,
        100.0 * w.conductance / w.mechanics,
        first.conductance
    );
}

fn spots(runs: usize) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("scenes/")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    println!(
        "\nN model with and without [conductance] ({runs} runs each, alternating; ψ node solves: the first run / each timed run):\n"
    );
    println!(
        "| scene (N model) | summits | ψ node solves | with (wall / CPU s) | without (wall / CPU s) | ratio wall / CPU | mechanics, conductance (engine s) | first run's conductance (s) |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for f in files {
        let Ok(scene) = Scene::from_file(&f) else {
            continue;
        };
        if scene.conductance.is_none() {
            continue;
        }
        let name = f
            .file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into());
        let mut base = scene.clone();
        base.model.kind = ModelKind::Independent;
        spots_item(&name, &base, runs);
        for k_max in [50.0, 100.0] {
            let mut s = base.clone();
            if let SurfaceSource::Generate(g) = &mut s.surface.source {
                g.k_max = k_max;
                spots_item(&format!("{name}, k_max = {k_max}"), &s, runs);
            }
        }
    }
}

/// Best of `runs` timings of `f` (s) and its last result.
fn best<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut t = f64::INFINITY;
    let mut out = None;
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        out = Some(f());
        t = t.min(t0.elapsed().as_secs_f64());
    }
    (t, out.expect("one run"))
}

fn bem(runs: usize, grid: Option<usize>) {
    let z = match grid {
        None => {
            let p =
                Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/reference/surface_km10.npy");
            read_heights_npy(&p).expect("tests/reference/surface_km10.npy")
        }
        Some(n) => paper_surface(n),
    };
    let n = z.nrows();
    let half = Stack::half_space(4e9, 0.15).expect("stack");
    let solver = BemSolver::new(&z, 1e-3, &half, BemOptions::default()).expect("solver");
    let gap = BemLoad::MeanGap(0.5 * solver.max_separation());
    println!(
        "\nForce-controlled capped BEM step against the elastic step at the same mean pressure ({n}², half-space, best of {runs}):\n"
    );
    println!(
        "| H (GPa) | step | p̄ (MPa) | plastic / contact | products elastic / capped | ratio (products) | elastic (s) | capped (s) | ratio (time) |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for h in [0.2e9, 0.05e9] {
        // the load: the capped solution's mean pressure at the mean gap
        let target = PlasticPath::new(&solver, h)
            .expect("path")
            .step(gap)
            .expect("capped at the mean gap")
            .0
            .mean_pressure;
        let fresh = PlasticPath::new(&solver, h).expect("path");
        let mut flattened = fresh.clone();
        flattened
            .step(BemLoad::MeanPressure(target))
            .expect("capped");
        for (what, path, load) in [
            ("fresh path", &fresh, target),
            ("flattened, 1.25×", &flattened, 1.25 * target),
        ] {
            let l = BemLoad::MeanPressure(load);
            let (te, e) = best(runs, || solver.solve(l).expect("elastic"));
            let (tc, (c, info)) = best(runs, || path.clone().step(l).expect("capped"));
            println!(
                "| {:.2} | {what} | {:.3} | {:.1} % | {} / {} | {:.2} | {te:.4} | {tc:.4} | {:.2} |",
                h / 1e9,
                load / 1e6,
                100.0 * info.plastic_points as f64 / c.contact_points.max(1) as f64,
                e.products,
                c.products,
                c.products as f64 / e.products as f64,
                tc / te
            );
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .map(|v| {
                v.parse::<usize>().unwrap_or_else(|_| {
                    eprintln!("{flag}: not a count: {v}");
                    std::process::exit(2)
                })
            })
    };
    let runs = value("--runs").unwrap_or(5);
    let grid = value("--grid");
    let only = |w: &str| args.iter().any(|a| a == w);
    let (s, b) = match (only("spots"), only("bem")) {
        (false, false) => (true, true),
        other => other,
    };
    if s {
        spots(runs);
    }
    if b {
        bem(runs, grid);
    }
}
