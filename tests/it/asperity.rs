//! End-to-end tests of `strata asperity` (one asperity on a layered solid).

use std::path::PathBuf;
use std::process::Command;

fn strata() -> Command {
    Command::new(env!("CARGO_BIN_EXE_strata"))
}

fn reference_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/reference")
}

fn tmp(name: &str) -> PathBuf {
    let dir = crate::support::scratch().join("asperity-cli");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The CLI reproduces the shared reference (independent solver) to 1e-4 in force and
/// prints exactly the header `delta,a,force`.
#[test]
fn reference_curve_through_cli() {
    let stack = reference_dir().join("stack_h100um_E2E1_5.toml");
    let csv = std::fs::read_to_string(reference_dir().join("axisym_h100um_E2E1_5.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("delta"))
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let list: Vec<String> = rows
        .iter()
        .step_by(4)
        .map(|r| format!("{:e}", r[0]))
        .collect();
    let out = strata()
        .arg("asperity")
        .arg(&stack)
        .args(["--radius", "1e-4", "--delta", &list.join(",")])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("delta,a,force"));
    let got: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(got.len(), list.len());
    for (g, r) in got.iter().zip(rows.iter().step_by(4)) {
        assert!(((g[0] - r[0]) / r[0]).abs() < 1e-12);
        assert!(
            ((g[1] - r[1]) / r[1]).abs() < 1e-4,
            "a: {} vs {}",
            g[1],
            r[1]
        );
        assert!(
            ((g[2] - r[2]) / r[2]).abs() < 1e-4,
            "force: {} vs {}",
            g[2],
            r[2]
        );
    }
}

/// Linear `LO:HI:N` ranges, a plot with the Hertz curve, and a profile file.
#[test]
fn range_plot_and_profile() {
    let stack = reference_dir().join("stack_h100um_E2E1_0.2.toml");
    let svg = tmp("force.svg");
    let prof = tmp("profile.csv");
    let out = strata()
        .arg("asperity")
        .arg(&stack)
        .args(["--radius", "1e-4", "--delta", "0:2e-6:5", "--plot"])
        .arg(&svg)
        .arg("--profile")
        .arg(&prof)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let d: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(d, vec![0.0, 5e-7, 1e-6, 1.5e-6, 2e-6]);
    let svg_text = std::fs::read_to_string(&svg).unwrap();
    assert!(svg_text.contains("<svg") && svg_text.contains("Hertz"));
    let p = std::fs::read_to_string(&prof).unwrap();
    assert!(p.starts_with("delta,r,pressure,displacement\n"));
    // At r = 0 the displacement equals δ and the pressure is positive.
    let first: Vec<f64> = p
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(first[0], 5e-7);
    assert!(first[2] > 0.0);
    assert!((first[3] - 5e-7).abs() < 1e-18);
}

fn fails_with(args: &[&str], needle: &str) {
    let stack = reference_dir().join("stack_h100um_E2E1_5.toml");
    let out = strata()
        .arg("asperity")
        .arg(&stack)
        .args(args)
        .output()
        .unwrap();
    assert!(!out.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(needle), "{args:?}: {err}");
}

#[test]
fn bad_inputs_give_clear_errors() {
    fails_with(&["--radius", "0", "--delta", "1e-7"], "--radius");
    fails_with(&["--radius", "-1e-4", "--delta", "1e-7"], "--radius");
    fails_with(&["--radius", "inf", "--delta", "1e-7"], "--radius");
    fails_with(&["--radius", "1e-4", "--delta", "-1e-7"], "--delta");
    fails_with(&["--radius", "1e-4", "--delta", "nan"], "--delta");
    fails_with(&["--radius", "1e-4", "--delta", ""], "--delta");
    // `--model approx` is served from the tables and tested there.
    fails_with(
        &["--radius", "1e-4", "--delta", "1e-7", "--plot", "x.pdf"],
        ".svg or .png",
    );
    let out = strata()
        .args([
            "asperity",
            "/nonexistent.toml",
            "--radius",
            "1",
            "--delta",
            "1",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
}
