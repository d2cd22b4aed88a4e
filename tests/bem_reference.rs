//! The FFT boundary-element solver against the shared reference data
//! (`../shared/reference`, computed by an independent implementation that agrees with
//! Tamaas 2.9 and ContactMechanics 1.8 to 1e-10), and against Tamaas itself when
//! `tests/python/run.sh` has written its results (ignored test, run by that script).
//!
//! Reference conventions (header of rough_h100um_E2E1_1.csv): the flat's approach δ is
//! measured from first touch of the undeformed surface, `gap` = z_M − z̄ − δ is the
//! nominal separation, `pressure_ratio` = p̄/E*₁ and `area_fraction` = A/A₀.

use std::path::{Path, PathBuf};

use strata_runtime::Stack;
use strata_runtime::bem::{
    Array2, BemLoad, BemOptions, BemSolver, read_heights_npy, resample_spectral,
};

fn reference_dir() -> PathBuf {
    // /work/shared sits beside the repository (also in CI).
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let here = root.join("../shared/reference");
    if here.is_dir() {
        here
    } else {
        root.join("../../shared/reference")
    }
}

/// Reads a numeric CSV with `#` comment lines and one header line.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let header: Vec<String> = lines
        .next()
        .expect("header line")
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.trim().parse::<f64>().expect("number"))
                .collect()
        })
        .collect();
    (header, rows)
}

fn column(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("column {name} missing"))
}

struct Case {
    heights: Array2<f64>,
    stack: Stack,
    header: Vec<String>,
    rows: Vec<Vec<f64>>,
}

fn case() -> Case {
    let dir = reference_dir();
    let heights = read_heights_npy(&dir.join("surface_km10.npy")).expect("surface");
    let stack = Stack::from_toml_file(&dir.join("stack_h100um_E2E1_1.toml")).expect("stack");
    let (header, rows) = read_csv(&dir.join("rough_h100um_E2E1_1.csv"));
    Case {
        heights,
        stack,
        header,
        rows,
    }
}

const L: f64 = 1e-3;

/// Done-when: the reference BEM columns matched to 0.1 % in pressure, 1 % in area.
#[test]
fn matches_reference_bem_512() {
    let c = case();
    let (id, ip, ia) = (
        column(&c.header, "delta"),
        column(&c.header, "bem_pressure_ratio"),
        column(&c.header, "bem_area_fraction"),
    );
    let solver = BemSolver::new(&c.heights, L, &c.stack, BemOptions::default()).expect("solver");
    // Header: E1* = 4.092072e9 Pa; z_M − z_mean = 1.128127e-05 m.
    assert!((solver.e_star1() / 4.092072e9 - 1.0).abs() < 1e-6);
    assert!((solver.max_separation() / 1.128127e-5 - 1.0).abs() < 1e-6);
    let loads: Vec<BemLoad> = c.rows.iter().map(|r| BemLoad::Approach(r[id])).collect();
    let sols = solver.solve_curve(&loads).expect("solve");
    let (mut worst_p, mut worst_a) = (0.0_f64, 0.0_f64);
    for (r, s) in c.rows.iter().zip(&sols) {
        let ep = (s.pressure_ratio / r[ip] - 1.0).abs();
        let ea = (s.area_fraction / r[ia] - 1.0).abs();
        eprintln!(
            "delta {:.4e}: p/E* {:.6e} (ref {:.6e}, rel {:.1e}), A/A0 {:.6e} (ref {:.6e}, rel {:.1e}), patches {}, iters {}",
            r[id], s.pressure_ratio, r[ip], ep, s.area_fraction, r[ia], ea, s.patches, s.iterations
        );
        worst_p = worst_p.max(ep);
        worst_a = worst_a.max(ea);
    }
    eprintln!("worst relative error: pressure {worst_p:.2e}, area {worst_a:.2e}");
    assert!(worst_p < 1e-3, "pressure off by {worst_p:e}");
    assert!(worst_a < 1e-2, "area off by {worst_a:e}");
}

/// The reference's 1024² column: the same surface spectrally resampled.
#[test]
#[ignore = "slow in the dev profile (1024² grid, ~1 min); run with --ignored"]
fn matches_reference_bem_1024() {
    let c = case();
    let (id, ip, ia) = (
        column(&c.header, "delta"),
        column(&c.header, "bem1024_pressure_ratio"),
        column(&c.header, "bem1024_area_fraction"),
    );
    let fine = resample_spectral(&c.heights, 1024).expect("resample");
    let solver = BemSolver::new(&fine, L, &c.stack, BemOptions::default()).expect("solver");
    // Same flat position as on the 512² grid: the finer grid samples the peak higher,
    // so δ (measured from the highest grid point) shifts by the difference.
    let coarse = BemSolver::new(&c.heights, L, &c.stack, BemOptions::default()).expect("solver");
    let shift = solver.max_separation() - coarse.max_separation();
    eprintln!("z_M(1024²) − z_M(512²) = {shift:.3e} m");
    let loads: Vec<BemLoad> = c
        .rows
        .iter()
        .map(|r| BemLoad::Approach(r[id] + shift))
        .collect();
    let sols = solver.solve_curve(&loads).expect("solve");
    for (r, s) in c.rows.iter().zip(&sols) {
        let ep = (s.pressure_ratio / r[ip] - 1.0).abs();
        let ea = (s.area_fraction / r[ia] - 1.0).abs();
        eprintln!("delta {:.4e}: rel p {ep:.1e}, rel A {ea:.1e}", r[id]);
        assert!(ep < 1e-3 && ea < 1e-2);
    }
}

/// Directory of the CSVs written by `tests/python/run.sh` (Tamaas, ContactMechanics).
fn python_reference_dir() -> PathBuf {
    std::env::var_os("STRATA_PY_REF")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target/python-reference"))
}

/// Compares (pressure ratio, area fraction) pairs: relative pressure ≤ 1e-4, area ≤
/// 0.5 %, and the rows must span A/A₀ from ≤ 1 % to ≥ 20 % (the range).
fn compare_rows(name: &str, theirs: &[(f64, f64)], ours: &[(f64, f64)]) {
    let (mut worst_p, mut worst_a) = (0.0_f64, 0.0_f64);
    let (mut a_min, mut a_max) = (f64::INFINITY, 0.0_f64);
    for (t, o) in theirs.iter().zip(ours) {
        let ep = (o.0 / t.0 - 1.0).abs();
        let ea = (o.1 / t.1 - 1.0).abs();
        eprintln!(
            "{name}: p/E* {:.8e} vs {:.8e} (rel {ep:.1e}); A/A0 {:.5e} vs {:.5e} (rel {ea:.1e})",
            o.0, t.0, o.1, t.1
        );
        worst_p = worst_p.max(ep);
        worst_a = worst_a.max(ea);
        a_min = a_min.min(t.1);
        a_max = a_max.max(t.1);
    }
    eprintln!(
        "{name}: worst rel. pressure {worst_p:.2e}, area {worst_a:.2e}, A/A0 {a_min:.3e}…{a_max:.3e}"
    );
    assert!(
        a_min <= 0.01 && a_max >= 0.2,
        "{name}: rows do not span A/A0 1 %…20 %"
    );
    assert!(worst_p <= 1e-4, "{name}: pressure off by {worst_p:e}");
    assert!(worst_a <= 5e-3, "{name}: area off by {worst_a:e}");
}

/// Homogeneous half-space against Tamaas 2.9 at equal mean gap.
#[test]
#[ignore = "needs target/python-reference/tamaas.csv from tests/python/run.sh"]
fn python_tamaas_homogeneous() {
    let (header, rows) = read_csv(&python_reference_dir().join("tamaas.csv"));
    let (ig, ip, ia) = (
        column(&header, "mean_gap"),
        column(&header, "pressure_ratio"),
        column(&header, "area_fraction"),
    );
    let c = case();
    let stack = Stack::half_space(4e9, 0.15).expect("stack");
    let solver = BemSolver::new(&c.heights, L, &stack, BemOptions::default()).expect("solver");
    let loads: Vec<BemLoad> = rows.iter().map(|r| BemLoad::MeanGap(r[ig])).collect();
    let sols = solver.solve_curve(&loads).expect("solve");
    let theirs: Vec<(f64, f64)> = rows.iter().map(|r| (r[ip], r[ia])).collect();
    let ours: Vec<(f64, f64)> = sols
        .iter()
        .map(|s| (s.pressure_ratio, s.area_fraction))
        .collect();
    compare_rows("tamaas", &theirs, &ours);
}

/// One layer (h = 100 µm) bonded to a rigid base against ContactMechanics 1.8 at equal
/// approach (its rigid offset + z_M); the mean gaps must agree too.
#[test]
#[ignore = "needs target/python-reference/cm.csv from tests/python/run.sh"]
fn python_contactmechanics_single_layer() {
    let (header, rows) = read_csv(&python_reference_dir().join("cm.csv"));
    let (id, ig, ip, ia) = (
        column(&header, "delta"),
        column(&header, "mean_gap"),
        column(&header, "pressure_ratio"),
        column(&header, "area_fraction"),
    );
    let c = case();
    let stack = Stack::from_toml_str(
        "[[layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 0.15\n[base]\nkind = \"rigid\"\n",
    )
    .expect("stack");
    let solver = BemSolver::new(&c.heights, L, &stack, BemOptions::default()).expect("solver");
    let loads: Vec<BemLoad> = rows.iter().map(|r| BemLoad::Approach(r[id])).collect();
    let sols = solver.solve_curve(&loads).expect("solve");
    for (r, s) in rows.iter().zip(&sols) {
        let eg = (s.mean_gap - r[ig]).abs() / r[ig];
        assert!(eg < 1e-4, "mean gap {} vs {}", s.mean_gap, r[ig]);
    }
    let theirs: Vec<(f64, f64)> = rows.iter().map(|r| (r[ip], r[ia])).collect();
    let ours: Vec<(f64, f64)> = sols
        .iter()
        .map(|s| (s.pressure_ratio, s.area_fraction))
        .collect();
    compare_rows("contactmechanics", &theirs, &ours);
}

/// Grid refinement on the reference case (two layers on a rigid base, E2/E1 = 1): the
/// surface is band-limited (k ≤ 10·2π/L), so it is resampled exactly to each grid.
/// The flat is held at the same height on every grid (δ given for the 512² grid's
/// highest point, shifted by the change of the sampled maximum).
/// The error against the 512² solution falls with refinement (at 64² and 128² a light
/// load touches a handful of points, so those two are not ordered).
fn refinement_table(grids: &[usize], deltas: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let c = case();
    let base = BemSolver::new(&c.heights, L, &c.stack, BemOptions::default())
        .expect("solver")
        .max_separation();
    grids
        .iter()
        .map(|&n| {
            let z = if n == 512 {
                c.heights.clone()
            } else {
                resample_spectral(&c.heights, n).expect("resample")
            };
            let solver = BemSolver::new(&z, L, &c.stack, BemOptions::default()).expect("solver");
            let shift = solver.max_separation() - base;
            let loads: Vec<BemLoad> = deltas
                .iter()
                .map(|&d| BemLoad::Approach(d + shift))
                .collect();
            solver
                .solve_curve(&loads)
                .expect("solve")
                .iter()
                .map(|s| (s.pressure_ratio, s.area_fraction))
                .collect()
        })
        .collect()
}

#[test]
fn grid_refinement_converges() {
    let deltas = [3.3048930490e-6, 6.1622812533e-6, 9.8328541182e-6];
    let grids = [64, 128, 256, 512];
    let t = refinement_table(&grids, &deltas);
    let fine = &t[grids.len() - 1];
    for (k, _) in deltas.iter().enumerate() {
        let rel = |i: usize, j: usize| -> f64 {
            let (a, b) = (t[i][k], fine[k]);
            if j == 0 {
                (a.0 / b.0 - 1.0).abs()
            } else {
                (a.1 / b.1 - 1.0).abs()
            }
        };
        let ep: Vec<f64> = (0..3).map(|i| rel(i, 0)).collect();
        let ea: Vec<f64> = (0..3).map(|i| rel(i, 1)).collect();
        eprintln!(
            "delta {:.3e}: vs 512², n = 64, 128, 256: pressure {:.2e} {:.2e} {:.2e}, area {:.2e} {:.2e} {:.2e}",
            deltas[k], ep[0], ep[1], ep[2], ea[0], ea[1], ea[2]
        );
        // The area (contact edges resolved to one cell) converges at first order and
        // monotonically; the mean pressure converges fast but not monotonically.
        assert!(
            ea[2] < ea[1] && ea[1] < ea[0],
            "area not converging: {ea:?}"
        );
        assert!(ea[2] < 0.05, "area at 256² still {:.2e} from 512²", ea[2]);
        assert!(
            ep[2] < 1e-3,
            "pressure at 256² still {:.2e} from 512²",
            ep[2]
        );
    }
}

/// Prints the convergence table reported in the README (1024² is slow in the dev profile).
#[test]
#[ignore = "slow (1024² grid); prints the grid-convergence table"]
fn grid_convergence_table() {
    let c = case();
    let (header, rows) = (&c.header, &c.rows);
    let id = column(header, "delta");
    let deltas: Vec<f64> = [2, 7, 11, 14].iter().map(|&i| rows[i][id]).collect();
    let grids = [64, 128, 256, 512, 1024];
    let t = refinement_table(&grids, &deltas);
    eprintln!("| δ (µm) | n | p̄/E*₁ | A/A₀ | rel. diff p vs 1024² | rel. diff A vs 1024² |");
    for (k, d) in deltas.iter().enumerate() {
        for (gi, n) in grids.iter().enumerate() {
            let (p, a) = t[gi][k];
            let (pf, af) = t[grids.len() - 1][k];
            eprintln!(
                "| {:.3} | {n} | {p:.6e} | {a:.5e} | {:.2e} | {:.2e} |",
                d * 1e6,
                (p / pf - 1.0).abs(),
                (a / af - 1.0).abs()
            );
        }
    }
}
