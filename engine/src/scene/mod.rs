//! Scenes (TOML): the stack, the surface, the model and the load of one rough-contact
//! case. Paths are relative to the scene file. SI units.
//!
//! ```toml
//! [stack]
//! file = "stacks/paper.toml"   # or inline [[stack.layer]] / [stack.base] (+ name);
//! table = "paper.strata"       # optional surrogate table for a layered stack
//! [surface]
//! file = "surface.npy"         # .x3p (ISO 25178-72), .nc (SurfaceTopography NetCDF: sizes,
//!                              # unit and periodic flag from the file), .zip (contact.engineering
//!                              # container), .npy (2-D f64) or a plain-text
//!                              # matrix; or [surface.generate]. First array axis = x.
//! topography = 0               # .zip: which topography (number from 0, or its name)
//! size = 1e-3                  # .npy/text: length of the first axis (m, square pixels),
//!                              # or size = [Lx, Ly] (m), or pixel_size = [dx, dy] (m);
//!                              # an .x3p gives its own pixel sizes (no size/pixel_size)
//! height_unit = "um"           # .npy/text: "m" (default) | "mm" | "um" | "nm"; .x3p is in m
//! detrend = "plane"            # files: "plane" (default) | "none" | "curvature"
//!                              # (least-squares form removed after reading; periodic
//!                              # files: "none", the only choice: a tilt is not periodic)
//! periodic = true              # default: true for generated surfaces, false for files
//! repair = "median"            # files only: fill NaN/inf heights, invalid points and
//!                              # spikes (clusters of any size) by harmonic interpolation
//!                              # ("harmonic" is the same; default: refuse)
//! [surface.generate]           # size, grid, fractal_dimension, k_min, k_max, rms, seed
//! [model]
//! kind = "interacting"         # "independent" | "interacting" | "bem"
//! images = "periodic"          # "periodic" | "isolated"; default periodic on a periodic surface
//! image_cells = 2              # periodic images on the (2m+1)² block, default m = 2 (5×5)
//! [load]
//! separations = [9e-6, 8e-6]   # or approach = { from = 1e-6, to = 9e-6, steps = 20 }
//!                              # or mean_pressures = [1e5, 1e6]  (Pa, solved for)
//! [output]                     # optional
//! maps = "last"                # "none" (default) | "last" | "all" (or true = "all");
//!                              # pressure and gap maps, model.kind = "bem" only
//! format = ["npy", "netcdf"]   # the maps' files: "npy" (default) and/or "netcdf"
//!                              # (contact.engineering's results.nc per step)
//! [solver]                     # optional: the budgets and tolerances error messages
//!                              # name (defaults of rough::Params and BemOptions)
//! max_step_newton_steps = 20000 # I model: Newton steps per load step
//! max_step_evaluations = 100000 # I model: energy evaluations per load step
//! kkt_tolerance = 1e-8         # I model: KKT acceptance (relative to max interference)
//! max_pressure_iterations = 200 # N and I models: solves per mean pressure
//! bem_max_iterations = 20000   # BEM: iterations per solve
//! bem_tolerance = 1e-10        # BEM: convergence tolerance
//! [conductance]                # optional (model.kind = "bem", periodic or not,
//!                              # "independent": Σ of the spots' conductances, or
//!                              # "interacting": the spots heat each other): the
//! kind = "thermal"             # interface conductance h_c of every step (physics.md §6.2),
//!                              # "thermal" (W/(m²·K)) or "electrical" (S/m²); both bodies
//!                              # must conduct: the stack's conductivities, and the
//!                              # counterface's: [counterface] thermal_conductivity = 50
//!                              # (a rigid flat as a conducting half-space), conduction =
//!                              # "perfect", or an elastic counterface's own stack
//! [friction]                   # optional (every model):
//! coefficient = 0.3            # μ > 0; curve.csv gains tangential_stiffness (N/m over the
//!                              # sample, full stick: Σ K_t(a_i) of the contact discs, or
//!                              # the BEM's contact set stuck to the flat)
//! # [load] tangential = { from = 0.1, to = 0.9, steps = 9 }
//! #                            # optional (model.kind = "bem" with [friction]): a
//! #                            # tangential path at the last normal step, Q/(μP) from
//! #                            # `from` to `to` (each in (−1, 1); from > to unloads):
//! #                            # Coulomb partial slip, written to tangential.csv
//! ```
//!
//! Every error names the offending field (`surface.size`, `load.approach.steps`, …).

use std::path::{Path, PathBuf};

use strata_bem::BemOptions;
use strata_runtime::conduction::{ConductionCompliance, ConductionKind};
use strata_runtime::resources::MemoryLimit;
use strata_runtime::rough::{Images, Params};
use strata_runtime::stack::{Bodies, Counterface, RigidConduction, Stack};
use strata_runtime::surface::container::Pick;
use strata_runtime::surface::{GenerateParams, ReadOptions, Spacing, Surface};

mod error;
mod fields;
pub mod file;
mod validate;
pub use error::SceneError;
use file::{SceneFile, serde_error};

/// Where the surface comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum SurfaceSource {
    /// An `.x3p`, `.npy` or text file (absolute, resolved against the scene directory).
    File(PathBuf),
    /// A generated self-affine surface.
    Generate(GenerateParams),
}

/// The `[surface]` table.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceSpec {
    pub source: SurfaceSource,
    /// How a file is read: `spacing` from `size` (L of the first axis, or [Lx, Ly]) or
    /// `pixel_size` (`None` for an `.x3p`, which gives its own; `Size(L)` for a generated
    /// surface), `periodic`, `repair`, `height_unit`, `detrend`.
    pub read: ReadOptions,
    /// A contact.engineering container's topography (`topography = n` or `"name"`;
    /// `None`: the first, or not a container).
    pub topography: Option<Pick>,
}

/// The model kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    Independent,
    Interacting,
    /// Full-field periodic boundary-element solution (the `bem` module).
    Bem,
}

/// The `[model]` table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModelSpec {
    pub kind: ModelKind,
    pub images: Images,
}

/// The `[load]` table.
#[derive(Debug, Clone, PartialEq)]
pub enum LoadSpec {
    /// Separations g_n (m).
    Separations(Vec<f64>),
    /// Approaches δ (m), `steps` values evenly from `from` to `to`.
    Approach { from: f64, to: f64, steps: usize },
    /// Mean pressures p_n (Pa), solved for.
    MeanPressures(Vec<f64>),
}

/// Which pressure and gap maps `strata solve` writes (`[output] maps`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MapsSpec {
    /// No maps (default).
    #[default]
    None,
    /// The maps of the last load step only.
    Last,
    /// The maps of every load step.
    All,
}

/// The files the maps are written as (`[output] format`): a set of formats, at least one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MapFormats {
    /// `.npy` maps of pressure and gap (the default; the PNG pictures come either way).
    pub npy: bool,
    /// One NetCDF-3 file per step in contact.engineering's `results.nc` layout.
    pub netcdf: bool,
}

impl Default for MapFormats {
    fn default() -> Self {
        MapFormats {
            npy: true,
            netcdf: false,
        }
    }
}

/// The optional `[output]` table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OutputSpec {
    /// Pressure (Pa) and gap (m) maps of the full-field solution (`model.kind = "bem"`).
    pub maps: MapsSpec,
    /// The maps' file formats (default: `.npy` and PNG only).
    pub format: MapFormats,
}

/// The optional `[solver]` table: budgets and tolerances of the solvers (unset: the
/// defaults of [`Params`] and [`BemOptions`]). Every one of them that an error message
/// asks to raise is here; the budgets count work (Newton steps, evaluations,
/// iterations), never time, so a scene's result does not depend on the machine's load.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SolverSpec {
    /// [`Params::max_step_newton_steps`].
    pub max_step_newton_steps: Option<usize>,
    /// [`Params::max_step_evaluations`].
    pub max_step_evaluations: Option<usize>,
    /// [`Params::kkt_tolerance`].
    pub kkt_tolerance: Option<f64>,
    /// [`Params::max_pressure_iterations`].
    pub max_pressure_iterations: Option<usize>,
    /// [`BemOptions::max_iterations`].
    pub bem_max_iterations: Option<usize>,
    /// [`BemOptions::tolerance`].
    pub bem_tolerance: Option<f64>,
}

/// The keys of `[solver]`.
pub const SOLVER_KEYS: &str = "max_step_newton_steps, max_step_evaluations, kkt_tolerance, \
                               max_pressure_iterations, bem_max_iterations, bem_tolerance";

impl SolverSpec {
    /// The asperity models' parameters: the defaults with the keys given.
    pub fn params(&self) -> Params {
        let mut p = Params::default();
        p.max_step_newton_steps = self
            .max_step_newton_steps
            .unwrap_or(p.max_step_newton_steps);
        p.max_step_evaluations = self.max_step_evaluations.unwrap_or(p.max_step_evaluations);
        p.kkt_tolerance = self.kkt_tolerance.unwrap_or(p.kkt_tolerance);
        p.max_pressure_iterations = self
            .max_pressure_iterations
            .unwrap_or(p.max_pressure_iterations);
        p
    }

    /// The BEM options: `base` (the caller's, or the defaults) with the keys given.
    pub fn bem_options(&self, base: BemOptions) -> BemOptions {
        BemOptions {
            max_iterations: self.bem_max_iterations.unwrap_or(base.max_iterations),
            tolerance: self.bem_tolerance.unwrap_or(base.tolerance),
            ..base
        }
    }
}

/// A validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The first body (`[stack]`) and its counterface (`[counterface]`, or the stack
    /// file's own): every model sees the pair (physics.md §6.1). The counterface's
    /// rough surface (`[counterface.surface]`), heights as seen from the first body, is
    /// added to the first body's ([`Surface::plus_counterface`]).
    pub bodies: Bodies<SurfaceSpec>,
    /// The stack file (`stack.file`, resolved), if the stack is not inline.
    pub stack_file: Option<PathBuf>,
    /// The counterface's stack file (`counterface.file`, resolved), if any.
    pub counterface_file: Option<PathBuf>,
    /// Optional table file (absolute).
    pub table: Option<PathBuf>,
    pub surface: SurfaceSpec,
    pub model: ModelSpec,
    pub load: LoadSpec,
    pub output: OutputSpec,
    /// The optional `[solver]` table.
    pub solver: SolverSpec,
    /// The optional `[plasticity]` table: the hardness cap (physics.md §6.3).
    pub plasticity: Option<PlasticitySpec>,
    /// `[load] unload = true`: after the loading steps, the same steps back in reverse
    /// (a return path; with plasticity it follows the flattened surface).
    pub unload: bool,
    /// The optional `[conductance]` table: the interface conductance per nominal area
    /// of every step (physics.md §6.2). Absent: nothing of conduction is computed.
    pub conductance: Option<ConductanceSpec>,
    /// The optional `[friction]` table: the coefficient of friction; with it every
    /// step gets the full-stick tangential stiffness of the sample (the engine's
    /// `effects::friction`). Absent: nothing tangential is computed.
    pub friction: Option<FrictionSpec>,
    /// `[load] tangential = { from, to, steps }` (BEM with `[friction]` only): the
    /// tangential path run at the last normal step. Absent: no path.
    pub tangential: Option<TangentialPathSpec>,
}

/// `[load] tangential`: a tangential load path at the fixed pressure of the load path's
/// last step, in ratios Q/(μP) of the tangential force Q (N, along x) to the friction
/// limit μP (P the normal force of that step, N): `steps` values evenly from `from` to
/// `to`, each in (−1, 1) (a negative ratio pulls along −x; `from > to` unloads). The
/// first value is reached from the fresh contact (q = 0) in one step, each next one from
/// the last (Coulomb's law with history).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentialPathSpec {
    /// The first ratio Q/(μP) (1).
    pub from: f64,
    /// The last ratio Q/(μP) (1).
    pub to: f64,
    /// The number of values (≥ 1).
    pub steps: usize,
}

impl TangentialPathSpec {
    /// The ratios Q/(μP) of the path, in order.
    pub fn ratios(&self) -> Vec<f64> {
        let n = self.steps;
        (0..n)
            .map(|i| {
                if n == 1 {
                    self.from
                } else {
                    self.from + (self.to - self.from) * i as f64 / (n - 1) as f64
                }
            })
            .collect()
    }
}

/// `[friction]`: Coulomb friction at the interface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionSpec {
    /// The coefficient of friction μ (1), finite and > 0.
    pub coefficient: f64,
}

/// `[conductance]`: the interface conductance h_c per nominal area (physics.md §6.2),
/// with the conduction of both bodies read and checked when the scene is read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConductanceSpec {
    /// `kind = "thermal"` (h_c in W/(m²·K)) or `"electrical"` (S/m²).
    pub kind: ConductionKind,
    /// How the counterface conducts.
    pub counterface: CounterfaceConduction,
}

/// How the counterface conducts for one conduction kind: a view of the scene's
/// [`Counterface`] ([`CounterfaceConduction::of`], the one place it is derived), which
/// the spot sums and the BEM read; the C ABI states it directly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CounterfaceConduction {
    /// `conduction = "perfect"`: a perfect conductor (C_th,B = 0).
    Perfect,
    /// The rigid flat as a conducting half-space of this conductivity (W/(m·K) or S/m):
    /// C_th,B = 1/(k_B |k|).
    HalfSpace(f64),
    /// The elastic counterface stack's own conductivities ([`Counterface::Elastic`]).
    Stack,
}

impl CounterfaceConduction {
    /// The view of `counterface` for `kind`: `None` for a rigid flat that gives no
    /// conductivity of this kind and is not a perfect conductor.
    pub fn of<S>(counterface: &Counterface<S>, kind: ConductionKind) -> Option<Self> {
        match counterface {
            Counterface::Elastic {
                perfect_conductor: true,
                ..
            }
            | Counterface::Rigid {
                conduction: RigidConduction::Perfect,
                ..
            } => Some(CounterfaceConduction::Perfect),
            Counterface::Elastic { .. } => Some(CounterfaceConduction::Stack),
            Counterface::Rigid {
                conduction: RigidConduction::HalfSpace(c),
                ..
            } => match kind {
                ConductionKind::Thermal => c.thermal,
                ConductionKind::Electrical => c.electrical,
            }
            .map(CounterfaceConduction::HalfSpace),
        }
    }
}

impl ConductanceSpec {
    /// The conduction compliance of the first body `stack` (its counterface not
    /// included) for this kind.
    pub fn body(&self, stack: &Stack) -> Result<ConductionCompliance, SceneError> {
        ConductionCompliance::new(stack, self.kind).map_err(|e| SceneError::Invalid {
            field: "stack".into(),
            reason: format!(
                "{e}; [conductance] kind = \"{}\" needs it",
                self.kind.name()
            ),
        })
    }

    /// The conduction compliance of the elastic `counterface`
    /// ([`CounterfaceConduction::Stack`]; `None` otherwise).
    pub fn counterface_stack<S>(
        &self,
        counterface: &Counterface<S>,
    ) -> Result<Option<ConductionCompliance>, SceneError> {
        match (self.counterface, counterface.stack()) {
            (CounterfaceConduction::Stack, Some(c)) => ConductionCompliance::new(c, self.kind)
                .map(Some)
                .map_err(|e| SceneError::Invalid {
                    field: "counterface".into(),
                    reason: format!(
                        "{e}; [conductance] kind = \"{}\" needs it (or counterface.conduction = \"perfect\")",
                        self.kind.name()
                    ),
                }),
            _ => Ok(None),
        }
    }
}

/// `[plasticity]`: elastic–perfectly plastic asperity tips, the contact pressure capped
/// by the hardness (physics.md §6.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlasticitySpec {
    /// The hardness H (Pa) of the top material.
    pub hardness: f64,
}

impl SurfaceSpec {
    /// Physical length (m) of the first axis of the surface, which has `rows` points
    /// along it: the generated size, `size = L` or `size = [L, _]`, or dx·rows for
    /// `pixel_size = [dx, _]`; NaN when only the file knows it (.x3p).
    pub fn first_axis_length(&self, rows: usize) -> f64 {
        match &self.source {
            SurfaceSource::Generate(g) => g.size,
            SurfaceSource::File(_) => match self.read.spacing {
                Some(Spacing::Size(l)) | Some(Spacing::Extent(l, _)) => l,
                Some(Spacing::Pixel(dx, _)) => dx * rows as f64,
                None => f64::NAN,
            },
        }
    }
}

impl Scene {
    /// Reads and validates a scene file; relative paths resolve against its directory.
    pub fn from_file(path: &Path) -> Result<Scene, SceneError> {
        let text = strata_runtime::resources::read_text_capped(
            path,
            strata_runtime::resources::TEXT_FILE_CAP,
            "a scene file",
            &MemoryLimit::of_machine(),
        )
        .map_err(|e| SceneError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Scene::from_str_in(&text, dir).map_err(|e| SceneError::InFile {
            path: path.display().to_string(),
            error: Box::new(e),
        })
    }

    /// The files a command reading this scene (from `path`) reads: (what, path) for the
    /// scene itself, its stack file, table and surface file, for the output sets' check
    /// that no output overwrites an input (`strata::output_set::refuse_inputs`).
    pub fn inputs(&self, path: &Path) -> Vec<(String, PathBuf)> {
        let mut v = vec![("the scene".to_string(), path.to_path_buf())];
        if let Some(p) = &self.stack_file {
            v.push(("the scene's stack file".into(), p.clone()));
        }
        if let Some(p) = &self.table {
            v.push(("the scene's table".into(), p.clone()));
        }
        if let SurfaceSource::File(p) = &self.surface.source {
            v.push(("the scene's surface file".into(), p.clone()));
        }
        if let Some(p) = &self.counterface_file {
            v.push(("the scene's counterface stack file".into(), p.clone()));
        }
        if let Some(SurfaceSpec {
            source: SurfaceSource::File(p),
            ..
        }) = self.bodies.counterface.surface()
        {
            v.push(("the scene's counterface surface file".into(), p.clone()));
        }
        v
    }

    /// Parses a scene from TOML text, resolving relative paths against `dir`.
    pub fn from_str_in(text: &str, dir: &Path) -> Result<Scene, SceneError> {
        let de = toml::de::Deserializer::parse(text)
            .map_err(|e| SceneError::Syntax(strata_runtime::stack::toml_error_line(text, &e)))?;
        let file: SceneFile = serde_path_to_error::deserialize(de)
            .map_err(|e| serde_error(&e.path().to_string(), e.inner().message()))?;
        file.validate(dir, None)
    }

    /// A scene from any serde data of the scene file's form (the Python package's dict,
    /// as a JSON value); with `surface`, the `[surface]` table is not read (and must be
    /// absent): the Python package passes a surface built in memory this way, its
    /// `[stack]`, `[model]` and `[load]` validated as a file's, with the same messages.
    pub fn from_data_in<'de, D>(
        data: D,
        dir: &Path,
        surface: Option<SurfaceSpec>,
    ) -> Result<Scene, SceneError>
    where
        D: serde::Deserializer<'de>,
        D::Error: std::fmt::Display,
    {
        let file: SceneFile = serde_path_to_error::deserialize(data)
            .map_err(|e| serde_error(&e.path().to_string(), &e.inner().to_string()))?;
        file.validate(dir, surface)
    }

    /// Builds (reads or generates) the surface; a file by its extension (`.x3p`,
    /// `.npy`, else text) with the scene's spacing, height unit, repair and detrend.
    /// What the reader did is in [`Surface::log`].
    ///
    /// With a rough counterface (`[counterface.surface]`) the result is the composite
    /// surface h_A + h_B (physics.md §6.1). What is allocated is checked against
    /// `memory` first.
    pub fn load_surface(&self, memory: &MemoryLimit) -> Result<Surface, SceneError> {
        let own = load_spec(&self.surface, memory)?;
        match self.bodies.counterface.surface() {
            None => Ok(own),
            Some(c) => Ok(own.plus_counterface(&load_spec(c, memory)?)?),
        }
    }
}

fn load_spec(s: &SurfaceSpec, memory: &MemoryLimit) -> Result<Surface, SceneError> {
    let read = ReadOptions {
        memory: *memory,
        ..s.read
    };
    Ok(match &s.source {
        SurfaceSource::Generate(g) => Surface::generate_within(g, memory)?,
        SurfaceSource::File(p) => match &s.topography {
            Some(pick) => strata_runtime::surface::container::read_container(p, pick, &read)?,
            None => Surface::read(p, &read)?,
        },
    })
}

impl LoadSpec {
    /// The first step at which the load goes back (a separation that grows, an approach
    /// or a mean pressure that falls), as (its field, e.g. `load.separations[2]`, and a
    /// description): such a path unloads, which only the BEM follows with `[plasticity]`
    /// (the capped N and I models answer every step as a virgin loading). Equal
    /// neighbours do not go back.
    pub fn first_reversal(&self) -> Option<(String, String)> {
        let back = |v: &[f64], rises: bool| {
            v.windows(2)
                .position(|w| if rises { w[1] > w[0] } else { w[1] < w[0] })
        };
        match self {
            LoadSpec::Separations(g) => back(g, true).map(|i| {
                (
                    format!("load.separations[{}]", i + 1),
                    format!("{:e} m after {:e} m goes back up (unloads)", g[i + 1], g[i]),
                )
            }),
            LoadSpec::MeanPressures(p) => back(p, false).map(|i| {
                (
                    format!("load.mean_pressures[{}]", i + 1),
                    format!(
                        "{:e} Pa after {:e} Pa goes back down (unloads)",
                        p[i + 1],
                        p[i]
                    ),
                )
            }),
            LoadSpec::Approach { from, to, steps } => (*steps > 1 && to < from).then(|| {
                (
                    "load.approach".into(),
                    format!("from {from:e} m to {to:e} m goes back (unloads)"),
                )
            }),
        }
    }

    /// The approaches δ (m) for displacement-type loads, given z_M − z̄ (m) and the
    /// admissible maximum z_M − z_min (m); errors name the offending entry. None for
    /// pressure control.
    pub fn approaches(
        &self,
        top_to_mean: f64,
        max_delta: f64,
    ) -> Result<Option<Vec<f64>>, SceneError> {
        let check = |field: String, d: f64, shown: f64| -> Result<f64, SceneError> {
            if !(0.0..=max_delta).contains(&d) {
                return Err(SceneError::Invalid {
                    field,
                    reason: format!(
                        "{shown:e} m is out of range: the approach must lie in [0, {max_delta:e}] m, i.e. separations in [{:e}, {top_to_mean:e}] m",
                        top_to_mean - max_delta
                    ),
                });
            }
            Ok(d)
        };
        match self {
            LoadSpec::Separations(g) => g
                .iter()
                .enumerate()
                .map(|(i, &x)| check(format!("load.separations[{i}]"), top_to_mean - x, x))
                .collect::<Result<Vec<_>, _>>()
                .map(Some),
            LoadSpec::Approach { from, to, steps } => {
                check("load.approach.from".into(), *from, *from)?;
                check("load.approach.to".into(), *to, *to)?;
                let n = *steps;
                Ok(Some(
                    (0..n)
                        .map(|i| {
                            if n == 1 {
                                *from
                            } else {
                                from + (to - from) * i as f64 / (n - 1) as f64
                            }
                        })
                        .collect(),
                ))
            }
            LoadSpec::MeanPressures(_) => Ok(None),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[stack]
[[stack.layer]]
thickness = 1e-4
young = 4e9
poisson = 0.15
[stack.base]
kind = "rigid"
[surface]
size = 1e-3
[surface.generate]
grid = 64
fractal_dimension = 2.4
k_min = 2
k_max = 10
rms = 3.4e-6
seed = 1
[model]
kind = "interacting"
[load]
approach = { from = 1e-6, to = 9e-6, steps = 5 }
"#;

    fn parse(s: &str) -> Result<Scene, SceneError> {
        Scene::from_str_in(s, Path::new("."))
    }

    #[test]
    fn good_scene() {
        let s = parse(GOOD).unwrap();
        assert_eq!(s.model.images, Images::Periodic(2));
        assert!(s.surface.read.periodic);
        assert_eq!(s.bodies.first.layers().len(), 1);
        let d = s.load.approaches(1e-5, 2e-5).unwrap().unwrap();
        for (x, y) in d.iter().zip([1e-6, 3e-6, 5e-6, 7e-6, 9e-6]) {
            assert!((x - y).abs() < 1e-20);
        }
        assert_eq!(d.len(), 5);
        assert!(s.load_surface(&MemoryLimit::default()).is_ok());
    }

    fn err(s: &str) -> String {
        parse(s).unwrap_err().to_string()
    }

    #[test]
    fn bad_scenes_name_the_field() {
        assert!(err(&GOOD.replace("[model]", "[model]\ncolour = 1")).contains("model.colour"));
        assert!(err(&format!("{GOOD}\n[extra]\n")).contains("`extra`"));
        assert!(err(&GOOD.replace("rms = 3.4e-6", "rms = -1")).contains("surface.generate.rms"));
        assert!(err(&GOOD.replace("size = 1e-3", "size = -1e-3")).contains("surface.size"));
        assert!(err(&GOOD.replace("\"interacting\"", "\"magic\"")).contains("model.kind"));
        assert!(err(&GOOD.replace("steps = 5", "steps = 0")).contains("load.approach.steps"));
        assert!(err(&GOOD.replace("from = 1e-6", "from = -1e-6")).contains("load.approach.from"));
        assert!(err(&GOOD.replace("young = 4e9", "young = -4e9")).contains("young"));
        let f = GOOD.replace(
            "[surface.generate]\ngrid = 64\nfractal_dimension = 2.4\nk_min = 2\nk_max = 10\nrms = 3.4e-6\nseed = 1\n",
            "file = \"no-such-file.npy\"\n",
        );
        assert!(err(&f).contains("surface.file"), "{}", err(&f));
        let p = GOOD.replace(
            "approach = { from = 1e-6, to = 9e-6, steps = 5 }",
            "mean_pressures = [1e5, -2]",
        );
        assert!(err(&p).contains("load.mean_pressures[1]"));
        let two = GOOD.replace(
            "approach = { from = 1e-6, to = 9e-6, steps = 5 }",
            "separations = [1e-6]\nmean_pressures = [1e5]",
        );
        assert!(err(&two).contains("exactly one"));
        let s = parse(&GOOD.replace(
            "approach = { from = 1e-6, to = 9e-6, steps = 5 }",
            "separations = [1e-6, 5e-5]",
        ))
        .unwrap();
        let e = s.load.approaches(1e-5, 2e-5).unwrap_err().to_string();
        assert!(e.contains("load.separations[1]"), "{e}");
        // [output]
        let bem = GOOD.replace("\"interacting\"", "\"bem\"");
        assert_eq!(parse(&bem).unwrap().output.maps, MapsSpec::None);
        let maps = |v: &str| format!("{bem}\n[output]\nmaps = {v}\n");
        assert_eq!(
            parse(&maps("\"last\"")).unwrap().output.maps,
            MapsSpec::Last
        );
        assert_eq!(parse(&maps("true")).unwrap().output.maps, MapsSpec::All);
        assert!(err(&maps("\"some\"")).contains("output.maps"));
        assert!(err(&maps("3")).contains("output.maps"));
        // [output] format: the maps' files
        assert_eq!(
            parse(&maps("\"last\"")).unwrap().output.format,
            MapFormats::default()
        );
        let fmt = |f: &str| format!("{bem}\n[output]\nmaps = \"all\"\nformat = {f}\n");
        assert_eq!(
            parse(&fmt("[\"npy\", \"netcdf\"]")).unwrap().output.format,
            MapFormats {
                npy: true,
                netcdf: true
            }
        );
        assert_eq!(
            parse(&fmt("\"netcdf\"")).unwrap().output.format,
            MapFormats {
                npy: false,
                netcdf: true
            }
        );
        assert!(err(&fmt("[\"hdf5\"]")).contains("output.format"));
        assert!(err(&fmt("[]")).contains("empty"));
        assert!(err(&fmt("[3]")).contains("output.format"));
        let no_maps = format!("{bem}\n[output]\nformat = \"netcdf\"\n");
        assert!(err(&no_maps).contains("output.maps"));
        assert!(err(&format!("{bem}\n[output]\ncolour = 1\n")).contains("output.colour"));
        // [solver]
        let solver = |body: &str| format!("{GOOD}\n[solver]\n{body}\n");
        assert_eq!(parse(GOOD).unwrap().solver, SolverSpec::default());
        assert_eq!(
            parse(GOOD).unwrap().solver.params(),
            strata_runtime::rough::Params::default()
        );
        let s = parse(&solver(
            "max_step_newton_steps = 40000\nmax_step_evaluations = 7\nkkt_tolerance = 1e-7\n\
             max_pressure_iterations = 300\nbem_max_iterations = 50000\nbem_tolerance = 1e-9",
        ))
        .unwrap();
        let p = s.solver.params();
        assert_eq!(
            (p.max_step_newton_steps, p.max_step_evaluations),
            (40000, 7)
        );
        assert_eq!((p.kkt_tolerance, p.max_pressure_iterations), (1e-7, 300));
        let b = s.solver.bem_options(BemOptions::default());
        assert_eq!((b.max_iterations, b.tolerance), (50000, 1e-9));
        assert!(err(&solver("colour = 1")).contains("solver.colour"));
        assert!(err(&solver("colour = 1")).contains("max_step_evaluations"));
        assert!(err(&solver("max_step_newton_steps = 0")).contains("solver.max_step_newton_steps"));
        assert!(err(&solver("max_step_newton_steps = 1.5")).contains("an integer"));
        assert!(err(&solver("kkt_tolerance = 2")).contains("solver.kkt_tolerance"));
        assert!(err(&solver("bem_tolerance = \"x\"")).contains("solver.bem_tolerance"));
        assert!(err(&format!("solver = 1\n{GOOD}")).contains("`solver` must be a table"));
        let asperity = format!("{GOOD}\n[output]\nmaps = \"all\"\n");
        assert!(err(&asperity).contains("output.maps") && err(&asperity).contains("bem"));
    }

    /// A counterface of a counterface cannot be written, elastic or rigid; a scene
    /// built from JSON values (the Python package) reads through the same serde types
    /// and names the same fields as the TOML text.
    #[test]
    fn one_counterface_reader_and_json_scenes() {
        let nested = "[counterface]\n[counterface.base]\nkind = \"elastic\"\nyoung = 2e11\n\
                      poisson = 0.3\n[counterface.counterface]\n[counterface.counterface.base]\n\
                      kind = \"rigid\"";
        for c in [
            nested.to_string(),
            nested.replace(
                "[counterface.base]\nkind = \"elastic\"\nyoung = 2e11\npoisson = 0.3\n",
                "",
            ),
        ] {
            let e = err(&format!("{GOOD}\n{c}\n"));
            assert!(
                e.contains("counterface.counterface") && e.contains("own counterface"),
                "{e}"
            );
        }
        let e = err(&format!("{GOOD}\n[stack.counterface]\n"));
        assert!(e.contains("unknown key `stack.counterface`"), "{e}");
        // the same scene as JSON values: accepted, and errors name the same fields
        let file: file::SceneFile = toml::from_str(GOOD).unwrap();
        let json = serde_json::to_value(&file).unwrap();
        let from_json = Scene::from_data_in(json.clone(), Path::new("."), None).unwrap();
        assert_eq!(from_json, parse(GOOD).unwrap());
        let mut bad = json.clone();
        bad["load"]["approach"]["steps"] = serde_json::json!(1.5);
        let e = Scene::from_data_in(bad, Path::new("."), None)
            .unwrap_err()
            .to_string();
        assert_eq!(e, err(&GOOD.replace("steps = 5", "steps = 1.5")));
        assert!(
            e.contains("load.approach.steps") && e.contains("an integer"),
            "{e}"
        );
        let mut bad = json.clone();
        bad["stack"]["layer"][0]["youngs"] = serde_json::json!(1);
        let e = Scene::from_data_in(bad, Path::new("."), None)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("stack: layer 1: unknown key `youngs`"), "{e}");
        let mut bad = json;
        bad["model"]["kind"] = serde_json::json!("magic");
        let e = Scene::from_data_in(bad, Path::new("."), None)
            .unwrap_err()
            .to_string();
        assert_eq!(e, err(&GOOD.replace("\"interacting\"", "\"magic\"")));
    }

    /// `[conductance]`: the kinds, the counterface's conduction, and every missing
    /// property named (layer/base and field).
    #[test]
    fn conductance_table() {
        let bem = GOOD.replace("\"interacting\"", "\"bem\"");
        assert_eq!(parse(&bem).unwrap().conductance, None);
        let conducting = bem.replace(
            "poisson = 0.15\n",
            "poisson = 0.15\nthermal_conductivity = 0.3\n",
        );
        let conducting = conducting.replace(
            "kind = \"rigid\"\n",
            "kind = \"rigid\"\nconduction = \"isothermal\"\n",
        );
        let with = |scene: &str, extra: &str| format!("{scene}\n{extra}\n");
        let c = "[conductance]\nkind = \"thermal\"";
        // a rigid flat: a conducting half-space or a perfect conductor, never implied
        let s = parse(&with(
            &conducting,
            &format!("{c}\n[counterface]\nkind = \"rigid\"\nthermal_conductivity = 50"),
        ))
        .unwrap();
        let spec = s.conductance.unwrap();
        assert_eq!(spec.kind, ConductionKind::Thermal);
        assert_eq!(spec.counterface, CounterfaceConduction::HalfSpace(50.0));
        assert_eq!(spec.body(&s.bodies.first).unwrap().top_conductivity(), 0.3);
        let s = parse(&with(
            &conducting,
            &format!("{c}\n[counterface]\nconduction = \"perfect\""),
        ))
        .unwrap();
        assert_eq!(
            s.conductance.unwrap().counterface,
            CounterfaceConduction::Perfect
        );
        let e = err(&with(&conducting, c));
        assert!(
            e.contains("counterface.thermal_conductivity") && e.contains("\"perfect\""),
            "{e}"
        );
        // missing on the first body: the layer and the property
        let e = err(&with(
            &bem,
            &format!("{c}\n[counterface]\nconduction = \"perfect\""),
        ));
        assert!(
            e.contains("`stack`") && e.contains("layer 1: missing `thermal_conductivity`"),
            "{e}"
        );
        let e = err(&with(
            &conducting,
            "[conductance]\nkind = \"electrical\"\n[counterface]\nconduction = \"perfect\"",
        ));
        assert!(
            e.contains("layer 1: missing `electrical_conductivity`"),
            "{e}"
        );
        // an elastic counterface conducts through its own stack
        let elastic = "[counterface]\n[[counterface.layer]]\nthickness = 1e-4\nyoung = 2e11\n\
                       poisson = 0.3\nthermal_conductivity = 40\n[counterface.base]\nkind = \"rigid\"\n\
                       conduction = \"isothermal\"";
        let s = parse(&with(&conducting, &format!("{c}\n{elastic}"))).unwrap();
        let spec = s.conductance.unwrap();
        assert_eq!(spec.counterface, CounterfaceConduction::Stack);
        let cf = spec
            .counterface_stack(&s.bodies.counterface)
            .unwrap()
            .unwrap();
        assert_eq!(cf.top_conductivity(), 40.0);
        let e = err(&with(
            &conducting,
            &format!(
                "{c}\n{}",
                elastic.replace("thermal_conductivity = 40\n", "")
            ),
        ));
        assert!(
            e.contains("`counterface`") && e.contains("layer 1: missing `thermal_conductivity`"),
            "{e}"
        );
        let perfect = elastic.replace("thermal_conductivity = 40\n", "").replace(
            "[counterface]\n",
            "[counterface]\nconduction = \"perfect\"\n",
        );
        let s = parse(&with(&conducting, &format!("{c}\n{perfect}"))).unwrap();
        assert_eq!(
            s.conductance.unwrap().counterface,
            CounterfaceConduction::Perfect
        );
        // fields named
        let e = err(&with(&conducting, "[conductance]\nkind = \"magnetic\""));
        assert!(e.contains("conductance.kind"), "{e}");
        let e = err(&with(&conducting, "[conductance]\n"));
        assert!(e.contains("conductance.kind"), "{e}");
        let e = err(&with(
            &conducting,
            "[conductance]\nkind = \"thermal\"\ncolour = 1",
        ));
        assert!(e.contains("conductance.colour"), "{e}");
        let e = err(&with(
            &conducting,
            &format!("{c}\n[counterface]\nconduction = \"perfect\"\nthermal_conductivity = 3"),
        ));
        assert!(e.contains("counterface.thermal_conductivity"), "{e}");
        let e = err(&with(
            &conducting,
            &format!("{c}\n[counterface]\nthermal_conductivity = -3"),
        ));
        assert!(e.contains("counterface.thermal_conductivity"), "{e}");
        let e = err(&with(
            &conducting,
            &format!("{c}\n[counterface]\nconduction = \"cold\""),
        ));
        assert!(e.contains("counterface.conduction"), "{e}");
        // the N model sums the spots, the I model solves their network
        for model in ["\"independent\"", "\"interacting\""] {
            assert!(
                parse(&with(
                    &conducting.replace("\"bem\"", model),
                    &format!("{c}\n[counterface]\nconduction = \"perfect\""),
                ))
                .is_ok()
            );
        }
    }
}
