//! One I-model load curve at scale with the solver's per-step diagnostics:
//! Newton steps, evaluations of the interaction sums, activation rounds, time, and
//! the far field in use (cut-off r_c, near radius, grid cells, measured error).
//!
//! ```text
//! cargo run --release -p strata-benches --features probes --example scale_probe -- [grid] [k_M] [steps] [far-field tolerance]
//! ```
//!
//! Defaults: grid 1024, k_M = 200 (≈ 1e4 summits, L = 1 mm, D_f = 2.4, the paper's
//! generator), 20 steps to 0.87 (z_M − z̄), 5×5 periodic images, the shipped table for
//! the paper's stack with E2/E1 = 5, the default far-field tolerance.
use std::time::Instant;
use strata_runtime::rough::{Images, Model, Params, RoughContact};
use strata_runtime::surface::{GenerateParams, Surface};

fn arg<T: std::str::FromStr>(i: usize, default: T) -> T {
    match std::env::args().nth(i) {
        None => default,
        Some(s) => s.parse().unwrap_or_else(|_| {
            eprintln!("argument {i}: cannot parse {s:?}");
            std::process::exit(2)
        }),
    }
}

fn main() {
    let grid: usize = arg(1, 1024);
    let km: f64 = arg(2, 200.0);
    let steps: usize = arg(3, 20);
    let mut prm = Params::default();
    prm.far_field_tolerance = arg(4, prm.far_field_tolerance);
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables/paper-two-layer.strata");
    let table = strata_runtime::table::Table::load(&path).expect("shipped table");
    let stack = strata_runtime::Stack::paper_two_layer(5.0).expect("stack");
    let law = table.law_for(&stack).expect("law");
    let s = Surface::generate(&GenerateParams::paper(grid, km)).expect("surface");
    let t0 = Instant::now();
    let rc = RoughContact::from_surface(&law, &s)
        .expect("summits")
        .with_params(prm);
    let top = rc.top_to_mean();
    let d: Vec<f64> = (1..=steps)
        .map(|i| 0.87 * top * i as f64 / steps as f64)
        .collect();
    println!(
        "{} summits, far-field tolerance {:e}",
        rc.summits().len(),
        rc.params().far_field_tolerance
    );
    let c = rc
        .curve(Model::Interacting(Images::Periodic(2)), &d)
        .expect("solve");
    println!("g_n/(z_M-z̄)  p/E*1  contacts  stiffness (N/m)  newton  evals  rounds  time (s)");
    for st in &c {
        let g = &st.diagnostics;
        println!(
            "{:.3} {:.9e} {:>6} {:.9e} {:>4} {:>5} {:>3} {:>7.2}",
            st.gap / top,
            st.pressure_ratio,
            st.contacts,
            st.stiffness,
            g.newton_steps,
            g.evaluations,
            g.activation_rounds,
            g.seconds
        );
    }
    if let Some(f) = c.last().and_then(|s| s.diagnostics.far_field) {
        println!(
            "far field: r_c {:.3e} m, near radius {:.3e} m, grid {:?}, measured error {:.2e}",
            f.cutoff, f.near_radius, f.grid_cells, f.measured_error
        );
    }
    println!("total {:.2} s", t0.elapsed().as_secs_f64());
}
