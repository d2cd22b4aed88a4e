//! `strata study [--quick] [--machine FILE] --out DIR [--report FILE]`: the accuracy–cost
//! study (the measurements are in `crate::study`; the machine's description is read from
//! FILE, written by `cargo run -p xtask -- machine FILE`).
//!
//! Writes one output set (replaced as a whole under a lock, [`crate::output_set`]):
//! - `DIR/report.md`: machine, tables per stage, the defaults and where they sit on
//!   the Pareto front, proposed changes;
//! - `DIR/*.svg`: log–log error-against-time plots with the front marked;
//! - `DIR/errors.csv`: every deterministic number (errors, file sizes), identical on a
//!   second run; `DIR/timings.csv`: every timing (median and run count).
//!
//! `--report FILE` writes the report there as well, with plot links relative to
//! FILE's directory (for `docs/accuracy-cost.md` beside `docs/accuracy-cost/`).
//! Modes: the full study (default, tens of minutes), `--quick` (< 3 min on 2 cores),
//! and a hidden `--tiny` for the end-to-end test (seconds).

use std::path::{Path, PathBuf};
use strata_runtime::resources::MemoryLimit;

use anyhow::{Context, Result, bail};

use crate::output_set::OutputSet;
use crate::study::{self, Inputs, Mode, report};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// The quick study (< 3 min on 2 cores): fewer points, BEM reference at n = 256.
    #[arg(long)]
    pub quick: bool,
    /// A few seconds' smoke run (tests only).
    #[arg(long, hide = true, conflicts_with = "quick")]
    pub tiny: bool,
    /// Also write the report to this file, with plot links relative to its directory.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Replace the outputs of a non-empty output directory (and an existing --report).
    #[arg(long)]
    pub force: bool,
    /// Image format of the plots.
    #[arg(long, value_parser = ["svg", "png"], default_value = "svg")]
    pub format: String,
    /// Scene of the rough-contact stage (surface, stack and table).
    #[arg(long, default_value = "scenes/paper-E2E1-1-interacting.toml")]
    pub scene: PathBuf,
    /// Family table of the paper's stacks (approximation stage).
    #[arg(long, default_value = "tables/paper-two-layer.strata")]
    pub table: PathBuf,
    /// The machine the study runs on, for the report (TOML, written by
    /// `cargo run -p xtask -- machine FILE`); without it the rows say "not recorded".
    #[arg(long)]
    pub machine: Option<PathBuf>,
}

/// Plot-link prefix from the directory of `report` to `out` ("sub/dir/"), or the
/// absolute path of `out` when it is not below that directory.
fn link_prefix(report: &Path, out: &Path) -> Result<String> {
    let dir = match report.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("--report {}", report.display()))?;
    let dir = dir
        .canonicalize()
        .with_context(|| format!("--report {}", report.display()))?;
    let out = out
        .canonicalize()
        .with_context(|| format!("--out {}", out.display()))?;
    let rel = match out.strip_prefix(&dir) {
        Ok(r) => r.to_path_buf(),
        Err(_) => out,
    };
    let s = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/");
    Ok(if s.is_empty() {
        String::new()
    } else if rel.is_absolute() {
        format!("/{}/", s.trim_start_matches('/'))
    } else {
        format!("{s}/")
    })
}

pub fn run(a: Args, memory: MemoryLimit) -> Result<()> {
    let mode = if a.tiny {
        Mode::Tiny
    } else if a.quick {
        Mode::Quick
    } else {
        Mode::Full
    };
    for (flag, p) in [("--scene", &a.scene), ("--table", &a.table)] {
        if !p.is_file() {
            bail!(
                "{flag} {}: no such file (run from the repository root or pass {flag})",
                p.display()
            );
        }
    }
    let machine = match &a.machine {
        Some(p) => study::machine::Machine::from_file(p)?,
        None => study::machine::Machine::not_recorded(),
    };
    let set = OutputSet::dir("--out", &a.out, a.force)?;
    let report_set = a
        .report
        .as_ref()
        .map(|r| OutputSet::file("--report", r, a.force))
        .transpose()?;
    let inputs = Inputs {
        scene: a.scene.clone(),
        table: a.table.clone(),
        memory,
    };
    let result = study::run(mode, &inputs, machine)?;
    report::plots(&result, set.root(), &a.format)?;
    let mut command = format!("strata study{}", mode.flag());
    if let Some(m) = &a.machine {
        command.push_str(&format!(" --machine {}", m.display()));
    }
    command.push_str(&format!(" --out {}", a.out.display()));
    if let Some(r) = &a.report {
        command.push_str(&format!(" --report {}", r.display()));
    }
    let md = report::markdown(&result, "", &a.format, &command);
    set.write("report.md", md.as_bytes())?;
    let (errors, timings) = report::csvs(&result)?;
    set.write("errors.csv", errors.as_bytes())?;
    set.write("timings.csv", timings.as_bytes())?;
    set.commit()?;
    if let (Some(r), Some(rs)) = (&a.report, report_set) {
        let prefix = link_prefix(r, &a.out)?;
        let md = report::markdown(&result, &prefix, &a.format, &command);
        let name = r
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        rs.write(&name, md.as_bytes())?;
        rs.commit()?;
    }
    let path = a.out.join("report.md");
    crate::stdio::print(|o| {
        writeln!(o, "report: {}", path.display())?;
        for line in report::summary(&result) {
            writeln!(o, "  {line}")?;
        }
        Ok(())
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prefix_is_relative_below_the_report_directory() {
        let base = std::env::temp_dir().join(format!("strata-study-prefix-{}", std::process::id()));
        let out = base.join("docs/accuracy-cost");
        std::fs::create_dir_all(&out).unwrap();
        let p = link_prefix(&base.join("docs/accuracy-cost.md"), &out).unwrap();
        assert_eq!(p, "accuracy-cost/");
        let p = link_prefix(&out.join("report.md"), &out).unwrap();
        assert_eq!(p, "");
        let other = base.join("elsewhere");
        std::fs::create_dir_all(&other).unwrap();
        let p = link_prefix(&other.join("r.md"), &out).unwrap();
        assert!(
            p.starts_with('/') && p.ends_with("docs/accuracy-cost/"),
            "{p}"
        );
        std::fs::remove_dir_all(&base).unwrap();
    }
}
