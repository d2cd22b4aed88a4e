//! The errors of scene reading and validation (a leaf: the parsers in `fields` and
//! the scene in the parent module both return it).

use strata_runtime::stack::StackError;
use strata_runtime::surface::SurfaceError;
use thiserror::Error;

/// Errors of scene reading and validation. Each names the field; [`Scene::from_file`](super::Scene::from_file)
/// adds the scene file ([`SceneError::InFile`]).
#[derive(Debug, Error)]

pub enum SceneError {
    #[error("cannot read scene {path}: {message}")]
    Io { path: String, message: String },
    #[error("not valid TOML: {0}")]
    Syntax(String),
    #[error("unknown key `{key}` (expected one of: {expected})")]
    UnknownKey { key: String, expected: String },
    #[error("missing field `{0}`")]
    Missing(String),
    #[error("field `{field}` must be {expected}")]
    WrongType { field: String, expected: String },
    #[error("field `{field}` is invalid: {reason}")]
    Invalid { field: String, reason: String },
    /// An error of the inline `[stack]` table.
    #[error("stack: {0}")]
    Stack(StackError),
    /// An error of the stack file named by `stack.file` (the error names the file).
    #[error(transparent)]
    StackFile(StackError),
    #[error(transparent)]
    Surface(#[from] SurfaceError),
    #[error(
        "{field} = \"{value}\": {what} {resolved} (paths in a scene are relative to the scene's directory, {dir}){hint}"
    )]
    MissingFile {
        field: &'static str,
        /// "no such file", or "a directory, not a file:".
        what: &'static str,
        value: String,
        resolved: String,
        dir: String,
        hint: &'static str,
    },
    /// Any of the above in a scene file.
    #[error("scene {path}: {error}")]
    InFile {
        path: String,
        error: Box<SceneError>,
    },
}

// passed on by the engine with `?` (engine/src/error.rs)
crate::error::passed_on!(SceneError);
