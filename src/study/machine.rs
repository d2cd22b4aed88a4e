//! The machine a study ran on: CPU, cores, memory, OS, compiler, build profile and
//! load, read from /proc and /etc where available ("unknown" otherwise).

use std::process::Command;

/// What the report's "Machine" section shows.
#[derive(Debug, Clone)]
pub struct Machine {
    pub cpu: String,
    pub logical_cpus: String,
    pub threads: usize,
    pub memory: String,
    pub os: String,
    pub kernel: String,
    pub rustc: String,
    pub profile: String,
    pub strata: String,
    pub commit: String,
    pub load: String,
}

fn read(path: &str) -> Option<String> {
    std::fs::read_to_string(path).ok()
}

fn run(cmd: &str, args: &[&str]) -> Option<String> {
    let out = Command::new(cmd).args(args).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let s = String::from_utf8_lossy(&out.stdout).trim().to_string();
    (!s.is_empty()).then_some(s)
}

/// /proc/loadavg's 1, 5 and 15 minute load averages.
pub fn load_average() -> String {
    read("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".into())
}

impl Machine {
    pub fn detect() -> Self {
        let cpuinfo = read("/proc/cpuinfo").unwrap_or_default();
        let cpu = cpuinfo
            .lines()
            .find(|l| l.starts_with("model name"))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.trim().to_string())
            .unwrap_or_else(|| "unknown".into());
        let logical = cpuinfo
            .lines()
            .filter(|l| l.starts_with("processor"))
            .count();
        let available = std::thread::available_parallelism().map_or(0, |n| n.get());
        let logical_cpus = if logical > 0 {
            format!("{logical} logical CPUs (/proc/cpuinfo), {available} available to the process")
        } else {
            format!("{available} available to the process")
        };
        let memory = read("/proc/meminfo")
            .and_then(|m| {
                m.lines()
                    .find(|l| l.starts_with("MemTotal"))
                    .and_then(|l| l.split_whitespace().nth(1))
                    .and_then(|kb| kb.parse::<f64>().ok())
            })
            .map_or_else(
                || "unknown".into(),
                |kb| format!("{:.1} GiB", kb / 1024.0 / 1024.0),
            );
        let os = read("/etc/os-release")
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("PRETTY_NAME="))
                    .map(|l| l["PRETTY_NAME=".len()..].trim_matches('"').to_string())
            })
            .unwrap_or_else(|| std::env::consts::OS.into());
        let kernel = read("/proc/sys/kernel/osrelease")
            .map(|s| format!("Linux {}", s.trim()))
            .unwrap_or_else(|| "unknown".into());
        let rustc = run("rustc", &["--version"])
            .map(|v| format!("{v} (the rustc on PATH at run time)"))
            .unwrap_or_else(|| "unknown".into());
        let profile = if cfg!(debug_assertions) {
            "dev/test (debug assertions on): times are not representative".into()
        } else {
            "release (optimised, no debug assertions)".into()
        };
        let commit = run("git", &["rev-parse", "--short", "HEAD"])
            .map(|c| {
                let dirty = run("git", &["status", "--porcelain", "--untracked-files=no"])
                    .is_some_and(|s| !s.is_empty());
                if dirty {
                    format!("{c} + uncommitted changes")
                } else {
                    c
                }
            })
            .unwrap_or_else(|| "unknown".into());
        Machine {
            cpu,
            logical_cpus,
            threads: rayon::current_num_threads(),
            memory,
            os,
            kernel,
            rustc,
            profile,
            strata: env!("CARGO_PKG_VERSION").into(),
            commit,
            load: load_average(),
        }
    }
}
