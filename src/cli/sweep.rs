//! `strata sweep SWEEP.toml --out DIR`: parametric sweeps over stack, surface and
//! model parameters, in parallel (rayon), with shards for batch schedulers. The
//! sweep file format and the case order are documented in [`spec`].
//!
//! Outputs of an unsharded run (one output set, replaced as a whole under a lock,
//! [`crate::output_set`]):
//! - `DIR/sweep.csv`: one row per case and load step, header
//!   `case,<swept columns…>,model,step,delta,gap,mean_pressure,pressure_ratio,area_fraction,contacts,stiffness,valid`
//!   where the swept columns are the axes in case order except `model.kind` (that is
//!   the `model` column); `case` and `step` count from 0; results are SI and full
//!   precision (`{:e}`), as in `strata solve`'s curve.csv; `valid` 1/0 (inside the
//!   model's validity); then, as in curve.csv, `plastic_area_fraction` when the base
//!   scene has `[plasticity]` and `conductance` (empty where infinite) when it has
//!   `[conductance]` and `tangential_stiffness` (every model) when it has
//!   `[friction]`, in that order (a base scene with `[load] tangential` is refused:
//!   the tangential path is `strata solve`'s);
//! - `DIR/sweep.json`: the sidecar (strata version, sweep fingerprint, case count,
//!   shard, columns, axes, per-case wall times, the CSV's row count and FNV-1a
//!   checksum, the input files and their checksums);
//! - `DIR/pressure_gap*.svg`, `DIR/area_pressure*.svg`, `DIR/bands.csv`: summary plots
//!   with the scatter over seeds (module `plots`).
//!
//! `--shard I/N` (1 ≤ I ≤ N) runs the cases with `id % N == I − 1` (round robin, so
//! expensive corners of a grid spread over all shards) and writes
//! `DIR/shard-I-of-N.csv` + `.json` (a file set of its own: several shards may share
//! DIR and run at once). `strata sweep merge DIR --out FILE` checks that shards 1…N
//! are all there, that each CSV still has the row count and checksum its sidecar
//! recorded (a truncated, cut or edited shard is refused), that they come from the
//! same sweep (fingerprint: FNV-1a of the strata version, the sweep file, the base
//! scene file and the content of every file it reads: stack, table, surface), share
//! the header and hold every case exactly once, and writes the rows sorted by case and
//! step: byte for byte the `sweep.csv` of an unsharded run.
//!
//! Per-case results do not depend on the thread count or scheduling: each case is
//! solved alone and sequentially (the solvers are not parallel inside), and rows are
//! written in case order.

mod plots;
pub mod spec;

use std::path::{Path, PathBuf};
use std::time::Instant;
use strata_runtime::resources::MemoryLimit;

use crate::csv_out::{self, num};
use crate::output_set::OutputSet;
use crate::progress;
use crate::scene::ModelKind;
use anyhow::{Context, Result, anyhow, bail};
use rayon::prelude::*;
use strata_runtime::hash::fnv1a;
use strata_runtime::rough::Step;
use strata_runtime::table::Table;
use strata_runtime::{Bodies, Solid};

use crate::engine::{Console, EngineOptions, Quiet, law_for, solve};
use spec::{Case, Sweep};

/// Result columns after the swept ones (the same as `strata solve`'s curve.csv).
const RESULT_COLUMNS: &str =
    "model,step,delta,gap,mean_pressure,pressure_ratio,area_fraction,contacts,stiffness,valid";

#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Args {
    #[command(subcommand)]
    pub command: Option<SweepCommand>,
    /// Sweep file (TOML): a base scene and the swept axes.
    #[arg(required = true)]
    pub sweep: Option<PathBuf>,
    /// Output directory (created if missing; shards may share it).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Run only the I-th of N slices (cases with id % N == I − 1), 1 ≤ I ≤ N, e.g.
    /// `--shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Overwrite: a non-empty DIR (unsharded), or this shard's own files.
    #[arg(long)]
    pub force: bool,
    /// Table cache: the tables of layered stacks without `stack.table`, the ψ tables of
    /// conducting ones and the capped response tables (default: STRATA_CACHE_DIR, else
    /// $XDG_CACHE_HOME/strata or ~/.cache/strata).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    /// Worker threads, at most 4 per core (default: RAYON_NUM_THREADS or all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Skip the summary plots.
    #[arg(long)]
    pub no_plots: bool,
    /// Keep going when a case fails (e.g. the I model does not converge): the other
    /// cases are solved and written, the failures are listed in the sidecar JSON and on
    /// stderr, and the exit status is non-zero.
    #[arg(long)]
    pub keep_going: bool,
    /// Print the cases (of the shard, if given) as CSV and exit; nothing is solved.
    #[arg(long)]
    pub list: bool,
}

#[derive(Debug, clap::Subcommand)]
pub enum SweepCommand {
    /// Join DIR/shard-I-of-N.csv (I = 1…N) into one CSV, identical to an unsharded run.
    Merge(MergeArgs),
}

#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// Directory holding the shard files.
    pub dir: PathBuf,
    /// The merged CSV.
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the summary plots and bands.csv into this directory.
    #[arg(long)]
    pub plots: Option<PathBuf>,
    /// Overwrite an existing --out file / non-empty --plots directory.
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: Args, memory: MemoryLimit) -> Result<()> {
    match a.command {
        Some(SweepCommand::Merge(m)) => merge(m, &memory),
        None => run_sweep(a, memory),
    }
}

/// Parses `I/N` with 1 ≤ I ≤ N.
pub fn parse_shard(s: &str) -> Result<(usize, usize)> {
    let bad = || anyhow!("--shard {s}: must be I/N with integers 1 ≤ I ≤ N (shards count from 1)");
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let i: usize = i.trim().parse().map_err(|_| bad())?;
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    if n == 0 || i == 0 || i > n {
        return Err(bad());
    }
    Ok((i, n))
}

fn shard_stem(i: usize, n: usize) -> String {
    format!("shard-{i}-of-{n}")
}

/// The effect columns after `valid`, as `strata solve` writes them to curve.csv:
/// `plastic_area_fraction` when the base scene has `[plasticity]`, `conductance` when it
/// has `[conductance]`, `tangential_stiffness` when it has `[friction]`, in that order
/// (every case shares the base scene's sections).
fn effect_header(sweep: &Sweep) -> Vec<&'static str> {
    let mut h = Vec::new();
    if sweep.base.plasticity.is_some() {
        h.push("plastic_area_fraction");
    }
    if sweep.base.conductance.is_some() {
        h.push("conductance");
    }
    if sweep.base.friction.is_some() {
        h.push("tangential_stiffness");
    }
    h
}

/// `case,<columns>,model,step,…,valid[,plastic_area_fraction][,conductance]`.
fn header(sweep: &Sweep) -> Vec<String> {
    let mut h = vec!["case".to_string()];
    h.extend(sweep.column_axes().map(|(_, a)| a.name.clone()));
    h.extend(RESULT_COLUMNS.split(',').map(String::from));
    h.extend(effect_header(sweep).into_iter().map(String::from));
    h
}

/// The CSV records of one case's steps; `effects` are the case's effect columns
/// ([`crate::engine::SceneSolution::effect_columns`] of its solution).
fn case_rows(
    sweep: &Sweep,
    case: &Case,
    steps: &[Step],
    effects: &[(&str, Vec<f64>)],
    out: &mut Vec<Vec<String>>,
) {
    let wanted = effect_header(sweep);
    let mut prefix = vec![case.id.to_string()];
    prefix.extend(sweep.column_axes().map(|(k, _)| case.values[k].to_string()));
    prefix.push(Sweep::model_name(&case.scene).to_string());
    for (i, st) in steps.iter().enumerate() {
        let mut r = prefix.clone();
        r.extend([
            i.to_string(),
            num(st.delta),
            num(st.gap),
            num(st.mean_pressure),
            num(st.pressure_ratio),
            num(st.area_fraction),
            st.contacts.to_string(),
            num(st.stiffness),
            u8::from(st.validity.is_valid()).to_string(),
        ]);
        r.extend(wanted.iter().map(|w| {
            let v = effects
                .iter()
                .find(|(name, _)| name == w)
                .and_then(|(_, v)| v.get(i).copied());
            num(v.unwrap_or(f64::NAN))
        }));
        out.push(r);
    }
}

/// Plot captions: the sweep's title (else its file stem) and the base stack.
fn caption(sweep: &Sweep) -> String {
    let name = sweep.title.clone().unwrap_or_else(|| {
        sweep
            .path
            .file_stem()
            .map_or("sweep".into(), |s| s.to_string_lossy().into_owned())
    });
    format!(
        "{name}, {}",
        crate::engine::stack_description(&sweep.base.bodies)
    )
}

/// Loads (or builds into the cache) the table of every distinct layered stack once,
/// before the parallel part, so that no two workers build the same table. A stack the
/// scene's table does not serve (a thickness ratio changed, E2/E1 outside the family
/// range) falls back to the engine's cache, with a message.
fn prepare_tables(cases: &mut [Case], opts: &EngineOptions) -> Result<()> {
    let mut seen: Vec<(Bodies, Option<PathBuf>, Option<PathBuf>)> = Vec::new();
    let mut loaded: Vec<(PathBuf, Table)> = Vec::new();
    for c in cases.iter_mut() {
        let s = &c.scene;
        if s.bodies.is_homogeneous() || s.model.kind == ModelKind::Bem {
            continue;
        }
        // (the mechanics of the pair: surfaces and conduction do not choose a table)
        let mechanics: Bodies = s.bodies.bodies();
        if let Some((_, _, resolved)) = seen
            .iter()
            .find(|(st, t, _)| *st == mechanics && *t == s.table)
        {
            c.scene.table = resolved.clone();
            continue;
        }
        let original = c.scene.table.clone();
        let mut resolved = original.clone();
        if let Some(p) = original.as_ref().filter(|p| p.is_file()) {
            let k = match loaded.iter().position(|(q, _)| q == p) {
                Some(k) => k,
                None => {
                    let t = Table::load_within(p, &opts.memory)
                        .with_context(|| format!("stack.table {}", p.display()))?;
                    loaded.push((p.clone(), t));
                    loaded.len() - 1
                }
            };
            if let Err(e) = loaded[k].1.family_coordinate(&c.scene.bodies) {
                let (dir, _) = crate::cache::dir(opts.cache_dir.as_deref());
                progress::log(format!(
                    "sweep: table {} does not serve the stack of case {} ({e}); using the table cache {} (built once if missing)",
                    p.display(),
                    c.id,
                    dir.display()
                ));
                resolved = None;
            }
        }
        c.scene.table = resolved.clone();
        law_for(&c.scene, opts, &Console).with_context(|| format!("case {}", c.id))?;
        seen.push((c.scene.bodies.bodies(), original, resolved));
    }
    Ok(())
}

/// Reads (or builds into the cache) the capped asperity's response table of every
/// distinct stack and hardness of the cases with `[plasticity]` and the N or I model once,
/// before the parallel part, so that no two workers build the same table (each case then
/// reads it from the cache, `crate::cache::capped_response`).
fn prepare_capped_tables(cases: &[Case], opts: &EngineOptions) -> Result<()> {
    let dir = crate::cache::dir(opts.cache_dir.as_deref()).0;
    let mut seen: Vec<(Bodies, f64)> = Vec::new();
    for c in cases {
        let s = &c.scene;
        let Some(pl) = s.plasticity else { continue };
        let capped = s.model.kind != ModelKind::Bem && !s.unload && s.conductance.is_none();
        let mechanics: Bodies = s.bodies.bodies();
        if !capped || seen.contains(&(mechanics.clone(), pl.hardness)) {
            continue;
        }
        crate::cache::capped_response(&s.bodies, pl.hardness, &dir, false)
            .with_context(|| format!("case {}: plasticity", c.id))?;
        seen.push((mechanics, pl.hardness));
    }
    Ok(())
}

/// A case's effect columns (name, one value per step).
type EffectColumns = Vec<(&'static str, Vec<f64>)>;

/// A solved (or, with --keep-going, failed) case and its wall time (s).
struct CaseOut {
    steps: Result<(Vec<Step>, EffectColumns), String>,
    seconds: f64,
}

fn run_sweep(a: Args, memory: MemoryLimit) -> Result<()> {
    let t0 = Instant::now();
    let path = a
        .sweep
        .clone()
        .ok_or_else(|| anyhow!("missing the sweep file"))?;
    let sweep = Sweep::from_file(&path)?;
    let shard = a.shard.as_deref().map(parse_shard).transpose()?;
    let (si, sn) = shard.unwrap_or((1, 1));
    let ids: Vec<usize> = (0..sweep.cases).filter(|id| id % sn == si - 1).collect();
    if a.list {
        let mut head = vec!["case".to_string()];
        head.extend(sweep.axes.iter().map(|ax| ax.name.clone()));
        let head: Vec<&str> = head.iter().map(String::as_str).collect();
        let s = csv_out::text(
            &head,
            ids.iter().map(|&id| {
                std::iter::once(id.to_string())
                    .chain(sweep.case_values(id).iter().map(|v| v.to_string()))
                    .collect::<Vec<_>>()
            }),
        )?;
        // A closed pipe (`| head`) is not an error.
        crate::stdio::print_str(&s)?;
        progress::log(format!(
            "sweep: {} cases in all{}",
            sweep.cases,
            match shard {
                Some((i, n)) => format!(", {} in shard {i}/{n}", ids.len()),
                None => String::new(),
            }
        ));
        return Ok(());
    }
    let out = a
        .out
        .clone()
        .ok_or_else(|| anyhow!("--out DIR is required (or --list)"))?;
    // The cap of every command (`crate::threads`), for this pool of its own.
    let (threads, _) = crate::threads::thread_count(a.threads.map(|n| ("--threads", n)))?;
    let (stem, set) = match shard {
        None => ("sweep".to_string(), OutputSet::dir("--out", &out, a.force)?),
        Some((i, n)) => {
            if out.exists() && !out.is_dir() {
                bail!("--out {}: exists and is not a directory", out.display());
            }
            let stem = shard_stem(i, n);
            let files = [
                out.join(format!("{stem}.csv")),
                out.join(format!("{stem}.json")),
            ];
            let set = OutputSet::files("--out", &files, a.force)?;
            if n > sweep.cases {
                progress::log(format!(
                    "sweep: warning: {n} shards for {} cases; some shards are empty",
                    sweep.cases
                ));
            }
            (stem, set)
        }
    };
    // Build and validate every case of this shard before any solving.
    let mut cases: Vec<Case> = ids
        .iter()
        .map(|&id| sweep.case(id))
        .collect::<Result<_>>()
        .with_context(|| format!("sweep {}", path.display()))?;
    let opts = EngineOptions {
        cache_dir: a.cache_dir.clone(),
        memory,
        ..Default::default()
    };
    prepare_tables(&mut cases, &opts)?;
    prepare_capped_tables(&cases, &opts)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("--threads: cannot start the worker threads")?;
    let threads = pool.current_num_threads();
    progress::log(format!(
        "sweep: {} — {} cases{} on {threads} thread(s); axes: {}",
        path.display(),
        cases.len(),
        match shard {
            Some((i, n)) => format!(" (shard {i}/{n} of {})", sweep.cases),
            None => String::new(),
        },
        sweep
            .axes
            .iter()
            .map(|x| format!("{} ({})", x.name, x.values.len()))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    // Expensive cases first (scheduling only; results go back to case order).
    let mut order: Vec<usize> = (0..cases.len()).collect();
    let hint: Vec<f64> = cases.iter().map(Sweep::cost_hint).collect();
    order.sort_by(|&x, &y| hint[y].total_cmp(&hint[x]).then(x.cmp(&y)));
    let bar = progress::bar(cases.len() as u64, "sweep: cases");
    let keep_going = a.keep_going;
    let mut solved: Vec<(usize, CaseOut)> = pool.install(|| {
        order
            .par_iter()
            .with_max_len(1)
            .map(|&k| {
                let c = &cases[k];
                let t = Instant::now();
                let sol = solve(&c.scene, None, &opts, &mut Quiet)
                    .with_context(|| format!("case {} ({})", c.id, sweep.describe(&c.values)));
                bar.inc();
                let steps = match sol {
                    Ok(sol) => {
                        let effects = sol.effect_columns();
                        Ok((sol.steps, effects))
                    }
                    Err(e) if keep_going => {
                        progress::log(format!("sweep: error (continuing): {e:#}"));
                        Err(format!("{e:#}"))
                    }
                    Err(e) => return Err(e),
                };
                let seconds = t.elapsed().as_secs_f64();
                Ok((k, CaseOut { steps, seconds }))
            })
            .collect::<Result<Vec<_>>>()
    })?;
    drop(bar);
    solved.sort_by_key(|(k, _)| *k);
    let mut rows = Vec::new();
    let mut failed = Vec::new();
    for (k, r) in &solved {
        match &r.steps {
            Ok((steps, effects)) => case_rows(&sweep, &cases[*k], steps, effects, &mut rows),
            Err(e) => failed.push(serde_json::json!({"case": cases[*k].id, "error": e})),
        }
    }
    let head = header(&sweep);
    let csv = csv_out::text(&head, &rows)?;
    set.write(&format!("{stem}.csv"), csv.as_bytes())?;
    let seconds = t0.elapsed().as_secs_f64();
    let inputs: Vec<serde_json::Value> = sweep
        .inputs
        .iter()
        .map(|p| {
            let sum = strata_runtime::resources::read_data_file(p, "an input file", &memory)
                .map(|b| format!("{:016x}", fnv1a(&b)));
            serde_json::json!({"path": p.display().to_string(),
                               "fnv1a": sum.unwrap_or_else(|e| format!("unreadable: {e}"))})
        })
        .collect();
    let sidecar = serde_json::json!({
        "strata_version": env!("CARGO_PKG_VERSION"),
        "sweep": path.display().to_string(),
        "title": sweep.title,
        "caption": caption(&sweep),
        "fingerprint": format!("{:016x}", sweep.fingerprint),
        "inputs": inputs,
        "cases": sweep.cases,
        "mode": format!("{:?}", sweep.mode).to_lowercase(),
        "axes": sweep.axes.iter().map(|x| serde_json::json!({
            "name": x.name, "values": x.values.iter().map(|v| v.to_string()).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "shard": shard.map(|(i, n)| serde_json::json!({"index": i, "count": n})),
        "header": head.join(","),
        "rows": rows.len(),
        "csv_fnv1a": format!("{:016x}", fnv1a(csv.as_bytes())),
        "case_ids": cases.iter().map(|c| c.id).collect::<Vec<_>>(),
        "case_seconds": solved.iter().map(|(_, r)| r.seconds).collect::<Vec<_>>(),
        "failed": failed,
        "threads": threads,
        "seconds": seconds,
    });
    set.write(
        &format!("{stem}.json"),
        serde_json::to_string_pretty(&sidecar)?.as_bytes(),
    )?;
    if shard.is_none() && !a.no_plots {
        plots::write(&set, "", &csv, &caption(&sweep))?;
    }
    set.commit()?;
    let csv_path = out.join(format!("{stem}.csv"));
    progress::log(format!(
        "sweep: wrote {} ({} cases, {} rows) in {seconds:.2} s",
        csv_path.display(),
        cases.len(),
        rows.len()
    ));
    if !failed.is_empty() {
        bail!(
            "{} case(s) failed (listed in {}; their rows are absent): {}",
            failed.len(),
            out.join(format!("{stem}.json")).display(),
            failed
                .iter()
                .map(|f| f["case"].to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}

/// One shard file found in the merge directory.
struct ShardFile {
    index: usize,
    count: usize,
    csv: PathBuf,
}

fn merge(a: MergeArgs, memory: &MemoryLimit) -> Result<()> {
    let dir = &a.dir;
    let mut found: Vec<ShardFile> = Vec::new();
    for e in std::fs::read_dir(dir).with_context(|| format!("merge: {}", dir.display()))? {
        let e = e.with_context(|| format!("merge: {}", dir.display()))?;
        let name = e.file_name().to_string_lossy().to_string();
        let Some(core) = name
            .strip_prefix("shard-")
            .and_then(|r| r.strip_suffix(".csv"))
        else {
            continue;
        };
        let Some((i, n)) = core.split_once("-of-") else {
            continue;
        };
        let (Ok(index), Ok(count)) = (i.parse::<usize>(), n.parse::<usize>()) else {
            continue;
        };
        found.push(ShardFile {
            index,
            count,
            csv: e.path(),
        });
    }
    if found.is_empty() {
        bail!(
            "merge: no shard files (shard-I-of-N.csv) in {}",
            dir.display()
        );
    }
    found.sort_by(|a, b| (a.count, a.index, &a.csv).cmp(&(b.count, b.index, &b.csv)));
    let n = found[0].count;
    if let Some(f) = found.iter().find(|f| f.count != n) {
        bail!(
            "merge: {} holds shards of different counts ({} and {}): remove the stale ones",
            dir.display(),
            n,
            f.count
        );
    }
    // Two files for one shard (`shard-1-of-2.csv` beside a copy `shard-01-of-2.csv`):
    // merging both would count its cases twice.
    if let Some(w) = found.windows(2).find(|w| w[0].index == w[1].index) {
        bail!(
            "merge: shard {}/{n} is duplicated: {} and {} both hold it; remove one",
            w[0].index,
            w[0].csv.display(),
            w[1].csv.display()
        );
    }
    for i in 1..=n {
        if !found.iter().any(|f| f.index == i) {
            bail!(
                "merge: shard {i}/{n} is missing ({} not found; run it with --shard {i}/{n})",
                dir.join(format!("{}.csv", shard_stem(i, n))).display()
            );
        }
    }
    if let Some(f) = found.iter().find(|f| f.index == 0 || f.index > n) {
        bail!("merge: {}: shard index out of 1..={n}", f.csv.display());
    }
    // Writing over an input would destroy a shard the merge is reading.
    let same = |p: &Path| match (p.canonicalize(), a.out.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    };
    if let Some(f) = found
        .iter()
        .find(|f| same(&f.csv) || same(&f.csv.with_extension("json")))
    {
        bail!(
            "--out {}: is the shard {} this merge reads; write the merged table elsewhere",
            a.out.display(),
            f.csv.display()
        );
    }
    let mut fingerprint: Option<(String, PathBuf)> = None;
    let mut head: Option<Vec<String>> = None;
    let mut total: Option<u64> = None;
    let mut rows: Vec<(usize, usize, Vec<String>)> = Vec::new();
    let mut failed: Vec<usize> = Vec::new();
    let mut title: Option<String> = None;
    let mut step_col = 0;
    for f in &found {
        let side = f.csv.with_extension("json");
        let meta: serde_json::Value = serde_json::from_str(
            &strata_runtime::resources::read_text_capped(
                &side,
                strata_runtime::resources::TEXT_FILE_CAP,
                "a shard sidecar",
                memory,
            )
            .with_context(|| format!("merge: sidecar {}", side.display()))?,
        )
        .with_context(|| format!("merge: sidecar {} is not valid JSON", side.display()))?;
        let sh = &meta["shard"];
        let (mi, mn) = (sh["index"].as_u64(), sh["count"].as_u64());
        if mi != Some(f.index as u64) || mn != Some(n as u64) {
            bail!(
                "merge: duplicate or renamed shard: {} holds shard {}/{} according to {}",
                f.csv.display(),
                mi.map_or("?".into(), |x| x.to_string()),
                mn.map_or("?".into(), |x| x.to_string()),
                side.display()
            );
        }
        let fp = meta["fingerprint"]
            .as_str()
            .ok_or_else(|| anyhow!("merge: {}: no fingerprint", side.display()))?
            .to_string();
        match &fingerprint {
            None => fingerprint = Some((fp, f.csv.clone())),
            Some((g, first)) if *g != fp => bail!(
                "merge: {} comes from a different sweep than {} (fingerprint {fp} ≠ {g}: the sweep file, the base scene, a file it reads (stack, table, surface) or the strata version differ)",
                f.csv.display(),
                first.display()
            ),
            _ => {}
        }
        let cases = meta["cases"]
            .as_u64()
            .ok_or_else(|| anyhow!("merge: {}: no case count", side.display()))?;
        if total.is_some_and(|t| t != cases) {
            bail!(
                "merge: {}: case count differs between shards",
                side.display()
            );
        }
        total = Some(cases);
        if let Some(list) = meta["failed"].as_array() {
            failed.extend(
                list.iter()
                    .filter_map(|f| f["case"].as_u64())
                    .map(|c| c as usize),
            );
        }
        if title.is_none() {
            title = meta["caption"]
                .as_str()
                .or(meta["title"].as_str())
                .map(str::to_string);
        }
        let bytes = strata_runtime::resources::read_data_file(&f.csv, "a shard CSV", memory)
            .with_context(|| format!("merge: {}", f.csv.display()))?;
        // The shard must be exactly what its run wrote: row count and checksum.
        let (want_rows, want_sum) = (meta["rows"].as_u64(), meta["csv_fnv1a"].as_str());
        let (Some(want_rows), Some(want_sum)) = (want_rows, want_sum) else {
            bail!(
                "merge: {}: no row count or checksum (written by an older strata: rerun the shard)",
                side.display()
            );
        };
        let sum = format!("{:016x}", fnv1a(&bytes));
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(true)
            .from_reader(bytes.as_slice());
        let h: Vec<String> = reader
            .headers()
            .with_context(|| format!("merge: {}: no CSV header", f.csv.display()))?
            .iter()
            .map(String::from)
            .collect();
        let mut records = Vec::new();
        for (ln, r) in reader.records().enumerate() {
            let r = r.with_context(|| format!("merge: {} row {}", f.csv.display(), ln + 1))?;
            records.push(r.iter().map(String::from).collect::<Vec<String>>());
        }
        if records.len() as u64 != want_rows {
            bail!(
                "merge: {} has {} rows but its run wrote {want_rows} ({}): the shard is truncated or was edited; rerun it with --shard {}/{n} --force",
                f.csv.display(),
                records.len(),
                side.display(),
                f.index
            );
        }
        if sum != want_sum {
            bail!(
                "merge: {} differs from what its run wrote (checksum {sum} ≠ {want_sum} in {}): the shard was cut or edited; rerun it with --shard {}/{n} --force",
                f.csv.display(),
                side.display(),
                f.index
            );
        }
        match &head {
            None => {
                step_col = h
                    .iter()
                    .position(|c| c == "step")
                    .ok_or_else(|| anyhow!("merge: {}: no `step` column", f.csv.display()))?;
                head = Some(h);
            }
            Some(g) if *g != h => bail!(
                "merge: {} has a different header than the other shards",
                f.csv.display()
            ),
            _ => {}
        }
        for (ln, fields) in records.into_iter().enumerate() {
            let parse = |k: usize, what: &str| -> Result<usize> {
                fields.get(k).and_then(|x| x.parse().ok()).ok_or_else(|| {
                    anyhow!("merge: {} line {}: bad {what}", f.csv.display(), ln + 2)
                })
            };
            let (case, step) = (parse(0, "case")?, parse(step_col, "step")?);
            if case as u64 >= cases || case % n != f.index - 1 {
                bail!(
                    "merge: {} line {}: case {case} does not belong to shard {}/{n} (duplicate or renamed shard?)",
                    f.csv.display(),
                    ln + 2,
                    f.index
                );
            }
            rows.push((case, step, fields));
        }
    }
    rows.sort_by_key(|r| (r.0, r.1));
    for w in rows.windows(2) {
        if w[0].0 == w[1].0 && w[0].1 == w[1].1 {
            bail!("merge: case {} step {} appears twice", w[0].0, w[0].1);
        }
    }
    let total = total.unwrap_or(0) as usize;
    let mut present = vec![false; total];
    for r in &rows {
        present[r.0] = true;
    }
    if let Some(c) = (0..total).find(|c| !present[*c] && !failed.contains(c)) {
        bail!(
            "merge: case {c} is missing (it belongs to shard {}/{n})",
            c % n + 1
        );
    }
    let head = head.unwrap_or_default();
    let csv = csv_out::text(&head, rows.iter().map(|r| &r.2))?;
    let set = OutputSet::file("--out", &a.out, a.force)?;
    let name = a
        .out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    set.write(&name, csv.as_bytes())?;
    if let Some(p) = &a.plots {
        let plots_set = OutputSet::dir("--plots", p, a.force)?;
        plots::write(&plots_set, "", &csv, title.as_deref().unwrap_or("sweep"))?;
        plots_set.commit()?;
    }
    set.commit()?;
    progress::log(format!(
        "merge: {n} shard(s), {total} cases, {} rows → {}",
        rows.len(),
        a.out.display()
    ));
    if !failed.is_empty() {
        failed.sort_unstable();
        progress::log(format!(
            "merge: warning: {} case(s) failed in their shards and have no rows: {:?}",
            failed.len(),
            failed
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_specs() {
        assert_eq!(parse_shard("1/1").unwrap(), (1, 1));
        assert_eq!(parse_shard("3/7").unwrap(), (3, 7));
        for bad in ["0/2", "3/2", "1/0", "a/2", "2", "1/2/3", "-1/2", ""] {
            let e = parse_shard(bad).unwrap_err().to_string();
            assert!(e.contains("--shard"), "{bad}: {e}");
        }
    }
}
