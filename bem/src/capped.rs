//! The capped contact problem 0 ≤ p ≤ H by the preconditioned constrained conjugate
//! gradient: Polonsky & Keer's iteration with Vollebregt's preconditioner
//! ([`crate::pcg`]), its working set widened to both bounds (physics.md §6.3). Under
//! displacement control (the offset c known) it minimises
//!
//! ```text
//!   f(p) = ½ pᵀ K p + pᵀ (c − z_e)      over 0 ≤ p ≤ H,     g = ∇f = K p − z_e + c,
//! ```
//!
//! the problem of [`crate::plastic`]. Per iteration, with the working set
//! W = {0 < p < H} ∪ {p = 0, g < 0} ∪ {p = H, g > 0} (the free points and the bound
//! points whose gradient points into the box):
//!
//! ```text
//!   y = P_W M⁻¹ P_W g,   M⁻¹ = F⁻¹ diag(1/K̂) F           (one product)
//!   t ← y + β t on W (0 elsewhere),  β = Σ_W g y / (Σ_W g y)_old   (0 after W changed)
//!   r = K t;  τ = Σ g t / Σ r t                           (one product)
//!   p ← clamp(p − τ t, 0, H);  u ← u − τ r,  or u = K p where the clamp acted
//! ```
//!
//! Two products per iteration, a third where the clamp acted; with H = ∞ and without
//! points re-entering this is the elastic preconditioned iteration. There is no
//! convergence proof for the projected conjugate directions (as for Polonsky–Keer's own
//! iteration); the caller checks the result with the bounded solver of
//! [`strata_runtime::bounded`] (MPRGP, convergent) and falls back on it when this
//! iteration stalls. Acceptance: the largest violation of the KKT conditions (m) —
//! |g| on 0 < p < H, max(−g, 0) at p = 0, max(g, 0) at p = H — at most `tol`, on the
//! exact gap K p − z_e + c.

use strata_runtime::fft::Fft2Work;

use crate::BemError;
use crate::operator::Operator;

/// Exact gap recomputations from p, at least every this many iterations.
const REFRESH: usize = 50;

/// Iterations without the violation halving after which the iteration counts as stalled.
const STALL: usize = 40;

/// The capped problem on one operator at a known offset.
pub(crate) struct Capped<'a> {
    pub op: &'a Operator,
    /// The preconditioner M⁻¹ (`None`: the plain direction, y = g on W).
    pub minv: Option<&'a Operator>,
    /// Include the periodic uniform mode (a rigid base's C₀).
    pub uniform: bool,
    /// Effective heights z_e = z − u_pl (m).
    pub z: &'a [f64],
    /// The hardness H (Pa).
    pub hardness: f64,
    /// Acceptance: largest KKT violation (m).
    pub tol: f64,
    pub max_iterations: usize,
    /// Checked at every iteration ([`crate::BemSolver::with_cancel`]).
    pub cancel: &'a strata_runtime::cancel::Cancel,
}

/// What a capped solve did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CappedOutcome {
    /// Whether the KKT violation fell below the tolerance (otherwise the iteration
    /// stalled or ran out of iterations).
    pub converged: bool,
    pub iterations: usize,
    /// Operator products (K and M⁻¹).
    pub products: usize,
    /// The largest KKT violation on the exact gap (m).
    pub violation: f64,
}

/// Whether point i is in the working set W (see the module docs).
#[inline]
fn working(p: f64, g: f64, h: f64) -> bool {
    (p > 0.0 && p < h) || (p <= 0.0 && g < 0.0) || (p >= h && g > 0.0)
}

/// The largest violation of the KKT conditions of the capped problem at one point (m).
#[inline]
fn violation(p: f64, g: f64, h: f64) -> f64 {
    if p <= 0.0 {
        (-g).max(0.0)
    } else if p >= h {
        g.max(0.0)
    } else {
        g.abs()
    }
}

/// The largest KKT violation over the field (m).
pub(crate) fn kkt_violation(p: &[f64], g: &[f64], h: f64) -> f64 {
    p.iter()
        .zip(g)
        .fold(0.0, |m: f64, (&p, &g)| m.max(violation(p, g, h)))
}

impl Capped<'_> {
    /// g = K p − z_e + c (one product).
    fn exact(
        &self,
        c: f64,
        p: &[f64],
        u: &mut [f64],
        g: &mut [f64],
        work: &mut Fft2Work,
    ) -> Result<(), BemError> {
        self.op.apply(p, u, self.uniform, work)?;
        for ((g, u), z) in g.iter_mut().zip(u.iter()).zip(self.z) {
            *g = u - z + c;
        }
        Ok(())
    }

    /// Solves at offset `c` from `p` (projected into the box); `g` receives the exact
    /// gap of the solution. Not `converged` when the iteration stalled or ran out of
    /// iterations (p and g then hold its last exact state, a start for another method).
    pub fn solve(&self, c: f64, p: &mut [f64], g: &mut [f64]) -> Result<CappedOutcome, BemError> {
        let n = p.len();
        let h = self.hardness;
        p.iter_mut().for_each(|v| *v = v.clamp(0.0, h));
        let mut u = vec![0.0; n];
        let (mut t, mut r, mut y) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut set = vec![false; n];
        let mut work = self.op.work();
        let mut products = 1;
        self.exact(c, p, &mut u, g, &mut work)?;
        let mut exact = true;
        let mut since_exact = 0;
        let (mut best, mut since_best) = (f64::INFINITY, 0);
        let mut d_old = 0.0;
        let mut conjugate = false;
        for it in 0..=self.max_iterations {
            self.cancel.check()?;
            let v = kkt_violation(p, g, h);
            if !v.is_finite() {
                return Err(BemError::NonFinite(it));
            }
            if v <= self.tol || it == self.max_iterations {
                if !exact {
                    self.exact(c, p, &mut u, g, &mut work)?;
                    products += 1;
                    exact = true;
                    since_exact = 0;
                    let v = kkt_violation(p, g, h);
                    if v > self.tol {
                        conjugate = false;
                        if it < self.max_iterations {
                            continue;
                        }
                    }
                }
                let v = kkt_violation(p, g, h);
                return Ok(CappedOutcome {
                    converged: v <= self.tol,
                    iterations: it,
                    products,
                    violation: v,
                });
            }
            if v < 0.5 * best {
                (best, since_best) = (v, 0);
            } else {
                since_best += 1;
                if since_best >= STALL {
                    return self.stop(c, p, g, &mut u, exact, it, products, &mut work);
                }
            }
            // The working set; conjugacy only while it stays put.
            let mut same = true;
            for i in 0..n {
                let w = working(p[i], g[i], h);
                same &= w == set[i];
                set[i] = w;
                y[i] = if w { g[i] } else { 0.0 };
            }
            conjugate &= same;
            // y = P_W M⁻¹ P_W g.
            let mut delta = 0.0;
            if let Some(minv) = self.minv {
                let gw = y.clone();
                minv.apply(&gw, &mut y, false, &mut work)?;
                products += 1;
                for i in 0..n {
                    if set[i] {
                        delta += g[i] * y[i];
                    } else {
                        y[i] = 0.0;
                    }
                }
            }
            if delta.is_nan() || delta <= 0.0 {
                // no preconditioner, or it is not positive on W: the gap itself
                delta = 0.0;
                for i in 0..n {
                    y[i] = if set[i] { g[i] } else { 0.0 };
                    delta += y[i] * y[i];
                }
                conjugate = false;
            }
            let beta = if conjugate && d_old > 0.0 {
                delta / d_old
            } else {
                0.0
            };
            d_old = delta;
            for i in 0..n {
                t[i] = if set[i] { y[i] + beta * t[i] } else { 0.0 };
            }
            self.op.apply(&t, &mut r, self.uniform, &mut work)?;
            products += 1;
            let (gt, rt) = (0..n).fold((0.0, 0.0), |(a, b), i| (a + g[i] * t[i], b + r[i] * t[i]));
            if !(rt > 0.0 && gt.is_finite()) {
                return self.stop(c, p, g, &mut u, exact, it, products, &mut work);
            }
            let tau = gt / rt;
            let mut clamped = false;
            for i in 0..n {
                let q = p[i] - tau * t[i];
                p[i] = if q < 0.0 {
                    clamped = true;
                    0.0
                } else if q > h {
                    clamped = true;
                    h
                } else {
                    q
                };
            }
            since_exact += 1;
            if clamped || since_exact >= REFRESH {
                self.exact(c, p, &mut u, g, &mut work)?;
                products += 1;
                exact = true;
                since_exact = 0;
                conjugate = !clamped;
            } else {
                for i in 0..n {
                    u[i] -= tau * r[i];
                    g[i] = u[i] - self.z[i] + c;
                }
                exact = false;
                conjugate = true;
            }
        }
        // (the loop returns at it == max_iterations)
        self.stop(
            c,
            p,
            g,
            &mut u,
            false,
            self.max_iterations,
            products,
            &mut work,
        )
    }

    /// An unconverged end: the exact gap of the last state.
    #[allow(clippy::too_many_arguments)]
    fn stop(
        &self,
        c: f64,
        p: &[f64],
        g: &mut [f64],
        u: &mut [f64],
        exact: bool,
        iterations: usize,
        mut products: usize,
        work: &mut Fft2Work,
    ) -> Result<CappedOutcome, BemError> {
        if !exact {
            self.exact(c, p, u, g, work)?;
            products += 1;
        }
        Ok(CappedOutcome {
            converged: false,
            iterations,
            products,
            violation: kkt_violation(p, g, self.hardness),
        })
    }
}
