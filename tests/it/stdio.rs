//! Standard output and standard error that cannot be written: a
//! reader that goes away (`strata table info T | head -5`) is quiet success (exit 0),
//! a full disk (`> /dev/full`) is one error line (exit 1), and log lines or errors that
//! stderr cannot take are dropped; never a panic (exit 101).

use std::io::Read;
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

use crate::support::{fresh_dir, repo, stderr_of, strata_in};

fn dir(name: &str) -> PathBuf {
    fresh_dir("stdio", name)
}

fn table() -> String {
    repo()
        .join("tables/paper-two-layer.strata")
        .display()
        .to_string()
}

fn stack() -> String {
    repo()
        .join("tables/stacks/paper-two-layer.toml")
        .display()
        .to_string()
}

/// Runs `c` with its stdout a pipe whose reader takes `take` bytes and then closes it.
fn with_closed_pipe(mut c: Command, take: usize) -> Output {
    let mut child = c
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn strata");
    let mut out = child.stdout.take().expect("stdout");
    let mut buf = vec![0u8; take];
    out.read_exact(&mut buf).expect("the first bytes");
    drop(out);
    child.wait_with_output().expect("wait")
}

fn quiet_success(o: &Output, what: &str) {
    let e = stderr_of(o);
    assert!(!e.contains("panicked"), "{what}: {e}");
    assert_eq!(o.status.code(), Some(0), "{what}: {e}");
}

/// `table info`, `compliance` (a long CSV) and `sweep --list` into a pipe closed early
/// end with exit 0 and nothing on stderr about it. The reader of `table info` closes
/// before the command writes (its output fits a pipe's buffer): it panicked there.
#[test]
fn a_closed_pipe_is_quiet_success() {
    let d = dir("pipe");
    let mut c = strata_in(&d);
    c.args(["table", "info", &table()]);
    quiet_success(&with_closed_pipe(c, 0), "table info");
    let mut c = strata_in(&d);
    c.args(["compliance", &stack(), "--rho-h", "0.01:100:50000:log"]);
    quiet_success(&with_closed_pipe(c, 16), "compliance");
    let mut c = strata_in(&d);
    c.args(["asperity", &stack(), "--radius", "1e-4", "--delta", "1e-7"]);
    quiet_success(&with_closed_pipe(c, 0), "asperity");
}

/// stdout on a full device: one line `error: cannot write to standard output: No space
/// left on device`, exit 1.
#[test]
fn a_full_disk_is_one_error_line() {
    let d = dir("full");
    for args in [
        vec!["table", "info", &table()],
        vec!["compliance", &stack(), "--rho-h", "0.01:100:50:log"],
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full");
        let o = strata_in(&d)
            .args(&args)
            .stdout(full)
            .output()
            .expect("run strata");
        let e = stderr_of(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {e}");
        assert_eq!(
            e, "error: cannot write to standard output: No space left on device\n",
            "{args:?}"
        );
    }
}

/// stderr on a full device: log lines are dropped (the command succeeds, its output is
/// written) and so is the error line of a failing command (exit 1, not 101).
#[test]
fn a_full_stderr_never_panics() {
    let d = dir("stderr");
    let scene = d.join("s.toml");
    std::fs::write(
        &scene,
        "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
         [surface]\nperiodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 32\n\
         fractal_dimension = 2.4\nk_min = 2\nk_max = 8\nrms = 3.4e-6\nseed = 3\n\
         [model]\nkind = \"independent\"\n[load]\nseparations = [3e-6]\n",
    )
    .unwrap();
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full")
    };
    let npy = d.join("surf.npy");
    let o = strata_in(&d)
        .args(["surface", "export", scene.to_str().unwrap(), "--out"])
        .arg(&npy)
        .env("STRATA_PROGRESS", "log")
        .stderr(full())
        .output()
        .expect("run strata");
    assert_eq!(o.status.code(), Some(0));
    assert!(npy.is_file());
    let o = strata_in(&d)
        .args(["compliance", "missing.toml", "--rho-h", "1"])
        .stderr(full())
        .output()
        .expect("run strata");
    assert_eq!(o.status.code(), Some(1));
}
