//! `strata compliance STACK.toml --rho-h LIST`: k_z(ρ) of a stack as CSV on stdout.
//! With `--thermal` (or `--electrical`): the conduction compliance S_th(ρ) of
//! physics.md §6.2 instead, header `rho_h,S_th` (the stack's `thermal_conductivity`,
//! or `electrical_conductivity`, of every layer and of a half-space base).
//!
//! With `--tangential`: the full compliance of the tangential module
//! ([`strata_runtime::compliance::tangential`]), header `rho_h,S_zz,S_LL,S_TT,S_zL`.
//!
//! Output header `rho_h,k_z`, with ρ·h₁ dimensionless (h₁ the top layer's thickness)
//! and every value printed with full f64 precision (shortest round-trip form). This
//! interface is relied on by other tools: keep it. The stack is validated as in every
//! other command (`Stack`'s rules, moduli in [`strata_runtime::stack::YOUNG_RANGE`]);
//! a value that is not finite is an error, never printed.

use std::path::PathBuf;

use anyhow::{Result, bail};
use strata_runtime::compliance::tangential::TangentialCompliance;
use strata_runtime::conduction::{ConductionCompliance, ConductionKind};
use strata_runtime::{Bodies, Compliance, Solid, Stack};

use crate::csv_out;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Stack file (TOML).
    pub stack: PathBuf,
    /// Values of ρ·h₁: a list `0.01,0.1,1`, or `LO:HI:N` (N linearly spaced values) or
    /// `LO:HI:N:log` (N log-spaced values).
    #[arg(long = "rho-h", allow_hyphen_values = true)]
    pub rho_h: String,
    /// Print the thermal conduction compliance S_th(ρ) (`rho_h,S_th`) instead of k_z.
    #[arg(long, conflicts_with = "electrical")]
    pub thermal: bool,
    /// Print the electrical conduction compliance S_th(ρ) (`rho_h,S_th`) instead of k_z.
    #[arg(long, conflicts_with = "tangential")]
    pub electrical: bool,
    /// Print the normal, tangential and coupling compliances
    /// (`rho_h,S_zz,S_LL,S_TT,S_zL`) instead of k_z.
    #[arg(long, conflicts_with = "thermal")]
    pub tangential: bool,
}

pub fn run(a: Args) -> Result<()> {
    // the stack, with the elastic counterface its file may name (the pair's compliance)
    let stack = Bodies::from_toml_file(&a.stack)?;
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
    let kind = match (a.thermal, a.electrical) {
        (true, _) => Some(ConductionKind::Thermal),
        (_, true) => Some(ConductionKind::Electrical),
        _ => None,
    };
    if let Some(kind) = kind {
        // conduction: the first body's own (the counterface conducts in series, apart)
        return conduction(&a, &stack.first, kind, &rho_h);
    }
    if a.tangential {
        return tangential(&a, &stack, &rho_h);
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

/// `rho_h,S_th` for `--thermal` / `--electrical`.
fn conduction(a: &Args, stack: &Stack, kind: ConductionKind, rho_h: &[f64]) -> Result<()> {
    let comp = ConductionCompliance::new(stack, kind)
        .map_err(|e| anyhow::anyhow!("stack file {}: {e}", a.stack.display()))?;
    // A half-space has no h₁; S_th ≡ 1 there whatever ρ is.
    let h1 = stack.top_thickness().unwrap_or(1.0);
    let mut rows = Vec::with_capacity(rho_h.len());
    for &x in rho_h {
        let s = comp.s(x / h1);
        if !s.is_finite() {
            bail!(
                "stack file {}: S_th at rho_h = {x:e} is {s} (not representable in f64 for this stack)",
                a.stack.display()
            );
        }
        rows.push([format!("{x:e}"), format!("{s:e}")]);
    }
    crate::stdio::print(|o| csv_out::write(o, ["rho_h", "S_th"], rows).map_err(Into::into))?;
    Ok(())
}

/// `rho_h,S_zz,S_LL,S_TT,S_zL` for `--tangential`.
fn tangential(a: &Args, stack: &Bodies, rho_h: &[f64]) -> Result<()> {
    let comp = TangentialCompliance::new(stack);
    // A half-space has no h₁; the values do not depend on ρ there.
    let h1 = stack.top_thickness().unwrap_or(1.0);
    let mut rows = Vec::with_capacity(rho_h.len());
    for &x in rho_h {
        let c = comp.eval(x / h1);
        let v = [c.s_zz, c.s_ll, c.s_tt, c.s_zl];
        if let Some(bad) = v.iter().find(|v| !v.is_finite()) {
            bail!(
                "stack file {}: a compliance at rho_h = {x:e} is {bad} (not representable in f64 for this stack)",
                a.stack.display()
            );
        }
        rows.push([
            format!("{x:e}"),
            format!("{:e}", v[0]),
            format!("{:e}", v[1]),
            format!("{:e}", v[2]),
            format!("{:e}", v[3]),
        ]);
    }
    crate::stdio::print(|o| {
        csv_out::write(o, ["rho_h", "S_zz", "S_LL", "S_TT", "S_zL"], rows).map_err(Into::into)
    })?;
    Ok(())
}
