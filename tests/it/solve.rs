//! End-to-end tests of `strata solve SCENE --out DIR`.

use std::path::{Path, PathBuf};
use std::process::Command;

use strata_runtime::law::Homogeneous;
use strata_runtime::rough::{Images, Model, RoughContact};
use strata_runtime::surface::Surface;

fn reference_surface() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/reference/surface_km10.npy")
}

fn tmp(name: &str) -> PathBuf {
    let d = crate::support::scratch().join(format!("solve-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

const HOMOGENEOUS: &str = r#"
[stack]
[[stack.layer]]
thickness = 1e-3
young = 4e9
poisson = 0.15
[stack.base]
kind = "elastic"
young = 4e9
poisson = 0.15
[surface]
file = "SURFACE"
size = 1e-3
periodic = true
[model]
kind = "KIND"
[load]
separations = [9e-6, 7e-6, 5e-6, 3e-6]
"#;

fn scene(dir: &Path, kind: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let text = HOMOGENEOUS
        .replace("SURFACE", &reference_surface().display().to_string())
        .replace("KIND", kind);
    let p = dir.join("scene.toml");
    std::fs::write(&p, edit(text)).expect("write scene");
    p
}

fn solve(scene: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_strata"))
        .arg("solve")
        .arg(scene)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("run strata")
}

/// The CSV has the fixed header and equals the library's solution (the library is
/// checked against closed forms and the shared reference in its own tests); JSON and
/// plots are written; a non-empty output dir is refused without --force.
#[test]
fn solve_writes_curve_and_refuses_overwrite() {
    let dir = tmp("ok");
    for kind in ["independent", "interacting"] {
        let sc = scene(&dir, kind, |s| s);
        let out = dir.join(format!("out-{kind}"));
        let o = solve(&sc, &out, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(err.contains("simulating:"), "{err}");
        assert!(err.contains("homogeneous"), "{err}");
        let csv = std::fs::read_to_string(out.join("curve.csv")).expect("curve.csv");
        let mut lines = csv.lines();
        assert_eq!(
            lines.next(),
            Some("delta,gap,mean_pressure,pressure_ratio,area_fraction,contacts,stiffness,valid")
        );
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
            .collect();
        assert_eq!(rows.len(), 4);
        let s = Surface::read_npy(&reference_surface(), 1e-3, true).expect("surface");
        let law = Homogeneous {
            e_star: 4e9 / (1.0 - 0.15 * 0.15),
        };
        let rc = RoughContact::from_surface(&law, &s).expect("rc");
        let model = if kind == "independent" {
            Model::Independent
        } else {
            Model::Interacting(Images::Periodic(2))
        };
        let deltas: Vec<f64> = [9e-6, 7e-6, 5e-6, 3e-6]
            .iter()
            .map(|g| rc.delta_for_gap(*g))
            .collect();
        let lib = rc.curve(model, &deltas).expect("library");
        for (r, st) in rows.iter().zip(&lib) {
            assert!((r[1] - st.gap).abs() < 1e-18, "{} {}", r[1], st.gap);
            assert!((r[2] - st.mean_pressure).abs() <= 1e-14 * st.mean_pressure);
            assert!((r[3] - st.pressure_ratio).abs() <= 1e-14 * st.pressure_ratio);
            assert!((r[4] - st.area_fraction).abs() <= 1e-14 * st.area_fraction);
            assert_eq!(r[5] as usize, st.contacts);
            assert!((r[6] - st.stiffness).abs() <= 1e-14 * st.stiffness);
        }
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("curve.json")).expect("json"))
                .expect("valid json");
        assert_eq!(json["steps"].as_array().map(|a| a.len()), Some(4));
        assert!(out.join("pressure_gap.svg").is_file());
        assert!(out.join("area_pressure.svg").is_file());
        // refuse to overwrite, then allow with --force
        let o = solve(&sc, &out, &[]);
        assert!(!o.status.success());
        assert!(String::from_utf8_lossy(&o.stderr).contains("--force"));
        let o = solve(&sc, &out, &["--force"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bad scenes fail with a message naming the field.
#[test]
fn bad_scenes_name_the_field() {
    let dir = tmp("bad");
    // an f32 .npy, written by hand
    let f32npy = dir.join("f32.npy");
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (4, 4), }";
    let mut h = header.to_string();
    while !(10 + h.len() + 1).is_multiple_of(64) {
        h.push(' ');
    }
    h.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(h.len() as u16).to_le_bytes());
    bytes.extend_from_slice(h.as_bytes());
    bytes.extend_from_slice(&[0u8; 64]);
    std::fs::write(&f32npy, bytes).expect("write npy");
    let f32path = f32npy.display().to_string();
    type Edit = Box<dyn Fn(String) -> String>;
    let cases: Vec<(Edit, &str)> = vec![
        (
            Box::new(|s| s.replace("[model]", "[model]\nspeed = 3")),
            "model.speed",
        ),
        (
            Box::new(|s| s.replace(&reference_surface().display().to_string(), "nope.npy")),
            "surface.file",
        ),
        (
            Box::new(move |s| s.replace(&reference_surface().display().to_string(), &f32path)),
            "dtype",
        ),
        (
            Box::new(|s| s.replace("size = 1e-3", "size = -1e-3")),
            "surface.size",
        ),
        (
            Box::new(|s| s.replace("[9e-6, 7e-6, 5e-6, 3e-6]", "[9e-6, 5e-5]")),
            "load.separations[1]",
        ),
        (
            Box::new(|s| s.replace("kind = \"independent\"", "kind = \"fem\"")),
            "model.kind",
        ),
    ];
    for (i, (edit, needle)) in cases.into_iter().enumerate() {
        let sc = scene(&dir, "independent", edit);
        let out = dir.join(format!("out{i}"));
        let o = solve(&sc, &out, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "case {needle} should fail");
        assert!(err.contains(needle), "case {needle}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Through the command: separations below the deepest valley (δ > z_M −
/// z_min) are solved by the I model on an isolated sample, logged as outside the model's
/// validity and flagged per step in curve.json; the first step is inside the surface.
/// With periodic images (the mean displacement removed, as the BEM does) the
/// contacts there cover the cell: that step is refused with the BEM advice, exit 1, and
/// the step before it is written as a partial curve.
#[test]
fn separations_below_the_valley_are_solved_and_flagged() {
    let dir = tmp("deep");
    let deep = |t: String| {
        t.replace(
            "separations = [9e-6, 7e-6, 5e-6, 3e-6]",
            "separations = [3e-6, -2e-5]",
        )
    };
    let sc = scene(&dir, "interacting\"\nimages = \"isolated", deep);
    let out = dir.join("out");
    let o = solve(&sc, &out, &["--no-plots"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("outside the asperity model's validity"),
        "{err}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("curve.json")).expect("json"))
            .expect("valid json");
    let steps = json["steps"].as_array().expect("steps");
    // (step 0: two contact circles overlap on the isolated sample, nothing else)
    assert_eq!(steps[0]["validity"]["beyond_deepest_valley"], false);
    assert_eq!(steps[0]["validity"]["below_mean_plane"], false);
    assert_eq!(steps[1]["validity"]["beyond_deepest_valley"], true);
    assert_eq!(steps[1]["validity"]["below_mean_plane"], true);
    // curve.csv's `valid` column is curve.json's verdict, each with its reason
    let csv = std::fs::read_to_string(out.join("curve.csv")).expect("csv");
    for (line, st) in csv.lines().skip(1).zip(steps) {
        let valid = st["validity"]["valid"].as_bool().expect("valid");
        assert!(
            line.ends_with(if valid { ",1" } else { ",0" }),
            "{line} {st}"
        );
        let reason = st["validity"]["reason"].as_str().expect("reason");
        assert_eq!(reason.is_empty(), valid, "{st}");
    }
    assert!(csv.lines().nth(2).expect("step 1").ends_with(",0"));
    assert!(steps[1]["kkt_residual"].as_f64().expect("kkt") < 1e-8);
    assert!(steps[1]["load"].as_f64().expect("load") > steps[0]["load"].as_f64().expect("load"));
    assert!(json.get("partial").is_none());

    // periodic images: refused at step 1, step 0 kept
    let sc = scene(&dir, "interacting", deep);
    let out = dir.join("out-periodic");
    let o = solve(&sc, &out, &["--no-plots"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains("load step 1")
            && err.contains("model.kind = \"bem\"")
            && err.contains("partial curve"),
        "{err}"
    );
    let csv = std::fs::read_to_string(out.join("curve.csv")).expect("partial curve.csv");
    assert_eq!(csv.lines().count(), 2, "{csv}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("curve.json")).expect("json"))
            .expect("valid json");
    assert_eq!(json["partial"]["failed_step"], 1);
    assert_eq!(json["steps"].as_array().expect("steps").len(), 1);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The approach (m) at which the N model's contact areas on the reference surface of
/// these scenes first sum to more than the nominal area (A/A₀ > 1), doubling from
/// z_M − z_min; and the library's contact (separation = z_M − z̄ − δ).
fn past_full_area() -> (f64, f64) {
    let s = Surface::read_npy(&reference_surface(), 1e-3, true).expect("surface");
    let law = Homogeneous {
        e_star: 4e9 / (1.0 - 0.15 * 0.15),
    };
    let rc = RoughContact::from_surface(&law, &s).expect("rc");
    let mut delta = rc.max_delta();
    for _ in 0..40 {
        let st = rc.solve_independent(delta).expect("N model");
        if st.area_fraction > 1.0 {
            assert!(rc.first_area_above_nominal(&[delta]).is_some());
            return (delta, rc.top_to_mean());
        }
        delta *= 2.0;
    }
    panic!("no approach with A/A0 > 1");
}

/// A load step whose N-model contact areas sum to more than the nominal
/// area (A/A₀ > 1, physically impossible) is refused at once by both asperity models,
/// with the step and the BEM advice; `solve` writes the steps before it (the same as
/// the library's, Newton steps included). The I model is never started on it: with a
/// budget of one energy evaluation (which any I-model Newton step exhausts) the refusal
/// is still the area's, not the budget's; `law` refuses alike.
#[test]
fn steps_past_full_area_are_refused_at_once_with_the_bem_advice() {
    let dir = tmp("full-area");
    let (delta, top) = past_full_area();
    let over = top - delta;
    let three = |t: String| {
        t.replace(
            "separations = [9e-6, 7e-6, 5e-6, 3e-6]",
            &format!("separations = [5e-6, 3e-6, {over:e}]"),
        )
    };
    let s = Surface::read_npy(&reference_surface(), 1e-3, true).expect("surface");
    let law = Homogeneous {
        e_star: 4e9 / (1.0 - 0.15 * 0.15),
    };
    let rc = RoughContact::from_surface(&law, &s).expect("rc");
    for (kind, model, name) in [
        ("independent", Model::Independent, "N model: "),
        (
            "interacting",
            Model::Interacting(Images::Periodic(2)),
            "I model not started: ",
        ),
    ] {
        let sc = scene(&dir, kind, three);
        let out = dir.join(format!("out-{kind}"));
        let o = solve(&sc, &out, &["--no-plots"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{kind}: {err}");
        assert!(
            err.contains("load step 2")
                && err.contains(name)
                && err.contains("A/A₀ = ")
                && err.contains("use model.kind = \"bem\"")
                && err.contains("partial curve"),
            "{kind}: {err}"
        );
        let json: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.join("curve.json")).expect("partial curve.json"),
        )
        .expect("json");
        let steps = json["steps"].as_array().expect("steps");
        assert_eq!(steps.len(), 2, "{kind}");
        let deltas: Vec<f64> = [5e-6, 3e-6].iter().map(|g| rc.delta_for_gap(*g)).collect();
        let lib = rc.curve(model, &deltas).expect("library");
        for (j, st) in steps.iter().zip(&lib) {
            let d = &st.diagnostics;
            assert_eq!(
                j["newton_steps"].as_u64(),
                Some(d.newton_steps as u64),
                "{kind}"
            );
            assert_eq!(
                j["evaluations"].as_u64(),
                Some(d.evaluations as u64),
                "{kind}"
            );
            assert_eq!(j["load"].as_f64(), Some(st.load), "{kind}");
        }

        // one step, a budget no I-model step fits in: refused by the area, not the budget
        let one = |t: String| {
            format!(
                "{}\n[solver]\nmax_step_evaluations = 1\nmax_step_newton_steps = 1\n",
                t.replace(
                    "separations = [9e-6, 7e-6, 5e-6, 3e-6]",
                    &format!("separations = [{over:e}]"),
                )
            )
        };
        let sc = scene(&dir, kind, one);
        let o = solve(&sc, &dir.join(format!("one-{kind}")), &["--no-plots"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{kind}: {err}");
        assert!(
            err.contains(name) && err.contains("model.kind = \"bem\"") && !err.contains("budget"),
            "{kind}: {err}"
        );
        let lo = dir.join(format!("law-{kind}.csv"));
        let o = Command::new(env!("CARGO_BIN_EXE_strata"))
            .args(["law", sc.to_str().unwrap(), "--out", lo.to_str().unwrap()])
            .output()
            .expect("run strata");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{kind}: {err}");
        assert!(
            err.contains("reaches A/A₀ = ")
                && err.contains("model.kind = \"bem\"")
                && !err.contains("budget"),
            "{kind}: {err}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The budgets an error asks to raise are `[solver]` keys, and the error
/// says so: a one-Newton-step budget fails the I model with the key to raise in the
/// scene, Python and C; a scene with the defaults written out gives the same curve as
/// one without `[solver]`.
#[test]
fn solver_budgets_are_scene_keys_named_by_their_errors() {
    let dir = tmp("solver-keys");
    let tight = |t: String| format!("{t}\n[solver]\nmax_step_newton_steps = 1\n");
    let sc = scene(&dir, "interacting", tight);
    let o = solve(&sc, &dir.join("tight"), &["--no-plots"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains("Newton-step budget exhausted")
            && err.contains("raise [solver] max_step_newton_steps in the scene")
            && err.contains("solver={\"max_step_newton_steps\"")
            && err.contains("StrataSolverOptions.max_step_newton_steps"),
        "{err}"
    );
    let defaults = |t: String| {
        format!(
            "{t}\n[solver]\nmax_step_newton_steps = 20000\nmax_step_evaluations = 100000\n\
             kkt_tolerance = 1e-8\nmax_pressure_iterations = 200\n"
        )
    };
    let a = dir.join("plain");
    let b = dir.join("defaults");
    let o = solve(&scene(&dir, "interacting", |t| t), &a, &["--no-plots"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = solve(&scene(&dir, "interacting", defaults), &b, &["--no-plots"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read_to_string(a.join("curve.csv")).unwrap(),
        std::fs::read_to_string(b.join("curve.csv")).unwrap()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The README's main job: the shipped demo stays inside its model's validity —
/// no validity warning on stderr, every step `valid` in curve.csv — and its last step is
/// within one step of where two contact circles begin to overlap (the range is the
/// model's, not a cautious cut).
#[test]
fn main_job_prints_no_validity_warning() {
    let d = crate::support::fresh_dir("solve", "main-job");
    let scene = crate::support::repo().join("scenes/paper-E2E1-5-interacting.toml");
    let o = crate::support::strata_in(&d.join("cache"))
        .arg("solve")
        .arg(&scene)
        .arg("--out")
        .arg(d.join("out"))
        .arg("--no-plots")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(!err.contains("validity"), "{err}");
    let rows = crate::support::csv_rows(&std::fs::read_to_string(d.join("out/curve.csv")).unwrap());
    assert_eq!(rows.len(), 20);
    assert!(rows.iter().all(|r| r[7] == 1.0), "a step outside validity");
    // one step further (the same spacing) two contact circles overlap
    let step = rows[1][0] - rows[0][0];
    let beyond = scene.to_string_lossy().into_owned();
    let text = std::fs::read_to_string(&beyond).unwrap().replace(
        "approach = { from = 1.3e-6, to = 5.3e-6, steps = 20 }",
        &{
            let d = rows[19][0] + 2.5 * step;
            format!("approach = {{ from = {d:e}, to = {d:e}, steps = 1 }}")
        },
    );
    let sc = d.join("beyond.toml");
    std::fs::write(
        &sc,
        text.replace(
            "../tables",
            &crate::support::repo().join("tables").display().to_string(),
        ),
    )
    .unwrap();
    let o = crate::support::strata_in(&d.join("cache"))
        .arg("solve")
        .arg(&sc)
        .arg("--out")
        .arg(d.join("beyond"))
        .arg("--no-plots")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("contact circles overlap"), "{err}");
}
