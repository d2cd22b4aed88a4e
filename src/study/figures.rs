//! The study's plots (SVG or PNG): error against time with the Pareto front, one per
//! accuracy–cost section.

use std::path::Path;

use anyhow::Result;

use super::Study;
use super::fredholm;
use super::pareto::{self, Point};
use super::tables::Order;
use crate::plot::{self, PlotSpec, Series, Style};

pub(super) fn front_series(points: &[Point], floor: f64) -> Series {
    Series {
        name: "Pareto front".into(),
        points: pareto::staircase(points, floor),
        style: Style::Line,
    }
}

pub(super) fn clamp(p: &Point, floor: f64) -> (f64, f64) {
    (p.time, p.error.max(floor))
}

/// An error-against-time plot: groups of points, the front, and rings on defaults.
pub(super) fn pareto_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    groups: Vec<(String, Vec<Point>)>,
    floor: f64,
    defaults: Vec<Point>,
) -> Result<()> {
    let all: Vec<Point> = groups.iter().flat_map(|g| g.1.iter().copied()).collect();
    let mut series = vec![front_series(&all, floor)];
    for (name, pts) in groups {
        if pts.is_empty() {
            continue;
        }
        series.push(Series {
            name,
            points: pts.iter().map(|p| clamp(p, floor)).collect(),
            style: Style::Points,
        });
    }
    if !defaults.is_empty() {
        series.push(Series {
            name: "default".into(),
            points: defaults.iter().map(|p| clamp(p, floor)).collect(),
            style: Style::Ring,
        });
    }
    // Room for the legend (upper left): extend the time axis to the left by 60 % of
    // the data's span in decades (at least half a decade).
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    let mut y = f64::NAN;
    for p in all.iter().filter(|p| p.time > 0.0 && p.time.is_finite()) {
        lo = lo.min(p.time);
        hi = hi.max(p.time);
        if p.error.is_finite() {
            y = p.error.max(floor);
        }
    }
    if lo.is_finite() && y.is_finite() {
        let decades = (hi / lo).log10().max(1.0);
        series.push(Series {
            name: String::new(),
            points: vec![(lo / 10f64.powf(0.6 * decades), y)],
            style: Style::Spacer,
        });
    }
    plot::lines(
        path,
        &PlotSpec {
            title: title.into(),
            x_label: x_label.into(),
            y_label: "relative error".into(),
            log_x: true,
            log_y: true,
            series,
        },
    )
}

pub(super) fn fred_file(c: &fredholm::Case, ext: &str) -> String {
    format!("fredholm-E2E1-{}-ah-{}.{ext}", c.ratio, c.a_over_h)
}

/// Writes every plot into `dir` (`ext`: "svg" or "png"); returns their file names.
pub fn plots(study: &Study, dir: &Path, ext: &str) -> Result<Vec<String>> {
    let mut files = Vec::new();
    for c in &study.fredholm.cases {
        let mut nys = Vec::new();
        let mut prod = Vec::new();
        for r in &c.rows {
            let p = Point {
                time: r.timing.median,
                error: r.force_error,
            };
            match r.disc {
                strata_tablegen::fredholm::Discretisation::Nystrom { .. } => nys.push(p),
                _ => prod.push(p),
            }
        }
        let defaults: Vec<Point> = c
            .default_index()
            .map(|i| c.points()[i])
            .into_iter()
            .collect();
        let f = fred_file(c, ext);
        pareto_plot(
            &dir.join(&f),
            &format!(
                "Fredholm solve, E2/E1 = {}, a/h1 = {}: force error vs time",
                c.ratio, c.a_over_h
            ),
            "time per solve (s)",
            vec![
                ("Nyström".into(), nys),
                ("product + Richardson".into(), prod),
            ],
            c.floor,
            defaults,
        )?;
        files.push(f);
    }
    let t = &study.tables;
    let pts = t.build_points();
    let group = |o: Order| -> Vec<Point> {
        t.rows
            .iter()
            .zip(&pts)
            .filter(|(r, _)| r.order == o)
            .map(|(_, p)| *p)
            .collect()
    };
    pareto_plot(
        &dir.join(format!("tables.{ext}")),
        "Tables: interpolation error vs build time",
        "build time (s)",
        vec![
            ("cubic Hermite".into(), group(Order::Cubic)),
            ("linear".into(), group(Order::Linear)),
        ],
        super::tables::FLOOR,
        t.default_index().map(|i| pts[i]).into_iter().collect(),
    )?;
    files.push(format!("tables.{ext}"));

    let a = &study.approx;
    let mut series = Vec::new();
    for &ratio in &a.settings.ratios {
        let rows: Vec<_> = a.rows.iter().filter(|r| r.ratio == ratio).collect();
        series.push(Series {
            name: format!("E2/E1 = {ratio}, direct χ, ζ"),
            points: rows.iter().map(|r| (r.a_over_h, r.error_direct)).collect(),
            style: Style::Line,
        });
        series.push(Series {
            name: format!("E2/E1 = {ratio}, table"),
            points: rows.iter().map(|r| (r.a_over_h, r.error_table)).collect(),
            style: Style::Points,
        });
    }
    plot::lines(
        &dir.join(format!("approx.{ext}")),
        &PlotSpec {
            title: "Second-order approximation: force error at equal approach".into(),
            x_label: "a/h1".into(),
            y_label: "|P_approx/P_full − 1|".into(),
            log_x: true,
            log_y: true,
            series,
        },
    )?;
    files.push(format!("approx.{ext}"));

    let r = &study.rough;
    let (idx, pts) = r.points();
    let mut groups: Vec<(String, Vec<Point>)> = Vec::new();
    for (k, &i) in idx.iter().enumerate() {
        let name = match r.rows[i].kind {
            super::rough::Kind::Bem { tolerance, .. } => format!("BEM, tol {tolerance:.0e}"),
            kind => kind.label(),
        };
        match groups.iter_mut().find(|g| g.0 == name) {
            Some(g) => g.1.push(pts[k]),
            None => groups.push((name, vec![pts[k]])),
        }
    }
    let defaults: Vec<Point> = idx
        .iter()
        .zip(&pts)
        .filter(|(i, _)| r.rows[**i].is_default)
        .map(|(_, p)| *p)
        .collect();
    pareto_plot(
        &dir.join(format!("rough.{ext}")),
        &format!(
            "Rough contact: p_n error vs the BEM at n = {} (time per load curve)",
            r.settings.ref_grid()
        ),
        "time per load curve (s)",
        groups,
        super::rough::FLOOR,
        defaults,
    )?;
    files.push(format!("rough.{ext}"));

    if r.far.is_empty() {
        return Ok(files);
    }
    let fp = r.far_points();
    let dfar: Vec<Point> = r
        .far
        .iter()
        .zip(&fp)
        .filter(|(f, _)| f.tolerance.is_none())
        .map(|(_, p)| *p)
        .collect();
    pareto_plot(
        &dir.join(format!("farfield.{ext}")),
        "I model (periodic 5×5): far-field tolerance, error vs exact interactions",
        "time per load curve (s)",
        vec![("far-field tolerance".into(), fp)],
        super::rough::FAR_FLOOR,
        dfar,
    )?;
    files.push(format!("farfield.{ext}"));
    Ok(files)
}
