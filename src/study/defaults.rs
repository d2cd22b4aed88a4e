//! The defaults the study measures and where each sits against its Pareto front.

use super::fredholm::label;
use super::pareto::{self, Point};
use super::tables::Order;
use super::{Study, fmt_err, fmt_time};

/// A measured default and where it sits.
pub(super) struct DefaultRow {
    pub(super) what: String,
    pub(super) value: String,
    pub(super) point: String,
    pub(super) status: String,
    /// A faster point at least as accurate (label, error, time), if any.
    pub(super) better: Option<String>,
    pub(super) off: bool,
}

pub(super) fn defaults(study: &Study) -> Vec<DefaultRow> {
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
