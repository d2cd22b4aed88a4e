//! The full surface compliance of a layered elastic solid: normal, tangential and
//! their coupling (the paper's flexibility matrix F of eq. 5, Appendix B, beyond its
//! F11).
//!
//! For a surface traction that varies as e^{iρ·x} (complex amplitudes; q_L along the
//! wavevector, q_T across it, p compressive; z and w point into the solid), the surface
//! displacement is
//!
//! ```text
//!   u_L = (2/(E*₁ρ)) (S_LL q_L + i S_zL p),
//!   w   = (2/(E*₁ρ)) (−i S_zL q_L + S_zz p),
//!   u_T = S_TT q_T / (μ₁ρ),
//! ```
//!
//! with E*₁ = E₁/(1−ν₁²) and μ₁ = E₁/(2(1+ν₁)) of the top material (Pa) and ρ in 1/m.
//! The four S are dimensionless and normalised so that a half-space of the top material
//! has S_zz = S_LL = S_TT = 1 and S_zL = β₁ = (1−2ν₁)/(2(1−ν₁)) (Dundurs' β of the body
//! against a rigid flat); they tend to these values as ρh₁ → ∞. S_zz is the normal
//! compliance S = 1 + k_z of [`super::Compliance`], computed by the same operations (the
//! same bits). In the paper's terms S_zz = αF11, and S_LL, S_zL are F22 and F12 = F21
//! (the 2×2 block of the in-plane P-SV mode is symmetric: Betti's reciprocity), S_TT is
//! F33 (the antiplane SH mode), each rescaled to the normalisation above.
//!
//! # Method
//! **P-SV** (S_zz, S_LL, S_zL): the scaled surface impedance Ẑ of the module above,
//! `[T/μ₁, S/μ₁] = Ẑ [ρU, ρW]` with u_x = iU e^{iρx}, u_z = W e^{iρx}, σ_xz = iT e^{iρx},
//! σ_zz = S e^{iρx} (physics.md §2.1), carried up from the base by the same bounded
//! transfer matrices, thick-layer cut and sublayer splitting. A traction q_L, p is
//! T = i q_L, S = −p at z = 0, so with Ĝ = Ẑ⁻¹ (rows U, W; columns T, S):
//!
//! ```text
//!   S_zz = −Ĝ_WS/(1−ν₁),   S_LL = −Ĝ_UT/(1−ν₁),   S_zL = −Ĝ_US/(1−ν₁) (= −Ĝ_WT/(1−ν₁)).
//! ```
//!
//! **SH** (S_TT): u_y = V e^{iρx} obeys V″ = ρ²V in each layer, the scalar counterpart
//! of conduction (physics.md §6.2 with μ for the conductivity): with t = tanh(ρhᵢ),
//! ζ_top,i = (ζ_bot,i + t)/(1 + ζ_bot,i t), ζ_bot,i = ζ_top,i+1·μᵢ/μᵢ₊₁,
//! ζ_bot,N = μ_N/μ_b on an elastic base and 0 on a rigid one, S_TT = ζ_top,1. Every
//! quantity is bounded (no overflow at any ρh); ζ − 1 is carried beside ζ so that
//! identical layers give S_TT = 1 exactly.
//!
//! # Limits
//! ρ → 0 on an elastic base (E*_b, μ_b, ν_b): S_zz, S_LL → E*₁/E*_b, S_TT → μ₁/μ_b,
//! S_zL → (E*₁/E*_b)β_b. On a rigid base all four vanish: a thin stack shears and
//! compresses as a slab, u = q Σhᵢ/μᵢ and w = p Σhᵢ/Mᵢ with
//! M = E(1−ν)/((1+ν)(1−2ν)), so S_LL → (ρE*₁/2)Σhᵢ/μᵢ, S_zz → (ρE*₁/2)Σhᵢ/Mᵢ,
//! S_TT → ρμ₁Σhᵢ/μᵢ and, for one layer, S_zL → (ρh)²(1−4ν)/(4(1−ν)²).
//!
//! # Two bodies
//! Against an elastic counterface B the relative displacements of the two surfaces add
//! (each body in its own frame, z into it, with the traction on B opposite to that on
//! the stack A in the plane): with 1/E* = 1/E*₁,A + 1/E*₁,B and 1/μ* = 1/μ₁,A + 1/μ₁,B,
//!
//! ```text
//!   S_zz = w S_zz,A + (1−w) S_zz,B,   S_LL = w S_LL,A + (1−w) S_LL,B,   w = E*/E*₁,A,
//!   S_TT = w_T S_TT,A + (1−w_T) S_TT,B,                                 w_T = μ*/μ₁,A,
//!   S_zL = w S_zL,A − w_B S_zL,B,                                       w_B = E*/E*₁,B,
//! ```
//!
//! normalised by E* and μ* in place of E*₁ and μ₁. The coupling is the difference of the
//! bodies' couplings (for two half-spaces it is Dundurs' β, with the sign of the stack
//! A): it vanishes between identical bodies, exactly. It is odd under swapping the
//! bodies (the frame is the stack's); S_zz, S_LL and S_TT are symmetric, bit for bit.

use super::{Body, SMALL_T};
use crate::stack::{Base, Solid, Stack, plane_strain_modulus, shear_modulus};

/// The four normalised compliances at one wavenumber (dimensionless; module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compliances {
    /// Normal: w per p, S_zz = 1 + k_z.
    pub s_zz: f64,
    /// In-plane along the wavevector: u_L per q_L.
    pub s_ll: f64,
    /// Antiplane, across the wavevector: u_T per q_T (normalised by μ₁, not E*₁/2).
    pub s_tt: f64,
    /// Normal–tangential coupling: u_L per p and −w per q_L, times i (module docs).
    pub s_zl: f64,
}

/// Precomputed S_zz, S_LL, S_TT, S_zL of a stack, or of a stack and its counterface.
#[derive(Debug, Clone)]
pub struct TangentialCompliance {
    /// The first body of the canonical order (physics.md §6.1).
    a: Side,
    /// The other body with (w, 1 − w is implied, w_B, w_T) and the sign of S_zL: +1
    /// when the stack itself is `a`, −1 when the canonical order swapped the bodies.
    b: Option<Pair>,
    /// E*₁ (Pa), or E* of the pair.
    e_star: f64,
    /// μ₁ (Pa), or μ* of the pair.
    mu_star: f64,
}

#[derive(Debug, Clone)]
struct Pair {
    side: Side,
    w: f64,
    w_b: f64,
    w_t: f64,
    zl_sign: f64,
}

/// One body: its P-SV impedance constants, its SH chain and its ρ → 0 values.
#[derive(Debug, Clone)]
struct Side {
    body: Body,
    sh: ShChain,
    zero: Compliances,
    /// β₁ = (1−2ν₁)/(2(1−ν₁)), S_zL at ρ = ∞.
    beta1: f64,
}

/// The SH chain of one body: (hᵢ, μᵢ/μᵢ₊₁) per layer, top first, the last ratio
/// μ_N/μ_b on an elastic base (unused on a rigid one).
#[derive(Debug, Clone)]
struct ShChain {
    layers: Vec<(f64, f64)>,
    rigid: bool,
}

impl TangentialCompliance {
    /// Precomputes the constants of a solid (one stack, or the two [`crate::Bodies`]).
    pub fn new<S: Solid + ?Sized>(stack: &S) -> Self {
        match stack.canonical_pair() {
            None => TangentialCompliance {
                a: Side::new(stack.first()),
                b: None,
                e_star: stack.first().top_plane_strain_modulus(),
                mu_star: top_shear_modulus(stack.first()),
            },
            Some((a, b)) => {
                let e_star = stack.contact_modulus();
                let (mu_a, mu_b) = (top_shear_modulus(&a), top_shear_modulus(&b));
                let mu_star = 1.0 / (1.0 / mu_a + 1.0 / mu_b);
                // The stack is `a` unless the canonical order swapped the bodies; two
                // bodies of the same mechanics give S_zL = 0 either way.
                let own_first =
                    a.layers() == stack.first().layers() && a.base() == stack.first().base();
                let zl_sign = if own_first { 1.0 } else { -1.0 };
                TangentialCompliance {
                    b: Some(Pair {
                        side: Side::new(&b),
                        w: e_star / a.top_plane_strain_modulus(),
                        w_b: e_star / b.top_plane_strain_modulus(),
                        w_t: mu_star / mu_a,
                        zl_sign,
                    }),
                    a: Side::new(&a),
                    e_star,
                    mu_star,
                }
            }
        }
    }

    /// The modulus E*₁ (Pa) that normalises S_zz, S_LL, S_zL: the top material's, or E*
    /// of the pair (1/E* = 1/E*₁,A + 1/E*₁,B).
    pub fn plane_strain_modulus(&self) -> f64 {
        self.e_star
    }

    /// The modulus μ₁ (Pa) that normalises S_TT: the top material's shear modulus, or μ*
    /// of the pair (1/μ* = 1/μ₁,A + 1/μ₁,B).
    pub fn shear_modulus(&self) -> f64 {
        self.mu_star
    }

    /// The four compliances at ρ → 0 (module docs, Limits).
    pub fn at_zero(&self) -> Compliances {
        self.combine(self.a.zero, self.b.as_ref().map(|p| p.side.zero))
    }

    /// S_zz, S_LL, S_TT, S_zL at the wavenumber ρ (1/m; even in ρ, finite for every
    /// ρ ≥ 0 including 0 and ∞).
    pub fn eval(&self, rho: f64) -> Compliances {
        self.combine(self.a.eval(rho), self.b.as_ref().map(|p| p.side.eval(rho)))
    }

    fn combine(&self, a: Compliances, b: Option<Compliances>) -> Compliances {
        match (b, &self.b) {
            (Some(b), Some(p)) => Compliances {
                s_zz: p.w * a.s_zz + (1.0 - p.w) * b.s_zz,
                s_ll: p.w * a.s_ll + (1.0 - p.w) * b.s_ll,
                s_tt: p.w_t * a.s_tt + (1.0 - p.w_t) * b.s_tt,
                s_zl: p.zl_sign * (p.w * a.s_zl - p.w_b * b.s_zl),
            },
            _ => a,
        }
    }
}

/// μ₁ of the top material (Pa).
fn top_shear_modulus(stack: &Stack) -> f64 {
    let (e, nu) = stack.top_material();
    shear_modulus(e, nu)
}

/// β = (1−2ν)/(2(1−ν)).
fn beta(nu: f64) -> f64 {
    (1.0 - 2.0 * nu) / (2.0 * (1.0 - nu))
}

impl Side {
    fn new(stack: &Stack) -> Self {
        let body = Body::new(stack);
        let ls = stack.layers();
        let mu: Vec<f64> = ls
            .iter()
            .map(|l| shear_modulus(l.young, l.poisson))
            .collect();
        let (zero, mu_b) = match stack.base() {
            Base::Rigid => (
                Compliances {
                    s_zz: 0.0,
                    s_ll: 0.0,
                    s_tt: 0.0,
                    s_zl: 0.0,
                },
                f64::NAN,
            ),
            Base::Elastic { young, poisson } => {
                let r = stack.top_plane_strain_modulus() / plane_strain_modulus(young, poisson);
                let mu_b = shear_modulus(young, poisson);
                (
                    Compliances {
                        s_zz: body.s0,
                        s_ll: r,
                        s_tt: top_shear_modulus(stack) / mu_b,
                        s_zl: r * beta(poisson),
                    },
                    mu_b,
                )
            }
        };
        let layers = ls
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let below = if i + 1 < ls.len() { mu[i + 1] } else { mu_b };
                (l.thickness, mu[i] / below)
            })
            .collect();
        let beta1 = beta(body.nu1);
        Side {
            body,
            sh: ShChain {
                layers,
                rigid: matches!(stack.base(), Base::Rigid),
            },
            zero,
            beta1,
        }
    }

    fn eval(&self, rho: f64) -> Compliances {
        let rho = rho.abs();
        let s_tt = self.sh.s(rho);
        let (s_zz, s_ll, s_zl) = self.psv(rho);
        Compliances {
            s_zz,
            s_ll,
            s_tt,
            s_zl,
        }
    }

    /// (S_zz, S_LL, S_zL) of the P-SV mode, ρ ≥ 0.
    fn psv(&self, rho: f64) -> (f64, f64, f64) {
        let b = &self.body;
        if rho == 0.0 {
            return (self.zero.s_zz, self.zero.s_ll, self.zero.s_zl);
        }
        if rho.is_infinite() {
            return (1.0, 1.0, self.beta1);
        }
        if rho * b.h_min < SMALL_T {
            // Linear in ρ from ρ = 0 to ρ₁ (see Body::s); S_zL on a rigid base is
            // O(ρ²) there and its value below ρ₁h ≈ 1e−60 is only bounded (|·| < ρ₁h).
            let r1 = 2.0 * SMALL_T / b.h_min;
            let (_, ll1, zl1) = self.psv(r1);
            let f = rho / r1;
            return (
                b.s(rho),
                self.zero.s_ll + (ll1 - self.zero.s_ll) * f,
                self.zero.s_zl + (zl1 - self.zero.s_zl) * f,
            );
        }
        let z = b.impedance(rho);
        let det = z[0][0] * z[1][1] - z[0][1] * z[1][0];
        let q = 1.0 - b.nu1;
        // Ĝ = Ẑ⁻¹ = [[z11, −z01], [−z10, z00]]/det; the S_zz line is Body::s's.
        let inv_ws = z[0][0] / det;
        let s_zz = -inv_ws / q;
        let s_ll = -(z[1][1] / det) / q;
        let s_zl = (z[0][1] / det) / q;
        (s_zz, s_ll, s_zl)
    }

    /// −Ĝ_WT/(1−ν₁): the coupling from the other off-diagonal entry (equal to S_zL by
    /// reciprocity; for the symmetry test).
    #[cfg(test)]
    fn s_zl_transpose(&self, rho: f64) -> f64 {
        let z = self.body.impedance(rho);
        let det = z[0][0] * z[1][1] - z[0][1] * z[1][0];
        (z[1][0] / det) / (1.0 - self.body.nu1)
    }
}

impl ShChain {
    /// S_TT = ζ_top,1 by the bounded recursion of the module docs, ρ ≥ 0.
    fn s(&self, rho: f64) -> f64 {
        let n = self.layers.len();
        if n == 0 || rho.is_infinite() {
            return 1.0;
        }
        let (mut z, mut d) = if self.rigid {
            (0.0, -1.0)
        } else {
            let r = self.layers[n - 1].1;
            (r, r - 1.0)
        };
        for i in (0..n).rev() {
            let (h, r) = self.layers[i];
            if i + 1 < n {
                // ζ_bot,i = ζ_top,i+1 · μᵢ/μᵢ₊₁.
                z *= r;
                d = d * r + (r - 1.0);
            }
            let x = rho * h;
            let e = (-2.0 * x).exp();
            let t = -(-2.0 * x).exp_m1() / (1.0 + e); // tanh x
            let one_minus_t = 2.0 * e / (1.0 + e);
            let den = 1.0 + z * t;
            d = d * one_minus_t / den;
            z = (z + t) / den;
        }
        // ζ from its own form where it is small (positive terms only), else 1 + d.
        if z < 0.5 { z } else { 1.0 + d }
    }
}

#[cfg(test)]
mod tests;
