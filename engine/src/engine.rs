//! Scene solving shared by every subcommand (`solve`, `law`, `sweep`, `compare`, `study`):
//! a validated [`Scene`] in, the load curve ([`Step`]s) and a JSON summary out.
//! No files are written here; the callers own their outputs.
//!
//! Only what the scene needs is computed: a homogeneous stack loads no table
//! (χ = ζ = 1, g = 0); a layered stack loads `stack.table` or builds the table once
//! into the cache and says so; the independent model forms no pairs; the BEM needs no
//! table (S is computed from the stack). The log (stderr, unless quiet) says which
//! effects were simulated.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::progress;
use crate::scene::{
    ConductanceSpec, CounterfaceConduction, LoadSpec, ModelKind, Scene, SurfaceSource,
};
use anyhow::{Context, Result, bail};
use strata_bem::{
    BemLoad, BemOptions, BemSolution, BemSolver, ConductanceOptions, ConductanceSolver, Conductor,
    Geometry,
};
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::resources;
use strata_runtime::rough::{Images, Model, RoughContact, RoughError, Step};
use strata_runtime::summits::find_summits;
use strata_runtime::surface::{GenerateParams, Surface};
use strata_runtime::table::Table;
use strata_tablegen::tablebuild::{Bars, BuildOptions};

/// The header of curve.csv: the columns every model writes per step (the effects add
/// theirs after `valid`).
pub const CURVE_HEADER: [&str; 8] = [
    "delta",
    "gap",
    "mean_pressure",
    "pressure_ratio",
    "area_fraction",
    "contacts",
    "stiffness",
    "valid",
];

/// How a scene is solved (not what: that is the scene).
#[derive(Debug, Clone, Default)]
pub struct EngineOptions {
    /// `--cache-dir`: where missing tables of layered stacks are built and cached
    /// (default: [`crate::cache::dir`]).
    pub cache_dir: Option<PathBuf>,
    /// No log lines or progress on stderr (sweeps, studies).
    pub quiet: bool,
    /// BEM only: solver options (tolerance…); `None` gives the defaults.
    pub bem: Option<BemOptions>,
    /// A table already in memory for a layered stack, used before `stack.table` and
    /// the cache (the Python package passes its `Table` objects this way).
    pub table: Option<std::sync::Arc<Table>>,
    /// Approach-controlled asperity models: when a step fails, return the steps solved
    /// before it with [`SceneSolution::failed`] set (the CLI's `solve` writes them as a
    /// partial curve) instead of an error.
    pub keep_partial: bool,
    /// Cancellation, checked between load steps and inside the BEM iteration and the
    /// I model's Newton steps (the Python package trips it on Ctrl-C): a cancelled
    /// solve returns an error and no result. Default: never cancelled.
    pub cancel: strata_runtime::cancel::Cancel,
}

/// The scene's `[solver]` parameters of the asperity models with the call's
/// cancellation token ([`EngineOptions::cancel`]).
pub fn solver_params(scene: &Scene, opts: &EngineOptions) -> strata_runtime::rough::Params {
    let mut p = scene.solver.params();
    p.cancel = opts.cancel.clone();
    p
}

/// The step at which a load path stopped ([`EngineOptions::keep_partial`]).
#[derive(Debug, Clone)]
pub struct StepFailure {
    /// Index of the failing step (= the number of steps solved before it).
    pub step: usize,
    /// Its approach δ (m).
    pub delta: f64,
    /// Why it failed.
    pub error: String,
}

/// Receives the BEM maps as they are solved: `(step, number of steps, solution)`.
/// Each map can be written and dropped at once, so `maps = "all"` never holds more
/// than one step's maps.
pub type MapSink<'a> = &'a mut dyn FnMut(usize, usize, BemSolution) -> Result<()>;

/// A solved scene.
#[derive(Debug, Clone)]
pub struct SceneSolution {
    /// One entry per load step, in the scene's order.
    pub steps: Vec<Step>,
    /// Summary for `curve.json`: model, solid, E*₁, nominal area, units…
    pub meta: serde_json::Value,
    /// Wall time of the solve, without table building (s).
    pub seconds: f64,
    /// Set when the path stopped early (only with [`EngineOptions::keep_partial`]).
    pub failed: Option<StepFailure>,
}

macro_rules! log {
    ($quiet:expr, $($t:tt)*) => { if !$quiet { progress::log(format!($($t)*)); } };
}

/// Checks the surface's size against the memory limit before it is generated (read
/// surfaces are checked by the reader, from the file's header).
fn check_surface_memory(scene: &Scene) -> Result<()> {
    if let SurfaceSource::Generate(g) = &scene.surface.source {
        check_generate_memory(g)?;
    }
    Ok(())
}

/// Checks the memory that generating the surface `g` needs against the limit.
pub fn check_generate_memory(g: &GenerateParams) -> Result<()> {
    let n = g.grid as u64;
    resources::check_memory(
        format!(
            "generating the {0}×{0} surface (surface.generate.grid)",
            g.grid
        ),
        resources::bytes_for(
            n.saturating_mul(n),
            strata_runtime::surface::GENERATE_BYTES_PER_POINT,
        ),
    )?;
    Ok(())
}

/// The scene's surface, read or generated after a memory check (what repair filled
/// is in its log, printed with the surface report).
pub fn load_surface(scene: &Scene, _quiet: bool) -> Result<Surface> {
    check_surface_memory(scene)?;
    Ok(scene.load_surface()?)
}

/// Table build options of the command line: progress through [`progress`].
fn build_options(quiet: bool) -> BuildOptions {
    BuildOptions {
        progress: !quiet,
        bars: Some(Bars(progress::raw_bar)),
        ..Default::default()
    }
}

/// The table of a layered `stack` from the cache (see [`crate::cache`]), built there
/// once if missing. The cache must be writable before a build starts.
pub fn cached_table(
    stack: &strata_runtime::Stack,
    cache_dir: Option<&Path>,
    quiet: bool,
    opts: Option<BuildOptions>,
) -> Result<(Table, PathBuf)> {
    let (dir, origin) = crate::cache::dir(cache_dir);
    crate::cache::ensure_writable(&dir, origin)?;
    log!(
        quiet,
        "stack: layered, no table given: using the table cache {} ({origin}; built once per stack)",
        dir.display()
    );
    let opts = opts.unwrap_or_else(|| build_options(quiet));
    let (t, p) =
        strata_tablegen::tablebuild::build_and_cache(stack, &dir, &opts).with_context(|| {
            format!(
                "building the table of the stack into the cache {}",
                dir.display()
            )
        })?;
    log!(quiet, "stack: table {}", p.display());
    Ok((t, p))
}

/// The reader's warnings and the plausibility warnings of the statistics
/// (`strata_runtime::surface::Surface::plausibility`).
pub fn surface_warnings(surface: &Surface) -> Vec<String> {
    let mut w: Vec<String> = surface.warnings().to_vec();
    w.extend(surface.plausibility());
    w
}

/// The statistics, repairs and reader log of a surface as JSON (curve.json
/// `surface`, `strata surface info --json`), SI units.
pub fn surface_json(surface: &Surface) -> serde_json::Value {
    let mut json = serde_json::to_value(surface.stats()).unwrap_or_default();
    json["repaired_points"] = serde_json::json!(surface.repaired());
    json["repair"] = surface
        .repair_report()
        .map_or(serde_json::Value::Null, |r| {
            serde_json::to_value(r).unwrap_or_default()
        });
    json["read"] = serde_json::json!(surface.log());
    json["form"] = surface.form().map_or(serde_json::Value::Null, form_json);
    json["units"] = serde_json::json!({"shape": "points (x, y)", "pixel_size": "m", "size": "m",
        "mean_height": "m", "rms_height": "m", "rms_slope": "1", "peak_to_valley": "m",
        "repair": {"fraction": "1", "iterations": "1", "else": "points"},
        "form": {"slope_x": "1", "slope_y": "1", "curvature_xx": "1/m", "curvature_xy": "1/m",
                 "curvature_yy": "1/m", "form_rms": "m", "roughness_rms": "m"}});
    json
}

/// The removed form (curve.json `surface.form`): the kind, the tilt as slopes z_x, z_y,
/// the second derivatives for `"curvature"`, the RMS of the removed form and of the
/// remaining roughness (m). The statistics beside it are those of the remaining
/// roughness.
fn form_json(f: &strata_runtime::surface::Form) -> serde_json::Value {
    let mut j = serde_json::json!({
        "detrend": f.kind.name(),
        "slope_x": f.slope.0,
        "slope_y": f.slope.1,
        "form_rms": f.rms,
        "roughness_rms": f.residual_rms,
    });
    if f.kind == strata_runtime::surface::Detrend::Curvature {
        j["curvature_xx"] = serde_json::json!(f.curvature.0);
        j["curvature_xy"] = serde_json::json!(f.curvature.1);
        j["curvature_yy"] = serde_json::json!(f.curvature.2);
    }
    j
}

/// Logs what the reader did (units, repairs, form removal, file metadata) and the
/// surface statistics, prints every warning ([`surface_warnings`]) on stderr even
/// when `quiet`, and returns [`surface_json`] with the warnings.
pub fn surface_report(surface: &Surface, quiet: bool) -> (serde_json::Value, Vec<String>) {
    for line in surface.log() {
        log!(quiet, "surface: {line}");
    }
    log!(quiet, "surface: {}", surface.stats().describe());
    let warnings = surface_warnings(surface);
    for w in &warnings {
        progress::warn(format_args!("surface: {w}"));
    }
    (surface_json(surface), warnings)
}

/// The asperity law of the scene's stack: Hertz for a homogeneous stack, otherwise
/// the surrogate table: `stack.table` (which must exist: an input is never written),
/// or the cache.
pub fn law_for(
    scene: &Scene,
    _scene_path: &Path,
    opts: &EngineOptions,
) -> Result<Box<dyn AsperityLaw>> {
    let quiet = opts.quiet;
    let stack = &scene.stack;
    if stack.is_homogeneous() {
        log!(
            quiet,
            "stack: homogeneous (E* = {:e} Pa): Hertz asperities, no table loaded",
            stack.contact_modulus()
        );
        return Ok(Box::new(Homogeneous {
            e_star: stack.contact_modulus(),
        }));
    }
    // With an elastic counterface the scene's table is `counterface.table` (of the pair).
    let (field, what) = if stack.counterface().is_some() {
        ("counterface.table", "pair (stack and counterface)")
    } else {
        ("stack.table", "stack")
    };
    let table = match (&opts.table, &scene.table) {
        (Some(t), _) => {
            log!(quiet, "stack: layered, table given in memory");
            Table::clone(t)
        }
        (None, Some(p)) => {
            log!(quiet, "stack: layered, table {}", p.display());
            Table::load(p).with_context(|| format!("{field} {}", p.display()))?
        }
        (None, None) => cached_table(stack, opts.cache_dir.as_deref(), quiet, None)?.0,
    };
    let law = table.law_for(stack).with_context(|| match &scene.table {
        Some(p) => format!("{field} {} does not serve the scene's {what}", p.display()),
        None => format!("the table does not serve the scene's {what}"),
    })?;
    Ok(Box::new(law))
}

/// Solves a scene with the model it names (BEM maps, if any, are dropped).
pub fn solve_scene(
    scene: &Scene,
    scene_path: &Path,
    opts: &EngineOptions,
) -> Result<SceneSolution> {
    solve_scene_with_maps(scene, scene_path, opts, &mut |_, _, _| Ok(()))
}

/// [`solve_scene`] on a surface already loaded (BEM maps, if any, are dropped).
pub fn solve_surface(
    scene: &Scene,
    scene_path: &Path,
    surface: Surface,
    opts: &EngineOptions,
) -> Result<SceneSolution> {
    solve_surface_with_maps(scene, scene_path, surface, opts, &mut |_, _, _| Ok(()))
}

/// [`solve_scene`], handing every BEM step's maps to `maps` as soon as it is solved.
pub fn solve_scene_with_maps(
    scene: &Scene,
    scene_path: &Path,
    opts: &EngineOptions,
    maps: MapSink<'_>,
) -> Result<SceneSolution> {
    let surface = load_surface(scene, opts.quiet)?;
    solve_surface_with_maps(scene, scene_path, surface, opts, maps)
}

/// [`solve_scene_with_maps`] on a surface already loaded (or built in memory, as the
/// Python package does): the scene's `[surface]` is not read again.
pub fn solve_surface_with_maps(
    scene: &Scene,
    scene_path: &Path,
    surface: Surface,
    opts: &EngineOptions,
    maps: MapSink<'_>,
) -> Result<SceneSolution> {
    if let Some(e) = surface.nothing_left() {
        return Err(e.into());
    }
    let model = match scene.model.kind {
        ModelKind::Independent => Model::Independent,
        ModelKind::Interacting => Model::Interacting(scene.model.images),
        ModelKind::Bem => return solve_bem(scene, scene_path, surface, opts, maps),
    };
    // the I model's conduction kernel (its table's cap) checked before any work: a
    // refusal after the mechanical solve would waste it
    if let (Some(spec), Model::Interacting(images)) = (&scene.conductance, model) {
        crate::spots::SpotSum::new(scene, spec)?
            .check_kernel(surface.extent(), images)
            .context("[conductance]")?;
    }
    if let (Some(pl), false) = (scene.plasticity, scene.unload) {
        return solve_plastic_asperities(scene, scene_path, surface, opts, pl.hardness, model);
    }
    if scene.unload {
        bail!(
            "load.unload is solved by the BEM in this version (model.kind = \"bem\"); the N and \
             I models with [plasticity] follow the loading path only"
        );
    }
    let quiet = opts.quiet;
    let (surface_json, warnings) = surface_report(&surface, quiet);
    let found = find_summits(&surface);
    log!(
        quiet,
        "surface: {} summits ({} dropped for κ ≤ 0)",
        found.summits.len(),
        found.dropped_nonpositive_curvature
    );
    let law = law_for(scene, scene_path, opts)?;
    let t0 = Instant::now();
    let rc =
        RoughContact::from_surface(law.as_ref(), &surface)?.with_params(solver_params(scene, opts));
    let effects = model_description(model);
    let layered = if law.is_homogeneous() {
        "homogeneous solid (χ = ζ = 1, g = 0)"
    } else {
        "layered solid (χ, ζ from the table; g too for the I model)"
    };
    log!(quiet, "simulating: {effects}; {layered}");
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
        log!(quiet, "{what} (δ = {delta:e} m): refused: {e}");
        (i, e)
    };
    let mut failed = None;
    let steps: Vec<Step> = match scene
        .load
        .approaches(rc.top_to_mean(), f64::INFINITY)
        .context("load")?
    {
        Some(d) => {
            let _spin = (!quiet).then(|| {
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
                        return Err(anyhow::Error::from(e).context(at));
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
                bail!("load: internal error");
            };
            let bar = (!quiet).then(|| {
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
                    return Err(anyhow::Error::from(e).context(field));
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
    let mut seconds = t0.elapsed().as_secs_f64();
    for (i, s) in steps.iter().enumerate() {
        if !s.validity.is_valid() {
            log!(
                quiet,
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
            quiet,
            "I model: largest KKT residual {w:.2e} (relative to the largest interference)"
        );
    }
    let meta = asperity_meta(
        scene,
        scene_path,
        (&effects, &model_short(model), layered),
        law.e_star(),
        &rc,
        (surface_json, warnings),
        seconds,
    );
    let mut meta = meta;
    add_counterface_meta(&mut meta, scene);
    if let Some(spec) = &scene.conductance {
        // the model's time includes its conductance, as the BEM's does
        seconds += asperity_conductance(scene, spec, (&steps, &rc, model), opts, &mut meta)?;
        meta["seconds"] = serde_json::json!(seconds);
    }
    if let Some(f) = &failed {
        meta["partial"] = serde_json::json!({
            "failed_step": f.step, "delta": f.delta, "error": f.error,
            "note": "the path stopped at this step: the steps before it are written",
        });
    }
    Ok(SceneSolution {
        steps,
        meta,
        seconds,
        failed,
    })
}

/// What the model simulates, for logs and `curve.json`.
fn model_description(model: Model) -> String {
    match model {
        Model::Independent => {
            "independent asperities (N model): no interactions, no pairs".to_string()
        }
        Model::Interacting(Images::Isolated) => {
            "interacting asperities (I model), isolated sample: interactions inside the sample only"
                .into()
        }
        Model::Interacting(Images::Periodic(m)) => format!(
            "interacting asperities (I model), periodic images on a {0}×{0} block of cells",
            2 * m + 1
        ),
    }
}

/// The model's short name for plot titles and legends: `N model`, `I model (periodic
/// 5×5)`, `I model (isolated)`.
pub fn model_short(model: Model) -> String {
    match model {
        Model::Independent => "N model".into(),
        Model::Interacting(Images::Isolated) => "I model (isolated)".into(),
        Model::Interacting(Images::Periodic(m)) => {
            format!("I model (periodic {0}×{0})", 2 * m + 1)
        }
    }
}

/// A modulus in a readable unit: `4 GPa`, `210 GPa`, `800 MPa`.
fn modulus(e: f64) -> String {
    let (v, unit) = if e >= 1e9 {
        (e * 1e-9, "GPa")
    } else if e >= 1e6 {
        (e * 1e-6, "MPa")
    } else if e >= 1e3 {
        (e * 1e-3, "kPa")
    } else {
        (e, "Pa")
    };
    format!("{} {unit}", crate::number::tick((v * 1e3).round() / 1e3))
}

/// curve.json's `counterface` entry when the scene has an elastic counterface (and a
/// rough one's note): the pair's E* is what `e_star_1` and `pressure_ratio` use.
pub fn add_counterface_meta(meta: &mut serde_json::Value, scene: &Scene) {
    let Some(c) = scene.stack.counterface() else {
        return;
    };
    meta["counterface"] = serde_json::json!({
        "stack": stack_description(c),
        "e_star_1_counterface": c.top_plane_strain_modulus(),
        "e_star_1_body": scene.stack.top_plane_strain_modulus(),
        "e_star_pair": scene.stack.contact_modulus(),
        "rough": scene.counterface_surface.is_some(),
        "note": "two elastic bodies (physics.md §6.1): e_star_1 and pressure_ratio are the pair's, \
                 1/E* = 1/E*1,body + 1/E*1,counterface; a rough counterface's heights are added to the body's",
    });
}

/// A stack in a few words for plot titles: its name, else its make-up
/// (`2 layers on a rigid base, E1 = 4 GPa`, `half-space, E = 210 GPa`).
pub fn stack_description(stack: &strata_runtime::Stack) -> String {
    if let Some(n) = &stack.name {
        return n.clone();
    }
    if let Some(c) = stack.counterface() {
        return format!(
            "{} against {}",
            stack_description(&stack.body()),
            stack_description(c)
        );
    }
    if stack.is_homogeneous() {
        return format!("half-space, E = {}", modulus(stack.top_material().0));
    }
    let base = match stack.base() {
        strata_runtime::Base::Rigid => "a rigid base".to_string(),
        strata_runtime::Base::Elastic { young, .. } => format!("a {} base", modulus(young)),
    };
    let n = stack.layers().len();
    format!(
        "{n} layer{} on {base}, E1 = {}",
        if n == 1 { "" } else { "s" },
        modulus(stack.top_material().0)
    )
}

/// `model.kind = "bem"`: the FFT boundary-element solution of the whole surface
/// (strata-bem): on a periodic surface with the layered kernel 2S(|k|)/(E*₁|k|), on a
/// non-periodic one with the pixel influence coefficients of the free solid, both
/// computed from the stack (no χ, ζ, g table is needed or loaded). Same steps as the asperity models;
/// `contacts` counts contact patches and the stiffness dP/dδ comes from one extra,
/// warm-started solve at δ(1 + 1e-4) per step (its error ~ tolerance/1e-4 ≈ 1e-6).
fn solve_bem(
    scene: &Scene,
    scene_path: &Path,
    surface: Surface,
    opts: &EngineOptions,
    maps: MapSink<'_>,
) -> Result<SceneSolution> {
    let quiet = opts.quiet;
    let (surface_json, mut warnings) = surface_report(&surface, quiet);
    let (n0, n1) = surface.shape();
    let periodic = surface.is_periodic();
    let heights = ndarray::Array2::from_shape_vec((n0, n1), surface.heights().to_vec())
        .context("surface: heights")?;
    // Rows (first index, n0 points) span extent().0, columns extent().1.
    let (rows_side, cols_side) = surface.extent();
    let geometry = Geometry {
        lx: cols_side,
        ly: rows_side,
        periodic,
    };
    let stack = &scene.stack;
    let t0 = Instant::now();
    let bem_options = scene.solver.bem_options(opts.bem.unwrap_or_default());
    let solver = BemSolver::with_geometry(&heights, geometry, stack, bem_options)
        .context("model.kind = \"bem\"")?
        .with_cancel(opts.cancel.clone());
    drop(heights);
    let z_max = surface.heights().iter().copied().fold(f64::MIN, f64::max);
    let top_to_mean = z_max - surface.mean();
    let solid = if stack.is_homogeneous() {
        "homogeneous solid (kernel 2/(E*|k|))".to_string()
    } else {
        format!(
            "layered solid ({} layers; kernel 2S(|k|)/(E*₁|k|) with S computed from the stack)",
            stack.layers().len()
        )
    };
    let effects = if periodic {
        format!("full-field boundary elements on the {n0}×{n1} grid, periodic")
    } else {
        format!(
            "full-field boundary elements on the {n0}×{n1} grid, non-periodic (isolated sample on an unbounded solid: zero-padded convolution with pixel influence coefficients)"
        )
    };
    log!(quiet, "simulating: {effects}; {solid}");
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
                bail!("load: internal error");
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
    let area = solver.area();
    let total = loads.len();
    let bar = (!quiet).then(|| progress::bar(total as u64, format!("BEM {n0}×{n1}: load steps")));
    let mut steps = Vec::with_capacity(total);
    let mut warm: Option<Vec<f64>> = None;
    let mut worst_error = 0.0f64;
    let mut plastic = match scene.plasticity {
        Some(pl) => {
            log!(
                quiet,
                "plasticity: pressure capped by the hardness H = {:e} Pa (capped preconditioned CG, MPRGP where it stalls; the plastic depth is kept along the path)",
                pl.hardness
            );
            Some(strata_bem::PlasticPath::new(&solver, pl.hardness).context("plasticity")?)
        }
        None => None,
    };
    let mut plastic_steps = Vec::new();
    let conduction = match &scene.conductance {
        Some(spec) => Some(conductance_solver(scene, spec, (n0, n1), geometry, quiet)?),
        None => None,
    };
    let mut conductance_steps = Vec::new();
    let mut conductance_seconds = 0.0;
    let mut flux: Option<Vec<f64>> = None;
    let mut failed = None;
    let mut resolution: Vec<StepResolution> = Vec::with_capacity(total);
    for (k, (name, load)) in loads.into_iter().enumerate() {
        opts.cancel.check()?;
        // One step; an error here stops the path (below: a partial curve or the error).
        let mut one_step = || -> Result<strata_bem::BemSolution> {
            let (sol, next, dd) = if let Some(path) = plastic.as_mut() {
                // the tangent from a copy of the path: the state is advanced by `step` only
                let mut probe = path.clone();
                let (sol, info) = path.step(load).with_context(|| name.clone())?;
                let dd = 1e-4 * sol.approach.abs().max(1e-3 * surface.rms());
                let (next, _) = probe
                    .step(BemLoad::Approach(sol.approach + dd))
                    .with_context(|| format!("{name}: stiffness"))?;
                plastic_steps.push(serde_json::json!({
                    "plastic_area_fraction": info.plastic_area_fraction,
                    "plastic_points": info.plastic_points,
                    "plastic_depth_max": info.plastic_depth_max,
                    "plastic_depth_mean": info.plastic_depth_mean,
                    "kkt_bounded": sol.error,
                    "bounded_iterations": sol.iterations,
                    "offset_iterations": info.offset_iterations,
                    "active_set_steps": info.active_set_steps,
                    "bounded_fallback": info.bounded_fallback,
                }));
                (sol, next, dd)
            } else {
                let sol = solver
                    .solve_from(load, warm.as_deref())
                    .with_context(|| name.clone())?;
                let flat: Vec<f64> = sol.pressure.iter().copied().collect();
                let dd = 1e-4 * sol.approach.abs().max(1e-3 * surface.rms());
                let next = solver
                    .solve_from(BemLoad::Approach(sol.approach + dd), Some(&flat))
                    .with_context(|| format!("{name}: stiffness"))?;
                (sol, next, dd)
            };
            let flat: Vec<f64> = sol.pressure.iter().copied().collect();
            resolution.push(StepResolution::of(&flat, n0, n1, periodic));
            worst_error = worst_error.max(sol.error).max(next.error);
            let mut st = Step::default();
            st.delta = sol.approach;
            st.gap = sol.separation;
            st.load = sol.total_load;
            st.mean_pressure = sol.mean_pressure;
            st.pressure_ratio = sol.pressure_ratio;
            st.area_fraction = sol.area_fraction;
            st.contacts = sol.patches;
            st.stiffness = (next.total_load - sol.total_load) / dd;
            st.iterations = sol.iterations;
            steps.push(st);
            if let Some(cs) = &conduction {
                // physics.md §6.2: a unit jump on this step's contact set (p > 0)
                let tc = Instant::now();
                let set: Vec<bool> = flat.iter().map(|&p| p > 0.0).collect();
                // the start: the previous step's flux and this step's pressure increment
                // (the exact flux on homogeneous bodies by Barber's analogy), best combined
                let dp: Vec<f64> = next
                    .pressure
                    .iter()
                    .zip(&flat)
                    .map(|(a, b)| a - b)
                    .collect();
                let guesses: Vec<&[f64]> = flux.as_deref().into_iter().chain([&dp[..]]).collect();
                let h = cs
                    .solve_from_guesses(&set, &guesses)
                    .with_context(|| format!("{name}: conductance"))?;
                conductance_seconds += tc.elapsed().as_secs_f64();
                conductance_steps.push(serde_json::json!({
                    "conductance": h.conductance,
                    "conductance_iterations": h.iterations,
                    "conductance_residual": h.residual,
                }));
                flux = h.conductance.is_finite().then_some(h.flux);
            }
            warm = Some(flat);
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
                plastic_steps.truncate(k);
                conductance_steps.truncate(k);
                resolution.truncate(k);
                log!(
                    quiet,
                    "{name} failed: {e:#}; the {k} steps before it are kept (a partial curve)"
                );
                failed = Some(StepFailure {
                    step: k,
                    delta: match load {
                        BemLoad::Approach(d) => d,
                        BemLoad::Separation(g) => top_to_mean - g,
                        _ => f64::NAN,
                    },
                    error: format!("{e:#}"),
                });
                break;
            }
        };
        maps(k, total, sol)?;
        if let Some(b) = &bar {
            b.inc();
        }
    }
    drop(bar);
    let seconds = t0.elapsed().as_secs_f64();
    log!(quiet, "BEM: largest final CG error {worst_error:.2e}");
    let e_star = stack.contact_modulus();
    for w in resolution_warnings(&resolution, e_star, scene.plasticity.is_some()) {
        progress::warn(format_args!("{w}"));
        warnings.push(w);
    }
    let meta = serde_json::json!({
        "scene": scene_path.display().to_string(),
        "model": effects,
        "model_short": "BEM",
        "stack": stack_description(stack),
        "solid": solid,
        "e_star_1": stack.contact_modulus(),
        "nominal_area": area,
        "z_max_minus_mean": top_to_mean,
        "surface": surface_json,
        "warnings": warnings,
        "bem_final_error": worst_error,
        "seconds": seconds,
        "units": {"delta": "m", "gap": "m", "mean_pressure": "Pa", "pressure_ratio": "1",
                  "area_fraction": "1", "stiffness": "N/m (dP/dδ of the sample)",
                  "contacts": "contact patches"},
    });
    let mut meta = meta;
    meta["resolution"] = resolution_meta(&resolution, e_star);
    add_counterface_meta(&mut meta, scene);
    if let Some(pl) = scene.plasticity {
        meta["plasticity"] = serde_json::json!({
            "hardness": pl.hardness,
            "note": "elastic–perfectly plastic surface (physics.md §6.3): 0 ≤ p ≤ H; points at p = H flow, \
                     their overlap kept as plastic depth for the rest of the path; stiffness = dP/dδ for an \
                     increase of δ from each step's state",
            "units": {"plastic_area_fraction": "1", "plastic_depth_max": "m", "plastic_depth_mean": "m (flattened volume / A0)",
                      "kkt_bounded": "largest KKT violation of the bounded problem / RMS height"},
        });
        meta["plastic_steps"] = serde_json::Value::Array(plastic_steps);
    }
    if let Some(spec) = &scene.conductance {
        meta["conductance"] = conductance_meta(scene, spec);
        if !geometry.periodic {
            meta["conductance"]["definition"] = serde_json::json!(
                "interface (spreading) conductance per nominal area h_c = sum(q)/(N dT) for a uniform jump dT \
                 on the contact set (p > 0) of the isolated sample and no flux elsewhere, both bodies unbounded \
                 (free-boundary kernel: zero-padded convolution with the pixel coefficients of the layered \
                 point-source field; no k = 0 mode to exclude) (physics.md 6.2)"
            );
        }
        meta["conductance"]["seconds"] = serde_json::json!(conductance_seconds);
        meta["conductance_steps"] = serde_json::Value::Array(conductance_steps);
    }
    if let Some(f) = &failed {
        meta["partial"] = serde_json::json!({
            "failed_step": f.step, "delta": f.delta, "error": f.error,
            "note": "the path stopped at this step: the steps before it are written",
        });
    }
    Ok(SceneSolution {
        steps,
        meta,
        seconds,
        failed,
    })
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
struct StepResolution {
    /// Median patch size (pixels); `None` without contact.
    median_patch_pixels: Option<f64>,
    /// Largest patch (pixels).
    largest_patch_pixels: usize,
    /// Peak pressure (Pa).
    peak_pressure: f64,
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
fn resolution_meta(steps: &[StepResolution], e_star: f64) -> serde_json::Value {
    serde_json::json!({
        "patch_pixels_min": PATCH_PIXELS_MIN,
        "peak_pressure_max_over_e_star": PEAK_PRESSURE_MAX_OVER_E_STAR,
        "note": "median_patch_pixels below patch_pixels_min: the typical contact patch is resolved by too few \
                 pixels (a Hertzian patch of ~10 pixels has its area ~20 % off); peak pressures above \
                 peak_pressure_max_over_e_star × E* are beyond the hardness of any real solid (use [plasticity])",
        "steps": steps.iter().map(|s| serde_json::json!({
            "median_patch_pixels": s.median_patch_pixels,
            "largest_patch_pixels": s.largest_patch_pixels,
            "peak_pressure": s.peak_pressure,
            "peak_pressure_over_e_star": s.peak_pressure / e_star,
        })).collect::<Vec<_>>(),
        "units": {"median_patch_pixels": "pixels", "largest_patch_pixels": "pixels", "peak_pressure": "Pa",
                  "peak_pressure_over_e_star": "1"},
    })
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
fn resolution_warnings(steps: &[StepResolution], e_star: f64, plastic: bool) -> Vec<String> {
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

/// The N and I models with capped tips (`[plasticity]`, physics.md §9): the capped
/// asperity's response table for the scene's stack and hardness (ring solves, built
/// here), then every summit through it at each approach (or at the approach of each
/// mean pressure, by bisection on δ, the load being monotone in it); the I model's
/// summits interact through the far field of their actual loads
/// (`RoughContact::solve_interacting_plastic`).
fn solve_plastic_asperities(
    scene: &Scene,
    scene_path: &Path,
    surface: Surface,
    opts: &EngineOptions,
    hardness: f64,
    model: Model,
) -> Result<SceneSolution> {
    let quiet = opts.quiet;
    let e_star = scene.stack.contact_modulus();
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
        && let Some(sol) =
            solve_elastic_tips(scene, scene_path, surface.clone(), opts, hardness, model)?
    {
        return Ok(sol);
    }
    let (surface_json, warnings) = surface_report(&surface, quiet);
    let found = find_summits(&surface);
    let t0 = Instant::now();
    // the elastic law: the I model's interactions, and every summit below the table
    let law = law_for(scene, scene_path, opts)?;
    let rc =
        RoughContact::from_surface(law.as_ref(), &surface)?.with_params(solver_params(scene, opts));
    log!(
        quiet,
        "plasticity: pressure capped by the hardness H = {hardness:e} Pa; the capped asperity's response table (ring solves, kept in the table cache)"
    );
    // a summit loaded past the table's lower end where the table has no y for it:
    // refused before the table is built (when the approaches are known)
    let uncovered_summit = |summit: usize, radius: f64, y: f64| {
        anyhow::Error::from(crate::law_build::UncoveredSummit { summit, radius, y })
    };
    if let Some((_, d)) = &approaches
        && let Some(h1) = scene
            .stack
            .top_thickness()
            .filter(|_| !scene.stack.is_homogeneous())
    {
        let (lo, hi, _) = strata_tablegen::plastic_asperity::RESPONSE_Y;
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
    let resp = crate::cache::capped_response(&scene.stack, hardness, &cache, quiet)
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
    log!(quiet, "simulating: {what}; {} summits", found.summits.len());
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
                bail!("load: internal error");
            };
            let mut out = Vec::with_capacity(ps.len());
            for (i, &p) in ps.iter().enumerate() {
                let f = |d: f64| -> Result<f64> { Ok(solve(d, &[])?.0.mean_pressure - p) };
                let (mut lo, mut hi) = (0.0, rc.max_delta().max(1e-12));
                let mut grow = 0;
                while f(hi)? < 0.0 {
                    lo = hi;
                    hi *= 2.0;
                    grow += 1;
                    if grow > 60 {
                        bail!(
                            "load.mean_pressures[{i}]: {p:e} Pa is out of reach of the capped N model"
                        );
                    }
                }
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if f(mid)? < 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                    if hi - lo <= 1e-14 * hi {
                        break;
                    }
                }
                out.push(0.5 * (lo + hi));
            }
            out
        }
    };
    let mut steps = Vec::with_capacity(deltas.len());
    let mut plastic_steps = Vec::with_capacity(deltas.len());
    // Approaches: the capped curve (the I model from its elastic load path, so that
    // steps where no summit yields are the elastic steps bit for bit); mean pressures:
    // each step at the approach its bisection found.
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
                return Err(anyhow::Error::from(e).context(format!("load.mean_pressures[{i}]")));
            }
            warm = r.0.radii.clone();
            out.push(r);
        }
        out
    } else {
        rc.capped_curve(&resp, model, &deltas)
            .map_err(|(i, e)| anyhow::Error::from(e).context(format!("load step {i}")))?
    };
    for (i, (s, plastic)) in solved.into_iter().enumerate() {
        let d = s.delta;
        if !s.validity.is_valid() {
            log!(
                quiet,
                "warning: load step {i} (δ = {d:e} m) is outside the asperity model's validity: {} (use model.kind = \"bem\" for this load)",
                s.validity.describe()
            );
        }
        plastic_steps.push(serde_json::json!({"plastic_area_fraction": plastic}));
        steps.push(s);
    }
    let seconds = t0.elapsed().as_secs_f64();
    let mut meta = asperity_meta(
        scene,
        scene_path,
        (
            what,
            &model_short(model),
            if interacting.is_some() {
                "the capped asperity's response table (ring solves in physical space); the elastic law's far field for the interactions"
            } else {
                "the capped asperity's response table (ring solves in physical space)"
            },
        ),
        scene.stack.contact_modulus(),
        &rc,
        (surface_json, warnings),
        seconds,
    );
    add_counterface_meta(&mut meta, scene);
    meta["plasticity"] = serde_json::json!({
        "hardness": hardness,
        "note": "elastic–perfectly plastic tips (physics.md §9): each summit a capped paraboloid, its response \
                 P = P_c F(δ/δ_c, a_c/h1), a = a_c G(…) tabulated from ring solves (I model: the summits \
                 interact through the far field of their actual loads; where none yields, the elastic I \
                 model's solution); loading only",
    });
    meta["plastic_steps"] = serde_json::Value::Array(plastic_steps);
    let mut seconds = seconds;
    if let Some(spec) = &scene.conductance {
        // the capped tips' contact radii conduct as the elastic ones do (physics.md §6.2)
        seconds += asperity_conductance(scene, spec, (&steps, &rc, model), opts, &mut meta)?;
        meta["seconds"] = serde_json::json!(seconds);
    }
    Ok(SceneSolution {
        steps,
        meta,
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
    scene_path: &Path,
    surface: Surface,
    opts: &EngineOptions,
    hardness: f64,
    model: Model,
) -> Result<Option<SceneSolution>> {
    let e_star = scene.stack.contact_modulus();
    let mut elastic = scene.clone();
    elastic.plasticity = None;
    let law = law_for(scene, scene_path, opts)?;
    let rc = RoughContact::from_surface(law.as_ref(), &surface)?;
    let mut sol =
        solve_surface_with_maps(&elastic, scene_path, surface, opts, &mut |_, _, _| Ok(()))?;
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
        opts.quiet,
        "plasticity: no summit reaches δ = {:e}·δ_c (δ_c = (πH/2E*)²R, H = {hardness:e} Pa) on this path: every tip is elastic, the elastic model's solution is the capped one (no response table needed)",
        strata_runtime::rough::plastic::ELASTIC_X
    );
    sol.meta["plasticity"] = serde_json::json!({
        "hardness": hardness,
        "note": "elastic–perfectly plastic tips (physics.md §9); no summit reaches the capped response \
                 table's range (δ ≥ 0.01 δ_c, δ_c = (πH/2E*)²R) on this load path, so every tip is elastic \
                 and the steps are the elastic model's; loading only",
    });
    sol.meta["plastic_steps"] = serde_json::Value::Array(
        sol.steps
            .iter()
            .map(|_| serde_json::json!({"plastic_area_fraction": 0.0}))
            .collect(),
    );
    Ok(Some(sol))
}

/// The conduction solver of a `[conductance]` scene on the BEM's periodic grid
/// (physics.md §6.2): the first body's conduction compliance and the counterface's.
fn conductance_solver(
    scene: &Scene,
    spec: &ConductanceSpec,
    (n0, n1): (usize, usize),
    geometry: Geometry,
    quiet: bool,
) -> Result<ConductanceSolver> {
    let body = spec.body(&scene.stack)?;
    let other = spec.counterface_stack(&scene.stack)?;
    let b = match (spec.counterface, &other) {
        (CounterfaceConduction::Perfect, _) => Conductor::Perfect,
        (CounterfaceConduction::HalfSpace(k), _) => Conductor::HalfSpace(k),
        (CounterfaceConduction::Stack, Some(c)) => Conductor::Layered(c),
        (CounterfaceConduction::Stack, None) => bail!("counterface: internal error (no stack)"),
    };
    log!(
        quiet,
        "conductance: {} interface conductance per nominal area on each step's contact set ({}; {})",
        spec.kind.name(),
        counterface_conduction(spec),
        if geometry.periodic {
            "k = 0 mode excluded"
        } else {
            "isolated sample on unbounded bodies: free-boundary kernel"
        }
    );
    ConductanceSolver::new(
        n0,
        n1,
        geometry,
        Conductor::Layered(&body),
        b,
        ConductanceOptions::default(),
    )
    .context("[conductance]")
}

/// The counterface's conduction in words.
fn counterface_conduction(spec: &ConductanceSpec) -> String {
    match spec.counterface {
        CounterfaceConduction::Perfect => "the counterface a perfect conductor".into(),
        CounterfaceConduction::HalfSpace(k) => format!(
            "the rigid counterface a conducting half-space, {k:e} {}",
            spec.kind.conductivity_unit()
        ),
        CounterfaceConduction::Stack => "the counterface conducting through its stack".into(),
    }
}

/// The N or I model's interface conductance of `steps` (physics.md §6.2) into `meta`
/// (`conductance`, `conductance_steps`): the N model's spots conduct in parallel, each
/// body in series; the I model's heat each other through both bodies. The contact radii
/// are the steps' own, elastic or capped (a capped tip's contact is a disc of its contact
/// radius, whatever its pressure). Returns the seconds it took.
fn asperity_conductance(
    scene: &Scene,
    spec: &ConductanceSpec,
    (steps, rc, model): (&[Step], &RoughContact<'_>, Model),
    opts: &EngineOptions,
    meta: &mut serde_json::Value,
) -> Result<f64> {
    let quiet = opts.quiet;
    // physics.md §6.2: the N model's spots conduct in parallel, each body in series;
    // the I model's heat each other through both bodies
    meta["conductance"] = conductance_meta(scene, spec);
    // ψ tables of layered sides live in the table cache: solved once per stack
    let psi_cache = crate::cache::dir(opts.cache_dir.as_deref()).0;
    let sum = crate::spots::SpotSum::new(scene, spec)?.with_cache(Some(psi_cache));
    let tc = Instant::now();
    let h = match model {
        Model::Independent => {
            log!(
                quiet,
                "conductance: {} conductance of the spots in parallel (Σ G(a)/A0, G = 4k1·a·ψ(a) per body, bodies in series; {}; no interactions)",
                spec.kind.name(),
                counterface_conduction(spec)
            );
            meta["conductance"]["definition"] = serde_json::json!(
                "N model: h_c = sum of the spots' conductances G(a_i) / A0, G = 4 k1 a psi(a) per body (an \
                 isothermal disc; psi = 1 on a homogeneous body, else the Fredholm spot solver, interpolated \
                 in ln a), the two bodies in series, no thermal interactions between the spots (physics.md 6.2)"
            );
            sum.conductances(steps, rc.area())
                .context("[conductance]")?
        }
        Model::Interacting(images) => {
            let t = Instant::now();
            let (h, info) = sum
                .interacting(steps, rc.summits(), rc.extent(), images)
                .context("[conductance]")?;
            log!(
                quiet,
                "conductance: {} conductance of interacting spots (Σ_j (δ_ij/G_i + I_ij) Q_j = ΔT, G = 4k1·a·ψ(a) per body, bodies in series, I_ij the layered point-source fields{}; {}) in {:.3} s",
                spec.kind.name(),
                match images {
                    Images::Periodic(_) => format!(
                        " with periodic images, k = 0 mode excluded, kernel table {}×{}",
                        info.grid.0, info.grid.1
                    ),
                    Images::Isolated => ", isolated sample".into(),
                },
                counterface_conduction(spec),
                t.elapsed().as_secs_f64()
            );
            meta["conductance"]["definition"] = serde_json::json!(
                "I model: the spots (isothermal discs of conductance G(a_i) = 4 k1 a psi(a) per body, the two \
                 bodies in series) heat each other through both bodies' point-source fields: \
                 sum_j (delta_ij / G_i + I_ij) Q_j = dT, h_c = sum Q_i / (dT A0), I_ij the temperature rise \
                 at spot i per unit heat into spot j (periodic images with the uniform k = 0 mode excluded, \
                 or an isolated sample) (physics.md 6.2)"
            );
            meta["conductance"]["kernel"] = serde_json::json!({
                "grid": [info.grid.0, info.grid.1],
                "ewald_width": info.sigma,
                "spectrum_extent": info.rho_max,
                "self_images": info.self_images,
            });
            h
        }
    };
    let tcs = tc.elapsed().as_secs_f64();
    log_psi_cache(&sum.cache_log(), quiet);
    meta["conductance"]["seconds"] = serde_json::json!(tcs);
    meta["conductance_steps"] = serde_json::Value::Array(
        h.iter()
            .map(|h| serde_json::json!({ "conductance": h }))
            .collect(),
    );
    Ok(tcs)
}

/// One log line per ψ table of the conductance: read from the table cache, or built
/// (or extended) and written there; a table that could not be written is a warning
/// (the result is the same, the next run solves it again).
fn log_psi_cache(uses: &[strata_tablegen::psi_table::CacheUse], quiet: bool) {
    use strata_tablegen::psi_table::CacheUse;
    for u in uses {
        match u {
            CacheUse::Read => log!(quiet, "conductance: ψ table read from the table cache"),
            CacheUse::Written { pieces: (k0, k1) } => log!(
                quiet,
                "conductance: ψ table solved for a/h1 = {:.3e} … {:.3e} (8 Fredholm solves per decade, per half decade above 10) and kept in the table cache",
                10f64.powf(strata_runtime::constriction::piece_start(*k0)),
                10f64.powf(strata_runtime::constriction::piece_start(*k1))
            ),
            CacheUse::NotWritten(why) => progress::warn(format_args!(
                "conductance: the ψ table could not be kept in the table cache ({why}); it is solved again next time"
            )),
        }
    }
}

/// curve.json's `conductance` entry: kind, unit, definition, the counterface.
fn conductance_meta(scene: &Scene, spec: &ConductanceSpec) -> serde_json::Value {
    let unit = spec.kind.interface_conductance_unit();
    let top = spec
        .body(&scene.stack)
        .map(|c| c.top_conductivity())
        .unwrap_or(f64::NAN);
    serde_json::json!({
        "kind": spec.kind.name(),
        "counterface": counterface_conduction(spec),
        "top_conductivity": top,
        "definition": "interface (constriction) conductance per nominal area h_c = mean(q)/dT for a uniform \
                       jump dT on the contact set (p > 0) and no flux elsewhere, the k = 0 mode (the bulk \
                       1-D resistance of both bodies) excluded (physics.md 6.2); infinite (null) at full contact",
        "units": {"conductance": unit, "top_conductivity": spec.kind.conductivity_unit()},
    })
}

/// curve.json's summary of an asperity-model solve: the scene, (model, its short name,
/// the solid) in words, E*, the sample (area, summits, z_M − z̄), the surface and its
/// warnings, the time and the units.
fn asperity_meta(
    scene: &Scene,
    scene_path: &Path,
    (model, short, solid): (&str, &str, &str),
    e_star: f64,
    rc: &RoughContact<'_>,
    (surface_json, warnings): (serde_json::Value, Vec<String>),
    seconds: f64,
) -> serde_json::Value {
    serde_json::json!({
        "scene": scene_path.display().to_string(),
        "model": model,
        "model_short": short,
        "stack": stack_description(&scene.stack),
        "solid": solid,
        "e_star_1": e_star,
        "nominal_area": rc.area(),
        "summits": rc.summits().len(),
        "z_max_minus_mean": rc.top_to_mean(),
        "surface": surface_json,
        "warnings": warnings,
        "seconds": seconds,
        "units": {"delta": "m", "gap": "m", "mean_pressure": "Pa", "pressure_ratio": "1",
                  "area_fraction": "1", "stiffness": "N/m (dP/dδ of the sample)"},
    })
}

/// The short name of a model kind for titles: `N model`, `I model (…)`, `BEM`.
pub fn kind_short(scene: &Scene) -> String {
    match scene.model.kind {
        ModelKind::Independent => model_short(Model::Independent),
        ModelKind::Interacting => model_short(Model::Interacting(scene.model.images)),
        ModelKind::Bem => "BEM".into(),
    }
}
