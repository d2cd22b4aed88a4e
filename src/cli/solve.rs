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
//!   (A/A₀ against p_n/E*₁), like the paper's Figs. 15–22;
//! - with `[output] maps = "last"` or `"all"` (`model.kind = "bem"` only; the scene
//!   refuses maps for the asperity models, which have no pressure field):
//!   `DIR/maps/pressure_step_KK.npy` (Pa) and `gap_step_KK.npy` (m), n×n f64 in the
//!   surface's orientation, their pictures `pressure_step_KK.png` / `gap_step_KK.png`
//!   (viridis; white = no contact; skipped with `--no-plots`) and `DIR/maps/maps.csv`
//!   (step, δ, g_n, p̄, A/A₀, contact patches, files). KK is the load step, zero-padded.
//!   The contact-patch count of every step is also curve.csv's `contacts` column.
//!
//! A non-empty DIR is refused unless `--force`. Only what the scene needs is computed:
//! a homogeneous stack loads no table (χ = ζ = 1, g = 0); a layered stack loads
//! `stack.table` or builds the table once into the cache and says so; the independent
//! model forms no pairs. The log (stderr) says which effects were simulated.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::scene::{MapsSpec, Scene};
use anyhow::{Context, Result, bail};
use strata_bem::BemSolution;
use strata_runtime::output::write_atomic;
use strata_runtime::rough::Step;

use crate::engine::{EngineOptions, solve_scene};

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

pub fn out_dir_ready(dir: &Path, force: bool) -> Result<()> {
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
    let opts = EngineOptions {
        cache_dir: a.cache_dir.clone(),
        keep_maps: scene.output.maps != MapsSpec::None,
        ..Default::default()
    };
    let sol = solve_scene(&scene, &a.scene, &opts)?;
    write_maps(&a.out, &sol.maps, scene.output.maps, !a.no_plots)?;
    write_outputs(&a.out, a.no_plots, t0, &sol.steps, sol.meta)
}

/// Writes the BEM maps selected by `which` into `DIR/maps` (see the module docs):
/// .npy maps, PNG pictures when `pictures`, and `maps.csv`. Nothing for `None`.
pub fn write_maps(out: &Path, maps: &[BemSolution], which: MapsSpec, pictures: bool) -> Result<()> {
    let picked: Vec<usize> = match which {
        MapsSpec::None => return Ok(()),
        MapsSpec::All => (0..maps.len()).collect(),
        MapsSpec::Last => maps.len().checked_sub(1).into_iter().collect(),
    };
    if picked.is_empty() {
        bail!("output.maps: the solution has no maps (model.kind must be \"bem\")");
    }
    let dir = out.join("maps");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let width = (maps.len() - 1).to_string().len().max(2);
    let mut index = String::from(
        "step,delta,gap,mean_pressure,area_fraction,contacts,pressure_file,gap_file\n",
    );
    for k in picked {
        let m = &maps[k];
        let (pf, gf) = (
            format!("pressure_step_{k:0width$}.npy"),
            format!("gap_step_{k:0width$}.npy"),
        );
        m.write_maps(&dir.join(&pf), &dir.join(&gf))?;
        index.push_str(&format!(
            "{k},{:e},{:e},{:e},{:e},{},{pf},{gf}\n",
            m.approach, m.separation, m.mean_pressure, m.area_fraction, m.patches
        ));
        if pictures {
            let (n0, n1) = m.pressure.dim();
            let p: Vec<f64> = m.pressure.iter().copied().collect();
            crate::plot::heatmap(
                &dir.join(format!("pressure_step_{k:0width$}.png")),
                &crate::plot::Heatmap {
                    title: format!(
                        "pressure, step {k}: g_n = {:.3e} m, mean p = {:.3e} Pa, A/A0 = {:.4}, {} patches",
                        m.separation, m.mean_pressure, m.area_fraction, m.patches
                    ),
                    label: "p (Pa)".into(),
                    values: &p,
                    n0,
                    n1,
                    zero_white: true,
                },
            )?;
            let g: Vec<f64> = m.gap.iter().copied().collect();
            crate::plot::heatmap(
                &dir.join(format!("gap_step_{k:0width$}.png")),
                &crate::plot::Heatmap {
                    title: format!(
                        "gap, step {k}: g_n = {:.3e} m, mean gap {:.3e} m",
                        m.separation, m.mean_gap
                    ),
                    label: "g (m)".into(),
                    values: &g,
                    n0,
                    n1,
                    zero_white: false,
                },
            )?;
        }
    }
    write_atomic(&dir.join("maps.csv"), index.as_bytes())?;
    Ok(())
}

/// Writes curve.csv, curve.json (`meta` plus the steps) and the plots.
pub fn write_outputs(
    out: &Path,
    no_plots: bool,
    t0: Instant,
    steps: &[Step],
    mut meta: serde_json::Value,
) -> Result<()> {
    meta["steps"] = serde_json::Value::Array(steps.iter().map(|s| serde_json::json!({
            "delta": s.delta, "gap": s.gap, "load": s.load, "mean_pressure": s.mean_pressure,
            "pressure_ratio": s.pressure_ratio, "area_fraction": s.area_fraction,
            "contacts": s.contacts, "stiffness": s.stiffness, "kkt_residual": s.kkt_residual,
            "validity": {"valid": s.validity.is_valid(), "below_mean_plane": s.validity.below_mean_plane,
                         "beyond_deepest_valley": s.validity.beyond_deepest_valley,
                         "area_above_nominal": s.validity.area_above_nominal,
                         "overlapping_contacts": s.validity.overlapping_contacts},
        })).collect());
    let json = meta;
    write_atomic(
        &out.join("curve.json"),
        serde_json::to_string_pretty(&json)?.as_bytes(),
    )?;
    if !no_plots && steps.iter().any(|s| s.contacts > 0) {
        let pg: Vec<(f64, f64)> = steps.iter().map(|s| (s.gap, s.pressure_ratio)).collect();
        crate::plot::lines(
            &out.join("pressure_gap.svg"),
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
            &out.join("area_pressure.svg"),
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
    // curve.csv last: a run that fails or is interrupted before this point leaves no
    // new curve (and an existing one untouched), never a curve that looks complete.
    write_atomic(&out.join("curve.csv"), curve_csv(steps).as_bytes())?;
    eprintln!(
        "wrote {} steps to {} in {:.3} s",
        steps.len(),
        out.display(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
