//! The error of table building and checking (a leaf: `tablebuild` and `tablecheck`
//! both return it).

use strata_runtime::table::TableError;
use thiserror::Error;

use crate::approx::ApproxError;

/// Errors of table building and checking.
#[derive(Debug, Error)]
pub enum BuildError {
    #[error(transparent)]
    Approx(#[from] ApproxError),
    #[error(transparent)]
    Table(#[from] TableError),
    #[error("invalid build option `{field}`: {reason}")]
    Option { field: &'static str, reason: String },
    #[error("cannot build a table for a homogeneous stack: chi = zeta = 1 and g = 0 exactly")]
    Homogeneous,
    #[error("cache directory {path}: {message}")]
    Cache { path: String, message: String },
    /// A measured error above the table's stated tolerance.
    #[error(
        "table refused: measured {what} error {measured:.3e} exceeds the stated tolerance {tolerance:.3e}{hint}"
    )]
    Tolerance {
        what: &'static str,
        measured: f64,
        tolerance: f64,
        hint: String,
    },
}
