//! Summary plots of a sweep CSV, like the paper's Figs. 19–22: p_n/E*₁ against g_n
//! (log y) and A/A₀ against p_n/E*₁, one pair of charts per *panel*.
//!
//! Grouping, from the CSV columns alone (so `sweep merge --plots` gives the same):
//! - a *series* is one model and one `surface.k_max` (if swept): the N model in reds,
//!   the I model in blues, BEM in greens, one shade per k_M;
//! - the samples of a series are its cases (typically `surface.seed`): each is drawn
//!   as a thin translucent curve;
//! - the bold curve is the mean over the samples at common abscissae (25 points
//!   evenly over the range every sample covers): geometric mean of p_n/E*₁ at fixed
//!   g_n, arithmetic mean of A/A₀ at fixed p_n/E*₁, by linear interpolation of each
//!   sample (in ln p for the pressure);
//! - every other swept column (`stack.modulus_ratio`, …) makes separate panels.
//!
//! `bands.csv` holds the mean, minimum and maximum over the samples at those
//! abscissae (`panel,model,k_max,plot,x,mean,min,max,samples`; `plot` is
//! `pressure_gap` (x = g_n in m, y = p_n/E*₁) or `area_pressure` (x = p_n/E*₁,
//! y = A/A₀)), i.e. the scatter over seeds in numbers.

use anyhow::{Context, Result, anyhow, bail};

use crate::csv_out::{self, num};
use crate::output_set::OutputSet;
use crate::plot::{PlotSpec, Series, Style};

/// Points of the mean curve.
const MEAN_POINTS: usize = 25;

struct Curve {
    /// (g_n, p_n/E*₁, A/A₀) per step.
    steps: Vec<(f64, f64, f64)>,
}

struct Group {
    model: String,
    k_max: Option<String>,
    curves: Vec<Curve>,
}

struct Panel {
    /// (column, value) of the panel's columns.
    key: Vec<(String, String)>,
    groups: Vec<Group>,
}

fn col(header: &[String], name: &str) -> Result<usize> {
    header
        .iter()
        .position(|h| *h == name)
        .ok_or_else(|| anyhow!("sweep CSV: no `{name}` column"))
}

fn parse_f(s: &str, what: &str, line: usize) -> Result<f64> {
    s.parse()
        .map_err(|_| anyhow!("sweep CSV line {line}: {what} `{s}` is not a number"))
}

/// Groups the rows of a sweep CSV into panels, series and sample curves.
fn panels(csv: &str) -> Result<Vec<Panel>> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(csv.as_bytes());
    let header: Vec<String> = reader
        .headers()
        .context("sweep CSV: no header")?
        .iter()
        .map(String::from)
        .collect();
    let (i_case, i_model) = (col(&header, "case")?, col(&header, "model")?);
    let (i_gap, i_p, i_a) = (
        col(&header, "gap")?,
        col(&header, "pressure_ratio")?,
        col(&header, "area_fraction")?,
    );
    let axis_cols: Vec<usize> = (i_case + 1..i_model).collect();
    let i_k = axis_cols
        .iter()
        .copied()
        .find(|&i| header[i] == "surface.k_max");
    let panel_cols: Vec<usize> = axis_cols
        .iter()
        .copied()
        .filter(|&i| header[i] != "surface.k_max" && header[i] != "surface.seed")
        .collect();
    let mut out: Vec<Panel> = Vec::new();
    let mut last_case: Option<String> = None;
    for (n, record) in reader.records().enumerate() {
        let record = record.with_context(|| format!("sweep CSV line {}", n + 2))?;
        let f: Vec<&str> = record.iter().collect();
        if f.len() != header.len() {
            bail!(
                "sweep CSV line {}: {} fields, header has {}",
                n + 2,
                f.len(),
                header.len()
            );
        }
        let key: Vec<(String, String)> = panel_cols
            .iter()
            .map(|&i| (header[i].to_string(), f[i].to_string()))
            .collect();
        let pi = match out.iter().position(|p| p.key == key) {
            Some(i) => i,
            None => {
                out.push(Panel {
                    key,
                    groups: Vec::new(),
                });
                out.len() - 1
            }
        };
        let panel = &mut out[pi];
        let model = f[i_model].to_string();
        let k_max = i_k.map(|i| f[i].to_string());
        let gi = match panel
            .groups
            .iter()
            .position(|g| g.model == model && g.k_max == k_max)
        {
            Some(i) => i,
            None => {
                panel.groups.push(Group {
                    model,
                    k_max,
                    curves: Vec::new(),
                });
                panel.groups.len() - 1
            }
        };
        let group = &mut panel.groups[gi];
        let step = (
            parse_f(f[i_gap], "gap", n + 2)?,
            parse_f(f[i_p], "pressure_ratio", n + 2)?,
            parse_f(f[i_a], "area_fraction", n + 2)?,
        );
        if last_case.as_deref() != Some(f[i_case]) || group.curves.is_empty() {
            group.curves.push(Curve { steps: Vec::new() });
            last_case = Some(f[i_case].to_string());
        }
        if let Some(c) = group.curves.last_mut() {
            c.steps.push(step);
        }
    }
    Ok(out)
}

/// Linear interpolation of sorted `pts` at x (inside their range).
fn interp(pts: &[(f64, f64)], x: f64) -> f64 {
    let j = pts.partition_point(|p| p.0 < x).clamp(1, pts.len() - 1);
    let (a, b) = (pts[j - 1], pts[j]);
    if b.0 == a.0 {
        return b.1;
    }
    a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
}

/// Mean, min and max over the samples at `MEAN_POINTS` common abscissae: for each x,
/// (x, mean, min, max). `log_y`: interpolate and average ln y (geometric mean).
/// None if the samples share no range.
fn band(samples: &[Vec<(f64, f64)>], log_y: bool) -> Option<Vec<(f64, f64, f64, f64)>> {
    let prepared: Vec<Vec<(f64, f64)>> = samples
        .iter()
        .map(|s| {
            let mut v: Vec<(f64, f64)> = s
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite() && (!log_y || *y > 0.0))
                .map(|(x, y)| (x, if log_y { y.ln() } else { y }))
                .collect();
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            v
        })
        .collect();
    if prepared.iter().any(|v| v.len() < 2) {
        return None;
    }
    let lo = prepared.iter().map(|v| v[0].0).fold(f64::MIN, f64::max);
    let hi = prepared
        .iter()
        .map(|v| v[v.len() - 1].0)
        .fold(f64::MAX, f64::min);
    if lo >= hi {
        return None;
    }
    let back = |y: f64| if log_y { y.exp() } else { y };
    Some(
        (0..MEAN_POINTS)
            .map(|i| {
                let x = lo + (hi - lo) * i as f64 / (MEAN_POINTS - 1) as f64;
                let ys: Vec<f64> = prepared.iter().map(|v| interp(v, x)).collect();
                let mean = ys.iter().sum::<f64>() / ys.len() as f64;
                let min = ys.iter().copied().fold(f64::INFINITY, f64::min);
                let max = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                (x, back(mean), back(min), back(max))
            })
            .collect(),
    )
}

fn short_model(m: &str) -> &str {
    match m {
        "independent" => "N model",
        "interacting" => "I model",
        "bem" => "BEM",
        other => other,
    }
}

/// Colour of a series: warm hues for the N model, cool ones for the I model, greens for
/// BEM; one hue per k_M (by its index).
fn colour(model: &str, k_index: usize) -> (u8, u8, u8) {
    const RED: [(u8, u8, u8); 4] = [(190, 0, 0), (240, 110, 0), (200, 0, 160), (120, 60, 20)];
    const BLUE: [(u8, u8, u8); 4] = [(0, 40, 160), (0, 150, 220), (0, 150, 90), (100, 40, 200)];
    const GREEN: [(u8, u8, u8); 4] = [(0, 130, 40), (100, 170, 0), (0, 90, 90), (60, 100, 0)];
    let fam = match model {
        "independent" => &RED,
        "interacting" => &BLUE,
        _ => &GREEN,
    };
    fam[k_index % fam.len()]
}

fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Writes the summary plots and `bands.csv` of a sweep CSV into `dir` (`""` or
/// `"sub/"`) of an output set; returns the files written (relative to the set).
/// `caption` names the sweep and its stack (`bandwidth study, paper two-layer`).
pub fn write(set: &OutputSet, dir: &str, csv: &str, caption: &str) -> Result<Vec<String>> {
    let panels = panels(csv)?;
    let mut written = Vec::new();
    let mut bands: Vec<Vec<String>> = Vec::new();
    for p in &panels {
        let suffix: String = p
            .key
            .iter()
            .map(|(c, v)| {
                let short = c.rsplit('.').next().unwrap_or(c);
                format!("_{}-{}", sanitize(short), sanitize(v))
            })
            .collect();
        let desc = p
            .key
            .iter()
            .map(|(c, v)| format!("{c} = {v}"))
            .collect::<Vec<_>>()
            .join(", ");
        let panel_label = if desc.is_empty() {
            "all".to_string()
        } else {
            desc.clone()
        };
        // k_M shades in order of appearance, per model
        let k_index = |g: &Group| {
            p.groups
                .iter()
                .filter(|h| h.model == g.model)
                .position(|h| h.k_max == g.k_max)
                .unwrap_or(0)
        };
        for (plot, file, x_label, y_label, log_y) in [
            (
                "pressure_gap",
                "pressure_gap",
                "separation g_n (µm)",
                "p_n / E*1",
                true,
            ),
            (
                "area_pressure",
                "area_pressure",
                "p_n / E*1",
                "A / A0",
                false,
            ),
        ] {
            let pick = |c: &Curve| -> Vec<(f64, f64)> {
                c.steps
                    .iter()
                    .map(|&(g, pr, a)| if log_y { (g * 1e6, pr) } else { (pr, a) })
                    .collect()
            };
            let mut faint = Vec::new();
            let mut bold = Vec::new();
            for g in &p.groups {
                let rgb = colour(&g.model, k_index(g));
                let samples: Vec<Vec<(f64, f64)>> = g.curves.iter().map(pick).collect();
                let mut name = short_model(&g.model).to_string();
                if let Some(k) = &g.k_max {
                    name.push_str(&format!(", k_M = {k}"));
                }
                if samples.len() == 1 {
                    bold.push(Series {
                        name,
                        points: samples[0].clone(),
                        style: Style::Rgb { rgb, faint: false },
                    });
                    continue;
                }
                for s in &samples {
                    faint.push(Series {
                        name: String::new(),
                        points: s.clone(),
                        style: Style::Rgb { rgb, faint: true },
                    });
                }
                if let Some(b) = band(&samples, log_y) {
                    for &(x, mean, min, max) in &b {
                        // bands.csv keeps SI: g_n in m.
                        let x_si = if log_y { x * 1e-6 } else { x };
                        bands.push(vec![
                            panel_label.clone(),
                            g.model.clone(),
                            g.k_max.clone().unwrap_or_default(),
                            plot.to_string(),
                            num(x_si),
                            num(mean),
                            num(min),
                            num(max),
                            samples.len().to_string(),
                        ]);
                    }
                    bold.push(Series {
                        name: format!("{name} (mean of {})", samples.len()),
                        points: b.iter().map(|&(x, m, _, _)| (x, m)).collect(),
                        style: Style::Rgb { rgb, faint: false },
                    });
                }
            }
            faint.extend(bold);
            if faint
                .iter()
                .all(|s| s.points.iter().all(|&(_, y)| y.is_nan() || y <= 0.0))
            {
                continue; // nothing in contact: no chart
            }
            let what = if log_y {
                "Mean pressure against separation"
            } else {
                "Real contact area against mean pressure"
            };
            let mut t = format!("{what}: {caption}");
            if !desc.is_empty() {
                t.push_str(&format!(" ({desc})"));
            }
            let rel = format!("{dir}{file}{suffix}.svg");
            crate::plot::lines(
                &set.path(&rel)?,
                &PlotSpec {
                    title: t,
                    x_label: x_label.into(),
                    y_label: y_label.into(),
                    log_x: false,
                    log_y,
                    series: faint,
                },
            )?;
            written.push(rel);
        }
    }
    let rel = format!("{dir}bands.csv");
    let text = csv_out::text(
        [
            "panel", "model", "k_max", "plot", "x", "mean", "min", "max", "samples",
        ],
        &bands,
    )?;
    set.write(&rel, text.as_bytes())?;
    written.push(rel);
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The band of two straight lines is their exact mean, min and max on the shared
    /// range; the geometric mean of exponentials is exact too.
    #[test]
    fn band_of_lines_and_exponentials() {
        let a: Vec<(f64, f64)> = (0..5).map(|i| (i as f64, 2.0 * i as f64)).collect();
        let b: Vec<(f64, f64)> = (1..7).map(|i| (i as f64, 4.0 * i as f64)).collect();
        let bd = band(&[a, b], false).unwrap();
        assert_eq!(bd.len(), MEAN_POINTS);
        assert_eq!(bd[0].0, 1.0);
        assert_eq!(bd[MEAN_POINTS - 1].0, 4.0);
        for (x, mean, min, max) in bd {
            assert!((mean - 3.0 * x).abs() < 1e-12);
            assert!((min - 2.0 * x).abs() < 1e-12 && (max - 4.0 * x).abs() < 1e-12);
        }
        let e = |k: f64| (0..10).map(|i| (i as f64, (k * i as f64).exp())).collect();
        let bd = band(&[e(1.0), e(3.0)], true).unwrap();
        for (x, mean, _, _) in bd {
            assert!((mean / (2.0 * x).exp() - 1.0).abs() < 1e-12);
        }
        let far: Vec<(f64, f64)> = vec![(10.0, 1.0), (11.0, 1.0)];
        assert!(band(&[e(1.0), far], false).is_none());
    }
}
