//! `strata compliance STACK.toml --rho-h LIST`: k_z(ρ) of a stack as CSV on stdout.
//!
//! Output header `rho_h,k_z`, with ρ·h₁ dimensionless (h₁ the top layer's thickness)
//! and every value printed with full f64 precision (shortest round-trip form). This
//! interface is relied on by other tools: keep it.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use strata_runtime::{Compliance, Stack};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Stack file (TOML).
    pub stack: PathBuf,
    /// Values of ρ·h₁: a list `0.01,0.1,1` or `LO:HI:N` for N log-spaced values.
    #[arg(long = "rho-h", allow_hyphen_values = true)]
    pub rho_h: String,
}

pub fn run(a: Args) -> Result<()> {
    let stack = Stack::from_toml_file(&a.stack)?;
    let rho_h = super::args::parse_list("--rho-h", &a.rho_h, true)?;
    if let Some(bad) = rho_h.iter().find(|x| **x < 0.0) {
        anyhow::bail!("--rho-h: values must be >= 0, got {bad}");
    }
    let comp = Compliance::new(&stack);
    // A half-space has no h₁; k_z ≡ 0 there whatever ρ is.
    let h1 = stack.top_thickness().unwrap_or(1.0);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    writeln!(out, "rho_h,k_z").context("writing to stdout")?;
    for x in rho_h {
        let kz = comp.kz(x / h1);
        writeln!(out, "{x:e},{kz:e}").context("writing to stdout")?;
    }
    out.flush().context("writing to stdout")?;
    Ok(())
}
