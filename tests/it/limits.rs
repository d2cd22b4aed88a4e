//! Inputs that never abort: sizes checked before allocation against
//! a settable limit (`--memory-limit`, STRATA_MEMORY_LIMIT), lying file headers, the
//! worker-thread cap, the table cache and `stack.table` rules, and BEM maps written as
//! they come. Every case exits 1 with a message, never 134.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::support::{fresh_dir, stderr_of, strata_in};

fn dir(name: &str) -> PathBuf {
    fresh_dir("limits", name)
}

/// Exit status 1 (not a crash) and a message containing every needle.
fn refused(o: &Output, needles: &[&str]) -> String {
    let e = stderr_of(o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        !e.contains("panicked") && !e.contains("memory allocation"),
        "{e}"
    );
    for n in needles {
        assert!(e.contains(n), "`{n}` missing in: {e}");
    }
    e
}

fn write_scene(d: &Path, name: &str, stack: &str, surface: &str, rest: &str) -> PathBuf {
    let p = d.join(name);
    std::fs::write(
        &p,
        format!("[stack]\n{stack}\n[surface]\n{surface}\n{rest}"),
    )
    .unwrap();
    p
}

const HALF_SPACE: &str = "[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15";
const LAYERED: &str = "[[stack.layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 0.15\n\
                       [stack.base]\nkind = \"rigid\"";
const MODEL_LOAD: &str = "[model]\nkind = \"independent\"\n[load]\nseparations = [3e-6]\n";

/// A 928-byte .npy whose header claims 100000×100000 float64 (80 GB): refused from the
/// header, naming the file, before anything is allocated.
#[test]
fn lying_npy_header_is_refused() {
    let d = dir("npy");
    let npy = d.join("liar.npy");
    let mut header =
        b"{'descr': '<f8', 'fortran_order': False, 'shape': (100000, 100000), }".to_vec();
    while !(10 + header.len() + 1).is_multiple_of(64) {
        header.push(b' ');
    }
    header.push(b'\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(&header);
    bytes.resize(928, 0);
    std::fs::write(&npy, &bytes).unwrap();
    let sc = write_scene(
        &d,
        "s.toml",
        HALF_SPACE,
        "file = \"liar.npy\"\nsize = 1e-3",
        MODEL_LOAD,
    );
    let o = strata_in(&d)
        .args(["solve", sc.to_str().unwrap(), "--out"])
        .arg(d.join("out"))
        .output()
        .unwrap();
    refused(&o, &["liar.npy", "100000×100000", "holds only"]);
    assert!(!d.join("out").exists());
}

/// A 16384² BEM scene under a 1 GiB limit (flag or environment) exits 1 naming the
/// estimate and the limit, before generating the surface (this branch's check; the
/// BEM solver's own grid check goes through the same limit). A bad limit is refused.
#[test]
fn huge_bem_grid_under_a_small_limit_is_refused() {
    let d = dir("bem");
    let sc = write_scene(
        &d,
        "big.toml",
        HALF_SPACE,
        "[surface.generate]\nsize = 1e-3\ngrid = 16384\nfractal_dimension = 2.4\n\
         k_min = 2\nk_max = 10\nrms = 3.4e-6\nseed = 1",
        "[model]\nkind = \"bem\"\n[load]\nseparations = [3e-6]\n",
    );
    let t0 = std::time::Instant::now();
    let o = strata_in(&d)
        .args([
            "solve",
            sc.to_str().unwrap(),
            "--memory-limit",
            "1G",
            "--out",
        ])
        .arg(d.join("out"))
        .output()
        .unwrap();
    refused(
        &o,
        &["16384×16384", "memory limit is 1.00 GiB", "--memory-limit"],
    );
    assert!(t0.elapsed().as_secs_f64() < 30.0, "checked before the work");
    let o = strata_in(&d)
        .env("STRATA_MEMORY_LIMIT", "1G")
        .args(["solve", sc.to_str().unwrap(), "--out"])
        .arg(d.join("out"))
        .output()
        .unwrap();
    refused(&o, &["16384×16384", "STRATA_MEMORY_LIMIT"]);
    let o = strata_in(&d)
        .args([
            "solve",
            sc.to_str().unwrap(),
            "--memory-limit",
            "lots",
            "--out",
        ])
        .arg(d.join("out"))
        .output()
        .unwrap();
    refused(&o, &["--memory-limit", "`lots`"]);
}

/// The I model past its memory limit (a 1024² surface with k_max = 400 under 64 MiB)
/// exits 1 with a message: the I model estimates its pair storage and checks it against
/// its `rough::Params::memory`, which the engine sets from `--memory-limit`.
#[test]
fn i_model_past_its_limit_is_refused() {
    let d = dir("imodel");
    let sc = write_scene(
        &d,
        "many.toml",
        HALF_SPACE,
        "[surface.generate]\nsize = 1e-3\ngrid = 1024\nfractal_dimension = 2.4\n\
         k_min = 2\nk_max = 400\nrms = 3.4e-6\nseed = 1",
        "[model]\nkind = \"interacting\"\n[load]\nseparations = [1e-6]\n",
    );
    let o = strata_in(&d)
        .args([
            "solve",
            sc.to_str().unwrap(),
            "--memory-limit",
            "64M",
            "--out",
        ])
        .arg(d.join("out"))
        .output()
        .unwrap();
    refused(&o, &["memory limit"]);
}

/// `sweep --threads 100000` (and RAYON_NUM_THREADS = 100000) is refused with the cap.
#[test]
fn thread_count_is_capped() {
    let d = dir("threads");
    let sw = d.join("sweep.toml");
    std::fs::write(
        &sw,
        "[scene]\n[scene.stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
         [scene.surface.generate]\nsize = 1e-3\ngrid = 64\nfractal_dimension = 2.4\n\
         k_min = 2\nk_max = 8\nrms = 3.4e-6\nseed = 1\n[scene.model]\nkind = \"independent\"\n\
         [scene.load]\nseparations = [3e-6]\n[sweep]\nsurface.seed = [1, 2]\n",
    )
    .unwrap();
    let o = strata_in(&d)
        .args([
            "sweep",
            sw.to_str().unwrap(),
            "--threads",
            "100000",
            "--out",
        ])
        .arg(d.join("out"))
        .output()
        .unwrap();
    refused(&o, &["--threads 100000", "at most", "per core"]);
    let o = strata_in(&d)
        .env("RAYON_NUM_THREADS", "100000")
        .args(["sweep", sw.to_str().unwrap(), "--out"])
        .arg(d.join("out"))
        .output()
        .unwrap();
    refused(&o, &["RAYON_NUM_THREADS 100000", "at most"]);
    assert!(!d.join("out").exists());
    let o = strata_in(&d)
        .args(["sweep", sw.to_str().unwrap(), "--threads", "2", "--out"])
        .arg(d.join("out"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
}

/// RAYON_NUM_THREADS above 4 per core is refused by every command, not only `sweep`
/// (`RAYON_NUM_THREADS=100000 strata asperity …` spawned threads without
/// end), at once and with the cap; so is a value that is not a number; the cap itself
/// is accepted.
#[test]
fn rayon_num_threads_is_capped_for_every_command() {
    let d = dir("rayon-threads");
    let cap = 4 * std::thread::available_parallelism().map_or(1, |n| n.get());
    let stack = crate::support::repo().join("tables/stacks/paper-two-layer.toml");
    let asperity = |threads: &str| {
        strata_in(&d)
            .env("RAYON_NUM_THREADS", threads)
            .arg("asperity")
            .arg(&stack)
            .args(["--radius", "1e-4", "--delta", "1e-7"])
            .output()
            .unwrap()
    };
    for n in [cap + 1, 100000] {
        let e = refused(
            &asperity(&n.to_string()),
            &[&format!(
                "RAYON_NUM_THREADS {n}: at most {cap} worker threads"
            )],
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    refused(
        &asperity("many"),
        &["RAYON_NUM_THREADS = `many`: not a number"],
    );
    let o = asperity(&cap.to_string());
    assert!(o.status.success(), "{}", stderr_of(&o));
    let o = strata_in(&d)
        .env("RAYON_NUM_THREADS", "100000")
        .arg("compliance")
        .arg(&stack)
        .args(["--rho-h", "1"])
        .output()
        .unwrap();
    refused(&o, &["RAYON_NUM_THREADS 100000", "at most"]);
}

/// A scene naming a table that does not exist is refused, naming the field, the path
/// and what it is relative to; nothing is built or written at that input path.
#[test]
fn missing_stack_table_is_never_built_in_place() {
    let d = dir("table");
    let sc = write_scene(
        &d,
        "s.toml",
        &format!("table = \"tables/nope.strata\"\n{LAYERED}"),
        "[surface.generate]\nsize = 1e-3\ngrid = 64\nfractal_dimension = 2.4\n\
         k_min = 2\nk_max = 8\nrms = 3.4e-6\nseed = 1",
        MODEL_LOAD,
    );
    let o = strata_in(&d.join("cache"))
        .args(["solve", sc.to_str().unwrap(), "--out"])
        .arg(d.join("out"))
        .output()
        .unwrap();
    refused(
        &o,
        &[
            "stack.table = \"tables/nope.strata\"",
            "no such file",
            "relative to the scene's directory",
            "strata table build",
        ],
    );
    assert!(!d.join("tables").exists() && !d.join("cache").exists());
}

/// A cache that cannot be written fails at once, before a table build (which takes
/// minutes), naming the directory and where its location came from.
#[test]
fn unwritable_cache_fails_before_building() {
    let d = dir("cache");
    let sc = write_scene(
        &d,
        "s.toml",
        LAYERED,
        "[surface.generate]\nsize = 1e-3\ngrid = 64\nfractal_dimension = 2.4\n\
         k_min = 2\nk_max = 8\nrms = 3.4e-6\nseed = 1",
        MODEL_LOAD,
    );
    std::fs::write(d.join("plain-file"), "not a directory").unwrap();
    let cache = d.join("plain-file/cache");
    for (how, env) in [("--cache-dir", false), ("STRATA_CACHE_DIR", true)] {
        let t0 = std::time::Instant::now();
        let mut c = strata_in(&cache);
        c.env("STRATA_PROGRESS", "log")
            .env("STRATA_LOG_INTERVAL", "0.05");
        c.args(["solve", sc.to_str().unwrap(), "--out"])
            .arg(d.join("out"));
        if !env {
            c.arg("--cache-dir").arg(&cache);
        }
        let o = c.output().unwrap();
        let e = refused(
            &o,
            &["table cache", "plain-file/cache", how, "not writable"],
        );
        assert!(!e.contains("building table"), "{e}");
        assert!(t0.elapsed().as_secs_f64() < 20.0);
    }
}

/// BEM maps with `maps = "all"` are written as each step is solved, not held until the
/// end: killed at the first file of step 1's maps, the run had finished one load step
/// only (its progress log never reached 2/3), and step 0's maps were already on disk.
#[test]
fn bem_maps_are_written_as_they_come() {
    let d = dir("maps");
    let surface = crate::support::repo().join("tests/reference/surface_km10.npy");
    let sc = write_scene(
        &d,
        "s.toml",
        HALF_SPACE,
        &format!(
            "file = \"{}\"\nsize = 1e-3\nperiodic = true",
            surface.display()
        ),
        "[model]\nkind = \"bem\"\n[load]\nseparations = [7e-6, 5e-6, 3e-6]\n\
         [output]\nmaps = \"all\"\n",
    );
    let o = strata_in(&d)
        .env("STRATA_TEST_KILL_AT", "write:5")
        .env("STRATA_PROGRESS", "log")
        .env("STRATA_LOG_INTERVAL", "0.05")
        .args(["solve", sc.to_str().unwrap(), "--out"])
        .arg(d.join("out"))
        .output()
        .unwrap();
    let e = stderr_of(&o);
    use std::os::unix::process::ExitStatusExt;
    assert_eq!(o.status.signal(), Some(9), "{e}");
    assert!(e.contains("load steps: 1/3"), "{e}");
    assert!(!e.contains("load steps: 2/3") && !e.contains("3/3"), "{e}");
    let staged = d.join(".out.strata-new/maps");
    for f in [
        "pressure_step_00.npy",
        "gap_step_00.npy",
        "pressure_step_00.png",
    ] {
        assert!(staged.join(f).is_file(), "{f} not written yet");
    }
    assert!(!d.join("out").exists());
    // The next run clears the debris and completes.
    let o = strata_in(&d)
        .args(["solve", sc.to_str().unwrap(), "--out"])
        .arg(d.join("out"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    assert!(!d.join(".out.strata-new").exists());
    assert!(d.join("out/maps/gap_step_02.png").is_file());
}

/// A stack, counterface or scene "file" that is an endless stream (`/dev/zero`) is
/// refused after the 16 MiB text-file cap, naming the file and the cap, under the
/// default memory limit (it was read without bound: 7.5 GB).
#[test]
fn endless_stack_and_scene_files_are_refused_at_the_text_cap() {
    if !Path::new("/dev/zero").exists() {
        return;
    }
    let d = dir("dev-zero");
    let stack = crate::support::repo().join("tables/stacks/half-space-steel.toml");
    let stack = stack.to_str().unwrap();
    let out = d.join("t.strata");
    for args in [
        vec!["compliance", "/dev/zero", "--rho-h", "1"],
        vec![
            "asperity",
            stack,
            "--radius",
            "1e-4",
            "--delta",
            "1e-7",
            "--counterface",
            "/dev/zero",
        ],
        vec![
            "table",
            "build",
            stack,
            "--out",
            out.to_str().unwrap(),
            "--counterface",
            "/dev/zero",
        ],
        vec!["solve", "/dev/zero", "--out", d.join("o").to_str().unwrap()],
    ] {
        let o = strata_in(&d).args(&args).output().unwrap();
        refused(&o, &["/dev/zero", "16.00 MiB cap"]);
    }
    assert!(!out.exists() && !d.join("o").exists());
}
