//! The normal and tangential stiffness of one contact disc on a layered solid: the
//! frictionless flat punch (normal) and the bonded, full-stick disc (tangential) of
//! radius a (m), by the Fredholm machinery of the asperity (physics.md §3).
//!
//! # Normal: the flat punch
//! A rigid flat punch of radius a pressed by δ: P = K_n δ with
//!
//! ```text
//!   K_n(a) = 2 E*₁ a ψ_zz(a),   φ(s) + ∫₀¹ K_a(s,t) φ(t) dt = 1,   ψ = ∫₀¹ φ dt,
//!   K_a(s,t) = (2/π) ∫₀^∞ k(ρ/a) cos(ρs) cos(ρt) dρ,   k = k_z = S_zz − 1,
//! ```
//!
//! (the paper's P9 and P10 with G = αδ; 2aE*₁ on a half-space).
//!
//! # Tangential: the full-stick disc, a harmonic mean of two punches
//! The disc is displaced by δ along x without rotation, the traction q = (q_x, q_y)
//! outside it vanishes, and the normal–tangential coupling S_zL is ignored (as in
//! Mindlin's solution). With the compliance of
//! [`strata_runtime::compliance::tangential`] (u_L = c_L q_L/ρ, u_T = c_T q_T/ρ for
//! the components along and across the wavevector, c_L = 2S_LL/E*₁, c_T = S_TT/μ₁,
//! c± = (c_L ± c_T)/2) and q_x + i q_y = f(r) + g(r) e^{2iθ} (f = (q_r + q_θ)/2, g =
//! (q_r − q_θ)/2 for the first angular harmonic), the 2-D Fourier transform gives
//!
//! ```text
//!   u(r) = ∫₀^∞ (c₊F₀ − c₋G₂) J₀(ρr) dρ,   v(r) = ∫₀^∞ (c₊G₂ − c₋F₀) J₂(ρr) dρ,
//! ```
//!
//! u_x + i u_y = u + v e^{2iθ}, with F₀, G₂ the Hankel transforms of f (order 0) and g
//! (order 2); the disc needs u = δ, v = 0 for r < a, and Q = 2πF₀(0). The traction
//! minimises the complementary energy ½∫[c₊(F₀² + G₂²) − 2c₋F₀G₂] dρ − δF₀(0). In the
//! Abel representations F₀ = ∫₀^a φ(t) cos ρt dt and G₂ = ∫₀^a η(t) cos ρt dt (every
//! order-2 transform of a g on the disc is of this form, with ∫₀^a η dt = G₂(0) = 0,
//! from J₂(ρr) = −(2/π)∫₀^r cos(ρt) T₂(t/r)/√(r²−t²) dt), the functions A = φ − η
//! (the L mode) and B = φ + η (the T mode) decouple:
//!
//! ```text
//!   energy = ¼ ∫ [c_L (∫A cos ρt dt)² + c_T (∫B cos ρt dt)²] dρ,   load δF₀(0) = ½δ(∫A + ∫B),
//! ```
//!
//! under the one constraint ∫A = ∫B. Its stationarity conditions are two flat-punch
//! equations, ∫ c_L Â cos ρt dρ = γ_L and ∫ c_T B̂ cos ρt dρ = γ_T on the disc, with
//! γ_L + γ_T = 2δ (the multiplier splits δ between the modes) and ∫A = ∫B fixing the
//! split. With K_L and K_T the punch stiffnesses of the two modes — the normal punch
//! above with k = S_LL − 1 and modulus E*₁, and with k = S_TT − 1 and modulus 2μ₁ —
//!
//! ```text
//!   K_t(a) = Q/δ = 2 K_L K_T/(K_L + K_T),   K_L = 2E*₁ a ψ_LL(a),   K_T = 4μ₁ a ψ_TT(a).
//! ```
//!
//! On a half-space (ψ ≡ 1) this is Mindlin's 8μa/(2−ν); on a thin layer bonded to a
//! rigid base (S_LL → (ρE*₁/2)Σh/μ, S_TT → ρμ₁Σh/μ) both punches tend to the slab's
//! πa²/Σ(hᵢ/μᵢ), and so does K_t. The reduction is exact for the uncoupled problem
//! (it replaces the 2×2 system of the first angular harmonic by two scalar Fredholm
//! equations of the normal solver's form, and Mindlin's η = 0 is its half-space
//! case); the tests check it against an independent Ritz solution of the coupled
//! (f, g) problem in physical variables, with the half-space integrals in closed form
//! (Weber–Schafheitlin) and no Abel step.
//!
//! # Discretisation
//! Each ψ as the spot solver's ([`crate::spot`]): Gauss–Legendre Nyström with
//! 16 + 8⌈a/h₁⌉ nodes up to a/h₁ = 4, product integration beyond (the kernel's width is
//! ~h₁/a), Richardson-extrapolated, the grid doubled from N = 2a/h₁ (256 … 2048) while
//! two successive extrapolations differ by more than [`REFINE_TOL`] (up to
//! [`MAX_INTERVALS`]). The three kernels share one u-rule ([`KzQuadrature`]), graded
//! down to u = 0.25/(H·c) with H the total depth and c the largest modulus contrast of
//! the stack (≤ 1e12): a stiff skin on a soft body carries shear as a membrane over c
//! times its thickness. With a counterface the moduli are the pair's (E*, μ*) and the
//! compliances the pair's (physics.md §6.1).

use rayon::prelude::*;
use strata_runtime::compliance::tangential::TangentialCompliance;
use strata_runtime::{Base, Compliance, Solid, Stack};
use thiserror::Error;

use crate::asperity::Method;
use crate::fredholm::{Discretisation, FredholmError};
use crate::kernel::{KernelError, KzQuadrature};

/// The discretisation's limits are the spot solver's (the same kernel shape, the same
/// Fredholm machinery): Nyström up to a/h₁ = [`NYSTROM_MAX_A_OVER_H`], the rule graded for
/// contrasts up to [`MAX_GRADED_CONTRAST`] (here of Young moduli).
pub use crate::spot::{MAX_GRADED_CONTRAST, NYSTROM_MAX_A_OVER_H};

/// Automatic product grids are doubled while two successive Richardson extrapolations
/// differ (relative, in ψ and φ(1)) by more than this (the spot solver's).
pub const REFINE_TOL: f64 = crate::spot::SPOT_REFINE_TOL;

/// The largest automatic product grid (intervals; the dense system takes 134 MB).
pub const MAX_INTERVALS: usize = crate::spot::SPOT_MAX_INTERVALS;

/// Errors of the stiffness solver.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum StiffnessError {
    /// The disc radius must be positive and finite.
    #[error("disc radius a = {0} m: must be positive and finite")]
    BadRadius(f64),
    #[error(transparent)]
    Kernel(#[from] KernelError),
    #[error(transparent)]
    Fredholm(#[from] FredholmError),
    /// A punch factor came out non-finite or not positive.
    #[error("the {which} punch factor at a = {a} m came out as {psi}")]
    NonFinite {
        which: &'static str,
        a: f64,
        psi: f64,
    },
}

pub use strata_runtime::disc_stiffness::{DiscStiffness, PunchFactors, harmonic_mean};

/// The disc-stiffness solver of one stack (module docs).
#[derive(Debug, Clone)]
pub struct Stiffness {
    comp: Compliance,
    tc: TangentialCompliance,
    h1: Option<f64>,
    u_first: f64,
    e_star: f64,
    mu_star: f64,
    method: Method,
    key: u64,
}

/// The largest ratio of two Young moduli in the stack (and its counterface), ≥ 1.
fn modulus_contrast<S: Solid + ?Sized>(stack: &S) -> f64 {
    let mut e = Vec::new();
    let mut eat = |s: &Stack| {
        e.extend(s.layers().iter().map(|l| l.young));
        if let Base::Elastic { young, .. } = s.base() {
            e.push(young);
        }
    };
    eat(stack.first());
    if let Some(c) = stack.elastic_counterface() {
        eat(c);
    }
    let hi = e.iter().copied().fold(f64::MIN, f64::max);
    let lo = e.iter().copied().fold(f64::MAX, f64::min);
    if lo > 0.0 && hi >= lo {
        (hi / lo).min(MAX_GRADED_CONTRAST)
    } else {
        1.0
    }
}

impl Stiffness {
    /// Prepares the solver for `stack` (with its counterface, if any).
    pub fn new<S: Solid + ?Sized>(stack: &S) -> Stiffness {
        let tc = TangentialCompliance::new(stack);
        Stiffness {
            comp: Compliance::new(stack),
            h1: stack.top_thickness(),
            u_first: 0.25 / (stack.total_thickness() * modulus_contrast(stack)),
            e_star: tc.plane_strain_modulus(),
            mu_star: tc.shear_modulus(),
            tc,
            method: Method::Auto,
            key: strata_runtime::disc_stiffness::fingerprint(stack),
        }
    }

    /// Uses `method` instead of [`Method::Auto`] (builder style; for checks).
    pub fn with_method(mut self, method: Method) -> Stiffness {
        self.method = method;
        self
    }

    /// E*₁ (Pa; E* of a pair) that scales K_n and K_L.
    pub fn plane_strain_modulus(&self) -> f64 {
        self.e_star
    }

    /// μ₁ (Pa; μ* of a pair) that scales K_T.
    pub fn shear_modulus(&self) -> f64 {
        self.mu_star
    }

    /// The top layer's thickness h₁ (m); None on a half-space.
    pub fn top_thickness(&self) -> Option<f64> {
        self.h1
    }

    /// The stack's fingerprint ([`strata_runtime::disc_stiffness::fingerprint`]): what
    /// names its table in the table cache.
    pub fn fingerprint(&self) -> u64 {
        self.key
    }

    /// The tangential compliance the solver uses.
    pub fn compliance(&self) -> &TangentialCompliance {
        &self.tc
    }

    /// The discretisation used at radius `a` (m).
    pub fn discretisation(&self, a: f64) -> Discretisation {
        crate::spot::discretisation_for(self.method, a, self.h1)
    }

    /// The three kernels' rules at radius `a`: one set of nodes (reaching the largest
    /// |k(0)|'s tail), k_z, S_LL − 1 and S_TT − 1 at them.
    fn rules(&self, h1: f64, a: f64) -> Result<[KzQuadrature; 3], StiffnessError> {
        let z = self.tc.at_zero();
        let k0 = [self.comp.s_at_zero() - 1.0, z.s_ll - 1.0, z.s_tt - 1.0];
        let big = k0.iter().copied().fold(0.0f64, |m, v| m.max(v.abs()));
        let comp = &self.comp;
        let q = KzQuadrature::for_kernel(h1, self.u_first, big, 2.0 * a, |u| comp.kz(u))?;
        let lt: Vec<(f64, f64)> =
            q.u.par_iter()
                .map(|&u| {
                    let c = self.tc.eval(u);
                    (c.s_ll - 1.0, c.s_tt - 1.0)
                })
                .collect();
        if let Some(k) = lt
            .iter()
            .position(|(l, t)| !(l.is_finite() && t.is_finite()))
        {
            return Err(KernelError::NonFinite { u: q.u[k] }.into());
        }
        let mut ql = q.clone();
        ql.kz = lt.iter().map(|v| v.0).collect();
        ql.kz0 = k0[1];
        let mut qt = q.clone();
        qt.kz = lt.iter().map(|v| v.1).collect();
        qt.kz0 = k0[2];
        let mut qz = q;
        qz.kz0 = k0[0];
        Ok([qz, ql, qt])
    }

    /// ψ = ∫₀¹ φ of the punch equation φ + K_a φ = 1 on the rule `quad`.
    fn psi(&self, quad: &KzQuadrature, a: f64, which: &'static str) -> Result<f64, StiffnessError> {
        let psi = crate::spot::punch_integral(quad, a, self.method, self.h1)?;
        if !(psi.is_finite() && psi > 0.0) {
            return Err(StiffnessError::NonFinite { which, a, psi });
        }
        Ok(psi)
    }

    /// The punch factors ψ_zz, ψ_LL, ψ_TT at radius `a` (m).
    pub fn factors(&self, a: f64) -> Result<PunchFactors, StiffnessError> {
        if !(a.is_finite() && a > 0.0) {
            return Err(StiffnessError::BadRadius(a));
        }
        let Some(h1) = self.h1 else {
            // A half-space (or two): k ≡ 0, ψ ≡ 1.
            return Ok(PunchFactors::HALF_SPACE);
        };
        let [qz, ql, qt] = self.rules(h1, a)?;
        Ok(PunchFactors {
            normal: self.psi(&qz, a, "normal")?,
            along: self.psi(&ql, a, "in-plane (S_LL)")?,
            across: self.psi(&qt, a, "antiplane (S_TT)")?,
        })
    }

    /// K_n and K_t from the punch factors at radius `a` (m).
    pub fn from_factors(&self, a: f64, psi: PunchFactors) -> DiscStiffness {
        strata_runtime::disc_stiffness::disc_stiffness(a, psi, self.e_star, self.mu_star)
    }

    /// The normal and tangential stiffness of the disc of radius `a` (m).
    pub fn at(&self, a: f64) -> Result<DiscStiffness, StiffnessError> {
        Ok(self.from_factors(a, self.factors(a)?))
    }
}

#[cfg(test)]
mod reference;
#[cfg(test)]
mod tests;
