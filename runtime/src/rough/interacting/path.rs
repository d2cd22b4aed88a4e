//! Load paths: a separation- or approach-controlled curve (one prepared problem for the
//! whole path, warm starts extrapolated with da/dδ) and pressure control (safeguarded
//! Newton on δ with the stiffness as slope), for both models.

use super::Problem;
use crate::numerics::{Falsi, Tolerance, bracketed};
use crate::rough::{Images, Model, PressureError, RoughContact, RoughError, Step};

/// The I-model load path of `rc` through the approaches `deltas` (m). The geometry is
/// prepared for a stretch of the path at a time: at a step beyond the prepared approach,
/// for the farthest remaining approach whose loaded summits are at most [`PATH_GROWTH`]
/// times those of this step (or the dense limit): a curve from first contact to 10⁴ or
/// 10⁵ contacts thus runs its early steps on small problems (dense sums, or a coarse grid)
/// instead of the grid of its last step, for a handful of preparations. Each step starts
/// from the previous radii with a² extrapolated linearly in δ (a² + 2a (da/dδ) Δδ, kept
/// inside (0, A]).
pub(crate) fn curve(
    rc: &RoughContact<'_>,
    images: Images,
    deltas: &[f64],
) -> Result<Vec<Step>, RoughError> {
    let mut out: Vec<Step> = Vec::with_capacity(deltas.len());
    match curve_into(rc, images, deltas, &mut out) {
        Ok(()) => Ok(out),
        Err(e) => Err(e),
    }
}

/// [`curve`] keeping the steps solved before a failing one in `out`.
pub(crate) fn curve_into(
    rc: &RoughContact<'_>,
    images: Images,
    deltas: &[f64],
    out: &mut Vec<Step>,
) -> Result<(), RoughError> {
    let mut warm: Vec<f64> = Vec::new();
    let mut last: Option<(f64, Vec<f64>)> = None; // (δ, da/dδ) of the previous step
    let mut problem: Option<(f64, Problem)> = None; // (prepared approach, problem)
    let loaded = |d: f64| {
        (0..rc.summits.len())
            .filter(|&k| rc.interference(k, d) > 0.0)
            .count()
    };
    for (i, &d) in deltas.iter().enumerate() {
        rc.params.cancel.check()?;
        rc.check_delta(d)?;
        if problem.as_ref().is_none_or(|(dp, _)| d > *dp) {
            let limit = (PATH_GROWTH * loaded(d)).max(2 * rc.params.dense_pair_limit);
            let mut dp = d;
            for &x in &deltas[i..] {
                if x.is_finite() && x > dp && loaded(x) <= limit {
                    dp = x;
                }
            }
            problem = Some((dp, Problem::new(rc, images, dp, &warm)?));
        }
        let (_, pb) = problem
            .as_mut()
            .ok_or(RoughError::NonFinite("I-model path (no prepared problem)"))?;
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
    Ok(())
}

/// Growth of the loaded summits over which one prepared I-model problem serves a load
/// path ([`curve`]).
const PATH_GROWTH: usize = 2;

/// Factor by which a pressure search prepares its I-model problem beyond the approach
/// it solves (the candidates and far-field bound then serve the next iterates too).
const PREPARE_MARGIN: f64 = 1.25;

/// Finds the approach giving mean pressure `target` (Pa) with `model` by safeguarded
/// Newton on δ ([`newton_on_delta`], slope: the stiffness dP/dδ/A₀) to the relative
/// tolerance [`crate::rough::Params::pressure_tolerance`]
/// ([`crate::rough::Params::independent_pressure_tolerance`] for the N model). The N
/// model starts at z_M − z_min. The I model starts at the N model's approach for the
/// target (cheap and exact; interactions lower the load at equal approach, so the I
/// model's approach lies beyond it) and solves every iterate on one prepared problem
/// (prepared for [`PREPARE_MARGIN`] × the approach, again only if an iterate goes
/// beyond), warm-started from the previous radii with a² extrapolated linearly in δ:
/// a pressure-controlled step costs one problem and a few warm-started solves, as a
/// separation-controlled step costs one problem and one cold solve.
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
    let n_model = newton_on_delta(
        rc,
        target,
        prm.independent_pressure_tolerance,
        rc.max_delta(),
        |d| rc.solve_independent(d),
    )?;
    let images = match model {
        Model::Independent => return Ok(n_model),
        Model::Interacting(im) => im,
    };
    let mut problem: Option<(f64, Problem)> = None;
    let mut w: Vec<f64> = warm.to_vec();
    let mut last: Option<(f64, Vec<f64>)> = None; // (δ, da/dδ) of the previous iterate
    newton_on_delta(rc, target, prm.pressure_tolerance, n_model.delta, |d| {
        let pb = match &mut problem {
            Some((dp, pb)) if d <= *dp => pb,
            _ => {
                let dp = PREPARE_MARGIN * d;
                &mut problem.insert((dp, Problem::new(rc, images, dp, &w)?)).1
            }
        };
        if let Some((d0, rate)) = &last {
            for (wk, r) in w.iter_mut().zip(rate) {
                if *wk > 0.0 {
                    let p2 = *wk * *wk + 2.0 * *wk * r * (d - d0);
                    *wk = if p2 > 0.0 { p2.sqrt() } else { 0.0 };
                }
            }
        }
        let (s, rate) = pb.solve(d, &w)?;
        w.clone_from(&s.radii);
        last = Some((d, rate));
        Ok(s)
    })
}

/// Safeguarded Newton on the approach ([`bracketed`] on the half-open bracket [0, ∞)):
/// from δ = `start` (m), solve(δ) gives a step whose mean pressure p(δ) is compared
/// with `target` (Pa); the next δ is the Newton step δ − (p − target)/(dP/dδ/A₀) when it
/// stays inside the bracket [lo, hi] known so far (lo: p < target, hi: p > target), else
/// the bracket's midpoint, or 2δ while no iterate has reached the target. Done at
/// |p − target| ≤ `tol`·target or a bracket narrower than 10⁻¹⁵ hi; the step solved last.
fn newton_on_delta(
    rc: &RoughContact<'_>,
    target: f64,
    tol: f64,
    start: f64,
    mut solve: impl FnMut(f64) -> Result<Step, RoughError>,
) -> Result<Step, RoughError> {
    let prm = &rc.params;
    let mut last: Option<Step> = None;
    let f = |d: f64| -> Result<(f64, Option<f64>), RoughError> {
        let s = solve(d)?;
        let slope = s.stiffness / rc.area();
        let err = s.mean_pressure - target;
        last = Some(s);
        Ok((err, Some(slope)))
    };
    let tolerance = Tolerance {
        f: tol * target,
        step: 0.0,
        width: 1e-15,
        width_abs: 0.0,
        falsi: Falsi::Illinois,
    };
    let (lo, hi) = ((0.0, -target), (f64::INFINITY, target));
    let d = start.max(f64::MIN_POSITIVE);
    let root = bracketed(f, lo, hi, Some(d), tolerance, prm.max_pressure_iterations)?;
    match last {
        Some(s) if root.converged => Ok(s),
        Some(s) if root.evaluations < prm.max_pressure_iterations => {
            Err(PressureError::OutOfRange {
                target,
                reason: format!(
                    "not reached at approach δ = {:e} m ({:e} Pa there)",
                    root.x, s.mean_pressure
                ),
            }
            .into())
        }
        _ => Err(PressureError::NoConvergence {
            target,
            iterations: prm.max_pressure_iterations,
            delta: root.x,
        }
        .into()),
    }
}
