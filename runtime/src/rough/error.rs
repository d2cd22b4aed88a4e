//! Errors of the rough-contact solvers: one type per stage, gathered in [`RoughError`].

use thiserror::Error;

use super::params::raise_advice;
use crate::resources::ResourceError;

/// Errors of the rough-contact solvers.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum RoughError {
    #[error("no summits: the surface has no asperity to load")]
    NoSummits,
    #[error("{field}: value {value} out of range: {reason}")]
    LoadOutOfRange {
        field: &'static str,
        value: f64,
        reason: String,
    },
    #[error("non-finite value in {0}")]
    NonFinite(&'static str),
    #[error("{field}: expected {expected} values (one per summit), found {found}")]
    Length {
        field: &'static str,
        expected: usize,
        found: usize,
    },
    /// A step refused before it is solved: the N model's contact areas at its approach
    /// sum to more than the nominal area (physically impossible; the I model, whose
    /// interactions shrink contacts, is not started there either).
    #[error(
        "{}the N model's contact areas sum to A/A₀ = {} > 1 at δ = {delta:e} m (more than \
         the nominal area: physically impossible, the asperity models do not hold there); use \
         model.kind = \"bem\" for this load",
        if *interacting { "I model not started: " } else { "N model: " },
        if *area < 1e4 { format!("{area:.3}") } else { format!("{area:.3e}") }
    )]
    AreaAboveNominal {
        delta: f64,
        area: f64,
        interacting: bool,
    },
    #[error(transparent)]
    Independent(#[from] IndependentError),
    #[error(transparent)]
    FarField(#[from] FarFieldError),
    #[error(transparent)]
    Newton(#[from] NewtonError),
    #[error(transparent)]
    Pressure(#[from] PressureError),
    #[error(transparent)]
    Memory(#[from] ResourceError),
    /// Stopped through the solve's [`Cancel`](crate::cancel::Cancel) token.
    #[error(transparent)]
    Cancelled(#[from] crate::cancel::Cancelled),
}

/// The N model (single-asperity inversions).
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum IndependentError {
    #[error(
        "N model: asperity {index}: cannot solve ζ(a)a²/R = δ for a (δ = {delta}, R = {radius})"
    )]
    NoRoot {
        index: usize,
        delta: f64,
        radius: f64,
    },
}

/// The far-field model of the interaction kernel.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum FarFieldError {
    #[error(
        "I model far field: contact radii keep leaving the far-field model's range (last bound A = {bound:e} m, \
         radius {radius:e} m) after {attempts} rebuilds"
    )]
    Bound {
        bound: f64,
        radius: f64,
        attempts: usize,
    },
    #[error("I model far field: the interaction grid could not be planned: {0}")]
    Grid(String),
}

/// The active-set Newton method of the I model.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum NewtonError {
    /// Stopped through the solve's [`Cancel`](crate::cancel::Cancel) token.
    #[error(transparent)]
    Cancelled(#[from] crate::cancel::Cancelled),
    #[error(
        "I model: did not converge at δ = {delta:e} m: KKT residual {residual:e} (tolerance {tolerance:e}) \
         after {newton_steps} Newton steps; to accept it, raise {advice}",
        advice = raise_advice("kkt_tolerance", true)
    )]
    NotConverged {
        delta: f64,
        residual: f64,
        tolerance: f64,
        newton_steps: usize,
    },
    #[error(
        "I model: stalled at δ = {delta:e} m: {what} budget exhausted ({used} of {limit}; KKT residual \
         {residual:e}); raise {advice} or reduce the load step",
        advice = raise_advice(.field, true)
    )]
    Budget {
        delta: f64,
        what: &'static str,
        field: &'static str,
        used: String,
        limit: String,
        residual: f64,
    },
    #[error("I model: non-finite value in the {0}")]
    NonFinite(&'static str),
    #[error(
        "I model: no asperity in contact at δ = {delta:e} m although summits are loaded by up to \
         {interference:e} m (no such equilibrium exists): interferences of that size on summit \
         radii up to {radius:e} m leave the model's numerical range"
    )]
    NoContact {
        delta: f64,
        interference: f64,
        radius: f64,
    },
    #[error("I model: the Jacobian of the stationarity system is singular at δ = {delta:e} m")]
    Singular { delta: f64 },
    #[error(
        "I model: at δ = {delta:e} m a contact radius passes {cap:e} m, half the periodic cell: the \
         contacts cover the sample and the asperity models do not hold there (with the mean \
         displacement removed, as the BEM removes it, their energy has no minimum); use \
         model.kind = \"bem\" for this load"
    )]
    CoversCell { delta: f64, cap: f64 },
}

/// The pressure-controlled driver.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum PressureError {
    #[error("load.mean_pressures: value {target:e} Pa out of range: {reason}")]
    OutOfRange { target: f64, reason: String },
    #[error(
        "load.mean_pressures: no convergence of the search for {target:e} Pa after \
         {iterations} solves (last δ = {delta:e} m); raise {advice}",
        advice = raise_advice("max_pressure_iterations", true)
    )]
    NoConvergence {
        target: f64,
        iterations: usize,
        delta: f64,
    },
}
