//! # strata: the command's library
//!
//! The command-line front end (`cli`), sweeps, the accuracy–cost study, plots and output
//! sets, over the engine crate `strata-engine` (scenes, the engine that solves them, the
//! sampled contact law; re-exported here under the same module names). The `strata` binary is a thin wrapper
//! over [`cli::main`]; the physics lives in `strata-runtime` (light, embeddable),
//! `strata-tablegen` (Fredholm solves, table builds) and `strata-bem` (the full-field
//! solver).

pub mod cli;
pub mod csv_out;
pub mod output_set;
pub mod plot;
pub mod study;
pub mod threads;

pub use strata_engine::{
    asperity_table, cache, contact_law, effects, engine, progress, sampled_law, scene, solution,
    spots, stdio,
};
