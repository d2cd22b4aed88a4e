//! Small reusable plotting helper for the CLI: x–y line/point charts written as SVG or
//! PNG (chosen by the file extension), with optional log axes.
//!
//! ```ignore
//! plot::lines(Path::new("out.svg"), &PlotSpec {
//!     title: "force".into(), x_label: "δ (m)".into(), y_label: "P (N)".into(),
//!     log_x: false, log_y: false,
//!     series: vec![Series { name: "full".into(), points, style: Style::Line }],
//! })?;
//! ```
//!
//! The text font (DejaVu Sans, shipped in assets/fonts) is embedded in the binary and
//! registered with plotters once, so plotting works on machines without system fonts.

use std::path::Path;
use std::sync::Once;

use anyhow::{Result, anyhow, bail};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

static FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A polyline through the points, in order.
    Line,
    /// A marker at each point.
    Points,
}

/// One named data series.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub style: Style,
}

/// A whole chart.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotSpec {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
    pub series: Vec<Series>,
}

const SIZE: (u32, u32) = (900, 600);

fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("plotting: {e}")
}

/// Data range of one axis over all series, padded; log axes use positive values only.
fn axis_range(values: impl Iterator<Item = f64>, log: bool) -> Result<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        bail!(
            "plotting: no finite{} values to plot",
            if log { " positive" } else { "" }
        );
    }
    if log {
        if hi <= lo {
            return Ok((lo / 2.0, hi * 2.0));
        }
        let f = (hi / lo).powf(0.03);
        Ok((lo / f, hi * f))
    } else {
        if hi <= lo {
            let w = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
            return Ok((lo - w, hi + w));
        }
        let pad = 0.03 * (hi - lo);
        Ok((lo - pad, hi + pad))
    }
}

/// Draws `spec` to `path` (`.svg` or `.png`). Points that are non-finite (or ≤ 0 on a
/// log axis) are skipped.
pub fn lines(path: &Path, spec: &PlotSpec) -> Result<()> {
    REGISTER.call_once(|| {
        // The font is a fixed, valid TTF: failure here would show as FontUnavailable
        // when drawing, reported as an error there.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
    if spec.series.iter().all(|s| s.points.is_empty()) {
        bail!("plotting {}: nothing to plot", path.display());
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("svg") => {
            let root = SVGBackend::new(path, SIZE).into_drawing_area();
            draw_any(root, spec)
        }
        Some("png") => {
            let root = BitMapBackend::new(path, SIZE).into_drawing_area();
            draw_any(root, spec)
        }
        _ => bail!(
            "plot file {}: extension must be .svg or .png",
            path.display()
        ),
    }
    .map_err(|e| e.context(format!("writing plot {}", path.display())))
}

fn draw_any<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, spec: &PlotSpec) -> Result<()> {
    let keep = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
    let pts = || {
        spec.series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|(x, y)| keep(*x, spec.log_x) && keep(*y, spec.log_y))
    };
    let (x0, x1) = axis_range(pts().map(|p| p.0), spec.log_x)?;
    let (y0, y1) = axis_range(pts().map(|p| p.1), spec.log_y)?;
    match (spec.log_x, spec.log_y) {
        (false, false) => draw(root, spec, x0..x1, y0..y1),
        (true, false) => draw(root, spec, (x0..x1).log_scale(), y0..y1),
        (false, true) => draw(root, spec, x0..x1, (y0..y1).log_scale()),
        (true, true) => draw(root, spec, (x0..x1).log_scale(), (y0..y1).log_scale()),
    }
}

/// Tick label: scientific notation for SI values that fixed decimals would show as
/// 0.0 (gaps of micrometres, compliances), plain decimals otherwise.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.2e}");
        // 1.50e-6 → 1.5e-6
        match s.split_once('e') {
            Some((m, e)) => {
                let m = m.trim_end_matches('0').trim_end_matches('.');
                format!("{m}e{e}")
            }
            None => s,
        }
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn draw<DB, X, Y>(root: DrawingArea<DB, Shift>, spec: &PlotSpec, x: X, y: Y) -> Result<()>
where
    DB: DrawingBackend,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    root.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&spec.title, ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(&spec.x_label)
        .y_desc(&spec.y_label)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    let keep = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
    for (i, s) in spec.series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|(x, y)| keep(*x, spec.log_x) && keep(*y, spec.log_y))
            .collect();
        match s.style {
            Style::Line => {
                chart
                    .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                    .map_err(err)?
                    .label(s.name.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
            }
            Style::Points => {
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))
                    .map_err(err)?
                    .label(s.name.clone())
                    .legend(move |(x, y)| Circle::new((x + 10, y), 3, color.filled()));
            }
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tick_tests {
    #[test]
    fn tick_labels_keep_small_values_readable() {
        assert_eq!(super::tick(2.5e-6), "2.5e-6");
        assert_eq!(super::tick(1e-5), "1e-5");
        assert_eq!(super::tick(0.0012), "0.0012");
        assert_eq!(super::tick(0.5), "0.5");
        assert_eq!(super::tick(0.0), "0");
        assert_eq!(super::tick(2e9), "2e9");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(log: bool) -> PlotSpec {
        PlotSpec {
            title: "test".into(),
            x_label: "x (m)".into(),
            y_label: "y (N)".into(),
            log_x: log,
            log_y: log,
            series: vec![
                Series {
                    name: "line".into(),
                    points: (1..20).map(|i| (i as f64, (i * i) as f64)).collect(),
                    style: Style::Line,
                },
                Series {
                    name: "points".into(),
                    points: vec![(2.0, 3.0), (f64::NAN, 1.0), (5.0, 30.0)],
                    style: Style::Points,
                },
            ],
        }
    }

    #[test]
    fn writes_svg_and_png() {
        let dir = std::env::temp_dir().join(format!("strata-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let svg = dir.join("a.svg");
        lines(&svg, &spec(false)).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("<svg") && text.contains("points"));
        let png = dir.join("b.png");
        lines(&png, &spec(true)).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        assert!(lines(&dir.join("c.pdf"), &spec(false)).is_err());
        let empty = PlotSpec {
            series: vec![],
            ..spec(false)
        };
        assert!(lines(&dir.join("d.svg"), &empty).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn ranges_are_padded_and_log_safe() {
        let (lo, hi) = axis_range([1.0, 2.0].into_iter(), false).unwrap();
        assert!(lo < 1.0 && hi > 2.0);
        let (lo, hi) = axis_range([-1.0, 0.0, 10.0, 100.0].into_iter(), true).unwrap();
        assert!(lo > 0.0 && lo < 10.0 && hi > 100.0);
        assert!(axis_range([f64::NAN].into_iter(), false).is_err());
        let (lo, hi) = axis_range([3.0, 3.0].into_iter(), false).unwrap();
        assert!(lo < 3.0 && hi > 3.0);
    }
}
