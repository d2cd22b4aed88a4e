//! Per-step diagnostics of the 20-step 512² BEM load curve (the `bem_floor` bench's
//! curve: paper-like surface, E2/E1 = 5, approaches 1.3…9.8 µm): iterations, operator
//! products and wall time of each step.
//!
//! Run: `cargo run --release -p strata-benches --features probes --example bem_probe [-- N TOL]`;
//! `-- pressure N` instead times the Tamaas comparison's cold steps (half-space
//! E = 4 GPa, ν = 0.15, tolerance 1e-8, the same generated surface): mean pressure
//! 0.005 E* and mean gap 0.5 (z_M − z̄). `STRATA_PLAIN=1` runs the curve with the plain
//! iteration.
use std::time::Instant;
use strata_bem::{BemLoad, BemOptions, BemSolver};
use strata_benches::{curve_approaches, paper_surface};
use strata_runtime::Stack;

fn cold_steps(n: usize) {
    let z = paper_surface(n);
    let half = Stack::half_space(4e9, 0.15).expect("stack");
    let es = half.top_plane_strain_modulus();
    let opts = BemOptions {
        tolerance: 1e-8,
        ..Default::default()
    };
    let solver = BemSolver::new(&z, 1e-3, &half, opts).expect("solver");
    for load in [
        BemLoad::MeanPressure(0.005 * es),
        BemLoad::MeanGap(0.5 * solver.max_separation()),
    ] {
        let t = Instant::now();
        let s = solver.solve(load).expect("solve");
        println!(
            "{load:?}: {:.3} s, {} iterations, {} products, p/E* {:.8e}, A/A0 {:.5e}",
            t.elapsed().as_secs_f64(),
            s.iterations,
            s.products,
            s.pressure_ratio,
            s.area_fraction
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("pressure") {
        let n = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(512);
        return cold_steps(n);
    }
    let n: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(512);
    let tol: f64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(1e-10);
    let z = paper_surface(n);
    let stack = Stack::paper_two_layer(5.0).expect("stack");
    let t0 = Instant::now();
    let opts = BemOptions {
        tolerance: tol,
        // STRATA_PLAIN=1: the plain iteration (no preconditioner).
        preconditioner: std::env::var_os("STRATA_PLAIN").is_none(),
        ..Default::default()
    };
    let solver = BemSolver::new(&z, 1e-3, &stack, opts).expect("solver");
    println!("set-up {:.3} s", t0.elapsed().as_secs_f64());
    let loads: Vec<BemLoad> = curve_approaches()
        .into_iter()
        .map(BemLoad::Approach)
        .collect();
    let t1 = Instant::now();
    let out = solver.solve_curve(&loads).expect("curve");
    let total = t1.elapsed().as_secs_f64();
    let (mut it, mut pr) = (0, 0);
    for (k, s) in out.iter().enumerate() {
        println!(
            "step {k:2}: p/E* {:.6e} A/A0 {:.5} iterations {:4} products {:4} error {:.2e}",
            s.pressure_ratio, s.area_fraction, s.iterations, s.products, s.error
        );
        it += s.iterations;
        pr += s.products;
    }
    println!(
        "curve {total:.3} s ({:.3} s with set-up), {it} iterations, {pr} products ({:.2} per iteration), {:.3} ms per product",
        t0.elapsed().as_secs_f64(),
        pr as f64 / it as f64,
        total / pr as f64 * 1e3
    );
}
