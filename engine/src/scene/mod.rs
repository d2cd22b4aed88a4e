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
//! ```
//!
//! Every error names the offending field (`surface.size`, `load.approach.steps`, …).

use std::path::{Path, PathBuf};

use toml::{Table, Value};

use strata_bem::BemOptions;
use strata_runtime::conduction::{ConductionCompliance, ConductionKind};
use strata_runtime::rough::{Images, Params};
use strata_runtime::stack::{Conductivity, Stack};
use strata_runtime::surface::container::Pick;
use strata_runtime::surface::{
    Detrend, FileKind, GenerateParams, ReadOptions, Repair, Spacing, Surface,
};

mod error;
mod fields;
pub use error::SceneError;
use fields::{
    boolean, check_keys, existing_file, file_scale, integer, number, numbers, positive, string,
    table,
};

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

    /// Parses `[solver]` (absent: all defaults).
    fn parse(top: &Table) -> Result<SolverSpec, SceneError> {
        if top.get("solver").is_none() {
            return Ok(SolverSpec::default());
        }
        let t = table(top, "solver", "solver")?;
        let keys: Vec<&str> = SOLVER_KEYS.split(',').map(str::trim).collect();
        check_keys(t, "solver.", &keys, SOLVER_KEYS)?;
        let count = |key: &str| -> Result<Option<usize>, SceneError> {
            if !t.contains_key(key) {
                return Ok(None);
            }
            let field = format!("solver.{key}");
            let n = integer(t, key, &field)?;
            if !(1..=1_000_000_000).contains(&n) {
                return Err(SceneError::Invalid {
                    field,
                    reason: format!("{n} must be in [1, 1000000000]"),
                });
            }
            Ok(Some(n as usize))
        };
        let fraction = |key: &str| -> Result<Option<f64>, SceneError> {
            let Some(v) = t.get(key) else {
                return Ok(None);
            };
            let field = format!("solver.{key}");
            let x = number(v, &field)?;
            if !(x > 0.0 && x < 1.0) {
                return Err(SceneError::Invalid {
                    field,
                    reason: format!("{x} must be in (0, 1) (a relative tolerance)"),
                });
            }
            Ok(Some(x))
        };
        Ok(SolverSpec {
            max_step_newton_steps: count("max_step_newton_steps")?,
            max_step_evaluations: count("max_step_evaluations")?,
            kkt_tolerance: fraction("kkt_tolerance")?,
            max_pressure_iterations: count("max_pressure_iterations")?,
            bem_max_iterations: count("bem_max_iterations")?,
            bem_tolerance: fraction("bem_tolerance")?,
        })
    }
}

/// A validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The first body; with an elastic `[counterface]`, pressed against it
    /// ([`Stack::counterface`]), so every model sees the pair (physics.md §6.1).
    pub stack: Stack,
    /// The stack file (`stack.file`, resolved), if the stack is not inline.
    pub stack_file: Option<PathBuf>,
    /// The counterface's stack file (`counterface.file`, resolved), if any.
    pub counterface_file: Option<PathBuf>,
    /// The counterface's rough surface (`[counterface.surface]`), heights as seen from
    /// the first body; added to the first body's ([`Surface::plus_counterface`]).
    pub counterface_surface: Option<SurfaceSpec>,
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

/// The counterface's conduction (`[counterface]` keys `conduction`,
/// `thermal_conductivity`, `electrical_conductivity`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CounterfaceConduction {
    /// `conduction = "perfect"`: a perfect conductor (C_th,B = 0).
    Perfect,
    /// The rigid flat as a conducting half-space of this conductivity (W/(m·K) or S/m):
    /// C_th,B = 1/(k_B |k|).
    HalfSpace(f64),
    /// The elastic counterface stack's own conductivities ([`Stack::counterface`]).
    Stack,
}

impl ConductanceSpec {
    /// The conduction compliance of the first body of `stack` (its counterface not
    /// included) for this kind.
    pub fn body(&self, stack: &Stack) -> Result<ConductionCompliance, SceneError> {
        ConductionCompliance::new(&stack.body(), self.kind).map_err(|e| SceneError::Invalid {
            field: "stack".into(),
            reason: format!(
                "{e}; [conductance] kind = \"{}\" needs it",
                self.kind.name()
            ),
        })
    }

    /// The conduction compliance of the elastic counterface of `stack`
    /// ([`CounterfaceConduction::Stack`]; `None` otherwise).
    pub fn counterface_stack(
        &self,
        stack: &Stack,
    ) -> Result<Option<ConductionCompliance>, SceneError> {
        match (self.counterface, stack.counterface()) {
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
        }) = &self.counterface_surface
        {
            v.push(("the scene's counterface surface file".into(), p.clone()));
        }
        v
    }

    /// Parses a scene from TOML text, resolving relative paths against `dir`.
    pub fn from_str_in(text: &str, dir: &Path) -> Result<Scene, SceneError> {
        let top: Table = text.parse().map_err(|e: toml::de::Error| {
            SceneError::Syntax(strata_runtime::stack::toml_error_line(text, &e))
        })?;
        Scene::from_table_in(top, dir, None)
    }

    /// A scene from its TOML tables; with `surface`, the `[surface]` table is not
    /// read (and must be absent): the Python package passes a surface built in memory
    /// this way, its `[stack]`, `[model]` and `[load]` validated as a file's.
    pub fn from_table_in(
        top: Table,
        dir: &Path,
        surface: Option<SurfaceSpec>,
    ) -> Result<Scene, SceneError> {
        if surface.is_some() && top.contains_key("surface") {
            return Err(SceneError::Invalid {
                field: "surface".into(),
                reason: "the surface is given separately".into(),
            });
        }
        check_keys(
            &top,
            "",
            &[
                "stack",
                "surface",
                "model",
                "load",
                "output",
                "solver",
                "counterface",
                "plasticity",
                "conductance",
            ],
            "stack, surface, model, load, output, solver, counterface, plasticity, conductance",
        )?;
        // [stack]
        let st = table(&top, "stack", "stack")?;
        check_keys(
            st,
            "stack.",
            &["file", "table", "name", "layer", "base"],
            "file, table, name, layer, base",
        )?;
        let file = string(st, "file", "stack.file")?;
        let stack_file = file
            .map(|f| existing_file(dir, "stack.file", f, ""))
            .transpose()?;
        let stack = match &stack_file {
            Some(f) => {
                if st.contains_key("layer") || st.contains_key("base") {
                    return Err(SceneError::Invalid {
                        field: "stack.file".into(),
                        reason:
                            "give either `file` or inline [[stack.layer]]/[stack.base], not both"
                                .into(),
                    });
                }
                Stack::from_toml_file(f).map_err(SceneError::StackFile)?
            }
            None => {
                let mut inline = st.clone();
                inline.remove("table");
                Stack::from_toml_table(&inline).map_err(SceneError::Stack)?
            }
        };
        let mut table_path = string(st, "table", "stack.table")?
            .map(|t| {
                existing_file(
                    dir,
                    "stack.table",
                    t,
                    "; build it with `strata table build STACK.toml --out FILE`, or leave `table` out to use the table cache",
                )
            })
            .transpose()?;
        // [counterface] (absent: a rigid smooth flat)
        let counter = parse_counterface(&top, dir)?;
        let mut stack = stack;
        // One counterface, given in one place: a stack file's own [counterface] is
        // neither replaced by the scene's nor overridden by an explicit rigid flat.
        if stack.counterface().is_some() {
            let own = match &stack_file {
                Some(f) => format!("the stack file {} has its own [counterface]", f.display()),
                None => "[stack] has its own [stack.counterface]".to_string(),
            };
            let given = if counter.stack.is_some() {
                Some("an elastic [counterface] too")
            } else if top
                .get("counterface")
                .and_then(|c| c.get("kind"))
                .and_then(|k| k.as_str())
                == Some("rigid")
            {
                Some("`kind = \"rigid\"`")
            } else {
                None
            };
            if let Some(given) = given {
                return Err(SceneError::Invalid {
                    field: "counterface".into(),
                    reason: format!(
                        "{own}, and the scene gives {given}: give the counterface in one place \
                         (remove the stack file's [counterface], or the scene's)"
                    ),
                });
            }
        }
        if let Some(c) = &counter.stack {
            if table_path.is_some() {
                return Err(SceneError::Invalid {
                    field: "stack.table".into(),
                    reason: "serves the stack against a rigid flat; with an elastic \
                             [counterface] give counterface.table (a table built for the pair, \
                             `strata table build STACK.toml --counterface STACK2 --out FILE`) or \
                             leave it out to use the table cache"
                        .into(),
                });
            }
            stack = stack.against(c.clone()).map_err(|e| SceneError::Invalid {
                field: "counterface".into(),
                reason: e.to_string(),
            })?;
            table_path = counter.table.clone();
        }
        // [surface] (or one given in memory)
        let surface = match surface {
            Some(s) => s,
            None => parse_surface(&top, dir)?,
        };
        // [model]
        let md = table(&top, "model", "model")?;
        check_keys(
            md,
            "model.",
            &["kind", "images", "image_cells"],
            "kind, images, image_cells",
        )?;
        let kind = match string(md, "kind", "model.kind")? {
            Some("independent") => ModelKind::Independent,
            Some("interacting") => ModelKind::Interacting,
            Some("bem") => ModelKind::Bem,
            Some(other) => {
                return Err(SceneError::Invalid {
                    field: "model.kind".into(),
                    reason: format!(
                        "`{other}` is not one of \"independent\", \"interacting\", \"bem\""
                    ),
                });
            }
            None => return Err(SceneError::Missing("model.kind".into())),
        };
        let cells = match md.get("image_cells") {
            None => 2,
            Some(_) => {
                let c = integer(md, "image_cells", "model.image_cells")?;
                if !(1..=20).contains(&c) {
                    return Err(SceneError::Invalid {
                        field: "model.image_cells".into(),
                        reason: format!("{c} must be in [1, 20]"),
                    });
                }
                c as usize
            }
        };
        let images = match string(md, "images", "model.images")? {
            None if surface.read.periodic => Images::Periodic(cells),
            None => Images::Isolated,
            Some("isolated") => Images::Isolated,
            Some("periodic") => {
                if !surface.read.periodic {
                    return Err(SceneError::Invalid {
                        field: "model.images".into(),
                        reason: "\"periodic\" needs a periodic surface (surface.periodic = true)"
                            .into(),
                    });
                }
                Images::Periodic(cells)
            }
            Some(other) => {
                return Err(SceneError::Invalid {
                    field: "model.images".into(),
                    reason: format!("`{other}` is not one of \"periodic\", \"isolated\""),
                });
            }
        };
        // [load]
        let ld = table(&top, "load", "load")?;
        check_keys(
            ld,
            "load.",
            &["separations", "approach", "mean_pressures", "unload"],
            "separations, approach, mean_pressures, unload",
        )?;
        let unload = boolean(ld, "unload", "load.unload")?.unwrap_or(false);
        if ld.len() - usize::from(ld.contains_key("unload")) != 1 {
            return Err(SceneError::Invalid {
                field: "load".into(),
                reason: "give exactly one of `separations`, `approach`, `mean_pressures`".into(),
            });
        }
        let load = if let Some(v) = ld.get("separations") {
            LoadSpec::Separations(numbers(v, "load.separations")?)
        } else if let Some(v) = ld.get("mean_pressures") {
            let p = numbers(v, "load.mean_pressures")?;
            if let Some((i, x)) = p.iter().enumerate().find(|(_, x)| **x <= 0.0) {
                return Err(SceneError::Invalid {
                    field: format!("load.mean_pressures[{i}]"),
                    reason: format!("{x} must be > 0 (Pa)"),
                });
            }
            LoadSpec::MeanPressures(p)
        } else {
            let a = table(ld, "approach", "load.approach")?;
            check_keys(
                a,
                "load.approach.",
                &["from", "to", "steps"],
                "from, to, steps",
            )?;
            let from = number(
                a.get("from")
                    .ok_or_else(|| SceneError::Missing("load.approach.from".into()))?,
                "load.approach.from",
            )?;
            let to = number(
                a.get("to")
                    .ok_or_else(|| SceneError::Missing("load.approach.to".into()))?,
                "load.approach.to",
            )?;
            if from < 0.0 {
                return Err(SceneError::Invalid {
                    field: "load.approach.from".into(),
                    reason: format!("{from} must be ≥ 0 (m)"),
                });
            }
            if to < 0.0 {
                return Err(SceneError::Invalid {
                    field: "load.approach.to".into(),
                    reason: format!("{to} must be ≥ 0 (m)"),
                });
            }
            let steps = integer(a, "steps", "load.approach.steps")?;
            if !(1..=100_000).contains(&steps) {
                return Err(SceneError::Invalid {
                    field: "load.approach.steps".into(),
                    reason: format!("{steps} must be in [1, 100000]"),
                });
            }
            LoadSpec::Approach {
                from,
                to,
                steps: steps as usize,
            }
        };
        // [output] (optional)
        let output = match top.get("output") {
            None => OutputSpec::default(),
            Some(_) => {
                let ot = table(&top, "output", "output")?;
                check_keys(ot, "output.", &["maps", "format"], "maps, format")?;
                let maps = match ot.get("maps") {
                    None | Some(Value::Boolean(false)) => MapsSpec::None,
                    Some(Value::Boolean(true)) => MapsSpec::All,
                    Some(Value::String(m)) => match m.as_str() {
                        "none" => MapsSpec::None,
                        "last" => MapsSpec::Last,
                        "all" => MapsSpec::All,
                        other => {
                            return Err(SceneError::Invalid {
                                field: "output.maps".into(),
                                reason: format!(
                                    "`{other}` is not one of \"none\", \"last\", \"all\""
                                ),
                            });
                        }
                    },
                    Some(_) => {
                        return Err(SceneError::WrongType {
                            field: "output.maps".into(),
                            expected: "\"none\", \"last\", \"all\", true or false",
                        });
                    }
                };
                if maps != MapsSpec::None && kind != ModelKind::Bem {
                    return Err(SceneError::Invalid {
                        field: "output.maps".into(),
                        reason: "pressure and gap maps come from the full-field solution and need \
                                 model.kind = \"bem\" (the asperity models resolve each contact \
                                 by its radius only, not a pressure field)"
                            .into(),
                    });
                }
                let format = match ot.get("format") {
                    None => MapFormats::default(),
                    Some(v) => {
                        let names: Vec<&Value> = match v {
                            Value::Array(a) => a.iter().collect(),
                            other => vec![other],
                        };
                        let mut f = MapFormats {
                            npy: false,
                            netcdf: false,
                        };
                        for n in names {
                            match n.as_str() {
                                Some("npy") => f.npy = true,
                                Some("netcdf") => f.netcdf = true,
                                Some(other) => {
                                    return Err(SceneError::Invalid {
                                        field: "output.format".into(),
                                        reason: format!(
                                            "`{other}` is not one of \"npy\", \"netcdf\""
                                        ),
                                    });
                                }
                                None => {
                                    return Err(SceneError::WrongType {
                                        field: "output.format".into(),
                                        expected: "\"npy\", \"netcdf\" or an array of them",
                                    });
                                }
                            }
                        }
                        if !f.npy && !f.netcdf {
                            return Err(SceneError::Invalid {
                                field: "output.format".into(),
                                reason: "is empty: name \"npy\", \"netcdf\" or both".into(),
                            });
                        }
                        if maps == MapsSpec::None {
                            return Err(SceneError::Invalid {
                                field: "output.format".into(),
                                reason:
                                    "chooses the files of the maps, but output.maps is \"none\" \
                                         (set maps = \"last\" or \"all\")"
                                        .into(),
                            });
                        }
                        f
                    }
                };
                OutputSpec { maps, format }
            }
        };
        if let Some(cs) = &counter.surface
            && matches!(cs.source, SurfaceSource::Generate(_))
            && cs.source == surface.source
        {
            return Err(SceneError::Invalid {
                field: "counterface.surface.generate.seed".into(),
                reason: "equals the first body's [surface.generate]: the two surfaces would be \
                         the same heights twice; give the counterface another seed"
                    .into(),
            });
        }
        let plasticity = if top.contains_key("plasticity") {
            let pt = table(&top, "plasticity", "plasticity")?;
            check_keys(pt, "plasticity.", &["hardness"], "hardness")?;
            let hardness = positive(pt, "hardness", "plasticity.hardness")?;
            if let Some(reason) = strata_runtime::rough::plastic::hardness_problem(hardness) {
                return Err(SceneError::Invalid {
                    field: "plasticity.hardness".into(),
                    reason,
                });
            }
            Some(PlasticitySpec { hardness })
        } else {
            None
        };
        if unload && kind != ModelKind::Bem {
            return Err(SceneError::Invalid {
                field: "load.unload".into(),
                reason: "a return path is solved by the BEM (model.kind = \"bem\"); the N and I \
                         models follow the loading path only (with [plasticity] too)"
                    .into(),
            });
        }
        if plasticity.is_some()
            && kind != ModelKind::Bem
            && let Some((field, what)) = load.first_reversal()
        {
            return Err(SceneError::Invalid {
                field,
                reason: format!(
                    "{what}: a path that unloads is solved by the BEM (model.kind = \"bem\"); the \
                     N and I models follow the loading path only (with [plasticity] too)"
                ),
            });
        }
        let conductance = parse_conductance(&top, &counter, &stack)?;
        Ok(Scene {
            conductance,
            plasticity,
            unload,
            stack,
            stack_file,
            counterface_file: counter.file,
            counterface_surface: counter.surface,
            table: table_path,
            surface,
            model: ModelSpec { kind, images },
            load,
            output,
            solver: SolverSpec::parse(&top)?,
        })
    }

    /// Builds (reads or generates) the surface; a file by its extension (`.x3p`,
    /// `.npy`, else text) with the scene's spacing, height unit, repair and detrend.
    /// What the reader did is in [`Surface::log`].
    ///
    /// With a rough counterface (`[counterface.surface]`) the result is the composite
    /// surface h_A + h_B (physics.md §6.1).
    pub fn load_surface(&self) -> Result<Surface, SceneError> {
        let own = load_spec(&self.surface)?;
        match &self.counterface_surface {
            None => Ok(own),
            Some(c) => Ok(own.plus_counterface(&load_spec(c)?)?),
        }
    }
}

fn load_spec(s: &SurfaceSpec) -> Result<Surface, SceneError> {
    Ok(match &s.source {
        SurfaceSource::Generate(g) => Surface::generate(g)?,
        SurfaceSource::File(p) => match &s.topography {
            Some(pick) => strata_runtime::surface::container::read_container(p, pick, &s.read)?,
            None => Surface::read(p, &s.read)?,
        },
    })
}

/// The parsed `[counterface]` table.
#[derive(Default)]
struct CounterfaceSpec {
    /// The elastic counterface; `None` for a rigid flat.
    stack: Option<Stack>,
    file: Option<PathBuf>,
    table: Option<PathBuf>,
    surface: Option<SurfaceSpec>,
    /// `conduction = "perfect"` or `"half-space"` (`None`: not given).
    conduction: Option<String>,
    /// A rigid flat's conductivities (`thermal_conductivity`, `electrical_conductivity`).
    conductivity: Conductivity,
}

/// `[counterface]`: `kind = "rigid"` (the default when absent) or an elastic stack
/// (`file`, or inline `[[counterface.layer]]`/`[counterface.base]`; `kind = "elastic"`
/// optional), an optional pair `table` and an optional `[counterface.surface]` with
/// the keys of `[surface]`.
fn parse_counterface(top: &Table, dir: &Path) -> Result<CounterfaceSpec, SceneError> {
    if !top.contains_key("counterface") {
        return Ok(CounterfaceSpec::default());
    }
    let ct = table(top, "counterface", "counterface")?;
    check_keys(
        ct,
        "counterface.",
        &[
            "kind",
            "file",
            "table",
            "name",
            "layer",
            "base",
            "surface",
            "conduction",
            "thermal_conductivity",
            "electrical_conductivity",
        ],
        "kind, file, table, name, layer, base, surface, conduction, thermal_conductivity, \
         electrical_conductivity",
    )?;
    let has_stack = ["file", "name", "layer", "base"]
        .iter()
        .any(|k| ct.contains_key(*k));
    let rigid = match string(ct, "kind", "counterface.kind")? {
        Some("rigid") => true,
        Some("elastic") => false,
        None => !has_stack,
        Some(other) => {
            return Err(SceneError::Invalid {
                field: "counterface.kind".into(),
                reason: format!("`{other}` is not one of \"rigid\", \"elastic\""),
            });
        }
    };
    let mut spec = CounterfaceSpec {
        conduction: match string(ct, "conduction", "counterface.conduction")? {
            None => None,
            Some(c @ ("perfect" | "half-space")) => Some(c.to_string()),
            Some(other) => {
                return Err(SceneError::Invalid {
                    field: "counterface.conduction".into(),
                    reason: format!("`{other}` is not one of \"perfect\", \"half-space\""),
                });
            }
        },
        ..Default::default()
    };
    for (key, slot) in [
        ("thermal_conductivity", &mut spec.conductivity.thermal),
        ("electrical_conductivity", &mut spec.conductivity.electrical),
    ] {
        if ct.contains_key(key) {
            let field = format!("counterface.{key}");
            if !rigid {
                return Err(SceneError::Invalid {
                    field,
                    reason: "an elastic counterface gives its conductivities per \
                             [[counterface.layer]] and [counterface.base], as a stack does"
                        .into(),
                });
            }
            let k = positive(ct, key, &field)?;
            if !(1e-30..=1e30).contains(&k) {
                return Err(SceneError::Invalid {
                    field,
                    reason: format!("{k} must lie in [1e-30, 1e30]"),
                });
            }
            *slot = Some(k);
        }
    }
    if !rigid && spec.conduction.as_deref() == Some("half-space") {
        return Err(SceneError::Invalid {
            field: "counterface.conduction".into(),
            reason: "\"half-space\" describes a rigid flat (counterface.kind = \"rigid\"); an \
                     elastic counterface conducts through its own stack, or give \"perfect\""
                .into(),
        });
    }
    if rigid {
        for k in ["file", "name", "layer", "base", "table"] {
            if ct.contains_key(k) {
                return Err(SceneError::Invalid {
                    field: format!("counterface.{k}"),
                    reason:
                        "a rigid counterface (counterface.kind = \"rigid\") has no stack or table"
                            .into(),
                });
            }
        }
    } else {
        let file = string(ct, "file", "counterface.file")?
            .map(|f| existing_file(dir, "counterface.file", f, ""))
            .transpose()?;
        let stack = match &file {
            Some(f) => {
                if ct.contains_key("layer") || ct.contains_key("base") {
                    return Err(SceneError::Invalid {
                        field: "counterface.file".into(),
                        reason: "give either `file` or inline [[counterface.layer]]/[counterface.base], not both"
                            .into(),
                    });
                }
                Stack::from_toml_file(f).map_err(|e| SceneError::Invalid {
                    field: "counterface.file".into(),
                    reason: e.to_string(),
                })?
            }
            None => {
                if !(ct.contains_key("layer") || ct.contains_key("base")) {
                    return Err(SceneError::Missing(
                        "counterface.file (or inline [[counterface.layer]]/[counterface.base]) for kind = \"elastic\""
                            .into(),
                    ));
                }
                let mut inline = ct.clone();
                for k in ["kind", "table", "surface", "conduction"] {
                    inline.remove(k);
                }
                Stack::from_toml_table(&inline).map_err(|e| SceneError::Invalid {
                    field: "counterface".into(),
                    reason: e.to_string(),
                })?
            }
        };
        spec.table = string(ct, "table", "counterface.table")?
            .map(|t| {
                existing_file(
                    dir,
                    "counterface.table",
                    t,
                    "; build it with `strata table build STACK.toml --counterface STACK2 --out FILE`, or leave `table` out to use the table cache",
                )
            })
            .transpose()?;
        spec.stack = Some(stack);
        spec.file = file;
    }
    if ct.contains_key("surface") {
        let mut fake = Table::new();
        fake.insert("surface".into(), ct["surface"].clone());
        spec.surface = Some(parse_surface(&fake, dir).map_err(in_counterface)?);
    }
    Ok(spec)
}

/// `[conductance]` (absent: `None`): `kind = "thermal"` or `"electrical"`. The scene's
/// bodies must conduct: every layer (and a half-space base) of the first body, and the
/// counterface (a rigid flat's `thermal_conductivity`/`electrical_conductivity` or
/// `conduction = "perfect"`; an elastic one's stack, or `"perfect"`); each missing
/// property is named. Solved by the BEM (periodic or not), the N and the I model.
fn parse_conductance(
    top: &Table,
    counter: &CounterfaceSpec,
    stack: &Stack,
) -> Result<Option<ConductanceSpec>, SceneError> {
    if !top.contains_key("conductance") {
        return Ok(None);
    }
    let ct = table(top, "conductance", "conductance")?;
    check_keys(ct, "conductance.", &["kind"], "kind")?;
    let kind = match string(ct, "kind", "conductance.kind")? {
        Some("thermal") => ConductionKind::Thermal,
        Some("electrical") => ConductionKind::Electrical,
        Some(other) => {
            return Err(SceneError::Invalid {
                field: "conductance.kind".into(),
                reason: format!("`{other}` is not one of \"thermal\", \"electrical\""),
            });
        }
        None => {
            return Err(SceneError::Missing(
                "conductance.kind (\"thermal\" or \"electrical\")".into(),
            ));
        }
    };
    let pick = |c: &Conductivity| match kind {
        ConductionKind::Thermal => c.thermal,
        ConductionKind::Electrical => c.electrical,
    };
    let perfect = counter.conduction.as_deref() == Some("perfect");
    let counterface = if stack.counterface().is_some() {
        if perfect {
            CounterfaceConduction::Perfect
        } else {
            CounterfaceConduction::Stack
        }
    } else {
        match (perfect, pick(&counter.conductivity)) {
            (true, Some(_)) => {
                return Err(SceneError::Invalid {
                    field: format!("counterface.{}", kind.field()),
                    reason: "a perfect conductor (counterface.conduction = \"perfect\") has no \
                             conductivity: give one or the other"
                        .into(),
                });
            }
            (true, None) => CounterfaceConduction::Perfect,
            (false, Some(k)) => CounterfaceConduction::HalfSpace(k),
            (false, None) => {
                return Err(SceneError::Missing(format!(
                    "counterface.{} ({}; the rigid flat as a conducting half-space) or \
                     counterface.conduction = \"perfect\": [conductance] kind = \"{}\" needs the \
                     counterface's conduction",
                    kind.field(),
                    kind.conductivity_unit(),
                    kind.name()
                )));
            }
        }
    };
    let spec = ConductanceSpec { kind, counterface };
    spec.body(stack)?;
    spec.counterface_stack(stack)?;
    Ok(Some(spec))
}

/// A `[surface]` error re-labelled as one of `[counterface.surface]`.
fn in_counterface(e: SceneError) -> SceneError {
    let f = |s: String| format!("counterface.{s}");
    match e {
        SceneError::UnknownKey { key, expected } => SceneError::UnknownKey {
            key: f(key),
            expected,
        },
        SceneError::Missing(m) => SceneError::Missing(f(m)),
        SceneError::WrongType { field, expected } => SceneError::WrongType {
            field: f(field),
            expected,
        },
        SceneError::Invalid { field, reason } => SceneError::Invalid {
            field: f(field),
            reason,
        },
        SceneError::MissingFile {
            field,
            what,
            value,
            resolved,
            dir,
            hint,
        } => SceneError::MissingFile {
            // the one file key of [surface]
            field: if field == "surface.file" {
                "counterface.surface.file"
            } else {
                field
            },
            what,
            value,
            resolved,
            dir,
            hint,
        },
        other => other,
    }
}

/// The `[surface]` table of a scene whose relative paths resolve against `dir`.
fn parse_surface(top: &Table, dir: &Path) -> Result<SurfaceSpec, SceneError> {
    let sf = table(top, "surface", "surface")?;
    check_keys(
        sf,
        "surface.",
        &[
            "file",
            "size",
            "pixel_size",
            "periodic",
            "generate",
            "repair",
            "detrend",
            "height_unit",
            "topography",
        ],
        "file, size, pixel_size, periodic, generate, repair, detrend, height_unit, topography",
    )?;
    let periodic = boolean(sf, "periodic", "surface.periodic")?;
    let repair = match string(sf, "repair", "surface.repair")? {
        None | Some("none") => Repair::Refuse,
        Some("median" | "harmonic") if sf.contains_key("file") => Repair::Median,
        Some("median" | "harmonic") => {
            return Err(SceneError::Invalid {
                field: "surface.repair".into(),
                reason: "applies to measured surfaces (surface.file), not generated ones".into(),
            });
        }
        Some(other) => {
            return Err(SceneError::Invalid {
                field: "surface.repair".into(),
                reason: format!(
                    "`{other}` is not one of \"none\", \"median\", \"harmonic\" (the last two \
                     the same harmonic fill)"
                ),
            });
        }
    };
    Ok(match (sf.get("file"), sf.get("generate")) {
        (Some(_), Some(_)) => {
            return Err(SceneError::Invalid {
                field: "surface.file".into(),
                reason: "give either `file` or [surface.generate], not both".into(),
            });
        }
        (None, None) => {
            return Err(SceneError::Missing(
                "surface.file (or a [surface.generate] table)".into(),
            ));
        }
        (Some(_), None) => {
            let f = string(sf, "file", "surface.file")?.unwrap_or_default();
            let p = existing_file(dir, "surface.file", f, "")?;
            let (spacing, height_unit) = file_scale(sf, FileKind::of(&p))?;
            let topography = container_pick(sf, &p)?;
            // A NetCDF topography's own periodic flag is the default (SurfaceTopography),
            // and so is a container's `is_periodic`.
            let periodic = periodic
                .or_else(|| match FileKind::of(&p) {
                    FileKind::NetCdf => strata_runtime::surface::netcdf::netcdf_periodic(&p)
                        .ok()
                        .flatten(),
                    FileKind::Container => strata_runtime::surface::container::find(
                        &p,
                        topography.as_ref().unwrap_or(&Pick::Index(0)),
                    )
                    .ok()
                    .and_then(|e| e.periodic),
                    _ => None,
                })
                .unwrap_or(false);
            // Measured files: the least-squares plane is removed unless asked otherwise;
            // a periodic sample has no tilt to remove (a plane is not periodic).
            let detrend = match string(sf, "detrend", "surface.detrend")? {
                None if periodic => Detrend::None,
                None => Detrend::Plane,
                Some(d) => Detrend::parse(d).ok_or_else(|| SceneError::Invalid {
                    field: "surface.detrend".into(),
                    reason: format!("`{d}` is not one of \"none\", \"plane\", \"curvature\""),
                })?,
            };
            if periodic && detrend != Detrend::None {
                return Err(SceneError::Invalid {
                    field: "surface.detrend".into(),
                    reason: format!(
                        "\"{}\" on a periodic surface (surface.periodic = true): a tilt or a \
                         curvature is not periodic (the sample's edges would no longer meet); \
                         remove the key (a periodic sample keeps its heights) or set periodic = false",
                        detrend.name()
                    ),
                });
            }
            SurfaceSpec {
                source: SurfaceSource::File(p),
                read: ReadOptions {
                    spacing,
                    periodic,
                    repair,
                    height_unit,
                    detrend,
                },
                topography,
            }
        }
        (None, Some(_)) => {
            let g = table(sf, "generate", "surface.generate")?;
            check_keys(
                g,
                "surface.generate.",
                &[
                    "size",
                    "grid",
                    "fractal_dimension",
                    "k_min",
                    "k_max",
                    "rms",
                    "seed",
                ],
                "size, grid, fractal_dimension, k_min, k_max, rms, seed",
            )?;
            let size = match (g.get("size"), sf.get("size")) {
                (Some(_), _) => positive(g, "size", "surface.generate.size")?,
                (None, Some(_)) => positive(sf, "size", "surface.size")?,
                (None, None) => {
                    return Err(SceneError::Missing("surface.generate.size".into()));
                }
            };
            let grid = integer(g, "grid", "surface.generate.grid")?;
            if !(4..=16384).contains(&grid) {
                return Err(SceneError::Invalid {
                    field: "surface.generate.grid".into(),
                    reason: format!("{grid} must be in [4, 16384]"),
                });
            }
            let seed = integer(g, "seed", "surface.generate.seed")?;
            if seed < 0 {
                return Err(SceneError::Invalid {
                    field: "surface.generate.seed".into(),
                    reason: format!("{seed} must be ≥ 0"),
                });
            }
            if periodic == Some(false) {
                return Err(SceneError::Invalid {
                    field: "surface.periodic".into(),
                    reason: "a generated surface is periodic".into(),
                });
            }
            for key in ["pixel_size", "height_unit", "detrend"] {
                if sf.contains_key(key) {
                    return Err(SceneError::Invalid {
                        field: format!("surface.{key}"),
                        reason: "applies to measured surfaces (surface.file), not generated ones"
                            .into(),
                    });
                }
            }
            let fd = g
                .get("fractal_dimension")
                .ok_or_else(|| SceneError::Missing("surface.generate.fractal_dimension".into()))?;
            SurfaceSpec {
                source: SurfaceSource::Generate(GenerateParams {
                    size,
                    grid: grid as usize,
                    fractal_dimension: number(fd, "surface.generate.fractal_dimension")?,
                    k_min: positive(g, "k_min", "surface.generate.k_min")?,
                    k_max: positive(g, "k_max", "surface.generate.k_max")?,
                    rms: positive(g, "rms", "surface.generate.rms")?,
                    seed: seed as u64,
                }),
                read: ReadOptions {
                    spacing: Some(Spacing::Size(size)),
                    periodic: true,
                    repair,
                    ..Default::default()
                },
                topography: None,
            }
        }
    })
}

/// `surface.topography`: which topography of a contact.engineering container (`.zip`)
/// to read, by number from 0 (across its surfaces) or by name; refused for other files.
fn container_pick(sf: &Table, file: &Path) -> Result<Option<Pick>, SceneError> {
    let Some(v) = sf.get("topography") else {
        return Ok(None);
    };
    let field = || "surface.topography".to_string();
    if FileKind::of(file) != FileKind::Container {
        return Err(SceneError::Invalid {
            field: field(),
            reason: "picks a topography of a contact.engineering container (a .zip file);                      remove it for other files"
                .into(),
        });
    }
    match v {
        toml::Value::Integer(i) if *i >= 0 => Ok(Some(Pick::Index(*i as usize))),
        toml::Value::String(n) => Ok(Some(Pick::Name(n.clone()))),
        _ => Err(SceneError::Invalid {
            field: field(),
            reason: format!(
                "`{v}` is neither a topography number (0, 1, ... across the container's                  surfaces) nor a topography name"
            ),
        }),
    }
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
        assert_eq!(s.stack.layers().len(), 1);
        let d = s.load.approaches(1e-5, 2e-5).unwrap().unwrap();
        for (x, y) in d.iter().zip([1e-6, 3e-6, 5e-6, 7e-6, 9e-6]) {
            assert!((x - y).abs() < 1e-20);
        }
        assert_eq!(d.len(), 5);
        assert!(s.load_surface().is_ok());
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
        assert_eq!(spec.body(&s.stack).unwrap().top_conductivity(), 0.3);
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
        let cf = spec.counterface_stack(&s.stack).unwrap().unwrap();
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
