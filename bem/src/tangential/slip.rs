//! Coulomb partial slip at a fixed pressure: the tangential traction q = (q_x, q_y) on
//! the contact set {p > 0} for a rigid shift s of the flat (displacement control) or a
//! mean traction Q̄ = Q/(Lx Ly) (force control), from a history field h.
//!
//! ```text
//!   minimise ½⟨q, K_tt q⟩ − ⟨q, h⟩ − s·Σq   over |q(x)| ≤ μ p(x),
//! ```
//!
//! (with Σq = N Q̄ and s the multiplier under force control), whose optimality
//! conditions are Coulomb's law: where |q| < μp (stick) u = s + h; where |q| = μp (slip)
//! s + h − u = λ q/|q| with λ ≥ 0 (u = K_tt q the tangential displacement). The history
//! h = u_prev − s_prev makes the slip direction that of the step's slip increment
//! (module [`super::path`]); under coupling h also holds −K_tz p.
//!
//! The error is the largest violation of these conditions: |u − s − h| on stick points,
//! the part of s + h − u not along q/|q| (or against it) on slip points, over the largest
//! |u − h| on the contact set.

use super::{TangentialError, TractionKernel};

/// The tangential load of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TangentialLoad {
    /// The mean tangential traction (Q_x, Q_y)/(Lx Ly) (Pa).
    Force([f64; 2]),
    /// The rigid shift (s_x, s_y) of the flat (m).
    Displacement([f64; 2]),
}

/// A solved step.
#[derive(Debug, Clone)]
pub struct SlipSolution {
    /// The traction (q_x, q_y) (Pa), row-major.
    pub traction: [Vec<f64>; 2],
    /// The tangential displacement (u_x, u_y) = K_tt q (m).
    pub displacement: [Vec<f64>; 2],
    /// The rigid shift s (m).
    pub shift: [f64; 2],
    /// Points in contact (p > 0).
    pub contact_points: usize,
    /// Points that stick (|q| < μp, in contact).
    pub stick_points: usize,
    /// Iterations: products by K_tt of a finite μ (power steps included), conjugate-
    /// gradient iterations under full stick.
    pub iterations: usize,
    /// The final error.
    pub error: f64,
}

impl SlipSolution {
    /// The stick area over the contact area.
    pub fn stick_fraction(&self) -> f64 {
        if self.contact_points == 0 {
            0.0
        } else {
            self.stick_points as f64 / self.contact_points as f64
        }
    }

    /// The mean traction (Q_x, Q_y)/(Lx Ly) (Pa).
    pub fn mean_traction(&self) -> [f64; 2] {
        let n = self.traction[0].len() as f64;
        [
            self.traction[0].iter().sum::<f64>() / n,
            self.traction[1].iter().sum::<f64>() / n,
        ]
    }
}

/// Relative margin under which |q| < μp counts as stick.
const STICK_MARGIN: f64 = 1e-12;

/// The relative accuracy of the mean traction under force control (of Σμp + |N Q̄|):
/// rounding in the sums over the contact set is ~1e-16 √N_c of it.
const SUM_TOLERANCE: f64 = 1e-13;

/// The most Newton steps (and step halvings) of the projection onto Σq = N Q̄.
const MAX_NEWTON_STEPS: usize = 50;

/// Power iterations for the largest eigenvalue of K_tt on the contact set.
const POWER_STEPS: usize = 12;

/// The most secant steps on s under force control.
const MAX_SHIFT_STEPS: usize = 60;

/// ⟨a, b⟩ over both components.
fn dot(a: &[Vec<f64>; 2], b: &[Vec<f64>; 2]) -> f64 {
    (0..2)
        .map(|c| a[c].iter().zip(&b[c]).map(|(x, y)| x * y).sum::<f64>())
        .sum()
}

/// Solves one step (module docs). `mu` may be +∞ (full stick: the linear problem on the
/// contact set); `history` is h (zero if `None`), `start` a starting traction;
/// `max_iterations` bounds the products by K_tt of a finite μ (the iterations of each
/// conjugate-gradient solve under full stick).
///
/// A finite μ is solved by an accelerated projected gradient over the friction discs
/// (`Problem::accelerated`), with the mean traction held exactly under force control.
/// Full stick is a conjugate-gradient solve at a given shift; under force control the
/// shift that carries the mean traction follows by secant steps on s, each solve
/// warm-started from the last.
#[allow(clippy::too_many_arguments)]
pub fn solve_slip(
    kernel: &TractionKernel,
    pressure: &[f64],
    mu: f64,
    history: Option<[&[f64]; 2]>,
    load: TangentialLoad,
    start: Option<[&[f64]; 2]>,
    tol: f64,
    max_iterations: usize,
) -> Result<SlipSolution, TangentialError> {
    let (ny, nx) = kernel.grid();
    let n = ny * nx;
    let check = |f: &[f64]| {
        if f.len() != n {
            Err(TangentialError::Length {
                got: f.len(),
                expected: n,
            })
        } else {
            Ok(())
        }
    };
    check(pressure)?;
    for f in history.iter().chain(start.iter()).flatten() {
        check(f)?;
    }
    if mu.is_nan() || mu <= 0.0 {
        return Err(TangentialError::Friction(mu));
    }
    let contact: Vec<usize> = (0..n).filter(|&i| pressure[i] > 0.0).collect();
    if contact.is_empty() {
        return Err(TangentialError::NoContact);
    }
    let nc = contact.len();
    let problem = Problem {
        kernel,
        n,
        limit: contact.iter().map(|&i| mu * pressure[i]).collect(),
        h: match history {
            Some([hx, hy]) => [
                contact.iter().map(|&i| hx[i]).collect(),
                contact.iter().map(|&i| hy[i]).collect(),
            ],
            None => [vec![0.0; nc], vec![0.0; nc]],
        },
        contact,
        tol,
        max_iterations,
    };
    let mut q: [Vec<f64>; 2] = match start {
        Some([sx, sy]) => [
            problem.contact.iter().map(|&i| sx[i]).collect(),
            problem.contact.iter().map(|&i| sy[i]).collect(),
        ],
        None => [vec![0.0; nc], vec![0.0; nc]],
    };
    problem.project(&mut q);
    let mut work = kernel.work();
    check_load(load, pressure, mu)?;
    if mu.is_finite() {
        return problem.accelerated(q, load, &mut work);
    }
    let mut total_iterations = 0;
    match load {
        TangentialLoad::Displacement(s) => {
            let inner = problem.solve_stick(&mut q, s, &mut work)?;
            problem.finish(q, inner, s, inner.iterations)
        }
        TangentialLoad::Force(target) => {
            let limit = pressure.iter().sum::<f64>() / n as f64 * mu;
            let tn = target[0].hypot(target[1]);
            let mean = |q: &[Vec<f64>; 2]| {
                [
                    q[0].iter().sum::<f64>() / n as f64,
                    q[1].iter().sum::<f64>() / n as f64,
                ]
            };
            // First shift: the mean displacement of the contact set under the target
            // traction spread evenly over it, from the history's mean.
            let mut s = {
                let mut full = [vec![0.0; n], vec![0.0; n]];
                let mut out = [vec![0.0; n], vec![0.0; n]];
                let each = [
                    target[0] * n as f64 / nc as f64,
                    target[1] * n as f64 / nc as f64,
                ];
                let cur = mean(&q);
                for (k, &i) in problem.contact.iter().enumerate() {
                    full[0][i] = q[0][k] + each[0] - cur[0] * n as f64 / nc as f64;
                    full[1][i] = q[1][k] + each[1] - cur[1] * n as f64 / nc as f64;
                }
                let [fx, fy] = &full;
                let [ox, oy] = &mut out;
                kernel.apply(
                    [Some(fx), Some(fy), None],
                    [Some(ox), Some(oy), None],
                    &mut work,
                )?;
                let mut s = [0.0; 2];
                for (k, &i) in problem.contact.iter().enumerate() {
                    s[0] += (out[0][i] - problem.h[0][k]) / nc as f64;
                    s[1] += (out[1][i] - problem.h[1][k]) / nc as f64;
                }
                s
            };
            let mut prev: Option<([f64; 2], [f64; 2])> = None;
            let mut last_err = f64::INFINITY;
            for _ in 0..MAX_SHIFT_STEPS {
                let inner = problem.solve_stick(&mut q, s, &mut work)?;
                total_iterations += inner.iterations;
                let got = mean(&q);
                let d = [target[0] - got[0], target[1] - got[1]];
                last_err = d[0].hypot(d[1]) / tn.max(f64::MIN_POSITIVE);
                if last_err <= tol || tn == 0.0 && d[0].hypot(d[1]) <= tol * limit {
                    return problem.finish(q, inner, s, total_iterations);
                }
                // Secant slope (Pa/m) of the carried traction against the shift; the
                // first step takes the slope of the even spread.
                let slope = match prev {
                    Some((ps, pq)) => {
                        let ds = [s[0] - ps[0], s[1] - ps[1]];
                        let dq = [got[0] - pq[0], got[1] - pq[1]];
                        let den = ds[0] * ds[0] + ds[1] * ds[1];
                        let num = dq[0] * ds[0] + dq[1] * ds[1];
                        if den > 0.0 && num > 0.0 {
                            num / den
                        } else {
                            f64::NAN
                        }
                    }
                    None => f64::NAN,
                };
                let slope = if slope.is_finite() {
                    slope
                } else {
                    let sn = s[0].hypot(s[1]);
                    let gn = got[0].hypot(got[1]);
                    if sn > 0.0 && gn > 0.0 {
                        gn / sn
                    } else {
                        tn / sn.max(f64::MIN_POSITIVE)
                    }
                };
                prev = Some((s, got));
                s = [s[0] + d[0] / slope, s[1] + d[1] / slope];
            }
            Err(TangentialError::NotConverged {
                what: "tangential force",
                iterations: total_iterations,
                error: last_err,
            })
        }
    }
}

/// Refuses a load that is not finite, or a mean traction that reaches μ times the mean
/// pressure (the contact would slide as a whole).
fn check_load(load: TangentialLoad, pressure: &[f64], mu: f64) -> Result<(), TangentialError> {
    match load {
        TangentialLoad::Displacement(s) => {
            if !(s[0].is_finite() && s[1].is_finite()) {
                return Err(TangentialError::Load {
                    what: "rigid shift",
                    value: if s[0].is_finite() { s[1] } else { s[0] },
                    extra: "",
                });
            }
        }
        TangentialLoad::Force(target) => {
            if !(target[0].is_finite() && target[1].is_finite()) {
                return Err(TangentialError::Load {
                    what: "mean tangential traction",
                    value: if target[0].is_finite() {
                        target[1]
                    } else {
                        target[0]
                    },
                    extra: "",
                });
            }
            let limit = pressure.iter().sum::<f64>() / pressure.len() as f64 * mu;
            let tn = target[0].hypot(target[1]);
            if tn >= limit * (1.0 - 1e-12) {
                return Err(TangentialError::Sliding { q: tn, limit });
            }
        }
    }
    Ok(())
}

/// One tangential problem on its contact set (compressed storage, `contact` the grid
/// indices).
struct Problem<'a> {
    kernel: &'a TractionKernel,
    n: usize,
    contact: Vec<usize>,
    limit: Vec<f64>,
    h: [Vec<f64>; 2],
    tol: f64,
    max_iterations: usize,
}

/// The end of an inner solve.
#[derive(Clone, Copy)]
struct Inner {
    iterations: usize,
    error: f64,
}

impl Problem<'_> {
    fn project(&self, q: &mut [Vec<f64>; 2]) {
        for k in 0..self.limit.len() {
            let m = q[0][k].hypot(q[1][k]);
            if m > self.limit[k] {
                let f = self.limit[k] / m;
                q[0][k] *= f;
                q[1][k] *= f;
            }
        }
    }

    fn is_stick(&self, q: &[Vec<f64>; 2], k: usize) -> bool {
        q[0][k].hypot(q[1][k]) < self.limit[k] * (1.0 - STICK_MARGIN)
    }

    /// u = K_tt src on the contact set.
    fn apply(
        &self,
        src: &[Vec<f64>; 2],
        out: &mut [Vec<f64>; 2],
        work: &mut super::KernelWork,
    ) -> Result<(), TangentialError> {
        let mut full = [vec![0.0; self.n], vec![0.0; self.n]];
        for c in 0..2 {
            for (k, &i) in self.contact.iter().enumerate() {
                full[c][i] = src[c][k];
            }
        }
        let mut grid = [vec![0.0; self.n], vec![0.0; self.n]];
        {
            let [fx, fy] = &full;
            let [ox, oy] = &mut grid;
            self.kernel
                .apply([Some(fx), Some(fy), None], [Some(ox), Some(oy), None], work)?;
        }
        for c in 0..2 {
            for (k, &i) in self.contact.iter().enumerate() {
                out[c][k] = grid[c][i];
            }
        }
        Ok(())
    }

    /// Full stick (μ = ∞): the linear problem K_tt q = s + h on the contact set at the
    /// shift s, by conjugate gradients from and into `q`.
    fn solve_stick(
        &self,
        q: &mut [Vec<f64>; 2],
        s: [f64; 2],
        work: &mut super::KernelWork,
    ) -> Result<Inner, TangentialError> {
        let nc = self.contact.len();
        let mut u = [vec![0.0; nc], vec![0.0; nc]];
        let mut v = [vec![0.0; nc], vec![0.0; nc]];
        let mut g = [vec![0.0; nc], vec![0.0; nc]];
        let mut t = [vec![0.0; nc], vec![0.0; nc]];
        let mut gg_old = 1.0;
        let mut error = f64::INFINITY;
        for it in 0..self.max_iterations {
            self.apply(q, &mut u, work)?;
            let mut scale: f64 = s[0].hypot(s[1]);
            error = 0.0;
            for k in 0..nc {
                scale = scale.max((u[0][k] - self.h[0][k]).hypot(u[1][k] - self.h[1][k]));
                g[0][k] = u[0][k] - self.h[0][k] - s[0];
                g[1][k] = u[1][k] - self.h[1][k] - s[1];
                error = error.max(g[0][k].hypot(g[1][k]));
            }
            if scale == 0.0 {
                return Ok(Inner {
                    iterations: it,
                    error: 0.0,
                });
            }
            error /= scale;
            if error <= self.tol {
                return Ok(Inner {
                    iterations: it,
                    error,
                });
            }
            let gg: f64 = (0..nc).map(|k| g[0][k] * g[0][k] + g[1][k] * g[1][k]).sum();
            let beta = if it > 0 && gg_old > 0.0 {
                gg / gg_old
            } else {
                0.0
            };
            gg_old = gg;
            for k in 0..nc {
                for c in 0..2 {
                    t[c][k] = g[c][k] + beta * t[c][k];
                }
            }
            self.apply(&t, &mut v, work)?;
            let (mut num, mut den) = (0.0, 0.0);
            for k in 0..nc {
                num += g[0][k] * t[0][k] + g[1][k] * t[1][k];
                den += v[0][k] * t[0][k] + v[1][k] * t[1][k];
            }
            let tau = if den > 0.0 && num > 0.0 {
                num / den
            } else {
                1.0 / self.diagonal()
            };
            for k in 0..nc {
                for c in 0..2 {
                    q[c][k] -= tau * t[c][k];
                }
            }
        }
        Err(TangentialError::NotConverged {
            what: "tangential",
            iterations: self.max_iterations,
            error,
        })
    }

    /// The error of the module docs at the traction `q` with the displacement `u` = K_tt q
    /// and the shift `s`: the largest violation of Coulomb's conditions over the largest
    /// |u − h| (or |s|), 0 when both are 0.
    fn violation(&self, q: &[Vec<f64>; 2], u: &[Vec<f64>; 2], s: [f64; 2]) -> f64 {
        let mut scale: f64 = s[0].hypot(s[1]);
        let mut error: f64 = 0.0;
        for k in 0..self.limit.len() {
            let (rx, ry) = (u[0][k] - self.h[0][k], u[1][k] - self.h[1][k]);
            scale = scale.max(rx.hypot(ry));
            let (gx, gy) = (rx - s[0], ry - s[1]);
            let e = if self.is_stick(q, k) {
                gx.hypot(gy)
            } else {
                let m = q[0][k].hypot(q[1][k]);
                let (dx, dy) = (q[0][k] / m, q[1][k] / m);
                let along = (-gx * dx - gy * dy).max(0.0);
                (-gx - along * dx).hypot(-gy - along * dy)
            };
            error = error.max(e);
        }
        if scale == 0.0 { 0.0 } else { error / scale }
    }

    /// The shift that a force-controlled traction carries: the mean of u − h over the
    /// stick points (where u − h = s holds), or `fallback` with no stick point.
    fn stick_shift(&self, q: &[Vec<f64>; 2], u: &[Vec<f64>; 2], fallback: [f64; 2]) -> [f64; 2] {
        let mut sum = [0.0; 2];
        let mut count = 0usize;
        for k in 0..self.limit.len() {
            if self.is_stick(q, k) {
                sum[0] += u[0][k] - self.h[0][k];
                sum[1] += u[1][k] - self.h[1][k];
                count += 1;
            }
        }
        if count == 0 {
            fallback
        } else {
            [sum[0] / count as f64, sum[1] / count as f64]
        }
    }

    /// Projects z onto the friction discs intersected with {Σq = total} (in place): the
    /// projection is P(z + σ) (P the discs' projection) with the common offset σ, the
    /// constraint's multiplier, which makes Σ P(z + σ) = total: the minimum of the convex
    /// Φ(σ) = Σ m(z + σ) − total·σ (m(v) = |v|²/2 inside the disc of radius r,
    /// r|v| − r²/2 outside, so that ∇m = P), found by Newton steps with a backtracking
    /// line search from the last σ. Returns σ (Pa).
    fn project_sum(&self, z: &mut [Vec<f64>; 2], total: [f64; 2], start: [f64; 2]) -> [f64; 2] {
        let nc = self.limit.len();
        let reach: f64 = self.limit.iter().sum::<f64>() + total[0].hypot(total[1]);
        // F(σ) = ∇Φ = Σ P(z + σ) − total and its Jacobian [[a, b], [b, c]].
        let gradient = |sigma: [f64; 2]| {
            let mut f = [-total[0], -total[1]];
            let mut j = [0.0; 3];
            for k in 0..nc {
                let (vx, vy) = (z[0][k] + sigma[0], z[1][k] + sigma[1]);
                let m = vx.hypot(vy);
                let r = self.limit[k];
                if m <= r {
                    f[0] += vx;
                    f[1] += vy;
                    j[0] += 1.0;
                    j[2] += 1.0;
                } else {
                    let (dx, dy) = (vx / m, vy / m);
                    let c = r / m;
                    f[0] += r * dx;
                    f[1] += r * dy;
                    j[0] += c * (1.0 - dx * dx);
                    j[1] -= c * dx * dy;
                    j[2] += c * (1.0 - dy * dy);
                }
            }
            (f, j)
        };
        // Φ(σ + δ) − Φ(σ), summed point by point as differences (exact where both ends
        // lie on one side of the disc's edge), so that the line search sees decreases
        // far below Φ's rounding.
        let change = |sigma: [f64; 2], d: [f64; 2]| {
            let mut dphi = -(total[0] * d[0] + total[1] * d[1]);
            for k in 0..nc {
                let (vx, vy) = (z[0][k] + sigma[0], z[1][k] + sigma[1]);
                let (wx, wy) = (vx + d[0], vy + d[1]);
                let (mv, mw) = (vx.hypot(vy), wx.hypot(wy));
                let r = self.limit[k];
                // |w|² − |v|² = 2v·δ + |δ|².
                let dsq = 2.0 * (vx * d[0] + vy * d[1]) + d[0] * d[0] + d[1] * d[1];
                dphi += match (mv <= r, mw <= r) {
                    (true, true) => 0.5 * dsq,
                    (false, false) => r * dsq / (mv + mw),
                    (true, false) => r * mw - 0.5 * r * r - 0.5 * mv * mv,
                    (false, true) => 0.5 * mw * mw - r * mv + 0.5 * r * r,
                };
            }
            dphi
        };
        let mut sigma = start;
        for _ in 0..MAX_NEWTON_STEPS {
            let (f, j) = gradient(sigma);
            if f[0].hypot(f[1]) <= SUM_TOLERANCE * reach {
                break;
            }
            // Newton step on the (semismooth) gradient; J is positive semidefinite and
            // singular only when every point slips along one line, hence the small shift.
            let eps = 1e-12 * (j[0] + j[2]);
            let (a, b, c) = (j[0] + eps, j[1], j[2] + eps);
            let det = a * c - b * b;
            let step = [-(c * f[0] - b * f[1]) / det, -(a * f[1] - b * f[0]) / det];
            let slope = f[0] * step[0] + f[1] * step[1];
            let mut alpha = 1.0;
            let mut moved = false;
            for _ in 0..MAX_NEWTON_STEPS {
                let d = [alpha * step[0], alpha * step[1]];
                if change(sigma, d) <= 1e-4 * alpha * slope {
                    sigma = [sigma[0] + d[0], sigma[1] + d[1]];
                    moved = true;
                    break;
                }
                alpha *= 0.5;
            }
            if !moved {
                break;
            }
        }
        for k in 0..nc {
            z[0][k] += sigma[0];
            z[1][k] += sigma[1];
        }
        self.project(z);
        sigma
    }

    /// The largest eigenvalue of K_tt on the contact set, by power iterations from a
    /// uniform traction (K_tt's largest eigenvalues belong to its longest waves), m/Pa.
    fn largest_eigenvalue(&self, work: &mut super::KernelWork) -> Result<f64, TangentialError> {
        let nc = self.limit.len();
        let mut v = [vec![1.0; nc], vec![1.0; nc]];
        let mut kv = [vec![0.0; nc], vec![0.0; nc]];
        let mut lambda: f64 = 0.0;
        for _ in 0..POWER_STEPS {
            let norm = dot(&v, &v).sqrt();
            for c in 0..2 {
                v[c].iter_mut().for_each(|x| *x /= norm);
            }
            self.apply(&v, &mut kv, work)?;
            lambda = lambda.max(dot(&v, &kv));
            std::mem::swap(&mut v, &mut kv);
        }
        Ok(lambda.max(self.diagonal()))
    }

    /// Finite μ: an accelerated projected gradient (FISTA, Beck & Teboulle, SIAM J.
    /// Imaging Sci. 2, 2009) on the complementary energy of the module docs over the
    /// friction discs (and, under force control, the plane Σq = N Q̄), with O'Donoghue &
    /// Candès' gradient restart (Found. Comput. Math. 15, 2015):
    ///
    /// ```text
    ///   x⁺ = Proj(y − (K_tt y − h − s)/L),   y⁺ = x⁺ + (t − 1)/t⁺ (x⁺ − x),
    ///   t⁺ = (1 + √(1 + 4t²))/2,   t⁺ = 1 and y⁺ = x⁺ when (y − x⁺)·(x⁺ − x) > 0,
    /// ```
    ///
    /// with L ≥ the largest eigenvalue of K_tt on the contact set (power iterations, then
    /// doubled whenever a step's ⟨d, K_tt d⟩ > L|d|², d = x⁺ − y). Each iterate is
    /// feasible (|q| ≤ μp at every point, the mean traction exact), so that the iteration
    /// converges from any start for any grid; it stops at the error `tol` of the module
    /// docs. Under force control s is the multiplier of Σq = N Q̄ (σL at the fixed point;
    /// measured as the mean of u − h over the stick points). One product K_tt x⁺ per
    /// step (K_tt y⁺ is the same combination of products).
    fn accelerated(
        &self,
        q: [Vec<f64>; 2],
        load: TangentialLoad,
        work: &mut super::KernelWork,
    ) -> Result<SlipSolution, TangentialError> {
        let nc = self.limit.len();
        let (given, total) = match load {
            TangentialLoad::Displacement(s) => (Some(s), [0.0; 2]),
            TangentialLoad::Force(t) => (None, [t[0] * self.n as f64, t[1] * self.n as f64]),
        };
        let mut x = q;
        let mut sigma = [0.0; 2];
        if given.is_none() {
            sigma = self.project_sum(&mut x, total, sigma);
        }
        let mut products = 0usize;
        let mut lip = self.largest_eigenvalue(work)?;
        products += POWER_STEPS;
        let mut ux = [vec![0.0; nc], vec![0.0; nc]];
        self.apply(&x, &mut ux, work)?;
        products += 1;
        let shift_of = |x: &[Vec<f64>; 2], u: &[Vec<f64>; 2], sigma: [f64; 2], lip: f64| {
            given.unwrap_or_else(|| self.stick_shift(x, u, [lip * sigma[0], lip * sigma[1]]))
        };
        let mut s = shift_of(&x, &ux, sigma, lip);
        let mut error = self.violation(&x, &ux, s);
        if error <= self.tol {
            return self.finish(
                x,
                Inner {
                    iterations: 0,
                    error,
                },
                s,
                products,
            );
        }
        let mut y = x.clone();
        let mut uy = ux.clone();
        let mut xn = [vec![0.0; nc], vec![0.0; nc]];
        let mut uxn = [vec![0.0; nc], vec![0.0; nc]];
        let mut t = 1.0f64;
        let b = given.unwrap_or([0.0; 2]);
        while products < self.max_iterations {
            for c in 0..2 {
                for k in 0..nc {
                    xn[c][k] = y[c][k] - (uy[c][k] - self.h[c][k] - b[c]) / lip;
                }
            }
            if given.is_some() {
                self.project(&mut xn);
            } else {
                sigma = self.project_sum(&mut xn, total, sigma);
            }
            self.apply(&xn, &mut uxn, work)?;
            products += 1;
            // The step is a descent step when L bounds K_tt along d = x⁺ − y.
            let (mut dkd, mut dd) = (0.0, 0.0);
            for c in 0..2 {
                for k in 0..nc {
                    let d = xn[c][k] - y[c][k];
                    dkd += d * (uxn[c][k] - uy[c][k]);
                    dd += d * d;
                }
            }
            if dkd > lip * dd * (1.0 + 1e-12) {
                lip *= 2.0;
                continue;
            }
            s = shift_of(&xn, &uxn, sigma, lip);
            error = self.violation(&xn, &uxn, s);
            if error <= self.tol {
                return self.finish(
                    xn,
                    Inner {
                        iterations: products,
                        error,
                    },
                    s,
                    products,
                );
            }
            let mut restart = 0.0;
            for c in 0..2 {
                for k in 0..nc {
                    restart += (y[c][k] - xn[c][k]) * (xn[c][k] - x[c][k]);
                }
            }
            let (tn, beta) = if restart > 0.0 {
                (1.0, 0.0)
            } else {
                let tn = 0.5 * (1.0 + (1.0 + 4.0 * t * t).sqrt());
                (tn, (t - 1.0) / tn)
            };
            for c in 0..2 {
                for k in 0..nc {
                    y[c][k] = xn[c][k] + beta * (xn[c][k] - x[c][k]);
                    uy[c][k] = uxn[c][k] + beta * (uxn[c][k] - ux[c][k]);
                }
            }
            std::mem::swap(&mut x, &mut xn);
            std::mem::swap(&mut ux, &mut uxn);
            t = tn;
        }
        Err(TangentialError::NotConverged {
            what: "tangential",
            iterations: products,
            error,
        })
    }

    /// K_tt's diagonal in real space, mean of Σ_k A_xx/N (m/Pa).
    fn diagonal(&self) -> f64 {
        let (ny, nx) = self.kernel.grid();
        let mut d = 0.0;
        for kx in 0..=nx / 2 {
            let w = if kx == 0 || kx == nx / 2 { 1.0 } else { 2.0 };
            for ky in 0..ny {
                d += w * self.kernel.entry(kx, ky).xx;
            }
        }
        (d / self.n as f64).max(f64::MIN_POSITIVE)
    }

    fn finish(
        &self,
        q: [Vec<f64>; 2],
        inner: Inner,
        s: [f64; 2],
        iterations: usize,
    ) -> Result<SlipSolution, TangentialError> {
        let n = self.n;
        let mut traction = [vec![0.0; n], vec![0.0; n]];
        let mut stick_points = 0;
        for (k, &i) in self.contact.iter().enumerate() {
            traction[0][i] = q[0][k];
            traction[1][i] = q[1][k];
            if self.is_stick(&q, k) {
                stick_points += 1;
            }
        }
        let mut displacement = [vec![0.0; n], vec![0.0; n]];
        let mut work = self.kernel.work();
        {
            let [ox, oy] = &mut displacement;
            // The displacement of the final traction (the fields are exact for it).
            self.kernel.apply(
                [Some(&traction[0]), Some(&traction[1]), None],
                [Some(ox), Some(oy), None],
                &mut work,
            )?;
        }
        Ok(SlipSolution {
            traction,
            displacement,
            shift: s,
            contact_points: self.contact.len(),
            stick_points,
            iterations,
            error: inner.error,
        })
    }
}
