//! The exception hierarchy of the Python package: every library error becomes a
//! subclass of `strata.StrataError` (itself a `ValueError`) carrying the library's
//! whole message chain (`scene s.toml: surface: field ...`). A missing input file is
//! Python's own `FileNotFoundError`, naming the argument and the path.

use pyo3::create_exception;
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;

create_exception!(
    strata,
    StrataError,
    PyValueError,
    "Base class of every strata error (a ValueError): bad input, or a problem the library refuses to solve. The message is the library's whole chain, naming the field and the file."
);
create_exception!(
    strata,
    StackError,
    StrataError,
    "A material stack that is invalid (the message names the field and the 1-based layer)."
);
create_exception!(
    strata,
    TableError,
    StrataError,
    "A surrogate table that cannot be read, built, or does not serve the stack."
);
create_exception!(
    strata,
    SurfaceError,
    StrataError,
    "A height map that is invalid: dtype, shape, non-finite heights, spikes, sizes, unreadable files."
);
create_exception!(
    strata,
    SceneError,
    StrataError,
    "A scene (TOML file or keyword arguments) with an invalid field; the message names it."
);
create_exception!(
    strata,
    SolveError,
    StrataError,
    "A solve that failed (load out of range, no contact, memory limit, non-convergence)."
);
create_exception!(
    strata,
    LawError,
    StrataError,
    "A contact-law query or sampling that is invalid (separation not finite, too few samples)."
);

/// Which exception class an error becomes.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    Stack,
    Table,
    Surface,
    Scene,
    Solve,
    Law,
}

/// The memory limit of a call (the package's edge, read at every call that allocates
/// in proportion to its input, so a script may change it between calls): the
/// environment variable `STRATA_MEMORY_LIMIT`, else 75 % of the machine's memory. A bad
/// value is an error of `kind` naming the variable.
pub fn memory_limit(kind: Kind) -> PyResult<strata_runtime::resources::MemoryLimit> {
    use strata_runtime::resources::MemoryLimit;
    let value = std::env::var(MemoryLimit::ENV_VAR).ok();
    MemoryLimit::from_setting(value.as_deref()).map_err(|e| to_py(kind, e))
}

/// The Python exception of `kind` with the error's whole chain (`a: b: c`).
pub fn to_py(kind: Kind, e: impl Into<anyhow::Error>) -> PyErr {
    let msg = format!("{:#}", e.into());
    match kind {
        Kind::Stack => StackError::new_err(msg),
        Kind::Table => TableError::new_err(msg),
        Kind::Surface => SurfaceError::new_err(msg),
        Kind::Scene => SceneError::new_err(msg),
        Kind::Solve => SolveError::new_err(msg),
        Kind::Law => LawError::new_err(msg),
    }
}

/// A closure for `map_err`: `.map_err(err(Kind::Stack))`.
pub fn err<E: Into<anyhow::Error>>(kind: Kind) -> impl Fn(E) -> PyErr {
    move |e| to_py(kind, e)
}

/// `FileNotFoundError` when `path` does not exist (`what` names the argument), so that
/// a missing file is told apart from a bad one before any reader runs.
pub fn require_file(what: &str, path: &std::path::Path) -> PyResult<()> {
    if path.exists() {
        Ok(())
    } else {
        Err(PyFileNotFoundError::new_err(format!(
            "{what}: no such file {}",
            path.display()
        )))
    }
}

/// Registers the exception classes in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("StrataError", py.get_type::<StrataError>())?;
    m.add("StackError", py.get_type::<StackError>())?;
    m.add("TableError", py.get_type::<TableError>())?;
    m.add("SurfaceError", py.get_type::<SurfaceError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("SolveError", py.get_type::<SolveError>())?;
    m.add("LawError", py.get_type::<LawError>())?;
    Ok(())
}
