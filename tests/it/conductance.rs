//! End-to-end tests of `strata conductance` and `strata compliance --thermal/--electrical`
//! (physics.md §6.2): conduction properties in stack files, the conduction
//! compliance S_th and the constriction conductance of one isothermal spot.

use std::path::PathBuf;

use strata_runtime::Stack;
use strata_runtime::conduction::ConductionKind;
use strata_tablegen::spot::Spot;

use crate::support::{fresh_dir, repo, run_strata, stderr_of};

fn stack_file(name: &str, text: &str) -> PathBuf {
    let p = fresh_dir("conductance", name).join("stack.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn rows(out: &std::process::Output, header: &str) -> Vec<Vec<f64>> {
    assert!(out.status.success(), "{}", stderr_of(out));
    let text = String::from_utf8(out.stdout.clone()).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(header));
    lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// One error line on stderr naming `needles`, a non-zero exit, nothing on stdout.
fn fails_with(args: &[&str], needles: &[&str]) {
    let out = run_strata(args);
    let err = stderr_of(&out);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert!(
        out.stdout.is_empty(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: `{n}` not in {err}");
    }
}

const LAYER_ON_HALF_SPACE: &str = "[[layer]]\nthickness = 1e-5\nyoung = 4e11\npoisson = 0.25\n\
    thermal_conductivity = 2\nelectrical_conductivity = 3e6\n\
    [base]\nkind = \"elastic\"\nyoung = 2e11\npoisson = 0.3\n\
    thermal_conductivity = 50\nelectrical_conductivity = 6e6\n";

/// `--thermal` and `--electrical` print S_th, equal to the closed form of one layer on
/// a half-space, (k₁ + k_b t)/(k_b + k₁ t) with t = tanh ρh₁, and to tanh ρh₁ on the
/// shipped isothermal-base stack.
#[test]
fn compliance_prints_the_conduction_compliance() {
    let p = stack_file("closed-form", LAYER_ON_HALF_SPACE);
    for (flag, k1, kb) in [("--thermal", 2.0, 50.0), ("--electrical", 3e6, 6e6)] {
        let out = run_strata(&[
            "compliance",
            p.to_str().unwrap(),
            "--rho-h",
            "0,1e-3,0.5,2,40,1e4",
            flag,
        ]);
        let r = rows(&out, "rho_h,S_th");
        assert_eq!(r.len(), 6);
        for v in &r {
            let t = v[0].tanh();
            let exact = (k1 + kb * t) / (kb + k1 * t);
            assert!(
                (v[1] - exact).abs() < 1e-14 * exact,
                "{flag} {v:?} vs {exact}"
            );
        }
    }
    let cooled = repo().join("tables/stacks/polymer-on-cooled-base.toml");
    let out = run_strata(&[
        "compliance",
        cooled.to_str().unwrap(),
        "--rho-h",
        "1e-3:1e3:7:log",
        "--thermal",
    ]);
    for v in rows(&out, "rho_h,S_th") {
        assert!((v[1] - v[0].tanh()).abs() <= 1e-15 * v[0].tanh(), "{v:?}");
    }
    // Without the flags: the elastic k_z, as before.
    let out = run_strata(&["compliance", p.to_str().unwrap(), "--rho-h", "1"]);
    assert_eq!(rows(&out, "rho_h,k_z").len(), 1);
}

/// A homogeneous conducting half-space: G = 4ka exactly, ψ = 1; a layered stack: the
/// library's values to the last bit (the CSV keeps full precision), ψ between its
/// limits (1 at a/h₁ → 0, k_b/k₁ = 2.25 at a/h₁ → ∞ on the shipped coating).
#[test]
fn conductance_of_one_spot() {
    let p = stack_file(
        "homogeneous",
        "[base]\nkind = \"elastic\"\nyoung = 2e11\npoisson = 0.3\nthermal_conductivity = 50\n",
    );
    let out = run_strata(&["conductance", p.to_str().unwrap(), "--a", "1e-6,1e-3"]);
    let r = rows(&out, "a,conductance,psi");
    assert_eq!(
        r,
        vec![vec![1e-6, 4.0 * 50.0 * 1e-6, 1.0], vec![1e-3, 0.2, 1.0]]
    );

    let coating = repo().join("tables/stacks/coating-on-steel-conducting.toml");
    let out = run_strata(&[
        "conductance",
        coating.to_str().unwrap(),
        "--a",
        "2e-8,2e-6,2e-5,2e-4",
    ]);
    let r = rows(&out, "a,conductance,psi");
    let st = Stack::from_toml_file(&coating).unwrap();
    let spot = Spot::new(&st, ConductionKind::Thermal).unwrap();
    let mut prev = 1.0;
    for v in &r {
        let g = spot.conductance(v[0]).unwrap();
        assert_eq!((v[1], v[2]), (g.conductance, g.psi), "a = {}", v[0]);
        assert!(v[2] > prev && v[2] < 2.25, "{v:?}");
        prev = v[2];
    }
    assert!(r[0][2] - 1.0 < 1e-3, "{:?}", r[0]);
    // Electrical: k₁ = 4e6 S/m on 6e6 S/m.
    let out = run_strata(&[
        "conductance",
        coating.to_str().unwrap(),
        "--a",
        "2e-5",
        "--kind",
        "electrical",
    ]);
    let r = rows(&out, "a,conductance,psi");
    let spot = Spot::new(&st, ConductionKind::Electrical).unwrap();
    assert_eq!(r[0][1], spot.conductance(2e-5).unwrap().conductance);
    assert!(r[0][2] > 1.0 && r[0][2] < 1.5, "{:?}", r[0]);
}

/// Bad input: one clear error line naming the field (and layer, and file), non-zero exit.
#[test]
fn bad_input_is_named() {
    let paper = repo().join("tables/stacks/paper-two-layer.toml");
    let paper = paper.to_str().unwrap();
    fails_with(
        &["conductance", paper, "--a", "1e-5"],
        &[paper, "layer 1", "thermal_conductivity"],
    );
    fails_with(
        &["compliance", paper, "--rho-h", "1", "--electrical"],
        &[paper, "layer 1", "electrical_conductivity"],
    );
    let cooled = repo().join("tables/stacks/polymer-on-cooled-base.toml");
    let cooled = cooled.to_str().unwrap();
    fails_with(
        &["conductance", cooled, "--a", "1e-5", "--kind", "electrical"],
        &[cooled, "layer 1", "electrical_conductivity"],
    );
    for a in ["-1e-5", "0", "1e-5,-2e-5"] {
        fails_with(&["conductance", cooled, "--a", a], &["--a", "> 0"]);
    }
    fails_with(
        &["conductance", cooled, "--a", "nan"],
        &["--a", "not a finite number"],
    );
    let base = stack_file(
        "no-base-k",
        "[[layer]]\nthickness = 1e-5\nyoung = 1e9\npoisson = 0.3\nthermal_conductivity = 1\n\
         [base]\nkind = \"rigid\"\n",
    );
    let base = base.to_str().unwrap();
    fails_with(
        &["conductance", base, "--a", "1e-5"],
        &[base, "base", "thermal_conductivity", "isothermal"],
    );
    let neg = stack_file(
        "negative-k",
        "[[layer]]\nthickness = 1e-5\nyoung = 1e9\npoisson = 0.3\n\
         [[layer]]\nthickness = 1e-5\nyoung = 1e9\npoisson = 0.3\nthermal_conductivity = -3\n\
         [base]\nkind = \"rigid\"\nconduction = \"isothermal\"\n",
    );
    let neg = neg.to_str().unwrap();
    fails_with(
        &["conductance", neg, "--a", "1e-5"],
        &[neg, "layer 2", "thermal_conductivity", "> 0"],
    );
    // A stack error stops every command alike, also those that need no conductivity.
    fails_with(
        &["compliance", neg, "--rho-h", "1"],
        &[neg, "layer 2", "thermal_conductivity"],
    );
    let iso = stack_file(
        "isothermal-with-k",
        "[[layer]]\nthickness = 1e-5\nyoung = 1e9\npoisson = 0.3\nthermal_conductivity = 1\n\
         [base]\nkind = \"rigid\"\nconduction = \"isothermal\"\nthermal_conductivity = 3\n",
    );
    let iso = iso.to_str().unwrap();
    fails_with(
        &["conductance", iso, "--a", "1e-5"],
        &[iso, "base", "thermal_conductivity", "isothermal"],
    );
}
