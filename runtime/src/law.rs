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

/// Force of one asperity, P = (4/3) E*₁ χ(a) a³/R (N), P24.
pub fn force(law: &dyn AsperityLaw, a: f64, radius: f64) -> f64 {
    4.0 / 3.0 * law.e_star() * law.chi(a) * a.powi(3) / radius
}

/// Interference of one asperity, δ = ζ(a) a²/R (m).
pub fn interference(law: &dyn AsperityLaw, a: f64, radius: f64) -> f64 {
    law.zeta(a) * a * a / radius
}

/// Surface displacement at distance r from an asperity of contact radius a and
/// radius R (m): (2a²ζ(a) − r²)/(2R) inside, the χ/(πR)[…] form of physics.md §4
/// outside.
pub fn displacement(law: &dyn AsperityLaw, a: f64, radius: f64, r: f64) -> f64 {
    if r <= a {
        return (2.0 * a * a * law.zeta(a) - r * r) / (2.0 * radius);
    }
    let half_space = (2.0 * a * a - r * r) * (a / r).asin() + a * (r * r - a * a).sqrt();
    let g = if law.is_homogeneous() {
        0.0
    } else {
        law.g(a, r)
    };
    law.chi(a) / (std::f64::consts::PI * radius) * (half_space + g)
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
    fn chi_zeta_derivs(&self, _a: f64) -> (f64, f64, f64, f64) {
        (1.0, 0.0, 1.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
