//! The BEM's stiffness dP/dδ of the sample (N/m), probed after each step: one extra
//! solve at δ + dδ, dδ = 10⁻⁴·max(|δ|, 10⁻³ R_q) (R_q the RMS height), from the state
//! the step started from (a capped solve's plastic depth before the step) and
//! warm-started from the step's pressure; dP/dδ = (P(δ + dδ) − P(δ))/dδ. Its error is
//! about the solver's tolerance / 10⁻⁴ ≈ 10⁻⁶ (relative). The asperity models' stiffness
//! is the runtime's own (dP/dδ of the summits' laws), not probed.

use crate::error::{Context, Result};
use strata_bem::BemSolution;

use super::plasticity::BemResponse;

/// The probe of one scene's BEM steps.
#[derive(Debug, Clone, Copy)]
pub struct StiffnessProbe {
    /// 10⁻³ R_q (m): the smallest approach the increment scales with.
    floor: f64,
}

impl StiffnessProbe {
    /// For a surface of RMS height `rms_height` (m).
    pub fn new(rms_height: f64) -> Self {
        StiffnessProbe {
            floor: 1e-3 * rms_height,
        }
    }

    /// The increment dδ (m) at approach `delta` (m).
    pub fn increment(&self, delta: f64) -> f64 {
        1e-4 * delta.abs().max(self.floor)
    }

    /// After step `name` solved to `solution` (whose pressure map the probe borrows as
    /// its start and gives back as it was): the stiffness dP/dδ (N/m) and the probe's
    /// solution at δ + dδ.
    pub fn after_step(
        &self,
        response: &mut dyn BemResponse,
        solution: &mut BemSolution,
        name: &str,
    ) -> Result<(f64, BemSolution)> {
        let dd = self.increment(solution.approach);
        let next = response
            .probe(solution.approach + dd, solution)
            .with_context(|| format!("{name}: stiffness"))?;
        Ok(((next.total_load - solution.total_load) / dd, next))
    }
}
