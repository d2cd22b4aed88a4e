//! `strata law SCENE.toml --out FILE`: the contact law of the scene's rough interface
//! as a monotone, finely sampled table (issue 9): p(g), A(g)/A₀ and dp/dg from first
//! contact down to a smallest separation, for FE contact definitions.
//!
//! Formats (by `--format`, else by the extension of FILE):
//! - `csv` (`.csv`): header `gap,overclosure,mean_pressure,area_fraction,dp_dg,valid`
//!   (m, m, Pa, -, Pa/m, 1/0), one line per sample in loading order; `valid` = 0 where
//!   the N or I model is outside its validity (BEM laws: always 1);
//! - `json` (`.json`): the same samples (`valid` and the `validity` reason), the
//!   ranges where the model is invalid (`validity_warnings`), the surface as solved
//!   (`surface`, `warnings`), the scene summary and the convention;
//! - `abaqus` (`.inp`): a `*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR` block, data
//!   lines `pressure, overclosure`, overclosure h = g₀ − g ≥ 0 relative to first contact
//!   (g₀ = z_M − z̄), first line `0., 0.`, h strictly increasing, p non-decreasing;
//!   the convention and units are in its `**` comment lines, every number in at most
//!   20 characters (what Abaqus and CalculiX read); `** WARNING:` lines give the
//!   separations where the model is outside its validity;
//! - `all`: FILE's stem with `.csv`, `.json` and `.inp`.
//!
//! With `[conductance]` in the scene (BEM or N model) the JSON gains each sample's
//! interface conductance h_c (physics.md §6.2) and the `.inp` a `*GAP CONDUCTANCE,
//! PRESSURE` block after the table ([`SampledLaw::gap_conductance_block`]).
//!
//! Sampling: `--samples` (default 200) separations evenly from g₀ down to `--min-gap`
//! (default: the smallest separation the scene's `[load]` reaches; for
//! `mean_pressures`, the separation of the largest one). The law between samples is the
//! monotone interpolation of `strata_runtime::interface` (cubic Hermite with the
//! solver's own slopes); the file reports how far the piecewise-linear table (what
//! Abaqus does) is from it. The files are one output set ([`crate::output_set`]):
//! staged, then moved into place together under a lock, so `--format all` never
//! leaves new and old files side by side; existing ones are kept unless `--force`.
//! When an Abaqus block is written, the log warns about what CalculiX 2.20 would
//! change in it (more than 200 lines, overclosure steps below 1e-10 m).

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::scene::{LoadSpec, ModelKind, Scene};
use anyhow::{Context, Result, bail};
use strata_runtime::conduction::ConductionKind;
use strata_runtime::interface::{
    InterfaceLaw, MAX_SAMPLES, SampleOptions, abaqus_real, sample_gaps,
};
use strata_runtime::rough::{Images, Model, RoughContact};

use crate::output_set::{OutputSet, refuse_inputs};
use crate::progress;

use crate::engine::{EngineOptions, law_for, solve_surface};
use strata_runtime::surface::Surface;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    Csv,
    Json,
    Abaqus,
    All,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output file (.csv, .json or .inp; with `--format all`, the stem of the three).
    #[arg(long)]
    pub out: PathBuf,
    /// Output format (default: from the extension of --out).
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// Number of samples from first contact down to --min-gap (2 to 100000; CalculiX
    /// keeps at most 200 table lines).
    #[arg(long, default_value_t = 200)]
    pub samples: usize,
    /// Smallest separation g (m) (default: the smallest one the scene's load reaches);
    /// negative below the mean plane (`--min-gap -1e-6` or `--min-gap=-1e-6`).
    #[arg(long, allow_hyphen_values = true)]
    pub min_gap: Option<f64>,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    /// Table cache for layered stacks without `stack.table` (default: STRATA_CACHE_DIR,
    /// else $XDG_CACHE_HOME/strata or ~/.cache/strata).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
}

/// A sampled contact law and what was solved, for the headers.
#[derive(Debug, Clone)]
pub struct SampledLaw {
    /// p(g), A(g)/A₀ and dp/dg (monotone interpolation of the samples).
    pub law: InterfaceLaw,
    /// The model, in words.
    pub model: String,
    /// The solid, in words.
    pub solid: String,
    /// E*₁ (Pa).
    pub e_star: f64,
    /// Nominal area A₀ (m²).
    pub nominal_area: f64,
    /// The surface as solved (curve.json's `surface`: statistics, reader log, removed
    /// form).
    pub surface: serde_json::Value,
    /// The surface's warnings (plausibility, a form that dominates the heights).
    pub warnings: Vec<String>,
    /// With `[conductance]`: the interface conductance h_c (W/(m²·K) or S/m²) at each
    /// sample, in the order of [`InterfaceLaw::samples`] (0 at first contact).
    pub conductance: Option<(ConductionKind, Vec<f64>)>,
}

impl SampledLaw {
    /// The Abaqus/CalculiX `*SURFACE BEHAVIOR` block with its `**` comment lines
    /// naming the scene (`scene`: how it is shown), the model and the solid.
    pub fn abaqus_block(&self, scene: &str) -> String {
        self.law.abaqus_block(&[
            "strata law: pressure-overclosure table of a rough (layered) interface".into(),
            format!("scene: {scene}"),
            format!("model: {}", self.model),
            format!("solid: {}", self.solid),
        ]) + &self.gap_conductance_block()
    }

    /// With `[conductance]`: the `*GAP CONDUCTANCE, PRESSURE` block (data lines
    /// `conductance, pressure`, pressure strictly increasing from the first line
    /// `0., 0.`) with its `**` comments; empty otherwise.
    pub fn gap_conductance_block(&self) -> String {
        let Some((kind, h)) = &self.conductance else {
            return String::new();
        };
        let unit = match kind {
            ConductionKind::Thermal => "W/(m^2 K)",
            ConductionKind::Electrical => "S/m^2",
        };
        let mut s = format!(
            "** strata law: {} gap conductance of the rough interface against contact pressure.\n\
             ** conductance = h_c, the interface (constriction) conductance per nominal area ({unit}):\n\
             **   a uniform jump dT on the contact spots, no flux elsewhere, h_c = mean flux / dT;\n\
             **   the bulk 1-D resistance of both bodies is excluded (the FE mesh carries it).\n\
             ** pressure = mean (nominal) contact pressure p = P/A0 (Pa), the same as in the table\n\
             **   above; h_c was solved at the same samples. Between lines linear interpolation.\n\
             ** Data lines: conductance, pressure. Abaqus: PRESSURE makes the second field the\n\
             **   contact pressure (else a clearance). CalculiX 2.20 warns \"parameter not\n\
             **   recognized: PRESSURE\" and reads the lines as its one form, conductance,\n\
             **   contact pressure[, temperature] (CalculiX manual, *GAP CONDUCTANCE).\n\
             *GAP CONDUCTANCE, PRESSURE\n",
            kind.name()
        );
        let mut last = f64::NEG_INFINITY;
        for ((_, p, _, _), &hc) in self.law.samples().zip(h) {
            // strictly increasing pressures; an infinite h_c (full contact) ends the table
            if p.is_nan() || p <= last || !hc.is_finite() {
                continue;
            }
            last = p;
            s.push_str(&format!("{}, {}\n", abaqus_real(hc), abaqus_real(p)));
        }
        s
    }
}

/// The contact law of a scene on its (already loaded) `surface`: `samples` separations
/// from first contact down to `min_gap` (default: the smallest separation the scene's
/// load reaches), by the scene's model (N, I or BEM), as `strata law` samples it.
pub fn sample_law(
    scene: &Scene,
    path: &Path,
    surface: Surface,
    opts: &EngineOptions,
    samples: usize,
    min_gap: Option<f64>,
) -> Result<SampledLaw> {
    check_samples(samples)?;
    check_min_gap(min_gap)?;
    let sampled = match model_of(scene) {
        Some(m) => solve_asperities(scene, path, surface, opts, m, samples, min_gap),
        None => solve_bem(scene, path, surface, opts, samples, min_gap),
    }?;
    for w in sampled.law.validity_warnings() {
        crate::stdio::eprint_line(format_args!("warning: law: {w}"));
    }
    Ok(sampled)
}

fn outputs(a: &Args) -> Result<Vec<(Format, PathBuf)>> {
    let ext = a
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let by_ext = match ext.as_deref() {
        Some("csv") => Some(Format::Csv),
        Some("json") => Some(Format::Json),
        Some("inp") => Some(Format::Abaqus),
        _ => None,
    };
    let format = match (a.format, by_ext) {
        (Some(f), _) => f,
        (None, Some(f)) => f,
        (None, None) => bail!(
            "--out {}: cannot tell the format from the extension: use .csv, .json or .inp, or give --format",
            a.out.display()
        ),
    };
    Ok(match format {
        Format::All => vec![
            (Format::Csv, a.out.with_extension("csv")),
            (Format::Json, a.out.with_extension("json")),
            (Format::Abaqus, a.out.with_extension("inp")),
        ],
        f => vec![(f, a.out.clone())],
    })
}

fn model_of(scene: &Scene) -> Option<Model> {
    match scene.model.kind {
        ModelKind::Independent => Some(Model::Independent),
        ModelKind::Interacting => Some(Model::Interacting(scene.model.images)),
        ModelKind::Bem => None,
    }
}

fn describe(model: Option<Model>) -> String {
    match model {
        Some(Model::Independent) => "independent asperities (N model)".into(),
        Some(Model::Interacting(Images::Isolated)) => {
            "interacting asperities (I model), isolated sample".into()
        }
        Some(Model::Interacting(Images::Periodic(m))) => format!(
            "interacting asperities (I model), periodic images on a {0}×{0} block",
            2 * m + 1
        ),
        None => "boundary elements (FFT-BEM, periodic)".into(),
    }
}

/// The smallest separation the scene's displacement-type load reaches, given g₀ (m).
fn load_min_gap(load: &LoadSpec, g0: f64) -> Option<f64> {
    match load {
        LoadSpec::Separations(g) => g.iter().copied().reduce(f64::min),
        LoadSpec::Approach { from, to, .. } => Some(g0 - from.max(*to)),
        LoadSpec::MeanPressures(_) => None,
    }
}

fn largest_pressure(load: &LoadSpec) -> Result<f64> {
    match load {
        LoadSpec::MeanPressures(p) => p
            .iter()
            .copied()
            .reduce(f64::max)
            .context("load.mean_pressures is empty"),
        _ => bail!("load: internal error"),
    }
}

fn check_samples(n: usize) -> Result<()> {
    if n < 2 {
        bail!("--samples {n}: at least 2 samples are needed (first contact and --min-gap)");
    }
    if n > MAX_SAMPLES {
        bail!("--samples {n}: at most {MAX_SAMPLES}");
    }
    Ok(())
}

fn check_min_gap(g: Option<f64>) -> Result<()> {
    if let Some(g) = g
        && !g.is_finite()
    {
        bail!("--min-gap {g}: not a finite separation (m)");
    }
    Ok(())
}

/// N and I models: the runtime's RoughContact, as the C ABI does.
fn solve_asperities(
    scene: &Scene,
    path: &Path,
    surface: Surface,
    opts: &EngineOptions,
    model: Model,
    samples: usize,
    min_gap: Option<f64>,
) -> Result<SampledLaw> {
    let (surface_json, warnings) = crate::engine::surface_report(&surface, opts.quiet);
    let keep = scene.conductance.is_some().then(|| surface.clone());
    let law = law_for(scene, path, opts)?;
    let rc = RoughContact::from_surface(law.as_ref(), &surface)?.with_params(scene.solver.params());
    let g0 = rc.top_to_mean();
    let given = min_gap.is_some();
    let min_gap = match min_gap.or_else(|| load_min_gap(&scene.load, g0)) {
        Some(g) => g,
        None => {
            let p = largest_pressure(&scene.load)?;
            rc.solve_pressure(model, p, &[])
                .context("load.mean_pressures: the largest one sets the default --min-gap")?
                .gap
        }
    };
    progress::log(format!(
        "law: {samples} samples from first contact g0 = {g0:e} m down to g = {min_gap:e} m"
    ));
    let _spin = progress::spinner(format!("law: sampling {samples} separations"));
    let il = InterfaceLaw::sample(&rc, model, &SampleOptions { samples, min_gap }).context(
        if given {
            "--min-gap"
        } else {
            "sampling the load curve"
        },
    )?;
    let conductance = match (&scene.conductance, keep) {
        (Some(spec), Some(surface)) => {
            // the N model's conductance at the law's own separations
            let mut at = scene.clone();
            at.load = LoadSpec::Separations(il.samples().map(|s| s.0).collect());
            let quiet = EngineOptions {
                quiet: true,
                ..opts.clone()
            };
            let sol = solve_surface(&at, path, surface, &quiet).context("[conductance]")?;
            Some((spec.kind, conductance_steps(&sol.meta)))
        }
        _ => None,
    };
    Ok(SampledLaw {
        law: il,
        model: describe(Some(model)),
        solid: solid(scene),
        e_star: law.e_star(),
        nominal_area: rc.area(),
        surface: surface_json,
        warnings,
        conductance,
    })
}

fn solid(scene: &Scene) -> String {
    let s = &scene.stack;
    if let Some(c) = s.counterface() {
        return format!(
            "{} against an elastic counterface ({}), pair E* = {:e} Pa",
            solid_of(&s.body()),
            solid_of(c),
            s.contact_modulus()
        );
    }
    solid_of(s)
}

fn solid_of(s: &strata_runtime::Stack) -> String {
    if s.is_homogeneous() {
        format!(
            "homogeneous (E* = {:e} Pa, Hertz asperities)",
            s.top_plane_strain_modulus()
        )
    } else {
        format!(
            "layered, {} layer(s) on a {} base, E*1 = {:e} Pa",
            s.layers().len(),
            match s.base() {
                strata_runtime::Base::Rigid => "rigid",
                _ => "elastic",
            },
            s.top_plane_strain_modulus()
        )
    }
}

/// BEM: the engine's scene solve at the sample separations.
fn solve_bem(
    scene: &Scene,
    path: &Path,
    surface: Surface,
    opts: &EngineOptions,
    samples: usize,
    min_gap: Option<f64>,
) -> Result<SampledLaw> {
    let z_max = surface
        .heights()
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let g0 = z_max - surface.mean();
    let min_gap = match min_gap.or_else(|| load_min_gap(&scene.load, g0)) {
        Some(g) => g,
        None => {
            let p = largest_pressure(&scene.load)?;
            let mut one = scene.clone();
            one.load = LoadSpec::MeanPressures(vec![p]);
            let s = solve_surface(&one, path, surface.clone(), opts)
                .context("load.mean_pressures: the largest one sets the default --min-gap")?;
            s.steps.first().context("BEM: no step")?.gap
        }
    };
    if min_gap.is_nan() || min_gap >= g0 {
        bail!("--min-gap {min_gap:e}: must lie below the first-contact separation {g0:e} m");
    }
    progress::log(format!(
        "law: {samples} BEM solves from first contact g0 = {g0:e} m down to g = {min_gap:e} m"
    ));
    let area = surface.extent().0 * surface.extent().1;
    let mut sampled = scene.clone();
    sampled.load = LoadSpec::Separations(sample_gaps(g0, min_gap, samples));
    let sol = solve_surface(&sampled, path, surface, opts)?;
    let mut steps = sol.steps;
    // First contact: the flat touches the highest grid point only, p = A = 0 exactly
    // (the iterative solve may leave round-off there).
    if let Some(s) = steps.first_mut() {
        s.mean_pressure = 0.0;
        s.area_fraction = 0.0;
    }
    let il = InterfaceLaw::from_steps(&steps, area).context("BEM load curve")?;
    let warnings = sol.meta["warnings"]
        .as_array()
        .map(|w| {
            w.iter()
                .filter_map(|s| s.as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default();
    let conductance = scene.conductance.as_ref().map(|spec| {
        let mut h = conductance_steps(&sol.meta);
        if let Some(first) = h.first_mut() {
            *first = 0.0; // first contact: one grid point, no area
        }
        (spec.kind, h)
    });
    Ok(SampledLaw {
        law: il,
        model: describe(None),
        solid: solid(scene),
        e_star: scene.stack.contact_modulus(),
        nominal_area: area,
        surface: sol.meta["surface"].clone(),
        warnings,
        conductance,
    })
}

/// The per-step conductances of a solution's meta (`conductance_steps`); an infinite
/// one (full contact, `null`) as ∞.
fn conductance_steps(meta: &serde_json::Value) -> Vec<f64> {
    meta["conductance_steps"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|s| s["conductance"].as_f64().unwrap_or(f64::INFINITY))
                .collect()
        })
        .unwrap_or_default()
}

const CONVENTION: &str = "g = separation of the mean planes (P26), g0 = z_M - zbar its value at first contact (z_M: the highest summit in the N and I models, the highest grid point in the BEM; g, the flat's height above the mean plane, means the same in every model); overclosure h = g0 - g (Abaqus convention: positive when closing); mean_pressure p = P/A0 (nominal pressure); area_fraction = A/A0; dp_dg = derivative of the monotone interpolant of p(g) (<= 0), equal to -(dP/d delta)/A0 of the solver at the samples; p = 0 for g >= g0";

fn json(s: &SampledLaw, scene: &Path) -> Result<String> {
    let g0 = s.law.first_contact_gap();
    let law: Vec<serde_json::Value> = s
        .law
        .samples()
        .zip(s.law.validity())
        .map(|((g, p, d, a), v)| {
            serde_json::json!({"gap": g, "overclosure": g0 - g, "mean_pressure": p,
                               "area_fraction": a, "dp_dg": d, "valid": v.is_valid(),
                               "validity": v.describe()})
        })
        .collect();
    let v = serde_json::json!({
        "scene": scene.display().to_string(),
        "model": s.model,
        "solid": s.solid,
        "e_star_1": s.e_star,
        "nominal_area": s.nominal_area,
        "first_contact_gap": g0,
        "min_gap": s.law.min_gap(),
        "samples": s.law.len(),
        "limited_slopes": s.law.limited_slopes(),
        "linear_table_deviation": {
            "of_max_pressure": s.law.linear_table_deviation().of_max,
            "local_where_p_above_1pc_of_max": s.law.linear_table_deviation().local,
        },
        "validity_warnings": s.law.validity_warnings(),
        "surface": s.surface,
        "warnings": s.warnings,
        "convention": CONVENTION,
        "units": {"valid": "inside the model's validity (validity: why not)",
                  "gap": "m", "overclosure": "m", "mean_pressure": "Pa",
                  "area_fraction": "1", "dp_dg": "Pa/m", "nominal_area": "m^2", "e_star_1": "Pa"},
        "law": law,
    });
    let mut v = v;
    if let Some((kind, h)) = &s.conductance {
        // [conductance]: h_c per sample (null where infinite: full contact)
        for (entry, &hc) in v["law"].as_array_mut().into_iter().flatten().zip(h) {
            entry["conductance"] = serde_json::json!(hc);
        }
        v["units"]["conductance"] = serde_json::json!(match kind {
            ConductionKind::Thermal => "W/(m^2 K)",
            ConductionKind::Electrical => "S/m^2",
        });
        v["conductance_kind"] = serde_json::json!(kind.name());
    }
    Ok(serde_json::to_string_pretty(&v)?)
}

pub fn run(a: Args) -> Result<()> {
    let t0 = Instant::now();
    check_samples(a.samples)?;
    check_min_gap(a.min_gap)?;
    let outs = outputs(&a)?;
    let scene = Scene::from_file(&a.scene)?;
    if scene.plasticity.is_some() || scene.unload {
        bail!(
            "scene {}: the law of a plastic interface (a loading and an unloading curve) is not \
             written yet; `strata solve` gives the plastic BEM curve, loading and unloading",
            a.scene.display()
        );
    }
    let paths: Vec<PathBuf> = outs.iter().map(|(_, p)| p.clone()).collect();
    let inputs = scene.inputs(&a.scene);
    for p in &paths {
        refuse_inputs("--out", p, &inputs)?;
    }
    let set = OutputSet::files("--out", &paths, a.force)?;
    let opts = EngineOptions {
        cache_dir: a.cache_dir.clone(),
        ..Default::default()
    };
    let solved = crate::engine::load_surface(&scene, opts.quiet)
        .and_then(|surface| sample_law(&scene, &a.scene, surface, &opts, a.samples, a.min_gap))
        .with_context(|| format!("scene {}", a.scene.display()))?;
    if outs.iter().any(|(f, _)| *f == Format::Abaqus) {
        for w in solved.law.calculix_warnings() {
            crate::stdio::eprint_line(format_args!("warning: {w}"));
        }
    }
    for (f, p) in &outs {
        let text = match f {
            Format::Csv => solved.law.csv(),
            Format::Json => json(&solved, &a.scene)?,
            Format::Abaqus => solved.abaqus_block(&a.scene.display().to_string()),
            Format::All => bail!("internal error: --format all was not expanded"),
        };
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        set.write(&name, text.as_bytes())?;
    }
    set.commit()?;
    let l = &solved.law;
    progress::log(format!(
        "wrote {} samples (g from {:e} to {:e} m, p up to {:e} Pa) to {} in {:.3} s; \
         piecewise-linear table within {:.1e} of p_max ({:.1e} locally where p > 1% of p_max){}",
        l.len(),
        l.first_contact_gap(),
        l.min_gap(),
        l.samples().last().map_or(0.0, |s| s.1),
        outs.iter()
            .map(|(_, p)| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
        t0.elapsed().as_secs_f64(),
        l.linear_table_deviation().of_max,
        l.linear_table_deviation().local,
        if l.limited_slopes() > 0 {
            format!(
                "; {} sample slope(s) limited for monotonicity",
                l.limited_slopes()
            )
        } else {
            String::new()
        }
    ));
    Ok(())
}
