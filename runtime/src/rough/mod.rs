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
//! The solver is organised by stage, each with its own error type:
//!
//! - [`independent`]: the N model, ζ(a_k)a_k²/R_k = δ_k per asperity;
//! - [`interacting`]: the I model — the far-field model of the interaction kernel
//!   (`far_field`), the image geometry and pair lists (`images`), the energy, its
//!   gradient and Jacobian (`energy`), the active-set Newton method (`newton`) and the
//!   load-path driver (`path`).
//!
//! Every tolerance and iteration limit is a documented field of [`Params`] (defaults
//! from `Params::default()`); every I-model step reports what its solve did in a
//! [`Diagnostics`]. A solve depends only on its inputs (the approach, the warm start it
//! is given and the parameters): no state is kept between calls.

mod error;
pub mod independent;
pub mod interacting;
mod local;
mod params;

pub use crate::law::contact_radius;
pub use error::{FarFieldError, IndependentError, NewtonError, PressureError, RoughError};
pub use interacting::Interaction;
pub use params::{Diagnostics, FarFieldInfo, Params, ParamsError, raise_advice};

use crate::law::AsperityLaw;
use crate::summits::Summit;

/// How interactions treat the sample boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Images {
    /// Interactions stop at the sample edge (plain distances).
    Isolated,
    /// The sample is one cell of a periodic pattern; sources are repeated on the
    /// (2m+1)×(2m+1) block of cells around it (m = 2: the 5×5 sum).
    Periodic(usize),
}

/// Which model a solve uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    /// N model: independent asperities.
    Independent,
    /// I model: interacting asperities with the given image convention.
    Interacting(Images),
}

/// Results of one load step.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Step {
    /// Approach δ (m).
    pub delta: f64,
    /// Separation g_n = (z_M − z̄) − δ (m).
    pub gap: f64,
    /// Total load P (N).
    pub load: f64,
    /// Mean pressure p_n = P/A₀ (Pa).
    pub mean_pressure: f64,
    /// p_n/E*₁ (-).
    pub pressure_ratio: f64,
    /// Real contact area fraction A/A₀ (-).
    pub area_fraction: f64,
    /// Number of asperities in contact.
    pub contacts: usize,
    /// Normal stiffness dP/dδ of the sample (N/m).
    pub stiffness: f64,
    /// I model only: KKT residual relative to the largest interference.
    pub kkt_residual: Option<f64>,
    /// Newton iterations (I model only; 0 otherwise).
    pub iterations: usize,
    /// Contact radius of every summit (m), 0 when out of contact.
    pub radii: Vec<f64>,
    /// What the solve did (I model; default for the N model).
    pub diagnostics: Diagnostics,
    /// Where the step leaves the models' validity (logged by the engine, recorded in
    /// curve.json).
    pub validity: Validity,
}

/// Where a step leaves the validity of the asperity models (physics.md §5): recorded,
/// never refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Validity {
    /// The flat is below the mean plane (g_n < 0).
    pub below_mean_plane: bool,
    /// The approach exceeds the peak-to-valley height z_M − z_min: every summit loaded.
    pub beyond_deepest_valley: bool,
    /// The summed contact areas exceed the nominal area (A/A₀ > 1).
    pub area_above_nominal: bool,
    /// I model: pairs of contacts whose circles overlap (r_kl < a_k + a_l) among the
    /// pairs summed exactly (the paper's model assumes separate circular contacts).
    pub overlapping_contacts: usize,
}

impl Validity {
    /// True when every check holds.
    pub fn is_valid(&self) -> bool {
        *self == Validity::default()
    }

    /// One line naming what does not hold (empty when valid).
    pub fn describe(&self) -> String {
        let mut out = Vec::new();
        if self.below_mean_plane {
            out.push("the flat is below the mean plane (g_n < 0)".to_string());
        }
        if self.beyond_deepest_valley {
            out.push("the approach exceeds z_M − z_min (every summit loaded)".to_string());
        }
        if self.area_above_nominal {
            out.push("the contact areas sum to more than the nominal area".to_string());
        }
        if self.overlapping_contacts > 0 {
            out.push(format!(
                "{} pairs of contact circles overlap",
                self.overlapping_contacts
            ));
        }
        out.join("; ")
    }
}

/// A rough surface reduced to its summits, on a given material law.
pub struct RoughContact<'a> {
    law: &'a dyn AsperityLaw,
    summits: Vec<Summit>,
    z_max: f64,
    z_mean: f64,
    z_min: f64,
    extent: (f64, f64),
    params: Params,
}

impl<'a> RoughContact<'a> {
    /// Reduces a surface (its summits, z̄, z_min and extent (m)) on a law, with the
    /// default [`Params`].
    pub fn new(
        law: &'a dyn AsperityLaw,
        summits: Vec<Summit>,
        z_mean: f64,
        z_min: f64,
        extent: (f64, f64),
    ) -> Result<Self, RoughError> {
        let z_max = summits
            .iter()
            .map(|s| s.z)
            .fold(f64::NEG_INFINITY, f64::max);
        if summits.is_empty() {
            return Err(RoughError::NoSummits);
        }
        // Library callers pass these directly: refuse what would turn into NaN or
        // negative pressures (found by tests/it/fuzz_solvers.rs).
        let bad = |field: &'static str, value: f64, reason: String| {
            Err(RoughError::LoadOutOfRange {
                field,
                value,
                reason,
            })
        };
        let e = law.e_star();
        if !(e.is_finite() && e > 0.0) {
            return bad(
                "E*",
                e,
                "the law's modulus must be finite and > 0 Pa".into(),
            );
        }
        for (name, v) in [("extent", extent.0), ("extent", extent.1)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, "sample sides must be finite and > 0 m".into());
            }
        }
        for (k, s) in summits.iter().enumerate() {
            for (name, v) in [("summit x", s.x), ("summit y", s.y), ("summit z", s.z)] {
                if !v.is_finite() {
                    return bad(name, v, format!("summit {k}: must be finite (m)"));
                }
            }
            if !(s.radius.is_finite() && s.radius > 0.0) {
                return bad(
                    "summit radius",
                    s.radius,
                    format!("summit {k}: must be finite and > 0 m"),
                );
            }
        }
        if !(z_mean.is_finite() && z_mean <= z_max) {
            return bad(
                "z_mean",
                z_mean,
                format!("must be finite and ≤ z_M = {z_max:e} m"),
            );
        }
        if !(z_min.is_finite() && z_min <= z_max) {
            return bad(
                "z_min",
                z_min,
                format!("must be finite and ≤ z_M = {z_max:e} m"),
            );
        }
        Ok(RoughContact {
            law,
            summits,
            z_max,
            z_mean,
            z_min,
            extent,
            params: Params::default(),
        })
    }

    /// Convenience: from a surface.
    pub fn from_surface(
        law: &'a dyn AsperityLaw,
        surface: &crate::surface::Surface,
    ) -> Result<Self, RoughError> {
        let s = crate::summits::find_summits(surface);
        let z_min = surface
            .heights()
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        Self::new(law, s.summits, surface.mean(), z_min, surface.extent())
    }

    /// Replaces the solver parameters (builder style).
    pub fn with_params(mut self, params: Params) -> Self {
        self.params = params;
        self
    }

    /// Sets the tolerance of the far-field interaction model ([`Params::far_field_tolerance`],
    /// default 1e-5): the largest error of every modelled G and ∂G/∂a relative to the
    /// point-force displacement (4/3)χa³/(πRr) and its a-derivative. 0 (or NaN) sums
    /// every image pair exactly.
    pub fn with_far_field_tolerance(mut self, tol: f64) -> Self {
        self.params.far_field_tolerance = if tol.is_nan() { 0.0 } else { tol.max(0.0) };
        self
    }

    /// The solver parameters in force.
    pub fn params(&self) -> &Params {
        &self.params
    }
    /// The material law.
    pub fn law(&self) -> &'a dyn AsperityLaw {
        self.law
    }
    /// The summits.
    pub fn summits(&self) -> &[Summit] {
        &self.summits
    }
    /// The sample's sides (Lx, Ly) (m).
    pub fn extent(&self) -> (f64, f64) {
        self.extent
    }
    /// z_M − z̄ (m): the approach at which g_n = 0.
    pub fn top_to_mean(&self) -> f64 {
        self.z_max - self.z_mean
    }
    /// The peak-to-valley height z_M − z_min (m): beyond this approach every summit is
    /// loaded (admissible, flagged in [`Step::validity`]).
    pub fn max_delta(&self) -> f64 {
        self.z_max - self.z_min
    }
    /// Nominal area A₀ (m²).
    pub fn area(&self) -> f64 {
        self.extent.0 * self.extent.1
    }
    /// Approach δ (m) for a separation g_n (m) (P26).
    pub fn delta_for_gap(&self, gap: f64) -> f64 {
        self.top_to_mean() - gap
    }

    /// Any finite approach δ ≥ 0 (m) is admissible: the layers compress as a whole, so
    /// the flat may pass the deepest valley while the contact is still partial; where a
    /// model leaves its validity the step says so ([`Validity`]).
    fn check_delta(&self, delta: f64) -> Result<(), RoughError> {
        if !delta.is_finite() || delta < 0.0 {
            return Err(RoughError::LoadOutOfRange {
                field: "load",
                value: delta,
                reason: format!(
                    "the approach δ must be finite and ≥ 0 m (separation ≤ z_M − z̄ = {:e} m)",
                    self.top_to_mean()
                ),
            });
        }
        Ok(())
    }

    /// Interference δ_k = ⟨δ − (z_M − z_k)⟩ of summit k at approach δ (m), eq. (P20).
    fn interference(&self, k: usize, delta: f64) -> f64 {
        self.signed_interference(k, delta).max(0.0)
    }

    /// δ − (z_M − z_k) (m): negative below the rigid plane.
    fn signed_interference(&self, k: usize, delta: f64) -> f64 {
        delta - (self.z_max - self.summits[k].z)
    }

    /// The summits that may touch at approach δ (m) when the surface between contacts
    /// may rise by up to `lift` (m): δ − (z_M − z_k) > −lift (lift 0: the loaded ones).
    fn candidates(&self, delta: f64, lift: f64) -> Vec<usize> {
        (0..self.summits.len())
            .filter(|&k| self.signed_interference(k, delta) > -lift)
            .collect()
    }

    /// The step at approach δ from the contact radii of every summit (m): load (P24),
    /// area (P25), pressures and the given stiffness, KKT residual and diagnostics.
    fn finish(
        &self,
        delta: f64,
        radii: Vec<f64>,
        stiffness: f64,
        kkt: Option<f64>,
        diagnostics: Diagnostics,
    ) -> Result<Step, RoughError> {
        let e = self.law.e_star();
        let mut load = 0.0;
        let mut area = 0.0;
        let mut contacts = 0;
        for (s, &a) in self.summits.iter().zip(&radii) {
            if a > 0.0 {
                load += crate::law::force(self.law, a, s.radius);
                area += std::f64::consts::PI * a * a;
                contacts += 1;
            }
        }
        let a0 = self.area();
        let validity = Validity {
            below_mean_plane: delta > self.top_to_mean(),
            beyond_deepest_valley: delta > self.max_delta(),
            area_above_nominal: area > a0,
            overlapping_contacts: 0,
        };
        let step = Step {
            delta,
            gap: self.top_to_mean() - delta,
            load,
            mean_pressure: load / a0,
            pressure_ratio: load / a0 / e,
            area_fraction: area / a0,
            contacts,
            stiffness,
            kkt_residual: kkt,
            iterations: diagnostics.newton_steps,
            radii,
            diagnostics,
            validity,
        };
        if !(step.load.is_finite()
            && step.mean_pressure.is_finite()
            && step.stiffness.is_finite()
            && step.area_fraction.is_finite())
        {
            return Err(RoughError::NonFinite("step results"));
        }
        Ok(step)
    }

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
