//! Multi-asperity rough contact: the N model (independent asperities) and the I model
//! (interacting asperities, complementary-energy minimisation), physics.md §5, paper
//! §4.2 and eqs. (P19)–(P26).
//!
//! Notation (SI): asperity k has height z_k (m), radius R_k (m), contact radius a_k (m).
//! A rigid flat approaching by δ (m) from first contact with the highest summit z_M gives
//! the interference δ_k = ⟨δ − (z_M − z_k)⟩ (P20) and the separation
//! g_n = (z_M − z̄) − δ (P26). The total load is P = (4/3)E*₁ Σ χ(a_k)a_k³/R_k (N, P24),
//! the real contact area A = π Σ a_k² (m², P25), p_n = P/A₀ (Pa). The normal stiffness
//! is dP/dδ of the whole sample (N/m), computed analytically (N model: chain rule on
//! P(a) and δ(a); I model: implicit differentiation of the stationarity system).
//!
//! The solver is organised by stage (crate-private modules), each with its own error type:
//!
//! - `independent`: the N model, ζ(a_k)a_k²/R_k = δ_k per asperity;
//! - [`conductance`] (feature `spectral`): the I model's interface conductance, the
//!   spots' thermal interactions through both bodies' periodic point-source fields;
//! - `interacting`: the I model — the far-field model of the interaction kernel
//!   (`far_field`), the image geometry and pair lists (`images`), the energy, its
//!   gradient and Jacobian (`energy`), the active-set Newton method (`newton`) and the
//!   load-path driver (`path`).
//!
//! Every tolerance and iteration limit is a documented field of [`Params`] (defaults
//! from `Params::default()`); every I-model step reports what its solve did in a
//! [`Diagnostics`]. A solve depends only on its inputs (the approach, the warm start it
//! is given and the parameters): no state is kept between calls.

#[cfg(feature = "spectral")]
pub mod conductance;
mod contact;
mod error;
pub(crate) mod independent;
pub(crate) mod interacting;
mod local;
mod params;
pub mod plastic;
mod step;

pub use crate::law::contact_radius;
pub use contact::RoughContact;
pub use error::{FarFieldError, IndependentError, NewtonError, PressureError, RoughError};
pub use interacting::Interaction;
pub use params::{Diagnostics, FarFieldInfo, Params, ParamsError};
pub use step::{Images, Model, Step, Validity};

impl RoughContact<'_> {
    /// Solves one step of `model` at approach δ (m); `warm` as in
    /// [`solve_interacting`](Self::solve_interacting).
    pub fn solve(&self, model: Model, delta: f64, warm: &[f64]) -> Result<Step, RoughError> {
        match model {
            Model::Independent => self.solve_independent(delta),
            Model::Interacting(im) => self.solve_interacting(delta, im, warm),
        }
    }

    /// The first of `deltas` (m, in their order) at which the N model's contact areas
    /// sum to more than the nominal area (A/A₀ > 1, physically impossible), with that
    /// A/A₀. Cheap: single-asperity inversions only, one N-model solve at the largest
    /// approach when no step exceeds (A grows with δ). Callers refuse such a step before
    /// spending time on it ([`RoughError::AreaAboveNominal`]); the I model, whose
    /// interactions shrink contacts, is not started there. Approaches the N model cannot
    /// solve are skipped (their solve reports them).
    pub fn first_area_above_nominal(&self, deltas: &[f64]) -> Option<(usize, f64)> {
        let area = |d: f64| self.solve_independent(d).map_or(0.0, |s| s.area_fraction);
        let max = deltas.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if deltas.is_empty() || area(max) <= 1.0 {
            return None;
        }
        deltas
            .iter()
            .enumerate()
            .map(|(i, &d)| (i, area(d)))
            .find(|&(_, a)| a > 1.0)
    }

    /// A load path: one step per approach (m). The I model prepares the interaction
    /// geometry once, for the largest approach of the path, and starts each step from
    /// the previous radii extrapolated with their rates da/dδ.
    pub fn curve(&self, model: Model, deltas: &[f64]) -> Result<Vec<Step>, RoughError> {
        match model {
            Model::Independent => deltas.iter().map(|&d| self.solve_independent(d)).collect(),
            Model::Interacting(images) => interacting::path::curve(self, images, deltas),
        }
    }

    /// [`curve`](Self::curve) keeping what was solved: the steps before the first that
    /// failed, and that step's index and error (None when the whole path was solved).
    pub fn curve_partial(
        &self,
        model: Model,
        deltas: &[f64],
    ) -> (Vec<Step>, Option<(usize, RoughError)>) {
        let mut out = Vec::with_capacity(deltas.len());
        let res = match model {
            Model::Independent => deltas.iter().try_for_each(|&d| {
                out.push(self.solve_independent(d)?);
                Ok(())
            }),
            Model::Interacting(images) => {
                interacting::path::curve_into(self, images, deltas, &mut out)
            }
        };
        let failed = res.err().map(|e| (out.len(), e));
        (out, failed)
    }

    /// Finds the approach giving mean pressure `target` (Pa) by safeguarded Newton on δ
    /// (the stiffness is dP/dδ) on a bracket grown from [0, z_M − z_min] by doubling, to
    /// the relative tolerance [`Params::pressure_tolerance`]; the I model solves every
    /// iterate on one prepared problem, warm-started. `warm` starts the first solve.
    pub fn solve_pressure(
        &self,
        model: Model,
        target: f64,
        warm: &[f64],
    ) -> Result<Step, RoughError> {
        interacting::path::solve_pressure(self, model, target, warm)
    }
}

#[cfg(test)]
mod tests;
