//! Stage 7: interface conductance (physics.md §6.2) on the rough stage's
//! surface: the thermal constriction conductance per nominal area h_c (W/(m²·K)) of the
//! contact spots in the three models — the FFT-BEM's conduction solve on its contact
//! set at several grids, the N model's spots in parallel (Σ G(aᵢ)/A₀) and the I model's
//! interacting spots (periodic 5×5 images for the mechanics, the periodic point-source
//! field for the heat) — against the BEM on the finest grid of the mode. Errors as
//! `strata compare` reports them: per reference step, h/h_ref − 1 at equal separation
//! g_n (the models loaded at the same g_n) and at equal mean pressure p_n (the model's
//! h_c interpolated log–log in p between its own steps, where they bracket p_ref); the
//! error of a model is the largest |h/h_ref − 1| over the steps.
//!
//! Stack: the scene's stack with its thermal conductivities, or — when it has none —
//! those of `tables/stacks/paper-two-layer-conducting.toml` ([`TOP_CONDUCTIVITY`] for the
//! top layer, [`LOWER_CONDUCTIVITY`] below, an isothermal base under a rigid one, a
//! half-space of [`LOWER_CONDUCTIVITY`] under an elastic one), pressed by a rigid steel
//! flat that conducts ([`FLAT_CONDUCTIVITY`]). The tiny mode (a smoke test) takes the
//! top layer's homogeneous conducting half-space (ψ ≡ 1: no spot solves).
//!
//! Time per load curve: from the surface to the curve with its conductance (as the
//! rough stage's, plus the conduction), and the conductance's own time of the same
//! curve on its solved contact sets (the BEM: the conduction operator and one warm-started
//! PCG per step; the N and I models: the ψ table, the I model's kernel table and network
//! solves), so that the share the conductance adds is read off.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use ndarray::Array2;
use strata_bem::{
    BemLoad, BemOptions, BemSolver, ConductanceOptions, ConductanceSolver, Conductor,
    resample_spectral,
};
use strata_runtime::Stack;
use strata_runtime::conduction::{ConductionCompliance, ConductionKind};
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::rough::{Images, Model, RoughContact, Step};
use strata_runtime::stack::{Base, BaseConduction, Conductivity};
use strata_runtime::surface::Surface;

use crate::cli::compare::conductance_rows;
use crate::spots::SpotSum;

use super::{Errors, Inputs, Mode, Runner, Timing};

/// The top layer's thermal conductivity when the scene's stack has none (W/(m·K)): the
/// paper's conducting stack's polymer-like coating.
pub const TOP_CONDUCTIVITY: f64 = 0.5;
/// The other layers' (and an elastic base's) thermal conductivity when the scene's stack
/// has none (W/(m·K)).
pub const LOWER_CONDUCTIVITY: f64 = 5.0;
/// The rigid flat's thermal conductivity (W/(m·K)): steel.
pub const FLAT_CONDUCTIVITY: f64 = 45.0;

/// One model's conductance curve.
#[derive(Debug, Clone)]
pub struct Row {
    pub label: String,
    /// p_n/E*₁ per step.
    pub pressure: Vec<f64>,
    /// h_c per step (W/(m²·K)).
    pub conductance: Vec<f64>,
    /// h/h_ref − 1 per reference step at equal separation (signed).
    pub rel_g: Vec<f64>,
    /// max |h/h_ref − 1| at equal separation.
    pub g_error: f64,
    /// max |h/h_ref − 1| at equal pressure, over the `p_steps` steps the model brackets.
    pub p_error: f64,
    pub p_steps: usize,
    /// The curve with its conductance.
    pub timing: Timing,
    /// The conductance's own time on the same curve.
    pub conductance_timing: Timing,
    pub is_reference: bool,
}

impl Row {
    /// The conductance's share of the curve's time.
    pub fn share(&self) -> f64 {
        self.conductance_timing.median / self.timing.median
    }

    /// The share the conductance adds to the mechanics' time: t_h/(t − t_h).
    pub fn added(&self) -> f64 {
        let t = self.conductance_timing.median;
        t / (self.timing.median - t)
    }
}

pub struct Results {
    /// The conducting stack and the counterface in words.
    pub stack: String,
    pub summits: usize,
    pub separations: Vec<f64>,
    pub rows: Vec<Row>,
    /// The N model's conductance with the stack's ψ table solved (a first run per
    /// stack: no table cache); None on a homogeneous stack (ψ ≡ 1).
    pub psi_timing: Option<Timing>,
}

/// The scene's stack with thermal conductivities (its own, else the defaults above).
fn conducting(stack: &Stack) -> Result<(Stack, bool)> {
    if ConductionCompliance::new(stack, ConductionKind::Thermal).is_ok() {
        return Ok((stack.clone(), true));
    }
    let k = Conductivity::thermal;
    let layers: Vec<Conductivity> = (0..stack.layers().len())
        .map(|i| {
            k(if i == 0 {
                TOP_CONDUCTIVITY
            } else {
                LOWER_CONDUCTIVITY
            })
        })
        .collect();
    let s = match stack.base() {
        Base::Rigid => stack.clone().with_conduction(
            layers,
            Conductivity::default(),
            BaseConduction::Isothermal,
        ),
        _ => {
            stack
                .clone()
                .with_conduction(layers, k(LOWER_CONDUCTIVITY), BaseConduction::HalfSpace)
        }
    }?;
    Ok((s, false))
}

/// A BEM solution as the compare functions read it.
fn bem_step(s: &strata_bem::BemSolution) -> Step {
    let mut st = Step::default();
    st.delta = s.approach;
    st.gap = s.separation;
    st.mean_pressure = s.mean_pressure;
    st.pressure_ratio = s.pressure_ratio;
    st.area_fraction = s.area_fraction;
    st.load = s.total_load;
    st
}

/// The conduction operator of an n × n periodic grid of `geometry`.
fn conduction(
    n: usize,
    geometry: strata_bem::Geometry,
    body: &ConductionCompliance,
) -> Result<ConductanceSolver> {
    Ok(ConductanceSolver::new(
        n,
        n,
        geometry,
        Conductor::Layered(body),
        Conductor::HalfSpace(FLAT_CONDUCTIVITY),
        ConductanceOptions::default(),
    )?)
}

/// h_c on each contact set, each solve warm-started from the previous flux.
fn bem_conductances(solver: &ConductanceSolver, sets: &[Vec<bool>]) -> Result<Vec<f64>> {
    let mut flux: Option<Vec<f64>> = None;
    let mut h = Vec::with_capacity(sets.len());
    for set in sets {
        let c = solver.solve_from(set, flux.as_deref())?;
        h.push(c.conductance);
        flux = c.conductance.is_finite().then_some(c.flux);
    }
    Ok(h)
}

/// A BEM curve with its conductance: the steps, h_c per step and the contact sets.
type BemCurve = (Vec<Step>, Vec<f64>, Vec<Vec<bool>>);

/// The BEM along `loads` with its conductance.
fn bem_curve(
    heights: &Array2<f64>,
    size: f64,
    stack: &Stack,
    body: &ConductionCompliance,
    loads: &[BemLoad],
) -> Result<BemCurve> {
    let solver = BemSolver::new(heights, size, stack, BemOptions::default())?;
    let sols = solver.solve_curve(loads)?;
    let sets: Vec<Vec<bool>> = sols
        .iter()
        .map(|s| s.pressure.iter().map(|&p| p > 0.0).collect())
        .collect();
    let cs = conduction(heights.nrows(), solver.geometry(), body)?;
    let h = bem_conductances(&cs, &sets)?;
    Ok((sols.iter().map(bem_step).collect(), h, sets))
}

/// The N or I model's h_c of `steps` (W/(m²·K)), the stack's ψ table read from (or
/// solved into) the table cache `cache` as `strata solve` does, or solved in memory
/// (None).
fn spot_conductances(
    stack: &Stack,
    rc: &RoughContact<'_>,
    model: Model,
    steps: &[Step],
    cache: Option<&Path>,
) -> Result<Vec<f64>> {
    let sum = SpotSum::against_rigid(stack, ConductionKind::Thermal, Some(FLAT_CONDUCTIVITY))?
        .with_cache(cache.map(Path::to_path_buf));
    match model {
        Model::Independent => Ok(sum.conductances(steps, rc.area())?),
        Model::Interacting(images) => Ok(sum
            .interacting(
                steps,
                rc.summits(),
                rc.extent(),
                images,
                &rc.params().memory,
            )?
            .0),
    }
}

/// The N or I model's curve at approaches `deltas` with its conductance.
fn asperity_curve(
    law: &dyn AsperityLaw,
    surface: &Surface,
    stack: &Stack,
    model: Model,
    deltas: &[f64],
    cache: &Path,
) -> Result<(Vec<Step>, Vec<f64>)> {
    let rc = RoughContact::from_surface(law, surface)?;
    let steps = rc.curve(model, deltas)?;
    let h = spot_conductances(stack, &rc, model, &steps, Some(cache))?;
    Ok((steps, h))
}

/// A table cache private to one study run (removed when dropped).
struct StudyCache(PathBuf);

impl Drop for StudyCache {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn max_abs(v: impl Iterator<Item = f64>) -> (f64, usize) {
    v.filter(|x| x.is_finite())
        .fold((0.0, 0), |(m, n), x| (f64::max(m, x.abs()), n + 1))
}

pub fn run(runner: &mut Runner, errors: &mut Errors, inputs: &Inputs) -> Result<Results> {
    let mode = runner.mode;
    let (scene, surface, table_path, table) = super::rough::inputs(inputs)?;
    let layered = mode != Mode::Tiny;
    let (stack, own, law): (Stack, bool, Box<dyn AsperityLaw>) = if layered {
        let law = table.law_for(&scene.bodies).with_context(|| {
            format!("{} does not serve the scene's stack", table_path.display())
        })?;
        let (stack, own) = conducting(&scene.bodies.first)?;
        (stack, own, Box::new(law))
    } else {
        let top = scene
            .bodies
            .first
            .layers()
            .first()
            .map(|l| (l.young, l.poisson))
            .unwrap_or((4e9, 0.15));
        let half = Stack::half_space(top.0, top.1)?.with_conduction(
            vec![],
            Conductivity::thermal(TOP_CONDUCTIVITY),
            BaseConduction::HalfSpace,
        )?;
        let e_star = half.contact_modulus();
        (half, false, Box::new(Homogeneous { e_star }))
    };
    let body = ConductionCompliance::new(&stack, ConductionKind::Thermal)?;
    let rc = RoughContact::from_surface(law.as_ref(), &surface)?;
    let all = scene
        .load
        .approaches(rc.top_to_mean(), rc.max_delta())?
        .context("the study's scene must give approaches or separations, not pressures")?;
    if all.is_empty() {
        bail!("--scene: no load steps");
    }
    let deltas = super::rough::spread(&all, super::rough::effect_steps(mode));
    let scale = rc.top_to_mean();
    let separations: Vec<f64> = deltas.iter().map(|d| scale - d).collect();
    let loads: Vec<BemLoad> = separations
        .iter()
        .map(|&g| BemLoad::Separation(g))
        .collect();
    let (n0, n1) = surface.shape();
    let heights = Array2::from_shape_vec((n0, n1), surface.heights().to_vec())?;
    let size = surface.extent().0;
    let e_star = stack.contact_modulus();
    let grids = super::rough::effect_grids(mode);
    let finest = grids.iter().copied().max().unwrap_or(0);
    // (row, steps): the steps for the comparison at equal pressure
    let mut rows: Vec<(Row, Vec<Step>)> = Vec::new();
    for &n in &grids {
        let h = resample_spectral(&heights, n)?;
        let label = format!("BEM n = {n}");
        let (steps, hc, sets) = runner.exact(|| bem_curve(&h, size, &stack, &body, &loads))?;
        let timing = runner.time("conductance", &label, || {
            bem_curve(&h, size, &stack, &body, &loads)
        })?;
        let geometry = strata_bem::Geometry::square(size);
        let conductance_timing =
            runner.time("conductance", &format!("{label}: conductance"), || {
                bem_conductances(&conduction(n, geometry, &body)?, &sets)
            })?;
        rows.push((
            Row {
                label,
                pressure: steps.iter().map(|s| s.pressure_ratio).collect(),
                conductance: hc,
                rel_g: Vec::new(),
                g_error: f64::NAN,
                p_error: f64::NAN,
                p_steps: 0,
                timing,
                conductance_timing,
                is_reference: n == finest,
            },
            steps,
        ));
    }
    // The N and I models read the stack's ψ table from a table cache, as `strata solve`
    // does (the first call solves it there): a private one, so that the first run is
    // this study's; that first solve is timed on its own (`psi_timing`).
    let cache =
        StudyCache(std::env::temp_dir().join(format!("strata-study-psi-{}", std::process::id())));
    let mut psi_timing = None;
    for (label, model) in [
        ("N model", Model::Independent),
        (
            "I model, periodic 5×5",
            Model::Interacting(Images::Periodic(2)),
        ),
    ] {
        let (steps, hc) = runner
            .exact(|| asperity_curve(law.as_ref(), &surface, &stack, model, &deltas, &cache.0))?;
        if model == Model::Independent && layered {
            // the ψ table's first solve: the N model's conductance without the cache
            psi_timing = Some(runner.time(
                "conductance",
                "N model: conductance, ψ table solved (no table cache)",
                || spot_conductances(&stack, &rc, model, &steps, None),
            )?);
        }
        let timing = runner.time("conductance", label, || {
            asperity_curve(law.as_ref(), &surface, &stack, model, &deltas, &cache.0)
        })?;
        let conductance_timing =
            runner.time("conductance", &format!("{label}: conductance"), || {
                spot_conductances(&stack, &rc, model, &steps, Some(&cache.0))
            })?;
        rows.push((
            Row {
                label: label.into(),
                pressure: steps.iter().map(|s| s.mean_pressure / e_star).collect(),
                conductance: hc,
                rel_g: Vec::new(),
                g_error: f64::NAN,
                p_error: f64::NAN,
                p_steps: 0,
                timing,
                conductance_timing,
                is_reference: false,
            },
            steps,
        ));
    }
    let Some((reference, ref_steps)) = rows.iter().find(|(r, _)| r.is_reference).cloned() else {
        bail!("internal: no BEM reference");
    };
    for (r, steps) in rows.iter_mut() {
        let cmp = conductance_rows(
            [Some((steps.as_slice(), r.conductance.as_slice())), None],
            &ref_steps,
            &reference.conductance,
            scale,
        );
        r.rel_g = cmp.iter().map(|c| c.rel[0]).collect();
        r.g_error = max_abs(r.rel_g.iter().copied()).0;
        (r.p_error, r.p_steps) = max_abs(cmp.iter().map(|c| c.rel_at_p[0]));
        errors.push("conductance", &r.label, "h error (equal g)", r.g_error);
        errors.push("conductance", &r.label, "h error (equal p)", r.p_error);
        errors.push(
            "conductance",
            &r.label,
            "steps compared (equal p)",
            r.p_steps as f64,
        );
        for (i, h) in r.conductance.iter().enumerate() {
            errors.push("conductance", &r.label, &format!("h step {i}"), *h);
        }
    }
    let stack_words = if !layered {
        format!(
            "the top layer's homogeneous half-space with k = {TOP_CONDUCTIVITY} W/(m·K) (tiny mode)"
        )
    } else if own {
        "the scene's stack with its own thermal conductivities".to_string()
    } else {
        format!(
            "the scene's stack with the conductivities of `tables/stacks/paper-two-layer-conducting.toml` \
             (top layer {TOP_CONDUCTIVITY} W/(m·K), the layers below {LOWER_CONDUCTIVITY} W/(m·K), \
             an isothermal base)"
        )
    };
    Ok(Results {
        stack: format!(
            "{stack_words}, pressed by a rigid steel flat conducting with {FLAT_CONDUCTIVITY} W/(m·K)"
        ),
        summits: rc.summits().len(),
        separations,
        rows: rows.into_iter().map(|(r, _)| r).collect(),
        psi_timing,
    })
}

/// The summary's line: each non-reference model's errors and what its conductance adds.
pub fn summary(r: &Results) -> Option<String> {
    let reference = r.rows.iter().find(|x| x.is_reference)?;
    let models: Vec<String> = r
        .rows
        .iter()
        .filter(|x| !x.is_reference)
        .map(|x| {
            format!(
                "{} {} / {} (the conductance adds {:+.0} % to its {} curve)",
                x.label,
                super::fmt_err(x.g_error),
                super::fmt_err(x.p_error),
                100.0 * x.added(),
                super::fmt_time(x.timing.median)
            )
        })
        .collect();
    Some(format!(
        "Interface conductance, h_c error against the {} at equal g_n / equal p_n: {}.",
        reference.label,
        models.join("; ")
    ))
}

/// The report's section.
pub fn markdown(r: &Results) -> String {
    use std::fmt::Write;
    let mut w = String::new();
    let _ = writeln!(
        w,
        "## 7. Interface conductance\n\nThe thermal interface (constriction) conductance per \
         nominal area h_c (physics.md §6.2) on {}: the BEM's conduction solve on its contact \
         set at several grids (the finest is the reference), the N model's spots in parallel \
         and the I model's interacting spots ({} summits). Errors per model: the largest \
         |h/h_ref − 1| over the reference's steps, at equal separation g_n and at equal mean \
         pressure p_n (log–log in p between the model's own steps, where they bracket p_ref: \
         \"steps\" counts them), as `strata compare` reports them. Time per curve: the \
         mechanics and the conductance; the conductance's own time on the same curve \
         (the BEM: the conduction operator and a warm-started PCG per step; the N and I \
         models: the ψ table read from the table cache as `strata solve` reads it, the I \
         model's kernel table and spot network), and what it adds to the mechanics. The \
         BEM's curve here is one solve per step; `strata solve` also probes each step's \
         stiffness dP/dδ (a second solve), whose pressure increment starts the conduction \
         solve there, so its share is about half of this one's (docs/performance.md).{}\n",
        r.stack,
        r.summits,
        r.psi_timing.as_ref().map_or(String::new(), |t| format!(
            " A first run per stack solves the ψ table into the cache: the N model's \
             conductance then takes {} ({} runs).",
            super::fmt_time(t.median),
            t.runs
        ))
    );
    let _ = writeln!(
        w,
        "| model | h error (equal g_n) | h error (equal p_n) | steps | time per curve | conductance's own | adds to the mechanics | runs |\n|---|---|---|---|---|---|---|---|"
    );
    for row in &r.rows {
        let (ge, pe) = if row.is_reference {
            ("reference".to_string(), "—".to_string())
        } else {
            (super::fmt_err(row.g_error), super::fmt_err(row.p_error))
        };
        let _ = writeln!(
            w,
            "| {} | {ge} | {pe} | {} | {} | {} | {:+.0} % | {} |",
            row.label,
            row.p_steps,
            super::fmt_time(row.timing.median),
            super::fmt_time(row.conductance_timing.median),
            100.0 * row.added(),
            row.timing.runs
        );
    }
    if let Some(reference) = r.rows.iter().find(|x| x.is_reference) {
        let _ = writeln!(
            w,
            "\nPer load step: the reference's p_n and h_c, and the signed deviation \
             h/h_ref − 1 of each model at equal separation:\n"
        );
        let shown: Vec<&Row> = r.rows.iter().filter(|x| !x.is_reference).collect();
        let _ = write!(w, "| g_n (m) | p_n/E*₁ | h_c (W/(m²·K)) |");
        for x in &shown {
            let _ = write!(w, " {} |", x.label);
        }
        let _ = writeln!(w);
        let _ = writeln!(w, "|{}", "---|".repeat(3 + shown.len()));
        for (k, g) in r.separations.iter().enumerate() {
            let _ = write!(
                w,
                "| {:.3e} | {:.4e} | {:.4e} |",
                g, reference.pressure[k], reference.conductance[k]
            );
            for x in &shown {
                let _ = write!(w, " {:+.2e} |", x.rel_g.get(k).copied().unwrap_or(f64::NAN));
            }
            let _ = writeln!(w);
        }
    }
    let _ = writeln!(w);
    w
}
