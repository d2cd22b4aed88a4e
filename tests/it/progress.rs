//! Progress on long operations: with stderr a pipe, periodic log
//! lines (interval shortened through STRATA_LOG_INTERVAL); on a pseudo-terminal,
//! indicatif bars; `--quiet` silences both.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::support::{fresh_dir, repo, stderr_of, strata_in};

fn dir(name: &str) -> PathBuf {
    fresh_dir("progress", name)
}

/// Runs strata with stderr a pipe and log lines every 50 ms.
fn logged(cache: &Path, args: &[&str]) -> Output {
    let o = strata_in(cache)
        .env("STRATA_LOG_INTERVAL", "0.05")
        .args(args)
        .output()
        .expect("run strata");
    assert!(o.status.success(), "{}", stderr_of(&o));
    o
}

fn bem_scene(d: &Path) -> PathBuf {
    let p = d.join("bem.toml");
    std::fs::write(
        &p,
        format!(
            "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
             [surface]\nfile = \"{}\"\nsize = 1e-3\nperiodic = true\n[model]\nkind = \"bem\"\n\
             [load]\nseparations = [7e-6, 5e-6]\n",
            repo().join("tests/reference/surface_km10.npy").display()
        ),
    )
    .unwrap();
    p
}

/// BEM load steps, a table build, a table check and law sampling each log their count,
/// elapsed time and a last line when done.
#[test]
fn long_operations_log_progress_lines() {
    let d = dir("log");
    let cache = d.join("cache");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let sc = bem_scene(&d);
    let e = stderr_of(&logged(
        &cache,
        &["solve", &s(&sc), "--out", &s(&d.join("o"))],
    ));
    assert!(e.contains("BEM 512×512: load steps: 1/2 (50 %)"), "{e}");
    assert!(e.contains("elapsed") && e.contains("(done)"), "{e}");
    let stack = repo().join("tables/stacks/paper-two-layer.toml");
    let table = d.join("t.strata");
    let e = stderr_of(&logged(
        &cache,
        &[
            "table",
            "build",
            &s(&stack),
            "--out",
            &s(&table),
            "--nx",
            "13",
            "--nw",
            "7",
            "--check-points",
            "40",
            "--tol",
            "1",
        ],
    ));
    assert!(e.contains("building table: "), "{e}");
    assert!(e.contains("checking table: "), "{e}");
    let e = stderr_of(&logged(
        &cache,
        &["table", "check", &s(&table), "--points", "60", "--tol", "1"],
    ));
    assert!(e.contains("table check: direct solves: "), "{e}");
    let interacting = d.join("i.toml");
    std::fs::write(
        &interacting,
        std::fs::read_to_string(&sc)
            .unwrap()
            .replace("\"bem\"", "\"interacting\""),
    )
    .unwrap();
    let e = stderr_of(&logged(
        &cache,
        &[
            "law",
            &s(&interacting),
            "--out",
            &s(&d.join("law.csv")),
            "--samples",
            "20000",
        ],
    ));
    assert!(e.contains("law: sampling 20000 separations: "), "{e}");
}

/// On a pseudo-terminal (`script`), indicatif draws its bar in place (cursor control
/// and `[elapsed]`); `--quiet` prints no progress and no log line on stderr (warnings
/// and errors still).
#[test]
fn a_terminal_gets_bars_and_quiet_gets_nothing() {
    let d = dir("tty");
    let cache = d.join("cache");
    let sc = bem_scene(&d);
    let script = Path::new("/usr/bin/script");
    assert!(
        script.is_file(),
        "{} (util-linux/bsdutils) is needed for the pseudo-terminal test",
        script.display()
    );
    let cmd = format!(
        "{} solve {} --out {}",
        env!("CARGO_BIN_EXE_strata"),
        sc.display(),
        d.join("o").display()
    );
    let o = std::process::Command::new(script)
        .args(["-qfec", &cmd, "/dev/null"])
        .env("STRATA_CACHE_DIR", &cache)
        .env_remove("STRATA_PROGRESS")
        .output()
        .expect("script");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}");
    assert!(text.contains("BEM 512×512: load steps"), "{text}");
    assert!(
        text.contains("\u{1b}[") && text.contains("[00:00:0"),
        "{text}"
    );
    let o = strata_in(&cache)
        .args(["--quiet", "solve", sc.to_str().unwrap(), "--out"])
        .arg(d.join("q"))
        .output()
        .unwrap();
    assert!(o.status.success());
    // warnings (here: the elastic peak pressure above 0.1 E*) and errors only
    let e = stderr_of(&o);
    assert!(e.lines().all(|l| l.starts_with("WARNING: ")), "{e}");
}

/// `strata conductance --a` reports progress per spot (it ran minutes at a/h1 ≥ 2000
/// without a line) and notes the spots large against the top layer, whose cost grows
/// as (a/h1)^1.5; a/h1 = 100 here (20 µm coating, a = 2 mm) keeps it short.
#[test]
fn conductance_reports_progress_per_spot_and_notes_large_spots() {
    let d = crate::support::fresh_dir("progress", "conductance");
    let stack = crate::support::repo().join("tables/stacks/coating-on-steel-conducting.toml");
    let o = crate::support::strata_in(&d)
        .env("STRATA_PROGRESS", "log")
        .env("STRATA_LOG_INTERVAL", "0.05")
        .arg("conductance")
        .arg(&stack)
        .args(["--a", "1e-6,2e-3"])
        .output()
        .unwrap();
    let e = crate::support::stderr_of(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("note: 1 of the 2 spots have a/h1 ≥ 100 (largest 1.000e2)"),
        "{e}"
    );
    assert!(
        e.contains("conductance: spot a = 2e-3 m (a/h1 = 1.000e2): 2/2 (100 %)")
            && e.contains("(done)"),
        "{e}"
    );
}

/// `strata asperity --counterface` with a many-layer counterface reports progress per
/// approach and says how many layers the solid has (1000 layers ran ~40 s without a line).
#[test]
fn asperity_on_a_many_layer_counterface_reports_progress() {
    let d = crate::support::fresh_dir("progress", "asperity-layers");
    let mut cf = String::from("name = \"graded counterface\"\n");
    for i in 0..120 {
        cf += &format!(
            "[[layer]]\nthickness = 1e-8\nyoung = {:e}\npoisson = 0.3\n",
            100e9 * (1.0 + i as f64 / 120.0)
        );
    }
    cf += "[base]\nkind = \"elastic\"\nyoung = 210e9\npoisson = 0.3\n";
    let cf_path = d.join("graded.toml");
    std::fs::write(&cf_path, cf).unwrap();
    let stack = crate::support::repo().join("tables/stacks/coating-on-steel.toml");
    let o = crate::support::strata_in(&d)
        .env("STRATA_PROGRESS", "log")
        .env("STRATA_LOG_INTERVAL", "0.05")
        .arg("asperity")
        .arg(&stack)
        .arg("--counterface")
        .arg(&cf_path)
        .args(["--radius", "1e-4", "--delta", "1e-8"])
        .output()
        .unwrap();
    let e = crate::support::stderr_of(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("asperity: 121 layers in the solid (both bodies)"),
        "{e}"
    );
    assert!(
        e.contains("asperity: delta = 1e-8 m: 1/1 (100 %)") && e.contains("(done)"),
        "{e}"
    );
}
