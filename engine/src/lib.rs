//! # strata-engine: scenes, their solution and the sampled contact law
//!
//! The library every front end of strata stands on — the `strata` command, the Python
//! package and the C ABI: scenes (`scene`: one rough-contact case, read from TOML and
//! validated), the engine that solves a scene with the model it names (`engine`), the
//! contact law sampled from a scene (`sampled_law`) or from inputs in memory
//! (`law_build`, the C ABI's), the spot sums of conductance
//! (`spots`), the table and response caches (`cache`, `asperity_table`), and progress
//! reporting (`progress`, `stdio`). The physics lives below it, in `strata-runtime`
//! (light, embeddable), `strata-tablegen` (Fredholm solves, table builds) and
//! `strata-bem` (the full-field solver); clap, plots and output sets live above it, in
//! the `strata` command.

pub mod asperity_table;
pub mod cache;
pub mod contact_law;
pub mod effects;
pub mod engine;
pub mod error;
pub mod friction_card;
pub mod law_build;
pub mod number;
pub mod progress;
pub mod sampled_law;
pub mod scene;
pub mod setup;
pub mod solution;
pub mod spots;
pub mod stdio;
