//! The elastic tips of the asperity models (a solver variant, [`ElasticTips`]): the N or
//! I model's load path through the runtime's `RoughContact` with Hertz tips on a
//! homogeneous stack and the surrogate table (χ, ζ, g) on a layered one; and the summary
//! every asperity path reports. The capped variant ([`crate::effects::plasticity`])
//! builds on it.

use std::time::Instant;

use crate::error::{Context, EngineError, Result};
use strata_runtime::rough::{Model, RoughContact, RoughError, Step};
use strata_runtime::summits::find_summits;
use strata_runtime::surface::Surface;

use crate::effects::observer::{AsperityPath, StepObserver};
use crate::progress;
use crate::scene::{LoadSpec, Scene};
use crate::setup::{
    EngineOptions, Observer, law_for, log, model_description, model_short, solver_params,
    stack_description, surface_report,
};
use crate::solution::{CurveUnits, SceneSolution, StepFailure, Summary, SurfaceReport};

/// How the asperity models' tips respond: a solver variant, chosen once per scene.
pub trait AsperityCurve {
    /// The load path of `scene` on `surface` with `model`; `observers` see the solved
    /// path before this returns (the contact that solved it is gone after).
    fn solve(
        &self,
        scene: &Scene,
        surface: Surface,
        opts: &EngineOptions,
        obs: &dyn Observer,
        model: Model,
        observers: &mut [Box<dyn StepObserver + '_>],
    ) -> Result<SceneSolution>;
}

/// Elastic tips: Hertz on a homogeneous stack, the surrogate table (χ, ζ, g) on a
/// layered one.
pub struct ElasticTips;

impl AsperityCurve for ElasticTips {
    fn solve(
        &self,
        scene: &Scene,
        surface: Surface,
        opts: &EngineOptions,
        obs: &dyn Observer,
        model: Model,
        observers: &mut [Box<dyn StepObserver + '_>],
    ) -> Result<SceneSolution> {
        solve_elastic(scene, surface, opts, obs, model, observers)
    }
}

/// The elastic N or I model ([`ElasticTips`]).
pub(crate) fn solve_elastic(
    scene: &Scene,
    surface: Surface,
    opts: &EngineOptions,
    obs: &dyn Observer,
    model: Model,
    observers: &mut [Box<dyn StepObserver + '_>],
) -> Result<SceneSolution> {
    let report = surface_report(&surface, obs);
    let found = find_summits(&surface);
    log!(
        obs,
        "surface: {} summits ({} dropped for κ ≤ 0)",
        found.summits.len(),
        found.dropped_nonpositive_curvature
    );
    let law = law_for(scene, opts, obs)?;
    let t0 = Instant::now();
    let rc =
        RoughContact::from_surface(law.as_ref(), &surface)?.with_params(solver_params(scene, opts));
    let described = model_description(model);
    let layered = if law.is_homogeneous() {
        "homogeneous solid (χ = ζ = 1, g = 0)"
    } else {
        "layered solid (χ, ζ from the table; g too for the I model)"
    };
    log!(obs, "simulating: {described}; {layered}");
    // Any approach δ ≥ 0 is admissible for the asperity models: steps beyond their
    // validity are solved, logged and flagged in curve.json, except where the N model's
    // contact areas sum to more than the nominal area (physically impossible): that step
    // is refused at once, before any I-model work on it (the N model is cheap), with the
    // BEM advice.
    let interacting = matches!(model, Model::Interacting(_));
    let refuse = |i: usize, what: String, delta: f64, area: f64| {
        let e = RoughError::AreaAboveNominal {
            delta,
            area,
            interacting,
        };
        log!(obs, "{what} (δ = {delta:e} m): refused: {e}");
        (i, e)
    };
    let mut failed = None;
    let steps: Vec<Step> = match scene
        .load
        .approaches(rc.top_to_mean(), f64::INFINITY)
        .context("load")?
    {
        Some(d) => {
            let _spin = (!obs.quiet()).then(|| {
                progress::spinner(format!("{}: {} load steps", model_short(model), d.len()))
            });
            let over = rc.first_area_above_nominal(&d);
            let solvable = over.map_or(d.len(), |(i, _)| i);
            let (steps, mut stop) = rc.curve_partial(model, &d[..solvable]);
            if let (None, Some((i, area))) = (&stop, over) {
                stop = Some(refuse(i, format!("load step {i}"), d[i], area));
            }
            if let Some((i, e)) = stop {
                if !opts.keep_partial || steps.is_empty() {
                    if matches!(e, RoughError::AreaAboveNominal { .. }) {
                        let at = format!("load step {i} (δ = {:e} m)", d[i]);
                        return Err(EngineError::at(at, e));
                    }
                    return Err(e.into());
                }
                failed = Some(StepFailure {
                    step: i,
                    delta: d[i],
                    error: e.to_string(),
                });
            }
            steps
        }
        None => {
            let LoadSpec::MeanPressures(ps) = &scene.load else {
                return Err(EngineError::Internal("load"));
            };
            let bar = (!obs.quiet()).then(|| {
                progress::bar(
                    ps.len() as u64,
                    format!("{}: mean pressures", model_short(model)),
                )
            });
            let mut out: Vec<Step> = Vec::new();
            let mut warm: Vec<f64> = Vec::new();
            for (i, &p) in ps.iter().enumerate() {
                opts.cancel.check()?;
                // The N model at this pressure first (cheap): past A/A₀ = 1 it is refused,
                // and so is the I model, which needs a larger approach for the same
                // pressure (interactions soften the contact).
                let field = format!("load.mean_pressures[{i}]");
                let n = rc
                    .solve_pressure(Model::Independent, p, &[])
                    .with_context(|| field.clone())?;
                if n.area_fraction > 1.0 {
                    let (_, e) = refuse(i, field.clone(), n.delta, n.area_fraction);
                    return Err(EngineError::at(field, e));
                }
                if !interacting {
                    warm = n.radii.clone();
                    out.push(n);
                    if let Some(b) = &bar {
                        b.inc();
                    }
                    continue;
                }
                let s = rc
                    .solve_pressure(model, p, &warm)
                    .with_context(|| field.clone())?;
                warm = s.radii.clone();
                out.push(s);
                if let Some(b) = &bar {
                    b.inc();
                }
            }
            out
        }
    };
    for (i, s) in steps.iter().enumerate() {
        if !s.validity.is_valid() {
            log!(
                obs,
                "warning: load step {i} (δ = {:e} m) is outside the asperity model's validity: {} (use model.kind = \"bem\" for this load)",
                s.delta,
                s.validity.describe()
            );
        }
    }
    if let Some(w) = steps
        .iter()
        .filter_map(|s| s.kkt_residual)
        .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))
    {
        log!(
            obs,
            "I model: largest KKT residual {w:.2e} (relative to the largest interference)"
        );
    }
    let mut seconds = t0.elapsed().as_secs_f64();
    // the model's time includes its effects' (conductance), as the BEM's does
    seconds += crate::effects::observer::after_path(
        observers,
        &AsperityPath {
            steps: &steps,
            contact: &rc,
            model,
        },
        opts,
        obs,
    )?;
    let summary = asperity_summary(
        scene,
        (&described, &model_short(model), layered),
        law.e_star(),
        &rc,
        report,
        seconds,
    );
    Ok(SceneSolution {
        steps,
        plastic: None,
        conductance: None,
        tangential: None,
        tangential_path: None,
        summary,
        seconds,
        failed,
    })
}

/// curve.json's summary of an asperity-model solve: (model, its short name, the solid)
/// in words, E* (Pa), the sample (area, summits, z_M − z̄), the surface and its
/// warnings, the time (s) and the units.
pub(crate) fn asperity_summary(
    scene: &Scene,
    (model, short, solid): (&str, &str, &str),
    e_star: f64,
    rc: &RoughContact<'_>,
    (surface, warnings): (SurfaceReport, Vec<String>),
    seconds: f64,
) -> Summary {
    Summary {
        scene: String::new(),
        model: model.into(),
        model_short: short.into(),
        stack: stack_description(&scene.bodies),
        solid: solid.into(),
        e_star_1: e_star,
        nominal_area: rc.area(),
        summits: Some(rc.summits().len()),
        z_max_minus_mean: rc.top_to_mean(),
        surface,
        warnings,
        bem_final_error: None,
        seconds,
        units: CurveUnits::asperity(),
        resolution: None,
        counterface: None,
        plasticity: None,
        conductance: None,
        friction: None,
        partial: None,
    }
}
