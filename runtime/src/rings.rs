//! Axisymmetric influence of ring loads on a layered half-space, in physical space: the
//! second, independent route beside the Abel–Fredholm one (physics.md §3), used by the
//! capped (plastic) asperity ([`crate::rough::plastic::asperity`]) and as a check.
//!
//! A uniform load q on the disc r < c of a homogeneous half-space gives the surface
//! response (Boussinesq's disc; displacement ×E*/2, or temperature ×k)
//!
//! ```text
//!   D(r, c) = (2c/π) E(r/c)                               r ≤ c
//!           = (2r/π) [E(c/r) − (1 − c²/r²) K(c/r)]        r > c
//! ```
//!
//! (K, E the complete elliptic integrals of modulus k), and on a layered body the
//! correction ∫₀^∞ k(ρ) c J₁(ρc) J₀(ρr)/ρ dρ with k = S − 1 (k_z of the stack, or k_th
//! for conduction), exponentially decaying beyond ρ ~ 1/h₁. A ring c₁ < r < c₂ is the
//! difference of two discs. The elastic surface displacement of a pressure p piecewise
//! constant on rings is u(rᵢ) = (2/E*) Σⱼ Mᵢⱼ pⱼ.

use std::f64::consts::PI;

/// Complete elliptic integrals (K(k), E(k)) of modulus 0 ≤ k < 1 by the
/// arithmetic–geometric mean (to round-off in ≤ 6 steps for k ≤ 0.999…); k = 1 gives
/// (∞, 1).
pub fn elliptic(k: f64) -> (f64, f64) {
    if k >= 1.0 {
        return (f64::INFINITY, 1.0);
    }
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).max(0.0).sqrt());
    let mut sum = 0.5 * k * k;
    let mut pow = 0.5;
    for _ in 0..40 {
        let c = 0.5 * (a - b);
        let (a2, b2) = (0.5 * (a + b), (a * b).sqrt());
        pow *= 2.0;
        sum += pow * c * c;
        a = a2;
        b = b2;
        if c.abs() < 1e-17 {
            break;
        }
    }
    let kk = PI / (2.0 * a);
    (kk, kk * (1.0 - sum))
}

/// D(r, c): the response at radius r to a unit uniform load on the disc r < c of a
/// unit half-space (module docs), m.
pub fn disc_response(r: f64, c: f64) -> f64 {
    if c <= 0.0 {
        return 0.0;
    }
    if r <= c {
        2.0 * c / PI * elliptic(r / c).1
    } else {
        let (kk, ee) = elliptic(c / r);
        2.0 * r / PI * (ee - (1.0 - c * c / (r * r)) * kk)
    }
}

/// The ring influence matrix M (row-major, `mids.len()` × (`edges.len()` − 1)): the
/// response at each mid-radius to a unit load on each ring `[edges[j], edges[j+1]]`, on
/// the body whose k(ρ) = S − 1 is `k` (None: a homogeneous half-space). `h` (m) is the
/// length on which k decays (the thinnest top layer); the ρ-rule has panels of width
/// min(h/4, 1/r_max)⁻¹ … up to 25/h, 16 Gauss–Legendre nodes each, graded
/// geometrically below the first panel.
pub(crate) fn ring_matrix(
    edges: &[f64],
    mids: &[f64],
    k: Option<&(dyn Fn(f64) -> f64 + Sync)>,
    h: f64,
) -> Vec<f64> {
    let n = edges.len().saturating_sub(1);
    let mut m = vec![0.0; mids.len() * n];
    for (i, &r) in mids.iter().enumerate() {
        for j in 0..n {
            m[i * n + j] = disc_response(r, edges[j + 1]) - disc_response(r, edges[j]);
        }
    }
    let Some(k) = k else {
        return m;
    };
    let r_max = edges.last().copied().unwrap_or(1.0).max(f64::MIN_POSITIVE);
    let (gx, gw) = crate::numerics::gauss_legendre(16);
    let dw = (0.25 / h).min(1.0 / r_max);
    let mut breaks = vec![0.0, (1e-3 / h).min(0.5 * dw)];
    while breaks[breaks.len() - 1] < dw {
        let b = (2.0 * breaks[breaks.len() - 1]).min(dw);
        breaks.push(b);
    }
    while breaks[breaks.len() - 1] < 25.0 / h {
        let b = breaks[breaks.len() - 1] + dw;
        breaks.push(b);
    }
    let mut rho = Vec::new();
    let mut wk = Vec::new();
    for p in breaks.windows(2) {
        let (c, hw) = (0.5 * (p[0] + p[1]), 0.5 * (p[1] - p[0]));
        for (x, w) in gx.iter().zip(&gw) {
            let u = c + hw * x;
            rho.push(u);
            wk.push(hw * w * k(u));
        }
    }
    // v[e][q] = c_e J₁(ρ_q c_e)/ρ_q (per disc edge), weighted by the rule and k.
    let v: Vec<Vec<f64>> = edges
        .iter()
        .map(|&c| {
            rho.iter()
                .zip(&wk)
                .map(|(&p, &w)| w * c * libm::j1(p * c) / p)
                .collect()
        })
        .collect();
    use rayon::prelude::*;
    m.par_chunks_mut(n.max(1))
        .zip(mids.par_iter())
        .for_each(|(row, &r)| {
            let j0: Vec<f64> = rho.iter().map(|&p| libm::j0(p * r)).collect();
            let disc: Vec<f64> = v
                .iter()
                .map(|ve| ve.iter().zip(&j0).map(|(a, b)| a * b).sum())
                .collect();
            for j in 0..n {
                row[j] += disc[j + 1] - disc[j];
            }
        });
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// E(0) = K(0) = π/2; K(0.5), E(0.5) against tabulated values (Abramowitz & Stegun
    /// 17.3, m = k² = 0.25: K = 1.685750354812596, E = 1.467462209339427).
    #[test]
    fn elliptic_values() {
        let (k0, e0) = elliptic(0.0);
        assert!((k0 - PI / 2.0).abs() < 1e-15 && (e0 - PI / 2.0).abs() < 1e-15);
        let (k, e) = elliptic(0.5);
        assert!((k - 1.685750354812596).abs() < 1e-14, "{k}");
        assert!((e - 1.467462209339427).abs() < 1e-14, "{e}");
    }

    /// The disc's centre c, its edge 2c/π·1, and far away → c²/(2r) (the point load
    /// πc² · 1/(2πr)).
    #[test]
    fn disc_limits() {
        assert!((disc_response(0.0, 2.0) - 2.0).abs() < 1e-15);
        assert!((disc_response(2.0, 2.0) - 4.0 / PI).abs() < 1e-15);
        let far = disc_response(1e4, 1.0);
        assert!((far / (1.0 / (2.0 * 1e4)) - 1.0).abs() < 1e-8, "{far}");
    }
}
