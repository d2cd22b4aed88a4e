//! # strata-runtime
//!
//! The light, embeddable half of strata: material stacks, the layered surface
//! compliance S(ρ), and (later) surrogate tables and the rough-contact solvers.
//! It has no dense linear-algebra dependency.
//!
//! Units are SI throughout: metres, pascals, newtons; wavenumbers ρ in 1/m.
//!
//! Library code never calls `unwrap`/`expect` (user-controlled data must come back as
//! typed errors); the lint below enforces it outside tests.

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod compliance;
#[cfg(feature = "spectral")]
pub mod fft;
pub mod hash;
pub mod interface;
pub mod law;
pub mod output;
pub mod resources;
pub mod rough;
pub mod stack;
pub mod summits;
pub mod surface;
pub mod table;

pub use compliance::Compliance;
pub use stack::{Base, Layer, Stack, StackError};
