//! An independent second method for the full-stick disc (tests only): a Ritz solution of
//! the coupled first-harmonic problem in physical variables, without the Abel step and
//! the L/T split of the solver.
//!
//! The traction q_x + i q_y = f(r) + g(r)e^{2iθ} on the disc is expanded in
//!
//! ```text
//!   f_k(s) = (1 − s²)^{k−½},   g_k(s) = s² (1 − s²)^{k−½},   s = r/a,   k = 0 … n−1,
//! ```
//!
//! whose Hankel transforms (orders 0 and 2) are, with x = aρ and up to a constant per
//! function, F̃_k = J_{k+½}(x)/x^{k+½} = √(2/π) j_k(x)/x^k and
//! G̃_k = J_{k+5/2}(x)/x^{k+½} = √(2/π) j_{k+2}(x)/x^k (Sonine's integral; j_n the
//! spherical Bessel functions). The complementary energy
//! ½∫[c₊(F₀² + G₂²) − 2c₋F₀G₂] dρ − δF₀(0) is minimised over the span: E x = b δ,
//! K_t = 2π bᵀE⁻¹b. The half-space part (c± constant) of E is in closed form, the
//! Weber–Schafheitlin integral
//!
//! ```text
//!   ∫₀^∞ J_μ(t) J_ν(t) t^{−λ} dt = Γ(λ) Γ((μ+ν−λ+1)/2)
//!       / [2^λ Γ((−μ+ν+λ+1)/2) Γ((μ+ν+λ+1)/2) Γ((μ−ν+λ+1)/2)],
//! ```
//!
//! (at half-integer and integer arguments: exact products), and the layered part
//! ∫Δc±(ρ) F̃_i F̃_j dρ (Δc± = c± − c±(∞), exponentially small beyond ρh₁ ~ 20) by
//! composite Gauss–Legendre. The Ritz value converges from below (a smaller span
//! stores less energy) and fast while a ≲ a few h₁.

use std::f64::consts::PI;

use faer::Mat;
use faer::linalg::solvers::Solve;
use strata_runtime::Stack;
use strata_runtime::compliance::tangential::TangentialCompliance;

use crate::kernel::gauss_legendre;

/// Γ(m/2) for a positive integer m (exact products of integers and √π).
fn gamma_half(m: u32) -> f64 {
    assert!(m > 0);
    let (mut g, mut x) = if m.is_multiple_of(2) {
        (1.0, 1.0)
    } else {
        (PI.sqrt(), 0.5)
    };
    while 2.0 * x < f64::from(m) - 0.5 {
        g *= x;
        x += 1.0;
    }
    g
}

/// 1/Γ(m/2) for an integer m ≥ 0 (0 at the pole m = 0).
fn rgamma_half(m: i32) -> f64 {
    if m == 0 {
        0.0
    } else {
        1.0 / gamma_half(m as u32)
    }
}

/// ∫₀^∞ J_μ J_ν t^{−λ} dt with μ = mu2/2, ν = nu2/2 (half-integers) and λ an integer.
fn weber_schafheitlin(mu2: i32, nu2: i32, lambda: i32) -> f64 {
    let l2 = 2 * lambda;
    let num = gamma_half(l2 as u32) * gamma_half(((mu2 + nu2 - l2) / 2 + 1) as u32);
    let r1 = rgamma_half((-mu2 + nu2 + l2) / 2 + 1);
    let r2 = rgamma_half((mu2 + nu2 + l2) / 2 + 1);
    let r3 = rgamma_half((mu2 - nu2 + l2) / 2 + 1);
    num * r1 * r2 * r3 / 2f64.powi(lambda)
}

/// t_n(x) = j_n(x)/x^n for n = 0 … n_max: the power series below x = n_max + 1, the
/// upward recurrence (stable for n < x) above.
fn t_values(x: f64, n_max: usize) -> Vec<f64> {
    let mut t = vec![0.0; n_max + 1];
    if x <= (n_max + 1) as f64 {
        let y = -0.5 * x * x;
        for (n, tn) in t.iter_mut().enumerate() {
            // 1/(2n+1)!!
            let mut term = 1.0;
            for k in 0..=n {
                term /= (2 * k + 1) as f64;
            }
            let mut s = term;
            let mut m = 1.0;
            loop {
                term *= y / (m * (2.0 * (n as f64 + m) + 1.0));
                s += term;
                if term.abs() < 1e-18 * s.abs() {
                    break;
                }
                m += 1.0;
            }
            *tn = s;
        }
    } else {
        let (sn, cs) = x.sin_cos();
        let mut jm = sn / x;
        let mut j = sn / (x * x) - cs / x;
        t[0] = jm;
        let mut xp = x;
        if n_max >= 1 {
            t[1] = j / xp;
        }
        for n in 1..n_max {
            let jn = (2 * n + 1) as f64 / x * j - jm;
            jm = j;
            j = jn;
            xp *= x;
            t[n + 1] = j / xp;
        }
    }
    t
}

/// K_t (N/m) of the full-stick disc of radius `a` (m) on `stack` by the Ritz method with
/// `n` functions of each kind (module docs).
pub fn ritz_tangential(stack: &Stack, a: f64, n: usize) -> f64 {
    let tc = TangentialCompliance::new(stack);
    let (e, mu) = (tc.plane_strain_modulus(), tc.shear_modulus());
    let cp = 0.5 * (2.0 / e + 1.0 / mu);
    let cm = 0.5 * (2.0 / e - 1.0 / mu);
    let s2p = (2.0 / PI).sqrt();
    let m = 2 * n;
    let mut mat = Mat::<f64>::zeros(m, m);
    // Half-space part: W(μ, ν, λ) with f: ν = k + ½, g: ν = k + 5/2, λ = i + j + 1.
    for i in 0..n {
        for j in 0..n {
            let lam = (i + j + 1) as i32;
            let (fi, fj) = (2 * i as i32 + 1, 2 * j as i32 + 1);
            let (gi, gj) = (fi + 4, fj + 4);
            mat[(i, j)] = cp * weber_schafheitlin(fi, fj, lam);
            mat[(n + i, n + j)] = cp * weber_schafheitlin(gi, gj, lam);
            mat[(i, n + j)] = -cm * weber_schafheitlin(fi, gj, lam);
            mat[(n + i, j)] = -cm * weber_schafheitlin(gi, fj, lam);
        }
    }
    // Layered part, when there is a layer: a ∫ Δc± F̃F̃ dρ on panels of width
    // min(0.25/h, 1/a) up to 40/h, graded geometrically from 1e-6/h.
    if let Some(h) = stack.top_thickness() {
        let (gx, gw) = gauss_legendre(20);
        let dw = (0.25 / h).min(1.0 / a);
        let mut breaks = vec![0.0, 1e-6 / h];
        while *breaks.last().unwrap() < dw {
            let b = (2.0 * breaks.last().unwrap()).min(dw);
            breaks.push(b);
        }
        while *breaks.last().unwrap() < 40.0 / h {
            breaks.push(breaks.last().unwrap() + dw);
        }
        for p in breaks.windows(2) {
            let (c, hw) = (0.5 * (p[0] + p[1]), 0.5 * (p[1] - p[0]));
            for (x, w) in gx.iter().zip(&gw) {
                let rho = c + hw * x;
                let s = tc.eval(rho);
                let dl = 2.0 * (s.s_ll - 1.0) / e;
                let dt = (s.s_tt - 1.0) / mu;
                let (dp, dm) = (0.5 * (dl + dt), 0.5 * (dl - dt));
                let xa = a * rho;
                let t = t_values(xa, n + 1);
                let f: Vec<f64> = (0..n).map(|k| s2p * t[k]).collect();
                let g: Vec<f64> = (0..n).map(|k| s2p * xa * xa * t[k + 2]).collect();
                let wk = a * hw * w;
                for i in 0..n {
                    for j in 0..n {
                        mat[(i, j)] += wk * dp * f[i] * f[j];
                        mat[(n + i, n + j)] += wk * dp * g[i] * g[j];
                        mat[(i, n + j)] -= wk * dm * f[i] * g[j];
                        mat[(n + i, j)] -= wk * dm * g[i] * f[j];
                    }
                }
            }
        }
    }
    // b_k = F̃_k(0) = √(2/π)/(2k+1)!!.
    let mut b = Mat::<f64>::zeros(m, 1);
    let mut df = 1.0;
    for k in 0..n {
        df *= (2 * k + 1) as f64;
        b[(k, 0)] = s2p / df;
    }
    let x = mat.partial_piv_lu().solve(&b);
    let btx: f64 = (0..m).map(|k| b[(k, 0)] * x[(k, 0)]).sum();
    2.0 * PI * a * btx
}

#[cfg(test)]
mod checks {
    use super::*;

    /// The closed forms the method rests on: Γ at half-integers, the
    /// Weber–Schafheitlin value ∫(sin t/t)² dt = π/2 (as (π/2)·W(½, ½, 1) = π/2), and
    /// t_n from the series and the recurrence on both sides of their switch.
    #[test]
    fn closed_forms() {
        assert!((gamma_half(1) - PI.sqrt()).abs() < 1e-15);
        assert!((gamma_half(7) - 15.0 / 8.0 * PI.sqrt()).abs() < 1e-14);
        assert_eq!(gamma_half(8), 6.0);
        assert!((weber_schafheitlin(1, 1, 1) - 1.0).abs() < 1e-15);
        // j_3(x)/x³ at x = 5: closed form.
        let x: f64 = 5.0;
        let (s, c) = x.sin_cos();
        let j3 = (15.0 / x.powi(3) - 6.0 / x) * s / x - (15.0 / x.powi(2) - 1.0) * c / x;
        let series = t_values(x, 6)[3];
        let rec = t_values(x, 3)[3];
        assert!((series - j3 / x.powi(3)).abs() < 1e-13 * (j3 / x.powi(3)).abs());
        assert!((rec - j3 / x.powi(3)).abs() < 1e-10 * (j3 / x.powi(3)).abs());
    }
}
