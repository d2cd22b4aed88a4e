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
use strata_runtime::Stack;
use strata_runtime::conduction::ConductionKind;
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
    let stack = Stack::from_toml_file(&a.stack)?;
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
    let spot = Spot::new(&stack, kind).map_err(in_file)?;
    let mut rows = Vec::with_capacity(radii.len());
    for r in radii {
        let g = spot
            .conductance(r)
            .map_err(|e| anyhow!("stack file {}: a = {r:e} m: {e}", a.stack.display()))?;
        rows.push([num(g.a), num(g.conductance), num(g.psi)]);
    }
    crate::stdio::print(|o| {
        csv_out::write(o, ["a", "conductance", "psi"], rows).map_err(Into::into)
    })?;
    Ok(())
}
