//! Validation of a deserialized scene ([`SceneFile`]) into a [`Scene`]: ranges, the
//! rules between tables, files resolved against the scene's directory. Every error
//! names the dotted field (`surface.size`, `load.approach.steps`, …).

use std::path::{Path, PathBuf};

use strata_runtime::conduction::ConductionKind;
use strata_runtime::rough::Images;
use strata_runtime::stack::{
    Bodies, Conductivity, Counterface, CounterfaceConductionFile, CounterfaceFile,
    CounterfaceKindFile, RigidConduction, Stack, StackError, StackFile,
};
use strata_runtime::surface::container::Pick;
use strata_runtime::surface::{
    Detrend, FileKind, GenerateParams, HeightUnit, ReadOptions, Repair, Spacing,
};

use super::fields::existing_file;
use super::file::{
    ConductanceFile, ConductionKindFile, Lengths, LoadFile, MapsFile, ModelKindFile, OutputFile,
    SceneFile, SolverFile, SurfaceFile, TopographyPick,
};
use super::{
    ConductanceSpec, CounterfaceConduction, FrictionSpec, LoadSpec, MapFormats, MapsSpec,
    ModelKind, ModelSpec, OutputSpec, PlasticitySpec, Scene, SceneError, SolverSpec, SurfaceSource,
    SurfaceSpec, TangentialPathSpec,
};

fn invalid(field: impl Into<String>, reason: impl Into<String>) -> SceneError {
    SceneError::Invalid {
        field: field.into(),
        reason: reason.into(),
    }
}

/// A finite number.
fn finite(x: f64, field: &str) -> Result<f64, SceneError> {
    if !x.is_finite() {
        return Err(invalid(field, format!("{x} is not finite")));
    }
    Ok(x)
}

/// A given, finite number > 0.
fn positive(x: Option<f64>, field: &str) -> Result<f64, SceneError> {
    let x = finite(x.ok_or_else(|| SceneError::Missing(field.into()))?, field)?;
    if x <= 0.0 {
        return Err(invalid(field, format!("{x} must be > 0")));
    }
    Ok(x)
}

/// A non-empty array of finite numbers.
fn numbers(v: &[f64], field: &str) -> Result<Vec<f64>, SceneError> {
    if v.is_empty() {
        return Err(invalid(field, "must not be empty"));
    }
    v.iter()
        .enumerate()
        .map(|(i, x)| finite(*x, &format!("{field}[{i}]")))
        .collect()
}

/// A length or a pair of lengths (m), each finite and > 0.
fn lengths(v: &Lengths, field: &str) -> Result<(f64, Option<f64>), SceneError> {
    let xs: Vec<(f64, String)> = match v {
        Lengths::One(x) => vec![(*x, field.to_string())],
        Lengths::Two([x, y]) => vec![(*x, format!("{field}[0]")), (*y, format!("{field}[1]"))],
    };
    let mut out = Vec::new();
    for (x, f) in xs {
        let x = finite(x, &f)?;
        if x <= 0.0 {
            return Err(invalid(f, format!("{x} must be > 0 (m)")));
        }
        out.push(x);
    }
    Ok((out[0], out.get(1).copied()))
}

fn height_unit(sf: &SurfaceFile) -> Result<Option<HeightUnit>, SceneError> {
    sf.height_unit
        .as_deref()
        .map(|u| {
            HeightUnit::parse(u).ok_or_else(|| {
                invalid(
                    "surface.height_unit",
                    format!("`{u}` is not one of \"m\", \"mm\", \"um\", \"nm\""),
                )
            })
        })
        .transpose()
}

/// The lateral scale and height unit of a surface file: from `size` or `pixel_size`
/// and `height_unit` for `.npy`/text; none of them for `.x3p` (from the file); for a
/// NetCDF topography optional (the file usually gives its sizes and unit).
fn file_scale(
    sf: &SurfaceFile,
    kind: FileKind,
) -> Result<(Option<Spacing>, Option<HeightUnit>), SceneError> {
    if kind == FileKind::X3p {
        for (key, given) in [
            ("size", sf.size.is_some()),
            ("pixel_size", sf.pixel_size.is_some()),
            ("height_unit", sf.height_unit.is_some()),
        ] {
            if given {
                return Err(invalid(
                    format!("surface.{key}"),
                    "an .x3p file gives its own pixel sizes and is in metres (ISO 25178-72): remove this key",
                ));
            }
        }
        return Ok((None, None));
    }
    let spacing = match (&sf.size, &sf.pixel_size) {
        (Some(_), Some(_)) => {
            return Err(invalid(
                "surface.pixel_size",
                "give either size or pixel_size, not both",
            ));
        }
        // A NetCDF topography usually gives its physical sizes (the reader says when not).
        (None, None) if matches!(kind, FileKind::NetCdf | FileKind::Container) => {
            return Ok((None, height_unit(sf)?));
        }
        (None, None) => {
            return Err(SceneError::Missing(
                "surface.size (the first axis' length L or [Lx, Ly] in m; or surface.pixel_size = [dx, dy])"
                    .into(),
            ));
        }
        (Some(v), None) => match lengths(v, "surface.size")? {
            (l, None) => Spacing::Size(l),
            (lx, Some(ly)) => Spacing::Extent(lx, ly),
        },
        (None, Some(v)) => match lengths(v, "surface.pixel_size")? {
            (d, None) => Spacing::Pixel(d, d),
            (dx, Some(dy)) => Spacing::Pixel(dx, dy),
        },
    };
    Ok((Some(spacing), height_unit(sf)?))
}

impl SceneFile {
    /// Validates the scene; relative paths resolve against `dir`. With `surface`, the
    /// `[surface]` table is not read (and must be absent): a surface given in memory.
    pub fn validate(self, dir: &Path, surface: Option<SurfaceSpec>) -> Result<Scene, SceneError> {
        if surface.is_some() && self.surface.is_some() {
            return Err(invalid("surface", "the surface is given separately"));
        }
        // [stack]
        let st = self
            .stack
            .ok_or_else(|| SceneError::Missing("stack".into()))?;
        let stack_file = st
            .file
            .as_deref()
            .map(|f| existing_file(dir, "stack.file", f, ""))
            .transpose()?;
        let stack = match &stack_file {
            Some(f) => {
                if st.layer.is_some() || st.base.is_some() {
                    return Err(invalid(
                        "stack.file",
                        "give either `file` or inline [[stack.layer]]/[stack.base], not both",
                    ));
                }
                Bodies::from_toml_file(f).map_err(SceneError::StackFile)?
            }
            None => StackFile {
                name: st.name,
                layer: st.layer,
                base: st.base,
                counterface: None,
            }
            .bodies()
            .map_err(SceneError::Stack)?,
        };
        let mut table_path = st
            .table
            .as_deref()
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
        let counter = counterface(self.counterface, dir)?;
        // One counterface, given in one place: a stack file's own [counterface] is
        // neither replaced by the scene's nor overridden by an explicit rigid flat.
        let Bodies {
            first: stack,
            counterface: own_counterface,
        } = stack;
        let mut elastic = own_counterface.stack().cloned();
        if elastic.is_some() {
            let own = match &stack_file {
                Some(f) => format!("the stack file {} has its own [counterface]", f.display()),
                None => "[stack] has its own counterface".to_string(),
            };
            let given = if counter.stack.is_some() {
                Some("an elastic [counterface] too")
            } else if counter.explicit_rigid {
                Some("`kind = \"rigid\"`")
            } else {
                None
            };
            if let Some(given) = given {
                return Err(invalid(
                    "counterface",
                    format!(
                        "{own}, and the scene gives {given}: give the counterface in one place \
                         (remove the stack file's [counterface], or the scene's)"
                    ),
                ));
            }
        }
        if let Some(c) = &counter.stack {
            if table_path.is_some() {
                return Err(invalid(
                    "stack.table",
                    "serves the stack against a rigid flat; with an elastic \
                     [counterface] give counterface.table (a table built for the pair, \
                     `strata table build STACK.toml --counterface STACK2 --out FILE`) or \
                     leave it out to use the table cache",
                ));
            }
            elastic = Some(c.clone());
            table_path = counter.table.clone();
        }
        let perfect = counter.conduction == Some(CounterfaceConductionFile::Perfect);
        let bodies = Bodies {
            first: stack,
            counterface: match elastic {
                Some(stack) => Counterface::Elastic {
                    stack,
                    surface: counter.surface.clone(),
                    perfect_conductor: perfect,
                },
                None => Counterface::Rigid {
                    conduction: if perfect {
                        RigidConduction::Perfect
                    } else {
                        RigidConduction::HalfSpace(counter.conductivity)
                    },
                    surface: counter.surface.clone(),
                },
            },
        };
        // [surface] (or one given in memory)
        let surface = match surface {
            Some(s) => s,
            None => surface_spec(
                self.surface
                    .as_ref()
                    .ok_or_else(|| SceneError::Missing("surface".into()))?,
                dir,
                "surface",
            )?,
        };
        // [model]
        let md = self
            .model
            .ok_or_else(|| SceneError::Missing("model".into()))?;
        let kind = match md.kind {
            Some(ModelKindFile::Independent) => ModelKind::Independent,
            Some(ModelKindFile::Interacting) => ModelKind::Interacting,
            Some(ModelKindFile::Bem) => ModelKind::Bem,
            None => return Err(SceneError::Missing("model.kind".into())),
        };
        let cells = match md.image_cells {
            None => 2,
            Some(c) => {
                if !(1..=20).contains(&c) {
                    return Err(invalid(
                        "model.image_cells",
                        format!("{c} must be in [1, 20]"),
                    ));
                }
                c as usize
            }
        };
        let images = match md.images {
            None if surface.read.periodic => Images::Periodic(cells),
            None => Images::Isolated,
            Some(super::file::ImagesFile::Isolated) => Images::Isolated,
            Some(super::file::ImagesFile::Periodic) => {
                if !surface.read.periodic {
                    return Err(invalid(
                        "model.images",
                        "\"periodic\" needs a periodic surface (surface.periodic = true)",
                    ));
                }
                Images::Periodic(cells)
            }
        };
        // [load]
        let ld = self
            .load
            .ok_or_else(|| SceneError::Missing("load".into()))?;
        let tangential_file = ld.tangential.clone();
        let (load, unload) = load(ld)?;
        // [output] (optional)
        let output = match self.output {
            None => OutputSpec::default(),
            Some(ot) => output(ot, kind)?,
        };
        if let Some(cs) = &counter.surface
            && matches!(cs.source, SurfaceSource::Generate(_))
            && cs.source == surface.source
        {
            return Err(invalid(
                "counterface.surface.generate.seed",
                "equals the first body's [surface.generate]: the two surfaces would be \
                 the same heights twice; give the counterface another seed",
            ));
        }
        let plasticity = match self.plasticity {
            None => None,
            Some(pt) => {
                let hardness = positive(pt.hardness, "plasticity.hardness")?;
                if let Some(reason) = strata_runtime::rough::plastic::hardness_problem(hardness) {
                    return Err(invalid("plasticity.hardness", reason));
                }
                Some(PlasticitySpec { hardness })
            }
        };
        if unload && kind != ModelKind::Bem {
            return Err(invalid(
                "load.unload",
                "a return path is solved by the BEM (model.kind = \"bem\"); the N and I \
                 models follow the loading path only (with [plasticity] too)",
            ));
        }
        if plasticity.is_some()
            && kind != ModelKind::Bem
            && let Some((field, what)) = load.first_reversal()
        {
            return Err(invalid(
                field,
                format!(
                    "{what}: a path that unloads is solved by the BEM (model.kind = \"bem\"); the \
                     N and I models follow the loading path only (with [plasticity] too)"
                ),
            ));
        }
        let conductance = match self.conductance {
            None => None,
            Some(c) => Some(conductance(c, &counter, &bodies)?),
        };
        let friction = match self.friction {
            None => None,
            Some(f) => {
                let coefficient = positive(f.coefficient, "friction.coefficient")?;
                Some(FrictionSpec { coefficient })
            }
        };
        let tangential = match tangential_file {
            None => None,
            Some(t) => Some(tangential_path(t, kind, friction.is_some())?),
        };
        let solver = match self.solver {
            None => SolverSpec::default(),
            Some(s) => solver(s)?,
        };
        Ok(Scene {
            conductance,
            friction,
            tangential,
            plasticity,
            unload,
            bodies,
            stack_file,
            counterface_file: counter.file,
            table: table_path,
            surface,
            model: ModelSpec { kind, images },
            load,
            output,
            solver,
        })
    }
}

/// `[load]`: the load path and `unload`.
fn load(ld: LoadFile) -> Result<(LoadSpec, bool), SceneError> {
    let unload = ld.unload.unwrap_or(false);
    let given = [
        ld.separations.is_some(),
        ld.approach.is_some(),
        ld.mean_pressures.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err(invalid(
            "load",
            "give exactly one of `separations`, `approach`, `mean_pressures`",
        ));
    }
    let load = if let Some(v) = &ld.separations {
        LoadSpec::Separations(numbers(v, "load.separations")?)
    } else if let Some(v) = &ld.mean_pressures {
        let p = numbers(v, "load.mean_pressures")?;
        if let Some((i, x)) = p.iter().enumerate().find(|(_, x)| **x <= 0.0) {
            return Err(invalid(
                format!("load.mean_pressures[{i}]"),
                format!("{x} must be > 0 (Pa)"),
            ));
        }
        LoadSpec::MeanPressures(p)
    } else {
        let a = ld.approach.unwrap_or_default();
        let from = finite(
            a.from
                .ok_or_else(|| SceneError::Missing("load.approach.from".into()))?,
            "load.approach.from",
        )?;
        let to = finite(
            a.to.ok_or_else(|| SceneError::Missing("load.approach.to".into()))?,
            "load.approach.to",
        )?;
        if from < 0.0 {
            return Err(invalid(
                "load.approach.from",
                format!("{from} must be ≥ 0 (m)"),
            ));
        }
        if to < 0.0 {
            return Err(invalid("load.approach.to", format!("{to} must be ≥ 0 (m)")));
        }
        let steps = a
            .steps
            .ok_or_else(|| SceneError::Missing("load.approach.steps".into()))?;
        if !(1..=100_000).contains(&steps) {
            return Err(invalid(
                "load.approach.steps",
                format!("{steps} must be in [1, 100000]"),
            ));
        }
        LoadSpec::Approach {
            from,
            to,
            steps: steps as usize,
        }
    };
    Ok((load, unload))
}

/// `load.tangential = { from, to, steps }`: ratios Q/(μP) in (−1, 1), 1 to 10 000
/// values; only for the BEM (`kind`) with `[friction]` (`friction`).
fn tangential_path(
    t: super::file::ApproachFile,
    kind: ModelKind,
    friction: bool,
) -> Result<TangentialPathSpec, SceneError> {
    let ratio = |x: Option<f64>, field: &str| -> Result<f64, SceneError> {
        let x = finite(x.ok_or_else(|| SceneError::Missing(field.into()))?, field)?;
        if x.abs() >= 1.0 {
            return Err(invalid(
                field,
                format!(
                    "{x} must be in (-1, 1): a ratio Q/(μP) of the tangential force to the \
                     friction limit μP (at |Q| = μP the whole contact slips: gross sliding, \
                     which no tangential force controls)"
                ),
            ));
        }
        Ok(x)
    };
    let from = ratio(t.from, "load.tangential.from")?;
    let to = ratio(t.to, "load.tangential.to")?;
    let steps = t
        .steps
        .ok_or_else(|| SceneError::Missing("load.tangential.steps".into()))?;
    if !(1..=10_000).contains(&steps) {
        return Err(invalid(
            "load.tangential.steps",
            format!("{steps} must be in [1, 10000]"),
        ));
    }
    if kind != ModelKind::Bem {
        return Err(invalid(
            "load.tangential",
            "a tangential path (Coulomb partial slip) is solved by the BEM (model.kind = \"bem\"); \
             the N and I models give the full-stick tangential stiffness only ([friction])",
        ));
    }
    if !friction {
        return Err(invalid(
            "load.tangential",
            "a tangential path needs the coefficient of friction: add [friction] coefficient = μ",
        ));
    }
    Ok(TangentialPathSpec {
        from,
        to,
        steps: steps as usize,
    })
}

/// `[output]`.
fn output(ot: OutputFile, kind: ModelKind) -> Result<OutputSpec, SceneError> {
    let maps = match ot.maps {
        None | Some(MapsFile::Flag(false)) => MapsSpec::None,
        Some(MapsFile::Flag(true)) => MapsSpec::All,
        Some(MapsFile::Name(m)) => match m.as_str() {
            "none" => MapsSpec::None,
            "last" => MapsSpec::Last,
            "all" => MapsSpec::All,
            other => {
                return Err(invalid(
                    "output.maps",
                    format!("`{other}` is not one of \"none\", \"last\", \"all\""),
                ));
            }
        },
    };
    if maps != MapsSpec::None && kind != ModelKind::Bem {
        return Err(invalid(
            "output.maps",
            "pressure and gap maps come from the full-field solution and need \
             model.kind = \"bem\" (the asperity models resolve each contact \
             by its radius only, not a pressure field)",
        ));
    }
    let format = match ot.format {
        None => MapFormats::default(),
        Some(names) => {
            let mut f = MapFormats {
                npy: false,
                netcdf: false,
            };
            for n in &names.0 {
                match n.as_str() {
                    "npy" => f.npy = true,
                    "netcdf" => f.netcdf = true,
                    other => {
                        return Err(invalid(
                            "output.format",
                            format!("`{other}` is not one of \"npy\", \"netcdf\""),
                        ));
                    }
                }
            }
            if !f.npy && !f.netcdf {
                return Err(invalid(
                    "output.format",
                    "is empty: name \"npy\", \"netcdf\" or both",
                ));
            }
            if maps == MapsSpec::None {
                return Err(invalid(
                    "output.format",
                    "chooses the files of the maps, but output.maps is \"none\" \
                     (set maps = \"last\" or \"all\")",
                ));
            }
            f
        }
    };
    Ok(OutputSpec { maps, format })
}

/// `[solver]`.
fn solver(s: SolverFile) -> Result<SolverSpec, SceneError> {
    let count = |v: Option<i64>, key: &str| -> Result<Option<usize>, SceneError> {
        let Some(n) = v else { return Ok(None) };
        if !(1..=1_000_000_000).contains(&n) {
            return Err(invalid(
                format!("solver.{key}"),
                format!("{n} must be in [1, 1000000000]"),
            ));
        }
        Ok(Some(n as usize))
    };
    let fraction = |v: Option<f64>, key: &str| -> Result<Option<f64>, SceneError> {
        let Some(x) = v else { return Ok(None) };
        let field = format!("solver.{key}");
        let x = finite(x, &field)?;
        if !(x > 0.0 && x < 1.0) {
            return Err(invalid(
                field,
                format!("{x} must be in (0, 1) (a relative tolerance)"),
            ));
        }
        Ok(Some(x))
    };
    Ok(SolverSpec {
        max_step_newton_steps: count(s.max_step_newton_steps, "max_step_newton_steps")?,
        max_step_evaluations: count(s.max_step_evaluations, "max_step_evaluations")?,
        kkt_tolerance: fraction(s.kkt_tolerance, "kkt_tolerance")?,
        max_pressure_iterations: count(s.max_pressure_iterations, "max_pressure_iterations")?,
        bem_max_iterations: count(s.bem_max_iterations, "bem_max_iterations")?,
        bem_tolerance: fraction(s.bem_tolerance, "bem_tolerance")?,
    })
}

/// The validated `[counterface]` table.
#[derive(Default)]
pub(super) struct CounterfaceSpec {
    /// The elastic counterface; `None` for a rigid flat.
    pub stack: Option<Stack>,
    pub file: Option<PathBuf>,
    pub table: Option<PathBuf>,
    pub surface: Option<SurfaceSpec>,
    /// `conduction = "perfect"` or `"half-space"` (`None`: not given).
    pub conduction: Option<CounterfaceConductionFile>,
    /// A rigid flat's conductivities (`thermal_conductivity`, `electrical_conductivity`).
    pub conductivity: Conductivity,
    /// `kind = "rigid"` written out.
    pub explicit_rigid: bool,
}

/// `[counterface]`: `kind = "rigid"` (the default when absent) or an elastic stack
/// (`file`, or inline `[[counterface.layer]]`/`[counterface.base]`; `kind = "elastic"`
/// optional), an optional pair `table` and an optional `[counterface.surface]` with
/// the keys of `[surface]`.
fn counterface(
    ct: Option<CounterfaceFile<SurfaceFile>>,
    dir: &Path,
) -> Result<CounterfaceSpec, SceneError> {
    let Some(ct) = ct else {
        return Ok(CounterfaceSpec::default());
    };
    if ct.counterface.is_some() {
        return Err(invalid(
            "counterface.counterface",
            strata_runtime::stack::StackError::NestedCounterface.to_string(),
        ));
    }
    let rigid = match ct.kind {
        Some(CounterfaceKindFile::Rigid) => true,
        Some(CounterfaceKindFile::Elastic) => false,
        None => !ct.has_stack(),
    };
    let mut spec = CounterfaceSpec {
        conduction: ct.conduction,
        explicit_rigid: ct.kind == Some(CounterfaceKindFile::Rigid),
        ..Default::default()
    };
    for (key, given, slot) in [
        (
            "thermal_conductivity",
            ct.thermal_conductivity,
            &mut spec.conductivity.thermal,
        ),
        (
            "electrical_conductivity",
            ct.electrical_conductivity,
            &mut spec.conductivity.electrical,
        ),
    ] {
        let Some(k) = given else { continue };
        let field = format!("counterface.{key}");
        if !rigid {
            return Err(invalid(
                field,
                "an elastic counterface gives its conductivities per \
                 [[counterface.layer]] and [counterface.base], as a stack does",
            ));
        }
        let k = positive(Some(k), &field)?;
        if !(1e-30..=1e30).contains(&k) {
            return Err(invalid(field, format!("{k} must lie in [1e-30, 1e30]")));
        }
        *slot = Some(k);
    }
    if !rigid && ct.conduction == Some(CounterfaceConductionFile::HalfSpace) {
        return Err(invalid(
            "counterface.conduction",
            "\"half-space\" describes a rigid flat (counterface.kind = \"rigid\"); an \
             elastic counterface conducts through its own stack, or give \"perfect\"",
        ));
    }
    if rigid {
        for (k, given) in [
            ("file", ct.file.is_some()),
            ("name", ct.name.is_some()),
            ("layer", ct.layer.is_some()),
            ("base", ct.base.is_some()),
            ("table", ct.table.is_some()),
        ] {
            if given {
                return Err(invalid(
                    format!("counterface.{k}"),
                    "a rigid counterface (counterface.kind = \"rigid\") has no stack or table",
                ));
            }
        }
    } else {
        let file = ct
            .file
            .as_deref()
            .map(|f| existing_file(dir, "counterface.file", f, ""))
            .transpose()?;
        let stack = match &file {
            Some(f) => {
                if ct.has_inline_stack() {
                    return Err(invalid(
                        "counterface.file",
                        "give either `file` or inline [[counterface.layer]]/[counterface.base], not both",
                    ));
                }
                // a counterface file that writes its own [counterface]: named as such
                let file_error = |e: StackError| StackError::InFile {
                    path: f.display().to_string(),
                    error: Box::new(e),
                };
                Bodies::from_toml_file(f)
                    .and_then(|b| {
                        b.single()
                            .map_err(|_| file_error(StackError::NestedCounterface))
                    })
                    .map_err(|e| invalid("counterface.file", e.to_string()))?
            }
            None => {
                if !ct.has_inline_stack() {
                    return Err(SceneError::Missing(
                        "counterface.file (or inline [[counterface.layer]]/[counterface.base]) for kind = \"elastic\""
                            .into(),
                    ));
                }
                ct.elastic_body()
                    .map_err(|e| invalid("counterface", e.to_string()))?
            }
        };
        spec.table = ct
            .table
            .as_deref()
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
    if let Some(sf) = &ct.surface {
        spec.surface = Some(surface_spec(sf, dir, "counterface.surface")?);
    }
    Ok(spec)
}

/// `[conductance]`: `kind = "thermal"` or `"electrical"`. The scene's bodies must
/// conduct: every layer (and a half-space base) of the first body, and the counterface
/// (a rigid flat's `thermal_conductivity`/`electrical_conductivity` or `conduction =
/// "perfect"`; an elastic one's stack, or `"perfect"`); each missing property is named.
/// Solved by the BEM (periodic or not), the N and the I model.
fn conductance(
    ct: ConductanceFile,
    counter: &CounterfaceSpec,
    bodies: &Bodies<SurfaceSpec>,
) -> Result<ConductanceSpec, SceneError> {
    let kind = match ct.kind {
        Some(ConductionKindFile::Thermal) => ConductionKind::Thermal,
        Some(ConductionKindFile::Electrical) => ConductionKind::Electrical,
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
    let rigid_perfect = matches!(
        bodies.counterface,
        Counterface::Rigid {
            conduction: RigidConduction::Perfect,
            ..
        }
    );
    if rigid_perfect && pick(&counter.conductivity).is_some() {
        return Err(invalid(
            format!("counterface.{}", kind.field()),
            "a perfect conductor (counterface.conduction = \"perfect\") has no \
             conductivity: give one or the other",
        ));
    }
    let Some(counterface) = CounterfaceConduction::of(&bodies.counterface, kind) else {
        return Err(SceneError::Missing(format!(
            "counterface.{} ({}; the rigid flat as a conducting half-space) or \
             counterface.conduction = \"perfect\": [conductance] kind = \"{}\" needs the \
             counterface's conduction",
            kind.field(),
            kind.conductivity_unit(),
            kind.name()
        )));
    };
    let spec = ConductanceSpec { kind, counterface };
    spec.body(&bodies.first)?;
    spec.counterface_stack(&bodies.counterface)?;
    Ok(spec)
}

/// A `[surface]` table (`at` = "surface" or "counterface.surface", the prefix of every
/// field named) whose relative paths resolve against `dir`.
fn surface_spec(sf: &SurfaceFile, dir: &Path, at: &str) -> Result<SurfaceSpec, SceneError> {
    surface_spec_in(sf, dir).map_err(|e| relabel(e, at))
}

/// A `surface.…` error as one of `at.…`.
fn relabel(e: SceneError, at: &str) -> SceneError {
    if at == "surface" {
        return e;
    }
    let f = |s: String| match s.strip_prefix("surface") {
        Some(rest) => format!("{at}{rest}"),
        None => s,
    };
    match e {
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

fn surface_spec_in(sf: &SurfaceFile, dir: &Path) -> Result<SurfaceSpec, SceneError> {
    let periodic = sf.periodic;
    let repair = match sf.repair.as_deref() {
        None | Some("none") => Repair::Refuse,
        Some("median" | "harmonic") if sf.file.is_some() => Repair::Median,
        Some("median" | "harmonic") => {
            return Err(invalid(
                "surface.repair",
                "applies to measured surfaces (surface.file), not generated ones",
            ));
        }
        Some(other) => {
            return Err(invalid(
                "surface.repair",
                format!(
                    "`{other}` is not one of \"none\", \"median\", \"harmonic\" (the last two \
                     the same harmonic fill)"
                ),
            ));
        }
    };
    Ok(match (&sf.file, &sf.generate) {
        (Some(_), Some(_)) => {
            return Err(invalid(
                "surface.file",
                "give either `file` or [surface.generate], not both",
            ));
        }
        (None, None) => {
            return Err(SceneError::Missing(
                "surface.file (or a [surface.generate] table)".into(),
            ));
        }
        (Some(f), None) => {
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
                        &strata_runtime::resources::MemoryLimit::of_machine(),
                    )
                    .ok()
                    .and_then(|e| e.periodic),
                    _ => None,
                })
                .unwrap_or(false);
            // Measured files: the least-squares plane is removed unless asked otherwise;
            // a periodic sample has no tilt to remove (a plane is not periodic).
            let detrend = match sf.detrend.as_deref() {
                None if periodic => Detrend::None,
                None => Detrend::Plane,
                Some(d) => Detrend::parse(d).ok_or_else(|| {
                    invalid(
                        "surface.detrend",
                        format!("`{d}` is not one of \"none\", \"plane\", \"curvature\""),
                    )
                })?,
            };
            if periodic && detrend != Detrend::None {
                return Err(invalid(
                    "surface.detrend",
                    format!(
                        "\"{}\" on a periodic surface (surface.periodic = true): a tilt or a \
                         curvature is not periodic (the sample's edges would no longer meet); \
                         remove the key (a periodic sample keeps its heights) or set periodic = false",
                        detrend.name()
                    ),
                ));
            }
            SurfaceSpec {
                source: SurfaceSource::File(p),
                read: ReadOptions {
                    spacing,
                    periodic,
                    repair,
                    height_unit,
                    detrend,
                    ..Default::default()
                },
                topography,
            }
        }
        (None, Some(g)) => {
            let size = match (g.size, &sf.size) {
                (Some(s), _) => positive(Some(s), "surface.generate.size")?,
                (None, Some(Lengths::One(s))) => positive(Some(*s), "surface.size")?,
                (None, Some(Lengths::Two(_))) => {
                    return Err(SceneError::WrongType {
                        field: "surface.size".into(),
                        expected: "a number".into(),
                    });
                }
                (None, None) => {
                    return Err(SceneError::Missing("surface.generate.size".into()));
                }
            };
            let grid = g
                .grid
                .ok_or_else(|| SceneError::Missing("surface.generate.grid".into()))?;
            if !(4..=16384).contains(&grid) {
                return Err(invalid(
                    "surface.generate.grid",
                    format!("{grid} must be in [4, 16384]"),
                ));
            }
            let seed = g
                .seed
                .ok_or_else(|| SceneError::Missing("surface.generate.seed".into()))?;
            if seed < 0 {
                return Err(invalid(
                    "surface.generate.seed",
                    format!("{seed} must be ≥ 0"),
                ));
            }
            if periodic == Some(false) {
                return Err(invalid(
                    "surface.periodic",
                    "a generated surface is periodic",
                ));
            }
            for (key, given) in [
                ("pixel_size", sf.pixel_size.is_some()),
                ("height_unit", sf.height_unit.is_some()),
                ("detrend", sf.detrend.is_some()),
            ] {
                if given {
                    return Err(invalid(
                        format!("surface.{key}"),
                        "applies to measured surfaces (surface.file), not generated ones",
                    ));
                }
            }
            let fd = g
                .fractal_dimension
                .ok_or_else(|| SceneError::Missing("surface.generate.fractal_dimension".into()))?;
            SurfaceSpec {
                source: SurfaceSource::Generate(GenerateParams {
                    size,
                    grid: grid as usize,
                    fractal_dimension: finite(fd, "surface.generate.fractal_dimension")?,
                    k_min: positive(g.k_min, "surface.generate.k_min")?,
                    k_max: positive(g.k_max, "surface.generate.k_max")?,
                    rms: positive(g.rms, "surface.generate.rms")?,
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
fn container_pick(sf: &SurfaceFile, file: &Path) -> Result<Option<Pick>, SceneError> {
    let Some(v) = &sf.topography else {
        return Ok(None);
    };
    if FileKind::of(file) != FileKind::Container {
        return Err(invalid(
            "surface.topography",
            "picks a topography of a contact.engineering container (a .zip file); \
             remove it for other files",
        ));
    }
    match v {
        TopographyPick::Index(i) if *i >= 0 => Ok(Some(Pick::Index(*i as usize))),
        TopographyPick::Name(n) => Ok(Some(Pick::Name(n.clone()))),
        TopographyPick::Index(i) => Err(invalid(
            "surface.topography",
            format!(
                "`{i}` is neither a topography number (0, 1, ... across the container's \
                 surfaces) nor a topography name"
            ),
        )),
    }
}
