//! Plasticity (`[plasticity]`): an elastic–perfectly plastic surface of hardness H
//! (Pa), the contact pressure capped at H. A solver variant, chosen once when the
//! load-path driver is built — never an `if plastic` inside its loop:
//!
//! - **BEM** ([`bem_response`]): the capped response ([`Capped`]: `strata_bem`'s
//!   `PlasticPath`, capped preconditioned CG with MPRGP where it stalls, the plastic
//!   depth kept along the path, physics.md §6.3) in place of the elastic one
//!   ([`Elastic`]);
//! - **N and I models** ([`CappedTips`]): each summit a capped paraboloid whose response
//!   P = P_c F(δ/δ_c, a_c/h₁), a = a_c G(…) is tabulated from ring solves
//!   (physics.md §9), in place of the elastic tips ([`crate::engine::elastic::ElasticTips`]).
//!
//! Its records are [`PlasticInfo`] per step and a [`PlasticitySummary`].

use std::time::Instant;

use crate::error::{Context, EngineError, Result};
use strata_bem::{BemLoad, BemSolution, BemSolver, PlasticPath, Tangent};
use strata_runtime::Solid;
use strata_runtime::law::Homogeneous;
use strata_runtime::numerics::{Falsi, Tolerance, bracketed};
use strata_runtime::rough::{Model, RoughContact, RoughError, Step};
use strata_runtime::summits::find_summits;
use strata_runtime::surface::Surface;
use thiserror::Error;

use super::observer::{AsperityPath, StepObserver, after_path};
use crate::engine::elastic::{AsperityCurve, asperity_summary, solve_elastic};
use crate::scene::{LoadSpec, Scene};
use crate::setup::{
    EngineOptions, Observer, law_for, log, model_short, solver_params, surface_report,
};
use crate::solution::{
    BemPlasticInfo, PlasticInfo, PlasticUnits, PlasticitySummary, SceneSolution,
};

/// A summit loaded past the capped asperity's response table's lower end
/// (x = δ/δ_c ≥ `strata_runtime::rough::plastic::ELASTIC_X`) that would yield at a
/// contact radius a_c = πHR/(2E*) outside the table's range of a_c/h₁: the hardness is
/// too high for the stack's top layer to be treated by the capped asperity models.
#[derive(Debug, Clone, PartialEq, Error)]
#[error(
    "plasticity: summit {summit} (radius {radius:e} m) is loaded past δ = {x:e}·δ_c (δ_c = (πH/2E*)²R, \
     the capped asperity's table's lower end) and would yield at a contact radius \
     a_c = πHR/(2E*) of {y:.3e} h1, outside the table (a_c/h1 in [{lo:e}, {hi:e}]): the hardness is \
     too high for this stack's top layer to be treated this way at this load; use \
     model.kind = \"bem\"",
    x = strata_runtime::rough::plastic::ELASTIC_X,
    lo = strata_runtime::rough::plastic::asperity::RESPONSE_Y.0,
    hi = strata_runtime::rough::plastic::asperity::RESPONSE_Y.1
)]
pub struct UncoveredSummit {
    /// The summit's index.
    pub summit: usize,
    /// Its radius of curvature R (m).
    pub radius: f64,
    /// a_c/h₁ of its yield.
    pub y: f64,
}

/// How the BEM's surface responds to a load step: elastic, or capped at the hardness.
pub trait BemResponse {
    /// Solves one load step from the state the previous one left (`warm`: the previous
    /// step's pressure, a start for the elastic solve, whose buffer it becomes); with the
    /// step's plastic records when capped.
    fn step(
        &mut self,
        load: BemLoad,
        warm: Option<Vec<f64>>,
    ) -> Result<(BemSolution, Option<PlasticInfo>)>;
    /// The tangent stiffness dP/dδ of `step` (the last step's solution, whose pressure
    /// map the solve borrows as a buffer and gives back bit for bit) on its contact set
    /// ([`BemSolver::tangent`]; capped: the points below the hardness).
    fn tangent(&mut self, step: &mut BemSolution) -> Result<Tangent>;
    /// The gap and displacement maps of a solution of [`Self::step`] that left them out
    /// (the elastic response solves for the pressure alone, so that a step and its
    /// tangent hold one pressure map each; the maps are formed from it when they are
    /// handed on, with the same values).
    fn complete(&self, solution: &mut BemSolution) -> Result<()>;
}

/// The elastic response: every step solved afresh, warm-started, for its pressure map
/// alone ([`BemSolver::solve_pressure_only`]; [`BemResponse::complete`] adds the gap and
/// displacement maps).
pub struct Elastic<'s>(pub &'s BemSolver);

impl BemResponse for Elastic<'_> {
    fn step(
        &mut self,
        load: BemLoad,
        warm: Option<Vec<f64>>,
    ) -> Result<(BemSolution, Option<PlasticInfo>)> {
        let sol = match warm {
            Some(p) => self.0.solve_pressure_only_in(load, p)?,
            None => self.0.solve_pressure_only(load, None)?,
        };
        Ok((sol, None))
    }

    fn tangent(&mut self, step: &mut BemSolution) -> Result<Tangent> {
        Ok(self.0.tangent(step, None)?)
    }

    fn complete(&self, solution: &mut BemSolution) -> Result<()> {
        Ok(self.0.complete_maps(solution)?)
    }
}

/// The capped response: the pressure capped at H, the plastic depth of the points that
/// flowed kept for the rest of the path (the state advances by [`BemResponse::step`]).
pub struct Capped<'s> {
    path: PlasticPath<'s>,
}

impl BemResponse for Capped<'_> {
    fn step(
        &mut self,
        load: BemLoad,
        _warm: Option<Vec<f64>>,
    ) -> Result<(BemSolution, Option<PlasticInfo>)> {
        let (sol, info) = self.path.step(load)?;
        let record = PlasticInfo {
            plastic_area_fraction: info.plastic_area_fraction,
            bem: Some(BemPlasticInfo {
                plastic_points: info.plastic_points,
                plastic_depth_max: info.plastic_depth_max,
                plastic_depth_mean: info.plastic_depth_mean,
                kkt_bounded: sol.error,
                bounded_iterations: sol.iterations,
                offset_iterations: info.offset_iterations,
                active_set_steps: info.active_set_steps,
                bounded_fallback: info.bounded_fallback,
            }),
        };
        Ok((sol, Some(record)))
    }

    fn tangent(&mut self, step: &mut BemSolution) -> Result<Tangent> {
        Ok(self.path.tangent(step)?)
    }

    fn complete(&self, _solution: &mut BemSolution) -> Result<()> {
        // a capped step returns its maps (they are the state the path advances by)
        Ok(())
    }
}

/// The BEM's response of `scene` on `solver`: capped when the scene has
/// `[plasticity]`, else elastic. Chosen once, before the first step.
pub fn bem_response<'s>(
    scene: &Scene,
    solver: &'s BemSolver,
    obs: &dyn Observer,
) -> Result<Box<dyn BemResponse + 's>> {
    Ok(match scene.plasticity {
        Some(pl) => {
            log!(
                obs,
                "plasticity: pressure capped by the hardness H = {:e} Pa (capped preconditioned CG, MPRGP where it stalls; the plastic depth is kept along the path)",
                pl.hardness
            );
            Box::new(Capped {
                path: PlasticPath::new(solver, pl.hardness).context("plasticity")?,
            })
        }
        None => Box::new(Elastic(solver)),
    })
}

/// curve.json's `plasticity` entry of a capped BEM solve of hardness `hardness` (Pa).
pub fn bem_summary(hardness: f64) -> PlasticitySummary {
    PlasticitySummary {
        hardness,
        note: "elastic–perfectly plastic surface (physics.md §6.3): 0 ≤ p ≤ H; points at p = H flow, \
                     their overlap kept as plastic depth for the rest of the path; stiffness = dP/dδ for an \
                     increase of δ from each step's state (the tangent on the elastic contact, p < H)",
        units: Some(PlasticUnits {
            plastic_area_fraction: "1",
            plastic_depth_max: "m",
            plastic_depth_mean: "m (flattened volume / A0)",
            kkt_bounded: "largest KKT violation of the bounded problem / RMS height",
        }),
    }
}

/// The N and I models with capped tips of hardness H (Pa).
pub struct CappedTips {
    /// H (Pa).
    pub hardness: f64,
}

impl AsperityCurve for CappedTips {
    fn solve(
        &self,
        scene: &Scene,
        surface: Surface,
        opts: &EngineOptions,
        obs: &dyn Observer,
        model: Model,
        observers: &mut [Box<dyn StepObserver + '_>],
    ) -> Result<SceneSolution> {
        solve_capped(scene, surface, opts, obs, self.hardness, model, observers)
    }
}

/// The N and I models with capped tips (`[plasticity]`, physics.md §9): the capped
/// asperity's response table for the scene's stack and hardness (ring solves, built
/// here), then every summit through it at each approach (or at the approach of each
/// mean pressure, by Illinois regula falsi on δ, the load being monotone in it); the I model's
/// summits interact through the far field of their actual loads
/// (`RoughContact::solve_interacting_plastic`). When no summit reaches the response
/// table's range on the path, the elastic tips' solution exactly.
/// How far beyond the largest summit height (a factor on δ, 2⁶⁰) a mean pressure's
/// approach is sought before it is out of reach.
const REACH: f64 = (1u64 << 60) as f64;

#[allow(clippy::too_many_arguments)]
fn solve_capped(
    scene: &Scene,
    surface: Surface,
    opts: &EngineOptions,
    obs: &dyn Observer,
    hardness: f64,
    model: Model,
    observers: &mut [Box<dyn StepObserver + '_>],
) -> Result<SceneSolution> {
    let e_star = scene.bodies.contact_modulus();
    // Summits that stay below the response table's range (x = δ/δ_c < ELASTIC_X) on the
    // whole path are elastic: when every summit does, the capped model is the elastic
    // model exactly and no table is built (H → ∞ on any stack).
    let approaches = {
        let hom = Homogeneous { e_star };
        let rc = RoughContact::from_surface(&hom, &surface)?;
        scene
            .load
            .approaches(rc.top_to_mean(), f64::INFINITY)
            .context("load")?
            .map(|d| (rc.first_summit_past_elastic(e_star, hardness, &d), d))
    };
    if !matches!(approaches, Some((Some(_), _)))
        && let Some(sol) = solve_elastic_tips(
            scene,
            surface.clone(),
            opts,
            obs,
            hardness,
            model,
            observers,
        )?
    {
        return Ok(sol);
    }
    let report = surface_report(&surface, obs);
    let found = find_summits(&surface);
    let t0 = Instant::now();
    // the elastic law: the I model's interactions, and every summit below the table
    let law = law_for(scene, opts, obs)?;
    let rc =
        RoughContact::from_surface(law.as_ref(), &surface)?.with_params(solver_params(scene, opts));
    log!(
        obs,
        "plasticity: pressure capped by the hardness H = {hardness:e} Pa; the capped asperity's response table (ring solves, kept in the table cache)"
    );
    // a summit loaded past the table's lower end where the table has no y for it:
    // refused before the table is built (when the approaches are known)
    let uncovered_summit = |summit: usize, radius: f64, y: f64| {
        EngineError::Source(Box::new(UncoveredSummit { summit, radius, y }))
    };
    if let Some((_, d)) = &approaches
        && let Some(h1) = scene
            .bodies
            .top_thickness()
            .filter(|_| !scene.bodies.is_homogeneous())
    {
        let (lo, hi, _) = strata_runtime::rough::plastic::asperity::RESPONSE_Y;
        let past = rc
            .summits_past_elastic(e_star, hardness, d)
            .find_map(|(k, r)| {
                let y = std::f64::consts::PI * hardness * r / (2.0 * e_star) / h1;
                (!(lo * (1.0 - 1e-9)..=hi * (1.0 + 1e-9)).contains(&y)).then_some((k, r, y))
            });
        if let Some((k, r, y)) = past {
            return Err(uncovered_summit(k, r, y));
        }
    }
    let cache = crate::cache::dir(opts.cache_dir.as_deref()).0;
    let resp = crate::cache::capped_response(&scene.bodies, hardness, &cache, obs.quiet())
        .context("plasticity")?;
    let interacting = match model {
        Model::Interacting(images) => Some(images),
        _ => None,
    };
    let what = if interacting.is_some() {
        "interacting asperities (I model) with capped tips"
    } else {
        "independent asperities (N model) with capped tips"
    };
    log!(obs, "simulating: {what}; {} summits", found.summits.len());
    let solve = |d: f64, warm: &[f64]| -> Result<(Step, f64), RoughError> {
        match interacting {
            Some(images) => rc.solve_interacting_plastic(&resp, images, d, warm),
            None => rc.solve_independent_plastic(&resp, d),
        }
    };
    let deltas: Vec<f64> = match scene
        .load
        .approaches(rc.top_to_mean(), f64::INFINITY)
        .context("load")?
    {
        Some(d) => d,
        None => {
            let LoadSpec::MeanPressures(ps) = &scene.load else {
                return Err(EngineError::Internal("load"));
            };
            let mut out = Vec::with_capacity(ps.len());
            // the approach of each mean pressure: Illinois on δ ∈ [0, ∞) from the
            // largest summit height (doubling until the load passes p), to 10⁻¹⁴ δ
            let start = rc.max_delta().max(1e-12);
            let tol = Tolerance {
                f: 0.0,
                step: 0.0,
                width: 1e-14,
                width_abs: 0.0,
                falsi: Falsi::Illinois,
            };
            for (i, &p) in ps.iter().enumerate() {
                let out_of_reach = || {
                    EngineError::Input(format!(
                        "load.mean_pressures[{i}]: {p:e} Pa is out of reach of the capped N model"
                    ))
                };
                let f = |d: f64| -> Result<(f64, Option<f64>)> {
                    let v = solve(d, &[])?.0.mean_pressure - p;
                    if v < 0.0 && d >= start * REACH {
                        return Err(out_of_reach());
                    }
                    Ok((v, None))
                };
                let root = bracketed(f, (0.0, -p), (f64::INFINITY, p), Some(start), tol, 300)?;
                if !root.converged {
                    return Err(out_of_reach());
                }
                out.push(root.x);
            }
            out
        }
    };
    let mut steps = Vec::with_capacity(deltas.len());
    let mut plastic = Vec::with_capacity(deltas.len());
    // Approaches: the capped curve (the I model from its elastic load path, so that
    // steps where no summit yields are the elastic steps bit for bit); mean pressures:
    // each step at the approach its root search found.
    let solved: Vec<(Step, f64)> = if matches!(scene.load, LoadSpec::MeanPressures(_)) {
        if let Some((k, r, y)) = rc.first_uncovered_loaded(&resp, &deltas) {
            return Err(uncovered_summit(k, r, y));
        }
        let mut out = Vec::with_capacity(deltas.len());
        let mut warm: Vec<f64> = Vec::new();
        for (i, &d) in deltas.iter().enumerate() {
            opts.cancel.check()?;
            let r = solve(d, &warm).with_context(|| format!("load step {i}"))?;
            if r.0.area_fraction > 1.0 {
                let e = RoughError::AreaAboveNominal {
                    delta: d,
                    area: r.0.area_fraction,
                    interacting: interacting.is_some(),
                };
                return Err(EngineError::at(format!("load.mean_pressures[{i}]"), e));
            }
            warm = r.0.radii.clone();
            out.push(r);
        }
        out
    } else {
        rc.capped_curve(&resp, model, &deltas)
            .map_err(|(i, e)| EngineError::at(format!("load step {i}"), e))?
    };
    for (i, (s, flowing)) in solved.into_iter().enumerate() {
        let d = s.delta;
        if !s.validity.is_valid() {
            log!(
                obs,
                "warning: load step {i} (δ = {d:e} m) is outside the asperity model's validity: {} (use model.kind = \"bem\" for this load)",
                s.validity.describe()
            );
        }
        plastic.push(PlasticInfo {
            plastic_area_fraction: flowing,
            bem: None,
        });
        steps.push(s);
    }
    let mut seconds = t0.elapsed().as_secs_f64();
    // the capped tips' contact radii conduct as the elastic ones do (physics.md §6.2)
    seconds += after_path(
        observers,
        &AsperityPath {
            steps: &steps,
            contact: &rc,
            model,
        },
        opts,
        obs,
    )?;
    let mut summary = asperity_summary(
        scene,
        (
            what,
            &model_short(model),
            if interacting.is_some() {
                "the capped asperity's response table (ring solves in physical space); the elastic law's far field for the interactions"
            } else {
                "the capped asperity's response table (ring solves in physical space)"
            },
        ),
        scene.bodies.contact_modulus(),
        &rc,
        report,
        seconds,
    );
    summary.plasticity = Some(PlasticitySummary {
        hardness,
        note: "elastic–perfectly plastic tips (physics.md §9): each summit a capped paraboloid, its response \
                 P = P_c F(δ/δ_c, a_c/h1), a = a_c G(…) tabulated from ring solves (I model: the summits \
                 interact through the far field of their actual loads; where none yields, the elastic I \
                 model's solution); loading only",
        units: None,
    });
    Ok(SceneSolution {
        steps,
        plastic: Some(plastic),
        conductance: None,
        tangential: None,
        tangential_path: None,
        summary,
        seconds,
        failed: None,
    })
}

/// The capped N or I scene when no summit reaches the capped response table's range
/// (x = δ/δ_c < `plastic::ELASTIC_X`) anywhere on its load path: the elastic scene's
/// solution exactly (every summit elastic, no table built), with the plastic area
/// fraction 0 at every step; `None` when some summit does reach it (N model: its
/// geometric interference at some step; I model: its effective interference δ_I(a_k)
/// at the elastic I model's solution).
fn solve_elastic_tips(
    scene: &Scene,
    surface: Surface,
    opts: &EngineOptions,
    obs: &dyn Observer,
    hardness: f64,
    model: Model,
    observers: &mut [Box<dyn StepObserver + '_>],
) -> Result<Option<SceneSolution>> {
    let e_star = scene.bodies.contact_modulus();
    let law = law_for(scene, opts, obs)?;
    let rc = RoughContact::from_surface(law.as_ref(), &surface)?;
    let mut sol = solve_elastic(scene, surface, opts, obs, model, observers)?;
    let deltas: Vec<f64> = sol.steps.iter().map(|s| s.delta).collect();
    let elastic_tips = match model {
        Model::Independent => rc
            .first_summit_past_elastic(e_star, hardness, &deltas)
            .is_none(),
        Model::Interacting(_) => sol
            .steps
            .iter()
            .all(|s| rc.elastic_i_step_below_table(s, e_star, hardness)),
    };
    if !elastic_tips {
        return Ok(None);
    }
    log!(
        obs,
        "plasticity: no summit reaches δ = {:e}·δ_c (δ_c = (πH/2E*)²R, H = {hardness:e} Pa) on this path: every tip is elastic, the elastic model's solution is the capped one (no response table needed)",
        strata_runtime::rough::plastic::ELASTIC_X
    );
    sol.summary.plasticity = Some(PlasticitySummary {
        hardness,
        note: "elastic–perfectly plastic tips (physics.md §9); no summit reaches the capped response \
                 table's range (δ ≥ 0.01 δ_c, δ_c = (πH/2E*)²R) on this load path, so every tip is elastic \
                 and the steps are the elastic model's; loading only",
        units: None,
    });
    sol.plastic = Some(
        sol.steps
            .iter()
            .map(|_| PlasticInfo {
                plastic_area_fraction: 0.0,
                bem: None,
            })
            .collect(),
    );
    Ok(Some(sol))
}
