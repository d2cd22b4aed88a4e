//! Criterion benchmarks of strata; see `benches/` and docs/performance.md ("Benchmarks").

use strata_bem::Array2;
use strata_runtime::surface::{GenerateParams, Surface};

/// The parameters of the BEM benches' paper-like surface at n² (L = 1 mm, D_f = 2.4,
/// k = 2…10, RMS 3.4 µm, seed 20240611).
pub fn paper_surface_params(n: usize) -> GenerateParams {
    GenerateParams::paper(n, 10.0)
}

/// The BEM benches' paper-like surface at n² ([`paper_surface_params`]), heights in m.
pub fn paper_surface(n: usize) -> Array2<f64> {
    let s = Surface::generate(&paper_surface_params(n)).expect("surface");
    Array2::from_shape_vec((n, n), s.heights().to_vec()).expect("heights")
}

/// The 20 approaches (m) of the BEM benches' 512² load curve: 1.3…9.8 µm.
pub fn curve_approaches() -> Vec<f64> {
    (0..20)
        .map(|i| 1.3e-6 + (9.8e-6 - 1.3e-6) * i as f64 / 19.0)
        .collect()
}

/// Whether the bench named `name` runs under the command line's filter (no filter: all;
/// else a filter contained in the name, or the name in a filter).
pub fn filter_matches(name: &str) -> bool {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    args.is_empty()
        || args
            .iter()
            .any(|a| name.contains(a.as_str()) || a.contains(name))
}

/// CPU time of this process so far (user + system of all its threads, s), from
/// /proc/self/stat (clock ticks of 10 ms: time many repetitions for short work); 0 where
/// /proc is missing.
pub fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = after.split_whitespace().collect();
    let tick = 100.0;
    let v = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    // fields 14 and 15 (utime, stime) are at 11 and 12 after the command name
    (v(11) + v(12)) / tick
}

/// Peak RSS (bytes) and exit status of `cmd` run as a child of this process.
// The child is reaped by `wait4` (for its rusage), not by `Child::wait`.
#[allow(clippy::zombie_processes)]
pub fn peak_of(cmd: &mut std::process::Command) -> (u64, bool) {
    let child = cmd.spawn().unwrap_or_else(|e| {
        eprintln!("cannot start {cmd:?}: {e}");
        std::process::exit(2)
    });
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: a zeroed rusage is a valid value; wait4 fills it for our own child.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `pid` is a child of this process not yet waited for (`child` is never
    // waited on by std); the pointers are valid for the call.
    let rc = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    if rc != pid {
        eprintln!("wait4 failed for {cmd:?}");
        std::process::exit(2)
    }
    // Linux: ru_maxrss in KiB.
    let ok = libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0;
    (usage.ru_maxrss as u64 * 1024, ok)
}
