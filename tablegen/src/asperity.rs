//! The axisymmetric asperity on a layered solid: full solution of the paper's §3
//! (physics.md §3).
//!
//! A rigid flat pressed by δ against an axisymmetric asperity of profile f(r) (or,
//! equivalently, a rigid indenter of that profile pressed into the layered solid),
//! contact radius a. With s = r/a the auxiliary function φ (Pa·m) solves (P9)
//!
//! ```text
//!   φ(s) + ∫₀¹ K_a(s,t) φ(t) dt = G(s),
//!   paraboloid  f = r²/(2R):      G = α(δ − (a²/R) s²)          (P13)
//!   cone (half-angle θ):          G = α(δ − (π/2) a s cot θ)
//!   flat punch (radius a):        G = α δ
//! ```
//!
//! with α = −E*₁/2. G is linear in δ, so two solves (right-hand sides α and α·g(s))
//! give φ = δ φ₁ − c φ_g for every δ, and for the smooth profiles the edge condition
//! φ(1) = 0 gives δ = c φ_g(1)/φ₁(1) without iteration. Then (P10, P11, P12)
//!
//! ```text
//!   P      = −4a ∫₀¹ φ dt                                   (N, positive in compression)
//!   p(s)   = (2/(πa)) [∫_s¹ φ′(t)/√(t²−s²) dt − φ(1)/√(1−s²)]   (Pa, = −σ_zz, s < 1)
//!   u_z(s) = δ − f(a s)                                          (s ≤ 1)
//!   u_z(s) = (2/(απ)) ∫₀¹ φ(t) [1/√(s²−t²) + ∫₀^∞ k_z(ρ/a) cos(ρt) J₀(ρs) dρ] dt   (s > 1)
//! ```
//!
//! (the φ(1) term of p vanishes for smooth profiles and gives the flat punch's edge
//! singularity). For a given δ the paraboloid's a is found by a safeguarded secant
//! (Illinois) iteration on ln δ(ln a), bracketed first.
//!
//! # Accuracy of the default ([`Options::default`])
//! * a ≤ 4 h₁: Gauss–Legendre Nyström, 12 + 4⌈a/h₁⌉ nodes (16–28): force and δ to ~1e−14
//!   relative (the accuracy–cost study, docs/accuracy-cost.md: 8–24 nodes reach round-off
//!   on the paper stacks; the rule keeps a margin for extreme modulus ratios).
//! * a > 4 h₁: product integration starting from N = 2 a/h₁ intervals (at least 256),
//!   Richardson-extrapolated against N/2, N doubled (up to 8192) while two successive
//!   extrapolations differ by more than [`AUTO_REFINE_TOL`] = 2e−3: ~1e−8 relative at
//!   a/h₁ ≤ 10, ~1e−6 at a/h₁ = 100 for compressible layers; nearly incompressible
//!   layers on stiff bases take the finer grids (ν = 0.5 at a/h₁ = 100: N = 4096).
//! * homogeneous stacks (k_z ≡ 0): closed form, exact to round-off.

use std::f64::consts::PI;

use strata_runtime::numerics::{Falsi, Tolerance, bracketed};
use strata_runtime::{Bodies, Compliance, Solid};
use thiserror::Error;

use crate::fredholm::{self, Discretisation, FredholmError, FredholmSolution};
use crate::kernel::{KernelError, KzQuadrature, gauss_legendre};

/// a/h₁ up to which the default uses Gauss–Legendre Nyström.
pub const NYSTROM_MAX_A_OVER_H: f64 = 4.0;

/// Automatic product grids are doubled while the Richardson extrapolations from
/// (N/4, N/2) and (N/2, N) differ (relative, in φ(1) and ∫φ) by more than this: the
/// difference estimates the error of the coarser extrapolation, the accepted one is
/// several times better (O(Δ³) or faster). Measured on one layer on a rigid base at
/// a/h₁ = 100 (errors of the accepted grid against N = 4096): ν = 0.3, 0.45, 0.49 stay
/// at N = 256 (6e-5, 3.4e-4, 1e-3); ν = 0.499 → 512 (3.3e-4); ν = 0.5 → 4096. At
/// a/h₁ = 1000, ν = 0.4999 on a stiff elastic base goes to N = 8016 (the fixed
/// N = 2a/h₁ was ~2 % off there).
pub const AUTO_REFINE_TOL: f64 = 2e-3;

/// The largest automatic product grid (intervals).
pub const AUTO_MAX_INTERVALS: usize = 8192;

/// Errors of the asperity solver. Each names the offending quantity.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum AsperityError {
    /// A parameter is out of range or not finite.
    #[error("{name} = {value}: {reason}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error(transparent)]
    Kernel(#[from] KernelError),
    #[error(transparent)]
    Fredholm(#[from] FredholmError),
    /// The root find for a(δ) did not converge.
    #[error("no contact radius found for delta = {delta} m: {reason}")]
    NoConvergence { delta: f64, reason: String },
    /// A result came out non-finite.
    #[error("non-finite {what} (a = {a} m)")]
    NonFinite { what: &'static str, a: f64 },
}

fn positive(name: &'static str, value: f64) -> Result<f64, AsperityError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(AsperityError::InvalidParameter {
            name,
            value,
            reason: "must be positive and finite",
        })
    }
}

/// How the Fredholm equation is discretised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Nyström for a ≤ [`NYSTROM_MAX_A_OVER_H`]·h₁, product integration beyond (see the
    /// module docs for node counts and accuracy).
    Auto,
    /// Always this discretisation.
    Fixed(Discretisation),
}

/// Solver options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    pub method: Method,
    /// Intervals of the uniform grid on which φ is kept for profiles (Nyström
    /// solutions; product solutions keep their own grid).
    pub profile_grid: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            method: Method::Auto,
            profile_grid: 512,
        }
    }
}

/// The asperity's profile f(r).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// f = r²/(2R), radius R (m).
    Paraboloid { radius: f64 },
    /// f = r cot θ, half-angle θ (rad) in (0, π/2).
    Cone { half_angle: f64 },
    /// Flat punch (f ≡ 0 inside the given radius a).
    FlatPunch,
}

impl Shape {
    /// f(r) (m).
    pub fn height(&self, r: f64) -> f64 {
        match *self {
            Shape::Paraboloid { radius } => r * r / (2.0 * radius),
            Shape::Cone { half_angle } => r / half_angle.tan(),
            Shape::FlatPunch => 0.0,
        }
    }
}

/// One solved contact.
#[derive(Debug, Clone)]
pub struct Solution {
    pub shape: Shape,
    /// Contact radius a (m).
    pub a: f64,
    /// Approach δ (m).
    pub delta: f64,
    /// Normal force P (N), positive in compression.
    pub force: f64,
    /// φ (Pa·m) on the uniform grid s_i = i/(len−1).
    pub phi: Vec<f64>,
    alpha: f64,
    stack: Bodies,
    homogeneous: bool,
}

/// The full solver for one stack.
#[derive(Debug, Clone)]
pub struct Asperity {
    stack: Bodies,
    comp: Compliance,
    alpha: f64,
    h1: Option<f64>,
    homogeneous: bool,
    opts: Options,
}

impl Asperity {
    /// Prepares the solver for `stack`.
    pub fn new(stack: &(impl Solid + ?Sized), opts: Options) -> Result<Asperity, AsperityError> {
        if opts.profile_grid < 2 || opts.profile_grid > 100_000 {
            return Err(AsperityError::InvalidParameter {
                name: "profile_grid",
                value: opts.profile_grid as f64,
                reason: "must be in 2..=100000",
            });
        }
        let homogeneous = stack.is_homogeneous();
        Ok(Asperity {
            stack: stack.bodies(),
            comp: Compliance::new(stack),
            alpha: stack.alpha(),
            h1: stack.top_thickness(),
            homogeneous,
            opts,
        })
    }

    /// The discretisation used at contact radius `a` (m).
    pub fn discretisation(&self, a: f64) -> Discretisation {
        match self.opts.method {
            Method::Fixed(d) => d,
            Method::Auto => {
                let ah = a / self.h1.unwrap_or(f64::INFINITY);
                if ah <= NYSTROM_MAX_A_OVER_H {
                    Discretisation::Nystrom {
                        nodes: 12 + 4 * ah.ceil() as usize,
                    }
                } else {
                    let n = (2.0 * ah).ceil().clamp(256.0, 2048.0) as usize;
                    Discretisation::Product {
                        intervals: n + n % 2,
                        richardson: true,
                    }
                }
            }
        }
    }

    /// Solves with right-hand sides α and α·g(s).
    fn solve_pair(
        &self,
        a: f64,
        g: &(dyn Fn(f64) -> f64 + Sync),
        grid: bool,
    ) -> Result<FredholmSolution, AsperityError> {
        let al = self.alpha;
        let r1 = move |_s: f64| al;
        let r2 = move |s: f64| al * g(s);
        if self.homogeneous {
            // K ≡ 0: φ = G exactly. ∫₀¹ g is needed in closed form.
            let n = self.opts.profile_grid;
            let int_g = integrate_01(g);
            return Ok(FredholmSolution {
                at_one: vec![al, al * g(1.0)],
                integral: vec![al, al * int_g],
                grid: if grid {
                    vec![
                        vec![al; n + 1],
                        (0..=n).map(|i| r2(i as f64 / n as f64)).collect(),
                    ]
                } else {
                    Vec::new()
                },
            });
        }
        let quad = KzQuadrature::new(&self.stack, &self.comp, 2.0 * a)?;
        let n = if grid { self.opts.profile_grid } else { 0 };
        match (self.opts.method, self.discretisation(a)) {
            (
                Method::Auto,
                Discretisation::Product {
                    intervals,
                    richardson: true,
                },
            ) => {
                // Adaptive: double N while two successive extrapolations (N/4, N/2)
                // and (N/2, N) differ by more than AUTO_REFINE_TOL: nearly
                // incompressible layers on a stiff base need 2–16× the default
                // N = 2a/h₁ at a/h₁ ≳ 100. Costs one extra N/4 solve when N suffices.
                let rhs: [fredholm::Rhs<'_>; 2] = [&r1, &r2];
                Ok(fredholm::product_adaptive(
                    &quad,
                    a,
                    intervals,
                    &rhs,
                    AUTO_REFINE_TOL,
                    AUTO_MAX_INTERVALS,
                )?)
            }
            (_, disc) => Ok(fredholm::solve(&quad, a, disc, &[&r1, &r2], n)?),
        }
    }

    fn finish(
        &self,
        shape: Shape,
        a: f64,
        delta: f64,
        c: f64,
        sol: &FredholmSolution,
    ) -> Result<Solution, AsperityError> {
        let force = -4.0 * a * (delta * sol.integral[0] - c * sol.integral[1]);
        let phi: Vec<f64> = if sol.grid.is_empty() {
            Vec::new()
        } else {
            sol.grid[0]
                .iter()
                .zip(&sol.grid[1])
                .map(|(p1, p2)| delta * p1 - c * p2)
                .collect()
        };
        if !delta.is_finite() {
            return Err(AsperityError::NonFinite {
                what: "approach",
                a,
            });
        }
        if !force.is_finite() {
            return Err(AsperityError::NonFinite { what: "force", a });
        }
        Ok(Solution {
            shape,
            a,
            delta,
            force,
            phi,
            alpha: self.alpha,
            stack: self.stack.clone(),
            homogeneous: self.homogeneous,
        })
    }

    /// δ(a) for a smooth profile with G = α(δ − c·g(s)).
    fn smooth_delta(
        &self,
        a: f64,
        c: f64,
        g: &(dyn Fn(f64) -> f64 + Sync),
        grid: bool,
    ) -> Result<(f64, FredholmSolution), AsperityError> {
        let sol = self.solve_pair(a, g, grid)?;
        let delta = c * sol.at_one[1] / sol.at_one[0];
        if !delta.is_finite() {
            return Err(AsperityError::NonFinite {
                what: "approach",
                a,
            });
        }
        Ok((delta, sol))
    }

    /// The paraboloid of radius `radius` (m) at contact radius `a` (m): δ from the
    /// smooth-edge condition φ(1) = 0, force from P10.
    pub fn paraboloid_at_radius(&self, a: f64, radius: f64) -> Result<Solution, AsperityError> {
        positive("contact radius a", a)?;
        positive("radius R", radius)?;
        let c = a * a / radius;
        let (delta, sol) = self.smooth_delta(a, c, &|s| s * s, true)?;
        self.finish(Shape::Paraboloid { radius }, a, delta, c, &sol)
    }

    /// δ(a) of the paraboloid only (no profile grid), for root finding and tables.
    pub fn paraboloid_delta(&self, a: f64, radius: f64) -> Result<f64, AsperityError> {
        positive("contact radius a", a)?;
        positive("radius R", radius)?;
        Ok(self.smooth_delta(a, a * a / radius, &|s| s * s, false)?.0)
    }

    /// The paraboloid of radius `radius` (m) at approach `delta` (m ≥ 0): a by a
    /// bracketed, safeguarded secant iteration on ln δ(ln a), to 1e−13 relative in a.
    pub fn paraboloid_at_delta(&self, delta: f64, radius: f64) -> Result<Solution, AsperityError> {
        positive("radius R", radius)?;
        if !(delta.is_finite() && delta >= 0.0) {
            return Err(AsperityError::InvalidParameter {
                name: "delta",
                value: delta,
                reason: "must be non-negative and finite",
            });
        }
        if delta == 0.0 {
            return Ok(Solution {
                shape: Shape::Paraboloid { radius },
                a: 0.0,
                delta: 0.0,
                force: 0.0,
                phi: Vec::new(),
                alpha: self.alpha,
                stack: self.stack.clone(),
                homogeneous: self.homogeneous,
            });
        }
        if self.homogeneous {
            return self.paraboloid_at_radius((radius * delta).sqrt(), radius);
        }
        let target = delta.ln();
        let f = |x: f64| -> Result<f64, AsperityError> {
            Ok(self.paraboloid_delta(x.exp(), radius)?.ln() - target)
        };
        let fail = |reason: &str| AsperityError::NoConvergence {
            delta,
            reason: reason.to_string(),
        };
        // ln δ ≈ 2 ln a + ln(ζ/R): start at Hertz, step by the slope 2, then expand.
        let mut x0 = 0.5 * (radius * delta).ln();
        let mut f0 = f(x0)?;
        let mut x1 = x0 - 0.5 * f0;
        let mut f1 = f(x1)?;
        let mut step = 0.5;
        let mut tries = 0;
        while f0.signum() == f1.signum() && f1 != 0.0 {
            tries += 1;
            if tries > 60 {
                return Err(fail("could not bracket the root"));
            }
            let dir = if f1 > 0.0 { -1.0 } else { 1.0 };
            x0 = x1;
            f0 = f1;
            x1 += dir * step;
            step *= 2.0;
            f1 = f(x1)?;
        }
        // Illinois regula falsi on [x0, x1].
        let (neg, pos) = if f0 < 0.0 {
            ((x0, f0), (x1, f1))
        } else {
            ((x1, f1), (x0, f0))
        };
        let tol = Tolerance {
            f: 1e-15,
            step: 0.0,
            width: 0.0,
            width_abs: 1e-14,
            falsi: Falsi::Illinois,
        };
        let x = bracketed(|x| f(x).map(|v| (v, None)), neg, pos, None, tol, 100)?.x;
        let a = x.exp();
        let c = a * a / radius;
        let (_, sol) = self.smooth_delta(a, c, &|s| s * s, true)?;
        // Report the requested δ; the force is the one of this a at that δ.
        self.finish(Shape::Paraboloid { radius }, a, delta, c, &sol)
    }

    /// The cone of half-angle `half_angle` (rad) at contact radius `a` (m).
    pub fn cone_at_radius(&self, a: f64, half_angle: f64) -> Result<Solution, AsperityError> {
        positive("contact radius a", a)?;
        if !(half_angle.is_finite() && half_angle > 0.0 && half_angle < 0.5 * PI) {
            return Err(AsperityError::InvalidParameter {
                name: "half_angle",
                value: half_angle,
                reason: "must be in (0, π/2) rad",
            });
        }
        let c = 0.5 * PI * a / half_angle.tan();
        let (delta, sol) = self.smooth_delta(a, c, &|s| s, true)?;
        self.finish(Shape::Cone { half_angle }, a, delta, c, &sol)
    }

    /// The flat punch of radius `a` (m) at approach `delta` (m ≥ 0).
    pub fn flat_punch(&self, a: f64, delta: f64) -> Result<Solution, AsperityError> {
        positive("punch radius a", a)?;
        if !(delta.is_finite() && delta >= 0.0) {
            return Err(AsperityError::InvalidParameter {
                name: "delta",
                value: delta,
                reason: "must be non-negative and finite",
            });
        }
        let sol = self.solve_pair(a, &|_s| 0.0, true)?;
        self.finish(Shape::FlatPunch, a, delta, 0.0, &sol)
    }
}

/// ∫₀¹ g by 32-point Gauss–Legendre (exact for the polynomial g used here).
fn integrate_01(g: &(dyn Fn(f64) -> f64 + Sync)) -> f64 {
    let (x, w) = gauss_legendre(32);
    x.iter()
        .zip(&w)
        .map(|(x, w)| 0.5 * w * g(0.5 * (x + 1.0)))
        .sum()
}

impl Solution {
    fn phi_at(&self, t: f64) -> f64 {
        let n = self.phi.len() - 1;
        let x = (t.clamp(0.0, 1.0)) * n as f64;
        let i = (x.floor() as usize).min(n - 1);
        let f = x - i as f64;
        self.phi[i] * (1.0 - f) + self.phi[i + 1] * f
    }

    /// φ′(t)/t on the grid (second-order finite differences; φ″(0) at t = 0).
    fn dphi_over_t(&self) -> Vec<f64> {
        let n = self.phi.len() - 1;
        let d = 1.0 / n as f64;
        let p = &self.phi;
        (0..=n)
            .map(|i| {
                if i == 0 {
                    // φ is even in s: φ″(0) ≈ 2(φ₁ − φ₀)/Δ².
                    2.0 * (p[1] - p[0]) / (d * d)
                } else {
                    let dp = if i == n {
                        (3.0 * p[n] - 4.0 * p[n - 1] + p[n - 2]) / (2.0 * d)
                    } else {
                        (p[i + 1] - p[i - 1]) / (2.0 * d)
                    };
                    dp / (i as f64 * d)
                }
            })
            .collect()
    }

    /// Contact pressure p(r) = −σ_zz (Pa) for 0 ≤ r < a (P11); 0 outside.
    /// With t² = s² + w² the Abel integral becomes ∫₀^√(1−s²) φ′(t)/t dw (64-point
    /// Gauss–Legendre, φ′/t interpolated linearly from the grid).
    pub fn pressure(&self, r: &[f64]) -> Vec<f64> {
        if self.phi.len() < 3 || self.a == 0.0 {
            return vec![0.0; r.len()];
        }
        let g = self.dphi_over_t();
        let n = g.len() - 1;
        let (x, w) = gauss_legendre(64);
        let phi1 = self.phi[n];
        r.iter()
            .map(|&r| {
                let s = (r / self.a).abs();
                if s >= 1.0 {
                    return 0.0;
                }
                let wm = (1.0 - s * s).sqrt();
                let mut acc = 0.0;
                for (xk, wk) in x.iter().zip(&w) {
                    let ww = 0.5 * wm * (xk + 1.0);
                    let t = (s * s + ww * ww).sqrt();
                    let xi = t.min(1.0) * n as f64;
                    let i = (xi.floor() as usize).min(n - 1);
                    let f = xi - i as f64;
                    acc += 0.5 * wm * wk * (g[i] * (1.0 - f) + g[i + 1] * f);
                }
                let edge = if matches!(self.shape, Shape::FlatPunch) {
                    phi1 / wm
                } else {
                    0.0
                };
                2.0 / (PI * self.a) * (acc - edge)
            })
            .collect()
    }

    /// Surface displacement u_z(r) (m, into the solid) at radii `r` (m): δ − f(r)
    /// inside, the P12 formula outside (see the module docs). The k_z part uses a
    /// u-quadrature resolving cos(ρt)J₀(ρs) up to the largest r.
    pub fn displacement(&self, r: &[f64]) -> Result<Vec<f64>, AsperityError> {
        for &ri in r {
            if !(ri.is_finite() && ri >= 0.0) {
                return Err(AsperityError::InvalidParameter {
                    name: "r",
                    value: ri,
                    reason: "must be non-negative and finite",
                });
            }
        }
        if self.a == 0.0 || self.phi.len() < 3 {
            return Ok(vec![0.0; r.len()]);
        }
        let a = self.a;
        let s_max = r.iter().fold(1.0f64, |m, &x| m.max(x / a));
        // F(ρ_k) = ∫₀¹ φ cos(ρ_k t) dt for the piecewise-linear φ, exactly.
        let layered = if self.homogeneous {
            None
        } else {
            let comp = Compliance::new(&self.stack);
            let q = KzQuadrature::new(&self.stack, &comp, a * (1.0 + s_max))?;
            let f: Vec<f64> = q.u.iter().map(|&u| self.cos_moment(a * u)).collect();
            Some((q, f))
        };
        let (gx, gw) = gauss_legendre(64);
        let mut out = Vec::with_capacity(r.len());
        for &ri in r {
            let s = ri / a;
            if s <= 1.0 {
                out.push(self.delta - self.shape.height(ri));
                continue;
            }
            // ∫₀¹ φ(t)/√(s²−t²) dt with t = s sin θ, θ ∈ [0, asin(1/s)].
            let th = (1.0 / s).asin();
            let mut first = 0.0;
            for (x, w) in gx.iter().zip(&gw) {
                let tt = 0.5 * th * (x + 1.0);
                first += 0.5 * th * w * self.phi_at(s * tt.sin());
            }
            let mut second = 0.0;
            if let Some((q, f)) = &layered {
                for (k, fk) in f.iter().enumerate() {
                    let rho = a * q.u[k];
                    second += a * q.w[k] * q.kz[k] * fk * libm::j0(rho * s);
                }
            }
            let u = 2.0 / (self.alpha * PI) * (first + second);
            if !u.is_finite() {
                return Err(AsperityError::NonFinite {
                    what: "displacement",
                    a,
                });
            }
            out.push(u);
        }
        Ok(out)
    }

    /// ∫₀¹ φ(t) cos(ρt) dt for the piecewise-linear φ on the grid (exact).
    fn cos_moment(&self, rho: f64) -> f64 {
        let n = self.phi.len() - 1;
        let d = 1.0 / n as f64;
        let th = rho * d;
        let half = 0.5 * th;
        let sinc_h = if half.abs() < 1e-4 {
            1.0 - half * half / 6.0
        } else {
            half.sin() / half
        };
        let full = d * sinc_h * sinc_h; // ∫ hat cos for a hat at 0
        let (st, ct) = th.sin_cos();
        let (mut s, mut c) = (st, ct);
        let mut inner = 0.0;
        for j in 1..n {
            if j % 64 == 0 {
                let (ss, cc) = (j as f64 * th).sin_cos();
                s = ss;
                c = cc;
            }
            inner += self.phi[j] * c;
            let c2 = c * ct - s * st;
            s = s * ct + c * st;
            c = c2;
        }
        let one_minus_sinc = if th.abs() < 1e-3 {
            th * th / 6.0 * (1.0 - th * th / 20.0)
        } else {
            1.0 - th.sin() / th
        };
        let end = rho.cos() * 0.5 * full + rho.sin() * one_minus_sinc / rho;
        full * inner + 0.5 * full * self.phi[0] + self.phi[n] * end
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_runtime::Stack;
    use strata_runtime::{Base, Layer};

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    fn two_layer(h: f64, e1: f64, e2: f64, nu: f64, base: Base) -> Stack {
        Stack::new(
            vec![
                Layer {
                    thickness: h,
                    young: e1,
                    poisson: nu,
                },
                Layer {
                    thickness: 9.0 * h,
                    young: e2,
                    poisson: nu,
                },
            ],
            base,
        )
        .unwrap()
    }

    fn one_layer(h: f64, e: f64, nu: f64, base: Base) -> Stack {
        Stack::new(
            vec![Layer {
                thickness: h,
                young: e,
                poisson: nu,
            }],
            base,
        )
        .unwrap()
    }

    #[test]
    fn homogeneous_hertz_flat_punch_and_cone() {
        let st = Stack::half_space(2e11, 0.3).unwrap();
        let es = 2e11 / (1.0 - 0.09);
        let asp = Asperity::new(&st, Options::default()).unwrap();
        let (a, r) = (1e-5, 1e-3);
        let s = asp.paraboloid_at_radius(a, r).unwrap();
        assert!(rel(s.force, 4.0 / 3.0 * es * a.powi(3) / r) < 1e-8);
        assert!(rel(s.delta, a * a / r) < 1e-8);
        let s = asp.paraboloid_at_delta(1e-7, r).unwrap();
        assert!(rel(s.a, (1e-7 * r).sqrt()) < 1e-8);
        assert!(rel(s.force, 4.0 / 3.0 * es * s.a.powi(3) / r) < 1e-8);
        let s = asp.flat_punch(a, 1e-7).unwrap();
        assert!(rel(s.force, 2.0 * es * a * 1e-7) < 1e-8);
        // Sneddon's cone: δ = (π/2) a cot θ, P = (π/2) E* a² cot θ.
        let th: f64 = 1.2;
        let s = asp.cone_at_radius(a, th).unwrap();
        assert!(rel(s.delta, 0.5 * PI * a / th.tan()) < 1e-8);
        assert!(rel(s.force, 0.5 * PI * es * a * a / th.tan()) < 1e-8);
        // Identical layers on an identical base are homogeneous too.
        let st = two_layer(
            1e-5,
            2e11,
            2e11,
            0.3,
            Base::Elastic {
                young: 2e11,
                poisson: 0.3,
            },
        );
        let s = Asperity::new(&st, Options::default())
            .unwrap()
            .paraboloid_at_radius(a, r)
            .unwrap();
        assert!(rel(s.force, 4.0 / 3.0 * es * a.powi(3) / r) < 1e-8);
    }

    /// Pressure and outside displacement of Hertz against the closed forms.
    #[test]
    fn hertz_profiles() {
        let st = Stack::half_space(1e9, 0.25).unwrap();
        let es = 1e9 / (1.0 - 0.0625);
        let asp = Asperity::new(&st, Options::default()).unwrap();
        let (a, rr) = (2e-6, 1e-4);
        let s = asp.paraboloid_at_radius(a, rr).unwrap();
        let r: Vec<f64> = [0.0, 0.3, 0.7, 0.95].iter().map(|x| x * a).collect();
        let p = s.pressure(&r);
        for (ri, pi) in r.iter().zip(&p) {
            let exact = 2.0 * es / (PI * rr) * (a * a - ri * ri).sqrt();
            assert!(
                (pi - exact).abs() < 1e-4 * (2.0 * es * a / (PI * rr)),
                "{pi} {exact}"
            );
        }
        let r: Vec<f64> = [0.5, 1.0, 1.01, 1.5, 3.0, 10.0]
            .iter()
            .map(|x| x * a)
            .collect();
        let u = s.displacement(&r).unwrap();
        for (ri, ui) in r.iter().zip(&u) {
            let exact = if *ri <= a {
                a * a / rr - ri * ri / (2.0 * rr)
            } else {
                ((2.0 * a * a - ri * ri) * (a / ri).asin() + a * (ri * ri - a * a).sqrt())
                    / (PI * rr)
            };
            assert!(
                (ui - exact).abs() < 1e-6 * a * a / rr,
                "r {ri}: {ui} {exact}"
            );
        }
    }

    /// A layer on an identical base through the *layered* code path (k_z = 0 to
    /// round-off but not flagged homogeneous): Hertz to 1e-8.
    #[test]
    fn near_homogeneous_layered_path() {
        let st = one_layer(
            1e-4,
            1e9,
            0.3,
            Base::Elastic {
                young: 1e9 * (1.0 + 1e-12),
                poisson: 0.3,
            },
        );
        let asp = Asperity::new(&st, Options::default()).unwrap();
        assert!(!st.is_homogeneous());
        let es = 1e9 / 0.91;
        for a in [1e-5, 1e-3] {
            let s = asp.paraboloid_at_radius(a, 1e-2).unwrap();
            assert!(
                rel(s.force, 4.0 / 3.0 * es * a.powi(3) / 1e-2) < 1e-8,
                "{a}"
            );
            assert!(rel(s.delta, a * a / 1e-2) < 1e-8);
        }
    }

    /// Thin bonded layer on a rigid base (Johnson §5.9): P → πMa⁴/(4Rh), δ → a²/(2R).
    #[test]
    fn thin_layer_rigid_base_limit() {
        for nu in [0.2, 0.3] {
            let (h, e, rr) = (1e-6, 1e9, 1e-2);
            let st = one_layer(h, e, nu, Base::Rigid);
            let m = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
            let asp = Asperity::new(&st, Options::default()).unwrap();
            for ah in [30.0, 100.0] {
                let a = ah * h;
                let s = asp.paraboloid_at_radius(a, rr).unwrap();
                let p_lim = PI * m * a.powi(4) / (4.0 * rr * h);
                let d_lim = a * a / (2.0 * rr);
                assert!(
                    rel(s.force, p_lim) < 0.03,
                    "nu {nu} a/h {ah}: {}",
                    rel(s.force, p_lim)
                );
                assert!(
                    rel(s.delta, d_lim) < 0.03,
                    "nu {nu} a/h {ah}: {}",
                    rel(s.delta, d_lim)
                );
            }
        }
    }

    /// Layered profiles are self-consistent: the pressure integrates to the force
    /// (P = ∫ 2πr p dr, with r = a sin θ) and the outside displacement (P12 with the
    /// k_z term) joins δ − r²/(2R) at r = a. Nyström (a/h = 0.2, 3) and product (a/h = 10).
    #[test]
    fn layered_profiles_consistent() {
        let st = two_layer(1e-4, 4e9, 2e10, 0.15, Base::Rigid);
        let asp = Asperity::new(&st, Options::default()).unwrap();
        let rr = 1e-3;
        let (x, w) = gauss_legendre(200);
        for ah in [0.2, 3.0, 10.0] {
            let a = ah * 1e-4;
            let s = asp.paraboloid_at_radius(a, rr).unwrap();
            let th: Vec<f64> = x.iter().map(|x| 0.25 * PI * (x + 1.0)).collect();
            let r: Vec<f64> = th.iter().map(|t| a * t.sin()).collect();
            let p = s.pressure(&r);
            let total: f64 = (0..th.len())
                .map(|k| 0.25 * PI * w[k] * 2.0 * PI * r[k] * p[k] * a * th[k].cos())
                .sum();
            assert!(
                rel(total, s.force) < 2e-3,
                "a/h {ah}: {}",
                rel(total, s.force)
            );
            let u = s.displacement(&[a * (1.0 + 1e-9), 2.0 * a]).unwrap();
            let inside = s.delta - a * a / (2.0 * rr);
            assert!(
                (u[0] - inside).abs() < 1e-4 * s.delta,
                "a/h {ah}: {} {}",
                u[0],
                inside
            );
            // At a/h = 10 on the rigid base the surface at r = 2a (10 h₁ from the edge)
            // is nearly undisturbed (a slight uplift, −0.25 % of δ, is computed).
            let ok = if ah < 5.0 {
                u[1] > 0.0 && u[1] < u[0]
            } else {
                u[1].abs() < 1e-2 * u[0]
            };
            assert!(ok, "a/h {ah}: {u:?} {inside}");
        }
    }

    /// a/h = 1000: thin-layer limit on a rigid base to 1 %; ν = 0.4999 on a stiff
    /// elastic base (the adaptive grid goes to N = 8016) stays finite and positive.
    #[test]
    #[ignore = "slow tier: CI runs `cargo test --workspace -- --ignored slow_`"]
    fn slow_extreme_a_over_h() {
        let (h, e, nu, rr) = (1e-6, 1e9, 0.3, 1.0);
        let st = one_layer(h, e, nu, Base::Rigid);
        let m = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let a = 1000.0 * h;
        let s = Asperity::new(&st, Options::default())
            .unwrap()
            .paraboloid_at_radius(a, rr)
            .unwrap();
        assert!(rel(s.force, PI * m * a.powi(4) / (4.0 * rr * h)) < 0.01);
        assert!(rel(s.delta, a * a / (2.0 * rr)) < 0.01);
        let st = one_layer(
            h,
            e,
            0.4999,
            Base::Elastic {
                young: 1e3 * e,
                poisson: 0.3,
            },
        );
        let s = Asperity::new(&st, Options::default())
            .unwrap()
            .paraboloid_at_radius(a, rr)
            .unwrap();
        assert!(s.force.is_finite() && s.force > 0.0 && s.delta > 0.0);
    }

    /// Elastic base, a ≫ h: Hertz with the base modulus. The layer's own compliance
    /// leaves an O(h/a) deviation that is larger than 2 % at a/h = 100 for these
    /// contrasts (measured, converged in N: E_b/E₁ = 0.1: +6.6 %, +2.8 %, +1.0 % at
    /// a/h = 100, 300, 1000; 1/3: +3.1 %; 3: −4.7 % at a/h = 100), so the test checks
    /// its sign and its decay like h/a.
    #[test]
    fn elastic_base_far_limit() {
        let (h, e1, nu, rr) = (1e-6, 1e9, 0.3, 1e-2);
        let dev = |ratio: f64, ah: f64| {
            let st = one_layer(
                h,
                e1,
                nu,
                Base::Elastic {
                    young: e1 * ratio,
                    poisson: nu,
                },
            );
            let es_b = e1 * ratio / (1.0 - nu * nu);
            let asp = Asperity::new(&st, Options::default()).unwrap();
            let a = ah * h;
            let s = asp.paraboloid_at_radius(a, rr).unwrap();
            (
                s.force / (4.0 / 3.0 * es_b * a.powi(3) / rr) - 1.0,
                s.delta / (a * a / rr) - 1.0,
            )
        };
        // Deviation from Hertz(E*_b) at a/h = 100, 300: it has the sign of the layer's
        // extra compliance and decays like h/a (ratio 1/3 between the two).
        for ratio in [0.1, 1.0 / 3.0, 3.0, 10.0] {
            let (p100, d100) = dev(ratio, 100.0);
            let (p300, d300) = dev(ratio, 300.0);
            assert!(p100 * (1.0 - ratio) > 0.0, "sign, ratio {ratio}: {p100}");
            assert!(
                (0.3..0.6).contains(&(p300 / p100)),
                "ratio {ratio}: {p100} {p300}"
            );
            assert!(
                (0.3..0.6).contains(&(d300 / d100)),
                "ratio {ratio}: {d100} {d300}"
            );
            eprintln!("E_b/E1 {ratio}: P/P_Hertz(E_b) - 1 = {p100:.4} (a/h 100), {p300:.4} (300)");
        }
    }

    /// Nyström (auto at a/h = 4) and product integration agree, and the force from the
    /// default product solve converges as intervals are added.
    #[test]
    fn product_force_converges() {
        let st = two_layer(1e-4, 4e9, 8e8, 0.15, Base::Rigid);
        let rr = 1e-4;
        let a = 4e-4;
        let ny = Asperity::new(&st, Options::default())
            .unwrap()
            .paraboloid_at_radius(a, rr)
            .unwrap();
        let mut errs = Vec::new();
        for n in [16, 32, 64, 128] {
            let o = Options {
                method: Method::Fixed(Discretisation::Product {
                    intervals: n,
                    richardson: false,
                }),
                ..Options::default()
            };
            let s = Asperity::new(&st, o)
                .unwrap()
                .paraboloid_at_radius(a, rr)
                .unwrap();
            errs.push(rel(s.force, ny.force));
        }
        for w in errs.windows(2) {
            assert!(w[1] < 0.3 * w[0], "{errs:?}");
        }
        let pr = Asperity::new(
            &st,
            Options {
                method: Method::Fixed(Discretisation::Product {
                    intervals: 256,
                    richardson: true,
                }),
                ..Options::default()
            },
        )
        .unwrap()
        .paraboloid_at_radius(a, rr)
        .unwrap();
        assert!(
            rel(pr.force, ny.force) < 1e-8,
            "{}",
            rel(pr.force, ny.force)
        );
        assert!(rel(pr.delta, ny.delta) < 1e-8);
    }

    fn reference(file: &str) -> Vec<[f64; 4]> {
        let path = format!("{}/../tests/reference/{file}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        text.lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("delta"))
            .map(|l| {
                let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
                [v[0], v[1], v[2], v[3]]
            })
            .collect()
    }

    /// The independent solver's results (shared/reference, paper two-layer stacks).
    #[test]
    fn matches_shared_reference() {
        for e in ["0.2", "5"] {
            let dir = format!("{}/../tests/reference", env!("CARGO_MANIFEST_DIR"));
            let st = Stack::from_toml_file(std::path::Path::new(&format!(
                "{dir}/stack_h100um_E2E1_{e}.toml"
            )))
            .unwrap();
            let asp = Asperity::new(&st, Options::default()).unwrap();
            for row in reference(&format!("axisym_h100um_E2E1_{e}.csv")) {
                let s = asp.paraboloid_at_delta(row[0], 1e-4).unwrap();
                // Required: 1e-4. Measured: 3.5e-11 (force), 3.8e-11 (a).
                assert!(
                    rel(s.force, row[2]) < 1e-8,
                    "E2/E1 {e} δ {}: {}",
                    row[0],
                    rel(s.force, row[2])
                );
                assert!(rel(s.a, row[1]) < 1e-8);
                let s2 = asp.paraboloid_at_radius(s.a, 1e-4).unwrap();
                assert!(rel(s2.delta, row[0]) < 1e-10);
            }
        }
    }

    /// Hard cases stay finite and physically sensible: a/h from 1e-3 to 30 here (1e3 in
    /// `extreme_a_over_h`), E2/E1 from 1e-3 to 1e3, ν = 0.4999. Small a/h tends to Hertz
    /// with E*₁: the approach deviates by O(a/h), the force by O((a/h)³).
    #[test]
    fn hard_cases_finite() {
        let h = 1e-5;
        for ratio in [1e-3, 1e3] {
            for nu in [0.3, 0.4999] {
                let st = two_layer(h, 1e9, 1e9 * ratio, nu, Base::Rigid);
                let asp = Asperity::new(&st, Options::default()).unwrap();
                let es = 1e9 / (1.0 - nu * nu);
                let mut dev = Vec::new();
                for ah in [1e-3, 1e-2, 1.0, 30.0] {
                    let a = ah * h;
                    let s = asp.paraboloid_at_radius(a, 1e-2).unwrap();
                    assert!(s.force.is_finite() && s.force > 0.0 && s.delta > 0.0);
                    let p = s.pressure(&[0.0, 0.5 * a]);
                    assert!(p.iter().all(|p| p.is_finite()));
                    dev.push((
                        s.force / (4.0 / 3.0 * es * a.powi(3) / 1e-2) - 1.0,
                        s.delta / (a * a / 1e-2) - 1.0,
                    ));
                }
                // Force: the O(a) part of κ_a is a constant kernel (a rigid shift absorbed
                // by δ), so the force deviation is O(a³), the approach's O(a).
                let rp = dev[0].0 / dev[1].0;
                let rd = dev[0].1 / dev[1].1;
                assert!(
                    (7e-4..1.3e-3).contains(&rp) && (0.07..0.13).contains(&rd),
                    "E2/E1 {ratio} nu {nu}: deviations {dev:?}"
                );
            }
        }
    }

    #[test]
    fn bad_inputs_are_errors() {
        let st = one_layer(1e-5, 1e9, 0.3, Base::Rigid);
        let asp = Asperity::new(&st, Options::default()).unwrap();
        for (a, r) in [
            (0.0, 1.0),
            (-1.0, 1.0),
            (f64::NAN, 1.0),
            (1e-6, 0.0),
            (1e-6, f64::INFINITY),
        ] {
            assert!(matches!(
                asp.paraboloid_at_radius(a, r),
                Err(AsperityError::InvalidParameter { .. })
            ));
        }
        for d in [-1e-9, f64::NAN, f64::INFINITY] {
            let e = asp.paraboloid_at_delta(d, 1e-3).unwrap_err();
            assert!(e.to_string().contains("delta"), "{e}");
        }
        assert!(asp.paraboloid_at_delta(1e-9, -1.0).is_err());
        assert!(asp.cone_at_radius(1e-6, 2.0).is_err());
        assert!(asp.flat_punch(1e-6, -1.0).is_err());
        assert_eq!(asp.paraboloid_at_delta(0.0, 1e-3).unwrap().force, 0.0);
    }
}
