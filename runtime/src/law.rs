//! The second-order asperity law (physics.md §4, paper §4.1 and Appendix C): the
//! functions χ(a), ζ(a) and g(a, r) of one material stack, and what follows from
//! them for one paraboloidal asperity of radius R and contact radius a:
//!
//! ```text
//!   P = (4/3) E*₁ χ(a) a³/R          (N, positive in compression; P24)
//!   δ = ζ(a) a²/R                    (m)
//!   u(r) = χ(a)/(πR) [(2a²−r²) asin(a/r) + a√(r²−a²) + g(a,r)],  r > a   (m)
//! ```
//!
//! A homogeneous solid has χ = ζ = 1 and g = 0 ([`Homogeneous`]); layered stacks get
//! theirs from a surrogate table (the `table` module).

use crate::numerics::{Falsi, Tolerance, bracketed};

/// χ, ζ, g of one stack. Lengths in m, moduli in Pa.
pub trait AsperityLaw: Send + Sync {
    /// E*₁ = E₁/(1−ν₁²) of the surface material (Pa).
    fn e_star(&self) -> f64;
    /// χ(a), dimensionless (physics.md §4).
    fn chi(&self, a: f64) -> f64;
    /// ζ(a), dimensionless (physics.md §4).
    fn zeta(&self, a: f64) -> f64;
    /// g(a, r) (m²) for r > a (physics.md §4).
    fn g(&self, a: f64, r: f64) -> f64;
    /// The far field of a point force on the solid, S(0): fixes the uniform mode of
    /// periodic loads (physics.md §5).
    fn point_force(&self) -> PointForce;
    /// True when χ ≡ ζ ≡ 1 and g ≡ 0, so callers may skip lookups.
    fn is_homogeneous(&self) -> bool {
        false
    }
    /// (χ, dχ/da, ζ, dζ/da); the default differentiates numerically (central
    /// differences, relative step 1e-5). Tables override it with exact spline slopes.
    fn chi_zeta_derivs(&self, a: f64) -> (f64, f64, f64, f64) {
        let h = 1e-5 * a;
        let (c, z) = (self.chi(a), self.zeta(a));
        if h == 0.0 {
            return (c, 0.0, z, 0.0);
        }
        let dc = (self.chi(a + h) - self.chi(a - h)) / (2.0 * h);
        let dz = (self.zeta(a + h) - self.zeta(a - h)) / (2.0 * h);
        (c, dc, z, dz)
    }
}

/// The far field of a point force on a solid: the surface displacement of a unit force is
/// w(r)/(πE*₁) with w(r) = ∫₀^∞ S(ρ) J₀(ρr) dρ (1/m), and far away w → S(0)/r
/// (physics.md §2). An elastic base has S(0) > 0 (the uniform mode of a periodic load is
/// unbounded, physics.md §5); a rigid base S(0) = 0. The rest of w, w − S(0)/r, is what
/// the law's g gives as a → 0 (`rough::interacting::uniform` integrates it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointForce {
    /// S(0) (-).
    pub s0: f64,
}

impl PointForce {
    /// The homogeneous half-space: S ≡ 1.
    pub const HALF_SPACE: PointForce = PointForce { s0: 1.0 };

    /// The point force on a solid (a stack, or [`crate::Bodies`]): S(0) of its
    /// compliance.
    pub fn of_stack<S: crate::Solid + ?Sized>(stack: &S) -> PointForce {
        PointForce {
            s0: crate::Compliance::new(stack).s(0.0),
        }
    }
}

/// Force of one asperity, P = (4/3) E*₁ χ(a) a³/R (N), paper eq. (P24).
pub fn force(law: &dyn AsperityLaw, a: f64, radius: f64) -> f64 {
    4.0 / 3.0 * law.e_star() * law.chi(a) * a.powi(3) / radius
}

/// Interference of one asperity, δ = ζ(a) a²/R (m).
pub fn interference(law: &dyn AsperityLaw, a: f64, radius: f64) -> f64 {
    law.zeta(a) * a * a / radius
}

/// Surface displacement at distance r from an asperity of contact radius a and
/// radius R (m): (2a²ζ(a) − r²)/(2R) inside, the χ/(πR)[B₀(a, r) + g(a, r)] form of
/// physics.md §4 outside (B₀ the [`half_space_bracket`]).
pub fn displacement(law: &dyn AsperityLaw, a: f64, radius: f64, r: f64) -> f64 {
    if r <= a {
        return (2.0 * a * a * law.zeta(a) - r * r) / (2.0 * radius);
    }
    let g = if law.is_homogeneous() {
        0.0
    } else {
        law.g(a, r)
    };
    law.chi(a) / (std::f64::consts::PI * radius) * (half_space_bracket(a, r) + g)
}

/// The half-space bracket B₀(a, r) = (2a² − r²) asin(a/r) + a√(r² − a²) (m², r ≥ a ≥ 0),
/// → (4/3)a³/r far away (physics.md §4): one copy, in the table's far-field module,
/// summed as its series below a/r = 0.3 where the closed form would cancel.
pub use crate::table::far::half_space_bracket;

/// ∂B₀/∂a = 4a·asin(a/r) (m) and ∂²B₀/∂a² = 4 asin(a/r) + 4(a/r)/√(1 − (a/r)²)
/// (dimensionless) of the [`half_space_bracket`], r ≥ a.
pub fn half_space_bracket_derivs(a: f64, r: f64) -> (f64, f64) {
    let q = (a / r).min(1.0);
    (
        4.0 * a * q.asin(),
        4.0 * q.asin() + 4.0 * q / (1.0 - q * q).max(f64::MIN_POSITIVE).sqrt(),
    )
}

/// The contact radius a ≥ 0 (m) of an asperity of radius R (m) at interference δ (m):
/// the root of δ = ζ(a)a²/R. Homogeneous: a = √(Rδ); otherwise safeguarded Newton
/// ([`bracketed`], exact slope (ζ′a² + 2ζa)/R) on a bracket grown by doubling from the
/// Hertz radius,
/// to round-off (|residual| ≤ 1e-15 δ or a step ≤ 1e-15 a). 0 for δ ≤ 0 or NaN;
/// None when no bracket is found within 2⁶⁰ × the Hertz radius or a value is not finite.
pub fn contact_radius(law: &dyn AsperityLaw, radius: f64, delta: f64) -> Option<f64> {
    if delta.is_nan() || delta <= 0.0 {
        return Some(0.0);
    }
    let hertz = (radius * delta).sqrt();
    if law.is_homogeneous() {
        return Some(hertz);
    }
    let f = |a: f64| interference(law, a, radius) - delta;
    let (mut lo, mut hi) = (0.0, hertz);
    let mut k = 0;
    let mut f_hi = f(hi);
    while f_hi < 0.0 {
        lo = hi;
        hi *= 2.0;
        k += 1;
        if k > 60 || !hi.is_finite() {
            return None;
        }
        f_hi = f(hi);
    }
    // Newton with the exact slope from the bracket's midpoint
    let eval = |a: f64| {
        let (_, _, z, dz) = law.chi_zeta_derivs(a);
        let v = z * a * a / radius - delta;
        Ok::<_, std::convert::Infallible>((v, Some((dz * a * a + 2.0 * z * a) / radius)))
    };
    let tol = Tolerance {
        f: 1e-15 * delta,
        step: 1e-15,
        width: 0.0,
        width_abs: 0.0,
        falsi: Falsi::Illinois,
    };
    let start = Some(0.5 * (lo + hi));
    let root = match bracketed(eval, (lo, -delta), (hi, f_hi), start, tol, 200) {
        Ok(root) => root,
        Err(never) => match never {},
    };
    root.f.is_finite().then_some(root.x)
}

/// The homogeneous half-space: χ = ζ = 1, g = 0.
#[derive(Debug, Clone, Copy)]
pub struct Homogeneous {
    /// E* (Pa).
    pub e_star: f64,
}

impl AsperityLaw for Homogeneous {
    fn e_star(&self) -> f64 {
        self.e_star
    }
    fn chi(&self, _a: f64) -> f64 {
        1.0
    }
    fn zeta(&self, _a: f64) -> f64 {
        1.0
    }
    fn g(&self, _a: f64, _r: f64) -> f64 {
        0.0
    }
    fn is_homogeneous(&self) -> bool {
        true
    }
    fn point_force(&self) -> PointForce {
        PointForce::HALF_SPACE
    }
    fn chi_zeta_derivs(&self, _a: f64) -> (f64, f64, f64, f64) {
        (1.0, 0.0, 1.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The half-space bracket: continuous (to 2e-11) where the closed form would start to
    /// cancel (q = 0.05, below the series switch); → (4/3)a³/r far
    /// away; B₀(a, a) = πa²/2; the derivatives match
    /// central differences to 1e-7 relative.
    #[test]
    fn half_space_bracket_series_and_derivatives() {
        let r = 1e-3;
        let (lo, hi) = (0.05 * r * (1.0 - 1e-12), 0.05 * r * (1.0 + 1e-12));
        let (b0, b1) = (half_space_bracket(lo, r), half_space_bracket(hi, r));
        assert!((b0 - b1).abs() < 2e-11 * b1, "{b0} {b1}");
        let a: f64 = 1e-9;
        let far = 4.0 / 3.0 * a.powi(3) / r;
        assert!((half_space_bracket(a, r) / far - 1.0 - 0.1e-12).abs() < 1e-15);
        let e = half_space_bracket(r, r);
        assert!((e - std::f64::consts::PI * r * r / 2.0).abs() < 1e-15 * e);
        for a in [1e-5, 3e-4, 0.9e-3] {
            let h = 1e-6 * a;
            let fd = (half_space_bracket(a + h, r) - half_space_bracket(a - h, r)) / (2.0 * h);
            let (d1, d2) = half_space_bracket_derivs(a, r);
            assert!((fd - d1).abs() < 1e-7 * d1.abs(), "{a}: {fd} {d1}");
            let (p, _) = half_space_bracket_derivs(a + h, r);
            let (m, _) = half_space_bracket_derivs(a - h, r);
            let fd2 = (p - m) / (2.0 * h);
            assert!((fd2 - d2).abs() < 1e-6 * d2.abs(), "{a}: {fd2} {d2}");
        }
    }

    /// Hertz: P = (4/3)E* a³/R, δ = a²/R, and the outside displacement is the
    /// half-space one, continuous at r = a (u(a) = a²/(2R)) and → (2/3)a³/(πR r)·2 far away.
    #[test]
    fn homogeneous_is_hertz() {
        let law = Homogeneous { e_star: 2e11 };
        let (a, r) = (1e-5, 1e-3);
        let p = 4.0 / 3.0 * 2e11 * 1e-15 / 1e-3;
        assert!((force(&law, a, r) - p).abs() < 1e-15 * p);
        assert!((interference(&law, a, r) - 1e-7).abs() < 1e-22);
        let inside = displacement(&law, a, r, a);
        let outside = displacement(&law, a, r, a * (1.0 + 1e-12));
        assert!((inside - a * a / (2.0 * r)).abs() < 1e-20);
        assert!((outside - inside).abs() < 1e-9 * inside);
        // Far field of a Hertz contact: u → P/(π E* r) = (4/3) a³/(π R r).
        let far = 1e3 * a;
        let u = displacement(&law, a, r, far);
        let expect = 4.0 / 3.0 * a.powi(3) / (std::f64::consts::PI * r * far);
        assert!((u - expect).abs() < 1e-6 * expect, "{u} {expect}");
    }
}
