//! The stack file format as serde types (`deny_unknown_fields`): [`StackFile`] (`name`,
//! `[[layer]]`, `[base]`, `[counterface]`) and [`CounterfaceFile`], the one reader of a
//! `[counterface]` table, in stack files and in scenes alike. Deserializing checks the
//! keys and their types; [`StackFile::bodies`] and [`CounterfaceFile::elastic_body`]
//! validate the values. Errors name the field and the layer ([`StackError`]); a serde
//! error is turned into one by [`StackError::from_serde`] from its dotted path
//! (`layer[1].young`, `counterface.base.kind`).

use serde::de::IgnoredAny;
use serde::{Deserialize, Serialize};

use super::{
    Base, BaseConduction, Bodies, Conductivity, Counterface, Layer, Location, Stack, StackError,
    check_poisson, check_thickness, check_young,
};

/// One `[[layer]]` table (SI units). Every field is optional here so that a missing one
/// is named with its layer ([`StackError::Missing`]).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table ([[layer]])")]
pub struct LayerFile {
    /// Thickness h (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// Young modulus E (Pa).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub young: Option<f64>,
    /// Poisson ratio ν.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson: Option<f64>,
    /// Thermal conductivity k (W/(m·K)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal_conductivity: Option<f64>,
    /// Electrical conductivity σ (S/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub electrical_conductivity: Option<f64>,
}

/// The `[base]` table: `kind = "rigid"` or `"elastic"` (with `young`, `poisson`), and
/// optionally `conduction = "isothermal" | "half-space"` and the conductivities.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table ([base])")]
pub struct BaseFile {
    /// "rigid" or "elastic".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<String>,
    /// Young modulus E (Pa) of an elastic base.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub young: Option<f64>,
    /// Poisson ratio ν of an elastic base.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson: Option<f64>,
    /// "isothermal" or "half-space" (the default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub conduction: Option<String>,
    /// Thermal conductivity k (W/(m·K)) of a conducting base.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal_conductivity: Option<f64>,
    /// Electrical conductivity σ (S/m) of a conducting base.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub electrical_conductivity: Option<f64>,
}

/// A stack file: one body (`name`, `[[layer]]`, `[base]`) and an optional elastic
/// `[counterface]` (a stack of the same keys).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table (a stack)")]
pub struct StackFile {
    /// Optional human-readable name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The layers, top first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layer: Option<Vec<LayerFile>>,
    /// What lies below the last layer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<BaseFile>,
    /// The elastic counterface.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub counterface: Option<CounterfaceFile<SceneOnly>>,
}

/// How a rigid counterface conducts (`counterface.conduction`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CounterfaceConductionFile {
    /// A perfect conductor.
    Perfect,
    /// A rigid flat as a conducting half-space of the given conductivity.
    HalfSpace,
}

/// `counterface.kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CounterfaceKindFile {
    /// A rigid flat (the default without stack keys).
    Rigid,
    /// An elastic stack (the default with stack keys).
    Elastic,
}

/// A `[counterface]` table: the one reader of it, in stack files (`S` = [`SceneOnly`]:
/// only the stack keys `name`, `[[counterface.layer]]`, `[counterface.base]`) and in
/// scenes (`S` the scene's surface table; also `kind`, `file`, `table`, `surface`,
/// `conduction` and a rigid flat's conductivities).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table ([counterface])",
    bound(serialize = "S: Serialize", deserialize = "S: Deserialize<'de>")
)]
pub struct CounterfaceFile<S> {
    /// "rigid" or "elastic".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<CounterfaceKindFile>,
    /// A stack file of the elastic counterface (scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// A table built for the pair (scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<String>,
    /// The elastic counterface's name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The elastic counterface's layers, top (the contact surface) first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layer: Option<Vec<LayerFile>>,
    /// The elastic counterface's base.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<BaseFile>,
    /// The counterface's rough surface (scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<S>,
    /// "perfect" or "half-space" (scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub conduction: Option<CounterfaceConductionFile>,
    /// A rigid flat's thermal conductivity (W/(m·K); scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal_conductivity: Option<f64>,
    /// A rigid flat's electrical conductivity (S/m; scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub electrical_conductivity: Option<f64>,
    /// Read only to be refused with a clear message: two bodies touch, a counterface
    /// has no counterface.
    #[serde(default, skip_serializing)]
    pub counterface: Option<IgnoredAny>,
}

impl<S> Default for CounterfaceFile<S> {
    fn default() -> Self {
        CounterfaceFile {
            kind: None,
            file: None,
            table: None,
            name: None,
            layer: None,
            base: None,
            surface: None,
            conduction: None,
            thermal_conductivity: None,
            electrical_conductivity: None,
            counterface: None,
        }
    }
}

/// The `surface` of a stack file's `[counterface]`: read only to be refused (a rough
/// counterface belongs to a scene).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SceneOnly;

impl<'de> Deserialize<'de> for SceneOnly {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        IgnoredAny::deserialize(d)?;
        Ok(SceneOnly)
    }
}

impl LayerFile {
    /// The layer of a stack, and its conductivities.
    pub fn of(stack: &Stack, i: usize) -> LayerFile {
        let l = stack.layers()[i];
        let c = stack.layer_conductivity(i);
        LayerFile {
            thickness: Some(l.thickness),
            young: Some(l.young),
            poisson: Some(l.poisson),
            thermal_conductivity: c.thermal,
            electrical_conductivity: c.electrical,
        }
    }

    fn read(&self, location: Location) -> Result<(Layer, Conductivity), StackError> {
        let get =
            |v: Option<f64>, field: &'static str| v.ok_or(StackError::Missing { location, field });
        let thickness = get(self.thickness, "thickness")?;
        check_thickness(location, thickness)?;
        let young = get(self.young, "young")?;
        check_young(location, young)?;
        let poisson = get(self.poisson, "poisson")?;
        check_poisson(location, poisson)?;
        Ok((
            Layer {
                thickness,
                young,
                poisson,
            },
            Conductivity {
                thermal: self.thermal_conductivity,
                electrical: self.electrical_conductivity,
            },
        ))
    }
}

impl BaseFile {
    /// The base of a stack, its conductivities and conduction kind.
    pub fn of(stack: &Stack) -> BaseFile {
        let (kind, young, poisson) = match stack.base() {
            Base::Rigid => ("rigid", None, None),
            Base::Elastic { young, poisson } => ("elastic", Some(young), Some(poisson)),
        };
        let c = stack.conduction();
        BaseFile {
            kind: Some(kind.into()),
            young,
            poisson,
            conduction: (c.base_kind == BaseConduction::Isothermal).then(|| "isothermal".into()),
            thermal_conductivity: c.base.thermal,
            electrical_conductivity: c.base.electrical,
        }
    }

    fn read(&self) -> Result<(Base, Conductivity, BaseConduction), StackError> {
        let loc = Location::Base;
        let kind = self.kind.as_deref().ok_or(StackError::Missing {
            location: loc,
            field: "kind",
        })?;
        let base = match kind {
            "rigid" => {
                for (key, given) in [("young", self.young), ("poisson", self.poisson)] {
                    if given.is_some() {
                        return Err(StackError::UnknownKey {
                            location: loc,
                            key: key.into(),
                            expected: "kind (a rigid base has no elastic properties), conduction, \
                                       thermal_conductivity, electrical_conductivity"
                                .into(),
                        });
                    }
                }
                Base::Rigid
            }
            "elastic" => {
                let get = |v: Option<f64>, field: &'static str| {
                    v.ok_or(StackError::Missing {
                        location: loc,
                        field,
                    })
                };
                let young = get(self.young, "young")?;
                check_young(loc, young)?;
                let poisson = get(self.poisson, "poisson")?;
                check_poisson(loc, poisson)?;
                Base::Elastic { young, poisson }
            }
            other => return Err(StackError::UnknownBaseKind(other.to_string())),
        };
        let kind = match self.conduction.as_deref() {
            None | Some("half-space") => BaseConduction::HalfSpace,
            Some("isothermal") => BaseConduction::Isothermal,
            Some(other) => return Err(StackError::UnknownBaseConduction(other.to_string())),
        };
        let cond = Conductivity {
            thermal: self.thermal_conductivity,
            electrical: self.electrical_conductivity,
        };
        Ok((base, cond, kind))
    }
}

/// One body from its `name`, `[[layer]]` and `[base]`: the validation shared by a stack
/// file and a `[counterface]`.
fn body(
    name: &Option<String>,
    layer: &Option<Vec<LayerFile>>,
    base: &Option<BaseFile>,
) -> Result<Stack, StackError> {
    let mut layers = Vec::new();
    let mut layer_cond = Vec::new();
    for (i, l) in layer.iter().flatten().enumerate() {
        let (l, c) = l.read(Location::Layer(i + 1))?;
        super::check_conductivities(Location::Layer(i + 1), &c)?;
        layers.push(l);
        layer_cond.push(c);
    }
    let Some(base) = base else {
        if layers.is_empty() {
            return Err(StackError::Empty);
        }
        return Err(StackError::Missing {
            location: Location::Top,
            field: "base",
        });
    };
    let (base, base_cond, base_kind) = base.read()?;
    let mut stack = Stack::new(layers, base)?;
    stack.name = name.clone();
    if base_kind != BaseConduction::HalfSpace
        || !base_cond.is_empty()
        || layer_cond.iter().any(|c| !c.is_empty())
    {
        stack = stack.with_conduction(layer_cond, base_cond, base_kind)?;
    }
    Ok(stack)
}

/// The file form of one body (no counterface).
fn body_file(stack: &Stack) -> (Option<String>, Option<Vec<LayerFile>>, BaseFile) {
    let layers: Vec<LayerFile> = (0..stack.layers().len())
        .map(|i| LayerFile::of(stack, i))
        .collect();
    (
        stack.name.clone(),
        (!layers.is_empty()).then_some(layers),
        BaseFile::of(stack),
    )
}

impl StackFile {
    /// Validates the file into its [`Bodies`]: the first body and its elastic
    /// `[counterface]` (a rigid flat without one).
    pub fn bodies(&self) -> Result<Bodies, StackError> {
        let first = body(&self.name, &self.layer, &self.base)?;
        let counterface = match &self.counterface {
            None => Counterface::default(),
            Some(c) => Counterface::elastic(
                c.stack_file_body()
                    .map_err(|e| StackError::Counterface(Box::new(e)))?,
            ),
        };
        Ok(Bodies { first, counterface })
    }

    /// The file form of `bodies` (what [`StackFile::bodies`] reads back to `bodies`;
    /// a rigid flat's conduction is not part of a stack file).
    pub fn of<S>(bodies: &Bodies<S>) -> StackFile {
        let (name, layer, base) = body_file(&bodies.first);
        StackFile {
            name,
            layer,
            base: Some(base),
            counterface: bodies.counterface.stack().map(CounterfaceFile::of),
        }
    }
}

impl<S> CounterfaceFile<S> {
    /// The elastic counterface `stack` as a `[counterface]` table.
    pub fn of(stack: &Stack) -> CounterfaceFile<S> {
        let (name, layer, base) = body_file(stack);
        CounterfaceFile {
            name,
            layer,
            base: Some(base),
            ..Default::default()
        }
    }

    /// True when the table gives stack keys (`file`, `name`, `layer`, `base`): an
    /// elastic counterface unless `kind = "rigid"` says otherwise.
    pub fn has_stack(&self) -> bool {
        self.file.is_some() || self.name.is_some() || self.layer.is_some() || self.base.is_some()
    }

    /// True when the table gives inline stack keys (`[[counterface.layer]]`,
    /// `[counterface.base]`).
    pub fn has_inline_stack(&self) -> bool {
        self.layer.is_some() || self.base.is_some()
    }

    /// The elastic counterface given inline (`name`, `[[counterface.layer]]`,
    /// `[counterface.base]`); a `[counterface.counterface]` is refused
    /// ([`StackError::NestedCounterface`]).
    pub fn elastic_body(&self) -> Result<Stack, StackError> {
        if self.counterface.is_some() {
            return Err(StackError::NestedCounterface);
        }
        body(&self.name, &self.layer, &self.base)
    }

    /// A stack file's `[counterface]`: a stack only (the scene keys refused).
    fn stack_file_body(&self) -> Result<Stack, StackError> {
        let scene_keys = [
            ("kind", self.kind.is_some()),
            ("file", self.file.is_some()),
            ("table", self.table.is_some()),
            ("surface", self.surface.is_some()),
            ("conduction", self.conduction.is_some()),
            ("thermal_conductivity", self.thermal_conductivity.is_some()),
            (
                "electrical_conductivity",
                self.electrical_conductivity.is_some(),
            ),
        ];
        if let Some((key, _)) = scene_keys.iter().find(|(_, given)| *given) {
            return Err(StackError::UnknownKey {
                location: Location::Top,
                key: (*key).into(),
                expected: "name, layer, base (a stack file's [counterface] is a stack; \
                           `kind`, `file`, `table`, `surface`, `conduction` and a rigid \
                           flat's conductivities belong to a scene's [counterface])"
                    .into(),
            });
        }
        self.elastic_body()
    }
}

/// What a serde error message says, in the terms of strata's messages.
#[derive(Debug, Clone, PartialEq)]
pub enum SerdeProblem {
    /// A key the table does not have; `expected` lists the keys it has.
    UnknownKey { key: String, expected: String },
    /// A required key absent.
    Missing(String),
    /// A value of the wrong type: what was expected and what was found.
    WrongType { expected: String, found: String },
    /// A name outside a set: the value and the allowed names, quoted (`"a", "b"`).
    UnknownName { value: String, allowed: String },
    /// Anything else, as the deserializer says it.
    Other(String),
}

/// The backticked words of `s`, in order.
fn backticked(s: &str) -> Vec<&str> {
    s.split('`').skip(1).step_by(2).collect()
}

/// Reads a serde error message (serde's derive wording, as `toml` and `serde_json`
/// pass it on) into a [`SerdeProblem`]; serde's type names become the user's words
/// (`f64` → "a number", `i64` → "an integer", a struct → "a table").
pub fn serde_problem(message: &str) -> SerdeProblem {
    let message = message.trim();
    if let Some(rest) = message.strip_prefix("unknown field ") {
        let words = backticked(rest);
        return SerdeProblem::UnknownKey {
            key: words.first().copied().unwrap_or_default().to_string(),
            expected: words.get(1..).unwrap_or_default().join(", "),
        };
    }
    if let Some(rest) = message.strip_prefix("missing field ") {
        let words = backticked(rest);
        return SerdeProblem::Missing(words.first().copied().unwrap_or_default().to_string());
    }
    if let Some(rest) = message.strip_prefix("unknown variant ") {
        let words = backticked(rest);
        return SerdeProblem::UnknownName {
            value: words.first().copied().unwrap_or_default().to_string(),
            allowed: words
                .get(1..)
                .unwrap_or_default()
                .iter()
                .map(|w| format!("\"{w}\""))
                .collect::<Vec<_>>()
                .join(", "),
        };
    }
    for prefix in ["invalid type: ", "invalid length ", "invalid value: "] {
        if let Some(rest) = message.strip_prefix(prefix)
            && let Some((found, expected)) = rest.rsplit_once(", expected ")
        {
            return SerdeProblem::WrongType {
                expected: user_type(expected),
                found: found.to_string(),
            };
        }
    }
    SerdeProblem::Other(message.to_string())
}

/// serde's name of an expected type in the user's words.
fn user_type(expected: &str) -> String {
    match expected {
        "f64" | "f32" => "a number".into(),
        "i64" | "u64" | "i32" | "u32" | "usize" | "isize" => "an integer".into(),
        "a boolean" => "true or false".into(),
        "a sequence" => "an array".into(),
        "a map" => "a table".into(),
        e if e.starts_with("struct ") => "a table".into(),
        e => e.to_string(),
    }
}

impl StackError {
    /// The error of a stack file's serde error at `path` (dotted, e.g. `layer[1].young`,
    /// `counterface.base.kind`, or `.` for the top) with serde's `message`.
    pub fn from_serde(path: &str, message: &str) -> StackError {
        let path = path.trim_start_matches('.');
        if let Some(rest) = path.strip_prefix("counterface.") {
            return StackError::Counterface(Box::new(StackError::from_serde(rest, message)));
        }
        // (location, the field within it: empty for the location itself)
        let (location, field) = if let Some(rest) = path.strip_prefix("layer[") {
            let (i, after) = rest.split_once(']').unwrap_or((rest, ""));
            let i = i.parse::<usize>().map_or(0, |i| i + 1);
            (Location::Layer(i), after.trim_start_matches('.'))
        } else if let Some(rest) = path.strip_prefix("base.") {
            (Location::Base, rest)
        } else {
            (Location::Top, path)
        };
        match serde_problem(message) {
            SerdeProblem::UnknownKey { key, expected } => StackError::UnknownKey {
                location,
                key,
                expected,
            },
            SerdeProblem::WrongType { expected, found } => StackError::WrongType {
                location,
                field: if field.is_empty() {
                    "layer".into()
                } else {
                    field.to_string()
                },
                expected,
                found,
            },
            SerdeProblem::UnknownName { value, .. } => StackError::UnknownBaseKind(value),
            SerdeProblem::Missing(_) | SerdeProblem::Other(_) => {
                StackError::Syntax(format!("{path}: {message}"))
            }
        }
    }
}
