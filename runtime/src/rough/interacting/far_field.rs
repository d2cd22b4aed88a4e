//! The far-field model of the interaction kernel (interacting module docs, "Far
//! field"): W(a, r) = B(a, r)/a³ replaced, for r ≥ r_c, by its Chebyshev interpolant in
//! x = 2(a/A)² − 1 with coefficients tabulated on a uniform ln r grid, validated against
//! the law's own g when it is built.

use crate::law::{AsperityLaw, half_space_bracket, half_space_bracket_derivs};

/// Number of Chebyshev nodes in s = (a/A)² of the far-field model (module docs).
pub const NB: usize = 12;
/// One coefficient (or basis) vector of the far-field model.
pub(crate) type Vb = [f64; NB];

/// Σ_i x_i y_i of two coefficient vectors.
#[inline]
pub(crate) fn dot(x: &Vb, y: &Vb) -> f64 {
    let mut s = 0.0;
    for i in 0..NB {
        s += x[i] * y[i];
    }
    s
}

/// The bracket B(a, r) = B₀(a, r) + g(a, r) (m²) of the outside displacement
/// (physics.md §4; B₀ the law's [`half_space_bracket`]), ∂B/∂a (m) and ∂²B/∂a² (-),
/// r > a > 0. The a-derivatives of g by central differences (relative step `h_rel`,
/// kept on the r > a branch), those of B₀ exact.
pub(crate) fn bracket(law: &dyn AsperityLaw, a: f64, r: f64, h_rel: f64) -> (f64, f64, f64) {
    let hs = half_space_bracket(a, r);
    let (dhs, d2hs) = half_space_bracket_derivs(a, r);
    if law.is_homogeneous() {
        return (hs, dhs, d2hs);
    }
    let h = (h_rel * a).min(0.5 * (r - a));
    let (g, gp, gm) = (law.g(a, r), law.g(a + h, r), law.g(a - h, r));
    (
        hs + g,
        dhs + (gp - gm) / (2.0 * h),
        d2hs + (gp - 2.0 * g + gm) / (h * h),
    )
}

/// W(a, r) = B(a, r)/a³ (1/m) and ∂W/∂a (1/m²), r > a > 0.
fn w_exact(law: &dyn AsperityLaw, a: f64, r: f64, h_rel: f64) -> (f64, f64) {
    let (b, db, _) = bracket(law, a, r, h_rel);
    let a3 = a * a * a;
    (b / a3, db / a3 - 3.0 * b / (a3 * a))
}

/// The far-field model of one law and bound A (module docs): the Chebyshev
/// coefficients c_j(r) of (3r/4) W(a, r) in x = 2(a/A)² − 1 (its interpolant at NB
/// Chebyshev points) on a uniform ln r grid, valid for a ≤ A and r_c ≤ r ≤ r_hi.
pub(crate) struct FarModel {
    /// A (m).
    pub a_max: f64,
    /// Smallest distance of the validated region (m).
    pub r_c: f64,
    /// Largest distance of the grid (m).
    pub r_hi: f64,
    ln_lo: f64,
    step: f64,
    /// (3r/4) c_j(r) at the grid nodes.
    v: Vec<Vb>,
    /// Largest measured error above r_c (units of the point-force scale).
    pub worst: f64,
}

impl FarModel {
    /// Interpolation radii a_i = A√((1 + x_i)/2), x_i = cos(θ_i), θ_i = π(i + ½)/NB, and
    /// the map c_j = Σ_i P[j][i] f(x_i) to Chebyshev coefficients (discrete
    /// orthogonality: P[j][i] = κ_j cos(jθ_i)/NB, κ_0 = 1, κ_j = 2).
    fn nodes(a_max: f64) -> (Vb, [Vb; NB]) {
        let th = |i: usize| std::f64::consts::PI * (i as f64 + 0.5) / NB as f64;
        let mut a = [0.0; NB];
        let mut proj = [[0.0; NB]; NB];
        for i in 0..NB {
            a[i] = a_max * (0.5 * (1.0 + th(i).cos())).sqrt();
            for (j, row) in proj.iter_mut().enumerate() {
                row[i] = if j == 0 { 1.0 } else { 2.0 } / NB as f64 * (j as f64 * th(i)).cos();
            }
        }
        (a, proj)
    }

    /// Exact (3r/4) c_j(r) from W at the interpolation radii.
    fn coefficients(law: &dyn AsperityLaw, a: &Vb, proj: &[Vb; NB], r: f64, h_rel: f64) -> Vb {
        let mut v = [0.0; NB];
        for (vi, &ai) in v.iter_mut().zip(a) {
            *vi = 0.75 * r * w_exact(law, ai, r, h_rel).0;
        }
        let mut c = [0.0; NB];
        for (cj, row) in c.iter_mut().zip(proj) {
            *cj = dot(row, &v);
        }
        c
    }

    /// (T_j(x), dT_j(x)/da) at contact radius a (m), x = 2(a/A)² − 1.
    #[inline]
    fn basis_of(a_max: f64, a: f64) -> (Vb, Vb) {
        let x = 2.0 * (a / a_max).powi(2) - 1.0;
        let dxda = 4.0 * a / (a_max * a_max);
        let mut t = [0.0; NB];
        let mut dt = [0.0; NB];
        t[0] = 1.0;
        t[1] = x;
        dt[1] = 1.0;
        for j in 2..NB {
            t[j] = 2.0 * x * t[j - 1] - t[j - 2];
            dt[j] = 2.0 * t[j - 1] + 2.0 * x * dt[j - 1] - dt[j - 2];
        }
        for d in dt.iter_mut() {
            *d *= dxda;
        }
        (t, dt)
    }

    pub fn basis(&self, a: f64) -> (Vb, Vb) {
        Self::basis_of(self.a_max, a)
    }

    /// 4-point Lagrange weights and first node at distance r.
    #[inline]
    fn stencil(&self, r: f64) -> (usize, [f64; 4]) {
        let n = self.v.len();
        let u = (r.ln() - self.ln_lo) / self.step;
        let i = (u.floor() as isize).clamp(1, n as isize - 3) as usize;
        let t = u - i as f64;
        let (tm, t1, t2) = (t + 1.0, t - 1.0, t - 2.0);
        (
            i - 1,
            [
                -t * t1 * t2 / 6.0,
                tm * t1 * t2 / 2.0,
                -tm * t * t2 / 2.0,
                tm * t * t1 / 6.0,
            ],
        )
    }

    /// Adds the coefficients c_j(r) (1/m) at distance r to `acc`.
    #[inline]
    pub fn accumulate(&self, r: f64, acc: &mut Vb) {
        let (i0, w) = self.stencil(r);
        let k = 4.0 / (3.0 * r);
        let (v0, v1, v2, v3) = (
            &self.v[i0],
            &self.v[i0 + 1],
            &self.v[i0 + 2],
            &self.v[i0 + 3],
        );
        for j in 0..NB {
            acc[j] += k * (w[0] * v0[j] + w[1] * v1[j] + w[2] * v2[j] + w[3] * v3[j]);
        }
    }

    /// Builds and validates the model for a ≤ `a_max` and r ≤ `r_hi` (module docs).
    /// None when no distance below `r_hi` meets the tolerance.
    pub fn build(
        law: &dyn AsperityLaw,
        a_max: f64,
        r_hi: f64,
        tol: f64,
        h_rel: f64,
    ) -> Option<FarModel> {
        if !(a_max.is_finite() && a_max > 0.0 && r_hi.is_finite() && tol > 0.0) {
            return None;
        }
        let (an, proj) = Self::nodes(a_max);
        // check points in a: x = cos(πk/(2NB)), k = 0..2NB (a floored at 1e-4 A)
        let checks: Vec<(f64, Vb, Vb)> = (0..=2 * NB)
            .map(|k| {
                let x = (std::f64::consts::PI * k as f64 / (2 * NB) as f64).cos();
                let a = (a_max * (0.5 * (1.0 + x)).max(0.0).sqrt()).max(1e-4 * a_max);
                let (l, dl) = Self::basis_of(a_max, a);
                (a, l, dl)
            })
            .collect();
        // error in W and (a/3)∂W/∂a from coefficient errors dv (point-force units)
        let propagate = |dv: &Vb| -> f64 {
            let mut worst: f64 = 0.0;
            for (a, l, dl) in &checks {
                worst = worst
                    .max(dot(dv, l).abs())
                    .max((a / 3.0 * dot(dv, dl)).abs());
            }
            worst
        };
        let r_lo = 1.1 * a_max;
        let r_hi = r_hi.max(8.0 * r_lo);
        let (ln_lo, ln_hi) = (r_lo.ln(), r_hi.ln());
        // a-direction error with exact coefficients v at r (point-force units)
        let fit_error = |r: f64, v: &Vb| -> f64 {
            let mut worst: f64 = 0.0;
            for (a, l, dl) in &checks {
                let (w, dw) = w_exact(law, *a, r, h_rel);
                let ev = (dot(v, l) - 0.75 * r * w).abs();
                let ed = a / 3.0 * (dot(v, dl) - 0.75 * r * dw).abs();
                worst = worst.max(ev).max(ed);
            }
            worst
        };
        // first index k with every error from k on at most `lim` (len when none)
        let suffix = |e: &[f64], lim: f64| -> usize {
            let mut k = e.len();
            while k > 0 && e[k - 1] <= lim {
                k -= 1;
            }
            k
        };
        let mut n = 257usize;
        let mut fit: Option<(f64, f64)> = None; // (r_a, worst fit error beyond r_a)
        loop {
            let step = (ln_hi - ln_lo) / (n - 1) as f64;
            let node_r = |i: f64| (ln_lo + step * i).exp();
            let v: Vec<Vb> = (0..n)
                .map(|i| Self::coefficients(law, &an, &proj, node_r(i as f64), h_rel))
                .collect();
            if v.iter().flatten().any(|x| !x.is_finite()) {
                return None;
            }
            let mut fm = FarModel {
                a_max,
                r_c: f64::INFINITY,
                r_hi,
                ln_lo,
                step,
                v,
                worst: 0.0,
            };
            // interpolation error at every midpoint (propagated), and on the first grid
            // the a-direction error at every node and midpoint
            let mut e_int = vec![0.0; n - 1];
            let mut e_fit = vec![0.0; n - 1];
            for i in 0..n - 1 {
                let r = node_r(i as f64 + 0.5);
                let exact = Self::coefficients(law, &an, &proj, r, h_rel);
                let mut acc = [0.0; NB];
                fm.accumulate(r, &mut acc);
                let mut dv = [0.0; NB];
                for j in 0..NB {
                    dv[j] = 0.75 * r * acc[j] - exact[j];
                }
                e_int[i] = propagate(&dv);
                if fit.is_none() {
                    e_fit[i] = fit_error(r, &exact).max(fit_error(node_r(i as f64), &fm.v[i]));
                }
            }
            let (r_a, worst_fit) = match fit {
                Some(f) => f,
                None => {
                    let k = suffix(&e_fit, 0.5 * tol);
                    if k + 1 >= n - 1 {
                        return None;
                    }
                    let f = (
                        node_r(k as f64),
                        e_fit[k..].iter().copied().fold(0.0, f64::max),
                    );
                    fit = Some(f);
                    f
                }
            };
            let k = suffix(&e_int, 0.5 * tol);
            let r_i = node_r(k as f64);
            if r_i <= r_a || n > 1 << 14 {
                fm.r_c = r_a.max(r_i);
                if k + 1 >= n - 1 {
                    return None;
                }
                let first = ((fm.r_c.ln() - ln_lo) / step).floor().max(0.0) as usize;
                let wi = e_int[first.min(n - 2)..]
                    .iter()
                    .copied()
                    .fold(0.0, f64::max);
                fm.worst = worst_fit + wi;
                return Some(fm);
            }
            n = 2 * n - 1;
        }
    }
}
