//! `strata.indent`: one paraboloid asperity pressed into the stack, by the full
//! Fredholm solution (paper §3) or the second-order approximation from a table (§4).

use std::path::PathBuf;

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use strata_tablegen::asperity::{Asperity, Options};

use crate::conv;
use crate::errors::{Kind, err, to_py};
use crate::stack::stack_of;
use crate::table::table_arg;

/// Presses a paraboloid of radius `radius` (m) into the stack by each approach in
/// `deltas` (m, ≥ 0), as `strata asperity` does. model="full" solves the Fredholm
/// equation of the second kind (paper §3, eq. 12); model="approx" uses the
/// second-order approximation δ = ζ(a)a²/R, P = (4/3)E*₁χ(a)a³/R (eqs. 16–17) from
/// `table` (a strata.Table or a path; default: the table cache, built on first use).
/// Returns a dict of arrays: delta (m), a (contact radius, m), force (N). Releases the
/// GIL; progress=True shows a table build's progress on stderr.
#[pyfunction]
#[pyo3(signature = (stack, radius, deltas, model="full", table=None, cache_dir=None, progress=false))]
#[allow(clippy::too_many_arguments)]
pub fn indent<'py>(
    py: Python<'py>,
    stack: &Bound<'py, PyAny>,
    radius: f64,
    deltas: &Bound<'py, PyAny>,
    model: &str,
    table: Option<&Bound<'py, PyAny>>,
    cache_dir: Option<PathBuf>,
    progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let stack = stack_of(stack, "indent: stack")?;
    if !(radius.is_finite() && radius > 0.0) {
        return Err(to_py(
            Kind::Solve,
            anyhow::anyhow!("radius: must be positive and finite (m), got {radius}"),
        ));
    }
    let deltas = conv::list(deltas, "deltas", Kind::Solve)?;
    if let Some(bad) = deltas.iter().find(|d| !(d.is_finite() && **d >= 0.0)) {
        return Err(to_py(
            Kind::Solve,
            anyhow::anyhow!("deltas: values must be finite and >= 0 (m), got {bad}"),
        ));
    }
    let table = table_arg(table)?;
    let full = match model {
        "full" => {
            if table.is_some() {
                return Err(to_py(
                    Kind::Solve,
                    anyhow::anyhow!("table: only used with model=\"approx\""),
                ));
            }
            true
        }
        "approx" => false,
        other => {
            return Err(to_py(
                Kind::Solve,
                anyhow::anyhow!("model: `{other}` is not one of \"full\", \"approx\""),
            ));
        }
    };
    let rows: Vec<(f64, f64)> = crate::progress::call(py, Some(progress), |_| {
        (|| -> anyhow::Result<Vec<(f64, f64)>> {
            if full {
                let solver = Asperity::new(&stack, Options::default())?;
                deltas
                    .iter()
                    .map(|&d| {
                        let s = solver
                            .paraboloid_at_delta(d, radius)
                            .map_err(|e| anyhow::anyhow!("delta = {d} m: {e}"))?;
                        Ok((s.a, s.force))
                    })
                    .collect()
            } else {
                let law = match &table {
                    Some(t) => t.law_for(&stack)?,
                    None => strata_engine::asperity_table::law_for_stack(
                        &stack,
                        None,
                        cache_dir.as_deref(),
                    )?,
                };
                deltas
                    .iter()
                    .map(|&d| {
                        strata_engine::asperity_table::approx_paraboloid(&law, d, radius)
                            .map_err(|e| anyhow::anyhow!("delta = {d} m: {e:#}"))
                    })
                    .collect()
            }
        })()
        .map_err(err(Kind::Solve))
    })??;
    let d = PyDict::new(py);
    d.set_item("delta", deltas.into_pyarray(py))?;
    d.set_item(
        "a",
        rows.iter()
            .map(|r| r.0)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item(
        "force",
        rows.iter()
            .map(|r| r.1)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    Ok(d)
}
