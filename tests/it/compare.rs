//! `strata compare`: the N model, the I model and the BEM on the same scene.
//! Each column must be the curve `strata solve` gives with that model (1e-12
//! relative), and the differences must be computed right: the signed pressure
//! differences at equal separation from those curves (1e-12), the areas at equal
//! pressure by an independent log–log interpolation of the solve curves (1e-12).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn dir(name: &str) -> PathBuf {
    let d = crate::support::scratch().join(format!("compare-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const HALF_SPACE: &str = r#"[[stack.layer]]
thickness = 1e-3
young = 4e9
poisson = 0.15
[stack.base]
kind = "elastic"
young = 4e9
poisson = 0.15"#;

/// A small scene on a generated paper-like surface (n = 128).
fn scene(d: &Path, name: &str, stack: &str, kind: &str, load: &str) -> PathBuf {
    let p = d.join(format!("{name}.toml"));
    std::fs::write(
        &p,
        format!(
            r#"[stack]
{stack}
[surface.generate]
size = 1e-3
grid = 128
fractal_dimension = 2.4
k_min = 2
k_max = 10
rms = 3.4e-6
seed = 11
[model]
kind = "{kind}"
[load]
{load}
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

fn ok(o: &std::process::Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A CSV as one map per row (empty cells → NaN).
fn csv(path: &Path) -> Vec<HashMap<String, f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(|x| x.parse().unwrap_or(f64::NAN)))
                .collect()
        })
        .collect()
}

/// `strata solve` of `scene` with `model.kind` replaced: its curve.csv rows.
fn solve_with(scene: &Path, kind: &str, d: &Path) -> Vec<HashMap<String, f64>> {
    let text = std::fs::read_to_string(scene).unwrap();
    let stem = scene.file_stem().unwrap().to_string_lossy().into_owned();
    let s = d.join(format!("solve-{stem}-{kind}.toml"));
    let replaced = text
        .lines()
        .map(|l| {
            if l.starts_with("kind = \"") && !l.contains("elastic") && !l.contains("rigid") {
                format!("kind = \"{kind}\"")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&s, replaced).unwrap();
    let out = d.join(format!("solve-{stem}-{kind}"));
    ok(&strata(&[
        "solve",
        s.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--no-plots",
    ]));
    csv(&out.join("curve.csv"))
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

/// The test's own log–log interpolation of A(p) from a curve (independent of the CLI).
fn area_at(curve: &[HashMap<String, f64>], p: f64) -> f64 {
    let mut pts: Vec<(f64, f64)> = curve
        .iter()
        .map(|r| (r["mean_pressure"], r["area_fraction"]))
        .filter(|(p, a)| *p > 0.0 && *a > 0.0)
        .collect();
    pts.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
    for w in pts.windows(2) {
        let ((p0, a0), (p1, a1)) = (w[0], w[1]);
        if p0 <= p && p <= p1 {
            let t = (p.ln() - p0.ln()) / (p1.ln() - p0.ln());
            return (a0.ln() + t * (a1.ln() - a0.ln())).exp();
        }
    }
    f64::NAN
}

/// Checks compare.csv of `scene` against three `strata solve` runs.
fn check_columns(scene: &Path, cmp: &Path, d: &Path) {
    let rows = csv(&cmp.join("compare.csv"));
    let bem = solve_with(scene, "bem", d);
    let n = solve_with(scene, "independent", d);
    let i = solve_with(scene, "interacting", d);
    assert_eq!(rows.len(), bem.len());
    let mut compared = 0;
    for (k, r) in rows.iter().enumerate() {
        // The BEM column is the BEM solve.
        assert!(
            close(r["p_bem"], bem[k]["mean_pressure"], 1e-12),
            "step {k}"
        );
        assert!(close(r["separation"], bem[k]["gap"], 1e-12), "step {k}");
        assert!(
            close(r["area_bem"], bem[k]["area_fraction"], 1e-12),
            "step {k}"
        );
        assert_eq!(r["contacts_bem"], bem[k]["contacts"]);
        for (tag, curve) in [("n", &n), ("i", &i)] {
            // Approach loads: the model's step k has the BEM's separation.
            assert!(close(curve[k]["gap"], bem[k]["gap"], 1e-12), "step {k}");
            let p = curve[k]["mean_pressure"];
            assert!(close(r[&format!("p_{tag}")], p, 1e-12), "step {k} p_{tag}");
            assert!(
                close(r[&format!("area_{tag}")], curve[k]["area_fraction"], 1e-12),
                "step {k} area_{tag}"
            );
            let rel = p / bem[k]["mean_pressure"] - 1.0;
            assert!(
                (r[&format!("rel_p_{tag}")] - rel).abs() <= 1e-12,
                "step {k} rel_p_{tag}"
            );
            let a = area_at(curve, bem[k]["mean_pressure"]);
            let got = r[&format!("area_{tag}_at_p")];
            if a.is_nan() {
                assert!(
                    got.is_nan(),
                    "step {k}: area_{tag}_at_p {got} outside the curve"
                );
            } else {
                compared += 1;
                assert!(
                    close(got, a, 1e-12),
                    "step {k} area_{tag}_at_p {got} vs {a}"
                );
                let rel = a / bem[k]["area_fraction"] - 1.0;
                assert!((r[&format!("rel_area_{tag}")] - rel).abs() <= 1e-12);
            }
        }
    }
    assert!(
        compared >= rows.len(),
        "too few areas at equal pressure compared"
    );
}

#[test]
fn columns_equal_separate_solves_and_differences_are_right() {
    let d = dir("one");
    let sc = scene(
        &d,
        "half-space",
        HALF_SPACE,
        "interacting",
        "approach = { from = 1e-6, to = 6e-6, steps = 6 }",
    );
    let out = d.join("out");
    ok(&strata(&[
        "compare",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]));
    check_columns(&sc, &out, &d);
    let md = std::fs::read_to_string(out.join("compare.md")).unwrap();
    for needle in [
        "N model (independent)",
        "I model (periodic images, 5×5 cells)",
        "BEM (reference)",
        "wall time (s)",
    ] {
        assert!(md.contains(needle), "compare.md lacks {needle}:\n{md}");
    }
    for f in [
        "pressure_gap.svg",
        "area_pressure.svg",
        "curve_bem.csv",
        "curve_independent.csv",
        "curve_interacting.csv",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    // A non-empty --out is refused without --force.
    let o = strata(&[
        "compare",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--force"));
}

#[test]
fn several_scenes_pressure_loads_and_layered_stack() {
    let d = dir("many");
    let a = scene(
        &d,
        "half-space",
        HALF_SPACE,
        "bem",
        "approach = { from = 1e-6, to = 6e-6, steps = 4 }",
    );
    let layered = format!(
        "file = \"{}\"\ntable = \"{}\"",
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tables/stacks/paper-two-layer.toml")
            .display(),
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tables/paper-two-layer.strata")
            .display()
    );
    let b = scene(
        &d,
        "layered",
        &layered,
        "independent",
        "mean_pressures = [1e6, 3e6, 1e7]",
    );
    let out = d.join("out");
    let o = strata(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--labels",
        "half-space,E2/E1 = 5",
    ]);
    ok(&o);
    for f in [
        "compare.md",
        "pressure_gap.svg",
        "area_pressure.svg",
        "pressure_gap_I_bem.svg",
        "area_pressure_I_bem.svg",
        "half-space/compare.csv",
        "layered/compare.csv",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let md = std::fs::read_to_string(out.join("compare.md")).unwrap();
    assert!(
        md.contains("## half-space") && md.contains("## E2/E1 = 5"),
        "{md}"
    );
    check_columns(&a, &out.join("half-space"), &d);
    // Pressure loads: every model solves the same p̄, so the area at equal pressure is
    // each model's own step (exact), and the pressures at the BEM separations are
    // interpolated (finite where the BEM separation lies inside the model's range).
    let rows = csv(&out.join("layered/compare.csv"));
    let n = solve_with(&b, "independent", &d);
    let bem = solve_with(&b, "bem", &d);
    for (k, r) in rows.iter().enumerate() {
        assert!(close(r["p_bem"], 1e6 * [1.0, 3.0, 10.0][k], 1e-9));
        assert!(close(r["area_n_at_p"], n[k]["area_fraction"], 1e-12));
        let rel = n[k]["area_fraction"] / bem[k]["area_fraction"] - 1.0;
        assert!((r["rel_area_n"] - rel).abs() <= 1e-12);
    }
    // Wrong label count: a clear error, no output.
    let o = strata(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out",
        d.join("out2").to_str().unwrap(),
        "--labels",
        "only-one",
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--labels"));
}

/// A non-periodic measured scan (the shared reference surface read as an isolated
/// sample): compare runs the three models (I model without images, BEM on the unbounded
/// solid) and every column is the curve of `strata solve` with that model.
#[test]
fn non_periodic_scan_is_compared_as_an_isolated_sample() {
    let d = dir("nonperiodic");
    let npy = crate::support::repo().join("tests/reference/surface_km10.npy");
    let sc = d.join("s.toml");
    std::fs::write(
        &sc,
        format!(
            "[stack]\n{HALF_SPACE}\n[surface]\nfile = \"{}\"\nsize = 1e-3\nperiodic = false\n\
             [model]\nkind = \"independent\"\n[load]\napproach = {{ from = 1e-6, to = 4e-6, steps = 4 }}\n",
            npy.display()
        ),
    )
    .unwrap();
    let cmp = d.join("out");
    let o = strata(&[
        "compare",
        sc.to_str().unwrap(),
        "--out",
        cmp.to_str().unwrap(),
        "--no-plots",
    ]);
    ok(&o);
    let md = std::fs::read_to_string(cmp.join("compare.md")).unwrap();
    assert!(md.contains("isolated sample"), "{md}");
    check_columns(&sc, &cmp, &d);
}
