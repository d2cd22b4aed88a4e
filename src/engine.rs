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

use crate::scene::{LoadSpec, ModelKind, Scene};
use anyhow::{Context, Result, bail};
use strata_bem::{BemLoad, BemOptions, BemSolution, BemSolver, Geometry};
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::rough::{Images, Model, RoughContact, Step};
use strata_runtime::summits::find_summits;
use strata_runtime::surface::Surface;
use strata_runtime::table::Table;

/// How a scene is solved (not what: that is the scene).
#[derive(Debug, Clone, Default)]
pub struct EngineOptions {
    /// Where missing tables of layered stacks are built and cached
    /// (default: `.strata-cache` beside the scene).
    pub cache_dir: Option<PathBuf>,
    /// No log lines on stderr (sweeps, studies).
    pub quiet: bool,
    /// BEM only: keep the pressure and gap maps of every step.
    pub keep_maps: bool,
    /// BEM only: solver options (tolerance…); `None` gives the defaults.
    pub bem: Option<BemOptions>,
}

/// A solved scene.
#[derive(Debug, Clone)]
#[allow(dead_code)] // maps, seconds: used by compare/study
pub struct SceneSolution {
    /// One entry per load step, in the scene's order.
    pub steps: Vec<Step>,
    /// Summary for `curve.json`: model, solid, E*₁, nominal area, units…
    pub meta: serde_json::Value,
    /// BEM with `keep_maps`: pressure (Pa) and gap (m) maps of every step.
    pub maps: Vec<BemSolution>,
    /// Wall time of the solve, without table building (s).
    pub seconds: f64,
}

macro_rules! log {
    ($quiet:expr, $($t:tt)*) => { if !$quiet { eprintln!($($t)*); } };
}

/// The reader's warnings and the plausibility warnings of the statistics
/// (`strata_runtime::surface::SurfaceStats::plausibility`).
pub fn surface_warnings(surface: &Surface) -> Vec<String> {
    let mut w: Vec<String> = surface.warnings().to_vec();
    w.extend(surface.stats().plausibility());
    w
}

/// The statistics, repairs and reader log of a surface as JSON (curve.json
/// `surface`, `strata surface info --json`), SI units.
pub fn surface_json(surface: &Surface) -> serde_json::Value {
    let mut json = serde_json::to_value(surface.stats()).unwrap_or_default();
    json["repaired_points"] = serde_json::json!(surface.repaired());
    json["read"] = serde_json::json!(surface.log());
    json["units"] = serde_json::json!({"shape": "points (x, y)", "pixel_size": "m", "size": "m",
        "mean_height": "m", "rms_height": "m", "rms_slope": "1", "peak_to_valley": "m"});
    json
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
        eprintln!("WARNING: surface: {w}");
    }
    (surface_json(surface), warnings)
}

/// The asperity law of the scene's stack: Hertz for a homogeneous stack, otherwise
/// the surrogate table (`stack.table`, or the cache, built once if missing).
pub fn law_for(
    scene: &Scene,
    scene_path: &Path,
    opts: &EngineOptions,
) -> Result<Box<dyn AsperityLaw>> {
    let quiet = opts.quiet;
    let stack = &scene.stack;
    if stack.is_homogeneous() {
        log!(
            quiet,
            "stack: homogeneous (E* = {:e} Pa): Hertz asperities, no table loaded",
            stack.top_plane_strain_modulus()
        );
        return Ok(Box::new(Homogeneous {
            e_star: stack.top_plane_strain_modulus(),
        }));
    }
    let table = match &scene.table {
        Some(p) if p.is_file() => {
            log!(quiet, "stack: layered, table {}", p.display());
            Table::load(p).with_context(|| format!("stack.table: {}", p.display()))?
        }
        Some(p) => {
            eprintln!(
                "stack: layered, table {} missing: building it once (this takes a while)…",
                p.display()
            );
            let t = strata_tablegen::tablebuild::build(stack, &Default::default())
                .context("building the table for the scene's stack")?;
            t.save(p)
                .with_context(|| format!("stack.table: saving {}", p.display()))?;
            eprintln!("stack: table built and cached at {}", p.display());
            t
        }
        None => {
            let dir = match &opts.cache_dir {
                Some(d) => d.to_path_buf(),
                None => scene_path
                    .parent()
                    .unwrap_or(Path::new("."))
                    .join(".strata-cache"),
            };
            log!(
                quiet,
                "stack: layered, no table given: using the cache in {} (built once if missing)",
                dir.display()
            );
            let (t, p) =
                strata_tablegen::tablebuild::build_and_cache(stack, &dir, &Default::default())
                    .context("building/caching the table for the scene's stack")?;
            log!(quiet, "stack: table {}", p.display());
            t
        }
    };
    let law = table
        .law_for(stack)
        .context("stack.table does not serve the scene's stack")?;
    Ok(Box::new(law))
}

/// Solves a scene with the model it names. `scene_path` locates the default cache.
pub fn solve_scene(
    scene: &Scene,
    scene_path: &Path,
    opts: &EngineOptions,
) -> Result<SceneSolution> {
    let model = match scene.model.kind {
        ModelKind::Independent => Model::Independent,
        ModelKind::Interacting => Model::Interacting(scene.model.images),
        ModelKind::Bem => return solve_bem(scene, scene_path, opts),
    };
    let quiet = opts.quiet;
    let surface = scene.load_surface().context("surface")?;
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
    let rc = RoughContact::from_surface(law.as_ref(), &surface)?;
    let effects = match model {
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
    };
    let layered = if law.is_homogeneous() {
        "homogeneous solid (χ = ζ = 1, g = 0)"
    } else {
        "layered solid (χ, ζ from the table; g too for the I model)"
    };
    log!(quiet, "simulating: {effects}; {layered}");
    // Any approach δ ≥ 0 is admissible for the asperity models: steps beyond their
    // validity are solved, logged and flagged in curve.json.
    let steps: Vec<Step> = match scene
        .load
        .approaches(rc.top_to_mean(), f64::INFINITY)
        .context("load")?
    {
        Some(d) => rc.curve(model, &d)?,
        None => {
            let LoadSpec::MeanPressures(ps) = &scene.load else {
                bail!("load: internal error");
            };
            let mut out: Vec<Step> = Vec::new();
            let mut warm: Vec<f64> = Vec::new();
            for (i, &p) in ps.iter().enumerate() {
                let s = rc
                    .solve_pressure(model, p, &warm)
                    .with_context(|| format!("load.mean_pressures[{i}]"))?;
                warm = s.radii.clone();
                out.push(s);
            }
            out
        }
    };
    let seconds = t0.elapsed().as_secs_f64();
    for (i, s) in steps.iter().enumerate() {
        if !s.validity.is_valid() {
            log!(
                quiet,
                "warning: load step {i} (δ = {:e} m) is outside the asperity model's validity: {}",
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
    let meta = serde_json::json!({
        "scene": scene_path.display().to_string(),
        "model": effects,
        "solid": layered,
        "e_star_1": law.e_star(),
        "nominal_area": rc.area(),
        "summits": rc.summits().len(),
        "z_max_minus_mean": rc.top_to_mean(),
        "surface": surface_json,
        "warnings": warnings,
        "seconds": seconds,
        "units": {"delta": "m", "gap": "m", "mean_pressure": "Pa", "pressure_ratio": "1",
                  "area_fraction": "1", "stiffness": "N/m (dP/dδ of the sample)"},
    });
    Ok(SceneSolution {
        steps,
        meta,
        maps: Vec::new(),
        seconds,
    })
}

/// `model.kind = "bem"`: the FFT boundary-element solution of the whole surface
/// (strata-bem): on a periodic surface with the layered kernel 2S(|k|)/(E*₁|k|), on a
/// non-periodic one with the pixel influence coefficients of the free solid, both
/// computed from the stack (no χ, ζ, g table is needed or loaded). Same steps as the asperity models;
/// `contacts` counts contact patches and the stiffness dP/dδ comes from one extra,
/// warm-started solve at δ(1 + 1e-4) per step (its error ~ tolerance/1e-4 ≈ 1e-6).
fn solve_bem(scene: &Scene, scene_path: &Path, opts: &EngineOptions) -> Result<SceneSolution> {
    let quiet = opts.quiet;
    let surface = scene.load_surface().context("surface")?;
    let (surface_json, warnings) = surface_report(&surface, quiet);
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
    let solver = BemSolver::with_geometry(&heights, geometry, stack, opts.bem.unwrap_or_default())
        .context("model.kind = \"bem\"")?;
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
    let area = solver.area();
    let mut steps = Vec::with_capacity(loads.len());
    let mut maps = Vec::new();
    let mut warm: Option<Vec<f64>> = None;
    let mut worst_error = 0.0f64;
    for (name, load) in loads {
        let sol = solver
            .solve_from(load, warm.as_deref())
            .with_context(|| name.clone())?;
        let flat: Vec<f64> = sol.pressure.iter().copied().collect();
        let dd = 1e-4 * sol.approach.abs().max(1e-3 * surface.rms());
        let next = solver
            .solve_from(BemLoad::Approach(sol.approach + dd), Some(&flat))
            .with_context(|| format!("{name}: stiffness"))?;
        worst_error = worst_error.max(sol.error).max(next.error);
        steps.push(Step {
            delta: sol.approach,
            gap: sol.separation,
            load: sol.total_load,
            mean_pressure: sol.mean_pressure,
            pressure_ratio: sol.pressure_ratio,
            area_fraction: sol.area_fraction,
            contacts: sol.patches,
            stiffness: (next.total_load - sol.total_load) / dd,
            kkt_residual: None,
            iterations: sol.iterations,
            radii: Vec::new(),
            ..Default::default()
        });
        warm = Some(flat);
        if opts.keep_maps {
            maps.push(sol);
        }
    }
    let seconds = t0.elapsed().as_secs_f64();
    log!(quiet, "BEM: largest final CG error {worst_error:.2e}");
    let meta = serde_json::json!({
        "scene": scene_path.display().to_string(),
        "model": effects,
        "solid": solid,
        "e_star_1": stack.top_plane_strain_modulus(),
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
    Ok(SceneSolution {
        steps,
        meta,
        maps,
        seconds,
    })
}
