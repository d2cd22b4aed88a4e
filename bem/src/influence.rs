//! Real-space influence coefficients of a uniformly loaded rectangular pixel on the
//! layered solid, for the non-periodic (free-boundary) solver.
//!
//! # Equations (physics.md §1–2)
//! A unit point force on the surface deflects it by (Hankel transform of ŵ = 2S/(E*₁ρ) p̂)
//!
//! ```text
//!   w(r) = 1/(π E*₁) ∫₀^∞ S(ρ) J₀(ρr) dρ = 1/(π E*₁) [ 1/r + I(r) ],
//!   I(r) = ∫₀^∞ k_z(ρ) J₀(ρr) dρ,   k_z = S − 1.
//! ```
//!
//! With k₀ = k_z(0) (−1 on a rigid base, E*₁/E*_b − 1 on an elastic one) and b = h₁ the
//! top layer's thickness, I(r) = k₀/√(r² + b²) + J(r), where J is the Hankel transform of
//! q(ρ) = k_z(ρ) − k₀e^{−bρ}: q(0) = 0 and q decays like e^{−ρh₁}, so J is smooth on the
//! scale h₁ and decays like 1/r³. J (and J′) are tabulated by composite Gauss–Legendre
//! quadrature in ρ and interpolated (cubic Hermite).
//!
//! The coefficient of a pixel dx × dy carrying unit pressure, seen at the centre offset
//! (X, Y), is the pixel integral of w:
//!
//! ```text
//!   G(X, Y) = 1/(π E*₁) [ Λ₀(X, Y) + k₀ Λ_b(X, Y) + ∬_pixel J ],
//!   Λ_b(X, Y) = Σ± Ψ_b(X ± dx/2, Y ± dy/2)  (corner sum, signs + − − +),
//!   Ψ_b(x, y) = x asinh(y/√(x²+b²)) + y asinh(x/√(y²+b²)) − b atan(xy/(b√(x²+y²+b²))),
//! ```
//!
//! the closed forms of ∬ dA/√(r² + b²) (b = 0: Love 1929, Johnson eq. 3.25); the last
//! integral by tensor Gauss–Legendre, subdivided near the source where J varies on the
//! scale h₁. On a homogeneous stack k_z ≡ 0 and G is Love's coefficient.

use strata_runtime::compliance::Compliance;
use strata_runtime::stack::{Base, Stack};

use crate::BemError;

/// Gauss–Legendre nodes and weights on [−1, 1], 8 points.
const GL8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];
/// Gauss–Legendre, 4 points.
const GL4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_85),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_85),
];

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

/// ∬ over the pixel |ξ| ≤ dx/2, |η| ≤ dy/2 of 1/√((X−ξ)² + (Y−η)² + b²) (m).
pub fn pixel_integral(x: f64, y: f64, dx: f64, dy: f64, b: f64) -> f64 {
    let (a, c) = (0.5 * dx, 0.5 * dy);
    psi(x + a, y + c, b) - psi(x + a, y - c, b) - psi(x - a, y + c, b) + psi(x - a, y - c, b)
}

/// Love's coefficient (Johnson eq. 3.25): deflection (m) at offset (X, Y) from the
/// centre of a dx × dy pixel under unit pressure on a half-space of plane-strain
/// modulus E* (Pa).
pub fn love(x: f64, y: f64, dx: f64, dy: f64, e_star: f64) -> f64 {
    pixel_integral(x, y, dx, dy, 0.0) / (std::f64::consts::PI * e_star)
}

/// The smooth remainder J(r) of the layered point-load response, tabulated.
pub struct Remainder {
    /// k₀ = k_z(0).
    pub k0: f64,
    /// Split length b = h₁ (m).
    pub b: f64,
    r_max: f64,
    n: usize,
    /// (J, J′) at r_k = r_max (k/n)².
    table: Vec<(f64, f64)>,
}

impl Remainder {
    /// Tabulates J on [0, r_max] for `stack`; `None` for a homogeneous stack.
    pub fn new(stack: &Stack, r_max: f64) -> Result<Option<Self>, BemError> {
        if stack.is_homogeneous() {
            return Ok(None);
        }
        let comp = Compliance::new(stack);
        let e1 = stack.contact_modulus();
        let k0 = match (stack.counterface(), stack.base()) {
            (Some(_), _) => comp.s_at_zero() - 1.0,
            (None, Base::Rigid) => -1.0,
            (None, Base::Elastic { young, poisson }) => {
                e1 * (1.0 - poisson * poisson) / young - 1.0
            }
        };
        let Some(b) = stack.top_thickness() else {
            return Ok(None);
        };
        let depth = stack.total_thickness();
        if !(b > 0.0 && depth.is_finite() && r_max.is_finite() && r_max > 0.0) {
            return Err(BemError::Influence(format!(
                "layer thickness {b:e} m or sample diagonal {r_max:e} m out of range"
            )));
        }
        // Beyond 50 depths J is its 1/r³ tail; tabulate up to there.
        let r_tab = r_max.min(50.0 * depth);
        let rho_max = 40.0 / b;
        let panel = (0.5 / depth).min(2.0 / r_tab);
        let panels = (rho_max / panel).ceil() as usize;
        if panels > 2_000_000 {
            return Err(BemError::Influence(format!(
                "{panels} quadrature panels needed (h₁ = {b:e} m, depth {depth:e} m, r = {r_tab:e} m)"
            )));
        }
        let mut nodes = Vec::with_capacity(panels * GL8.len());
        for k in 0..panels {
            let (lo, hi) = (k as f64 * panel, (k + 1) as f64 * panel);
            for &(x, w) in &GL8 {
                let rho = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x;
                let s = comp.s(rho);
                if !s.is_finite() {
                    return Err(BemError::Kernel { k: rho, s });
                }
                let q = s - 1.0 - k0 * (-b * rho).exp();
                nodes.push((rho, q * w * 0.5 * (hi - lo)));
            }
        }
        let n = 400;
        let table: Vec<(f64, f64)> = (0..=n)
            .map(|k| {
                let r = r_tab * (k as f64 / n as f64).powi(2);
                let (mut j, mut dj) = (0.0, 0.0);
                for &(rho, qw) in &nodes {
                    j += qw * libm::j0(rho * r);
                    dj -= qw * rho * libm::j1(rho * r);
                }
                (j, dj)
            })
            .collect();
        Ok(Some(Remainder {
            k0,
            b,
            r_max: r_tab,
            n,
            table,
        }))
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
        let mut acc = 0.0;
        for a in 0..sx {
            let cx = -0.5 * dx + (a as f64 + 0.5) * hx;
            for c in 0..sy {
                let cy = -0.5 * dy + (c as f64 + 0.5) * hy;
                for &(u, wu) in &GL4 {
                    for &(v, wv) in &GL4 {
                        let px = x - (cx + 0.5 * hx * u);
                        let py = y - (cy + 0.5 * hy * v);
                        acc += wu * wv * self.j(px.hypot(py));
                    }
                }
            }
        }
        acc * 0.25 * hx * hy
    }
}

/// Influence coefficients G[dy·nx + dx] (m/Pa) for offsets 0 ≤ dy < ny, 0 ≤ dx < nx of
/// pixels `px` × `py` (m) on `stack` (module docs).
pub fn coefficients(
    stack: &Stack,
    ny: usize,
    nx: usize,
    px: f64,
    py: f64,
) -> Result<Vec<f64>, BemError> {
    let e1 = stack.contact_modulus();
    let diag = (nx as f64 * px).hypot(ny as f64 * py);
    let rem = Remainder::new(stack, diag)?;
    let pi_e = std::f64::consts::PI * e1;
    let mut g = vec![0.0; ny * nx];
    use rayon::prelude::*;
    g.par_chunks_mut(nx).enumerate().for_each(|(i, row)| {
        let y = i as f64 * py;
        for (j, slot) in row.iter_mut().enumerate() {
            let x = j as f64 * px;
            let mut v = pixel_integral(x, y, px, py, 0.0);
            if let Some(rem) = &rem {
                v +=
                    rem.k0 * pixel_integral(x, y, px, py, rem.b) + rem.pixel_integral(x, y, px, py);
            }
            *slot = v / pi_e;
        }
    });
    if let Some((k, v)) = g.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(BemError::Influence(format!(
            "coefficient at offset ({}, {}) is {v}",
            k / nx,
            k % nx
        )));
    }
    Ok(g)
}
