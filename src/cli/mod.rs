//! Command-line interface: argument definitions and one module per subcommand.

pub mod args;
pub mod asperity;
pub mod compare;
pub mod compliance;
pub mod conductance;
pub mod law;
#[cfg(feature = "mpi")]
pub mod ranks;
pub mod ratio_map;
pub mod solve;
pub mod stiffness;
pub mod study;
pub mod surface;
pub mod sweep;
pub mod table;

use anyhow::Result;

use crate::stdio::eprint_line;
use clap::{Parser, Subcommand};
use strata_runtime::resources::MemoryLimit;

/// strata: normal contact of rough surfaces on multi-layered elastic solids (SI units).
///
/// Paths given on the command line are relative to the current directory; paths inside
/// a scene or sweep file are relative to that file's directory. Outputs are replaced as
/// a whole (an existing output needs --force); tables built on demand go to one cache
/// (--cache-dir, else STRATA_CACHE_DIR, else $XDG_CACHE_HOME/strata or ~/.cache/strata).
#[derive(Debug, Parser)]
#[command(name = "strata", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// No progress bars and no log lines on stderr (warnings and errors are still printed).
    #[arg(long, short, global = true)]
    pub quiet: bool,
    /// Largest single allocation strata may attempt, e.g. 512M or 8G (powers of 1024;
    /// default: STRATA_MEMORY_LIMIT, else 75 % of the machine's memory). Larger
    /// problems fail with a message before allocating.
    #[arg(long, global = true, value_name = "BYTES")]
    pub memory_limit: Option<String>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print the surface compliance k_z(ρ) = S(ρ) − 1 of a stack as CSV (`rho_h,k_z`); with --thermal/--electrical the conduction compliance (`rho_h,S_th`).
    Compliance(compliance::Args),
    /// Constriction conductance of one isothermal spot of radius a on the stack: CSV `a,conductance,psi`.
    Conductance(conductance::Args),
    /// A paraboloidal asperity pressed into the stack: CSV `delta,a,force` (full solution).
    Asperity(asperity::Args),
    /// Normal and tangential stiffness of one contact disc of radius a on the stack: CSV `a,normal_stiffness,tangential_stiffness`.
    Stiffness(stiffness::Args),
    /// Surrogate tables of χ, ζ, g: build, info, check, export.
    Table(table::Args),
    /// Load curve of a rough contact described by a scene: DIR/curve.csv, curve.json, plots.
    Solve(solve::Args),
    /// Contact law p(g), A(g), dp/dg of a scene's interface as a table: CSV, JSON or an Abaqus PRESSURE-OVERCLOSURE=TABULAR block.
    Law(law::Args),
    /// N model, I model and BEM on the same scene(s): DIR/compare.csv, compare.md (differences, times), plots.
    Compare(compare::Args),
    /// Parametric sweep of scenes (grid or list, parallel, shardable): DIR/sweep.csv, plots; `sweep merge` joins shards.
    Sweep(sweep::Args),
    /// Accuracy–cost study of the solvers: DIR/report.md with tables, Pareto plots,
    /// defaults. A developers' command (it regenerates docs/accuracy-cost.md): runnable,
    /// not listed by `strata --help` (docs/guide/study.md).
    #[command(hide = true)]
    Study(study::Args),
    /// K_t/K_n of the shipped stacks (one asperity against a/h₁, rough surfaces against
    /// load) between Mindlin's and the thin layer's limits: DIR/ratio_*.csv, .svg. A
    /// developers' command (it makes docs/figures/tangential-ratio-*.svg).
    #[command(hide = true)]
    RatioMap(ratio_map::Args),
    /// Surfaces: `export` a scene's surface to .x3p (ISO 25178-72) or .npy; `info` on a file's sizes and statistics.
    Surface(surface::Args),
}

/// Runs the command under the memory limit `memory` (every solver's options carry it).
pub fn run(cli: Cli, memory: MemoryLimit) -> Result<()> {
    match cli.command {
        Command::Compliance(a) => compliance::run(a),
        Command::Conductance(a) => conductance::run(a),
        Command::Asperity(a) => asperity::run(a),
        Command::Stiffness(a) => stiffness::run(a),
        Command::Table(a) => table::run(a),
        Command::Solve(a) => solve::run(a, memory),
        Command::Law(a) => law::run(a, memory),
        Command::Compare(a) => compare::run(a, memory),
        Command::Sweep(a) => sweep::run(a, memory),
        Command::Study(a) => study::run(a, memory),
        Command::RatioMap(a) => ratio_map::run(a),
        Command::Surface(a) => surface::run(a, memory),
    }
}

/// Parses the process arguments, runs the command and maps the result to an exit code
/// (errors are printed once, as one chain, on stderr).
pub fn main() -> std::process::ExitCode {
    let args = Cli::parse();
    crate::progress::init(args.quiet);
    // The memory limit of every solve: --memory-limit, else STRATA_MEMORY_LIMIT, else
    // 75 % of the machine's memory (read here, at the command's edge, only).
    let memory = match &args.memory_limit {
        Some(m) => match MemoryLimit::parse(m, MemoryLimit::SET_BY_CALLER) {
            Ok(l) => l,
            Err(e) => {
                eprint_line(format_args!("error: --memory-limit: {e}"));
                return std::process::ExitCode::FAILURE;
            }
        },
        None => {
            let value = std::env::var(MemoryLimit::ENV_VAR).ok();
            match MemoryLimit::from_setting(value.as_deref()) {
                Ok(l) => l,
                Err(e) => {
                    eprint_line(format_args!("error: {e}"));
                    return std::process::ExitCode::FAILURE;
                }
            }
        }
    };
    // Every command's parallel loops run on this one pool, capped as `sweep --threads`.
    if let Err(e) = crate::threads::init_global_pool() {
        eprint_line(format_args!("error: {e}"));
        return std::process::ExitCode::FAILURE;
    }
    match run(args, memory) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprint_line(format_args!("error: {e:#}"));
            std::process::ExitCode::FAILURE
        }
    }
}
