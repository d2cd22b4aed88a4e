//! End-to-end tests of `strata stiffness` and `strata asperity --tangential`: the normal
//! flat punch and the full-stick tangential disc of one contact radius.

use std::path::PathBuf;

use strata_runtime::Stack;
use strata_tablegen::stiffness::Stiffness;

use crate::support::{fresh_dir, run_strata, stderr_of};

fn stack_file(name: &str, text: &str) -> PathBuf {
    let p = fresh_dir("stiffness", name).join("stack.toml");
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

const LAYER_ON_RIGID: &str =
    "[[layer]]\nthickness = 1e-4\nyoung = 1e9\npoisson = 0.3\n[base]\nkind = \"rigid\"\n";

/// A half-space: 2aE* and Mindlin's 8μa/(2−ν) to 1e-12; a layer on a rigid base: the
/// library's values to the last bit, K_t/K_n from Mindlin's 2(1−ν)/(2−ν) at a ≪ h
/// towards the slab's (1−2ν)/(2(1−ν)) at a ≫ h.
#[test]
fn stiffness_of_one_disc() {
    let (e, nu) = (2e11, 0.3);
    let p = stack_file(
        "half-space",
        &format!("[base]\nkind = \"elastic\"\nyoung = {e}\npoisson = {nu}\n"),
    );
    let out = run_strata(&["stiffness", p.to_str().unwrap(), "--a", "1e-6,1e-3"]);
    let r = rows(&out, "a,normal_stiffness,tangential_stiffness");
    let mu = e / (2.0 * (1.0 + nu));
    for v in &r {
        let (kn, kt) = (
            2.0 * v[0] * e / (1.0 - nu * nu),
            8.0 * mu * v[0] / (2.0 - nu),
        );
        assert!(
            (v[1] / kn - 1.0).abs() < 1e-12 && (v[2] / kt - 1.0).abs() < 1e-12,
            "{v:?}"
        );
    }
    let p = stack_file("layer", LAYER_ON_RIGID);
    let out = run_strata(&["stiffness", p.to_str().unwrap(), "--a", "1e-8,1e-4,3e-3"]);
    let r = rows(&out, "a,normal_stiffness,tangential_stiffness");
    let s = Stiffness::new(&Stack::from_toml_file(&p).unwrap());
    for v in &r {
        let d = s.at(v[0]).unwrap();
        assert_eq!((v[1], v[2]), (d.normal, d.tangential), "a = {}", v[0]);
    }
    let ratio: Vec<f64> = r.iter().map(|v| v[2] / v[1]).collect();
    let (mindlin, slab) = (2.0 * 0.7 / 1.7, 0.4 / 1.4);
    assert!((ratio[0] / mindlin - 1.0).abs() < 1e-3, "{ratio:?}");
    assert!(ratio[1] < ratio[0] && ratio[2] < ratio[1], "{ratio:?}");
    assert!(ratio[2] > slab && ratio[2] < 1.2 * slab, "{ratio:?}");
}

/// `strata asperity --tangential` adds the disc's K_t at each δ's contact radius.
#[test]
fn asperity_tangential_column() {
    let p = stack_file("asperity", LAYER_ON_RIGID);
    let out = run_strata(&[
        "asperity",
        p.to_str().unwrap(),
        "--radius",
        "1e-3",
        "--delta",
        "0,1e-7,1e-6",
        "--tangential",
    ]);
    let r = rows(&out, "delta,a,force,tangential_stiffness");
    let s = Stiffness::new(&Stack::from_toml_file(&p).unwrap());
    assert_eq!(r[0], vec![0.0, 0.0, 0.0, 0.0]);
    for v in &r[1..] {
        assert_eq!(v[3], s.at(v[1]).unwrap().tangential, "{v:?}");
    }
}

/// Bad radii: one error line naming the flag, non-zero exit, nothing on stdout.
#[test]
fn bad_radii_refused() {
    let p = stack_file("bad", LAYER_ON_RIGID);
    for bad in ["0", "-1e-6", "nan", "1e-6,abc"] {
        let out = run_strata(&["stiffness", p.to_str().unwrap(), "--a", bad]);
        let err = stderr_of(&out);
        assert!(!out.status.success() && out.stdout.is_empty(), "{bad}");
        assert!(err.contains("--a"), "{bad}: {err}");
    }
    let out = run_strata(&["stiffness", "/nonexistent/stack.toml", "--a", "1e-6"]);
    assert!(!out.status.success());
    assert!(stderr_of(&out).contains("/nonexistent/stack.toml"));
}
