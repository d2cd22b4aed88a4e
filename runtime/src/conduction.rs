//! Steady conduction (thermal or electrical) through a layered body: the surface
//! conduction compliance S_th(ρ) (physics.md §6.2).
//!
//! A surface flux q into the body (W/m², or A/m² for current) raises the surface
//! temperature (potential) by, in Hankel (or Fourier) space,
//!
//! ```text
//!   T̂(ρ) = C_th(ρ) q̂(ρ),   C_th(ρ) = S_th(ρ) / (k₁ ρ),   S_th(∞) = 1,   k_th = S_th − 1,
//! ```
//!
//! with k₁ the top material's conductivity (W/(m·K), or S/m) and ρ in 1/m: S_th is the
//! compliance normalised by that of a half-space of the top material, the counterpart
//! of the elastic S(ρ) of [`crate::compliance`]. Electrical conduction is the same with
//! σ for k ([`ConductionKind`]).
//!
//! # Method: impedance recursion from the base up (bounded)
//! In layer i (conductivity kᵢ, thickness hᵢ, t = tanh(ρhᵢ)) the surface impedance
//! normalised by the layer's own 1/(kᵢρ) obeys
//!
//! ```text
//!   ζ_top,i = (ζ_bot,i + t)/(1 + ζ_bot,i t),   ζ_bot,i = ζ_top,i+1 · kᵢ/kᵢ₊₁,
//!   ζ_bot,N = k_N/k_b (conducting half-space base),  0 (isothermal sink),   S_th = ζ_top,1.
//! ```
//!
//! Every quantity is bounded (t ∈ [0, 1], ζ between its bottom value and 1), so there is
//! no overflow at any ρh. The recursion carries d = ζ − 1 rather than ζ,
//! d_top = d_bot (1 − t)/(1 + ζ_bot t) with 1 − t = 2e^{−2ρh}/(1 + e^{−2ρh}) computed
//! without cancellation, so k_th = d keeps its relative accuracy where it is small
//! (ρh ≫ 1) and identical layers give k_th = 0 exactly.
//!
//! Limits (checks of physics.md §6.2): S_th(0) = k₁/k_b on a half-space base; on an
//! isothermal sink S_th(ρ) → ρ k₁ Σ hᵢ/kᵢ → 0 as ρ → 0. One layer on a half-space:
//! S_th = (k₁ + k_b t)/(k_b + k₁ t); one layer on a sink: S_th = t.

use thiserror::Error;

use crate::stack::{BaseConduction, Location, Stack};

/// Which conduction problem: selects the conductivity read from the stack.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ConductionKind {
    /// Heat: `thermal_conductivity` k (W/(m·K)); conductance in W/K.
    Thermal,
    /// Current: `electrical_conductivity` σ (S/m); conductance in S.
    Electrical,
}

impl ConductionKind {
    /// The stack-file field of the conductivity (`thermal_conductivity` or
    /// `electrical_conductivity`).
    pub fn field(self) -> &'static str {
        match self {
            ConductionKind::Thermal => "thermal_conductivity",
            ConductionKind::Electrical => "electrical_conductivity",
        }
    }

    /// "thermal" or "electrical".
    pub fn name(self) -> &'static str {
        match self {
            ConductionKind::Thermal => "thermal",
            ConductionKind::Electrical => "electrical",
        }
    }

    /// Unit of the conductivity.
    pub fn conductivity_unit(self) -> &'static str {
        match self {
            ConductionKind::Thermal => "W/(m·K)",
            ConductionKind::Electrical => "S/m",
        }
    }

    /// Unit of a conductance.
    pub fn conductance_unit(self) -> &'static str {
        match self {
            ConductionKind::Thermal => "W/K",
            ConductionKind::Electrical => "S",
        }
    }

    /// Unit of an interface conductance per nominal area h_c (ASCII, as written to
    /// JSON and FE decks).
    pub fn interface_conductance_unit(self) -> &'static str {
        match self {
            ConductionKind::Thermal => "W/(m^2 K)",
            ConductionKind::Electrical => "S/m^2",
        }
    }
}

/// Errors of the conduction set-up: each names the missing property and where.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ConductionError {
    /// A layer or the (half-space) base lacks the conductivity the problem needs.
    #[error("{location}: missing `{field}` ({})", missing_hint(*.location, .kind))]
    Missing {
        location: Location,
        field: &'static str,
        kind: &'static str,
    },
}

fn missing_hint(location: Location, kind: &str) -> String {
    match location {
        Location::Base => format!(
            "{kind} conduction through a half-space base needs it; or set [base] conduction = \"isothermal\""
        ),
        _ => format!("{kind} conduction needs it on every layer"),
    }
}

/// The conduction compliance of one stack for one [`ConductionKind`], precomputed for
/// fast repeated evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct ConductionCompliance {
    kind: ConductionKind,
    /// (hᵢ, kᵢ/kᵢ₊₁) per layer, top first; for the last layer the ratio is k_N/k_b on
    /// a half-space base and unused on a sink.
    layers: Vec<(f64, f64)>,
    /// True for an isothermal sink under the last layer.
    isothermal: bool,
    /// k₁ (the top material's conductivity).
    k1: f64,
    /// S_th(0).
    s0: f64,
    /// Σ hᵢ/kᵢ (per unit area: the layers' 1-D resistance).
    series: f64,
    /// Largest over smallest conductivity (layers and a half-space base), ≥ 1.
    contrast: f64,
}

impl ConductionCompliance {
    /// Reads the conductivities of `kind` from `stack`. Every layer needs one, and so
    /// does the base unless it is an isothermal sink; the first missing one is named.
    pub fn new(stack: &Stack, kind: ConductionKind) -> Result<Self, ConductionError> {
        let pick = |c: crate::stack::Conductivity| match kind {
            ConductionKind::Thermal => c.thermal,
            ConductionKind::Electrical => c.electrical,
        };
        let missing = |location| ConductionError::Missing {
            location,
            field: kind.field(),
            kind: kind.name(),
        };
        let n = stack.layers().len();
        let mut k = Vec::with_capacity(n);
        for i in 0..n {
            k.push(pick(stack.layer_conductivity(i)).ok_or(missing(Location::Layer(i + 1)))?);
        }
        let cond = stack.conduction();
        let isothermal = cond.base_kind == BaseConduction::Isothermal;
        let kb = if isothermal {
            f64::NAN
        } else {
            pick(cond.base).ok_or(missing(Location::Base))?
        };
        let layers: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let below = if i + 1 < n { k[i + 1] } else { kb };
                (stack.layers()[i].thickness, k[i] / below)
            })
            .collect();
        let k1 = k.first().copied().unwrap_or(kb);
        let s0 = if isothermal { 0.0 } else { k1 / kb };
        let series = stack
            .layers()
            .iter()
            .zip(&k)
            .map(|(l, k)| l.thickness / k)
            .sum();
        let all = k.iter().copied().chain((!isothermal).then_some(kb));
        let (lo, hi) = all.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        Ok(ConductionCompliance {
            kind,
            layers,
            isothermal,
            k1,
            s0,
            series,
            contrast: hi / lo,
        })
    }

    /// The problem's kind.
    pub fn kind(&self) -> ConductionKind {
        self.kind
    }

    /// k₁: the conductivity of the surface material (W/(m·K) or S/m).
    pub fn top_conductivity(&self) -> f64 {
        self.k1
    }

    /// True for an isothermal (equipotential) sink under the last layer.
    pub fn is_isothermal(&self) -> bool {
        self.isothermal
    }

    /// True when S_th ≡ 1: a conducting half-space base and every layer of its
    /// conductivity (or no layer).
    pub fn is_homogeneous(&self) -> bool {
        !self.isothermal && self.layers.iter().all(|&(_, r)| r == 1.0)
    }

    /// S_th(0): k₁/k_b on a half-space base, 0 on an isothermal sink.
    pub fn s_at_zero(&self) -> f64 {
        self.s0
    }

    /// h₁: the top layer's thickness (m); `None` without layers.
    pub fn top_thickness(&self) -> Option<f64> {
        self.layers.first().map(|&(h, _)| h)
    }

    /// Σ hᵢ: the layers' total thickness (m), 0 without layers.
    pub fn total_thickness(&self) -> f64 {
        self.layers.iter().map(|&(h, _)| h).sum()
    }

    /// Σ hᵢ/kᵢ: the layers' 1-D resistance per unit area (m²·K/W, or m²·Ω).
    pub fn series_resistance(&self) -> f64 {
        self.series
    }

    /// (ζ_top,1, ζ_top,1 − 1) by the two forms of the recursion (module docs): ζ from
    /// its own form (positive terms only: accurate where S_th is small, as on a sink at
    /// small ρh), d = ζ − 1 from its form (accurate where k_th is small, ρh ≫ 1).
    fn recursion(&self, rho: f64) -> (f64, f64) {
        let n = self.layers.len();
        if n == 0 {
            return (1.0, 0.0);
        }
        let (mut z, mut d) = if self.isothermal {
            (0.0, -1.0)
        } else {
            let r = self.layers[n - 1].1;
            (r, r - 1.0)
        };
        for i in (0..n).rev() {
            let (h, r) = self.layers[i];
            if i + 1 < n {
                // Across the interface below layer i: ζ_bot,i = ζ_top,i+1 · kᵢ/kᵢ₊₁.
                z *= r;
                d = d * r + (r - 1.0);
            }
            let x = rho * h;
            let e = (-2.0 * x).exp();
            // tanh and 1 − tanh from one exponential, both without cancellation.
            let t = -(-2.0 * x).exp_m1() / (1.0 + e);
            let one_minus_t = 2.0 * e / (1.0 + e);
            let den = 1.0 + z * t;
            d = d * one_minus_t / den;
            z = (z + t) / den;
        }
        (z, d)
    }

    /// A fingerprint of what ψ and S_th depend on (FNV-1a 64 of the layers' thicknesses
    /// and conductivity ratios, bit for bit, and the base's conduction): two stacks with
    /// the same fingerprint have the same spot conductance factor ψ(a)
    /// ([`crate::constriction`]) whatever their k₁ and kind of conduction.
    pub fn fingerprint(&self) -> u64 {
        let mut h = crate::hash::Fnv1a::default();
        h.part(b"strata conduction stack v1")
            .part(&[u8::from(self.isothermal)]);
        for &(t, r) in &self.layers {
            h.update(&t.to_le_bytes());
            // the last layer's ratio is unused (NaN) on a sink
            let r = if r.is_nan() { 0.0 } else { r };
            h.part(&r.to_le_bytes());
        }
        h.finish()
    }

    /// The conductivity contrast: largest over smallest conductivity of the layers and
    /// (unless isothermal) the base, ≥ 1.
    pub fn contrast(&self) -> f64 {
        self.contrast
    }

    /// k_th(ρ) = S_th(ρ) − 1 at wavenumber ρ ≥ 0 (1/m), by the bounded recursion of the
    /// module docs (accurate also where it is small). At ρ = 0 it is S_th(0) − 1.
    pub fn k_th(&self, rho: f64) -> f64 {
        self.recursion(rho).1
    }

    /// S_th(ρ) = 1 + k_th(ρ) (dimensionless), ρ ≥ 0 in 1/m, accurate also where it is
    /// small (an isothermal sink at small ρ).
    pub fn s(&self, rho: f64) -> f64 {
        self.recursion(rho).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stack::{Base, Conductivity, Layer};

    fn thermal(k: f64) -> Conductivity {
        Conductivity::thermal(k)
    }

    fn stack(layers: &[(f64, f64)], base: Option<f64>) -> Stack {
        let ls = layers
            .iter()
            .map(|&(h, _)| Layer {
                thickness: h,
                young: 1e9,
                poisson: 0.3,
            })
            .collect();
        let st = Stack::new(ls, Base::Rigid).unwrap();
        let cs = layers.iter().map(|&(_, k)| thermal(k)).collect();
        match base {
            Some(kb) => st.with_conduction(cs, thermal(kb), BaseConduction::HalfSpace),
            None => st.with_conduction(cs, Conductivity::default(), BaseConduction::Isothermal),
        }
        .unwrap()
    }

    fn comp(layers: &[(f64, f64)], base: Option<f64>) -> ConductionCompliance {
        ConductionCompliance::new(&stack(layers, base), ConductionKind::Thermal).unwrap()
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    const RHO_H: [f64; 9] = [0.0, 1e-6, 1e-3, 0.1, 1.0, 3.0, 30.0, 700.0, 1e4];

    /// One layer on a half-space: S_th = (k₁ + k_b t)/(k_b + k₁ t), t = tanh ρh.
    #[test]
    fn one_layer_on_half_space_closed_form() {
        let h = 1e-4;
        for (k1, kb) in [
            (1.0, 50.0),
            (400.0, 0.2),
            (1.0, 1e4),
            (1e4, 1.0),
            (3.0, 3.0),
        ] {
            let c = comp(&[(h, k1)], Some(kb));
            for x in RHO_H {
                let t = x.tanh();
                let exact = (k1 + kb * t) / (kb + k1 * t);
                let s = c.s(x / h);
                assert!(rel(s, exact) < 1e-14, "{k1}/{kb} rho_h {x}: {s} vs {exact}");
            }
            assert_eq!(c.s_at_zero(), k1 / kb);
            assert_eq!(c.s(0.0), k1 / kb);
        }
    }

    /// One layer on an isothermal sink: S_th = tanh ρh; S_th → ρ k₁ Σh/k as ρ → 0.
    #[test]
    fn one_layer_on_sink_is_tanh() {
        let h = 2e-5;
        let c = comp(&[(h, 7.0)], None);
        for x in RHO_H {
            let s = c.s(x / h);
            assert!(
                (s - x.tanh()).abs() <= 1e-15 * x.tanh().max(1e-300),
                "{x}: {s}"
            );
        }
        assert_eq!(c.s_at_zero(), 0.0);
        assert!(c.is_isothermal());
        // Large ρh: k_th = tanh − 1 = −2e^{−2x}/(1+e^{−2x}) with full relative accuracy.
        let x: f64 = 20.0;
        let exact = -2.0 * (-2.0 * x).exp() / (1.0 + (-2.0 * x).exp());
        assert!(rel(c.k_th(x / h), exact) < 1e-14);
        // Three layers on a sink: small-ρ slope k₁ Σ hᵢ/kᵢ.
        let c = comp(&[(1e-5, 2.0), (3e-5, 0.5), (1e-4, 40.0)], None);
        let rho = 1e-3;
        let slope = 2.0 * (1e-5 / 2.0 + 3e-5 / 0.5 + 1e-4 / 40.0);
        assert!(
            rel(c.s(rho) / rho, slope) < 1e-9,
            "{} vs {slope}",
            c.s(rho) / rho
        );
        assert!(rel(c.series_resistance(), slope / 2.0) < 1e-15);
    }

    /// Identical layers on an identical half-space: S_th = 1 (k_th = 0 exactly).
    #[test]
    fn identical_layers_are_a_half_space() {
        let layers: Vec<(f64, f64)> = (0..50).map(|i| (1e-6 * (1 + i % 7) as f64, 13.0)).collect();
        let c = comp(&layers, Some(13.0));
        assert!(c.is_homogeneous());
        for x in RHO_H {
            assert!((c.s(x / 1e-6) - 1.0).abs() <= 1e-15, "{x}");
        }
    }

    /// ρ → 0 on a half-space: S_th → k₁/k_b, continuously; ρ → ∞: S_th → 1.
    #[test]
    fn limits() {
        let c = comp(&[(1e-5, 2.0), (3e-5, 0.5)], Some(40.0));
        assert_eq!(c.s_at_zero(), 0.05);
        // S_th − S_th(0) is linear in ρ near 0.
        let (d1, d2) = (c.s(1e-2) - 0.05, c.s(1e-3) - 0.05);
        assert!((d1 / d2 - 10.0).abs() < 1e-3, "{d1} {d2}");
        assert!(d2.abs() < 1e-6, "{d2}");
        assert!((c.s(1e12) - 1.0).abs() < 1e-15);
        assert_eq!(c.k_th(f64::INFINITY), 0.0);
    }

    /// 200 layers, ρh to 1e4, conductivity ratios 1e-4 … 1e4: finite, bounded by the
    /// extreme ratios, continuous in ρ. Two layers of the same conductivity equal one
    /// layer of their total thickness.
    #[test]
    fn hard_cases_are_finite() {
        let layers: Vec<(f64, f64)> = (0..200)
            .map(|i| (1e-6, if i % 2 == 0 { 1e-2 } else { 1e2 }))
            .collect();
        for base in [Some(1.0), None] {
            let c = comp(&layers, base);
            let mut prev = c.s(0.0);
            for i in 0..=400 {
                let x = 10f64.powf(-8.0 + 12.0 * i as f64 / 400.0);
                let s = c.s(x / 1e-6);
                assert!((0.0..=1e4 + 1e-9).contains(&s), "{x}: {s}");
                // Continuity: neighbouring ρ (log step 0.03) never jump by 2×... unless
                // at the sink's linear start.
                if base.is_some() {
                    assert!(s / prev < 2.0 && prev / s < 2.0, "{x}: {prev} -> {s}");
                }
                prev = s;
            }
        }
        for (k1, kb) in [(1e-4, 1.0), (1e4, 1.0), (1.0, 1e-4), (1.0, 1e4)] {
            for base in [Some(kb), None] {
                let c = comp(&[(1e-4, k1), (1e-4, kb)], base);
                for x in [0.0, 1e-12, 1e-4, 1.0, 1e4, 1e8] {
                    let s = c.s(x / 1e-4);
                    assert!(s.is_finite() && s >= 0.0, "{k1} {kb} {base:?} {x}: {s}");
                }
            }
        }
        let one = comp(&[(3e-5, 5.0)], Some(2.0));
        let two = comp(&[(1e-5, 5.0), (2e-5, 5.0)], Some(2.0));
        for x in RHO_H {
            assert!((one.s(x / 1e-5) - two.s(x / 1e-5)).abs() < 1e-14, "{x}");
        }
    }

    /// Missing conductivities are named: which layer or the base, which property.
    #[test]
    fn missing_properties_are_named() {
        let st = stack(&[(1e-5, 5.0)], Some(2.0));
        let e = ConductionCompliance::new(&st, ConductionKind::Electrical).unwrap_err();
        let m = e.to_string();
        assert!(
            m.starts_with("layer 1: missing `electrical_conductivity`"),
            "{m}"
        );
        let st = Stack::paper_two_layer(5.0)
            .unwrap()
            .with_conduction(
                vec![thermal(1.0), Conductivity::default()],
                Conductivity::default(),
                BaseConduction::HalfSpace,
            )
            .unwrap();
        let m = ConductionCompliance::new(&st, ConductionKind::Thermal)
            .unwrap_err()
            .to_string();
        assert!(
            m.starts_with("layer 2: missing `thermal_conductivity`"),
            "{m}"
        );
        let st = Stack::half_space(1e9, 0.3).unwrap();
        let m = ConductionCompliance::new(&st, ConductionKind::Thermal)
            .unwrap_err()
            .to_string();
        assert!(m.starts_with("base: missing `thermal_conductivity`"), "{m}");
        // A half-space with its conductivity: S_th ≡ 1.
        let st = st
            .with_conduction(vec![], thermal(3.0), BaseConduction::HalfSpace)
            .unwrap();
        let c = ConductionCompliance::new(&st, ConductionKind::Thermal).unwrap();
        assert!(c.is_homogeneous() && c.s(1.0) == 1.0 && c.top_conductivity() == 3.0);
    }
}
