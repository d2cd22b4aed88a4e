//! Measured-style samples (the scenes' solid: E = 4 GPa, ν = 0.15 as in
//! `support::homogeneous_scene`): rectangular grids (768×576), rectangular pixels
//! (dx ≠ dy), non-periodic and periodic with Lx ≠ Ly, heights in other units, form
//! removal. Checked against computations written out here: summits and curvatures
//! by direct loops, the N model as the Hertz sum, the I model by the KKT conditions of
//! the complementary energy (P22) with the half-space interaction and its gradient
//! summed directly (images included).

use std::path::{Path, PathBuf};

use crate::support::{homogeneous_scene, run_strata, solve_no_plots, temp_dir};
use strata_runtime::law::Homogeneous;
use strata_runtime::rough::{Images, RoughContact};
use strata_runtime::surface::{GenerateParams, Spacing, Surface};

const E: f64 = 4e9;
const NU: f64 = 0.15;

fn e_star() -> f64 {
    E / (1.0 - NU * NU)
}

fn tmp(name: &str) -> PathBuf {
    temp_dir(&format!("rect-{name}"))
}

/// A 768×576 non-periodic sample: the top-left corner of a generated 1024² periodic
/// surface (pixel 1.27 mm / 768, RMS 1 µm), row-major, first axis x.
fn crop_768x576() -> Vec<f64> {
    let dx = 1.27e-3 / 768.0;
    let s = Surface::generate(&GenerateParams {
        size: 1024.0 * dx,
        grid: 1024,
        fractal_dimension: 2.4,
        k_min: 2.0,
        k_max: 24.0,
        rms: 1e-6,
        seed: 11,
    })
    .expect("surface");
    (0..768 * 576).map(|k| s.z(k / 576, k % 576)).collect()
}

/// Summits written out: strict 8-neighbour maxima (wrapping when periodic, the border
/// excluded otherwise), κ = −(z_xx/dx² + z_yy/dy²)/2 from raw second differences;
/// (x, y, z, R) in row-major order.
fn direct_summits(
    z: &[f64],
    n0: usize,
    n1: usize,
    dx: f64,
    dy: f64,
    periodic: bool,
) -> Vec<[f64; 4]> {
    let at = |i: isize, j: isize| {
        z[(i.rem_euclid(n0 as isize) as usize) * n1 + j.rem_euclid(n1 as isize) as usize]
    };
    let mut out = Vec::new();
    for i in 0..n0 as isize {
        for j in 0..n1 as isize {
            if !periodic && (i == 0 || j == 0 || i == n0 as isize - 1 || j == n1 as isize - 1) {
                continue;
            }
            let c = at(i, j);
            let strict = (-1..=1)
                .flat_map(|a| (-1..=1).map(move |b| (a, b)))
                .all(|(a, b)| (a, b) == (0, 0) || at(i + a, j + b) < c);
            let k = -((at(i + 1, j) - 2.0 * c + at(i - 1, j)) / (dx * dx)
                + (at(i, j + 1) - 2.0 * c + at(i, j - 1)) / (dy * dy))
                / 2.0;
            if strict && k > 0.0 {
                out.push([i as f64 * dx, j as f64 * dy, c, 1.0 / k]);
            }
        }
    }
    out
}

/// Homogeneous half-space displacement G(r) of asperity (a, R) at distance r and its
/// a-derivative (physics.md §4 with χ = ζ = 1, g = 0; the paper's constant a²/R inside,
/// P19): outside [(2a² − r²) asin(a/r) + a√(r² − a²)]/(πR), ∂/∂a = 4a asin(a/r)/(πR).
fn g_and_da(a: f64, radius: f64, r: f64) -> (f64, f64) {
    if r <= a {
        return (a * a / radius, 2.0 * a / radius);
    }
    let s = (a / r).asin();
    (
        ((2.0 * a * a - r * r) * s + a * (r * r - a * a).sqrt()) / (std::f64::consts::PI * radius),
        4.0 * a * s / (std::f64::consts::PI * radius),
    )
}

/// KKT residual of the I model written out (homogeneous): the gradient of U_E (P22)
/// in a_k, scaled by c·Q_k' (Q = a³/R, s = 1.2a²/R):
/// F_k = D_k + 2a_k²/R_k − 2δ_k + Σ_j Q_j ∂G_k(r_kj)/∂a_k / Q_k', D_k = Σ_l G_l(r_lk),
/// both sums over the other asperities and every image on the (2m+1)² block of cells
/// of size (lx, ly) (own images included); at a_k = 0 the last sum is its limit
/// Σ_j (4/3)Q_j/(π r_kj). Returns max |F_k| over contacts and max(−F_k) over the
/// others, relative to the largest interference.
fn kkt_direct(sm: &[[f64; 4]], radii: &[f64], delta: f64, m: i64, lx: f64, ly: f64) -> f64 {
    let z_max = sm.iter().map(|s| s[2]).fold(f64::MIN, f64::max);
    let dk = |k: usize| (delta - (z_max - sm[k][2])).max(0.0);
    let scale = (0..sm.len()).map(dk).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for k in 0..sm.len() {
        let (ak, rk) = (radii[k], sm[k][3]);
        let (mut d, mut x) = (0.0, 0.0);
        for l in 0..sm.len() {
            if radii[l] <= 0.0 {
                continue;
            }
            let ql = radii[l].powi(3) / sm[l][3];
            for sx in -m..=m {
                for sy in -m..=m {
                    if l == k && (sx, sy) == (0, 0) {
                        continue;
                    }
                    let r = (sm[l][0] + sx as f64 * lx - sm[k][0])
                        .hypot(sm[l][1] + sy as f64 * ly - sm[k][1]);
                    d += g_and_da(radii[l], sm[l][3], r).0;
                    x += if ak > 0.0 {
                        ql * g_and_da(ak, rk, r).1 / (3.0 * ak * ak / rk)
                    } else {
                        4.0 * ql / (3.0 * std::f64::consts::PI * r)
                    };
                }
            }
        }
        let f = d + 2.0 * ak * ak / rk - 2.0 * dk(k) + x;
        worst = worst.max(if ak > 0.0 { f.abs() } else { -f });
    }
    worst / scale
}

fn strata(args: &[&str]) -> std::process::Output {
    run_strata(args)
}

/// A generated 96² periodic surface on 1 mm (D_f = 2.3, k = 2…16, RMS 1.7 µm).
fn small_surface(seed: u64) -> Surface {
    Surface::generate(&GenerateParams {
        size: 1e-3,
        grid: 96,
        fractal_dimension: 2.3,
        k_min: 2.0,
        k_max: 16.0,
        rms: 1.7e-6,
        seed,
    })
    .expect("surface")
}

fn scene(dir: &Path, name: &str, surface: &str, kind: &str, load: &str) -> PathBuf {
    let p = dir.join(name);
    let model = format!("\"{kind}\"\nimages = \"isolated\"");
    std::fs::write(&p, homogeneous_scene(surface, &model, load)).expect("scene");
    p
}

fn curve(out: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(out.join("curve.csv"))
        .expect("curve.csv")
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect()
}

/// 768×576 non-periodic samples with dx = dy (size = [Lx, Ly]) and dx ≠ dy
/// (pixel_size): `strata solve` with the N and I (isolated) models succeeds; the N
/// curve equals the Hertz sum over directly computed summits (positions, heights,
/// radii with each axis' spacing) on A₀ = Lx·Ly; the library's I solution satisfies
/// the KKT conditions with the interaction summed directly.
#[test]
fn rectangular_768x576_n_and_i_models() {
    let dir = tmp("768");
    let z = crop_768x576();
    let (n0, n1) = (768usize, 576usize);
    let dx = 1.27e-3 / 768.0;
    for (name, dy, spec) in [
        (
            "square-pixels",
            dx,
            format!("size = [1.27e-3, {:e}]", 576.0 * dx),
        ),
        (
            "rect-pixels",
            1.5 * dx,
            format!("pixel_size = [{dx:e}, {:e}]", 1.5 * dx),
        ),
    ] {
        let s = Surface::with_spacing(z.clone(), n0, n1, Spacing::Pixel(dx, dy), false)
            .expect("surface");
        let f = dir.join(format!("{name}.npy"));
        s.write_npy(&f).expect("npy");
        // the heights as given (the direct summits are computed from them)
        let surface = format!("file = \"{name}.npy\"\n{spec}\ndetrend = \"none\"");
        let load = "approach = { from = 0.5e-6, to = 1.5e-6, steps = 3 }";
        let sm = direct_summits(&z, n0, n1, dx, dy, false);
        let z_max = sm.iter().map(|s| s[2]).fold(f64::MIN, f64::max);
        let (lx, ly) = (n0 as f64 * dx, n1 as f64 * dy);
        for kind in ["independent", "interacting"] {
            let sc = scene(&dir, &format!("{name}-{kind}.toml"), &surface, kind, load);
            let out = dir.join(format!("{name}-{kind}"));
            let o = solve_no_plots(&sc, &out);
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(o.status.success(), "{name} {kind}: {err}");
            assert!(
                err.contains("768×576 points") && err.contains("non-periodic"),
                "{err}"
            );
            assert!(!err.contains("WARNING"), "{err}");
            let rows = curve(&out);
            assert_eq!(rows.len(), 3);
            assert!(rows.iter().all(|r| r[2] > 0.0 && r[5] > 0.0), "{rows:?}");
            if kind == "independent" {
                for r in &rows {
                    let delta = r[0];
                    let p: f64 = sm
                        .iter()
                        .map(|s| {
                            let d = (delta - (z_max - s[2])).max(0.0);
                            4.0 / 3.0 * e_star() * s[3].sqrt() * d.powf(1.5)
                        })
                        .sum::<f64>()
                        / (lx * ly);
                    assert!((r[2] - p).abs() <= 1e-12 * p, "{name}: {} vs {p}", r[2]);
                }
            }
            let json: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(out.join("curve.json")).expect("json"),
            )
            .expect("json");
            assert_eq!(json["surface"]["shape"][0], 768);
            let dy_json = json["surface"]["pixel_size"][1]
                .as_f64()
                .unwrap_or_default();
            assert!((dy_json - dy).abs() < 1e-14 * dy, "{dy_json:e} {dy:e}");
            let a0 = json["nominal_area"].as_f64().unwrap_or_default();
            assert!((a0 - lx * ly).abs() < 1e-12 * lx * ly, "{a0:e}");
            assert_eq!(json["warnings"].as_array().map(Vec::len), Some(0));
        }
        // Library: summits equal the direct ones; the I solution is a KKT point.
        let law = Homogeneous { e_star: e_star() };
        let rc = RoughContact::from_surface(&law, &s).expect("rc");
        assert_eq!(rc.summits().len(), sm.len());
        for (a, b) in rc.summits().iter().zip(&sm) {
            assert_eq!([a.x, a.y, a.z], [b[0], b[1], b[2]]);
            assert!((a.radius - b[3]).abs() <= 1e-14 * b[3]);
        }
        let delta = rc.top_to_mean();
        let st = rc
            .solve_interacting(delta, Images::Isolated, &[])
            .expect("I model");
        assert!(st.contacts > 20, "{}", st.contacts);
        let r = kkt_direct(&sm, &st.radii, delta, 0, lx, ly);
        eprintln!(
            "{name}: I model isolated, {} contacts, direct KKT residual {r:e}",
            st.contacts
        );
        assert!(r < 1e-8, "{name}: direct KKT residual {r:e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Periodic images with Lx ≠ Ly and dx ≠ dy: the I model with the 3×3 block of cells
/// and the raw image sums (`Params::zero_mean_images` off) is a KKT point of the
/// interaction summed directly over the images (residual < 1e-10 with exact sums, < 1e-5
/// with the default far-field model). The default, zero-mean images are checked against
/// Ewald sums in `zero_mean_images.rs`.
#[test]
fn periodic_images_rectangular_cell() {
    let (n0, n1, dx, dy) = (96usize, 64usize, 1e-5, 2e-5);
    let (lx, ly) = (n0 as f64 * dx, n1 as f64 * dy);
    let z = crate::support::rectangular_cosines(n0, n1, dx, dy);
    let s =
        Surface::with_spacing(z.clone(), n0, n1, Spacing::Pixel(dx, dy), true).expect("surface");
    let sm = direct_summits(&z, n0, n1, dx, dy, true);
    let law = Homogeneous { e_star: e_star() };
    let z_max = sm.iter().map(|s| s[2]).fold(f64::MIN, f64::max);
    let z_min = z.iter().copied().fold(f64::MAX, f64::min);
    let delta = 0.4 * (z_max - z_min);
    for (tol, limit) in [(0.0, 1e-10), (1e-5, 1e-5)] {
        let rc = RoughContact::from_surface(&law, &s)
            .expect("rc")
            .with_params({
                let mut p = strata_runtime::rough::Params::default();
                p.zero_mean_images = false;
                p
            })
            .with_far_field_tolerance(tol);
        assert_eq!(rc.summits().len(), sm.len());
        let st = rc
            .solve_interacting(delta, Images::Periodic(1), &[])
            .expect("I model");
        assert!(st.contacts >= 3, "{}", st.contacts);
        let r = kkt_direct(&sm, &st.radii, delta, 1, lx, ly);
        eprintln!(
            "periodic Lx ≠ Ly, far-field tol {tol}: {} contacts, direct KKT residual {r:e}",
            st.contacts
        );
        assert!(r < limit, "far-field tol {tol}: direct KKT residual {r:e}");
        if tol == 0.0 {
            // Swapping Lx and Ly in the direct sum breaks the conditions: the images
            // are placed on the rectangular lattice, not a square one.
            let wrong = kkt_direct(&sm, &st.radii, delta, 1, ly, lx);
            eprintln!("  with Lx and Ly swapped: {wrong:e}");
            assert!(wrong > 100.0 * r.max(1e-9), "{wrong:e} vs {r:e}");
        }
    }
}

/// Heights in µm: declared as metres they produce warnings naming the RMS height and
/// the RMS slope (stderr and curve.json); with height_unit = "um" the file gives the
/// curve of the same file converted to metres to 1e-12, and the log says so.
#[test]
fn height_units_and_plausibility() {
    let dir = tmp("units");
    let (n0, n1) = (96usize, 80usize);
    let s = small_surface(5);
    let um: Vec<f64> = (0..n0 * n1).map(|k| s.z(k / n1, k % n1) * 1e6).collect();
    let metres: Vec<f64> = um.iter().map(|v| v / 1e6).collect();
    let pixel = Spacing::Pixel(1e-3 / 96.0, 1.2e-3 / 96.0);
    for (name, z) in [("um.npy", &um), ("m.npy", &metres)] {
        Surface::with_spacing(z.clone(), n0, n1, pixel, false)
            .expect("surface")
            .write_npy(&dir.join(name))
            .expect("npy");
    }
    let px = "pixel_size = [1.0416666666666666e-5, 1.25e-5]";
    let load = "approach = { from = 0.5e-6, to = 3e-6, steps = 4 }";
    let mut curves = Vec::new();
    for (name, surface) in [
        (
            "um",
            format!("file = \"um.npy\"\n{px}\nheight_unit = \"um\""),
        ),
        ("m", format!("file = \"m.npy\"\n{px}")),
    ] {
        let sc = scene(&dir, &format!("{name}.toml"), &surface, "independent", load);
        let out = dir.join(name);
        let o = solve_no_plots(&sc, &out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(!err.contains("WARNING"), "{err}");
        if name == "um" {
            assert!(
                err.contains("heights read in um (height_unit = \"um\"), converted to metres"),
                "{err}"
            );
        }
        curves.push(curve(&out));
    }
    assert_eq!(curves[0].len(), 4);
    for (a, b) in curves[0].iter().zip(&curves[1]) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-12 * y.abs().max(1e-300), "{a:?} {b:?}");
        }
    }
    // µm read as metres: loud warnings naming the statistics, recorded in curve.json.
    let sc = scene(
        &dir,
        "wrong.toml",
        &format!("file = \"um.npy\"\n{px}"),
        "independent",
        load,
    );
    let out = dir.join("wrong");
    let o = solve_no_plots(&sc, &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("WARNING: surface: RMS height"), "{err}");
    assert!(err.contains("WARNING: surface: RMS slope"), "{err}");
    assert!(err.contains("heights read as metres (the default"), "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("curve.json")).expect("json"))
            .expect("json");
    let w = json["warnings"].as_array().cloned().unwrap_or_default();
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w[0].as_str().unwrap_or_default().starts_with("RMS height"));
    // Scene errors name the field.
    for (surface, field) in [
        (
            format!("file = \"um.npy\"\n{px}\nheight_unit = \"furlong\""),
            "surface.height_unit",
        ),
        (
            "file = \"um.npy\"\nsize = [1e-3, -1e-3]".to_string(),
            "surface.size[1]",
        ),
        (
            format!("file = \"um.npy\"\n{px}\nsize = 1e-3"),
            "surface.pixel_size",
        ),
        ("file = \"um.npy\"".to_string(), "surface.size"),
        (
            format!("file = \"um.npy\"\n{px}\ndetrend = \"sphere\""),
            "surface.detrend",
        ),
    ] {
        let sc = scene(&dir, "bad.toml", &surface, "independent", load);
        let o = strata(&[
            "solve",
            sc.to_str().unwrap_or_default(),
            "--out",
            dir.join("bad").to_str().unwrap_or_default(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(field), "{field}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// detrend = "plane" on a tilted sample: the log names the removed slopes, and the
/// curve equals that of the untilted sample detrended the same way (least squares is
/// linear; the tilt itself is removed exactly).
#[test]
fn detrend_removes_a_tilt() {
    let dir = tmp("detrend");
    let (n0, n1) = (96usize, 96usize);
    let s = small_surface(9);
    let d = 1e-3 / 96.0;
    let tilted: Vec<f64> = (0..n0 * n1)
        .map(|k| s.heights()[k] + 0.004 * (k / n1) as f64 * d - 0.002 * (k % n1) as f64 * d)
        .collect();
    Surface::new(tilted, n0, n1, 1e-3, false)
        .expect("s")
        .write_npy(&dir.join("tilted.npy"))
        .expect("npy");
    Surface::new(s.heights().to_vec(), n0, n1, 1e-3, false)
        .expect("s")
        .write_npy(&dir.join("flat.npy"))
        .expect("npy");
    let load = "approach = { from = 0.5e-6, to = 3e-6, steps = 4 }";
    let mut curves = Vec::new();
    for name in ["tilted", "flat"] {
        let surface = format!("file = \"{name}.npy\"\nsize = 1e-3\ndetrend = \"plane\"");
        let sc = scene(&dir, &format!("{name}.toml"), &surface, "independent", load);
        let out = dir.join(name);
        let o = solve_no_plots(&sc, &out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(
            err.contains("detrend = \"plane\": removed the least-squares form"),
            "{err}"
        );
        curves.push(curve(&out));
    }
    for (a, b) in curves[0].iter().zip(&curves[1]) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-9 * y.abs().max(1e-300), "{a:?} {b:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
