//! The contact law of a scene's rough interface, sampled (the library behind `strata
//! law`, the Python package's `Scene.law` and the C ABI's laws): p(g), A(g)/A₀ and dp/dg
//! from first contact down to a smallest separation, by the scene's model.

use crate::error::{Context, EngineError, Result, bail_input};
use strata_runtime::Solid;
use strata_runtime::conduction::ConductionKind;
use strata_runtime::interface::{
    InterfaceLaw, MAX_SAMPLES, SampleOptions, abaqus_real, sample_gaps,
};
use strata_runtime::rough::{Images, Model, RoughContact};
use strata_runtime::surface::Surface;

use crate::contact_law::{ContactLaw, ContactLawError};
use crate::engine::solve;
use crate::progress;
use crate::scene::{LoadSpec, ModelKind, Scene};
use crate::setup::{EngineOptions, Observer, Quiet, law_for};
use crate::solution::SurfaceReport;

/// One sample of a plastic interface's unloading curve: (gap (m), mean pressure (Pa),
/// area fraction).
pub type UnloadingSample = (f64, f64, f64);

/// The unloading branch's slopes dp/dg (Pa/m, ≤ 0) at its samples `back` (deepest
/// first, gaps growing): the one-sided difference along the branch, forward (towards
/// the next, larger gap) at every sample but the last, backward there — at the deepest
/// sample the unloading slope, not the loading one (the tips flowed on the way in); 0
/// where two samples share a gap.
pub fn unloading_slopes(back: &[UnloadingSample]) -> Vec<f64> {
    let n = back.len();
    (0..n)
        .map(|j| {
            let (a, b) = if j + 1 < n {
                (back[j], back[j + 1])
            } else if j > 0 {
                (back[j - 1], back[j])
            } else {
                return 0.0;
            };
            let dg = b.0 - a.0;
            if dg == 0.0 { 0.0 } else { (b.1 - a.1) / dg }
        })
        .collect()
}
/// Samples the `*GAP CONDUCTANCE` block leaves out: (at full contact, the first such
/// pressure, with a pressure not above the previous line's).
type LeftOut = (usize, Option<f64>, usize);

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
    pub surface: SurfaceReport,
    /// The surface's warnings (plausibility, a form that dominates the heights).
    pub warnings: Vec<String>,
    /// With `[conductance]`: the interface conductance h_c (W/(m²·K) or S/m²) at each
    /// sample, in the order of [`InterfaceLaw::samples`] (0 at first contact).
    pub conductance: Option<(ConductionKind, Vec<f64>)>,
    /// With `[friction]` (N and I models): the full-stick tangential stiffness K_t of the
    /// sample (N/m) at each sample, in the order of [`InterfaceLaw::samples`] (0 at
    /// first contact).
    pub tangential_stiffness: Option<Vec<f64>>,
    /// With `[plasticity]` (BEM): the hardness (Pa) and the unloading curve from the
    /// deepest sample back to first contact, (gap, mean pressure, area fraction) per
    /// sample — it lies below the loading curve (the flattened tips do not spring back).
    pub unloading: Option<(f64, Vec<UnloadingSample>)>,
}

impl SampledLaw {
    /// The law as a [`ContactLaw`]: p(g), A(g)/A₀, dp/dg and, with `[conductance]`,
    /// h_c(g) and h_c(p), with `[friction]` K_t(g) and K_t(p). An error when a
    /// sample's conductance is infinite (full contact).
    pub fn contact_law(&self) -> Result<ContactLaw, ContactLawError> {
        let law = ContactLaw::new(
            self.law.clone(),
            self.conductance.as_ref().map(|(k, h)| (*k, h.as_slice())),
        )?;
        match &self.tangential_stiffness {
            Some(k) => law.with_tangential_stiffness(k),
            None => Ok(law),
        }
    }

    /// The Abaqus/CalculiX `*SURFACE BEHAVIOR` block with its `**` comment lines
    /// naming the scene (`scene`: how it is shown), the model and the solid.
    pub fn abaqus_block(&self, scene: &str) -> String {
        let (h_max, p_max) = self.fe_range();
        self.law.abaqus_block(&[
            "strata law: pressure-overclosure table of a rough (layered) interface".into(),
            format!("scene: {scene}"),
            format!("model: {}", self.model),
            format!("solid: {}", self.solid),
            format!(
                "FE RANGE: this table covers overclosure 0 <= h <= {} m, pressure 0 <= p <= {} Pa.\n  \
                 Size the FE load so that no contact node's overclosure exceeds h_max = {} m: beyond\n  \
                 it CalculiX holds p = {} Pa (no stiffness) and reports nothing; check the run's\n  \
                 contact pressures (*CONTACT PRINT) against p_max, or sample deeper (--min-gap).",
                abaqus_real(h_max),
                abaqus_real(p_max),
                abaqus_real(h_max),
                abaqus_real(p_max)
            ),
        ]) + &self.plastic_note()
            + &self.gap_conductance_block()
    }

    /// The name of the amplitude in [`SampledLaw::range_block`].
    pub const RANGE_AMPLITUDE: &'static str = "STRATA_LAW_RANGE";

    /// A CalculiX/Abaqus `*AMPLITUDE` that rises linearly over the step's time from 0
    /// to the law's h_max (m, [`SampledLaw::fe_range`]), with `**` comments: a face
    /// driven by `*BOUNDARY, AMPLITUDE=STRATA_LAW_RANGE` with magnitude −1 moves h_max
    /// over the step. The interface's overclosure is that motion less the bodies'
    /// compression (≥ 0 under a compressive load), so it stays inside the table
    /// whatever the FE model's compliance: the deck is sized from the law.
    pub fn range_block(&self, law_file: &str) -> String {
        let (h_max, p_max) = self.fe_range();
        format!(
            "** strata law: the FE range of {law_file}: overclosure 0 <= h <= {h} m, pressure\n\
             ** 0 <= p <= {p} Pa. A face moved by *BOUNDARY, AMPLITUDE={name} with a magnitude\n\
             ** of -1. moves h_max = {h} m over the step; the interface's overclosure (that\n\
             ** motion less the bodies' compression) stays inside the table.\n\
             *AMPLITUDE, NAME={name}\n\
             0., 0., 1., {h}\n",
            h = abaqus_real(h_max),
            p = abaqus_real(p_max),
            name = Self::RANGE_AMPLITUDE,
        )
    }

    /// The FE range the table covers: the largest overclosure h_max = g₀ − g_min (m) and
    /// the pressure there, p_max (Pa). An FE interface driven beyond h_max leaves the
    /// table (CalculiX holds p_max with zero stiffness).
    pub fn fe_range(&self) -> (f64, f64) {
        let g0 = self.law.first_contact_gap();
        let p_max = self
            .law
            .samples()
            .map(|(_, p, _, _)| p)
            .fold(0.0_f64, f64::max);
        (g0 - self.law.min_gap(), p_max)
    }

    /// With `[plasticity]`: `**` lines saying that the tabular law above is elastic in
    /// Abaqus and CalculiX (unloading retraces it) while the interface's unloading
    /// curve (in strata's CSV and JSON) lies below it; empty otherwise.
    pub fn plastic_note(&self) -> String {
        let Some((h, back)) = &self.unloading else {
            return String::new();
        };
        if back.is_empty() {
            return format!(
                "** PLASTIC INTERFACE: the asperity tips were capped at the hardness H = {} Pa. The\n\
                 **   table above is the LOADING curve; Abaqus and CalculiX tabular laws are elastic\n\
                 **   (unloading retraces loading), while the flattened tips do not spring back. The\n\
                 **   N and I models follow the loading path only: model.kind = \"bem\" with\n\
                 **   [plasticity] gives the unloading curve.\n",
                abaqus_real(*h)
            );
        }
        let drop = back
            .iter()
            .zip(self.law.samples().collect::<Vec<_>>().iter().rev())
            .map(|((_, pu, _), (_, pl, _, _))| if *pl > 0.0 { 1.0 - pu / pl } else { 0.0 })
            .fold(0.0_f64, f64::max);
        format!(
            "** PLASTIC INTERFACE: the asperity tips were capped at the hardness H = {} Pa. The\n\
             **   table above is the LOADING curve; Abaqus and CalculiX tabular laws are elastic\n\
             **   (unloading retraces loading), while the flattened tips do not spring back: the\n\
             **   unloading curve (strata's CSV `branch` column and JSON `unloading`) lies up to\n\
             **   {:.1} % below it in pressure at equal separation.\n",
            abaqus_real(*h),
            100.0 * drop
        )
    }

    /// With `[conductance]`: the `*GAP CONDUCTANCE, PRESSURE` block (data lines
    /// `conductance, pressure`, pressure strictly increasing from the first line
    /// `0., 0.`) with its `**` comments, which say what Abaqus and CalculiX 2.20 read
    /// (CalculiX's source: gapconductances.f, springstiff_n2f_th.f, springforc_f2f_th.f;
    /// checked by tests/it/calculix_thermal.rs); empty otherwise.
    pub fn gap_conductance_block(&self) -> String {
        let Some((kind, _)) = &self.conductance else {
            return String::new();
        };
        let (rows, _) = self.gap_conductance_rows();
        let n = rows.len();
        let lines: String = rows
            .iter()
            .map(|(hc, p)| format!("{}, {}\n", abaqus_real(*hc), abaqus_real(*p)))
            .collect();
        let dropped = self
            .gap_conductance_dropped()
            .map(|w| format!("** NOTE: {w}.\n"))
            .unwrap_or_default();
        let unit = kind.interface_conductance_unit();
        format!(
            "** strata law: {} gap conductance of the rough interface against contact pressure.\n\
             ** conductance = h_c, the interface (constriction) conductance per nominal area ({unit}):\n\
             **   a uniform jump dT on the contact spots, no flux elsewhere, h_c = mean flux / dT;\n\
             **   the bulk 1-D resistance of both bodies is excluded (the FE mesh carries it).\n\
             ** pressure = mean (nominal) contact pressure p = P/A0 (Pa), the same as in the table\n\
             **   above; h_c was solved at the same samples. {n} data lines: conductance, pressure.\n\
             ** Abaqus: PRESSURE makes the second field the contact pressure (else a clearance).\n\
             ** CalculiX 2.20 warns \"parameter not recognized: PRESSURE\" and reads its one form,\n\
             **   conductance, contact pressure[, temperature] (no temperature: one table),\n\
             **   linear in p between lines, the first (last) line's conductance below (above)\n\
             **   the table; more than 200 lines are resampled onto 200 evenly spaced pressures.\n\
             ** CalculiX 2.20 evaluates the conductance at the pressure of a LINEAR or\n\
             **   EXPONENTIAL law only. With the TABULAR law above, NODE TO SURFACE takes the\n\
             **   FIRST line's conductance at every pressure (0: no heat crosses, ccx stops) and\n\
             **   SURFACE TO SURFACE does not run. In CalculiX use this block without the table\n\
             **   above, under PRESSURE-OVERCLOSURE=LINEAR with TYPE=SURFACE TO SURFACE and at\n\
             **   most 20 lines (its arrays hold 20: strata law --samples 20), or\n\
             **   PRESSURE-OVERCLOSURE=EXPONENTIAL with TYPE=NODE TO SURFACE and NLGEOM on the\n\
             **   step (LINEAR there gives the last line's conductance; without NLGEOM the\n\
             **   undeformed pressure's); the contact pressure then follows that law, not\n\
             **   strata's. Tested deck: strata's examples/calculix/thermal_block.inp.\n\
             {dropped}\
             *GAP CONDUCTANCE, PRESSURE\n{lines}",
            kind.name()
        )
    }

    /// The data lines of the `*GAP CONDUCTANCE` block, (h_c, p) with p strictly
    /// increasing, and the samples left out: (at full contact: h_c infinite, with the
    /// first such pressure; pressure not above the previous line's).
    fn gap_conductance_rows(&self) -> (Vec<(f64, f64)>, LeftOut) {
        let Some((_, h)) = &self.conductance else {
            return (Vec::new(), (0, None, 0));
        };
        let mut rows = Vec::new();
        let (mut full, mut first_full, mut flat) = (0, None, 0);
        let mut last = f64::NEG_INFINITY;
        for ((_, p, _, _), &hc) in self.law.samples().zip(h) {
            if !hc.is_finite() {
                // full contact: the interface conducts without bound
                full += 1;
                first_full = first_full.or(Some(p));
                continue;
            }
            if p.is_nan() || p <= last {
                flat += 1;
                continue;
            }
            last = p;
            rows.push((hc, p));
        }
        (rows, (full, first_full, flat))
    }

    /// Why the `*GAP CONDUCTANCE` block has fewer data lines than samples (a warning
    /// and a `**` note in the deck), or `None` when every sample is written.
    pub fn gap_conductance_dropped(&self) -> Option<String> {
        let (rows, (full, first_full, flat)) = self.gap_conductance_rows();
        if full + flat == 0 {
            return None;
        }
        let mut why = Vec::new();
        if full > 0 {
            why.push(format!(
                "{full} at full contact (h_c infinite, from p = {} Pa on: the table's last line holds above it)",
                abaqus_real(first_full.unwrap_or(f64::NAN))
            ));
        }
        if flat > 0 {
            why.push(format!(
                "{flat} whose pressure does not rise above the previous line's"
            ));
        }
        Some(format!(
            "the *GAP CONDUCTANCE block has {} data lines for {} samples: {} left out",
            rows.len(),
            rows.len() + full + flat,
            why.join(", ")
        ))
    }
}

/// The contact law of a scene on its (already loaded) `surface`: `samples` separations
/// from first contact down to `min_gap` (default: the smallest separation the scene's
/// load reaches), by the scene's model (N, I or BEM), as `strata law` samples it.
pub fn sample_law(
    scene: &Scene,
    surface: Surface,
    opts: &EngineOptions,
    obs: &mut dyn Observer,
    samples: usize,
    min_gap: Option<f64>,
) -> Result<SampledLaw> {
    check_samples(samples)?;
    check_min_gap(min_gap)?;
    let sampled = match model_of(scene) {
        Some(m) => solve_asperities(scene, surface, opts, obs, m, samples, min_gap),
        None => solve_bem(scene, surface, opts, obs, samples, min_gap),
    }?;
    for w in sampled.law.validity_warnings() {
        crate::stdio::eprint_line(format_args!("warning: law: {w}"));
    }
    Ok(sampled)
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
        None => "boundary elements (FFT-BEM)".into(),
    }
}

/// The BEM's description with what ran: a periodic cell, or a non-periodic sample on
/// the unbounded solid (zero-padded convolution), square or rectangular grid.
fn describe_bem(periodic: bool, shape: (usize, usize)) -> String {
    format!(
        "boundary elements (FFT-BEM, {}, {}×{} grid)",
        if periodic {
            "periodic cell"
        } else {
            "non-periodic sample on the unbounded solid"
        },
        shape.0,
        shape.1
    )
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
        _ => Err(EngineError::Internal("load")),
    }
}

pub fn check_samples(n: usize) -> Result<()> {
    if n < 2 {
        bail_input!("--samples {n}: at least 2 samples are needed (first contact and --min-gap)");
    }
    if n > MAX_SAMPLES {
        bail_input!("--samples {n}: at most {MAX_SAMPLES}");
    }
    Ok(())
}

pub fn check_min_gap(g: Option<f64>) -> Result<()> {
    if let Some(g) = g
        && !g.is_finite()
    {
        bail_input!("--min-gap {g}: not a finite separation (m)");
    }
    Ok(())
}

/// N and I models: the law of `strata law` on a scene of the asperity models (and of
/// the C ABI's laws, through `law_build::sample_asperity_law`).
pub fn solve_asperities(
    scene: &Scene,
    surface: Surface,
    opts: &EngineOptions,
    obs: &mut dyn Observer,
    model: Model,
    samples: usize,
    min_gap: Option<f64>,
) -> Result<SampledLaw> {
    if let Some(pl) = scene.plasticity {
        return solve_capped_asperities(scene, surface, opts, obs, model, samples, min_gap, pl);
    }
    let (surface_json, warnings) = crate::setup::surface_report(&surface, obs);
    let keep = (scene.conductance.is_some() || scene.friction.is_some()).then(|| surface.clone());
    let law = law_for(scene, opts, obs)?;
    let rc = RoughContact::from_surface(law.as_ref(), &surface)?
        .with_params(crate::setup::solver_params(scene, opts));
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
    // the model's (N or I) effects (conductance, tangential stiffness) at the law's own
    // separations, in one solve
    let effects = match keep {
        Some(surface) => {
            let mut at = scene.clone();
            at.load = LoadSpec::Separations(il.samples().map(|s| s.0).collect());
            let what = match (&scene.conductance, &scene.friction) {
                (Some(_), Some(_)) => "[conductance], [friction]",
                (Some(_), None) => "[conductance]",
                _ => "[friction]",
            };
            Some(solve(&at, Some(surface), opts, &mut Quiet).context(what)?)
        }
        None => None,
    };
    let conductance = match (&scene.conductance, &effects) {
        (Some(spec), Some(sol)) => Some((spec.kind, sol.conductances().unwrap_or_default())),
        _ => None,
    };
    let tangential_stiffness = effects.as_ref().and_then(|s| s.tangential_stiffnesses());
    Ok(SampledLaw {
        law: il,
        model: describe(Some(model)),
        solid: solid(scene),
        e_star: law.e_star(),
        nominal_area: rc.area(),
        surface: surface_json,
        warnings,
        conductance,
        tangential_stiffness,
        unloading: None,
    })
}

/// The capped N and I models (`[plasticity]`): the engine's scene solve at the sample
/// separations (loading only: the asperity models have no unloading branch, so the law
/// carries the hardness and an empty unloading curve, and its note says so), with the
/// capped spots' conductance when the scene asks for it.
#[allow(clippy::too_many_arguments)]
fn solve_capped_asperities(
    scene: &Scene,
    surface: Surface,
    opts: &EngineOptions,
    obs: &mut dyn Observer,
    model: Model,
    samples: usize,
    min_gap: Option<f64>,
    pl: crate::scene::PlasticitySpec,
) -> Result<SampledLaw> {
    let (surface_json, warnings) = crate::setup::surface_report(&surface, obs);
    // first contact and the area need no elastic law
    let e_star = scene.bodies.contact_modulus();
    let hom = strata_runtime::law::Homogeneous { e_star };
    let rc = RoughContact::from_surface(&hom, &surface)?;
    let (g0, nominal_area) = (rc.top_to_mean(), rc.area());
    let min_gap = scene_min_gap(scene, &surface, opts, obs, g0, min_gap)?;
    progress::log(format!(
        "law: {samples} capped solves from first contact g0 = {g0:e} m down to g = {min_gap:e} m"
    ));
    let mut sampled = scene.clone();
    sampled.load = LoadSpec::Separations(sample_gaps(g0, min_gap, samples));
    let sol = solve(&sampled, Some(surface), opts, obs)?;
    let il = InterfaceLaw::from_steps(&sol.steps, nominal_area).context("capped load curve")?;
    Ok(SampledLaw {
        law: il,
        model: describe(Some(model)) + " with tips capped at the hardness",
        solid: solid(scene),
        e_star,
        nominal_area,
        surface: surface_json,
        warnings,
        // the capped tips' spots at the same solves (the engine's, with [conductance])
        conductance: scene
            .conductance
            .as_ref()
            .map(|spec| (spec.kind, sol.conductances().unwrap_or_default())),
        tangential_stiffness: sol.tangential_stiffnesses(),
        unloading: Some((pl.hardness, Vec::new())),
    })
}

fn solid(scene: &Scene) -> String {
    let s = &scene.bodies;
    if let Some(c) = s.counterface.stack() {
        return format!(
            "{} against an elastic counterface ({}), pair E* = {:e} Pa",
            solid_of(&s.first),
            solid_of(c),
            s.contact_modulus()
        );
    }
    solid_of(&s.first)
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

/// The law's smallest separation (m): `--min-gap`, else the scene's load's deepest
/// separation, else the separation of the scene's largest mean pressure (one engine
/// solve); it must lie below first contact `g0` (m).
fn scene_min_gap(
    scene: &Scene,
    surface: &Surface,
    opts: &EngineOptions,
    obs: &mut dyn Observer,
    g0: f64,
    min_gap: Option<f64>,
) -> Result<f64> {
    let min_gap = match min_gap.or_else(|| load_min_gap(&scene.load, g0)) {
        Some(g) => g,
        None => {
            let p = largest_pressure(&scene.load)?;
            let mut one = scene.clone();
            one.load = LoadSpec::MeanPressures(vec![p]);
            let s = solve(&one, Some(surface.clone()), opts, obs)
                .context("load.mean_pressures: the largest one sets the default --min-gap")?;
            s.steps.first().context("no step")?.gap
        }
    };
    if min_gap.is_nan() || min_gap >= g0 {
        bail_input!("--min-gap {min_gap:e}: must lie below the first-contact separation {g0:e} m");
    }
    Ok(min_gap)
}

/// BEM: the engine's scene solve at the sample separations.
fn solve_bem(
    scene: &Scene,
    surface: Surface,
    opts: &EngineOptions,
    obs: &mut dyn Observer,
    samples: usize,
    min_gap: Option<f64>,
) -> Result<SampledLaw> {
    let z_max = surface
        .heights()
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let g0 = z_max - surface.mean();
    let min_gap = scene_min_gap(scene, &surface, opts, obs, g0, min_gap)?;
    progress::log(format!(
        "law: {samples} BEM solves from first contact g0 = {g0:e} m down to g = {min_gap:e} m"
    ));
    let area = surface.extent().0 * surface.extent().1;
    let mut sampled = scene.clone();
    sampled.load = LoadSpec::Separations(sample_gaps(g0, min_gap, samples));
    // [plasticity]: the return path too (the unloading curve), the law from the loading
    sampled.unload = scene.plasticity.is_some();
    // the law is the normal one: no tangential path
    sampled.tangential = None;
    let ran = describe_bem(surface.is_periodic(), surface.shape());
    let sol = solve(&sampled, Some(surface), opts, obs)?;
    let conductances = sol.conductances().unwrap_or_default();
    // [friction]: the full-stick K_t of each sample's contact set (0 at first contact:
    // one grid point, no area)
    let tangential_stiffness = sol.tangential_stiffnesses().map(|mut k| {
        k.truncate(samples);
        if let Some(first) = k.first_mut() {
            *first = 0.0;
        }
        k
    });
    let mut steps = sol.steps;
    let unloading = scene.plasticity.map(|pl| {
        let back: Vec<UnloadingSample> = steps
            .iter()
            .skip(samples.saturating_sub(1))
            .map(|s| (s.gap, s.mean_pressure, s.area_fraction))
            .collect();
        (pl.hardness, back)
    });
    steps.truncate(samples);
    // First contact: the flat touches the highest grid point only, p = A = 0 exactly
    // (the iterative solve may leave round-off there).
    if let Some(s) = steps.first_mut() {
        s.mean_pressure = 0.0;
        s.area_fraction = 0.0;
    }
    let il = InterfaceLaw::from_steps(&steps, area).context("BEM load curve")?;
    let warnings = sol.summary.warnings.clone();
    let conductance = scene.conductance.as_ref().map(|spec| {
        let mut h = conductances;
        h.truncate(samples);
        if let Some(first) = h.first_mut() {
            *first = 0.0; // first contact: one grid point, no area
        }
        (spec.kind, h)
    });
    Ok(SampledLaw {
        law: il,
        model: ran,
        solid: solid(scene),
        e_star: scene.bodies.contact_modulus(),
        nominal_area: area,
        surface: sol.summary.surface.clone(),
        warnings,
        conductance,
        tangential_stiffness,
        unloading,
    })
}

/// The file of the law's FE range beside its Abaqus block `inp` (`law.inp` →
/// `law_range.inp`), and the block's file name for its comment.
pub fn range_path(inp: &std::path::Path) -> (std::path::PathBuf, String) {
    let stem = inp
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = inp
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    (inp.with_file_name(format!("{stem}_range.inp")), name)
}

/// The law's CSV; with `[conductance]` a `conductance` column after `valid` (h_c,
/// W/(m²·K) or S/m², empty where infinite: full contact); with `[friction]` a
/// `tangential_stiffness` column after it (K_t of the sample, N/m); with `[plasticity]` a
/// `branch` column (`loading`, then `unloading` from the deepest sample back to first
/// contact: gap, overclosure, pressure, area, dp_dg the one-sided difference along the
/// unloading branch (`sampled_law::unloading_slopes`); valid 1 and the conductance NaN
/// on the unloading rows). The Python package's `ContactLaw.csv()` writes this text too.
pub fn csv(s: &SampledLaw) -> String {
    let base = s.law.csv();
    let mut out = String::new();
    let h = s.conductance.as_ref().map(|(_, h)| h);
    for (i, line) in base.lines().enumerate() {
        out.push_str(line);
        if let Some(h) = h {
            match i {
                0 => out.push_str(",conductance"),
                _ => match h.get(i - 1) {
                    Some(v) if v.is_finite() => out.push_str(&format!(",{v:e}")),
                    _ => out.push(','),
                },
            }
        }
        if let Some(k) = &s.tangential_stiffness {
            match i {
                0 => out.push_str(",tangential_stiffness"),
                _ => match k.get(i - 1) {
                    Some(v) => out.push_str(&format!(",{v:e}")),
                    None => out.push(','),
                },
            }
        }
        if s.unloading.is_some() {
            out.push_str(if i == 0 { ",branch" } else { ",loading" });
        }
        out.push('\n');
    }
    if let Some((_, back)) = &s.unloading {
        let g0 = s.law.first_contact_gap();
        let hc = if h.is_some() { ",NaN" } else { "" };
        let kt = if s.tangential_stiffness.is_some() {
            ",NaN"
        } else {
            ""
        };
        let slopes = unloading_slopes(back);
        for ((g, p, a), d) in back.iter().zip(&slopes).skip(1) {
            out.push_str(&format!(
                "{g:e},{:e},{p:e},{a:e},{d:e},1{hc}{kt},unloading\n",
                g0 - g
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 20 samples of which the last 10 are at full contact (h_c infinite): the block
    /// holds the 10 finite ones and says, in a `**` note and in the warning, that 10 were
    /// left out at full contact and from which pressure (the deck said nothing).
    #[test]
    fn gap_conductance_block_says_what_full_contact_left_out() {
        let n = 20;
        let gaps: Vec<f64> = (0..n).map(|i| 1e-6 * (n - i) as f64).collect();
        let p: Vec<f64> = (0..n).map(|i| 1e5 * (i * i) as f64).collect();
        let k: Vec<f64> = (0..n).map(|i| 1e11 * (1 + i) as f64).collect();
        let a: Vec<f64> = (0..n).map(|i| i as f64 / n as f64).collect();
        let law = InterfaceLaw::from_samples(&gaps, &p, &k, &a).unwrap();
        let h: Vec<f64> = (0..n)
            .map(|i| {
                if i < 10 {
                    1e3 * i as f64
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        let s = SampledLaw {
            law,
            model: "test".into(),
            solid: "test".into(),
            e_star: 1e9,
            nominal_area: 1e-6,
            surface: SurfaceReport::of(
                &Surface::new(
                    vec![0.0, 1e-6, 2e-6, 0.0, 1e-6, 0.0, 2e-6, 0.0, 1e-6],
                    3,
                    3,
                    1e-3,
                    true,
                )
                .unwrap(),
            ),
            warnings: Vec::new(),
            conductance: Some((ConductionKind::Thermal, h)),
            tangential_stiffness: None,
            unloading: None,
        };
        let block = s.gap_conductance_block();
        let data = block
            .split_once("*GAP CONDUCTANCE, PRESSURE\n")
            .unwrap()
            .1
            .lines()
            .count();
        assert_eq!(data, 10);
        let w = s.gap_conductance_dropped().unwrap();
        assert!(
            w.contains("10 data lines for 20 samples") && w.contains("10 at full contact"),
            "{w}"
        );
        assert!(w.contains(&format!("p = {} Pa", abaqus_real(1e7))), "{w}");
        assert!(block.contains(&format!("** NOTE: {w}.")), "{block}");
        // every sample finite: no note
        let all = SampledLaw {
            conductance: Some((ConductionKind::Thermal, (0..n).map(|i| i as f64).collect())),
            ..s
        };
        assert!(all.gap_conductance_dropped().is_none());
        assert!(!all.gap_conductance_block().contains("NOTE"));
    }
}
