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

use std::sync::atomic::AtomicBool;
use std::sync::atomic::Ordering::Relaxed;

use rayon::prelude::*;
use strata_runtime::fft::{Fft2Work, Merge};

use crate::BemError;
use crate::operator::Operator;
use crate::state::CHUNK;

/// Exact gap recomputations from p, at least every this many iterations.
const REFRESH: usize = 50;

/// Iterations without the violation halving after which the iteration counts as stalled.
const STALL: usize = 40;

/// Most halvings of a load-held step whose projection raises the energy.
const MAX_HALVINGS: usize = 6;

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

    /// u = K p with the load offset's sums and the energy formed in the product's drain
    /// (one product, no pass of its own): returns c ([`LoadSums::offset`]) and the
    /// energy f = ½ pᵀ u − pᵀ z_e. The gap g = u − z_e + c is left to the next scan.
    fn exact_sums(
        &self,
        p: &mut [f64],
        u: &mut [f64],
        work: &mut Fft2Work,
    ) -> Result<(f64, f64), BemError> {
        let (h, z, nx) = (self.hardness, self.z, self.op.nx());
        let (_, sums) = self.op.apply_fields(
            [p, u],
            self.uniform,
            work,
            |_, [p, _], input| input.copy_from_slice(p),
            |_| Some(()),
            |_, i, [p, u], q| {
                u.copy_from_slice(q);
                LoadSums::of(p, u, &z[i * nx..(i + 1) * nx], h)
            },
        )?;
        let s = sums.unwrap_or_default();
        Ok((s.offset(), s.energy))
    }

    /// g = K p − z_e + c with c the load's offset ([`LoadSums::offset`]; one product);
    /// returns c and the energy ([`Self::exact_sums`]).
    fn exact_load(
        &self,
        p: &mut [f64],
        u: &mut [f64],
        g: &mut [f64],
        work: &mut Fft2Work,
    ) -> Result<(f64, f64), BemError> {
        let (c, f) = self.exact_sums(p, u, work)?;
        g.par_chunks_mut(CHUNK)
            .zip(u.par_chunks(CHUNK))
            .zip(self.z.par_chunks(CHUNK))
            .for_each(|((g, u), z)| {
                for k in 0..g.len() {
                    g[k] = u[k] - z[k] + c;
                }
            });
        Ok((c, f))
    }

    /// The capped problem under load control: mean p = `mean` (Pa, 0 < mean < H) held
    /// in the same iteration, the offset c its Lagrange multiplier,
    ///
    /// ```text
    ///   min ½ pᵀ K p − pᵀ z_e   over 0 ≤ p ≤ H, Σ p = N p̄,   g = K p − z_e + c,
    /// ```
    ///
    /// c = −mean_F(K p − z_e) over the free points F = {0 < p < H}. The iteration of
    /// [`Self::solve`] with the direction kept in the load's plane (y ← y − mean_W y on
    /// the working set W, so Σ t = 0) and, where a step leaves the box, p clamped into
    /// it and the load restored by shifting the free points alike ([`project_load`]) —
    /// instead of Polonsky–Keer's rescaling of p, which stalls with the contact just
    /// below H; a projected step that raises the energy ½ pᵀK p − pᵀz_e is halved
    /// (at most [`MAX_HALVINGS`] times), which stops the cycling of large projected
    /// steps far from the solution. From `p` (projected first); returns the outcome and
    /// c. Not `converged` when it stalled (p, g then hold its last exact state, at the
    /// load, a start for another method). Measured (128², three stacks, six loads,
    /// `tests::force_controlled_capped_step_products`): 48–72 products, 0.69–1.04×
    /// the elastic step's at the same mean pressure.
    pub fn solve_load(
        &self,
        mean: f64,
        p: &mut [f64],
        g: &mut [f64],
    ) -> Result<(CappedOutcome, f64), BemError> {
        let n = p.len();
        let h = self.hardness;
        let total = mean * n as f64;
        if !(mean > 0.0 && total < h * n as f64) {
            return Err(BemError::NonFinite(0));
        }
        project_load(p, h, total);
        let mut u = vec![0.0; n];
        // the start of a step that leaves the box (u's: by a swap, not a copy)
        let (mut p_prev, mut u_prev): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
        // y (the preconditioned gap) and r = K t share a buffer: the direction's fill
        // reads row i of y before its drain writes row i of r.
        let (mut t, mut yr) = (vec![0.0; n], vec![0.0; n]);
        let set: Vec<AtomicBool> = (0..n).map(|_| AtomicBool::new(false)).collect();
        let mut work = self.op.work();
        let mut products = 1;
        // the energy ½ pᵀ u − pᵀ z_e of the current state, kept by every update of p and u
        let (mut c, mut f_cur) = self.exact_load(p, &mut u, g, &mut work)?;
        // Whether g = u − z_e + c is still to be formed from u (it is, in the next scan).
        let mut pending = false;
        let mut exact = true;
        let mut since_exact = 0;
        let (mut best, mut since_best) = (f64::INFINITY, 0);
        let mut d_old = 0.0;
        let mut conjugate = false;
        let end = |p: &[f64], g: &[f64], it, products| {
            let v = kkt_violation(p, g, h);
            CappedOutcome {
                converged: v <= self.tol,
                iterations: it,
                products,
                violation: v,
            }
        };
        let nx = self.op.nx();
        let z = self.z;
        for it in 0..=self.max_iterations {
            self.cancel.check()?;
            // The scan (g formed where pending, the KKT violation, the working set W),
            // fused with the forward half of y = P_W M⁻¹ P_W g; the product goes on only
            // if the iteration does (the gate), its drain writes y and the sums of y.
            let cp = pending.then_some(c);
            let go = |s: &Scan| {
                s.finite
                    && s.viol.is_finite()
                    && !(s.viol <= self.tol || it == self.max_iterations)
                    && !(s.viol >= 0.5 * best && since_best + 1 >= STALL)
                    && s.m > 0
            };
            let (scan, drained) = match self.minv {
                Some(minv) => {
                    let (scan, drained) = minv.apply_fields(
                        [&mut *p, &mut *g, &mut u, &mut yr],
                        false,
                        &mut work,
                        |i, [p, g, u, _], input| {
                            let row = i * nx..(i + 1) * nx;
                            scan_row(p, g, u, &z[row.clone()], &set[row], h, cp, input)
                        },
                        |s| go(s).then_some(()),
                        |_, i, [_, g, _, y], q| drain_y(g, y, q, &set[i * nx..(i + 1) * nx]),
                    )?;
                    (scan.finish(), drained)
                }
                None => (scan_plain(p, g, &u, z, &set, h, cp, &mut yr), None),
            };
            pending = false;
            if !scan.viol.is_finite() {
                return Err(BemError::NonFinite(it));
            }
            let v = scan.viol;
            if v <= self.tol || it == self.max_iterations {
                if !exact {
                    (c, f_cur) = self.exact_load(p, &mut u, g, &mut work)?;
                    products += 1;
                    exact = true;
                    since_exact = 0;
                    if kkt_violation(p, g, h) > self.tol {
                        conjugate = false;
                        if it < self.max_iterations {
                            continue;
                        }
                    }
                }
                return Ok((end(p, g, it, products), c));
            }
            if v < 0.5 * best {
                (best, since_best) = (v, 0);
            } else {
                since_best += 1;
                if since_best >= STALL {
                    if !exact {
                        (c, _) = self.exact_load(p, &mut u, g, &mut work)?;
                        products += 1;
                    }
                    return Ok((end(p, g, it, products), c));
                }
            }
            conjugate &= !scan.changed;
            let m = scan.m;
            if m == 0 {
                return Ok((end(p, g, it, products), c));
            }
            // The direction's y in the load's plane: y − ȳ on W (ȳ its mean over W),
            // δ = Σ_W g (y − ȳ) = Σ_W g y − ȳ Σ_W g.
            let in_plane = |[sy, sgy, sg]: [f64; 3]| {
                let ybar = sy / m as f64;
                (ybar, sgy - ybar * sg)
            };
            let (mut ybar, mut delta) = (0.0, f64::NAN);
            if let Some(sums) = drained {
                products += 1;
                (ybar, delta) = in_plane(sums);
            }
            if delta.is_nan() || delta <= 0.0 {
                // no preconditioner, or it is not positive on W: the gap itself
                (ybar, delta) = in_plane(plain_y(g, &mut yr, &set));
                conjugate = false;
                if delta.is_nan() || delta <= 0.0 {
                    if !exact {
                        (c, _) = self.exact_load(p, &mut u, g, &mut work)?;
                        products += 1;
                    }
                    return Ok((end(p, g, it, products), c));
                }
            }
            let beta = if conjugate && d_old > 0.0 {
                delta / d_old
            } else {
                0.0
            };
            d_old = delta;
            // t = (y − ȳ) + β t on W (0 elsewhere) formed in the fill of r = K t, whose
            // drain sums g·t and r·t.
            let (gt, rt) = {
                let g = &*g;
                let (_, sums) = self.op.apply_fields(
                    [&mut t, &mut yr],
                    self.uniform,
                    &mut work,
                    |i, [t, y], input| {
                        let w = &set[i * nx..(i + 1) * nx];
                        for k in 0..t.len() {
                            t[k] = if w[k].load(Relaxed) {
                                (y[k] - ybar) + beta * t[k]
                            } else {
                                0.0
                            };
                        }
                        input.copy_from_slice(t);
                    },
                    |_| Some(()),
                    |_, i, [t, r], q| {
                        r.copy_from_slice(q);
                        let g = &g[i * nx..(i + 1) * nx];
                        let (mut a, mut b) = (0.0, 0.0);
                        for k in 0..t.len() {
                            a += g[k] * t[k];
                            b += q[k] * t[k];
                        }
                        [a, b]
                    },
                )?;
                let [gt, rt] = sums.unwrap_or_default();
                (gt, rt)
            };
            products += 1;
            let r = &yr;
            if !(rt > 0.0 && gt.is_finite()) {
                if !exact {
                    (c, _) = self.exact_load(p, &mut u, g, &mut work)?;
                    products += 1;
                }
                return Ok((end(p, g, it, products), c));
            }
            let mut tau = gt / rt;
            let inside = if step_inside(p, &t, tau, h) {
                true
            } else {
                // The step, halved while a projected one raises the energy
                // f = ½ pᵀK p − pᵀz_e (one product per trial: a projection changes u,
                // formed into u's spare buffer; the start's u stays in u_prev).
                let f_now = f_cur;
                p_prev.clear();
                p_prev.extend_from_slice(p);
                if u_prev.len() != n {
                    u_prev = vec![0.0; n];
                }
                std::mem::swap(&mut u, &mut u_prev);
                let mut halvings = 0;
                loop {
                    let (inside, sums) = trial_step(p, &p_prev, &t, tau, h);
                    if inside {
                        // (after a halving: p and u are the step's start again)
                        p.copy_from_slice(&p_prev);
                        std::mem::swap(&mut u, &mut u_prev);
                        break true;
                    }
                    shift_to_load(p, h, total, sums);
                    (c, f_cur) = self.exact_sums(p, &mut u, &mut work)?;
                    products += 1;
                    if f_cur <= f_now || halvings >= MAX_HALVINGS {
                        break false;
                    }
                    halvings += 1;
                    tau *= 0.5;
                }
            };
            since_exact += 1;
            if !inside {
                // u = K p exactly; g formed from it in the next scan
                pending = true;
                exact = true;
                since_exact = 0;
                conjugate = false;
            } else if since_exact >= REFRESH {
                advance(p, &mut u, &t, r, z, tau, h);
                (c, f_cur) = self.exact_load(p, &mut u, g, &mut work)?;
                products += 1;
                exact = true;
                since_exact = 0;
                conjugate = true;
            } else {
                let sums = advance(p, &mut u, &t, r, z, tau, h);
                (c, f_cur) = (sums.offset(), sums.energy);
                pending = true;
                exact = false;
                conjugate = true;
            }
        }
        // (the loop returns at it == max_iterations)
        Ok((end(p, g, self.max_iterations, products), c))
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

/// What the scan of the load-held iteration found: the largest KKT violation (m), the
/// size of the working set W, whether W changed, whether every violation was finite.
#[derive(Debug, Clone, Copy)]
struct Scan {
    viol: f64,
    m: usize,
    changed: bool,
    finite: bool,
}

impl Default for Scan {
    fn default() -> Self {
        Scan {
            viol: 0.0,
            m: 0,
            changed: false,
            finite: true,
        }
    }
}

impl Merge for Scan {
    fn merge(self, o: Self) -> Self {
        Scan {
            viol: self.viol.max(o.viol),
            m: self.m + o.m,
            changed: self.changed || o.changed,
            finite: self.finite && o.finite,
        }
    }
}

impl Scan {
    /// The violation, NaN if one was not finite.
    fn finish(mut self) -> Self {
        if !self.finite {
            self.viol = f64::NAN;
        }
        self
    }
}

/// One stretch of the scan: g = u − z_e + c where `c` is given (the pending gap), the
/// violation and the working set W (written to `set`), and P_W g into `input`.
#[allow(clippy::too_many_arguments)]
fn scan_row(
    p: &[f64],
    g: &mut [f64],
    u: &[f64],
    z: &[f64],
    set: &[AtomicBool],
    h: f64,
    c: Option<f64>,
    input: &mut [f64],
) -> Scan {
    if let Some(c) = c {
        for k in 0..g.len() {
            g[k] = u[k] - z[k] + c;
        }
    }
    let mut s = Scan::default();
    for k in 0..g.len() {
        let v = violation(p[k], g[k], h);
        s.finite &= v.is_finite();
        s.viol = s.viol.max(v);
        let w = working(p[k], g[k], h);
        s.changed |= set[k].swap(w, Relaxed) != w;
        s.m += usize::from(w);
        input[k] = if w { g[k] } else { 0.0 };
    }
    s
}

/// The preconditioner's result q on one row: y = q on W, 0 elsewhere; returns
/// [Σ_W y, Σ_W g y, Σ_W g].
fn drain_y(g: &[f64], y: &mut [f64], q: &[f64], set: &[AtomicBool]) -> [f64; 3] {
    let mut s = [0.0; 3];
    for k in 0..y.len() {
        if set[k].load(Relaxed) {
            y[k] = q[k];
            s[0] += q[k];
            s[1] += g[k] * q[k];
            s[2] += g[k];
        } else {
            y[k] = 0.0;
        }
    }
    s
}

/// The scan without a preconditioner product (P_W g goes to `y`). Partial results per
/// stretch of `CHUNK` points, merged in their order (the sums do not depend on how the
/// threads share the stretches).
#[allow(clippy::too_many_arguments)]
fn scan_plain(
    p: &[f64],
    g: &mut [f64],
    u: &[f64],
    z: &[f64],
    set: &[AtomicBool],
    h: f64,
    c: Option<f64>,
    y: &mut [f64],
) -> Scan {
    let parts: Vec<Scan> = g
        .par_chunks_mut(CHUNK)
        .zip(y.par_chunks_mut(CHUNK))
        .enumerate()
        .map(|(b, (g, y))| {
            let r = b * CHUNK..b * CHUNK + g.len();
            scan_row(
                &p[r.clone()],
                g,
                &u[r.clone()],
                &z[r.clone()],
                &set[r],
                h,
                c,
                y,
            )
        })
        .collect();
    parts
        .into_iter()
        .fold(Scan::default(), Scan::merge)
        .finish()
}

/// y = g on W (0 elsewhere); returns [Σ_W y, Σ_W g y, Σ_W g].
fn plain_y(g: &[f64], y: &mut [f64], set: &[AtomicBool]) -> [f64; 3] {
    let parts: Vec<[f64; 3]> = y
        .par_chunks_mut(CHUNK)
        .enumerate()
        .map(|(b, y)| {
            let r = b * CHUNK..b * CHUNK + y.len();
            let g = &g[r.clone()];
            drain_y(g, y, g, &set[r])
        })
        .collect();
    parts.into_iter().fold([0.0; 3], Merge::merge)
}

/// Whether the step p − τ t stays in the box 0 ≤ p ≤ h everywhere.
fn step_inside(p: &[f64], t: &[f64], tau: f64, h: f64) -> bool {
    p.par_chunks(CHUNK).zip(t.par_chunks(CHUNK)).all(|(p, t)| {
        p.iter()
            .zip(t)
            .all(|(p, t)| (0.0..=h).contains(&(p - tau * t)))
    })
}

/// The sums of the load's offset over a field ([`LoadSums::offset`]) and the energy
/// f = ½ pᵀ u − pᵀ z_e of the load-held problem (m · Pa · points: its differences are
/// what count).
#[derive(Debug, Clone, Copy)]
struct LoadSums {
    sum: f64,
    m: usize,
    lo: f64,
    hi: f64,
    energy: f64,
}

impl Default for LoadSums {
    fn default() -> Self {
        LoadSums {
            sum: 0.0,
            m: 0,
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
            energy: 0.0,
        }
    }
}

impl Merge for LoadSums {
    fn merge(self, o: Self) -> Self {
        LoadSums {
            sum: self.sum + o.sum,
            m: self.m + o.m,
            lo: self.lo.max(o.lo),
            hi: self.hi.min(o.hi),
            energy: self.energy + o.energy,
        }
    }
}

impl LoadSums {
    /// Adds point (p, d = u − z_e, z_e).
    #[inline]
    fn add(&mut self, p: f64, d: f64, z: f64, h: f64) {
        if p > 0.0 && p < h {
            self.sum += d;
            self.m += 1;
        } else if p <= 0.0 {
            self.lo = self.lo.max(-d);
        } else {
            self.hi = self.hi.min(-d);
        }
        // ½ p u − p z_e = p (½ d − ½ z_e)
        self.energy += 0.5 * p * (d - z);
    }

    /// The sums of one stretch.
    fn of(p: &[f64], u: &[f64], z: &[f64], h: f64) -> Self {
        let mut s = LoadSums::default();
        for k in 0..p.len() {
            s.add(p[k], u[k] - z[k], z[k], h);
        }
        s
    }

    /// c = −mean over the free points F = {0 < p < H} of (u − z_e), the Lagrange
    /// multiplier of the load; without free points the middle of the offsets that keep
    /// the bound points' gaps signed right.
    fn offset(self) -> f64 {
        if self.m > 0 {
            -self.sum / self.m as f64
        } else if self.lo.is_finite() && self.hi.is_finite() {
            0.5 * (self.lo + self.hi)
        } else if self.lo.is_finite() {
            self.lo
        } else {
            self.hi
        }
    }
}

/// The step inside the box: p ← p − τ t, u ← u − τ r, and the load offset's sums of
/// the new state.
fn advance(
    p: &mut [f64],
    u: &mut [f64],
    t: &[f64],
    r: &[f64],
    z: &[f64],
    tau: f64,
    h: f64,
) -> LoadSums {
    let parts: Vec<LoadSums> = p
        .par_chunks_mut(CHUNK)
        .zip(u.par_chunks_mut(CHUNK))
        .enumerate()
        .map(|(b, (p, u))| {
            let rg = b * CHUNK..b * CHUNK + p.len();
            let (t, r, z) = (&t[rg.clone()], &r[rg.clone()], &z[rg]);
            let mut s = LoadSums::default();
            for k in 0..p.len() {
                p[k] -= tau * t[k];
                u[k] -= tau * r[k];
                s.add(p[k], u[k] - z[k], z[k], h);
            }
            s
        })
        .collect();
    parts.into_iter().fold(LoadSums::default(), Merge::merge)
}

/// The sum and the number of free points (0 < p < h) of a field, per stretch of
/// `CHUNK` points merged in their order.
#[derive(Debug, Clone, Copy, Default)]
struct PlaneSums {
    sum: f64,
    free: usize,
}

impl Merge for PlaneSums {
    fn merge(self, o: Self) -> Self {
        PlaneSums {
            sum: self.sum + o.sum,
            free: self.free + o.free,
        }
    }
}

impl PlaneSums {
    #[inline]
    fn add(&mut self, v: f64, h: f64) {
        self.sum += v;
        self.free += usize::from(v > 0.0 && v < h);
    }
}

/// `f` over stretches of `CHUNK` points of `q` (the offset of the stretch and the
/// stretch), the partial sums merged in their order: the result does not depend on how
/// the threads share the stretches.
fn fold_chunks(q: &mut [f64], f: impl Fn(usize, &mut [f64]) -> PlaneSums + Sync) -> PlaneSums {
    let parts: Vec<PlaneSums> = q
        .par_chunks_mut(CHUNK)
        .enumerate()
        .map(|(b, q)| f(b * CHUNK, q))
        .collect();
    parts.into_iter().fold(PlaneSums::default(), Merge::merge)
}

/// The trial step of a step that leaves the box: p = clamp(p₀ − τ t, 0, h); returns
/// whether p₀ − τ t was inside the box everywhere (p is then that step) and the sums
/// of the clamped p.
fn trial_step(p: &mut [f64], p0: &[f64], t: &[f64], tau: f64, h: f64) -> (bool, PlaneSums) {
    let inside = std::sync::atomic::AtomicBool::new(true);
    let sums = fold_chunks(p, |at, p| {
        let (p0, t) = (&p0[at..at + p.len()], &t[at..at + p.len()]);
        let mut s = PlaneSums::default();
        let mut all = true;
        for k in 0..p.len() {
            let q = p0[k] - tau * t[k];
            all &= (0.0..=h).contains(&q);
            p[k] = q.clamp(0.0, h);
            s.add(p[k], h);
        }
        if !all {
            inside.store(false, Relaxed);
        }
        s
    });
    (inside.load(Relaxed), sums)
}

/// Puts `q` into the box 0 ≤ p ≤ `h` and onto the plane Σ p = `total` (0 < total <
/// N h) the way Polonsky–Keer's rescaling does, but by a shift: q clamped into the box,
/// then the free points (0 < p < h) shifted alike by the excess over their number,
/// clamped again, until |Σ p − total| ≤ 1e−14 total — the points at a bound stay there
/// (they enter and leave it through the working set, not here). Where the free points
/// cannot take the excess, the exact projection ([`project_plane`]).
pub(crate) fn project_load(q: &mut [f64], h: f64, total: f64) {
    let sums = fold_chunks(q, |_, q| {
        let mut s = PlaneSums::default();
        for v in q.iter_mut() {
            *v = v.clamp(0.0, h);
            s.add(*v, h);
        }
        s
    });
    shift_to_load(q, h, total, sums);
}

/// [`project_load`] of a `q` inside the box whose sums are `sums`. The shifts move the
/// free points only, so they run on a compact copy of those (one pass over the field
/// to gather them, one to put them back; few where most of the contact is at H).
fn shift_to_load(q: &mut [f64], h: f64, total: f64, sums: PlaneSums) {
    let tol = 1e-14 * total;
    if (sums.sum - total).abs() <= tol {
        return;
    }
    if sums.free == 0 {
        return project_plane(q, h, total);
    }
    // the free points (index, value) per stretch in their order, and the bound points' sum
    let parts: Vec<(Vec<(usize, f64)>, f64)> = q
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(b, q)| {
            let mut free = Vec::new();
            let mut bound = 0.0;
            for (k, &v) in q.iter().enumerate() {
                if v > 0.0 && v < h {
                    free.push((b * CHUNK + k, v));
                } else {
                    bound += v;
                }
            }
            (free, bound)
        })
        .collect();
    let bound: f64 = parts.iter().map(|(_, s)| s).sum();
    let mut free: Vec<(usize, f64)> = parts.into_iter().flat_map(|(f, _)| f).collect();
    let mut settled = false;
    for _ in 0..100 {
        let (mut sum, mut m) = (bound, 0usize);
        for &(_, v) in &free {
            sum += v;
            m += usize::from(v > 0.0 && v < h);
        }
        let excess = sum - total;
        if excess.abs() <= tol {
            settled = true;
            break;
        }
        if m == 0 {
            break;
        }
        let lambda = excess / m as f64;
        for (_, v) in free.iter_mut() {
            if *v > 0.0 && *v < h {
                *v = (*v - lambda).clamp(0.0, h);
            }
        }
    }
    for &(i, v) in &free {
        q[i] = v;
    }
    if !settled {
        project_plane(q, h, total);
    }
}

/// The projection of `q` onto the box 0 ≤ p ≤ `h` intersected with the plane Σ p =
/// `total` (0 < total < N h), the points at q ≤ 0 kept out of contact (p = 0) when the
/// others can carry the load: p = clamp(q − λ, 0, h) on the points q > 0, λ the root
/// of the nonincreasing, piecewise linear φ(λ) = Σ clamp(q − λ, 0, h) − total, found
/// by Newton steps on it (slope −#{0 < q − λ < h}) safeguarded by bisection of its
/// bracket, to |φ| ≤ 1e−14 total.
fn project_plane(q: &mut [f64], h: f64, total: f64) {
    let tol = 1e-14 * total;
    let (inside, positive) = q
        .par_chunks(CHUNK)
        .map(|q| {
            let inside = q.iter().all(|v| (0.0..=h).contains(v));
            (inside, q.iter().filter(|&&v| v > 0.0).count())
        })
        .reduce(|| (true, 0), |a, b| (a.0 && b.0, a.1 + b.1));
    // the support: the points in contact, or all of them if those cannot carry it
    let floor = if positive as f64 * h > total {
        0.0
    } else {
        f64::NEG_INFINITY
    };
    // φ runs on a compact copy of the support (in the field's order: the sums do not
    // depend on the threads), the contact alone where it carries the load
    let support: Vec<f64> = q.par_iter().copied().filter(|&v| v > floor).collect();
    let phi = |lambda: f64| {
        let (mut s, mut m) = (0.0, 0usize);
        for &v in &support {
            let x = v - lambda;
            if x >= h {
                s += h;
            } else if x > 0.0 {
                s += x;
                m += 1;
            }
        }
        (s - total, m)
    };
    let (f0, m0) = phi(0.0);
    if inside && f0.abs() <= tol {
        return;
    }
    let (qmin, qmax) = support
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    // φ(qmin − h) = (points) h − total > 0, φ(qmax) = −total < 0
    let (mut lo, mut hi) = (qmin - h, qmax);
    let (mut lambda, mut f, mut m) = (0.0, f0, m0);
    for _ in 0..200 {
        if f.abs() <= tol {
            break;
        }
        if f > 0.0 {
            lo = lo.max(lambda);
        } else {
            hi = hi.min(lambda);
        }
        let newton = lambda + f / m as f64;
        let next = if m > 0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if next == lambda || hi <= lo || hi.is_nan() || lo.is_nan() {
            break;
        }
        lambda = next;
        (f, m) = phi(lambda);
    }
    q.par_chunks_mut(CHUNK).for_each(|q| {
        for v in q.iter_mut() {
            *v = if *v <= floor {
                0.0
            } else {
                (*v - lambda).clamp(0.0, h)
            };
        }
    });
}
