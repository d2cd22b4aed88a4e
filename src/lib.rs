//! # strata: the command's library
//!
//! Scenes (`scene`: the TOML description of one rough-contact case), the engine that
//! solves them with the model they name (`engine`), sweeps, the accuracy–cost study,
//! plots and the command-line front end (`cli`). The `strata` binary is a thin wrapper
//! over [`cli::main`]; the physics lives in `strata-runtime` (light, embeddable),
//! `strata-tablegen` (Fredholm solves, table builds) and `strata-bem` (the full-field
//! solver).

pub mod asperity_table;
pub mod cache;
pub mod cli;
pub mod csv_out;
pub mod engine;
pub mod output_set;
pub mod plot;
pub mod progress;
pub mod sampled_law;
pub mod scene;
pub mod spots;
pub mod stdio;
pub mod study;
pub mod threads;
