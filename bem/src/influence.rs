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
use strata_runtime::hankel::{HankelError, Remainder as Hankel};
use strata_runtime::stack::{Base, Solid};

use crate::BemError;

pub use strata_runtime::hankel::{pixel_integral, psi};

/// Love's coefficient (Johnson eq. 3.25): deflection (m) at offset (X, Y) from the
/// centre of a dx × dy pixel under unit pressure on a half-space of plane-strain
/// modulus E* (Pa).
pub fn love(x: f64, y: f64, dx: f64, dy: f64, e_star: f64) -> f64 {
    pixel_integral(x, y, dx, dy, 0.0) / (std::f64::consts::PI * e_star)
}

/// The smooth remainder J(r) of the layered point-load response of `stack`, tabulated
/// on [0, r_max] ([`strata_runtime::hankel::Remainder`], k = S − 1 of the elastic
/// compliance); `None` for a homogeneous stack.
pub fn remainder<S: Solid + ?Sized>(stack: &S, r_max: f64) -> Result<Option<Hankel>, BemError> {
    if stack.is_homogeneous() {
        return Ok(None);
    }
    let comp = Compliance::new(stack);
    let e1 = stack.contact_modulus();
    let k0 = match (stack.elastic_counterface(), stack.first().base()) {
        (Some(_), _) => comp.s_at_zero() - 1.0,
        (None, Base::Rigid) => -1.0,
        (None, Base::Elastic { young, poisson }) => e1 * (1.0 - poisson * poisson) / young - 1.0,
    };
    let Some(b) = stack.top_thickness() else {
        return Ok(None);
    };
    let depth = stack.total_thickness();
    // beyond 50 depths J is its 1/r³ tail; tabulate up to there
    Hankel::new(k0, b, depth, r_max.min(50.0 * depth), |rho| {
        comp.s(rho) - 1.0
    })
    .map(Some)
    .map_err(|e| match e {
        HankelError::NonFinite { rho, value } => BemError::Kernel { k: rho, s: value },
        other => BemError::Influence(other.to_string()),
    })
}

/// Influence coefficients G[dy·nx + dx] (m/Pa) for offsets 0 ≤ dy < ny, 0 ≤ dx < nx of
/// pixels `px` × `py` (m) on `stack` (module docs).
pub fn coefficients(
    stack: &(impl Solid + ?Sized),
    ny: usize,
    nx: usize,
    px: f64,
    py: f64,
) -> Result<Vec<f64>, BemError> {
    let e1 = stack.contact_modulus();
    let diag = (nx as f64 * px).hypot(ny as f64 * py);
    let rem = remainder(stack, diag)?;
    let pi_e = std::f64::consts::PI * e1;
    let mut g = vec![0.0; ny * nx];
    use rayon::prelude::*;
    g.par_chunks_mut(nx).enumerate().for_each(|(i, row)| {
        let y = i as f64 * py;
        for (j, slot) in row.iter_mut().enumerate() {
            let x = j as f64 * px;
            let mut v = pixel_integral(x, y, px, py, 0.0);
            if let Some(rem) = &rem {
                v += rem.pixel_layered(x, y, px, py);
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
