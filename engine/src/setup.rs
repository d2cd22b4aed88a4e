//! What every load path shares: the engine's options and observer (log lines, progress,
//! maps), the asperity law of a stack (from a table or the cache), the surface's report,
//! and the descriptions of the model and the solid for logs and `curve.json`. Below the
//! drivers and the effects, which both use it.

use std::path::{Path, PathBuf};

use crate::error::{Context, Result};
use crate::progress;
use crate::scene::{ModelKind, Scene, SurfaceSource};
use strata_bem::{BemOptions, BemSolution};
use strata_runtime::Solid;
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::resources::{self, MemoryLimit};
use strata_runtime::rough::{Images, Model};
use strata_runtime::surface::{GenerateParams, Surface};
use strata_runtime::table::Table;
use strata_tablegen::tablebuild::{Bars, BuildOptions};

pub use crate::solution::{
    ConductanceInfo, CounterfaceSummary, PlasticInfo, SceneSolution, StepFailure, Summary,
    SurfaceReport,
};
pub use strata_runtime::rough::Step;
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

/// How a scene is solved (not what: that is the scene; not where the log goes: that is
/// the [`Observer`]).
#[derive(Debug, Clone, Default)]
pub struct EngineOptions {
    /// `--cache-dir`: where missing tables of layered stacks are built and cached
    /// (default: [`crate::cache::dir`]).
    pub cache_dir: Option<PathBuf>,
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
    /// The memory limit of everything the solve allocates in proportion to its input
    /// (the surface, the BEM grid, the I model's pair sums, the law's samples, the
    /// conduction kernels, tables read): passed to every solver's options. Default: 75 %
    /// of the machine's memory; the front ends set it (`--memory-limit`,
    /// `STRATA_MEMORY_LIMIT`).
    pub memory: MemoryLimit,
}

/// Watches a solve: its log lines and progress, and the BEM's maps as they are solved.
/// Warnings are always printed (they are part of the result).
pub trait Observer {
    /// No log lines or progress bars (sweeps, studies, the law's inner solves).
    fn quiet(&self) -> bool {
        false
    }
    /// One log line (stderr, unless [`Observer::quiet`]).
    fn log(&self, line: std::fmt::Arguments<'_>) {
        if !self.quiet() {
            progress::log(line);
        }
    }
    /// One BEM step's maps: `(step, number of steps, solution)`, handed over as soon as
    /// the step is solved, so that `maps = "all"` never holds more than one step's maps.
    /// Default: dropped.
    fn maps(&mut self, _step: usize, _steps: usize, _solution: BemSolution) -> Result<()> {
        Ok(())
    }
}

/// Log lines and progress on stderr; maps dropped.
#[derive(Debug, Clone, Copy, Default)]
pub struct Console;

impl Observer for Console {}

/// No log lines or progress; maps dropped.
#[derive(Debug, Clone, Copy, Default)]
pub struct Quiet;

impl Observer for Quiet {
    fn quiet(&self) -> bool {
        true
    }
}

/// Log lines unless `quiet`; each BEM step's maps to `sink` (step, steps, solution).
pub struct WithMaps<F> {
    /// No log lines or progress.
    pub quiet: bool,
    /// Receives the maps.
    pub sink: F,
}

impl<F: FnMut(usize, usize, BemSolution) -> Result<()>> Observer for WithMaps<F> {
    fn quiet(&self) -> bool {
        self.quiet
    }
    fn maps(&mut self, step: usize, steps: usize, solution: BemSolution) -> Result<()> {
        (self.sink)(step, steps, solution)
    }
}

/// A log line through an [`Observer`] (`log!(obs, "…", args)`).
macro_rules! log {
    ($obs:expr, $($t:tt)*) => { $obs.log(format_args!($($t)*)) };
}
pub(crate) use log;

/// The scene's `[solver]` parameters of the asperity models with the call's
/// cancellation token ([`EngineOptions::cancel`]) and memory limit
/// ([`EngineOptions::memory`]).
pub fn solver_params(scene: &Scene, opts: &EngineOptions) -> strata_runtime::rough::Params {
    let mut p = scene.solver.params();
    p.cancel = opts.cancel.clone();
    p.memory = opts.memory;
    p
}

/// Checks the surface's size against `memory` before it is generated (read surfaces
/// are checked by the reader, from the file's header).
fn check_surface_memory(scene: &Scene, memory: &MemoryLimit) -> Result<()> {
    if let SurfaceSource::Generate(g) = &scene.surface.source {
        check_generate_memory(g, memory)?;
    }
    Ok(())
}

/// Checks the memory that generating the surface `g` needs against `memory`.
pub fn check_generate_memory(g: &GenerateParams, memory: &MemoryLimit) -> Result<()> {
    let n = g.grid as u64;
    memory.check(
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

/// The scene's surface, read or generated after a check against `memory` (what repair
/// filled is in its log, printed with the surface report).
pub fn load_surface(scene: &Scene, memory: &MemoryLimit) -> Result<Surface> {
    check_surface_memory(scene, memory)?;
    Ok(scene.load_surface(memory)?)
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
pub fn cached_table<S: Solid + ?Sized>(
    stack: &S,
    cache_dir: Option<&Path>,
    quiet: bool,
    opts: Option<BuildOptions>,
) -> Result<(Table, PathBuf)> {
    let (dir, origin) = crate::cache::dir(cache_dir);
    crate::cache::ensure_writable(&dir, origin)?;
    if !quiet {
        progress::log(format!(
            "stack: layered, no table given: using the table cache {} ({origin}; built once per stack)",
            dir.display()
        ));
    }
    let opts = opts.unwrap_or_else(|| build_options(quiet));
    let (t, p) =
        strata_tablegen::tablebuild::build_and_cache(stack, &dir, &opts).with_context(|| {
            format!(
                "building the table of the stack into the cache {}",
                dir.display()
            )
        })?;
    if !quiet {
        progress::log(format!("stack: table {}", p.display()));
    }
    Ok((t, p))
}

/// The reader's warnings and the plausibility warnings of the statistics
/// (`strata_runtime::surface::Surface::plausibility`).
pub fn surface_warnings(surface: &Surface) -> Vec<String> {
    let mut w: Vec<String> = surface.warnings().to_vec();
    w.extend(surface.plausibility());
    w
}

/// Logs what the reader did (units, repairs, form removal, file metadata) and the
/// surface statistics, prints every warning ([`surface_warnings`]) on stderr even
/// when quiet, and returns the [`SurfaceReport`] with the warnings.
pub fn surface_report(surface: &Surface, obs: &dyn Observer) -> (SurfaceReport, Vec<String>) {
    for line in surface.log() {
        log!(obs, "surface: {line}");
    }
    log!(obs, "surface: {}", surface.stats().describe());
    let warnings = surface_warnings(surface);
    for w in &warnings {
        progress::warn(format_args!("surface: {w}"));
    }
    (SurfaceReport::of(surface), warnings)
}

/// The asperity law of the scene's stack: Hertz for a homogeneous stack, otherwise
/// the surrogate table: `stack.table` (which must exist: an input is never written),
/// or the cache.
pub fn law_for(
    scene: &Scene,
    opts: &EngineOptions,
    obs: &dyn Observer,
) -> Result<Box<dyn AsperityLaw>> {
    let stack = &scene.bodies;
    if stack.is_homogeneous() {
        log!(
            obs,
            "stack: homogeneous (E* = {:e} Pa): Hertz asperities, no table loaded",
            stack.contact_modulus()
        );
        return Ok(Box::new(Homogeneous {
            e_star: stack.contact_modulus(),
        }));
    }
    // With an elastic counterface the scene's table is `counterface.table` (of the pair).
    let (field, what) = if stack.counterface.stack().is_some() {
        ("counterface.table", "pair (stack and counterface)")
    } else {
        ("stack.table", "stack")
    };
    let table = match (&opts.table, &scene.table) {
        (Some(t), _) => {
            log!(obs, "stack: layered, table given in memory");
            Table::clone(t)
        }
        (None, Some(p)) => {
            log!(obs, "stack: layered, table {}", p.display());
            Table::load_within(p, &opts.memory)
                .with_context(|| format!("{field} {}", p.display()))?
        }
        (None, None) => cached_table(stack, opts.cache_dir.as_deref(), obs.quiet(), None)?.0,
    };
    let law = table.law_for(stack).with_context(|| match &scene.table {
        Some(p) => format!("{field} {} does not serve the scene's {what}", p.display()),
        None => format!("the table does not serve the scene's {what}"),
    })?;
    Ok(Box::new(law))
}

/// What the model simulates, for logs and `curve.json`.
pub(crate) fn model_description(model: Model) -> String {
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
pub fn counterface_summary(scene: &Scene) -> Option<CounterfaceSummary> {
    let c = scene.bodies.counterface.stack()?;
    Some(CounterfaceSummary {
        stack: stack_description(c),
        e_star_1_counterface: c.top_plane_strain_modulus(),
        e_star_1_body: scene.bodies.first.top_plane_strain_modulus(),
        e_star_pair: scene.bodies.contact_modulus(),
        rough: scene.bodies.counterface.surface().is_some(),
        note: "two elastic bodies (physics.md §6.1): e_star_1 and pressure_ratio are the pair's, \
               1/E* = 1/E*1,body + 1/E*1,counterface; a rough counterface's heights are added to the body's",
    })
}

/// A stack in a few words for plot titles: its name, else its make-up
/// (`2 layers on a rigid base, E1 = 4 GPa`, `half-space, E = 210 GPa`).
/// A pair reads `A against B` unless its first body is named.
pub fn stack_description<S: Solid + ?Sized>(solid: &S) -> String {
    let stack = solid.first();
    if let Some(n) = &stack.name {
        return n.clone();
    }
    if let Some(c) = solid.elastic_counterface() {
        return format!(
            "{} against {}",
            stack_description(stack),
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

/// The short name of a model kind for titles: `N model`, `I model (…)`, `BEM`.
pub fn kind_short(scene: &Scene) -> String {
    match scene.model.kind {
        ModelKind::Independent => model_short(Model::Independent),
        ModelKind::Interacting => model_short(Model::Interacting(scene.model.images)),
        ModelKind::Bem => "BEM".into(),
    }
}
