//! Load paths: a separation- or approach-controlled curve (one prepared problem for the
//! whole path, warm starts extrapolated with da/dδ) and pressure control (safeguarded
//! Newton on δ with the stiffness as slope), for both models.

use super::Problem;
use crate::rough::{Images, Model, PressureError, RoughContact, RoughError, Step};

/// The I-model load path of `rc` through the approaches `deltas` (m): the geometry is
/// prepared once, for the largest approach, and each step starts from the previous radii
/// with a² extrapolated linearly in δ (a² + 2a (da/dδ) Δδ, kept inside (0, A]).
pub(crate) fn curve(
    rc: &RoughContact<'_>,
    images: Images,
    deltas: &[f64],
) -> Result<Vec<Step>, RoughError> {
    let mut out: Vec<Step> = Vec::with_capacity(deltas.len());
    let mut warm: Vec<f64> = Vec::new();
    let mut last: Option<(f64, Vec<f64>)> = None; // (δ, da/dδ) of the previous step
    let mut problem: Option<Problem> = None;
    for &d in deltas {
        rc.check_delta(d)?;
        let pb = match &mut problem {
            Some(p) => p,
            None => {
                let dmax = deltas
                    .iter()
                    .copied()
                    .filter(|x| x.is_finite())
                    .fold(d, f64::max);
                problem.insert(Problem::new(rc, images, dmax, &[])?)
            }
        };
        if let Some((d0, rate)) = &last {
            let a_valid = pb.geo.a_valid;
            for (w, r) in warm.iter_mut().zip(rate) {
                if *w > 0.0 {
                    let p2 = *w * *w + 2.0 * *w * r * (d - d0);
                    *w = if p2 <= 0.0 {
                        0.0
                    } else if p2.sqrt() > a_valid {
                        *w
                    } else {
                        p2.sqrt()
                    };
                }
            }
        }
        let (s, rate) = pb.solve(d, &warm)?;
        last = Some((d, rate));
        warm.clone_from(&s.radii);
        out.push(s);
    }
    Ok(out)
}

/// Finds the approach giving mean pressure `target` (Pa) with `model`: the bracket
/// [0, hi] grows from hi = z_M − z_min by doubling until p(hi) ≥ target (at most
/// [`crate::rough::Params::max_pressure_iterations`] doublings), then safeguarded Newton
/// on δ (slope: the stiffness dP/dδ/A₀) to the relative tolerance
/// [`crate::rough::Params::pressure_tolerance`]. The I model prepares one problem for
/// the bracket and warm-starts every iterate from the previous radii extrapolated with
/// da/dδ, so a pressure-controlled step costs a few warm-started solves.
pub(crate) fn solve_pressure(
    rc: &RoughContact<'_>,
    model: Model,
    target: f64,
    warm: &[f64],
) -> Result<Step, RoughError> {
    let prm = &rc.params;
    if !(target.is_finite() && target > 0.0) {
        return Err(PressureError::OutOfRange {
            target,
            reason: "must be finite and > 0 Pa".into(),
        }
        .into());
    }
    let images = match model {
        Model::Independent => None,
        Model::Interacting(im) => Some(im),
    };
    // Bracket: the N model is cheap; the I model's pressure at δ is below the N
    // model's, so the N-model bracket is a lower bound of the I-model one.
    let mut hi = rc.max_delta().max(f64::MIN_POSITIVE);
    let mut grown = 0;
    let mut problem: Option<Problem> = None;
    let mut hi_step = loop {
        let s = match images {
            None => rc.solve_independent(hi)?,
            Some(im) => {
                let pb = problem.insert(Problem::new(rc, im, hi, warm)?);
                pb.solve(hi, warm)?.0
            }
        };
        if s.mean_pressure >= target {
            break s;
        }
        grown += 1;
        if grown > prm.max_pressure_iterations || !(2.0 * hi).is_finite() {
            return Err(PressureError::OutOfRange {
                target,
                reason: format!(
                    "not reached at approach δ = {hi:e} m ({:e} Pa there)",
                    s.mean_pressure
                ),
            }
            .into());
        }
        hi *= 2.0;
    };
    let tol = match images {
        None => prm.independent_pressure_tolerance,
        Some(_) => prm.pressure_tolerance,
    };
    let (mut lo, mut d) = (0.0, hi);
    let mut w = hi_step.radii.clone();
    let mut rate: Vec<f64> = Vec::new();
    for _ in 0..prm.max_pressure_iterations {
        let err = hi_step.mean_pressure - target;
        if err.abs() <= tol * target {
            return Ok(hi_step);
        }
        if err < 0.0 {
            lo = d;
        } else {
            hi = d;
        }
        let slope = hi_step.stiffness / rc.area();
        let mut next = d - err / slope;
        if !next.is_finite() || next <= lo || next >= hi {
            next = 0.5 * (lo + hi);
        }
        if (hi - lo) <= 1e-15 * hi {
            return Ok(hi_step);
        }
        // warm start: a² extrapolated linearly in δ
        for (k, wk) in w.iter_mut().enumerate() {
            let r = rate.get(k).copied().unwrap_or(0.0);
            if *wk > 0.0 {
                let p2 = *wk * *wk + 2.0 * *wk * r * (next - d);
                *wk = if p2 > 0.0 { p2.sqrt() } else { 0.0 };
            }
        }
        d = next;
        hi_step = match (&mut problem, images) {
            (Some(pb), Some(_)) => {
                let (s, r) = pb.solve(d, &w)?;
                rate = r;
                s
            }
            _ => rc.solve_independent(d)?,
        };
        w.clone_from(&hi_step.radii);
    }
    Err(PressureError::NoConvergence {
        target,
        iterations: prm.max_pressure_iterations,
        delta: d,
    }
    .into())
}
