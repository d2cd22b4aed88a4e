//! The contact law of an interface, one type for every front end (the CLI's `compare`
//! and `law`, the Python package's `ContactLaw`, the C ABI): p(g), A(g)/A₀, dp/dg from
//! the runtime's [`InterfaceLaw`] (monotone interpolation of the samples) and, with
//! `[conductance]`, h_c(g) and h_c(p) from its [`ConductanceCurve`] (PCHIP in g, ∝ √δ
//! next to first contact; h_c(p) at the largest separation where p(g) = p, by bisection
//! on the monotone p(g)) and, with `[friction]`, the full-stick tangential stiffness
//! K_t(g) and K_t(p) of the sample (the same PCHIP curve: K_t ∝ √δ next to first contact
//! as h_c is, one Hertz disc of radius √(Rδ)). SI units: g in m, p in Pa, dp/dg in Pa/m,
//! h_c in W/(m²·K) (thermal) or S/m² (electrical), K_t in N/m over the sample.

use strata_runtime::conduction::ConductionKind;
use strata_runtime::interface::InterfaceError;
use strata_runtime::interface::InterfaceLaw;
use strata_runtime::interface::conductance_curve::{ConductanceCurve, CurveError};
use strata_runtime::rough::Step;
use thiserror::Error;

/// Errors of building or querying a [`ContactLaw`].
#[derive(Debug, Error)]
pub enum ContactLawError {
    /// The samples do not make a law (too few, not monotone, not finite…).
    #[error(transparent)]
    Law(#[from] InterfaceError),
    /// A conductance query outside the sampled range, or not a finite argument.
    #[error(transparent)]
    Conductance(#[from] CurveError),
    /// The law carries no conductance.
    #[error("this law has no conductance: add [conductance] to the scene (thermal or electrical)")]
    NoConductance,
    /// A conductance that is not finite and ≥ 0 at some sample (full contact: infinite).
    #[error(
        "the law's conductances are not finite and ≥ 0 at every sample (full contact): h_c is infinite there"
    )]
    InfiniteConductance,
    /// The law carries no tangential stiffness.
    #[error("this law has no tangential stiffness: add [friction] to the scene (coefficient = μ)")]
    NoTangentialStiffness,
    /// Tangential stiffnesses that are not one finite value ≥ 0 per sample.
    #[error("the law's tangential stiffnesses are not one finite value >= 0 per sample")]
    BadTangentialStiffness,
}

/// p(g), A(g)/A₀, dp/dg and (with a conductance) h_c(g), h_c(p) of an interface.
#[derive(Debug, Clone)]
pub struct ContactLaw {
    law: InterfaceLaw,
    conductance: Option<(ConductionKind, ConductanceCurve)>,
    tangential: Option<ConductanceCurve>,
}

impl ContactLaw {
    /// The law `law` with, optionally, the conductances h_c at its samples (in the
    /// order of [`InterfaceLaw::samples`]); they must be finite and ≥ 0.
    pub fn new(
        law: InterfaceLaw,
        conductance: Option<(ConductionKind, &[f64])>,
    ) -> Result<Self, ContactLawError> {
        let conductance = match conductance {
            Some((kind, h)) => {
                let gaps: Vec<f64> = law.samples().map(|(g, ..)| g).collect();
                Some((
                    kind,
                    ConductanceCurve::new(&gaps, h).ok_or(ContactLawError::InfiniteConductance)?,
                ))
            }
            None => None,
        };
        Ok(ContactLaw {
            law,
            conductance,
            tangential: None,
        })
    }

    /// The law with the full-stick tangential stiffnesses K_t (N/m over the sample) at
    /// its samples (in the order of [`InterfaceLaw::samples`], 0 at first contact);
    /// they must be finite and ≥ 0.
    pub fn with_tangential_stiffness(mut self, k: &[f64]) -> Result<Self, ContactLawError> {
        let gaps: Vec<f64> = self.law.samples().map(|(g, ..)| g).collect();
        self.tangential =
            Some(ConductanceCurve::new(&gaps, k).ok_or(ContactLawError::BadTangentialStiffness)?);
        Ok(self)
    }

    /// The full-stick tangential stiffness's curve K_t(g) (its samples, PCHIP between
    /// them), when the law carries one (`[friction]`).
    pub fn tangential_stiffness(&self) -> Option<&ConductanceCurve> {
        self.tangential.as_ref()
    }

    /// Whether the law carries the tangential stiffness (`[friction]`).
    pub fn has_tangential_stiffness(&self) -> bool {
        self.tangential.is_some()
    }

    /// The full-stick tangential stiffness K_t (N/m over the sample) at separation `gap`
    /// (m): the solved values at the samples, PCHIP between them (∝ √δ next to first
    /// contact), 0 at and above first contact; below the smallest sample an error.
    pub fn tangential_stiffness_at_gap(&self, gap: f64) -> Result<f64, ContactLawError> {
        let c = self
            .tangential
            .as_ref()
            .ok_or(ContactLawError::NoTangentialStiffness)?;
        Ok(c.at_gap(gap)?)
    }

    /// K_t (N/m) at mean contact pressure `pressure` (Pa): at the largest separation
    /// where p(g) equals it (bisection on the monotone p(g)); a sample's own pressure
    /// gives its K_t exactly.
    pub fn tangential_stiffness_at_pressure(&self, pressure: f64) -> Result<f64, ContactLawError> {
        let c = self
            .tangential
            .as_ref()
            .ok_or(ContactLawError::NoTangentialStiffness)?;
        let law = &self.law;
        Ok(c.at_pressure(pressure, |g| law.eval(g).map_or(f64::NAN, |q| q.pressure))?)
    }

    /// The law of a solved load path: first contact at separation `first_contact_gap`
    /// (m; p = A = h_c = 0 there, prepended when the first step is not at it), then the
    /// `steps` in loading order (separations decreasing), nominal area `nominal_area`
    /// (m²), with the steps' conductances `conductance` (W/(m²·K) or S/m²).
    pub fn from_steps(
        first_contact_gap: f64,
        steps: &[Step],
        nominal_area: f64,
        conductance: Option<(ConductionKind, &[f64])>,
    ) -> Result<Self, ContactLawError> {
        Self::from_steps_with(first_contact_gap, steps, nominal_area, conductance, None)
    }

    /// As [`ContactLaw::from_steps`], with the steps' full-stick tangential stiffnesses
    /// `tangential` (N/m over the sample; 0 at first contact when it is prepended).
    pub fn from_steps_with(
        first_contact_gap: f64,
        steps: &[Step],
        nominal_area: f64,
        conductance: Option<(ConductionKind, &[f64])>,
        tangential: Option<&[f64]>,
    ) -> Result<Self, ContactLawError> {
        let starts_at_contact = steps.first().is_some_and(|s| s.gap >= first_contact_gap);
        let mut all: Vec<Step> = Vec::with_capacity(steps.len() + 1);
        let mut h: Vec<f64> = Vec::with_capacity(steps.len() + 1);
        if !starts_at_contact {
            let mut first = Step::default();
            first.gap = first_contact_gap;
            all.push(first);
            h.push(0.0);
        }
        all.extend(steps.iter().cloned());
        let mut k: Vec<f64> = vec![0.0; h.len()];
        let law = InterfaceLaw::from_steps(&all, nominal_area)?;
        let out = match conductance {
            Some((kind, hs)) => {
                h.extend_from_slice(hs);
                Self::new(law, Some((kind, &h)))
            }
            None => Self::new(law, None),
        }?;
        match tangential {
            Some(ks) => {
                k.extend_from_slice(ks);
                out.with_tangential_stiffness(&k)
            }
            None => Ok(out),
        }
    }

    /// The runtime's law p(g), A(g)/A₀, dp/dg.
    pub fn law(&self) -> &InterfaceLaw {
        &self.law
    }

    /// Mean (nominal) pressure p(g) = P/A₀ (Pa) at separation `gap` (m).
    pub fn pressure(&self, gap: f64) -> Result<f64, ContactLawError> {
        Ok(self.law.pressure(gap)?)
    }

    /// Real contact area fraction A(g)/A₀ (1).
    pub fn area_fraction(&self, gap: f64) -> Result<f64, ContactLawError> {
        Ok(self.law.area_fraction(gap)?)
    }

    /// dp/dg (Pa/m, ≤ 0): minus the interface's normal stiffness per unit area.
    pub fn dp_dg(&self, gap: f64) -> Result<f64, ContactLawError> {
        Ok(self.law.dp_dg(gap)?)
    }

    /// `thermal` or `electrical` when the law carries a conductance.
    pub fn conductance_kind(&self) -> Option<ConductionKind> {
        self.conductance.as_ref().map(|(k, _)| *k)
    }

    /// The conductance's kind and its curve h_c(g) (its samples, PCHIP between them),
    /// when the law carries one.
    pub fn conductance(&self) -> Option<(ConductionKind, &ConductanceCurve)> {
        self.conductance.as_ref().map(|(k, c)| (*k, c))
    }

    fn curve(&self) -> Result<&ConductanceCurve, ContactLawError> {
        self.conductance
            .as_ref()
            .map(|(_, c)| c)
            .ok_or(ContactLawError::NoConductance)
    }

    /// Interface conductance h_c(g) (W/(m²·K) or S/m²) at separation `gap` (m): the
    /// solved values at the samples, PCHIP between them (∝ √δ next to first contact), 0
    /// at and above first contact; below the smallest sample an error.
    pub fn conductance_at_gap(&self, gap: f64) -> Result<f64, ContactLawError> {
        Ok(self.curve()?.at_gap(gap)?)
    }

    /// h_c at mean contact pressure `pressure` (Pa): at the largest separation where
    /// p(g) equals it (bisection on the monotone p(g)); a sample's own pressure gives
    /// its h_c exactly; above the largest sampled pressure an error.
    pub fn conductance_at_pressure(&self, pressure: f64) -> Result<f64, ContactLawError> {
        let law = &self.law;
        Ok(self
            .curve()?
            .at_pressure(pressure, |g| law.eval(g).map_or(f64::NAN, |q| q.pressure))?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Hertz-like path from first contact: p = c δ^{3/2}, h = k √δ. The law built
    /// from steps that start past first contact gets the first-contact sample
    /// prepended; h_c(p) at a step's own pressure is that step's h_c exactly, and
    /// between steps it is h_c(g) at the g where p(g) = p (a second route: the law's
    /// own p(g) inverted by bisection here).
    #[test]
    fn from_steps_prepends_first_contact_and_inverts_pressure() {
        let g0 = 1e-5;
        let (c, k) = (1e15, 3e4);
        let deltas: Vec<f64> = (1..9).map(|i| 1e-6 * i as f64).collect();
        let steps: Vec<Step> = deltas
            .iter()
            .map(|&d| {
                let mut s = Step::default();
                s.delta = d;
                s.gap = g0 - d;
                s.mean_pressure = c * d.powf(1.5);
                s.stiffness = 1e-6 * 1.5 * c * d.sqrt();
                s.area_fraction = 1e-3 * d / 1e-6;
                s
            })
            .collect();
        let h: Vec<f64> = deltas.iter().map(|d| k * d.sqrt()).collect();
        let l =
            ContactLaw::from_steps(g0, &steps, 1e-6, Some((ConductionKind::Thermal, &h))).unwrap();
        assert_eq!(l.law().len(), 9);
        assert_eq!(l.pressure(g0).unwrap(), 0.0);
        for (s, hv) in steps.iter().zip(&h) {
            assert_eq!(l.conductance_at_pressure(s.mean_pressure).unwrap(), *hv);
            assert_eq!(l.conductance_at_gap(s.gap).unwrap(), *hv);
        }
        // between samples: the g of p(g) = p by a separate bisection, then h_c(g)
        let p = 0.5 * (steps[3].mean_pressure + steps[4].mean_pressure);
        let (mut lo, mut hi) = (steps[4].gap, steps[3].gap);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if l.pressure(mid).unwrap() >= p {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let want = l.conductance_at_gap(lo).unwrap();
        let got = l.conductance_at_pressure(p).unwrap();
        assert!((got / want - 1.0).abs() < 1e-12, "{got} {want}");
        // and close to the exact k √δ(p) of the smooth path (PCHIP's error, measured
        // 3.0e-5 here)
        let exact = k * (p / c).powf(1.0 / 3.0);
        eprintln!("h_c(p) against k √δ(p): {:.3e}", got / exact - 1.0);
        assert!((got / exact - 1.0).abs() < 3e-4, "{got} {exact}");
        assert!(matches!(
            l.conductance_at_pressure(2.0 * steps[7].mean_pressure),
            Err(ContactLawError::Conductance(
                CurveError::AboveSampledPressure { .. }
            ))
        ));
        let plain = ContactLaw::from_steps(g0, &steps, 1e-6, None).unwrap();
        assert!(matches!(
            plain.conductance_at_gap(g0 - 1e-6),
            Err(ContactLawError::NoConductance)
        ));
    }
}
