//! The BEM's stiffness dP/dδ of the sample (N/m) after each step: the exact tangent of
//! the load in the approach with the step's contact set A held fixed,
//!
//! ```text
//!   K_AA Δp = 1 on A,   dP/dδ = (Lx·Ly/(ny·nx)) Σ_A Δp
//! ```
//!
//! (Δp = dp/dδ in Pa/m, K the influence operator in m/Pa: the flat-punch stiffness of
//! the contact set, Barber's theorem), solved by a preconditioned linear CG to a
//! relative residual of 10⁻¹³ ([`strata_bem::tangent`]). A change of the set
//! contributes at second order only (the pressure vanishes at its edge). Capped at the
//! hardness H ([`crate::effects::plasticity`]) the points at H take no load on an increase
//! of δ: A is the elastic contact, 0 < p < H. The pressure rate Δp goes to the step's
//! observers (the BEM's conductance starts from it: by Barber's analogy it is the flux of
//! a unit temperature jump on a homogeneous body). The asperity models' stiffness is the
//! runtime's own (dP/dδ of the summits' laws).

use crate::error::{Context, Result};
use strata_bem::{BemSolution, Tangent};

use super::plasticity::BemResponse;

/// The tangent of step `name` solved to `solution` (whose pressure map the solve
/// borrows as a buffer and gives back as it was): dP/dδ (N/m) and Δp (Pa/m).
pub fn after_step(
    response: &mut dyn BemResponse,
    solution: &mut BemSolution,
    name: &str,
) -> Result<Tangent> {
    response
        .tangent(solution)
        .with_context(|| format!("{name}: stiffness"))
}
