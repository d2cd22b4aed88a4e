//! Developers' tasks of strata, kept out of the user's `strata` binary and out of the
//! test binaries: `cargo run -p xtask -- TASK [ARGS]`.
//!
//! - `machine FILE`: probes the machine (CPU, cores, memory, OS, kernel, compiler, commit,
//!   load average) and writes it as TOML for `strata study --machine FILE`, whose report
//!   states the machine it ran on (`docs/accuracy-cost.md`).
//! - `grid-convergence`: the BEM's grid-convergence table of `docs/validation.md` (the
//!   reference surface of `tests/reference` on 64² … 1024² grids, against 1024²); run it
//!   with `--release` (the 1024² grid is slow in the dev profile).

use anyhow::{Result, bail};

mod grid;
mod machine;

const USAGE: &str = "usage: cargo run -p xtask -- machine FILE | grid-convergence";

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>()
        .as_slice()
    {
        ["machine", file] => machine::write(std::path::Path::new(file)),
        ["grid-convergence"] => grid::table(),
        _ => bail!("{USAGE}"),
    }
}
