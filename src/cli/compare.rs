//! `strata compare SCENE.toml… --out DIR`: model accuracy. Each scene's
//! surface, stack and load are solved three times: with the independent asperities
//! (N model), the interacting asperities (I model, the scene's `model.images`) and the
//! full-field boundary elements (BEM, the reference); the scene's own `model.kind` is
//! ignored. A non-periodic (measured) surface is compared as an isolated sample: the
//! I model without images, the BEM on the unbounded solid (zero-padded convolution).
//!
//! Differences, per BEM load step k (separation g_k, mean pressure p_k, area A_k):
//! - pressure at equal separation: p_X(g_k)/p_k − 1 for X = N, I, where p_X(g) is the
//!   model's own step when its separation equals g_k (approach and separation loads:
//!   the same δ gives the same g_n = z_M − z̄ − δ in every model) and otherwise ln p
//!   interpolated linearly in g between the model's steps (empty outside its range);
//! - area at equal pressure: A_X(p_k)/A_k − 1, A_X(p) interpolated log–log between the
//!   model's steps (exact at a step of equal pressure, e.g. `mean_pressures` loads).
//!
//! Writes, for one scene, into DIR (for several, into `DIR/<scene stem>/` each, plus the
//! combined files below):
//! - `compare.csv`: per BEM step `step,delta,separation,pressure_ratio_bem,p_bem,p_n,
//!   p_i,rel_p_n,rel_p_i,area_bem,area_n,area_i,area_n_at_p,area_i_at_p,rel_area_n,
//!   rel_area_i,contacts_bem,contacts_n,contacts_i` (SI: m, Pa; `rel_*` signed;
//!   `area_n`, `area_i`, `contacts_*` = A/A₀ and contacts of the model's step of equal
//!   separation, `area_*_at_p` = A/A₀ at the BEM pressure; `contacts_bem` counts contact
//!   patches, the others asperities in contact; empty = no such step / outside the
//!   model's range);
//! - `compare.md`: the wall time of each model and the max and median |differences|,
//!   then the per-step table;
//! - `curve_independent.csv`, `curve_interacting.csv`, `curve_bem.csv` (the
//!   `strata solve` curve.csv of each model, with `[friction]` its
//!   `tangential_stiffness` column too) and, with `[load] tangential`, the BEM's
//!   `tangential_bem.csv` (`strata solve`'s tangential.csv);
//! - plots `pressure_gap.svg` (p_n/E*₁ against g_n, log y) and `area_pressure.svg`
//!   (A/A₀ against p_n/E*₁), the three models (skipped with `--no-plots`);
//! - BEM maps under `maps/` when the scene asks for them (`[output] maps`);
//! - with `[conductance]` in the scene: `conductance.csv`
//!   (`step,separation,p_bem,conductance_bem,conductance_n,rel_conductance_n,
//!   conductance_i,rel_conductance_i`, the N and I models' h_c at each BEM step's
//!   separation) and a conductance section in `compare.md` (errors and times per model).
//!
//! With several scenes, DIR also gets `compare.md` (every scene's summary), and plots
//! of all scenes together: `pressure_gap.svg`, `area_pressure.svg` (N, I, BEM: the
//! paper's Figs. 17–18 with the BEM added) and `pressure_gap_I_bem.svg`,
//! `area_pressure_I_bem.svg` (I model against the BEM: the paper's Figs. 15–16 with the
//! BEM in the place of the FEM). Wall times exclude surface generation and table
//! loading; they are one run each, on whatever else the machine is doing.

use std::path::{Path, PathBuf};
use std::time::Instant;
use strata_runtime::resources::MemoryLimit;

use crate::csv_out::{self, num};
use crate::output_set::{OutputSet, refuse_inputs};
use crate::progress;
use crate::scene::{ModelKind, Scene};
use anyhow::{Context, Result, bail};
use strata_runtime::rough::{Images, Step};

use crate::cli::solve::{MapWriter, curve_csv_extra};
use crate::contact_law::ContactLaw;
use crate::engine::{EngineOptions, WithMaps, solve};
use crate::plot::{PlotSpec, Series, Style};
use strata_runtime::conduction::ConductionKind;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scene file(s) (TOML): surface, stack and load; `model.images` sets the I model's
    /// images, `model.kind` is ignored (all three models are run).
    #[arg(required = true)]
    pub scenes: Vec<PathBuf>,
    /// Output directory (created if missing).
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
    /// Legend labels of the scenes, comma-separated, one per scene
    /// (default: the stack's name, else the scene file's stem).
    #[arg(long, value_delimiter = ',')]
    pub labels: Vec<String>,
}

/// The three models, in table order.
const MODELS: [(&str, &str); 3] = [
    ("independent", "N model"),
    ("interacting", "I model"),
    ("bem", "BEM"),
];

/// One model's solution of a scene.
#[derive(Debug, Clone)]
pub struct ModelRun {
    pub steps: Vec<Step>,
    pub seconds: f64,
    /// With `[conductance]`: h_c per step (`None` otherwise).
    pub conductance: Option<Vec<f64>>,
    /// With `[plasticity]`: the plastic area fraction per step (every model).
    pub plastic: Option<Vec<f64>>,
    /// The conductance's own time (s; 0 without).
    pub conductance_seconds: f64,
}

/// One row of compare.csv (see the module docs); NaN = outside the model's range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    pub delta: f64,
    pub separation: f64,
    pub pressure_ratio_bem: f64,
    pub p_bem: f64,
    pub p: [f64; 2],
    pub rel_p: [f64; 2],
    pub area_bem: f64,
    pub area: [f64; 2],
    pub area_at_p: [f64; 2],
    pub rel_area: [f64; 2],
    pub contacts_bem: usize,
    pub contacts: [Option<usize>; 2],
}

/// Relative closeness under which two separations are the same load (δ → g_n round-off).
const SAME: f64 = 1e-12;

/// p_X at separation `g` (Pa): the step with that separation if there is one (relative
/// to `scale` = z_M − z̄, within 1e-12), else ln p linear in g between the two steps
/// around g (p linear if one of them is 0); NaN outside the steps' range.
pub fn pressure_at_separation(steps: &[Step], g: f64, scale: f64) -> (f64, Option<usize>) {
    let pts: Vec<(f64, f64)> = steps.iter().map(|s| (s.gap, s.mean_pressure)).collect();
    match value_at_separation(&pts, g, scale) {
        (v, Some(k)) => (v, Some(steps[k].contacts)),
        (v, None) => (v, None),
    }
}

/// A quantity y (> 0 where it grows with the load: a pressure, a conductance) at
/// separation `g` (m) from the steps' (gap, y): the step with that separation (its
/// index; relative to `scale` = z_M − z̄, within 1e-12), else ln y linear in g between
/// the two steps around g (y linear if one of them is 0); NaN outside their range.
fn value_at_separation(pts: &[(f64, f64)], g: f64, scale: f64) -> (f64, Option<usize>) {
    if let Some(k) = pts
        .iter()
        .position(|&(gap, _)| (gap - g).abs() <= SAME * scale.abs().max(g.abs()))
    {
        return (pts[k].1, Some(k));
    }
    let mut pts = pts.to_vec();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in pts.windows(2) {
        let ((g0, p0), (g1, p1)) = (w[0], w[1]);
        if g0 <= g && g <= g1 && g1 > g0 {
            let t = (g - g0) / (g1 - g0);
            let p = if p0 > 0.0 && p1 > 0.0 {
                (p0.ln() + t * (p1.ln() - p0.ln())).exp()
            } else {
                p0 + t * (p1 - p0)
            };
            return (p, None);
        }
    }
    (f64::NAN, None)
}

/// A_X/A₀ at mean pressure `p` (Pa): the step of that pressure (within 1e-12) if there
/// is one, else ln A linear in ln p between the steps around p (steps with p > 0 and
/// A > 0 only); NaN outside their range.
pub fn area_at_pressure(steps: &[Step], p: f64) -> f64 {
    let pts: Vec<(f64, f64)> = steps
        .iter()
        .map(|s| (s.mean_pressure, s.area_fraction))
        .collect();
    value_at_pressure(&pts, p)
}

/// A quantity y (an area fraction, a conductance) at mean pressure `p` (Pa) from the
/// steps' (p, y): the step of that pressure (within 1e-12) if there is one, else ln y
/// linear in ln p between the steps around p (those with p > 0 and y > 0 only); NaN
/// outside their range.
fn value_at_pressure(pts: &[(f64, f64)], p: f64) -> f64 {
    if let Some(&(_, y)) = pts.iter().find(|&&(q, _)| (q - p).abs() <= SAME * p.abs()) {
        return y;
    }
    let mut pts: Vec<(f64, f64)> = pts
        .iter()
        .filter(|&&(q, y)| q > 0.0 && y > 0.0)
        .map(|&(q, y)| (q.ln(), y.ln()))
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    if p.is_nan() || p <= 0.0 {
        return f64::NAN;
    }
    let x = p.ln();
    for w in pts.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if x0 <= x && x <= x1 && x1 > x0 {
            return (y0 + (x - x0) / (x1 - x0) * (y1 - y0)).exp();
        }
    }
    f64::NAN
}

/// The rows of compare.csv: one per BEM step. `scale` = z_M − z̄ (m).
pub fn compare_rows(n: &[Step], i: &[Step], bem: &[Step], scale: f64) -> Vec<Row> {
    bem.iter()
        .map(|b| {
            let models = [n, i];
            let mut row = Row {
                delta: b.delta,
                separation: b.gap,
                pressure_ratio_bem: b.pressure_ratio,
                p_bem: b.mean_pressure,
                p: [f64::NAN; 2],
                rel_p: [f64::NAN; 2],
                area_bem: b.area_fraction,
                area: [f64::NAN; 2],
                area_at_p: [f64::NAN; 2],
                rel_area: [f64::NAN; 2],
                contacts_bem: b.contacts,
                contacts: [None; 2],
            };
            for (m, steps) in models.iter().enumerate() {
                let (p, at) = pressure_at_separation(steps, b.gap, scale);
                row.p[m] = p;
                row.contacts[m] = at;
                row.area[m] = match at {
                    Some(_) => steps
                        .iter()
                        .find(|s| (s.gap - b.gap).abs() <= SAME * scale.abs().max(b.gap.abs()))
                        .map_or(f64::NAN, |s| s.area_fraction),
                    None => f64::NAN,
                };
                if b.mean_pressure > 0.0 {
                    row.rel_p[m] = p / b.mean_pressure - 1.0;
                    let a = area_at_pressure(steps, b.mean_pressure);
                    row.area_at_p[m] = a;
                    if b.area_fraction > 0.0 {
                        row.rel_area[m] = a / b.area_fraction - 1.0;
                    }
                }
            }
            row
        })
        .collect()
}

/// The header of compare.csv.
const COMPARE_HEADER: [&str; 19] = [
    "step",
    "delta",
    "separation",
    "pressure_ratio_bem",
    "p_bem",
    "p_n",
    "p_i",
    "rel_p_n",
    "rel_p_i",
    "area_bem",
    "area_n",
    "area_i",
    "area_n_at_p",
    "area_i_at_p",
    "rel_area_n",
    "rel_area_i",
    "contacts_bem",
    "contacts_n",
    "contacts_i",
];

/// compare.csv text (header in the module docs), full precision.
pub fn compare_csv(rows: &[Row]) -> Result<String> {
    let c = |x: Option<usize>| x.map(|v| v.to_string()).unwrap_or_default();
    Ok(csv_out::text(
        &COMPARE_HEADER,
        rows.iter().enumerate().map(|(k, r)| {
            vec![
                k.to_string(),
                num(r.delta),
                num(r.separation),
                num(r.pressure_ratio_bem),
                num(r.p_bem),
                num(r.p[0]),
                num(r.p[1]),
                num(r.rel_p[0]),
                num(r.rel_p[1]),
                num(r.area_bem),
                num(r.area[0]),
                num(r.area[1]),
                num(r.area_at_p[0]),
                num(r.area_at_p[1]),
                num(r.rel_area[0]),
                num(r.rel_area[1]),
                r.contacts_bem.to_string(),
                c(r.contacts[0]),
                c(r.contacts[1]),
            ]
        }),
    )?)
}

/// (max, median, count) of |x| over the finite values; None if there are none.
pub fn abs_stats(xs: impl Iterator<Item = f64>) -> Option<(f64, f64, usize)> {
    let mut v: Vec<f64> = xs.filter(|x| x.is_finite()).map(f64::abs).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let med = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    Some((v[n - 1], med, n))
}

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:+.2} %", 100.0 * x)
    } else {
        "—".into()
    }
}

fn stats_cells(s: Option<(f64, f64, usize)>) -> String {
    match s {
        Some((max, med, n)) => format!("{:.2} % | {:.2} % | {n}", 100.0 * max, 100.0 * med),
        None => "— | — | 0".into(),
    }
}

/// One row of conductance.csv: the BEM step's separation g_k (m), p_BEM (Pa), h_BEM,
/// and the N and I models' h_c at g_k with their relative differences h/h_BEM − 1
/// (NaN: no such step / outside the model's range).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConductanceRow {
    pub separation: f64,
    pub p_bem: f64,
    pub h_bem: f64,
    /// h_N, h_I (W/(m²·K) or S/m²).
    pub h: [f64; 2],
    /// h_N/h_BEM − 1, h_I/h_BEM − 1.
    pub rel: [f64; 2],
    /// h_N, h_I at the BEM step's mean pressure (the model's [`ContactLaw`]: h_c(g) where p(g) = p).
    pub h_at_p: [f64; 2],
    /// h_N(p)/h_BEM − 1, h_I(p)/h_BEM − 1.
    pub rel_at_p: [f64; 2],
}

/// A model's interface law from its steps and h_c (the engine's [`ContactLaw`]: p(g)
/// and h_c(g) monotone piecewise-cubic, h_c(p) at the g where p(g) = p), first contact
/// at `scale` = z_M − z̄ (m); the nominal area is the steps' own P/p. `None` when the
/// steps do not make a law (no step with contact, a non-monotone path). The kind only
/// labels the values: thermal and electrical interpolate alike.
fn model_law(steps: &[Step], h: &[f64], scale: f64) -> Option<ContactLaw> {
    let area = steps
        .iter()
        .find(|s| s.mean_pressure > 0.0)
        .map(|s| s.load / s.mean_pressure)?;
    ContactLaw::from_steps(scale, steps, area, Some((ConductionKind::Thermal, h))).ok()
}

/// A model's h_c at the BEM step's mean pressure `p` (Pa); a pressure above the model's
/// largest sample by round-off only (≤ 1e−12 relative: a pressure-controlled BEM step
/// and the model's step at the same target differ by an ulp) is read at that sample.
fn conductance_at_pressure(law: &ContactLaw, p: f64) -> Option<f64> {
    use strata_runtime::interface::conductance_curve::CurveError;
    match law.conductance_at_pressure(p) {
        Ok(h) => Some(h),
        Err(crate::contact_law::ContactLawError::Conductance(
            CurveError::AboveSampledPressure { max, .. },
        )) if p <= max * (1.0 + 1e-12) => law.conductance_at_pressure(max).ok(),
        Err(_) => None,
    }
}

/// With `[conductance]`: the N and I models' h_c at each BEM step's separation against
/// the BEM's (`models`: each model's steps and h_c, N then I; None where a model has
/// none). `scale` = z_M − z̄ (m).
pub fn conductance_rows(
    models: [Option<(&[Step], &[f64])>; 2],
    bem: &[Step],
    h_bem: &[f64],
    scale: f64,
) -> Vec<ConductanceRow> {
    let laws = models.map(|m| m.and_then(|(steps, h)| model_law(steps, h, scale)));
    bem.iter()
        .zip(h_bem)
        .map(|(b, &hb)| {
            let h = laws.each_ref().map(|l| {
                l.as_ref()
                    .and_then(|l| l.conductance_at_gap(b.gap).ok())
                    .unwrap_or(f64::NAN)
            });
            let h_at_p = laws.each_ref().map(|l| {
                l.as_ref()
                    .and_then(|l| conductance_at_pressure(l, b.mean_pressure))
                    .unwrap_or(f64::NAN)
            });
            let rel_to = |h: f64| {
                if hb > 0.0 && hb.is_finite() {
                    h / hb - 1.0
                } else {
                    f64::NAN
                }
            };
            ConductanceRow {
                separation: b.gap,
                p_bem: b.mean_pressure,
                h_bem: hb,
                h,
                rel: h.map(rel_to),
                h_at_p,
                rel_at_p: h_at_p.map(rel_to),
            }
        })
        .collect()
}

/// conductance.csv: `step,separation,p_bem,conductance_bem,conductance_n,rel_conductance_n,
/// conductance_i,rel_conductance_i,conductance_n_at_p,rel_conductance_n_at_p,
/// conductance_i_at_p,rel_conductance_i_at_p` (m, Pa, W/(m²·K) or S/m², signed; `_at_p`:
/// at the BEM step's mean pressure).
pub fn conductance_csv(rows: &[ConductanceRow]) -> Result<String> {
    Ok(csv_out::text(
        &[
            "step",
            "separation",
            "p_bem",
            "conductance_bem",
            "conductance_n",
            "rel_conductance_n",
            "conductance_i",
            "rel_conductance_i",
            "conductance_n_at_p",
            "rel_conductance_n_at_p",
            "conductance_i_at_p",
            "rel_conductance_i_at_p",
        ],
        rows.iter().enumerate().map(|(k, r)| {
            vec![
                k.to_string(),
                num(r.separation),
                num(r.p_bem),
                num(r.h_bem),
                num(r.h[0]),
                num(r.rel[0]),
                num(r.h[1]),
                num(r.rel[1]),
                num(r.h_at_p[0]),
                num(r.rel_at_p[0]),
                num(r.h_at_p[1]),
                num(r.rel_at_p[1]),
            ]
        }),
    )?)
}

/// The plastic section of compare.md: the plastic area fraction of each model at each
/// BEM step (the models' steps share the approaches of approach and separation loads).
fn plastic_report(bem: &[Step], [b, n, i]: [&Vec<f64>; 3]) -> String {
    let mut md = String::from(
        "\n## Plastic area (A_pl/A₀: the share of the nominal area at p = H)\n\n\
         | step | g_n (µm) | BEM | N model | I model |\n|---:|---:|---:|---:|---:|\n",
    );
    let at = |v: &Vec<f64>, k: usize| v.get(k).map_or("—".into(), |x| format!("{x:.4e}"));
    for (k, s) in bem.iter().enumerate() {
        md.push_str(&format!(
            "| {k} | {:.3} | {} | {} | {} |\n",
            s.gap * 1e6,
            at(b, k),
            at(n, k),
            at(i, k)
        ));
    }
    md
}

/// The conductance section of compare.md; `seconds`: the conductance's own time in
/// the N model, the I model and the BEM (s).
fn conductance_report(rows: &[ConductanceRow], seconds: [f64; 3]) -> String {
    let stats = |m: usize, name: &str| {
        let cells = |x: Option<(f64, f64, usize)>| match x {
            Some((max, med, n)) => format!("{:.2} % | {:.2} % | {n}", 100.0 * max, 100.0 * med),
            None => "— | — | 0".into(),
        };
        format!(
            "| {name} | {} | {} | {:.3} |\n",
            cells(abs_stats(rows.iter().map(|r| r.rel_at_p[m]))),
            cells(abs_stats(rows.iter().map(|r| r.rel[m]))),
            seconds[m]
        )
    };
    let mut s = format!(
        "\n## Interface conductance (physics.md §6.2)\n\n\
         The N model (the spots in parallel, no thermal interactions) and the I model (the \
         spots heat each other through both bodies) against the BEM: at equal mean pressure \
         (h_c(p), what an FE table holds: the conduction model's error with the mechanics' \
         area error) and at equal separation (with the pressure's error too); the \
         conductance's own time in each model (the BEM's: {:.3} s).\n\n\
         | model | max \\|h/h_BEM − 1\\| (equal p_n) | median | steps compared | max \\|h/h_BEM − 1\\| (equal g_n) | median | steps compared | conductance time (s) |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|\n{}{}\n\
         | step | g_n (µm) | p_BEM (Pa) | h_BEM | h_N/h_BEM − 1 (equal p) | h_I/h_BEM − 1 (equal p) | h_N/h_BEM − 1 (equal g) | h_I/h_BEM − 1 (equal g) |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|\n",
        seconds[2],
        stats(0, "N model"),
        stats(1, "I model"),
    );
    for (k, r) in rows.iter().enumerate() {
        s.push_str(&format!(
            "| {k} | {:.3} | {:.4e} | {:.4e} | {} | {} | {} | {} |\n",
            r.separation * 1e6,
            r.p_bem,
            r.h_bem,
            pct(r.rel_at_p[0]),
            pct(r.rel_at_p[1]),
            pct(r.rel[0]),
            pct(r.rel[1]),
        ));
    }
    s
}

/// One compared scene, for the reports and combined plots.
struct Compared {
    label: String,
    scene_path: PathBuf,
    describe: String,
    i_model: String,
    runs: [ModelRun; 3],
    rows: Vec<Row>,
    e_star: f64,
}

fn summary_table(c: &Compared) -> String {
    let mut s = String::from(
        "| model | wall time (s) | steps | max \\|p/p_BEM − 1\\| (equal g_n) | median | steps compared | max \\|A/A_BEM − 1\\| (equal p_n) | median | steps compared |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for m in 0..2 {
        let name = if m == 0 {
            "N model (independent)".to_string()
        } else {
            format!("I model ({})", c.i_model)
        };
        s.push_str(&format!(
            "| {name} | {:.3} | {} | {} | {} |\n",
            c.runs[m].seconds,
            c.runs[m].steps.len(),
            stats_cells(abs_stats(c.rows.iter().map(|r| r.rel_p[m]))),
            stats_cells(abs_stats(c.rows.iter().map(|r| r.rel_area[m]))),
        ));
    }
    s.push_str(&format!(
        "| BEM (reference) | {:.3} | {} | — | — | — | — | — | — |\n",
        c.runs[2].seconds,
        c.runs[2].steps.len()
    ));
    s
}

fn step_table(c: &Compared) -> String {
    let mut s = String::from(
        "| step | g_n (µm) | p_BEM/E*₁ | p_N/p_BEM − 1 | p_I/p_BEM − 1 | A_BEM/A₀ | A_N/A_BEM − 1 (equal p) | A_I/A_BEM − 1 (equal p) | patches (BEM) |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for (k, r) in c.rows.iter().enumerate() {
        s.push_str(&format!(
            "| {k} | {:.3} | {:.4e} | {} | {} | {:.4e} | {} | {} | {} |\n",
            r.separation * 1e6,
            r.pressure_ratio_bem,
            pct(r.rel_p[0]),
            pct(r.rel_p[1]),
            r.area_bem,
            pct(r.rel_area[0]),
            pct(r.rel_area[1]),
            r.contacts_bem
        ));
    }
    s
}

fn report(c: &Compared, heading: &str) -> String {
    format!(
        "{heading} {}\n\nScene `{}`: {}; I model: {}; E*₁ = {:.6e} Pa.\n\
         Differences to the BEM: pressure at equal separation g_n (the flat's height above \
         the mean plane: the same in every model, although δ is measured from the highest \
         summit in the N and I models and from the highest grid point in the BEM), area at \
         equal mean pressure p_n (log–log interpolation). Wall times: one run each, without surface \
         generation and table loading.\n\n{}\n{}",
        c.label,
        c.scene_path.display(),
        c.describe,
        c.i_model,
        c.e_star,
        summary_table(c),
        step_table(c)
    )
}

/// Colours of the scenes in the plots (colour-blind-safe Okabe–Ito hues), cycled.
const COLOURS: [(u8, u8, u8); 6] = [
    (0, 114, 178),
    (213, 94, 0),
    (0, 158, 115),
    (204, 121, 167),
    (230, 159, 0),
    (86, 180, 233),
];

/// p_n/E*₁ against g_n (µm) and A/A₀ against p_n/E*₁ of the selected models of every
/// scene, into `dir` of the set: one colour per scene; N model dashed, I model solid,
/// BEM dots; the legend beside the axes.
fn plots(
    set: &OutputSet,
    dir: &str,
    suffix: &str,
    cs: &[&Compared],
    models: &[usize],
) -> Result<()> {
    let many = cs.len() > 1;
    let mut pg = Vec::new();
    let mut ap = Vec::new();
    for (ci, c) in cs.iter().enumerate() {
        let rgb = COLOURS[ci % COLOURS.len()];
        for &m in models {
            let name = if many {
                format!("{}: {}", c.label, MODELS[m].1)
            } else {
                MODELS[m].1.to_string()
            };
            let style = match m {
                0 => Style::Dashed { rgb },
                1 => Style::Rgb { rgb, faint: false },
                _ => Style::Dots { rgb },
            };
            let steps = &c.runs[m].steps;
            pg.push(Series {
                name: name.clone(),
                points: steps
                    .iter()
                    .map(|s| (s.gap * 1e6, s.pressure_ratio))
                    .collect(),
                style,
            });
            ap.push(Series {
                name,
                points: steps
                    .iter()
                    .map(|s| (s.pressure_ratio, s.area_fraction))
                    .collect(),
                style,
            });
        }
    }
    let what = if models.len() == 3 {
        "N model, I model and BEM"
    } else {
        "I model and BEM"
    };
    let whose = if many {
        format!("{} scenes", cs.len())
    } else {
        cs.first().map(|c| c.label.clone()).unwrap_or_default()
    };
    crate::plot::lines(
        &set.path(&format!("{dir}pressure_gap{suffix}.svg"))?,
        &PlotSpec {
            title: format!("Mean pressure against separation: {what}, {whose}"),
            x_label: "separation g_n (µm)".into(),
            y_label: "p_n / E*1".into(),
            log_x: false,
            log_y: true,
            series: pg,
        },
    )?;
    crate::plot::lines(
        &set.path(&format!("{dir}area_pressure{suffix}.svg"))?,
        &PlotSpec {
            title: format!("Real contact area against mean pressure: {what}, {whose}"),
            x_label: "p_n / E*1".into(),
            y_label: "A / A0".into(),
            log_x: false,
            log_y: false,
            series: ap,
        },
    )?;
    Ok(())
}

fn describe(scene: &Scene) -> String {
    let s = &scene.surface;
    let src = match &s.source {
        crate::scene::SurfaceSource::File(p) => format!("surface {}", p.display()),
        crate::scene::SurfaceSource::Generate(g) => format!(
            "generated surface {0}×{0}, L = {1:e} m, D_f = {2}, k = {3}…{4}, RMS {5:e} m, seed {6}",
            g.grid, g.size, g.fractal_dimension, g.k_min, g.k_max, g.rms, g.seed
        ),
    };
    let mut stack = match &scene.bodies.first.name {
        Some(n) => format!("stack \"{n}\""),
        None => format!("stack of {} layer(s)", scene.bodies.first.layers().len()),
    };
    if let Some(p) = scene.plasticity {
        stack.push_str(&format!(
            ", tips capped at the hardness H = {:e} Pa in every model (physics.md §9; the \
             N and I models through the capped asperity's response table)",
            p.hardness
        ));
    }
    match scene.bodies.counterface.stack() {
        None => format!("{src}; {stack}"),
        Some(c) => format!(
            "{src}{}; {stack} against an elastic counterface \"{}\" (two bodies, physics.md §6.1: \
             E*₁ below is the pair's, 1/E* = 1/E*₁,body + 1/E*₁,counterface)",
            if scene.bodies.counterface.surface().is_some() {
                " plus the counterface's heights"
            } else {
                ""
            },
            crate::engine::stack_description(c)
        ),
    }
}

fn images_name(images: Images) -> String {
    match images {
        Images::Isolated => "isolated sample".into(),
        Images::Periodic(m) => format!("periodic images, {0}×{0} cells", 2 * m + 1),
    }
}

/// Solves one scene with the three models and writes its files into `dir` of the set
/// (`""` or `"stem/"`).
fn compare_scene(
    path: &Path,
    label: Option<&str>,
    set: &OutputSet,
    dir: &str,
    a: &Args,
    heading: &str,
    memory: MemoryLimit,
) -> Result<Compared> {
    let scene = Scene::from_file(path)?;
    let mut runs = Vec::new();
    let mut scale = f64::NAN;
    let mut e_star = f64::NAN;
    for (kind, (key, name)) in [
        ModelKind::Independent,
        ModelKind::Interacting,
        ModelKind::Bem,
    ]
    .into_iter()
    .zip(MODELS)
    {
        let mut sc = scene.clone();
        sc.model.kind = kind;
        if kind != ModelKind::Bem {
            // the tangential path is the BEM's alone (tangential_bem.csv)
            sc.tangential = None;
        }
        let opts = EngineOptions {
            cache_dir: a.cache_dir.clone(),
            memory,
            ..Default::default()
        };
        progress::log(format!("compare {}: {name}…", path.display()));
        let mut maps = MapWriter::in_dir(
            set,
            &format!("{dir}maps/"),
            if kind == ModelKind::Bem {
                scene.output.maps
            } else {
                crate::scene::MapsSpec::None
            },
            !a.no_plots,
        )
        .with_formats(scene.output.format, scene.plasticity.map(|p| p.hardness));
        let sol = solve(
            &sc,
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
        .with_context(|| format!("scene {}: {name}", path.display()))?;
        maps.finish()?;
        progress::log(format!(
            "compare {}: {name} took {:.3} s",
            path.display(),
            sol.seconds
        ));
        set.write(
            &format!("{dir}curve_{key}.csv"),
            curve_csv_extra(&sol.steps, &sol.effect_columns())?.as_bytes(),
        )?;
        if let Some(t) = &sol.tangential_path {
            set.write(
                &format!("{dir}tangential_{key}.csv"),
                crate::cli::solve::tangential_csv(t)?.as_bytes(),
            )?;
        }
        if kind == ModelKind::Bem {
            scale = sol.summary.z_max_minus_mean;
            e_star = sol.summary.e_star_1;
        }
        let conductance = sol.conductances();
        let plastic = sol.plastic_area_fractions();
        let conductance_seconds = sol.summary.conductance.as_ref().map_or(0.0, |c| c.seconds);
        runs.push(ModelRun {
            steps: sol.steps,
            seconds: sol.seconds,
            conductance,
            plastic,
            conductance_seconds,
        });
    }
    let rows = compare_rows(&runs[0].steps, &runs[1].steps, &runs[2].steps, scale);
    let runs: [ModelRun; 3] = runs
        .try_into()
        .map_err(|_| anyhow::anyhow!("internal error: three models expected"))?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let c = Compared {
        label: label
            .map(String::from)
            .or_else(|| scene.bodies.first.name.clone())
            .unwrap_or(stem),
        scene_path: path.to_path_buf(),
        describe: describe(&scene),
        i_model: images_name(scene.model.images),
        runs,
        rows,
        e_star,
    };
    set.write(
        &format!("{dir}compare.csv"),
        compare_csv(&c.rows)?.as_bytes(),
    )?;
    let mut md = report(&c, heading);
    if let Some(b) = &c.runs[2].conductance {
        let model = |m: usize| {
            c.runs[m]
                .conductance
                .as_ref()
                .map(|h| (c.runs[m].steps.as_slice(), h.as_slice()))
        };
        let rows = conductance_rows([model(0), model(1)], &c.runs[2].steps, b, scale);
        set.write(
            &format!("{dir}conductance.csv"),
            conductance_csv(&rows)?.as_bytes(),
        )?;
        md.push_str(&conductance_report(
            &rows,
            [0, 1, 2].map(|m| c.runs[m].conductance_seconds),
        ));
    }
    if let [Some(n), Some(i), Some(b)] = c.runs.each_ref().map(|r| r.plastic.as_ref()) {
        md.push_str(&plastic_report(&c.runs[2].steps, [b, n, i]));
    }
    set.write(&format!("{dir}compare.md"), md.as_bytes())?;
    if !a.no_plots
        && c.runs
            .iter()
            .any(|r| r.steps.iter().any(|s| s.contacts > 0))
    {
        plots(set, dir, "", &[&c], &[0, 1, 2])?;
    }
    Ok(c)
}

pub fn run(a: Args, memory: MemoryLimit) -> Result<()> {
    let t0 = Instant::now();
    if !a.labels.is_empty() && a.labels.len() != a.scenes.len() {
        bail!(
            "--labels: {} labels for {} scenes (give one per scene)",
            a.labels.len(),
            a.scenes.len()
        );
    }
    for p in &a.scenes {
        let scene = Scene::from_file(p)?;
        if scene.unload {
            bail!(
                "scene {}: load.unload (a return path) is solved by the BEM only; the N and I models \
                 follow the loading path, so there is nothing to compare on the way back: drop \
                 `unload` to compare the loading curves, `strata solve` gives the BEM's return path",
                p.display()
            );
        }
        if scene.plasticity.is_some()
            && let Some((field, what)) = scene.load.first_reversal()
        {
            bail!(
                "scene {}: {field}: {what}: with [plasticity] a path that unloads is solved by the \
                 BEM only; the capped N and I models follow the loading path, so there is nothing to \
                 compare on the way back: give a loading path to compare the loading curves, \
                 `strata solve` gives the BEM's",
                p.display()
            );
        }
        refuse_inputs("--out", &a.out, &scene.inputs(p))?;
    }
    let set = OutputSet::dir("--out", &a.out, a.force)?;
    if a.scenes.len() == 1 {
        let c = compare_scene(
            &a.scenes[0],
            a.labels.first().map(String::as_str),
            &set,
            "",
            &a,
            "# Model comparison:",
            memory,
        )?;
        progress::log(summary_table(&c));
    } else {
        let mut done = Vec::new();
        let mut used = std::collections::HashSet::new();
        for (k, p) in a.scenes.iter().enumerate() {
            let stem = p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scene".into());
            let name = if used.insert(stem.clone()) {
                stem
            } else {
                format!("{stem}-{k}")
            };
            done.push(compare_scene(
                p,
                a.labels.get(k).map(String::as_str),
                &set,
                &format!("{name}/"),
                &a,
                "# Model comparison:",
                memory,
            )?);
        }
        let mut md = String::from(
            "# Model comparison: N model, I model and BEM\n\nOne section per scene; \
             per-step tables and compare.csv in each scene's directory.\n\n",
        );
        for c in &done {
            md.push_str(&format!(
                "## {}\n\nScene `{}`: {}; I model: {}.\n\n{}\n",
                c.label,
                c.scene_path.display(),
                c.describe,
                c.i_model,
                summary_table(c)
            ));
        }
        set.write("compare.md", md.as_bytes())?;
        if !a.no_plots {
            let refs: Vec<&Compared> = done.iter().collect();
            plots(&set, "", "", &refs, &[0, 1, 2])?;
            plots(&set, "", "_I_bem", &refs, &[1, 2])?;
        }
        for c in &done {
            progress::log(format!("{}:\n{}", c.label, summary_table(c)));
        }
    }
    set.commit()?;
    progress::log(format!(
        "wrote the comparison to {} in {:.1} s",
        a.out.display(),
        t0.elapsed().as_secs_f64()
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(gap: f64, p: f64, a: f64) -> Step {
        let mut s = Step::default();
        s.delta = 1e-5 - gap;
        s.gap = gap;
        s.load = p * 1e-6;
        s.mean_pressure = p;
        s.pressure_ratio = p / 4e9;
        s.area_fraction = a;
        s.contacts = 3;
        s
    }

    /// p = p₀ exp(−g/λ) and A = c p^0.9: the interpolations are exact for these forms.
    #[test]
    fn interpolation_is_exact_for_exponential_pressure_and_power_law_area() {
        let p = |g: f64| 1e7 * (-g / 1e-6).exp();
        let a = |p: f64| 1e-9 * p.powf(0.9);
        let steps: Vec<Step> = [1e-6, 2e-6, 4e-6, 8e-6]
            .iter()
            .map(|&g| step(g, p(g), a(p(g))))
            .collect();
        let (x, at) = pressure_at_separation(&steps, 3e-6, 1e-5);
        assert!((x / p(3e-6) - 1.0).abs() < 1e-12 && at.is_none());
        let (x, at) = pressure_at_separation(&steps, 2e-6 * (1.0 + 1e-15), 1e-5);
        assert_eq!((x, at), (p(2e-6), Some(3)));
        assert!(pressure_at_separation(&steps, 9e-6, 1e-5).0.is_nan());
        let q = p(3e-6);
        assert!((area_at_pressure(&steps, q) / a(q) - 1.0).abs() < 1e-12);
        assert_eq!(area_at_pressure(&steps, p(4e-6)), a(p(4e-6)));
        assert!(area_at_pressure(&steps, 1e9).is_nan());
        assert!(area_at_pressure(&steps, 0.0).is_nan());
    }

    #[test]
    fn rows_hold_signed_relative_differences() {
        let bem = vec![step(2e-6, 1e6, 0.1), step(1e-6, 2e6, 0.2)];
        let n = vec![step(2e-6, 1.1e6, 0.1), step(1e-6, 2.4e6, 0.25)];
        let i = vec![step(2e-6, 0.9e6, 0.1), step(1e-6, 1.8e6, 0.2)];
        let r = compare_rows(&n, &i, &bem, 1e-5);
        assert!((r[0].rel_p[0] - 0.1).abs() < 1e-12);
        assert!((r[0].rel_p[1] + 0.1).abs() < 1e-12);
        assert!((r[1].rel_p[0] - 0.2).abs() < 1e-12);
        // Area at equal pressure: N at p = 1e6 lies below its first step → empty.
        assert!(r[0].rel_area[0].is_nan());
        assert_eq!(r[1].area[0], 0.25);
        let csv = compare_csv(&r).unwrap();
        assert_eq!(csv.lines().count(), 3);
        assert!(csv.lines().nth(1).unwrap().contains(",,"));
        let (max, med, k) = abs_stats([0.1, -0.3, f64::NAN, 0.2].into_iter()).unwrap();
        assert_eq!((max, med, k), (0.3, 0.2, 3));
        assert!(abs_stats([f64::NAN].into_iter()).is_none());
    }
}
