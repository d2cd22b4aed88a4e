//! End-to-end tests of `strata table build|info|check|export` and of the shipped
//! family table `tables/paper-two-layer.strata` against the shared reference data
//! (`../shared/reference`, an independent implementation).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use strata_runtime::Stack;
use strata_runtime::law::{self, AsperityLaw};
use strata_runtime::table::Table;

fn strata(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_strata"));
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run strata")
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn reference(name: &str) -> PathBuf {
    repo().join("tests/reference").join(name)
}

fn tmp(name: &str) -> PathBuf {
    let dir = crate::support::scratch().join("tables");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn rows(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with(|c: char| c.is_alphabetic()))
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

fn shipped() -> Table {
    Table::load(&repo().join("tables/paper-two-layer.strata")).expect("shipped table loads")
}

/// Build (twice, reproducibly), info, check and export of a small single-stack table.
#[test]
fn build_info_check_export() {
    let stack = repo().join("tables/stacks/paper-two-layer.toml");
    let (a, b) = (tmp("a.strata"), tmp("b.strata"));
    for out in [&a, &b] {
        let o = strata(
            &[
                "table",
                "build",
                stack.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--nx",
                "25",
                "--nw",
                "13",
                "--check-points",
                "0",
                "--tol",
                "1e-2",
                "--quiet",
            ],
            &[("SOURCE_DATE_EPOCH", "1700000000")],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    // Byte-for-byte reproducible with a fixed SOURCE_DATE_EPOCH.
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());

    let o = strata(&["table", "info", a.to_str().unwrap()], &[]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success());
    assert!(text.contains("format version: 2") && text.contains("build time: 1700000000"));
    assert!(text.contains("stated tolerance: 1e-2"), "{text}");
    assert!(text.contains("family: none"));

    let a_path = a.to_str().unwrap();
    let check = |extra: &[&str]| {
        let mut args = vec!["table", "check", a_path, "--points", "30", "--seed", "3"];
        args.extend_from_slice(extra);
        strata(&args, &[])
    };
    let o = check(&[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    let last: Vec<f64> = text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    eprintln!("coarse table check: {last:?}");
    assert_eq!(last[0], 30.0);
    // A coarse table (25 x nodes over six decades) is still good to ~1e-3, within
    // its stated tolerance 1e-2; the far field (rigid base) is exact.
    assert!(
        last[2] < 1e-2 && last[3] < 1e-2 && last[4] < 1e-2 && last[5] < 1e-7,
        "{last:?}"
    );
    assert_eq!(last[6], 1e-2);

    // The same table checked against a tighter tolerance fails: exit 1, the measured
    // error and the tolerance named.
    let o = check(&["--tol", "1e-6"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("table check failed") && err.contains("exceeds the tolerance 1.000e-6"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");

    let dir = tmp("npy");
    let o = strata(
        &[
            "table",
            "export",
            a.to_str().unwrap(),
            "--npy",
            dir.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let chi = std::fs::read(dir.join("chi.npy")).unwrap();
    assert_eq!(&chi[..6], b"\x93NUMPY");
    let header = String::from_utf8_lossy(&chi[..128]);
    assert!(header.contains("(1, 25)"), "{header}");
    assert!(dir.join("g_r_over_a3.npy").exists() && dir.join("ln_x.npy").exists());
}

/// A deliberately coarse grid, or a tolerance no grid meets, is refused by `table
/// build`: exit 1, the measured error and the tolerance in the message, no file.
#[test]
fn build_above_tolerance_refused() {
    let stack = repo().join("tables/stacks/paper-two-layer.toml");
    for (extra, msg) in [
        (
            ["--nx", "7", "--nw", "7"],
            "exceeds the stated tolerance 1.000e-4",
        ),
        (
            ["--tol", "1e-12", "--nw", "13"],
            "exceeds the stated tolerance 1.000e-12",
        ),
    ] {
        let out = tmp("refused.strata");
        let mut args = vec![
            "table",
            "build",
            stack.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--check-points",
            "30",
            "--quiet",
        ];
        args.extend_from_slice(&extra);
        let o = strata(&args, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{extra:?}: {err}");
        assert!(err.contains(msg) && err.contains("measured"), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "a refused table must not be written");
    }
    // 0, and above 1 (a table stating a relative tolerance of 1e30 passed any check).
    for tol in ["0", "1e30", "nan"] {
        let never = tmp("never.strata");
        let o = strata(
            &[
                "table",
                "build",
                stack.to_str().unwrap(),
                "--out",
                never.to_str().unwrap(),
                "--tol",
                tol,
            ],
            &[],
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            o.status.code() == Some(1) && err.contains("--tol must be in (0, 1]"),
            "{tol}: {err}"
        );
        assert!(!never.exists());
    }
}

/// Bad table files and bad arguments: clear errors, no panic.
#[test]
fn bad_files_and_arguments() {
    let good = std::fs::read(repo().join("tables/paper-two-layer.strata")).unwrap();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("trunc.strata", good[..good.len() / 2].to_vec(), "truncated"),
        (
            "garbage.strata",
            b"hello, world: not a table".to_vec(),
            "not a strata table",
        ),
        (
            "version.strata",
            {
                let mut v = good.clone();
                v[8] = 7;
                v
            },
            "version 7",
        ),
        (
            "corrupt.strata",
            {
                let mut v = good.clone();
                let k = v.len() - 100;
                v[k] ^= 1;
                v
            },
            "corrupt",
        ),
    ];
    for (name, bytes, msg) in cases {
        let p = tmp(name);
        std::fs::write(&p, bytes).unwrap();
        let o = strata(&["table", "info", p.to_str().unwrap()], &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{name}");
        assert!(err.contains(msg), "{name}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let stack = repo().join("tables/stacks/paper-two-layer.toml");
    for (vary, msg) in [
        ("1:0.1:10:9", "LAYER must be >= 2"),
        ("2:10:0.1:9", "LO < HI"),
        ("x:1:2:9", "layer number or `base`"),
        ("base:0.5:2:9", "rigid"),
        ("3:0.5:2:9", "layer 3 cannot vary"),
    ] {
        let o = strata(
            &[
                "table",
                "build",
                stack.to_str().unwrap(),
                "--out",
                tmp("never.strata").to_str().unwrap(),
                "--vary",
                vary,
                "--quiet",
            ],
            &[],
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(msg), "{vary}: {err}");
    }
}

/// The shipped family table reproduces the reference χ, ζ (E2/E1 = 5, off the family
/// grid) to 1e-4 and refuses stacks outside the family.
#[test]
fn shipped_table_matches_reference_chi_zeta() {
    let t = shipped();
    let e = t
        .header
        .interp_error
        .expect("shipped table records its check");
    eprintln!("shipped table header check: {e:?}");
    assert!(e.points >= 1000 && e.exceeds(1e-4).is_none(), "{e:?}");
    assert_eq!(t.header.tolerance, 1e-4);
    let stack = Stack::from_toml_file(&reference("stack_h100um_E2E1_5.toml")).unwrap();
    let law = t.law_for(&stack).unwrap();
    let mut worst: f64 = 0.0;
    for r in rows(&reference("chi_zeta_h100um_E2E1_5.csv")) {
        worst = worst
            .max((law.chi(r[0]) / r[2] - 1.0).abs())
            .max((law.zeta(r[0]) / r[3] - 1.0).abs());
    }
    eprintln!("shipped table vs reference chi/zeta: max rel {worst:e}");
    assert!(worst < 1e-4, "{worst}");
    let mut worst_g: f64 = 0.0;
    for r in rows(&reference("g_h100um_E2E1_5.csv")) {
        let (a, rr) = (r[0], r[1]);
        worst_g = worst_g.max((law.g(a, rr) - r[2]).abs() / (4.0 / 3.0 * a.powi(3) / rr));
    }
    eprintln!("shipped table vs reference g: max {worst_g:e} of (4/3)a^3/r");
    assert!(worst_g < 1e-4, "{worst_g}");
    let mut layers = stack.layers().to_vec();
    layers[1].young = 20.0 * layers[0].young;
    let st = Stack::new(layers, stack.base()).unwrap();
    let e = t.law_for(&st).unwrap_err().to_string();
    assert!(e.contains("outside the table's family range"), "{e}");
}

/// The approximate force (table) against the full Fredholm force of the reference
/// (paraboloid R = 100 µm, E2/E1 = 0.2 and 5) at the same interference δ:
/// within 1 % (the paper reports ≤ 1 %).
#[test]
fn approximate_force_within_one_percent_of_full() {
    let t = shipped();
    let radius = 1e-4;
    for ratio in ["0.2", "5"] {
        let stack =
            Stack::from_toml_file(&reference(&format!("stack_h100um_E2E1_{ratio}.toml"))).unwrap();
        let law = t.law_for(&stack).unwrap();
        let mut worst: f64 = 0.0;
        for r in rows(&reference(&format!("axisym_h100um_E2E1_{ratio}.csv"))) {
            let (delta, force) = (r[0], r[2]);
            // Solve δ = ζ(a) a²/R for a by bisection (monotone over the range).
            let (mut lo, mut hi) = (1e-9_f64, 1e-2_f64);
            for _ in 0..200 {
                let mid = (lo * hi).sqrt();
                if law::interference(&law, mid, radius) < delta {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let p = law::force(&law, lo, radius);
            worst = worst.max((p / force - 1.0).abs());
        }
        eprintln!("E2/E1 = {ratio}: max |P_approx/P_full - 1| = {worst:e}");
        assert!(worst < 0.01, "{ratio}: {worst}");
    }
}

/// The approximate force (shipped table) against the full Fredholm solution of
/// strata-tablegen (`Asperity`) for the paper's stacks (E2/E1 = 0.2, 1, 5) at equal
/// approach δ, R = 100 µm: within 1 % for a/h₁ ≤ 0.5 (paper: ≤ 1 %; its contacts
/// have a/h₁ ≲ 0.2; measured ≤ 1e-3 there). Beyond, the parabolic trial function
/// degrades when the sub-layer differs from the layer (printed, not asserted: at
/// a/h₁ = 1, −0.8 % for E2/E1 = 0.2 and +1.6 % for 5; at a/h₁ = 3, −5.7 % and +13 %).
#[test]
fn approximate_force_vs_fredholm() {
    use strata_tablegen::asperity::{Asperity, Options};
    let t = shipped();
    let radius = 1e-4;
    for ratio in ["0.2", "1", "5"] {
        let stack =
            Stack::from_toml_file(&reference(&format!("stack_h100um_E2E1_{ratio}.toml"))).unwrap();
        let law = t.law_for(&stack).unwrap();
        let full = Asperity::new(&stack, Options::default()).unwrap();
        let mut worst: f64 = 0.0;
        for x in [0.05, 0.2, 0.5, 1.0, 2.0, 3.0] {
            let s = full.paraboloid_at_radius(x * 1e-4, radius).unwrap();
            let (mut lo, mut hi) = (1e-9_f64, 1e-2_f64);
            for _ in 0..200 {
                let mid = (lo * hi).sqrt();
                if law::interference(&law, mid, radius) < s.delta {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let p = law::force(&law, lo, radius);
            eprintln!(
                "  E2/E1 = {ratio}, a/h = {x}: delta {:e} P_full {:e} P_approx {p:e} ({:+.2e})",
                s.delta,
                s.force,
                p / s.force - 1.0
            );
            if x <= 0.5 {
                worst = worst.max((p / s.force - 1.0).abs());
            }
        }
        eprintln!("E2/E1 = {ratio}: max |P_approx/P_fredholm - 1| = {worst:e} (a/h 0.05 … 0.5)");
        assert!(worst < 0.01, "{ratio}: {worst}");
    }
}

/// `strata asperity --model approx --table FILE` against `--model full` (within 1 %
/// at a/h₁ ≲ 0.2), and refusal of a stack outside the table's family.
#[test]
fn asperity_cli_approx_from_table() {
    let stack = reference("stack_h100um_E2E1_0.2.toml");
    let table = repo().join("tables/paper-two-layer.strata");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "asperity",
            stack.to_str().unwrap(),
            "--radius",
            "1e-4",
            "--delta",
            "1e-6,3e-6",
        ];
        args.extend_from_slice(extra);
        let o = strata(&args, &[]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| {
                l.split(',')
                    .map(|v| v.parse::<f64>().unwrap())
                    .collect::<Vec<_>>()
            })
            .collect::<Vec<_>>()
    };
    let approx = run(&["--model", "approx", "--table", table.to_str().unwrap()]);
    let full = run(&["--model", "full"]);
    assert_eq!(approx.len(), 2);
    for (p, f) in approx.iter().zip(&full) {
        assert_eq!(p[0], f[0]);
        assert!((p[2] / f[2] - 1.0).abs() < 0.01, "{p:?} vs {f:?}");
        assert!((p[1] / f[1] - 1.0).abs() < 0.01, "{p:?} vs {f:?}");
    }
    // A single-layer stack is not in the two-layer family.
    let one = tmp("one.toml");
    std::fs::write(
        &one,
        "[[layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 0.15\n[base]\nkind = \"rigid\"\n",
    )
    .unwrap();
    let o = strata(
        &[
            "asperity",
            one.to_str().unwrap(),
            "--radius",
            "1e-4",
            "--delta",
            "1e-6",
            "--model",
            "approx",
            "--table",
            table.to_str().unwrap(),
        ],
        &[],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("cannot serve this stack"),
        "{err}"
    );
}
