//! The I model (physics.md §5, paper §4.2): it minimises over a ≥ 0 (P22)
//!
//! ```text
//! U_E = c Σ_j Q_j [ Σ_{l≠j} G_l(r_lj) + s_j − 2δ_j ],  c = −4α/3 = 2E*₁/3,
//! Q_j = χ(a_j)a_j³/R_j,  s_j = (a_j²/R_j)(ζ(a_j) + 1/5),
//! ```
//!
//! G_l(r) the displacement asperity l causes at distance r: the outside displacement of
//! physics.md §4 for r > a_l and, inside l's contact (r ≤ a_l, only where contacts
//! overlap), the parabola in r of eq. (P18) joined to it with value and slope at r = a_l
//! (`energy::inside_bracket`). The paper's (P19) uses the centre value a_l²ζ(a_l)/R_l
//! inside, which jumps by ≈ a_l²/(2R_l) at r = a_l: U_E then has no minimum where a
//! contact grows over another asperity's centre and the Newton iteration crawled
//! towards the jump; with G and ∂G/∂a continuous U_E is C¹. Its gradient,
//! scaled by the positive c·Q_k'(a_k), is
//!
//! ```text
//! F_k = D_k + s_k − 2δ_k + (Q_k s_k' + Σ_j Q_j ∂G_k(r_kj)/∂a_k) / Q_k',   D_k = Σ_{l≠k} G_l(r_lk)
//! ```
//!
//! (homogeneous solid: F_k = 2(a_k²/R_k − δ_k + D_k)). KKT: F_k = 0 where a_k > 0 and
//! F_k(0⁺) ≥ 0 where a_k = 0. The solver is an active-set projected Newton method on F
//! (∂U_E/∂Q_k = c F_k, so F is the gradient in Q = χa³/R, where U_E is convex for a
//! homogeneous solid): each Newton step backtracks on U_E itself (Armijo) and stays
//! inside a ≥ 0 and the far-field range a ≤ A; every asperity violating F_k(0⁺) ≥ 0 is
//! activated at once, at the radius of its single-asperity problem under the others'
//! displacement scaled down (½, ¼, …) until U_E decreases; below the KKT acceptance a
//! Newton round stops at the noise floor of F instead of crawling. A load path ([`RoughContact::curve`]) starts each step from the
//! previous radii extrapolated with da/dδ (the stiffness solve gives it). The residual
//! of both KKT conditions, relative to the largest interference, is returned with each
//! step and must be below [`Params::kkt_tolerance`](crate::rough::Params::kkt_tolerance) (1e-8). With periodic images, every source asperity is
//! repeated on a (2m+1)² block of cells (its own images included); isolated means plain
//! distances inside the sample.
//!
//! # Far field: the accelerated interaction sum
//! Source l acts on asperity k through G_l(r) = Q_l W(a_l, r)/π for r > a_l, with
//!
//! ```text
//! W(a, r) = [(2a² − r²) asin(a/r) + a√(r² − a²) + g(a, r)] / a³   (1/m).
//! ```
//!
//! Far away this is the point force on the layered solid, W → (4/3)/r + g/a³; nearer
//! the a-dependence matters (relative O((a/h₁)²) for the layered g, so the point force
//! alone misses 1e-6 accuracy wherever contacts are not tiny against the layer). For
//! r ≥ r_c > A ≥ a, W is a smooth function of x = 2(a/A)² − 1 (its singularities sit at
//! a = r and at |Im a| ~ 2h₁), so it is replaced by its Chebyshev interpolant at [`far_field::NB`]
//! points: W(a, r) ≈ Σ_j c_j(r) T_j(x) ([`far_field::NB`]). The coefficients c_j(r)·3r/4 are tabulated once
//! per law and bound A on a uniform ln r grid (4-point Lagrange in ln r). For each
//! pair of asperities the sum over its far images then collapses into NB numbers
//! N_kl,j = Σ_images c_j(r) (built once per solve, or once per load path in
//! [`RoughContact::curve`]: the far model is an explicit part of the prepared problem,
//! never kept between calls), and every evaluation of U_E, F or the Jacobian costs
//! O(NB) multiply–adds per pair instead of table lookups per image. Image pairs closer
//! than r_c (and all of them when the tolerance is 0) are summed exactly, image by
//! image, with `law.g`.
//!
//! Error control: when the model is built, (i) the interpolant in a with exact
//! coefficients is compared with the exact W and ∂W/∂a (from `law.g`) at every ln r
//! node and midpoint and 2·NB + 1 points of a ∈ [0, A], and (ii) the ln r
//! interpolation error of the coefficients at every midpoint is carried through the
//! basis to W and ∂W/∂a. r_c is the smallest grid distance beyond which both stay
//! below half the far-field tolerance in units of the point-force displacement: the
//! errors of G and ∂G/∂a are then below tol·(4/3)Q/(πr) and tol·(4/3)Q'/(πr). Default
//! tol = 3e-5 ([`Params::far_field_tolerance`](crate::rough::Params::far_field_tolerance)), half the accuracy of the
//! surrogate tables' g (~6e-5 of that scale, its `interp_error.g`), whose C¹
//! interpolant is smooth in a only to ~1e-5: on the shipped table at k_M = 200, tol
//! 1e-5 puts r_c at 70 µm (≈ 5A; 227 000 exact pairs per evaluation, 2.4× the time of
//! a 20-step curve), 3e-5 at 1.1A, and 1e-6 would push r_c out to the sample size. A is [`Params::far_field_bound_factor`](crate::rough::Params::far_field_bound_factor) (1.2) × the
//! largest N-model contact radius of the solve (interactions shrink contacts); a
//! minimum beyond A is solved again with a larger A.

pub(crate) mod capped;
pub(crate) mod energy;
pub mod far_field;
#[cfg(feature = "spectral")]
pub(crate) mod far_grid;
pub(crate) mod images;
pub(crate) mod krylov;
pub(crate) mod lu;
#[cfg(feature = "spectral")]
pub(crate) mod near;
pub(crate) mod newton;
pub(crate) mod pair_sums;
pub(crate) mod path;
#[cfg(all(test, feature = "spectral"))]
mod scale_tests;
pub(crate) mod uniform;

use std::time::Instant;

use energy::{Energy, State};
use far_field::FarModel;
use images::{Prepared, Sums};
use newton::{Newton, Search};
use uniform::ZeroMean;

use super::{
    Diagnostics, FarFieldError, FarFieldInfo, Images, NewtonError, RoughContact, RoughError, Step,
};
use crate::law::contact_radius;

/// Safety factor on the lift of the zero-mean images when choosing candidates.
const LIFT_MARGIN: f64 = 1.25;
/// Rounds of widening the candidates to the lift of the solution.
const LIFT_ROUNDS: usize = 4;

/// An I-model problem prepared for approaches up to the one it was built for: the
/// candidates (summits loaded at that approach), the far-field model and the image
/// geometry. Built per solve or per load path; nothing survives it.
pub(crate) struct Problem<'r, 'a> {
    rc: &'r RoughContact<'a>,
    images: Images,
    geo: Prepared,
    /// The uniform mode removed from the periodic image sums on an elastic base
    /// (physics.md §5; None: isolated, a rigid base, or not asked for by
    /// [`Params::zero_mean_images`](crate::rough::Params::zero_mean_images)).
    zero_mean: Option<ZeroMean>,
    /// How far below the rigid plane summits are candidates (m): 0 without the
    /// zero-mean correction.
    lift: f64,
    /// Far-field models built so far (rebuilds with a larger bound included).
    builds: usize,
}

impl<'r, 'a> Problem<'r, 'a> {
    /// The problem for approaches up to `delta` (m), with the far-field bound A from the
    /// N-model radii at `delta` and the warm start `warm` (m, per summit).
    pub fn new(
        rc: &'r RoughContact<'a>,
        images: Images,
        delta: f64,
        warm: &[f64],
    ) -> Result<Self, RoughError> {
        Self::with_lift(rc, images, delta, warm, None)
    }

    /// [`Problem::new`] with the candidates' lift (m) given (None: estimated from the
    /// N-model loads; only with the zero-mean images).
    fn with_lift(
        rc: &'r RoughContact<'a>,
        images: Images,
        delta: f64,
        warm: &[f64],
        lift: Option<f64>,
    ) -> Result<Self, RoughError> {
        let zero_mean = match images {
            Images::Periodic(m) if rc.params.zero_mean_images && rc.law.point_force().s0 > 0.0 => {
                // the correction is interpolated for offsets within one cell
                let (lx, ly) = rc.extent;
                if let Some(s) = rc
                    .summits
                    .iter()
                    .find(|s| !(0.0..=lx).contains(&s.x) || !(0.0..=ly).contains(&s.y))
                {
                    return Err(RoughError::LoadOutOfRange {
                        field: "summits",
                        value: if (0.0..=lx).contains(&s.x) { s.y } else { s.x },
                        reason: format!(
                            "periodic images on an elastic base need every summit inside the cell [0, {lx:e}] × [0, {ly:e}] m"
                        ),
                    });
                }
                if m == 0 {
                    return Err(RoughError::LoadOutOfRange {
                        field: "images",
                        value: 0.0,
                        reason: "periodic images on an elastic base need at least one image cell per side (m ≥ 1)".into(),
                    });
                }
                let zm = ZeroMean::build(rc.law, rc.extent, m);
                if zm.is_none() {
                    return Err(RoughError::NonFinite(
                        "I model: the periodic images' zero-mean correction (no interpolant met its tolerance)",
                    ));
                }
                zm
            }
            _ => None,
        };
        // With the mean displacement removed the surface between contacts rises (by at
        // most |V(0)| Σ Q, the correction's largest share), so summits below the rigid
        // plane may touch: they are candidates from the start (lift from the N-model
        // loads; [`Problem::solve`] widens it if the solution lifts more).
        let lift = zero_mean.as_ref().map_or(0.0, |zm| {
            if let Some(l) = lift {
                return l;
            }
            let q: f64 = (0..rc.summits.len())
                .filter_map(|k| {
                    let r = rc.summits[k].radius;
                    let a = contact_radius(rc.law, r, rc.interference(k, delta))?;
                    Some(rc.law.chi(a) * a.powi(3) / r)
                })
                .sum();
            LIFT_MARGIN * (-zm.v0).max(0.0) * q
        });
        let cand = rc.candidates(delta, lift);
        let mut amax: f64 = 0.0;
        for &k in &cand {
            let a = contact_radius(rc.law, rc.summits[k].radius, rc.interference(k, delta))
                .unwrap_or(0.0);
            amax = amax.max(a).max(warm.get(k).copied().unwrap_or(0.0));
        }
        let mut p = Problem {
            rc,
            images,
            zero_mean,
            lift,
            geo: Prepared::new(
                &rc.summits,
                rc.extent,
                images,
                Vec::new(),
                None,
                Sums::Dense,
                0.0,
                &rc.params.memory,
            )?,
            builds: 0,
        };
        p.prepare(cand, rc.params.far_field_bound_factor * amax, false)?;
        Ok(p)
    }

    /// (Re)builds the geometry of `cand` for contact radii up to `bound` (m); `exact`
    /// sums every image pair exactly.
    fn prepare(&mut self, cand: Vec<usize>, bound: f64, exact: bool) -> Result<(), RoughError> {
        let rc = self.rc;
        let tol = rc.params.far_field_tolerance;
        let sums = if cand.len() > rc.params.dense_pair_limit {
            Sums::Grid
        } else {
            Sums::Dense
        };
        // the grid's stencils reach a few cells beyond the sample's diagonal
        let reach =
            images::reach(self.images, rc.extent) * if sums == Sums::Grid { 1.25 } else { 1.0 };
        let far = if exact || tol.is_nan() || tol <= 0.0 || bound.is_nan() || bound <= 0.0 {
            None
        } else {
            self.builds += 1;
            FarModel::build(rc.law, bound, reach, tol, rc.params.g_difference_step)
        };
        self.geo = Prepared::new(
            &rc.summits,
            rc.extent,
            self.images,
            cand,
            far,
            sums,
            tol,
            &rc.params.memory,
        )?;
        self.geo.a_valid = self.geo.a_valid.min(self.radius_cap());
        if self.zero_mean.is_some() {
            self.geo.rows_from = f64::NEG_INFINITY;
        }
        Ok(())
    }

    /// The largest contact radius the model may reach (m): half the cell with the
    /// zero-mean periodic images (beyond it contacts overlap their own images and the
    /// energy, its pair terms point values of each contact's field, has no minimum);
    /// unbounded otherwise.
    fn radius_cap(&self) -> f64 {
        if self.zero_mean.is_some() {
            0.5 * self.rc.extent.0.min(self.rc.extent.1)
        } else {
            f64::INFINITY
        }
    }

    /// The interferences δ_k = δ − (z_M − z_k) of the candidates at approach δ (m):
    /// positive but for candidates below the rigid plane within the lift.
    fn deltas(&self, delta: f64) -> Vec<f64> {
        self.geo
            .cand
            .iter()
            .map(|&k| self.rc.signed_interference(k, delta))
            .collect()
    }

    /// The energy of approach δ on this geometry.
    fn energy<'p>(&'p self, deltas: &'p [f64]) -> Energy<'p> {
        Energy {
            law: self.rc.law,
            geo: &self.geo,
            zero_mean: self.zero_mean.as_ref(),
            deltas,
            h_g: self.rc.params.g_difference_step,
            h_jac: self.rc.params.jacobian_difference_step,
            source_scale: None,
        }
    }

    /// Solves approach δ (m) from `warm` (per summit, m), preparing again (larger bound
    /// A, finally exact sums) while a contact radius leaves the far-field model's range:
    /// the step and da_k/dδ of every summit (-).
    pub fn solve(&mut self, delta: f64, warm: &[f64]) -> Result<(Step, Vec<f64>), RoughError> {
        let mut warm = warm.to_vec();
        for _ in 0..LIFT_ROUNDS {
            let (s, rate) = self.solve_bounded(delta, &warm)?;
            let Some(zm) = &self.zero_mean else {
                return Ok((s, rate));
            };
            // Did the solution lift the surface further than the candidates allow?
            let rc = self.rc;
            let q: f64 = s
                .radii
                .iter()
                .zip(&rc.summits)
                .filter(|(a, _)| **a > 0.0)
                .map(|(&a, sm)| rc.law.chi(a) * a.powi(3) / sm.radius)
                .sum();
            let lift = (-zm.v0).max(0.0) * q;
            let mut is_cand = vec![false; rc.summits.len()];
            self.geo.cand.iter().for_each(|&k| is_cand[k] = true);
            let wanted = rc.candidates(delta, lift);
            if wanted.iter().all(|&k| is_cand[k]) {
                return Ok((s, rate));
            }
            self.lift = self.lift.max(LIFT_MARGIN * lift);
            let mut cand = rc.candidates(delta, self.lift);
            cand.extend(self.geo.cand.iter().copied());
            cand.sort_unstable();
            cand.dedup();
            let amax = s.radii.iter().copied().fold(0.0, f64::max);
            let bound = self
                .geo
                .far
                .as_ref()
                .map_or(0.0, |f| f.a_max)
                .max(rc.params.far_field_bound_factor * amax);
            self.prepare(cand, bound, false)?;
            warm = s.radii;
        }
        Err(RoughError::NonFinite(
            "I-model candidates (the lift of the zero-mean images kept growing)",
        ))
    }

    /// [`Problem::solve`] on the current candidates, preparing again while a contact
    /// radius leaves the far-field model's range.
    fn solve_bounded(&mut self, delta: f64, warm: &[f64]) -> Result<(Step, Vec<f64>), RoughError> {
        let t0 = Instant::now();
        let builds0 = self.builds;
        let mut diag = Diagnostics::default();
        let rebuilds = self.rc.params.far_field_rebuilds;
        for attempt in 0..=rebuilds {
            match self.solve_on(delta, warm, &mut diag)? {
                Ok((mut s, rate)) => {
                    s.diagnostics.far_field_builds = self.builds - builds0;
                    s.diagnostics.seconds = t0.elapsed().as_secs_f64();
                    return Ok((s, rate));
                }
                Err(amax) => {
                    let cap = self.radius_cap();
                    if amax > cap || self.geo.a_valid >= cap {
                        return Err(NewtonError::CoversCell { delta, cap }.into());
                    }
                    if attempt == rebuilds {
                        return Err(FarFieldError::Bound {
                            bound: self.geo.a_valid,
                            radius: amax,
                            attempts: rebuilds,
                        }
                        .into());
                    }
                    let cand = std::mem::take(&mut self.geo.cand);
                    let bound = self.rc.params.far_field_bound_factor * amax;
                    self.prepare(cand, bound, attempt + 1 == rebuilds)?;
                }
            }
        }
        Err(RoughError::NonFinite(
            "I-model contact radii (far-field bound)",
        ))
    }

    /// The far-field model in use, for the diagnostics.
    fn far_info(&self) -> Option<FarFieldInfo> {
        let g = &self.geo;
        let (grid_cells, near_radius, grid_error) =
            g.sums.grid().map_or(((0, 0), 0.0, 0.0), |gi| {
                (gi.cells, gi.near_radius, gi.worst)
            });
        g.far.as_ref().map(|f| FarFieldInfo {
            bound: f.a_max,
            cutoff: f.r_c,
            measured_error: f.worst + grid_error,
            exact_pairs: g.near.len() + g.n() * g.near_self.len(),
            modelled_pairs: g.far_pairs,
            grid_cells,
            near_radius,
        })
    }

    /// The active-set Newton solve of one approach on the prepared geometry (module
    /// docs): the step and its rates da/dδ, or the radius (m) that left the far-field
    /// range. Local indices with zero interference stay out of contact.
    fn solve_on(
        &self,
        delta: f64,
        warm: &[f64],
        diag: &mut Diagnostics,
    ) -> Result<Result<(Step, Vec<f64>), f64>, RoughError> {
        let (rc, geo) = (self.rc, &self.geo);
        let prm = &rc.params;
        let n = geo.n();
        let deltas = self.deltas(delta);
        let scale = deltas.iter().copied().fold(0.0, f64::max);
        let ns = rc.summits.len();
        if scale <= 0.0 {
            let zero = vec![0.0; ns];
            let s = rc.finish(delta, zero.clone(), 0.0, Some(0.0), diag.clone())?;
            return Ok(Ok((s, zero)));
        }
        let en = self.energy(&deltas);
        // Start: the previous radii where positive; asperities newly loaded (or out of
        // contact) enter through the KKT activation.
        let a: Vec<f64> = (0..n)
            .map(|p| {
                let w = warm.get(geo.cand[p]).copied().unwrap_or(0.0);
                let loaded = deltas[p] > 0.0 || self.zero_mean.is_some();
                if loaded && w > 0.0 { w } else { 0.0 }
            })
            .collect();
        let mut newton = Newton {
            energy: &en,
            params: prm,
            scale,
            diag,
            delta,
        };
        let first = newton.search(a, true)?;
        let search = if first.kkt < prm.kkt_tolerance || first.exceeded > 0.0 {
            first
        } else {
            // No KKT point reached from the warm start (e.g. stuck on the jump of G
            // where contacts overlap): start again from the N-model radii, on the
            // residual merit Σ F².
            newton.diag.restarts += 1;
            let a: Vec<f64> = (0..n)
                .map(|p| {
                    if deltas[p] > 0.0 {
                        contact_radius(rc.law, geo.radius[p], deltas[p])
                            .unwrap_or(0.0)
                            .min(geo.a_valid)
                    } else {
                        0.0
                    }
                })
                .collect();
            let again = newton.search(a, false)?;
            if again.kkt < first.kkt || again.exceeded > 0.0 {
                again
            } else {
                first
            }
        };
        let Search { a, kkt, exceeded } = search;
        if exceeded > 0.0 && (kkt.is_nan() || kkt >= prm.kkt_tolerance) {
            return Ok(Err(exceeded));
        }
        if kkt.is_nan() || kkt >= prm.kkt_tolerance {
            return Err(NewtonError::NotConverged {
                delta,
                residual: kkt,
                tolerance: prm.kkt_tolerance,
                newton_steps: newton.diag.newton_steps,
            }
            .into());
        }
        let amax = a.iter().copied().fold(0.0, f64::max);
        if amax > geo.a_valid {
            return Ok(Err(amax));
        }
        if amax <= 0.0 {
            // The most loaded summit would have F_k(0⁺) = −δ_k < 0 with no contact
            // anywhere: a "solution" without contact is numerical breakdown (found with
            // a 1e−100 m RMS surface and a 1e50 m approach), never a result.
            return Err(NewtonError::NoContact {
                delta,
                interference: scale,
                radius: geo.radius.iter().copied().fold(0.0, f64::max),
            }
            .into());
        }
        // Stiffness: J da/dδ = 2·1 on the active set; dP/dδ = (4/3)E* Σ Q'_k da_k/dδ.
        let act: Vec<usize> = (0..n).filter(|&p| a[p] > 0.0).collect();
        let dadd = newton.rates(&a, &act, delta)?;
        let mut st = State::default();
        en.eval(&a, &mut st);
        let e = rc.law.e_star();
        let mut stiffness = 0.0;
        for (ii, &p) in act.iter().enumerate() {
            stiffness += 4.0 / 3.0 * e * st.loc[p].dq * dadd[ii];
        }
        let mut radii = vec![0.0; ns];
        let mut rate = vec![0.0; ns];
        for p in 0..n {
            radii[geo.cand[p]] = a[p];
        }
        for (ii, &p) in act.iter().enumerate() {
            rate[geo.cand[p]] = dadd[ii];
        }
        let mut d = newton.diag.clone();
        d.far_field = self.far_info();
        let mut s = rc.finish(delta, radii, stiffness, Some(kkt), d)?;
        s.validity.overlapping_contacts = geo
            .near
            .iter()
            .filter(|&&(p, q, r)| a[p] > 0.0 && a[q] > 0.0 && r < a[p] + a[q])
            .count();
        Ok(Ok((s, rate)))
    }
}

/// The I-model complementary energy of one approach, ready to evaluate (for studies and
/// benchmarks of the solver's hot path): see [`RoughContact::interaction`].
pub struct Interaction<'r, 'a> {
    problem: Problem<'r, 'a>,
    deltas: Vec<f64>,
}

impl Interaction<'_, '_> {
    /// U_E of eq. (P22) (J) and its gradient ∂U_E/∂a_k (N) at the contact radii `radii`
    /// (m, one per summit, as [`Step::radii`]); `grad` (one per summit) receives the
    /// gradient, 0 for asperities out of contact or, without the zero-mean images, not loaded (their
    /// radii are ignored). ∂U_E/∂a_k = c·Q'_k·F_k with c = 2E*₁/3 (module docs).
    pub fn energy_gradient(&self, radii: &[f64], grad: &mut [f64]) -> Result<f64, RoughError> {
        let rc = self.problem.rc;
        let ns = rc.summits.len();
        for (field, len) in [("radii", radii.len()), ("grad", grad.len())] {
            if len != ns {
                return Err(RoughError::Length {
                    field,
                    expected: ns,
                    found: len,
                });
            }
        }
        let p = &self.problem.geo;
        let mut a = vec![0.0; p.n()];
        for (k, &s) in p.cand.iter().enumerate() {
            let v = radii[s];
            if !v.is_finite() || v < 0.0 {
                return Err(RoughError::LoadOutOfRange {
                    field: "radii",
                    value: v,
                    reason: "contact radii must be finite and ≥ 0 (m)".into(),
                });
            }
            if self.deltas[k] > 0.0 || self.problem.zero_mean.is_some() {
                a[k] = v;
            }
        }
        let en = self.problem.energy(&self.deltas);
        let mut st = State::default();
        en.eval(&a, &mut st);
        let c = 2.0 * rc.law.e_star() / 3.0;
        grad.iter_mut().for_each(|g| *g = 0.0);
        for k in 0..p.n() {
            if st.a[k] > 0.0 {
                grad[p.cand[k]] = c * st.loc[k].dq * st.f[k];
            }
        }
        let u = c * en.energy(&st);
        if !u.is_finite() {
            return Err(RoughError::NonFinite("I-model energy"));
        }
        Ok(u)
    }

    /// The far-field cut-off r_c (m): image pairs closer than this are summed exactly
    /// (∞ when the far field is disabled or not reachable).
    pub fn far_field_cutoff(&self) -> f64 {
        self.problem
            .geo
            .far
            .as_ref()
            .map_or(f64::INFINITY, |f| f.r_c)
    }

    /// Image pairs summed exactly and by the far-field model.
    pub fn image_pairs(&self) -> (usize, usize) {
        let g = &self.problem.geo;
        (g.near.len() + g.n() * g.near_self.len(), g.far_pairs)
    }

    /// Largest error of the far-field model measured at build time, relative to the
    /// point-force scale (0 when disabled).
    pub fn far_field_error(&self) -> f64 {
        self.problem.geo.far.as_ref().map_or(0.0, |f| f.worst)
    }
}

impl<'a> RoughContact<'a> {
    /// I model at approach δ (m), warm-started from `warm` (contact radii of every
    /// summit, m; empty for a cold start). Prepares its own geometry and far-field model.
    pub fn solve_interacting(
        &self,
        delta: f64,
        images: Images,
        warm: &[f64],
    ) -> Result<Step, RoughError> {
        self.check_delta(delta)?;
        Ok(Problem::new(self, images, delta, warm)?
            .solve(delta, warm)?
            .0)
    }

    /// The I-model energy U_E of approach δ (m) under `images`, prepared for contact
    /// radii up to [`Params::far_field_bound_factor`](crate::rough::Params::far_field_bound_factor) × the N-model ones, to evaluate
    /// with [`Interaction::energy_gradient`].
    pub fn interaction(
        &self,
        images: Images,
        delta: f64,
    ) -> Result<Interaction<'_, 'a>, RoughError> {
        self.check_delta(delta)?;
        // with the zero-mean images any summit may touch: all are candidates
        let mut problem = Problem::with_lift(self, images, delta, &[], Some(f64::INFINITY))?;
        if problem.zero_mean.is_some() {
            // the surface between contacts rises, so contacts may outgrow the N model's:
            // the far field prepared for radii up to the cap
            let cand = std::mem::take(&mut problem.geo.cand);
            problem.prepare(cand, problem.radius_cap(), false)?;
        }
        let deltas = problem.deltas(delta);
        Ok(Interaction { problem, deltas })
    }
}
