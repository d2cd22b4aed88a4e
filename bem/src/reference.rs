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
//! ```text
//!   g = K p − z + c    (c = −mean_{p>0}(K p − z) under pressure control)
//!   t = g + δ (G/G_old) t on p > 0 (0 elsewhere),  G = Σ_{p>0} g²
//!   r = K t,  r ← r − mean_{p>0} r (pressure control)
//!   τ = Σ_{p>0} g t / Σ_{p>0} r t
//!   p ← max(p − τ t, 0) on p > 0;  p ← −τ g where p = 0 and g < 0 (δ = 0 then, else 1)
//!   p ← p · p̄ / mean p (pressure control)
//! ```

use crate::BemError;
use crate::iteration::{CgOutcome, Problem};
use crate::state::Control;

/// Solves from a cold start; on return `p` holds the pressure.
pub(crate) fn solve(pb: &Problem, control: Control, p: &mut [f64]) -> Result<CgOutcome, BemError> {
    let (z, n) = (pb.z, pb.z.len());
    let (known, uniform) = match control {
        Control::Offset { c, uniform } => (Some(c), uniform),
        Control::Pressure(_) => (None, false),
    };
    match control {
        Control::Offset { c, .. } => {
            for i in 0..n {
                p[i] = pb.stiffness * (z[i] - c).max(0.0);
            }
        }
        Control::Pressure(pbar) => p.fill(pbar),
    }
    let mut work = pb.op.work();
    let (mut u, mut g, mut t, mut r) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut g_old = 1.0;
    let mut delta = 0.0;
    let mut error = f64::INFINITY;
    for it in 0..=pb.max_iterations {
        pb.op.apply(p, &mut u, uniform, &mut work)?;
        let contact: Vec<usize> = (0..n).filter(|&i| p[i] > 0.0).collect();
        let c = match known {
            Some(c) => c,
            None if contact.is_empty() => 0.0,
            None => -contact.iter().map(|&i| u[i] - z[i]).sum::<f64>() / contact.len() as f64,
        };
        for i in 0..n {
            g[i] = u[i] - z[i] + c;
        }
        let comp = contact.iter().map(|&i| g[i].abs()).fold(0.0f64, f64::max);
        let pen = (0..n)
            .filter(|&i| p[i] <= 0.0)
            .map(|i| -g[i])
            .fold(0.0f64, f64::max);
        error = comp.max(pen) / pb.z_rms;
        if !error.is_finite() {
            return Err(BemError::NonFinite(it));
        }
        if error <= pb.tolerance {
            return Ok(CgOutcome {
                iterations: it,
                // Two products per iteration and the final gap's.
                products: 2 * it + 1,
                error,
                offset: c,
                gap: g,
            });
        }
        if it == pb.max_iterations {
            break;
        }
        if contact.is_empty() {
            // Displacement control with no contact left: restart locally.
            for i in 0..n {
                p[i] = pb.stiffness * (-g[i]).max(0.0);
            }
            delta = 0.0;
            continue;
        }
        let gg: f64 = contact.iter().map(|&i| g[i] * g[i]).sum();
        let beta = delta * gg / g_old;
        g_old = gg;
        let mut next = vec![0.0; n];
        for &i in &contact {
            next[i] = g[i] + beta * t[i];
        }
        t = next;
        pb.op.apply(&t, &mut r, uniform, &mut work)?;
        if known.is_none() {
            let rbar = contact.iter().map(|&i| r[i]).sum::<f64>() / contact.len() as f64;
            for &i in &contact {
                r[i] -= rbar;
            }
        }
        let num: f64 = contact.iter().map(|&i| g[i] * t[i]).sum();
        let den: f64 = contact.iter().map(|&i| r[i] * t[i]).sum();
        let tau = if den > 0.0 { num / den } else { 0.0 };
        let mut was = vec![false; n];
        for &i in &contact {
            was[i] = true;
        }
        for &i in &contact {
            p[i] = (p[i] - tau * t[i]).max(0.0);
        }
        delta = 1.0;
        for i in 0..n {
            if !was[i] && g[i] < 0.0 {
                p[i] = -tau * g[i];
                delta = 0.0;
            }
        }
        if let Control::Pressure(pbar) = control {
            let mean = p.iter().sum::<f64>() / n as f64;
            if mean > 0.0 {
                p.iter_mut().for_each(|v| *v *= pbar / mean);
            } else {
                p.fill(pbar);
            }
        }
    }
    Err(BemError::NotConverged {
        iterations: pb.max_iterations,
        error,
        tolerance: pb.tolerance,
    })
}
