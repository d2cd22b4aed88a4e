//! A second method for the layered surface compliance (tests only): the boundary-value
//! problem of all layers solved at once as one dense linear system, from the
//! Papkovich–Neuber solution of Navier's equations rather than from the transfer
//! matrices of the production code.
//!
//! **P-SV.** With B = (0, 0, ψ), ψ = c·e^{iρx+sρζ}, B₀ = φ = d·e^{iρx+sρζ} (s = ±1,
//! ζ the depth below the layer's top), 2μu = 4(1−ν)B − ∇(ζψ + φ) gives, for
//! u_x = iU e^{iρx}, u_z = W e^{iρx}, σ_xz = iT e^{iρx}, σ_zz = S e^{iρx} and with
//! E = e^{sρζ}, X = ζc + d:
//!
//! ```text
//!   2μU = −ρX E,   2μW = ((3−4ν)c − sρX) E,
//!   T = (ρ(1−2ν)c − sρ²X) E,   S = (sρ(2−2ν)c − ρ²X) E
//! ```
//!
//! (σ_zz = λ∇·u + 2μ∂_z u_z with μ∇·u = (1−2ν)ψ_z). Four solutions per layer (s = ±1,
//! c or d), the growing ones written as e^{ρ(ζ−h)} so nothing overflows; two decaying
//! ones in an elastic base. Conditions: the surface traction, continuity of U, W, T, S
//! at every interface, U = W = 0 on a rigid base: 4N (+2) equations, solved by Gaussian
//! elimination with partial pivoting in the scaled variables (ρU, ρW, T/μ₁, S/μ₁).
//!
//! **SH.** u_y = V e^{iρx}, V = a e^{−ρζ} + b e^{ρ(ζ−h)}, σ_yz = μV′: the same
//! assembly with 2N (+1) unknowns.
//!
//! The loads then give the normalised compliances by their definitions
//! (tangential.rs): a traction q_L is T = i q_L and u_L = iU, so u_L = −U(T = 1)·q_L.

// Dense assembly and elimination read by row and column index.
#![allow(clippy::needless_range_loop)]

use super::tangential::Compliances;
use crate::stack::{Base, Stack, plane_strain_modulus, shear_modulus};

/// (U, W, T, S) at depth ζ of one P-SV basis solution with unit amplitude, in the
/// scaled form (ρU, ρW, T/μ_ref, S/μ_ref) with c = μĉ/ρ and d = μd̂/ρ² (so ĉ, d̂ are
/// dimensionless): `kind` 0: s = −1, ĉ = 1; 1: s = −1, d̂ = 1; 2: s = +1, ĉ = 1;
/// 3: s = +1, d̂ = 1. `t` = ρζ, `th` = ρh (the growing ones carry e^{ρ(ζ−h)}).
pub(crate) fn psv_basis(kind: usize, t: f64, th: f64, nu: f64, mu_ratio: f64) -> [f64; 4] {
    let (s, c, d) = match kind {
        0 => (-1.0, 1.0, 0.0),
        1 => (-1.0, 0.0, 1.0),
        2 => (1.0, 1.0, 0.0),
        _ => (1.0, 0.0, 1.0),
    };
    let e = if s < 0.0 { (-t).exp() } else { (t - th).exp() };
    let x = t * c + d; // ρX·ρ/μ
    [
        -0.5 * x * e,
        0.5 * ((3.0 - 4.0 * nu) * c - s * x) * e,
        mu_ratio * ((1.0 - 2.0 * nu) * c - s * x) * e,
        mu_ratio * (s * (2.0 - 2.0 * nu) * c - x) * e,
    ]
}

/// Solves a·x = b in place by Gaussian elimination with partial pivoting.
fn gauss(mut a: Vec<Vec<f64>>, mut b: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    let n = a.len();
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
            .unwrap();
        a.swap(k, p);
        b.swap(k, p);
        for i in k + 1..n {
            let f = a[i][k] / a[k][k];
            if f == 0.0 {
                continue;
            }
            for j in k..n {
                a[i][j] -= f * a[k][j];
            }
            for j in 0..b[i].len() {
                b[i][j] -= f * b[k][j];
            }
        }
    }
    for k in (0..n).rev() {
        for j in 0..b[k].len() {
            let mut v = b[k][j];
            for i in k + 1..n {
                v -= a[k][i] * b[i][j];
            }
            b[k][j] = v / a[k][k];
        }
    }
    b
}

/// g[U or W][load T or S]: the surface (ρU, ρW) under T/μ₁ = 1 and under S/μ₁ = 1.
fn psv_g(stack: &Stack, rho: f64) -> [[f64; 2]; 2] {
    let ls = stack.layers();
    let n = ls.len();
    let (e1, nu1) = stack.top_material();
    let mu1 = shear_modulus(e1, nu1);
    let base = stack.base();
    let nb = if matches!(base, Base::Rigid) { 0 } else { 2 };
    let size = 4 * n + nb;
    let mut a = vec![vec![0.0; size]; size];
    let mut row = 0;
    let layer = |i: usize| {
        let l = ls[i];
        (
            rho * l.thickness,
            l.poisson,
            shear_modulus(l.young, l.poisson) / mu1,
        )
    };
    // Surface: T, S of layer 0 (or of the base for a half-space).
    if n == 0 {
        let Base::Elastic { young, poisson } = base else {
            unreachable!()
        };
        let r = shear_modulus(young, poisson) / mu1;
        for k in 0..2 {
            let v = psv_basis(k, 0.0, 0.0, poisson, r);
            a[0][k] = v[2];
            a[1][k] = v[3];
        }
        row = 2;
    } else {
        let (th, nu, r) = layer(0);
        for k in 0..4 {
            let v = psv_basis(k, 0.0, th, nu, r);
            a[0][k] = v[2];
            a[1][k] = v[3];
        }
        row += 2;
        for i in 0..n {
            let (th, nu, r) = layer(i);
            let bottom: Vec<[f64; 4]> = (0..4).map(|k| psv_basis(k, th, th, nu, r)).collect();
            if i + 1 < n {
                let (th2, nu2, r2) = layer(i + 1);
                for q in 0..4 {
                    for k in 0..4 {
                        a[row + q][4 * i + k] = bottom[k][q];
                        a[row + q][4 * (i + 1) + k] = -psv_basis(k, 0.0, th2, nu2, r2)[q];
                    }
                }
                row += 4;
            } else {
                match base {
                    Base::Rigid => {
                        for q in 0..2 {
                            for k in 0..4 {
                                a[row + q][4 * i + k] = bottom[k][q];
                            }
                        }
                        row += 2;
                    }
                    Base::Elastic { young, poisson } => {
                        let rb = shear_modulus(young, poisson) / mu1;
                        for q in 0..4 {
                            for k in 0..4 {
                                a[row + q][4 * i + k] = bottom[k][q];
                            }
                            for k in 0..2 {
                                a[row + q][4 * n + k] = -psv_basis(k, 0.0, 0.0, poisson, rb)[q];
                            }
                        }
                        row += 4;
                    }
                }
            }
        }
    }
    assert_eq!(row, size);
    let mut rhs = vec![vec![0.0; 2]; size];
    rhs[0][0] = 1.0; // T/μ₁ = 1
    rhs[1][1] = 1.0; // S/μ₁ = 1
    let x = gauss(a, rhs);
    // Surface (ρU, ρW) for each load.
    let (th0, nu0, r0) = if n == 0 {
        let Base::Elastic { young, poisson } = base else {
            unreachable!()
        };
        (0.0, poisson, shear_modulus(young, poisson) / mu1)
    } else {
        layer(0)
    };
    let kinds = if n == 0 { 2 } else { 4 };
    let mut g = [[0.0; 2]; 2]; // g[U or W][load T or S]
    for load in 0..2 {
        for k in 0..kinds {
            let v = psv_basis(k, 0.0, th0, nu0, r0);
            g[0][load] += v[0] * x[k][load];
            g[1][load] += v[1] * x[k][load];
        }
    }
    g
}

/// E*₁/(2μ₁) of the top material.
fn factor(stack: &Stack) -> f64 {
    let (e1, nu1) = stack.top_material();
    plane_strain_modulus(e1, nu1) / (2.0 * shear_modulus(e1, nu1))
}

/// The four normalised compliances of one body (no counterface) at ρ (1/m) by the
/// global solve.
pub fn compliances(stack: &Stack, rho: f64) -> Compliances {
    let g = psv_g(stack, rho);
    // U = g/ρ per T = μ₁. A traction q_L is T = i q_L and u_L = iU, so
    // u_L = −U(T = μ₁)·q_L/μ₁ and S_LL = u_L·E*₁ρ/(2q_L) = −g_UT·E*₁/(2μ₁). A pressure p
    // is S = −p: w = −W(S = μ₁)·p/μ₁, S_zz = −g_WS·E*₁/(2μ₁); u_L = iU = −i g_US p/(μ₁ρ),
    // so S_zL = −g_US·E*₁/(2μ₁).
    let f = factor(stack);
    Compliances {
        s_zz: -g[1][1] * f,
        s_ll: -g[0][0] * f,
        s_tt: sh(stack, rho),
        s_zl: -g[0][1] * f,
    }
}

/// S_zL from the other off-diagonal entry: w = W = i g_WT q_L/(μ₁ρ) under T = i q_L,
/// and w = −i S_zL q_L·2/(E*₁ρ) by definition, so S_zL = −g_WT·E*₁/(2μ₁).
pub(crate) fn s_zl_transpose(stack: &Stack, rho: f64) -> f64 {
    -psv_g(stack, rho)[1][0] * factor(stack)
}

/// S_TT by the global SH solve.
pub fn sh(stack: &Stack, rho: f64) -> f64 {
    let ls = stack.layers();
    let n = ls.len();
    if n == 0 {
        return 1.0;
    }
    let (e1, nu1) = stack.top_material();
    let mu1 = shear_modulus(e1, nu1);
    let base = stack.base();
    let nb = if matches!(base, Base::Rigid) { 0 } else { 1 };
    let size = 2 * n + nb;
    // (ρV, τ/μ₁) of the two basis functions at ρζ = t.
    let basis = |k: usize, t: f64, th: f64, r: f64| -> [f64; 2] {
        if k == 0 {
            let e = (-t).exp();
            [e, -r * e]
        } else {
            let e = (t - th).exp();
            [e, r * e]
        }
    };
    let lay = |i: usize| {
        let l = ls[i];
        (rho * l.thickness, shear_modulus(l.young, l.poisson) / mu1)
    };
    let mut a = vec![vec![0.0; size]; size];
    let (th, r) = lay(0);
    a[0][0] = basis(0, 0.0, th, r)[1];
    a[0][1] = basis(1, 0.0, th, r)[1];
    let mut row = 1;
    for i in 0..n {
        let (th, r) = lay(i);
        if i + 1 < n {
            let (th2, r2) = lay(i + 1);
            for q in 0..2 {
                for k in 0..2 {
                    a[row + q][2 * i + k] = basis(k, th, th, r)[q];
                    a[row + q][2 * (i + 1) + k] = -basis(k, 0.0, th2, r2)[q];
                }
            }
            row += 2;
        } else {
            match base {
                Base::Rigid => {
                    for k in 0..2 {
                        a[row][2 * i + k] = basis(k, th, th, r)[0];
                    }
                    row += 1;
                }
                Base::Elastic { young, poisson } => {
                    let rb = shear_modulus(young, poisson) / mu1;
                    for q in 0..2 {
                        for k in 0..2 {
                            a[row + q][2 * i + k] = basis(k, th, th, r)[q];
                        }
                        a[row + q][2 * n] = -basis(0, 0.0, 0.0, rb)[q];
                    }
                    row += 2;
                }
            }
        }
    }
    assert_eq!(row, size);
    let mut rhs = vec![vec![0.0]; size];
    rhs[0][0] = -1.0; // σ_yz = −q_T with q_T = μ₁ (units of ρV)
    let x = gauss(a, rhs);
    // u_T = V(0) = S_TT q_T/(μ₁ρ) ⇒ S_TT = ρV(0).
    x[0][0] * basis(0, 0.0, th, r)[0] + x[1][0] * basis(1, 0.0, th, r)[0]
}
