//! `strata table build|info|check|export`: surrogate tables of χ, ζ, g and S
//! (physics.md §4; format and interpolation in `strata_runtime::table`).
//!
//! * `build STACK.toml --out FILE [--vary LAYER:LO:HI:N] [--force]` builds a table (a
//!   family when `--vary` is given: LAYER is a layer number ≥ 2 or `base`, LO/HI the
//!   range of E_LAYER/E₁, N log-spaced members), in parallel, with progress on stderr.
//!   An existing FILE is kept unless `--force`; the file is written as an output set
//!   (staged, then renamed into place under a lock).
//!   The header's build time is SOURCE_DATE_EPOCH when set (else now): with it fixed,
//!   a rebuild reproduces the file byte for byte.
//! * `info FILE` prints the header.
//! * `check FILE [--points N --seed S --tol T]` compares interpolated values (and the
//!   far field of g beyond the tabulated range) with fresh direct solves at N random
//!   off-grid points, prints the max errors and fails (exit 1) when one exceeds the
//!   table's stated tolerance (or T).
//!
//! `build` fails likewise (exit 1, no file written) when the measured far-field or
//! interpolation error exceeds `--tol` (default 1e-4), naming both.
//! * `export FILE --npy DIR [--force]` writes every array as .npy (one output set).

use std::io::{self, Write};
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use strata_runtime::stack::NoSurface;
use strata_runtime::table::{Table, Vary};
use strata_runtime::{Bodies, Solid, Stack};
use strata_tablegen::tablebuild::{self, Bars, BuildOptions};

pub use crate::asperity_table::{approx_paraboloid, approx_profile, build_time, law_for_stack};
use crate::output_set::{OutputSet, refuse_inputs};
use crate::progress;
use crate::stdio;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub command: Sub,
}

#[derive(Debug, clap::Subcommand)]
pub enum Sub {
    /// Build a table for a stack (or a family of stacks).
    Build(BuildArgs),
    /// Print a table's header.
    Info {
        /// Table file.
        file: PathBuf,
    },
    /// Compare a table with direct solves at random off-grid points.
    Check {
        /// Table file.
        file: PathBuf,
        /// Number of random points.
        #[arg(long, default_value_t = 1000)]
        points: usize,
        /// Seed of the random points.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Tolerance to check against (default: the one stated in the table).
        #[arg(long)]
        tol: Option<f64>,
    },
    /// Write the table's arrays as .npy files.
    Export {
        /// Table file.
        file: PathBuf,
        /// Output directory.
        #[arg(long)]
        npy: PathBuf,
        /// Replace the outputs of a non-empty directory.
        #[arg(long)]
        force: bool,
    },
}

#[derive(Debug, clap::Args)]
pub struct BuildArgs {
    /// Stack file (TOML).
    pub stack: PathBuf,
    /// Output table file.
    #[arg(long)]
    pub out: PathBuf,
    /// A second elastic body (stack file): the table is of the pair, its two
    /// compliances added (physics.md §6.1); no family axis.
    #[arg(long)]
    pub counterface: Option<PathBuf>,
    /// Family axis `LAYER:LO:HI:N` (LAYER = layer number >= 2 or `base`; LO, HI =
    /// modulus ratios to layer 1; N members, log-spaced).
    #[arg(long)]
    pub vary: Option<String>,
    /// Nodes on the a/h1 axis (1e-3 … 1e3, log-spaced).
    #[arg(long, default_value_t = 97)]
    pub nx: usize,
    /// Nodes on the w axis of g.
    #[arg(long, default_value_t = 49)]
    pub nw: usize,
    /// Random points for the interpolation error stored in the header (0: skip).
    #[arg(long, default_value_t = 1000)]
    pub check_points: usize,
    /// Overwrite an existing table file.
    #[arg(long)]
    pub force: bool,
    /// Stated tolerance stored in the table: chi, zeta (relative) and g (of
    /// (4/3)a^3/r, tabulated and far field); the build fails above it.
    #[arg(long, default_value_t = strata_runtime::table::DEFAULT_TOLERANCE)]
    pub tol: f64,
    /// Farthest join of the tabulated g and its far field, in units of H (the total
    /// layer depth; the join starts at 20 H and doubles while the far field misses the
    /// tolerance): raise it when the build says so.
    #[arg(long, default_value_t = BuildOptions::default().far_max)]
    pub far_max: f64,
}

/// A tolerance given on the command line: in (0, 1] (relative errors; above 1 a
/// table would state, and a check would pass, anything).
fn check_tol(tol: f64) -> Result<f64> {
    if !(tol > 0.0 && tol <= 1.0) {
        bail!("--tol must be in (0, 1] (a relative error), got {tol:e}");
    }
    Ok(tol)
}

/// `--far-max`: finite and ≥ 20 (the join starts at 20 H).
fn check_far_max(far_max: f64) -> Result<f64> {
    if !(far_max.is_finite() && far_max >= 20.0) {
        bail!(
            "--far-max must be a finite number ≥ 20 (units of H, the total layer depth), got {far_max}"
        );
    }
    Ok(far_max)
}

/// Parses `LAYER:LO:HI:N`.
pub fn parse_vary(s: &str) -> Result<(Vary, f64, f64, usize)> {
    let parts: Vec<&str> = s.split(':').map(str::trim).collect();
    if parts.len() != 4 {
        bail!("--vary: `{s}` must be LAYER:LO:HI:N (e.g. 2:0.1:10:21 or base:0.5:2:9)");
    }
    let vary = if parts[0].eq_ignore_ascii_case("base") {
        Vary::Base
    } else {
        let i: usize = parts[0].parse().map_err(|_| {
            anyhow::anyhow!(
                "--vary: LAYER `{}` must be a layer number or `base`",
                parts[0]
            )
        })?;
        if i < 2 {
            bail!("--vary: LAYER must be >= 2 (ratios are to layer 1), got {i}");
        }
        Vary::Layer(i)
    };
    let num = |t: &str, what: &str| -> Result<f64> {
        let v: f64 = t
            .parse()
            .map_err(|_| anyhow::anyhow!("--vary: {what} `{t}` is not a number"))?;
        if !(v.is_finite() && v > 0.0) {
            bail!("--vary: {what} must be a finite ratio > 0, got `{t}`");
        }
        Ok(v)
    };
    let (lo, hi) = (num(parts[1], "LO")?, num(parts[2], "HI")?);
    if hi <= lo {
        bail!("--vary: need LO < HI, got {lo} and {hi}");
    }
    let n: usize = parts[3]
        .parse()
        .map_err(|_| anyhow::anyhow!("--vary: N `{}` must be a positive integer", parts[3]))?;
    Ok((vary, lo, hi, n))
}

fn load(file: &std::path::Path) -> Result<Table> {
    Table::load(file).with_context(|| format!("loading table {}", file.display()))
}

pub fn run(a: Args) -> Result<()> {
    match a.command {
        Sub::Build(b) => {
            let mut stack = Bodies::from_toml_file(&b.stack)?;
            let mut inputs = vec![("the stack file".to_string(), b.stack.clone())];
            if let Some(c) = &b.counterface {
                crate::cli::args::refuse_two_counterfaces(&stack, &b.stack, c)?;
                stack = stack
                    .first
                    .against(Stack::from_toml_file(c).context("--counterface")?);
                inputs.push(("the counterface stack file".into(), c.clone()));
            }
            let family = b.vary.as_deref().map(parse_vary).transpose()?;
            refuse_inputs("--out", &b.out, &inputs)?;
            let set = OutputSet::file("--out", &b.out, b.force)?;
            let opts = BuildOptions {
                nx: b.nx,
                nw: b.nw,
                family,
                check_points: b.check_points,
                build_time: build_time()?,
                progress: true,
                bars: Some(Bars(progress::raw_bar)),
                tolerance: check_tol(b.tol)?,
                far_max: check_far_max(b.far_max)?,
                ..BuildOptions::default()
            };
            let t0 = std::time::Instant::now();
            let table = tablebuild::build(&stack, &opts)?;
            let name = b
                .out
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            set.write(&name, &table.to_bytes()?)?;
            set.commit()?;
            progress::log(format!(
                "wrote {} in {:.1} s",
                b.out.display(),
                t0.elapsed().as_secs_f64()
            ));
            stdio::print(|o| print_info(&table, o))?;
        }
        Sub::Info { file } => {
            let table = load(&file)?;
            stdio::print(|o| print_info(&table, o))?;
        }
        Sub::Check {
            file,
            points,
            seed,
            tol,
        } => {
            let table = load(&file)?;
            if points == 0 {
                bail!("--points must be at least 1");
            }
            let tol = match tol {
                Some(t) => check_tol(t)?,
                None => table.header.tolerance,
            };
            let bar = progress::bar(points as u64, "table check: direct solves");
            let e = tablebuild::check_with(&table, points, seed, bar.bar())?;
            stdio::print(|o| {
                writeln!(
                    o,
                    "points,seed,max_rel_err_chi,max_rel_err_zeta,max_err_g_over_4a3_3r,max_err_g_far_over_4a3_3r,tolerance"
                )?;
                writeln!(
                    o,
                    "{},{},{:e},{:e},{:e},{:e},{:e}",
                    e.points, e.seed, e.chi, e.zeta, e.g, e.far, tol
                )
            })?;
            if let Some((what, measured)) = e.exceeds(tol) {
                bail!(
                    "table check failed for {}: measured {what} error {measured:.3e} exceeds the tolerance {tol:.3e}",
                    file.display()
                );
            }
        }
        Sub::Export { file, npy, force } => {
            let table = load(&file)?;
            let set = OutputSet::dir("--npy", &npy, force)?;
            let files = strata_runtime::table::export::export_npy(&table, set.root())?;
            set.commit()?;
            stdio::print(|o| {
                for f in files {
                    let name = f.file_name().map(PathBuf::from).unwrap_or(f);
                    writeln!(o, "{}", npy.join(name).display())?;
                }
                Ok(())
            })?;
        }
    }
    Ok(())
}

/// What `table info` prints: the header of `t` in words.
fn print_info(t: &Table, o: &mut dyn Write) -> io::Result<()> {
    let h = &t.header;
    writeln!(o, "format version: {}", h.format_version)?;
    writeln!(o, "strata version: {}", h.strata_version)?;
    writeln!(o, "build time: {} (s since Unix epoch)", h.build_time)?;
    writeln!(
        o,
        "stack: {}",
        h.stack.name.as_deref().unwrap_or("(unnamed)")
    )?;
    if let Some(c) = h.counterface.stack() {
        writeln!(
            o,
            "counterface: {} (an elastic second body: the table is of the pair, E* = {:e} Pa; \
             file format version {})",
            c.name.as_deref().unwrap_or("(unnamed)"),
            h.contact_modulus(),
            strata_runtime::table::codec::PAIR_VERSION
        )?;
    }
    for line in Solid::bodies::<NoSurface>(h).to_toml_string().lines() {
        writeln!(o, "  {line}")?;
    }
    match h.family {
        Some(f) => writeln!(
            o,
            "family: {} modulus ratio to layer 1 from {} to {}, {} members (log grid)",
            f.vary,
            f.ratio.lo.exp(),
            f.ratio.hi.exp(),
            f.ratio.n
        ),
        None => writeln!(o, "family: none (single stack)"),
    }?;
    writeln!(
        o,
        "a/h1: {:e} … {:e}, {} nodes (log grid)",
        h.x.lo.exp(),
        h.x.hi.exp(),
        h.x.n
    )?;
    writeln!(
        o,
        "g: w = asinh(sqrt((r-a)/h1)) in [0, {:.4}], {} nodes; far field beyond r - a = {:.1} H with {} correction terms (error {:.2e} of (4/3)a^3/r)",
        h.w.hi,
        h.w.n,
        h.top_thickness().unwrap_or(1.0) * h.w.hi.sinh().powi(2) / h.total_thickness(),
        h.far_terms,
        h.far_field_error
    )?;
    writeln!(o, "stated tolerance: {:e}", h.tolerance)?;
    writeln!(
        o,
        "S: rho*h1 {:e} … {:e}, {} nodes (log grid)",
        h.s.lo.exp(),
        h.s.hi.exp(),
        h.s.n
    )?;
    match h.interp_error {
        Some(e) => writeln!(
            o,
            "interpolation error at {} random points (seed {}): chi {:.2e}, zeta {:.2e} (relative), g {:.2e}, far field {:.2e} (of (4/3)a^3/r)",
            e.points, e.seed, e.chi, e.zeta, e.g, e.far
        ),
        None => writeln!(o, "interpolation error: not measured"),
    }
}
