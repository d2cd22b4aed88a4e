//! Real instrument scans (tests/data/measured: a Wyko .opd, a Digital Surf .sur and a
//! Nanosurf .nid map, as they come off the instrument): described raw by `surface info`,
//! read with `repair = "median"` (harmonic fill of the invalid points and spikes, plane
//! removed) and solved with the N model, the I model and the BEM; the order of
//! operations (form removed before spikes are judged) makes a tilt or a quadric change
//! nothing; a pure plane is refused before the solve; a scan declared periodic whose
//! edges do not meet is warned about.

use std::path::{Path, PathBuf};

use strata_runtime::surface::{Detrend, ReadOptions, Repair, Spacing, Surface};

use crate::support::{fresh_dir, homogeneous_scene, repo, run_strata, stderr_of};

/// (name, Lx, Ly, invalid points, their clusters, the largest): the README's figures.
const SCANS: [(&str, f64, f64, usize, usize, usize); 3] = [
    (
        "opd-1",
        1.259091403335333e-4,
        9.443185525014996e-5,
        116,
        3,
        95,
    ),
    (
        "sur-2",
        1.9614921233151107e-3,
        1.6862561060115694e-3,
        117,
        12,
        44,
    ),
    ("nid-1", 2e-5, 2e-5, 0, 0, 0),
];

fn scan(name: &str) -> PathBuf {
    repo()
        .join("tests/data/measured")
        .join(format!("{name}.npy"))
}

/// Heights and shape of a 2-D little-endian f64 C-order .npy (NaN kept).
fn read_raw(p: &Path) -> (Vec<f64>, usize, usize) {
    let b = std::fs::read(p).unwrap();
    let hlen = u16::from_le_bytes([b[8], b[9]]) as usize;
    let head = String::from_utf8_lossy(&b[10..10 + hlen]).into_owned();
    assert!(head.contains("'<f8'") && head.contains("'fortran_order': False"));
    let shape = head.split_once("'shape': (").unwrap().1;
    let shape = shape.split_once(')').unwrap().0;
    let d: Vec<usize> = shape
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let z = b[10 + hlen..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect::<Vec<_>>();
    assert_eq!(z.len(), d[0] * d[1]);
    (z, d[0], d[1])
}

/// Writes heights (NaN kept) as a 2-D f64 .npy.
fn write_raw(p: &Path, z: &[f64], n0: usize, n1: usize) {
    let mut head = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({n0}, {n1}), }}");
    while (10 + head.len() + 1) % 64 != 0 {
        head.push(' ');
    }
    head.push('\n');
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend_from_slice(&(head.len() as u16).to_le_bytes());
    b.extend_from_slice(head.as_bytes());
    for v in z {
        b.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(p, b).unwrap();
}

fn surface_keys(file: &Path, lx: f64, ly: f64, extra: &str) -> String {
    format!("file = {file:?}\nsize = [{lx:e}, {ly:e}]\nrepair = \"median\"\n{extra}")
}

/// RMS height after plane removal and repair (m).
fn roughness(name: &str, lx: f64, ly: f64) -> f64 {
    Surface::read(
        &scan(name),
        &ReadOptions {
            spacing: Some(Spacing::Extent(lx, ly)),
            repair: Repair::Median,
            detrend: Detrend::Plane,
            ..Default::default()
        },
    )
    .unwrap()
    .rms()
}

/// `strata solve` of `scene` into `dir/name`; the curve's rows and curve.json.
fn solve(dir: &Path, name: &str, scene: &str) -> (Vec<Vec<f64>>, serde_json::Value) {
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, scene).unwrap();
    let out = dir.join(name);
    let o = run_strata(&[
        "solve",
        p.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--no-plots",
        "--force",
        "-q",
    ]);
    assert!(o.status.success(), "{name}: {}", stderr_of(&o));
    let csv = std::fs::read_to_string(out.join("curve.csv")).unwrap();
    let rows = crate::support::csv_rows(&csv);
    let json =
        serde_json::from_str(&std::fs::read_to_string(out.join("curve.json")).unwrap()).unwrap();
    (rows, json)
}

/// `surface info` on each raw file exits 0 and prints the counts: the invalid points,
/// their clusters and the largest (the README's figures), the spikes, and what repair
/// would fill.
#[test]
fn info_describes_raw_files() {
    for (name, lx, ly, invalid, clusters, largest) in SCANS {
        let o = run_strata(&[
            "surface",
            "info",
            scan(name).to_str().unwrap(),
            "--size",
            &format!("{lx:e},{ly:e}"),
        ]);
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{name}: {}", stderr_of(&o));
        assert!(
            out.contains(&format!(
                "invalid points (NaN/inf): {invalid} in {clusters} clusters, the largest {largest} points"
            )),
            "{name}: {out}"
        );
        assert!(out.contains("spikes (judged after removing"), "{out}");
        assert!(out.contains("would fill"), "{name}: {out}");
        assert!(out.contains("over the valid points"), "{out}");
        let rms = out
            .lines()
            .find_map(|l| l.strip_prefix("RMS height: "))
            .and_then(|l| l.trim_end_matches(" m").parse::<f64>().ok())
            .expect("RMS height");
        assert!(rms.is_finite() && rms > 0.0, "{name}: {rms}");
    }
}

/// The three scans read with repair = "median" (plane removed) and solve with the N and
/// I models (two approaches each, scaled to the scan's roughness) and, on the smallest
/// (nid-1, 256², its band of spikes filled), the BEM (two steps); curve.json carries
/// the repair report. The BEM on the two larger scans is in `slow_measured_bem`.
#[test]
fn scans_solve_with_n_i_and_bem() {
    let dir = fresh_dir("measured_scans", "solve");
    for (name, lx, ly, invalid, _, _) in SCANS {
        let rms = roughness(name, lx, ly);
        let load = format!(
            "approach = {{ from = {:e}, to = {:e}, steps = 2 }}",
            0.5 * rms,
            0.8 * rms
        );
        let models: &[&str] = if name == "nid-1" {
            &["\"independent\"", "\"interacting\"", "\"bem\""]
        } else {
            &["\"independent\"", "\"interacting\""]
        };
        for model in models {
            let scene = homogeneous_scene(&surface_keys(&scan(name), lx, ly, ""), model, &load);
            let (rows, json) = solve(&dir, &format!("{name}-{}", model.trim_matches('"')), &scene);
            assert_eq!(rows.len(), 2, "{name} {model}");
            // pressure and area grow with the approach, both positive
            assert!(
                rows[0][2] > 0.0 && rows[1][2] > rows[0][2],
                "{name} {model}: {rows:?}"
            );
            assert!(rows[1][4] > rows[0][4] && rows[1][4] < 1.0, "{rows:?}");
            let r = &json["surface"]["repair"];
            assert_eq!(r["invalid"], invalid, "{name}: {r}");
            assert!(r["repaired"].as_u64().unwrap() >= invalid as u64, "{r}");
            assert_eq!(json["surface"]["form"]["detrend"], "plane");
        }
    }
}

/// The BEM on the two larger scans (≈ 10 s each).
#[test]
#[ignore = "slow: run with --ignored"]
fn slow_measured_bem() {
    let dir = fresh_dir("measured_scans", "slow-bem");
    for (name, lx, ly, _, _, _) in &SCANS[..2] {
        let rms = roughness(name, *lx, *ly);
        let load = format!(
            "approach = {{ from = {:e}, to = {:e}, steps = 2 }}",
            0.5 * rms,
            0.8 * rms
        );
        let scene = homogeneous_scene(&surface_keys(&scan(name), *lx, *ly, ""), "\"bem\"", &load);
        let (rows, _) = solve(&dir, &format!("{name}-bem"), &scene);
        assert!(
            rows[0][2] > 0.0 && rows[1][2] > rows[0][2],
            "{name}: {rows:?}"
        );
    }
}

/// Spikes are judged after form removal: a scan with invalid points and spikes (sur-2:
/// 117 NaN, 276 spikes), plain and tilted by 1e-2 in x and 0.5e-2 in y, gives the same
/// N-model curve to 1e-9 (relative) with repair on, and the same repair counts; with a
/// quadric added (sag ≈ 1 µm over the sample, 70 × the roughness) under detrend =
/// "curvature", the same curve as the plain scan under "curvature". Measured: equal to
/// round-off (relative differences below 1e-12).
#[test]
fn tilt_and_quadric_change_nothing() {
    let dir = fresh_dir("measured_scans", "tilt");
    let (name, lx, ly) = ("sur-2", SCANS[1].1, SCANS[1].2);
    let (z, n0, n1) = read_raw(&scan(name));
    let (dx, dy) = (lx / n0 as f64, ly / n1 as f64);
    let with = |f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
        (0..n0 * n1)
            .map(|k| z[k] + f((k / n1) as f64 * dx, (k % n1) as f64 * dy))
            .collect()
    };
    let tilted = dir.join("tilted.npy");
    write_raw(&tilted, &with(&|x, y| 1e-2 * x + 0.5e-2 * y), n0, n1);
    let (cx, cy) = (lx / 2.0, ly / 2.0);
    let quadric = dir.join("quadric.npy");
    let q = |x: f64, y: f64| {
        1e-2 * x + 2e-6 * ((x - cx).powi(2) / (cx * cx) + 0.5 * (x - cx) * (y - cy) / (cx * cy))
            - 1e-6 * (y - cy).powi(2) / (cy * cy)
    };
    write_raw(&quadric, &with(&q), n0, n1);
    let rms = roughness(name, lx, ly);
    let load = format!(
        "approach = {{ from = {:e}, to = {:e}, steps = 3 }}",
        0.4 * rms,
        0.8 * rms
    );
    let run = |tag: &str, file: &Path, extra: &str| {
        let scene = homogeneous_scene(&surface_keys(file, lx, ly, extra), "\"independent\"", &load);
        solve(&dir, tag, &scene)
    };
    let close = |a: &[Vec<f64>], b: &[Vec<f64>], what: &str| {
        assert_eq!(a.len(), b.len());
        let mut worst = 0.0_f64;
        for (ra, rb) in a.iter().zip(b) {
            for (x, y) in ra.iter().zip(rb) {
                worst = worst.max((x - y).abs() / x.abs().max(y.abs()).max(1e-300));
            }
        }
        assert!(worst < 1e-9, "{what}: relative difference {worst:e}");
        eprintln!("{what}: largest relative difference {worst:e}");
    };
    let (plain, jp) = run("plain", &scan(name), "");
    let (tilt, jt) = run("tilted", &tilted, "");
    close(&plain, &tilt, "tilt");
    for key in ["invalid", "spikes", "repaired", "clusters", "largest"] {
        assert_eq!(
            jp["surface"]["repair"][key], jt["surface"]["repair"][key],
            "{key}"
        );
    }
    assert!(jp["surface"]["repair"]["spikes"].as_u64().unwrap() > 0);
    let (plain_c, _) = run("plain-c", &scan(name), "detrend = \"curvature\"");
    let (quad_c, jq) = run("quadric-c", &quadric, "detrend = \"curvature\"");
    close(&plain_c, &quad_c, "quadric");
    assert_eq!(
        jp["surface"]["repair"]["spikes"],
        jq["surface"]["repair"]["spikes"]
    );
}

/// A pure plane (no roughness) with the plane removed is refused before the solve,
/// naming what is left (its RMS, below 1e-11 m) and the form removed.
#[test]
fn pure_plane_refused_before_the_solve() {
    let dir = fresh_dir("measured_scans", "plane");
    let (n0, n1) = (64, 48);
    let z: Vec<f64> = (0..n0 * n1)
        .map(|k| 1e-6 + 1e-3 * (k / n1) as f64 * 1e-6 - 2e-3 * (k % n1) as f64 * 1e-6)
        .collect();
    let f = dir.join("plane.npy");
    write_raw(&f, &z, n0, n1);
    for model in ["\"independent\"", "\"bem\""] {
        let scene = homogeneous_scene(
            &format!("file = {f:?}\npixel_size = [1e-6, 1e-6]"),
            model,
            "approach = { from = 1e-9, to = 2e-9, steps = 2 }",
        );
        let p = dir.join("plane.toml");
        std::fs::write(&p, scene).unwrap();
        let o = run_strata(&[
            "solve",
            p.to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
            "--no-plots",
            "--force",
        ]);
        let e = stderr_of(&o);
        assert!(!o.status.success(), "{model}: {e}");
        assert!(
            e.contains("nothing is left after removing the form (detrend = \"plane\")")
                && e.contains("RMS of")
                && e.contains("slopes z_x"),
            "{model}: {e}"
        );
        assert!(!e.contains("BEM") && !e.contains("summits"), "{model}: {e}");
    }
}

/// A non-periodic scan declared periodic with edges that do not meet is warned about
/// (nid-1: the seam steps are tens of times the steps inside); a periodic generated
/// surface written to a file and declared periodic is not.
#[test]
fn periodic_declared_scan_with_mismatched_edges_is_warned() {
    let dir = fresh_dir("measured_scans", "seams");
    let info = |file: &Path, size: &str| {
        let o = run_strata(&[
            "surface",
            "info",
            file.to_str().unwrap(),
            "--size",
            size,
            "--periodic",
            "--repair",
        ]);
        assert!(o.status.success(), "{}", stderr_of(&o));
        stderr_of(&o)
    };
    let e = info(&scan("nid-1"), "2e-5");
    assert!(
        e.contains("declared periodic") && e.contains("opposite edges do not meet"),
        "{e}"
    );
    let s = crate::support::paper_like_surface(128, 3);
    let f = dir.join("periodic.npy");
    s.write_npy(&f).unwrap();
    let e = info(&f, "1e-3");
    assert!(!e.contains("opposite edges"), "{e}");
}

/// Harmonic fill on a real scan: a 24 × 24 hole punched (inside, and in a corner) into
/// the repaired sur-2 map (plane removed) is filled with heights whose RMS difference
/// from the removed ones stays within 0.5 × the map's RMS height (measured 0.21). A
/// scan rough at the pixel scale gives more: opd-1, whose heights decorrelate within
/// two pixels (RMS slope × pixel = 0.53 RMS height), 0.35 for 4 × 4 holes and 0.87 for
/// 24 × 24 (the fill is smooth, the removed heights are not).
#[test]
fn punched_hole_in_a_real_scan() {
    let (lx, ly) = (SCANS[1].1, SCANS[1].2);
    let opts = ReadOptions {
        spacing: Some(Spacing::Extent(lx, ly)),
        repair: Repair::Median,
        detrend: Detrend::Plane,
        ..Default::default()
    };
    let s = Surface::read(&scan("sur-2"), &opts).unwrap();
    let (n0, n1) = s.shape();
    let rms = s.rms();
    let mut worst = 0.0_f64;
    let side = 24;
    for (i0, j0) in [(200, 300), (400, 100), (0, 0)] {
        let mut z = s.heights().to_vec();
        let hole: Vec<usize> = (i0..i0 + side)
            .flat_map(|i| (j0..j0 + side).map(move |j| i * n1 + j))
            .collect();
        for &k in &hole {
            z[k] = f64::NAN;
        }
        let f = Surface::measured_with(
            z,
            n0,
            n1,
            Spacing::Extent(lx, ly),
            false,
            Repair::Median,
            &strata_runtime::resources::MemoryLimit::default(),
        )
        .unwrap();
        assert!(f.repaired() >= hole.len());
        let d = (hole
            .iter()
            .map(|&k| (f.heights()[k] - s.heights()[k]).powi(2))
            .sum::<f64>()
            / hole.len() as f64)
            .sqrt();
        worst = worst.max(d / rms);
    }
    eprintln!("punched holes: RMS difference / RMS height = {worst:.3}");
    assert!(worst < 0.5, "{worst}");
}

/// The height-unit advice only where the unit is unknown: heights of 34 µm RMS on a 1 mm
/// sample (3.4 %) as .npy are warned about with the advice to set `height_unit`; the same
/// map as .x3p (metres by the standard, `height_unit` refused there) is warned about
/// without it.
#[test]
fn height_unit_advice_only_where_the_unit_is_unknown() {
    let dir = fresh_dir("measured_scans", "unit");
    let s = crate::support::paper_like_surface(64, 5);
    let z: Vec<f64> = s.heights().iter().map(|v| 10.0 * v).collect();
    let big = Surface::new(z, 64, 64, 1e-3, false).unwrap();
    let npy = dir.join("big.npy");
    let x3p = dir.join("big.x3p");
    big.write_npy(&npy).unwrap();
    big.write_x3p(&x3p, &Default::default()).unwrap();
    let info = |args: &[&str]| {
        let o = run_strata(args);
        assert!(o.status.success(), "{}", stderr_of(&o));
        stderr_of(&o)
    };
    let e = info(&["surface", "info", npy.to_str().unwrap(), "--size", "1e-3"]);
    assert!(
        e.contains("RMS height") && e.contains("Set [surface] height_unit"),
        "{e}"
    );
    let e = info(&["surface", "info", x3p.to_str().unwrap()]);
    assert!(e.contains("RMS height"), "{e}");
    assert!(
        !e.contains("height_unit") && e.contains("the file gives its height unit"),
        "{e}"
    );
}
