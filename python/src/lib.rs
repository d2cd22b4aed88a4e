//! # strata-python: the native module `strata._strata`
//!
//! pyo3 bindings of the strata workspace for the pure-Python package `strata`
//! (python/python/strata/), built by maturin (`pip install ./python`). The classes
//! mirror the library's concepts in SI units: `Stack`, `Table` and `AsperityLaw`,
//! `Surface`, `Scene` (solved by the engine of `strata solve`, so the numbers are the
//! CLI's), `ContactLaw` and `indent`. Every error is a `strata.StrataError` subclass
//! carrying the library's message chain (module `errors`); inputs (dtype, shape, finite values, files)
//! are checked before any library call, never left to a panic. Long solves release
//! the GIL.

#![deny(clippy::unwrap_used, clippy::expect_used)]

use pyo3::prelude::*;

mod asperity;
mod conv;
mod errors;
mod law;
mod progress;
mod solve;
mod stack;
mod surface;
mod table;

#[pymodule]
fn _strata(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add_class::<stack::PyStack>()?;
    m.add_class::<table::PyTable>()?;
    m.add_class::<table::PyAsperityLaw>()?;
    m.add_class::<surface::PySurface>()?;
    m.add_class::<solve::PyScene>()?;
    m.add_class::<law::PyContactLaw>()?;
    m.add_function(wrap_pyfunction!(asperity::indent, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "CURVE_COLUMNS",
        strata_engine::engine::CURVE_HEADER.to_vec(),
    )?;
    Ok(())
}
