//! The N model: every asperity alone (physics.md §5), ζ(a_k)a_k²/R_k = δ_k, with the
//! sample stiffness from the chain rule, dP/dδ = Σ_k (dP_k/da)/(dδ_k/da),
//! dP_k/da = (4/3)E*₁(χ′a³ + 3χa²)/R_k and dδ_k/da = (ζ′a² + 2ζa)/R_k.

use super::local::Local;
use super::{Diagnostics, IndependentError, RoughContact, RoughError, Step};
use crate::law::contact_radius;

impl RoughContact<'_> {
    /// N model at approach δ (m): every asperity alone, ζ(a_k)a_k²/R_k = δ_k.
    pub fn solve_independent(&self, delta: f64) -> Result<Step, RoughError> {
        self.check_delta(delta)?;
        let e = self.law.e_star();
        let mut radii = vec![0.0; self.summits.len()];
        let mut stiffness = 0.0;
        for (k, s) in self.summits.iter().enumerate() {
            let dk = self.interference(k, delta);
            if dk <= 0.0 {
                continue;
            }
            let a = contact_radius(self.law, s.radius, dk).ok_or(IndependentError::NoRoot {
                index: k,
                delta: dk,
                radius: s.radius,
            })?;
            radii[k] = a;
            // dP/dδ_k = (4/3)E*₁ Q′/δ′
            let l = Local::at(self.law, a, s.radius);
            stiffness += 4.0 / 3.0 * e * l.dq / l.ddelta(a, s.radius);
        }
        self.finish(delta, radii, stiffness, None, Diagnostics::default())
    }
}
