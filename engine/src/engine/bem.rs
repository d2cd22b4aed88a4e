//! The load-path driver of `model.kind = "bem"`: the FFT boundary-element solution of
//! the whole surface (strata-bem): on a periodic surface with the layered kernel
//! 2S(|k|)/(E*₁|k|), on a non-periodic one with the pixel influence coefficients of the
//! free solid, both computed from the stack (no χ, ζ, g table is needed or loaded).
//! Same steps as the asperity models; `contacts` counts contact patches. The surface's
//! response (elastic or capped) is chosen once ([`crate::effects::plasticity`]); after
//! each step its tangent stiffness ([`crate::effects::stiffness`]) and the effects'
//! observers ([`crate::effects`]) run; the maps go to the [`Observer`]. No effect code
//! here.

use std::borrow::Cow;
use std::time::Instant;

use crate::error::{Context, EngineError, Result};
use strata_bem::{BemLoad, BemOptions, BemSolver, Geometry};
use strata_runtime::Solid;
use strata_runtime::rough::Step;
use strata_runtime::surface::Surface;

use crate::effects::observer::{BemStep, finish};
use crate::effects::plasticity;
use crate::effects::stiffness;
use crate::progress;
use crate::scene::{LoadSpec, Scene};
use crate::setup::{
    EngineOptions, Observer, counterface_summary, log, stack_description, surface_report,
};
use crate::solution::{
    CurveUnits, PartialSummary, ResolutionSummary, ResolutionUnits, SceneSolution, StepFailure,
    StepResolutionReport, Summary,
};

/// The BEM's solution of `scene` on `surface`.
pub fn solve(
    scene: &Scene,
    surface: Surface,
    opts: &EngineOptions,
    obs: &mut dyn Observer,
) -> Result<SceneSolution> {
    let (surface_report, mut warnings) = surface_report(&surface, obs);
    let (n0, n1) = surface.shape();
    let periodic = surface.is_periodic();
    // Rows (first index, n0 points) span extent().0, columns extent().1.
    let (rows_side, cols_side) = surface.extent();
    let z_max = surface.heights().iter().copied().fold(f64::MIN, f64::max);
    let top_to_mean = z_max - surface.mean();
    // The heights move into the solver: one copy of the grid in the process, not two.
    let heights = ndarray::Array2::from_shape_vec((n0, n1), surface.into_heights())
        .context("surface: heights")?;
    let geometry = Geometry {
        lx: cols_side,
        ly: rows_side,
        periodic,
    };
    let stack = &scene.bodies;
    let t0 = Instant::now();
    let bem_options = BemOptions {
        memory: opts.memory,
        ..scene.solver.bem_options(opts.bem.unwrap_or_default())
    };
    let solver = BemSolver::with_geometry_owned(heights, geometry, stack, bem_options)
        .context("model.kind = \"bem\"")?
        .with_cancel(opts.cancel.clone());
    let solid = if stack.is_homogeneous() {
        "homogeneous solid (kernel 2/(E*|k|))".to_string()
    } else {
        format!(
            "layered solid ({} layers; kernel 2S(|k|)/(E*₁|k|) with S computed from the stack)",
            stack.first.layers().len()
        )
    };
    let described = if periodic {
        format!("full-field boundary elements on the {n0}×{n1} grid, periodic")
    } else {
        format!(
            "full-field boundary elements on the {n0}×{n1} grid, non-periodic (isolated sample on an unbounded solid: zero-padded convolution with pixel influence coefficients)"
        )
    };
    log!(obs, "simulating: {described}; {solid}");
    let loads = loads(scene, top_to_mean)?;
    let area = solver.area();
    let total = loads.len();
    let bar =
        (!obs.quiet()).then(|| progress::bar(total as u64, format!("BEM {n0}×{n1}: load steps")));
    let mut steps = Vec::with_capacity(total);
    let mut warm: Option<Vec<f64>> = None;
    let mut worst_error = 0.0f64;
    // the surface's response, chosen once: elastic or capped at the hardness
    let mut response = plasticity::bem_response(scene, &solver, obs)?;
    let mut plastic = scene.plasticity.map(|_| Vec::with_capacity(total));
    let mut observers = crate::effects::for_bem(scene, (n0, n1), geometry, opts, obs)?;
    let mut failed = None;
    let mut resolution: Vec<StepResolution> = Vec::with_capacity(total);
    for (k, (name, load)) in loads.into_iter().enumerate() {
        opts.cancel.check()?;
        // One step; an error here stops the path (below: a partial curve or the error).
        // Memory: the step holds its pressure map only (the previous step's, the warm
        // start, becomes this step's; it is kept as its contact points while the tangent
        // iterates in its buffer); the step's gap and deflection maps are formed after
        // the tangent, when they go to the observer.
        let mut one_step = || -> Result<strata_bem::BemSolution> {
            let (mut sol, record) = response
                .step(load, warm.take())
                .with_context(|| name.clone())?;
            if let (Some(p), Some(r)) = (plastic.as_mut(), record) {
                p.push(r);
            }
            let tangent = stiffness::after_step(response.as_mut(), &mut sol, &name)?;
            let flat: Cow<'_, [f64]> = match sol.pressure.as_slice() {
                Some(p) => Cow::Borrowed(p),
                None => Cow::Owned(sol.pressure.iter().copied().collect()),
            };
            resolution.push(StepResolution::of(&flat, n0, n1, periodic));
            worst_error = worst_error.max(sol.error);
            let mut st = Step::default();
            st.delta = sol.approach;
            st.gap = sol.separation;
            st.load = sol.total_load;
            st.mean_pressure = sol.mean_pressure;
            st.pressure_ratio = sol.pressure_ratio;
            st.area_fraction = sol.area_fraction;
            st.contacts = sol.patches;
            st.stiffness = tangent.stiffness;
            st.iterations = sol.iterations;
            steps.push(st);
            let seen = BemStep {
                name: &name,
                pressure: &flat,
                pressure_rate: &tangent.pressure_rate,
            };
            for o in observers.iter_mut() {
                o.after_step(&seen, obs)?;
            }
            drop(tangent);
            warm = Some(flat.into_owned());
            response.complete(&mut sol).with_context(|| name.clone())?;
            Ok(sol)
        };
        let sol = match one_step() {
            Ok(sol) => sol,
            // Cancelled, no step converged, or no partial curve asked: the error.
            Err(e) if opts.cancel.is_cancelled() || k == 0 || !opts.keep_partial => {
                return Err(e);
            }
            Err(e) => {
                // the steps before this one stand; this one's partial records go
                steps.truncate(k);
                if let Some(p) = plastic.as_mut() {
                    p.truncate(k);
                }
                for o in observers.iter_mut() {
                    o.truncate(k);
                }
                resolution.truncate(k);
                failed = Some(step_failure(obs, &name, k, load, top_to_mean, &e));
                break;
            }
        };
        obs.maps(k, total, sol)?;
        if let Some(b) = &bar {
            b.inc();
        }
    }
    drop(bar);
    if failed.is_none() {
        for o in observers.iter_mut() {
            o.after_bem_path(obs)?;
        }
    } else if scene.tangential.is_some() {
        log!(
            obs,
            "load.tangential: not run, the normal path stopped before its last step"
        );
    }
    let seconds = t0.elapsed().as_secs_f64();
    log!(obs, "BEM: largest final CG error {worst_error:.2e}");
    let e_star = stack.contact_modulus();
    for w in resolution_warnings(&resolution, e_star, scene.plasticity.is_some()) {
        progress::warn(format_args!("{w}"));
        warnings.push(w);
    }
    let summary = Summary {
        scene: String::new(),
        model: described,
        model_short: "BEM".into(),
        stack: stack_description(stack),
        solid,
        e_star_1: stack.contact_modulus(),
        nominal_area: area,
        summits: None,
        z_max_minus_mean: top_to_mean,
        surface: surface_report,
        warnings,
        bem_final_error: Some(worst_error),
        seconds,
        units: CurveUnits::bem(),
        resolution: Some(resolution_summary(&resolution, e_star)),
        counterface: counterface_summary(scene),
        plasticity: scene
            .plasticity
            .map(|pl| plasticity::bem_summary(pl.hardness)),
        conductance: None,
        friction: None,
        partial: failed.as_ref().map(PartialSummary::of),
    };
    let mut solution = SceneSolution {
        steps,
        plastic,
        conductance: None,
        tangential: None,
        tangential_path: None,
        summary,
        seconds,
        failed,
    };
    finish(observers, &mut solution);
    Ok(solution)
}

/// The load steps of a BEM scene, named as its errors name them: the approaches (any
/// δ ≥ 0) or the mean pressures of `[load]`, and with `[load] unload` the return path.
/// `top_to_mean` is z_M − z̄ of the surface (m).
pub(super) fn loads(scene: &Scene, top_to_mean: f64) -> Result<Vec<(String, BemLoad)>> {
    let loads: Vec<(String, BemLoad)> = match scene
        .load
        // Any approach δ ≥ 0: beyond the peak-to-valley height z_M − z_min the layers
        // (or the unbounded solid) still compress as a whole with partial contact; the
        // solver refuses only what its convention cannot hold (periodic, elastic base:
        // δ < z_M − z̄).
        .approaches(top_to_mean, f64::INFINITY)
        .context("load")?
    {
        Some(d) => d
            .into_iter()
            .enumerate()
            .map(|(i, d)| (format!("load step {i}"), BemLoad::Approach(d)))
            .collect(),
        None => {
            let LoadSpec::MeanPressures(ps) = &scene.load else {
                return Err(EngineError::Internal("load"));
            };
            ps.iter()
                .enumerate()
                .map(|(i, &p)| {
                    (
                        format!("load.mean_pressures[{i}]"),
                        BemLoad::MeanPressure(p),
                    )
                })
                .collect()
        }
    };
    let mut loads = loads;
    if scene.unload {
        // the return path: the loading steps back, the last one not repeated
        let back: Vec<(String, BemLoad)> = loads
            .iter()
            .rev()
            .skip(1)
            .map(|(name, l)| (format!("{name} (unloading)"), *l))
            .collect();
        loads.extend(back);
    }
    Ok(loads)
}

/// Below this median contact-patch size (pixels) a BEM step is flagged as under-resolved.
/// A Hertzian patch of N pixels against Hertz's solution (`strata_bem` test
/// `hertz_patch_error_by_pixels_per_patch`): 4 pixels have their area 33 % and peak
/// pressure 44 % off, 12 pixels 20 % and 4.7 %, 32 pixels 6.7 % and 2.1 %. Below ~10
/// pixels the typical patch's area and pressure are the grid's, not the surface's.
pub const PATCH_PIXELS_MIN: f64 = 10.0;

/// The elastic peak pressure above which a step is flagged as implausible without
/// `[plasticity]`, as a fraction of E*: 0.1 E*, about the hardness of the hardest solids
/// (diamond H ≈ 0.1 E*; ceramics 0.05–0.1, hardened steel ≈ 0.05, most metals and
/// polymers 0.005–0.05): beyond it no real solid stays elastic. Rubber-like solids that
/// do not yield may ignore the warning.
pub const PEAK_PRESSURE_MAX_OVER_E_STAR: f64 = 0.1;

/// One BEM step's resolution diagnostics: its contact patches' sizes and peak pressure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct StepResolution {
    /// Median patch size (pixels); `None` without contact.
    pub(super) median_patch_pixels: Option<f64>,
    /// Largest patch (pixels).
    pub(super) largest_patch_pixels: usize,
    /// Peak pressure (Pa).
    pub(super) peak_pressure: f64,
}

impl StepResolution {
    /// Of a pressure map (row-major n0 × n1).
    fn of(pressure: &[f64], n0: usize, n1: usize, periodic: bool) -> Self {
        let mask: Vec<bool> = pressure.iter().map(|&p| p > 0.0).collect();
        let sizes = strata_bem::patch_sizes(&mask, n0, n1, periodic);
        StepResolution {
            median_patch_pixels: strata_bem::median_patch_size(&sizes),
            largest_patch_pixels: sizes.iter().copied().max().unwrap_or(0),
            peak_pressure: pressure.iter().copied().fold(0.0, f64::max),
        }
    }
}

/// curve.json's `resolution`: per step, the median and largest patch (pixels) and the
/// peak pressure (Pa and /E*), with the thresholds of the warnings.
pub(super) fn resolution_summary(steps: &[StepResolution], e_star: f64) -> ResolutionSummary {
    ResolutionSummary {
        patch_pixels_min: PATCH_PIXELS_MIN,
        peak_pressure_max_over_e_star: PEAK_PRESSURE_MAX_OVER_E_STAR,
        note: "median_patch_pixels below patch_pixels_min: the typical contact patch is resolved by too few \
                 pixels (a Hertzian patch of ~10 pixels has its area ~20 % off); peak pressures above \
                 peak_pressure_max_over_e_star × E* are beyond the hardness of any real solid (use [plasticity])",
        steps: steps
            .iter()
            .map(|s| StepResolutionReport {
                median_patch_pixels: s.median_patch_pixels,
                largest_patch_pixels: s.largest_patch_pixels,
                peak_pressure: s.peak_pressure,
                peak_pressure_over_e_star: s.peak_pressure / e_star,
            })
            .collect(),
        units: ResolutionUnits {
            median_patch_pixels: "pixels",
            largest_patch_pixels: "pixels",
            peak_pressure: "Pa",
            peak_pressure_over_e_star: "1",
        },
    }
}

/// Steps as a short list: `0–3, 7` (0-based).
fn step_list(ks: &[usize]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut i = 0;
    while i < ks.len() {
        let mut j = i;
        while j + 1 < ks.len() && ks[j + 1] == ks[j] + 1 {
            j += 1;
        }
        parts.push(if j > i {
            format!("{}–{}", ks[i], ks[j])
        } else {
            ks[i].to_string()
        });
        i = j + 1;
    }
    parts.join(", ")
}

/// The BEM's resolution warnings: steps whose median contact patch is below
/// [`PATCH_PIXELS_MIN`] pixels, and (elastic solves) steps whose peak pressure exceeds
/// [`PEAK_PRESSURE_MAX_OVER_E_STAR`] × E*, with what to do.
pub(super) fn resolution_warnings(
    steps: &[StepResolution],
    e_star: f64,
    plastic: bool,
) -> Vec<String> {
    let mut out = Vec::new();
    let coarse: Vec<usize> = (0..steps.len())
        .filter(|&k| {
            steps[k]
                .median_patch_pixels
                .is_some_and(|m| m < PATCH_PIXELS_MIN)
        })
        .collect();
    if let Some(&worst) = coarse.iter().min_by(|&&a, &&b| {
        let m = |k: usize| steps[k].median_patch_pixels.unwrap_or(0.0);
        m(a).total_cmp(&m(b))
    }) {
        out.push(format!(
            "BEM resolution: the median contact patch has fewer than {PATCH_PIXELS_MIN} pixels at {} of {} \
             steps (steps {}; {} pixels at step {worst}): a patch that small has its area and peak pressure \
             set by the pixels (a Hertzian patch of ~10 pixels: area ~20 % off, 4 pixels: 33 %, peak pressure 44 %); \
             use a finer scan or grid, or read those steps' areas and pressures as resolution-limited \
             (curve.json: resolution)",
            coarse.len(),
            steps.len(),
            step_list(&coarse),
            steps[worst].median_patch_pixels.unwrap_or(0.0),
        ));
    }
    if !plastic {
        let high: Vec<usize> = (0..steps.len())
            .filter(|&k| steps[k].peak_pressure > PEAK_PRESSURE_MAX_OVER_E_STAR * e_star)
            .collect();
        if let Some(&top) = high
            .iter()
            .max_by(|&&a, &&b| steps[a].peak_pressure.total_cmp(&steps[b].peak_pressure))
        {
            let p = steps[top].peak_pressure;
            out.push(format!(
                "elastic peak pressure {p:.3e} Pa at step {top} = {:.3} E* (E* = {e_star:.3e} Pa), above \
                 {PEAK_PRESSURE_MAX_OVER_E_STAR} E* at {} of {} steps (steps {}): beyond the hardness of any \
                 real solid (metals yield at H ≈ 0.005–0.05 E*), the contact would deform plastically; give \
                 the material's hardness in [plasticity] (hardness = H, Pa) to cap the pressure at H",
                p / e_star,
                high.len(),
                steps.len(),
                step_list(&high),
            ));
        }
    }
    out
}

/// The failure of step `k` (`name`, under `load`) that ends a load path: logged, and kept
/// beside the `k` steps before it (a partial curve). `top_to_mean` (m) turns a separation
/// into the approach it stands for.
pub(super) fn step_failure(
    obs: &mut dyn Observer,
    name: &str,
    k: usize,
    load: BemLoad,
    top_to_mean: f64,
    e: &dyn std::fmt::Display,
) -> StepFailure {
    log!(
        obs,
        "{name} failed: {e:#}; the {k} steps before it are kept (a partial curve)"
    );
    StepFailure {
        step: k,
        delta: match load {
            BemLoad::Approach(d) => d,
            BemLoad::Separation(g) => top_to_mean - g,
            _ => f64::NAN,
        },
        error: format!("{e:#}"),
    }
}
