//! `strata stiffness STACK.toml --a LIST [--counterface FILE]`: the normal and tangential
//! stiffness of one contact disc of radius a on the stack.
//!
//! Prints CSV on stdout with the header `a,normal_stiffness,tangential_stiffness` (m,
//! N/m, N/m), one row per radius, every value in shortest round-trip form:
//! the frictionless rigid flat punch, K_n = P/δ = 2E*₁aψ_zz(a), and the bonded disc in
//! full stick displaced tangentially without rotation, K_t = Q/δ, the normal–tangential
//! coupling ignored (as in Mindlin's solution). K_t is the harmonic mean of two punch
//! stiffnesses, 2K_LK_T/(K_L + K_T), with the in-plane (S_LL) and antiplane (S_TT)
//! compliances of the stack ([`strata_tablegen::stiffness`]). On a half-space:
//! K_n = 2E*a, K_t = 8μa/(2−ν); a layer of thickness h bonded to a rigid base with
//! a ≫ h: K_n → πa²/Σ(h/M), K_t → πa²/Σ(h/μ), M = E(1−ν)/((1+ν)(1−2ν)).

use std::path::PathBuf;

use anyhow::{Result, anyhow, bail};
use strata_runtime::Solid;
use strata_tablegen::stiffness::Stiffness;

use crate::csv_out::{self, num};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Stack file (TOML).
    pub stack: PathBuf,
    /// Disc radii a (m, > 0): a list `1e-6,1e-5`, or `LO:HI:N` (N linearly spaced
    /// values) or `LO:HI:N:log` (N log-spaced values).
    #[arg(long, allow_hyphen_values = true)]
    pub a: String,
    /// A second elastic body (stack file) in place of the rigid counterface: the two
    /// compliances add (physics.md §6.1).
    #[arg(long)]
    pub counterface: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<()> {
    let stack = super::args::bodies(&a.stack, a.counterface.as_deref())?;
    let radii = super::args::parse_list("--a", &a.a)?;
    if let Some(bad) = radii.iter().find(|r| r.is_nan() || **r <= 0.0) {
        bail!("--a: disc radii must be > 0 (m), got {bad}");
    }
    if super::args::wide_linear_range(&a.a) {
        crate::progress::log(format!(
            "note: --a {} is linearly spaced; write {}:log for log spacing",
            a.a, a.a
        ));
    }
    let solver = Stiffness::new(&stack);
    let h1 = stack.top_thickness();
    if let Some(note) = h1.and_then(|h| super::conductance::large_spot_note(&radii, h)) {
        crate::progress::log(note.replace("spots", "discs"));
    }
    let bar = crate::progress::bar(radii.len() as u64, "stiffness: discs");
    let mut rows = Vec::with_capacity(radii.len());
    for r in radii {
        if let Some(h) = h1 {
            bar.set_message(format!(
                "stiffness: disc a = {r:e} m (a/h1 = {:.3e})",
                r / h
            ));
        }
        let d = solver
            .at(r)
            .map_err(|e| anyhow!("stack file {}: a = {r:e} m: {e}", a.stack.display()))?;
        rows.push([num(d.a), num(d.normal), num(d.tangential)]);
        bar.inc();
    }
    drop(bar);
    crate::stdio::print(|o| {
        csv_out::write(o, ["a", "normal_stiffness", "tangential_stiffness"], rows)
            .map_err(Into::into)
    })?;
    Ok(())
}
