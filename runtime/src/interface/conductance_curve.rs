//! The interface conductance h_c between the samples of a law: h_c(g) at a
//! separation g and h_c at a mean contact pressure p, from the conductances solved at
//! the law's samples (W/(m²·K) or S/m², physics.md §6.2).
//!
//! - **h_c(g)**: monotone piecewise-cubic Hermite interpolation (PCHIP: Fritsch–Butland
//!   slopes, the three-point shape-preserving end rule, as the law's A(g)/A₀) in g,
//!   the samples reproduced exactly; in the interval touching first contact, where
//!   one spot conducts (G = 4k a ψ, a = √(Rδ) for a Hertz asperity), h_c ∝ √δ,
//!   δ = g₀ − g; 0 at and above first contact.
//! - **h_c(p)**: h_c at the separation where the law's p(g) equals p (the loading path
//!   reaches p first there: the largest such g), found by bisection on the monotone
//!   p(g) to the last representable separation; a sample's own pressure gives the
//!   sample's h_c exactly. This is the conductance an FE code needs at a contact
//!   pressure (Abaqus' `*GAP CONDUCTANCE, PRESSURE` tabulates the samples and
//!   interpolates linearly in p between them; this follows the physics between them).

use crate::numerics::{bisect_adjacent, hermite, pchip_slopes};
use thiserror::Error;

/// Errors of a conductance query.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum CurveError {
    /// Below the smallest sampled separation.
    #[error(
        "gap {gap:e} m lies below the smallest sampled separation {min_gap:e} m: rebuild the law with a smaller min_gap"
    )]
    BelowSampledRange { gap: f64, min_gap: f64 },
    /// Above the largest sampled pressure.
    #[error(
        "pressure {pressure:e} Pa exceeds the largest sampled mean pressure {max:e} Pa: rebuild the law with a smaller min_gap"
    )]
    AboveSampledPressure { pressure: f64, max: f64 },
    /// A non-finite or negative argument.
    #[error("{value} is not a finite {what}")]
    Invalid { value: f64, what: &'static str },
}

/// h_c at the samples of a law, ascending separations.
#[derive(Debug, Clone, PartialEq)]
pub struct ConductanceCurve {
    /// Separations (m), strictly increasing, g₀ last.
    x: Vec<f64>,
    /// h_c at `x` (W/(m²·K) or S/m²).
    h: Vec<f64>,
    /// PCHIP slopes of h_c (per m).
    dh: Vec<f64>,
}

impl ConductanceCurve {
    /// From samples in loading order (g strictly decreasing from first contact; the
    /// law's [`super::InterfaceLaw::samples`]) and their h_c, at
    /// least two. `None` when a value is not finite and ≥ 0 (the N and I models give
    /// finite conductances; full contact would be infinite).
    pub fn new(gaps: &[f64], conductance: &[f64]) -> Option<ConductanceCurve> {
        let n = gaps.len();
        if n < 2
            || conductance.len() != n
            || conductance.iter().any(|h| !(*h >= 0.0 && h.is_finite()))
        {
            return None;
        }
        let x: Vec<f64> = gaps.iter().rev().copied().collect();
        if x.iter().any(|v| !v.is_finite()) || x.windows(2).any(|w| w[0] >= w[1]) {
            return None;
        }
        let h: Vec<f64> = conductance.iter().rev().copied().collect();
        let dh = pchip_slopes(&x, &h);
        Some(ConductanceCurve { x, h, dh })
    }

    /// The conductances at the samples, in loading order.
    pub fn samples(&self) -> impl Iterator<Item = f64> + '_ {
        self.h.iter().rev().copied()
    }

    /// h_c at separation `gap` (m): 0 at and above first contact, an error below the
    /// smallest sampled separation.
    pub fn at_gap(&self, gap: f64) -> Result<f64, CurveError> {
        if !gap.is_finite() {
            return Err(CurveError::Invalid {
                value: gap,
                what: "separation (m)",
            });
        }
        let n = self.x.len();
        if gap >= self.x[n - 1] {
            return Ok(0.0);
        }
        if gap < self.x[0] {
            return Err(CurveError::BelowSampledRange {
                gap,
                min_gap: self.x[0],
            });
        }
        let k = self.x.partition_point(|&v| v <= gap) - 1;
        if gap == self.x[k] {
            return Ok(self.h[k]);
        }
        if k == n - 2 {
            // one spot: h_c ∝ √δ through the first sample
            let g0 = self.x[n - 1];
            return Ok(self.h[n - 2] * ((g0 - gap) / (g0 - self.x[n - 2])).sqrt());
        }
        Ok(hermite(
            &self.x[k..k + 2],
            &self.h[k..k + 2],
            &self.dh[k..k + 2],
            gap,
        )
        .0)
    }

    /// h_c at mean contact pressure `pressure` (Pa, ≥ 0) on the law `p_of_g` (the law's
    /// p(g), non-increasing in g, whose samples are these separations): at the largest
    /// g with p(g) = `pressure` (module docs). 0 at p = 0; an error above the largest
    /// sampled pressure.
    pub fn at_pressure(
        &self,
        pressure: f64,
        p_of_g: impl Fn(f64) -> f64,
    ) -> Result<f64, CurveError> {
        if !(pressure.is_finite() && pressure >= 0.0) {
            return Err(CurveError::Invalid {
                value: pressure,
                what: "mean contact pressure ≥ 0 (Pa)",
            });
        }
        if pressure == 0.0 {
            return Ok(0.0);
        }
        let n = self.x.len();
        let p: Vec<f64> = self.x.iter().map(|&g| p_of_g(g)).collect();
        let max = p[0];
        if pressure > max {
            return Err(CurveError::AboveSampledPressure { pressure, max });
        }
        // the largest sample index k with p[k] ≥ pressure (p is non-increasing in k)
        let k = p.partition_point(|&v| v >= pressure) - 1;
        if p[k] == pressure || k == n - 1 {
            return Ok(self.h[k]);
        }
        // p(x[k]) > pressure > p(x[k+1]): bisection to adjacent floats
        let lo = bisect_adjacent(|g| p_of_g(g) >= pressure, self.x[k], self.x[k + 1]);
        self.at_gap(lo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One Hertz spot and a smooth curve: the √δ first interval is exact for
    /// h = c√δ; PCHIP reproduces the samples and stays monotone; the pressure inverse
    /// returns the samples exactly and h_c(g) between them.
    #[test]
    fn first_interval_sqrt_samples_and_inverse() {
        let g0 = 1e-5;
        let gaps: Vec<f64> = (0..9).map(|i| g0 - 1e-6 * i as f64).collect();
        let h: Vec<f64> = gaps.iter().map(|g| 3e4 * (g0 - g).sqrt()).collect();
        let c = ConductanceCurve::new(&gaps, &h).unwrap();
        for (g, hv) in gaps.iter().zip(&h) {
            assert_eq!(c.at_gap(*g).unwrap(), *hv);
        }
        let g = g0 - 0.3e-6;
        let exact = 3e4 * (g0 - g).sqrt();
        assert!((c.at_gap(g).unwrap() / exact - 1.0).abs() < 1e-14);
        assert_eq!(c.at_gap(g0 + 1e-7).unwrap(), 0.0);
        assert!(matches!(
            c.at_gap(g0 - 9e-6),
            Err(CurveError::BelowSampledRange { .. })
        ));
        // p = (g0 − g)^{3/2}·1e15: strictly monotone
        let p = |g: f64| {
            if g >= g0 {
                0.0
            } else {
                1e15 * (g0 - g).powf(1.5)
            }
        };
        for (g, hv) in gaps.iter().zip(&h) {
            assert_eq!(c.at_pressure(p(*g), p).unwrap(), *hv);
        }
        let gm = g0 - 4.4e-6;
        let back = c.at_pressure(p(gm), p).unwrap();
        assert!((back / c.at_gap(gm).unwrap() - 1.0).abs() < 1e-13, "{back}");
        assert!(matches!(
            c.at_pressure(p(gaps[8]) * 1.01, p),
            Err(CurveError::AboveSampledPressure { .. })
        ));
        assert!(c.at_pressure(-1.0, p).is_err());
        assert!(ConductanceCurve::new(&gaps[..2], &[0.0, f64::INFINITY]).is_none());
    }
}
