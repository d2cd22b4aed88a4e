//! Multi-asperity rough contact: the N model (independent asperities) and the I model
//! (interacting asperities, complementary-energy minimisation), physics.md §5, paper
//! §4.2 and eqs. (P19)–(P26).
//!
//! Notation (SI): asperity k has height z_k (m), radius R_k (m), contact radius a_k (m).
//! A rigid flat approaching by δ (m) from first contact with the highest summit z_M gives
//! the interference δ_k = ⟨δ − (z_M − z_k)⟩ (P20) and the separation
//! g_n = (z_M − z̄) − δ (P26). The total load is P = (4/3)E*₁ Σ χ(a_k)a_k³/R_k (N, P24),
//! the real contact area A = π Σ a_k² (m², P25), p_n = P/A₀ (Pa). The normal stiffness
//! is dP/dδ of the whole sample (N/m), computed analytically (N model: chain rule on
//! P(a) and δ(a); I model: implicit differentiation of the stationarity system).
//!
//! The I model minimises over a ≥ 0 (P22)
//!
//! ```text
//! U_E = c Σ_j Q_j [ Σ_{l≠j} G_l(r_lj) + s_j − 2δ_j ],  c = −4α/3 = 2E*₁/3,
//! Q_j = χ(a_j)a_j³/R_j,  s_j = (a_j²/R_j)(ζ(a_j) + 1/5),
//! ```
//!
//! G_l(r) = a_l²ζ(a_l)/R_l for r ≤ a_l and the outside displacement of physics.md §4 for
//! r > a_l. Its gradient, scaled by the positive c·Q_k'(a_k), is
//!
//! ```text
//! F_k = D_k + s_k − 2δ_k + (Q_k s_k' + Σ_j Q_j ∂G_k(r_kj)/∂a_k) / Q_k',   D_k = Σ_{l≠k} G_l(r_lk)
//! ```
//!
//! (homogeneous solid: F_k = 2(a_k²/R_k − δ_k + D_k)). KKT: F_k = 0 where a_k > 0 and
//! F_k(0⁺) ≥ 0 where a_k = 0. The solver is an active-set projected Newton method on F
//! (∂U_E/∂Q_k = c F_k, so F is the gradient in Q = χa³/R, where U_E is convex for a
//! homogeneous solid): each Newton step backtracks on U_E itself (Armijo) and stays
//! inside a ≥ 0 and the far-field range a ≤ A; every asperity violating F_k(0⁺) ≥ 0 is
//! activated at once, at the radius of its single-asperity problem under the others'
//! displacement. A load path ([`RoughContact::curve`]) starts each step from the
//! previous radii extrapolated with da/dδ (the stiffness solve gives it). The residual
//! of both KKT conditions, relative to the largest interference, is returned with each
//! step and must be below 1e-8. With periodic images, every source asperity is
//! repeated on a (2m+1)² block of cells (its own images included); isolated means plain
//! distances inside the sample.
//!
//! # Far field: the accelerated interaction sum
//! Source l acts on asperity k through G_l(r) = Q_l W(a_l, r)/π for r > a_l, with
//!
//! ```text
//! W(a, r) = [(2a² − r²) asin(a/r) + a√(r² − a²) + g(a, r)] / a³   (1/m).
//! ```
//!
//! Far away this is the point force on the layered solid, W → (4/3)/r + g/a³; nearer
//! the a-dependence matters (relative O((a/h₁)²) for the layered g, so the point force
//! alone misses 1e-6 accuracy wherever contacts are not tiny against the layer). For
//! r ≥ r_c > A ≥ a, W is a smooth function of x = 2(a/A)² − 1 (its singularities sit at
//! a = r and at |Im a| ~ 2h₁), so it is replaced by its Chebyshev interpolant at [`NB`]
//! points: W(a, r) ≈ Σ_j c_j(r) T_j(x). The coefficients c_j(r)·3r/4 are tabulated once
//! per law and bound A on a uniform ln r grid (4-point Lagrange in ln r). For each
//! pair of asperities the sum over its far images then collapses into NB numbers
//! N_kl,j = Σ_images c_j(r) (built once per solve, or once per load path in
//! [`RoughContact::curve`]), and every evaluation of U_E, F or the Jacobian costs
//! O(NB) multiply–adds per pair instead of table lookups per image. Image pairs closer
//! than r_c (and all of them when the tolerance is 0) are summed exactly, image by
//! image, with `law.g`.
//!
//! Error control: when the model is built, (i) the interpolant in a with exact
//! coefficients is compared with the exact W and ∂W/∂a (from `law.g`) at every ln r
//! node and midpoint and 2·NB + 1 points of a ∈ [0, A], and (ii) the ln r
//! interpolation error of the coefficients at every midpoint is carried through the
//! basis to W and ∂W/∂a. r_c is the smallest grid distance beyond which both stay
//! below half the far-field tolerance in units of the point-force displacement: the
//! errors of G and ∂G/∂a are then below tol·(4/3)Q/(πr) and tol·(4/3)Q'/(πr). Default
//! tol = 1e-5 ([`RoughContact::with_far_field_tolerance`]): the surrogate tables' g is
//! itself only smooth in a to ~1e-6 of that scale (and accurate to ~6e-5, its
//! `interp_error.g`), so 1e-6 would push r_c out to the sample size. A is 1.2 × the
//! largest N-model contact radius of the solve (interactions shrink contacts); a
//! minimum beyond A is solved again with a larger A.

use crate::law::AsperityLaw;
use crate::summits::Summit;
use thiserror::Error;

/// Errors of the rough-contact solvers.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RoughError {
    #[error("no summits: the surface has no asperity to load")]
    NoSummits,
    #[error("{field}: value {value} out of range: {reason}")]
    LoadOutOfRange {
        field: &'static str,
        value: f64,
        reason: String,
    },
    #[error("asperity {index}: cannot solve ζ(a)a²/R = δ for a (δ = {delta}, R = {radius})")]
    NoRoot {
        index: usize,
        delta: f64,
        radius: f64,
    },
    #[error("I model did not converge at δ = {delta}: KKT residual {residual:e}")]
    NotConverged { delta: f64, residual: f64 },
    #[error("non-finite value in {0}")]
    NonFinite(&'static str),
    #[error("{field}: expected {expected} values (one per summit), found {found}")]
    Length {
        field: &'static str,
        expected: usize,
        found: usize,
    },
}

/// How interactions treat the sample boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Images {
    /// Interactions stop at the sample edge (plain distances).
    Isolated,
    /// The sample is one cell of a periodic pattern; sources are repeated on the
    /// (2m+1)×(2m+1) block of cells around it (m = 2: the 5×5 sum).
    Periodic(usize),
}

/// Which model a solve uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    /// N model: independent asperities.
    Independent,
    /// I model: interacting asperities with the given image convention.
    Interacting(Images),
}

/// Results of one load step.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// Approach δ (m).
    pub delta: f64,
    /// Separation g_n = (z_M − z̄) − δ (m).
    pub gap: f64,
    /// Total load P (N).
    pub load: f64,
    /// Mean pressure p_n = P/A₀ (Pa).
    pub mean_pressure: f64,
    /// p_n/E*₁ (-).
    pub pressure_ratio: f64,
    /// Real contact area fraction A/A₀ (-).
    pub area_fraction: f64,
    /// Number of asperities in contact.
    pub contacts: usize,
    /// Normal stiffness dP/dδ of the sample (N/m).
    pub stiffness: f64,
    /// I model only: KKT residual relative to the largest interference.
    pub kkt_residual: Option<f64>,
    /// Newton iterations (I model only; 0 otherwise).
    pub iterations: usize,
    /// Contact radius of every summit (m), 0 when out of contact.
    pub radii: Vec<f64>,
}

/// Number of Chebyshev nodes in s = (a/A)² of the far-field model (module docs).
pub const NB: usize = 12;
type Vb = [f64; NB];

#[inline]
fn dot(x: &Vb, y: &Vb) -> f64 {
    let mut s = 0.0;
    for i in 0..NB {
        s += x[i] * y[i];
    }
    s
}

/// A rough surface reduced to its summits, on a given material law.
pub struct RoughContact<'a> {
    law: &'a dyn AsperityLaw,
    summits: Vec<Summit>,
    z_max: f64,
    z_mean: f64,
    z_min: f64,
    extent: (f64, f64),
    /// Relative tolerance of the far-field interaction model; 0 disables it.
    far_tol: f64,
    /// The last far-field model built (reused while its bound A fits).
    far: std::sync::Mutex<Option<std::sync::Arc<FarModel>>>,
}

/// The half-space bracket (2a² − r²) asin(a/r) + a√(r² − a²) (m²) and its a-derivative
/// 4a·asin(a/r) (m), r ≥ a; a series in q = a/r below q = 0.05 (no cancellation).
fn half_space(a: f64, r: f64) -> (f64, f64) {
    let q = (a / r).min(1.0);
    let d = 4.0 * a * q.asin();
    if q < 0.05 {
        let q2 = q * q;
        let v = r
            * r
            * q
            * q2
            * (4.0 / 3.0
                + q2 * (2.0 / 15.0
                    + q2 * (3.0 / 70.0 + q2 * (5.0 / 252.0 + q2 * (35.0 / 3168.0)))));
        return (v, d);
    }
    (
        (2.0 * a * a - r * r) * q.asin() + a * (r * r - a * a).max(0.0).sqrt(),
        d,
    )
}

/// The bracket B(a, r) = (2a² − r²) asin(a/r) + a√(r² − a²) + g(a, r) (m²) of the
/// outside displacement (physics.md §4), ∂B/∂a (m) and ∂²B/∂a² (-), r > a > 0; the
/// a-derivatives of g by central differences (relative step 1e-5, kept on the r > a
/// branch), those of the half-space part exact: 4a·asin(a/r) and
/// 4 asin(a/r) + 4(a/r)/√(1 − (a/r)²).
fn bracket(law: &dyn AsperityLaw, a: f64, r: f64) -> (f64, f64, f64) {
    let (hs, dhs) = half_space(a, r);
    let q = (a / r).min(1.0);
    let d2hs = 4.0 * q.asin() + 4.0 * q / (1.0 - q * q).max(f64::MIN_POSITIVE).sqrt();
    if law.is_homogeneous() {
        return (hs, dhs, d2hs);
    }
    let h = (1e-5 * a).min(0.5 * (r - a));
    let (g, gp, gm) = (law.g(a, r), law.g(a + h, r), law.g(a - h, r));
    (
        hs + g,
        dhs + (gp - gm) / (2.0 * h),
        d2hs + (gp - 2.0 * g + gm) / (h * h),
    )
}

/// W(a, r) = B(a, r)/a³ (1/m) and ∂W/∂a (1/m²), r > a > 0.
fn w_exact(law: &dyn AsperityLaw, a: f64, r: f64) -> (f64, f64) {
    let (b, db, _) = bracket(law, a, r);
    let a3 = a * a * a;
    (b / a3, db / a3 - 3.0 * b / (a3 * a))
}

/// The far-field model of one law and bound A (module docs): the Chebyshev
/// coefficients c_j(r) of (3r/4) W(a, r) in x = 2(a/A)² − 1 (its interpolant at NB
/// Chebyshev points) on a uniform ln r grid, valid for a ≤ A and r_c ≤ r ≤ r_hi.
struct FarModel {
    /// A (m).
    a_max: f64,
    /// Smallest distance of the validated region (m).
    r_c: f64,
    /// Largest distance of the grid (m).
    r_hi: f64,
    ln_lo: f64,
    step: f64,
    /// (3r/4) c_j(r) at the grid nodes.
    v: Vec<Vb>,
    /// Largest measured error above r_c (units of the point-force scale).
    worst: f64,
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
    fn coefficients(law: &dyn AsperityLaw, a: &Vb, proj: &[Vb; NB], r: f64) -> Vb {
        let mut v = [0.0; NB];
        for (vi, &ai) in v.iter_mut().zip(a) {
            *vi = 0.75 * r * w_exact(law, ai, r).0;
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

    fn basis(&self, a: f64) -> (Vb, Vb) {
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
    fn accumulate(&self, r: f64, acc: &mut Vb) {
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
    fn build(law: &dyn AsperityLaw, a_max: f64, r_hi: f64, tol: f64) -> Option<FarModel> {
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
                let (w, dw) = w_exact(law, *a, r);
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
                .map(|i| Self::coefficients(law, &an, &proj, node_r(i as f64)))
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
                let exact = Self::coefficients(law, &an, &proj, r);
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

/// Solves ζ(a)a²/R = δ for a ≥ 0 (m): homogeneous a = √(Rδ); otherwise safeguarded
/// Newton on a bracket grown from the Hertz value.
pub fn contact_radius(law: &dyn AsperityLaw, radius: f64, delta: f64) -> Option<f64> {
    if delta.is_nan() || delta <= 0.0 {
        return Some(0.0);
    }
    let hertz = (radius * delta).sqrt();
    if law.is_homogeneous() {
        return Some(hertz);
    }
    let f = |a: f64| law.zeta(a) * a * a / radius - delta;
    let (mut lo, mut hi) = (0.0, hertz);
    let mut k = 0;
    while f(hi) < 0.0 {
        lo = hi;
        hi *= 2.0;
        k += 1;
        if k > 60 || !hi.is_finite() {
            return None;
        }
    }
    let mut a = 0.5 * (lo + hi);
    for _ in 0..200 {
        let (_, _, z, dz) = law.chi_zeta_derivs(a);
        let v = z * a * a / radius - delta;
        if !v.is_finite() {
            return None;
        }
        if v.abs() <= 1e-15 * delta {
            return Some(a);
        }
        if v < 0.0 {
            lo = a;
        } else {
            hi = a;
        }
        let d = (dz * a * a + 2.0 * z * a) / radius;
        let mut next = a - v / d;
        if !next.is_finite() || next <= lo || next >= hi {
            next = 0.5 * (lo + hi);
        }
        if (next - a).abs() <= 1e-15 * a {
            return Some(next);
        }
        a = next;
    }
    Some(a)
}

/// Local (single-asperity) quantities at contact radius a.
#[derive(Debug, Clone, Copy, Default)]
struct Local {
    q: f64,
    dq: f64,
    s: f64,
    ds: f64,
    zeta: f64,
    dzeta: f64,
    chi: f64,
    dchi: f64,
}

fn local(law: &dyn AsperityLaw, a: f64, r: f64) -> Local {
    let (chi, dchi, zeta, dzeta) = law.chi_zeta_derivs(a);
    Local {
        q: chi * a.powi(3) / r,
        dq: (dchi * a.powi(3) + 3.0 * chi * a * a) / r,
        s: a * a / r * (zeta + 0.2),
        ds: (2.0 * a * (zeta + 0.2) + a * a * dzeta) / r,
        zeta,
        dzeta,
        chi,
        dchi,
    }
}

/// G(r) and ∂G/∂a (P19) of an asperity (contact radius a, radius R, local quantities
/// `l`) at distance r: a²ζ/R inside, χB(a, r)/(πR) outside.
fn g_and_da(law: &dyn AsperityLaw, l: &Local, a: f64, radius: f64, r: f64) -> (f64, f64) {
    let d = g_derivs(law, l, a, radius, r);
    (d[0], d[1])
}

/// [G, ∂G/∂a, c₀, c_χ, c_ζ] of an asperity at distance r (as [`g_and_da`]), with
/// ∂²G/∂a² = c₀ + c_χ χ″ + c_ζ ζ″ (the law gives no second derivatives of χ, ζ):
/// outside G″ = (χ″B + 2χ′B′ + χB″)/(πR), inside G″ = (2ζ + 4aζ′ + a²ζ″)/R.
fn g_derivs(law: &dyn AsperityLaw, l: &Local, a: f64, radius: f64, r: f64) -> [f64; 5] {
    if a <= 0.0 {
        return [0.0; 5];
    }
    if r <= a {
        return [
            a * a * l.zeta / radius,
            (2.0 * a * l.zeta + a * a * l.dzeta) / radius,
            (2.0 * l.zeta + 4.0 * a * l.dzeta) / radius,
            0.0,
            a * a / radius,
        ];
    }
    let (b, db, d2b) = bracket(law, a, r);
    let k = 1.0 / (std::f64::consts::PI * radius);
    [
        l.chi * k * b,
        k * (l.dchi * b + l.chi * db),
        k * (2.0 * l.dchi * db + l.chi * d2b),
        k * b,
        0.0,
    ]
}

/// The interaction geometry of a set of candidate asperities under one image
/// convention: far-field coefficient sums per pair and the exact (near) image distances.
struct Prepared {
    /// Candidate summit indices (local index → summit).
    cand: Vec<usize>,
    /// Radius R of each local index (m).
    radius: Vec<f64>,
    far: Option<std::sync::Arc<FarModel>>,
    /// N_kl,j = Σ_far images c_j(r), the Chebyshev coefficients of Σ_far images W(·, r)
    /// (1/m; m×m row-major, symmetric; the diagonal holds the far self-images); empty
    /// without a far model.
    nf: Vec<Vb>,
    /// Near cross entries (p, q, r), p < q, one per image.
    near: Vec<(usize, usize, f64)>,
    /// Near cross entries of each local index.
    near_of: Vec<Vec<usize>>,
    /// Near self-image distances (m), the same for every local index.
    near_self: Vec<f64>,
    /// Contact-radius bound A of the far model (m; ∞ without one).
    a_valid: f64,
    /// Number of image pairs in the far-field model.
    far_pairs: usize,
}

/// Everything the residual needs at one set of contact radii.
struct State {
    a: Vec<f64>,
    loc: Vec<Local>,
    /// (ℓ_i(a), dℓ_i/da) per local index (zero where a = 0 or without far model).
    basis: Vec<(Vb, Vb)>,
    /// Σ_{l≠k} G_l at k (m).
    d_other: Vec<f64>,
    /// Σ_{l≠k} Q_l N_kl (far model).
    u_other: Vec<Vb>,
    /// Per near entry (G_p, ∂G_p/∂a_p, G_q, ∂G_q/∂a_q) at its distance.
    near_vals: Vec<[f64; 4]>,
    /// Σ_near Q_q ∂²G_k/∂a_k² + Q_k Σ_self ∂²G_k/∂a_k² as [c₀, c_χ, c_ζ] (see
    /// [`g_derivs`]): the a_k-derivative of the near part of E_k, for the Jacobian.
    near_d2: Vec<[f64; 3]>,
    /// Σ_near Q_q ∂G_k(r)/∂a_k.
    e_cross: Vec<f64>,
    /// Σ of the near self images G_k(r) and ∂G_k(r)/∂a_k.
    self_g: Vec<f64>,
    self_h: Vec<f64>,
    /// F (NaN where a = 0).
    f: Vec<f64>,
}

const ZB: (Vb, Vb) = ([0.0; NB], [0.0; NB]);

impl Prepared {
    fn n(&self) -> usize {
        self.cand.len()
    }

    fn state(&self, law: &dyn AsperityLaw, a: Vec<f64>, deltas: &[f64]) -> State {
        let n = self.n();
        let pi = std::f64::consts::PI;
        let loc: Vec<Local> = (0..n)
            .map(|p| {
                if a[p] > 0.0 {
                    local(law, a[p], self.radius[p])
                } else {
                    Local::default()
                }
            })
            .collect();
        let act: Vec<usize> = (0..n).filter(|&p| a[p] > 0.0).collect();
        let mut basis = vec![ZB; n];
        let mut d_other = vec![0.0; n];
        let mut u_other = vec![[0.0; NB]; n];
        if let Some(far) = &self.far {
            for &l in &act {
                basis[l] = far.basis(a[l]);
            }
            let y: Vec<(usize, f64, Vb)> = act
                .iter()
                .map(|&l| {
                    let mut v = basis[l].0;
                    v.iter_mut().for_each(|x| *x *= loc[l].q / pi);
                    (l, loc[l].q, v)
                })
                .collect();
            for k in 0..n {
                if deltas[k] <= 0.0 {
                    continue;
                }
                let row = &self.nf[k * n..(k + 1) * n];
                let mut d = 0.0;
                let mut u = [0.0; NB];
                for (l, ql, yl) in &y {
                    if *l == k {
                        continue;
                    }
                    let nkl = &row[*l];
                    for i in 0..NB {
                        d += nkl[i] * yl[i];
                        u[i] += ql * nkl[i];
                    }
                }
                d_other[k] = d;
                u_other[k] = u;
            }
        }
        let mut near_vals = vec![[0.0; 4]; self.near.len()];
        let mut near_d2 = vec![[0.0; 3]; n];
        let mut e_cross = vec![0.0; n];
        for (e, &(p, q, r)) in self.near.iter().enumerate() {
            if a[p] <= 0.0 && a[q] <= 0.0 {
                continue;
            }
            let dp = g_derivs(law, &loc[p], a[p], self.radius[p], r);
            let dq = g_derivs(law, &loc[q], a[q], self.radius[q], r);
            near_vals[e] = [dp[0], dp[1], dq[0], dq[1]];
            d_other[q] += dp[0];
            d_other[p] += dq[0];
            e_cross[p] += loc[q].q * dp[1];
            e_cross[q] += loc[p].q * dq[1];
            for i in 0..3 {
                near_d2[p][i] += loc[q].q * dp[2 + i];
                near_d2[q][i] += loc[p].q * dq[2 + i];
            }
        }
        let mut self_g = vec![0.0; n];
        let mut self_h = vec![0.0; n];
        for &p in &act {
            for &r in &self.near_self {
                let d = g_derivs(law, &loc[p], a[p], self.radius[p], r);
                self_g[p] += d[0];
                self_h[p] += d[1];
                for i in 0..3 {
                    near_d2[p][i] += loc[p].q * d[2 + i];
                }
            }
        }
        let mut st = State {
            a,
            loc,
            basis,
            d_other,
            u_other,
            near_vals,
            near_d2,
            e_cross,
            self_g,
            self_h,
            f: vec![f64::NAN; n],
        };
        for &p in &act {
            st.f[p] = self.f_of(
                &st,
                p,
                &st.loc[p],
                &st.basis[p],
                (st.self_g[p], st.self_h[p], st.e_cross[p]),
                deltas[p],
            );
        }
        st
    }

    /// Total displacement D_k at k (m) and E_k = Σ_j Q_j ∂G_k(r_kj)/∂a_k (m²) with
    /// asperity p at the local state `lp`, `b` (basis), and its near sums
    /// `near` = (Σ self G, Σ self ∂G/∂a, Σ_near Q_q ∂G_p/∂a_p); others from `st`.
    fn d_e(
        &self,
        st: &State,
        p: usize,
        lp: &Local,
        b: &(Vb, Vb),
        near: (f64, f64, f64),
    ) -> (f64, f64) {
        let mut d = st.d_other[p] + near.0;
        let mut e = near.2 + lp.q * near.1;
        if self.far.is_some() {
            let n = self.n();
            let nkk = &self.nf[p * n + p];
            let mut u = st.u_other[p];
            for i in 0..NB {
                u[i] += lp.q * nkk[i];
            }
            let pi = std::f64::consts::PI;
            d += lp.q * dot(nkk, &b.0) / pi;
            e += (lp.dq * dot(&u, &b.0) + lp.q * dot(&u, &b.1)) / pi;
        }
        (d, e)
    }

    /// U_E/c (m³) at the state `st`: Σ_k Q_k (D_k + s_k − 2δ_k) (module docs).
    fn energy(&self, st: &State, deltas: &[f64]) -> f64 {
        let mut u = 0.0;
        for (k, dk) in deltas.iter().enumerate() {
            if st.a[k] > 0.0 {
                let l = &st.loc[k];
                let near = (st.self_g[k], st.self_h[k], st.e_cross[k]);
                let (d, _) = self.d_e(st, k, l, &st.basis[k], near);
                u += l.q * (d + l.s - 2.0 * dk);
            }
        }
        u
    }

    /// F_p (m) with asperity p in the local state `lp` (module docs).
    fn f_of(
        &self,
        st: &State,
        p: usize,
        lp: &Local,
        b: &(Vb, Vb),
        near: (f64, f64, f64),
        delta_p: f64,
    ) -> f64 {
        let (d, e) = self.d_e(st, p, lp, b, near);
        d + lp.s - 2.0 * delta_p + (lp.q * lp.ds + e) / lp.dq
    }

    /// F_p as a function of a_p = `ap` alone, the others fixed at `st`: the Jacobian
    /// diagonal and F_p(0⁺) of inactive asperities.
    fn row(&self, law: &dyn AsperityLaw, st: &State, p: usize, ap: f64, delta_p: f64) -> f64 {
        let rp = self.radius[p];
        let lp = local(law, ap, rp);
        let b = self.far.as_ref().map_or(ZB, |f| f.basis(ap));
        let (mut sg, mut sh, mut ec) = (0.0, 0.0, 0.0);
        for &r in &self.near_self {
            let (g, h) = g_and_da(law, &lp, ap, rp, r);
            sg += g;
            sh += h;
        }
        for &e in &self.near_of[p] {
            let (i, j, r) = self.near[e];
            let o = if i == p { j } else { i };
            if st.a[o] > 0.0 {
                ec += st.loc[o].q * g_and_da(law, &lp, ap, rp, r).1;
            }
        }
        self.f_of(st, p, &lp, &b, (sg, sh, ec), delta_p)
    }

    /// The Jacobian ∂F_k/∂a_l on the active set `act` (row-major |act|²): off-diagonal
    /// entries analytic, the diagonal by central differences of [`Self::row`]
    /// (relative step 1e-6).
    fn jacobian(
        &self,
        law: &dyn AsperityLaw,
        st: &State,
        deltas: &[f64],
        act: &[usize],
    ) -> Vec<f64> {
        let (n, ma) = (self.n(), act.len());
        let mut jm = vec![0.0; ma * ma];
        let pi = std::f64::consts::PI;
        if self.far.is_some() {
            let z: Vec<Vb> = act
                .iter()
                .map(|&l| {
                    let (lq, (b, db)) = (&st.loc[l], &st.basis[l]);
                    let mut v = [0.0; NB];
                    for i in 0..NB {
                        v[i] = (lq.dq * b[i] + lq.q * db[i]) / pi;
                    }
                    v
                })
                .collect();
            for (ii, &k) in act.iter().enumerate() {
                let row = &self.nf[k * n..(k + 1) * n];
                let dqk = st.loc[k].dq;
                let out = &mut jm[ii * ma..(ii + 1) * ma];
                for (jj, &l) in act.iter().enumerate() {
                    if l != k {
                        let nkl = &row[l];
                        out[jj] = dot(nkl, &z[jj]) + st.loc[l].dq / dqk * dot(nkl, &z[ii]);
                    }
                }
            }
        }
        let mut pos = vec![usize::MAX; n];
        for (ii, &p) in act.iter().enumerate() {
            pos[p] = ii;
        }
        for (e, &(p, q, _)) in self.near.iter().enumerate() {
            let (ip, iq) = (pos[p], pos[q]);
            if ip == usize::MAX || iq == usize::MAX {
                continue;
            }
            let [_, hp, _, hq] = st.near_vals[e];
            let (dp, dq) = (st.loc[p].dq, st.loc[q].dq);
            jm[iq * ma + ip] += hp + dp * hq / dq;
            jm[ip * ma + iq] += hq + dq * hp / dp;
        }
        for (ii, &p) in act.iter().enumerate() {
            // local and far parts by differences with the near sums frozen …
            let h = 1e-6 * st.a[p];
            let near = (st.self_g[p], st.self_h[p], st.e_cross[p]);
            let frozen = |ap: f64| {
                let lp = local(law, ap, self.radius[p]);
                let b = self.far.as_ref().map_or(ZB, |f| f.basis(ap));
                self.f_of(st, p, &lp, &b, near, deltas[p])
            };
            let mut d = (frozen(st.a[p] + h) - frozen(st.a[p] - h)) / (2.0 * h);
            // … plus their a_p-derivative: Σ_self ∂G_p/∂a_p + (∂E_p^near/∂a_p)/Q'_p
            let [c0, cc, cz] = st.near_d2[p];
            if c0 != 0.0 || cc != 0.0 || cz != 0.0 {
                let (mut d2c, mut d2z) = (0.0, 0.0);
                if cc != 0.0 || cz != 0.0 {
                    let ha = 1e-5 * st.a[p];
                    let (_, c1, _, z1) = law.chi_zeta_derivs(st.a[p] + ha);
                    let (_, c2, _, z2) = law.chi_zeta_derivs(st.a[p] - ha);
                    d2c = (c1 - c2) / (2.0 * ha);
                    d2z = (z1 - z2) / (2.0 * ha);
                }
                d += st.self_h[p] + (c0 + cc * d2c + cz * d2z) / st.loc[p].dq;
            } else {
                d += st.self_h[p];
            }
            jm[ii * ma + ii] = d;
        }
        jm
    }
}

/// Where one active-set Newton search ended (see `RoughContact::active_set_newton`).
struct Search {
    a: Vec<f64>,
    st: State,
    kkt: f64,
    iterations: usize,
    exceeded: f64,
}

/// What one solve on a prepared geometry gave.
enum Outcome {
    /// The step and da_k/dδ of every summit (-).
    Done(Step, Vec<f64>),
    /// A contact radius (m) exceeded the far-field bound A: prepare again.
    Exceeded(f64),
}

/// The I-model complementary energy of one approach, ready to evaluate (for studies and
/// benchmarks of the solver's hot path): see [`RoughContact::interaction`].
pub struct Interaction<'r, 'a> {
    rc: &'r RoughContact<'a>,
    prep: Prepared,
    deltas: Vec<f64>,
}

impl Interaction<'_, '_> {
    /// U_E of eq. (P22) (J) and its gradient ∂U_E/∂a_k (N) at the contact radii `radii`
    /// (m, one per summit, as [`Step::radii`]); `grad` (one per summit) receives the
    /// gradient, 0 for asperities out of contact or not loaded at this approach (their
    /// radii are ignored). ∂U_E/∂a_k = c·Q'_k·F_k with c = 2E*₁/3 (module docs).
    pub fn energy_gradient(&self, radii: &[f64], grad: &mut [f64]) -> Result<f64, RoughError> {
        let ns = self.rc.summits.len();
        for (field, len) in [("radii", radii.len()), ("grad", grad.len())] {
            if len != ns {
                return Err(RoughError::Length {
                    field,
                    expected: ns,
                    found: len,
                });
            }
        }
        let p = &self.prep;
        let mut a = vec![0.0; p.n()];
        for (k, &s) in p.cand.iter().enumerate() {
            let v = radii[s];
            if !v.is_finite() || v < 0.0 {
                return Err(RoughError::LoadOutOfRange {
                    field: "radii",
                    value: v,
                    reason: "contact radii must be finite and ≥ 0 (m)".into(),
                });
            }
            if self.deltas[k] > 0.0 {
                a[k] = v;
            }
        }
        let st = p.state(self.rc.law, a, &self.deltas);
        let c = 2.0 * self.rc.law.e_star() / 3.0;
        grad.iter_mut().for_each(|g| *g = 0.0);
        for k in 0..p.n() {
            if st.a[k] > 0.0 {
                grad[p.cand[k]] = c * st.loc[k].dq * st.f[k];
            }
        }
        let u = c * p.energy(&st, &self.deltas);
        if !u.is_finite() {
            return Err(RoughError::NonFinite("I-model energy"));
        }
        Ok(u)
    }

    /// The far-field cut-off r_c (m): image pairs closer than this are summed exactly
    /// (∞ when the far field is disabled or not reachable).
    pub fn far_field_cutoff(&self) -> f64 {
        self.prep.far.as_ref().map_or(f64::INFINITY, |f| f.r_c)
    }

    /// Image pairs summed exactly and by the far-field model.
    pub fn image_pairs(&self) -> (usize, usize) {
        let n = self.prep.n();
        (
            self.prep.near.len() + n * self.prep.near_self.len(),
            self.prep.far_pairs,
        )
    }

    /// Largest error of the far-field model measured at build time, relative to the
    /// point-force scale (0 when disabled).
    pub fn far_field_error(&self) -> f64 {
        self.prep.far.as_ref().map_or(0.0, |f| f.worst)
    }
}

impl<'a> RoughContact<'a> {
    /// Reduces a surface (its summits, z̄, z_min and extent (m)) on a law.
    pub fn new(
        law: &'a dyn AsperityLaw,
        summits: Vec<Summit>,
        z_mean: f64,
        z_min: f64,
        extent: (f64, f64),
    ) -> Result<Self, RoughError> {
        let z_max = summits
            .iter()
            .map(|s| s.z)
            .fold(f64::NEG_INFINITY, f64::max);
        if summits.is_empty() {
            return Err(RoughError::NoSummits);
        }
        // Library callers pass these directly: refuse what would turn into NaN or
        // negative pressures (found by tests/fuzz_solvers.rs).
        let bad = |field: &'static str, value: f64, reason: String| {
            Err(RoughError::LoadOutOfRange {
                field,
                value,
                reason,
            })
        };
        let e = law.e_star();
        if !(e.is_finite() && e > 0.0) {
            return bad(
                "E*",
                e,
                "the law's modulus must be finite and > 0 Pa".into(),
            );
        }
        for (name, v) in [("extent", extent.0), ("extent", extent.1)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, "sample sides must be finite and > 0 m".into());
            }
        }
        for (k, s) in summits.iter().enumerate() {
            for (name, v) in [("summit x", s.x), ("summit y", s.y), ("summit z", s.z)] {
                if !v.is_finite() {
                    return bad(name, v, format!("summit {k}: must be finite (m)"));
                }
            }
            if !(s.radius.is_finite() && s.radius > 0.0) {
                return bad(
                    "summit radius",
                    s.radius,
                    format!("summit {k}: must be finite and > 0 m"),
                );
            }
        }
        if !(z_mean.is_finite() && z_mean <= z_max) {
            return bad(
                "z_mean",
                z_mean,
                format!("must be finite and ≤ z_M = {z_max:e} m"),
            );
        }
        if !(z_min.is_finite() && z_min <= z_max) {
            return bad(
                "z_min",
                z_min,
                format!("must be finite and ≤ z_M = {z_max:e} m"),
            );
        }
        Ok(RoughContact {
            law,
            summits,
            z_max,
            z_mean,
            z_min,
            extent,
            far_tol: 1e-5,
            far: std::sync::Mutex::new(None),
        })
    }

    /// Convenience: from a surface.
    pub fn from_surface(
        law: &'a dyn AsperityLaw,
        surface: &crate::surface::Surface,
    ) -> Result<Self, RoughError> {
        let s = crate::summits::find_summits(surface);
        let z_min = surface
            .heights()
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        Self::new(law, s.summits, surface.mean(), z_min, surface.extent())
    }

    /// Sets the tolerance of the far-field interaction model (module docs; default 1e-5):
    /// the largest error of every modelled G and ∂G/∂a relative to the point-force
    /// displacement (4/3)χa³/(πRr) and its a-derivative. 0 (or NaN) sums every image
    /// pair exactly.
    pub fn with_far_field_tolerance(mut self, tol: f64) -> Self {
        self.far_tol = if tol.is_nan() { 0.0 } else { tol.max(0.0) };
        self
    }

    /// The summits.
    pub fn summits(&self) -> &[Summit] {
        &self.summits
    }
    /// z_M − z̄ (m): the approach at which g_n = 0.
    pub fn top_to_mean(&self) -> f64 {
        self.z_max - self.z_mean
    }
    /// Largest meaningful approach z_M − z_min (m).
    pub fn max_delta(&self) -> f64 {
        self.z_max - self.z_min
    }
    /// Nominal area A₀ (m²).
    pub fn area(&self) -> f64 {
        self.extent.0 * self.extent.1
    }
    /// Approach δ (m) for a separation g_n (m) (P26).
    pub fn delta_for_gap(&self, gap: f64) -> f64 {
        self.top_to_mean() - gap
    }

    fn check_delta(&self, delta: f64) -> Result<(), RoughError> {
        if !delta.is_finite() || delta < 0.0 || delta > self.max_delta() {
            return Err(RoughError::LoadOutOfRange {
                field: "load",
                value: delta,
                reason: format!(
                    "the approach δ must lie in [0, z_M − z_min] = [0, {:e}] m (separation in [{:e}, {:e}] m)",
                    self.max_delta(),
                    self.top_to_mean() - self.max_delta(),
                    self.top_to_mean()
                ),
            });
        }
        Ok(())
    }

    fn interference(&self, k: usize, delta: f64) -> f64 {
        (delta - (self.z_max - self.summits[k].z)).max(0.0)
    }

    fn finish(
        &self,
        delta: f64,
        radii: Vec<f64>,
        stiffness: f64,
        kkt: Option<f64>,
        iterations: usize,
    ) -> Result<Step, RoughError> {
        let e = self.law.e_star();
        let mut load = 0.0;
        let mut area = 0.0;
        let mut contacts = 0;
        for (s, &a) in self.summits.iter().zip(&radii) {
            if a > 0.0 {
                load += 4.0 / 3.0 * e * self.law.chi(a) * a.powi(3) / s.radius;
                area += std::f64::consts::PI * a * a;
                contacts += 1;
            }
        }
        let a0 = self.area();
        let step = Step {
            delta,
            gap: self.top_to_mean() - delta,
            load,
            mean_pressure: load / a0,
            pressure_ratio: load / a0 / e,
            area_fraction: area / a0,
            contacts,
            stiffness,
            kkt_residual: kkt,
            iterations,
            radii,
        };
        if !(step.load.is_finite()
            && step.mean_pressure.is_finite()
            && step.stiffness.is_finite()
            && step.area_fraction.is_finite())
        {
            return Err(RoughError::NonFinite("step results"));
        }
        Ok(step)
    }

    /// N model at approach δ (m): every asperity alone, ζ(a_k)a_k²/R_k = δ_k.
    pub fn solve_independent(&self, delta: f64) -> Result<Step, RoughError> {
        self.check_delta(delta)?;
        let e = self.law.e_star();
        let mut radii = vec![0.0; self.summits.len()];
        let mut stiffness = 0.0;
        for (k, s) in self.summits.iter().enumerate() {
            let dk = self.interference(k, delta);
            if dk <= 0.0 {
                continue;
            }
            let a = contact_radius(self.law, s.radius, dk).ok_or(RoughError::NoRoot {
                index: k,
                delta: dk,
                radius: s.radius,
            })?;
            radii[k] = a;
            let l = local(self.law, a, s.radius);
            // dP/dδ_k = (dP/da)/(dδ_k/da), dδ_k/da = (ζ'a² + 2ζa)/R
            let dd = (l.dzeta * a * a + 2.0 * l.zeta * a) / s.radius;
            stiffness += 4.0 / 3.0 * e * l.dq / dd;
        }
        self.finish(delta, radii, stiffness, None, 0)
    }

    /// The far-field model for contact radii up to `a_need` and distances up to `r_hi`
    /// (m): the cached one while its bound A lies in [a_need, 2 a_need], else a new one.
    fn far_model(&self, a_need: f64, r_hi: f64) -> Option<std::sync::Arc<FarModel>> {
        if self.far_tol.is_nan() || self.far_tol <= 0.0 || a_need.is_nan() || a_need <= 0.0 {
            return None;
        }
        let mut guard = self.far.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(f) = guard.as_ref()
            && f.a_max >= a_need
            && f.a_max <= 2.0 * a_need
            && f.r_hi >= r_hi
        {
            return Some(f.clone());
        }
        let f = std::sync::Arc::new(FarModel::build(self.law, a_need, r_hi, self.far_tol)?);
        *guard = Some(f.clone());
        Some(f)
    }

    /// Summits with positive interference at approach δ.
    fn candidates(&self, delta: f64) -> Vec<usize> {
        (0..self.summits.len())
            .filter(|&k| self.interference(k, delta) > 0.0)
            .collect()
    }

    /// 1.2 × the largest N-model (or warm-start) contact radius of `cand` at δ (m):
    /// interactions shrink contacts, so this bounds the I-model radii (re-checked after
    /// every solve).
    fn a_bound(&self, cand: &[usize], delta: f64, warm: &[f64]) -> f64 {
        let mut amax: f64 = 0.0;
        for &k in cand {
            let a = contact_radius(
                self.law,
                self.summits[k].radius,
                self.interference(k, delta),
            )
            .unwrap_or(0.0);
            amax = amax.max(a).max(warm.get(k).copied().unwrap_or(0.0));
        }
        1.2 * amax
    }

    /// Interaction geometry of `cand` under `images` for contact radii up to `a_bound`
    /// (m); `exact` sums every image pair exactly.
    fn prepare(&self, images: Images, cand: Vec<usize>, a_bound: f64, exact: bool) -> Prepared {
        let (lx, ly) = self.extent;
        let m = match images {
            Images::Isolated => 0i64,
            Images::Periodic(m) => m as i64,
        };
        let r_hi = 1.01 * (2 * m + 1) as f64 * lx.hypot(ly);
        let far = if exact {
            None
        } else {
            self.far_model(a_bound, r_hi)
        };
        let (r_c, r_top) = far
            .as_ref()
            .map_or((f64::INFINITY, 0.0), |f| (f.r_c, f.r_hi));
        let is_far = |r: f64| r >= r_c && r <= r_top;
        let n = cand.len();
        let mut nf = Vec::new();
        let mut self_far = [0.0; NB];
        let mut near_self = Vec::new();
        let mut far_pairs = 0;
        for sx in -m..=m {
            for sy in -m..=m {
                if (sx, sy) != (0, 0) {
                    let r = (sx as f64 * lx).hypot(sy as f64 * ly);
                    match &far {
                        Some(f) if is_far(r) => f.accumulate(r, &mut self_far),
                        _ => near_self.push(r),
                    }
                }
            }
        }
        if far.is_some() {
            nf = vec![[0.0; NB]; n * n];
            for p in 0..n {
                nf[p * n + p] = self_far;
            }
            far_pairs += n * ((2 * m + 1) * (2 * m + 1) - 1) as usize - n * near_self.len();
        }
        let mut near = Vec::new();
        for p in 0..n {
            let a = &self.summits[cand[p]];
            for q in p + 1..n {
                let b = &self.summits[cand[q]];
                let mut acc = [0.0; NB];
                for sx in -m..=m {
                    for sy in -m..=m {
                        let dx = b.x + sx as f64 * lx - a.x;
                        let dy = b.y + sy as f64 * ly - a.y;
                        let r = (dx * dx + dy * dy).sqrt();
                        match &far {
                            Some(f) if is_far(r) => {
                                f.accumulate(r, &mut acc);
                                far_pairs += 1;
                            }
                            _ => near.push((p, q, r)),
                        }
                    }
                }
                if far.is_some() {
                    nf[p * n + q] = acc;
                    nf[q * n + p] = acc;
                }
            }
        }
        let mut near_of = vec![Vec::new(); n];
        for (i, &(p, q, _)) in near.iter().enumerate() {
            near_of[p].push(i);
            near_of[q].push(i);
        }
        let a_valid = far.as_ref().map_or(f64::INFINITY, |f| f.a_max);
        Prepared {
            radius: cand.iter().map(|&k| self.summits[k].radius).collect(),
            cand,
            far,
            nf,
            near,
            near_of,
            near_self,
            a_valid,
            far_pairs,
        }
    }

    /// I model at approach δ (m), warm-started from `warm` (contact radii of every
    /// summit, m; empty for a cold start).
    pub fn solve_interacting(
        &self,
        delta: f64,
        images: Images,
        warm: &[f64],
    ) -> Result<Step, RoughError> {
        self.check_delta(delta)?;
        let cand = self.candidates(delta);
        let bound = self.a_bound(&cand, delta, warm);
        let mut prep = self.prepare(images, cand, bound, false);
        Ok(self.solve_prepared(&mut prep, images, delta, warm)?.0)
    }

    /// Solves on `prep`, preparing again (larger bound A, finally exact sums) while a
    /// contact radius leaves the far-field model's range.
    fn solve_prepared(
        &self,
        prep: &mut Prepared,
        images: Images,
        delta: f64,
        warm: &[f64],
    ) -> Result<(Step, Vec<f64>), RoughError> {
        for attempt in 0..4 {
            match self.solve_on(prep, delta, warm)? {
                Outcome::Done(s, rate) => return Ok((s, rate)),
                Outcome::Exceeded(amax) => {
                    let cand = std::mem::take(&mut prep.cand);
                    *prep = self.prepare(images, cand, 1.2 * amax, attempt == 2);
                }
            }
        }
        Err(RoughError::NonFinite(
            "I-model contact radii (far-field bound)",
        ))
    }

    /// The I-model energy U_E of approach δ (m) under `images`, prepared for contact
    /// radii up to 1.2 × the N-model ones, to evaluate with
    /// [`Interaction::energy_gradient`].
    pub fn interaction(
        &self,
        images: Images,
        delta: f64,
    ) -> Result<Interaction<'_, 'a>, RoughError> {
        self.check_delta(delta)?;
        let cand = self.candidates(delta);
        let bound = self.a_bound(&cand, delta, &[]);
        let prep = self.prepare(images, cand, bound, false);
        let deltas = prep
            .cand
            .iter()
            .map(|&k| self.interference(k, delta))
            .collect();
        Ok(Interaction {
            rc: self,
            prep,
            deltas,
        })
    }

    /// The projected Newton / active-set iteration of [`Self::solve_on`] from the radii
    /// `a` (local indices), backtracking on U_E (`on_energy`) or on Σ F²: the final
    /// radii and state, the KKT residual (relative), the Newton steps taken and the
    /// largest radius (m) refused for leaving the far-field range (0 if none).
    fn active_set_newton(
        &self,
        geo: &Prepared,
        deltas: &[f64],
        scale: f64,
        mut a: Vec<f64>,
        on_energy: bool,
    ) -> Result<Search, RoughError> {
        let law = self.law;
        let n = geo.n();
        // Newton target; the KKT acceptance threshold is 1e-8 (relative).
        let tol = 1e-11 * scale;
        let mut iterations = 0;
        let mut kkt = f64::INFINITY;
        let mut st = geo.state(law, a.clone(), deltas);
        let mut u = geo.energy(&st, deltas);
        let mut exceeded: f64 = 0.0;
        // KKT check: active F = 0, inactive F(0⁺) ≥ 0; returns the worst violations
        // (m) and the violated inactive asperities with −F(0⁺).
        let check = |a: &[f64], st: &State| {
            let mut worst_act: f64 = 0.0;
            let mut worst_inact: f64 = 0.0;
            let mut violated = Vec::new();
            for p in 0..n {
                if a[p] > 0.0 {
                    worst_act = worst_act.max(st.f[p].abs());
                } else if deltas[p] > 0.0 {
                    let tiny = 1e-6 * (geo.radius[p] * deltas[p]).sqrt();
                    let f0 = geo.row(law, st, p, tiny, deltas[p]);
                    worst_inact = worst_inact.max(-f0);
                    if -f0 > tol {
                        violated.push((p, -f0));
                    }
                }
            }
            (worst_act, worst_inact, violated)
        };
        let mut converged = false;
        for _outer in 0..100 {
            let (worst_act, worst_inact, violated) = check(&a, &st);
            kkt = worst_act.max(worst_inact) / scale;
            if violated.is_empty() {
                // Done when the active set is solved (else Newton goes on from here).
                if worst_act <= 1e-9 * scale {
                    converged = true;
                    break;
                }
            } else {
                // Activate every violated asperity at the radius of its single-asperity
                // problem under the others' displacement: ζa²/R = δ_p − D_p ≈ −F_p(0⁺)/2.
                for (p, v) in violated {
                    let r = geo.radius[p];
                    a[p] = contact_radius(law, r, (0.5 * v).min(deltas[p]))
                        .unwrap_or(0.0)
                        .max(1e-3 * (r * deltas[p]).sqrt())
                        .min(geo.a_valid);
                }
                st = geo.state(law, a.clone(), deltas);
                u = geo.energy(&st, deltas);
            }
            // Projected Newton on the active set, backtracking on the energy U_E.
            for _ in 0..100 {
                let act: Vec<usize> = (0..n).filter(|&p| a[p] > 0.0).collect();
                let fmax = act.iter().map(|&p| st.f[p].abs()).fold(0.0, f64::max);
                let f2: f64 = act.iter().map(|&p| st.f[p] * st.f[p]).sum();
                if !fmax.is_finite() {
                    return Err(RoughError::NonFinite("I-model residual"));
                }
                if fmax <= tol || act.is_empty() {
                    break;
                }
                iterations += 1;
                let m = act.len();
                let mut jm = geo.jacobian(law, &st, deltas, &act);
                let mut rhs: Vec<f64> = act.iter().map(|&p| -st.f[p]).collect();
                let mut step = lu_solve(&mut jm, &mut rhs, m)
                    .ok_or(RoughError::NonFinite("I-model Jacobian (singular)"))?;
                // dU/dt/c along the step: Σ Q'_k F_k Δa_k (< 0 for a descent direction,
                // as when the Hessian in Q = χa³/R is positive definite)
                let mut slope: f64 = act
                    .iter()
                    .zip(&step)
                    .map(|(&p, s)| st.loc[p].dq * st.f[p] * s)
                    .sum();
                if on_energy && (slope.is_nan() || slope >= 0.0) {
                    // not a descent direction: steepest descent in Q, scaled by the
                    // single-asperity curvature dδ/da = (ζ'a² + 2ζa)/R
                    for (s, &p) in step.iter_mut().zip(&act) {
                        let l = &st.loc[p];
                        let curv = (l.dzeta * a[p] * a[p] + 2.0 * l.zeta * a[p]) / geo.radius[p];
                        *s = -st.f[p] / (2.0 * curv);
                    }
                    slope = act
                        .iter()
                        .zip(&step)
                        .map(|(&p, s)| st.loc[p].dq * st.f[p] * s)
                        .sum();
                }
                let mut t = 1.0;
                let mut accepted = false;
                for _ in 0..40 {
                    let mut trial = a.clone();
                    for (ii, &p) in act.iter().enumerate() {
                        let v = a[p] + t * step[ii];
                        trial[p] = if v <= 1e-9 * a[p] { 0.0 } else { v };
                    }
                    // The far-field model holds for a ≤ A only: stay inside, and prepare
                    // again with a larger A if the minimum lies beyond.
                    let beyond = act.iter().map(|&p| trial[p]).fold(0.0, f64::max);
                    if beyond > geo.a_valid {
                        exceeded = exceeded.max(beyond);
                        t *= 0.5;
                        continue;
                    }
                    let dropped = act.iter().any(|&p| trial[p] == 0.0);
                    let sn = geo.state(law, trial.clone(), deltas);
                    let un = geo.energy(&sn, deltas);
                    let ft2: f64 = (0..n)
                        .filter(|&p| trial[p] > 0.0)
                        .map(|p| sn.f[p] * sn.f[p])
                        .sum();
                    // Armijo on U_E; a full Newton step that halves Σ F² is taken too
                    // (close to the minimum the decrease of U_E is below its round-off).
                    // The fallback merit is Σ F², taking steps that drop a contact and
                    // tiny ones anyway, to move off a jump of G (overlapping contacts).
                    let take = if on_energy {
                        un <= u + 1e-4 * t * slope || (t == 1.0 && !dropped && ft2 <= 0.5 * f2)
                    } else {
                        dropped || ft2 < (1.0 - 1e-4 * t) * f2 || t < 1e-3
                    };
                    if take {
                        a = trial;
                        st = sn;
                        u = un;
                        accepted = true;
                        break;
                    }
                    if fmax <= 1e-9 * scale {
                        // within the acceptance threshold and at the round-off floor of
                        // F (differenced derivatives): stop rather than crawl
                        break;
                    }
                    t *= 0.5;
                }
                if !accepted {
                    break;
                }
            }
        }
        if !converged {
            let (worst_act, worst_inact, _) = check(&a, &st);
            kkt = worst_act.max(worst_inact) / scale;
        }
        Ok(Search {
            a,
            st,
            kkt,
            iterations,
            exceeded,
        })
    }

    /// The active-set Newton solve of one approach on a prepared geometry (module
    /// docs). Local indices with zero interference stay out of contact.
    fn solve_on(&self, geo: &Prepared, delta: f64, warm: &[f64]) -> Result<Outcome, RoughError> {
        let law = self.law;
        let n = geo.n();
        let deltas: Vec<f64> = geo
            .cand
            .iter()
            .map(|&k| self.interference(k, delta))
            .collect();
        let scale = deltas.iter().copied().fold(0.0, f64::max);
        if scale <= 0.0 {
            let zero = vec![0.0; self.summits.len()];
            return self
                .finish(delta, zero.clone(), 0.0, Some(0.0), 0)
                .map(|s| Outcome::Done(s, zero));
        }
        // Start: the previous radii where positive; asperities newly loaded (or out of
        // contact) enter through the KKT activation.
        let a: Vec<f64> = (0..n)
            .map(|p| {
                let w = warm.get(geo.cand[p]).copied().unwrap_or(0.0);
                if deltas[p] > 0.0 && w > 0.0 { w } else { 0.0 }
            })
            .collect();
        let search = self.active_set_newton(geo, &deltas, scale, a, true)?;
        let search = if search.kkt < 1e-8 || search.exceeded > 0.0 {
            search
        } else {
            // No KKT point reached from the warm start (e.g. stuck on the jump of G
            // where contacts overlap): start again from the N-model radii, on the
            // residual merit Σ F².
            let a: Vec<f64> = (0..n)
                .map(|p| {
                    if deltas[p] > 0.0 {
                        contact_radius(self.law, geo.radius[p], deltas[p])
                            .unwrap_or(0.0)
                            .min(geo.a_valid)
                    } else {
                        0.0
                    }
                })
                .collect();
            let mut again = self.active_set_newton(geo, &deltas, scale, a, false)?;
            again.iterations += search.iterations;
            if again.kkt < search.kkt || again.exceeded > 0.0 {
                again
            } else {
                search
            }
        };
        let Search {
            a,
            st,
            kkt,
            iterations,
            exceeded,
        } = search;
        if exceeded > 0.0 && (kkt.is_nan() || kkt >= 1e-8) {
            return Ok(Outcome::Exceeded(exceeded));
        }
        if kkt.is_nan() || kkt >= 1e-8 {
            return Err(RoughError::NotConverged {
                delta,
                residual: kkt,
            });
        }
        let amax = a.iter().copied().fold(0.0, f64::max);
        if amax > geo.a_valid {
            return Ok(Outcome::Exceeded(amax));
        }
        // Stiffness: J da/dδ = 2·1 on the active set; dP/dδ = (4/3)E* Σ Q'_k da_k/dδ.
        let act: Vec<usize> = (0..n).filter(|&p| a[p] > 0.0).collect();
        let m = act.len();
        let mut jm = geo.jacobian(law, &st, &deltas, &act);
        let mut rhs = vec![2.0; m];
        let dadd = lu_solve(&mut jm, &mut rhs, m)
            .ok_or(RoughError::NonFinite("I-model Jacobian (singular)"))?;
        let e = law.e_star();
        let mut stiffness = 0.0;
        for (ii, &p) in act.iter().enumerate() {
            stiffness += 4.0 / 3.0 * e * st.loc[p].dq * dadd[ii];
        }
        let mut radii = vec![0.0; self.summits.len()];
        let mut rate = vec![0.0; self.summits.len()];
        for p in 0..n {
            radii[geo.cand[p]] = a[p];
        }
        for (ii, &p) in act.iter().enumerate() {
            rate[geo.cand[p]] = dadd[ii];
        }
        self.finish(delta, radii, stiffness, Some(kkt), iterations)
            .map(|s| Outcome::Done(s, rate))
    }

    /// Solves one step of `model` at approach δ (m); `warm` as in
    /// [`solve_interacting`](Self::solve_interacting).
    pub fn solve(&self, model: Model, delta: f64, warm: &[f64]) -> Result<Step, RoughError> {
        match model {
            Model::Independent => self.solve_independent(delta),
            Model::Interacting(im) => self.solve_interacting(delta, im, warm),
        }
    }

    /// A load path: one step per approach. The I model prepares the interaction
    /// geometry once, for the largest approach of the path, and starts each step from
    /// the previous radii extrapolated with their rates da/dδ.
    pub fn curve(&self, model: Model, deltas: &[f64]) -> Result<Vec<Step>, RoughError> {
        let mut out: Vec<Step> = Vec::with_capacity(deltas.len());
        let mut warm: Vec<f64> = Vec::new();
        let mut last: Option<(f64, Vec<f64>)> = None; // (δ, da/dδ) of the previous step
        let mut prep: Option<Prepared> = None;
        for &d in deltas {
            let s = match model {
                Model::Independent => self.solve_independent(d)?,
                Model::Interacting(images) => {
                    self.check_delta(d)?;
                    let geo = match &mut prep {
                        Some(g) => g,
                        None => {
                            let dmax = deltas
                                .iter()
                                .copied()
                                .filter(|x| x.is_finite())
                                .fold(d, f64::max)
                                .min(self.max_delta());
                            let cand = self.candidates(dmax);
                            let bound = self.a_bound(&cand, dmax, &[]);
                            prep.insert(self.prepare(images, cand, bound, false))
                        }
                    };
                    // first-order predictor of a² (linear in δ for a Hertz contact):
                    // a² + 2a (da/dδ) Δδ, kept inside (0, A]
                    if let Some((d0, rate)) = &last {
                        for (w, r) in warm.iter_mut().zip(rate) {
                            if *w > 0.0 {
                                let p2 = *w * *w + 2.0 * *w * r * (d - d0);
                                *w = if p2 <= 0.0 {
                                    0.0
                                } else if p2.sqrt() > geo.a_valid {
                                    *w
                                } else {
                                    p2.sqrt()
                                };
                            }
                        }
                    }
                    let (s, rate) = self.solve_prepared(geo, images, d, &warm)?;
                    last = Some((d, rate));
                    s
                }
            };
            warm.clone_from(&s.radii);
            out.push(s);
        }
        Ok(out)
    }

    /// Finds the approach giving mean pressure `target` (Pa) by safeguarded Newton
    /// (the stiffness is dP/dδ) on the bracket [0, z_M − z_min]; relative tolerance 1e-10.
    pub fn solve_pressure(
        &self,
        model: Model,
        target: f64,
        warm: &[f64],
    ) -> Result<Step, RoughError> {
        let hi_step = self.solve(model, self.max_delta(), warm)?;
        if target.is_nan() || target <= 0.0 || target > hi_step.mean_pressure {
            return Err(RoughError::LoadOutOfRange {
                field: "load.mean_pressures",
                value: target,
                reason: format!(
                    "must lie in (0, {:e}] Pa (the mean pressure at full approach z_M − z_min)",
                    hi_step.mean_pressure
                ),
            });
        }
        let (mut lo, mut hi) = (0.0, self.max_delta());
        let mut d = 0.5 * hi;
        let mut w = warm.to_vec();
        for _ in 0..200 {
            let s = self.solve(model, d, &w)?;
            let err = s.mean_pressure - target;
            if err.abs() <= 1e-10 * target {
                return Ok(s);
            }
            if err < 0.0 {
                lo = d;
            } else {
                hi = d;
            }
            let slope = s.stiffness / self.area();
            let mut next = d - err / slope;
            if !next.is_finite() || next <= lo || next >= hi {
                next = 0.5 * (lo + hi);
            }
            if (hi - lo) <= 1e-15 * self.max_delta() {
                return Ok(s);
            }
            w = s.radii;
            d = next;
        }
        Err(RoughError::LoadOutOfRange {
            field: "load.mean_pressures",
            value: target,
            reason: "no convergence of the pressure search".into(),
        })
    }
}

/// Dense LU solve with partial pivoting (row-major m×m); None when singular.
fn lu_solve(a: &mut [f64], b: &mut [f64], m: usize) -> Option<Vec<f64>> {
    for k in 0..m {
        let piv = (k..m).max_by(|&i, &j| {
            a[i * m + k]
                .abs()
                .partial_cmp(&a[j * m + k].abs())
                .unwrap_or(std::cmp::Ordering::Equal)
        })?;
        if a[piv * m + k].is_nan() || a[piv * m + k] == 0.0 {
            return None;
        }
        if piv != k {
            for c in 0..m {
                a.swap(k * m + c, piv * m + c);
            }
            b.swap(k, piv);
        }
        let d = a[k * m + k];
        for i in k + 1..m {
            let f = a[i * m + k] / d;
            if f != 0.0 {
                for c in k..m {
                    a[i * m + c] -= f * a[k * m + c];
                }
                b[i] -= f * b[k];
            }
        }
    }
    let mut x = vec![0.0; m];
    for i in (0..m).rev() {
        let mut s = b[i];
        for c in i + 1..m {
            s -= a[i * m + c] * x[c];
        }
        x[i] = s / a[i * m + i];
    }
    if x.iter().all(|v| v.is_finite()) {
        Some(x)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::Homogeneous;
    use crate::surface::Surface;

    fn reference_surface() -> Option<Surface> {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/reference/surface_km10.npy");
        Some(Surface::read_npy(&p, 1e-3, true).expect("reference surface readable"))
    }

    /// Homogeneous N model = Greenwood–Williamson sum of Hertz contacts, written out
    /// directly: P = Σ (4/3)E*√R_k δ_k^{3/2}, A = π Σ R_k δ_k, dP/dδ = Σ 2E*√(R_k δ_k).
    #[test]
    fn n_model_is_greenwood_williamson() {
        let s = reference_surface().unwrap();
        let law = Homogeneous { e_star: 4.092e9 };
        let rc = RoughContact::from_surface(&law, &s).unwrap();
        let zm = rc.summits().iter().map(|s| s.z).fold(f64::MIN, f64::max);
        for delta in [1e-7, 2e-6, 7.3e-6, 1.1e-5] {
            let st = rc.solve_independent(delta).unwrap();
            let (mut p, mut a, mut k, mut c) = (0.0, 0.0, 0.0, 0);
            for sm in rc.summits() {
                let d = delta - (zm - sm.z);
                if d > 0.0 {
                    p += 4.0 / 3.0 * 4.092e9 * sm.radius.sqrt() * d.powf(1.5);
                    a += std::f64::consts::PI * sm.radius * d;
                    k += 2.0 * 4.092e9 * (sm.radius * d).sqrt();
                    c += 1;
                }
            }
            assert_eq!(st.contacts, c);
            assert!((st.load - p).abs() <= 1e-13 * p, "{} {p}", st.load);
            assert!((st.area_fraction * 1e-6 - a).abs() <= 1e-13 * a);
            assert!((st.stiffness - k).abs() <= 1e-13 * k);
            assert!((st.mean_pressure - p / 1e-6).abs() <= 1e-13 * p / 1e-6);
        }
    }

    fn summit(x: f64, y: f64, z: f64, r: f64) -> Summit {
        Summit {
            index: (0, 0),
            x,
            y,
            z,
            radius: r,
        }
    }

    /// U_E of eq. (P22) written out directly with `law::displacement` (independent of
    /// the solver's G/∂G code), for an isolated set of summits.
    fn u_e(law: &dyn AsperityLaw, sums: &[Summit], a: &[f64], dk: &[f64]) -> f64 {
        let c = 2.0 * law.e_star() / 3.0;
        let mut u = 0.0;
        for j in 0..sums.len() {
            if a[j] <= 0.0 {
                continue;
            }
            let mut inter = 0.0;
            for l in 0..sums.len() {
                if l != j && a[l] > 0.0 {
                    let r = (sums[j].x - sums[l].x).hypot(sums[j].y - sums[l].y);
                    inter += crate::law::displacement(law, a[l], sums[l].radius, r);
                }
            }
            let rj = sums[j].radius;
            let zj = law.zeta(a[j]);
            u += c * law.chi(a[j]) * a[j].powi(3) / rj
                * (inter + a[j] * a[j] / rj * (zj + 0.2) - 2.0 * dk[j]);
        }
        u
    }

    /// Two Hertz asperities at several distances: the solution is a stationary point
    /// of U_E (central differences of the directly written U_E vanish to 1e-6 of the
    /// gradient scale) and a minimum (U_E rises under ±1e-3 perturbations); far apart
    /// the I model equals the N model; the stiffness equals dP/dδ by central differences.
    #[test]
    fn two_asperities_energy_minimum() {
        let law = Homogeneous { e_star: 1e9 };
        for dist in [3e-5, 5e-5, 1e-3, 1.0] {
            let sums = vec![
                summit(0.0, 0.0, 1e-6, 1e-4),
                summit(dist, 0.0, 0.8e-6, 2e-4),
            ];
            let rc = RoughContact::new(&law, sums.clone(), 0.0, -1e-5, (10.0, 10.0)).unwrap();
            let delta = 0.9e-6;
            let st = rc.solve_interacting(delta, Images::Isolated, &[]).unwrap();
            let dk = [delta, delta - 0.2e-6];
            let a = st.radii.clone();
            assert!(a[0] > 0.0 && a[1] > 0.0);
            let u0 = u_e(&law, &sums, &a, &dk);
            // gradient scale: c·(3a²/R)·δ
            let scale = 2.0 / 3.0 * 1e9 * 3.0 * a[0] * a[0] / 1e-4 * delta;
            for k in 0..2 {
                let h = 1e-6 * a[k];
                let mut ap = a.clone();
                let mut am = a.clone();
                ap[k] += h;
                am[k] -= h;
                let g = (u_e(&law, &sums, &ap, &dk) - u_e(&law, &sums, &am, &dk)) / (2.0 * h);
                assert!(
                    g.abs() < 1e-6 * scale,
                    "{dist} {k}: grad {g:e} scale {scale:e}"
                );
                for f in [1.001, 0.999] {
                    let mut t = a.clone();
                    t[k] *= f;
                    assert!(u_e(&law, &sums, &t, &dk) > u0);
                }
            }
            assert!(st.kkt_residual.unwrap() < 1e-8);
            let n = rc.solve_independent(delta).unwrap();
            assert!(st.load < n.load);
            // Far apart the coupling is the point-force displacement ~ (4/3)a³/(πRr),
            // here ≈ 4e-12 m against δ ≈ 1e-6 m: I → N to that order.
            if dist >= 1.0 {
                assert!((st.load - n.load).abs() < 1e-5 * n.load);
            }
            let h = 1e-4 * delta;
            let sp = rc
                .solve_interacting(delta + h, Images::Isolated, &a)
                .unwrap();
            let sm = rc
                .solve_interacting(delta - h, Images::Isolated, &a)
                .unwrap();
            let fd = (sp.load - sm.load) / (2.0 * h);
            assert!(
                (st.stiffness - fd).abs() < 1e-5 * fd,
                "{} {fd}",
                st.stiffness
            );
        }
    }

    /// A shadowed asperity: its interference is smaller than the neighbour's
    /// displacement, so the KKT conditions keep it out of contact.
    #[test]
    fn shadowed_asperity_stays_out() {
        let law = Homogeneous { e_star: 1e9 };
        let sums = vec![
            summit(0.0, 0.0, 1e-6, 1e-3),
            summit(3e-5, 0.0, 0.2e-6, 1e-4),
        ];
        let rc = RoughContact::new(&law, sums, 0.0, -1e-5, (1.0, 1.0)).unwrap();
        let st = rc.solve_interacting(1.0e-6, Images::Isolated, &[]).unwrap();
        let n = rc.solve_independent(1.0e-6).unwrap();
        assert_eq!(n.contacts, 2);
        assert_eq!(st.contacts, 1);
        assert_eq!(st.radii[1], 0.0);
        assert!(st.kkt_residual.unwrap() < 1e-8);
    }

    /// Whole reference surface, homogeneous: I model converges with KKT < 1e-8 on
    /// a load path, is below the N model in load, and periodic images lower it further.
    #[test]
    fn reference_surface_interacting_homogeneous() {
        let s = reference_surface().unwrap();
        let law = Homogeneous { e_star: 4.092e9 };
        let rc = RoughContact::from_surface(&law, &s).unwrap();
        let deltas: Vec<f64> = (1..=10).map(|i| i as f64 * 1.1e-6).collect();
        let iso = rc
            .curve(Model::Interacting(Images::Isolated), &deltas)
            .unwrap();
        let per = rc
            .curve(Model::Interacting(Images::Periodic(2)), &deltas)
            .unwrap();
        let nm = rc.curve(Model::Independent, &deltas).unwrap();
        for ((i, p), n) in iso.iter().zip(&per).zip(&nm) {
            assert!(i.kkt_residual.unwrap() < 1e-8);
            assert!(p.kkt_residual.unwrap() < 1e-8);
            // (equal when a single contact has no neighbour: Newton tolerance 1e-11)
            assert!(i.load <= n.load * (1.0 + 1e-9));
            assert!(p.load <= i.load * (1.0 + 1e-9));
        }
    }

    #[test]
    fn pressure_control_and_range_errors() {
        let s = reference_surface().unwrap();
        let law = Homogeneous { e_star: 4.092e9 };
        let rc = RoughContact::from_surface(&law, &s).unwrap();
        let st = rc.solve_independent(5e-6).unwrap();
        let back = rc
            .solve_pressure(Model::Independent, st.mean_pressure, &[])
            .unwrap();
        assert!((back.delta - 5e-6).abs() < 1e-9 * 5e-6);
        assert!(rc.solve_independent(-1e-9).is_err());
        assert!(rc.solve_independent(1.0).is_err());
        let e = rc
            .solve_pressure(Model::Independent, 1e12, &[])
            .unwrap_err();
        assert!(e.to_string().contains("mean_pressures"), "{e}");
    }

    /// Homogeneous solid: the far-field model (default tolerance) changes loads and areas
    /// by less than 1e-6 relative and stiffnesses by less than 1e-5 against exact pair
    /// sums (tolerance 0), periodic 5×5 and isolated.
    #[test]
    fn far_field_matches_exact_sums() {
        let s = reference_surface().unwrap();
        let law = Homogeneous { e_star: 4.092e9 };
        let fast = RoughContact::from_surface(&law, &s).unwrap();
        let exact = RoughContact::from_surface(&law, &s)
            .unwrap()
            .with_far_field_tolerance(0.0);
        let deltas: Vec<f64> = (1..=10).map(|i| i as f64 * 1.1e-6).collect();
        for im in [Images::Periodic(2), Images::Isolated] {
            let f = fast.curve(Model::Interacting(im), &deltas).unwrap();
            let e = exact.curve(Model::Interacting(im), &deltas).unwrap();
            for (x, y) in f.iter().zip(&e) {
                if y.load > 0.0 {
                    assert!(
                        (x.load - y.load).abs() <= 1e-6 * y.load,
                        "{} {}",
                        x.load,
                        y.load
                    );
                    assert!((x.area_fraction - y.area_fraction).abs() <= 1e-6 * y.area_fraction);
                    assert!((x.stiffness - y.stiffness).abs() <= 1e-5 * y.stiffness);
                }
            }
        }
    }

    /// The shipped family table (tables/paper-two-layer.strata) on the paper's stack
    /// with E2/E1 = `ratio`.
    fn paper_law(ratio: f64) -> crate::table::TableLaw {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tables/paper-two-layer.strata");
        let table = crate::table::Table::load(&p).expect("shipped table readable");
        let stack = crate::stack::Stack::paper_two_layer(ratio).expect("stack");
        table.law_for(&stack).expect("law")
    }

    /// The paper's surface (scenes/paper-E2E1-5-interacting.toml) with k_M = `k_max`.
    fn paper_surface(k_max: f64) -> Surface {
        Surface::generate(&crate::surface::GenerateParams {
            size: 1e-3,
            grid: 512,
            fractal_dimension: 2.4,
            k_min: 2.0,
            k_max,
            rms: 3.4e-6,
            seed: 20240611,
        })
        .expect("surface")
    }

    /// 20 approaches up to 0.87 (z_M − z̄), as the benches.
    fn path(rc: &RoughContact) -> Vec<f64> {
        (1..=20)
            .map(|i| 0.87 * rc.top_to_mean() * i as f64 / 20.0)
            .collect()
    }

    /// The error control of the far field, stated as a bound and checked against the
    /// exact pair-by-pair image sum (tolerance 0) on the layered table, k_M = 40, 5×5
    /// periodic images (687k image pairs) and isolated, at the solved state of the last
    /// step plus a perturbed one: every gradient component obeys
    /// |Δ∂U_E/∂a_k| ≤ c Q'_k · 2 tol · P_k and |ΔU_E| ≤ c tol Σ_k Q_k P_k, where
    /// P_k = Σ_{l, images} (4/3)Q_l/(π r) is the point-force displacement at k (each
    /// modelled G and ∂G/∂a is within tol of its point-force scale); and the residual
    /// F_k itself moves by less than 2e-7 δ (measured 3e-8 δ).
    #[test]
    fn far_field_error_bound_layered_km40() {
        let law = paper_law(5.0);
        let s = paper_surface(40.0);
        let fast = RoughContact::from_surface(&law, &s).unwrap();
        let exact = RoughContact::from_surface(&law, &s)
            .unwrap()
            .with_far_field_tolerance(0.0);
        let tol = 1e-5;
        let (lx, ly) = s.extent();
        let delta = path(&fast)[19];
        for (images, m) in [(Images::Periodic(2), 2i64), (Images::Isolated, 0)] {
            let st = fast.solve_interacting(delta, images, &[]).unwrap();
            let mut states = vec![st.radii.clone()];
            // a perturbed state (±5 %), off the minimum
            states.push(
                st.radii
                    .iter()
                    .enumerate()
                    .map(|(k, a)| a * (1.0 + 0.05 * ((k % 3) as f64 - 1.0)))
                    .collect(),
            );
            let fi = fast.interaction(images, delta).unwrap();
            let ei = exact.interaction(images, delta).unwrap();
            let (near, far) = fi.image_pairs();
            assert!(far > 2 * near, "far field barely used: {near} {far}");
            let c = 2.0 * law.e_star() / 3.0;
            for radii in &states {
                let ns = radii.len();
                let (mut gf, mut ge) = (vec![0.0; ns], vec![0.0; ns]);
                let uf = fi.energy_gradient(radii, &mut gf).unwrap();
                let ue = ei.energy_gradient(radii, &mut ge).unwrap();
                let sm = fast.summits();
                let q: Vec<f64> = (0..ns)
                    .map(|k| law.chi(radii[k]) * radii[k].powi(3) / sm[k].radius)
                    .collect();
                let mut bound_u = 0.0;
                let mut worst: f64 = 0.0;
                let mut worst_f: f64 = 0.0; // max |ΔF_k|/δ
                for k in 0..ns {
                    if radii[k] <= 0.0 {
                        continue;
                    }
                    let mut pk = 0.0;
                    for l in 0..ns {
                        for sx in -m..=m {
                            for sy in -m..=m {
                                let r = (sm[l].x + sx as f64 * lx - sm[k].x)
                                    .hypot(sm[l].y + sy as f64 * ly - sm[k].y);
                                if r > 0.0 {
                                    pk += 4.0 / 3.0 * q[l] / (std::f64::consts::PI * r);
                                }
                            }
                        }
                    }
                    let (_, dchi, _, _) = law.chi_zeta_derivs(radii[k]);
                    let dq = (dchi * radii[k].powi(3) + 3.0 * law.chi(radii[k]) * radii[k].powi(2))
                        / sm[k].radius;
                    let bound = c * dq * 2.0 * tol * pk;
                    worst = worst.max((gf[k] - ge[k]).abs() / bound);
                    worst_f = worst_f.max((gf[k] - ge[k]).abs() / (c * dq) / delta);
                    bound_u += c * tol * q[k] * pk;
                }
                eprintln!(
                    "{images:?}: gradient error / bound {worst:.2e}, energy error / bound {:.2e}, max |ΔF|/δ {worst_f:.2e}",
                    (uf - ue).abs() / bound_u
                );
                assert!(worst <= 1.0, "{images:?}: gradient error / bound {worst:e}");
                // and in absolute terms (measured 3e-8): F moves by < 2e-7 δ
                assert!(worst_f <= 2e-7, "{images:?}: max |ΔF|/δ {worst_f:e}");
                assert!(
                    (uf - ue).abs() <= bound_u,
                    "{images:?}: energy error {:e} bound {bound_u:e}",
                    (uf - ue).abs()
                );
            }
        }
    }

    /// The energy and gradient of [`Interaction`] are consistent (central differences of
    /// U_E match ∂U_E/∂a_k to 1e-6 of the gradient scale) on the layered table with
    /// periodic images, far field on.
    #[test]
    fn energy_gradient_consistent_layered() {
        let law = paper_law(5.0);
        let s = paper_surface(10.0);
        let rc = RoughContact::from_surface(&law, &s).unwrap();
        let delta = path(&rc)[15];
        let st = rc
            .solve_interacting(delta, Images::Periodic(2), &[])
            .unwrap();
        let it = rc.interaction(Images::Periodic(2), delta).unwrap();
        let radii: Vec<f64> = st.radii.iter().map(|a| a * 0.97).collect();
        let mut g = vec![0.0; radii.len()];
        let _ = it.energy_gradient(&radii, &mut g).unwrap();
        let scale = g.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let mut dummy = vec![0.0; radii.len()];
        for k in (0..radii.len()).filter(|&k| radii[k] > 0.0) {
            let h = 1e-6 * radii[k];
            let (mut p, mut m) = (radii.clone(), radii.clone());
            p[k] += h;
            m[k] -= h;
            let fd = (it.energy_gradient(&p, &mut dummy).unwrap()
                - it.energy_gradient(&m, &mut dummy).unwrap())
                / (2.0 * h);
            assert!(
                (fd - g[k]).abs() <= 1e-6 * scale,
                "{k}: {fd:e} {:e} (scale {scale:e})",
                g[k]
            );
        }
    }

    /// k_M = 40, layered table (E2/E1 = 5 and 1), isolated and 5×5 periodic: the
    /// 20-step load path converges with KKT residual < 1e-8 at every step, and at the
    /// last step U_E is a local minimum (rises when any of 40 asperities' radius moves
    /// by ±0.1 %, or an asperity out of contact enters). Isolated k_M = 40 and periodic
    /// k_M = 10 agree with exact pair sums: loads and areas to 1e-6, stiffness to 1e-5.
    #[test]
    fn km40_paths_converge_and_match_exact() {
        for ratio in [5.0, 1.0] {
            let law = paper_law(ratio);
            for km in [40.0, 10.0] {
                let s = paper_surface(km);
                let rc = RoughContact::from_surface(&law, &s).unwrap();
                let deltas = path(&rc);
                for images in [Images::Isolated, Images::Periodic(2)] {
                    let c = rc.curve(Model::Interacting(images), &deltas).unwrap();
                    for st in &c {
                        assert!(st.kkt_residual.unwrap() < 1e-8, "{st:?}");
                    }
                    let last = c.last().unwrap();
                    if km == 40.0 {
                        let it = rc.interaction(images, *deltas.last().unwrap()).unwrap();
                        let mut g = vec![0.0; last.radii.len()];
                        let u0 = it.energy_gradient(&last.radii, &mut g).unwrap();
                        let (inside, outside): (Vec<usize>, Vec<usize>) =
                            (0..last.radii.len()).partition(|&k| last.radii[k] > 0.0);
                        for &k in inside.iter().step_by((inside.len() / 40).max(1)) {
                            for f in [1.001, 0.999] {
                                let mut r = last.radii.clone();
                                r[k] *= f;
                                assert!(it.energy_gradient(&r, &mut g).unwrap() > u0);
                            }
                        }
                        let zm = rc.summits().iter().map(|s| s.z).fold(f64::MIN, f64::max);
                        let loaded = outside
                            .iter()
                            .filter(|&&k| rc.summits()[k].z > zm - deltas[19]);
                        for &k in loaded.take(20) {
                            let mut r = last.radii.clone();
                            r[k] = 1e-7;
                            assert!(it.energy_gradient(&r, &mut g).unwrap() > u0);
                        }
                    }
                    let compare = (km == 40.0 && images == Images::Isolated)
                        || (km == 10.0 && images == Images::Periodic(2));
                    if compare {
                        let ex = RoughContact::from_surface(&law, &s)
                            .unwrap()
                            .with_far_field_tolerance(0.0)
                            .curve(Model::Interacting(images), &deltas)
                            .unwrap();
                        for (x, y) in c.iter().zip(&ex) {
                            if y.load > 0.0 {
                                assert!((x.load / y.load - 1.0).abs() <= 1e-6);
                                assert!((x.area_fraction / y.area_fraction - 1.0).abs() <= 1e-6);
                                assert!((x.stiffness / y.stiffness - 1.0).abs() <= 1e-5);
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn interaction_rejects_bad_input() {
        let law = Homogeneous { e_star: 1e9 };
        let sums = vec![
            summit(0.0, 0.0, 1e-6, 1e-4),
            summit(5e-5, 0.0, 0.8e-6, 2e-4),
        ];
        let rc = RoughContact::new(&law, sums, 0.0, -1e-5, (1e-3, 1e-3)).unwrap();
        let it = rc.interaction(Images::Isolated, 0.9e-6).unwrap();
        let mut g = vec![0.0; 2];
        let e = it.energy_gradient(&[1e-6], &mut g).unwrap_err();
        assert!(e.to_string().contains("radii"), "{e}");
        let e = it.energy_gradient(&[1e-6, f64::NAN], &mut g).unwrap_err();
        assert!(e.to_string().contains("radii"), "{e}");
        assert!(rc.interaction(Images::Isolated, -1.0).is_err());
    }
}
