//! Errors of the boundary-element solver.

use strata_runtime::resources::ResourceError;
use thiserror::Error;

/// Errors of the boundary-element solver. Each names the offending input.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BemError {
    #[error(
        "heights: the grid must be at least 4×4 (2×2 for a non-periodic sample), got {rows}×{cols}"
    )]
    Grid { rows: usize, cols: usize },
    #[error(
        "heights: a grid of {rows} rows cannot be cut into slabs for {ranks} ranks (at least one row each); run on at most {rows} ranks"
    )]
    Ranks { rows: usize, ranks: usize },
    /// A distributed solve stopped because another rank failed (that rank reports why).
    #[error("{what} failed on another rank (its message says why)")]
    OtherRank { what: String },
    #[error("heights[{row}, {col}] = {value} is not finite")]
    NonFiniteHeight { row: usize, col: usize, value: f64 },
    #[error("heights: the surface is flat (zero RMS height); there is no rough contact to solve")]
    FlatSurface,
    #[error(
        "heights: the largest |height| {0:e} m is too large (the RMS overflows); heights are in metres"
    )]
    HeightRange(f64),
    #[error("size: the sample side {what} must be finite and > 0 (m), got {value}")]
    Size { what: &'static str, value: f64 },
    #[error("E*₁ must be finite and > 0 (Pa), got {0}")]
    Modulus(f64),
    #[error("the uniform-mode compliance C₀ must be finite and ≥ 0 (m/Pa), got {0}")]
    UniformCompliance(f64),
    #[error("options: tolerance must be finite and in (0, 1), got {0}")]
    Tolerance(f64),
    #[error("options: max_iterations must be ≥ 1")]
    MaxIterations,
    #[error("load: {what} = {value} is invalid: {reason}")]
    Load {
        what: &'static str,
        value: f64,
        reason: String,
    },
    #[error("resample: target grid must be even and ≥ 4, got {0}")]
    Resample(usize),
    #[error(
        "the stack's compliance S(|k| = {k:e} 1/m) = {s} is not finite and non-negative; check the stack"
    )]
    Kernel { k: f64, s: f64 },
    #[error(
        "non-periodic influence coefficients: {0} (the Hankel transform of the stack's compliance)"
    )]
    Influence(String),
    #[error("initial pressure: expected {expected} finite non-negative values, got {got}")]
    Initial { expected: usize, got: usize },
    #[error(
        "not converged after {iterations} iterations (error {error:e} > tolerance {tolerance:e}); raise \
         [solver] bem_max_iterations or bem_tolerance in the scene (Python: Scene(..., \
         solver={{\"bem_max_iterations\": ...}}); Rust: BemOptions::max_iterations, tolerance)"
    )]
    NotConverged {
        iterations: usize,
        error: f64,
        tolerance: f64,
    },
    #[error("the solution became non-finite at iteration {0} (ill-posed load or stack?)")]
    NonFinite(usize),
    /// Stopped through the solver's cancellation token ([`crate::BemSolver::with_cancel`]).
    #[error(transparent)]
    Cancelled(#[from] strata_runtime::cancel::Cancelled),
    /// The message includes the limit's; no `source` (a chain would print it twice).
    #[error("BEM: {0}")]
    Memory(ResourceError),
    #[error("BEM: internal FFT error: {0}")]
    Fft(String),
    /// The conduction set-up (physics.md §6.2) is invalid.
    #[error("conduction: {0}")]
    Conduction(String),
    /// A conduction operator given as a spectral compliance C(|k|) on a non-periodic
    /// sample (only the bodies define the free-boundary kernel).
    #[error(
        "conduction: a compliance C(|k|) defines the operator of a periodic cell only; a \
         non-periodic sample takes the bodies (ConductanceSolver::new)"
    )]
    ConductionNonPeriodic,
    #[error("cannot read {path}: {message}")]
    Read { path: String, message: String },
    #[error("cannot write {path}: {message}")]
    Write { path: String, message: String },
}

impl From<ResourceError> for BemError {
    fn from(e: ResourceError) -> Self {
        BemError::Memory(e)
    }
}

impl From<strata_runtime::fft::FftError> for BemError {
    fn from(e: strata_runtime::fft::FftError) -> Self {
        BemError::Fft(e.to_string())
    }
}
