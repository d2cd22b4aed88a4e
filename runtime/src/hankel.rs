//! The smooth remainder of a layered body's point-source surface field: one Hankel
//! transform, tabulated, shared by the elastic free-boundary coefficients of the BEM and
//! the isolated conduction fields (BEM and I model).
//!
//! # Equations (physics.md §1–2, §6.2)
//! A layered body answers a point load (force, or heat) at the surface with the surface
//! field (deflection, or temperature)
//!
//! ```text
//!   w(r) = c/(2π) ∫₀^∞ S(ρ) J₀(ρr) dρ = c/(2π) [ 1/r + I(r) ],   I(r) = ∫₀^∞ k(ρ) J₀(ρr) dρ,
//! ```
//!
//! k = S − 1 the layered part of the normalised compliance S (S(∞) = 1), c the top
//! material's half-space constant (2/E*₁ elastic, 1/k₁ conduction). With k₀ = k(0) and
//! b = h₁ the top layer's thickness, I(r) = k₀/√(r² + b²) + J(r), where J is the Hankel
//! transform of q(ρ) = k(ρ) − k₀e^{−bρ}: q(0) = 0 and q decays like e^{−ρh₁}, so J is
//! smooth on the scale h₁ and decays like 1/r³. J (and J′) are tabulated by composite
//! Gauss–Legendre quadrature in ρ and interpolated (cubic Hermite).

use thiserror::Error;

use crate::numerics::gauss_legendre_cached;

/// Why the remainder could not be tabulated.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum HankelError {
    /// A length out of range, or too many quadrature panels.
    #[error("{0}")]
    Range(String),
    /// The compliance is not finite at a quadrature node.
    #[error("the normalised compliance at ρ = {rho:e} 1/m is {value}")]
    NonFinite { rho: f64, value: f64 },
}

/// Ψ_b(x, y): ∂²Ψ_b/∂x∂y = 1/√(x² + y² + b²) (b ≥ 0; b = 0 is Love's kernel).
pub fn psi(x: f64, y: f64, b: f64) -> f64 {
    let sx = (x * x + b * b).sqrt();
    let sy = (y * y + b * b).sqrt();
    let mut v = 0.0;
    if x != 0.0 {
        v += x * (y / sx).asinh();
    }
    if y != 0.0 {
        v += y * (x / sy).asinh();
    }
    if b > 0.0 {
        let r = (x * x + y * y + b * b).sqrt();
        v -= b * (x * y / (b * r)).atan();
    }
    v
}

/// ∬ over the pixel |ξ| ≤ dx/2, |η| ≤ dy/2 of 1/√((X−ξ)² + (Y−η)² + b²) (m): the
/// corner sum of [`psi`] (b = 0: Love 1929, Johnson eq. 3.25).
pub fn pixel_integral(x: f64, y: f64, dx: f64, dy: f64, b: f64) -> f64 {
    let (a, c) = (0.5 * dx, 0.5 * dy);
    psi(x + a, y + c, b) - psi(x + a, y - c, b) - psi(x - a, y + c, b) + psi(x - a, y - c, b)
}

/// Where J is its 1/r³ tail to the table's accuracy (m): 50 depths, times the
/// conductivity (or stiffness) contrast of the layers where it is above 1 (a good
/// conductor on a poor one channels the field sideways over ~ depth × contrast).
pub fn tail_start(depth: f64, contrast: f64) -> f64 {
    50.0 * depth * contrast.max(1.0)
}

/// The smooth remainder J(r) of a layered point-source field, tabulated.
#[derive(Debug, Clone)]
pub struct Remainder {
    /// k₀ = k(0).
    pub k0: f64,
    /// Split length b = h₁ (m).
    pub b: f64,
    r_max: f64,
    n: usize,
    /// (J, J′) at r_k = r_max (k/n)².
    table: Vec<(f64, f64)>,
}

impl Remainder {
    /// Tabulates J on [0, r_max] (beyond, its 1/r³ tail) for the layered part
    /// `k(ρ)` = S(ρ) − 1 with k₀ = k(0), top layer thickness `b` and total layer
    /// thickness `depth` (m). J reaches its tail within ~50 depths of a body of
    /// moderate contrast ([`tail_start`]).
    pub fn new(
        k0: f64,
        b: f64,
        depth: f64,
        r_max: f64,
        k: impl Fn(f64) -> f64,
    ) -> Result<Self, HankelError> {
        if !(b > 0.0 && depth.is_finite() && r_max.is_finite() && r_max > 0.0 && k0.is_finite()) {
            return Err(HankelError::Range(format!(
                "layer thickness {b:e} m or sample diagonal {r_max:e} m out of range"
            )));
        }
        let r_tab = r_max;
        let rho_max = 40.0 / b;
        let panel = (0.5 / depth).min(2.0 / r_tab);
        let panels = (rho_max / panel).ceil() as usize;
        if panels > 2_000_000 {
            return Err(HankelError::Range(format!(
                "{panels} quadrature panels needed (h₁ = {b:e} m, depth {depth:e} m, r = {r_tab:e} m)"
            )));
        }
        let gl8 = gauss_legendre_cached(8);
        let mut nodes = Vec::with_capacity(panels * gl8.len());
        for p in 0..panels {
            let (lo, hi) = (p as f64 * panel, (p + 1) as f64 * panel);
            for &(x, w) in gl8 {
                let rho = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x;
                let kr = k(rho);
                if !kr.is_finite() {
                    return Err(HankelError::NonFinite {
                        rho,
                        value: 1.0 + kr,
                    });
                }
                let q = kr - k0 * (-b * rho).exp();
                nodes.push((rho, q * w * 0.5 * (hi - lo)));
            }
        }
        let n = 400;
        let table: Vec<(f64, f64)> = (0..=n)
            .map(|i| {
                let r = r_tab * (i as f64 / n as f64).powi(2);
                let (mut j, mut dj) = (0.0, 0.0);
                for &(rho, qw) in &nodes {
                    j += qw * libm::j0(rho * r);
                    dj -= qw * rho * libm::j1(rho * r);
                }
                (j, dj)
            })
            .collect();
        Ok(Remainder {
            k0,
            b,
            r_max: r_tab,
            n,
            table,
        })
    }

    /// J(r) (1/m), by cubic Hermite interpolation; the 1/r³ tail beyond the table.
    pub fn j(&self, r: f64) -> f64 {
        if r >= self.r_max {
            return self.table[self.n].0 * (self.r_max / r).powi(3);
        }
        let s = (r / self.r_max).sqrt() * self.n as f64;
        let k = (s.floor() as usize).min(self.n - 1);
        let r0 = self.r_max * (k as f64 / self.n as f64).powi(2);
        let r1 = self.r_max * ((k + 1) as f64 / self.n as f64).powi(2);
        let h = r1 - r0;
        let t = (r - r0) / h;
        let (f0, d0) = self.table[k];
        let (f1, d1) = self.table[k + 1];
        let t2 = t * t;
        let t3 = t2 * t;
        (2.0 * t3 - 3.0 * t2 + 1.0) * f0
            + (t3 - 2.0 * t2 + t) * h * d0
            + (-2.0 * t3 + 3.0 * t2) * f1
            + (t3 - t2) * h * d1
    }

    /// The layered part of the point field, I(r) = k₀/√(r² + b²) + J(r) (1/m).
    pub fn layered(&self, r: f64) -> f64 {
        self.k0 / r.hypot(self.b) + self.j(r)
    }

    /// ∬ over the pixel of J (m), tensor Gauss–Legendre, the pixel split into cells no
    /// larger than b/2 near the source (where J varies on the scale b).
    pub fn pixel_integral(&self, x: f64, y: f64, dx: f64, dy: f64) -> f64 {
        let near = x.abs() < 2.0 * dx + 4.0 * self.b && y.abs() < 2.0 * dy + 4.0 * self.b;
        let split = |d: f64| -> usize {
            if near {
                ((2.0 * d / self.b).ceil() as usize).clamp(1, 32)
            } else {
                1
            }
        };
        let (sx, sy) = (split(dx), split(dy));
        let (hx, hy) = (dx / sx as f64, dy / sy as f64);
        let gl4 = gauss_legendre_cached(4);
        let mut acc = 0.0;
        for a in 0..sx {
            let cx = -0.5 * dx + (a as f64 + 0.5) * hx;
            for c in 0..sy {
                let cy = -0.5 * dy + (c as f64 + 0.5) * hy;
                for &(u, wu) in gl4 {
                    for &(v, wv) in gl4 {
                        let px = x - (cx + 0.5 * hx * u);
                        let py = y - (cy + 0.5 * hy * v);
                        acc += wu * wv * self.j(px.hypot(py));
                    }
                }
            }
        }
        acc * 0.25 * hx * hy
    }

    /// ∬ over the pixel of the layered part k₀/√(r² + b²) + J (m): the closed form and
    /// [`Self::pixel_integral`].
    pub fn pixel_layered(&self, x: f64, y: f64, dx: f64, dy: f64) -> f64 {
        self.k0 * pixel_integral(x, y, dx, dy, self.b) + self.pixel_integral(x, y, dx, dy)
    }
}
