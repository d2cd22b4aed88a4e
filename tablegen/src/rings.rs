//! Axisymmetric ring-load influence on a layered half-space: moved to the runtime
//! ([`strata_runtime::rings`], feature `capped`) with the capped asperity that uses it;
//! re-exported here under its former path.

pub use strata_runtime::rings::*;
