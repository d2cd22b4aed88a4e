//! `strata solve` with `[output] maps`: the BEM's pressure and gap maps as .npy and
//! PNG pictures (issue 6). The maps must be the solution curve.csv summarises: the mean
//! of the pressure map is curve.csv's mean pressure (1e-12 relative), the contact
//! fraction of the map is its A/A₀ (exact count), and on a half-space the mean of the gap
//! map is the separation g_n (the elastic-base convention of the bem module, 1e-10).

use std::path::{Path, PathBuf};
use std::process::Command;

use strata_bem::read_heights_npy;

const N: usize = 64;

fn dir(name: &str) -> PathBuf {
    let d = crate::support::scratch().join(format!("maps-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small BEM scene: homogeneous half-space (E = 4 GPa, ν = 0.15), generated paper-like
/// surface on a 64² grid, three approaches.
fn scene(d: &Path, kind: &str, output: &str) -> PathBuf {
    let p = d.join("scene.toml");
    std::fs::write(
        &p,
        format!(
            r#"[stack]
[[stack.layer]]
thickness = 1e-3
young = 4e9
poisson = 0.15
[stack.base]
kind = "elastic"
young = 4e9
poisson = 0.15
[surface.generate]
size = 1e-3
grid = {N}
fractal_dimension = 2.4
k_min = 2
k_max = 10
rms = 3.4e-6
seed = 7
[model]
kind = "{kind}"
[load]
approach = {{ from = 1e-6, to = 5e-6, steps = 3 }}
{output}
"#
        ),
    )
    .unwrap();
    p
}

fn strata(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .output()
        .unwrap()
}

fn solve(scene: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "solve",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    strata(&args)
}

/// curve.csv rows as numbers (delta, gap, mean_pressure, pressure_ratio, area_fraction,
/// contacts, stiffness).
fn curve(out: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(out.join("curve.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

/// PNG signature and the IHDR width and height.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(
        &b[..8],
        b"\x89PNG\r\n\x1a\n",
        "{}: not a PNG",
        path.display()
    );
    assert_eq!(&b[12..16], b"IHDR");
    let be = |o: usize| u32::from_be_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
    (be(16), be(20))
}

#[test]
fn bem_maps_match_the_curve() {
    let d = dir("all");
    let sc = scene(&d, "bem", "[output]\nmaps = \"all\"");
    let out = d.join("out");
    let o = solve(&sc, &out, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = curve(&out);
    assert_eq!(rows.len(), 3);
    let index = std::fs::read_to_string(out.join("maps/maps.csv")).unwrap();
    let index: Vec<Vec<String>> = index
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    assert_eq!(index.len(), 3);
    for (k, r) in rows.iter().enumerate() {
        let p = read_heights_npy(&out.join(format!("maps/pressure_step_{k:02}.npy"))).unwrap();
        let g = read_heights_npy(&out.join(format!("maps/gap_step_{k:02}.npy"))).unwrap();
        assert_eq!(p.dim(), (N, N));
        assert_eq!(g.dim(), (N, N));
        let nn = (N * N) as f64;
        let mean_p = p.iter().sum::<f64>() / nn;
        let rel_p = (mean_p / r[2] - 1.0).abs();
        assert!(
            rel_p <= 1e-12,
            "step {k}: mean of map {mean_p:e} vs {:e}",
            r[2]
        );
        let in_contact = p.iter().filter(|&&x| x > 0.0).count() as f64 / nn;
        assert_eq!(in_contact, r[4], "step {k}: contact fraction of the map");
        // The error as the bem module defines it (tolerance 1e-10, σ_z the RMS height):
        // p ≥ 0, max over p > 0 of |g|/σ_z and max over p = 0 of −g/σ_z ≤ 1e-10.
        let sigma = 3.4e-6;
        assert!(p.iter().all(|&x| x >= 0.0));
        let comp = p
            .iter()
            .zip(g.iter())
            .filter(|(a, _)| **a > 0.0)
            .map(|(_, b)| b.abs() / sigma)
            .fold(0.0_f64, f64::max);
        let pen = p
            .iter()
            .zip(g.iter())
            .filter(|(a, _)| **a == 0.0)
            .map(|(_, b)| -b / sigma)
            .fold(0.0_f64, f64::max);
        assert!(comp <= 1e-10 && pen <= 1e-10, "step {k}: {comp:e}, {pen:e}");
        let mean_g = g.iter().sum::<f64>() / nn;
        assert!(
            (mean_g / r[1] - 1.0).abs() <= 1e-10,
            "step {k}: mean gap {mean_g:e} vs g_n {:e}",
            r[1]
        );
        // maps.csv: the same step, patches = curve.csv contacts.
        assert_eq!(index[k][0], k.to_string());
        assert_eq!(index[k][5].parse::<f64>().unwrap(), r[5]);
        assert!(r[5] >= 1.0, "step {k}: no contact patch");
        for pic in ["pressure", "gap"] {
            let size = png_size(&out.join(format!("maps/{pic}_step_{k:02}.png")));
            // 64² magnified ×8 to 512 px, + title band, axes, colour bar and labels.
            assert_eq!(size, strata::plot::heatmap_size(64, 64));
            assert_eq!(strata::plot::heatmap_map_size(64, 64), (512, 512));
        }
    }
}

#[test]
fn last_only_and_no_pictures() {
    let d = dir("last");
    let sc = scene(&d, "bem", "[output]\nmaps = \"last\"");
    let out = d.join("out");
    let o = solve(&sc, &out, &["--no-plots"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut names: Vec<String> = std::fs::read_dir(out.join("maps"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["gap_step_02.npy", "maps.csv", "pressure_step_02.npy"]
    );
}

#[test]
fn no_maps_by_default_and_refused_for_asperity_models() {
    let d = dir("none");
    let out = d.join("out");
    let o = solve(&scene(&d, "bem", ""), &out, &["--no-plots"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.join("maps").exists());
    for kind in ["independent", "interacting"] {
        let d = dir(kind);
        let o = solve(
            &scene(&d, kind, "[output]\nmaps = \"all\""),
            &d.join("out"),
            &[],
        );
        assert!(!o.status.success());
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains("output.maps") && e.contains("bem"), "{e}");
        assert!(!e.contains("panicked"), "{e}");
    }
    let d = dir("bad");
    let o = solve(
        &scene(&d, "bem", "[output]\nmaps = \"some\""),
        &d.join("out"),
        &[],
    );
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("output.maps"));
}
