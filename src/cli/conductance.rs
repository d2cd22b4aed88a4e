//! `strata conductance STACK.toml --a LIST [--kind thermal|electrical]`: the
//! constriction conductance of one isothermal spot of radius a on the stack, the other
//! side a perfect conductor (physics.md §6.2): G(a) = 4 k₁ a ψ(a).
//!
//! Prints CSV on stdout with the header `a,conductance,psi` (m, W/K or S, –), one row
//! per radius, every value in shortest round-trip form. ψ = 1 on a homogeneous
//! half-space (G = 4ka); otherwise ψ comes from the Fredholm equation of
//! [`strata_tablegen::spot`]. The stack needs the kind's conductivity
//! (`thermal_conductivity` or `electrical_conductivity`) on every layer and on a
//! half-space base (`[base] conduction = "isothermal"` needs none): a missing one is
//! named with the file.

use std::path::PathBuf;

use anyhow::{Result, anyhow, bail};
use strata_runtime::conduction::ConductionKind;
use strata_runtime::{Bodies, Solid};
use strata_tablegen::spot::{Spot, SpotError};

use crate::csv_out::{self, num};

/// Which conduction problem.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Kind {
    /// Heat: `thermal_conductivity` (W/(m·K)); conductance in W/K.
    Thermal,
    /// Current: `electrical_conductivity` (S/m); conductance in S.
    Electrical,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Stack file (TOML) with conductivities.
    pub stack: PathBuf,
    /// Spot radii a (m, > 0): a list `1e-6,1e-5`, or `LO:HI:N` (N linearly spaced
    /// values) or `LO:HI:N:log` (N log-spaced values).
    #[arg(long, allow_hyphen_values = true)]
    pub a: String,
    /// Thermal (W/K) or electrical (S) conductance.
    #[arg(long, value_enum, default_value_t = Kind::Thermal)]
    pub kind: Kind,
}

pub fn run(a: Args) -> Result<()> {
    // the first body's spots; the counterface its file may name sets h₁ for the notes
    let bodies = Bodies::from_toml_file(&a.stack)?;
    let stack = &bodies.first;
    let radii = super::args::parse_list("--a", &a.a)?;
    if let Some(bad) = radii.iter().find(|r| **r <= 0.0) {
        bail!("--a: spot radii must be > 0 (m), got {bad}");
    }
    if super::args::wide_linear_range(&a.a) {
        crate::progress::log(format!(
            "note: --a {} is linearly spaced; write {}:log for log spacing",
            a.a, a.a
        ));
    }
    let kind = match a.kind {
        Kind::Thermal => ConductionKind::Thermal,
        Kind::Electrical => ConductionKind::Electrical,
    };
    let in_file = |e: SpotError| anyhow!("stack file {}: {e}", a.stack.display());
    let spot = Spot::new(stack, kind).map_err(in_file)?;
    let mut rows = Vec::with_capacity(radii.len());
    // Progress per spot (a log line every few seconds in batch jobs), and a note where
    // spots are large against the top layer: each is then a product-integration solve
    // whose cost grows as (a/h1)^1.5 (minutes above a/h1 ≈ 1000).
    let h1 = Solid::top_thickness(&bodies);
    if let Some(note) = h1.and_then(|h| large_spot_note(&radii, h)) {
        crate::progress::log(note);
    }
    let bar = crate::progress::bar(radii.len() as u64, "conductance: spots");
    for r in radii {
        if let Some(h) = h1 {
            bar.set_message(format!(
                "conductance: spot a = {r:e} m (a/h1 = {:.3e})",
                r / h
            ));
        }
        let g = spot
            .conductance(r)
            .map_err(|e| anyhow!("stack file {}: a = {r:e} m: {e}", a.stack.display()))?;
        rows.push([num(g.a), num(g.conductance), num(g.psi)]);
        bar.inc();
    }
    drop(bar);
    crate::stdio::print(|o| {
        csv_out::write(o, ["a", "conductance", "psi"], rows).map_err(Into::into)
    })?;
    Ok(())
}

/// Spots at which a/h₁ ≥ [`LARGE_SPOT`]: a note saying how many and that each costs a
/// product-integration solve growing as (a/h₁)^1.5; `None` when there is none.
pub fn large_spot_note(radii: &[f64], h1: f64) -> Option<String> {
    let large: Vec<f64> = radii
        .iter()
        .map(|r| r / h1)
        .filter(|x| *x >= LARGE_SPOT)
        .collect();
    let worst = large.iter().copied().fold(0.0_f64, f64::max);
    (!large.is_empty()).then(|| {
        format!(
            "note: {} of the {} spots have a/h1 ≥ {LARGE_SPOT} (largest {worst:.3e}): each is a \
             product-integration solve whose cost grows as (a/h1)^1.5 — minutes above a/h1 ≈ 1000",
            large.len(),
            radii.len()
        )
    })
}

/// a/h₁ from which `strata conductance` notes the cost of a spot.
pub const LARGE_SPOT: f64 = 100.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_spots_are_noted_with_their_count_and_largest_ratio() {
        assert!(large_spot_note(&[1e-6, 1e-5], 1e-6).is_none());
        let n = large_spot_note(&[1e-6, 2e-4, 2e-3], 1e-6).unwrap();
        assert!(
            n.contains("2 of the 3 spots") && n.contains("2.000e3"),
            "{n}"
        );
    }
}
