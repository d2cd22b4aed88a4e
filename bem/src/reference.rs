//! The unaccelerated reference path of the solver: Polonsky & Keer's constrained
//! conjugate gradient written out as in the paper (Wear 231, 1999), for checking the
//! fast path ([`crate::cg`]) against.
//!
//! Every iteration recomputes the gap from the pressure (u = K p, the first
//! convolution) and the step's product r = K t (the second); no incremental gap, no
//! fused passes, no deferred rescale; the start is cold (no warm start along a path, no
//! coarse grid). The stop is the same physical error ε as the fast path (crate docs),
//! evaluated on the gap of the current pressure.
//!
//! The same iteration runs on a slab decomposition ([`run`] on
//! [`crate::slab::SlabOperator`], the distributed solve of [`crate::distributed`]): every
//! field is held by rows, the sums and maxima are global reductions in rank order
//! ([`crate::decomp`]); on one rank ([`crate::decomp::Serial`]) they are the serial sums
//! bit for bit.
//!
//! ```text
//!   g = K p − z + c    (c = −mean_{p>0}(K p − z) under pressure control)
//!   t = g + δ (G/G_old) t on p > 0 (0 elsewhere),  G = Σ_{p>0} g²
//!   r = K t,  r ← r − mean_{p>0} r (pressure control)
//!   τ = Σ_{p>0} g t / Σ_{p>0} r t
//!   p ← max(p − τ t, 0) on p > 0;  p ← −τ g where p = 0 and g < 0 (δ = 0 then, else 1)
//!   p ← p · p̄ / mean p (pressure control)
//! ```

use crate::BemError;
use crate::decomp::{self, Decomposition, Serial};
use crate::iteration::{CgOutcome, Problem};
use crate::state::Control;

/// Solves from a cold start; on return `p` holds the pressure.
pub(crate) fn solve(pb: &Problem, control: Control, p: &mut [f64]) -> Result<CgOutcome, BemError> {
    let mut work = pb.op.work();
    let product = |_: Apply, input: &[f64], out: &mut [f64], uniform: bool| {
        pb.op.apply(input, out, uniform, &mut work)
    };
    let settings = Settings {
        z_rms: pb.z_rms,
        stiffness: pb.stiffness,
        tolerance: pb.tolerance,
        max_iterations: pb.max_iterations,
        points: pb.z.len(),
        warm: false,
        precondition: false,
    };
    run(&Serial, product, pb.z, settings, control, p)
}

/// The scalars of a solve on a decomposition.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Settings {
    /// RMS height σ_z (m), of the whole grid.
    pub z_rms: f64,
    /// Stiffness (Pa/m) of the initial guess.
    pub stiffness: f64,
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Points of the whole grid.
    pub points: usize,
    /// Start from the given `p` (rescaled to the mean pressure under pressure control)
    /// instead of the cold guess.
    pub warm: bool,
    /// Precondition the direction with the inverse operator M⁻¹ (Vollebregt, as
    /// [`crate::pcg`]): y = P_C M⁻¹ P_C g (less its mean on C under pressure control),
    /// t = y + β t, β = Σ_C g y / (Σ_C g y)_old; the plain direction g once the
    /// preconditioned one stalls (offset control without the uniform mode, see `pcg`).
    pub precondition: bool,
}

/// Which operator a product applies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Apply {
    /// The influence operator K.
    K,
    /// The preconditioner M⁻¹ = K̂⁻¹.
    Inverse,
}

/// Iterations without the error halving after which the preconditioned direction counts
/// as stalled (as `pcg`).
const STALL: usize = 24;

/// The iteration on this rank's rows: `z` and `p` are the rank's rows, `product(which,
/// p, u, uniform)` the operator K (or the preconditioner) on them (every rank calls it
/// together), the sums global.
pub(crate) fn run(
    comm: &dyn Decomposition,
    mut product: impl FnMut(Apply, &[f64], &mut [f64], bool) -> Result<(), BemError>,
    z: &[f64],
    s: Settings,
    control: Control,
    p: &mut [f64],
) -> Result<CgOutcome, BemError> {
    let n = z.len();
    let (known, uniform) = match control {
        Control::Offset { c, uniform } => (Some(c), uniform),
        Control::Pressure(_) => (None, false),
    };
    match control {
        Control::Offset { c, .. } if !s.warm => {
            for i in 0..n {
                p[i] = s.stiffness * (z[i] - c).max(0.0);
            }
        }
        Control::Pressure(pbar) if !s.warm => p.fill(pbar),
        Control::Pressure(pbar) => rescale(comm, p, pbar, s.points),
        Control::Offset { .. } => {}
    }
    let (mut u, mut g, mut t, mut r) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut g_old = 1.0;
    let mut delta = 0.0;
    let mut error = f64::INFINITY;
    let mut precondition = s.precondition;
    // The stall watch of the preconditioned direction (offset control without the
    // uniform mode only): the best error and the iterations since it halved.
    let watch = matches!(control, Control::Offset { uniform: false, .. });
    let (mut best, mut since) = (f64::INFINITY, 0usize);
    let mut products = 0usize;
    for it in 0..=s.max_iterations {
        products += 1;
        product(Apply::K, p, &mut u, uniform)?;
        // Σ_{p>0} (u − z) and the count of the contact set.
        let mut sums = [
            contact_sum(p, |i| u[i] - z[i]),
            (0..n).filter(|&i| p[i] > 0.0).count() as f64,
        ];
        decomp::sum(comm, &mut sums);
        let [su, count] = sums;
        let c = match known {
            Some(c) => c,
            None if count == 0.0 => 0.0,
            None => -su / count,
        };
        for i in 0..n {
            g[i] = u[i] - z[i] + c;
        }
        let mut extremes = [
            (0..n)
                .filter(|&i| p[i] > 0.0)
                .map(|i| g[i].abs())
                .fold(0.0f64, f64::max),
            (0..n)
                .filter(|&i| p[i] <= 0.0)
                .map(|i| -g[i])
                .fold(0.0f64, f64::max),
        ];
        decomp::max(comm, &mut extremes);
        error = extremes[0].max(extremes[1]) / s.z_rms;
        if !error.is_finite() {
            return Err(BemError::NonFinite(it));
        }
        if error <= s.tolerance {
            return Ok(CgOutcome {
                iterations: it,
                products,
                error,
                offset: c,
                gap: g,
            });
        }
        if it == s.max_iterations {
            break;
        }
        if count == 0.0 {
            // Displacement control with no contact left: restart locally.
            for i in 0..n {
                p[i] = s.stiffness * (-g[i]).max(0.0);
            }
            delta = 0.0;
            continue;
        }
        if precondition && watch {
            if error < 0.5 * best {
                (best, since) = (error, 0);
            } else {
                since += 1;
            }
            if since >= STALL {
                // Stalled: the plain direction from here on, conjugation restarted.
                precondition = false;
                delta = 0.0;
            }
        }
        if precondition {
            // y = P_C M⁻¹ P_C g, into u (free until the next product K p); P_C g in r.
            for i in 0..n {
                r[i] = if p[i] > 0.0 { g[i] } else { 0.0 };
            }
            products += 1;
            product(Apply::Inverse, &r, &mut u, uniform)?;
            for i in 0..n {
                if p[i] <= 0.0 {
                    u[i] = 0.0;
                }
            }
            if known.is_none() {
                let mut ys = [contact_sum(p, |i| u[i])];
                decomp::sum(comm, &mut ys);
                let ybar = ys[0] / count;
                for i in (0..n).filter(|&i| p[i] > 0.0) {
                    u[i] -= ybar;
                }
            }
            let mut gy = [contact_sum(p, |i| g[i] * u[i])];
            decomp::sum(comm, &mut gy);
            let gy = gy[0];
            let beta = if g_old > 0.0 { delta * gy / g_old } else { 0.0 };
            g_old = gy;
            for i in 0..n {
                t[i] = if p[i] > 0.0 { u[i] + beta * t[i] } else { 0.0 };
            }
        } else {
            let mut gg = [contact_sum(p, |i| g[i] * g[i])];
            decomp::sum(comm, &mut gg);
            let gg = gg[0];
            let beta = delta * gg / g_old;
            g_old = gg;
            for i in 0..n {
                t[i] = if p[i] > 0.0 { g[i] + beta * t[i] } else { 0.0 };
            }
        }
        products += 1;
        product(Apply::K, &t, &mut r, uniform)?;
        if known.is_none() {
            let mut rs = [contact_sum(p, |i| r[i])];
            decomp::sum(comm, &mut rs);
            let rbar = rs[0] / count;
            for i in (0..n).filter(|&i| p[i] > 0.0) {
                r[i] -= rbar;
            }
        }
        let mut step = [
            contact_sum(p, |i| g[i] * t[i]),
            contact_sum(p, |i| r[i] * t[i]),
        ];
        decomp::sum(comm, &mut step);
        let [num, den] = step;
        let tau = if den > 0.0 { num / den } else { 0.0 };
        // Each point on its own: a contact point steps along t (clipped at 0), a point
        // out of contact with a negative gap re-enters.
        let mut reentry = false;
        for i in 0..n {
            if p[i] > 0.0 {
                p[i] = (p[i] - tau * t[i]).max(0.0);
            } else if g[i] < 0.0 {
                p[i] = -tau * g[i];
                reentry = true;
            }
        }
        delta = if decomp::any(comm, reentry) { 0.0 } else { 1.0 };
        if let Control::Pressure(pbar) = control {
            rescale(comm, p, pbar, s.points);
        }
    }
    Err(BemError::NotConverged {
        iterations: s.max_iterations,
        error,
        tolerance: s.tolerance,
    })
}

/// Σ over the contact set (p > 0) of `f(i)`, in index order (as `Iterator::sum`).
fn contact_sum(p: &[f64], f: impl Fn(usize) -> f64) -> f64 {
    (0..p.len()).filter(|&i| p[i] > 0.0).map(f).sum()
}

/// p ← p · p̄ / mean p (p̄ everywhere if the mean is 0); `points` of the whole grid.
fn rescale(comm: &dyn Decomposition, p: &mut [f64], pbar: f64, points: usize) {
    let mut total = [p.iter().sum::<f64>()];
    decomp::sum(comm, &mut total);
    let mean = total[0] / points as f64;
    if mean > 0.0 {
        p.iter_mut().for_each(|v| *v *= pbar / mean);
    } else {
        p.fill(pbar);
    }
}
