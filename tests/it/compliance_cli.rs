//! End-to-end tests of `strata compliance` and of stack-file errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn strata(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .output()
        .expect("run strata")
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp_stack(name: &str, text: &str) -> PathBuf {
    let dir = crate::support::scratch().join("cli");
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn parse_csv(out: &[u8]) -> Vec<(f64, f64)> {
    let text = String::from_utf8(out.to_vec()).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("rho_h,k_z"));
    lines
        .map(|l| {
            let (a, b) = l.split_once(',').unwrap();
            (a.parse().unwrap(), b.parse().unwrap())
        })
        .collect()
}

/// The paper's stack: values equal the closed-form-checked library to the last bit
/// (full precision in the CSV), k_z(ρh₁ = 10) ≈ −2.8e-7 and k_z → −1 at small ρh₁.
#[test]
fn compliance_prints_full_precision_csv() {
    let stack = repo().join("tables/stacks/paper-two-layer.toml");
    let out = strata(&[
        "compliance",
        stack.to_str().unwrap(),
        "--rho-h",
        "0.01,0.1,1,10",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = parse_csv(&out.stdout);
    assert_eq!(rows.len(), 4);
    let s = strata_runtime::Stack::from_toml_file(&stack).unwrap();
    let c = strata_runtime::Compliance::new(&s);
    for (x, kz) in &rows {
        assert_eq!(*kz, c.kz(x / 1e-4), "bit-exact round trip at rho_h = {x}");
    }
    assert!(rows[0].1 < -0.98 && rows[0].1 > -1.0);
    assert!(rows[3].1 < 0.0 && rows[3].1 > -1e-6);
}

#[test]
fn compliance_log_range() {
    let stack = repo().join("tables/stacks/coating-on-steel.toml");
    let out = strata(&[
        "compliance",
        stack.to_str().unwrap(),
        "--rho-h",
        "1e-3:1e3:7:log",
    ]);
    assert!(out.status.success());
    let rows = parse_csv(&out.stdout);
    assert_eq!(rows.len(), 7);
    assert_eq!(rows[0].0, 1e-3);
    assert_eq!(rows[6].0, 1e3);
    assert!((rows[3].0 - 1.0).abs() < 1e-14);
    // Stiff coating on softer steel: S(0) = E*₁/E*_b > 1, so k_z > 0, falling to 0.
    let s0 = (400e9 / (1.0 - 0.25f64 * 0.25)) / (210e9 / (1.0 - 0.09)) - 1.0;
    assert!((rows[0].1 - s0).abs() < 1e-2 * s0);
    assert!(rows[6].1.abs() < 1e-15);
    // A homogeneous half-space: k_z ≡ 0.
    let hs = repo().join("tables/stacks/half-space-steel.toml");
    let out = strata(&["compliance", hs.to_str().unwrap(), "--rho-h", "0.1,1,10"]);
    assert!(out.status.success());
    assert!(parse_csv(&out.stdout).iter().all(|r| r.1 == 0.0));
    // One spelling everywhere: LO:HI:N is linear (here too), with a hint on stderr.
    let out = strata(&[
        "compliance",
        stack.to_str().unwrap(),
        "--rho-h",
        "0.01:100:3",
    ]);
    assert!(out.status.success());
    let rows = parse_csv(&out.stdout);
    let want = [0.01, 0.01 + (100.0 - 0.01) * 0.5, 100.0];
    assert_eq!(rows.iter().map(|r| r.0).collect::<Vec<_>>(), want);
    assert!(String::from_utf8_lossy(&out.stderr).contains(":log for log spacing"));
}

/// Moduli outside [1e-3, 1e15] Pa (E₁ = 1e-300, a 1e300 base) are refused as in every
/// other command, naming the file and the field; k_z is never printed as NaN.
#[test]
fn unrepresentable_moduli_are_refused() {
    for (name, layer_e, base_e, needle) in [
        ("tiny.toml", "1e-300", "1e9", "layer 1"),
        ("huge.toml", "4e9", "1e300", "base"),
    ] {
        let p = tmp_stack(
            name,
            &format!(
                "[[layer]]\nthickness = 1e-4\nyoung = {layer_e}\npoisson = 0.3\n[base]\nkind = \"elastic\"\nyoung = {base_e}\npoisson = 0.3\n"
            ),
        );
        assert_fails(
            &["compliance", p.to_str().unwrap(), "--rho-h", "1e-4,1,1e4"],
            &[p.to_str().unwrap(), needle, "young", "[1e-3, 1e15]"],
        );
    }
}

fn assert_fails(args: &[&str], needles: &[&str]) {
    let out = strata(args);
    assert!(!out.status.success(), "expected failure for {args:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "one-line error, got: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "error `{err}` should mention `{n}`");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(out.stdout.is_empty(), "nothing on stdout on error");
}

#[test]
fn bad_stack_files_give_one_line_errors() {
    let ok_layer = "[[layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 0.15\n";
    let cases: Vec<(&str, String, Vec<&str>)> = vec![
        ("missing.toml", format!("{ok_layer}[[layer]]\nthickness = 1e-4\npoisson = 0.2\n[base]\nkind = \"rigid\"\n"), vec!["layer 2", "young"]),
        ("nan.toml", format!("{ok_layer}[[layer]]\nthickness = nan\nyoung = 1e9\npoisson = 0.2\n[base]\nkind = \"rigid\"\n"), vec!["layer 2", "thickness", "finite"]),
        ("neg.toml", "[[layer]]\nthickness = -1e-4\nyoung = 4e9\npoisson = 0.15\n[base]\nkind = \"rigid\"\n".into(), vec!["layer 1", "thickness"]),
        ("zeroE.toml", "[[layer]]\nthickness = 1e-4\nyoung = 0.0\npoisson = 0.15\n[base]\nkind = \"rigid\"\n".into(), vec!["layer 1", "young"]),
        ("nu.toml", format!("{ok_layer}[base]\nkind = \"elastic\"\nyoung = 1e9\npoisson = 0.7\n"), vec!["base", "poisson"]),
        ("norigid.toml", "name = \"x\"\n[base]\nkind = \"rigid\"\n".into(), vec!["no layers"]),
        ("unknown.toml", "[[layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 0.15\ndensity = 7800\n[base]\nkind = \"rigid\"\n".into(), vec!["layer 1", "density"]),
        ("syntax.toml", "[[layer]\nthickness = \n".into(), vec!["TOML"]),
    ];
    for (name, text, needles) in cases {
        let p = tmp_stack(name, &text);
        assert_fails(
            &["compliance", p.to_str().unwrap(), "--rho-h", "1"],
            &needles,
        );
    }
    assert_fails(
        &["compliance", "/nonexistent/stack.toml", "--rho-h", "1"],
        &["cannot read", "stack.toml"],
    );
}

#[test]
fn bad_rho_h_flags() {
    let stack = repo().join("tables/stacks/paper-two-layer.toml");
    let s = stack.to_str().unwrap();
    assert_fails(&["compliance", s, "--rho-h", "abc"], &["--rho-h", "abc"]);
    assert_fails(
        &["compliance", s, "--rho-h", "0:10:5:log"],
        &["--rho-h", "LO > 0"],
    );
    assert_fails(
        &["compliance", s, "--rho-h", "1:10:5:cubic"],
        &["--rho-h", "LO:HI:N:log"],
    );
    assert_fails(&["compliance", s, "--rho-h", "-1"], &["--rho-h", ">= 0"]);
    assert_fails(&["compliance", s, "--rho-h", ""], &["--rho-h", "empty"]);
    let _ = Path::new(s);
}

/// `--tangential`: the header, the library's values to the last bit (full precision
/// in the CSV), S_zz equal to today's S to the bit and to 1 + k_z of the plain command
/// (to round-off: k_z = S − 1 is rounded), and the ρh₁ → ∞ values
/// S_zz = S_LL = S_TT = 1, S_zL = (1−2ν₁)/(2(1−ν₁)) on the paper's stack.
#[test]
fn compliance_tangential_prints_four_columns() {
    let stack = repo().join("tables/stacks/paper-two-layer.toml");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "compliance",
            stack.to_str().unwrap(),
            "--rho-h",
            "0.01,1,100",
        ];
        args.extend_from_slice(extra);
        let out = strata(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let text = run(&["--tangential"]);
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("rho_h,S_zz,S_LL,S_TT,S_zL"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 3);
    let s = strata_runtime::Stack::from_toml_file(&stack).unwrap();
    let c = strata_runtime::compliance::tangential::TangentialCompliance::new(&s);
    let h1 = s.top_thickness().unwrap();
    let normal = strata_runtime::Compliance::new(&s);
    let kz = parse_csv(run(&[]).as_bytes());
    for (row, (_, k)) in rows.iter().zip(&kz) {
        let v = c.eval(row[0] / h1);
        assert_eq!(row[1..], [v.s_zz, v.s_ll, v.s_tt, v.s_zl]);
        assert_eq!(row[1], normal.s(row[0] / h1));
        assert!((row[1] - (1.0 + k)).abs() < 1e-15);
    }
    let (_, nu1) = s.top_material();
    let last = &rows[2];
    assert!((last[1] - 1.0).abs() < 1e-12 && (last[2] - 1.0).abs() < 1e-12);
    assert!((last[3] - 1.0).abs() < 1e-12);
    assert!((last[4] - (1.0 - 2.0 * nu1) / (2.0 * (1.0 - nu1))).abs() < 1e-12);
    // --tangential with --thermal is refused by the argument parser.
    let out = strata(&[
        "compliance",
        stack.to_str().unwrap(),
        "--rho-h",
        "1",
        "--tangential",
        "--thermal",
    ]);
    assert!(!out.status.success());
}
