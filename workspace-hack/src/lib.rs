//! No code: see `Cargo.toml`. This crate only pins the features of host dependencies
//! when CI checks `strata-runtime` without its default features.
