//! Polonsky–Keer constrained conjugate gradient (Wear 231, 1999; the form of Rey,
//! Anciaux & Molinari, Comput. Mech. 2017 for displacement control), with one
//! convolution per iteration.
//!
//! The unknown is the pressure p ≥ 0 (Pa); the gap g = u − z + c with u = K p (m) and c
//! the flat's offset, known under displacement control, the Lagrange multiplier of the
//! mean pressure otherwise (c = −mean of u − z over the contact set). Per iteration:
//!
//! ```text
//!   t ← g + β t on the contact set (0 elsewhere),  β = Σg²/Σg²_old (0 after re-entry)
//!   r = K t                                           ← the one convolution
//!   τ = Σ g t / Σ r̃ t        (r̃ = r − mean_contact r under pressure control)
//!   p ← max(p − τ t, 0);  p ← −τ g where p = 0 and g < 0 (re-entry)
//!   u ← u − τ r  (+ K Δ if the projection or the re-entry changed p by Δ ≠ −τ t)
//! ```
//!
//! so the gap is updated from the product that the step needs anyway; a second product
//! is spent only on iterations where the contact set changes, and u is recomputed from p
//! every [`REFRESH`] iterations and before the solution is accepted (no drift).
//!
//! Stopping criterion on the physical error (σ_z the RMS height):
//!
//! ```text
//!   ε = max( Σ p|g| / (σ_z Σ p),  max_{p=0} max(−g, 0) / σ_z )
//! ```
//!
//! (complementarity on the contact set, interpenetration outside it), evaluated on the
//! exact u = K p.

use rayon::prelude::*;
use strata_runtime::fft::Fft2Work;

use crate::BemError;
use crate::operator::Operator;

/// Incremental gap updates between two exact products u = K p.
pub(crate) const REFRESH: usize = 64;
/// Points per parallel chunk of the vector operations.
const CHUNK: usize = 1 << 14;

/// What the constrained CG holds fixed.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Control {
    /// g = K p − z + c with c known; `uniform`: the periodic k = 0 mode is included.
    Offset { c: f64, uniform: bool },
    /// Mean pressure p̄ (Pa); the offset is the Lagrange multiplier.
    Pressure(f64),
}

/// Result of one constrained solve.
pub(crate) struct CgOutcome {
    pub iterations: usize,
    pub error: f64,
    /// The offset c (m): g = K p − z + c.
    pub offset: f64,
    pub gap: Vec<f64>,
}

/// The problem data of one solve.
pub(crate) struct Problem<'a> {
    pub op: &'a Operator,
    pub z: &'a [f64],
    pub z_rms: f64,
    /// Stiffness (Pa/m) for initial guesses.
    pub stiffness: f64,
    pub tolerance: f64,
    pub max_iterations: usize,
}

/// Buffers of the iteration (allocated once per solve, none per iteration).
struct State {
    u: Vec<f64>,
    t: Vec<f64>,
    r: Vec<f64>,
    corr: Vec<f64>,
    work: Fft2Work,
}

/// Sums over the contact set (p > 0) of h = u − z: (Σh, count).
fn contact_mean(p: &[f64], u: &[f64], z: &[f64]) -> (f64, f64) {
    p.par_chunks(CHUNK)
        .zip(u.par_chunks(CHUNK))
        .zip(z.par_chunks(CHUNK))
        .map(|((p, u), z)| {
            let (mut s, mut m) = (0.0, 0.0);
            for i in 0..p.len() {
                if p[i] > 0.0 {
                    s += u[i] - z[i];
                    m += 1.0;
                }
            }
            (s, m)
        })
        .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// The offset c of the current state.
fn offset(control: Control, p: &[f64], u: &[f64], z: &[f64]) -> f64 {
    match control {
        Control::Offset { c, .. } => c,
        Control::Pressure(_) => {
            let (s, m) = contact_mean(p, u, z);
            if m > 0.0 { -s / m } else { 0.0 }
        }
    }
}

/// Error terms and Σg² on the contact set for g = u − z + c:
/// [Σ p|g|, Σ p, max_{p=0}(−g), Σ_{p>0} g²].
fn error_terms(p: &[f64], u: &[f64], z: &[f64], c: f64) -> [f64; 4] {
    p.par_chunks(CHUNK)
        .zip(u.par_chunks(CHUNK))
        .zip(z.par_chunks(CHUNK))
        .map(|((p, u), z)| {
            let mut a = [0.0f64; 4];
            for i in 0..p.len() {
                let g = u[i] - z[i] + c;
                if p[i] > 0.0 {
                    a[0] += p[i] * g.abs();
                    a[1] += p[i];
                    a[3] += g * g;
                } else {
                    a[2] = a[2].max(-g);
                }
            }
            a
        })
        .reduce(
            || [0.0; 4],
            |a, b| [a[0] + b[0], a[1] + b[1], a[2].max(b[2]), a[3] + b[3]],
        )
}

/// ε from the error terms.
fn error_of(e: &[f64; 4], z_rms: f64) -> f64 {
    let comp = if e[1] > 0.0 { e[0] / e[1] } else { 0.0 };
    comp.max(e[2]) / z_rms
}

/// Solves; on return `p` holds the pressure.
pub(crate) fn solve(pb: &Problem, control: Control, p: &mut [f64]) -> Result<CgOutcome, BemError> {
    let n = pb.z.len();
    let z = pb.z;
    let uniform = match control {
        Control::Offset { uniform, .. } => uniform,
        Control::Pressure(_) => false,
    };
    let gap_of = |u: &[f64], c: f64| -> Vec<f64> {
        u.par_iter()
            .zip(z.par_iter())
            .map(|(u, z)| u - z + c)
            .collect()
    };
    // Initial guess.
    match control {
        Control::Offset { c, .. } => {
            if z.iter().all(|&zi| zi <= c) {
                // No overlap: the flat does not touch.
                p.fill(0.0);
                return Ok(CgOutcome {
                    iterations: 0,
                    error: 0.0,
                    offset: c,
                    gap: z.iter().map(|zi| c - zi).collect(),
                });
            }
            if p.iter().all(|&v| v == 0.0) {
                for i in 0..n {
                    p[i] = pb.stiffness * (z[i] - c).max(0.0);
                }
            }
        }
        Control::Pressure(pbar) => scale_to_mean(p, None, pbar),
    }
    let mut s = State {
        u: vec![0.0; n],
        t: vec![0.0; n],
        r: vec![0.0; n],
        corr: vec![0.0; n],
        work: pb.op.work(),
    };
    pb.op.apply(p, &mut s.u, uniform, &mut s.work)?;
    let mut exact = true;
    let mut since_exact = 0usize;
    let mut g_old = 1.0;
    let mut conjugate = false;
    let mut error = f64::INFINITY;
    for it in 0..=pb.max_iterations {
        let mut c = offset(control, p, &s.u, z);
        let mut e = error_terms(p, &s.u, z, c);
        error = error_of(&e, pb.z_rms);
        if !exact && (error <= pb.tolerance || it == pb.max_iterations || since_exact >= REFRESH) {
            // Accept only on the exact gap; refresh it now and then against drift.
            pb.op.apply(p, &mut s.u, uniform, &mut s.work)?;
            since_exact = 0;
            c = offset(control, p, &s.u, z);
            e = error_terms(p, &s.u, z, c);
            error = error_of(&e, pb.z_rms);
        }
        if !error.is_finite() {
            return Err(BemError::NonFinite(it));
        }
        if error <= pb.tolerance {
            return Ok(CgOutcome {
                iterations: it,
                error,
                offset: c,
                gap: gap_of(&s.u, c),
            });
        }
        if it == pb.max_iterations {
            break;
        }
        if e[1] == 0.0 {
            // The step emptied the contact set (displacement control only): restart
            // from the local estimate on the interpenetrating points.
            for i in 0..n {
                p[i] = pb.stiffness * (-(s.u[i] - z[i] + c)).max(0.0);
            }
            pb.op.apply(p, &mut s.u, uniform, &mut s.work)?;
            exact = true;
            since_exact = 0;
            conjugate = false;
            continue;
        }
        step(
            pb,
            control,
            p,
            &mut s,
            c,
            &e,
            &mut g_old,
            &mut conjugate,
            uniform,
        )?;
        exact = false;
        since_exact += 1;
    }
    Err(BemError::NotConverged {
        iterations: pb.max_iterations,
        error,
        tolerance: pb.tolerance,
    })
}

/// Scales p to the mean `pbar` (uniform p̄ if p ≡ 0), and u with it (u = K p is linear).
fn scale_to_mean(p: &mut [f64], u: Option<&mut [f64]>, pbar: f64) {
    let mean = p.par_iter().sum::<f64>() / p.len() as f64;
    if mean > 0.0 {
        let f = pbar / mean;
        p.par_iter_mut().for_each(|v| *v *= f);
        if let Some(u) = u {
            u.par_iter_mut().for_each(|v| *v *= f);
        }
    } else {
        p.fill(pbar);
        // u is recomputed by the caller in this (initial) case.
    }
}

/// One conjugate-gradient step from the state with offset `c` and error terms `e`.
#[allow(clippy::too_many_arguments)]
fn step(
    pb: &Problem,
    control: Control,
    p: &mut [f64],
    s: &mut State,
    c: f64,
    e: &[f64; 4],
    g_old: &mut f64,
    conjugate: &mut bool,
    uniform: bool,
) -> Result<(), BemError> {
    let z = pb.z;
    let gg = e[3];
    let beta = if *conjugate { gg / *g_old } else { 0.0 };
    *g_old = gg;
    // Direction t on the contact set, and Σ g t.
    let gt: f64 =
        s.t.par_chunks_mut(CHUNK)
            .zip(p.par_chunks(CHUNK))
            .zip(s.u.par_chunks(CHUNK))
            .zip(z.par_chunks(CHUNK))
            .map(|(((t, p), u), z)| {
                let mut acc = 0.0;
                for i in 0..t.len() {
                    t[i] = if p[i] > 0.0 {
                        let g = u[i] - z[i] + c;
                        let v = g + beta * t[i];
                        acc += g * v;
                        v
                    } else {
                        0.0
                    };
                }
                acc
            })
            .sum();
    pb.op.apply(&s.t, &mut s.r, uniform, &mut s.work)?;
    // [Σ r t, Σ t, Σ r, count] on the contact set.
    let d = p
        .par_chunks(CHUNK)
        .zip(s.r.par_chunks(CHUNK))
        .zip(s.t.par_chunks(CHUNK))
        .map(|((p, r), t)| {
            let mut a = [0.0f64; 4];
            for i in 0..p.len() {
                if p[i] > 0.0 {
                    a[0] += r[i] * t[i];
                    a[1] += t[i];
                    a[2] += r[i];
                    a[3] += 1.0;
                }
            }
            a
        })
        .reduce(
            || [0.0; 4],
            |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]],
        );
    let den = match control {
        Control::Pressure(_) if d[3] > 0.0 => d[0] - d[2] / d[3] * d[1],
        _ => d[0],
    };
    let tau = if den > 0.0 { gt / den } else { 0.0 };
    // Step, projection and re-entry; u follows by −τ r, corrections collected.
    let flags = p
        .par_chunks_mut(CHUNK)
        .zip(s.u.par_chunks_mut(CHUNK))
        .zip(s.corr.par_chunks_mut(CHUNK))
        .zip(s.t.par_chunks(CHUNK))
        .zip(s.r.par_chunks(CHUNK))
        .zip(z.par_chunks(CHUNK))
        .map(|(((((p, u), corr), t), r), z)| {
            let (mut changed, mut overlap) = (false, false);
            for i in 0..p.len() {
                let g = u[i] - z[i] + c;
                let mut k = 0.0;
                if p[i] > 0.0 {
                    let v = p[i] - tau * t[i];
                    if v < 0.0 {
                        k = -v;
                        p[i] = 0.0;
                    } else {
                        p[i] = v;
                    }
                } else if g < 0.0 {
                    k = -tau * g;
                    p[i] = k;
                    overlap = true;
                }
                changed |= k != 0.0;
                corr[i] = k;
                u[i] -= tau * r[i];
            }
            (changed, overlap)
        })
        .reduce(|| (false, false), |a, b| (a.0 || b.0, a.1 || b.1));
    if flags.0 {
        // The contact set changed: add K Δ (the second product of this iteration).
        pb.op.apply(&s.corr, &mut s.r, uniform, &mut s.work)?;
        s.u.par_iter_mut()
            .zip(s.r.par_iter())
            .for_each(|(u, r)| *u += r);
    }
    *conjugate = !flags.1;
    if let Control::Pressure(pbar) = control {
        scale_to_mean(p, Some(&mut s.u), pbar);
    }
    Ok(())
}
