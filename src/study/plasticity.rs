//! Stage 6: yielding tips (physics.md §9) on the rough stage's surface: the
//! contact pressure capped at a hardness H = 0.05 E*₁ (a soft, polymer-like coating) in
//! the three models — the FFT-BEM at several grids, the N and the I model (periodic 5×5
//! images) through the capped asperity's response table. The reference is the capped
//! BEM on the finest grid of the mode; errors as in the rough stage (max over steps of
//! |p_n − p_n,ref|/p_n,ref), and the same for the plastic area A_pl/A₀.
//!
//! Stack: the scene's (its table serves the I model's interactions) in the quick and
//! full modes; the tiny mode (a smoke test) takes the homogeneous half-space of the top
//! layer, whose response table needs no ring solves against a layered kernel. Time per
//! load curve: from the surface to the curve (summits and solves for the asperity
//! models, the response table already built — its build is a row of its own, as the
//! table's load is for the elastic models; kernel set-up and solves for the BEM).

use anyhow::{Context, Result};
use ndarray::Array2;
use strata_bem::{BemLoad, BemOptions, BemSolver, resample_spectral};
use strata_runtime::Stack;
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::rough::plastic::PlasticResponse;
use strata_runtime::rough::{Images, Model, RoughContact};
use strata_runtime::surface::Surface;

use super::{Errors, Inputs, Mode, Reps, Runner, Timing};

/// H / E*₁ of the stage.
pub const HARDNESS_RATIO: f64 = 0.05;

/// One model's capped curve.
#[derive(Debug, Clone)]
pub struct Row {
    pub label: String,
    /// p_n/E*₁ per step.
    pub pressure: Vec<f64>,
    /// A_pl/A₀ per step.
    pub plastic: Vec<f64>,
    pub p_error: f64,
    pub plastic_error: f64,
    pub timing: Timing,
    pub is_reference: bool,
}

pub struct Results {
    /// What was capped: the stack's description and H (Pa).
    pub stack: String,
    pub hardness: f64,
    pub separations: Vec<f64>,
    pub rows: Vec<Row>,
    /// The response table's build (once per stack and hardness).
    pub response_timing: Timing,
    /// The elastic BEM on the reference grid at the same steps (p_n/E*₁): what the cap
    /// changes.
    pub elastic_reference: Vec<f64>,
}

/// The capped BEM along `loads`: (p_n/E*₁, A_pl/A₀) per step.
fn bem_curve(
    heights: &Array2<f64>,
    size: f64,
    stack: &Stack,
    hardness: f64,
    loads: &[BemLoad],
) -> Result<(Vec<f64>, Vec<f64>)> {
    let solver = BemSolver::new(heights, size, stack, BemOptions::default())?;
    let sols = solver.solve_plastic_curve(loads, hardness)?;
    Ok((
        sols.iter().map(|(s, _)| s.pressure_ratio).collect(),
        sols.iter().map(|(_, i)| i.plastic_area_fraction).collect(),
    ))
}

/// The capped N or I model at approaches `deltas`: (p_n/E*₁, A_pl/A₀) per step.
fn asperity_curve(
    law: &dyn AsperityLaw,
    surface: &Surface,
    resp: &PlasticResponse,
    model: Model,
    deltas: &[f64],
) -> Result<(Vec<f64>, Vec<f64>)> {
    let rc = RoughContact::from_surface(law, surface)?;
    let steps: Vec<(strata_runtime::rough::Step, f64)> = match model {
        Model::Interacting(images) => rc
            .curve(model, deltas)?
            .into_iter()
            .map(|s| rc.capped_from_elastic(resp, images, s, false))
            .collect::<Result<_, _>>()?,
        _ => deltas
            .iter()
            .map(|&d| rc.solve_independent_plastic(resp, d))
            .collect::<Result<_, _>>()?,
    };
    let e = resp.e_star;
    Ok((
        steps.iter().map(|(s, _)| s.mean_pressure / e).collect(),
        steps.iter().map(|(_, p)| *p).collect(),
    ))
}

pub fn run(runner: &mut Runner, errors: &mut Errors, inputs: &Inputs) -> Result<Results> {
    let mode = runner.mode;
    let (scene, surface, table_path, table) = super::rough::inputs(inputs)?;
    let layered = mode != Mode::Tiny;
    let half;
    let (stack, law): (&Stack, Box<dyn AsperityLaw>) = if layered {
        let law = table.law_for(&scene.bodies).with_context(|| {
            format!("{} does not serve the scene's stack", table_path.display())
        })?;
        (&scene.bodies.first, Box::new(law))
    } else {
        let top = scene
            .bodies
            .first
            .layers()
            .first()
            .map(|l| (l.young, l.poisson))
            .unwrap_or((4e9, 0.15));
        half = Stack::half_space(top.0, top.1)?;
        let e_star = half.contact_modulus();
        (&half, Box::new(Homogeneous { e_star }))
    };
    let e_star = stack.contact_modulus();
    let hardness = HARDNESS_RATIO * e_star;
    // the response table: one build per stack and hardness (timed once: seconds)
    let once = Reps {
        min_runs: 1,
        max_runs: 1,
        budget: 0.0,
    };
    let (resp, response_timing) =
        runner.time_value_with(once, "plasticity", "response table", || {
            Ok(strata_runtime::rough::plastic::asperity::response(
                stack, hardness,
            )?)
        })?;
    let rc = RoughContact::from_surface(law.as_ref(), &surface)?;
    let all = scene
        .load
        .approaches(rc.top_to_mean(), rc.max_delta())?
        .context("the study's scene must give approaches or separations, not pressures")?;
    let deltas = super::rough::spread(&all, super::rough::effect_steps(mode));
    let separations: Vec<f64> = deltas.iter().map(|d| rc.top_to_mean() - d).collect();
    let loads: Vec<BemLoad> = separations
        .iter()
        .map(|&g| BemLoad::Separation(g))
        .collect();
    let (n0, n1) = surface.shape();
    let heights = Array2::from_shape_vec((n0, n1), surface.heights().to_vec())?;
    let size = surface.extent().0;
    let grids = super::rough::effect_grids(mode);
    let finest = grids.iter().copied().max().unwrap_or(0);
    let mut rows = Vec::new();
    let mut elastic_reference = Vec::new();
    for &n in &grids {
        let h = resample_spectral(&heights, n)?;
        let case = format!("capped BEM n = {n}");
        let (pressure, plastic) = runner.exact(|| bem_curve(&h, size, stack, hardness, &loads))?;
        let timing = runner.time("plasticity", &case, || {
            bem_curve(&h, size, stack, hardness, &loads)
        })?;
        if n == finest {
            let solver = BemSolver::new(&h, size, stack, BemOptions::default())?;
            elastic_reference = runner
                .exact(|| solver.solve_curve(&loads))?
                .iter()
                .map(|s| s.pressure_ratio)
                .collect();
        }
        rows.push(Row {
            label: case,
            pressure,
            plastic,
            p_error: f64::NAN,
            plastic_error: f64::NAN,
            timing,
            is_reference: n == finest,
        });
    }
    for (label, model) in [
        ("capped N model", Model::Independent),
        (
            "capped I model, periodic 5×5",
            Model::Interacting(Images::Periodic(2)),
        ),
    ] {
        let (pressure, plastic) =
            runner.exact(|| asperity_curve(law.as_ref(), &surface, &resp, model, &deltas))?;
        let timing = runner.time("plasticity", label, || {
            asperity_curve(law.as_ref(), &surface, &resp, model, &deltas)
        })?;
        rows.push(Row {
            label: label.into(),
            pressure,
            plastic,
            p_error: f64::NAN,
            plastic_error: f64::NAN,
            timing,
            is_reference: false,
        });
    }
    let reference = rows
        .iter()
        .find(|r| r.is_reference)
        .cloned()
        .context("internal: no capped BEM reference")?;
    for r in rows.iter_mut() {
        r.p_error = super::rough::max_rel(&r.pressure, &reference.pressure);
        r.plastic_error = super::rough::max_rel(&r.plastic, &reference.plastic);
        errors.push("plasticity", &r.label, "p error", r.p_error);
        errors.push(
            "plasticity",
            &r.label,
            "plastic area error",
            r.plastic_error,
        );
    }
    Ok(Results {
        stack: if layered {
            format!(
                "the scene's stack (table {})",
                table_path.file_name().map_or_else(
                    || table_path.display().to_string(),
                    |f| f.to_string_lossy().into_owned()
                )
            )
        } else {
            "the top layer's homogeneous half-space (tiny mode)".into()
        },
        hardness,
        separations,
        rows,
        response_timing,
        elastic_reference,
    })
}

/// The report's section.
pub fn markdown(r: &Results) -> String {
    use std::fmt::Write;
    let mut w = String::new();
    let _ = writeln!(
        w,
        "## 6. Yielding tips (hardness cap)\n\nThe contact pressure capped at H = {:.3e} Pa \
         (H/E*₁ = {HARDNESS_RATIO}) on {}: the capped BEM at several grids (the finest is the \
         reference), the N and the I model through the capped asperity's response table \
         (physics.md §9). The response table took {} to build (once per stack and hardness; \
         not in the models' times).\n",
        r.hardness,
        r.stack,
        super::fmt_time(r.response_timing.median)
    );
    let _ = writeln!(
        w,
        "| model | p error | plastic area error | time per curve | runs |\n|---|---|---|---|---|"
    );
    for row in &r.rows {
        let (pe, ae) = if row.is_reference {
            ("reference".to_string(), "—".to_string())
        } else {
            (
                super::fmt_err(row.p_error),
                super::fmt_err(row.plastic_error),
            )
        };
        let _ = writeln!(
            w,
            "| {} | {pe} | {ae} | {} | {} |",
            row.label,
            super::fmt_time(row.timing.median),
            row.timing.runs
        );
    }
    if let Some(reference) = r.rows.iter().find(|x| x.is_reference) {
        let _ = writeln!(
            w,
            "\nPer load step: the reference (capped), the elastic BEM on the same grid, the \
             plastic area, and the signed deviation of each model's p_n:\n"
        );
        let shown: Vec<&Row> = r.rows.iter().filter(|x| !x.is_reference).collect();
        let _ = write!(
            w,
            "| g_n (m) | capped p_n/E*₁ | elastic p_n/E*₁ | A_pl/A₀ |"
        );
        for x in &shown {
            let _ = write!(w, " {} |", x.label);
        }
        let _ = writeln!(w);
        let _ = writeln!(w, "|{}", "---|".repeat(4 + shown.len()));
        for (k, g) in r.separations.iter().enumerate() {
            let _ = write!(
                w,
                "| {:.3e} | {:.4e} | {:.4e} | {:.3e} |",
                g,
                reference.pressure[k],
                r.elastic_reference.get(k).copied().unwrap_or(f64::NAN),
                reference.plastic[k]
            );
            for x in &shown {
                let _ = write!(w, " {:+.2e} |", x.pressure[k] / reference.pressure[k] - 1.0);
            }
            let _ = writeln!(w);
        }
    }
    let _ = writeln!(w);
    w
}
