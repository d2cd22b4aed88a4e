//! `strata ratio-map --out DIR`: the tangential-to-normal stiffness ratio K_t/K_n of
//! the shipped stacks, between its two limits — a developers' command that makes
//! docs/figures/tangential-ratio-asperity.svg and tangential-ratio-rough.svg (shown in
//! docs/guide/friction.md).
//!
//! - One asperity (`ratio_asperity.csv`, `.svg`): K_t/K_n of one contact disc of radius a
//!   against a/h₁, K_n = 2E*₁aψ_zz the frictionless flat punch and K_t the full-stick
//!   disc ([`strata_tablegen::stiffness`], direct Fredholm solves: `strata stiffness`),
//!   for every stack of `--stacks`. A half-space has no h₁: its ratio (Mindlin's, at every
//!   a) is drawn over the axis.
//! - Rough surfaces (`ratio_rough.csv`, `.svg`): K_t/K_n of the sample against p_n/E*₁
//!   along each scene of `--scenes` with `[friction]` added (μ = 0.3; μ enters no
//!   stiffness), the N and the I model: K_t the `tangential_stiffness` and K_n the
//!   `stiffness` (dP/dδ) of curve.csv.
//! - The limits (dashed): Mindlin's 2(1 − ν)/(2 − ν) (= 8μa/(2 − ν) over 2E*a, a disc
//!   small against the layers) and the thin layer on a rigid base,
//!   Σ(h/M)/Σ(h/μ) = (1 − 2ν)/(2(1 − ν)) for one ν (a disc wide against the layers;
//!   M = E(1 − ν)/((1 + ν)(1 − 2ν))), for each ν the stacks have.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use strata_runtime::{Base, Solid, Stack};
use strata_tablegen::stiffness::Stiffness;

use crate::engine::{EngineOptions, Quiet, solve};
use crate::plot::{self, PlotSpec, Series, Style};
use crate::scene::{FrictionSpec, ModelKind, Scene};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output directory (created; existing files in it are replaced only with --force).
    #[arg(long)]
    pub out: PathBuf,
    /// Stack files of the one-asperity map.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "tables/stacks/half-space-steel.toml,tables/stacks/coating-on-steel.toml,\
tables/stacks/paper-two-layer-E2E1-0.2.toml,tables/stacks/paper-two-layer-E2E1-1.toml,\
tables/stacks/paper-two-layer.toml,tables/stacks/polymer-on-cooled-base.toml"
    )]
    pub stacks: Vec<PathBuf>,
    /// Scenes of the rough-surface map (N or I model; each solved with both).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "scenes/homogeneous-km10-independent.toml,\
scenes/paper-E2E1-0.2-interacting.toml,scenes/paper-E2E1-1-interacting.toml,\
scenes/paper-E2E1-5-interacting.toml"
    )]
    pub scenes: Vec<PathBuf>,
    /// Radii per decade of a/h₁ (one-asperity map, from 1e-2 to 1e2).
    #[arg(long, default_value_t = 4)]
    pub per_decade: usize,
    /// Plot format.
    #[arg(long, value_parser = ["svg", "png"], default_value = "svg")]
    pub format: String,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    /// Table cache (the stacks' disc-stiffness tables; default as `strata solve`).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
}

/// Mindlin's K_t/K_n of a disc on a half-space of Poisson ratio ν: 2(1 − ν)/(2 − ν).
pub fn mindlin_ratio(nu: f64) -> f64 {
    2.0 * (1.0 - nu) / (2.0 - nu)
}

/// The thin-layer K_t/K_n of `stack` on a rigid base, Σ(h/M)/Σ(h/μ); `None` on an
/// elastic base (a wide disc then sees the base's half-space: Mindlin's ratio of it).
pub fn thin_layer_ratio(stack: &Stack) -> Option<f64> {
    if !matches!(stack.base(), Base::Rigid) {
        return None;
    }
    let (mut by_m, mut by_mu) = (0.0, 0.0);
    for l in stack.layers() {
        let (e, nu) = (l.young, l.poisson);
        let m = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        by_m += l.thickness / m;
        by_mu += l.thickness / mu;
    }
    Some(by_m / by_mu)
}

const COLOURS: [(u8, u8, u8); 6] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
];

fn name_of(p: &std::path::Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The limits' colours (none a stack's).
const LIMIT_COLOURS: [(u8, u8, u8); 6] = [
    (0, 0, 0),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
    (227, 119, 194),
    (90, 90, 160),
];

/// Horizontal dashed lines at the limits `values` (label, value) over `x`.
fn limit_series(values: &[(String, f64)], x: (f64, f64)) -> Vec<Series> {
    values
        .iter()
        .enumerate()
        .map(|(i, (label, v))| Series {
            name: format!("{label}: {v:.3}"),
            points: vec![(x.0, *v), (x.1, *v)],
            style: Style::Dashed {
                rgb: LIMIT_COLOURS[i % LIMIT_COLOURS.len()],
            },
        })
        .collect()
}

/// Each ν's Mindlin and thin-layer limits over `stacks`, labelled, without repeats.
fn limits(stacks: &[Stack]) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> = Vec::new();
    let mut push = |label: String, v: f64| {
        if !out.iter().any(|(_, w)| (w - v).abs() < 1e-9) {
            out.push((label, v));
        }
    };
    for s in stacks {
        let nu = s.top_material().1;
        push(format!("Mindlin, ν = {nu}"), mindlin_ratio(nu));
        if let Base::Elastic { poisson, .. } = s.base() {
            push(format!("Mindlin, ν = {poisson}"), mindlin_ratio(poisson));
        }
        if let Some(t) = thin_layer_ratio(s) {
            push(format!("thin layer, ν = {nu}"), t);
        }
    }
    out
}

pub fn run(a: Args) -> Result<()> {
    if a.per_decade == 0 || a.per_decade > 50 {
        bail!("--per-decade {}: 1 to 50 radii a decade", a.per_decade);
    }
    std::fs::create_dir_all(&a.out).with_context(|| format!("--out {}", a.out.display()))?;
    let (asperity_plot, rough_plot) = (
        format!("ratio_asperity.{}", a.format),
        format!("ratio_rough.{}", a.format),
    );
    let files = [
        "ratio_asperity.csv",
        asperity_plot.as_str(),
        "ratio_rough.csv",
        rough_plot.as_str(),
    ];
    if !a.force
        && let Some(f) = files.iter().find(|f| a.out.join(f).exists())
    {
        bail!(
            "--out {}: {f} exists (--force replaces it)",
            a.out.display()
        );
    }
    // one asperity: direct solves against a/h1
    let n = 4 * a.per_decade;
    let x_over_h: Vec<f64> = (0..=n)
        .map(|i| 10f64.powf(-2.0 + 4.0 * i as f64 / n as f64))
        .collect();
    let mut csv = String::from("stack,a_over_h1,a,normal_stiffness,tangential_stiffness,ratio\n");
    let mut series = Vec::new();
    let mut stacks = Vec::new();
    let bar = crate::progress::bar(
        (a.stacks.len() * x_over_h.len()) as u64,
        "ratio map: one-asperity discs",
    );
    for (k, path) in a.stacks.iter().enumerate() {
        let bodies = strata_runtime::Bodies::from_toml_file(path)
            .with_context(|| format!("--stacks {}", path.display()))?;
        let stack = bodies.first.clone();
        let solver = Stiffness::new(&bodies);
        // a half-space has no h1: any length scale gives the same ratio
        let h1 = stack.top_thickness().unwrap_or(1e-4);
        let mut pts = Vec::new();
        for &x in &x_over_h {
            let d = solver
                .at(x * h1)
                .with_context(|| format!("stack {}: a/h1 = {x:e}", path.display()))?;
            let r = d.tangential / d.normal;
            csv.push_str(&format!(
                "{},{x:e},{:e},{:e},{:e},{r:e}\n",
                name_of(path),
                d.a,
                d.normal,
                d.tangential
            ));
            pts.push((x, r));
            bar.inc();
        }
        series.push(Series {
            name: name_of(path),
            points: pts,
            style: Style::Rgb {
                rgb: COLOURS[k % COLOURS.len()],
                faint: false,
            },
        });
        stacks.push(stack);
    }
    drop(bar);
    let lims = limits(&stacks);
    series.extend(limit_series(
        &lims,
        (x_over_h[0], x_over_h[x_over_h.len() - 1]),
    ));
    std::fs::write(a.out.join("ratio_asperity.csv"), &csv)?;
    plot::lines(
        &a.out.join(&asperity_plot),
        &PlotSpec {
            title: "K_t/K_n of one contact disc: full-stick disc over frictionless flat punch"
                .into(),
            x_label: "a/h₁ (disc radius over the top layer's thickness)".into(),
            y_label: "K_t/K_n".into(),
            log_x: true,
            log_y: true,
            series,
        },
    )?;

    // rough surfaces: N and I model with [friction] along each scene's load
    let opts = EngineOptions {
        cache_dir: a.cache_dir.clone(),
        ..Default::default()
    };
    let mut csv = String::from(
        "scene,model,mean_pressure,pressure_over_e_star,stiffness,tangential_stiffness,ratio\n",
    );
    let mut series = Vec::new();
    let (mut x_lo, mut x_hi) = (f64::INFINITY, 0.0f64);
    let mut rough_stacks = Vec::new();
    for (k, path) in a.scenes.iter().enumerate() {
        let base =
            Scene::from_file(path).with_context(|| format!("--scenes {}", path.display()))?;
        rough_stacks.push(base.bodies.first.clone());
        let e_star = base.bodies.contact_modulus();
        for (kind, label) in [(ModelKind::Independent, "N"), (ModelKind::Interacting, "I")] {
            let mut scene = base.clone();
            scene.model.kind = kind;
            scene.friction = Some(FrictionSpec { coefficient: 0.3 });
            crate::progress::log(format!("ratio map: {} ({label} model)", path.display()));
            let sol = solve(&scene, None, &opts, &mut Quiet)
                .with_context(|| format!("scene {} ({label} model)", path.display()))?;
            let kt = sol
                .tangential_stiffnesses()
                .context("no tangential stiffness")?;
            let mut pts = Vec::new();
            for (s, k) in sol.steps.iter().zip(&kt) {
                if s.stiffness <= 0.0 || s.mean_pressure <= 0.0 {
                    continue;
                }
                let x = s.mean_pressure / e_star;
                let r = k / s.stiffness;
                csv.push_str(&format!(
                    "{},{label},{:e},{x:e},{:e},{k:e},{r:e}\n",
                    name_of(path),
                    s.mean_pressure,
                    s.stiffness
                ));
                x_lo = x_lo.min(x);
                x_hi = x_hi.max(x);
                pts.push((x, r));
            }
            let rgb = COLOURS[k % COLOURS.len()];
            series.push(Series {
                name: format!("{}, {label} model", name_of(path)),
                points: pts,
                style: match kind {
                    ModelKind::Independent => Style::Dashed { rgb },
                    _ => Style::Rgb { rgb, faint: false },
                },
            });
        }
    }
    if !x_lo.is_finite() {
        bail!("--scenes: no step in contact");
    }
    series.extend(limit_series(&limits(&rough_stacks), (x_lo, x_hi)));
    std::fs::write(a.out.join("ratio_rough.csv"), &csv)?;
    plot::lines(
        &a.out.join(&rough_plot),
        &PlotSpec {
            title: "K_t/K_n of rough surfaces: full-stick tangential over normal stiffness (dP/dδ)"
                .into(),
            x_label: "p_n/E*₁".into(),
            y_label: "K_t/K_n".into(),
            log_x: true,
            log_y: true,
            series,
        },
    )?;
    crate::progress::log(format!(
        "ratio map: wrote {} in {}",
        files.join(", "),
        a.out.display()
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The limits' closed forms: Mindlin 8μa/(2−ν) over 2E*a, and the thin layer
    /// μ/M for one ν (0.919 and 0.412 at ν = 0.15).
    #[test]
    fn ratio_map_limits() {
        let nu: f64 = 0.15;
        let e = 4e9;
        let mu = e / (2.0 * (1.0 + nu));
        let e_star = e / (1.0 - nu * nu);
        let per_disc = (8.0 * mu / (2.0 - nu)) / (2.0 * e_star);
        assert!((mindlin_ratio(nu) - per_disc).abs() < 1e-15);
        assert!((mindlin_ratio(nu) - 0.918_918_918_918_919).abs() < 1e-12);
        let s = Stack::paper_two_layer(5.0).unwrap();
        let t = thin_layer_ratio(&s).unwrap();
        assert!(
            (t - (1.0 - 2.0 * nu) / (2.0 * (1.0 - nu))).abs() < 1e-15,
            "{t}"
        );
        assert!(thin_layer_ratio(&Stack::half_space(e, nu).unwrap()).is_none());
    }
}
