//! Sweep files (TOML): a base scene and the axes swept over it.
//!
//! ```toml
//! title = "bandwidth study"               # optional, used in plot titles
//! scene = "../scenes/paper.toml"          # the base scene (relative to this file) …
//! # … or inline: [scene.stack], [scene.surface], [scene.surface.generate], [scene.model], [scene.load]
//!
//! [sweep]
//! mode = "grid"                           # "grid" (cartesian, default) | "list" (zip)
//! stack.modulus_ratio = [1, 5]            # E2/E1
//! surface.k_max = [10, 20, 40]            # units of 2π/L
//! surface.seed = { from = 1, count = 20 } # seeds 1…20
//! model.kind = ["independent", "interacting"]
//! ```
//!
//! Axes (dotted or quoted keys, both mean the same):
//! - `stack.modulus_ratio`: E₂/E₁ — the Young modulus of layer 2 (or of the elastic
//!   base under a single layer) set to ratio × E₁;
//! - `stack.layerN.thickness|young|poisson` (N = 1, 2, … from the top),
//!   `stack.base.young|poisson` (elastic base);
//! - `surface.k_min|k_max|rms|fractal_dimension|size` (numbers),
//!   `surface.grid|seed` (integers): generated surfaces only;
//! - `model.kind` (`"independent"`, `"interacting"`, `"bem"`),
//!   `model.images` (`"isolated"`, `"periodic"`).
//!
//! Values: a non-empty array, `{ from = I, count = N }` (integers I, I+1, …, I+N−1)
//! or `{ from = A, to = B, count = N, log = false }` (N numbers evenly, or
//! geometrically with `log = true`, from A to B).
//!
//! Case order (fixed, documented): axes are sorted by name (byte order); in `grid`
//! mode the case id `c = 0, 1, …` runs over the cartesian product with the first axis
//! varying slowest and the last fastest (mixed radix); in `list` mode every axis has
//! the same length and case c takes the c-th value of each.
//!
//! Every error names the offending field (`sweep.surface.k_max[2]`, `scene.load`, …).

use std::fmt;
use std::path::{Path, PathBuf};
use strata_runtime::resources::MemoryLimit;

use crate::scene::{ModelKind, Scene, SurfaceSource, SurfaceSpec};
use anyhow::{Context, Result, anyhow, bail};
use strata_runtime::hash::Fnv1a;
use strata_runtime::rough::Images;
use strata_runtime::stack::{Base, Counterface, Stack};
use toml::Value as Toml;

/// Largest number of cases a sweep may enumerate.
pub const MAX_CASES: usize = 1_000_000;

/// How axes combine into cases.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Cartesian product.
    Grid,
    /// Zip: all axes of equal length.
    List,
}

/// One value of an axis.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Num(f64),
    Int(i64),
    Str(String),
}

impl fmt::Display for Value {
    /// Shortest round-trip text (`10`, `0.2`, `3.4e-6` prints as `0.0000034`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Num(x) => write!(f, "{x}"),
            Value::Int(i) => write!(f, "{i}"),
            Value::Str(s) => f.write_str(s),
        }
    }
}

impl Value {
    fn num(&self) -> f64 {
        match self {
            Value::Num(x) => *x,
            Value::Int(i) => *i as f64,
            Value::Str(_) => f64::NAN,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LayerField {
    Thickness,
    Young,
    Poisson,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SurfaceField {
    KMin,
    KMax,
    Rms,
    FractalDimension,
    Size,
    Grid,
    Seed,
}

/// What an axis sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Param {
    ModulusRatio,
    Layer(usize, LayerField),
    BaseYoung,
    BasePoisson,
    /// `counterface.layerN.*` of the elastic counterface.
    CounterLayer(usize, LayerField),
    CounterBaseYoung,
    CounterBasePoisson,
    Surface(SurfaceField),
    ModelKind,
    ModelImages,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Float,
    Int,
    Str,
}

const KNOWN: &str = "stack.modulus_ratio, stack.layerN.thickness|young|poisson, \
stack.base.young|poisson, counterface.layerN.thickness|young|poisson, \
counterface.base.young|poisson, surface.k_min|k_max|rms|fractal_dimension|size|grid|seed, \
model.kind, model.images";

fn param_of(name: &str) -> Option<(Param, Kind)> {
    use SurfaceField::*;
    let f = Kind::Float;
    Some(match name {
        "stack.modulus_ratio" => (Param::ModulusRatio, f),
        "stack.base.young" => (Param::BaseYoung, f),
        "stack.base.poisson" => (Param::BasePoisson, f),
        "counterface.base.young" => (Param::CounterBaseYoung, f),
        "counterface.base.poisson" => (Param::CounterBasePoisson, f),
        "surface.k_min" => (Param::Surface(KMin), f),
        "surface.k_max" => (Param::Surface(KMax), f),
        "surface.rms" => (Param::Surface(Rms), f),
        "surface.fractal_dimension" => (Param::Surface(FractalDimension), f),
        "surface.size" => (Param::Surface(Size), f),
        "surface.grid" => (Param::Surface(Grid), Kind::Int),
        "surface.seed" => (Param::Surface(Seed), Kind::Int),
        "model.kind" => (Param::ModelKind, Kind::Str),
        "model.images" => (Param::ModelImages, Kind::Str),
        _ => {
            let (counter, rest) = match name.strip_prefix("stack.layer") {
                Some(rest) => (false, rest),
                None => (true, name.strip_prefix("counterface.layer")?),
            };
            let (n, field) = rest.split_once('.')?;
            let n: usize = n.parse().ok().filter(|n| *n >= 1)?;
            let field = match field {
                "thickness" => LayerField::Thickness,
                "young" => LayerField::Young,
                "poisson" => LayerField::Poisson,
                _ => return None,
            };
            if counter {
                (Param::CounterLayer(n, field), f)
            } else {
                (Param::Layer(n, field), f)
            }
        }
    })
}

/// Sets one field of a swept layer.
fn set_layer(l: &mut strata_runtime::Layer, f: LayerField, x: f64) {
    match f {
        LayerField::Thickness => l.thickness = x,
        LayerField::Young => l.young = x,
        LayerField::Poisson => l.poisson = x,
    }
}

/// Sets the Young modulus (`young`) or the Poisson ratio of a swept elastic base (a
/// rigid base has neither; such axes are refused before).
fn set_base(base: &mut Base, young: bool, x: f64) {
    if let Base::Elastic {
        young: e,
        poisson: nu,
    } = base
    {
        if young {
            *e = x;
        } else {
            *nu = x;
        }
    }
}

/// One swept parameter.
#[derive(Debug, Clone)]
pub struct Axis {
    /// Name as in the sweep file without the `sweep.` prefix (`surface.k_max`); also
    /// the CSV column.
    pub name: String,
    param: Param,
    pub values: Vec<Value>,
}

/// A parsed, validated sweep file.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The sweep file.
    pub path: PathBuf,
    pub title: Option<String>,
    pub mode: Mode,
    /// Sorted by name.
    pub axes: Vec<Axis>,
    /// The base scene.
    pub base: Scene,
    /// FNV-1a (64 bit) of the strata version, the sweep file, the base scene file and
    /// the content of every file the base scene reads ([`input_files`]).
    pub fingerprint: u64,
    /// The files the base scene reads, hashed into the fingerprint.
    pub inputs: Vec<PathBuf>,
    /// Number of cases.
    pub cases: usize,
}

/// One case: its id, the value of every axis (in axis order) and its scene.
#[derive(Debug, Clone)]
pub struct Case {
    pub id: usize,
    pub values: Vec<Value>,
    pub scene: Scene,
}

/// The files a scene reads besides itself: its stack file, table and surface file.
pub fn input_files(scene: &Scene) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = scene.stack_file.iter().cloned().collect();
    v.extend(scene.table.iter().cloned());
    if let SurfaceSource::File(p) = &scene.surface.source {
        v.push(p.clone());
    }
    v.extend(scene.counterface_file.iter().cloned());
    if let Some(SurfaceSpec {
        source: SurfaceSource::File(p),
        ..
    }) = scene.bodies.counterface.surface()
    {
        v.push(p.clone());
    }
    v
}

fn scalar(v: &Toml, kind: Kind, field: &str) -> Result<Value> {
    let bad = |what: &str| anyhow!("{field}: must be {what}");
    match (kind, v) {
        (Kind::Float, Toml::Float(x)) if x.is_finite() => Ok(Value::Num(*x)),
        (Kind::Float, Toml::Integer(i)) => Ok(Value::Num(*i as f64)),
        (Kind::Float, _) => Err(bad("a finite number")),
        (Kind::Int, Toml::Integer(i)) => Ok(Value::Int(*i)),
        (Kind::Int, _) => Err(bad("an integer")),
        (Kind::Str, Toml::String(s)) => Ok(Value::Str(s.clone())),
        (Kind::Str, _) => Err(bad("a string")),
    }
}

fn range(t: &toml::Table, kind: Kind, field: &str) -> Result<Vec<Value>> {
    for k in t.keys() {
        if !["from", "to", "count", "log"].contains(&k.as_str()) {
            bail!("{field}.{k}: unknown key (a range has from, to, count, log)");
        }
    }
    let count = match t.get("count") {
        Some(Toml::Integer(n)) if (1..=MAX_CASES as i64).contains(n) => *n as usize,
        Some(_) => bail!("{field}.count: must be an integer in [1, {MAX_CASES}]"),
        None => {
            bail!("{field}.count: missing (a range is {{ from, count }} or {{ from, to, count }})")
        }
    };
    let from = t
        .get("from")
        .ok_or_else(|| anyhow!("{field}.from: missing"))?;
    match t.get("to") {
        None => {
            if t.contains_key("log") {
                bail!("{field}.log: needs `to`");
            }
            let Toml::Integer(i) = from else {
                bail!("{field}.from: must be an integer without `to` (from, from+1, …)");
            };
            if kind == Kind::Str {
                bail!("{field}: takes strings, not a range");
            }
            (0..count as i64)
                .map(|k| {
                    let v = i
                        .checked_add(k)
                        .ok_or_else(|| anyhow!("{field}: range overflows"))?;
                    Ok(if kind == Kind::Int {
                        Value::Int(v)
                    } else {
                        Value::Num(v as f64)
                    })
                })
                .collect()
        }
        Some(to) => {
            if kind != Kind::Float {
                bail!("{field}: `to` ranges are for real-valued axes; use {{ from, count }}");
            }
            let a = scalar(from, Kind::Float, &format!("{field}.from"))?.num();
            let b = scalar(to, Kind::Float, &format!("{field}.to"))?.num();
            let log = match t.get("log") {
                None => false,
                Some(Toml::Boolean(l)) => *l,
                Some(_) => bail!("{field}.log: must be true or false"),
            };
            if log && (a <= 0.0 || b <= 0.0) {
                bail!("{field}: a log range needs from > 0 and to > 0");
            }
            Ok((0..count)
                .map(|k| {
                    let u = if count == 1 {
                        0.0
                    } else {
                        k as f64 / (count - 1) as f64
                    };
                    let x = if k == 0 {
                        a
                    } else if k + 1 == count {
                        b
                    } else if log {
                        (a.ln() + (b.ln() - a.ln()) * u).exp()
                    } else {
                        a + (b - a) * u
                    };
                    Value::Num(x)
                })
                .collect())
        }
    }
}

/// Checks one value's domain (independent of the other axes).
fn check_value(param: Param, v: &Value, field: &str) -> Result<()> {
    let x = v.num();
    let need = |ok: bool, what: &str| -> Result<()> {
        if ok {
            Ok(())
        } else {
            Err(anyhow!("{field}: {v} {what}"))
        }
    };
    match param {
        Param::ModulusRatio | Param::BaseYoung | Param::CounterBaseYoung => {
            need(x > 0.0, "must be > 0")
        }
        Param::Layer(_, LayerField::Thickness) | Param::CounterLayer(_, LayerField::Thickness) => {
            need(x > 0.0, "must be > 0 (m)")
        }
        Param::Layer(_, LayerField::Young) | Param::CounterLayer(_, LayerField::Young) => {
            need(x > 0.0, "must be > 0 (Pa)")
        }
        Param::Layer(_, LayerField::Poisson)
        | Param::CounterLayer(_, LayerField::Poisson)
        | Param::BasePoisson
        | Param::CounterBasePoisson => need(x > -1.0 && x <= 0.5, "must be in (−1, 0.5]"),
        Param::Surface(f) => match f {
            SurfaceField::KMin | SurfaceField::KMax => need(x > 0.0, "must be > 0 (units of 2π/L)"),
            SurfaceField::Rms | SurfaceField::Size => need(x > 0.0, "must be > 0 (m)"),
            SurfaceField::FractalDimension => need((2.0..3.0).contains(&x), "must be in [2, 3)"),
            SurfaceField::Grid => need((4.0..=16384.0).contains(&x), "must be in [4, 16384]"),
            SurfaceField::Seed => need(x >= 0.0, "must be ≥ 0"),
        },
        Param::ModelKind => need(
            matches!(v, Value::Str(s) if ["independent", "interacting", "bem"].contains(&s.as_str())),
            "is not one of \"independent\", \"interacting\", \"bem\"",
        ),
        Param::ModelImages => need(
            matches!(v, Value::Str(s) if ["isolated", "periodic"].contains(&s.as_str())),
            "is not one of \"isolated\", \"periodic\"",
        ),
    }
}

/// Flattens `[sweep]` into (dotted name, leaf): a leaf is an array or a range table
/// (a table with a `from` key).
fn flatten<'a>(prefix: &str, t: &'a toml::Table, out: &mut Vec<(String, &'a Toml)>) {
    for (k, v) in t {
        let name = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            Toml::Table(sub) if !sub.contains_key("from") => flatten(&name, sub, out),
            _ => out.push((name, v)),
        }
    }
}

impl Sweep {
    /// Reads and validates a sweep file.
    pub fn from_file(path: &Path) -> Result<Sweep> {
        let text = strata_runtime::resources::read_text_capped(
            path,
            strata_runtime::resources::TEXT_FILE_CAP,
            "a sweep file",
            &MemoryLimit::of_machine(),
        )
        .with_context(|| format!("sweep {}: cannot read it", path.display()))?;
        Sweep::from_str_at(&text, path).with_context(|| format!("sweep {}", path.display()))
    }

    /// Parses a sweep from its text; `path` locates relative paths.
    pub fn from_str_at(text: &str, path: &Path) -> Result<Sweep> {
        let dir = path.parent().unwrap_or(Path::new("."));
        let top: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| anyhow!("sweep file is not valid TOML: {e}"))?;
        for k in top.keys() {
            if !["title", "scene", "sweep"].contains(&k.as_str()) {
                bail!("`{k}`: unknown key (a sweep file has title, scene, sweep)");
            }
        }
        let title = match top.get("title") {
            None => None,
            Some(Toml::String(s)) => Some(s.clone()),
            Some(_) => bail!("title: must be a string"),
        };
        let (base, scene_text) = match top.get("scene") {
            None => bail!("scene: missing (a path to a scene file, or an inline [scene] table)"),
            Some(Toml::String(p)) => {
                let p = dir.join(p);
                let t = strata_runtime::resources::read_text_capped(
                    &p,
                    strata_runtime::resources::TEXT_FILE_CAP,
                    "a scene file",
                    &MemoryLimit::of_machine(),
                )
                .with_context(|| format!("scene: cannot read {}", p.display()))?;
                let s =
                    Scene::from_str_in(&t, p.parent().unwrap_or(Path::new("."))).map_err(|e| {
                        crate::scene::SceneError::InFile {
                            path: p.display().to_string(),
                            error: Box::new(e),
                        }
                    })?;
                (s, t)
            }
            Some(Toml::Table(t)) => {
                let t = toml::to_string(t).context("scene: inline table")?;
                let s = Scene::from_str_in(&t, dir).context("scene (inline)")?;
                (s, String::new())
            }
            Some(_) => bail!("scene: must be a path (string) or a table"),
        };
        let sw = match top.get("sweep") {
            Some(Toml::Table(t)) => t,
            Some(_) => bail!("sweep: must be a table"),
            None => bail!("sweep: missing [sweep] table with at least one axis"),
        };
        let mode = match sw.get("mode") {
            None => Mode::Grid,
            Some(Toml::String(s)) if s == "grid" => Mode::Grid,
            Some(Toml::String(s)) if s == "list" => Mode::List,
            Some(_) => bail!("sweep.mode: must be \"grid\" or \"list\""),
        };
        let mut leaves = Vec::new();
        let mut rest = sw.clone();
        rest.remove("mode");
        flatten("", &rest, &mut leaves);
        if leaves.is_empty() {
            bail!("sweep: no axis given (e.g. surface.seed = {{ from = 1, count = 20 }})");
        }
        let mut axes = Vec::new();
        for (name, leaf) in leaves {
            let field = format!("sweep.{name}");
            let (param, kind) =
                param_of(&name).ok_or_else(|| anyhow!("{field}: unknown axis (known: {KNOWN})"))?;
            let values = match leaf {
                Toml::Array(a) => {
                    if a.is_empty() {
                        bail!("{field}: empty list (give at least one value)");
                    }
                    a.iter()
                        .enumerate()
                        .map(|(i, v)| scalar(v, kind, &format!("{field}[{i}]")))
                        .collect::<Result<Vec<_>>>()?
                }
                Toml::Table(t) => range(t, kind, &field)?,
                _ => bail!("{field}: must be an array of values or a range {{ from, count }}"),
            };
            for (i, v) in values.iter().enumerate() {
                check_value(param, v, &format!("{field}[{i}]"))?;
            }
            axes.push(Axis {
                name,
                param,
                values,
            });
        }
        axes.sort_by(|a, b| a.name.cmp(&b.name));
        let has = |p: Param| axes.iter().any(|a| a.param == p);
        if has(Param::ModulusRatio) && has(Param::Layer(2, LayerField::Young)) {
            bail!(
                "sweep.stack.modulus_ratio: conflicts with sweep.stack.layer2.young (both set E2)"
            );
        }
        let cases = match mode {
            Mode::Grid => axes.iter().try_fold(1usize, |n, a| {
                n.checked_mul(a.values.len())
                    .filter(|n| *n <= MAX_CASES)
                    .ok_or_else(|| anyhow!("sweep: more than {MAX_CASES} cases"))
            })?,
            Mode::List => {
                let n = axes[0].values.len();
                if let Some(a) = axes.iter().find(|a| a.values.len() != n) {
                    bail!(
                        "sweep.{}: has {} values but sweep.{} has {n}: in mode = \"list\" all axes must have the same length",
                        a.name,
                        a.values.len(),
                        axes[0].name
                    );
                }
                n
            }
        };
        let mut hash = Fnv1a::default();
        hash.part(env!("CARGO_PKG_VERSION").as_bytes())
            .part(text.as_bytes())
            .part(scene_text.as_bytes());
        let inputs = input_files(&base);
        for f in &inputs {
            let bytes = strata_runtime::resources::read_data_file(
                f,
                "an input file",
                &MemoryLimit::of_machine(),
            )
            .with_context(|| format!("reading {} for the sweep's fingerprint", f.display()))?;
            hash.part(&bytes);
        }
        let sweep = Sweep {
            path: path.to_path_buf(),
            title,
            mode,
            axes,
            base,
            fingerprint: hash.finish(),
            inputs,
            cases,
        };
        sweep.check_applicable()?;
        Ok(sweep)
    }

    /// Refuses axes the base scene cannot take (surface axes on a surface read from a
    /// file, layer indices beyond the stack, …), on the first case's values.
    fn check_applicable(&self) -> Result<()> {
        for a in &self.axes {
            let field = format!("sweep.{}", a.name);
            match a.param {
                Param::Surface(_)
                    if !matches!(self.base.surface.source, SurfaceSource::Generate(_)) =>
                {
                    bail!(
                        "{field}: the base scene's surface is read from a file; only generated surfaces ([surface.generate]) can be swept"
                    )
                }
                Param::Layer(n, _) if n > self.base.bodies.first.layers().len() => bail!(
                    "{field}: the base scene's stack has {} layer(s)",
                    self.base.bodies.first.layers().len()
                ),
                Param::BaseYoung | Param::BasePoisson
                    if matches!(self.base.bodies.first.base(), Base::Rigid) =>
                {
                    bail!("{field}: the base scene's stack has a rigid base")
                }
                Param::CounterLayer(..) | Param::CounterBaseYoung | Param::CounterBasePoisson
                    if self.base.bodies.counterface.stack().is_none() =>
                {
                    bail!(
                        "{field}: the base scene has no elastic counterface (give a [counterface] stack)"
                    )
                }
                Param::CounterLayer(n, _)
                    if n > self
                        .base
                        .bodies
                        .counterface
                        .stack()
                        .map_or(0, |c| c.layers().len()) =>
                {
                    bail!(
                        "{field}: the base scene's counterface has {} layer(s)",
                        self.base
                            .bodies
                            .counterface
                            .stack()
                            .map_or(0, |c| c.layers().len())
                    )
                }
                Param::CounterBaseYoung | Param::CounterBasePoisson
                    if self
                        .base
                        .bodies
                        .counterface
                        .stack()
                        .is_some_and(|c| matches!(c.base(), Base::Rigid)) =>
                {
                    bail!("{field}: the base scene's counterface has a rigid base")
                }
                Param::ModulusRatio
                    if self.base.bodies.first.layers().len() < 2
                        && !(self.base.bodies.first.layers().len() == 1
                            && matches!(self.base.bodies.first.base(), Base::Elastic { .. })) =>
                {
                    bail!(
                        "{field}: E2/E1 needs a second layer (or one layer on an elastic base) in the base scene's stack"
                    )
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// The axis values of case `id` (< `self.cases`), in axis order.
    pub fn case_values(&self, id: usize) -> Vec<Value> {
        match self.mode {
            Mode::List => self.axes.iter().map(|a| a.values[id].clone()).collect(),
            Mode::Grid => {
                let mut rem = id;
                let mut out = vec![Value::Int(0); self.axes.len()];
                for (k, a) in self.axes.iter().enumerate().rev() {
                    let n = a.values.len();
                    out[k] = a.values[rem % n].clone();
                    rem /= n;
                }
                out
            }
        }
    }

    /// Case `id`: the base scene with the case's values applied and validated. Errors
    /// name the case and the axes involved.
    pub fn case(&self, id: usize) -> Result<Case> {
        let values = self.case_values(id);
        let scene = self
            .apply(&values)
            .with_context(|| format!("case {id} ({})", self.describe(&values)))?;
        Ok(Case { id, values, scene })
    }

    /// `name = value, …` of a case.
    pub fn describe(&self, values: &[Value]) -> String {
        self.axes
            .iter()
            .zip(values)
            .map(|(a, v)| format!("{} = {v}", a.name))
            .collect::<Vec<_>>()
            .join(", ")
    }

    fn apply(&self, values: &[Value]) -> Result<Scene> {
        let mut scene = self.base.clone();
        let stack_swept = self.axes.iter().any(|a| {
            matches!(
                a.param,
                Param::ModulusRatio | Param::Layer(..) | Param::BaseYoung | Param::BasePoisson
            )
        });
        if stack_swept {
            let mut layers = scene.bodies.first.layers().to_vec();
            let mut base = scene.bodies.first.base();
            let mut ratio = None;
            for (a, v) in self.axes.iter().zip(values) {
                let x = v.num();
                match a.param {
                    Param::Layer(n, f) => set_layer(&mut layers[n - 1], f, x),
                    Param::BaseYoung => set_base(&mut base, true, x),
                    Param::BasePoisson => set_base(&mut base, false, x),
                    Param::ModulusRatio => ratio = Some(x),
                    _ => {}
                }
            }
            if let Some(r) = ratio {
                let e1 = layers[0].young;
                if layers.len() >= 2 {
                    layers[1].young = r * e1;
                } else if let Base::Elastic { young, .. } = &mut base {
                    *young = r * e1;
                }
            }
            // (a swept stack loses its name: the name described the base scene's)
            scene.bodies.first = Stack::new(layers, base).context("stack")?;
        }
        let counter_swept = self.axes.iter().any(|a| {
            matches!(
                a.param,
                Param::CounterLayer(..) | Param::CounterBaseYoung | Param::CounterBasePoisson
            )
        });
        if let (true, Counterface::Elastic { stack: c, .. }) =
            (counter_swept, &mut scene.bodies.counterface)
        {
            let mut layers = c.layers().to_vec();
            let mut base = c.base();
            for (a, v) in self.axes.iter().zip(values) {
                let x = v.num();
                match a.param {
                    Param::CounterLayer(n, f) => set_layer(&mut layers[n - 1], f, x),
                    Param::CounterBaseYoung => set_base(&mut base, true, x),
                    Param::CounterBasePoisson => set_base(&mut base, false, x),
                    _ => {}
                }
            }
            *c = Stack::new(layers, base).context("counterface")?;
        }
        for (a, v) in self.axes.iter().zip(values) {
            match a.param {
                Param::Surface(f) => {
                    let SurfaceSource::Generate(g) = &mut scene.surface.source else {
                        bail!("sweep.{}: the surface is not generated", a.name);
                    };
                    let x = v.num();
                    match f {
                        SurfaceField::KMin => g.k_min = x,
                        SurfaceField::KMax => g.k_max = x,
                        SurfaceField::Rms => g.rms = x,
                        SurfaceField::FractalDimension => g.fractal_dimension = x,
                        SurfaceField::Size => {
                            g.size = x;
                            scene.surface.read.spacing =
                                Some(strata_runtime::surface::Spacing::Size(x));
                        }
                        SurfaceField::Grid => g.grid = x as usize,
                        SurfaceField::Seed => g.seed = x as u64,
                    }
                }
                Param::ModelKind => {
                    scene.model.kind = match v {
                        Value::Str(s) if s == "independent" => ModelKind::Independent,
                        Value::Str(s) if s == "interacting" => ModelKind::Interacting,
                        _ => ModelKind::Bem,
                    }
                }
                Param::ModelImages => {
                    scene.model.images = match (v, self.base.model.images) {
                        (Value::Str(s), _) if s == "isolated" => Images::Isolated,
                        (_, Images::Periodic(m)) => Images::Periodic(m),
                        _ => Images::Periodic(2),
                    };
                    if matches!(scene.model.images, Images::Periodic(_))
                        && !scene.surface.read.periodic
                    {
                        bail!("sweep.model.images: \"periodic\" needs a periodic surface");
                    }
                }
                _ => {}
            }
        }
        if let SurfaceSource::Generate(g) = &scene.surface.source {
            if g.k_max < g.k_min {
                bail!(
                    "surface: k_max = {} < k_min = {} (sweep.surface.k_max / k_min)",
                    g.k_max,
                    g.k_min
                );
            }
            if g.k_max > g.grid as f64 / 2.0 {
                bail!(
                    "surface: k_max = {} exceeds grid/2 = {} (sweep.surface.k_max / grid)",
                    g.k_max,
                    g.grid / 2
                );
            }
        }
        if scene.tangential.is_some() {
            bail!(
                "load.tangential: a sweep writes the load curves only (sweep.csv), not a \
                 tangential path; remove [load] tangential from the base scene or solve the \
                 scene with `strata solve`"
            );
        }
        if scene.plasticity.is_some()
            && scene.model.kind != ModelKind::Bem
            && let Some((field, what)) = scene.load.first_reversal()
        {
            bail!(
                "{field}: {what}: a path that unloads is solved by the BEM (model.kind = \"bem\"); \
                 the N and I models follow the loading path only (with [plasticity] too) \
                 (sweep.model.kind)"
            );
        }
        Ok(scene)
    }

    /// The name of the model of a case, for the CSV `model` column.
    pub fn model_name(scene: &Scene) -> &'static str {
        match scene.model.kind {
            ModelKind::Independent => "independent",
            ModelKind::Interacting => "interacting",
            ModelKind::Bem => "bem",
        }
    }

    /// Axes that are CSV columns: all but `model.kind` (that is the `model` column).
    pub fn column_axes(&self) -> impl Iterator<Item = (usize, &Axis)> {
        self.axes
            .iter()
            .enumerate()
            .filter(|(_, a)| a.param != Param::ModelKind)
    }

    /// A rough relative cost of a case (scheduling only: expensive cases start first).
    pub fn cost_hint(case: &Case) -> f64 {
        let (k, n) = match &case.scene.surface.source {
            SurfaceSource::Generate(g) => (g.k_max.max(1.0), g.grid as f64),
            SurfaceSource::File(_) => (10.0, 512.0),
        };
        let surface = (n / 512.0).powi(2);
        let summits = k * k;
        surface
            + match case.scene.model.kind {
                ModelKind::Independent => 0.001 * summits,
                ModelKind::Interacting => match case.scene.model.images {
                    Images::Isolated => 0.005 * summits.powf(1.5),
                    Images::Periodic(m) => 0.005 * summits.powf(1.5) * ((2 * m + 1).pow(2) as f64),
                },
                ModelKind::Bem => 100.0 * surface,
            }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = r#"
[scene.stack]
[[scene.stack.layer]]
thickness = 1e-4
young = 4e9
poisson = 0.15
[[scene.stack.layer]]
thickness = 9e-4
young = 4e9
poisson = 0.15
[scene.stack.base]
kind = "rigid"
[scene.surface]
size = 1e-3
[scene.surface.generate]
grid = 64
fractal_dimension = 2.4
k_min = 2
k_max = 10
rms = 3.4e-6
seed = 1
[scene.model]
kind = "independent"
[scene.load]
approach = { from = 1e-6, to = 4e-6, steps = 3 }
"#;

    fn parse(sweep: &str) -> Result<Sweep> {
        Sweep::from_str_at(&format!("{BASE}\n{sweep}"), Path::new("x/sweep.toml"))
    }

    #[test]
    fn grid_order_is_sorted_mixed_radix() {
        let s = parse(
            "[sweep]\nsurface.seed = { from = 3, count = 2 }\n\"model.kind\" = [\"independent\", \"interacting\"]\nstack.modulus_ratio = [1, 5, 0.5]\n",
        )
        .unwrap();
        let names: Vec<_> = s.axes.iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, ["model.kind", "stack.modulus_ratio", "surface.seed"]);
        assert_eq!(s.cases, 12);
        let v = s.case_values(7); // 7 = 1·6 + 0·2 + 1
        assert_eq!(
            v,
            [
                Value::Str("interacting".into()),
                Value::Num(1.0),
                Value::Int(4)
            ]
        );
        let c = s.case(11).unwrap();
        assert_eq!(c.scene.model.kind, ModelKind::Interacting);
        assert_eq!(c.scene.bodies.first.layers()[1].young, 0.5 * 4e9);
        let SurfaceSource::Generate(g) = c.scene.surface.source else {
            panic!()
        };
        assert_eq!(g.seed, 4);
    }

    #[test]
    fn list_mode_zips_and_ranges_expand() {
        let s = parse(
            "[sweep]\nmode = \"list\"\nsurface.rms = { from = 1e-6, to = 4e-6, count = 4 }\nsurface.k_max = [4, 5, 6, 8]\n",
        )
        .unwrap();
        assert_eq!(s.cases, 4);
        assert_eq!(s.case_values(2), [Value::Num(6.0), Value::Num(3e-6)]);
        let s = parse("[sweep]\nsurface.rms = { from = 1e-6, to = 1e-4, count = 3, log = true }\n")
            .unwrap();
        let Value::Num(mid) = s.axes[0].values[1] else {
            panic!()
        };
        assert!((mid / 1e-5 - 1.0).abs() < 1e-12);
        assert!(
            parse("[sweep]\nmode = \"list\"\nsurface.k_max = [4, 5]\nsurface.seed = [1]\n")
                .unwrap_err()
                .to_string()
                .contains("same length")
        );
    }

    #[test]
    fn bad_sweeps_name_the_field() {
        let e = |s: &str| format!("{:#}", parse(s).unwrap_err());
        assert!(e("[sweep]\nsurface.colour = [1]\n").contains("sweep.surface.colour"));
        assert!(e("[sweep]\nsurface.k_max = []\n").contains("sweep.surface.k_max: empty"));
        assert!(e("[sweep]\nsurface.seed = [1.5]\n").contains("sweep.surface.seed[0]"));
        assert!(e("[sweep]\nsurface.rms = [1e-6, -1]\n").contains("sweep.surface.rms[1]"));
        assert!(e("[sweep]\nmodel.kind = [\"magic\"]\n").contains("sweep.model.kind[0]"));
        assert!(e("[sweep]\nstack.layer3.young = [1e9]\n").contains("sweep.stack.layer3.young"));
        assert!(e("[sweep]\nsurface.seed = { from = 1 }\n").contains("sweep.surface.seed.count"));
        assert!(e("[sweep]\n").contains("no axis"));
        assert!(e("[sweep]\nmode = \"zip\"\nsurface.seed = [1]\n").contains("sweep.mode"));
        let top = Sweep::from_str_at(
            &format!("colour = 1\n{BASE}\n[sweep]\nsurface.seed = [1]\n"),
            Path::new("x/sweep.toml"),
        );
        assert!(top.unwrap_err().to_string().contains("`colour`"));
        let k = parse("[sweep]\nsurface.k_max = [10, 40]\n").unwrap();
        let ce = format!("{:#}", k.case(1).unwrap_err());
        assert!(ce.contains("case 1") && ce.contains("grid/2"), "{ce}");
    }
}
