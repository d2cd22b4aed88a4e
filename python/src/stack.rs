//! `strata.Stack`: a validated material stack (layer 1 on top), from a TOML file or text
//! or from Python lists, and its surface compliance S(ρ).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use strata_runtime::{Base, Bodies, Compliance, Layer, Solid, Stack};

use crate::conv;
use crate::errors::{Kind, err, require_file, to_py};

/// A material stack: elastic layers (layer 1 on top, the contact layer) bonded on a
/// rigid base or on an elastic half-space. SI units: thickness in m, Young modulus in
/// Pa, Poisson ratio in (-1, 0.5].
///
/// Stack(layers, base="rigid", name=None)
///
/// layers: a list of (thickness, young, poisson) tuples or of dicts with those keys;
/// base: "rigid", or (young, poisson), or a dict {"young": ..., "poisson": ...} for an
/// elastic half-space. Zero layers on an elastic base is a homogeneous half-space.
/// Errors (strata.StackError) name the field and the 1-based layer, as for a file.
#[pyclass(name = "Stack", module = "strata", frozen, from_py_object)]
#[derive(Clone)]
pub struct PyStack {
    /// The first body, with the elastic `[counterface]` of a stack file if any.
    pub stack: Bodies,
}

fn number(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<f64> {
    obj.extract::<f64>().map_err(|_| {
        to_py(
            Kind::Stack,
            anyhow::anyhow!(
                "{field}: expected a number, got {}",
                obj.repr().map(|r| r.to_string()).unwrap_or_default()
            ),
        )
    })
}

/// (a, b, c) from a 3-sequence or a dict with `keys`.
fn triple(obj: &Bound<'_, PyAny>, keys: &[&str], what: &str) -> PyResult<Vec<f64>> {
    if let Ok(d) = obj.cast::<PyDict>() {
        for k in d.keys() {
            let k: String = k.extract().unwrap_or_default();
            if !keys.contains(&k.as_str()) {
                return Err(to_py(
                    Kind::Stack,
                    anyhow::anyhow!("{what}: unknown key `{k}` (expected {})", keys.join(", ")),
                ));
            }
        }
        return keys
            .iter()
            .map(|k| match d.get_item(k)? {
                Some(v) => number(&v, &format!("{what}.{k}")),
                None => Err(to_py(
                    Kind::Stack,
                    anyhow::anyhow!("{what}: missing field `{k}`"),
                )),
            })
            .collect();
    }
    let items: Vec<Bound<'_, PyAny>> = obj.extract().map_err(|_| {
        to_py(
            Kind::Stack,
            anyhow::anyhow!(
                "{what}: expected a dict or a sequence ({})",
                keys.join(", ")
            ),
        )
    })?;
    if items.len() != keys.len() {
        return Err(to_py(
            Kind::Stack,
            anyhow::anyhow!(
                "{what}: expected {} numbers ({}), got {}",
                keys.len(),
                keys.join(", "),
                items.len()
            ),
        ));
    }
    items
        .iter()
        .zip(keys)
        .map(|(v, k)| number(v, &format!("{what}.{k}")))
        .collect()
}

fn base_of(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Base> {
    let Some(obj) = obj else {
        return Ok(Base::Rigid);
    };
    if let Ok(s) = obj.extract::<String>() {
        return match s.as_str() {
            "rigid" => Ok(Base::Rigid),
            other => Err(to_py(
                Kind::Stack,
                anyhow::anyhow!(
                    "base: `{other}` is not \"rigid\"; an elastic base is (young, poisson) or {{\"young\": ..., \"poisson\": ...}}"
                ),
            )),
        };
    }
    let v = triple(obj, &["young", "poisson"], "base")?;
    Ok(Base::Elastic {
        young: v[0],
        poisson: v[1],
    })
}

fn layer_dict<'py>(py: Python<'py>, l: &Layer) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("thickness", l.thickness)?;
    d.set_item("young", l.young)?;
    d.set_item("poisson", l.poisson)?;
    Ok(d)
}

#[pymethods]
impl PyStack {
    #[new]
    #[pyo3(signature = (layers, base=None, name=None))]
    fn new(
        layers: &Bound<'_, PyAny>,
        base: Option<&Bound<'_, PyAny>>,
        name: Option<String>,
    ) -> PyResult<Self> {
        let items: Vec<Bound<'_, PyAny>> = layers.extract().map_err(|_| {
            to_py(
                Kind::Stack,
                anyhow::anyhow!("layers: expected a list of (thickness, young, poisson)"),
            )
        })?;
        let layers = items
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let v = triple(
                    l,
                    &["thickness", "young", "poisson"],
                    &format!("layers[{i}]"),
                )?;
                Ok(Layer {
                    thickness: v[0],
                    young: v[1],
                    poisson: v[2],
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        let mut stack = Stack::new(layers, base_of(base)?).map_err(err(Kind::Stack))?;
        if let Some(n) = name {
            stack = stack.with_name(n);
        }
        Ok(PyStack {
            stack: Bodies::rigid(stack),
        })
    }

    /// Reads a stack TOML file (the format of `tables/stacks/*.toml`).
    #[staticmethod]
    fn from_file(path: PathBuf) -> PyResult<Self> {
        require_file("Stack.from_file", &path)?;
        Ok(PyStack {
            stack: Bodies::from_toml_file(&path).map_err(err(Kind::Stack))?,
        })
    }

    /// Parses a stack from TOML text.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Self> {
        Ok(PyStack {
            stack: Bodies::from_toml_str(text).map_err(err(Kind::Stack))?,
        })
    }

    /// A homogeneous elastic half-space (Young modulus in Pa, Poisson ratio).
    #[staticmethod]
    fn half_space(young: f64, poisson: f64) -> PyResult<Self> {
        Ok(PyStack {
            stack: Bodies::rigid(Stack::half_space(young, poisson).map_err(err(Kind::Stack))?),
        })
    }

    /// The stack as TOML text (what Stack.from_toml reads back).
    fn to_toml(&self) -> String {
        self.stack.to_toml_string()
    }

    /// The layers, top first: a list of dicts (thickness m, young Pa, poisson).
    #[getter]
    fn layers<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let l = self
            .stack
            .first
            .layers()
            .iter()
            .map(|l| layer_dict(py, l))
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, l)
    }

    /// "rigid", or a dict {"young": Pa, "poisson": -} for an elastic half-space.
    #[getter]
    fn base<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(match self.stack.first.base() {
            Base::Rigid => "rigid".into_pyobject(py)?.into_any(),
            Base::Elastic { young, poisson } => {
                let d = PyDict::new(py);
                d.set_item("young", young)?;
                d.set_item("poisson", poisson)?;
                d.into_any()
            }
        })
    }

    #[getter]
    fn name(&self) -> Option<String> {
        self.stack.first.name.clone()
    }

    /// E*₁ = E₁/(1 − ν₁²) of the top material (Pa).
    #[getter]
    fn e_star1(&self) -> f64 {
        self.stack.first.top_plane_strain_modulus()
    }

    /// True for a homogeneous half-space (no table needed: χ = ζ = 1, g = 0).
    #[getter]
    fn is_homogeneous(&self) -> bool {
        self.stack.is_homogeneous()
    }

    /// Total thickness of the layers (m).
    #[getter]
    fn total_thickness(&self) -> f64 {
        self.stack.total_thickness()
    }

    /// The normalised surface compliance S(ρ) = 1 + k_z(ρ) (physics.md §2; the
    /// paper's eq. 7): ŵ = 2 S(ρ) p̂ / (E*₁ ρ), ρ in 1/m (scalar or array; S is even
    /// in ρ, S(0) its limit). Computed by the transfer-matrix technique, no table.
    fn compliance<'py>(
        &self,
        py: Python<'py>,
        rho: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let c = Compliance::new(&self.stack);
        conv::map(py, rho, "rho", Kind::Stack, |r| {
            if r.is_nan() {
                anyhow::bail!("rho: NaN is not a wavenumber (1/m)");
            }
            Ok(c.s(r))
        })
    }

    fn __repr__(&self) -> String {
        let s = &self.stack.first;
        format!(
            "Stack({}, {} layer(s), {} base, E*1 = {:e} Pa)",
            s.name.as_deref().unwrap_or("unnamed"),
            s.layers().len(),
            match s.base() {
                Base::Rigid => "rigid",
                Base::Elastic { .. } => "elastic",
            },
            s.top_plane_strain_modulus()
        )
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .extract::<PyStack>()
            .map(|o| o.stack == self.stack)
            .unwrap_or(false)
    }
}

/// Unwraps `to_py`'s anyhow conversion for callers that hold a stack by reference.
pub fn stack_of(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Bodies> {
    if let Ok(s) = obj.extract::<PyStack>() {
        return Ok(s.stack);
    }
    if let Ok(p) = obj.extract::<PathBuf>() {
        require_file(what, &p)?;
        return Bodies::from_toml_file(&p).map_err(err(Kind::Stack));
    }
    Err(to_py(
        Kind::Stack,
        anyhow::anyhow!("{what}: expected a strata.Stack or the path of a stack TOML file"),
    ))
}
