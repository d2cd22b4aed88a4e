//! The machine a study runs on, read from /proc and /etc where available ("unknown"
//! otherwise), written as TOML for `strata study --machine FILE`: the study itself does
//! not probe the machine (no /proc, no subprocesses in the user's binary).

use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result};

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
fn load_average() -> String {
    read("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".into())
}

/// (key, value) pairs, in the order of the report's rows.
fn probe() -> Vec<(&'static str, String)> {
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
    let cores = if logical > 0 {
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
        .map(|v| format!("{v} (the rustc on PATH)"))
        .unwrap_or_else(|| "unknown".into());
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
    vec![
        ("cpu", cpu),
        ("cores", cores),
        ("memory", memory),
        ("os", os),
        ("kernel", kernel),
        ("rustc", rustc),
        ("commit", commit),
        ("load", load_average()),
    ]
}

/// A TOML basic string.
fn quoted(s: &str) -> String {
    let mut q = String::from('"');
    for c in s.chars() {
        match c {
            '"' => q.push_str("\\\""),
            '\\' => q.push_str("\\\\"),
            c if c.is_control() => q.push_str(&format!("\\u{:04X}", c as u32)),
            c => q.push(c),
        }
    }
    q.push('"');
    q
}

pub fn write(file: &Path) -> Result<()> {
    let mut text = String::from(
        "# The machine of a `strata study` run (cargo run -p xtask -- machine FILE).\n",
    );
    for (k, v) in probe() {
        text.push_str(&format!("{k} = {}\n", quoted(&v)));
    }
    if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| dir.display().to_string())?;
    }
    std::fs::write(file, &text).with_context(|| file.display().to_string())?;
    eprint!("{}: \n{text}", file.display());
    Ok(())
}
