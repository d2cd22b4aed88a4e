//! `strata.Scene`: a rough-contact case (stack, surface, model, load) from a scene file
//! or from Python objects, solved by the engine of `strata solve` (same numbers as the
//! CLI's curve.csv), and its contact law as `strata law` samples it.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use strata_bem::BemSolution;
use strata_engine::engine::{Console, EngineOptions, WithMaps, solve};
use strata_engine::scene::{ModelKind, Scene, SurfaceSource, SurfaceSpec};
use strata_runtime::Solid;
use strata_runtime::stack::{CounterfaceFile, StackFile};
use strata_runtime::surface::{ReadOptions, Spacing, Surface};
use strata_runtime::table::Table;

use crate::errors::{Kind, err, require_file, to_py};
use crate::law::PyContactLaw;
use crate::stack::{PyStack, stack_of};
use crate::surface::PySurface;
use crate::table::table_arg;

/// A rough-contact case: a material stack, a surface, a model and a load.
///
/// Scene.from_file(path) reads a scene TOML file (as `strata solve` does); or
///
/// Scene(stack, surface, model="interacting", load=..., images=None, image_cells=None, table=None, solver=None)
///
/// builds one from Python objects: stack a strata.Stack (or a stack file), surface a
/// strata.Surface, model "independent" (N model), "interacting" (I model) or "bem"
/// (full-field FFT boundary elements), load a dict as the scene's [load] table:
/// {"separations": [...]} (m), {"approach": {"from": m, "to": m, "steps": n}} or
/// {"mean_pressures": [...]} (Pa); images "periodic" or "isolated", image_cells m
/// ((2m+1)² block); table a strata.Table or a `.strata` path for a layered stack
/// (default: the table cache); solver a dict as the scene's [solver] table, the budgets
/// and tolerances an error message may ask to raise ({"max_step_newton_steps": n,
/// "max_step_evaluations": n, "kkt_tolerance": x, "max_pressure_iterations": n,
/// "bem_max_iterations": n, "bem_tolerance": x}); counterface a strata.Stack (or a stack
/// file path) pressed against the first body instead of a rigid flat (the two compliances
/// add, physics.md §6.1) and counterface_surface its rough strata.Surface, heights as seen
/// from the first body on the same grid (added to `surface`); plasticity a dict as the
/// scene's [plasticity] table ({"hardness": Pa}) and conductance one as its
/// [conductance] table ({"kind": "thermal"}). Fields are validated as in a scene file,
/// and errors (strata.SceneError) name them (`load.approach.steps`, `model.images`,
/// `counterface.base`, `plasticity.hardness`, ...).
#[pyclass(name = "Scene", module = "strata", frozen)]
pub struct PyScene {
    scene: Scene,
    /// The scene file, or `<python>` for a scene built in memory.
    path: PathBuf,
    /// A surface given in memory (replaces the scene's `[surface]`).
    surface: Option<Surface>,
    /// A table given in memory.
    table: Option<Arc<Table>>,
}

/// A Python value (dict with string keys, list, tuple, bool, int, float, str; numpy
/// arrays and scalars through `tolist`) as a JSON value, for the scene's serde types;
/// `field` is its dotted place in the scene, for the message. Numbers must be finite
/// (a scene file's are), and None is not a value.
fn py_to_json(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<serde_json::Value> {
    use pyo3::types::{PyBool, PyFloat, PyInt, PyString, PyTuple};
    use serde_json::Value as J;
    let bad = |what: String| to_py(Kind::Scene, anyhow::anyhow!("field `{field}`: {what}"));
    if obj.is_none() {
        return Err(bad("None is not a value".into()));
    }
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(J::Bool(b.is_true()));
    }
    if let Ok(i) = obj.cast::<PyInt>() {
        return match i.extract::<i64>() {
            Ok(i) => Ok(J::from(i)),
            Err(_) => Err(bad(format!("{i} is out of range"))),
        };
    }
    if let Ok(x) = obj.cast::<PyFloat>() {
        let x = x.value();
        return serde_json::Number::from_f64(x)
            .map(J::Number)
            .ok_or_else(|| bad(format!("every number must be finite, got {x}")));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(J::String(s.to_cow()?.into_owned()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut m = serde_json::Map::new();
        for (k, v) in d.iter() {
            let k: String = k
                .extract()
                .map_err(|_| bad(format!("key {k} is not a string")))?;
            let x = py_to_json(&v, &format!("{field}.{k}"))?;
            m.insert(k, x);
        }
        return Ok(J::Object(m));
    }
    if obj.cast::<PyList>().is_ok() || obj.cast::<PyTuple>().is_ok() {
        return obj
            .try_iter()?
            .enumerate()
            .map(|(i, x)| py_to_json(&x?, &format!("{field}[{i}]")))
            .collect::<PyResult<Vec<_>>>()
            .map(J::Array);
    }
    if obj.hasattr("tolist")? {
        return py_to_json(&obj.call_method0("tolist")?, field);
    }
    Err(bad(format!(
        "a {} is not a value (give numbers, strings, lists or dicts)",
        obj.get_type().name()?
    )))
}

/// The scene's surface in memory: spacing, periodicity (the reader's options are not
/// used, the file name only labels it).
fn memory_surface_spec(s: &Surface) -> SurfaceSpec {
    let (dx, dy) = s.pixel_size();
    SurfaceSpec {
        source: SurfaceSource::File(PathBuf::from("<numpy array>")),
        read: ReadOptions {
            spacing: Some(Spacing::Pixel(dx, dy)),
            periodic: s.is_periodic(),
            ..Default::default()
        },
        topography: None,
    }
}

/// The label of an in-memory scene (curve.json's `scene`).
const MEMORY: &str = "<python>";

#[pymethods]
impl PyScene {
    #[new]
    #[pyo3(signature = (stack, surface, model="interacting", load=None, images=None, image_cells=None, table=None, solver=None, counterface=None, counterface_surface=None, plasticity=None, conductance=None, friction=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        stack: &Bound<'_, PyAny>,
        surface: &Bound<'_, PySurface>,
        model: &str,
        load: Option<&Bound<'_, PyAny>>,
        images: Option<&str>,
        image_cells: Option<i64>,
        table: Option<&Bound<'_, PyAny>>,
        solver: Option<&Bound<'_, PyAny>>,
        counterface: Option<&Bound<'_, PyAny>>,
        counterface_surface: Option<&Bound<'_, PySurface>>,
        plasticity: Option<&Bound<'_, PyAny>>,
        conductance: Option<&Bound<'_, PyAny>>,
        friction: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let stack = stack_of(stack, "Scene: stack")?;
        let mut surface = surface.get().surface.clone();
        if let Some(cs) = counterface_surface {
            surface = surface
                .plus_counterface(&cs.get().surface)
                .map_err(|e| to_py(Kind::Scene, anyhow::anyhow!("counterface_surface: {e}")))?;
        }
        let counterface = counterface
            .map(|c| {
                stack_of(c, "Scene: counterface")?
                    .single()
                    .map_err(|e| to_py(Kind::Scene, anyhow::anyhow!("Scene: counterface: {e}")))
            })
            .transpose()?;
        let load = load.ok_or_else(|| {
            to_py(
                Kind::Scene,
                anyhow::anyhow!("missing field `load`: give load={{\"separations\": [...]}}, {{\"approach\": {{\"from\": ..., \"to\": ..., \"steps\": ...}}}} or {{\"mean_pressures\": [...]}}"),
            )
        })?;
        // The scene file's tables as serde_json values, deserialized into the scene's
        // serde types and validated as a file's (same messages).
        use serde_json::{Value as J, json};
        let mut top = serde_json::Map::new();
        top.insert(
            "stack".into(),
            serde_json::to_value(StackFile::of(&stack))
                .map_err(|e| to_py(Kind::Scene, anyhow::anyhow!("stack: {e}")))?,
        );
        let mut md = serde_json::Map::new();
        md.insert("kind".into(), json!(model));
        if let Some(i) = images {
            md.insert("images".into(), json!(i));
        }
        if let Some(c) = image_cells {
            md.insert("image_cells".into(), json!(c));
        }
        top.insert("model".into(), J::Object(md));
        top.insert("load".into(), py_to_json(load, "load")?);
        if let Some(sv) = solver {
            top.insert("solver".into(), py_to_json(sv, "solver")?);
        }
        if let Some(c) = counterface {
            top.insert(
                "counterface".into(),
                serde_json::to_value(CounterfaceFile::<()>::of(&c))
                    .map_err(|e| to_py(Kind::Scene, anyhow::anyhow!("counterface: {e}")))?,
            );
        }
        // [plasticity] and [conductance] as dicts, validated as a scene file's
        if let Some(pl) = plasticity {
            top.insert("plasticity".into(), py_to_json(pl, "plasticity")?);
        }
        if let Some(cd) = conductance {
            top.insert("conductance".into(), py_to_json(cd, "conductance")?);
        }
        // [friction] as a dict ({"coefficient": 0.3}), validated as a scene file's
        if let Some(fr) = friction {
            top.insert("friction".into(), py_to_json(fr, "friction")?);
        }
        let scene = Scene::from_data_in(
            J::Object(top),
            Path::new("."),
            Some(memory_surface_spec(&surface)),
        )
        .map_err(err(Kind::Scene))?;
        Ok(PyScene {
            scene,
            path: PathBuf::from(MEMORY),
            surface: Some(surface),
            table: table_arg(table)?,
        })
    }

    /// Reads a scene TOML file (paths inside it are relative to its directory).
    #[staticmethod]
    fn from_file(path: PathBuf) -> PyResult<Self> {
        require_file("Scene.from_file", &path)?;
        Ok(PyScene {
            scene: Scene::from_file(&path).map_err(err(Kind::Scene))?,
            path,
            surface: None,
            table: None,
        })
    }

    /// Parses a scene from TOML text; relative paths resolve against `dir`.
    #[staticmethod]
    #[pyo3(signature = (text, dir=PathBuf::from(".")))]
    fn from_toml(text: &str, dir: PathBuf) -> PyResult<Self> {
        Ok(PyScene {
            scene: Scene::from_str_in(text, &dir).map_err(err(Kind::Scene))?,
            path: PathBuf::from(MEMORY),
            surface: None,
            table: None,
        })
    }

    /// The material stack.
    #[getter]
    fn stack(&self) -> PyStack {
        PyStack {
            stack: self.scene.bodies.bodies(),
        }
    }

    /// "independent", "interacting" or "bem".
    #[getter]
    fn model(&self) -> &'static str {
        match self.scene.model.kind {
            ModelKind::Independent => "independent",
            ModelKind::Interacting => "interacting",
            ModelKind::Bem => "bem",
        }
    }

    /// The scene file (or "<python>").
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// The scene's surface (read or generated now, or the one given).
    fn surface(&self, py: Python<'_>) -> PyResult<PySurface> {
        Ok(PySurface {
            surface: crate::progress::call(py, Some(false), |_| self.load_surface())??,
        })
    }

    /// Solves the load curve with the scene's model, by the engine of `strata solve`:
    /// returns a dict of numpy arrays with the columns of curve.csv (delta, gap,
    /// mean_pressure, pressure_ratio, area_fraction, contacts, stiffness) plus load,
    /// kkt_residual (NaN where none), valid, and `meta` (curve.json's summary); a scene
    /// with `[conductance]` adds `conductance` (h_c per step, W/(m²·K) or S/m²), one with
    /// `[friction]` `tangential_stiffness` (K_t of the sample per step, N/m, full stick),
    /// one with `[load] tangential` (BEM) `tangential` (the tangential path: arrays
    /// force_ratio, tangential_force (N), tangential_displacement (m), stick_fraction,
    /// dissipation (J), and normal_force (N) and coefficient).
    /// maps ("none", "last", "all"; BEM only) adds the pressure (Pa) and gap (m) maps.
    /// Runs off the GIL; progress: True shows progress and log lines (in a notebook's
    /// cell, else on stderr), False only warnings, None (default) progress when in a
    /// notebook or on a terminal. Ctrl-C raises KeyboardInterrupt within about one
    /// solver iteration (nothing of the interrupted solve is kept).
    #[pyo3(signature = (progress=None, cache_dir=None, maps="none", table=None))]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        progress: Option<bool>,
        cache_dir: Option<PathBuf>,
        maps: &str,
        table: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let keep = match maps {
            "none" => 0,
            "last" => 1,
            "all" => 2,
            other => {
                return Err(to_py(
                    Kind::Scene,
                    anyhow::anyhow!("maps: `{other}` is not one of \"none\", \"last\", \"all\""),
                ));
            }
        };
        if keep > 0 && self.scene.model.kind != ModelKind::Bem {
            return Err(to_py(
                Kind::Scene,
                anyhow::anyhow!(
                    "maps: pressure and gap maps come from the full-field solution and need model \"bem\""
                ),
            ));
        }
        let opts = self.options(cache_dir, table)?;
        let mut kept: Vec<(usize, BemSolution)> = Vec::new();
        let sol = crate::progress::call(py, progress, |cancel| {
            let opts = EngineOptions {
                cancel: cancel.clone(),
                ..opts
            };
            let surface = self.load_surface()?;
            let mut observer = WithMaps {
                quiet: false,
                sink: |k, _, m| {
                    if keep == 1 {
                        kept.clear();
                    }
                    if keep > 0 {
                        kept.push((k, m));
                    }
                    Ok(())
                },
            };
            solve(&self.scene, Some(surface), &opts, &mut observer)
                .with_context_path(&self.path)
                .map_err(err(Kind::Solve))
        })??;
        let mut sol = sol;
        sol.summary.scene = self.path.display().to_string();
        let out = curve_dict(py, &sol.steps)?;
        // [conductance]: h_c per step (W/(m²·K) or S/m²; inf at full contact)
        if let Some(h) = sol.conductances() {
            out.set_item("conductance", h.into_pyarray(py))?;
        }
        // [friction]: the full-stick tangential stiffness of the sample per step (N/m)
        if let Some(k) = sol.tangential_stiffnesses() {
            out.set_item("tangential_stiffness", k.into_pyarray(py))?;
        }
        // [load] tangential (BEM): the tangential path as a dict of arrays (tangential.csv)
        if let Some(t) = &sol.tangential_path {
            let d = PyDict::new(py);
            let col = |f: fn(&strata_engine::solution::TangentialPoint) -> f64| -> Vec<f64> {
                t.steps.iter().map(f).collect()
            };
            d.set_item("force_ratio", col(|p| p.force_ratio).into_pyarray(py))?;
            d.set_item(
                "tangential_force",
                col(|p| p.tangential_force).into_pyarray(py),
            )?;
            d.set_item(
                "tangential_displacement",
                col(|p| p.tangential_displacement).into_pyarray(py),
            )?;
            d.set_item("stick_fraction", col(|p| p.stick_fraction).into_pyarray(py))?;
            d.set_item("dissipation", col(|p| p.dissipation).into_pyarray(py))?;
            d.set_item("normal_force", t.normal_force)?;
            d.set_item("coefficient", t.coefficient)?;
            out.set_item("tangential", d)?;
        }
        // the summary as a dict: JSON made here, at the Python boundary
        let meta = serde_json::to_value(&sol.summary)
            .map_err(|e| to_py(Kind::Solve, anyhow::Error::from(e)))?;
        out.set_item("meta", crate::conv::json_to_py(py, &meta)?)?;
        let list = PyList::empty(py);
        for (k, m) in kept {
            let d = PyDict::new(py);
            d.set_item("step", k)?;
            d.set_item("delta", m.approach)?;
            d.set_item("gap", m.separation)?;
            d.set_item("mean_pressure", m.mean_pressure)?;
            d.set_item("area_fraction", m.area_fraction)?;
            d.set_item("contacts", m.patches)?;
            d.set_item("pressure", m.pressure.into_pyarray(py))?;
            d.set_item("gap_map", m.gap.into_pyarray(py))?;
            list.append(d)?;
        }
        out.set_item("maps", list)?;
        Ok(out)
    }

    /// The contact law p(g) of the scene's interface, sampled as `strata law` does:
    /// `samples` separations from first contact down to `min_gap` (m; default the
    /// smallest separation the load reaches). Runs off the GIL; progress and Ctrl-C as
    /// in `solve`.
    #[pyo3(signature = (samples=200, min_gap=None, progress=None, cache_dir=None, table=None))]
    fn law(
        &self,
        py: Python<'_>,
        samples: usize,
        min_gap: Option<f64>,
        progress: Option<bool>,
        cache_dir: Option<PathBuf>,
        table: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyContactLaw> {
        let opts = self.options(cache_dir, table)?;
        let sampled = crate::progress::call(py, progress, |cancel| {
            let opts = EngineOptions {
                cancel: cancel.clone(),
                ..opts
            };
            let surface = self.load_surface()?;
            strata_engine::sampled_law::sample_law(
                &self.scene,
                surface,
                &opts,
                &mut Console,
                samples,
                min_gap,
            )
            .with_context_path(&self.path)
            .map_err(err(Kind::Law))
        })??;
        Ok(PyContactLaw {
            sampled,
            scene: self.path.display().to_string(),
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene({}, model {}, {})",
            self.path.display(),
            self.model(),
            strata_engine::engine::stack_description(&self.scene.bodies)
        )
    }
}

/// Adds "scene PATH" to an engine error, as the CLI does.
trait WithPath<T> {
    fn with_context_path(self, p: &Path) -> anyhow::Result<T>;
}

impl<T> WithPath<T> for Result<T, strata_engine::error::EngineError> {
    fn with_context_path(self, p: &Path) -> anyhow::Result<T> {
        use anyhow::Context;
        self.with_context(|| format!("scene {}", p.display()))
    }
}

impl PyScene {
    /// The engine options of a call: its progress and cancellation come from
    /// [`crate::progress::call`] (the report filters the log, so never `quiet`).
    fn options(
        &self,
        cache_dir: Option<PathBuf>,
        table: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<EngineOptions> {
        let table = match table_arg(table)? {
            Some(t) => Some(t),
            None => self.table.clone(),
        };
        Ok(EngineOptions {
            cache_dir,
            table,
            memory: crate::errors::memory_limit(Kind::Scene)?,
            ..Default::default()
        })
    }

    fn load_surface(&self) -> PyResult<Surface> {
        match &self.surface {
            Some(s) => Ok(s.clone()),
            None => strata_engine::engine::load_surface(
                &self.scene,
                &crate::errors::memory_limit(Kind::Surface)?,
            )
            .with_context_path(&self.path)
            .map_err(err(Kind::Surface)),
        }
    }
}

/// The curve.csv columns (and load, kkt_residual, valid) as numpy arrays.
pub fn curve_dict<'py>(
    py: Python<'py>,
    steps: &[strata_runtime::rough::Step],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let col = |f: &dyn Fn(&strata_runtime::rough::Step) -> f64| -> Vec<f64> {
        steps.iter().map(f).collect()
    };
    d.set_item("delta", col(&|s| s.delta).into_pyarray(py))?;
    d.set_item("gap", col(&|s| s.gap).into_pyarray(py))?;
    d.set_item("mean_pressure", col(&|s| s.mean_pressure).into_pyarray(py))?;
    d.set_item(
        "pressure_ratio",
        col(&|s| s.pressure_ratio).into_pyarray(py),
    )?;
    d.set_item("area_fraction", col(&|s| s.area_fraction).into_pyarray(py))?;
    let contacts: Vec<i64> = steps.iter().map(|s| s.contacts as i64).collect();
    d.set_item("contacts", contacts.into_pyarray(py))?;
    d.set_item("stiffness", col(&|s| s.stiffness).into_pyarray(py))?;
    d.set_item("load", col(&|s| s.load).into_pyarray(py))?;
    d.set_item(
        "kkt_residual",
        col(&|s| s.kkt_residual.unwrap_or(f64::NAN)).into_pyarray(py),
    )?;
    let valid: Vec<bool> = steps.iter().map(|s| s.validity.is_valid()).collect();
    d.set_item("valid", valid.into_pyarray(py))?;
    Ok(d)
}
