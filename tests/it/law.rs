//! End-to-end tests of `strata law SCENE --out FILE`: the Abaqus block obeys the
//! rules of `*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR` (data lines
//! `pressure, overclosure`, overclosure strictly increasing, pressure ≥ 0 and
//! non-decreasing, first line at zero pressure and zero overclosure), the samples equal
//! the closed-form Greenwood–Williamson sum of Hertz contacts on a homogeneous solid,
//! and the interpolated law agrees with `strata solve` at the scenes' own load steps.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use strata::scene::Scene;
use strata_runtime::interface::InterfaceLaw;
use strata_runtime::interface::abaqus::{FIELD_WIDTH, read_f20};
use strata_runtime::summits::find_summits;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let d = crate::support::scratch().join(format!("law-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn strata(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("run strata")
}

fn ok(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "strata failed:\n{err}");
    err
}

fn fail(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success(), "strata should have failed:\n{err}");
    let last = err.lines().last().unwrap_or("");
    assert!(last.starts_with("error:"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// CSV samples: (gap, overclosure, p, A/A₀, dp/dg) in loading order.
pub fn read_csv(p: &Path) -> Vec<[f64; 5]> {
    let text = std::fs::read_to_string(p).expect("csv");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("gap,overclosure,mean_pressure,area_fraction,dp_dg,valid")
    );
    lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().expect("number")).collect();
            [v[0], v[1], v[2], v[3], v[4]]
        })
        .collect()
}

/// The Abaqus rules; returns the (pressure, overclosure) data lines, each number read
/// as CalculiX reads it (`f20.0` on the first 20 characters) from a field that must
/// be at most 20 characters long.
fn check_abaqus(p: &Path) -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(p).expect("inp");
    let mut keyword_seen = false;
    let mut data: Vec<(f64, f64)> = Vec::new();
    let mut first_line = None;
    for line in text.lines() {
        assert!(
            line.len() <= 256,
            "Abaqus input lines are at most 256 characters"
        );
        if line.starts_with("**") {
            assert!(!keyword_seen, "comment inside the data lines: {line}");
            continue;
        }
        if line.starts_with('*') {
            assert!(!keyword_seen, "a second keyword: {line}");
            assert_eq!(line, "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR");
            keyword_seen = true;
            continue;
        }
        assert!(keyword_seen, "data before the keyword: {line}");
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        assert_eq!(f.len(), 2, "data line `pressure, overclosure`: {line}");
        for field in &f {
            assert!(field.len() <= FIELD_WIDTH, "`{field}`: over 20 characters");
        }
        let (pr, h) = (
            read_f20(f[0]).expect("pressure field"),
            read_f20(f[1]).expect("overclosure field"),
        );
        assert!(pr.is_finite() && h.is_finite(), "{line}");
        first_line.get_or_insert_with(|| line.to_string());
        data.push((pr, h));
    }
    assert!(keyword_seen);
    assert!(data.len() >= 2, "Abaqus needs at least two data lines");
    assert_eq!(first_line.as_deref(), Some("0., 0."));
    for w in data.windows(2) {
        assert!(
            w[1].1 > w[0].1,
            "overclosure not strictly increasing: {w:?}"
        );
        assert!(w[1].0 > w[0].0, "pressure not increasing: {w:?}");
    }
    assert!(data.iter().all(|d| d.0 >= 0.0 && d.1 >= 0.0));
    assert!(
        text.contains("overclosure h = g0 - g"),
        "convention documented"
    );
    assert!(text.contains("SI (Pa, m)"), "units documented");
    data
}

/// Every Abaqus field, read back as CalculiX reads it, is within 1e-13 of the full
/// precision CSV value (pressure and overclosure; zero exactly).
fn fields_match_csv(abq: &[(f64, f64)], csv: &[[f64; 5]]) {
    assert_eq!(abq.len(), csv.len());
    let mut worst = 0.0f64;
    for ((p, h), r) in abq.iter().zip(csv) {
        for (got, want) in [(*p, r[2]), (*h, r[1])] {
            let e = if want == 0.0 {
                got.abs()
            } else {
                (got - want).abs() / want.abs()
            };
            assert!(e <= 1e-13, "field {got:e} vs CSV {want:e}");
            worst = worst.max(e);
        }
    }
    eprintln!("Abaqus fields vs CSV: worst relative {worst:.1e}");
}

/// The law as the runtime rebuilds it from the CSV samples.
fn law_from_csv(s: &[[f64; 5]]) -> InterfaceLaw {
    let g: Vec<f64> = s.iter().map(|r| r[0]).collect();
    let p: Vec<f64> = s.iter().map(|r| r[2]).collect();
    let k: Vec<f64> = s.iter().map(|r| -r[4]).collect();
    let a: Vec<f64> = s.iter().map(|r| r[3]).collect();
    InterfaceLaw::from_samples(&g, &p, &k, &a).expect("CSV is a valid law")
}

/// (gap, mean_pressure) of `strata solve` on the scene.
fn solve_curve(scene: &str, dir: &Path) -> Vec<(f64, f64)> {
    let out = dir.join("solve");
    ok(&strata(&[
        "solve",
        scene,
        "--out",
        out.to_str().expect("utf-8"),
        "--no-plots",
    ]));
    let text = std::fs::read_to_string(out.join("curve.csv")).expect("curve.csv");
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().expect("number")).collect();
            (v[1], v[2])
        })
        .collect()
}

/// Homogeneous scene, N model: the samples equal the closed-form GW sum
/// p(g) = Σ (4/3)E*√R_k δ_k^{3/2}/A₀, dp/dg = −Σ 2E*√(R_k δ_k)/A₀,
/// A/A₀ = Σ πR_kδ_k/A₀ with δ_k = ⟨z_k − z̄ − g⟩ (relative 1e-10); between the samples
/// the interpolated law is within 5e-4 of it and Abaqus's piecewise-linear table within
/// 2e-3 (where p ≥ 1 % of p_max; measured 1.8e-4 and 7.1e-4: the cubic's error sits at
/// the onsets of new contacts, where δ_k^{3/2} is not smooth); at `strata solve`'s own
/// steps the law is within 1e-5.
#[test]
fn homogeneous_law_is_the_gw_sum_and_a_valid_abaqus_table() {
    let dir = tmp("hom");
    let stem = dir.join("law");
    let scene = "scenes/homogeneous-km10-independent.toml";
    let err = ok(&strata(&[
        "law",
        scene,
        "--out",
        stem.to_str().expect("utf-8"),
        "--format",
        "all",
    ]));
    assert!(err.contains("wrote 200 samples"), "{err}");
    let s = read_csv(&stem.with_extension("csv"));
    assert_eq!(s.len(), 200);
    let abq = check_abaqus(&stem.with_extension("inp"));
    assert_eq!(abq.len(), 200);
    fields_match_csv(&abq, &s);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(stem.with_extension("json")).expect("json"))
            .expect("valid JSON");
    assert_eq!(json["law"].as_array().map(Vec::len), Some(200));
    assert_eq!(json["limited_slopes"], 0);
    assert!(
        json["convention"]
            .as_str()
            .is_some_and(|c| c.contains("g0 - g"))
    );
    // Default --min-gap: the separation of the scene's largest mean pressure (1e7 Pa).
    let p_last = s[199][2];
    assert!((p_last - 1e7).abs() <= 1e-9 * 1e7, "{p_last}");
    // The FE range the table covers, stated in the log, the JSON and the deck's comments
    // (an FE run beyond it leaves the table: CalculiX holds the last pressure silently).
    let (h_max, p_max) = (s[199][1], s[199][2]);
    assert_eq!(json["fe_range"]["overclosure_max"].as_f64(), Some(h_max));
    assert_eq!(json["fe_range"]["pressure_max"].as_f64(), Some(p_max));
    assert!(
        err.contains("FE range: the table covers overclosure 0 to"),
        "{err}"
    );
    let inp = std::fs::read_to_string(stem.with_extension("inp")).expect("inp");
    let range = inp
        .lines()
        .find(|l| l.starts_with("** FE RANGE:"))
        .unwrap_or_else(|| panic!("no FE RANGE comment:\n{inp}"));
    let h_field = range
        .split("<= h <= ")
        .nth(1)
        .and_then(|r| r.split(" m,").next())
        .and_then(read_f20)
        .expect("h_max in the FE RANGE line");
    assert!((h_field / h_max - 1.0).abs() < 1e-13, "{range}");
    assert_eq!(
        abq.last().map(|l| l.1),
        Some(h_field),
        "the table's last overclosure"
    );

    // Closed form on the scene's own surface.
    let sc = Scene::from_file(&root().join(scene)).expect("scene");
    let surf = sc
        .load_surface(&strata_runtime::resources::MemoryLimit::default())
        .expect("surface");
    let summits = find_summits(&surf).summits;
    let e = sc.bodies.first.top_plane_strain_modulus();
    let a0 = surf.extent().0 * surf.extent().1;
    let zbar = surf.mean();
    let gw = |g: f64| {
        let (mut p, mut d, mut a) = (0.0, 0.0, 0.0);
        for k in &summits {
            let dk = k.z - zbar - g;
            if dk > 0.0 {
                p += 4.0 / 3.0 * e * k.radius.sqrt() * dk.powf(1.5);
                d -= 2.0 * e * (k.radius * dk).sqrt();
                a += std::f64::consts::PI * k.radius * dk;
            }
        }
        (p / a0, d / a0, a / a0)
    };
    for r in &s {
        let (p, d, a) = gw(r[0]);
        assert!(
            (r[2] - p).abs() <= 1e-10 * p,
            "p at g={:e}: {} {p}",
            r[0],
            r[2]
        );
        assert!((r[4] - d).abs() <= 1e-10 * d.abs(), "dp/dg at g={:e}", r[0]);
        assert!((r[3] - a).abs() <= 1e-10 * a, "A at g={:e}", r[0]);
    }
    let law = law_from_csv(&s);
    let pmax = s[199][2];
    let (mut worst_cubic, mut worst_linear) = (0.0f64, 0.0f64);
    for w in s.windows(2) {
        let g = 0.5 * (w[0][0] + w[1][0]);
        let (p, _, _) = gw(g);
        if p < 1e-2 * pmax {
            continue;
        }
        let q = law.eval(g).expect("eval");
        worst_cubic = worst_cubic.max((q.pressure - p).abs() / p);
        worst_linear = worst_linear.max((0.5 * (w[0][2] + w[1][2]) - p).abs() / p);
    }
    eprintln!("midpoints vs GW: cubic {worst_cubic:.2e}, linear {worst_linear:.2e}");
    assert!(worst_cubic < 5e-4, "{worst_cubic}");
    assert!(worst_linear < 2e-3, "{worst_linear}");

    // `strata solve` at the scene's steps.
    for (g, p) in solve_curve(scene, &dir) {
        let q = law.eval(g).expect("inside the sampled range");
        assert!(
            (q.pressure - p).abs() <= 1e-5 * p,
            "g={g:e}: law {} solve {p}",
            q.pressure
        );
    }
}

/// Layered stack (E2/E1 = 1 on a rigid base, shipped table), I model with periodic
/// images: a valid Abaqus table, and the law agrees with `strata solve` at the scene's
/// 20 load steps within 1e-5 (measured 8.5e-7: interpolation plus the I model's
/// warm-start path).
#[test]
fn layered_interacting_law_matches_solve() {
    let dir = tmp("layered");
    let inp = dir.join("law.inp");
    let csv = dir.join("law.csv");
    let scene = "scenes/paper-E2E1-1-interacting.toml";
    for out in [&inp, &csv] {
        ok(&strata(&[
            "law",
            scene,
            "--out",
            out.to_str().expect("utf-8"),
        ]));
    }
    let abq = check_abaqus(&inp);
    let s = read_csv(&csv);
    assert_eq!(abq.len(), s.len());
    fields_match_csv(&abq, &s);
    let law = law_from_csv(&s);
    let mut worst = 0.0f64;
    let curve = solve_curve(scene, &dir);
    assert_eq!(curve.len(), 20);
    for (g, p) in curve {
        let q = law.eval(g).expect("inside the sampled range");
        worst = worst.max((q.pressure - p).abs() / p);
    }
    eprintln!("layered I model: law vs solve {worst:.2e}");
    assert!(worst < 1e-5, "{worst}");
    // The smallest sampled separation is the scene's deepest step.
    assert!((law.min_gap() - (law.first_contact_gap() - 9.8e-6)).abs() < 1e-18);
}

/// Bad input: clear one-line errors naming the argument, non-zero exit, no panic,
/// nothing written.
#[test]
fn bad_input_is_refused() {
    let dir = tmp("bad");
    let scene = "scenes/homogeneous-km10-independent.toml";
    let out = dir.join("law.csv");
    let o = out.to_str().expect("utf-8");
    let e = fail(&strata(&["law", "no/such/scene.toml", "--out", o]));
    assert!(e.contains("no/such/scene.toml"), "{e}");
    let e = fail(&strata(&["law", scene, "--out", o, "--samples", "1"]));
    assert!(e.contains("--samples"), "{e}");
    for bad in ["nan", "inf"] {
        let e = fail(&strata(&["law", scene, "--out", o, "--min-gap", bad]));
        assert!(e.contains("--min-gap"), "{e}");
    }
    let e = fail(&strata(&["law", scene, "--out", o, "--min-gap", "1e-3"]));
    assert!(e.contains("min_gap") && e.contains("first-contact"), "{e}");
    let txt = dir.join("law.txt");
    let e = fail(&strata(&[
        "law",
        scene,
        "--out",
        txt.to_str().expect("utf-8"),
    ]));
    assert!(e.contains("--format"), "{e}");
    assert!(!out.exists() && !txt.exists());
    let e = fail(&strata(&["law", scene, "--out", o, "--samples", "100001"]));
    assert!(e.contains("--samples") && e.contains("100000"), "{e}");
    let log = ok(&strata(&["law", scene, "--out", o, "--samples", "20"]));
    assert!(!log.contains("warning"), "{log}");
    // More lines than CalculiX keeps: a warning when an Abaqus block is written.
    let inp = dir.join("long.inp");
    let log = ok(&strata(&[
        "law",
        scene,
        "--out",
        inp.to_str().expect("utf-8"),
        "--samples",
        "201",
    ]));
    assert!(
        log.contains("warning: 201 table lines: CalculiX 2.20"),
        "{log}"
    );
    let e = fail(&strata(&["law", scene, "--out", o, "--samples", "20"]));
    assert!(e.contains("--force"), "{e}");
    ok(&strata(&[
        "law",
        scene,
        "--out",
        o,
        "--samples",
        "30",
        "--force",
    ]));
    assert_eq!(read_csv(&out).len(), 30);
}
