//! `strata solve SCENE.toml --out DIR`: load curve of a rough contact.
//!
//! Writes one output set, replaced as a whole ([`crate::output_set`]: staged beside
//! DIR, swapped in at the end, under a lock; files you put in DIR yourself are kept):
//! - `DIR/curve.csv`, header exactly
//!   `delta,gap,mean_pressure,pressure_ratio,area_fraction,contacts,stiffness,valid`
//!   (SI: δ and g_n in m, p_n in Pa, p_n/E*₁ and A/A₀ dimensionless, stiffness dP/dδ
//!   of the whole sample in N/m; valid 1/0: inside the model's validity), followed by
//!   `plastic_area_fraction` for a scene with `[plasticity]` and `conductance` (h_c,
//!   W/(m²·K) or S/m², empty where infinite: full contact) for a scene with
//!   `[conductance]` and `tangential_stiffness` (K_t of the sample in full stick, N/m)
//!   for a scene with `[friction]`, in that order;
//! - with `[load] tangential` (BEM): `DIR/tangential.csv`, header exactly
//!   `force_ratio,tangential_force,tangential_displacement,stick_fraction` (Q/(μP),
//!   Q in N, the flat's tangential displacement in m, the stick area over the contact
//!   area), one row per step of the tangential path at the last load step, and
//!   `DIR/tangential.svg`; curve.json's `tangential_path` holds the same with each
//!   step's dissipation and solver record;
//! - `DIR/curve.json`: the same per step plus the KKT residual, the validity and its
//!   reasons, the scene summary and which effects were simulated;
//! - `DIR/pressure_gap.svg` (p_n/E*₁ against g_n, log y) and `DIR/area_pressure.svg`
//!   (A/A₀ against p_n/E*₁), like the paper's Figs. 15–22;
//! - with `[output] maps = "last"` or `"all"` (`model.kind = "bem"` only; the scene
//!   refuses maps for the asperity models, which have no pressure field):
//!   `DIR/maps/pressure_step_KK.npy` (Pa) and `gap_step_KK.npy` (m), n×n f64 in the
//!   surface's orientation, their pictures `pressure_step_KK.png` / `gap_step_KK.png`
//!   (viridis, axes in mm with a scale bar; pressure in MPa, gap in µm; white = no
//!   contact; skipped with `--no-plots`), each written as its step is solved, and
//!   `DIR/maps/maps.csv`
//!   (step, δ, g_n, p̄, A/A₀, contact patches, files). KK is the load step, zero-padded.
//!   With `[output] format = ["npy", "netcdf"]` (or `"netcdf"` alone: no .npy maps)
//!   also `DIR/maps/results_step_KK.nc`, contact.engineering's per-step `results.nc`
//!   (NetCDF-3, 64-bit offsets): `pressure` (Pa), `contacting_points`, `gap` and
//!   `displacement` (m) on dimensions (x, y), x the input's first axis (the .npy maps'
//!   rows: a field is the .npy map element for element), with
//!   `mean_pressure`, `total_contact_area` and the step's summary as attributes
//!   ([`strata_bem::netcdf`]); maps.csv then has a `netcdf_file` column.
//!   The contact-patch count of every step is also curve.csv's `contacts` column.
//!
//! A non-empty DIR is refused unless `--force`; a second `strata` writing the same DIR
//! fails at once. Only what the scene needs is computed:
//! a homogeneous stack loads no table (χ = ζ = 1, g = 0); a layered stack loads
//! `stack.table` or builds the table once into the cache and says so; the independent
//! model forms no pairs. The log (stderr) says which effects were simulated.

use std::path::{Path, PathBuf};
use std::time::Instant;
use strata_runtime::resources::MemoryLimit;

use crate::csv_out;
use crate::output_set::{OutputSet, refuse_inputs};
use crate::progress;
use crate::scene::{MapFormats, MapsSpec, Scene};
use anyhow::{Context, Result, bail};
use strata_bem::BemSolution;
use strata_runtime::rough::Step;

use crate::engine::{EngineOptions, SceneSolution, WithMaps, solve};

use crate::plot::{PlotSpec, Series, Style};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output directory (created if missing; replaced as a whole, files you put there
    /// yourself are kept).
    #[arg(long)]
    pub out: PathBuf,
    /// Replace the outputs of a non-empty output directory.
    #[arg(long)]
    pub force: bool,
    /// Table cache: the tables of layered stacks without `stack.table`, the ψ tables of
    /// conducting ones and the capped response tables (default: STRATA_CACHE_DIR, else
    /// $XDG_CACHE_HOME/strata or ~/.cache/strata).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    /// Skip the plots.
    #[arg(long)]
    pub no_plots: bool,
}

pub use crate::csv_out::CURVE_HEADER;

/// curve.csv text: the fixed header, full precision; `valid` is 1 where the step is
/// inside the model's validity (curve.json's `validity` says why not), else 0.
pub fn curve_csv(steps: &[Step]) -> Result<String> {
    curve_csv_extra(steps, &[])
}

/// curve.csv with extra columns after `valid`, in the order given (scenes with
/// `[plasticity]`: `plastic_area_fraction`; with `[conductance]`: `conductance`; both
/// in that order). Each column holds one value per step.
pub fn curve_csv_extra(steps: &[Step], extra: &[(&str, Vec<f64>)]) -> Result<String> {
    let mut header: Vec<&str> = CURVE_HEADER.to_vec();
    header.extend(extra.iter().map(|(name, _)| *name));
    Ok(csv_out::text(
        &header,
        steps.iter().enumerate().map(|(i, st)| {
            let mut row = vec![
                csv_out::num(st.delta),
                csv_out::num(st.gap),
                csv_out::num(st.mean_pressure),
                csv_out::num(st.pressure_ratio),
                csv_out::num(st.area_fraction),
                st.contacts.to_string(),
                csv_out::num(st.stiffness),
                u8::from(st.validity.is_valid()).to_string(),
            ];
            row.extend(
                extra
                    .iter()
                    .map(|(_, v)| csv_out::num(v.get(i).copied().unwrap_or(f64::NAN))),
            );
            row
        }),
    )?)
}

pub fn run(a: Args, memory: MemoryLimit) -> Result<()> {
    // Under mpirun (the `mpi` build): the BEM distributed over the ranks.
    #[cfg(feature = "mpi")]
    if let Some(world) = crate::cli::ranks::launched() {
        use strata_bem::Decomposition;
        if world.size() > 1 {
            return run_ranks(a, memory, &world);
        }
    }
    run_one(a, memory)
}

/// The options of a solve.
fn engine_options(a: &Args, memory: MemoryLimit) -> EngineOptions {
    EngineOptions {
        cache_dir: a.cache_dir.clone(),
        keep_partial: true,
        memory,
        ..Default::default()
    }
}

/// The solve in this process alone.
fn run_one(a: Args, memory: MemoryLimit) -> Result<()> {
    let t0 = Instant::now();
    let scene = Scene::from_file(&a.scene)?;
    refuse_inputs("--out", &a.out, &scene.inputs(&a.scene))?;
    let set = OutputSet::dir("--out", &a.out, a.force)?;
    let opts = engine_options(&a, memory);
    let mut maps = MapWriter::new(&set, scene.output.maps, !a.no_plots)
        .with_formats(scene.output.format, scene.plasticity.map(|p| p.hardness));
    let sol = solve(
        &scene,
        None,
        &opts,
        &mut WithMaps {
            quiet: false,
            sink: |k, n, m| {
                maps.accept(k, n, m)
                    .map_err(|e| strata_engine::error::EngineError::Source(e.into()))
            },
        },
    )
    .with_context(|| format!("scene {}", a.scene.display()))?;
    maps.finish()?;
    finish(&a, memory, set, sol, t0)
}

/// A scene under `mpirun -np P` (P > 1, the `mpi` build): a BEM scene solved on the
/// ranks together ([`strata_engine::engine::distributed`]), rank 0 writing the outputs;
/// any other model on rank 0 alone (the log says so), the other ranks exiting at once.
#[cfg(feature = "mpi")]
fn run_ranks(a: Args, memory: MemoryLimit, comm: &dyn strata_bem::Decomposition) -> Result<()> {
    use crate::engine::distributed;
    use crate::scene::ModelKind;
    use strata_bem::decomp;
    let (ranks, rank) = (comm.size(), comm.rank());
    if rank != 0 {
        progress::init(true);
    }
    let t0 = Instant::now();
    let on_rank = |e: anyhow::Error| {
        if rank == 0 {
            e
        } else {
            e.context(format!("rank {rank} of {ranks}"))
        }
    };
    let scene = Scene::from_file(&a.scene).map_err(|e| on_rank(e.into()))?;
    if scene.model.kind != ModelKind::Bem {
        if rank != 0 {
            return Ok(());
        }
        progress::log(format!(
            "mpirun: {ranks} ranks, but only the BEM is distributed: the {:?} model runs on rank 0 alone (ranks 1..{ranks} exit)",
            scene.model.kind
        ));
        return run_one(a, memory);
    }
    // Rank 0 checks the scene's fields and prepares the output set; the others follow
    // its word (on its error they exit at once, rank 0 reports it).
    let set = (rank == 0).then(|| -> Result<OutputSet> {
        if let Some(why) = distributed::not_distributed(&scene) {
            bail!("scene {}: {why}", a.scene.display());
        }
        refuse_inputs("--out", &a.out, &scene.inputs(&a.scene))?;
        Ok(OutputSet::dir("--out", &a.out, a.force)?)
    });
    if decomp::any(comm, matches!(set, Some(Err(_)))) {
        return match set {
            Some(Err(e)) => Err(e),
            _ => Ok(()),
        };
    }
    let opts = engine_options(&a, memory);
    let sol = if rank == 0 {
        distributed::solve(&scene, comm, &opts, &mut crate::engine::Console)
    } else {
        distributed::solve(&scene, comm, &opts, &mut crate::engine::Quiet)
    }
    .with_context(|| format!("scene {}", a.scene.display()))
    .map_err(on_rank)?;
    match set {
        Some(Ok(set)) => finish(&a, memory, set, sol, t0),
        _ => Ok(()),
    }
}

/// Writes a solution's outputs into `set` (a partial curve never replaces a complete
/// one) and reports.
fn finish(
    a: &Args,
    memory: MemoryLimit,
    set: OutputSet,
    mut sol: SceneSolution,
    t0: Instant,
) -> Result<()> {
    sol.summary.scene = a.scene.display().to_string();
    if let Some(f) = &sol.failed {
        // A failing run never replaces complete results (docs/conventions.md).
        if holds_complete_curve(&a.out, &memory) {
            bail!(
                "scene {}: load step {} (δ = {:e} m) failed: {}; {} holds the complete results of an earlier run, which are kept (a partial curve never replaces a complete one): the {} steps before the failure were not written (give another --out to keep them)",
                a.scene.display(),
                f.step,
                f.delta,
                f.error,
                a.out.display(),
                f.step,
            );
        }
    }
    write_outputs(&set, a.no_plots, &sol)?;
    set.commit()?;
    if let Some(f) = &sol.failed {
        bail!(
            "scene {}: load step {} (δ = {:e} m) failed: {}; the {} steps before it were written to {} as a partial curve (curve.csv: a `partial` column; curve.json: \"partial\")",
            a.scene.display(),
            f.step,
            f.delta,
            f.error,
            f.step,
            a.out.display()
        );
    }
    progress::log(format!(
        "wrote {} steps to {} in {:.3} s",
        sol.steps.len(),
        a.out.display(),
        t0.elapsed().as_secs_f64()
    ));
    Ok(())
}

/// Writes the BEM maps selected by the scene into `maps/` of an output set as they
/// come (see the module docs): .npy maps and/or NetCDF files (`[output] format`), PNG
/// pictures when `pictures`, and `maps.csv`. `last` keeps one step's maps in memory
/// until the end; `all` none.
pub struct MapWriter<'a> {
    set: &'a OutputSet,
    /// Directory of the maps inside the set, with a trailing '/' (`maps/`).
    dir: String,
    which: MapsSpec,
    pictures: bool,
    /// The files: .npy and/or NetCDF.
    formats: MapFormats,
    /// The hardness (Pa) of a plastic solve, for the NetCDF files' attributes.
    hardness: Option<f64>,
    rows: Vec<Vec<String>>,
    last: Option<(usize, usize, BemSolution)>,
}

impl<'a> MapWriter<'a> {
    pub fn new(set: &'a OutputSet, which: MapsSpec, pictures: bool) -> Self {
        Self::in_dir(set, "maps/", which, pictures)
    }

    /// A writer into `dir` of the set (`sub/maps/`).
    pub fn in_dir(set: &'a OutputSet, dir: &str, which: MapsSpec, pictures: bool) -> Self {
        MapWriter {
            set,
            dir: dir.to_string(),
            which,
            pictures,
            formats: MapFormats::default(),
            hardness: None,
            rows: Vec::new(),
            last: None,
        }
    }

    /// The same writer with the scene's map formats (`[output] format`) and the hardness
    /// (Pa) of a plastic solve (a NetCDF attribute).
    pub fn with_formats(mut self, formats: MapFormats, hardness: Option<f64>) -> Self {
        self.formats = formats;
        self.hardness = hardness;
        self
    }

    /// Takes step `k` of `n`'s maps.
    pub fn accept(&mut self, k: usize, n: usize, m: BemSolution) -> Result<()> {
        match self.which {
            MapsSpec::None => Ok(()),
            MapsSpec::All => self.write(k, n, &m),
            MapsSpec::Last => {
                self.last = Some((k, n, m));
                Ok(())
            }
        }
    }

    /// Writes the pending last step and `maps.csv`.
    pub fn finish(mut self) -> Result<()> {
        if self.which == MapsSpec::None {
            return Ok(());
        }
        if let Some((k, n, m)) = self.last.take() {
            self.write(k, n, &m)?;
        }
        if self.rows.is_empty() {
            anyhow::bail!("output.maps: the solution has no maps (model.kind must be \"bem\")");
        }
        let mut header = vec![
            "step",
            "delta",
            "gap",
            "mean_pressure",
            "area_fraction",
            "contacts",
            "pressure_file",
            "gap_file",
        ];
        if self.formats.netcdf {
            header.push("netcdf_file");
        }
        let text = csv_out::text(&header, &self.rows)?;
        self.set
            .write(&format!("{}maps.csv", self.dir), text.as_bytes())?;
        Ok(())
    }

    fn write(&mut self, k: usize, n: usize, m: &BemSolution) -> Result<()> {
        let width = (n.max(1) - 1).to_string().len().max(2);
        let (pf, gf) = (
            format!("pressure_step_{k:0width$}.npy"),
            format!("gap_step_{k:0width$}.npy"),
        );
        let d = &self.dir;
        let (pf, gf) = if self.formats.npy {
            m.write_maps(
                &self.set.path(&format!("{d}{pf}"))?,
                &self.set.path(&format!("{d}{gf}"))?,
            )?;
            (pf, gf)
        } else {
            (String::new(), String::new())
        };
        // a capped solve's plastic depth u_pl beside them (g = w − z + u_pl + c)
        if self.formats.npy && m.plastic_depth.is_some() {
            m.write_plastic_depth(
                &self
                    .set
                    .path(&format!("{d}plastic_depth_step_{k:0width$}.npy"))?,
            )?;
        }
        let mut row = vec![
            k.to_string(),
            csv_out::num(m.approach),
            csv_out::num(m.separation),
            csv_out::num(m.mean_pressure),
            csv_out::num(m.area_fraction),
            m.patches.to_string(),
            pf,
            gf,
        ];
        if self.formats.netcdf {
            let nf = format!("results_step_{k:0width$}.nc");
            m.write_netcdf(&self.set.path(&format!("{d}{nf}"))?, k, self.hardness)?;
            row.push(nf);
        }
        self.rows.push(row);
        let (n0, n1) = m.pressure.dim();
        // The pictures' axes: the solved sample's own length along the first axis (from
        // the surface as read, so a file that carries its sizes — .x3p, .nc, .zip — is
        // drawn too; the scene's keys alone left those without pictures).
        let size = m.physical_sizes()[0];
        if self.pictures && size.is_finite() && size > 0.0 {
            let p: Vec<f64> = m.pressure.iter().map(|v| v * 1e-6).collect();
            crate::plot::heatmap(
                &self
                    .set
                    .path(&format!("{d}pressure_step_{k:0width$}.png"))?,
                &crate::plot::Heatmap {
                    title: format!(
                        "contact pressure, step {k}: g_n = {:.3} µm, mean p = {:.3e} Pa, A/A0 = {:.4}, {} patches",
                        m.separation * 1e6,
                        m.mean_pressure,
                        m.area_fraction,
                        m.patches
                    ),
                    label: "p (MPa)".into(),
                    values: &p,
                    n0,
                    n1,
                    zero_white: true,
                    size,
                },
            )?;
            let g: Vec<f64> = m.gap.iter().map(|v| v * 1e6).collect();
            crate::plot::heatmap(
                &self.set.path(&format!("{d}gap_step_{k:0width$}.png"))?,
                &crate::plot::Heatmap {
                    title: format!(
                        "gap, step {k}: g_n = {:.3} µm, mean gap {:.3} µm",
                        m.separation * 1e6,
                        m.mean_gap * 1e6
                    ),
                    label: "g (µm)".into(),
                    values: &g,
                    n0,
                    n1,
                    zero_white: false,
                    size,
                },
            )?;
        }
        Ok(())
    }
}

/// The header of tangential.csv.
pub const TANGENTIAL_HEADER: [&str; 4] = [
    "force_ratio",
    "tangential_force",
    "tangential_displacement",
    "stick_fraction",
];

/// tangential.csv text (`[load] tangential`, BEM): one row per step of the tangential
/// path, full precision: Q/(μP) (1), Q (N), the flat's tangential displacement (m), the
/// stick area over the contact area (1).
pub fn tangential_csv(t: &strata_engine::solution::TangentialCurve) -> Result<String> {
    Ok(csv_out::text(
        &TANGENTIAL_HEADER,
        t.steps.iter().map(|p| {
            vec![
                csv_out::num(p.force_ratio),
                csv_out::num(p.tangential_force),
                csv_out::num(p.tangential_displacement),
                csv_out::num(p.stick_fraction),
            ]
        }),
    )?)
}

/// tangential.svg: Q/(μP) against the tangential displacement (µm), the path in order.
fn tangential_plot(
    path: &Path,
    t: &strata_engine::solution::TangentialCurve,
    stack: &str,
) -> Result<()> {
    crate::plot::lines(
        path,
        &PlotSpec {
            title: format!(
                "Tangential force against displacement (BEM, μ = {}): {stack}",
                t.coefficient
            ),
            x_label: "tangential displacement (µm)".into(),
            y_label: "Q / (μP)".into(),
            log_x: false,
            log_y: false,
            series: vec![Series {
                name: "BEM partial slip".into(),
                points: t
                    .steps
                    .iter()
                    .map(|p| (p.tangential_displacement * 1e6, p.force_ratio))
                    .collect(),
                style: Style::Line,
            }],
        },
    )
}

/// The steps as JSON objects (curve.json's `steps`).
fn steps_json(steps: &[Step]) -> serde_json::Value {
    serde_json::Value::Array(steps.iter().map(|s| serde_json::json!({
            "delta": s.delta, "gap": s.gap, "load": s.load, "mean_pressure": s.mean_pressure,
            "pressure_ratio": s.pressure_ratio, "area_fraction": s.area_fraction,
            "contacts": s.contacts, "stiffness": s.stiffness, "kkt_residual": s.kkt_residual,
            "newton_steps": s.diagnostics.newton_steps, "evaluations": s.diagnostics.evaluations,
            "validity": {"valid": s.validity.is_valid(), "reason": s.validity.describe(),
                         "below_mean_plane": s.validity.below_mean_plane,
                         "beyond_deepest_valley": s.validity.beyond_deepest_valley,
                         "area_above_nominal": s.validity.area_above_nominal,
                         "overlapping_contacts": s.validity.overlapping_contacts},
        })).collect())
}

/// Whether `dir` holds the curve of an earlier complete run: a `curve.csv` beside a
/// readable `curve.json` without a `partial` record.
fn holds_complete_curve(dir: &Path, memory: &MemoryLimit) -> bool {
    if !dir.join("curve.csv").is_file() {
        return false;
    }
    strata_runtime::resources::read_data_file(&dir.join("curve.json"), "curve.json", memory)
        .ok()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        .is_some_and(|j| j.get("partial").is_none_or(serde_json::Value::is_null))
}

/// Writes curve.csv, curve.json (the summary plus the steps, made here by serde from
/// the typed solution) and the plots into `set`. A partial curve (the path stopped at a
/// failing step) gets a last column `partial`, 1 on every row, so that CSV readers see
/// it too; a complete curve has no such column.
pub fn write_outputs(set: &OutputSet, no_plots: bool, sol: &SceneSolution) -> Result<()> {
    let steps = &sol.steps[..];
    let mut meta = serde_json::to_value(&sol.summary)?;
    meta["steps"] = steps_json(steps);
    // With [plasticity]: each step's plastic quantities in curve.json and the
    // plastic_area_fraction column in curve.csv; with [conductance]: each step's
    // conductance and the conductance column after it (only then: a scene's outputs
    // carry only the effects it asked for).
    if let Some(arr) = meta["steps"].as_array_mut() {
        for (k, s) in arr.iter_mut().enumerate() {
            let Some(s) = s.as_object_mut() else {
                continue;
            };
            let records = [
                sol.plastic
                    .as_ref()
                    .and_then(|p| p.get(k))
                    .map(serde_json::to_value),
                sol.conductance
                    .as_ref()
                    .and_then(|c| c.get(k))
                    .map(serde_json::to_value),
                sol.tangential
                    .as_ref()
                    .and_then(|t| t.get(k))
                    .map(serde_json::to_value),
            ];
            for r in records.into_iter().flatten() {
                if let serde_json::Value::Object(r) = r? {
                    s.extend(r);
                }
            }
        }
    }
    let extra = sol.effect_columns();
    let mut csv = if extra.is_empty() {
        curve_csv(steps)?
    } else {
        curve_csv_extra(steps, &extra)?
    };
    if sol.summary.partial.is_some() {
        // the last column `partial`: 1 on every row (numeric cells only before it)
        csv = csv
            .lines()
            .enumerate()
            .map(|(i, l)| format!("{l},{}\n", if i == 0 { "partial" } else { "1" }))
            .collect();
    }
    set.write("curve.csv", csv.as_bytes())?;
    if let Some(t) = &sol.tangential_path {
        meta["tangential_path"] = serde_json::to_value(t)?;
        set.write("tangential.csv", tangential_csv(t)?.as_bytes())?;
        if !no_plots {
            tangential_plot(&set.path("tangential.svg")?, t, &sol.summary.stack)?;
        }
    }
    set.write(
        "curve.json",
        serde_json::to_string_pretty(&meta)?.as_bytes(),
    )?;
    if !no_plots && steps.iter().any(|s| s.contacts > 0) {
        let model = sol.summary.model_short.clone();
        let stack = sol.summary.stack.clone();
        let pg: Vec<(f64, f64)> = steps
            .iter()
            .map(|s| (s.gap * 1e6, s.pressure_ratio))
            .collect();
        crate::plot::lines(
            &set.path("pressure_gap.svg")?,
            &PlotSpec {
                title: format!("Mean pressure against separation: {model}, {stack}"),
                x_label: "separation g_n (µm)".into(),
                y_label: "p_n / E*1".into(),
                log_x: false,
                log_y: true,
                series: vec![Series {
                    name: model.clone(),
                    points: pg,
                    style: Style::Line,
                }],
            },
        )?;
        let ap: Vec<(f64, f64)> = steps
            .iter()
            .map(|s| (s.pressure_ratio, s.area_fraction))
            .collect();
        crate::plot::lines(
            &set.path("area_pressure.svg")?,
            &PlotSpec {
                title: format!("Real contact area against mean pressure: {model}, {stack}"),
                x_label: "p_n / E*1".into(),
                y_label: "A / A0".into(),
                log_x: false,
                log_y: false,
                series: vec![Series {
                    name: model,
                    points: ap,
                    style: Style::Line,
                }],
            },
        )?;
    }
    Ok(())
}
