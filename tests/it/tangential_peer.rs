//! The BEM's coupled normal–tangential solve against Tamaas' PolonskyKeerTan (an
//! independent public FFT-BEM with Coulomb friction, `tests/python/pkt_stick.py`), on the
//! same rough half-space surface at ν = 0.3 (S_zL = β ≠ 0), loaded as PolonskyKeerTan
//! loads: the mean pressure and the mean tangential traction in one step, force control.
//! The stick-area fraction (stick over contact) must agree to 1e-3. Beside it, the
//! incremental path (frictionless normal loading, then the tangential load with the
//! normal step's history) is solved and its distance from the one-step answer printed.
//!
//! Needs Python with `tamaas`: ignored in the normal tier, run by the cross-check
//! (tests/python/run.sh, with `$STRATA_PY_VENV/bin/python` of its venv; else `python3`).
//! Without tamaas the test says so and passes; `STRATA_REQUIRE_TOOLS=1` (CI) makes that
//! a failure.

use std::f64::consts::TAU;
use std::process::Command;

use strata_bem::tangential::{Coupling, NormalLoad, TractionKernel, solve_coupled, solve_normal};
use strata_runtime::Stack;

use crate::support::{fresh_dir, repo};

const N: usize = 64;
const E: f64 = 1.0;
const NU: f64 = 0.3;
const MU: f64 = 0.5;
const P_MEAN: f64 = 1e-3;
const Q_MEAN: f64 = 2.5e-4;

/// A random-phase rough surface on the unit cell (wavenumbers 2–12 per cell, amplitude
/// ∝ |k|^−1.8, phases from a fixed linear congruential sequence), RMS 1e-3.
fn surface() -> Vec<f64> {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut z = vec![0.0; N * N];
    for kx in -12i32..=12 {
        for ky in 0i32..=12 {
            let k = ((kx * kx + ky * ky) as f64).sqrt();
            if !(2.0..=12.0).contains(&k) || (ky == 0 && kx < 0) {
                continue;
            }
            let a = k.powf(-1.8);
            let phi = TAU * next();
            for i in 0..N {
                for j in 0..N {
                    let arg = TAU * (kx as f64 * j as f64 + ky as f64 * i as f64) / N as f64;
                    z[i * N + j] += a * (arg + phi).cos();
                }
            }
        }
    }
    let m = z.iter().sum::<f64>() / z.len() as f64;
    let s = (z.iter().map(|v| (v - m).powi(2)).sum::<f64>() / z.len() as f64).sqrt();
    z.iter().map(|v| (v - m) / s * 1e-3).collect()
}

/// Python with tamaas, or None after saying so (a failure under STRATA_REQUIRE_TOOLS=1).
fn python_with_tamaas() -> Option<String> {
    let candidates: Vec<String> = std::env::var("STRATA_PY_VENV")
        .ok()
        .map(|v| format!("{v}/bin/python"))
        .into_iter()
        .chain(std::iter::once("python3".to_string()))
        .collect();
    for py in &candidates {
        let ok = Command::new(py)
            .args(["-c", "import tamaas"])
            .output()
            .is_ok_and(|o| o.status.success());
        if ok {
            return Some(py.clone());
        }
    }
    let msg = "*** Python with tamaas not found: this test did NOT run. Install it \
               (pip install -r tests/python/requirements.txt; set STRATA_PY_VENV to its venv) \
               or set STRATA_REQUIRE_TOOLS=1 to make its absence a failure (CI does).";
    assert!(
        std::env::var_os("STRATA_REQUIRE_TOOLS").is_none_or(|v| v != "1"),
        "{msg}"
    );
    eprintln!("\n{msg}\n");
    None
}

fn stick_fraction(p: &[f64], q: &[Vec<f64>; 2]) -> (usize, usize) {
    let mut contact = 0;
    let mut stick = 0;
    for i in 0..p.len() {
        if p[i] > 0.0 {
            contact += 1;
            if q[0][i].hypot(q[1][i]) < MU * p[i] * (1.0 - 1e-6) {
                stick += 1;
            }
        }
    }
    (contact, stick)
}

#[test]
#[ignore = "needs Python with tamaas: tests/python/run.sh runs it with the peers' venv"]
fn coupled_solve_matches_polonsky_keer_tan() {
    let z = surface();
    let stack = Stack::half_space(E, NU).unwrap();
    let kernel = TractionKernel::periodic(&stack, (N, N), (1.0, 1.0), Coupling::Coupled).unwrap();
    let one_step =
        solve_coupled(&kernel, &z, P_MEAN, [Q_MEAN, 0.0], MU, None, 1e-10, 20000).unwrap();
    let (c1, s1) = stick_fraction(&one_step.normal.pressure, &one_step.slip.traction);
    let f1 = s1 as f64 / c1 as f64;
    // The incremental path: frictionless normal loading, then the tangential load from
    // the normal step's tangential displacement (its history).
    let normal = solve_normal(
        &kernel,
        &z,
        None,
        NormalLoad::MeanPressure(P_MEAN),
        None,
        1e-10,
        20000,
    )
    .unwrap();
    let n = N * N;
    let (mut ux, mut uy) = (vec![0.0; n], vec![0.0; n]);
    let mut work = kernel.work();
    kernel
        .apply(
            [None, None, Some(&normal.pressure)],
            [Some(&mut ux), Some(&mut uy), None],
            &mut work,
        )
        .unwrap();
    let path = solve_coupled(
        &kernel,
        &z,
        P_MEAN,
        [Q_MEAN, 0.0],
        MU,
        Some([&ux, &uy]),
        1e-10,
        20000,
    )
    .unwrap();
    let (c2, s2) = stick_fraction(&path.normal.pressure, &path.slip.traction);
    let f2 = s2 as f64 / c2 as f64;
    eprintln!(
        "strata one step: contact {c1}, stick {s1} (fraction {f1:.5}, {} alternations); \
         incremental path: contact {c2}, stick {s2} (fraction {f2:.5}), difference {:.2e}",
        one_step.outer_iterations,
        f2 - f1
    );
    let Some(py) = python_with_tamaas() else {
        return;
    };
    let dir = fresh_dir("tangential_peer", "pkt");
    let heights = dir.join("heights.txt");
    let text: String = (0..N)
        .map(|i| {
            let row: Vec<String> = (0..N).map(|j| format!("{:e}", z[i * N + j])).collect();
            row.join(" ") + "\n"
        })
        .collect();
    std::fs::write(&heights, text).unwrap();
    let out = Command::new(&py)
        .env("OMP_NUM_THREADS", "1")
        .arg(repo().join("tests/python/pkt_stick.py"))
        .arg(&heights)
        .args([E, NU, MU, P_MEAN, Q_MEAN, 1e-8].map(|v| format!("{v:e}")))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "pkt_stick.py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = stdout.lines().last().unwrap_or_default().to_string();
    let v: Vec<usize> = last
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    let ft = v[1] as f64 / v[0] as f64;
    eprintln!(
        "Tamaas PolonskyKeerTan: contact {}, stick {} (fraction {ft:.5}); strata − Tamaas {:.2e}",
        v[0],
        v[1],
        f1 - ft
    );
    assert!((f1 - ft).abs() <= 1e-3, "stick fractions {f1} and {ft}");
}
