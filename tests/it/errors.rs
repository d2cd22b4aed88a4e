//! One error chain per failure: each context once, the file named,
//! and what relative paths are relative to.

use std::path::{Path, PathBuf};

use crate::support::{fresh_dir, repo, stderr_of, strata_in};

fn dir(name: &str) -> PathBuf {
    fresh_dir("errors", name)
}

/// The error line, checked: exit 1, one line, `error: ` once, no `: `-separated part
/// repeated.
fn error_line(d: &Path, args: &[&str]) -> String {
    let o = strata_in(&d.join("cache")).args(args).output().unwrap();
    let e = stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    let line = e.trim_end();
    assert_eq!(line.lines().count(), 1, "one line: {e}");
    assert_eq!(line.matches("error:").count(), 1, "{e}");
    let parts: Vec<&str> = line.split(": ").filter(|p| p.len() >= 6).collect();
    for (i, p) in parts.iter().enumerate() {
        assert!(!parts[i + 1..].contains(p), "`{p}` repeated in: {line}");
    }
    line.to_string()
}

const GENERATED: &str = "[surface.generate]\nsize = 1e-3\ngrid = 256\nfractal_dimension = 2.4\n\
                         k_min = 2\nk_max = 200\nrms = 3.4e-6\nseed = 1\n";

/// The typical case: one chain naming the scene file and the field.
#[test]
fn surface_errors_are_reported_once() {
    let d = dir("kmax");
    let sc = d.join("bad.toml");
    std::fs::write(
        &sc,
        format!(
            "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
             [surface]\n{GENERATED}[model]\nkind = \"independent\"\n[load]\nseparations = [1e-6]\n"
        ),
    )
    .unwrap();
    let e = error_line(
        &d,
        &["solve", sc.to_str().unwrap(), "--out", "/nonexistent/o"],
    );
    assert_eq!(
        e,
        format!(
            "error: scene {}: surface: field `generate.k_max` = 200 is invalid: must satisfy k_min ≤ k_max ≤ grid/2",
            sc.display()
        )
    );
}

/// Stack-file errors name the stack file and the scene; a missing file says what the
/// relative path was relative to; the same stack error reads the same in `compliance`,
/// `asperity`, `table build` and `solve`.
#[test]
fn files_are_named_and_relative_paths_explained() {
    let d = dir("files");
    std::fs::create_dir_all(d.join("stacks")).unwrap();
    let stack = d.join("stacks/bad.toml");
    std::fs::write(
        &stack,
        "[[layer]]\nthickness = 1e-4\nyoung = -4e9\npoisson = 0.15\n[base]\nkind = \"rigid\"\n",
    )
    .unwrap();
    let scene = |name: &str, stack_file: &str| {
        let p = d.join(name);
        std::fs::write(
            &p,
            format!(
                "[stack]\nfile = \"{stack_file}\"\n[surface]\n{}[model]\nkind = \"independent\"\n\
                 [load]\nseparations = [1e-6]\n",
                GENERATED.replace("200", "10")
            ),
        )
        .unwrap();
        p
    };
    let sc = scene("s.toml", "stacks/bad.toml");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let want = format!(
        "stack file {}: layer 1: field `young` = -4000000000.0 is invalid: Young modulus must be > 0 (Pa)",
        stack.display()
    );
    let e = error_line(&d, &["solve", &s(&sc), "--out", &s(&d.join("o"))]);
    assert_eq!(e, format!("error: scene {}: {want}", sc.display()));
    for args in [
        vec!["compliance", &s(&stack), "--rho-h", "1"],
        vec![
            "asperity",
            &s(&stack),
            "--radius",
            "1e-3",
            "--delta",
            "1e-7",
        ],
        vec![
            "table",
            "build",
            &s(&stack),
            "--out",
            &s(&d.join("t.strata")),
        ],
    ]
    .iter()
    {
        let e = error_line(&d, args);
        assert_eq!(e, format!("error: {want}"), "{args:?}");
    }
    let missing = scene("m.toml", "stacks/none.toml");
    let e = error_line(&d, &["law", &s(&missing), "--out", &s(&d.join("law.csv"))]);
    assert!(
        e.contains("stack.file = \"stacks/none.toml\"")
            && e.contains(&format!(
                "no such file {}",
                d.join("stacks/none.toml").display()
            ))
            && e.contains(&format!(
                "relative to the scene's directory, {}",
                d.display()
            )),
        "{e}"
    );
    // A directory where a file is expected says so (it said "no such file").
    let folder = scene("f.toml", "stacks");
    let e = error_line(&d, &["solve", &s(&folder), "--out", &s(&d.join("o"))]);
    assert!(
        e.contains(&format!(
            "stack.file = \"stacks\": a directory, not a file: {}",
            d.join("stacks").display()
        )),
        "{e}"
    );
    // Sweeps name the sweep file and the base scene.
    let sw = d.join("sweep.toml");
    std::fs::write(&sw, "scene = \"s.toml\"\n[sweep]\nsurface.seed = [1, 2]\n").unwrap();
    let e = error_line(&d, &["sweep", &s(&sw), "--out", &s(&d.join("sw"))]);
    assert!(
        e.starts_with(&format!(
            "error: sweep {}: scene {}: stack file",
            sw.display(),
            sc.display()
        )),
        "{e}"
    );
    let _ = repo();
}

/// Every command's bad input gives one chain without repeats.
#[test]
fn bad_inputs_give_one_chain_each() {
    let d = dir("misc");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let table = repo().join("tables/paper-two-layer.strata");
    let stack = repo().join("tables/stacks/paper-two-layer.toml");
    for args in [
        vec![
            "solve".to_string(),
            s(&d.join("none.toml")),
            "--out".into(),
            s(&d.join("o")),
        ],
        vec!["table".into(), "info".into(), s(&d.join("none.strata"))],
        vec!["table".into(), "check".into(), s(&stack)],
        vec![
            "asperity".into(),
            s(&stack),
            "--radius".into(),
            "1e-3".into(),
            "--delta".into(),
            "1:2:3:cubic".into(),
        ],
        vec![
            "asperity".into(),
            s(&stack),
            "--radius".into(),
            "1e-3".into(),
            "--delta".into(),
            "1e-7".into(),
            "--model".into(),
            "approx".into(),
            "--table".into(),
            s(&stack),
        ],
        vec![
            "compliance".into(),
            s(&stack),
            "--rho-h".into(),
            "0:1:3:log".into(),
        ],
        vec![
            "sweep".into(),
            "merge".into(),
            s(&d),
            "--out".into(),
            s(&d.join("m.csv")),
        ],
    ] {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        error_line(&d, &a);
    }
    // An output directory that holds the working directory is refused (it would be
    // replaced as a whole); run from a scratch directory.
    let o = strata_in(&d.join("cache"))
        .current_dir(&d)
        .args(["table", "export", &s(&table), "--npy", ".", "--force"])
        .output()
        .unwrap();
    let e = stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("--npy .: is the current directory"), "{e}");
}

/// TOML syntax errors are one line with the line and column (they once
/// spanned five lines with a source excerpt), in scenes and stack files.
#[test]
fn toml_syntax_errors_are_one_line() {
    let d = crate::support::fresh_dir("errors", "toml-one-line");
    let scene = d.join("bad.toml");
    std::fs::write(&scene, "[stack]\nfile = 3 x\n").unwrap();
    let stack = d.join("st.toml");
    std::fs::write(&stack, "name = \"x\"\n[[layer]]\nthickness = \n").unwrap();
    for (args, want) in [
        (
            vec![
                "solve".to_string(),
                scene.display().to_string(),
                "--out".into(),
                d.join("o").display().to_string(),
            ],
            "line 2, column 8",
        ),
        (
            vec![
                "compliance".to_string(),
                stack.display().to_string(),
                "--rho-h".into(),
                "1".into(),
            ],
            "line 3, column 13",
        ),
    ] {
        let o = crate::support::run_strata(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(want), "{err}");
    }
}
