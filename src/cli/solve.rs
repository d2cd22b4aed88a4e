//! `strata solve SCENE.toml --out DIR`: load curve of a rough contact (issue 5).
//!
//! Writes, atomically (temporary file + rename):
//! - `DIR/curve.csv`, header exactly
//!   `delta,gap,mean_pressure,pressure_ratio,area_fraction,contacts,stiffness`
//!   (SI: δ and g_n in m, p_n in Pa, p_n/E*₁ and A/A₀ dimensionless, stiffness dP/dδ
//!   of the whole sample in N/m);
//! - `DIR/curve.json`: the same per step plus the KKT residual, the scene summary and
//!   which effects were simulated;
//! - `DIR/pressure_gap.svg` (p_n/E*₁ against g_n, log y) and `DIR/area_pressure.svg`
//!   (A/A₀ against p_n/E*₁), like the paper's Figs. 15–22.
//!
//! A non-empty DIR is refused unless `--force`. Only what the scene needs is computed:
//! a homogeneous stack loads no table (χ = ζ = 1, g = 0); a layered stack loads
//! `stack.table` or builds the table once into the cache and says so; the independent
//! model forms no pairs. The log (stderr) says which effects were simulated.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::output::write_atomic;
use strata_runtime::rough::{Images, Model, RoughContact, Step};
use strata_runtime::scene::{LoadSpec, ModelKind, Scene};
use strata_runtime::summits::find_summits;
use strata_runtime::table::Table;

use crate::plot::{PlotSpec, Series, Style};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite files in a non-empty output directory.
    #[arg(long)]
    pub force: bool,
    /// Where missing tables of layered stacks are built and cached
    /// (default: `.strata-cache` beside the scene).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    /// Skip the plots.
    #[arg(long)]
    pub no_plots: bool,
}

fn law_for(scene: &Scene, scene_path: &Path, cache: Option<&Path>) -> Result<Box<dyn AsperityLaw>> {
    let stack = &scene.stack;
    if stack.is_homogeneous() {
        eprintln!(
            "stack: homogeneous (E* = {:e} Pa): Hertz asperities, no table loaded",
            stack.top_plane_strain_modulus()
        );
        return Ok(Box::new(Homogeneous {
            e_star: stack.top_plane_strain_modulus(),
        }));
    }
    let table = match &scene.table {
        Some(p) if p.is_file() => {
            eprintln!("stack: layered, table {}", p.display());
            Table::load(p).with_context(|| format!("stack.table: {}", p.display()))?
        }
        Some(p) => {
            eprintln!(
                "stack: layered, table {} missing: building it once (this takes a while)…",
                p.display()
            );
            let t = strata_tablegen::tablebuild::build(stack, &Default::default())
                .context("building the table for the scene's stack")?;
            t.save(p)
                .with_context(|| format!("stack.table: saving {}", p.display()))?;
            eprintln!("stack: table built and cached at {}", p.display());
            t
        }
        None => {
            let dir = match cache {
                Some(d) => d.to_path_buf(),
                None => scene_path
                    .parent()
                    .unwrap_or(Path::new("."))
                    .join(".strata-cache"),
            };
            eprintln!(
                "stack: layered, no table given: using the cache in {} (built once if missing)",
                dir.display()
            );
            let (t, p) =
                strata_tablegen::tablebuild::build_and_cache(stack, &dir, &Default::default())
                    .context("building/caching the table for the scene's stack")?;
            eprintln!("stack: table {}", p.display());
            t
        }
    };
    let law = table
        .law_for(stack)
        .context("stack.table does not serve the scene's stack")?;
    Ok(Box::new(law))
}

fn out_dir_ready(dir: &Path, force: bool) -> Result<()> {
    if dir.exists() {
        if !dir.is_dir() {
            bail!("--out {}: exists and is not a directory", dir.display());
        }
        let non_empty = std::fs::read_dir(dir)
            .with_context(|| format!("--out {}", dir.display()))?
            .next()
            .is_some();
        if non_empty && !force {
            bail!(
                "--out {}: directory is not empty (use --force to overwrite)",
                dir.display()
            );
        }
    } else {
        std::fs::create_dir_all(dir).with_context(|| format!("--out {}", dir.display()))?;
    }
    Ok(())
}

/// CSV body with the fixed header; full precision.
pub fn curve_csv(steps: &[Step]) -> String {
    let mut s =
        String::from("delta,gap,mean_pressure,pressure_ratio,area_fraction,contacts,stiffness\n");
    for st in steps {
        s.push_str(&format!(
            "{:e},{:e},{:e},{:e},{:e},{},{:e}\n",
            st.delta,
            st.gap,
            st.mean_pressure,
            st.pressure_ratio,
            st.area_fraction,
            st.contacts,
            st.stiffness
        ));
    }
    s
}

pub fn run(a: Args) -> Result<()> {
    let t0 = Instant::now();
    let scene =
        Scene::from_file(&a.scene).with_context(|| format!("scene {}", a.scene.display()))?;
    out_dir_ready(&a.out, a.force)?;
    let model = match scene.model.kind {
        ModelKind::Independent => Model::Independent,
        ModelKind::Interacting => Model::Interacting(scene.model.images),
        ModelKind::Bem => return run_bem(&scene, &a, t0),
    };
    let surface = scene.load_surface().context("surface")?;
    let (n0, n1) = surface.shape();
    let found = find_summits(&surface);
    eprintln!(
        "surface: {n0}×{n1}, L = {:e} m, {}, RMS {:e} m; {} summits ({} dropped for κ ≤ 0)",
        surface.extent().0,
        if surface.is_periodic() {
            "periodic"
        } else {
            "non-periodic"
        },
        surface.rms(),
        found.summits.len(),
        found.dropped_nonpositive_curvature
    );
    let law = law_for(&scene, &a.scene, a.cache_dir.as_deref())?;
    let rc = RoughContact::from_surface(law.as_ref(), &surface)?;
    let effects = match model {
        Model::Independent => {
            "independent asperities (N model): no interactions, no pairs".to_string()
        }
        Model::Interacting(Images::Isolated) => {
            "interacting asperities (I model), isolated sample: interactions inside the sample only"
                .into()
        }
        Model::Interacting(Images::Periodic(m)) => format!(
            "interacting asperities (I model), periodic images on a {0}×{0} block of cells",
            2 * m + 1
        ),
    };
    let layered = if law.is_homogeneous() {
        "homogeneous solid (χ = ζ = 1, g = 0)"
    } else {
        "layered solid (χ, ζ from the table; g too for the I model)"
    };
    eprintln!("simulating: {effects}; {layered}");
    let steps: Vec<Step> = match scene
        .load
        .approaches(rc.top_to_mean(), rc.max_delta())
        .context("load")?
    {
        Some(d) => rc.curve(model, &d)?,
        None => {
            let LoadSpec::MeanPressures(ps) = &scene.load else {
                bail!("load: internal error");
            };
            let mut out: Vec<Step> = Vec::new();
            let mut warm: Vec<f64> = Vec::new();
            for (i, &p) in ps.iter().enumerate() {
                let s = rc
                    .solve_pressure(model, p, &warm)
                    .with_context(|| format!("load.mean_pressures[{i}]"))?;
                warm = s.radii.clone();
                out.push(s);
            }
            out
        }
    };
    if let Some(w) = steps
        .iter()
        .filter_map(|s| s.kkt_residual)
        .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))
    {
        eprintln!("I model: largest KKT residual {w:.2e} (relative to the largest interference)");
    }
    let meta = serde_json::json!({
        "scene": a.scene.display().to_string(),
        "model": effects,
        "solid": layered,
        "e_star_1": law.e_star(),
        "nominal_area": rc.area(),
        "summits": rc.summits().len(),
        "z_max_minus_mean": rc.top_to_mean(),
        "units": {"delta": "m", "gap": "m", "mean_pressure": "Pa", "pressure_ratio": "1",
                  "area_fraction": "1", "stiffness": "N/m (dP/dδ of the sample)"},
    });
    write_outputs(&a, t0, &steps, meta)
}

/// Writes curve.csv, curve.json (`meta` plus the steps) and the plots.
fn write_outputs(a: &Args, t0: Instant, steps: &[Step], mut meta: serde_json::Value) -> Result<()> {
    write_atomic(&a.out.join("curve.csv"), curve_csv(steps).as_bytes())?;
    meta["steps"] = serde_json::Value::Array(steps.iter().map(|s| serde_json::json!({
            "delta": s.delta, "gap": s.gap, "load": s.load, "mean_pressure": s.mean_pressure,
            "pressure_ratio": s.pressure_ratio, "area_fraction": s.area_fraction,
            "contacts": s.contacts, "stiffness": s.stiffness, "kkt_residual": s.kkt_residual,
        })).collect());
    let json = meta;
    write_atomic(
        &a.out.join("curve.json"),
        serde_json::to_string_pretty(&json)?.as_bytes(),
    )?;
    if !a.no_plots && steps.iter().any(|s| s.contacts > 0) {
        let pg: Vec<(f64, f64)> = steps.iter().map(|s| (s.gap, s.pressure_ratio)).collect();
        crate::plot::lines(
            &a.out.join("pressure_gap.svg"),
            &PlotSpec {
                title: "mean pressure against separation".into(),
                x_label: "g_n (m)".into(),
                y_label: "p_n / E*1".into(),
                log_x: false,
                log_y: true,
                series: vec![Series {
                    name: "strata".into(),
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
            &a.out.join("area_pressure.svg"),
            &PlotSpec {
                title: "real contact area against mean pressure".into(),
                x_label: "p_n / E*1".into(),
                y_label: "A / A0".into(),
                log_x: false,
                log_y: false,
                series: vec![Series {
                    name: "strata".into(),
                    points: ap,
                    style: Style::Line,
                }],
            },
        )?;
    }
    eprintln!(
        "wrote {} steps to {} in {:.3} s",
        steps.len(),
        a.out.display(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

/// `model.kind = "bem"`: the periodic FFT boundary-element solution of the whole
/// surface (runtime `bem`), with the layered kernel 2S(|k|)/(E*₁|k|) computed from the
/// stack (no χ, ζ, g table is needed or loaded). Same outputs as the asperity models;
/// `contacts` counts contact patches and the stiffness dP/dδ comes from one extra,
/// warm-started solve at δ(1 + 1e-4) per step (its error ~ tolerance/1e-4 ≈ 1e-6).
fn run_bem(scene: &Scene, a: &Args, t0: Instant) -> Result<()> {
    use strata_runtime::bem::{BemLoad, BemOptions, BemSolver};
    let surface = scene.load_surface().context("surface")?;
    let (n0, n1) = surface.shape();
    if !surface.is_periodic() {
        bail!(
            "model.kind = \"bem\": the boundary-element solver is periodic; set surface.periodic = true"
        );
    }
    let heights = ndarray::Array2::from_shape_vec((n0, n1), surface.heights().to_vec())
        .context("surface: heights")?;
    let size = surface.extent().0;
    let stack = &scene.stack;
    let solver = BemSolver::new(&heights, size, stack, BemOptions::default())
        .context("model.kind = \"bem\"")?;
    let z_max = surface.heights().iter().copied().fold(f64::MIN, f64::max);
    let z_min = surface.heights().iter().copied().fold(f64::MAX, f64::min);
    let top_to_mean = z_max - surface.mean();
    let solid = if stack.is_homogeneous() {
        "homogeneous solid (kernel 2/(E*|k|))".to_string()
    } else {
        format!(
            "layered solid ({} layers; kernel 2S(|k|)/(E*₁|k|) with S computed from the stack)",
            stack.layers().len()
        )
    };
    let effects = format!("full-field boundary elements on the {n0}×{n1} grid, periodic");
    eprintln!(
        "surface: {n0}×{n1}, L = {size:e} m, periodic, RMS {:e} m",
        surface.rms()
    );
    eprintln!("simulating: {effects}; {solid}");
    let loads: Vec<(String, BemLoad)> = match scene
        .load
        .approaches(top_to_mean, z_max - z_min)
        .context("load")?
    {
        Some(d) => d
            .into_iter()
            .enumerate()
            .map(|(i, d)| (format!("load step {i}"), BemLoad::Approach(d)))
            .collect(),
        None => {
            let LoadSpec::MeanPressures(ps) = &scene.load else {
                bail!("load: internal error");
            };
            ps.iter()
                .enumerate()
                .map(|(i, &p)| {
                    (
                        format!("load.mean_pressures[{i}]"),
                        BemLoad::MeanPressure(p),
                    )
                })
                .collect()
        }
    };
    let area = size * size;
    let mut steps = Vec::with_capacity(loads.len());
    let mut warm: Option<Vec<f64>> = None;
    let mut worst_error = 0.0f64;
    for (name, load) in loads {
        let sol = solver
            .solve_from(load, warm.as_deref())
            .with_context(|| name.clone())?;
        let flat: Vec<f64> = sol.pressure.iter().copied().collect();
        let dd = 1e-4 * sol.approach.abs().max(1e-3 * surface.rms());
        let next = solver
            .solve_from(BemLoad::Approach(sol.approach + dd), Some(&flat))
            .with_context(|| format!("{name}: stiffness"))?;
        worst_error = worst_error.max(sol.error).max(next.error);
        steps.push(Step {
            delta: sol.approach,
            gap: sol.separation,
            load: sol.total_load,
            mean_pressure: sol.mean_pressure,
            pressure_ratio: sol.pressure_ratio,
            area_fraction: sol.area_fraction,
            contacts: sol.patches,
            stiffness: (next.total_load - sol.total_load) / dd,
            kkt_residual: None,
            iterations: sol.iterations,
            radii: Vec::new(),
        });
        warm = Some(flat);
    }
    eprintln!("BEM: largest final CG error {worst_error:.2e}");
    let meta = serde_json::json!({
        "scene": a.scene.display().to_string(),
        "model": effects,
        "solid": solid,
        "e_star_1": stack.top_plane_strain_modulus(),
        "nominal_area": area,
        "z_max_minus_mean": top_to_mean,
        "bem_final_error": worst_error,
        "units": {"delta": "m", "gap": "m", "mean_pressure": "Pa", "pressure_ratio": "1",
                  "area_fraction": "1", "stiffness": "N/m (dP/dδ of the sample)",
                  "contacts": "contact patches"},
    });
    write_outputs(a, t0, &steps, meta)
}
