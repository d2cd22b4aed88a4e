//! The main use case: a measured scan to an FE contact law.
//!
//! - Form removal is on by default for measured files: a non-periodic sample and the
//!   same sample on a tilted stage give the same `strata law` (the removed plane is in
//!   the log and in the JSON's `surface.form`); kept with `detrend = "none"`, the tilt
//!   is warned about.
//! - Validity travels: where the model is outside its validity, the law's CSV and JSON
//!   say so per sample and the Abaqus block's header gives the range.

use std::path::{Path, PathBuf};
use std::process::Output;

use strata_runtime::surface::{GenerateParams, Surface};

use crate::support::{homogeneous_scene, run_strata};

fn tmp(name: &str) -> PathBuf {
    let d = crate::support::scratch().join(format!("measured-law-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn ok(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "strata failed:\n{err}");
    err
}

/// `strata law SCENE --out STEM --format all --samples N` (+ extra arguments).
fn law(scene: &Path, stem: &Path, samples: usize, extra: &[&str]) -> Output {
    let n = samples.to_string();
    let mut args = vec![
        "law",
        scene.to_str().expect("utf-8"),
        "--out",
        stem.to_str().expect("utf-8"),
        "--format",
        "all",
        "--samples",
        &n,
    ];
    args.extend_from_slice(extra);
    run_strata(&args)
}

/// The CSV's header and rows (every column as f64).
fn csv(p: &Path) -> (String, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(p).expect("csv");
    let mut lines = text.lines();
    let header = lines.next().expect("header").to_string();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect();
    (header, rows)
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).expect("json")).expect("valid json")
}

/// A 96×80 window of a generated 128² surface (not periodic: a crop), RMS ~0.5 µm,
/// square pixels of 1e-3/128 m.
fn measured_like() -> (Vec<f64>, usize, usize, f64) {
    let s = Surface::generate(&GenerateParams {
        size: 1e-3,
        grid: 128,
        fractal_dimension: 2.3,
        k_min: 2.0,
        k_max: 16.0,
        rms: 0.5e-6,
        seed: 38,
    })
    .expect("surface");
    let (n0, n1) = (96, 80);
    let z = (0..n0 * n1).map(|k| s.z(k / n1, k % n1)).collect();
    (z, n0, n1, 1e-3 / 128.0)
}

/// A scan and the same scan on a stage tilted by z_x = 1e-2, z_y = 0.5e-2: with the
/// default form removal, `strata law` (N model, and the I model on the isolated
/// sample) gives the same samples to 1e-6 relative (measured ~1e-12 and below), the log
/// names the removed slopes and the JSON's `surface.form` has them (the tilt
/// difference 1e-2, 0.5e-2 to 1e-12); the tilted scan kept with `detrend = "none"`
/// carries a warning (log and JSON `warnings`) advising `detrend = "plane"`.
#[test]
fn a_tilted_scan_gives_the_same_law() {
    let dir = tmp("tilt");
    let (z, n0, n1, d) = measured_like();
    let (sx, sy) = (1e-2, 0.5e-2);
    let tilted: Vec<f64> = z
        .iter()
        .enumerate()
        .map(|(k, h)| h + sx * (k / n1) as f64 * d + sy * (k % n1) as f64 * d)
        .collect();
    for (name, h) in [("scan", &z), ("tilted", &tilted)] {
        Surface::with_spacing(
            h.clone(),
            n0,
            n1,
            strata_runtime::surface::Spacing::Pixel(d, d),
            false,
        )
        .expect("surface")
        .write_npy(&dir.join(format!("{name}.npy")))
        .expect("npy");
    }
    let px = format!("pixel_size = [{d:e}, {d:e}]");
    let load = "approach = { from = 0.2e-6, to = 1.2e-6, steps = 3 }";
    let write_scene = |name: &str, file: &str, extra: &str, model: &str| {
        let p = dir.join(name);
        let surface = format!("file = \"{file}\"\n{px}\n{extra}");
        std::fs::write(&p, homogeneous_scene(&surface, model, load)).expect("scene");
        p
    };
    for (model, samples) in [
        ("\"independent\"", 200),
        ("\"interacting\"\nimages = \"isolated\"", 40),
    ] {
        let tag = if model.contains("independent") {
            "n"
        } else {
            "i"
        };
        let mut laws = Vec::new();
        let mut forms = Vec::new();
        for file in ["scan", "tilted"] {
            let sc = write_scene(
                &format!("{file}-{tag}.toml"),
                &format!("{file}.npy"),
                "",
                model,
            );
            let stem = dir.join(format!("{file}-{tag}"));
            let t0 = std::time::Instant::now();
            let err = ok(&law(&sc, &stem, samples, &[]));
            eprintln!("{tag} {file}: {:.2} s", t0.elapsed().as_secs_f64());
            assert!(
                err.contains("detrend = \"plane\": removed the least-squares form with slopes"),
                "{err}"
            );
            assert!(!err.contains("WARNING"), "{err}");
            let (header, rows) = csv(&stem.with_extension("csv"));
            assert_eq!(
                header,
                "gap,overclosure,mean_pressure,area_fraction,dp_dg,valid"
            );
            laws.push(rows);
            let j = json(&stem.with_extension("json"));
            let f = &j["surface"]["form"];
            assert_eq!(f["detrend"], "plane", "{j}");
            forms.push((
                f["slope_x"].as_f64().expect("slope_x"),
                f["slope_y"].as_f64().expect("slope_y"),
                f["form_rms"].as_f64().expect("form_rms"),
                f["roughness_rms"].as_f64().expect("roughness_rms"),
            ));
            assert!(
                j["warnings"].as_array().expect("warnings").is_empty(),
                "{j}"
            );
        }
        assert!((forms[1].0 - forms[0].0 - sx).abs() < 1e-12, "{forms:?}");
        assert!((forms[1].1 - forms[0].1 - sy).abs() < 1e-12, "{forms:?}");
        assert!(
            (forms[1].3 - forms[0].3).abs() < 1e-12 * forms[0].3,
            "{forms:?}"
        );
        assert!(forms[1].2 > 3.0 * forms[1].3, "{forms:?}");
        let (a, b) = (&laws[0], &laws[1]);
        assert_eq!(a.len(), b.len());
        let mut worst = 0.0f64;
        for (ra, rb) in a.iter().zip(b) {
            for (c, (x, y)) in ra.iter().zip(rb).enumerate() {
                // relative to the column's scale (gaps pass through zero)
                let scale = a
                    .iter()
                    .map(|r| r[c].abs())
                    .fold(0.0f64, f64::max)
                    .max(1e-300);
                worst = worst.max((x - y).abs() / scale);
            }
        }
        eprintln!("{tag}: largest relative difference of the laws {worst:.2e}");
        assert!(worst <= 1e-6, "{worst:e}");
    }

    // Kept tilt: warned, with the advice.
    let sc = write_scene(
        "kept.toml",
        "tilted.npy",
        "detrend = \"none\"",
        "\"independent\"",
    );
    let stem = dir.join("kept");
    let err = ok(&law(&sc, &stem, 50, &[]));
    assert!(
        err.contains("WARNING: surface: detrend = \"none\" keeps a tilt")
            && err.contains("set [surface] detrend = \"plane\""),
        "{err}"
    );
    let j = json(&stem.with_extension("json"));
    assert!(j["surface"]["form"].is_null(), "{j}");
    let w = j["warnings"].as_array().expect("warnings");
    assert!(
        w.iter()
            .any(|w| w.as_str().unwrap_or("").contains("keeps a tilt")),
        "{w:?}"
    );
    // A periodic file keeps its heights; asking for form removal there is refused.
    let sc = write_scene(
        "periodic.toml",
        "scan.npy",
        "periodic = true\ndetrend = \"plane\"",
        "\"independent\"",
    );
    let o = law(&sc, &dir.join("periodic"), 50, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("surface.detrend") && err.contains("not periodic"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The N model sampled past the mean plane and the deepest valley: the CSV's `valid`
/// column is 1 down to g ≥ 0 and 0 below, the JSON's samples say why, and the Abaqus
/// block's header gives the range (`** WARNING: the N model is outside its validity
/// for g <= …`) at the first invalid sample.
#[test]
fn law_validity_reaches_the_abaqus_header() {
    let dir = tmp("validity");
    let params = GenerateParams {
        size: 1e-3,
        grid: 96,
        fractal_dimension: 2.3,
        k_min: 2.0,
        k_max: 16.0,
        rms: 1.7e-6,
        seed: 9,
    };
    let s = Surface::generate(&params).expect("surface");
    let zmin = s.heights().iter().copied().fold(f64::INFINITY, f64::min);
    let valley = zmin - s.mean();
    let surface = "[surface.generate]\nsize = 1e-3\ngrid = 96\nfractal_dimension = 2.3\nk_min = 2\n\
                   k_max = 16\nrms = 1.7e-6\nseed = 9";
    let sc = dir.join("deep.toml");
    let load = "separations = [3e-6, 1e-6]";
    std::fs::write(&sc, homogeneous_scene(surface, "\"independent\"", load)).expect("scene");
    let stem = dir.join("deep");
    let min_gap = format!("{:e}", valley - 0.3e-6);
    let err = ok(&law(&sc, &stem, 101, &["--min-gap", &min_gap]));
    assert!(
        err.contains("warning: law: the N model is outside its validity for g <="),
        "{err}"
    );
    let (header, rows) = csv(&stem.with_extension("csv"));
    assert!(header.ends_with(",valid"), "{header}");
    let first_invalid = rows.iter().position(|r| r[5] == 0.0).expect("invalid rows");
    for r in &rows {
        assert_eq!(r[5], if r[0] >= 0.0 { 1.0 } else { 0.0 }, "{r:?}");
    }
    let g_inv = rows[first_invalid][0];
    let j = json(&stem.with_extension("json"));
    let samples = j["law"].as_array().expect("law");
    assert_eq!(samples.len(), rows.len());
    for (sj, r) in samples.iter().zip(&rows) {
        assert_eq!(sj["valid"].as_bool(), Some(r[5] == 1.0), "{sj}");
        let why = sj["validity"].as_str().expect("validity");
        assert_eq!(why.is_empty(), r[5] == 1.0, "{sj}");
        if r[0] < valley {
            assert!(why.contains("every summit loaded"), "{sj}");
        }
    }
    let warnings = j["validity_warnings"]
        .as_array()
        .expect("validity_warnings");
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let inp = std::fs::read_to_string(stem.with_extension("inp")).expect("inp");
    // The comment header as one line of words (the warning is wrapped over lines).
    let text = inp
        .lines()
        .take_while(|l| l.starts_with("**"))
        .flat_map(|l| l.split_whitespace())
        .filter(|w| *w != "**")
        .collect::<Vec<_>>()
        .join(" ");
    assert!(
        inp.contains("\n** WARNING: the N model is outside its validity"),
        "{inp}"
    );
    let want = format!("WARNING: the N model is outside its validity for g <= {g_inv:.6e} m");
    assert!(text.contains(&want), "{want}\n{text}");
    assert!(
        text.contains("below the mean plane")
            && text.contains("z_M - z_min")
            && text.contains("the law there is an extrapolation of the model"),
        "{text}"
    );
    for l in inp.lines() {
        assert!(l.is_ascii() && l.len() <= 256, "{l}");
    }
    // Inside the surface the law is valid everywhere: no warning, every sample 1.
    let stem = dir.join("shallow");
    let err = ok(&law(&sc, &stem, 50, &[]));
    assert!(!err.contains("outside its validity"), "{err}");
    let (_, rows) = csv(&stem.with_extension("csv"));
    assert!(rows.iter().all(|r| r[5] == 1.0));
    let inp = std::fs::read_to_string(stem.with_extension("inp")).expect("inp");
    assert!(!inp.contains("outside its validity"), "{inp}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `surface info --plot DIR`: the PSD (log–log, round-off bins left out), the height and
/// slope densities beside the Gaussian of the same RMS, and psd.csv; the pictures carry
/// their axis labels with units and a legend placed right of the plot area (readable at
/// single-column size: nothing drawn over the curves). The PSD integrates to the RMS.
#[test]
fn surface_info_plots_psd_and_distributions() {
    let d = crate::support::fresh_dir("measured-law", "info-plot");
    let scene = crate::support::repo().join("scenes/paper-E2E1-5-interacting.toml");
    let out = d.join("plots");
    let o = crate::support::run_strata(&[
        "surface",
        "info",
        scene.to_str().unwrap(),
        "--plot",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (file, labels) in [
        (
            "psd.svg",
            &["wavenumber q (1/m)", "C(q) (m^4)", "radial average"][..],
        ),
        (
            "heights.svg",
            &[
                "height − mean (µm)",
                "probability density (1/µm)",
                "measured",
                "Gaussian, same RMS",
            ][..],
        ),
        (
            "slopes.svg",
            &["probability density (-)", "measured", "Gaussian, same RMS"][..],
        ),
    ] {
        let svg = std::fs::read_to_string(out.join(file)).unwrap();
        for l in labels {
            assert!(svg.contains(l), "{file}: no `{l}`");
        }
        // the legend's text starts right of every grid line of the plot area
        let num = |tag: &str, key: &str| -> Vec<f64> {
            svg.split(tag)
                .skip(1)
                .filter_map(|t| {
                    let i = t.find(key)? + key.len();
                    t[i..].split('"').next()?.parse().ok()
                })
                .collect()
        };
        let grid_right = num("<line", " x2=\"").into_iter().fold(0.0, f64::max);
        let legend = labels.last().unwrap();
        let legend_x = svg
            .split("<text")
            .find(|t| t.contains(legend))
            .and_then(|t| {
                t.split("x=\"")
                    .nth(1)?
                    .split('"')
                    .next()?
                    .parse::<f64>()
                    .ok()
            })
            .unwrap();
        assert!(
            legend_x > grid_right,
            "{file}: legend at x = {legend_x} over the plot (right edge {grid_right})"
        );
    }
    // Parseval on the written bins: Σ C·count·Δq²/(2π)² = RMS² (the scene's 3.4 µm)
    let csv = std::fs::read_to_string(out.join("psd.csv")).unwrap();
    let dq = std::f64::consts::TAU / 1e-3;
    let var: f64 = csv
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            v[1] * v[2]
        })
        .sum::<f64>()
        * dq
        * dq
        / (std::f64::consts::TAU * std::f64::consts::TAU);
    assert!((var.sqrt() / 3.4e-6 - 1.0).abs() < 1e-9, "{}", var.sqrt());
}
