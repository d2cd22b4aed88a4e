//! Elastic–perfectly plastic contact: the contact pressure capped by a hardness H
//! (physics.md §6.3). The pressure p (Pa) minimises
//!
//! ```text
//!   f(p) = ½ pᵀ K p + pᵀ (c − z_e)      over the box 0 ≤ p ≤ H,
//! ```
//!
//! (K the influence operator, c the flat's offset, z_e = z − u_pl the heights lowered by
//! the plastic depth kept from earlier steps), whose gradient is the elastic gap
//! g = K p − z_e + c. The optimality (KKT) conditions are the contact conditions of the
//! capped surface: g ≥ 0 where p = 0, g = 0 where 0 < p < H, g ≤ 0 where p = H — there
//! the elastic overlap −g is taken by plastic flattening, added to u_pl after the step
//! (ContactMechanics' plastic system and Tamaas' saturated solver solve the same
//! problem).
//!
//! # Method
//! Under displacement control the capped preconditioned iteration (`capped.rs`:
//! Polonsky–Keer with Vollebregt's preconditioner, the working set widened to both
//! bounds; 1.0–1.3× the elastic step at 512²), and where it stalls MPRGP
//! ([`strata_runtime::bounded`]): Dostál's modified proportioning with reduced gradient
//! projections for box constraints, R-linearly convergent for a strictly convex
//! quadratic whatever fraction of the contact is plastic — no rescaling of p, so it does
//! not stall with the whole set just below H (the failure of a projected Polonsky–Keer
//! rescaling under force control, physics.md §9). ‖K‖ is bounded by the operator's
//! spectrum. Stopping: the largest violation of the KKT conditions (m) below
//! `tolerance × σ_z` on the exact gap. Force control: the same capped iteration with
//! the mean pressure held in it, the offset c its Lagrange multiplier
//! (`Capped::solve_load`: one iteration, 0.7–1.8× the elastic step's products),
//! started from the same step on the half grid (grids from 256², the plastic depth and
//! the last pressure on 2×2 blocks; 1.0–1.2× the elastic step's products at 512²); where
//! that stalls, primal–dual active-set steps on the elastic iteration, checked by
//! MPRGP, and if the sets do not settle the offset c found by a safeguarded secant
//! (Illinois) on the mean pressure, monotone in c, each evaluation warm-started from
//! the last (3–5.5× the elastic step).

use strata_runtime::bounded::{BoundedError, Mprgp, Outcome};
use strata_runtime::numerics::{Falsi, Tolerance, bracketed};

use crate::BemError;
use crate::capped::Capped;
use crate::maps::count_patches;
use crate::operator::Operator;

/// Exact gap recomputations from p, at least every this many iterations.
const REFRESH: usize = 50;

/// The bounded problem on one operator: g = K p − z_e + c.
pub(crate) struct Bounded<'a> {
    pub op: &'a Operator,
    /// Include the periodic uniform mode (a rigid base's C₀).
    pub uniform: bool,
    /// Effective heights z_e = z − u_pl (m).
    pub z: &'a [f64],
    /// The hardness H (Pa).
    pub hardness: f64,
    /// Step length ᾱ of the projected gradient steps (Pa/m), ≤ 2/‖K‖.
    pub alpha: f64,
    /// Acceptance: largest KKT violation (m).
    pub tol: f64,
    pub max_iterations: usize,
    /// Checked before every product ([`crate::BemSolver::with_cancel`]).
    pub cancel: &'a strata_runtime::cancel::Cancel,
}

fn bem_error(e: BoundedError<BemError>) -> BemError {
    match e {
        BoundedError::NotConverged {
            iterations,
            violation,
            tolerance,
        } => BemError::NotConverged {
            iterations,
            error: violation,
            tolerance,
        },
        BoundedError::NonFinite(i) => BemError::NonFinite(i),
        BoundedError::Operator(e) => e,
        _ => BemError::NonFinite(0),
    }
}

impl Bounded<'_> {
    /// Solves the bounded problem at offset `c`, from `p` (projected into the box);
    /// `g` receives the exact elastic gap K p − z_e + c of the solution.
    pub fn solve(&self, c: f64, p: &mut [f64], g: &mut [f64]) -> Result<Outcome, BemError> {
        let b: Vec<f64> = self.z.iter().map(|z| z - c).collect();
        let mut work = self.op.work();
        let uniform = self.uniform;
        let mut apply = |x: &[f64], y: &mut [f64]| {
            self.cancel.check()?;
            self.op.apply(x, y, uniform, &mut work)
        };
        Mprgp {
            upper: self.hardness,
            alpha: self.alpha,
            tol: self.tol,
            max_iterations: self.max_iterations,
            refresh: REFRESH,
        }
        .solve(&mut apply, &b, p, g)
        .map_err(bem_error)
    }
}

/// Per-step plastic quantities of a solution (see [`PlasticPath::step`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlasticInfo {
    /// Fraction of the grid at p = H (the plastic area over A₀).
    pub plastic_area_fraction: f64,
    /// Grid points at p = H.
    pub plastic_points: usize,
    /// Largest accumulated plastic depth u_pl after the step (m).
    pub plastic_depth_max: f64,
    /// Mean accumulated plastic depth over the cell (m): the flattened volume over A₀.
    pub plastic_depth_mean: f64,
    /// Outer secant steps of a force-controlled step (0 under displacement control or
    /// when the active-set steps settled).
    pub offset_iterations: usize,
    /// Active-set steps (elastic solves with the plastic set fixed) before the bounded
    /// solve checked the result (force control only).
    pub active_set_steps: usize,
    /// Whether the bounded solver (MPRGP) finished the step: the capped preconditioned
    /// iteration (`capped.rs`) stalled, or force control's active-set steps ran.
    pub bounded_fallback: bool,
}

/// Contact patches and area of a pressure field.
pub(crate) fn contact_stats(p: &[f64], ny: usize, nx: usize, periodic: bool) -> (usize, usize) {
    let contact: Vec<bool> = p.iter().map(|&v| v > 0.0).collect();
    let points = contact.iter().filter(|&&c| c).count();
    (points, count_patches(&contact, ny, nx, periodic))
}

/// What the path reads of its [`crate::BemSolver`].
struct Parts<'a> {
    pub op: &'a Operator,
    pub z: &'a [f64],
    pub ny: usize,
    pub nx: usize,
    pub periodic: bool,
    /// Sides (m) along x and y.
    pub sides: [f64; 2],
    pub z_max: f64,
    pub z_mean: f64,
    pub z_rms: f64,
    pub c0: Option<f64>,
    pub e_star1: f64,
    pub area: f64,
    pub options: crate::BemOptions,
}

fn parts(s: &crate::BemSolver) -> Parts<'_> {
    let (z, [z_max, z_mean, z_rms]) = s.heights_and_stats();
    let (c0, options) = s.uniform_and_options();
    let (ny, nx) = s.shape();
    Parts {
        op: s.operator(),
        z,
        ny,
        nx,
        periodic: s.geometry().periodic,
        sides: [s.geometry().lx, s.geometry().ly],
        z_max,
        z_mean,
        z_rms,
        c0,
        e_star1: s.e_star1(),
        area: s.area(),
        options,
    }
}

/// Relative margin below the hardness within which a point counts as plastic
/// (p ≥ H(1 − margin)): the bounded solves meet their KKT tolerance, not p = H exactly,
/// where a flattened point is reloaded.
pub const PLASTIC_SHARE: f64 = 1e-6;

/// A load path of elastic–perfectly plastic contact on one [`crate::BemSolver`]: the
/// plastic depth u_pl accumulates from step to step, so a path may load and unload in
/// any order and unloading follows the flattened surface (physics.md §6.3).
#[derive(Clone)]
pub struct PlasticPath<'s> {
    solver: &'s crate::BemSolver,
    hardness: f64,
    alpha: f64,
    /// Accumulated plastic depth u_pl per grid point (m).
    depth: Vec<f64>,
    /// The last pressure (warm start), Pa.
    p: Vec<f64>,
    /// The last offset c (force control's first guess).
    c: Option<f64>,
    /// Force control by the load-held capped iteration first (`Capped::solve_load`);
    /// off, the active-set steps and the offset search alone (tests compare the two).
    pub(crate) load_iteration: bool,
    /// Force-controlled steps start from the half grid's step
    /// ([`Self::half_grid_start`]); off, from the last pressure (tests compare the two).
    pub(crate) half_grid: bool,
}

impl<'s> PlasticPath<'s> {
    /// A path with hardness `hardness` (Pa, > 0; `f64::INFINITY` is elastic) from the
    /// undeformed surface.
    pub fn new(solver: &'s crate::BemSolver, hardness: f64) -> Result<Self, BemError> {
        if hardness.is_nan() || hardness <= 0.0 {
            return Err(BemError::Load {
                what: "hardness",
                value: hardness,
                reason: "must be > 0 Pa".into(),
            });
        }
        let parts = parts(solver);
        let n = parts.ny * parts.nx;
        // ‖K‖ (a bound from the spectrum) with the uniform mode where a rigid base has one.
        let uniform = parts.periodic && parts.c0.is_some();
        let norm = parts.op.norm_bound(uniform);
        if !(norm.is_finite() && norm > 0.0) {
            return Err(BemError::NonFinite(0));
        }
        Ok(PlasticPath {
            solver,
            hardness,
            alpha: 1.0 / norm,
            depth: vec![0.0; n],
            p: vec![0.0; n],
            c: None,
            load_iteration: true,
            half_grid: true,
        })
    }

    /// The accumulated plastic depth u_pl (m), row-major like the heights.
    pub fn depth(&self) -> &[f64] {
        &self.depth
    }

    /// The tangent stiffness dP/dδ (N/m) of `solution`, this path's last step: the
    /// elastic contact (0 < p < H(1 − [`PLASTIC_SHARE`])) held fixed, the points at H
    /// flowing ([`crate::BemSolver::tangent`]).
    pub fn tangent(&self, solution: &mut crate::BemSolution) -> Result<crate::Tangent, BemError> {
        self.solver
            .tangent(solution, Some(self.hardness * (1.0 - PLASTIC_SHARE)))
    }

    /// The start of a force-controlled step: the same load with the same cap on the
    /// half grid ([`crate::BemSolver::half_grid`]: its heights, this path's plastic depth
    /// and last pressure on 2×2 blocks; solved to 1e−6 from its own half grid's start),
    /// injected on 2×2 blocks. Where there is no half grid or its step fails, the last
    /// pressure, or on a fresh path the elastic solver's coarse start. Its products are
    /// not counted in the step's. Measured (512², H = 0.05 GPa, 95 % of the contact at
    /// H): 78 → 53 products on a fresh path, 80 → 47 at 1.25× the load on the flattened
    /// surface (docs/performance.md).
    fn half_grid_start(&self, load: crate::BemLoad, control: crate::state::Control, p: &mut [f64]) {
        if let Some(coarse) = self.solver.half_grid().filter(|_| self.half_grid) {
            let step = PlasticPath::new(&coarse, self.hardness).and_then(|mut path| {
                path.load_iteration = self.load_iteration;
                path.depth = self.solver.restrict_half(&self.depth);
                path.p = self.solver.restrict_half(&self.p);
                path.step(load)
            });
            if let Ok((sol, _)) = step
                && let Some(pc) = sol.pressure.as_slice()
            {
                self.solver.inject_half(pc, p);
                return;
            }
        }
        if p.iter().all(|&v| v == 0.0) {
            self.solver.start_guess(control, p);
        }
    }

    /// Solves one load on the current (flattened) surface and keeps its plastic depth.
    pub fn step(
        &mut self,
        load: crate::BemLoad,
    ) -> Result<(crate::BemSolution, PlasticInfo), BemError> {
        use crate::state::Control;
        let parts = parts(self.solver);
        let control = self.solver.control_of(load)?;
        let n = parts.ny * parts.nx;
        // Without a cap the problem is the elastic solver's: its solution (the
        // preconditioned iteration). (Under force control a capped step needs no
        // elastic solve first: the load-held capped iteration is that iteration where
        // no pressure reaches H.)
        if !self.hardness.is_finite() {
            let e = self.solver.solve_from(load, Some(&self.p[..]))?;
            self.p = e.pressure.iter().copied().collect();
            self.c = None;
            let info = PlasticInfo {
                plastic_area_fraction: 0.0,
                plastic_points: 0,
                plastic_depth_max: 0.0,
                plastic_depth_mean: 0.0,
                offset_iterations: 0,
                active_set_steps: 0,
                bounded_fallback: false,
            };
            let mut e = e;
            e.plastic_depth = Some(ndarray::Array2::zeros((parts.ny, parts.nx)));
            return Ok((e, info));
        }
        let z_e: Vec<f64> = parts
            .z
            .iter()
            .zip(&self.depth)
            .map(|(z, d)| z - d)
            .collect();
        let mut bounded = Bounded {
            op: parts.op,
            uniform: false,
            z: &z_e,
            hardness: self.hardness,
            alpha: self.alpha,
            tol: parts.options.tolerance * parts.z_rms,
            max_iterations: parts.options.max_iterations,
            cancel: self.solver.cancel_token(),
        };
        let mut capped = Capped {
            op: parts.op,
            minv: self.solver.preconditioner(),
            uniform: false,
            z: &z_e,
            hardness: self.hardness,
            tol: bounded.tol,
            max_iterations: parts.options.max_iterations,
            cancel: self.solver.cancel_token(),
        };
        let mut g = vec![0.0; n];
        let mut p = self.p.clone();
        let fallback;
        let (c, out, offset_iterations, set_steps) = match control {
            Control::Offset { c, uniform } => {
                // The capped preconditioned iteration from the last step's pressure or
                // the elastic solver's cold (coarse-to-fine) start.
                if p.iter().all(|&v| v == 0.0) {
                    self.solver.start_guess(control, &mut p);
                }
                bounded.uniform = uniform;
                capped.uniform = uniform;
                let (out, bounded_ran) = solve_at(&bounded, &capped, c, &mut p, &mut g)?;
                fallback = bounded_ran;
                (c, out, 0, 0)
            }
            Control::Pressure(target) => {
                if target >= self.hardness {
                    return Err(BemError::Load {
                        what: "mean pressure",
                        value: target,
                        reason: format!(
                            "is at or above the hardness {:e} Pa: a capped pressure cannot carry it",
                            self.hardness
                        ),
                    });
                }
                // The capped preconditioned iteration with the load held in it (the
                // offset its Lagrange multiplier, `Capped::solve_load`), from the last
                // step's pressure or the capped step on the half grid.
                self.half_grid_start(load, control, &mut p);
                let (o, c_load) = if self.load_iteration {
                    capped.solve_load(target, &mut p, &mut g)?
                } else {
                    let none = crate::capped::CappedOutcome {
                        converged: false,
                        iterations: 0,
                        products: 0,
                        violation: f64::INFINITY,
                    };
                    (none, f64::NAN)
                };
                if o.converged {
                    let out = Outcome {
                        iterations: o.iterations,
                        products: o.products,
                        violation: o.violation,
                    };
                    fallback = false;
                    (c_load, out, 0, 0)
                } else {
                    // Where it stalls: active-set steps on the elastic iteration (fast); the
                    // bounded solve then checks (and, if the sets did not settle, finishes)
                    // the result.
                    let (settled, set_steps, set_products) =
                        self.active_set(&parts, &z_e, control, &mut p)?;
                    let mut ran_bounded = true;
                    let (c, mut out, offset_iterations) = match settled {
                        Some(c) => {
                            // the check at the settled offset: the capped preconditioned
                            // iteration from the active-set pressure (MPRGP only if it stalls;
                            // force control leaves the uniform mode out, as both start)
                            let (o, ran) = solve_at(&bounded, &capped, c, &mut p, &mut g)?;
                            ran_bounded = ran;
                            (c, o, 0)
                        }
                        None => self.force_control(&bounded, &capped, target, &mut p, &mut g)?,
                    };
                    out.iterations += set_steps + o.iterations;
                    out.products += set_products + o.products;
                    fallback = ran_bounded;
                    (c, out, offset_iterations, set_steps)
                }
            }
        };
        // at the cap within the solve's tolerance: reloading to a state reached before
        // meets the cap from below, to the solve's accuracy, at the points that flowed
        let h = self.hardness * (1.0 - PLASTIC_SHARE);
        let mut plastic_points = 0;
        let mut gap_sum = 0.0;
        for i in 0..n {
            if p[i] >= h {
                plastic_points += 1;
                // the elastic overlap is taken by flattening: the actual gap is 0
                self.depth[i] += (-g[i]).max(0.0);
            } else {
                gap_sum += g[i].max(0.0);
            }
        }
        let n2 = n as f64;
        let mean_pressure = p.iter().sum::<f64>() / n2;
        let (contact_points, patches) = contact_stats(&p, parts.ny, parts.nx, parts.periodic);
        let rigid_periodic = parts.periodic && parts.c0.is_some();
        let w = if rigid_periodic {
            parts.c0.unwrap_or(0.0) * mean_pressure
        } else {
            0.0
        };
        // δ = z_M − c in the frame of the undeformed surface (plus the uniform mode a
        // force-controlled solve leaves out on a rigid base).
        let approach = parts.z_max - c + if bounded.uniform { 0.0 } else { w };
        let mean_gap = gap_sum / n2;
        let displacement = crate::maps::deflection(&g, &z_e, c, parts.periodic.then_some(w));
        let solution = crate::BemSolution {
            load,
            mean_pressure,
            pressure_ratio: mean_pressure / parts.e_star1,
            area_fraction: contact_points as f64 / n2,
            contact_points,
            patches,
            mean_gap,
            approach,
            separation: parts.z_max - parts.z_mean - approach,
            total_load: mean_pressure * parts.area,
            mean_deflection: if parts.periodic { w } else { f64::NAN },
            iterations: out.iterations,
            products: out.products,
            error: out.violation / parts.z_rms,
            pressure: ndarray::Array2::from_shape_vec((parts.ny, parts.nx), p.clone())
                .unwrap_or_default(),
            gap: ndarray::Array2::from_shape_vec(
                (parts.ny, parts.nx),
                g.iter().map(|v| v.max(0.0)).collect(),
            )
            .unwrap_or_default(),
            displacement: ndarray::Array2::from_shape_vec((parts.ny, parts.nx), displacement)
                .unwrap_or_default(),
            plastic_depth: Some(
                ndarray::Array2::from_shape_vec((parts.ny, parts.nx), self.depth.clone())
                    .unwrap_or_default(),
            ),
            sides: parts.sides,
            periodic: parts.periodic,
            offset: c,
        };
        let info = PlasticInfo {
            plastic_area_fraction: plastic_points as f64 / n2,
            plastic_points,
            plastic_depth_max: self.depth.iter().fold(0.0, |m: f64, d| m.max(*d)),
            plastic_depth_mean: self.depth.iter().sum::<f64>() / n2,
            offset_iterations,
            active_set_steps: set_steps,
            bounded_fallback: fallback,
        };
        self.p = p;
        self.c = Some(c);
        Ok((solution, info))
    }

    /// Primal–dual active-set steps: with the plastic set P fixed (p = H there) the
    /// rest is an elastic contact problem on the heights z_e − K(H 1_P), P kept out of
    /// contact (its heights lowered far below the surface), solved by the elastic
    /// (preconditioned) iteration; then P gains the points whose pressure exceeds H and
    /// loses those whose gap opens. Stops when P repeats (every KKT condition of the box
    /// problem then holds) and returns the offset c; `None` after 30 steps (the bounded
    /// solve takes over from the last pressure). Under force control the elastic solve
    /// carries the target less P's share.
    fn active_set(
        &self,
        parts: &Parts,
        z_e: &[f64],
        control: crate::state::Control,
        p: &mut [f64],
    ) -> Result<(Option<f64>, usize, usize), BemError> {
        use crate::state::Control;
        let n = p.len();
        let (mut steps, mut products) = (0, 0);
        let h = self.hardness;
        if !h.is_finite() {
            return Ok((None, 0, 0));
        }
        let (zmin, zmax) = z_e
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| {
                (a.min(*z), b.max(*z))
            });
        let low = zmin - 1e3 * (zmax - zmin).max(parts.z_rms);
        let uniform = matches!(control, Control::Offset { uniform: true, .. });
        let mut plastic: Vec<bool> = p.iter().map(|&v| v >= h).collect();
        let mut load = vec![0.0; n];
        let mut q_h = vec![0.0; n];
        let mut work = parts.op.work();
        for _ in 0..30 {
            steps += 1;
            for i in 0..n {
                load[i] = if plastic[i] { h } else { 0.0 };
            }
            parts.op.apply(&load, &mut q_h, uniform, &mut work)?;
            products += 1;
            let zp: Vec<f64> = (0..n)
                .map(|i| if plastic[i] { low } else { z_e[i] - q_h[i] })
                .collect();
            let inner = match control {
                Control::Offset { .. } => control,
                Control::Pressure(t) => {
                    let share = h * plastic.iter().filter(|&&b| b).count() as f64 / n as f64;
                    if t - share <= 0.0 {
                        return Ok((None, steps, products));
                    }
                    Control::Pressure(t - share)
                }
            };
            let mut q: Vec<f64> = (0..n)
                .map(|i| if plastic[i] { 0.0 } else { p[i].min(h) })
                .collect();
            let (c, gap, k) = self.solver.solve_on(&zp, inner, &mut q)?;
            products += k;
            let mut next = plastic.clone();
            for i in 0..n {
                // the true gap: on P the lowered height is replaced by z_e − q_H
                let g = if plastic[i] {
                    gap[i] + low - (z_e[i] - q_h[i])
                } else {
                    gap[i]
                };
                next[i] = if plastic[i] { g <= 0.0 } else { q[i] > h };
                p[i] = if plastic[i] { h } else { q[i] };
            }
            if next == plastic {
                return Ok((Some(c), steps, products));
            }
            plastic = next;
        }
        Ok((None, steps, products))
    }

    /// Force control: the offset c with mean p(c) = `target` (mean p falls as c grows)
    /// to 1e-12 relative, from the last offset (or the elastic solution's) and a second
    /// point from p̄ ∝ (z_M − c)^{3/2}: secant steps through the last two points until
    /// they bracket the root, then the Illinois regula falsi of [`bracketed`] on the
    /// bracket from the last secant point. p and g hold the solution at the offset
    /// returned (the last one solved).
    fn force_control(
        &self,
        bounded: &Bounded,
        capped: &Capped,
        target: f64,
        p: &mut [f64],
        g: &mut [f64],
    ) -> Result<(f64, Outcome, usize), BemError> {
        /// Solves of a force-controlled step before it stops where it is.
        const MAX_SOLVES: usize = 102;
        let parts = parts(self.solver);
        let n2 = (parts.ny * parts.nx) as f64;
        let mut total = Outcome {
            iterations: 0,
            products: 0,
            violation: 0.0,
        };
        let evals = std::cell::Cell::new(0usize);
        let solved = std::cell::Cell::new(f64::NAN);
        let mut eval = |c: f64| -> Result<(f64, Option<f64>), BemError> {
            let (o, _) = solve_at(bounded, capped, c, p, g)?;
            total.iterations += o.iterations;
            total.products += o.products;
            total.violation = o.violation;
            evals.set(evals.get() + 1);
            solved.set(c);
            Ok((p.iter().sum::<f64>() / n2 - target, None))
        };
        let zmax = bounded.z.iter().fold(f64::MIN, |m, z| m.max(*z));
        // First guess: the elastic solution at the same mean pressure (the
        // preconditioned Polonsky–Keer solve, cheap) — its offset c = ḡ + z̄ (periodic,
        // the uniform mode excluded as here) or z_M − δ (non-periodic) — unless the
        // path has an offset already.
        let c0 = match self.c {
            Some(c) => c,
            None => {
                let e = self.solver.solve(crate::BemLoad::MeanPressure(target))?;
                if parts.periodic {
                    e.mean_gap + parts.z_mean
                } else {
                    parts.z_max - e.approach
                }
            }
        };
        let done = |f: f64| f.abs() <= 1e-12 * target;
        let f0 = eval(c0)?.0;
        if done(f0) {
            return Ok((c0, total, evals.get()));
        }
        // Second point: p̄ ∝ (z_M − c)^{3/2} through the first.
        let depth0 = (zmax - c0).max(parts.z_rms * 1e-3);
        let ratio = (target / (f0 + target).max(1e-3 * target)).powf(2.0 / 3.0);
        let c1 = zmax - depth0 * ratio;
        let mut pts = [(c0, f0), (c1, eval(c1)?.0)];
        // f > 0: too much pressure, the root at a larger offset
        let secant = |[(ca, fa), (cb, fb)]: [(f64, f64); 2]| {
            let next = cb - fb * (cb - ca) / (fb - fa);
            if next.is_finite() {
                next
            } else {
                // no slope: step by σ_z towards more or less load
                cb + if fb > 0.0 { parts.z_rms } else { -parts.z_rms }
            }
        };
        // the bracket's ends: on each side the point nearest the root (smallest |f|)
        type End = Option<(f64, f64)>;
        fn keep(ends: &mut (End, End), (c, f): (f64, f64)) {
            let side = if f < 0.0 { &mut ends.0 } else { &mut ends.1 };
            if side.is_none_or(|(_, fs)| f.abs() < fs.abs()) {
                *side = Some((c, f));
            }
        }
        let mut ends: (End, End) = (None, None);
        keep(&mut ends, pts[0]);
        keep(&mut ends, pts[1]);
        while ends.0.is_none() || ends.1.is_none() {
            let (c, f) = pts[1];
            if !f.is_finite() {
                return Err(BemError::NonFinite(total.iterations));
            }
            if done(f) || evals.get() >= MAX_SOLVES {
                return Ok((c, total, evals.get()));
            }
            let c = secant(pts);
            pts = [pts[1], (c, eval(c)?.0)];
            keep(&mut ends, pts[1]);
        }
        let (c, f) = pts[1];
        if done(f) {
            return Ok((c, total, evals.get()));
        }
        let (Some(neg), Some(pos)) = ends else {
            return Err(BemError::NonFinite(total.iterations));
        };
        let tol = Tolerance {
            f: 1e-12 * target,
            step: 0.0,
            width: 1e-15,
            width_abs: 1e-15,
            falsi: Falsi::Illinois,
        };
        let left = MAX_SOLVES.saturating_sub(evals.get());
        let root = bracketed(&mut eval, neg, pos, Some(secant(pts)), tol, left)?;
        if root.f.is_nan() {
            return Err(BemError::NonFinite(total.iterations));
        }
        Ok((solved.get(), total, evals.get()))
    }
}

/// The capped problem at offset `c`: the capped preconditioned iteration
/// ([`crate::capped`]), and where it stalls the bounded solver (MPRGP) from its last
/// state (then `true`). Both accept on the same KKT violation of the exact gap.
fn solve_at(
    bounded: &Bounded,
    capped: &Capped,
    c: f64,
    p: &mut [f64],
    g: &mut [f64],
) -> Result<(Outcome, bool), BemError> {
    let (mut iterations, mut products) = (0, 0);
    if capped.hardness.is_finite() {
        let o = capped.solve(c, p, g)?;
        if o.converged {
            let out = Outcome {
                iterations: o.iterations,
                products: o.products,
                violation: o.violation,
            };
            return Ok((out, false));
        }
        (iterations, products) = (o.iterations, o.products);
    }
    let mut out = bounded.solve(c, p, g)?;
    out.iterations += iterations;
    out.products += products;
    Ok((out, true))
}

impl crate::BemSolver {
    /// Elastic–perfectly plastic contact along `loads` (in any order: loading and
    /// unloading), hardness `hardness` (Pa): each step's solution and its plastic
    /// quantities ([`PlasticPath`]).
    pub fn solve_plastic_curve(
        &self,
        loads: &[crate::BemLoad],
        hardness: f64,
    ) -> Result<Vec<(crate::BemSolution, PlasticInfo)>, BemError> {
        let mut path = PlasticPath::new(self, hardness)?;
        loads.iter().map(|&l| path.step(l)).collect()
    }
}
