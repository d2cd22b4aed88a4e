//! numpy in and out: element-wise maps of scalars or arrays of float64, and the
//! checks of a height array (dtype, dimensions, finite values) before any library call.

use numpy::{
    IntoPyArray, PyArrayDescrMethods, PyArrayDyn, PyReadonlyArrayDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use crate::errors::{Kind, to_py};

/// An input that is a float scalar or a float64 array of any shape.
pub enum Values {
    Scalar(f64),
    Array(Vec<f64>, Vec<usize>),
}

/// Reads `obj` as a float scalar, a float array (float64, or float32/float16 widened
/// exactly) or a list of numbers; `name` is the argument, for the message. Other
/// dtypes (integers, complex, objects, strings) are refused with `kind`.
pub fn values(obj: &Bound<'_, PyAny>, name: &str, kind: Kind) -> PyResult<Values> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        let dt = a.dtype();
        if dt.kind() != b'f' {
            return Err(to_py(
                kind,
                anyhow::anyhow!(
                    "{name}: array dtype {} is not a floating-point type (give float64, SI units)",
                    dt.str().map(|s| s.to_string()).unwrap_or_default()
                ),
            ));
        }
        let shape = a.shape().to_vec();
        let a64 = if dt.is_equiv_to(&numpy::dtype::<f64>(obj.py())) {
            obj.clone()
        } else {
            obj.call_method1("astype", ("float64",))?
        };
        let ro: PyReadonlyArrayDyn<'_, f64> = a64
            .extract()
            .map_err(|e| to_py(kind, anyhow::anyhow!("{name}: {e}")))?;
        return Ok(Values::Array(
            ro.as_array().iter().copied().collect(),
            shape,
        ));
    }
    if let Ok(x) = obj.extract::<f64>() {
        return Ok(Values::Scalar(x));
    }
    match obj.extract::<Vec<f64>>() {
        Ok(v) => {
            let n = v.len();
            Ok(Values::Array(v, vec![n]))
        }
        Err(_) => Err(to_py(
            kind,
            anyhow::anyhow!(
                "{name}: expected a number or an array of numbers, got {}",
                obj.get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ),
        )),
    }
}

/// `f` applied to every value of `obj` ([`values`]); a scalar gives a float, an array
/// an array of the same shape.
pub fn map<'py>(
    py: Python<'py>,
    obj: &Bound<'py, PyAny>,
    name: &str,
    kind: Kind,
    f: impl Fn(f64) -> anyhow::Result<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    match values(obj, name, kind)? {
        Values::Scalar(x) => Ok(f(x)
            .map_err(|e| to_py(kind, e))?
            .into_pyobject(py)?
            .into_any()),
        Values::Array(v, shape) => {
            let out = v
                .into_iter()
                .map(&f)
                .collect::<anyhow::Result<Vec<f64>>>()
                .map_err(|e| to_py(kind, e))?;
            array(py, out, &shape)
        }
    }
}

/// A float64 array of `shape` from row-major values.
pub fn array<'py>(py: Python<'py>, v: Vec<f64>, shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    let a = ndarray::ArrayD::from_shape_vec(ndarray::IxDyn(shape), v)
        .map_err(|e| to_py(Kind::Solve, anyhow::anyhow!("internal: {e}")))?;
    let out: Bound<'py, PyArrayDyn<f64>> = a.into_pyarray(py);
    Ok(out.into_any())
}

/// The values of `obj` as a flat list ([`values`]; a scalar is one value).
pub fn list(obj: &Bound<'_, PyAny>, name: &str, kind: Kind) -> PyResult<Vec<f64>> {
    Ok(match values(obj, name, kind)? {
        Values::Scalar(x) => vec![x],
        Values::Array(v, _) => v,
    })
}

/// A height map: a 2-D floating-point array (m), row-major.
/// Returns the heights and the shape (n0, n1); the first axis is x.
pub fn heights(obj: &Bound<'_, PyAny>) -> PyResult<(Vec<f64>, usize, usize)> {
    // A masked array's masked points are missing values (NaN: refused with their row
    // and column, or repaired on request), never the numbers hidden under the mask.
    let filled;
    let obj = if is_masked(obj)? {
        filled = obj
            .call_method1("astype", ("float64",))?
            .call_method1("filled", (f64::NAN,))?;
        &filled
    } else {
        obj
    };
    if obj.cast::<PyUntypedArray>().is_err() {
        return Err(to_py(
            Kind::Surface,
            anyhow::anyhow!(
                "heights: expected a 2-D numpy array of float64 (m), got {}",
                obj.get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ),
        ));
    }
    // the memory limit before the copy: a huge array (or a broadcast view of one) is
    // refused by name instead of aborting the interpreter
    if let Ok(a) = obj.cast::<PyUntypedArray>()
        && let [n0, n1] = a.shape()
    {
        let memory = crate::errors::memory_limit(Kind::Surface)?;
        strata_runtime::surface::Surface::check_measured_memory(*n0, *n1, &memory)
            .map_err(|e| to_py(Kind::Surface, anyhow::Error::new(e)))?;
    }
    let Values::Array(z, shape) = values(obj, "heights", Kind::Surface)? else {
        return Err(to_py(
            Kind::Surface,
            anyhow::anyhow!("heights: expected a 2-D array"),
        ));
    };
    if shape.len() != 2 {
        return Err(to_py(
            Kind::Surface,
            anyhow::anyhow!(
                "heights: expected a 2-D array (n0 × n1, first axis x), got {} dimension(s) {:?}",
                shape.len(),
                shape
            ),
        ));
    }
    // Non-finite heights and spikes are the library's to find (Surface::measured_with,
    // with the row and column), as for a file.
    Ok((z, shape[0], shape[1]))
}

/// True for a `numpy.ma.MaskedArray`.
fn is_masked(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    let ma = obj.py().import("numpy.ma")?;
    ma.call_method1("isMaskedArray", (obj,))?.is_truthy()
}

/// A non-negative integer argument `name` (a count, a grid size, a seed): a Python
/// `bool` or a negative or non-integer value is refused naming the parameter (PyO3's
/// own conversion raised `OverflowError` without it, and took `True` as 1).
pub fn count(obj: &Bound<'_, PyAny>, name: &str, kind: Kind) -> PyResult<u64> {
    if obj.is_instance_of::<pyo3::types::PyBool>() {
        return Err(to_py(
            kind,
            anyhow::anyhow!("{name}: expected a non-negative integer, got a bool"),
        ));
    }
    let v: i128 = obj.extract().map_err(|_| {
        to_py(
            kind,
            anyhow::anyhow!("{name}: expected a non-negative integer, got {obj}"),
        )
    })?;
    u64::try_from(v).map_err(|_| {
        to_py(
            kind,
            anyhow::anyhow!("{name} = {v}: must be a non-negative integer below 2^64"),
        )
    })
}

/// A JSON value (curve.json's summary, surface statistics) as Python objects.
pub(crate) fn json_to_py<'py>(
    py: Python<'py>,
    v: &serde_json::Value,
) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (v.to_string(),))
}
