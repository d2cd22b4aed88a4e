//! The kernel of the axisymmetric Fredholm equation (physics.md §3, paper eq. P9).
//!
//! ```text
//!   K_a(s,t) = (2/π) ∫₀^∞ k_z(ρ/a) cos(ρs) cos(ρt) dρ = ½ [κ_a(s−t) + κ_a(s+t)],
//!   κ_a(x)   = (2/π) ∫₀^∞ k_z(ρ/a) cos(ρx) dρ = (2a/π) ∫₀^∞ k_z(u) cos(a u x) du,
//! ```
//!
//! with s = r/a, t = x/a dimensionless and u = ρ/a in 1/m. Everything here is built on
//! one fixed quadrature rule in u ([`KzQuadrature`]): k_z is evaluated once per node and
//! reused for every s, t and x (k_z costs ~1 µs per layer and call).
//!
//! # The u-quadrature
//! Composite Gauss–Legendre (16 nodes per panel). Panels are graded geometrically from
//! u = 0.25/H (H the total layer depth, where k_z has its features near u = 0 and its
//! |u| kink) up to the top-layer scale, then uniform. Every panel is at most 1/h₁ long
//! (k_z varies like e^{−2u h₁}) and at most [`PANEL_PHASE`]/x_max long, so that
//! cos(u·x) for |x| ≤ x_max (m) turns by at most one period per panel: 16-point
//! Gauss–Legendre then integrates the oscillation to round-off. The rule stops at
//! u_max = (25 + ½ ln(1 + |k_z(0)|))/h₁, where |k_z| ≲ (u h₁)² e^{−2u h₁}·|k_z(0)| < 1e−18.

use std::f64::consts::PI;

use rayon::prelude::*;
use strata_runtime::{Compliance, Solid};
use thiserror::Error;

/// Largest phase (radians) of cos(u·x_max) across one 16-node panel.
pub const PANEL_PHASE: f64 = 6.0;
/// Gauss–Legendre nodes per panel.
pub const PANEL_NODES: usize = 16;
/// u_max·h₁ before the correction for a large |k_z(0)|.
pub const TAIL: f64 = 25.0;

/// Errors while building the kernel.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum KernelError {
    /// The stack has no layer: a half-space has k_z ≡ 0 and needs no kernel.
    #[error("the stack has no layers: a homogeneous half-space needs no kernel")]
    NoLayers,
    /// x_max (the largest |x| in cos(u x)) must be positive and finite.
    #[error("kernel: x_max must be positive and finite, got {0}")]
    BadRange(f64),
    /// k_z came out non-finite at some u.
    #[error("k_z(u) is not finite at u = {u} 1/m")]
    NonFinite { u: f64 },
    /// The rule would need more than [`MAX_RULE_PANELS`] panels (x_max ≫ h₁).
    #[error(
        "kernel: x_max/h1 = {ratio:e} is too large (the contact radius is far beyond the \
         top layer's thickness; the quadrature would need {panels:e} panels)"
    )]
    TooWide { ratio: f64, panels: f64 },
}

/// Largest number of panels of a [`KzQuadrature`] (about a/h₁ ≤ 3e4; a/h₁ = 1e3 needs
/// ~1e4). Beyond it the rule's memory would grow without bound (found by fuzzing:
/// a vanishing approach drove the root find to a/h₁ ~ 1e20 and 15 GB).
pub const MAX_RULE_PANELS: f64 = 262_144.0;

/// Gauss–Legendre nodes and weights on [−1, 1]: the runtime's one rule, re-exported
/// under its former path.
pub use strata_runtime::numerics::gauss_legendre;

/// A quadrature rule for ∫₀^∞ f(u) du over the support of k_z, with k_z at its nodes
/// (or of any other kernel function k(u) of the same form: [`KzQuadrature::for_kernel`];
/// the fields then hold k).
#[derive(Debug, Clone)]
pub struct KzQuadrature {
    /// Nodes u_k (1/m).
    pub u: Vec<f64>,
    /// Weights w_k (1/m).
    pub w: Vec<f64>,
    /// k_z(u_k) (dimensionless).
    pub kz: Vec<f64>,
    /// k_z(0) = S(0) − 1.
    pub kz0: f64,
    /// Largest |x| (m) for which cos(u x) is resolved.
    pub x_max: f64,
}

impl KzQuadrature {
    /// Builds the rule for `stack`, resolving cos(u·x) for |x| ≤ `x_max` (m).
    pub fn new(
        stack: &(impl Solid + ?Sized),
        comp: &Compliance,
        x_max: f64,
    ) -> Result<Self, KernelError> {
        let h1 = stack.top_thickness().ok_or(KernelError::NoLayers)?;
        if !(x_max.is_finite() && x_max > 0.0) {
            return Err(KernelError::BadRange(x_max));
        }
        let depth = stack.total_thickness();
        let kz0 = comp.s_at_zero() - 1.0;
        Self::for_kernel(h1, 0.25 / depth, kz0, x_max, |u| comp.kz(u))
    }

    /// The same rule for any kernel function k(u) of the Fredholm equation's form
    /// (physics.md §3: K_a built from k(ρ/a) as from k_z), e.g. the conduction kernel
    /// k_th = S_th − 1 of physics.md §6.2 ([`crate::spot`]). `h1` (m) is the length on
    /// which k decays like e^{−2u h₁}; `u_first` (1/m) the first panel's end, below
    /// which k has its slowest features (0.25/H for k_z, H the total depth); `k0` = k(0).
    /// [`KzQuadrature::new`] is this with k = k_z, so its nodes, weights and values are
    /// unchanged by the generalisation.
    pub fn for_kernel(
        h1: f64,
        u_first: f64,
        k0: f64,
        x_max: f64,
        k: impl Fn(f64) -> f64 + Sync,
    ) -> Result<Self, KernelError> {
        if !(x_max.is_finite() && x_max > 0.0) {
            return Err(KernelError::BadRange(x_max));
        }
        let u_max = (TAIL + 0.5 * (1.0 + k0.abs()).ln()) / h1;
        let du_max = (1.0 / h1).min(PANEL_PHASE / x_max);
        let panels = u_max / du_max;
        if panels.is_nan() || panels > MAX_RULE_PANELS {
            return Err(KernelError::TooWide {
                ratio: x_max / h1,
                panels,
            });
        }
        let mut breaks = vec![0.0];
        let mut u = u_first.min(du_max);
        breaks.push(u);
        while u < u_max {
            u = (2.0 * u).min(u + du_max).min(u_max);
            breaks.push(u);
        }
        let (gx, gw) = gauss_legendre(PANEL_NODES);
        let mut nodes = Vec::with_capacity((breaks.len() - 1) * PANEL_NODES);
        let mut weights = Vec::with_capacity(nodes.capacity());
        for p in breaks.windows(2) {
            let (c, hw) = (0.5 * (p[0] + p[1]), 0.5 * (p[1] - p[0]));
            for (x, w) in gx.iter().zip(&gw) {
                nodes.push(c + hw * x);
                weights.push(hw * w);
            }
        }
        let kz: Vec<f64> = nodes.par_iter().map(|&u| k(u)).collect();
        if let Some(k) = kz.iter().position(|v| !v.is_finite()) {
            return Err(KernelError::NonFinite { u: nodes[k] });
        }
        Ok(KzQuadrature {
            u: nodes,
            w: weights,
            kz,
            kz0: k0,
            x_max,
        })
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.u.len()
    }

    /// True when the rule has no node (never, for a built rule).
    pub fn is_empty(&self) -> bool {
        self.u.is_empty()
    }

    /// κ_a(x) = (2a/π) ∫ k_z(u) cos(a u x) du (dimensionless x; accurate for
    /// |a x| ≤ the rule's x_max).
    pub fn kappa(&self, a: f64, x: f64) -> f64 {
        let mut s = 0.0;
        for k in 0..self.u.len() {
            s += self.w[k] * self.kz[k] * (a * self.u[k] * x).cos();
        }
        2.0 * a / PI * s
    }

    /// The Nyström kernel matrix K_a(s_i, t_j) (row-major, `s.len() × t.len()`),
    /// from the separable form K = (2a/π) Σ_k w_k k_z(u_k) cos(a u_k s) cos(a u_k t).
    /// Needs x_max ≥ a·max(s, t).
    pub fn kernel_matrix(&self, a: f64, s: &[f64], t: &[f64]) -> Vec<f64> {
        let m = self.u.len();
        let cs: Vec<f64> = s
            .iter()
            .flat_map(|&si| self.u.iter().map(move |&u| (a * u * si).cos()))
            .collect();
        let ct: Vec<f64> = t
            .iter()
            .flat_map(|&tj| self.u.iter().map(move |&u| (a * u * tj).cos()))
            .collect();
        let c: Vec<f64> = (0..m)
            .map(|k| 2.0 * a / PI * self.w[k] * self.kz[k])
            .collect();
        let nt = t.len();
        let mut out = vec![0.0; s.len() * nt];
        out.par_chunks_mut(nt).enumerate().for_each(|(i, row)| {
            let ci = &cs[i * m..(i + 1) * m];
            for (j, r) in row.iter_mut().enumerate() {
                let cj = &ct[j * m..(j + 1) * m];
                let mut acc = 0.0;
                for k in 0..m {
                    acc += c[k] * ci[k] * cj[k];
                }
                *r = acc;
            }
        });
        out
    }

    /// Product-integration moments of κ_a on the uniform grid x_m = mΔ, m = 0..=m_max:
    ///
    /// ```text
    ///   Dh(m) = ∫ κ_a(mΔ − y) hat(y) dy
    ///         = (2/π) ∫ k_z(ρ/a) cos(mρΔ) · 4 sin²(ρΔ/2)/(ρ²Δ) dρ,
    ///   E(m)  = ∫_{(m−1)Δ}^{mΔ} κ_a(y) (y − (m−1)Δ)/Δ dy
    ///         = (2/π) ∫ k_z(ρ/a) [sin(mθ)(1 − sinθ/θ) + cos(mθ)(1 − cosθ)/θ] dρ/ρ,  θ = ρΔ,
    /// ```
    ///
    /// (hat = the unit hat of half-width Δ centred at 0; E(0) = Φ(Δ)/Δ by the same
    /// formula). Both come from the second antiderivative Φ (Φ″ = κ_a) without the
    /// cancellation of its differences. cos(mθ), sin(mθ) are generated by rotation,
    /// re-seeded every 64 steps. Needs x_max ≥ a·m_max·Δ.
    pub fn product_moments(&self, a: f64, delta: f64, m_max: usize) -> (Vec<f64>, Vec<f64>) {
        let len = m_max + 1;
        let chunk = 256;
        let zero = || (vec![0.0; len], vec![0.0; len]);
        let (dh, e) = (0..self.u.len())
            .into_par_iter()
            .with_min_len(chunk)
            .fold(zero, |(mut dh, mut e), k| {
                let u = self.u[k];
                let base = 2.0 / PI * self.w[k] * self.kz[k];
                let th = a * u * delta;
                let half = 0.5 * th;
                let sinc_half = if half.abs() < 1e-4 {
                    1.0 - half * half / 6.0
                } else {
                    half.sin() / half
                };
                // 4 sin²(θ/2)/(ρ²Δ) dρ with ρ = a u: a Δ sinc²(θ/2) du.
                let cd = base * a * delta * sinc_half * sinc_half;
                // (1 − sinθ/θ)/u and (1 − cosθ)/(θ u) (dρ/ρ = du/u).
                let one_minus_sinc = if th.abs() < 1e-3 {
                    th * th / 6.0 * (1.0 - th * th / 20.0)
                } else {
                    1.0 - th.sin() / th
                };
                let cb = base * one_minus_sinc / u;
                let ca = base * 2.0 * (half.sin() * half.sin()) / (th * u);
                let (st, ct) = th.sin_cos();
                let (mut s, mut c) = (0.0f64, 1.0f64);
                for m in 0..len {
                    if m % 64 == 0 && m > 0 {
                        let (ss, cc) = (m as f64 * th).sin_cos();
                        s = ss;
                        c = cc;
                    }
                    dh[m] += cd * c;
                    e[m] += cb * s + ca * c;
                    let c2 = c * ct - s * st;
                    s = s * ct + c * st;
                    c = c2;
                }
                (dh, e)
            })
            .reduce(zero, |(mut d1, mut e1), (d2, e2)| {
                for m in 0..len {
                    d1[m] += d2[m];
                    e1[m] += e2[m];
                }
                (d1, e1)
            });
        (dh, e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_runtime::Stack;
    use strata_runtime::{Base, Layer};

    fn layer_on_rigid(nu: f64) -> Stack {
        Stack::new(
            vec![Layer {
                thickness: 1e-4,
                young: 1e9,
                poisson: nu,
            }],
            Base::Rigid,
        )
        .unwrap()
    }

    /// The rule reaches far enough: k_z is negligible at u_max.
    #[test]
    fn tail_is_negligible() {
        for nu in [0.0, 0.3, 0.4999] {
            let st = layer_on_rigid(nu);
            let comp = Compliance::new(&st);
            let q = KzQuadrature::new(&st, &comp, 1e-4).unwrap();
            let last = *q.u.last().unwrap();
            assert!(comp.kz(last).abs() < 2e-15, "nu {nu}: {}", comp.kz(last));
            assert!((q.kz0 + 1.0).abs() < 1e-15);
        }
    }

    /// ∫₀^∞ k_z(u) du for the single layer on a rigid base against an independent
    /// adaptive Simpson integration of the Carbone–Mangialardi closed form.
    #[test]
    fn quadrature_integrates_kz() {
        let st = layer_on_rigid(0.3);
        let comp = Compliance::new(&st);
        let q = KzQuadrature::new(&st, &comp, 1e-4).unwrap();
        let ours: f64 = q.w.iter().zip(&q.kz).map(|(w, k)| w * k).sum();
        let h = 1e-4;
        let f = |u: f64| strata_runtime::compliance::single_layer_on_rigid(u * h, 0.3) - 1.0;
        // Composite Simpson on [0, 40/h] with 200 000 intervals.
        let n = 200_000;
        let hstep = 40.0 / h / n as f64;
        // k_z(0) = −1 on a rigid base (the closed form's series does not stop at t = 0).
        let mut s = -1.0 + f(40.0 / h);
        for i in 1..n {
            s += f(i as f64 * hstep) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        let simpson = s * hstep / 3.0;
        assert!(
            ((ours - simpson) / simpson).abs() < 1e-10,
            "{ours} vs {simpson}"
        );
    }

    /// The product moments against direct quadrature of κ_a (Dh(m) ≈ ∫ κ hat with a
    /// fine trapezoid in y).
    #[test]
    fn product_moments_match_direct_integrals() {
        let st = layer_on_rigid(0.3);
        let comp = Compliance::new(&st);
        let a = 3e-4; // a/h = 3
        let delta = 1.0 / 16.0;
        let q = KzQuadrature::new(&st, &comp, a * 2.0).unwrap();
        let (dh, e) = q.product_moments(a, delta, 32);
        for m in [0usize, 1, 5, 17, 32] {
            let n = 400;
            let hy = delta / n as f64;
            // Full hat centred at mΔ: ∫ κ(mΔ − y) hat(y) dy by Simpson on each half.
            let g = |y: f64| q.kappa(a, m as f64 * delta - y) * (1.0 - y.abs() / delta);
            let mut s = 0.0;
            for i in 0..2 * n {
                let y0 = -delta + i as f64 * hy;
                s += hy / 6.0 * (g(y0) + 4.0 * g(y0 + 0.5 * hy) + g(y0 + hy));
            }
            assert!(
                (s - dh[m]).abs() < 1e-9 * dh[0].abs(),
                "Dh({m}): {s} vs {}",
                dh[m]
            );
            if m >= 1 {
                let lo = (m - 1) as f64 * delta;
                let g = |y: f64| q.kappa(a, y) * (y - lo) / delta;
                let mut s = 0.0;
                for i in 0..n {
                    let y0 = lo + i as f64 * hy;
                    s += hy / 6.0 * (g(y0) + 4.0 * g(y0 + 0.5 * hy) + g(y0 + hy));
                }
                assert!(
                    (s - e[m]).abs() < 1e-9 * dh[0].abs(),
                    "E({m}): {s} vs {}",
                    e[m]
                );
            }
        }
    }
}
