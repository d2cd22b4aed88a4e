//! The friction card of a sampled law with `[friction]` (N and I models): what `strata
//! law` writes after the pressure-overclosure table for CalculiX and Abaqus.
//!
//! - CalculiX `*FRICTION`, data line `μ, λ`: the Coulomb coefficient μ and the stick
//!   slope λ (Pa/m = N/m³: tangential traction per relative tangential displacement
//!   while sticking), one constant,
//!
//!   ```text
//!     λ = K_t(p_d)/A₀
//!   ```
//!
//!   with K_t the sample's full-stick tangential stiffness (N/m, the `tangential_stiffness`
//!   column), A₀ the nominal area (m²) and p_d the design pressure (Pa) the user names.
//!   CalculiX 2.20 refuses λ ≤ 0: no such card is written.
//! - Abaqus `*FRICTION, ELASTIC SLIP=γ`, data line `μ`: Abaqus sticks with the stiffness
//!   μp/γ (Pa/m) at contact pressure p, so the card matches K_t/A₀ at p_d with
//!
//!   ```text
//!     γ(p) = μ p A₀/K_t(p)   (m), written at p = p_d,
//!   ```
//!
//!   and follows K_t over the whole path only where γ(p) is nearly constant: its spread
//!   (max − min)/γ(p_d) over the samples with p ≥ 1 % of the largest is stated, with a
//!   note when it exceeds 10 %.
//!
//! Every number is at most 20 characters ([`abaqus_real`]).

use crate::error::{EngineError, Result, bail_input};
use crate::sampled_law::SampledLaw;
use strata_runtime::interface::abaqus_real;

/// The spread of γ over the path above which the card says it is not nearly constant.
pub const GAMMA_SPREAD_NOTE: f64 = 0.10;

/// The samples that set the ranges: p at least this fraction of the largest pressure
/// (next to first contact K_t → 0 and p/K_t → 0 with the contact radii).
pub const RANGE_FROM: f64 = 0.01;

/// Which card is active in the `.inp` (the other is written as `**` comment lines).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeCode {
    /// CalculiX: `*FRICTION` with `μ, λ`.
    Calculix,
    /// Abaqus: `*FRICTION, ELASTIC SLIP=γ` with `μ`.
    Abaqus,
}

/// The friction card's values.
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionCard {
    /// Coulomb coefficient μ (1).
    pub coefficient: f64,
    /// Design pressure p_d (Pa).
    pub design_pressure: f64,
    /// K_t at p_d (N/m over the nominal area).
    pub tangential_stiffness: f64,
    /// Nominal area A₀ (m²).
    pub nominal_area: f64,
    /// Stick slope λ = K_t(p_d)/A₀ (Pa/m).
    pub stick_slope: f64,
    /// λ's smallest and largest value over the samples with p ≥ [`RANGE_FROM`] p_max,
    /// each with its pressure: ((λ, p), (λ, p)).
    pub stick_slope_range: ((f64, f64), (f64, f64)),
    /// Elastic slip γ = μ p_d A₀/K_t(p_d) (m).
    pub elastic_slip: f64,
    /// γ's smallest and largest value over the same samples (m).
    pub elastic_slip_range: (f64, f64),
    /// (max − min)/γ(p_d) over them.
    pub elastic_slip_spread: f64,
    /// The law's largest pressure p_max (Pa).
    pub max_pressure: f64,
}

impl FrictionCard {
    /// The card of `law` (which must carry `tangential_stiffness`) with coefficient
    /// `mu` at design pressure `design_pressure` (Pa; `None`: the law's largest pressure,
    /// that of the deepest sample). An input error names `--design-pressure` when p_d is
    /// not inside (0, p_max], and says why when λ ≤ 0 (CalculiX refuses it).
    pub fn new(law: &SampledLaw, mu: f64, design_pressure: Option<f64>) -> Result<Self> {
        let Some(kt) = &law.tangential_stiffness else {
            bail_input!("the friction card needs the law's tangential stiffness: add [friction]");
        };
        if !(mu.is_finite() && mu > 0.0) {
            bail_input!("friction.coefficient {mu}: CalculiX needs a coefficient > 0");
        }
        let a0 = law.nominal_area;
        let samples: Vec<(f64, f64)> = law
            .law
            .samples()
            .zip(kt)
            .map(|((_, p, _, _), &k)| (p, k))
            .collect();
        let p_max = samples.iter().map(|s| s.0).fold(0.0_f64, f64::max);
        let pd = design_pressure.unwrap_or(p_max);
        if !(pd.is_finite() && pd > 0.0 && pd <= p_max) {
            bail_input!(
                "--design-pressure {pd:e}: must lie inside the law's pressures, 0 < p <= {p_max:e} Pa \
                 (sample deeper with --min-gap for a larger one)"
            );
        }
        let k = law
            .contact_law()
            .and_then(|c| c.tangential_stiffness_at_pressure(pd))
            .map_err(|e| EngineError::at("friction card", e))?;
        let lambda = k / a0;
        if !(lambda.is_finite() && lambda > 0.0) {
            bail_input!(
                "--design-pressure {pd:e}: the stick slope lambda = K_t/A0 = {lambda:e} Pa/m there is not > 0 \
                 (no contact spot sticks): CalculiX refuses a *FRICTION stick slope <= 0, so no card is written"
            );
        }
        let gamma = mu * pd / lambda;
        let used: Vec<(f64, f64)> = samples
            .iter()
            .copied()
            .filter(|&(p, k)| p >= RANGE_FROM * p_max && k > 0.0)
            .collect();
        let mut lo = (lambda, pd);
        let mut hi = (lambda, pd);
        let (mut g_lo, mut g_hi) = (gamma, gamma);
        for &(p, k) in &used {
            let l = k / a0;
            if l < lo.0 {
                lo = (l, p);
            }
            if l > hi.0 {
                hi = (l, p);
            }
            let g = mu * p / l;
            g_lo = g_lo.min(g);
            g_hi = g_hi.max(g);
        }
        Ok(FrictionCard {
            coefficient: mu,
            design_pressure: pd,
            tangential_stiffness: k,
            nominal_area: a0,
            stick_slope: lambda,
            stick_slope_range: (lo, hi),
            elastic_slip: gamma,
            elastic_slip_range: (g_lo, g_hi),
            elastic_slip_spread: (g_hi - g_lo) / gamma,
            max_pressure: p_max,
        })
    }

    /// Whether γ is nearly constant over the path (spread ≤ [`GAMMA_SPREAD_NOTE`]).
    pub fn elastic_slip_nearly_constant(&self) -> bool {
        self.elastic_slip_spread <= GAMMA_SPREAD_NOTE
    }

    /// The `*FRICTION` block with its `**` comments: `code`'s card active, the other's
    /// lines commented out.
    pub fn block(&self, code: FeCode) -> String {
        let r = abaqus_real;
        let ((l_lo, p_lo), (l_hi, p_hi)) = self.stick_slope_range;
        let calculix = format!(
            "*FRICTION\n{}, {}\n",
            r(self.coefficient),
            r(self.stick_slope)
        );
        let abaqus = format!(
            "*FRICTION, ELASTIC SLIP={}\n{}\n",
            r(self.elastic_slip),
            r(self.coefficient)
        );
        let commented = |s: &str| s.lines().map(|l| format!("** {l}\n")).collect::<String>();
        let (active, other, other_name) = match code {
            FeCode::Calculix => (calculix, commented(&abaqus), "Abaqus"),
            FeCode::Abaqus => (abaqus, commented(&calculix), "CalculiX"),
        };
        let constant = if self.elastic_slip_nearly_constant() {
            format!(
                "**   gamma(p) varies by {:.1} % over the path (p >= {} % of p_max): nearly constant, so\n\
                 **   Abaqus' stick stiffness mu p/gamma follows K_t/A0 over the whole path.\n",
                100.0 * self.elastic_slip_spread,
                100.0 * RANGE_FROM
            )
        } else {
            format!(
                "** NOTE: gamma(p) = mu p A0/K_t(p) is NOT nearly constant: it varies by {:.1} % over the\n\
                 **   path (from {} to {} m for p >= {} % of p_max): Abaqus' stick stiffness mu p/gamma\n\
                 **   equals K_t/A0 at the design pressure only.\n",
                100.0 * self.elastic_slip_spread,
                r(self.elastic_slip_range.0),
                r(self.elastic_slip_range.1),
                100.0 * RANGE_FROM
            )
        };
        format!(
            "** strata law: friction card of the rough interface (full-stick tangential stiffness).\n\
             ** mu = {mu} (the scene's [friction] coefficient); design pressure p_d = {pd} Pa\n\
             **   (strata law --design-pressure; p_max of the table = {pmax} Pa);\n\
             **   K_t(p_d) = {kt} N/m over the nominal area A0 = {a0} m2.\n\
             ** CalculiX: *FRICTION data line mu, lambda with the stick slope\n\
             **   lambda = K_t(p_d)/A0 = {lambda} Pa/m (N/m3), one constant at every pressure.\n\
             **   Over the load path (p >= {from} % of p_max) K_t/A0 ranges from {l_lo} Pa/m\n\
             **   (at p = {p_lo} Pa) to {l_hi} Pa/m (at p = {p_hi} Pa).\n\
             ** Abaqus: *FRICTION, ELASTIC SLIP=gamma, data line mu: stick stiffness mu p/gamma;\n\
             **   gamma = mu p_d A0/K_t(p_d) = {gamma} m matches K_t/A0 at p_d.\n\
             {constant}\
             ** Active below: the {active_name} card; the {other_name} card is commented out under it.\n\
             {active}\
             ** {other_name}:\n\
             {other}",
            mu = r(self.coefficient),
            pd = r(self.design_pressure),
            pmax = r(self.max_pressure),
            kt = r(self.tangential_stiffness),
            a0 = r(self.nominal_area),
            lambda = r(self.stick_slope),
            from = 100.0 * RANGE_FROM,
            l_lo = r(l_lo),
            p_lo = r(p_lo),
            l_hi = r(l_hi),
            p_hi = r(p_hi),
            gamma = r(self.elastic_slip),
            active_name = match code {
                FeCode::Calculix => "CalculiX",
                FeCode::Abaqus => "Abaqus",
            },
        )
    }

    /// One log line: λ, its range, γ and its spread.
    pub fn summary(&self) -> String {
        let ((l_lo, _), (l_hi, _)) = self.stick_slope_range;
        format!(
            "friction card: mu = {}, design pressure {:e} Pa: stick slope lambda = K_t/A0 = {:e} Pa/m \
             (from {:e} to {:e} over the path), elastic slip gamma = {:e} m, spread {:.1} % over the path ({})",
            self.coefficient,
            self.design_pressure,
            self.stick_slope,
            l_lo,
            l_hi,
            self.elastic_slip,
            100.0 * self.elastic_slip_spread,
            if self.elastic_slip_nearly_constant() {
                "nearly constant"
            } else {
                "NOT nearly constant: Abaqus' stick stiffness is K_t/A0 at the design pressure only"
            }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solution::SurfaceReport;
    use strata_runtime::interface::InterfaceLaw;
    use strata_runtime::interface::abaqus::read_f20;
    use strata_runtime::surface::Surface;

    /// A law whose K_t ∝ p^`exp` (p = 1e5 i² Pa, K_t = 1e6 (p/1e5)^exp N/m, A₀ = 1e-6 m²).
    fn law(exp: f64) -> SampledLaw {
        let n = 20;
        let gaps: Vec<f64> = (0..n).map(|i| 1e-6 * (n - i) as f64).collect();
        let p: Vec<f64> = (0..n).map(|i| 1e5 * (i * i) as f64).collect();
        let dp: Vec<f64> = (0..n).map(|i| 1e11 * (2 * i) as f64).collect();
        let a: Vec<f64> = (0..n).map(|i| i as f64 / n as f64).collect();
        let kt: Vec<f64> = p.iter().map(|p| 1e6 * (p / 1e5).powf(exp)).collect();
        SampledLaw {
            law: InterfaceLaw::from_samples(&gaps, &p, &dp, &a).unwrap(),
            model: "test".into(),
            solid: "test".into(),
            e_star: 1e9,
            nominal_area: 1e-6,
            surface: SurfaceReport::of(
                &Surface::new(
                    vec![0.0, 1e-6, 2e-6, 0.0, 1e-6, 0.0, 2e-6, 0.0, 1e-6],
                    3,
                    3,
                    1e-3,
                    true,
                )
                .unwrap(),
            ),
            warnings: Vec::new(),
            conductance: None,
            tangential_stiffness: Some(kt),
            unloading: None,
        }
    }

    /// K_t ∝ p: γ constant, λ and γ at a sample's pressure its own; the card's fields
    /// read back (20 characters) to those values; the Abaqus card commented out.
    #[test]
    fn fecard_linear_kt_gives_constant_gamma() {
        let s = law(1.0);
        let c = FrictionCard::new(&s, 0.3, Some(1e5 * 49.0)).unwrap();
        assert!((c.stick_slope - 49e6 / 1e-6).abs() <= 1e-12 * c.stick_slope);
        // γ = μ p A0/K_t = 0.3 · 1e5 · 1e-6/1e6 = 3e-8 m at every sample
        assert!(
            (c.elastic_slip - 3e-8).abs() <= 1e-12 * 3e-8,
            "{}",
            c.elastic_slip
        );
        assert!(c.elastic_slip_spread <= 1e-12 && c.elastic_slip_nearly_constant());
        let b = c.block(FeCode::Calculix);
        let data = b
            .split_once("*FRICTION\n")
            .unwrap()
            .1
            .lines()
            .next()
            .unwrap();
        let f: Vec<&str> = data.split(',').collect();
        assert!(f.iter().all(|x| x.trim().len() <= 20), "{data}");
        assert_eq!(read_f20(f[0].trim()), Some(0.3));
        let l = read_f20(f[1].trim()).unwrap();
        assert!((l / c.stick_slope - 1.0).abs() <= 1e-13);
        assert!(b.contains("** *FRICTION, ELASTIC SLIP=") && !b.contains("NOT nearly"));
        let a = c.block(FeCode::Abaqus);
        assert!(a.contains("\n*FRICTION, ELASTIC SLIP=") && a.contains("** *FRICTION\n"));
        // the default design pressure is the deepest sample's
        let d = FrictionCard::new(&s, 0.3, None).unwrap();
        assert_eq!(d.design_pressure, 1e5 * 361.0);
    }

    /// K_t ∝ √p: γ ∝ √p varies over the path; the card says so, with its spread.
    #[test]
    fn fecard_says_when_gamma_is_not_constant() {
        let s = law(0.5);
        let c = FrictionCard::new(&s, 0.5, None).unwrap();
        // γ ∝ √p from p = 4e5 (the first at ≥ 1 % of 3.61e7) to 3.61e7: (19 − 2)/19
        assert!(
            (c.elastic_slip_spread - 17.0 / 19.0).abs() <= 1e-12,
            "{}",
            c.elastic_slip_spread
        );
        let b = c.block(FeCode::Calculix);
        assert!(
            b.contains("NOT nearly constant") && b.contains("89.5 %"),
            "{b}"
        );
        assert!(c.summary().contains("NOT nearly constant"));
    }

    /// λ ≤ 0 (no contact at the design pressure) and p_d outside the table are refused
    /// with the reason.
    #[test]
    fn fecard_refuses_zero_slope_and_pressures_outside_the_table() {
        let mut s = law(1.0);
        let e = FrictionCard::new(&s, 0.3, Some(1e9))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--design-pressure") && e.contains("3.61e7"),
            "{e}"
        );
        let e = FrictionCard::new(&s, 0.3, Some(0.0))
            .unwrap_err()
            .to_string();
        assert!(e.contains("--design-pressure"), "{e}");
        s.tangential_stiffness = Some(vec![0.0; 20]);
        let e = FrictionCard::new(&s, 0.3, None).unwrap_err().to_string();
        assert!(e.contains("CalculiX refuses") && e.contains("<= 0"), "{e}");
        s.tangential_stiffness = None;
        assert!(FrictionCard::new(&s, 0.3, None).is_err());
    }
}
