//! The study's outputs: the Markdown report, its plots (SVG), `errors.csv` (the
//! deterministic numbers) and `timings.csv` (every timing).
//!
//! Every number in the report is formatted from a measurement of the run; the only
//! literal values are the settings of the mode (grids, node counts, a/h₁ values),
//! which the report states as such.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;

use super::fredholm::{self, label};
use super::pareto::{self, Point};
use super::tables::Order;
use super::{Study, fmt_err, fmt_time};
use crate::plot::{self, PlotSpec, Series, Style};

fn front_series(points: &[Point], floor: f64) -> Series {
    Series {
        name: "Pareto front".into(),
        points: pareto::staircase(points, floor),
        style: Style::Line,
    }
}

fn clamp(p: &Point, floor: f64) -> (f64, f64) {
    (p.time, p.error.max(floor))
}

/// An error-against-time plot: groups of points, the front, and rings on defaults.
fn pareto_plot(
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

fn fred_file(c: &fredholm::Case, ext: &str) -> String {
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

/// A measured default and where it sits.
struct DefaultRow {
    what: String,
    value: String,
    point: String,
    status: String,
    /// A faster point at least as accurate (label, error, time), if any.
    better: Option<String>,
    off: bool,
}

fn defaults(study: &Study) -> Vec<DefaultRow> {
    let mut out = Vec::new();
    for c in &study.fredholm.cases {
        let Some(i) = c.default_index() else { continue };
        let pts = c.points();
        let row = &c.rows[i];
        let better = pareto::better(&pts, i, c.floor).map(|j| {
            format!(
                "{} (error {}, {})",
                label(c.rows[j].disc),
                fmt_err(c.rows[j].force_error),
                fmt_time(c.rows[j].timing.median)
            )
        });
        out.push(DefaultRow {
            what: format!(
                "Fredholm discretisation (`asperity::Options::default()`, Auto), E₂/E₁ = {}, a/h₁ = {}",
                c.ratio, c.a_over_h
            ),
            value: label(row.disc),
            point: format!(
                "force error {}, {} per solve",
                fmt_err(row.force_error),
                fmt_time(row.timing.median)
            ),
            status: pareto::status(&pts, i, c.floor),
            off: pareto::time_factor(&pts, i, c.floor) > pareto::NEAR,
            better,
        });
    }
    let t = &study.tables;
    if let Some(i) = t.default_index() {
        let pts = t.build_points();
        let row = &t.rows[i];
        let lin = t
            .rows
            .iter()
            .find(|r| r.nx == row.nx && r.nw == row.nw && r.order == Order::Linear);
        out.push(DefaultRow {
            what: "table grid (`tablebuild::BuildOptions::default()`)".into(),
            value: format!("n_x = {}, n_w = {}", row.nx, row.nw),
            point: format!(
                "table error {}, build {}, {} bytes",
                fmt_err(row.error()),
                fmt_time(row.build.median),
                row.bytes
            ),
            status: pareto::status(&pts, i, super::tables::FLOOR),
            off: pareto::time_factor(&pts, i, super::tables::FLOOR) > pareto::NEAR,
            better: pareto::better(&pts, i, super::tables::FLOOR).map(|j| {
                let r = &t.rows[j];
                format!(
                    "n_x = {}, n_w = {}, {} (error {}, build {})",
                    r.nx,
                    r.nw,
                    r.order.name(),
                    fmt_err(r.error()),
                    fmt_time(r.build.median)
                )
            }),
        });
        let lp = t.lookup_points();
        out.push(DefaultRow {
            what: "interpolation order (runtime `TableLaw`)".into(),
            value: "cubic Hermite (order 3)".into(),
            point: format!(
                "at the default grid: error {} at {} per χ+ζ+g lookup{}",
                fmt_err(row.error()),
                fmt_time(row.lookup.median),
                lin.map_or(String::new(), |l| format!(
                    "; linear: error {} at {}",
                    fmt_err(l.error()),
                    fmt_time(l.lookup.median)
                ))
            ),
            status: format!(
                "{} (error vs lookup time); {} (error vs build time)",
                pareto::status(&lp, i, super::tables::FLOOR),
                pareto::short_status(&pts, i, super::tables::FLOOR)
            ),
            off: pareto::time_factor(&lp, i, super::tables::FLOOR) > pareto::NEAR,
            better: pareto::better(&lp, i, super::tables::FLOOR).map(|j| {
                let r = &t.rows[j];
                format!(
                    "n_x = {}, n_w = {}, {} (error {}, lookup {})",
                    r.nx,
                    r.nw,
                    r.order.name(),
                    fmt_err(r.error()),
                    fmt_time(r.lookup.median)
                )
            }),
        });
    }
    let r = &study.rough;
    let ref_grid = r.settings.ref_grid();
    for &n in r.settings.grids.iter().filter(|&&n| n != ref_grid) {
        let idx: Vec<usize> = (0..r.rows.len())
            .filter(|&i| matches!(r.rows[i].kind, super::rough::Kind::Bem { n: m, .. } if m == n))
            .collect();
        let pts: Vec<Point> = idx
            .iter()
            .map(|&i| Point {
                time: r.rows[i].timing.median,
                error: r.rows[i].p_error,
            })
            .collect();
        let Some(k) = idx.iter().position(|&i| r.rows[i].is_default) else {
            continue;
        };
        let row = &r.rows[idx[k]];
        out.push(DefaultRow {
            what: format!("BEM tolerance (`bem::BemOptions::default()`) at n = {n}"),
            value: format!("{:.0e}", r.default_tolerance),
            point: format!(
                "p error {} vs the BEM at n = {ref_grid}, {} per curve",
                fmt_err(row.p_error),
                fmt_time(row.timing.median)
            ),
            status: pareto::status(&pts, k, super::rough::FLOOR),
            off: pareto::time_factor(&pts, k, super::rough::FLOOR) > pareto::NEAR,
            better: pareto::better(&pts, k, super::rough::FLOOR).map(|j| {
                let b = &r.rows[idx[j]];
                format!(
                    "{} (error {}, {})",
                    b.kind.label(),
                    fmt_err(b.p_error),
                    fmt_time(b.timing.median)
                )
            }),
        });
    }
    let fp = r.far_points();
    if let Some(k) = r.far.iter().position(|f| f.tolerance.is_none()) {
        let f = &r.far[k];
        out.push(DefaultRow {
            what: "I-model far-field tolerance (`RoughContact` without `with_far_field_tolerance`)"
                .into(),
            value: f.label(),
            point: format!(
                "p error {} vs exact interactions, {} per curve",
                fmt_err(f.p_error),
                fmt_time(f.timing.median)
            ),
            status: pareto::status(&fp, k, super::rough::FAR_FLOOR),
            off: pareto::time_factor(&fp, k, super::rough::FAR_FLOOR) > pareto::NEAR,
            better: pareto::better(&fp, k, super::rough::FAR_FLOOR).map(|j| {
                let b = &r.far[j];
                format!(
                    "tolerance {} (error {}, {})",
                    b.label(),
                    fmt_err(b.p_error),
                    fmt_time(b.timing.median)
                )
            }),
        });
    }
    // The rough-contact model (N, I, BEM) is not a default: every scene names
    // `model.kind`. Where each model sits against the BEM is section 4's table and plot.
    out
}

/// The q-quantile of sorted values (nearest rank; NaN when empty).
fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let k = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[k - 1]
}

/// "a, b, c".
fn list(items: impl Iterator<Item = String>) -> String {
    items.collect::<Vec<_>>().join(", ")
}

fn cell_status(points: &[Point], i: usize, floor: f64) -> String {
    pareto::short_status(points, i, floor)
}

/// The Markdown report. `prefix` is prepended to plot file names in links, `ext` is
/// the plots' extension.
pub fn markdown(study: &Study, prefix: &str, ext: &str, command: &str) -> String {
    let mut s = String::new();
    let m = &study.machine_start;
    let w = &mut s;
    let _ = writeln!(w, "# Accuracy and cost of strata's solvers\n");
    let _ = writeln!(
        w,
        "Generated by `{command}` (mode **{}**) in {:.1} s of wall time. Every number on \
         this page was measured in that run and written by the program; nothing is typed \
         in. The settings of the mode (which grids, node counts, a/h₁ values) are listed \
         with each stage. The deterministic numbers (all errors) are also in `errors.csv`, \
         every timing in `timings.csv`.\n",
        study.mode.name(),
        study.seconds
    );
    let _ = writeln!(w, "## Machine\n");
    let _ = writeln!(w, "| | |\n|---|---|");
    let _ = writeln!(w, "| CPU | {} |", m.cpu);
    let _ = writeln!(
        w,
        "| cores | {}; rayon pool: {} threads |",
        m.logical_cpus, m.threads
    );
    let _ = writeln!(w, "| memory | {} |", m.memory);
    let _ = writeln!(w, "| OS | {} ({}) |", m.os, m.kernel);
    let _ = writeln!(w, "| compiler | {} |", m.rustc);
    let _ = writeln!(w, "| build profile | {} |", m.profile);
    let _ = writeln!(w, "| strata | {} (commit {}) |", m.strata, m.commit);
    let _ = writeln!(
        w,
        "| load average (1, 5, 15 min) | {} at the start, {} at the end (the study keeps up to {} threads busy; a higher load means the machine was shared and times are noisier) |",
        m.load, study.load_end, m.threads
    );
    let reps = study.mode.reps();
    let mut spreads: Vec<f64> = study
        .timings
        .iter()
        .filter(|(_, _, t)| t.runs > 1)
        .map(|(_, _, t)| t.spread())
        .collect();
    spreads.sort_by(f64::total_cmp);
    let _ = writeln!(w, "\n## How to read this\n");
    let _ = writeln!(
        w,
        "* **Times** are wall-clock medians on all {} rayon threads: every item runs at \
         least {} and at most {} times, as many as fit in {} s (estimated from its first \
         run); the number of runs is given per row. Fast operations (lookups) are timed \
         in batches and divided. Noise of this run: over the {} items timed more than \
         once, the spread of their runs, (slowest − fastest)/median, has median {:.0} % \
         and 90th percentile {:.0} % (per item in `timings.csv`).",
        m.threads,
        reps.min_runs,
        reps.max_runs,
        reps.budget,
        spreads.len(),
        100.0 * percentile(&spreads, 0.5),
        100.0 * percentile(&spreads, 0.9)
    );
    let _ = writeln!(
        w,
        "* **Errors** are relative and deterministic: every value entering an error is \
         computed on a one-thread pool, so parallel sums have a fixed order, and inputs \
         are fixed (seeded surface, seeded check points). A second run reproduces them \
         bit for bit."
    );
    let _ = writeln!(
        w,
        "* **Pareto front**: a point is *on the front* when no other point is at least as \
         fast and at least as accurate. Errors within a factor {} of each other, and \
         errors below a stage's *floor* (its reference's own accuracy), count as equal. The *time factor* of a point is its time over that \
         of the fastest point at least as accurate: `on` = 1, `near (k×)` for k ≤ {}, \
         `off (k×)` beyond. Plots: log–log, dots = measured points, line = the front, \
         rings = defaults.\n",
        pareto::SAME,
        pareto::NEAR
    );

    // Summary.
    let _ = writeln!(w, "## Summary\n");
    for line in summary(study) {
        let _ = writeln!(w, "* {line}");
    }

    // Defaults.
    let ds = defaults(study);
    let _ = writeln!(w, "\n## Defaults and the front\n");
    let _ = writeln!(
        w,
        "| default | value | measured point | where it sits |\n|---|---|---|---|"
    );
    for d in &ds {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} |",
            d.what, d.value, d.point, d.status
        );
    }
    let off: Vec<&DefaultRow> = ds.iter().filter(|d| d.off).collect();
    let _ = writeln!(w, "\n### Proposed changes\n");
    if off.is_empty() {
        let _ = writeln!(
            w,
            "None: every default measured here is on the front or within {}× of it.",
            pareto::NEAR
        );
    } else {
        for d in off {
            let _ = writeln!(
                w,
                "* {} = {}: off the front. {}",
                d.what,
                d.value,
                d.better.as_ref().map_or_else(
                    || "No faster point at least as accurate was measured.".to_string(),
                    |b| format!("Measured here, at least as accurate and faster: {b}.")
                )
            );
        }
    }

    // Stage 1.
    let f = &study.fredholm;
    let _ = writeln!(w, "\n## 1. Fredholm solver (full asperity solution)\n");
    let _ = writeln!(
        w,
        "Paraboloid R = {:e} m on the paper's stacks (h₁ = 100 µm, E₁ = 4 GPa, ν = 0.15, \
         second layer E₂ down to a rigid base at 1 mm), force P and approach δ at contact \
         radius a by `Asperity::paraboloid_at_radius` with a fixed discretisation. \
         Settings: E₂/E₁ ∈ {{{}}}, a/h₁ ∈ {{{}}}, Nyström nodes {{{}}}, product intervals {{{}}} \
         (always with Richardson extrapolation), reference Nyström {} (a ≤ 4h₁) or product \
         {} + Richardson (beyond). The floor of each case is its reference's uncertainty \
         (the same method one step coarser), at least 1e−14. Time per solve includes the \
         k_z quadrature, assembly, LU and two right-hand sides (no profile output).\n",
        fredholm::RADIUS,
        list(f.settings.ratios.iter().map(|x| x.to_string())),
        list(f.settings.a_over_h.iter().map(|x| x.to_string())),
        list(f.settings.nystrom.iter().map(|x| x.to_string())),
        list(f.settings.product.iter().map(|x| x.to_string())),
        f.settings.ref_nodes,
        f.settings.ref_intervals
    );
    for c in &f.cases {
        let pts = c.points();
        let _ = writeln!(w, "### E₂/E₁ = {}, a/h₁ = {}\n", c.ratio, c.a_over_h);
        let _ = writeln!(
            w,
            "Reference {}: uncertainty {}; cross-check {} differs by {}.\n",
            label(c.reference),
            fmt_err(c.ref_uncertainty),
            label(c.cross_check.0),
            fmt_err(c.cross_check.1)
        );
        let _ = writeln!(
            w,
            "| discretisation | force error | δ error | time per solve | runs | front |\n|---|---|---|---|---|---|"
        );
        for (i, r) in c.rows.iter().enumerate() {
            let _ = writeln!(
                w,
                "| {}{} | {} | {} | {} | {} | {} |",
                label(r.disc),
                if r.is_default { " (default)" } else { "" },
                fmt_err(r.force_error),
                fmt_err(r.delta_error),
                fmt_time(r.timing.median),
                r.timing.runs,
                cell_status(&pts, i, c.floor)
            );
        }
        let _ = writeln!(
            w,
            "\n![Fredholm E2/E1 = {}, a/h1 = {}]({prefix}{})\n",
            c.ratio,
            c.a_over_h,
            fred_file(c, ext)
        );
    }

    // Stage 2.
    let t = &study.tables;
    let _ = writeln!(w, "## 2. Surrogate tables\n");
    let _ = writeln!(
        w,
        "Single-stack tables of the paper's stack E₂/E₁ = {} (a/h₁ from 1e−3 to 1e3, \
         w up to its default), built at grids (n_x, n_w) ∈ {{{}}} (S axis at its default). \
         Errors at {} random points (uniform in ln(a/h₁) and w, seed {}) against direct \
         quadrature: χ and ζ relative, g relative to (4/3)a³/r; *table error* = the \
         largest. Linear = multilinear interpolation of the same nodes. Build: all cores, \
         no interpolation check; size: the encoded file; lookup: one χ, ζ and g. Floor \
         {:.0e} (direct quadrature).\n",
        super::tables::RATIO,
        list(t.settings.grids.iter().map(|(x, w)| format!("({x}, {w})"))),
        t.settings.points,
        super::tables::SEED,
        super::tables::FLOOR
    );
    let _ = writeln!(
        w,
        "| n_x | n_w | order | χ error | ζ error | g error | build time | runs | file size | lookup | front (build) |\n|---|---|---|---|---|---|---|---|---|---|---|"
    );
    let bp = t.build_points();
    for (i, r) in t.rows.iter().enumerate() {
        let _ = writeln!(
            w,
            "| {} | {} | {}{} | {} | {} | {} | {} | {} | {:.1} kB | {} | {} |",
            r.nx,
            r.nw,
            r.order.name(),
            if r.is_default { " (default)" } else { "" },
            fmt_err(r.chi),
            fmt_err(r.zeta),
            fmt_err(r.g),
            fmt_time(r.build.median),
            r.build.runs,
            r.bytes as f64 / 1e3,
            fmt_time(r.lookup.median),
            cell_status(&bp, i, super::tables::FLOOR)
        );
    }
    let _ = writeln!(w, "\n![tables]({prefix}tables.{ext})\n");

    // Stage 3.
    let a = &study.approx;
    let _ = writeln!(
        w,
        "## 3. Second-order approximation against the full solution\n"
    );
    let _ = writeln!(
        w,
        "Force at equal approach δ, paraboloid R = {:e} m: the full solution (default \
         discretisation) at contact radius a gives δ and P; the approximation solves \
         ζ(a′)a′²/R = δ and gives P′ = (4/3)E*₁χ(a′)a′³/R. *direct*: χ, ζ by quadrature \
         (the approximation alone); *table*: from `{}` (approximation + interpolation). \
         Settings: E₂/E₁ ∈ {{{}}}, a/h₁ ∈ {{{}}}.\n",
        fredholm::RADIUS,
        a.table,
        list(a.settings.ratios.iter().map(|x| x.to_string())),
        list(a.settings.a_over_h.iter().map(|x| format!("{x:.3}")))
    );
    for (ratio, lim) in a.limits() {
        let _ = writeln!(
            w,
            "* E₂/E₁ = {ratio}: error below {} % {}",
            super::approx::LIMIT * 100.0,
            match lim {
                Some(x) => format!("for every a/h₁ ≤ {x:.3} of the sweep"),
                None => "at no a/h₁ of the sweep".into(),
            }
        );
    }
    let _ = writeln!(
        w,
        "\n| E₂/E₁ | a/h₁ | δ (m) | P full (N) | error, direct χ ζ | error, table | full solve | direct χ, ζ | table a′(δ), P′ |\n|---|---|---|---|---|---|---|---|---|"
    );
    for r in &a.rows {
        let _ = writeln!(
            w,
            "| {} | {:.3} | {:.3e} | {:.3e} | {} | {} | {} | {} | {} |",
            r.ratio,
            r.a_over_h,
            r.delta,
            r.force,
            fmt_err(r.error_direct),
            fmt_err(r.error_table),
            fmt_time(r.full.median),
            fmt_time(r.direct.median),
            fmt_time(r.table.median)
        );
    }
    let _ = writeln!(w, "\n![approximation]({prefix}approx.{ext})\n");

    // Stage 4.
    let r = &study.rough;
    let ref_grid = r.settings.ref_grid();
    let _ = writeln!(w, "## 4. Rough contact\n");
    let _ = writeln!(
        w,
        "The paper scene's surface (generated, 512², L = 1 mm, k = 2…10, RMS 3.4 µm; \
         {} summits) on E₂/E₁ = 1. N and I models on the 512² summits with the scene's \
         table; FFT-BEM on the surface resampled spectrally to n² (exact for this \
         band-limited surface), grids {{{}}}, tolerances {{{}}}. Reference: the BEM at n = {} \
         and the default tolerance {:.0e}{}. {} load steps at separations g_n (m) = {}. \
         p error = max over steps of |p_n/p_n,ref − 1|; same for A/A₀. Time per load curve \
         from the surface (summits or BEM kernel) to the last step. Floor {:.0e}.\n",
        r.summits,
        list(r.settings.grids.iter().map(|x| x.to_string())),
        list(r.settings.tolerances.iter().map(|x| format!("{x:.0e}"))),
        ref_grid,
        r.default_tolerance,
        if study.mode == super::Mode::Full {
            ""
        } else {
            " (the full study uses n = 512, the scene's own grid; `--quick` stops at 256 to stay within its time budget)"
        },
        r.separations.len(),
        list(r.separations.iter().map(|g| format!("{g:.3e}"))),
        super::rough::FLOOR
    );
    let (idx, pts) = r.points();
    let _ = writeln!(
        w,
        "| model | p error | area error | time per curve | runs | front |\n|---|---|---|---|---|---|"
    );
    for (i, row) in r.rows.iter().enumerate() {
        let front = match idx.iter().position(|&j| j == i) {
            Some(k) => cell_status(&pts, k, super::rough::FLOOR),
            None => "reference".into(),
        };
        let _ = writeln!(
            w,
            "| {}{} | {} | {} | {} | {} | {} |",
            row.kind.label(),
            if row.is_default && !row.is_reference {
                " (default)"
            } else {
                ""
            },
            if row.is_reference {
                "—".into()
            } else {
                fmt_err(row.p_error)
            },
            if row.is_reference {
                "—".into()
            } else {
                fmt_err(row.area_error)
            },
            fmt_time(row.timing.median),
            row.timing.runs,
            front
        );
    }
    if let Some(reference) = r.reference() {
        let _ = writeln!(
            w,
            "\nPer load step (signed relative deviation of p_n from the reference):\n"
        );
        let shown: Vec<&super::rough::Row> = r
            .rows
            .iter()
            .filter(|x| {
                !x.is_reference
                    && (matches!(x.kind, super::rough::Kind::Asperity(_))
                        || (x.is_default
                            && matches!(x.kind, super::rough::Kind::Bem { n, .. } if n * 2 == ref_grid)))
            })
            .collect();
        let _ = write!(w, "| g_n (m) | reference p_n/E*₁ | reference A/A₀ |");
        for x in &shown {
            let _ = write!(w, " {} |", x.kind.label());
        }
        let _ = writeln!(w);
        let _ = writeln!(w, "|{}", "---|".repeat(3 + shown.len()));
        for (k, g) in r.separations.iter().enumerate() {
            let _ = write!(
                w,
                "| {:.3e} | {:.4e} | {:.4e} |",
                g, reference.pressure[k], reference.area[k]
            );
            for x in &shown {
                let _ = write!(w, " {:+.2e} |", x.pressure[k] / reference.pressure[k] - 1.0);
            }
            let _ = writeln!(w);
        }
    }
    let _ = writeln!(w, "\n![rough contact]({prefix}rough.{ext})\n");
    if !r.far.is_empty() {
        far_section(w, r, prefix, ext);
    }
    w.push_str(&super::scaling::markdown(&study.scaling));
    let _ = writeln!(
        w,
        "## Regenerating\n\n```sh\ncargo run --release -- study{} --out docs/accuracy-cost \\\n    --report docs/accuracy-cost.md --force\n```\n\nwrites this page (`--report`), its plots, `errors.csv` and `timings.csv` \
         (in `docs/accuracy-cost/`) and `docs/accuracy-cost/report.md` (the same page with \
         links relative to that directory).",
        study.mode.flag()
    );
    s
}

fn far_section(w: &mut String, r: &super::rough::Results, prefix: &str, ext: &str) {
    let _ = writeln!(
        w,
        "### I-model far-field tolerance\n\nPeriodic 5×5 I model with distant pairs treated \
         as point forces within the tolerance, against exact interactions (tolerance 0). \
         Floor {:.0e} (the Newton tolerance).\n",
        super::rough::FAR_FLOOR
    );
    let _ = writeln!(
        w,
        "| tolerance | p error vs exact | time per curve | runs | front |\n|---|---|---|---|---|"
    );
    let fp = r.far_points();
    for (i, f) in r.far.iter().enumerate() {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} |",
            f.label(),
            fmt_err(f.p_error),
            fmt_time(f.timing.median),
            f.timing.runs,
            cell_status(&fp, i, super::rough::FAR_FLOOR)
        );
    }
    let _ = writeln!(w, "\n![far field]({prefix}farfield.{ext})\n");
}

/// Five measured headline numbers (also the README's summary).
pub fn summary(study: &Study) -> Vec<String> {
    let mut out = Vec::new();
    let f = &study.fredholm;
    let mut parts = Vec::new();
    for (name, nystrom_side) in [("a/h₁ ≤ 4", true), ("a/h₁ > 4", false)] {
        let rows: Vec<&fredholm::Row> = f
            .cases
            .iter()
            .filter(|c| {
                (c.a_over_h <= strata_tablegen::asperity::NYSTROM_MAX_A_OVER_H) == nystrom_side
            })
            .filter_map(|c| c.default_index().map(|i| &c.rows[i]))
            .collect();
        if rows.is_empty() {
            continue;
        }
        let e = rows.iter().map(|r| r.force_error).fold(0.0, f64::max);
        let lo = rows
            .iter()
            .map(|r| r.timing.median)
            .fold(f64::INFINITY, f64::min);
        let hi = rows.iter().map(|r| r.timing.median).fold(0.0, f64::max);
        parts.push(format!(
            "{name}: force error ≤ {} in {} – {} per solve",
            fmt_err(e),
            fmt_time(lo),
            fmt_time(hi)
        ));
    }
    out.push(format!(
        "Fredholm solver, default discretisation, on the measured stacks and a/h₁: {}.",
        parts.join("; ")
    ));
    let t = &study.tables;
    if let Some(i) = t.default_index() {
        let r = &t.rows[i];
        out.push(format!(
            "Default table ({}×{}): χ {}, ζ {}, g {} against direct quadrature; built in {} \
             (one stack), {:.0} kB, {} per χ+ζ+g lookup.",
            r.nx,
            r.nw,
            fmt_err(r.chi),
            fmt_err(r.zeta),
            fmt_err(r.g),
            fmt_time(r.build.median),
            r.bytes as f64 / 1e3,
            fmt_time(r.lookup.median)
        ));
    }
    let lims: Vec<String> = study
        .approx
        .limits()
        .iter()
        .map(|(ratio, l)| match l {
            Some(x) => format!("a/h₁ ≤ {x:.3} (E₂/E₁ = {ratio})"),
            None => format!("nowhere in the sweep (E₂/E₁ = {ratio})"),
        })
        .collect();
    out.push(format!(
        "Second-order approximation: force within {} % of the full solution for {}.",
        super::approx::LIMIT * 100.0,
        lims.join(", ")
    ));
    let r = &study.rough;
    let ref_grid = r.settings.ref_grid();
    let models: Vec<String> = r
        .rows
        .iter()
        .filter(|x| {
            !x.is_reference
                && (matches!(x.kind, super::rough::Kind::Asperity(_))
                    || (x.is_default
                        && matches!(x.kind, super::rough::Kind::Bem { n, .. } if n * 2 == ref_grid)))
        })
        .map(|x| {
            format!(
                "{} {} in {}",
                x.kind.label(),
                fmt_err(x.p_error),
                fmt_time(x.timing.median)
            )
        })
        .collect();
    if let Some(reference) = r.reference() {
        out.push(format!(
            "Rough contact, p_n error against the BEM at n = {ref_grid} ({} per curve), time per {}-step curve: {}.",
            fmt_time(reference.timing.median),
            r.separations.len(),
            models.join("; ")
        ));
    }
    let off = defaults(study).iter().filter(|d| d.off).count();
    out.push(format!(
        "Defaults: {} measured, {} off the front (see below).",
        defaults(study).len(),
        off
    ));
    out
}

/// `errors.csv` and `timings.csv`.
pub fn csvs(study: &Study) -> Result<(String, String)> {
    let t = crate::csv_out::text(
        [
            "stage",
            "case",
            "median_seconds",
            "min_seconds",
            "max_seconds",
            "runs",
        ],
        study.timings.iter().map(|(st, c, tm)| {
            [
                st.clone(),
                c.clone(),
                format!("{:.6e}", tm.median),
                format!("{:.6e}", tm.min),
                format!("{:.6e}", tm.max),
                tm.runs.to_string(),
            ]
        }),
    )?;
    Ok((study.errors.csv()?, t))
}
