//! # strata-tablegen
//!
//! The offline half of strata: full Fredholm solves of the axisymmetric asperity on
//! a layered solid and the generation of surrogate tables (χ, ζ, g) for the runtime.
//!
//! # Tests
//! Unit tests whose name starts with `slow_` are the slow tier (table builds with
//! direct-quadrature checks, the dense a/h = 1000 Fredholm solve): `cargo test`
//! and CI run them; skip them while iterating with
//! `cargo test -p strata-tablegen -- --skip slow_`. Tables that several tests need
//! are built once per test binary (`std::sync::OnceLock` fixtures).
//!
//! Library code never calls `unwrap`/`expect` (user-controlled data must come back as
//! typed errors); the lint below enforces it outside tests.

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub use strata_runtime as runtime;

pub mod asperity;
pub mod fredholm;
pub mod kernel;
#[cfg(test)]
mod plastic_asperity;
pub mod psi_table;
pub mod spot;
pub mod spot_pair;
pub mod stiffness;
pub mod stiffness_table;

pub mod approx;
mod error;
mod progress;
pub mod tablebuild;
pub mod tablecheck;
