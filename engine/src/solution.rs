//! The typed result of a solved scene: the load curve ([`Step`]s), one column per
//! effect the scene asked for ([`PlasticInfo`], [`ConductanceInfo`] per step), and the
//! summary that `curve.json` holds ([`Summary`]). Everything here derives
//! [`serde::Serialize`]; JSON is made only by the front ends that write it (the CLI's
//! `curve.json`, the Python package's `meta`), never between the engine's layers.
//!
//! Units are SI throughout: lengths in m, pressures and moduli in Pa, areas in m²,
//! conductances per nominal area in W/(m²·K) (thermal) or S/m² (electrical), times in s.

use serde::Serialize;
use strata_runtime::rough::Step;
use strata_runtime::surface::{Detrend, Form, RepairReport, Surface, SurfaceStats};

/// The step at which a load path stopped ([`crate::engine::EngineOptions::keep_partial`]).
#[derive(Debug, Clone)]
pub struct StepFailure {
    /// Index of the failing step (= the number of steps solved before it).
    pub step: usize,
    /// Its approach δ (m).
    pub delta: f64,
    /// Why it failed.
    pub error: String,
}

/// A solved scene.
#[derive(Debug, Clone)]
pub struct SceneSolution {
    /// One entry per load step, in the scene's order.
    pub steps: Vec<Step>,
    /// With `[plasticity]`: one record per step (same order as `steps`).
    pub plastic: Option<Vec<PlasticInfo>>,
    /// With `[conductance]`: one record per step (same order as `steps`).
    pub conductance: Option<Vec<ConductanceInfo>>,
    /// With `[friction]`: one record per step (same order as `steps`).
    pub tangential: Option<Vec<TangentialInfo>>,
    /// With `[load] tangential` (BEM): the tangential path at the last step's pressure
    /// (`tangential.csv`).
    pub tangential_path: Option<TangentialCurve>,
    /// Summary for `curve.json`: model, solid, E*₁, nominal area, the effects' settings…
    pub summary: Summary,
    /// Wall time of the solve, without table building (s).
    pub seconds: f64,
    /// Set when the path stopped early (only with
    /// [`crate::engine::EngineOptions::keep_partial`]).
    pub failed: Option<StepFailure>,
}

impl SceneSolution {
    /// The conductance h_c of each step (W/(m²·K) or S/m²; ∞ at full contact), when the
    /// scene has `[conductance]`.
    pub fn conductances(&self) -> Option<Vec<f64>> {
        self.conductance
            .as_ref()
            .map(|c| c.iter().map(|c| c.conductance).collect())
    }

    /// The plastic area fraction A_pl/A₀ of each step (1), when the scene has
    /// `[plasticity]`.
    pub fn plastic_area_fractions(&self) -> Option<Vec<f64>> {
        self.plastic
            .as_ref()
            .map(|p| p.iter().map(|p| p.plastic_area_fraction).collect())
    }

    /// The full-stick tangential stiffness K_t of the sample at each step (N/m), when the
    /// scene has `[friction]`.
    pub fn tangential_stiffnesses(&self) -> Option<Vec<f64>> {
        self.tangential
            .as_ref()
            .map(|t| t.iter().map(|t| t.tangential_stiffness).collect())
    }

    /// The per-step columns the scene's effects add to curve.csv after `valid`, in their
    /// order: `plastic_area_fraction` with `[plasticity]`, then `conductance` with
    /// `[conductance]` (∞ at full contact), then `tangential_stiffness` with
    /// `[friction]`.
    pub fn effect_columns(&self) -> Vec<(&'static str, Vec<f64>)> {
        let mut out = Vec::new();
        if let Some(p) = self.plastic_area_fractions() {
            out.push(("plastic_area_fraction", p));
        }
        if let Some(h) = self.conductances() {
            out.push(("conductance", h));
        }
        if let Some(k) = self.tangential_stiffnesses() {
            out.push(("tangential_stiffness", k));
        }
        out
    }
}

/// One step's plastic quantities (`[plasticity]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlasticInfo {
    /// Plastic area fraction A_pl/A₀ (1): BEM, the points at p = H; asperity models,
    /// the capped tips' flowing area.
    pub plastic_area_fraction: f64,
    /// The BEM's further per-step records (none for the asperity models).
    #[serde(flatten)]
    pub bem: Option<BemPlasticInfo>,
}

/// The capped BEM solve's records of one step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BemPlasticInfo {
    /// Grid points at p = H.
    pub plastic_points: usize,
    /// Largest plastic depth u_pl (m).
    pub plastic_depth_max: f64,
    /// Flattened volume / A₀ (m).
    pub plastic_depth_mean: f64,
    /// Largest KKT violation of the bounded problem / RMS height (1).
    pub kkt_bounded: f64,
    /// Iterations of the bounded solve.
    pub bounded_iterations: usize,
    /// Iterations on the rigid offset.
    pub offset_iterations: usize,
    /// Active-set changes (MPRGP).
    pub active_set_steps: usize,
    /// Whether the bounded solve fell back to MPRGP.
    pub bounded_fallback: bool,
}

/// One step's interface conductance (`[conductance]`, physics.md §6.2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ConductanceInfo {
    /// h_c per nominal area (W/(m²·K) or S/m²); ∞ at full contact (null in JSON).
    pub conductance: f64,
    /// The BEM's iterative solve (none for the asperity models).
    #[serde(flatten)]
    pub bem: Option<BemConductanceInfo>,
}

/// One step's full-stick tangential stiffness (`[friction]`,
/// [`crate::effects::friction`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TangentialInfo {
    /// K_t of the sample (N/m): the contact discs' full-stick stiffnesses in parallel.
    pub tangential_stiffness: f64,
}

/// The tangential path of `[load] tangential` (BEM, [`crate::effects::friction`]): Coulomb
/// partial slip of the last load step's contact at its fixed pressure, the tangential
/// force Q = (Q/μP)·μP applied along x in the path's steps (force control, the
/// normal–tangential coupling ignored), each step from the last one's stick/slip state.
#[derive(Debug, Clone, Serialize)]
pub struct TangentialCurve {
    /// The coefficient of friction μ (1).
    pub coefficient: f64,
    /// The normal force P of the last load step (N): Σ p times the pixel area.
    pub normal_force: f64,
    /// What the path is.
    pub definition: &'static str,
    /// One record per value of the path, in order.
    pub steps: Vec<TangentialPoint>,
    /// The energy dissipated by slip over the path (J, ≥ 0).
    pub dissipation: f64,
    /// Time of the path (s).
    pub seconds: f64,
    pub units: TangentialCurveUnits,
}

/// One step of a [`TangentialCurve`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TangentialPoint {
    /// The ratio Q/(μP) asked for (1).
    pub force_ratio: f64,
    /// The tangential force Q carried along x (N): the traction's sum times the pixel area.
    pub tangential_force: f64,
    /// The flat's rigid tangential displacement s along x (m), from the fresh contact
    /// (the periodic cell's displacements have zero mean, as in the normal BEM).
    pub tangential_displacement: f64,
    /// The stick area over the contact area (1): points with |q| < μp over points with
    /// p > 0.
    pub stick_fraction: f64,
    /// The energy dissipated by slip in the step (J).
    pub dissipation: f64,
    /// Iterations of the step's slip solve.
    pub iterations: usize,
    /// The step's final error (Coulomb's conditions, relative).
    pub error: f64,
}

/// The units of [`TangentialCurve`] and its steps.
#[derive(Debug, Clone, Serialize)]
pub struct TangentialCurveUnits {
    pub normal_force: &'static str,
    pub force_ratio: &'static str,
    pub tangential_force: &'static str,
    pub tangential_displacement: &'static str,
    pub stick_fraction: &'static str,
    pub dissipation: &'static str,
}

impl TangentialCurveUnits {
    /// SI.
    pub fn si() -> Self {
        TangentialCurveUnits {
            normal_force: "N",
            force_ratio: "1",
            tangential_force: "N",
            tangential_displacement: "m",
            stick_fraction: "1 (stick area over contact area)",
            dissipation: "J",
        }
    }
}

/// The BEM conduction solve's records of one step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BemConductanceInfo {
    /// CG iterations.
    pub conductance_iterations: usize,
    /// Final relative residual (1).
    pub conductance_residual: f64,
}

/// The summary of a solved scene (`curve.json` without its `steps`).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// The scene file as the front end names it (empty when solved from memory: the
    /// front end sets it).
    pub scene: String,
    /// The model in words.
    pub model: String,
    /// The model's short name for titles (`N model`, `I model (periodic 5×5)`, `BEM`).
    pub model_short: String,
    /// The stack in a few words.
    pub stack: String,
    /// The solid in words.
    pub solid: String,
    /// E*₁ of the pair (Pa): the scale of `pressure_ratio`.
    pub e_star_1: f64,
    /// Nominal area A₀ (m²).
    pub nominal_area: f64,
    /// Asperity models: the summits of the surface.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub summits: Option<usize>,
    /// z_M − z̄ (m): the separation at first contact.
    pub z_max_minus_mean: f64,
    /// The surface as solved.
    pub surface: SurfaceReport,
    /// The surface's and the solve's warnings.
    pub warnings: Vec<String>,
    /// BEM: the largest final CG error of the steps.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bem_final_error: Option<f64>,
    /// Wall time of the solve with its effects, without table building (s).
    pub seconds: f64,
    /// The units of the steps' columns.
    pub units: CurveUnits,
    /// BEM: the resolution diagnostics per step.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resolution: Option<ResolutionSummary>,
    /// An elastic counterface.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub counterface: Option<CounterfaceSummary>,
    /// `[plasticity]`: its settings.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plasticity: Option<PlasticitySummary>,
    /// `[conductance]`: its settings.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub conductance: Option<ConductanceSummary>,
    /// `[friction]`: its settings and what was computed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionSummary>,
    /// A path that stopped at a failing step.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub partial: Option<PartialSummary>,
}

/// The units of curve.json's per-step columns.
#[derive(Debug, Clone, Serialize)]
pub struct CurveUnits {
    pub delta: &'static str,
    pub gap: &'static str,
    pub mean_pressure: &'static str,
    pub pressure_ratio: &'static str,
    pub area_fraction: &'static str,
    pub stiffness: &'static str,
    /// BEM: contacts are patches.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contacts: Option<&'static str>,
}

impl CurveUnits {
    /// The asperity models' units (contacts are summits in contact).
    pub fn asperity() -> Self {
        CurveUnits {
            delta: "m",
            gap: "m",
            mean_pressure: "Pa",
            pressure_ratio: "1",
            area_fraction: "1",
            stiffness: "N/m (dP/dδ of the sample)",
            contacts: None,
        }
    }

    /// The BEM's units (contacts are contact patches).
    pub fn bem() -> Self {
        CurveUnits {
            contacts: Some("contact patches"),
            ..Self::asperity()
        }
    }
}

/// The surface as solved: its statistics, what repair filled, the reader's log and the
/// removed form (curve.json `surface`, `strata surface info --json`), SI units.
#[derive(Debug, Clone, Serialize)]
pub struct SurfaceReport {
    /// Shape, pixel size, sides, periodicity, mean, RMS height and slope, peak to valley.
    #[serde(flatten)]
    pub stats: SurfaceStats,
    /// Points filled by repair.
    pub repaired_points: usize,
    /// What the checks found and repair filled (null when not checked).
    pub repair: Option<RepairReport>,
    /// The reader's log lines.
    pub read: Vec<String>,
    /// The removed form (null when none was removed).
    pub form: Option<FormReport>,
    /// The units of the fields.
    pub units: SurfaceUnits,
}

impl SurfaceReport {
    /// Of a surface.
    pub fn of(surface: &Surface) -> Self {
        SurfaceReport {
            stats: surface.stats(),
            repaired_points: surface.repaired(),
            repair: surface.repair_report().copied(),
            read: surface.log().to_vec(),
            form: surface.form().map(FormReport::of),
            units: SurfaceUnits::default(),
        }
    }
}

/// The removed form: the kind, the tilt as slopes z_x, z_y (1), the second derivatives
/// for `"curvature"` (1/m), the RMS of the removed form and of the remaining roughness
/// (m). The statistics beside it are those of the remaining roughness.
#[derive(Debug, Clone, Serialize)]
pub struct FormReport {
    pub detrend: &'static str,
    pub slope_x: f64,
    pub slope_y: f64,
    pub form_rms: f64,
    pub roughness_rms: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curvature_xx: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curvature_xy: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curvature_yy: Option<f64>,
}

impl FormReport {
    /// Of a removed form.
    pub fn of(f: &Form) -> Self {
        let curved = f.kind == Detrend::Curvature;
        FormReport {
            detrend: f.kind.name(),
            slope_x: f.slope.0,
            slope_y: f.slope.1,
            form_rms: f.rms,
            roughness_rms: f.residual_rms,
            curvature_xx: curved.then_some(f.curvature.0),
            curvature_xy: curved.then_some(f.curvature.1),
            curvature_yy: curved.then_some(f.curvature.2),
        }
    }
}

/// The units of [`SurfaceReport`].
#[derive(Debug, Clone, Serialize)]
pub struct SurfaceUnits {
    pub shape: &'static str,
    pub pixel_size: &'static str,
    pub size: &'static str,
    pub mean_height: &'static str,
    pub rms_height: &'static str,
    pub rms_slope: &'static str,
    pub peak_to_valley: &'static str,
    pub repair: RepairUnits,
    pub form: FormUnits,
}

impl Default for SurfaceUnits {
    fn default() -> Self {
        SurfaceUnits {
            shape: "points (x, y)",
            pixel_size: "m",
            size: "m",
            mean_height: "m",
            rms_height: "m",
            rms_slope: "1",
            peak_to_valley: "m",
            repair: RepairUnits {
                fraction: "1",
                iterations: "1",
                r#else: "points",
            },
            form: FormUnits {
                slope_x: "1",
                slope_y: "1",
                curvature_xx: "1/m",
                curvature_xy: "1/m",
                curvature_yy: "1/m",
                form_rms: "m",
                roughness_rms: "m",
            },
        }
    }
}

/// The units of [`RepairReport`]: the fraction and iterations dimensionless, the rest
/// counts of points.
#[derive(Debug, Clone, Serialize)]
pub struct RepairUnits {
    pub fraction: &'static str,
    pub iterations: &'static str,
    #[serde(rename = "else")]
    pub r#else: &'static str,
}

/// The units of [`FormReport`].
#[derive(Debug, Clone, Serialize)]
pub struct FormUnits {
    pub slope_x: &'static str,
    pub slope_y: &'static str,
    pub curvature_xx: &'static str,
    pub curvature_xy: &'static str,
    pub curvature_yy: &'static str,
    pub form_rms: &'static str,
    pub roughness_rms: &'static str,
}

/// An elastic counterface: the pair's E* is what `e_star_1` and `pressure_ratio` use.
#[derive(Debug, Clone, Serialize)]
pub struct CounterfaceSummary {
    /// The counterface's stack in a few words.
    pub stack: String,
    /// E*₁ of the counterface's top (Pa).
    pub e_star_1_counterface: f64,
    /// E*₁ of the body's top (Pa).
    pub e_star_1_body: f64,
    /// The pair's E* (Pa): 1/E* = 1/E*₁,body + 1/E*₁,counterface.
    pub e_star_pair: f64,
    /// Whether the counterface is rough (its heights added to the body's).
    pub rough: bool,
    pub note: &'static str,
}

/// `[plasticity]`'s settings.
#[derive(Debug, Clone, Serialize)]
pub struct PlasticitySummary {
    /// Hardness H (Pa): the pressure cap.
    pub hardness: f64,
    /// What was simulated, in words.
    pub note: &'static str,
    /// BEM: the units of the per-step records.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub units: Option<PlasticUnits>,
}

/// The units of [`PlasticInfo`] (BEM).
#[derive(Debug, Clone, Serialize)]
pub struct PlasticUnits {
    pub plastic_area_fraction: &'static str,
    pub plastic_depth_max: &'static str,
    pub plastic_depth_mean: &'static str,
    pub kkt_bounded: &'static str,
}

/// `[conductance]`'s settings and what was solved.
#[derive(Debug, Clone, Serialize)]
pub struct ConductanceSummary {
    /// `thermal` or `electrical`.
    pub kind: &'static str,
    /// The counterface's conduction in words.
    pub counterface: String,
    /// The first body's top conductivity (W/(m·K) or S/m).
    pub top_conductivity: f64,
    /// What h_c is, for the model that solved it.
    pub definition: &'static str,
    /// The I model's conduction kernel.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kernel: Option<KernelSummary>,
    /// Time of the conductance solves (s).
    pub seconds: f64,
    pub units: ConductanceUnits,
}

/// `[friction]`'s settings and what was computed.
#[derive(Debug, Clone, Serialize)]
pub struct FrictionSummary {
    /// The coefficient of friction μ (1).
    pub coefficient: f64,
    /// What the tangential stiffness is.
    pub definition: &'static str,
    /// The decades [k₀, k₁) of log₁₀(a/h₁) of the disc-stiffness table used (null on a
    /// half-space or without contact).
    pub table_decades: Option<[i32; 2]>,
    /// Time of the tangential stiffness, with its table (s).
    pub seconds: f64,
    pub units: FrictionUnits,
}

/// The units of [`FrictionSummary`] and its per-step column.
#[derive(Debug, Clone, Serialize)]
pub struct FrictionUnits {
    pub coefficient: &'static str,
    pub tangential_stiffness: &'static str,
}

/// The units of [`ConductanceSummary`].
#[derive(Debug, Clone, Serialize)]
pub struct ConductanceUnits {
    pub conductance: &'static str,
    pub top_conductivity: &'static str,
}

/// The I model's conduction kernel (periodic Ewald sums or an isolated sample).
#[derive(Debug, Clone, Serialize)]
pub struct KernelSummary {
    /// The kernel table's grid.
    pub grid: [usize; 2],
    /// Ewald width σ (m); 0 isolated.
    pub ewald_width: f64,
    /// Extent ρ_max of the smooth rest's spectrum (1/m); 0 isolated.
    pub spectrum_extent: f64,
    /// A spot's own periodic images G_self (K/W, or Ω); 0 isolated.
    pub self_images: f64,
}

/// A path that stopped at a failing step: the steps before it stand.
#[derive(Debug, Clone, Serialize)]
pub struct PartialSummary {
    pub failed_step: usize,
    /// The failing step's approach (m).
    pub delta: f64,
    pub error: String,
    pub note: &'static str,
}

impl PartialSummary {
    /// Of a failure.
    pub fn of(f: &StepFailure) -> Self {
        PartialSummary {
            failed_step: f.step,
            delta: f.delta,
            error: f.error.clone(),
            note: "the path stopped at this step: the steps before it are written",
        }
    }
}

/// The BEM's resolution diagnostics with the thresholds of its warnings.
#[derive(Debug, Clone, Serialize)]
pub struct ResolutionSummary {
    pub patch_pixels_min: f64,
    pub peak_pressure_max_over_e_star: f64,
    pub note: &'static str,
    pub steps: Vec<StepResolutionReport>,
    pub units: ResolutionUnits,
}

/// One BEM step's resolution diagnostics.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct StepResolutionReport {
    /// Median contact patch (pixels); null without contact.
    pub median_patch_pixels: Option<f64>,
    /// Largest patch (pixels).
    pub largest_patch_pixels: usize,
    /// Peak pressure (Pa).
    pub peak_pressure: f64,
    /// Peak pressure / E* (1).
    pub peak_pressure_over_e_star: f64,
}

/// The units of [`StepResolutionReport`].
#[derive(Debug, Clone, Serialize)]
pub struct ResolutionUnits {
    pub median_patch_pixels: &'static str,
    pub largest_patch_pixels: &'static str,
    pub peak_pressure: &'static str,
    pub peak_pressure_over_e_star: &'static str,
}
