//! Shared helpers of the integration tests: where the repository and its reference data
//! are, and the `strata` binary.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The repository root (the `strata` package's manifest directory).
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The independent reference data, `tests/reference/` (provenance in its README).
/// Panics with the path when the directory is missing: these tests never skip.
pub fn reference_dir() -> PathBuf {
    let dir = repo().join("tests/reference");
    assert!(
        dir.join("README.md").is_file(),
        "reference data missing: {} (part of the repository)",
        dir.display()
    );
    dir
}

/// One reference file; panics with its path when it is missing.
#[allow(dead_code)]
pub fn reference(name: &str) -> PathBuf {
    let p = reference_dir().join(name);
    assert!(p.is_file(), "reference file missing: {}", p.display());
    p
}

/// A fresh, empty temporary directory for one test (`TAG-` below [`scratch`]).
#[allow(dead_code)]
pub fn temp_dir(tag: &str) -> PathBuf {
    fresh_dir(tag, "")
}

/// The `strata` binary, with the environment a test needs: no inherited progress or
/// kill settings, and the table cache in `cache` (never the user's).
#[allow(dead_code)]
pub fn strata_in(cache: &std::path::Path) -> std::process::Command {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_strata"));
    c.env("STRATA_CACHE_DIR", cache)
        .env_remove("STRATA_TEST_KILL_AT")
        .env_remove("STRATA_PROGRESS")
        .env_remove("STRATA_LOG_INTERVAL")
        .env_remove("STRATA_MEMORY_LIMIT");
    c
}

/// This run's scratch root, `$TMPDIR/strata-it-PID`: every test's files go below it.
/// On first use the roots of earlier runs whose process has ended are removed (on
/// Linux, where `/proc` tells), so the tests leave at most one run's files behind, kept
/// for inspection until the next run (a `cargo test --workspace` wrote ~22 MB that
/// nothing removed).
pub fn scratch() -> &'static Path {
    static ROOT: OnceLock<PathBuf> = OnceLock::new();
    ROOT.get_or_init(|| {
        let tmp = std::env::temp_dir();
        let me = std::process::id();
        if Path::new("/proc/self").exists() {
            for entry in std::fs::read_dir(&tmp).into_iter().flatten().flatten() {
                let name = entry.file_name();
                let pid = name.to_str().and_then(|n| n.strip_prefix("strata-it-"));
                let Some(pid) = pid.and_then(|p| p.parse::<u32>().ok()) else {
                    continue;
                };
                if pid != me && !Path::new(&format!("/proc/{pid}")).exists() {
                    let _ = std::fs::remove_dir_all(entry.path());
                }
            }
        }
        let root = tmp.join(format!("strata-it-{me}"));
        std::fs::create_dir_all(&root)
            .unwrap_or_else(|e| panic!("cannot create {}: {e}", root.display()));
        root
    })
}

/// A fresh temporary directory for one test, below [`scratch`].
#[allow(dead_code)]
pub fn fresh_dir(module: &str, name: &str) -> PathBuf {
    let d = scratch().join(format!("{module}-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// Every file below `dir` (relative path → bytes), hidden ones included; empty when
/// `dir` does not exist.
#[allow(dead_code)]
pub fn snapshot(dir: &std::path::Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    fn go(
        root: &std::path::Path,
        dir: &std::path::Path,
        out: &mut std::collections::BTreeMap<String, Vec<u8>>,
    ) {
        let Ok(rd) = std::fs::read_dir(dir) else {
            return;
        };
        for e in rd.filter_map(|e| e.ok()) {
            let p = e.path();
            if p.is_dir() {
                go(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).expect("below root");
                out.insert(
                    rel.to_string_lossy().into_owned(),
                    std::fs::read(&p).expect("read"),
                );
            }
        }
    }
    let mut out = std::collections::BTreeMap::new();
    go(dir, dir, &mut out);
    out
}

/// stderr of a finished command.
#[allow(dead_code)]
pub fn stderr_of(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs the `strata` binary with `args` (paths as given) and returns its output.
#[allow(dead_code)]
pub fn run_strata<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .output()
        .expect("run strata")
}

/// Scene text on a homogeneous solid (E = 4 GPa, ν = 0.15) with the given `[surface]`
/// body, `model.kind` (plus extra `[model]` lines) and `[load]` body.
#[allow(dead_code)]
pub fn homogeneous_scene(surface: &str, model: &str, load: &str) -> String {
    format!(
        "[stack]\n[[stack.layer]]\nthickness = 1e-3\nyoung = 4e9\npoisson = 0.15\n\
         [stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
         [surface]\n{surface}\n[model]\nkind = {model}\n[load]\n{load}\n"
    )
}

/// `strata solve SCENE --out OUT --no-plots`.
#[allow(dead_code)]
pub fn solve_no_plots(scene: &std::path::Path, out: &std::path::Path) -> std::process::Output {
    run_strata(&[
        std::ffi::OsStr::new("solve"),
        scene.as_os_str(),
        std::ffi::OsStr::new("--out"),
        out.as_os_str(),
        std::ffi::OsStr::new("--no-plots"),
    ])
}

/// The proptest configuration of the fuzz modules: `cases` cases (PROPTEST_CASES
/// overrides), a fixed seed per module (PROPTEST_RNG_SEED overrides), no persistence
/// files: CI runs the same cases every time; longer runs set the variables.
#[allow(dead_code)]
pub fn fuzz_config(cases: u32, seed: u64) -> proptest::test_runner::Config {
    let env = |k: &str| std::env::var(k).ok();
    proptest::test_runner::Config {
        cases: env("PROPTEST_CASES")
            .and_then(|s| s.parse().ok())
            .unwrap_or(cases),
        rng_seed: proptest::test_runner::RngSeed::Fixed(
            env("PROPTEST_RNG_SEED")
                .and_then(|s| s.parse().ok())
                .unwrap_or(seed),
        ),
        failure_persistence: None,
        ..proptest::test_runner::Config::default()
    }
}

/// Heights (m, row-major n0 × n1, x along the rows) of a smooth periodic rectangular
/// cell: five plane waves of wave numbers (p/Lx, q/Ly) with amplitudes 1 µm/(p² + q²) —
/// a few summits per cell, for the rectangular-cell and periodic-image tests.
pub fn rectangular_cosines(n0: usize, n1: usize, dx: f64, dy: f64) -> Vec<f64> {
    let (lx, ly) = (n0 as f64 * dx, n1 as f64 * dy);
    let tau = std::f64::consts::TAU;
    let z: Vec<f64> = (0..n0 * n1)
        .map(|k| {
            let (x, y) = ((k / n1) as f64 * dx, (k % n1) as f64 * dy);
            let mut v = 0.0;
            for (p, q, ph) in [
                (3.0, 2.0, 0.3),
                (5.0, 1.0, 1.1),
                (2.0, 4.0, 2.0),
                (7.0, 3.0, 0.7),
                (1.0, 6.0, 2.9),
            ] {
                v += (tau * (p * x / lx + q * y / ly) + ph).cos() / (p * p + q * q);
            }
            1e-6 * v
        })
        .collect();
    z
}

/// Writes `text` as `DIR/NAME.toml` and runs `strata solve -q --no-plots --force` on it
/// into `DIR/NAME` (the table cache in DIR): the output and the output directory.
#[allow(dead_code)]
pub fn solve_text(dir: &Path, name: &str, text: &str) -> (std::process::Output, PathBuf) {
    let scene = dir.join(format!("{name}.toml"));
    std::fs::write(&scene, text).unwrap();
    let out = dir.join(name);
    let o = strata_in(dir)
        .args(["solve", "-q", "--no-plots", "--force"])
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    (o, out)
}

/// The numbers of a CSV text below its header line, row by row.
#[allow(dead_code)]
pub fn csv_rows(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

/// The paper-like generated surface of the tests: L = 1 mm, D_f = 2.4, k = 2…10 (units
/// of 2π/L), RMS 3.4 µm, on a `grid`² grid with `seed`.
#[allow(dead_code)]
pub fn paper_like_surface(grid: usize, seed: u64) -> strata_runtime::surface::Surface {
    strata_runtime::surface::Surface::generate(&strata_runtime::surface::GenerateParams {
        size: 1e-3,
        grid,
        fractal_dimension: 2.4,
        k_min: 2.0,
        k_max: 10.0,
        rms: 3.4e-6,
        seed,
    })
    .expect("paper-like surface")
}
