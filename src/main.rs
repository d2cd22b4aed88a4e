//! The `strata` command: a thin wrapper over the `strata` library ([`strata::cli`]).

use std::process::ExitCode;

fn main() -> ExitCode {
    strata::cli::main()
}
