//! `strata asperity STACK.toml --radius R --delta LIST [--model full|approx]
//! [--plot out.svg] [--profile profile.csv]`: a paraboloidal asperity of radius R
//! pressed by δ into the layered solid (physics.md §3, the paper's full solution).
//!
//! Prints CSV on stdout with the header `delta,a,force` (m, m, N; force positive in
//! compression), one row per δ, every value in shortest round-trip form. `--plot`
//! draws force against approach with the Hertz curve for the top material (E*₁).
//! `--profile FILE` also writes `delta,r,pressure,displacement` (m, m, Pa, m) on
//! 0 ≤ r ≤ 3a for every δ > 0. Existing `--plot`/`--profile` files are kept unless
//! `--force`. `--tangential` adds the column `tangential_stiffness` (N/m): the
//! full-stick stiffness of the contact disc of radius a at that δ
//! ([`strata_tablegen::stiffness`]).

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use strata_runtime::{Bodies, Solid};
use strata_tablegen::asperity::{Asperity, Options};

use crate::csv_out::{self, num};
use crate::output_set::{OutputSet, refuse_inputs};
use crate::plot::{self, PlotSpec, Series, Style};

/// Which solution to compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Model {
    /// The full Fredholm solution.
    Full,
    /// The second-order approximation (physics.md §4) from a surrogate table
    /// (`--table FILE`, else this stack's table, built once and cached).
    Approx,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Stack file (TOML).
    pub stack: PathBuf,
    /// Asperity radius of curvature R (m), > 0.
    #[arg(long, allow_hyphen_values = true)]
    pub radius: f64,
    /// Approaches δ (m, ≥ 0): a list `1e-7,2e-7`, or `LO:HI:N` (N linearly spaced
    /// values) or `LO:HI:N:log` (N log-spaced values).
    #[arg(long, allow_hyphen_values = true)]
    pub delta: String,
    /// Solution model.
    #[arg(long, value_enum, default_value_t = Model::Full)]
    pub model: Model,
    /// Table for `--model approx` (a family table serves any member stack; other
    /// stacks are refused). Without it the stack's table is built once into the table
    /// cache.
    #[arg(long)]
    pub table: Option<PathBuf>,
    /// Table cache (default: STRATA_CACHE_DIR, else $XDG_CACHE_HOME/strata or
    /// ~/.cache/strata).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    /// Draw force against approach (with Hertz) to this file (.svg or .png).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Write pressure and displacement profiles to this CSV file.
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Overwrite existing --plot and --profile files.
    #[arg(long)]
    pub force: bool,
    /// A second elastic body (stack file) in place of the rigid flat: the asperity is
    /// pressed against it, the two compliances add (physics.md §6.1).
    #[arg(long)]
    pub counterface: Option<PathBuf>,
    /// Hardness H (Pa) of the asperity's tip: the pressure is capped at H (an
    /// elastic–perfectly plastic tip, physics.md §6.3), solved on rings in physical
    /// space; prints `delta,a,force,a_plastic` (a_plastic: the radius of the core at H).
    #[arg(long, allow_hyphen_values = true)]
    pub hardness: Option<f64>,
    /// Also print the tangential stiffness Q/δ_t (N/m) of the contact disc in full
    /// stick at each δ, normal–tangential coupling ignored (`strata stiffness`):
    /// header `delta,a,force,tangential_stiffness`.
    #[arg(long, conflicts_with = "hardness")]
    pub tangential: bool,
}

/// K_t (N/m) of the full-stick disc at each row's contact radius (0 where a = 0), by
/// the Fredholm solves of [`strata_tablegen::stiffness`].
fn tangential_stiffness(
    stack: &Bodies,
    rows: &[(f64, f64, f64)],
    file: &std::path::Path,
) -> Result<Vec<f64>> {
    let solver = strata_tablegen::stiffness::Stiffness::new(stack);
    rows.iter()
        .map(|&(_, r, _)| {
            if r > 0.0 {
                solver.at(r).map(|d| d.tangential).map_err(|e| {
                    anyhow::anyhow!(
                        "stack file {}: tangential stiffness at a = {r:e} m: {e}",
                        file.display()
                    )
                })
            } else {
                Ok(0.0)
            }
        })
        .collect()
}

pub fn run(a: Args) -> Result<()> {
    let stack = super::args::bodies(&a.stack, a.counterface.as_deref())?;
    if !(a.radius.is_finite() && a.radius > 0.0) {
        bail!("--radius: must be positive and finite, got {}", a.radius);
    }
    let deltas = super::args::parse_list("--delta", &a.delta)?;
    if let Some(bad) = deltas.iter().find(|d| **d < 0.0) {
        bail!("--delta: values must be >= 0, got {bad}");
    }
    if a.table.is_some() && a.model == Model::Full {
        bail!("--table is only used with --model approx");
    }
    if let Some(p) = &a.plot {
        let ext = p
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if !matches!(ext.as_deref(), Some("svg" | "png")) {
            bail!("--plot {}: extension must be .svg or .png", p.display());
        }
    }
    let mut inputs = vec![("the stack file".to_string(), a.stack.clone())];
    inputs.extend(
        a.counterface
            .iter()
            .map(|c| ("the counterface stack file".to_string(), c.clone())),
    );
    inputs.extend(a.table.iter().map(|t| ("the table".to_string(), t.clone())));
    for (flag, out) in [("--plot", &a.plot), ("--profile", &a.profile)] {
        if let Some(p) = out {
            refuse_inputs(flag, p, &inputs)?;
        }
    }
    let plot_set = a
        .plot
        .as_ref()
        .map(|p| OutputSet::file("--plot", p, a.force))
        .transpose()?;
    let profile_set = a
        .profile
        .as_ref()
        .map(|p| OutputSet::file("--profile", p, a.force))
        .transpose()?;
    if let Some(h) = a.hardness {
        if a.model == Model::Approx {
            bail!(
                "--hardness: the capped asperity is solved in full (--model full); its tables are not built yet"
            );
        }
        if a.profile.is_some() || a.plot.is_some() {
            bail!("--hardness: --profile and --plot are not written for the capped asperity yet");
        }
        if let Some(why) = strata_runtime::rough::plastic::hardness_problem(h) {
            bail!("--hardness: {why}");
        }
        let s = strata_runtime::rough::plastic::asperity::PlasticAsperity::new(&stack, h)
            .context("--hardness")?;
        // Where the elastic (Fredholm) asperity's pressure stays at or below H nothing
        // flows: its solution is the capped one (so H → ∞ is `--model full` exactly).
        let elastic = Asperity::new(&stack, Options::default())?;
        let mut rows = Vec::with_capacity(deltas.len());
        let bar = approach_bar(&stack, deltas.len());
        for &d in &deltas {
            bar.set_message(format!("asperity: delta = {d:e} m"));
            if d == 0.0 {
                rows.push([0.0, 0.0, 0.0, 0.0]);
                bar.inc();
                continue;
            }
            let e = elastic
                .paraboloid_at_delta(d, a.radius)
                .with_context(|| format!("solving delta = {d:e} m"))?;
            let r: Vec<f64> = (0..=200).map(|i| e.a * i as f64 / 200.0).collect();
            let peak = e.pressure(&r).into_iter().fold(0.0, f64::max);
            if peak <= h {
                rows.push([d, e.a, e.force, 0.0]);
                bar.inc();
                continue;
            }
            let c = s
                .at_delta(d, a.radius)
                .with_context(|| format!("solving delta = {d:e} m"))?;
            rows.push([d, c.a, c.force, c.a_plastic]);
            bar.inc();
        }
        drop(bar);
        crate::stdio::print(|o| {
            csv_out::write(
                o,
                ["delta", "a", "force", "a_plastic"],
                rows.iter().map(|r| r.map(num)),
            )
            .map_err(Into::into)
        })?;
        return Ok(());
    }
    let (solver, approx) = match a.model {
        Model::Full => (Some(Asperity::new(&stack, Options::default())?), None),
        Model::Approx => (
            None,
            Some(super::table::law_for_stack(
                &stack,
                a.table.as_deref(),
                a.cache_dir.as_deref(),
            )?),
        ),
    };
    let mut rows = Vec::with_capacity(deltas.len());
    let mut profile_rows = Vec::new();
    let bar = approach_bar(&stack, deltas.len());
    for &d in &deltas {
        bar.set_message(format!("asperity: delta = {d:e} m"));
        if let Some(law) = &approx {
            let (ca, force) = super::table::approx_paraboloid(law, d, a.radius)
                .with_context(|| format!("solving delta = {d:e} m"))?;
            if a.profile.is_some() && ca > 0.0 {
                for i in 0..=60 {
                    let r = 3.0 * ca * i as f64 / 60.0;
                    let (p, u) = super::table::approx_profile(law, ca, a.radius, r);
                    profile_rows.push((d, r, p, u));
                }
            }
            rows.push((d, ca, force));
            bar.inc();
            continue;
        }
        let Some(solver) = &solver else {
            bail!("internal error: no solver for --model full");
        };
        let s = solver
            .paraboloid_at_delta(d, a.radius)
            .with_context(|| format!("solving delta = {d:e} m"))?;
        if a.profile.is_some() && s.a > 0.0 {
            let r: Vec<f64> = (0..=60).map(|i| 3.0 * s.a * i as f64 / 60.0).collect();
            let p = s.pressure(&r);
            let u = s.displacement(&r)?;
            for i in 0..r.len() {
                profile_rows.push((d, r[i], p[i], u[i]));
            }
        }
        rows.push((d, s.a, s.force));
        bar.inc();
    }
    drop(bar);
    if a.tangential {
        let k = tangential_stiffness(&stack, &rows, &a.stack)?;
        crate::stdio::print(|o| {
            csv_out::write(
                o,
                ["delta", "a", "force", "tangential_stiffness"],
                rows.iter()
                    .zip(&k)
                    .map(|((d, r, f), k)| [num(*d), num(*r), num(*f), num(*k)]),
            )
            .map_err(Into::into)
        })?;
    } else {
        crate::stdio::print(|o| {
            csv_out::write(
                o,
                ["delta", "a", "force"],
                rows.iter().map(|(d, r, f)| [num(*d), num(*r), num(*f)]),
            )
            .map_err(Into::into)
        })?;
    }
    if let (Some(path), Some(set)) = (&a.profile, profile_set) {
        let text = csv_out::text(
            ["delta", "r", "pressure", "displacement"],
            profile_rows
                .iter()
                .map(|(d, r, p, u)| [num(*d), num(*r), num(*p), num(*u)]),
        )?;
        set.write(&file_name(path), text.as_bytes())?;
        set.commit()?;
    }
    if let (Some(path), Some(set)) = (&a.plot, plot_set) {
        let es = stack.contact_modulus();
        let hertz = |d: f64| 4.0 / 3.0 * es * a.radius.sqrt() * d.powf(1.5);
        let (lo, hi) = rows.iter().fold((f64::INFINITY, 0.0f64), |(l, h), r| {
            (l.min(r.0), h.max(r.0))
        });
        let hz: Vec<(f64, f64)> = (0..=200)
            .map(|i| {
                let d = lo + (hi - lo) * i as f64 / 200.0;
                (d * 1e6, hertz(d))
            })
            .collect();
        let spec = PlotSpec {
            title: format!(
                "Force against approach: {}, {}, sphere R = {}",
                match a.model {
                    Model::Full => "full solution",
                    Model::Approx => "second-order approximation",
                },
                crate::engine::stack_description(&stack),
                crate::plot::ticks::length(a.radius)
            ),
            x_label: "approach δ (µm)".into(),
            y_label: "force P (N)".into(),
            log_x: false,
            log_y: false,
            series: vec![
                Series {
                    name: match a.model {
                        Model::Full => "full solution",
                        Model::Approx => "second-order approximation (table)",
                    }
                    .into(),
                    points: rows.iter().map(|r| (r.0 * 1e6, r.2)).collect(),
                    style: if rows.len() > 30 {
                        Style::Line
                    } else {
                        Style::Points
                    },
                },
                Series {
                    name: "Hertz (E*₁)".into(),
                    points: hz,
                    style: Style::Line,
                },
            ],
        };
        plot::lines(&set.path(&file_name(path))?, &spec)?;
        set.commit()?;
    }
    Ok(())
}

fn file_name(p: &std::path::Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Progress over the approaches (a log line every few seconds in batch jobs): one
/// Fredholm solve on a stack of hundreds of layers (a graded coating, a 1000-layer
/// counterface) takes tens of seconds, its kernel ~ the layers' count; the first line
/// says how many layers the solid has.
fn approach_bar(stack: &Bodies, n: usize) -> crate::progress::Progress {
    let layers =
        stack.first.layers().len() + stack.counterface.stack().map_or(0, |c| c.layers().len());
    if layers >= MANY_LAYERS {
        crate::progress::log(format!(
            "asperity: {layers} layers in the solid (both bodies): each approach's kernel \
             costs ~{layers} transfer-matrix products per wavenumber"
        ));
    }
    crate::progress::bar(n as u64, "asperity: approaches")
}

/// From this many layers on, [`approach_bar`] says how many.
const MANY_LAYERS: usize = 100;
