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
    /// Conjugate-gradient iterations.
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

/// The most secant steps on s under force control.
const MAX_SHIFT_STEPS: usize = 60;

/// Solves one step (module docs). `mu` may be +∞ (full stick: the linear problem on the
/// contact set); `history` is h (zero if `None`), `start` a starting traction.
///
/// Displacement control is one constrained conjugate-gradient solve; force control finds
/// the shift s whose solve carries the mean traction by secant steps on s (the carried
/// traction is a monotone function of s), each solve warm-started from the last.
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
    let mut total_iterations = 0;
    match load {
        TangentialLoad::Displacement(s) => {
            if !(s[0].is_finite() && s[1].is_finite()) {
                return Err(TangentialError::Load {
                    what: "rigid shift",
                    value: if s[0].is_finite() { s[1] } else { s[0] },
                    extra: "",
                });
            }
            let inner = problem.solve(&mut q, s, &mut work)?;
            problem.finish(q, inner, s, inner.iterations)
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
            let limit = pressure.iter().sum::<f64>() / n as f64 * mu;
            let tn = target[0].hypot(target[1]);
            if tn >= limit * (1.0 - 1e-12) {
                return Err(TangentialError::Sliding { q: tn, limit });
            }
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
                let inner = problem.solve(&mut q, s, &mut work)?;
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

    /// The displacement-controlled solve at the shift s, from and into `q`.
    fn solve(
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
        let mut stick = vec![false; nc];
        let mut gg_old = 1.0;
        let mut conjugate = false;
        let mut error = f64::INFINITY;
        for it in 0..self.max_iterations {
            self.apply(q, &mut u, work)?;
            let mut scale: f64 = s[0].hypot(s[1]);
            error = 0.0;
            let mut ns = 0usize;
            for k in 0..nc {
                scale = scale.max((u[0][k] - self.h[0][k]).hypot(u[1][k] - self.h[1][k]));
                g[0][k] = u[0][k] - self.h[0][k] - s[0];
                g[1][k] = u[1][k] - self.h[1][k] - s[1];
                stick[k] = self.is_stick(q, k);
                let e = if stick[k] {
                    ns += 1;
                    g[0][k].hypot(g[1][k])
                } else {
                    let m = q[0][k].hypot(q[1][k]);
                    let (dx, dy) = (q[0][k] / m, q[1][k] / m);
                    let (vx, vy) = (-g[0][k], -g[1][k]);
                    let along = (vx * dx + vy * dy).max(0.0);
                    (vx - along * dx).hypot(vy - along * dy)
                };
                error = error.max(e);
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
            let gg: f64 = (0..nc)
                .filter(|&k| stick[k])
                .map(|k| g[0][k] * g[0][k] + g[1][k] * g[1][k])
                .sum();
            let beta = if conjugate && gg_old > 0.0 {
                gg / gg_old
            } else {
                0.0
            };
            gg_old = gg;
            for k in 0..nc {
                for c in 0..2 {
                    t[c][k] = if stick[k] {
                        g[c][k] + beta * t[c][k]
                    } else {
                        0.0
                    };
                }
            }
            let (mut num, mut den) = (0.0, 0.0);
            if ns > 0 {
                self.apply(&t, &mut v, work)?;
                for k in 0..nc {
                    if stick[k] {
                        num += g[0][k] * t[0][k] + g[1][k] * t[1][k];
                        den += v[0][k] * t[0][k] + v[1][k] * t[1][k];
                    }
                }
            }
            // Slipping points move by the gradient with the stick set's step, or (with no
            // stick point) by the inverse of K_tt's diagonal.
            let tau = if den > 0.0 && num > 0.0 {
                num / den
            } else {
                1.0 / self.diagonal()
            };
            for k in 0..nc {
                for c in 0..2 {
                    let d = if stick[k] { t[c][k] } else { g[c][k] };
                    q[c][k] -= tau * d;
                }
            }
            self.project(q);
            conjugate = (0..nc).all(|k| self.is_stick(q, k) == stick[k]);
        }
        Err(TangentialError::NotConverged {
            what: "tangential",
            iterations: self.max_iterations,
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
