//! Single-asperity quantities shared by the N and I models, at contact radius a (m) of
//! an asperity of radius R (m) on the law's χ, ζ (physics.md §4):
//!
//! ```text
//!   Q = χ(a)a³/R                 (m², P = (4/3)E*₁Q, eq. P24)
//!   Q′ = (χ′a³ + 3χa²)/R         (m)
//!   s = (a²/R)(ζ(a) + 1/5)       (m, the self term of U_E, eq. P22)
//!   s′ = (2a(ζ + 1/5) + a²ζ′)/R  (-)
//!   δ′ = dδ/da = (ζ′a² + 2ζa)/R  (-, δ = ζa²/R)
//! ```

use crate::law::AsperityLaw;

/// Local (single-asperity) quantities at one contact radius (module docs).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Local {
    pub q: f64,
    pub dq: f64,
    pub s: f64,
    pub ds: f64,
    pub zeta: f64,
    pub dzeta: f64,
    pub chi: f64,
    pub dchi: f64,
}

impl Local {
    /// The quantities at contact radius `a` (m) of an asperity of radius `radius` (m).
    pub fn at(law: &dyn AsperityLaw, a: f64, radius: f64) -> Local {
        let (chi, dchi, zeta, dzeta) = law.chi_zeta_derivs(a);
        Local {
            q: chi * a.powi(3) / radius,
            dq: (dchi * a.powi(3) + 3.0 * chi * a * a) / radius,
            s: a * a / radius * (zeta + 0.2),
            ds: (2.0 * a * (zeta + 0.2) + a * a * dzeta) / radius,
            zeta,
            dzeta,
            chi,
            dchi,
        }
    }

    /// dδ/da = (ζ′a² + 2ζa)/R at contact radius `a` (m) (-).
    pub fn ddelta(&self, a: f64, radius: f64) -> f64 {
        (self.dzeta * a * a + 2.0 * self.zeta * a) / radius
    }
}
