//! Peak memory per grid point of one pressure-controlled BEM step with its stiffness
//! (the engine's step: the solve at p̄ = 0.005 E* from a cold start, then the tangent
//! dP/dδ on its contact set), each grid size in a
//! child process whose peak resident set (`getrusage`'s `ru_maxrss`, read by `wait4`:
//! what `/usr/bin/time -f %M` prints) is divided by the number of grid points.
//!
//! ```text
//! cargo run --release -p strata-benches --features probes --example bem_memory -- [N ...] [--peers PYTHON]
//! ```
//!
//! Defaults: N = 1024 2048 4096 8192. The surface is the benches' paper-like one (L = 1 mm,
//! D_f = 2.4, σ = 3.4 µm), written once per size as a periodic `.npy` that every solver
//! reads; the solid a homogeneous half-space (E = 4 GPa, ν = 0.15), tolerance 1e-8.
//! `--peers PYTHON` runs the same steps in Tamaas and ContactMechanics with that Python
//! (`benches/peers_memory.py`; e.g. the cross-check venv `target/python-venv/bin/python`
//! of `tests/python/run.sh`), measured the same way. Memory is not timing: the figures
//! do not depend on the machine's load.
use std::path::{Path, PathBuf};
use std::process::Command;

use strata::engine::{EngineOptions, Quiet, solve};
use strata::scene::Scene;
use strata_benches::{paper_surface_params, peak_of};
use strata_runtime::surface::Surface;

/// Mean pressure of the step as a fraction of E* (the Tamaas comparison's load).
const PRESSURE_OVER_E_STAR: f64 = 0.005;
const YOUNG: f64 = 4e9;
const POISSON: f64 = 0.15;

/// The surface file of grid `n`, written by a child of its own when missing (this
/// process stays small: a child started by `posix_spawn` shares its parent's memory
/// until `exec`, and Linux counts that in the child's `ru_maxrss`).
fn surface_file(exe: &Path, dir: &Path, n: usize) -> PathBuf {
    let path = dir.join(format!("surface_{n}.npy"));
    if !path.is_file() {
        let mut c = Command::new(exe);
        c.arg("--write-surface").arg(n.to_string()).arg(&path);
        let (_, ok) = peak_of(&mut c);
        if !ok {
            eprintln!("could not write the {n}² surface");
            std::process::exit(2)
        }
    }
    path
}

/// The child: the engine's BEM step on `surface` (one mean pressure, stiffness included).
fn child(n: usize, surface: &Path) {
    let e_star = YOUNG / (1.0 - POISSON * POISSON);
    let scene = format!(
        "[stack]\n[[stack.layer]]\nthickness = 1e-3\nyoung = {YOUNG:e}\npoisson = {POISSON}\n\
         [stack.base]\nkind = \"elastic\"\nyoung = {YOUNG:e}\npoisson = {POISSON}\n\
         [surface]\nfile = {file:?}\nsize = 1e-3\nperiodic = true\ndetrend = \"none\"\n\
         [model]\nkind = \"bem\"\n[load]\nmean_pressures = [{p:e}]\n[solver]\nbem_tolerance = 1e-8\n",
        file = surface.display().to_string(),
        p = PRESSURE_OVER_E_STAR * e_star,
    );
    let dir = surface.parent().unwrap_or(Path::new("."));
    let scene = Scene::from_str_in(&scene, dir).expect("scene");
    // The step's maps are formed as for `strata solve` and dropped by the observer.
    let sol = solve(&scene, None, &EngineOptions::default(), &mut Quiet).expect("solve");
    let st = &sol.steps[0];
    println!(
        "n {n}: p/E* {:.6e}, A/A0 {:.5}, stiffness {:.6e} N/m, iterations {}",
        st.pressure_ratio, st.area_fraction, st.stiffness, st.iterations
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--child") {
        let n: usize = args[1].parse().expect("grid");
        return child(n, Path::new(&args[2]));
    }
    if args.first().map(String::as_str) == Some("--write-surface") {
        let n: usize = args[1].parse().expect("grid");
        let s = Surface::generate(&paper_surface_params(n)).expect("surface");
        s.write_npy(Path::new(&args[2])).expect("write the surface");
        return;
    }
    let mut sizes = Vec::new();
    let mut python = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--peers" {
            python = it.next().cloned();
        } else {
            sizes.push(a.parse::<usize>().unwrap_or_else(|_| {
                eprintln!("not a grid size: {a:?}");
                std::process::exit(2)
            }));
        }
    }
    if sizes.is_empty() {
        sizes = vec![1024, 2048, 4096, 8192];
    }
    let dir = std::env::temp_dir().join("strata-bem-memory");
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let exe = std::env::current_exe().expect("this program");
    let peers = Path::new(env!("CARGO_MANIFEST_DIR")).join("peers_memory.py");
    println!("| n | solver | peak RSS (MB) | bytes per point |");
    println!("|---|---|---|---|");
    for &n in &sizes {
        let surf = surface_file(&exe, &dir, n);
        let points = (n * n) as f64;
        let mut runs: Vec<(&str, Command)> = Vec::new();
        let mut c = Command::new(&exe);
        c.arg("--child").arg(n.to_string()).arg(&surf);
        runs.push(("strata", c));
        if let Some(py) = &python {
            for peer in ["tamaas", "contactmechanics"] {
                let mut c = Command::new(py);
                c.arg(&peers).arg(peer).arg(&surf);
                runs.push((peer, c));
            }
        }
        for (name, mut cmd) in runs {
            let (peak, ok) = peak_of(&mut cmd);
            let note = if ok { "" } else { " (failed)" };
            println!(
                "| {n}² | {name}{note} | {:.0} | {:.1} |",
                peak as f64 / 1e6,
                peak as f64 / points
            );
        }
    }
}
