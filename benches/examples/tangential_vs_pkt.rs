//! One partial-slip solve of strata's tangential BEM beside Tamaas' PolonskyKeerTan on the
//! same surface and load, timed side by side: the paper-like surface at n² (default 128)
//! scaled to a unit cell, a half-space E = 1, ν = 0.3 (coupled, S_zL = β), μ = 0.5, the
//! mean pressure 2e-3 E and the mean tangential traction 0.5 μ p̄ applied in one step
//! (force control), both solvers at tolerance 1e-8 on one thread.
//!
//! Run on a quiet machine: `cargo run --release -p strata-benches --features probes
//! --example tangential_vs_pkt [-- N [PYTHON]]` (PYTHON: a Python with `tamaas`, default
//! `$STRATA_PY_VENV/bin/python` or `python3`). Prints each solver's wall time, contact and
//! stick points, and the time ratio.
use std::process::Command;
use std::time::Instant;

use strata_bem::tangential::{Coupling, TractionKernel, solve_coupled};
use strata_benches::paper_surface;
use strata_runtime::Stack;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(128, |s| s.parse().expect("N"));
    let py = args.get(2).cloned().unwrap_or_else(|| {
        std::env::var("STRATA_PY_VENV")
            .map(|v| format!("{v}/bin/python"))
            .unwrap_or_else(|_| "python3".into())
    });
    let (e, nu, mu) = (1.0, 0.3, 0.5);
    let p_mean = 2e-3 * e;
    let q_mean = 0.5 * mu * p_mean;
    let z: Vec<f64> = paper_surface(n).iter().map(|h| h / 1e-3).collect();
    let stack = Stack::half_space(e, nu).expect("stack");
    let kernel =
        TractionKernel::periodic(&stack, (n, n), (1.0, 1.0), Coupling::Coupled).expect("kernel");
    let t = Instant::now();
    let sol = solve_coupled(&kernel, &z, p_mean, [q_mean, 0.0], mu, None, 1e-8, 100_000)
        .expect("strata solve");
    let ours = t.elapsed().as_secs_f64();
    println!(
        "strata: {ours:.3} s, contact {}, stick {} ({} alternations)",
        sol.slip.contact_points, sol.slip.stick_points, sol.outer_iterations
    );
    let dir = std::env::temp_dir().join("strata-tangential-vs-pkt");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let heights = dir.join("heights.txt");
    let text: String = (0..n)
        .map(|i| {
            let row: Vec<String> = (0..n).map(|j| format!("{:e}", z[i * n + j])).collect();
            row.join(" ") + "\n"
        })
        .collect();
    std::fs::write(&heights, text).expect("heights");
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/python/pkt_stick.py");
    let t = Instant::now();
    let out = Command::new(&py)
        .env("OMP_NUM_THREADS", "1")
        .arg(script)
        .arg(&heights)
        .args([e, nu, mu, p_mean, q_mean, 1e-8].map(|v| format!("{v:e}")))
        .output()
        .expect("python");
    let theirs = t.elapsed().as_secs_f64();
    if !out.status.success() {
        eprintln!(
            "pkt_stick.py failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::process::exit(1);
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!(
        "Tamaas PolonskyKeerTan: {theirs:.3} s (with Python start-up), contact and stick {}",
        stdout.lines().last().unwrap_or_default()
    );
    println!("n = {n}: PolonskyKeerTan / strata = {:.1}", theirs / ours);
}
