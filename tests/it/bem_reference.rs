//! The FFT boundary-element solver against the shared reference data
//! (`tests/reference`, computed by an independent implementation that agrees with
//! Tamaas 2.9 and ContactMechanics 1.8 to 1e-10), and against Tamaas and
//! ContactMechanics themselves (the ignored `python_*` tests, run by
//! `tests/python/run.sh` in CI): run.sh exports strata's generated paper-like surface
//! (`strata surface export`), the Python solvers load it, these tests compare.
//! Self-contained: the Python check needs nothing outside the repository.
//!
//! Reference conventions (header of rough_h100um_E2E1_1.csv): the flat's approach δ is
//! measured from first touch of the undeformed surface, `gap` = z_M − z̄ − δ is the
//! nominal separation, `pressure_ratio` = p̄/E*₁ and `area_fraction` = A/A₀.

use std::path::{Path, PathBuf};

use strata_bem::{Array2, BemLoad, BemOptions, BemSolver, read_heights_npy, resample_spectral};
use strata_runtime::surface::{GenerateParams, Surface};
use strata_runtime::{Solid, Stack};

fn reference_dir() -> PathBuf {
    crate::support::reference_dir()
}

/// The reference directory (in the repository: `tests/reference`); a missing file is a
/// failure naming its path, never a skip.
fn shared_or_skip(test: &str) -> Option<PathBuf> {
    let dir = reference_dir();
    let f = dir.join("rough_h100um_E2E1_1.csv");
    assert!(
        f.is_file(),
        "{test}: reference data missing: {}",
        f.display()
    );
    Some(dir)
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

fn case(test: &str) -> Option<Case> {
    let dir = shared_or_skip(test)?;
    let heights = read_heights_npy(&dir.join("surface_km10.npy")).expect("surface");
    let stack = Stack::from_toml_file(&dir.join("stack_h100um_E2E1_1.toml")).expect("stack");
    let (header, rows) = read_csv(&dir.join("rough_h100um_E2E1_1.csv"));
    Some(Case {
        heights,
        stack,
        header,
        rows,
    })
}

const L: f64 = 1e-3;

/// The reference BEM columns: required 0.1 % in pressure, 1 % in area; measured
/// 9.0e-11 and 2.5e-11 (the scene-level `solve_bem::bem_scene_matches_reference_bem_column`
/// measures 4.9e-11 on the same data), asserted 1e-9 and 3e-10.
#[test]
fn matches_reference_bem_512() {
    let Some(c) = case("matches_reference_bem_512") else {
        return;
    };
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
    assert!(worst_p < 1e-9, "pressure off by {worst_p:e}");
    assert!(worst_a < 3e-10, "area off by {worst_a:e}");
}

/// The reference's 1024² column: the same surface spectrally resampled.
#[test]
#[ignore = "slow in the dev profile (1024² grid, ~1 min); run with --ignored"]
fn matches_reference_bem_1024() {
    let Some(c) = case("matches_reference_bem_1024") else {
        return;
    };
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

/// Directory of the surface and CSVs of `tests/python/run.sh` (Tamaas, ContactMechanics).
fn python_reference_dir() -> PathBuf {
    std::env::var_os("STRATA_PY_REF")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target/python-reference"))
}

/// The paper-like surface of the grid-refinement test: strata's self-affine generator
/// with the paper's parameters (L = 1 mm, D_f = 2.4, k = 2…10 · 2π/L, RMS 3.4 µm, the
/// shipped scenes' seed) on a 512² grid; tests/python/run.sh exports the same surface
/// for the Python solvers (at 256² in CI).
fn paper_surface_params() -> GenerateParams {
    GenerateParams {
        size: L,
        grid: 512,
        fractal_dimension: 2.4,
        k_min: 2.0,
        k_max: 10.0,
        rms: 3.4e-6,
        seed: 20240611,
    }
}

/// The surface tests/python/run.sh exported (what the Python solvers saw).
fn python_surface() -> Array2<f64> {
    let path = python_reference_dir().join("surface.npy");
    read_heights_npy(&path)
        .unwrap_or_else(|e| panic!("{e}: run tests/python/run.sh (it writes the surface first)"))
}

/// Compares (pressure ratio, area fraction) pairs: relative pressure ≤ `p_tol` (about 10×
/// the measured difference; required 1e-4), area fraction within two grid points of
/// `point` = 1/n² (required 0.5 %; measured identical), and the rows must span A/A₀ from
/// ≤ 1 % to ≥ 20 % (the required range).
fn compare_rows(name: &str, theirs: &[(f64, f64)], ours: &[(f64, f64)], p_tol: f64, point: f64) {
    let (mut worst_p, mut worst_a) = (0.0_f64, 0.0_f64);
    let (mut a_min, mut a_max) = (f64::INFINITY, 0.0_f64);
    for (t, o) in theirs.iter().zip(ours) {
        let ep = (o.0 / t.0 - 1.0).abs();
        let ea = (o.1 - t.1).abs();
        eprintln!(
            "{name}: p/E* {:.8e} vs {:.8e} (rel {ep:.1e}); A/A0 {:.5e} vs {:.5e} (diff {ea:.1e})",
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
    assert!(worst_p <= p_tol, "{name}: pressure off by {worst_p:e}");
    assert!(
        worst_a <= 2.0 * point,
        "{name}: area off by {worst_a:e} (> 2 grid points)"
    );
}

/// Homogeneous half-space against Tamaas 2.9 at equal mean gap: mean pressure measured
/// 9.3e-11 (CI mode, 256²) and 6.2e-10 (512²), asserted 5e-9.
#[test]
#[ignore = "needs target/python-reference/{surface.npy,tamaas.csv}: run tests/python/run.sh"]
fn python_tamaas_homogeneous() {
    let (header, rows) = read_csv(&python_reference_dir().join("tamaas.csv"));
    let (ig, ip, ia) = (
        column(&header, "mean_gap"),
        column(&header, "pressure_ratio"),
        column(&header, "area_fraction"),
    );
    let heights = python_surface();
    let stack = Stack::half_space(4e9, 0.15).expect("stack");
    let solver = BemSolver::new(&heights, L, &stack, BemOptions::default()).expect("solver");
    let loads: Vec<BemLoad> = rows.iter().map(|r| BemLoad::MeanGap(r[ig])).collect();
    let sols = solver.solve_curve(&loads).expect("solve");
    let theirs: Vec<(f64, f64)> = rows.iter().map(|r| (r[ip], r[ia])).collect();
    let ours: Vec<(f64, f64)> = sols
        .iter()
        .map(|s| (s.pressure_ratio, s.area_fraction))
        .collect();
    compare_rows("tamaas", &theirs, &ours, 5e-9, 1.0 / heights.len() as f64);
}

/// Steel on steel (two elastic bodies, strata's counterface, physics.md §6.1) against
/// Tamaas 2.9 given the composite E* = E*_steel/2 (one deformable body) at equal mean
/// gap: mean pressure within 1e-9 (required 1e-6; measured 9.3e-11), the
/// contact points the same (area within 0.5 %), loads spanning A/A₀ 1 %…20 %.
#[test]
#[ignore = "needs target/python-reference/{surface.npy,tamaas_pair.csv}: run tests/python/run.sh"]
fn python_tamaas_steel_pair() {
    let (header, rows) = read_csv(&python_reference_dir().join("tamaas_pair.csv"));
    let (ig, ip, ia) = (
        column(&header, "mean_gap"),
        column(&header, "mean_pressure"),
        column(&header, "area_fraction"),
    );
    let heights = python_surface();
    let steel = Stack::half_space(210e9, 0.3).expect("stack");
    let pair = steel.clone().against(steel);
    let solver = BemSolver::new(&heights, L, &pair, BemOptions::default()).expect("solver");
    let loads: Vec<BemLoad> = rows.iter().map(|r| BemLoad::MeanGap(r[ig])).collect();
    let sols = solver.solve_curve(&loads).expect("solve");
    let mut worst: f64 = 0.0;
    for (r, s) in rows.iter().zip(&sols) {
        worst = worst.max((s.mean_pressure / r[ip] - 1.0).abs());
    }
    eprintln!("tamaas steel/steel pair: worst rel. mean pressure {worst:.2e}");
    // required 1e-6; measured 9.3e-11 (CI mode, 256², A/A₀ 0.58 %…24 %)
    assert!(worst <= 1e-9, "pressure off by {worst:e}");
    // Areas and the A/A₀ span, as for the other references (pressure_ratio column
    // replaced by p/E*_pair on both sides).
    let e = pair.contact_modulus();
    let theirs: Vec<(f64, f64)> = rows.iter().map(|r| (r[ip] / e, r[ia])).collect();
    let ours: Vec<(f64, f64)> = sols
        .iter()
        .map(|s| (s.mean_pressure / e, s.area_fraction))
        .collect();
    compare_rows(
        "tamaas steel/steel",
        &theirs,
        &ours,
        1e-9,
        1.0 / heights.len() as f64,
    );
}

/// The hardness cap (physics.md §6.3) on a half-space against ContactMechanics
/// 1.8's plastic system (zero-mean half-space, `stiffness_q0 = 0`) at equal approach along
/// a path that loads and unloads (both keep the plastic depth between steps): mean
/// pressure within 5e-9 (required 1e-4, measured 1.3e-10), contact and plastic areas
/// within two grid points (measured identical).
#[test]
#[ignore = "needs target/python-reference/{surface.npy,cm_plastic.csv}: run tests/python/run.sh"]
fn python_contactmechanics_plastic() {
    let (header, rows) = read_csv(&python_reference_dir().join("cm_plastic.csv"));
    let (id, ip, ia, ipl) = (
        column(&header, "delta"),
        column(&header, "mean_pressure"),
        column(&header, "area_fraction"),
        column(&header, "plastic_area_fraction"),
    );
    let heights = python_surface();
    let stack = Stack::half_space(4e9, 0.15).expect("stack");
    let solver = BemSolver::new(&heights, L, &stack, BemOptions::default()).expect("solver");
    let loads: Vec<BemLoad> = rows.iter().map(|r| BemLoad::Approach(r[id])).collect();
    let ours = solver
        .solve_plastic_curve(&loads, 0.2e9)
        .expect("plastic path");
    let (mut wp, mut wa, mut wpl) = (0.0_f64, 0.0_f64, 0.0_f64);
    for (r, (s, info)) in rows.iter().zip(&ours) {
        let ep = (s.mean_pressure / r[ip] - 1.0).abs();
        let ea = (s.area_fraction - r[ia]).abs();
        let epl = (info.plastic_area_fraction - r[ipl]).abs();
        eprintln!(
            "cm plastic δ {:.1e}: p {:.8e} vs {:.8e} (rel {ep:.1e}); A/A0 {:.5e} vs {:.5e}; plastic {:.5e} vs {:.5e}",
            r[id],
            s.mean_pressure,
            r[ip],
            s.area_fraction,
            r[ia],
            info.plastic_area_fraction,
            r[ipl]
        );
        wp = wp.max(ep);
        wa = wa.max(ea);
        wpl = wpl.max(epl);
    }
    eprintln!("cm plastic: worst rel. pressure {wp:.2e}, area {wa:.2e}, plastic area {wpl:.2e}");
    // required 1e-4; measured 1.3e-10 in pressure, areas and plastic areas
    // identical (CI mode, 256², A/A₀ 0.1 %…24 %, plastic up to 10.4 %)
    let point = 2.0 / (heights.len() as f64);
    assert!(wp <= 5e-9, "pressure off by {wp:e}");
    assert!(wa <= point && wpl <= point, "areas off by {wa:e}, {wpl:e}");
}

/// One layer (h = 100 µm) bonded to a rigid base against ContactMechanics 1.8 at equal
/// approach (its rigid offset + z_M); the mean gaps must agree too. Mean pressure measured
/// 1.5e-12 (CI mode, 256²) and 3.4e-11 (512²), asserted 3e-10.
#[test]
#[ignore = "needs target/python-reference/{surface.npy,cm.csv}: run tests/python/run.sh"]
fn python_contactmechanics_single_layer() {
    let (header, rows) = read_csv(&python_reference_dir().join("cm.csv"));
    let (id, ig, ip, ia) = (
        column(&header, "delta"),
        column(&header, "mean_gap"),
        column(&header, "pressure_ratio"),
        column(&header, "area_fraction"),
    );
    let heights = python_surface();
    let stack = Stack::from_toml_str(
        "[[layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 0.15\n[base]\nkind = \"rigid\"\n",
    )
    .expect("stack");
    let solver = BemSolver::new(&heights, L, &stack, BemOptions::default()).expect("solver");
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
    compare_rows(
        "contactmechanics",
        &theirs,
        &ours,
        3e-10,
        1.0 / heights.len() as f64,
    );
}

/// Grid refinement of a paper-like surface on the paper's two layers (E2/E1 = 1, rigid
/// base): the surface is band-limited (k ≤ 10·2π/L), so it is resampled exactly to
/// each grid. The flat is held at the same height on every grid (δ given for the 512²
/// grid's highest point, shifted by the change of the sampled maximum).
/// The error against the 512² solution falls with refinement (at 64² and 128² a light
/// load touches a handful of points, so those two are not ordered).
fn refinement_table(
    heights: &Array2<f64>,
    stack: &Stack,
    grids: &[usize],
    deltas: &[f64],
) -> Vec<Vec<(f64, f64)>> {
    let base = BemSolver::new(heights, L, stack, BemOptions::default())
        .expect("solver")
        .max_separation();
    grids
        .iter()
        .map(|&n| {
            let z = if n == heights.dim().0 {
                heights.clone()
            } else {
                resample_spectral(heights, n).expect("resample")
            };
            let solver = BemSolver::new(&z, L, stack, BemOptions::default()).expect("solver");
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

/// Self-contained: strata's generated paper-like surface (512², the shipped scenes'
/// parameters and seed), not the shared one.
#[test]
fn grid_refinement_converges() {
    let p = paper_surface_params();
    let s = Surface::generate(&p).expect("surface");
    let heights = Array2::from_shape_vec((512, 512), s.heights().to_vec()).expect("shape");
    let stack = Stack::paper_two_layer(1.0).expect("stack");
    // z_M − z̄ = 10.16 µm on this surface: separations 6.9, 4.0 and 0.4 µm.
    let deltas = [3.3e-6, 6.2e-6, 9.8e-6];
    let grids = [64, 128, 256, 512];
    let t = refinement_table(&heights, &stack, &grids, &deltas);
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
        // monotonically (256² vs 512²: 1.0e-2 … 3.1e-2 measured); the mean pressure
        // converges fast but not monotonically (256² vs 512²: 7.7e-6 … 3.4e-5 measured,
        // asserted 3e-4).
        assert!(
            ea[2] < ea[1] && ea[1] < ea[0],
            "area not converging: {ea:?}"
        );
        assert!(ea[2] < 0.05, "area at 256² still {:.2e} from 512²", ea[2]);
        assert!(
            ep[2] < 3e-4,
            "pressure at 256² still {:.2e} from 512²",
            ep[2]
        );
    }
}

/// Non-periodic homogeneous half-space against ContactMechanics 1.8's
/// FreeFFTElasticHalfSpace on the same surface taken as an isolated sample, at equal
/// approach: mean pressure within 3e-9 (required 1e-3; measured 1.1e-11 in CI mode, 256²,
/// and 2.6e-10 at 512²), contact area within two grid points (required 0.5 %; measured
/// identical), over A/A₀ from ≤ 1 % to ≥ 20 %.
#[test]
#[ignore = "needs target/python-reference/{surface.npy,free.csv}: run tests/python/run.sh"]
fn python_contactmechanics_free_boundary() {
    let (header, rows) = read_csv(&python_reference_dir().join("free.csv"));
    let (id, ip, ia) = (
        column(&header, "delta"),
        column(&header, "pressure_ratio"),
        column(&header, "area_fraction"),
    );
    let heights = python_surface();
    let stack = Stack::half_space(4e9, 0.15).expect("stack");
    let geo = strata_bem::Geometry {
        lx: L,
        ly: L,
        periodic: false,
    };
    let solver =
        BemSolver::with_geometry(&heights, geo, &stack, BemOptions::default()).expect("solver");
    let loads: Vec<BemLoad> = rows.iter().map(|r| BemLoad::Approach(r[id])).collect();
    let sols = solver.solve_curve(&loads).expect("solve");
    let (mut worst_p, mut worst_a) = (0.0_f64, 0.0_f64);
    let (mut a_min, mut a_max) = (f64::INFINITY, 0.0_f64);
    for (r, s) in rows.iter().zip(&sols) {
        let ep = (s.pressure_ratio / r[ip] - 1.0).abs();
        let ea = (s.area_fraction - r[ia]).abs();
        eprintln!(
            "free: delta {:.3e}: p/E* {:.8e} vs {:.8e} (rel {ep:.1e}); A/A0 {:.5e} vs {:.5e} (diff {ea:.1e})",
            r[id], s.pressure_ratio, r[ip], s.area_fraction, r[ia]
        );
        worst_p = worst_p.max(ep);
        worst_a = worst_a.max(ea);
        a_min = a_min.min(r[ia]);
        a_max = a_max.max(r[ia]);
    }
    eprintln!(
        "free: worst rel. pressure {worst_p:.2e}, area {worst_a:.2e}, A/A0 {a_min:.3e}…{a_max:.3e}"
    );
    assert!(
        a_min <= 0.01 && a_max >= 0.2,
        "rows do not span A/A0 1 %…20 %"
    );
    assert!(worst_p <= 3e-9, "pressure off by {worst_p:e}");
    let point = 1.0 / heights.len() as f64;
    assert!(
        worst_a <= 2.0 * point,
        "area off by {worst_a:e} (> 2 grid points)"
    );
}
