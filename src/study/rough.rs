//! Stage 4: rough contact on the paper's surface (the scene's generated k_M = 10
//! surface, L = 1 mm, n = 512) and stack E₂/E₁ = 1 (h₁ = 100 µm on a rigid base).
//!
//! Models: the N model, the I model with isolated interactions and with 5×5 periodic
//! images (runtime `rough`, χ, ζ, g from the scene's table, on the 512² surface's
//! summits), and the FFT-BEM (runtime `bem`) on the surface resampled spectrally to
//! n × n (exact: the surface has no wavenumber above 10·2π/L) at several tolerances.
//! All are loaded at the same nominal separations g_n (the flat at z̄ + g_n; a few
//! of the scene's load steps). The reference is the BEM at the finest grid of the mode
//! at the default tolerance; the error of a model is
//!
//! ```text
//!   p error = max over steps |p_n − p_n,ref| / p_n,ref      (p_n = P/A₀)
//! ```
//!
//! (and the same for the area fraction A/A₀, shown but not used for the front).
//! Time per load curve: from the surface to the curve — summit search and solves for
//! the asperity models (table already loaded), kernel set-up and warm-started solves
//! for the BEM (resampling excluded).
//!
//! The far-field tolerance of the I model (point-force treatment of distant pairs) is
//! studied separately: periodic I model at several tolerances against exact
//! interactions (tolerance 0).

use crate::scene::Scene;
use anyhow::{Context, Result, bail};
use ndarray::Array2;
use strata_bem::{BemLoad, BemOptions, BemSolver, resample_spectral};
use strata_runtime::law::AsperityLaw;
use strata_runtime::rough::{Images, Model, RoughContact, Step};
use strata_runtime::surface::Surface;
use strata_runtime::table::Table;

use super::pareto::Point;
use super::{Errors, Inputs, Mode, Runner, Timing};

/// Errors below this are below the reference's own accuracy (10× the default BEM
/// tolerance).
pub const FLOOR: f64 = 1e-9;
/// Far-field errors below this are at the I model's Newton tolerance.
pub const FAR_FLOOR: f64 = 1e-10;

#[derive(Debug, Clone)]
pub struct Settings {
    pub steps: usize,
    pub grids: Vec<usize>,
    pub tolerances: Vec<f64>,
    pub far_tolerances: Vec<f64>,
}

impl Settings {
    pub fn for_mode(mode: Mode) -> Settings {
        match mode {
            Mode::Tiny => Settings {
                steps: 3,
                grids: vec![32, 64],
                tolerances: vec![1e-6, 1e-10],
                far_tolerances: vec![],
            },
            Mode::Quick => Settings {
                steps: 6,
                grids: vec![32, 64, 128, 256],
                tolerances: vec![1e-6, 1e-8, 1e-10],
                far_tolerances: vec![0.0, 1e-8, 1e-6, 1e-5, 1e-4, 1e-2],
            },
            Mode::Full => Settings {
                steps: 10,
                grids: vec![32, 64, 128, 256, 512],
                tolerances: vec![1e-6, 1e-8, 1e-10],
                far_tolerances: vec![0.0, 1e-8, 1e-6, 1e-5, 1e-4, 1e-2],
            },
        }
    }

    pub fn ref_grid(&self) -> usize {
        self.grids.iter().copied().max().unwrap_or(0)
    }
}

/// What a row solved with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    Asperity(Model),
    Bem { n: usize, tolerance: f64 },
}

impl Kind {
    pub fn label(&self) -> String {
        match self {
            Kind::Asperity(Model::Independent) => "N model".into(),
            Kind::Asperity(Model::Interacting(Images::Isolated)) => "I model, isolated".into(),
            Kind::Asperity(Model::Interacting(Images::Periodic(m))) => {
                format!("I model, periodic {0}×{0}", 2 * m + 1)
            }
            Kind::Bem { n, tolerance } => format!("BEM n = {n}, tol {tolerance:.0e}"),
        }
    }
}

#[derive(Debug, Clone)]
pub struct Row {
    pub kind: Kind,
    /// p_n/E*₁ per step.
    pub pressure: Vec<f64>,
    /// A/A₀ per step.
    pub area: Vec<f64>,
    pub p_error: f64,
    pub area_error: f64,
    pub timing: Timing,
    pub is_reference: bool,
    /// Uses the library defaults (BEM tolerance; I model with its far-field default).
    pub is_default: bool,
}

#[derive(Debug, Clone)]
pub struct FarRow {
    /// None: the library default (`RoughContact` without a tolerance set).
    pub tolerance: Option<f64>,
    /// For the default: the studied tolerance whose curve is bit-identical.
    pub same_as: Option<f64>,
    /// p_n/E*₁ per step.
    pub pressure: Vec<f64>,
    pub p_error: f64,
    pub timing: Timing,
}

impl FarRow {
    pub fn label(&self) -> String {
        match (self.tolerance, self.same_as) {
            (Some(0.0), _) => "0 (exact)".into(),
            (Some(t), _) => format!("{t:.0e}"),
            (None, Some(t)) => format!("library default (= {t:.0e}: identical curve)"),
            (None, None) => "library default".into(),
        }
    }
}

pub struct Results {
    pub settings: Settings,
    /// The scene's surface as the report describes it (file, grid, sides, RMS).
    pub surface: String,
    pub summits: usize,
    pub separations: Vec<f64>,
    pub rows: Vec<Row>,
    pub far: Vec<FarRow>,
    pub default_tolerance: f64,
}

impl Results {
    /// Non-reference rows as front points (time per curve, p error).
    pub fn points(&self) -> (Vec<usize>, Vec<Point>) {
        let idx: Vec<usize> = (0..self.rows.len())
            .filter(|&i| !self.rows[i].is_reference)
            .collect();
        let pts = idx
            .iter()
            .map(|&i| Point {
                time: self.rows[i].timing.median,
                error: self.rows[i].p_error,
            })
            .collect();
        (idx, pts)
    }

    pub fn far_points(&self) -> Vec<Point> {
        self.far
            .iter()
            .map(|r| Point {
                time: r.timing.median,
                error: r.p_error,
            })
            .collect()
    }

    pub fn reference(&self) -> Option<&Row> {
        self.rows.iter().find(|r| r.is_reference)
    }
}

fn curve_values(steps: &[Step]) -> (Vec<f64>, Vec<f64>) {
    (
        steps.iter().map(|s| s.pressure_ratio).collect(),
        steps.iter().map(|s| s.area_fraction).collect(),
    )
}

/// The largest relative deviation of `v` from `r` (absolute where r = 0).
pub fn max_rel(v: &[f64], r: &[f64]) -> f64 {
    v.iter()
        .zip(r)
        .map(|(v, r)| {
            if *r > 0.0 {
                ((v - r) / r).abs()
            } else {
                v.abs()
            }
        })
        .fold(0.0, f64::max)
}

fn asperity_curve(
    law: &dyn AsperityLaw,
    surface: &Surface,
    model: Model,
    far: Option<f64>,
    deltas: &[f64],
) -> Result<Vec<Step>> {
    let mut rc = RoughContact::from_surface(law, surface)?;
    if let Some(t) = far {
        rc = rc.with_far_field_tolerance(t);
    }
    Ok(rc.curve(model, deltas)?)
}

fn bem_curve(
    heights: &Array2<f64>,
    size: f64,
    stack: &(impl strata_runtime::Solid + ?Sized),
    tolerance: f64,
    loads: &[BemLoad],
) -> Result<(Vec<f64>, Vec<f64>)> {
    let solver = BemSolver::new(
        heights,
        size,
        stack,
        BemOptions {
            tolerance,
            ..BemOptions::default()
        },
    )?;
    let sols = solver.solve_curve(loads)?;
    Ok((
        sols.iter().map(|s| s.pressure_ratio).collect(),
        sols.iter().map(|s| s.area_fraction).collect(),
    ))
}

/// The stage's inputs, read and checked: the scene, its (periodic) surface, and the table
/// that serves its stack (the scene's, else `--table`). [`super::run`] calls it before
/// the first stage, so that a bad `--scene` fails at once, not after minutes of work.
pub fn inputs(inputs: &Inputs) -> Result<(Scene, Surface, std::path::PathBuf, Table)> {
    let scene = Scene::from_file(&inputs.scene)
        .with_context(|| format!("--scene {}", inputs.scene.display()))?;
    let surface = crate::engine::load_surface(&scene, &inputs.memory).context("scene surface")?;
    if !surface.is_periodic() {
        bail!("--scene: the study's BEM needs a periodic surface");
    }
    let table_path = scene.table.clone().unwrap_or_else(|| inputs.table.clone());
    let table = Table::load_within(&table_path, &inputs.memory)
        .with_context(|| table_path.display().to_string())?;
    table
        .law_for(&scene.bodies)
        .with_context(|| format!("{} does not serve the scene's stack", table_path.display()))?;
    Ok((scene, surface, table_path, table))
}

/// The BEM grids of the effect stages (yielding tips, conductance) per mode: the finest
/// is their reference.
pub fn effect_grids(mode: Mode) -> Vec<usize> {
    match mode {
        Mode::Tiny => vec![32, 64],
        Mode::Quick => vec![64, 128, 256],
        Mode::Full => vec![64, 128, 256, 512],
    }
}

/// Load steps of the effect stages per mode.
pub fn effect_steps(mode: Mode) -> usize {
    match mode {
        Mode::Tiny => 3,
        Mode::Quick => 6,
        Mode::Full => 10,
    }
}

/// `k` of the scene's approaches `all`, spread evenly over its list (the first and the
/// last included; all of them when there are fewer).
pub fn spread(all: &[f64], k: usize) -> Vec<f64> {
    let k = k.min(all.len()).max(1);
    (0..k)
        .map(|i| {
            let j = if k == 1 {
                0
            } else {
                (i * (all.len() - 1) + (k - 1) / 2) / (k - 1)
            };
            all[j]
        })
        .collect()
}

pub fn run(runner: &mut Runner, errors: &mut Errors, inputs: &Inputs) -> Result<Results> {
    let set = Settings::for_mode(runner.mode);
    let (scene, surface, table_path, table) = self::inputs(inputs)?;
    let law = table
        .law_for(&scene.bodies)
        .with_context(|| format!("{} does not serve the scene's stack", table_path.display()))?;
    let rc = RoughContact::from_surface(&law, &surface)?;
    let summits = rc.summits().len();
    let all = scene
        .load
        .approaches(rc.top_to_mean(), rc.max_delta())?
        .context("the study's scene must give approaches or separations, not pressures")?;
    if all.is_empty() {
        bail!("--scene: no load steps");
    }
    let deltas = spread(&all, set.steps);
    let separations: Vec<f64> = deltas.iter().map(|d| rc.top_to_mean() - d).collect();
    let loads: Vec<BemLoad> = separations
        .iter()
        .map(|&g| BemLoad::Separation(g))
        .collect();
    let (n0, n1) = surface.shape();
    let heights = Array2::from_shape_vec((n0, n1), surface.heights().to_vec())?;
    let size = surface.extent().0;
    let default_tol = BemOptions::default().tolerance;
    let ref_grid = set.ref_grid();
    let mut rows: Vec<Row> = Vec::new();

    // BEM, coarse to fine; the reference (finest grid, default tolerance) is first
    // solved so that every row's error can be computed.
    let mut tols = set.tolerances.clone();
    if !tols.contains(&default_tol) {
        tols.push(default_tol);
    }
    let resampled: Vec<(usize, Array2<f64>)> = set
        .grids
        .iter()
        .map(|&n| Ok((n, resample_spectral(&heights, n)?)))
        .collect::<Result<_>>()?;
    for (n, h) in &resampled {
        for &tol in &tols {
            let case = format!("bem,n={n},tol={tol:e}");
            let (pressure, area) =
                runner.exact(|| bem_curve(h, size, &scene.bodies, tol, &loads))?;
            let timing = runner.time("rough", &case, || {
                bem_curve(h, size, &scene.bodies, tol, &loads)
            })?;
            rows.push(Row {
                kind: Kind::Bem {
                    n: *n,
                    tolerance: tol,
                },
                pressure,
                area,
                p_error: f64::NAN,
                area_error: f64::NAN,
                timing,
                is_reference: *n == ref_grid && tol == default_tol,
                is_default: tol == default_tol,
            });
        }
    }
    for model in [
        Model::Independent,
        Model::Interacting(Images::Isolated),
        Model::Interacting(Images::Periodic(2)),
    ] {
        let kind = Kind::Asperity(model);
        let steps = runner.exact(|| asperity_curve(&law, &surface, model, None, &deltas))?;
        let (pressure, area) = curve_values(&steps);
        let timing = runner.time("rough", &kind.label(), || {
            asperity_curve(&law, &surface, model, None, &deltas)
        })?;
        rows.push(Row {
            kind,
            pressure,
            area,
            p_error: f64::NAN,
            area_error: f64::NAN,
            timing,
            is_reference: false,
            is_default: matches!(model, Model::Interacting(Images::Periodic(_))),
        });
    }
    let Some(reference) = rows.iter().find(|r| r.is_reference).cloned() else {
        bail!("internal: no BEM reference row");
    };
    for r in rows.iter_mut() {
        r.p_error = max_rel(&r.pressure, &reference.pressure);
        r.area_error = max_rel(&r.area, &reference.area);
        let case = r.kind.label();
        errors.push("rough", &case, "p error", r.p_error);
        errors.push("rough", &case, "area error", r.area_error);
        for (i, p) in r.pressure.iter().enumerate() {
            errors.push("rough", &case, &format!("p/E* step {i}"), *p);
        }
    }

    // Far-field tolerance of the periodic I model against exact interactions; the
    // library default (no tolerance set) is a row of its own.
    let periodic = Model::Interacting(Images::Periodic(2));
    let mut far_tols: Vec<Option<f64>> = set.far_tolerances.iter().map(|&t| Some(t)).collect();
    if !far_tols.is_empty() {
        if !far_tols.contains(&Some(0.0)) {
            far_tols.insert(0, Some(0.0));
        }
        far_tols.push(None);
    }
    let mut p_exact = Vec::new();
    if !far_tols.is_empty() {
        let exact_curve =
            runner.exact(|| asperity_curve(&law, &surface, periodic, Some(0.0), &deltas))?;
        p_exact = curve_values(&exact_curve).0;
    }
    let mut far: Vec<FarRow> = Vec::new();
    for &tol in &far_tols {
        let steps = runner.exact(|| asperity_curve(&law, &surface, periodic, tol, &deltas))?;
        let (p, _) = curve_values(&steps);
        let case = match tol {
            Some(t) => format!("far-field tol={t:e}"),
            None => "far-field library default".into(),
        };
        let timing = runner.time("rough", &case, || {
            asperity_curve(&law, &surface, periodic, tol, &deltas)
        })?;
        let p_error = max_rel(&p, &p_exact);
        errors.push("rough", &case, "p error", p_error);
        // The default's curve is bit-identical to the tolerance it uses.
        let same_as = match tol {
            None => far
                .iter()
                .find(|f| f.pressure == p)
                .and_then(|f| f.tolerance),
            Some(_) => None,
        };
        far.push(FarRow {
            tolerance: tol,
            same_as,
            pressure: p,
            p_error,
            timing,
        });
    }
    let (n0, n1) = surface.shape();
    let (lx, ly) = surface.extent();
    Ok(Results {
        settings: set,
        surface: format!(
            "scene {}: {n0}×{n1} points, {lx:.3e} × {ly:.3e} m, RMS {:.2e} m",
            inputs.scene.display(),
            surface.rms()
        ),
        summits,
        separations,
        rows,
        far,
        default_tolerance: default_tol,
    })
}
