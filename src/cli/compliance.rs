//! `strata compliance STACK.toml --rho-h LIST`: k_z(ρ) of a stack as CSV on stdout.
//!
//! Output header `rho_h,k_z`, with ρ·h₁ dimensionless (h₁ the top layer's thickness)
//! and every value printed with full f64 precision (shortest round-trip form). This
//! interface is relied on by other tools: keep it. The stack is validated as in every
//! other command (`Stack`'s rules, moduli in [`strata_runtime::stack::YOUNG_RANGE`]);
//! a value that is not finite is an error, never printed.

use std::path::PathBuf;

use anyhow::{Result, bail};
use strata_runtime::{Compliance, Stack};

use crate::csv_out;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Stack file (TOML).
    pub stack: PathBuf,
    /// Values of ρ·h₁: a list `0.01,0.1,1`, or `LO:HI:N` (N linearly spaced values) or
    /// `LO:HI:N:log` (N log-spaced values).
    #[arg(long = "rho-h", allow_hyphen_values = true)]
    pub rho_h: String,
}

pub fn run(a: Args) -> Result<()> {
    let stack = Stack::from_toml_file(&a.stack)?;
    let rho_h = super::args::parse_list("--rho-h", &a.rho_h)?;
    if let Some(bad) = rho_h.iter().find(|x| **x < 0.0) {
        bail!("--rho-h: values must be >= 0, got {bad}");
    }
    if super::args::wide_linear_range(&a.rho_h) {
        crate::progress::log(format!(
            "note: --rho-h {} is linearly spaced; write {}:log for log spacing",
            a.rho_h, a.rho_h
        ));
    }
    let comp = Compliance::new(&stack);
    // A half-space has no h₁; k_z ≡ 0 there whatever ρ is.
    let h1 = stack.top_thickness().unwrap_or(1.0);
    let mut rows = Vec::with_capacity(rho_h.len());
    for x in rho_h {
        let kz = comp.kz(x / h1);
        if !kz.is_finite() {
            bail!(
                "stack file {}: k_z at rho_h = {x:e} is {kz} (not representable in f64 for this stack)",
                a.stack.display()
            );
        }
        rows.push([format!("{x:e}"), format!("{kz:e}")]);
    }
    crate::stdio::print(|o| csv_out::write(o, ["rho_h", "k_z"], rows).map_err(Into::into))?;
    Ok(())
}
