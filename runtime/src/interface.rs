//! The contact law of a rough layered interface: mean contact pressure p(g), real
//! contact-area fraction A(g)/A₀ and the tangent dp/dg as functions of the mean-plane
//! separation g, for use as a constitutive law of the interface (FE contact, C ABI).
//!
//! The law is built from a solved load curve (physics.md §5, paper §4.2): a rigid flat
//! at approach δ from first contact has the separation (P26)
//!
//! ```text
//!   g = (z_M − z̄) − δ,            g₀ = z_M − z̄  (first contact: p = 0)
//!   p(g) = P(δ)/A₀                 (Pa; P from P24, A₀ the nominal area)
//!   A(g)/A₀ = π Σ a_k²/A₀          (P25)
//!   dp/dg = −(dP/dδ)/A₀  ≤ 0       (Pa/m; dP/dδ the sample's normal stiffness)
//! ```
//!
//! It is sampled at `n` separations evenly spaced from g₀ down to a chosen smallest
//! separation g_min (so δ runs evenly from 0 to g₀ − g_min) and interpolated between
//! the samples:
//!
//! - **p(g)**: cubic Hermite interpolation with the solver's own analytic slopes
//!   dp/dg = −(dP/dδ)/A₀ at the samples (fourth-order accurate), passed through the
//!   Fritsch–Carlson monotonicity limiter so the interpolant never decreases with
//!   decreasing g. The limiter leaves exact slopes alone unless they would overshoot;
//!   how many it changed is [`InterfaceLaw::limited_slopes`]. In the interval touching
//!   first contact, where one asperity carries the load and p ∝ δ^{3/2} (Hertz onset,
//!   χ, ζ → 1 as a → 0), p = Aδ^{3/2} + Bδ^{5/2} instead of a cubic.
//! - **dp/dg**: the derivative of that interpolant, so the tangent is consistent with
//!   p(g) (what an implicit FE solver needs); it equals the model's stiffness at every
//!   sample whose slope the limiter left alone.
//! - **A(g)/A₀**: monotone piecewise-cubic interpolation (PCHIP, Fritsch–Butland slopes
//!   with the three-point shape-preserving end rule), since the solver gives no dA/dδ;
//!   linear in δ in the first-contact interval (A = πRδ for one Hertz asperity).
//!
//! Outside the sampled range: for g ≥ g₀ the surfaces are apart, p = A = dp/dg = 0;
//! below g_min a query is an error ([`InterfaceError::BelowSampledRange`]) rather than
//! an extrapolation: rebuild the law with a smaller g_min. The samples are reproduced
//! exactly at the nodes.
//!
//! Validity: every sample keeps the solved step's [`Validity`] (the N and I models
//! leave theirs below the mean plane, past the deepest valley, with overlapping
//! contact circles; built from samples or BEM steps, every sample is valid). The CSV
//! has a `valid` column, and [`InterfaceLaw::invalid_ranges`] gives the separations
//! where the model is outside its validity, which the Abaqus block states in its
//! comments (the law there is an extrapolation of the model).
//!
//! Output: [`InterfaceLaw::csv`] (full precision) and the Abaqus/CalculiX block of the
//! submodule [`abaqus`] (20-character fields, and what each FE code does with the table).

use thiserror::Error;

use crate::numerics::{fritsch_carlson, hermite, pchip_slopes};
use crate::resources::{ResourceError, bytes_for};
use crate::rough::{Model, RoughContact, RoughError, Step, Validity};

pub mod abaqus;
pub use abaqus::abaqus_real;
/// h_c(g) and h_c(p) between the samples of a law (PCHIP in g, bisection on p(g)).
pub mod conductance_curve;

/// Largest number of samples [`InterfaceLaw::sample`] accepts (the command line's
/// `--samples` and the C ABI's `STRATA_MAX_SAMPLES` share it). 100 000 samples resolve
/// a load curve far beyond what any FE table uses (CalculiX keeps 200 lines).
pub const MAX_SAMPLES: usize = 100_000;

/// Errors building or querying an [`InterfaceLaw`]. Each names the offending input.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum InterfaceError {
    #[error("samples: {0} samples given, at least 2 are needed")]
    TooFewSamples(usize),
    #[error("samples: {0} samples requested, at most {MAX_SAMPLES}")]
    TooManySamples(usize),
    #[error("samples: the {field} arrays have different lengths")]
    LengthMismatch { field: &'static str },
    #[error("samples: {field}[{index}] = {value} is not finite")]
    NonFinite {
        field: &'static str,
        index: usize,
        value: f64,
    },
    #[error("samples: {field}[{index}] = {value}: {reason}")]
    Invalid {
        field: &'static str,
        index: usize,
        value: f64,
        reason: &'static str,
    },
    #[error(
        "min_gap = {value:e} m is invalid: it must be finite and below the first-contact separation {first_contact:e} m"
    )]
    MinGap {
        value: f64,
        first_contact: f64,
        lowest: f64,
    },
    #[error("gap = {0} is not a finite separation (m)")]
    NonFiniteGap(f64),
    #[error(
        "gap = {gap:e} m is below the sampled range (smallest separation {min_gap:e} m): rebuild the law with a smaller min_gap"
    )]
    BelowSampledRange { gap: f64, min_gap: f64 },
    #[error(
        "the sampled curve reaches A/A₀ = {} > 1 at g = {gap:e} m (the summed contact \
         areas exceed the nominal area: outside the asperity models' validity); end the law at a \
         larger separation (min_gap, --min-gap), or use model.kind = \"bem\" for this load",
        if *area < 1e4 { format!("{area}") } else { format!("{area:.3e}") }
    )]
    AreaAboveNominal { gap: f64, area: f64 },
    /// The message includes the solver's; no `source` (a chain would print it twice).
    #[error("solving the load curve: {0}")]
    Rough(RoughError),
    #[error(transparent)]
    Resource(#[from] ResourceError),
}

impl From<RoughError> for InterfaceError {
    fn from(e: RoughError) -> Self {
        InterfaceError::Rough(e)
    }
}

/// Which samples [`InterfaceLaw::sample`] solves: `samples` separations evenly from
/// first contact g₀ down to `min_gap` (m), both included.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleOptions {
    /// Number of samples n ≥ 2 (the first is first contact, p = 0).
    pub samples: usize,
    /// Smallest separation g_min (m), below first contact.
    pub min_gap: f64,
}

/// Deviation of the piecewise-linear table from the law
/// ([`InterfaceLaw::linear_table_deviation`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearDeviation {
    /// max |Δp|/p_max over all intervals.
    pub of_max: f64,
    /// max |Δp|/p where p ≥ 1 % of p_max.
    pub local: f64,
}

/// A run of consecutive samples outside the model's validity
/// ([`InterfaceLaw::invalid_ranges`]).
#[derive(Debug, Clone, PartialEq)]
pub struct InvalidRange {
    /// Largest separation of the run (m): its first sample in loading order.
    pub from_gap: f64,
    /// Smallest separation of the run (m).
    pub to_gap: f64,
    /// Whether the run reaches the smallest sampled separation (the model stays
    /// invalid down to g_min).
    pub to_end: bool,
    /// Number of samples in the run.
    pub samples: usize,
    /// Every check that fails somewhere in the run (flags or-ed, the largest number of
    /// overlapping pairs).
    pub validity: Validity,
}

/// One evaluation of the law at a separation g.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawPoint {
    /// Mean contact pressure p (Pa).
    pub pressure: f64,
    /// Real contact-area fraction A/A₀ (-).
    pub area_fraction: f64,
    /// dp/dg (Pa/m), ≤ 0: the tangent of p(g).
    pub dp_dg: f64,
}

/// A sampled, monotone contact law p(g), A(g)/A₀, dp/dg of a rough interface (see the
/// module documentation for the interpolation and the conventions).
#[derive(Debug, Clone, PartialEq)]
pub struct InterfaceLaw {
    /// Separations (m), strictly increasing: g_min first, g₀ last.
    x: Vec<f64>,
    /// p at the separations (Pa).
    p: Vec<f64>,
    /// dp/dg at the separations (Pa/m), after the monotonicity limiter.
    dp: Vec<f64>,
    /// A/A₀ at the separations.
    area: Vec<f64>,
    /// PCHIP slopes of A/A₀ (1/m).
    darea: Vec<f64>,
    limited: usize,
    /// The model's validity at the separations (ascending, as `x`).
    validity: Vec<Validity>,
    /// The model's short name for the validity warnings ("N model", "I model", or
    /// "model" when built from samples).
    model: &'static str,
}

/// The `n` separations (m) evenly spaced from `first_contact` down to `min_gap`, both
/// exact (first = `first_contact`, last = `min_gap`).
pub fn sample_gaps(first_contact: f64, min_gap: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            if i + 1 == n {
                min_gap
            } else {
                first_contact - (first_contact - min_gap) * i as f64 / (n - 1) as f64
            }
        })
        .collect()
}

/// Bytes [`InterfaceLaw::sample`] allocates for `samples` samples of a surface with
/// `summits` summits (an estimate for [`crate::resources::MemoryLimit::check`]): one solved [`Step`] per sample,
/// each with the contact radius of every summit (8 bytes), and the law's twelve f64
/// arrays (gaps, approaches, p, stiffness, A/A₀ and their ascending copies and slopes).
pub(crate) fn sample_bytes(samples: usize, summits: usize) -> u64 {
    let per_step =
        (std::mem::size_of::<Step>() as u64).saturating_add(bytes_for(summits as u64, 8));
    bytes_for(samples as u64, per_step.saturating_add(12 * 8))
}

impl InterfaceLaw {
    /// Solves the load curve of `rc` with `model` at the separations of `opts`
    /// ([`sample_gaps`] from g₀ = z_M − z̄) and builds the law. The solve is warm-started
    /// along the path, as [`RoughContact::curve`]. At most [`MAX_SAMPLES`] samples
    /// ([`InterfaceError::TooManySamples`]); the memory they need (`sample_bytes`) is
    /// checked against the memory limit of `rc`'s parameters
    /// ([`crate::rough::Params::memory`]) before anything is allocated
    /// ([`InterfaceError::Resource`]).
    pub fn sample(
        rc: &RoughContact<'_>,
        model: Model,
        opts: &SampleOptions,
    ) -> Result<Self, InterfaceError> {
        let g0 = rc.top_to_mean();
        // Any separation below first contact is admissible (the flat may pass the
        // deepest valley; the steps record where the model leaves its validity).
        let lowest = f64::NEG_INFINITY;
        let n = opts.samples;
        if n < 2 {
            return Err(InterfaceError::TooFewSamples(n));
        }
        if n > MAX_SAMPLES {
            return Err(InterfaceError::TooManySamples(n));
        }
        let summits = rc.summits().len();
        rc.params().memory.check(
            format!("the contact law ({n} samples of {summits} summits)"),
            sample_bytes(n, summits),
        )?;
        let gmin = opts.min_gap;
        if !(gmin.is_finite() && gmin < g0 && gmin >= lowest) {
            return Err(InterfaceError::MinGap {
                value: gmin,
                first_contact: g0,
                lowest,
            });
        }
        let gaps = sample_gaps(g0, gmin, n);
        let deltas: Vec<f64> = gaps.iter().map(|&g| (g0 - g).max(0.0)).collect();
        // The I model is not started on a path the N model (cheap) already takes past
        // A/A₀ = 1 (interactions shrink contacts; the same refusal as `strata solve`).
        if let Model::Interacting(_) = model
            && let Some((i, area)) = rc.first_area_above_nominal(&deltas)
        {
            return Err(InterfaceError::AreaAboveNominal { gap: gaps[i], area });
        }
        let steps = rc.curve(model, &deltas)?;
        let p: Vec<f64> = steps.iter().map(|s| s.mean_pressure).collect();
        let k: Vec<f64> = steps.iter().map(|s| s.stiffness / rc.area()).collect();
        let a: Vec<f64> = steps.iter().map(|s| s.area_fraction).collect();
        if let Some((i, &area)) = a.iter().enumerate().find(|(_, a)| **a > 1.0) {
            return Err(InterfaceError::AreaAboveNominal { gap: gaps[i], area });
        }
        let mut law = Self::from_samples(&gaps, &p, &k, &a)?;
        law.validity = steps.iter().rev().map(|s| s.validity).collect();
        law.model = match model {
            Model::Independent => "N model",
            Model::Interacting(_) => "I model",
        };
        Ok(law)
    }

    /// From solved steps (first step at first contact, δ = 0) and the nominal area A₀
    /// (m²): uses each step's `gap`, `mean_pressure`, `stiffness`/A₀, `area_fraction`
    /// and `validity`.
    pub fn from_steps(steps: &[Step], nominal_area: f64) -> Result<Self, InterfaceError> {
        if !(nominal_area.is_finite() && nominal_area > 0.0) {
            return Err(InterfaceError::Invalid {
                field: "nominal_area",
                index: 0,
                value: nominal_area,
                reason: "must be a finite area > 0 (m²)",
            });
        }
        let g: Vec<f64> = steps.iter().map(|s| s.gap).collect();
        let p: Vec<f64> = steps.iter().map(|s| s.mean_pressure).collect();
        let k: Vec<f64> = steps.iter().map(|s| s.stiffness / nominal_area).collect();
        let a: Vec<f64> = steps.iter().map(|s| s.area_fraction).collect();
        let mut law = Self::from_samples(&g, &p, &k, &a)?;
        law.validity = steps.iter().rev().map(|s| s.validity).collect();
        Ok(law)
    }

    /// From samples in loading order: separations `gaps` (m) strictly decreasing, the
    /// first at first contact; mean pressures `pressure` (Pa) starting at exactly 0 and
    /// non-decreasing; `stiffness` = dp/dδ = −dp/dg (Pa/m) ≥ 0; area fractions in
    /// [0, 1]. Every value must be finite; every sample is taken as valid.
    pub fn from_samples(
        gaps: &[f64],
        pressure: &[f64],
        stiffness: &[f64],
        area_fraction: &[f64],
    ) -> Result<Self, InterfaceError> {
        let n = gaps.len();
        if n < 2 {
            return Err(InterfaceError::TooFewSamples(n));
        }
        if pressure.len() != n || stiffness.len() != n || area_fraction.len() != n {
            return Err(InterfaceError::LengthMismatch {
                field: "gap, pressure, stiffness, area_fraction",
            });
        }
        for (field, v) in [
            ("gap", gaps),
            ("pressure", pressure),
            ("stiffness", stiffness),
            ("area_fraction", area_fraction),
        ] {
            if let Some((index, &value)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
                return Err(InterfaceError::NonFinite {
                    field,
                    index,
                    value,
                });
            }
        }
        let invalid = |field, index: usize, value, reason| InterfaceError::Invalid {
            field,
            index,
            value,
            reason,
        };
        if pressure[0] != 0.0 {
            return Err(invalid(
                "pressure",
                0,
                pressure[0],
                "the first sample must be first contact, p = 0",
            ));
        }
        for i in 1..n {
            if gaps[i] >= gaps[i - 1] {
                return Err(invalid(
                    "gap",
                    i,
                    gaps[i],
                    "separations must decrease strictly along the load path",
                ));
            }
            if pressure[i] < pressure[i - 1] {
                return Err(invalid(
                    "pressure",
                    i,
                    pressure[i],
                    "the pressure decreases under increasing load (not a monotone law)",
                ));
            }
        }
        if let Some((i, &k)) = stiffness.iter().enumerate().find(|(_, k)| **k < 0.0) {
            return Err(invalid("stiffness", i, k, "must be ≥ 0"));
        }
        if let Some((i, &a)) = area_fraction
            .iter()
            .enumerate()
            .find(|(_, a)| !(0.0..=1.0).contains(*a))
        {
            return Err(invalid("area_fraction", i, a, "must lie in [0, 1]"));
        }
        // Ascending separations.
        let x: Vec<f64> = gaps.iter().rev().copied().collect();
        let p: Vec<f64> = pressure.iter().rev().copied().collect();
        let mut dp: Vec<f64> = stiffness.iter().rev().map(|k| 0.0 - k).collect();
        let area: Vec<f64> = area_fraction.iter().rev().copied().collect();
        // First-contact interval [x[n−2], g₀]: p = Aδ^{3/2} + Bδ^{5/2} needs A ≥ 0, i.e.
        // (dp/dδ)·δ₁ ≤ (5/2)p₁ at its inner node.
        let u = x[n - 1] - x[n - 2];
        let mut limited = 0;
        if -dp[n - 2] * u > 2.5 * p[n - 2] {
            dp[n - 2] = -2.5 * p[n - 2] / u;
            limited += 1;
        }
        limited += fritsch_carlson(&x[..n - 1], &p[..n - 1], &mut dp[..n - 1]);
        let darea = pchip_slopes(&x, &area);
        Ok(InterfaceLaw {
            x,
            p,
            dp,
            area,
            darea,
            limited,
            validity: vec![Validity::default(); n],
            model: "model",
        })
    }

    /// First-contact separation g₀ = z_M − z̄ (m): p = 0 at and above it.
    pub fn first_contact_gap(&self) -> f64 {
        self.x[self.x.len() - 1]
    }

    /// Smallest sampled separation g_min (m): queries below it are errors.
    pub fn min_gap(&self) -> f64 {
        self.x[0]
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Always false (a law has at least two samples); for clippy's `len` rule.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// How many sample slopes the Fritsch–Carlson limiter changed (0: dp/dg equals the
    /// solver's stiffness at every sample).
    pub fn limited_slopes(&self) -> usize {
        self.limited
    }

    /// The samples in loading order (g decreasing from g₀): (g (m), p (Pa),
    /// dp/dg (Pa/m), A/A₀).
    pub fn samples(&self) -> impl Iterator<Item = (f64, f64, f64, f64)> + '_ {
        (0..self.x.len())
            .rev()
            .map(|i| (self.x[i], self.p[i], self.dp[i], self.area[i]))
    }

    /// The model's validity at each sample, in loading order (as [`Self::samples`]).
    pub fn validity(&self) -> impl Iterator<Item = &Validity> + '_ {
        self.validity.iter().rev()
    }

    /// The model's short name: `"N model"`, `"I model"` (sampled by
    /// [`InterfaceLaw::sample`]) or `"model"`.
    pub fn model_name(&self) -> &'static str {
        self.model
    }

    /// The runs of consecutive samples outside the model's validity, in loading order
    /// (g decreasing); empty when every sample is valid.
    pub fn invalid_ranges(&self) -> Vec<InvalidRange> {
        let mut out: Vec<InvalidRange> = Vec::new();
        let mut open = false;
        for i in (0..self.x.len()).rev() {
            let v = self.validity[i];
            if v.is_valid() {
                open = false;
                continue;
            }
            if open && let Some(r) = out.last_mut() {
                r.to_gap = self.x[i];
                r.to_end = i == 0;
                r.samples += 1;
                let w = &mut r.validity;
                w.below_mean_plane |= v.below_mean_plane;
                w.beyond_deepest_valley |= v.beyond_deepest_valley;
                w.area_above_nominal |= v.area_above_nominal;
                w.overlapping_contacts = w.overlapping_contacts.max(v.overlapping_contacts);
            } else {
                out.push(InvalidRange {
                    from_gap: self.x[i],
                    to_gap: self.x[i],
                    to_end: i == 0,
                    samples: 1,
                    validity: v,
                });
                open = true;
            }
        }
        out
    }

    /// p, A/A₀ and dp/dg at separation `gap` (m).
    pub fn eval(&self, gap: f64) -> Result<LawPoint, InterfaceError> {
        if !gap.is_finite() {
            return Err(InterfaceError::NonFiniteGap(gap));
        }
        let n = self.x.len();
        if gap >= self.x[n - 1] {
            return Ok(LawPoint {
                pressure: 0.0,
                area_fraction: 0.0,
                dp_dg: 0.0,
            });
        }
        if gap < self.x[0] {
            return Err(InterfaceError::BelowSampledRange {
                gap,
                min_gap: self.x[0],
            });
        }
        // x[k] ≤ gap < x[k+1].
        let k = self.x.partition_point(|&v| v <= gap) - 1;
        if gap == self.x[k] {
            return Ok(LawPoint {
                pressure: self.p[k],
                area_fraction: self.area[k],
                dp_dg: self.dp[k],
            });
        }
        if k == n - 2 {
            return Ok(self.first_interval(gap));
        }
        let (pv, dv) = hermite(
            &self.x[k..k + 2],
            &self.p[k..k + 2],
            &self.dp[k..k + 2],
            gap,
        );
        let (av, _) = hermite(
            &self.x[k..k + 2],
            &self.area[k..k + 2],
            &self.darea[k..k + 2],
            gap,
        );
        Ok(LawPoint {
            pressure: pv,
            area_fraction: av,
            dp_dg: dv,
        })
    }

    /// The interval touching first contact, δ = g₀ − g ∈ (0, δ₁): the Hertz onset
    /// p = Aδ^{3/2} + Bδ^{5/2} through p(δ₁) = p₁ with the sample's slope m₁ = dp/dδ
    /// (A = (5p₁/2 − m₁δ₁)/δ₁^{3/2}, B = (m₁δ₁ − 3p₁/2)/δ₁^{5/2}; exact for one Hertz
    /// asperity, where m₁δ₁ = 3p₁/2, and monotone for A ≥ 0), and A/A₀ linear in δ
    /// (A = πRδ for one Hertz asperity).
    fn first_interval(&self, gap: f64) -> LawPoint {
        let n = self.x.len();
        let g0 = self.x[n - 1];
        let u = g0 - self.x[n - 2];
        let d = g0 - gap;
        let (p1, m1) = (self.p[n - 2], -self.dp[n - 2]);
        let a = (2.5 * p1 - m1 * u) / u.powf(1.5);
        let b = (m1 * u - 1.5 * p1) / u.powf(2.5);
        let sd = d.sqrt();
        LawPoint {
            pressure: (a + b * d) * d * sd,
            area_fraction: self.area[n - 2] * d / u,
            dp_dg: -(1.5 * a + 2.5 * b * d) * sd,
        }
    }

    /// Mean contact pressure p(g) (Pa).
    pub fn pressure(&self, gap: f64) -> Result<f64, InterfaceError> {
        Ok(self.eval(gap)?.pressure)
    }

    /// Real contact-area fraction A(g)/A₀ (-).
    pub fn area_fraction(&self, gap: f64) -> Result<f64, InterfaceError> {
        Ok(self.eval(gap)?.area_fraction)
    }

    /// Tangent dp/dg (Pa/m, ≤ 0), the derivative of the interpolant p(g).
    pub fn dp_dg(&self, gap: f64) -> Result<f64, InterfaceError> {
        Ok(self.eval(gap)?.dp_dg)
    }

    /// How far the piecewise-linear interpolation of the samples (what an FE tabular
    /// law does) is from p(g), at the interval midpoints: `of_max` = max |Δp|/p_max over
    /// all intervals; `local` = max |Δp|/p over the intervals whose midpoint pressure is
    /// at least 1 % of p_max (near first contact p ∝ δ^{3/2} and the relative error of a
    /// chord is large but the pressure tiny). Zeros with two samples.
    pub fn linear_table_deviation(&self) -> LinearDeviation {
        let n = self.x.len();
        let pmax = self.p[0];
        let mut d = LinearDeviation {
            of_max: 0.0,
            local: 0.0,
        };
        if pmax <= 0.0 {
            return d;
        }
        for k in 0..n - 1 {
            let mid = 0.5 * (self.x[k] + self.x[k + 1]);
            let pc = self.eval(mid).map_or(0.0, |q| q.pressure);
            let dev = (0.5 * (self.p[k] + self.p[k + 1]) - pc).abs();
            d.of_max = d.of_max.max(dev / pmax);
            if pc >= 1e-2 * pmax {
                d.local = d.local.max(dev / pc);
            }
        }
        d
    }
}

impl InterfaceLaw {
    /// The samples as CSV, header `gap,overclosure,mean_pressure,area_fraction,dp_dg,valid`
    /// (m, m, Pa, -, Pa/m, 1/0), in loading order, full precision; `valid` is 1 where
    /// the model is inside its validity ([`InterfaceLaw::validity`]), else 0.
    pub fn csv(&self) -> String {
        let g0 = self.first_contact_gap();
        let mut s = String::from("gap,overclosure,mean_pressure,area_fraction,dp_dg,valid\n");
        for ((g, p, d, a), v) in self.samples().zip(self.validity()) {
            s.push_str(&format!(
                "{g:e},{:e},{p:e},{a:e},{d:e},{}\n",
                g0 - g,
                u8::from(v.is_valid())
            ));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::Homogeneous;
    use crate::summits::Summit;

    /// A single Hertz asperity: P = (4/3)E*√R δ^{3/2} (Johnson eq. 4.23), A = πRδ.
    fn hertz_rc(law: &Homogeneous) -> RoughContact<'_> {
        let summits = vec![Summit {
            index: (0, 0),
            x: 0.5e-3,
            y: 0.5e-3,
            z: 1e-6,
            radius: 1e-4,
        }];
        RoughContact::new(law, summits, 0.0, -4e-6, (1e-3, 1e-3)).expect("rc")
    }

    /// Between the samples the law matches the closed form. With sample spacing h, the
    /// cubic Hermite error is O((h/δ)⁴) relative for p ∝ δ^{3/2} (O((h/δ)³) for the
    /// tangent, O((h/δ)²) for the PCHIP area); the first-contact interval is exact.
    /// Measured constants ×3 margin are asserted; nodes are reproduced bit for bit.
    #[test]
    fn single_hertz_asperity_matches_closed_form() {
        let law = Homogeneous { e_star: 2e11 };
        let rc = hertz_rc(&law);
        let il = InterfaceLaw::sample(
            &rc,
            Model::Independent,
            &SampleOptions {
                samples: 200,
                min_gap: -2e-6,
            },
        )
        .expect("law");
        assert_eq!(il.first_contact_gap(), 1e-6);
        assert_eq!(il.min_gap(), -2e-6);
        assert_eq!(il.limited_slopes(), 0);
        let (e, r, a0): (f64, f64, f64) = (2e11, 1e-4, 1e-6);
        let h = 3e-6 / 199.0;
        let (mut wp, mut wd, mut wa) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..1000 {
            let g = 1e-6 - 3e-6 * (i as f64 + 0.37) / 1000.0;
            let d = 1e-6 - g;
            let p = 4.0 / 3.0 * e * r.sqrt() * d.powf(1.5) / a0;
            let dp = -2.0 * e * r.sqrt() * d.sqrt() / a0;
            let a = std::f64::consts::PI * r * d / a0;
            let q = il.eval(g).expect("eval");
            let s = (h / d).min(1.0);
            let (ep, ed, ea) = (
                (q.pressure - p).abs() / p,
                (q.dp_dg - dp).abs() / dp.abs(),
                (q.area_fraction - a).abs() / a,
            );
            if d < h {
                assert!(ep < 1e-12 && ed < 1e-12 && ea < 1e-12, "δ={d:e}: {q:?}");
            } else {
                wp = wp.max(ep / s.powi(4));
                wd = wd.max(ed / s.powi(3));
                wa = wa.max(ea / s.powi(2));
            }
        }
        eprintln!("error constants: p {wp:.2e}, dp/dg {wd:.2e}, A {wa:.2e}");
        assert!(wp < 5e-3 && wd < 1.5e-2 && wa < 1e-9, "{wp} {wd} {wa}");
        // The tangent is the derivative of the interpolant (central differences, 1e-6).
        for i in 1..300 {
            let g = 1e-6 - 3e-6 * (i as f64 + 0.5) / 300.0;
            let e = 1e-13;
            let fd = (il.pressure(g + e).expect("p") - il.pressure(g - e).expect("p")) / (2.0 * e);
            let d = il.dp_dg(g).expect("dp");
            assert!((fd - d).abs() <= 1e-6 * d.abs(), "g={g:e}: {fd} {d}");
        }
        // Samples reproduced exactly.
        for (g, p, d, a) in il.samples() {
            let q = il.eval(g).expect("eval");
            assert_eq!((q.pressure, q.dp_dg, q.area_fraction), (p, d, a));
        }
    }

    #[test]
    fn outside_the_range() {
        let law = Homogeneous { e_star: 2e11 };
        let rc = hertz_rc(&law);
        let opts = SampleOptions {
            samples: 20,
            min_gap: 0.0,
        };
        let il = InterfaceLaw::sample(&rc, Model::Independent, &opts).expect("law");
        for g in [1e-6, 2e-6, 1.0] {
            let q = il.eval(g).expect("eval");
            assert_eq!((q.pressure, q.area_fraction, q.dp_dg), (0.0, 0.0, 0.0));
        }
        assert!(il.eval(0.0).is_ok());
        assert!(matches!(
            il.eval(-1e-12),
            Err(InterfaceError::BelowSampledRange { .. })
        ));
        for g in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(matches!(il.eval(g), Err(InterfaceError::NonFiniteGap(_))));
        }
        // below the deepest valley (−4e-6 m) is admissible: the steps flag it
        let o = SampleOptions {
            samples: 20,
            min_gap: -4.1e-6,
        };
        let deep = InterfaceLaw::sample(&rc, Model::Independent, &o).expect("beyond the valley");
        assert!(deep.eval(-4.1e-6).expect("eval").pressure > 0.0);
        for bad in [f64::NAN, 1e-6, 2e-6] {
            let o = SampleOptions {
                samples: 20,
                min_gap: bad,
            };
            let e = InterfaceLaw::sample(&rc, Model::Independent, &o).unwrap_err();
            assert!(e.to_string().contains("min_gap"), "{e}");
        }
        let o = SampleOptions {
            samples: 1,
            min_gap: 0.0,
        };
        assert!(InterfaceLaw::sample(&rc, Model::Independent, &o).is_err());
    }

    #[test]
    fn bad_samples_are_rejected() {
        let g = [3.0, 2.0, 1.0];
        let ok = InterfaceLaw::from_samples(&g, &[0.0, 1.0, 2.0], &[0.5, 1.0, 1.0], &[0.0; 3]);
        assert!(ok.is_ok());
        type Case<'a> = (&'a [f64], &'a [f64], &'a [f64], &'a [f64], &'a str);
        let cases: [Case; 7] = [
            (
                &[3.0, 3.0, 1.0],
                &[0.0, 1.0, 2.0],
                &[1.0; 3],
                &[0.0; 3],
                "gap",
            ),
            (&g, &[0.1, 1.0, 2.0], &[1.0; 3], &[0.0; 3], "pressure"),
            (&g, &[0.0, 2.0, 1.0], &[1.0; 3], &[0.0; 3], "pressure"),
            (
                &g,
                &[0.0, 1.0, 2.0],
                &[1.0, -1.0, 1.0],
                &[0.0; 3],
                "stiffness",
            ),
            (&g, &[0.0, 1.0, f64::NAN], &[1.0; 3], &[0.0; 3], "pressure"),
            (&g, &[0.0, 1.0, 2.0], &[1.0; 3], &[0.0, 0.5, 1.5], "area"),
            (&g, &[0.0, 1.0], &[1.0; 3], &[0.0; 3], "lengths"),
        ];
        for (g, p, k, a, what) in cases {
            let e = InterfaceLaw::from_samples(g, p, k, a).unwrap_err();
            assert!(e.to_string().contains(what), "{what}: {e}");
        }
    }

    /// The memory limit is a parameter of each solve, not of the process: two samplings
    /// run at once in one process, one under a 1 KiB limit and one under the machine's,
    /// each honour their own (the former process-wide limit held one value for both, so
    /// one of the two would have been wrong). The refusal names its limit and source;
    /// the other solve gives the law of a solve with the default parameters bit for bit.
    #[test]
    fn two_solves_honour_their_own_memory_limits() {
        use crate::resources::MemoryLimit;
        use crate::rough::Params;
        let law = Homogeneous { e_star: 2e11 };
        let o = SampleOptions {
            samples: 200,
            min_gap: -2e-6,
        };
        let needed = sample_bytes(200, 1);
        assert!(needed > 1 << 10, "{needed}");
        let tight = Params {
            memory: MemoryLimit::new(1 << 10, "the first solve's"),
            ..Params::default()
        };
        let ample = Params {
            memory: MemoryLimit::new(needed, "the second solve's"),
            ..Params::default()
        };
        let (refused, solved) = std::thread::scope(|s| {
            let a = s.spawn(|| {
                let rc = hertz_rc(&law).with_params(tight);
                InterfaceLaw::sample(&rc, Model::Independent, &o)
            });
            let b = s.spawn(|| {
                let rc = hertz_rc(&law).with_params(ample);
                InterfaceLaw::sample(&rc, Model::Independent, &o)
            });
            (a.join().unwrap(), b.join().unwrap())
        });
        let e = refused.unwrap_err();
        assert_eq!(
            e,
            InterfaceError::Resource(ResourceError::Memory {
                what: "the contact law (200 samples of 1 summits)".into(),
                needed,
                limit: 1 << 10,
                source_of_limit: "the first solve's",
            })
        );
        assert!(
            e.to_string().contains("1.00 KiB (the first solve's)"),
            "{e}"
        );
        let reference = InterfaceLaw::sample(&hertz_rc(&law), Model::Independent, &o).unwrap();
        assert_eq!(solved.unwrap(), reference);
    }

    /// Absurd sample counts are refused before anything is allocated; the memory
    /// estimate grows with samples × summits and is refused above a limit.
    #[test]
    fn absurd_sizes_are_refused() {
        let law = Homogeneous { e_star: 2e11 };
        let rc = hertz_rc(&law);
        for n in [MAX_SAMPLES + 1, 1_000_000_000, usize::MAX] {
            let o = SampleOptions {
                samples: n,
                min_gap: 0.0,
            };
            let e = InterfaceLaw::sample(&rc, Model::Independent, &o).unwrap_err();
            assert_eq!(e, InterfaceError::TooManySamples(n));
            assert!(e.to_string().contains("at most 100000"), "{e}");
        }
        assert_eq!(sample_bytes(usize::MAX, usize::MAX), u64::MAX);
        let b = sample_bytes(MAX_SAMPLES, 100_000);
        assert!(b > 80_000_000_000, "{b}");
        let limit = crate::resources::MemoryLimit::new(16 << 30, "test");
        let e = limit.check("law", b).unwrap_err();
        assert!(e.to_string().contains("memory limit"), "{e}");
        assert!(limit.check("law", sample_bytes(200, 5000)).is_ok());
    }

    /// Sampled past the deepest valley (−4e-6 m) and below the mean plane (the summit
    /// at 1e-6 m above it): the samples at g < 0 are invalid, one run to the end, and
    /// the Abaqus block says so in ASCII `** WARNING:` lines; a law from samples is
    /// valid everywhere.
    #[test]
    fn invalid_samples_form_ranges() {
        let law = Homogeneous { e_star: 2e11 };
        let rc = hertz_rc(&law);
        let o = SampleOptions {
            samples: 11,
            min_gap: -4.5e-6,
        };
        let il = InterfaceLaw::sample(&rc, Model::Independent, &o).expect("law");
        let valid: Vec<bool> = il.validity().map(|v| v.is_valid()).collect();
        let gaps: Vec<f64> = il.samples().map(|s| s.0).collect();
        for (g, v) in gaps.iter().zip(&valid) {
            assert_eq!(*v, *g >= 0.0, "g = {g:e}");
        }
        let r = il.invalid_ranges();
        assert_eq!(r.len(), 1, "{r:?}");
        let first = gaps.iter().position(|g| *g < 0.0).expect("g < 0");
        assert_eq!(r[0].from_gap, gaps[first]);
        assert_eq!(r[0].to_gap, -4.5e-6);
        assert!(r[0].to_end && r[0].samples == gaps.len() - first);
        assert!(r[0].validity.below_mean_plane && r[0].validity.beyond_deepest_valley);
        let w = il.validity_warnings();
        assert!(
            w[0].starts_with("the N model is outside its validity for g <="),
            "{w:?}"
        );
        let block = il.abaqus_block(&[]);
        assert!(
            block.contains("** WARNING: the N model is outside"),
            "{block}"
        );
        assert!(block.contains("z_M - z_min"), "{block}");
        for line in block.lines() {
            assert!(line.is_ascii() && line.len() <= 256, "{line}");
        }
        assert!(il.csv().lines().nth(1).expect("row").ends_with(",1"));
        assert!(il.csv().lines().last().expect("row").ends_with(",0"));
        let fs = InterfaceLaw::from_samples(&[2.0, 1.0], &[0.0, 1.0], &[1.0, 1.0], &[0.0, 0.1])
            .expect("law");
        assert!(fs.invalid_ranges().is_empty() && fs.validity_warnings().is_empty());
    }

    /// Overshooting slopes are limited and the interpolant stays monotone.
    #[test]
    fn limiter_keeps_monotone() {
        let g = [4.0, 3.0, 2.0, 1.0];
        let p = [0.0, 0.01, 0.02, 10.0];
        let k = [0.0, 50.0, 50.0, 50.0];
        let il = InterfaceLaw::from_samples(&g, &p, &k, &[0.0, 0.1, 0.2, 0.3]).expect("law");
        assert!(il.limited_slopes() > 0);
        let mut last = f64::INFINITY;
        for i in 0..=3000 {
            let x = 1.0 + 3.0 * i as f64 / 3000.0;
            let q = il.eval(x).expect("eval");
            assert!(q.pressure <= last + 1e-12, "at {x}");
            assert!(q.dp_dg <= 1e-12, "at {x}");
            last = q.pressure;
        }
    }
}
