//! # strata-tablegen
//!
//! The offline half of strata: full Fredholm solves of the axisymmetric asperity on
//! a layered solid and the generation of surrogate tables (χ, ζ, g) for the runtime.

pub use strata_runtime as runtime;

pub mod asperity;
pub mod fredholm;
pub mod kernel;

pub mod approx;
pub mod tablebuild;
