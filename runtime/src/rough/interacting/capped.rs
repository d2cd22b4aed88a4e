//! The I model with capped tips (physics.md §9): every summit an elastic–perfectly
//! plastic paraboloid (pressure ≤ H) through the capped asperity's response table
//! ([`PlasticResponse`]), the summits interacting through the far field of their actual
//! loads.
//!
//! Summit k sits in the effective displacement D̃_k (m) the others cause over its
//! contact (and its own periodic images, with the zero-mean correction on an elastic
//! base, summed as the elastic I model sums them: D̃_k = (D_k + E_k/Q′_k)/2, the centre
//! value and the reciprocal average of the I model's gradient, `Energy::
//! effective_displacement`); its own effective interference is
//!
//! ```text
//!   d_k = δ_k − D̃_k,   (a_k, P_k) = response of one summit at d_k,
//!   G_l = (P_l / P_el(a_l)) · G_l^el(a_l, r),
//! ```
//!
//! G_l^el the elastic I model's field of source l at its contact radius a_l (its point
//! force on the layered solid far away, the second-order shape nearer) and P_el(a) =
//! (4/3)E*χ(a)a³/R the elastic load at that radius: a source carries its actual load
//! P_l. An elastic summit (below its yield onset) answers through the I model's own
//! relation δ_I(a) = (s + Q s′/Q′)/2 = d (a²/R on a homogeneous solid), so that with no
//! summit yielded the fixed point is the elastic I model's KKT condition F_k = 0
//! exactly; a yielded one through the capped table. The fixed point d = δ − D̃(d) is
//! solved by Anderson-accelerated damped iteration, the stiffness dP/dδ by central
//! differences of it (step 1e-4 δ, each side solved to 1e-12 of δ_max). Where no
//! summit yields at the elastic I model's solution, that solution is returned as it is
//! (so H → ∞ is the elastic I model bit for bit). Loading only: each approach from the
//! undeformed summits.

use super::Problem;
use super::energy::State;
use crate::law::{AsperityLaw, contact_radius, force};
use crate::numerics::{Falsi, Tolerance, bracketed};
use crate::rough::local::Local;
use crate::rough::plastic::{PlasticResponse, below_table};
use crate::rough::{Images, Model, NewtonError, RoughContact, RoughError, Step};

/// Iterations of the fixed point (and of the stiffness's linear fixed point).
const MAX_ITERATIONS: usize = 1000;
/// Anderson history depth.
const DEPTH: usize = 6;
/// Damping β of the Anderson update (x ← x + β f − …).
const MIXING: f64 = 0.5;
/// Rebuilds of the far-field model when a capped contact outgrows its range.
const REBUILDS: usize = 3;
/// Tolerance of the fixed point relative to the largest interference (at most
/// `Params::kkt_tolerance`): the stiffness differences two solves.
const TIGHT: f64 = 1e-12;
/// Relative step δ of the stiffness's central differences.
const FD_STEP: f64 = 1e-4;

/// One summit's answer at effective interference d.
#[derive(Debug, Clone, Copy, Default)]
struct Answer {
    /// Contact radius (m).
    a: f64,
    /// Load (N).
    force: f64,
    /// Plastic radius (m).
    a_plastic: f64,
    /// P / P_el(a): the source factor of its field.
    scale: f64,
}

/// The summit of radius `radius` at effective interference `d`: the elastic law below
/// the yield onset, the capped table above it.
fn answer(law: &dyn AsperityLaw, resp: &PlasticResponse, d: f64, radius: f64) -> Answer {
    if d.is_nan() || d <= 0.0 {
        return Answer::default();
    }
    let c = if below_table(resp.e_star, resp.hardness, d, radius) {
        None
    } else {
        Some(resp.at(d, radius))
    };
    if let Some(c) = c.filter(|c| c.a_plastic > 0.0) {
        let el = force(law, c.a, radius);
        return Answer {
            a: c.a,
            force: c.force,
            a_plastic: c.a_plastic,
            scale: if el > 0.0 { c.force / el } else { 0.0 },
        };
    }
    let Some(a) = own_radius(law, radius, d) else {
        return Answer::default();
    };
    Answer {
        a,
        force: force(law, a, radius),
        a_plastic: 0.0,
        scale: 1.0,
    }
}

/// The I model's own interference of one asperity at contact radius a (m):
/// δ_I(a) = (s + Q s′/Q′)/2 (a²/R on a homogeneous solid).
fn own_interference(law: &dyn AsperityLaw, a: f64, radius: f64) -> f64 {
    let l = Local::at(law, a, radius);
    0.5 * (l.s + l.q * l.ds / l.dq)
}

/// The contact radius a with δ_I(a) = d (m), by the halving regula falsi of
/// [`bracketed`] ([`Falsi::Halving`]) on a bracket grown by doubling from the N model's radius
/// (ζ(a)a²/R = d); δ_I grows with a. None when no bracket is found or δ_I is not finite.
fn own_radius(law: &dyn AsperityLaw, radius: f64, d: f64) -> Option<f64> {
    if law.is_homogeneous() {
        return Some((radius * d).sqrt());
    }
    let a0 = contact_radius(law, radius, d)?;
    let h = |a: f64| own_interference(law, a, radius) - d;
    let (mut lo, mut hi) = (0.0, a0);
    let mut grow = 0;
    while h(hi) < 0.0 {
        lo = hi;
        hi *= 2.0;
        grow += 1;
        if grow > 60 {
            return None;
        }
    }
    let tol = Tolerance {
        f: 1e-15 * d,
        step: 0.0,
        width: 1e-15,
        width_abs: 0.0,
        falsi: Falsi::Halving,
    };
    let eval = |a: f64| Ok::<_, std::convert::Infallible>((h(a), None));
    let root = match bracketed(eval, (lo, -d), (hi, h(hi)), None, tol, 200) {
        Ok(root) => root,
        Err(never) => match never {},
    };
    root.f.is_finite().then_some(root.x)
}

/// D̃_k (m) at every local index for contact radii `a` and source factors `scale`.
fn displacements(prob: &Problem, deltas: &[f64], a: &[f64], scale: &[f64]) -> Vec<f64> {
    let mut en = prob.energy(deltas);
    en.source_scale = Some(scale);
    let mut st = State::default();
    en.eval(a, &mut st);
    (0..a.len())
        .map(|p| en.effective_displacement(&st, p))
        .collect()
}

/// A converged fixed point: x, the iterations, the residual.
type Converged = (Vec<f64>, usize, f64);

/// The fixed point x = G(x) by Anderson acceleration (depth [`DEPTH`], damping
/// [`MIXING`]) to max |G(x) − x| ≤ `tol`: (x, iterations, residual), or the residual
/// reached when the budget ran out (Err).
fn anderson(
    mut map: impl FnMut(&[f64]) -> Result<Vec<f64>, RoughError>,
    mut x: Vec<f64>,
    tol: f64,
) -> Result<Result<Converged, f64>, RoughError> {
    let n = x.len();
    let mut hist: Vec<(Vec<f64>, Vec<f64>)> = Vec::new(); // (x_i, f_i)
    let mut best = f64::INFINITY;
    for it in 0..MAX_ITERATIONS {
        let gx = map(&x)?;
        let f: Vec<f64> = gx.iter().zip(&x).map(|(g, x)| g - x).collect();
        let res = f.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if !res.is_finite() {
            return Err(RoughError::NonFinite("capped I model (fixed point)"));
        }
        if res <= tol {
            return Ok(Ok((gx, it + 1, res)));
        }
        if res > 1e3 * best {
            hist.clear(); // restart the history after a blow-up
        }
        best = best.min(res);
        hist.push((x.clone(), f.clone()));
        if hist.len() > DEPTH + 1 {
            hist.remove(0);
        }
        // least squares: min ‖f − Σ γ_j (f − f_j)‖ over the history (normal equations,
        // Tikhonov-regularised)
        let m = hist.len() - 1;
        let mut next: Vec<f64> = (0..n).map(|i| x[i] + MIXING * f[i]).collect();
        if m > 0 {
            let df: Vec<Vec<f64>> = (0..m)
                .map(|j| (0..n).map(|i| f[i] - hist[j].1[i]).collect())
                .collect();
            let mut a = vec![0.0; m * m];
            let mut b = vec![0.0; m];
            for j in 0..m {
                for k in 0..=j {
                    let v: f64 = (0..n).map(|i| df[j][i] * df[k][i]).sum();
                    a[j * m + k] = v;
                    a[k * m + j] = v;
                }
                b[j] = (0..n).map(|i| df[j][i] * f[i]).sum();
            }
            let trace: f64 = (0..m)
                .map(|j| a[j * m + j])
                .sum::<f64>()
                .max(f64::MIN_POSITIVE);
            for j in 0..m {
                a[j * m + j] += 1e-12 * trace;
            }
            if let Some(g) = solve_small(a, b, m) {
                for (j, gj) in g.iter().enumerate() {
                    for i in 0..n {
                        let dx = x[i] - hist[j].0[i];
                        next[i] -= gj * (dx + MIXING * df[j][i]);
                    }
                }
            }
        }
        x = next;
        let _ = it;
    }
    let gx = map(&x)?;
    let res = gx
        .iter()
        .zip(&x)
        .fold(0.0_f64, |m, (g, x)| m.max((g - x).abs()));
    Ok(Err(res))
}

/// Gaussian elimination with partial pivoting on an m × m system (None if singular).
fn solve_small(mut a: Vec<f64>, mut b: Vec<f64>, m: usize) -> Option<Vec<f64>> {
    for c in 0..m {
        let piv = (c..m).max_by(|&i, &j| a[i * m + c].abs().total_cmp(&a[j * m + c].abs()))?;
        if a[piv * m + c].abs() <= f64::MIN_POSITIVE {
            return None;
        }
        if piv != c {
            for k in 0..m {
                a.swap(c * m + k, piv * m + k);
            }
            b.swap(c, piv);
        }
        for r in c + 1..m {
            let f = a[r * m + c] / a[c * m + c];
            for k in c..m {
                a[r * m + k] -= f * a[c * m + k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = vec![0.0; m];
    for c in (0..m).rev() {
        let s: f64 = (c + 1..m).map(|k| a[c * m + k] * x[k]).sum();
        x[c] = (b[c] - s) / a[c * m + c];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

impl RoughContact<'_> {
    /// Whether every contact of the elastic I model's step `elastic` stays below the
    /// capped response table's range (x = δ_I(a_k)/δ_c < `plastic::ELASTIC_X`, its
    /// effective interference δ_I(a_k) at the I model's solution) for contact modulus
    /// `e_star` and hardness `hardness` (Pa): then the capped I model's step is
    /// `elastic` itself, and no table is needed.
    pub fn elastic_i_step_below_table(&self, elastic: &Step, e_star: f64, hardness: f64) -> bool {
        self.summits.iter().zip(&elastic.radii).all(|(s, &a)| {
            a <= 0.0
                || below_table(
                    e_star,
                    hardness,
                    own_interference(self.law, a, s.radius),
                    s.radius,
                )
        })
    }

    /// The I model with capped tips at approach δ (m) from `warm` (contact radii per
    /// summit, m): the step (its `radii` the contact radii, `kkt_residual` the fixed
    /// point's residual relative to the largest interference) and the plastic area
    /// fraction Σ π a_p²/A₀ (module docs).
    pub fn solve_interacting_plastic(
        &self,
        resp: &PlasticResponse,
        images: Images,
        delta: f64,
        warm: &[f64],
    ) -> Result<(Step, f64), RoughError> {
        self.check_delta(delta)?;
        let elastic = self.solve(Model::Interacting(images), delta, warm)?;
        self.capped_from_elastic(resp, images, elastic, false)
    }

    /// The capped step from the elastic I model's step at the same approach (module
    /// docs): `elastic` itself where no summit yields at it (unless `always`, which
    /// runs the fixed point whatever yields: the tests of its elastic limit).
    pub fn capped_from_elastic(
        &self,
        resp: &PlasticResponse,
        images: Images,
        elastic: Step,
        always: bool,
    ) -> Result<(Step, f64), RoughError> {
        let law = self.law;
        let delta = elastic.delta;
        // At the I model's solution every contact meets δ_I(a_k) = δ_k − D̃_k: its
        // effective interference is δ_I(a_k), so the yield check needs no sums.
        let yielded = self.summits.iter().zip(&elastic.radii).any(|(s, &a)| {
            if a <= 0.0 {
                return false;
            }
            let d = own_interference(law, a, s.radius);
            !below_table(resp.e_star, resp.hardness, d, s.radius)
                && resp.at(d, s.radius).a_plastic > 0.0
        });
        if !(yielded || always) {
            return Ok((elastic, 0.0));
        }
        let mut prob = Problem::new(self, images, delta, &elastic.radii)?;
        let mut rebuilds = 0;
        loop {
            let deltas = prob.deltas(delta);
            let n = prob.geo.n();
            let radius = prob.geo.radius.clone();
            let scale = deltas.iter().copied().fold(0.0, f64::max);
            if scale <= 0.0 {
                return Ok((elastic, 0.0));
            }
            let a_el: Vec<f64> = prob.geo.cand.iter().map(|&k| elastic.radii[k]).collect();
            let d_el = displacements(&prob, &deltas, &a_el, &vec![1.0; n]);
            let eff0: Vec<f64> = (0..n).map(|p| deltas[p] - d_el[p]).collect();
            let tol = self.params.kkt_tolerance.min(TIGHT) * scale;
            let answers = |eff: &[f64]| -> Vec<Answer> {
                (0..n)
                    .map(|p| answer(law, resp, eff[p], radius[p]))
                    .collect()
            };
            let fixed = |approach: f64, start: Vec<f64>| {
                let deltas = prob.deltas(approach);
                let out = anderson(
                    |eff| {
                        self.params.cancel.check()?;
                        let ans = answers(eff);
                        let a: Vec<f64> = ans.iter().map(|x| x.a).collect();
                        let s: Vec<f64> = ans.iter().map(|x| x.scale).collect();
                        let d = displacements(&prob, &deltas, &a, &s);
                        Ok((0..n).map(|p| deltas[p] - d[p]).collect())
                    },
                    start,
                    tol,
                )?;
                out.map_err(|res| -> RoughError {
                    NewtonError::NotConverged {
                        delta: approach,
                        residual: res / scale,
                        tolerance: tol / scale,
                        newton_steps: MAX_ITERATIONS,
                    }
                    .into()
                })
            };
            let (eff, iterations, residual) = fixed(delta, eff0)?;
            let ans = answers(&eff);
            let amax = ans.iter().map(|x| x.a).fold(0.0, f64::max);
            if amax > prob.geo.a_valid {
                // a capped contact outgrew the far-field model's range: build it again
                if rebuilds == REBUILDS {
                    return Err(crate::rough::FarFieldError::Bound {
                        bound: prob.geo.a_valid,
                        radius: amax,
                        attempts: REBUILDS,
                    }
                    .into());
                }
                rebuilds += 1;
                let cand = std::mem::take(&mut prob.geo.cand);
                prob.prepare(cand, self.params.far_field_bound_factor * amax, false)?;
                continue;
            }
            // dP/dδ by central differences of the fixed point (step FD_STEP·δ)
            let h = FD_STEP * delta;
            let total = |eff: &[f64]| answers(eff).iter().map(|x| x.force).sum::<f64>();
            let up = fixed(delta + h, eff.iter().map(|e| e + h).collect())?;
            let down = fixed(delta - h, eff.iter().map(|e| e - h).collect())?;
            let stiffness = (total(&up.0) - total(&down.0)) / (2.0 * h);
            let iterations = iterations + up.1 + down.1;
            let mut radii = vec![0.0; self.summits.len()];
            let (mut load, mut area, mut plastic, mut contacts) = (0.0, 0.0, 0.0, 0);
            let pi = std::f64::consts::PI;
            for p in 0..n {
                let x = ans[p];
                if x.a <= 0.0 {
                    continue;
                }
                radii[prob.geo.cand[p]] = x.a;
                load += x.force;
                area += pi * x.a * x.a;
                plastic += pi * x.a_plastic * x.a_plastic;
                contacts += 1;
            }
            let a0 = self.area();
            let mut validity = elastic.validity;
            validity.area_above_nominal = area > a0;
            let mut diagnostics = elastic.diagnostics.clone();
            diagnostics.newton_steps += iterations;
            let step = Step {
                delta,
                gap: self.top_to_mean() - delta,
                load,
                mean_pressure: load / a0,
                pressure_ratio: load / a0 / law.e_star(),
                area_fraction: area / a0,
                contacts,
                stiffness,
                kkt_residual: Some(residual / scale),
                iterations: elastic.iterations + iterations,
                radii,
                diagnostics,
                validity,
            };
            if !(step.load.is_finite() && step.stiffness.is_finite()) {
                return Err(RoughError::NonFinite("capped I model step"));
            }
            return Ok((step, plastic / a0));
        }
    }
}
