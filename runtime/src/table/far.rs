//! The far field of g (physics.md §4): the asymptotic expansion of
//!
//! ```text
//!   g(a, r) = 4 ∫₀^∞ k_z(ρ) J₀(ρr) (sin aρ − aρ cos aρ)/ρ³ dρ          (m², Appendix C)
//! ```
//!
//! for r − a ≫ H (H the depth of the layers). Only small ρ matters there. k_z is
//! analytic at ρ = 0 (an elastic base's impedance is linear in ρ, the layers' transfer
//! matrices are entire in ρ), so k_z(ρ) = Σ k_n ρⁿ near 0, and since ρ² J₀(ρr) =
//! −Δ_r J₀(ρr) (Δ_r = ∂²_r + r⁻¹∂_r, the 2-D radial Laplacian), every even power
//! contributes a Laplacian of the half-space bracket HS, while odd powers contribute
//! nothing to any order in 1/r (∫₀^∞ ρ^{2m+1} J₀(ρr) cos(bρ) dρ = 0 for r > b):
//!
//! ```text
//!   g(a, r) ≈ Σ_{m=0}^{M} k_{2m} Φ_m(a, r),     Φ_m = (−Δ_r)^m HS(a, r)
//!   Φ₀ = HS = (2a² − r²) asin(a/r) + a √(r² − a²)        → (4/3) a³/r
//!   Φ₁ = 4 [asin(a/r) − a/√(r² − a²)]                    → −(4/3) a³/r³
//!   Φ₂ = 12 a³ / (r² − a²)^{5/2}
//!   Φ_m = a³ Σ_k β_{m,k} a^{2k} (r² − a²)^{−(2m+1+2k)/2}   (m ≥ 2; recurrence below)
//! ```
//!
//! The relative size of term m is ~ k_{2m}/(r(r − a))^m: the series is asymptotic in
//! H/(r − a). On a rigid base S(ρ) is odd in ρ (the compliance of a finite stack is an
//! even analytic function of ρ, S = E*₁ρ/2 × compliance), so k_{2m} = 0 for m ≥ 1 and
//! the first term k_z(0)·HS is exact up to exponentially small terms; on an elastic
//! base the even coefficients are not zero and the first term alone is off by
//! ~k₂/r² (9 % of (4/3)a³/r at r − a = 20H for a 10 MPa layer on a 2 MPa base).
//!
//! The even Taylor coefficients k_{2m} are computed from S(ρ) on ρ > 0 by Chebyshev
//! interpolation on [0, U] and differentiation at the end point ([`even_taylor`]);
//! U shrinks until the interpolant has converged, so k_z must be analytic only on a
//! neighbourhood of [0, U].

use crate::compliance::Compliance;

/// Number of even Taylor coefficients beyond k_z(0) used by [`FarField`]
/// (terms Φ₁ … Φ_M).
pub const FAR_TERMS: usize = 3;

/// The half-space part of the outside-displacement bracket (physics.md §4),
/// HS(a, r) = (2a² − r²) asin(a/r) + a √(r² − a²) (m²) for r ≥ a, → (4/3) a³/r for
/// r ≫ a; the series Σ_j c_j a^{2j+3} r^{−2j−1} below a/r = 0.3 (no cancellation).
pub fn half_space_bracket(a: f64, r: f64) -> f64 {
    let q = (a / r).min(1.0);
    if q < SERIES_Q {
        return series(a, r, 0);
    }
    (2.0 * a * a - r * r) * q.asin() + a * (r * r - a * a).max(0.0).sqrt()
}

/// Below this a/r the Laplacian terms are summed from their series.
const SERIES_Q: f64 = 0.3;

/// Φ_m(a, r) = (−Δ_r)^m HS(a, r) as the series
/// (−1)^m Σ_j c_j Π_{i<m} (2j+2i+1)² a^{2j+3} r^{−2j−2m−1}, with the coefficients
/// c_j = 4 C(2j, j)/(4^j (2j+1)(2j+3)) of HS (Δ_r r^{−n} = n² r^{−n−2}). For
/// a/r < 0.3 it converges to round-off in < 40 terms.
fn series(a: f64, r: f64, m: usize) -> f64 {
    let q2 = (a / r) * (a / r);
    let mut cj = 4.0 / 3.0; // c_0
    let mut pow = a * a * a / r.powi(2 * m as i32 + 1);
    let mut sum = 0.0;
    for j in 0..60 {
        let jf = j as f64;
        let mut f = cj;
        for i in 0..m {
            let n = 2.0 * jf + 2.0 * i as f64 + 1.0;
            f *= n * n;
        }
        let term = f * pow;
        sum += term;
        if term.abs() <= 1e-17 * sum.abs() {
            break;
        }
        // c_{j+1}/c_j = (2j+1)(2j+2)/(4(j+1)²) · (2j+1)(2j+3)/((2j+3)(2j+5))
        cj *= (2.0 * jf + 1.0) / (2.0 * jf + 2.0) * (2.0 * jf + 1.0) / (2.0 * jf + 5.0);
        pow *= q2;
    }
    if m % 2 == 1 { -sum } else { sum }
}

/// Φ_m(a, r) = (−Δ_r)^m HS(a, r) (m², r > a; module docs). Φ_m for m ≥ 1 diverges
/// like (r − a)^{−(2m−1)/2}·… as r → a: use it only well outside the contact.
pub fn laplacian_term(a: f64, r: f64, m: usize) -> f64 {
    let q = a / r;
    if m == 0 {
        return half_space_bracket(a, r);
    }
    if q < SERIES_Q {
        return series(a, r, m);
    }
    let s2 = (r - a) * (r + a);
    let s = s2.sqrt();
    if m == 1 {
        return 4.0 * (q.min(1.0).asin() - a / s);
    }
    // Φ₂ = 12 a³ S⁻⁵; −Δ_r S^{−n} = −n² S^{−n−2} − n(n+2) a² S^{−n−4} (S² = r² − a²).
    let mut beta = vec![12.0];
    for mm in 2..m {
        let mut next = vec![0.0; beta.len() + 1];
        for (k, b) in beta.iter().enumerate() {
            let n = (2 * mm + 1 + 2 * k) as f64;
            next[k] -= n * n * b;
            next[k + 1] -= n * (n + 2.0) * b;
        }
        beta = next;
    }
    let (a2s2, mut p) = (a * a / s2, a * a * a / s.powi(2 * m as i32 + 1));
    let mut v = 0.0;
    for b in beta {
        v += b * p;
        p *= a2s2;
    }
    v
}

/// The far-field expansion of g of one stack: k_z(0) and the even Taylor
/// coefficients k₂, k₄, … of k_z at ρ = 0 (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct FarField {
    /// [k_z(0), k₂ (m²), k₄ (m⁴), …].
    pub coeffs: Vec<f64>,
}

impl FarField {
    /// The leading term only, g ≈ k_z(0)·HS (exact on a rigid base).
    pub fn leading(k0: f64) -> Self {
        FarField { coeffs: vec![k0] }
    }

    /// The expansion with [`FAR_TERMS`] correction terms for a stack, from its
    /// compliance; `depth` is the total layer depth H (m), the scale of k_z.
    pub fn new(comp: &Compliance, depth: f64) -> Self {
        let k0 = comp.s_at_zero() - 1.0;
        let mut coeffs = vec![k0];
        match even_taylor(&|u| comp.kz(u), k0, depth, FAR_TERMS) {
            Some(k) => coeffs.extend(k),
            None => coeffs.extend(std::iter::repeat_n(0.0, FAR_TERMS)),
        }
        FarField { coeffs }
    }

    /// k_z(0).
    pub fn k0(&self) -> f64 {
        self.coeffs.first().copied().unwrap_or(0.0)
    }

    /// g(a, r) ≈ Σ_m k_{2m} Φ_m(a, r) (m², r > a, r − a ≫ H).
    pub fn g(&self, a: f64, r: f64) -> f64 {
        self.coeffs
            .iter()
            .enumerate()
            .filter(|&(m, k)| m == 0 || *k != 0.0)
            .map(|(m, k)| k * laplacian_term(a, r, m))
            .sum()
    }
}

/// Even Taylor coefficients [k₂, k₄, …, k_{2M}] of f at u = 0 (f(0) = `f0` exactly),
/// from Chebyshev–Lobatto interpolation of degree N = 20 on [0, U], U = 1/H first
/// and halved until the last Chebyshev coefficients fall below 1e-13 of the largest.
/// Derivatives at the end point u = 0 amplify round-off by
/// T_N^{(n)}(1) = Π_{l<n}(N²−l²)/(2l+1), so the degree is kept low: k₂, k₄, k₆ come
/// out to ~1e-10, 1e-8, 1e-6 relative for smooth f (tests; degree 32 gave 1e-2 on
/// k₆). `None` when f is not resolved on any interval down to U = 1e-6/H.
pub fn even_taylor(f: &dyn Fn(f64) -> f64, f0: f64, depth: f64, m: usize) -> Option<Vec<f64>> {
    const N: usize = 20;
    let mut u_max = 1.0 / depth;
    for _ in 0..20 {
        let vals: Vec<f64> = (0..=N)
            .map(|j| {
                // x_j = cos(πj/N) ∈ [−1, 1] ↦ u = U(1 + x)/2; j = N is u = 0.
                let x = (std::f64::consts::PI * j as f64 / N as f64).cos();
                if j == N {
                    f0
                } else {
                    f(0.5 * u_max * (1.0 + x))
                }
            })
            .collect();
        if vals.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let cheb: Vec<f64> = (0..=N)
            .map(|k| {
                let s: f64 = vals
                    .iter()
                    .enumerate()
                    .map(|(j, v)| {
                        let half = if j == 0 || j == N { 0.5 } else { 1.0 };
                        half * v * (std::f64::consts::PI * (j * k) as f64 / N as f64).cos()
                    })
                    .sum();
                let half = if k == 0 || k == N { 0.5 } else { 1.0 };
                2.0 / N as f64 * half * s
            })
            .collect();
        let big = cheb.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        let tail = cheb[N - 3..].iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        if tail <= 1e-13 * big.max(f0.abs()) {
            let mut out = Vec::with_capacity(m);
            for order in (2..=2 * m).step_by(2) {
                // d^n T_k/dx^n at x = −1: (−1)^{k+n} Π_{l<n} (k² − l²)/(2l + 1).
                let mut d = 0.0;
                for (k, c) in cheb.iter().enumerate() {
                    let mut t = if (k + order) % 2 == 0 { 1.0 } else { -1.0 };
                    for l in 0..order {
                        t *= ((k * k) as f64 - (l * l) as f64) / (2 * l + 1) as f64;
                    }
                    d += c * t;
                }
                let mut fact = 1.0;
                for i in 1..=order {
                    fact *= i as f64;
                }
                out.push(d * (2.0 / u_max).powi(order as i32) / fact);
            }
            return Some(out);
        }
        u_max *= 0.5;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Φ_m by series and closed forms agree at the switch; Φ₁ = −Δ Φ₀ and
    /// Φ₂ = −Δ Φ₁ by finite differences of the 2-D radial Laplacian.
    #[test]
    fn laplacian_terms_are_consistent() {
        let a = 1.0;
        for m in 0..5 {
            let r = a / SERIES_Q;
            let (s, c) = (series(a, r * (1.0 + 1e-12), m), laplacian_term(a, r, m));
            assert!((s / c - 1.0).abs() < 1e-9, "m {m}: {s} {c}");
        }
        for r in [1.2, 2.5, 4.0, 10.0] {
            for m in 0..4 {
                let h = 2e-4 * r;
                let f = |x: f64| laplacian_term(a, x, m);
                let lap = (f(r + h) - 2.0 * f(r) + f(r - h)) / (h * h)
                    + (f(r + h) - f(r - h)) / (2.0 * h * r);
                let next = laplacian_term(a, r, m + 1);
                // Central differences: O(h²·Φ'''') ≲ 1e-4 relative next to r = a.
                assert!(
                    (-lap - next).abs() < 1e-4 * next.abs().max(f(r).abs() / (r * r)),
                    "m {m} r {r}: {} vs {next}",
                    -lap
                );
            }
        }
        // Leading behaviour far away: Φ_m → (−1)^m (4/3)·1²·3²…(2m−1)² a³/r^{2m+1}.
        let r = 1e4;
        let expect = [4.0 / 3.0, -4.0 / 3.0, 12.0, -300.0];
        for (m, e) in expect.iter().enumerate() {
            let v = laplacian_term(a, r, m) * r.powi(2 * m as i32 + 1);
            assert!((v / e - 1.0).abs() < 1e-7, "m {m}: {v}");
        }
    }

    /// Taylor coefficients of known functions: exp (all orders) and an odd function
    /// plus a constant (even coefficients zero).
    #[test]
    fn even_taylor_of_known_functions() {
        let k = even_taylor(&|u| (-2.0 * u).exp(), 1.0, 1.0, 3).unwrap();
        let exact = [2.0, 2.0 / 3.0, 4.0 / 45.0]; // 2^n/n!, n = 2, 4, 6
        for (v, e, tol) in [
            (k[0], exact[0], 1e-9),
            (k[1], exact[1], 1e-7),
            (k[2], exact[2], 1e-5),
        ] {
            assert!((v / e - 1.0).abs() < tol, "{k:?}");
        }
        let k = even_taylor(&|u| -1.0 + u.tanh(), -1.0, 1.0, 3).unwrap();
        for (v, tol) in k.iter().zip([1e-9, 1e-7, 1e-5]) {
            assert!(v.abs() < tol, "{k:?}");
        }
    }
}
