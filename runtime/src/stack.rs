//! Material stacks: N bonded elastic layers on an elastic half-space or a rigid base.
//!
//! A stack is read from TOML (SI units):
//!
//! ```toml
//! name = "coating on steel"
//! [[layer]]
//! thickness = 100e-6   # m
//! young = 4e9          # Pa
//! poisson = 0.15       # -
//! [base]
//! kind = "rigid"       # or kind = "elastic" with young and poisson
//! ```
//!
//! A stack is one body. It may be pressed against a second elastic body, the
//! **counterface** ([`Bodies`], a `[counterface]` table of the same keys in a stack or
//! scene file; physics.md §6.1). Frictionless normal displacements of the two bodies
//! add, so every mechanical property the models read — S(ρ) ([`crate::Compliance`]),
//! the contact modulus E* ([`Solid::contact_modulus`]), the length scales, homogeneity
//! — is then that of the pair ([`Solid`]). A lone stack is pressed by a rigid smooth
//! flat; it has no counterface field, so a counterface's counterface cannot be written.
//!
//! Conduction (optional, physics.md §6.2): any `[[layer]]` and the `[base]` may give
//! `thermal_conductivity` (W/(m·K)) and `electrical_conductivity` (S/m); the base is
//! then a conducting half-space. `[base] conduction = "isothermal"` makes the bottom of
//! the last layer an isothermal (equipotential) sink instead, the usual case under a
//! rigid base. Stacks without these fields read, write and compute exactly as before;
//! see [`crate::conduction`].
//!
//! Layer 1 is the top layer (the contact surface). Validation names the offending
//! field and the layer index (1-based, as a user counts them). Poisson ratios are
//! accepted in (−1, 0.5]: ν = 0.5 is an exactly incompressible material, which the
//! transfer-matrix formulation handles without special cases (all its coefficients,
//! 1−2ν, 3−4ν, 1−ν, stay finite); E* = E/(1−ν²) stays finite too.

use std::fmt;
#[cfg(feature = "toml")]
use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

mod bodies;
mod file;
pub use bodies::{Bodies, Counterface, NoSurface, RigidConduction, Solid};
pub use file::{
    BaseFile, CounterfaceConductionFile, CounterfaceFile, CounterfaceKindFile, LayerFile,
    SceneOnly, SerdeProblem, StackFile, serde_problem,
};

/// One elastic layer (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Layer {
    /// Thickness h (m), > 0.
    pub thickness: f64,
    /// Young modulus E (Pa), > 0.
    pub young: f64,
    /// Poisson ratio ν, in (−1, 0.5].
    pub poisson: f64,
}

/// What lies below the last layer.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Base {
    /// The last layer is bonded to a rigid base (zero displacement).
    Rigid,
    /// An elastic half-space with Young modulus `young` (Pa) and Poisson ratio `poisson`.
    Elastic { young: f64, poisson: f64 },
}

/// Conductivities of one layer or of a conducting base (SI units); `None` where the
/// stack does not give one (physics.md §6.2).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Conductivity {
    /// Thermal conductivity k (W/(m·K)), > 0.
    pub thermal: Option<f64>,
    /// Electrical conductivity σ (S/m), > 0.
    pub electrical: Option<f64>,
}

impl Conductivity {
    /// A thermal conductivity `k` (W/(m·K)) alone.
    pub fn thermal(k: f64) -> Conductivity {
        Conductivity {
            thermal: Some(k),
            electrical: None,
        }
    }

    /// True when neither conductivity is given.
    pub fn is_empty(&self) -> bool {
        self.thermal.is_none() && self.electrical.is_none()
    }
}

/// How heat (or current) leaves through the bottom of the stack (physics.md §6.2).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum BaseConduction {
    /// The base is a conducting half-space of the base's conductivities
    /// ([`StackConduction::base`]; the default).
    #[default]
    HalfSpace,
    /// An isothermal (equipotential) sink at the bottom of the last layer
    /// (`[base] conduction = "isothermal"`).
    Isothermal,
}

/// The conduction properties of a stack: per layer (top first) and of the base.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct StackConduction {
    /// One entry per layer, top first (all empty when the stack gives none).
    pub layers: Vec<Conductivity>,
    /// The base's conductivities (a conducting half-space); empty for an isothermal base.
    pub base: Conductivity,
    /// Conducting half-space or isothermal sink below the last layer.
    pub base_kind: BaseConduction,
}

/// A validated material stack. Construct with [`Stack::new`] or [`Stack::from_toml_str`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Stack {
    /// Optional human-readable name.
    pub name: Option<String>,
    layers: Vec<Layer>,
    base: Base,
    /// Conduction properties. Not part of a table file's binary header
    /// (`serde(skip)`: tables stay byte-identical and loadable); empty unless given.
    #[serde(skip)]
    conduction: StackConduction,
}

/// Errors from reading or validating a stack. Each names the field, and the layer
/// (1-based) where one is concerned.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum StackError {
    #[error("cannot read stack file {path}: {message}")]
    Io { path: String, message: String },
    #[error("stack is not valid TOML: {0}")]
    Syntax(String),
    #[error("{location}: missing field `{field}`")]
    Missing {
        location: Location,
        field: &'static str,
    },
    #[error("{location}: unknown key `{key}` (expected one of: {expected})")]
    UnknownKey {
        location: Location,
        key: String,
        expected: String,
    },
    #[error("{location}: field `{field}` must be {expected}, found {found}")]
    WrongType {
        location: Location,
        field: String,
        expected: String,
        found: String,
    },
    #[error("{location}: field `{field}` = {value:?} is invalid: {reason}")]
    Invalid {
        location: Location,
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error("base: unknown kind `{0}` (expected \"rigid\" or \"elastic\")")]
    UnknownBaseKind(String),
    #[error("stack has no layers: a rigid base needs at least one layer on top")]
    NoLayersOnRigid,
    #[error("stack has no layers and no base: give [[layer]] tables and/or an elastic [base]")]
    Empty,
    /// An error of the `[counterface]` of a stack.
    #[error("counterface: {0}")]
    Counterface(Box<StackError>),
    /// A counterface that has a counterface itself.
    #[error("a counterface cannot have its own counterface (two bodies touch)")]
    NestedCounterface,
    /// A `[counterface]` where one body is expected ([`Stack::from_toml_str`]; read the
    /// pair with [`Bodies::from_toml_str`]).
    #[error("the stack gives a [counterface] (two bodies) where one body is expected")]
    TwoBodies,
    /// An error in a stack file, with the file's path.
    #[error("stack file {path}: {error}")]
    InFile {
        path: String,
        error: Box<StackError>,
    },
    /// `[base] conduction` is neither "isothermal" nor "half-space".
    #[error("base: unknown conduction `{0}` (expected \"isothermal\" or \"half-space\")")]
    UnknownBaseConduction(String),
    /// An isothermal base given a conductivity.
    #[error(
        "base: field `{field}` is not allowed with conduction = \"isothermal\" (an isothermal sink has no conductivity)"
    )]
    IsothermalWithConductivity { field: &'static str },
    /// An isothermal base under no layer.
    #[error("base: conduction = \"isothermal\" needs at least one layer on top")]
    NoLayersOnIsothermal,
    /// [`Stack::with_conduction`] got another number of entries than layers.
    #[error("conduction properties for {given} layers given to a stack of {layers} layers")]
    ConductionLayers { layers: usize, given: usize },
}

/// Admissible Young moduli (Pa), inclusive: from far below the softest gels to far
/// above diamond (1.2e12 Pa). Outside this range the transfer-matrix products of
/// S(ρ) (`compliance`) over- or underflow in f64 for common neighbours (E₁ = 1e-300 Pa
/// on a 1e9 Pa base gives NaN), so every command refuses such stacks alike.
pub const YOUNG_RANGE: (f64, f64) = (1e-3, 1e15);

/// Where in the stack file an error is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// The top level of the file.
    Top,
    /// `[[layer]]` number i (1-based).
    Layer(usize),
    /// The `[base]` table.
    Base,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Top => write!(f, "stack"),
            Location::Layer(i) => write!(f, "layer {i}"),
            Location::Base => write!(f, "base"),
        }
    }
}

/// Plane-strain modulus E* = E/(1−ν²) (Pa).
pub fn plane_strain_modulus(young: f64, poisson: f64) -> f64 {
    young / (1.0 - poisson * poisson)
}

/// Shear modulus μ = E/(2(1+ν)) (Pa).
pub fn shear_modulus(young: f64, poisson: f64) -> f64 {
    young / (2.0 * (1.0 + poisson))
}

fn check_young(location: Location, value: f64) -> Result<(), StackError> {
    if !value.is_finite() {
        return Err(StackError::Invalid {
            location,
            field: "young",
            value,
            reason: "must be a finite number (Pa)",
        });
    }
    if value <= 0.0 {
        return Err(StackError::Invalid {
            location,
            field: "young",
            value,
            reason: "Young modulus must be > 0 (Pa)",
        });
    }
    if !(YOUNG_RANGE.0..=YOUNG_RANGE.1).contains(&value) {
        return Err(StackError::Invalid {
            location,
            field: "young",
            value,
            reason: "Young modulus must lie in [1e-3, 1e15] Pa (outside it S(ρ) over- or underflows)",
        });
    }
    Ok(())
}

fn check_poisson(location: Location, value: f64) -> Result<(), StackError> {
    if !value.is_finite() {
        return Err(StackError::Invalid {
            location,
            field: "poisson",
            value,
            reason: "must be a finite number",
        });
    }
    if value <= -1.0 || value > 0.5 {
        return Err(StackError::Invalid {
            location,
            field: "poisson",
            value,
            reason: "Poisson ratio must lie in (-1, 0.5]",
        });
    }
    Ok(())
}

/// Admissible conductivities (W/(m·K) or S/m), inclusive: from far below PTFE's
/// electrical conductivity to far above any metal's. Within it every ratio of two
/// conductivities, and so the conduction compliance S_th, stays finite in f64.
pub const CONDUCTIVITY_RANGE: (f64, f64) = (1e-30, 1e30);

fn check_conductivity(
    location: Location,
    field: &'static str,
    value: f64,
) -> Result<(), StackError> {
    let reason = if !value.is_finite() {
        "must be a finite number"
    } else if value <= 0.0 {
        "conductivity must be > 0"
    } else if !(CONDUCTIVITY_RANGE.0..=CONDUCTIVITY_RANGE.1).contains(&value) {
        "conductivity must lie in [1e-30, 1e30]"
    } else {
        return Ok(());
    };
    Err(StackError::Invalid {
        location,
        field,
        value,
        reason,
    })
}

fn check_conductivities(location: Location, c: &Conductivity) -> Result<(), StackError> {
    if let Some(k) = c.thermal {
        check_conductivity(location, "thermal_conductivity", k)?;
    }
    if let Some(s) = c.electrical {
        check_conductivity(location, "electrical_conductivity", s)?;
    }
    Ok(())
}

fn check_thickness(location: Location, value: f64) -> Result<(), StackError> {
    if !value.is_finite() {
        return Err(StackError::Invalid {
            location,
            field: "thickness",
            value,
            reason: "must be a finite number (m)",
        });
    }
    if value <= 0.0 {
        return Err(StackError::Invalid {
            location,
            field: "thickness",
            value,
            reason: "thickness must be > 0 (m)",
        });
    }
    Ok(())
}

impl Stack {
    /// Builds and validates a stack. Layer 1 (index 0) is the top layer.
    pub fn new(layers: Vec<Layer>, base: Base) -> Result<Self, StackError> {
        for (i, l) in layers.iter().enumerate() {
            let loc = Location::Layer(i + 1);
            check_thickness(loc, l.thickness)?;
            check_young(loc, l.young)?;
            check_poisson(loc, l.poisson)?;
        }
        match base {
            Base::Rigid => {
                if layers.is_empty() {
                    return Err(StackError::NoLayersOnRigid);
                }
            }
            Base::Elastic { young, poisson } => {
                check_young(Location::Base, young)?;
                check_poisson(Location::Base, poisson)?;
            }
        }
        Ok(Stack {
            name: None,
            layers,
            base,
            conduction: StackConduction::default(),
        })
    }

    /// Sets the conduction properties (physics.md §6.2): one [`Conductivity`] per layer
    /// (top first, or none at all), the base's, and whether the base is a conducting
    /// half-space or an isothermal sink. Validated like a stack file: conductivities
    /// positive and finite in [`CONDUCTIVITY_RANGE`], an isothermal base without
    /// conductivities and under at least one layer.
    pub fn with_conduction(
        mut self,
        layers: Vec<Conductivity>,
        base: Conductivity,
        base_kind: BaseConduction,
    ) -> Result<Self, StackError> {
        let layers = if layers.is_empty() {
            vec![Conductivity::default(); self.layers.len()]
        } else {
            layers
        };
        if layers.len() != self.layers.len() {
            return Err(StackError::ConductionLayers {
                layers: self.layers.len(),
                given: layers.len(),
            });
        }
        for (i, c) in layers.iter().enumerate() {
            check_conductivities(Location::Layer(i + 1), c)?;
        }
        check_conductivities(Location::Base, &base)?;
        if base_kind == BaseConduction::Isothermal {
            if base.thermal.is_some() {
                return Err(StackError::IsothermalWithConductivity {
                    field: "thermal_conductivity",
                });
            }
            if base.electrical.is_some() {
                return Err(StackError::IsothermalWithConductivity {
                    field: "electrical_conductivity",
                });
            }
            if self.layers.is_empty() {
                return Err(StackError::NoLayersOnIsothermal);
            }
        }
        self.conduction = StackConduction {
            layers,
            base,
            base_kind,
        };
        Ok(self)
    }

    /// The conduction properties (empty when the stack gives none).
    pub fn conduction(&self) -> &StackConduction {
        &self.conduction
    }

    /// The conductivities of layer `i` (0-based, top first); empty when not given.
    pub fn layer_conductivity(&self, i: usize) -> Conductivity {
        self.conduction.layers.get(i).copied().unwrap_or_default()
    }

    /// This stack pressed against the elastic stack `counterface` instead of a rigid
    /// flat (physics.md §6.1): the pair as [`Bodies`].
    pub fn against(self, counterface: Stack) -> Bodies {
        Bodies::elastic(self, counterface)
    }

    /// A homogeneous elastic half-space (zero layers on an elastic base).
    pub fn half_space(young: f64, poisson: f64) -> Result<Self, StackError> {
        Stack::new(Vec::new(), Base::Elastic { young, poisson })
    }

    /// The paper's two-layer stack (Waddad et al. §5): a 100 µm layer (E₁ = 4 GPa,
    /// ν = 0.15) on a 900 µm layer of modulus `e2_over_e1`·E₁ (ν = 0.15), bonded to a
    /// rigid base at 1 mm depth.
    pub fn paper_two_layer(e2_over_e1: f64) -> Result<Self, StackError> {
        let layer = |thickness, young| Layer {
            thickness,
            young,
            poisson: 0.15,
        };
        Stack::new(
            vec![layer(100e-6, 4e9), layer(900e-6, 4e9 * e2_over_e1)],
            Base::Rigid,
        )
    }

    /// Sets the name (builder style).
    pub fn with_name(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// The layers, top first.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }

    /// The base below the last layer.
    pub fn base(&self) -> Base {
        self.base
    }

    /// Young modulus and Poisson ratio of the surface material (layer 1, or the
    /// base of a zero-layer half-space).
    pub fn top_material(&self) -> (f64, f64) {
        match (self.layers.first(), self.base) {
            (Some(l), _) => (l.young, l.poisson),
            (None, Base::Elastic { young, poisson }) => (young, poisson),
            (None, Base::Rigid) => unreachable!("validated: a rigid base has layers"),
        }
    }

    /// E*₁ = E₁/(1−ν₁²) of the surface material (Pa).
    pub fn top_plane_strain_modulus(&self) -> f64 {
        let (e, nu) = self.top_material();
        plane_strain_modulus(e, nu)
    }

    /// The contact modulus E* (Pa) of this body against a rigid flat: E*₁ of its top
    /// material ([`Solid::contact_modulus`]).
    pub fn contact_modulus(&self) -> f64 {
        Solid::contact_modulus(self)
    }

    /// α = −E*/2 (Pa) against a rigid flat ([`Solid::alpha`]).
    pub fn alpha(&self) -> f64 {
        Solid::alpha(self)
    }

    /// The top layer's thickness h₁ (m), `None` for a half-space
    /// ([`Solid::top_thickness`]).
    pub fn top_thickness(&self) -> Option<f64> {
        Solid::top_thickness(self)
    }

    /// Total thickness of the layers (m) ([`Solid::total_thickness`]).
    pub fn total_thickness(&self) -> f64 {
        Solid::total_thickness(self)
    }

    /// True when the body is mechanically a homogeneous half-space (k_z ≡ 0)
    /// ([`Solid::is_homogeneous`]).
    pub fn is_homogeneous(&self) -> bool {
        Solid::is_homogeneous(self)
    }

    /// True when S(0) = 0: a rigid base ([`Solid::on_rigid_bases`]).
    pub fn on_rigid_bases(&self) -> bool {
        Solid::on_rigid_bases(self)
    }

    #[cfg(feature = "toml")]
    /// Reads one body from a TOML file (a `[counterface]` in it is refused,
    /// [`StackError::TwoBodies`]; [`Bodies::from_toml_file`] reads the pair). See the
    /// module docs for the format.
    pub fn from_toml_file(path: &Path) -> Result<Self, StackError> {
        Bodies::from_toml_file(path)?
            .single()
            .map_err(|e| StackError::InFile {
                path: path.display().to_string(),
                error: Box::new(e),
            })
    }

    #[cfg(feature = "toml")]
    /// Parses one body from TOML text (a `[counterface]` in it is refused,
    /// [`StackError::TwoBodies`]). See the module docs for the format.
    pub fn from_toml_str(text: &str) -> Result<Self, StackError> {
        Bodies::from_toml_str(text)?.single()
    }

    #[cfg(feature = "toml")]
    /// Serialises the stack back to the TOML format it is read from.
    pub fn to_toml_string(&self) -> String {
        self.body_toml("")
    }

    #[cfg(feature = "toml")]
    /// The TOML of the first body, tables prefixed by `prefix` (e.g. `counterface.`).
    fn body_toml(&self, prefix: &str) -> String {
        let mut s = String::new();
        if let Some(n) = &self.name {
            s.push_str(&format!("name = {}\n", toml::Value::String(n.clone())));
        }
        for (i, l) in self.layers.iter().enumerate() {
            s.push_str(&format!(
                "[[{prefix}layer]]\nthickness = {:e}\nyoung = {:e}\npoisson = {:e}\n",
                l.thickness, l.young, l.poisson
            ));
            push_conductivity(&mut s, &self.layer_conductivity(i));
        }
        match self.base {
            Base::Rigid => s.push_str(&format!("[{prefix}base]\nkind = \"rigid\"\n")),
            Base::Elastic { young, poisson } => s.push_str(&format!(
                "[{prefix}base]\nkind = \"elastic\"\nyoung = {young:e}\npoisson = {poisson:e}\n"
            )),
        }
        if self.conduction.base_kind == BaseConduction::Isothermal {
            s.push_str("conduction = \"isothermal\"\n");
        }
        push_conductivity(&mut s, &self.conduction.base);
        s
    }
}

impl Bodies {
    #[cfg(feature = "toml")]
    /// Reads a stack file's bodies: the first body and its `[counterface]`, if any.
    /// See the module docs for the format. The file may hold at most
    /// [`crate::resources::TEXT_FILE_CAP`] bytes (or the machine's memory limit, if
    /// smaller).
    pub fn from_toml_file(path: &Path) -> Result<Self, StackError> {
        let text = crate::resources::read_text_capped(
            path,
            crate::resources::TEXT_FILE_CAP,
            "a stack file",
            &crate::resources::MemoryLimit::of_machine(),
        )
        .map_err(|e| StackError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Bodies::from_toml_str(&text).map_err(|e| StackError::InFile {
            path: path.display().to_string(),
            error: Box::new(e),
        })
    }

    #[cfg(feature = "toml")]
    /// Parses a stack file's bodies from TOML text: the first body and its
    /// `[counterface]`, if any. See the module docs for the format.
    pub fn from_toml_str(text: &str) -> Result<Self, StackError> {
        let de = toml::de::Deserializer::parse(text)
            .map_err(|e| StackError::Syntax(toml_error_line(text, &e)))?;
        let file: StackFile = serde_path_to_error::deserialize(de)
            .map_err(|e| StackError::from_serde(&e.path().to_string(), e.inner().message()))?;
        file.bodies()
    }

    #[cfg(feature = "toml")]
    /// Serialises the bodies back to the stack file format (an elastic counterface as a
    /// `[counterface]` table with `[[counterface.layer]]` and `[counterface.base]`).
    pub fn to_toml_string(&self) -> String {
        let mut s = self.first.body_toml("");
        if let Some(c) = self.counterface.stack() {
            s.push_str("[counterface]\n");
            s.push_str(&c.body_toml("counterface."));
        }
        s
    }

    /// The first body alone; [`StackError::TwoBodies`] if there is an elastic
    /// counterface.
    pub fn single(self) -> Result<Stack, StackError> {
        match self.counterface {
            Counterface::Elastic { .. } => Err(StackError::TwoBodies),
            Counterface::Rigid { .. } => Ok(self.first),
        }
    }
}

/// Appends the given conductivities as TOML lines (nothing when none is given).
#[cfg(feature = "toml")]
fn push_conductivity(s: &mut String, c: &Conductivity) {
    if let Some(k) = c.thermal {
        s.push_str(&format!("thermal_conductivity = {k:e}\n"));
    }
    if let Some(k) = c.electrical {
        s.push_str(&format!("electrical_conductivity = {k:e}\n"));
    }
}

/// A TOML parse error in one line: `line L, column C: message` (the parser's own text
/// spans five lines with a source excerpt).
#[cfg(feature = "toml")]
pub fn toml_error_line(text: &str, e: &toml::de::Error) -> String {
    let message = one_line(e.message());
    match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            format!("line {line}, column {column}: {message}")
        }
        None => message,
    }
}

#[cfg(feature = "toml")]
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    const PAPER: &str = r#"
name = "paper"
[[layer]]
thickness = 100e-6
young = 4e9
poisson = 0.15
[[layer]]
thickness = 900e-6
young = 20e9
poisson = 0.15
[base]
kind = "rigid"
"#;

    /// The file form built directly ([`StackFile::of`]) equals the parsed text form,
    /// and reads back to the same stack (with a counterface and conductivities too).
    #[test]
    fn file_form_equals_the_text_form() {
        let paper = Stack::from_toml_str(PAPER).unwrap();
        let cond = Stack::from_toml_str(
            "[[layer]]\nthickness = 1e-5\nyoung = 4e11\npoisson = 0.25\nthermal_conductivity = 20\n\
             [base]\nkind = \"rigid\"\nconduction = \"isothermal\"\n",
        )
        .unwrap();
        let pair = paper
            .clone()
            .against(Stack::half_space(210e9, 0.3).unwrap());
        for st in [paper, cond, Stack::half_space(1e9, 0.5).unwrap()] {
            let direct = StackFile::of(&Bodies::<NoSurface>::rigid(st.clone()));
            let text: StackFile = toml::from_str(&st.to_toml_string()).unwrap();
            assert_eq!(direct, text);
            assert_eq!(direct.bodies().unwrap().single().unwrap(), st);
        }
        let direct = StackFile::of(&pair);
        let text: StackFile = toml::from_str(&pair.to_toml_string()).unwrap();
        assert_eq!(direct, text);
        assert_eq!(direct.bodies().unwrap(), pair);
        // one body expected: the pair's text is refused by name
        let e = Stack::from_toml_str(&pair.to_toml_string()).unwrap_err();
        assert_eq!(e, StackError::TwoBodies);
    }

    /// A stack file's `[counterface]` is a stack: its own counterface and the scene's
    /// keys are refused by name, and errors inside it say so.
    #[test]
    fn counterface_errors_name_the_counterface() {
        let base = "[base]\nkind = \"elastic\"\nyoung = 1e9\npoisson = 0.3\n";
        let with = |c: &str| format!("{base}[counterface]\n{c}");
        let e = err(&with(&format!(
            "{}[counterface.counterface]\n{}",
            base.replace("[base]", "[counterface.base]"),
            base.replace("[base]", "[counterface.counterface.base]")
        )));
        assert!(e.contains("cannot have its own counterface"), "{e}");
        let e = err(&with("kind = \"rigid\"\n"));
        assert!(
            e.starts_with("counterface: stack: unknown key `kind`"),
            "{e}"
        );
        let e = err(&with(
            "[[counterface.layer]]\nthickness = 1e-4\nyoung = \"x\"\n",
        ));
        assert!(
            e.starts_with("counterface: layer 1: field `young` must be a number"),
            "{e}"
        );
        let e = err(&with(
            "[counterface.base]\nkind = \"elastic\"\nyoung = 1e9\ncolour = 2\n",
        ));
        assert!(
            e.starts_with("counterface: base: unknown key `colour`") && e.contains("poisson"),
            "{e}"
        );
    }

    #[test]
    fn parses_paper_stack() {
        let s = Stack::from_toml_str(PAPER).unwrap();
        assert_eq!(s.layers().len(), 2);
        assert_eq!(s.base(), Base::Rigid);
        assert_eq!(s.name.as_deref(), Some("paper"));
        assert!((s.total_thickness() - 1e-3).abs() < 1e-18);
        let round = Stack::from_toml_str(&s.to_toml_string()).unwrap();
        assert_eq!(round, s);
    }

    #[test]
    fn paper_constructor_matches_shipped_file() {
        let s = Stack::from_toml_str(PAPER).unwrap();
        let p = Stack::paper_two_layer(5.0).unwrap();
        assert_eq!(p.layers(), s.layers());
        assert_eq!(p.base(), s.base());
    }

    #[test]
    fn half_space_needs_no_layers() {
        let s =
            Stack::from_toml_str("[base]\nkind = \"elastic\"\nyoung = 1e9\npoisson = 0.3").unwrap();
        assert!(s.layers().is_empty());
        assert!(s.is_homogeneous());
        assert_eq!(s.top_thickness(), None);
        assert!((s.top_plane_strain_modulus() - 1e9 / 0.91).abs() < 1e-3);
    }

    fn err(text: &str) -> String {
        Stack::from_toml_str(text).unwrap_err().to_string()
    }

    #[test]
    fn errors_name_field_and_layer() {
        let e = err(
            "[[layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 0.15\n[[layer]]\nthickness = -1\nyoung = 4e9\npoisson = 0.15\n[base]\nkind = \"rigid\"",
        );
        assert!(e.contains("layer 2") && e.contains("thickness"), "{e}");
        let e = err("[[layer]]\nthickness = 1e-4\npoisson = 0.15\n[base]\nkind = \"rigid\"");
        assert!(e.contains("layer 1") && e.contains("young"), "{e}");
        let e = err(
            "[[layer]]\nthickness = 1e-4\nyoung = nan\npoisson = 0.15\n[base]\nkind = \"rigid\"",
        );
        assert!(
            e.contains("layer 1") && e.contains("young") && e.contains("finite"),
            "{e}"
        );
        let e =
            err("[[layer]]\nthickness = 1e-4\nyoung = 0\npoisson = 0.15\n[base]\nkind = \"rigid\"");
        assert!(e.contains("young") && e.contains("> 0"), "{e}");
        let e = err(
            "[[layer]]\nthickness = 1e-4\nyoung = 1e9\npoisson = 0.51\n[base]\nkind = \"rigid\"",
        );
        assert!(e.contains("poisson") && e.contains("(-1, 0.5]"), "{e}");
        let e =
            err("[[layer]]\nthickness = 1e-4\nyoung = 1e9\npoisson = -1\n[base]\nkind = \"rigid\"");
        assert!(e.contains("poisson"), "{e}");
        let e = err(
            "[[layer]]\nthickness = 1e-4\nyoung = 1e9\npoisson = 0.2\nyoungs = 3\n[base]\nkind = \"rigid\"",
        );
        assert!(e.contains("layer 1") && e.contains("youngs"), "{e}");
        let e = err("[base]\nkind = \"rigid\"");
        assert!(e.contains("no layers"), "{e}");
        let e = err("[base]\nkind = \"elastic\"\nyoung = 1e9");
        assert!(e.contains("base") && e.contains("poisson"), "{e}");
        let e = err("[base]\nkind = \"granite\"");
        assert!(e.contains("granite"), "{e}");
        let e = err("colour = 3\n[base]\nkind = \"rigid\"");
        assert!(e.contains("colour"), "{e}");
        let e = err(
            "[[layer]]\nthickness = \"thin\"\nyoung = 1e9\npoisson = 0.2\n[base]\nkind = \"rigid\"",
        );
        assert!(e.contains("thickness") && e.contains("number"), "{e}");
        let e = err("[[layer]]\nthickness = 1e-4\nyoung = 1e9\npoisson = 0.2\n");
        assert!(e.contains("base"), "{e}");
        for text in ["", "[[layer]", "layer = 3\n[base]\nkind=\"rigid\""] {
            let e = err(text);
            assert!(!e.contains('\n'), "one line: {e}");
        }
    }

    #[test]
    fn thousand_layer_file() {
        let mut text = String::from("name = \"graded\"\n");
        for i in 0..1000 {
            text.push_str(&format!(
                "[[layer]]\nthickness = 1e-6\nyoung = {:e}\npoisson = 0.3\n",
                4e9 * (1.0 + i as f64 / 100.0)
            ));
        }
        text.push_str("[base]\nkind = \"elastic\"\nyoung = 5e10\npoisson = 0.3\n");
        let s = Stack::from_toml_str(&text).unwrap();
        assert_eq!(s.layers().len(), 1000);
        assert!((s.total_thickness() - 1e-3).abs() < 1e-15);
        // The error in layer 1000 names it.
        let bad = text.replacen("young = 4e9\n", "young = -4e9\n", 1);
        assert!(
            Stack::from_toml_str(&bad)
                .unwrap_err()
                .to_string()
                .contains("layer 1")
        );
        let last = text.rfind("poisson = 0.3\n[base]").unwrap();
        let mut bad = text.clone();
        bad.replace_range(last..last + 13, "poisson = 0.6");
        let e = Stack::from_toml_str(&bad).unwrap_err().to_string();
        assert!(e.contains("layer 1000") && e.contains("poisson"), "{e}");
    }

    #[test]
    fn incompressible_is_accepted() {
        let s = Stack::from_toml_str(
            "[[layer]]\nthickness = 1e-4\nyoung = 1e9\npoisson = 0.5\n[base]\nkind = \"rigid\"",
        )
        .unwrap();
        assert!((s.top_plane_strain_modulus() - 1e9 / 0.75).abs() < 1e-3);
    }

    /// Moduli whose transfer-matrix products leave f64 are refused, naming the field;
    /// the ends of the admissible range are accepted.
    #[test]
    fn moduli_outside_the_representable_range_are_refused() {
        let st = |e1: &str, eb: &str| {
            Stack::from_toml_str(&format!(
                "[[layer]]\nthickness = 1e-4\nyoung = {e1}\npoisson = 0.3\n[base]\nkind = \"elastic\"\nyoung = {eb}\npoisson = 0.3"
            ))
        };
        let e = st("1e-300", "1e9").unwrap_err().to_string();
        assert!(
            e.contains("layer 1") && e.contains("young") && e.contains("1e15"),
            "{e}"
        );
        let e = st("1e9", "1e300").unwrap_err().to_string();
        assert!(e.starts_with("base") && e.contains("young"), "{e}");
        for (a, b) in [("1e-3", "1e15"), ("1e15", "1e-3")] {
            assert!(st(a, b).is_ok(), "{a} on {b}");
        }
        // (their S(ρ) is finite: `compliance::tests::ends_of_the_modulus_range_are_finite`)
    }

    #[test]
    fn file_errors_name_the_file() {
        let p = std::env::temp_dir().join(format!("strata-stack-{}.toml", std::process::id()));
        std::fs::write(
            &p,
            "[[layer]]\nthickness = 1e-4\nyoung = -1\npoisson = 0.3\n",
        )
        .unwrap();
        let e = Stack::from_toml_file(&p).unwrap_err().to_string();
        std::fs::remove_file(&p).unwrap();
        assert!(
            e.starts_with(&format!("stack file {}: layer 1", p.display())),
            "{e}"
        );
    }

    const CONDUCTING: &str = r#"
[[layer]]
thickness = 1e-5
young = 2e11
poisson = 0.3
thermal_conductivity = 400
electrical_conductivity = 5.8e7
[[layer]]
thickness = 1e-4
young = 4e9
poisson = 0.3
thermal_conductivity = 0.2
[base]
kind = "elastic"
young = 2e11
poisson = 0.3
thermal_conductivity = 50
"#;

    /// Conductivities are read per layer and base, written back, and absent ones stay
    /// absent: a stack without them writes exactly what it wrote before.
    #[test]
    fn conductivities_round_trip() {
        let s = Stack::from_toml_str(CONDUCTING).unwrap();
        assert_eq!(s.layer_conductivity(0).thermal, Some(400.0));
        assert_eq!(s.layer_conductivity(0).electrical, Some(5.8e7));
        assert_eq!(s.layer_conductivity(1).electrical, None);
        assert_eq!(s.conduction().base.thermal, Some(50.0));
        assert_eq!(s.conduction().base_kind, BaseConduction::HalfSpace);
        let round = Stack::from_toml_str(&s.to_toml_string()).unwrap();
        assert_eq!(round, s);
        let iso = Stack::from_toml_str(
            "[[layer]]\nthickness = 1e-4\nyoung = 1e9\npoisson = 0.3\nthermal_conductivity = 1\n[base]\nkind = \"rigid\"\nconduction = \"isothermal\"",
        )
        .unwrap();
        assert_eq!(iso.conduction().base_kind, BaseConduction::Isothermal);
        let text = iso.to_toml_string();
        assert!(
            text.ends_with("[base]\nkind = \"rigid\"\nconduction = \"isothermal\"\n"),
            "{text}"
        );
        assert_eq!(Stack::from_toml_str(&text).unwrap(), iso);
        // Without conduction fields: the exact text of before.
        let p = Stack::from_toml_str(PAPER).unwrap();
        assert_eq!(
            p.to_toml_string(),
            "name = \"paper\"\n[[layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 1.5e-1\n\
             [[layer]]\nthickness = 9e-4\nyoung = 2e10\npoisson = 1.5e-1\n[base]\nkind = \"rigid\"\n"
        );
        assert_eq!(p.conduction(), &StackConduction::default());
        assert_eq!(p, Stack::paper_two_layer(5.0).unwrap().with_name("paper"));
    }

    #[test]
    fn conduction_errors_name_field_and_layer() {
        let layer = |extra: &str| {
            format!(
                "[[layer]]\nthickness = 1e-4\nyoung = 1e9\npoisson = 0.3\n{extra}\n[base]\nkind = \"rigid\"\n"
            )
        };
        let e = err(&layer("thermal_conductivity = -1"));
        assert!(
            e.contains("layer 1") && e.contains("thermal_conductivity") && e.contains("> 0"),
            "{e}"
        );
        let e = err(&layer("electrical_conductivity = nan"));
        assert!(
            e.contains("layer 1") && e.contains("electrical_conductivity") && e.contains("finite"),
            "{e}"
        );
        let e = err(&layer("electrical_conductivity = 1e40"));
        assert!(
            e.contains("electrical_conductivity") && e.contains("1e30"),
            "{e}"
        );
        let e = err(&layer("thermal_conductivity = \"high\""));
        assert!(
            e.contains("thermal_conductivity") && e.contains("number"),
            "{e}"
        );
        let e = err(&(layer("") + "thermal_conductivity = 0"));
        assert!(
            e.starts_with("base") && e.contains("thermal_conductivity"),
            "{e}"
        );
        let e = err(&(layer("") + "conduction = \"isothermal\"\nthermal_conductivity = 3"));
        assert!(
            e.starts_with("base") && e.contains("isothermal") && e.contains("thermal_conductivity"),
            "{e}"
        );
        let e = err(&(layer("") + "conduction = \"adiabatic\""));
        assert!(e.contains("adiabatic") && e.contains("isothermal"), "{e}");
        let e = err(&(layer("") + "conduction = 1"));
        assert!(e.contains("conduction") && e.contains("string"), "{e}");
        let e = err(
            "[base]\nkind = \"elastic\"\nyoung = 1e9\npoisson = 0.3\nconduction = \"isothermal\"",
        );
        assert!(e.contains("isothermal") && e.contains("layer"), "{e}");
        let e = err(&layer("thermal_conductvity = 1"));
        assert!(
            e.contains("thermal_conductvity") && e.contains("thermal_conductivity"),
            "{e}"
        );
        let st = Stack::paper_two_layer(5.0).unwrap();
        let e = st
            .with_conduction(
                vec![Conductivity::default()],
                Conductivity::default(),
                BaseConduction::HalfSpace,
            )
            .unwrap_err();
        assert!(
            matches!(
                e,
                StackError::ConductionLayers {
                    layers: 2,
                    given: 1
                }
            ),
            "{e}"
        );
    }
}
