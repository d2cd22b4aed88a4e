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
use strata_runtime::output::write_atomic;
use strata_runtime::rough::Step;
use strata_runtime::scene::Scene;

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
        ..Default::default()
    };
    let sol = solve_scene(&scene, &a.scene, &opts)?;
    write_outputs(&a.out, a.no_plots, t0, &sol.steps, sol.meta)
}

/// Writes curve.csv, curve.json (`meta` plus the steps) and the plots.
pub fn write_outputs(
    out: &Path,
    no_plots: bool,
    t0: Instant,
    steps: &[Step],
    mut meta: serde_json::Value,
) -> Result<()> {
    write_atomic(&out.join("curve.csv"), curve_csv(steps).as_bytes())?;
    meta["steps"] = serde_json::Value::Array(steps.iter().map(|s| serde_json::json!({
            "delta": s.delta, "gap": s.gap, "load": s.load, "mean_pressure": s.mean_pressure,
            "pressure_ratio": s.pressure_ratio, "area_fraction": s.area_fraction,
            "contacts": s.contacts, "stiffness": s.stiffness, "kkt_residual": s.kkt_residual,
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
    eprintln!(
        "wrote {} steps to {} in {:.3} s",
        steps.len(),
        out.display(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
