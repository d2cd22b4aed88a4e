//! End-to-end tests of `strata study`, in its hidden `--tiny` mode (a few
//! seconds): the report and its plots are written, a second run reproduces every
//! error bit for bit, and the measured numbers obey known convergence facts.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let d = crate::support::scratch().join(format!("study-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn study(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_strata"))
        .arg("study")
        .args(args)
        .arg("--scene")
        .arg(root().join("scenes/paper-E2E1-1-interacting.toml"))
        .arg("--table")
        .arg(root().join("tables/paper-two-layer.strata"))
        .output()
        .expect("strata runs")
}

fn tiny(out: &Path) {
    let o = study(&["--tiny", "--out", out.to_str().unwrap()]);
    assert!(
        o.status.success(),
        "strata study --tiny failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// errors.csv as (stage, case, quantity) → value.
fn errors(dir: &Path) -> HashMap<(String, String, String), f64> {
    let text = std::fs::read_to_string(dir.join("errors.csv")).unwrap();
    let mut r = csv::Reader::from_reader(text.as_bytes());
    assert_eq!(
        r.headers().unwrap().iter().collect::<Vec<_>>(),
        ["stage", "case", "quantity", "value"]
    );
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            (
                (rec[0].to_string(), rec[1].to_string(), rec[2].to_string()),
                rec[3].parse().unwrap(),
            )
        })
        .collect()
}

fn get(e: &HashMap<(String, String, String), f64>, s: &str, c: &str, q: &str) -> f64 {
    *e.get(&(s.into(), c.into(), q.into()))
        .unwrap_or_else(|| panic!("errors.csv lacks {s} / {c} / {q}"))
}

/// Two tiny runs: byte-identical errors.csv; the report has every section, the
/// machine, and links only to plots that exist; timings.csv has one row per item.
/// Then the numbers themselves against known facts (tolerances stated inline).
#[test]
fn tiny_study_is_reproducible_and_sound() {
    let (a, b) = (tmp("a"), tmp("b"));
    tiny(&a);
    tiny(&b);
    let ea = std::fs::read(a.join("errors.csv")).unwrap();
    let eb = std::fs::read(b.join("errors.csv")).unwrap();
    assert!(ea.len() > 500, "errors.csv too short");
    assert!(ea == eb, "errors.csv differs between two runs");

    let report = std::fs::read_to_string(a.join("report.md")).unwrap();
    for section in [
        "## Machine",
        "| CPU |",
        "| build profile |",
        "## Summary",
        "## Defaults and the front",
        "### Proposed changes",
        "## 1. Fredholm solver",
        "## 2. Surrogate tables",
        "## 3. Second-order approximation",
        "## 4. Rough contact",
        "## 5. I model at scale",
        "## 6. Yielding tips",
        "## 7. Interface conductance",
        "## 8. Tangential stiffness",
        "## Regenerating",
    ] {
        assert!(report.contains(section), "report lacks {section}");
    }
    // the scaling section fitted a time exponent from its two curves
    let fitted = report
        .split("Fitted exponents: time ∝ N^")
        .nth(1)
        .and_then(|s| s.split(',').next())
        .and_then(|s| s.parse::<f64>().ok());
    assert!(
        fitted.is_some_and(|e| e.is_finite()),
        "no fitted time exponent"
    );
    let mut plots = 0;
    for part in report.split("](").skip(1) {
        let file = part.split(')').next().unwrap();
        if file.ends_with(".svg") {
            let p = a.join(file);
            let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{file}: {e}"));
            assert!(text.contains("<svg"), "{file}");
            if file != "approx.svg" {
                assert!(text.contains("Pareto front"), "{file}: no front drawn");
            }
            plots += 1;
        }
    }
    assert!(plots >= 5, "{plots} plots linked");
    let timings = std::fs::read_to_string(a.join("timings.csv")).unwrap();
    assert!(timings.starts_with("stage,case,median_seconds,min_seconds,max_seconds,runs\n"));
    for l in timings.lines().skip(1) {
        let v: Vec<&str> = l.rsplitn(5, ',').collect();
        let runs: usize = v[0].parse().unwrap();
        let (max, min, median): (f64, f64, f64) = (
            v[1].parse().unwrap(),
            v[2].parse().unwrap(),
            v[3].parse().unwrap(),
        );
        assert!(
            runs >= 1 && min > 0.0 && min <= median && median <= max,
            "{l}"
        );
    }

    let e = errors(&a);
    let f = |case: &str, q: &str| get(&e, "fredholm", case, q);
    // Nyström converges spectrally: at a/h = 1, 16 nodes are at round-off (< 1e-13;
    // measured 7e-16), and the two references (Nyström vs product integration, two
    // independent discretisations) agree to 1e-8 (tablegen's own test bound).
    assert!(f("E2/E1=5,a/h=1,nystrom-16", "force error") < 1e-13);
    assert!(f("E2/E1=5,a/h=1", "cross-check") < 1e-8);
    assert!(f("E2/E1=5,a/h=10", "cross-check") < 1e-8);
    // Product integration with Richardson: error falls ≥ 8× per doubling (measured 16×).
    for ah in ["1", "10"] {
        let p = |n: u32| f(&format!("E2/E1=5,a/h={ah},product-{n}-r"), "force error");
        assert!(p(32) > 8.0 * p(64) && p(64) > 8.0 * p(128), "a/h {ah}");
    }
    // Tables: the cubic beats the linear interpolant of the same nodes, for χ and g.
    let t = |o: &str, q: &str| get(&e, "tables", &format!("nx=13,nw=7,{o}"), q);
    assert!(t("cubic Hermite", "chi error") < t("linear", "chi error"));
    assert!(t("cubic Hermite", "g error") < t("linear", "g error"));
    // Approximation: within 1e-3 of the full force at a/h = 0.1 (tests/tables.rs,
    // measured 3.7e-7); the table changes it by less than its interpolation error 1e-4.
    let d = get(&e, "approx", "E2/E1=5,a/h=0.1000", "force error (direct)");
    let tb = get(&e, "approx", "E2/E1=5,a/h=0.1000", "force error (table)");
    assert!(d < 1e-3 && (tb - d).abs() < 1e-4, "{d} {tb}");
    // Rough contact: at the reference grid, tolerance 1e-6 changes p_n by < 1e-4
    // (measured 2.5e-6); the I model is within 30 % of the BEM (measured 13 %) and
    // closer than the N model at the highest load.
    assert!(get(&e, "rough", "BEM n = 64, tol 1e-6", "p error") < 1e-4);
    let ip = get(&e, "rough", "I model, periodic 5×5", "p error");
    let n = get(&e, "rough", "N model", "p error");
    assert!(ip < 0.3 && ip < n, "I {ip}, N {n}");
    // Yielding tips (tiny: the top layer's half-space, H = 0.05 E*₁): the 32² capped BEM
    // within 30 % of the 64² one (measured 21 %, the first, sparsest step); the capped I
    // model nearer the capped BEM than the capped N model (measured 52 % and 68 % at the
    // deepest step, near full contact, where both asperity models fail as elastic ones do).
    let pl = |case: &str| get(&e, "plasticity", case, "p error");
    assert!(pl("capped BEM n = 32") < 0.3, "{}", pl("capped BEM n = 32"));
    let (ci, cn) = (pl("capped I model, periodic 5×5"), pl("capped N model"));
    assert!(ci < cn && cn < 1.0, "I {ci}, N {cn}");
    // Tangential stiffness (tiny: the scene's stack, a/h1 = 0.1 … 10): the shipped
    // table's 17 nodes a decade within 1e-9 (K_t) and 3e-9 (K_n) of direct solves
    // (the table's requirement 1e-5; measured 1.1e-10 and 2.6e-10), and more nodes are
    // more accurate (5: 2.7e-4, 9: 5.0e-7).
    let f = |n: usize, q: &str| get(&e, "friction", &format!("{n} nodes a decade"), q);
    assert!(f(17, "K_t error") < 1e-9, "{}", f(17, "K_t error"));
    assert!(f(17, "K_n error") < 3e-9, "{}", f(17, "K_n error"));
    assert!(f(5, "K_t error") > f(9, "K_t error") && f(9, "K_t error") > f(17, "K_t error"));
    // Interface conductance (tiny: the top layer's conducting half-space, k = 0.5 W/(m·K),
    // against a 45 W/(m·K) flat; 3 steps). h_c grows with the load in every model (more
    // and larger spots conduct more); the 32² BEM within 50 % of the 64² one (measured
    // 4.9 %: a spot's pixelated edge costs ~0.17 dx/a of its conductance); the I model
    // nearer the BEM than the N model at equal separation and at equal pressure (measured
    // 85 % and 19 % against 95 % and 30 %, as `strata compare` finds on the paper's scene:
    // both fall below the BEM as the load grows, the interactions are what N misses); each
    // model's equal-pressure error over at least one step its curve brackets.
    let c = |case: &str, q: &str| get(&e, "conductance", case, q);
    for case in [
        "BEM n = 32",
        "BEM n = 64",
        "N model",
        "I model, periodic 5×5",
    ] {
        let h: Vec<f64> = (0..3).map(|i| c(case, &format!("h step {i}"))).collect();
        assert!(
            h[0] > 0.0 && h[0] < h[1] && h[1] < h[2] && h[2].is_finite(),
            "{case}: {h:?}"
        );
        assert!(c(case, "steps compared (equal p)") >= 1.0, "{case}");
    }
    assert_eq!(c("BEM n = 64", "h error (equal g)"), 0.0);
    assert!(c("BEM n = 32", "h error (equal g)") < 0.5);
    let (ni, ii) = ("N model", "I model, periodic 5×5");
    for q in ["h error (equal g)", "h error (equal p)"] {
        assert!(
            c(ii, q) < c(ni, q) && c(ni, q) < 1.0,
            "{q}: I {}, N {}",
            c(ii, q),
            c(ni, q)
        );
    }
    let _ = std::fs::remove_dir_all(&a);
    let _ = std::fs::remove_dir_all(&b);
}

/// Bad input: a clear message naming the flag, non-zero exit.
#[test]
fn bad_arguments_are_refused() {
    let out = tmp("bad");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("x"), "occupied").unwrap();
    let o = study(&["--tiny", "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--force"));
    let o = Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(["study", "--tiny", "--out"])
        .arg(out.join("new"))
        .args(["--scene", "/nonexistent/scene.toml"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--scene") && err.contains("/nonexistent/scene.toml"),
        "{err}"
    );
    let o = study(&["--tiny", "--quick", "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    // A bad --table or a scene the rough stage refuses (non-periodic) fails before the
    // first stage (it failed after ~33 s of Fredholm and table work).
    let flat = out.join("flat.toml");
    let text = std::fs::read_to_string(root().join("scenes/paper-E2E1-1-interacting.toml"))
        .unwrap()
        .replace("periodic = true", "periodic = false")
        .replace("file = \"../", &format!("file = \"{}/", root().display()))
        .replace("table = \"../", &format!("table = \"{}/", root().display()));
    assert!(text.contains("periodic = false"), "{text}");
    std::fs::write(&flat, text).unwrap();
    for (flag, value, expect) in [
        ("--table", root().join("README.md"), "not a strata table"),
        ("--scene", flat, "periodic"),
    ] {
        let mut c = Command::new(env!("CARGO_BIN_EXE_strata"));
        c.args(["study", "--tiny", "--out"]).arg(out.join("early"));
        c.arg("--scene").arg(if flag == "--scene" {
            value.clone()
        } else {
            root().join("scenes/paper-E2E1-1-interacting.toml")
        });
        c.arg("--table").arg(if flag == "--table" {
            value.clone()
        } else {
            root().join("tables/paper-two-layer.strata")
        });
        let o = c.output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{flag}: {err}");
        assert!(err.contains(expect), "{flag}: {err}");
        assert!(
            !err.contains("Fredholm solver"),
            "{flag}: before any stage: {err}"
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}
