//! The rough contact of one surface on one law: its summits, the sample's extent and
//! heights, the solver parameters, and what every model shares (interferences,
//! candidates, and a step's load, area and validity from its contact radii). The
//! models build on it (`independent`, `interacting`); the entry points that dispatch to
//! them are in the parent module.

use super::error::RoughError;
use super::params::{Diagnostics, Params};
use super::step::{Step, Validity};
use crate::law::AsperityLaw;
use crate::summits::Summit;

/// A rough surface reduced to its summits, on a given material law.
pub struct RoughContact<'a> {
    pub(super) law: &'a dyn AsperityLaw,
    pub(super) summits: Vec<Summit>,
    pub(super) z_max: f64,
    pub(super) z_mean: f64,
    pub(super) z_min: f64,
    pub(super) extent: (f64, f64),
    pub(super) params: Params,
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
    pub(super) fn check_delta(&self, delta: f64) -> Result<(), RoughError> {
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
    pub(super) fn interference(&self, k: usize, delta: f64) -> f64 {
        self.signed_interference(k, delta).max(0.0)
    }

    /// δ − (z_M − z_k) (m): negative below the rigid plane.
    pub(super) fn signed_interference(&self, k: usize, delta: f64) -> f64 {
        delta - (self.z_max - self.summits[k].z)
    }

    /// The summits that may touch at approach δ (m) when the surface between contacts
    /// may rise by up to `lift` (m): δ − (z_M − z_k) > −lift (lift 0: the loaded ones).
    pub(super) fn candidates(&self, delta: f64, lift: f64) -> Vec<usize> {
        (0..self.summits.len())
            .filter(|&k| self.signed_interference(k, delta) > -lift)
            .collect()
    }

    /// The step at approach δ from the contact radii of every summit (m): load (P24),
    /// area (P25), pressures and the given stiffness, KKT residual and diagnostics.
    pub(super) fn finish(
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
}
