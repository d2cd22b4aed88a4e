//! The scene file format as serde types (`deny_unknown_fields`): what a scene file (or a
//! dict from Python) says, before validation. Deserializing checks the keys and their
//! types; [`SceneFile::validate`](super::Scene) checks the values and resolves paths.
//! A serde error becomes a [`SceneError`] naming the dotted field ([`serde_error`]).

use std::fmt;

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};

use strata_runtime::stack::{
    BaseFile, CounterfaceFile, LayerFile, SerdeProblem, StackError, serde_problem,
};

use super::error::SceneError;

/// A whole scene file.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table (a scene)")]
pub struct SceneFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stack: Option<StackSection>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<SurfaceFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<ModelFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load: Option<LoadFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output: Option<OutputFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solver: Option<SolverFile>,
    /// `[counterface]`: the reader shared with stack files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub counterface: Option<CounterfaceFile<SurfaceFile>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plasticity: Option<PlasticityFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub conductance: Option<ConductanceFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionFile>,
}

/// `[stack]`: a stack `file` or an inline stack (`name`, `[[stack.layer]]`,
/// `[stack.base]`), and an optional `table`. A scene gives its counterface in
/// `[counterface]`, not inside `[stack]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct StackSection {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layer: Option<Vec<LayerFile>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<BaseFile>,
}

/// `[surface]` (and `[counterface.surface]`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct SurfaceFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<Lengths>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pixel_size: Option<Lengths>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub periodic: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generate: Option<GenerateFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repair: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detrend: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_unit: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub topography: Option<TopographyPick>,
}

/// `[surface.generate]`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct GenerateFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<i64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fractal_dimension: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k_min: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k_max: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<i64>,
}

/// A length (m) or a pair `[x, y]` of lengths (m).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Lengths {
    One(f64),
    Two([f64; 2]),
}

impl<'de> Deserialize<'de> for Lengths {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Lengths;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a length (m) or an array [x, y] of two lengths (m)")
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<Lengths, E> {
                Ok(Lengths::One(x))
            }
            fn visit_i64<E: de::Error>(self, x: i64) -> Result<Lengths, E> {
                Ok(Lengths::One(x as f64))
            }
            fn visit_u64<E: de::Error>(self, x: u64) -> Result<Lengths, E> {
                Ok(Lengths::One(x as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<Lengths, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = a.next_element::<f64>()? {
                    v.push(x);
                }
                match v[..] {
                    [x, y] => Ok(Lengths::Two([x, y])),
                    _ => Err(de::Error::invalid_length(v.len(), &self)),
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// `surface.topography`: a number from 0, or a name.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum TopographyPick {
    Index(i64),
    Name(String),
}

impl<'de> Deserialize<'de> for TopographyPick {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = TopographyPick;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a topography number (0, 1, ... across the container's surfaces) or a \
                     topography name",
                )
            }
            fn visit_i64<E: de::Error>(self, x: i64) -> Result<TopographyPick, E> {
                Ok(TopographyPick::Index(x))
            }
            fn visit_u64<E: de::Error>(self, x: u64) -> Result<TopographyPick, E> {
                Ok(TopographyPick::Index(i64::try_from(x).unwrap_or(i64::MAX)))
            }
            fn visit_str<E: de::Error>(self, x: &str) -> Result<TopographyPick, E> {
                Ok(TopographyPick::Name(x.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

/// `model.kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ModelKindFile {
    Independent,
    Interacting,
    Bem,
}

/// `model.images`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ImagesFile {
    Periodic,
    Isolated,
}

/// `[model]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct ModelFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<ModelKindFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub images: Option<ImagesFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image_cells: Option<i64>,
}

/// `[load]`: exactly one of `separations`, `approach`, `mean_pressures`; `unload`;
/// `tangential`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct LoadFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub separations: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub approach: Option<ApproachFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_pressures: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unload: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential: Option<ApproachFile>,
}

/// `load.approach = { from, to, steps }` (and `load.tangential`, the same shape).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct ApproachFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub to: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<i64>,
}

/// `output.maps`: "none" | "last" | "all", or true ("all") / false ("none").
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(untagged)]
pub enum MapsFile {
    Flag(bool),
    Name(String),
}

impl<'de> Deserialize<'de> for MapsFile {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = MapsFile;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"none\", \"last\", \"all\", true or false")
            }
            fn visit_bool<E: de::Error>(self, x: bool) -> Result<MapsFile, E> {
                Ok(MapsFile::Flag(x))
            }
            fn visit_str<E: de::Error>(self, x: &str) -> Result<MapsFile, E> {
                Ok(MapsFile::Name(x.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

/// `output.format`: a name or an array of names.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct FormatsFile(pub Vec<String>);

impl<'de> Deserialize<'de> for FormatsFile {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = FormatsFile;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"npy\", \"netcdf\" or an array of them")
            }
            fn visit_str<E: de::Error>(self, x: &str) -> Result<FormatsFile, E> {
                Ok(FormatsFile(vec![x.to_string()]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<FormatsFile, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = a.next_element::<Name>()? {
                    v.push(x.0);
                }
                Ok(FormatsFile(v))
            }
        }
        d.deserialize_any(V)
    }
}

/// One format name inside `output.format`.
struct Name(String);

impl<'de> Deserialize<'de> for Name {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Name;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"npy\", \"netcdf\" or an array of them")
            }
            fn visit_str<E: de::Error>(self, x: &str) -> Result<Name, E> {
                Ok(Name(x.to_string()))
            }
        }
        d.deserialize_str(V)
    }
}

/// `[output]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct OutputFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub maps: Option<MapsFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<FormatsFile>,
}

/// `[solver]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct SolverFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_step_newton_steps: Option<i64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_step_evaluations: Option<i64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kkt_tolerance: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_pressure_iterations: Option<i64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bem_max_iterations: Option<i64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bem_tolerance: Option<f64>,
}

/// `[plasticity]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct PlasticityFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hardness: Option<f64>,
}

/// `[friction]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct FrictionFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coefficient: Option<f64>,
}

/// `conductance.kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ConductionKindFile {
    Thermal,
    Electrical,
}

/// `[conductance]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub struct ConductanceFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<ConductionKindFile>,
}

/// The [`SceneError`] of a serde error at the dotted `path` (`model.colour`,
/// `load.separations[1]`, `stack.layer[0].young`, `counterface.surface.size`) with
/// serde's `message`: inside a stack (`stack.layer`, `counterface.base`, …) the stack's
/// own wording ([`StackError::from_serde`]), elsewhere the field and what it must be.
pub fn serde_error(path: &str, message: &str) -> SceneError {
    let path = path.trim_start_matches('.');
    let in_stack = |rest: &str| {
        rest.starts_with("layer")
            || rest.starts_with("base.")
            || rest.starts_with("counterface.")
            || rest == "base"
    };
    if let Some(rest) = path.strip_prefix("stack.")
        && in_stack(rest)
    {
        return SceneError::Stack(StackError::from_serde(rest, message));
    }
    if let Some(rest) = path.strip_prefix("counterface.")
        && in_stack(rest)
    {
        return SceneError::Invalid {
            field: "counterface".into(),
            reason: StackError::from_serde(rest, message).to_string(),
        };
    }
    match serde_problem(message) {
        SerdeProblem::UnknownKey { key, expected } => SceneError::UnknownKey {
            key: if path.is_empty() {
                key
            } else {
                path.to_string()
            },
            expected,
        },
        SerdeProblem::Missing(f) => SceneError::Missing(format!("{path}.{f}")),
        SerdeProblem::WrongType { expected, .. } => SceneError::WrongType {
            field: path.to_string(),
            expected,
        },
        SerdeProblem::UnknownName { value, allowed } => SceneError::Invalid {
            field: path.to_string(),
            reason: format!("`{value}` is not one of {allowed}"),
        },
        SerdeProblem::Other(m) => SceneError::Invalid {
            field: path.to_string(),
            reason: m,
        },
    }
}
