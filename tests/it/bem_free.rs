//! The boundary-element solver on isolated (non-periodic) and rectangular samples, and
//! loads beyond the peak-to-valley height:
//! * a single paraboloid on the paper's layered stack against the independent Fredholm
//!   solution of strata-tablegen (force within 0.5 % at equal approach);
//! * 768×576 non-periodic samples with dx = dy and dx ≠ dy: the same smooth surface on
//!   both pixel shapes gives the same load at equal approach (discretisation only);
//! * a load curve on the paper's E₂/E₁ = 0.2 stack (k_max = 20) to A/A₀ ≥ 15 %, at
//!   approaches beyond z_M − z_min;
//! * a grid too large for the memory limit fails with a message (subprocess).

use std::process::Command;

use strata_bem::{Array2, BemLoad, BemOptions, BemSolver, Geometry};
use strata_runtime::Stack;
use strata_runtime::resources::MemoryLimit;
use strata_runtime::surface::{GenerateParams, Surface};
use strata_tablegen::asperity::{Asperity, Options};

/// A paraboloid z = −r²/(2R) centred on a grid corner of an n×n sample of side l.
fn paraboloid(n: usize, l: f64, r: f64) -> Array2<f64> {
    let dx = l / n as f64;
    let c = (n as f64 - 1.0) / 2.0;
    Array2::from_shape_fn((n, n), |(i, j)| {
        let (x, y) = ((j as f64 - c) * dx, (i as f64 - c) * dx);
        -(x * x + y * y) / (2.0 * r)
    })
}

/// Force of an isolated paraboloid at the Fredholm solution's approach, BEM vs
/// Fredholm, on the paper's two-layer stack (E₂/E₁ = 5 and 0.2, rigid base at 1 mm),
/// contact radius ≈ h = 100 µm resolved by ~40 pixels. Homogeneous Hertz on the same
/// grid gives the discretisation error for scale.
#[test]
fn layered_paraboloid_matches_fredholm() {
    let (n, l, r) = (160, 0.36e-3, 1e-3);
    let heights = paraboloid(n, l, r);
    let z_top = heights.iter().cloned().fold(f64::MIN, f64::max);
    let geo = Geometry {
        lx: l,
        ly: l,
        periodic: false,
    };
    let hom = Stack::half_space(4e9, 0.15).unwrap();
    let es = hom.top_plane_strain_modulus();
    let delta: f64 = 1e-5;
    let s = BemSolver::with_geometry(&heights, geo, &hom, BemOptions::default())
        .unwrap()
        .solve(BemLoad::Approach(delta + z_top))
        .unwrap();
    let hertz = 4.0 / 3.0 * es * r.sqrt() * delta.powf(1.5);
    let e_hertz = s.total_load / hertz - 1.0;
    eprintln!(
        "homogeneous: BEM {:.6e} N vs Hertz {hertz:.6e} N ({e_hertz:+.2e})",
        s.total_load
    );
    assert!(e_hertz.abs() < 5e-3);
    for ratio in [5.0, 0.2] {
        let stack = Stack::paper_two_layer(ratio).unwrap();
        let f = Asperity::new(&stack, Options::default())
            .unwrap()
            .paraboloid_at_radius(1e-4, r)
            .unwrap();
        let bem = BemSolver::with_geometry(&heights, geo, &stack, BemOptions::default())
            .unwrap()
            .solve(BemLoad::Approach(f.delta + z_top))
            .unwrap();
        let e = bem.total_load / f.force - 1.0;
        let a = (bem.contact_points as f64 * (l / n as f64).powi(2) / std::f64::consts::PI).sqrt();
        eprintln!(
            "E2/E1 = {ratio}: δ {:.4e} m, Fredholm P {:.6e} N a {:.4e} m; BEM P {:.6e} N ({e:+.2e}) a {a:.4e} m, {} iterations",
            f.delta, f.force, f.a, bem.total_load, bem.iterations
        );
        assert!(e.abs() < 5e-3, "E2/E1 = {ratio}: force off by {e:e}");
        assert!((a / f.a - 1.0).abs() < 0.03);
    }
}

/// A smooth non-periodic surface (bumps of 60…120 µm radius) on 768×576 pixels: once
/// with square pixels, once with dy = 1.5 dx over the same area (768×384). Equal
/// approach: equal load within the discretisation error (1 %), both converged.
#[test]
fn rectangular_non_periodic_768x576() {
    let lx = 1.27e-3;
    let ly = 0.96e-3;
    let bumps = [
        (0.3e-3, 0.25e-3, 60e-6, 1.0),
        (0.9e-3, 0.5e-3, 90e-6, 0.8),
        (0.6e-3, 0.7e-3, 120e-6, 0.9),
        (1.1e-3, 0.2e-3, 70e-6, 0.7),
    ];
    let h = |x: f64, y: f64| -> f64 {
        bumps
            .iter()
            .map(|&(cx, cy, w, a)| {
                a * 2e-6 * (-((x - cx).powi(2) + (y - cy).powi(2)) / (w * w)).exp()
            })
            .sum::<f64>()
            + 1e-7 * (x / lx * 7.3).sin()
    };
    let stack = Stack::paper_two_layer(1.0).unwrap();
    let geo = Geometry {
        lx,
        ly,
        periodic: false,
    };
    let mut loads = Vec::new();
    for ny in [576usize, 384] {
        let nx = 768;
        let (dx, dy) = (lx / nx as f64, ly / ny as f64);
        let z = Array2::from_shape_fn((ny, nx), |(i, j)| {
            h((j as f64 + 0.5) * dx, (i as f64 + 0.5) * dy)
        });
        let solver = BemSolver::with_geometry(&z, geo, &stack, BemOptions::default()).unwrap();
        assert_eq!(solver.shape(), (ny, nx));
        // The flat 1 µm below the analytic top (2 µm plus the ripple at the first bump).
        let top = z.iter().cloned().fold(f64::MIN, f64::max);
        let s = solver
            .solve(BemLoad::Approach(1e-6 - (h(0.3e-3, 0.25e-3) - top)))
            .unwrap();
        eprintln!(
            "{ny}×{nx} (dx {dx:.3e}, dy {dy:.3e}): P {:.6e} N, A/A0 {:.4e}, {} patches, {} iterations, error {:.1e}",
            s.total_load, s.area_fraction, s.patches, s.iterations, s.error
        );
        assert!(s.error <= 1e-10 && s.patches >= 2 && s.area_fraction > 0.0);
        loads.push(s.total_load);
    }
    let rel = (loads[1] / loads[0] - 1.0).abs();
    assert!(rel < 1e-2, "dx ≠ dy vs dx = dy: {rel:e}");
}

/// The BEM on soft stacks: on the paper's E₂/E₁ = 0.2 stack (rigid base) a generated k_max = 20
/// surface is loaded by approaches up to 2.2 × its peak-to-valley height: the curve
/// keeps rising with partial contact and reaches A/A₀ ≥ 15 %.
#[test]
fn soft_stack_beyond_peak_to_valley() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/stacks");
    let stack = Stack::from_toml_file(&dir.join("paper-two-layer-E2E1-0.2.toml")).unwrap();
    let n = 256;
    let s = Surface::generate(&GenerateParams {
        size: 1e-3,
        grid: n,
        fractal_dimension: 2.4,
        k_min: 2.0,
        k_max: 20.0,
        rms: 3.4e-6,
        seed: 20240611,
    })
    .unwrap();
    let z = Array2::from_shape_vec((n, n), s.heights().to_vec()).unwrap();
    let pv =
        z.iter().cloned().fold(f64::MIN, f64::max) - z.iter().cloned().fold(f64::MAX, f64::min);
    let solver = BemSolver::new(&z, 1e-3, &stack, BemOptions::default()).unwrap();
    let loads: Vec<BemLoad> = [0.5, 1.0, 1.4, 1.9, 2.2]
        .iter()
        .map(|f| BemLoad::Approach(f * pv))
        .collect();
    let sols = solver.solve_curve(&loads).unwrap();
    let mut last = 0.0;
    for (l, s) in loads.iter().zip(&sols) {
        eprintln!(
            "{l:?}: p/E* {:.4e}, A/A0 {:.4}, {} iterations",
            s.pressure_ratio, s.area_fraction, s.iterations
        );
        assert!(s.mean_pressure > last && s.area_fraction < 1.0);
        last = s.mean_pressure;
    }
    assert!(sols[4].area_fraction >= 0.15, "{}", sols[4].area_fraction);
    assert!(sols[1].area_fraction < 0.15);
}

/// A 16384² grid needs more than a small limit: refused with a message naming the
/// estimate, before allocating (library estimate), and through `strata solve` in a
/// subprocess with STRATA_MEMORY_LIMIT (a 2048² scene on a 64 MiB limit).
#[test]
fn memory_limit_is_an_error_not_an_abort() {
    let need = BemSolver::memory_needed(16384, 16384, true);
    // ≈ 60 B per point: 15 GiB
    assert!(need > 14 << 30 && need < 16 << 30, "{need}");
    let e = MemoryLimit::new(1 << 30, "test")
        .check("BEM grid 16384×16384", need)
        .unwrap_err();
    assert!(e.to_string().contains("BEM grid 16384×16384"), "{e}");
    assert!(BemSolver::memory_needed(16384, 16384, false) > need);
    let d = crate::support::scratch().join("bem-mem");
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let scene = d.join("scene.toml");
    std::fs::write(
        &scene,
        "[stack]\nfile = \"STACK\"\n[surface]\nperiodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 2048\nfractal_dimension = 2.4\nk_min = 2\nk_max = 10\nrms = 3.4e-6\nseed = 1\n[model]\nkind = \"bem\"\n[load]\nseparations = [5e-6]\n"
            .replace("STACK", &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/stacks/paper-two-layer-E2E1-1.toml").display().to_string()),
    )
    .unwrap();
    let out = d.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_strata"))
        .args([
            "solve",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--no-plots",
        ])
        .env("STRATA_MEMORY_LIMIT", "64M")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(o.status.code().is_some(), "killed by a signal: {err}");
    assert!(
        (err.contains("BEM grid 2048×2048") || err.contains("2048×2048 surface"))
            && err.contains("memory limit"),
        "{err}"
    );
    assert!(!out.join("curve.csv").exists());
}
