//! `[friction]`: the full-stick tangential stiffness of the N and I models' steps (the
//! engine's `effects::friction`), against independent truth — Mindlin's 8μa/(2 − ν) per
//! contact disc on a half-space summed over the model's own radii, and Mindlin's ratio
//! K_t/K_n = 2(1 − ν)/(2 − ν) against the Hertz summits' dP/dδ = Σ 2E*a — and on a
//! layered stack against direct Fredholm solves of each disc; through `strata solve`
//! (the `tangential_stiffness` column) and the scene's refusals.

use strata::engine::{EngineOptions, Quiet, solve};
use strata::scene::Scene;
use strata_runtime::Stack;
use strata_tablegen::stiffness::Stiffness;

use crate::support::{csv_rows, fresh_dir, homogeneous_scene, repo, stderr_of};

const E: f64 = 4e9;
const NU: f64 = 0.15;

const SURFACE: &str = "periodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 256\n\
    fractal_dimension = 2.4\nk_min = 2\nk_max = 10\nrms = 3.4e-6\nseed = 20240611";

fn scene_at(dir: &std::path::Path, name: &str, text: &str) -> Scene {
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    Scene::from_file(&p).unwrap()
}

/// On a homogeneous half-space (E = 4 GPa, ν = 0.15), the N and I models' tangential
/// stiffness of each step equals Σ 8μa_i/(2 − ν) over the step's own contact radii
/// (the I model's interacting ones), and the N model's K_t/K_n equals Mindlin's
/// 2(1 − ν)/(2 − ν) (K_n = Σ 2E*a_i, the Hertz summits' dP/dδ) at every step.
#[test]
fn half_space_is_mindlin_per_asperity() {
    let d = fresh_dir("friction", "half_space");
    let mu = E / (2.0 * (1.0 + NU));
    let mindlin = 2.0 * (1.0 - NU) / (2.0 - NU);
    let opts = EngineOptions {
        cache_dir: Some(d.join("cache")),
        ..Default::default()
    };
    let mut worst = [0.0f64; 2];
    for (model, extra) in [("\"independent\"", ""), ("\"interacting\"", "")] {
        let text = homogeneous_scene(
            SURFACE,
            &format!("{model}{extra}"),
            "approach = { from = 2e-6, to = 8e-6, steps = 4 }",
        ) + "[friction]\ncoefficient = 0.3\n";
        let scene = scene_at(&d, model.trim_matches('"'), &text);
        let sol = solve(&scene, None, &opts, &mut Quiet).unwrap();
        let kt = sol.tangential_stiffnesses().unwrap();
        assert_eq!(kt.len(), 4);
        for (s, k) in sol.steps.iter().zip(&kt) {
            let sum: f64 = s.radii.iter().map(|a| 8.0 * mu * a / (2.0 - NU)).sum();
            assert!(s.contacts > 0 && sum > 0.0);
            worst[0] = worst[0].max((k / sum - 1.0).abs());
            if model == "\"independent\"" {
                worst[1] = worst[1].max((k / s.stiffness / mindlin - 1.0).abs());
            }
        }
        assert_eq!(
            sol.effect_columns().last().map(|c| c.0),
            Some("tangential_stiffness")
        );
        let f = sol.summary.friction.as_ref().unwrap();
        assert_eq!(f.coefficient, 0.3);
        assert_eq!(f.table_decades, None, "a half-space needs no table");
    }
    eprintln!(
        "half-space: K_t vs Σ 8μa/(2−ν) {:.1e}, K_t/K_n vs Mindlin {:.1e}",
        worst[0], worst[1]
    );
    // measured 2.2e-16 and 3.3e-16 (round-off of the sums)
    assert!(worst[0] < 5e-15, "{worst:?}");
    assert!(worst[1] < 5e-15, "{worst:?}");
}

/// On the paper's two-layer stack (E2/E1 = 5), the N model's K_t of each step (from
/// the disc-stiffness table in the cache) equals the sum of direct Fredholm solves of
/// each contact disc (1e−5, the table's requirement); a second solve reads the table
/// from the cache and gives the same bits; `strata solve` writes the column.
#[test]
fn layered_n_model_against_direct_disc_solves() {
    let d = fresh_dir("friction", "layered");
    let text = std::fs::read_to_string(repo().join("scenes/paper-E2E1-5-independent.toml"))
        .unwrap()
        .replace("grid = 512", "grid = 256")
        .replace("steps = 20", "steps = 3")
        .replace("../tables", &repo().join("tables").display().to_string())
        + "\n[friction]\ncoefficient = 0.5\n";
    let scene = scene_at(&d, "layered", &text);
    let opts = EngineOptions {
        cache_dir: Some(d.join("cache")),
        ..Default::default()
    };
    let sol = solve(&scene, None, &opts, &mut Quiet).unwrap();
    let kt = sol.tangential_stiffnesses().unwrap();
    let stack = Stack::paper_two_layer(5.0).unwrap();
    let direct = Stiffness::new(&stack);
    let mut worst = 0.0f64;
    // the last step (every radius of the path's deepest step), all its discs
    let s = sol.steps.last().unwrap();
    let sum: f64 = s
        .radii
        .iter()
        .filter(|a| **a > 0.0)
        .map(|&a| direct.at(a).unwrap().tangential)
        .sum();
    worst = worst.max((kt.last().unwrap() / sum - 1.0).abs());
    eprintln!("layered N model: K_t (table) vs Σ direct solves {worst:.1e}");
    // requirement 1e-5 (the table's); measured 3.2e-13 (a/h1 = 1e-2 … 1e-1 here)
    assert!(worst < 3e-12, "{worst}");
    assert!(
        sol.summary
            .friction
            .as_ref()
            .unwrap()
            .table_decades
            .is_some()
    );
    let again = solve(&scene, None, &opts, &mut Quiet).unwrap();
    assert_eq!(again.tangential_stiffnesses().unwrap(), kt);
    // through the command: the column last, K_t growing with the load
    let (o, out) = crate::support::solve_text(&d, "cli", &text);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let csv = std::fs::read_to_string(out.join("curve.csv")).unwrap();
    assert!(
        csv.lines()
            .next()
            .unwrap()
            .ends_with(",valid,tangential_stiffness"),
        "{csv}"
    );
    let rows = csv_rows(&csv);
    let col: Vec<f64> = rows.iter().map(|r| *r.last().unwrap()).collect();
    for (c, k) in col.iter().zip(&kt) {
        assert!((c / k - 1.0).abs() < 1e-15, "{col:?} {kt:?}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("curve.json")).unwrap()).unwrap();
    assert_eq!(json["friction"]["coefficient"].as_f64(), Some(0.5));
    assert!(json["steps"][0]["tangential_stiffness"].as_f64().unwrap() > 0.0);
}

/// `[friction]` refusals name the file and the field; a scene without it writes no
/// column.
#[test]
fn friction_table_errors_name_the_field() {
    let d = fresh_dir("friction", "errors");
    let base = homogeneous_scene(SURFACE, "\"independent\"", "mean_pressures = [1e5]");
    for (tail, needle) in [
        ("[friction]\ncoefficient = 0\n", "friction.coefficient"),
        ("[friction]\ncoefficient = -0.2\n", "friction.coefficient"),
        ("[friction]\ncoefficient = nan\n", "friction.coefficient"),
        ("[friction]\ncoefficient = inf\n", "friction.coefficient"),
        ("[friction]\n", "friction.coefficient"),
        (
            "[friction]\ncoefficient = 0.3\nstatic = 1\n",
            "friction.static",
        ),
        (
            "[friction]\ncoefficient = \"high\"\n",
            "friction.coefficient",
        ),
    ] {
        let (o, out) = crate::support::solve_text(&d, "bad", &(base.clone() + tail));
        let err = stderr_of(&o);
        assert!(!o.status.success(), "{tail}");
        assert!(err.contains(needle), "{tail}: {err}");
        assert!(err.contains("bad.toml"), "{tail}: {err}");
        assert!(!out.join("curve.csv").exists());
    }
    // The BEM serves `[friction]`: the full-stick K_t of each step's contact set,
    // positive and growing with the load.
    let bem = homogeneous_scene(SURFACE, "\"bem\"", "mean_pressures = [1e5, 3e5]")
        + "[friction]\ncoefficient = 0.3\n";
    let (o, out) = crate::support::solve_text(&d, "bem", &bem);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let k = last_column(&std::fs::read_to_string(out.join("curve.csv")).unwrap());
    assert_eq!(k.len(), 2);
    assert!(k[0] > 0.0 && k[1] > k[0] && k[1].is_finite(), "{k:?}");
    let (o, out) = crate::support::solve_text(&d, "plain", &base);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let csv = std::fs::read_to_string(out.join("curve.csv")).unwrap();
    assert!(!csv.contains("tangential_stiffness"), "{csv}");
}

/// The `tangential_stiffness` column of `csv` (the last).
fn last_column(csv: &str) -> Vec<f64> {
    let header = csv.lines().next().unwrap();
    assert!(header.ends_with(",tangential_stiffness"), "{header}");
    csv.lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect()
}

/// `strata compare` and `strata sweep` give the same tangential_stiffness as
/// `strata solve` of the same scene, for the N and I models and the BEM (bit for bit:
/// the same solve); a sweep whose base scene has `[load] tangential` is refused, naming
/// the field.
#[test]
fn compare_and_sweep_equal_solve() {
    let d = fresh_dir("friction", "front_ends");
    let surface = SURFACE
        .replace("grid = 256", "grid = 64")
        .replace("k_max = 10", "k_max = 8");
    let load = "separations = [6e-6, 4.5e-6, 3e-6]";
    let mut solved = Vec::new();
    for model in ["independent", "interacting"] {
        let text = homogeneous_scene(
            &surface,
            &format!("\"{model}\"\nimages = \"isolated\""),
            load,
        ) + "[friction]\ncoefficient = 0.3\n";
        let (o, out) = crate::support::solve_text(&d, model, &text);
        assert!(o.status.success(), "{}", stderr_of(&o));
        solved.push(last_column(
            &std::fs::read_to_string(out.join("curve.csv")).unwrap(),
        ));
    }
    let bem_text = homogeneous_scene(&surface, "\"bem\"", load) + "[friction]\ncoefficient = 0.3\n";
    let (o, out) = crate::support::solve_text(&d, "bem", &bem_text);
    assert!(o.status.success(), "{}", stderr_of(&o));
    solved.push(last_column(
        &std::fs::read_to_string(out.join("curve.csv")).unwrap(),
    ));
    assert!(solved[0].iter().all(|k| *k > 0.0), "{solved:?}");
    assert!(solved[2].iter().all(|k| *k > 0.0), "{solved:?}");
    // compare on the I model's scene: curve_independent.csv and curve_interacting.csv carry the column
    let scene = d.join("interacting.toml");
    let cmp = d.join("compare");
    let o = crate::support::run_strata(&[
        "compare",
        scene.to_str().unwrap(),
        "--out",
        cmp.to_str().unwrap(),
        "--no-plots",
    ]);
    assert!(o.status.success(), "{}", stderr_of(&o));
    for (file, want) in [
        ("curve_independent.csv", &solved[0]),
        ("curve_interacting.csv", &solved[1]),
        ("curve_bem.csv", &solved[2]),
    ] {
        let got = last_column(&std::fs::read_to_string(cmp.join(file)).unwrap());
        assert_eq!(&got, want, "{file}");
    }
    // sweep over the two models
    let base = homogeneous_scene(&surface, "\"independent\"\nimages = \"isolated\"", load)
        + "[friction]\ncoefficient = 0.3\n";
    let nested: String = base
        .lines()
        .map(|l| match l.strip_prefix('[') {
            Some(rest) if rest.starts_with('[') => format!("[[scene.{}", &rest[1..]),
            Some(rest) => format!("[scene.{rest}"),
            None => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    let sweep = d.join("sweep.toml");
    std::fs::write(
        &sweep,
        format!("{nested}\n[sweep]\nmodel.kind = [\"independent\", \"interacting\"]\n"),
    )
    .unwrap();
    let out = d.join("sweep");
    let o = crate::support::run_strata(&[
        "sweep",
        sweep.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--no-plots",
    ]);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let col = last_column(&csv);
    assert_eq!(col.len(), 6);
    assert_eq!(&col[..3], &solved[0][..]);
    assert_eq!(&col[3..], &solved[1][..]);
    // the BEM's column too
    std::fs::write(
        &sweep,
        format!("{nested}\n[sweep]\nmodel.kind = [\"independent\", \"bem\"]\n"),
    )
    .unwrap();
    let out = d.join("sweep-bem");
    let o = crate::support::run_strata(&[
        "sweep",
        sweep.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--no-plots",
    ]);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let col = last_column(&std::fs::read_to_string(out.join("sweep.csv")).unwrap());
    assert_eq!(col.len(), 6);
    assert_eq!(&col[..3], &solved[0][..]);
    assert_eq!(&col[3..], &solved[2][..]);
    // a tangential path is `strata solve`'s: refused in a sweep, naming the field
    let with_path = nested
        .replace(
            "[scene.model]\nkind = \"independent\"",
            "[scene.model]\nkind = \"bem\"",
        )
        .replace(
            load,
            &format!("{load}\ntangential = {{ from = 0.1, to = 0.5, steps = 2 }}"),
        );
    assert!(with_path.contains("tangential ="), "{with_path}");
    std::fs::write(
        &sweep,
        format!("{with_path}\n[sweep]\nsurface.seed = [1, 2]\n"),
    )
    .unwrap();
    let o = crate::support::run_strata(&[
        "sweep",
        sweep.to_str().unwrap(),
        "--out",
        d.join("sweep-path").to_str().unwrap(),
        "--no-plots",
    ]);
    assert!(!o.status.success());
    let err = stderr_of(&o);
    assert!(err.contains("load.tangential"), "{err}");
}

/// `strata law` on a `[friction]` scene: the law's `tangential_stiffness` column equals
/// `strata solve`'s at the law's own separations, bit for bit (the same steps), and the
/// first-contact row is `0e0` (an empty f64 sum is −0 and printed `-0e0`).
#[test]
fn law_column_equals_solve_at_its_samples() {
    let d = fresh_dir("friction", "law");
    let scene = d.join("law.toml");
    let text = homogeneous_scene(
        &SURFACE.replace("grid = 256", "grid = 128"),
        "\"independent\"",
        "mean_pressures = [1e5, 1e7]",
    ) + "[friction]\ncoefficient = 0.3\n";
    std::fs::write(&scene, &text).unwrap();
    let law = d.join("law.csv");
    let o = crate::support::strata_in(&d)
        .args(["law", "--samples", "20", "-q", "--out"])
        .arg(&law)
        .arg(&scene)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    let csv = std::fs::read_to_string(&law).unwrap();
    assert!(!csv.contains("-0e0"), "{csv}");
    assert!(csv.starts_with("gap,"), "{csv}");
    let gaps: Vec<f64> = csv_rows(&csv).iter().map(|r| r[0]).collect();
    let kt = last_column(&csv);
    assert_eq!(kt[0], 0.0);
    let pick = [1, 7, 13, 19];
    let list: Vec<String> = pick.iter().map(|&i| format!("{:?}", gaps[i])).collect();
    let at = d.join("at.toml");
    std::fs::write(
        &at,
        text.replace(
            "mean_pressures = [1e5, 1e7]",
            &format!("separations = [{}]", list.join(", ")),
        ),
    )
    .unwrap();
    let out = d.join("out");
    let o = crate::support::strata_in(&d)
        .args(["solve", "--no-plots", "-q", "--out"])
        .arg(&out)
        .arg(&at)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    let curve = last_column(&std::fs::read_to_string(out.join("curve.csv")).unwrap());
    assert_eq!(curve.len(), pick.len());
    for (&i, k) in pick.iter().zip(&curve) {
        assert!(kt[i] > 0.0);
        assert_eq!(*k, kt[i], "sample {i}");
    }
}

/// On a half-space with ν = 0 the full-stick tangential problem is the normal one:
/// Cerruti's kernel u_x = Q/(πE r) (its ν x²/r³ and ν x y/r³ terms vanish) equals
/// Boussinesq's w = (1 − ν²)P/(πE r), so the BEM's K_t of a step's contact set (a uniform
/// tangential displacement) is the flat-punch stiffness of that set, which is the step's
/// dP/dδ (the `stiffness` column, the tangent on the same set). Measured:
/// |K_t/K_n − 1| ≤ 3.7e-10 up to A/A₀ = 7 % at 256² (against the finite difference the
/// stiffness was before, 2.1e-7; 2.0e-4 at A/A₀ = 20 %, where its contact set grew).
#[test]
fn bem_full_stick_stiffness_on_a_nu_zero_half_space_is_the_normal_one() {
    let d = fresh_dir("friction", "bem_nu_zero");
    let surface = SURFACE.replace("periodic = true\n", "");
    let scene = format!(
        "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.0\n\
         [surface]\nperiodic = true\n{surface}\n[model]\nkind = \"bem\"\n\
         [load]\nmean_pressures = [1e5, 1e6, 1e7]\n[friction]\ncoefficient = 0.3\n"
    );
    let (o, out) = crate::support::solve_text(&d, "nu0", &scene);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let csv = std::fs::read_to_string(out.join("curve.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (kn, kt, area) = (
        col("stiffness"),
        col("tangential_stiffness"),
        col("area_fraction"),
    );
    let mut worst = 0.0f64;
    for line in csv.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        assert!(v[area] > 0.0 && v[area] < 0.1, "{line}");
        worst = worst.max((v[kt] / v[kn] - 1.0).abs());
    }
    eprintln!("nu = 0 half-space: worst |K_t/K_n - 1| = {worst:.1e}");
    // measured 3.7e-10 (the full-stick solve stops at a tolerance of 1e-8, the tangent
    // at 1e-13; 2.1e-7 against the finite difference the stiffness was before)
    assert!(worst < 4e-9, "{worst:e}\n{csv}");
}

/// The rows of a CSV by column name.
fn columns(csv: &str) -> std::collections::HashMap<String, Vec<f64>> {
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let rows = csv_rows(csv);
    header
        .iter()
        .enumerate()
        .map(|(k, h)| (h.to_string(), rows.iter().map(|r| r[k]).collect()))
        .collect()
}

/// The half-space sphere scene of the tangential path: E = 1 GPa, ν = 0.3, R = 5 mm on a
/// periodic n² cell of side L = 1 mm, pressed to Hertz's contact radius a = 0.12 L
/// (P = 4E*a³/(3R)), μ = 0.3, and `[load] tangential = { tangential }`. Returns the scene
/// text (the sphere written beside it as sphere.npy), P (N), a (m), G and ν. The
/// paraboloid's kinks across the cell's edges, heights −L²/(8R) and below, far out of
/// contact, read as spikes: `repair = "median"` smooths them there.
fn sphere_scene(dir: &std::path::Path, n: usize, tangential: &str) -> (String, f64, f64, f64, f64) {
    let (e, nu, l, r) = (1.0e9, 0.3, 1.0e-3, 5.0e-3);
    let mut z = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let x = (i as f64 - (n / 2) as f64) * l / n as f64;
            let y = (j as f64 - (n / 2) as f64) * l / n as f64;
            z[i * n + j] = -(x * x + y * y) / (2.0 * r);
        }
    }
    strata_runtime::surface::Surface::new(z, n, n, l, true)
        .unwrap()
        .write_npy(&dir.join("sphere.npy"))
        .unwrap();
    let e_star = e / (1.0 - nu * nu);
    let a = 0.12 * l;
    let p = 4.0 * e_star * a.powi(3) / (3.0 * r);
    let text = format!(
        "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = {e:e}\npoisson = {nu}\n\
         [surface]\nfile = \"sphere.npy\"\nsize = {l:e}\nperiodic = true\ndetrend = \"none\"\n\
         repair = \"median\"\n\
         [model]\nkind = \"bem\"\n[load]\nmean_pressures = [{:e}]\ntangential = {tangential}\n\
         [friction]\ncoefficient = 0.3\n",
        p / (l * l)
    );
    (text, p, a, e / (2.0 * (1.0 + nu)), nu)
}

/// `[load] tangential` on a sphere pressed on a half-space (the BEM, uncoupled): the
/// stick area over the contact area of tangential.csv equals Cattaneo–Mindlin's
/// (c/a)² = (1 − Q/μP)^(2/3) and the displacement's part beyond the full-stick line,
/// δ_t − Q/K_t (K_t the `tangential_stiffness` of curve.csv), equals Cattaneo–Mindlin's
/// δ_CM − Q/K_M, δ_CM = 3μP(2 − ν)/(16Ga)·(1 − (1 − Q/μP)^(2/3)), K_M = 8Ga/(2 − ν)
/// (Johnson 7.42; the periodic cell adds the same compliance to both); Q equals
/// (Q/μP)·μP; on loading the displacement grows and the stick fraction falls; the
/// unloading path that follows dissipates (curve.json).
#[test]
fn bem_tangential_path_is_cattaneo_mindlin() {
    let d = fresh_dir("friction", "tangential_path");
    let n = 128;
    let (text, p, a, g, nu) = sphere_scene(&d, n, "{ from = 0.1, to = 0.8, steps = 8 }");
    let (o, out) = crate::support::solve_text(&d, "sphere", &text);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let curve = columns(&std::fs::read_to_string(out.join("curve.csv")).unwrap());
    let kt = curve["tangential_stiffness"][0];
    let csv = std::fs::read_to_string(out.join("tangential.csv")).unwrap();
    assert!(
        csv.starts_with("force_ratio,tangential_force,tangential_displacement,stick_fraction\n"),
        "{csv}"
    );
    let t = columns(&csv);
    let mu = 0.3;
    let p_bem = curve["mean_pressure"][0] * 1e-6;
    assert!((p_bem / p - 1.0).abs() < 1e-9, "{p_bem} {p}");
    let (mut worst_stick, mut worst_d, mut worst_q) = (0.0f64, 0.0f64, 0.0f64);
    for (k, &ratio) in t["force_ratio"].iter().enumerate() {
        let q = ratio * mu * p;
        worst_q = worst_q.max((t["tangential_force"][k] / q - 1.0).abs());
        let cm = (1.0 - ratio).powf(2.0 / 3.0);
        worst_stick = worst_stick.max((t["stick_fraction"][k] / cm - 1.0).abs());
        let delta_cm = 3.0 * mu * p * (2.0 - nu) / (16.0 * g * a) * (1.0 - cm);
        let nonlinear_bem = t["tangential_displacement"][k] - q / kt;
        let nonlinear_cm = delta_cm - q / (8.0 * g * a / (2.0 - nu));
        worst_d = worst_d.max(((nonlinear_bem - nonlinear_cm) / delta_cm).abs());
        eprintln!(
            "Q/μP = {ratio}: stick fraction {:.4} (CM {cm:.4}), δ_t − Q/K_t = {nonlinear_bem:e} (CM {nonlinear_cm:e})",
            t["stick_fraction"][k]
        );
    }
    eprintln!(
        "tangential.csv at {n}²: stick fraction vs CM {worst_stick:.2e}, nonlinear δ_t {worst_d:.2e} of δ_CM, Q {worst_q:.1e}"
    );
    // Measured at 128² (a ≈ 15 pixels): Q 7.7e-9 (the force control's tolerance is 1e-8);
    // the stick fraction 3.5e-2 (0.56 against 0.54 at Q/μP = 0.6: the stick area's
    // boundary pixels, 1.8e-2 in c/a); the nonlinear displacement 4.6e-3 of δ_CM. The
    // stick fraction is asserted at 2× its measured error (a grid error, deterministic;
    // 10× would pass any stick fraction), the displacement at 10×.
    assert!(worst_q < 1.5e-8, "{worst_q:e}");
    assert!(worst_stick < 0.07, "{worst_stick:e}");
    assert!(worst_d < 0.05, "{worst_d:e}");
    for w in t["tangential_displacement"].windows(2) {
        assert!(w[1] > w[0], "{csv}");
    }
    for w in t["stick_fraction"].windows(2) {
        assert!(w[1] < w[0], "{csv}");
    }
    // curve.json: the path with its dissipation, ≥ 0 on loading
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("curve.json")).unwrap()).unwrap();
    let path = &json["tangential_path"];
    assert_eq!(path["steps"].as_array().unwrap().len(), 8);
    assert_eq!(path["units"]["tangential_displacement"], "m");
    assert!(path["dissipation"].as_f64().unwrap() >= 0.0);
}

/// A loading then unloading path (from > to): the unloading steps' displacement falls
/// and every step dissipates ≥ 0 (Coulomb's law, point by point).
#[test]
fn bem_tangential_unloading_dissipates() {
    let d = fresh_dir("friction", "tangential_unload");
    let (text, ..) = sphere_scene(&d, 64, "{ from = 0.8, to = -0.8, steps = 5 }");
    let (o, out) = crate::support::solve_text(&d, "sphere", &text);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let t = columns(&std::fs::read_to_string(out.join("tangential.csv")).unwrap());
    for (r, want) in t["force_ratio"].iter().zip([0.8, 0.4, 0.0, -0.4, -0.8]) {
        assert!((r - want).abs() < 1e-15, "{:?}", t["force_ratio"]);
    }
    for w in t["tangential_displacement"].windows(2) {
        assert!(w[1] < w[0], "{:?}", t["tangential_displacement"]);
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("curve.json")).unwrap()).unwrap();
    let steps = json["tangential_path"]["steps"].as_array().unwrap();
    let largest = steps
        .iter()
        .map(|s| s["dissipation"].as_f64().unwrap().abs())
        .fold(0.0, f64::max);
    assert!(largest > 0.0);
    for s in steps {
        assert!(s["dissipation"].as_f64().unwrap() >= -1e-9 * largest, "{s}");
    }
}

/// `[load] tangential` refusals: not the BEM, no `[friction]`, ratios beyond [−1, 1], bad
/// or missing steps; each a non-zero exit naming the field and the scene file, no
/// outputs.
#[test]
fn tangential_path_errors_name_the_field() {
    let d = fresh_dir("friction", "tangential_errors");
    let surface = SURFACE
        .replace("grid = 256", "grid = 32")
        .replace("k_max = 10", "k_max = 8");
    let scene = |model: &str, tangential: &str, friction: bool| {
        homogeneous_scene(
            &surface,
            model,
            &format!("mean_pressures = [1e5]\ntangential = {tangential}"),
        ) + if friction {
            "[friction]\ncoefficient = 0.3\n"
        } else {
            ""
        }
    };
    let good = "{ from = 0.1, to = 0.5, steps = 3 }";
    for (text, needle, also) in [
        (
            scene("\"independent\"", good, true),
            "load.tangential",
            "bem",
        ),
        (
            scene("\"interacting\"", good, true),
            "load.tangential",
            "bem",
        ),
        (
            scene("\"bem\"", good, false),
            "load.tangential",
            "[friction]",
        ),
        (
            scene("\"bem\"", "{ from = 1.5, to = 0.5, steps = 3 }", true),
            "load.tangential.from",
            "(-1, 1)",
        ),
        (
            scene("\"bem\"", "{ from = 0.1, to = -1.0, steps = 3 }", true),
            "load.tangential.to",
            "(-1, 1)",
        ),
        (
            scene("\"bem\"", "{ from = 0.1, to = nan, steps = 3 }", true),
            "load.tangential.to",
            "finite",
        ),
        (
            scene("\"bem\"", "{ from = 0.1, to = 0.5, steps = 0 }", true),
            "load.tangential.steps",
            "[1, 10000]",
        ),
        (
            scene("\"bem\"", "{ from = 0.1, to = 0.5 }", true),
            "load.tangential.steps",
            "missing",
        ),
        (
            scene(
                "\"bem\"",
                "{ from = 0.1, to = 0.5, steps = 3, by = 1 }",
                true,
            ),
            "by",
            "unknown",
        ),
    ] {
        let (o, out) = crate::support::solve_text(&d, "bad", &text);
        let err = stderr_of(&o);
        assert!(!o.status.success(), "{text}");
        assert!(
            err.contains(needle) && err.contains(also),
            "{needle}: {err}"
        );
        assert!(err.contains("bad.toml"), "{err}");
        assert!(!out.join("curve.csv").exists());
        assert!(!out.join("tangential.csv").exists());
    }
}
