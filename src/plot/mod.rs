//! Plots for the CLI: x–y line/point charts written as SVG or PNG (chosen by the file
//! extension), with optional log axes, and colour-mapped field pictures ([`heatmap`]).
//!
//! ```ignore
//! plot::lines(Path::new("out.svg"), &PlotSpec {
//!     title: "force".into(), x_label: "δ (m)".into(), y_label: "P (N)".into(),
//!     log_x: false, log_y: false,
//!     series: vec![Series { name: "full".into(), points, style: Style::Line }],
//! })?;
//! ```
//!
//! Charts a paper can take: the title above (split after its first `: ` when long:
//! what is plotted, then the model and stack), the legend in its own column right of
//! the axes (never over the data), log axes labelled at 1-2-5 or 1…9 per decade when
//! they span few decades ([`ticks`]). The text font (DejaVu Sans, shipped in
//! assets/fonts) is embedded in the binary and registered with plotters once, so
//! plotting works on machines without system fonts.

mod heatmap;
pub mod ticks;

pub use heatmap::{Heatmap, heatmap, heatmap_map_size, heatmap_size, viridis};

use std::path::Path;
use std::sync::Once;

use anyhow::{Result, anyhow, bail};
use plotters::coord::Shift;
use plotters::coord::combinators::BindKeyPoints;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use ticks::{log_ticks, tick, tick_sci};

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Registers the shipped font with plotters (once).
fn register_font() {
    REGISTER.call_once(|| {
        // The font is a fixed, valid TTF: failure here would show as FontUnavailable
        // when drawing, reported as an error there.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A polyline through the points, in order.
    Line,
    /// A marker at each point.
    Points,
    /// A polyline in the given colour; `faint`: thin, translucent and without legend
    /// entry (one sample of many), else bold with a legend entry.
    Rgb { rgb: (u8, u8, u8), faint: bool },
    /// A hollow ring around each point (highlights points of other series).
    Ring,
    /// Nothing is drawn and no legend entry: the points only extend the axes.
    Spacer,
    /// A dashed polyline in the given colour, with a legend entry.
    Dashed { rgb: (u8, u8, u8) },
    /// A filled marker at each point in the given colour, with a legend entry.
    Dots { rgb: (u8, u8, u8) },
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

/// Canvas (px): the axes take the width left of the legend column.
const SIZE: (u32, u32) = (1000, 620);

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
    register_font();
    if spec.series.iter().all(|s| s.points.is_empty()) {
        bail!("plotting {}: nothing to plot", path.display());
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    // Drawn to a temporary file (same extension) renamed over `path`: never half a plot.
    strata_runtime::output::write_atomic_with(path, |tmp| match ext.as_deref() {
        Some("svg") => draw_any(SVGBackend::new(tmp, SIZE).into_drawing_area(), spec),
        Some("png") => draw_any(BitMapBackend::new(tmp, SIZE).into_drawing_area(), spec),
        _ => bail!(
            "plot file {}: extension must be .svg or .png",
            path.display()
        ),
    })
    .map_err(|e| e.context(format!("writing plot {}", path.display())))
}

/// The title in one or two centred lines (split after the first `: ` when long).
fn title_lines(title: &str) -> Vec<String> {
    match title.split_once(": ") {
        Some((a, b)) if title.chars().count() > 70 => vec![format!("{a}:"), b.to_string()],
        _ => vec![title.to_string()],
    }
}

/// The legend entries: named series that are drawn with a legend.
fn legend_entries(spec: &PlotSpec) -> Vec<(usize, &Series)> {
    spec.series
        .iter()
        .enumerate()
        .filter(|(_, s)| {
            !s.name.is_empty() && !matches!(s.style, Style::Spacer | Style::Rgb { faint: true, .. })
        })
        .collect()
}

/// The colour of series `i` drawn in a palette style.
fn palette(i: usize) -> RGBAColor {
    Palette99::pick(i).to_rgba()
}

fn draw_any<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, spec: &PlotSpec) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let lines = title_lines(&spec.title);
    let title_h = 14 + 26 * lines.len() as u32;
    let (top, body) = root.split_vertically(title_h);
    let w = SIZE.0 as i32;
    for (k, l) in lines.iter().enumerate() {
        let style = ("sans-serif", if k == 0 { 22 } else { 18 })
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top));
        top.draw_text(l, &style, (w / 2, 8 + 26 * k as i32))
            .map_err(err)?;
    }
    let entries = legend_entries(spec);
    let longest = entries
        .iter()
        .map(|(_, s)| s.name.chars().count())
        .max()
        .unwrap_or(0);
    let legend_w = if entries.is_empty() {
        0
    } else {
        (48 + 8 * longest as u32).clamp(120, 340)
    };
    let (plot_area, legend_area) = body.split_horizontally(SIZE.0 - legend_w);
    draw_legend(&legend_area, &entries)?;
    let keep = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
    let pts = || {
        spec.series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|(x, y)| keep(*x, spec.log_x) && keep(*y, spec.log_y))
    };
    let (x0, x1) = axis_range(pts().map(|p| p.0), spec.log_x)?;
    let (y0, y1) = axis_range(pts().map(|p| p.1), spec.log_y)?;
    let log_axis = |lo: f64, hi: f64| {
        let (bold, light) = log_ticks(lo, hi);
        (lo..hi)
            .log_scale()
            .with_key_points(bold)
            .with_light_points(light)
    };
    let (xs, ys) = ((x0, x1), (y0, y1));
    match (spec.log_x, spec.log_y) {
        (false, false) => draw(plot_area, spec, (x0..x1, xs), (y0..y1, ys)),
        (true, false) => draw(plot_area, spec, (log_axis(x0, x1), xs), (y0..y1, ys)),
        (false, true) => draw(plot_area, spec, (x0..x1, xs), (log_axis(y0, y1), ys)),
        (true, true) => draw(
            plot_area,
            spec,
            (log_axis(x0, x1), xs),
            (log_axis(y0, y1), ys),
        ),
    }?;
    root.present().map_err(err)?;
    Ok(())
}

/// The legend in its own column: a sample of each series' line or marker and its name.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(usize, &Series)],
) -> Result<()> {
    let font = ("sans-serif", 14).into_font().color(&BLACK);
    for (row, (i, s)) in entries.iter().enumerate() {
        let y = 40 + 24 * row as i32;
        let (x, x2) = (8, 36);
        let c = palette(*i);
        match s.style {
            Style::Line => area.draw(&PathElement::new(vec![(x, y), (x2, y)], c.stroke_width(2))),
            Style::Points => area.draw(&Circle::new((x + 14, y), 3, c.filled())),
            Style::Ring => area.draw(&Circle::new((x + 14, y), 6, c.stroke_width(2))),
            Style::Rgb { rgb, .. } => {
                let c = RGBColor(rgb.0, rgb.1, rgb.2).stroke_width(3);
                area.draw(&PathElement::new(vec![(x, y), (x2, y)], c))
            }
            Style::Dashed { rgb } => {
                let c = RGBColor(rgb.0, rgb.1, rgb.2).stroke_width(2);
                area.draw(&PathElement::new(vec![(x, y), (x + 10, y)], c))
                    .and_then(|()| area.draw(&PathElement::new(vec![(x + 17, y), (x2, y)], c)))
            }
            Style::Dots { rgb } => area.draw(&Circle::new(
                (x + 14, y),
                4,
                RGBColor(rgb.0, rgb.1, rgb.2).filled(),
            )),
            Style::Spacer => Ok(()),
        }
        .map_err(err)?;
        area.draw_text(&s.name, &font, (x2 + 8, y - 8))
            .map_err(err)?;
    }
    Ok(())
}

fn draw<DB, X, Y>(
    area: DrawingArea<DB, Shift>,
    spec: &PlotSpec,
    (x, x_span): (X, (f64, f64)),
    (y, y_span): (Y, (f64, f64)),
) -> Result<()>
where
    DB: DrawingBackend,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut chart = ChartBuilder::on(&area)
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    // A log axis reaching below 1e-3 or above 1e5 is labelled in one notation.
    let sci = |log: bool, (lo, hi): (f64, f64)| log && (lo < 1e-3 || hi >= 1e5);
    let (sx, sy) = (sci(spec.log_x, x_span), sci(spec.log_y, y_span));
    let fx = move |v: &f64| if sx { tick_sci(*v) } else { tick(*v) };
    let fy = move |v: &f64| if sy { tick_sci(*v) } else { tick(*v) };
    chart
        .configure_mesh()
        .x_desc(&spec.x_label)
        .y_desc(&spec.y_label)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .x_labels(10)
        .y_labels(10)
        .max_light_lines(4)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    let keep = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
    for (i, s) in spec.series.iter().enumerate() {
        let color = palette(i);
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
                    .map_err(err)?;
            }
            Style::Points => {
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))
                    .map_err(err)?;
            }
            Style::Spacer => {}
            Style::Ring => {
                let style = color.stroke_width(2);
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 8, style)))
                    .map_err(err)?;
            }
            Style::Rgb { rgb, faint } => {
                let c = if faint {
                    RGBColor(rgb.0, rgb.1, rgb.2).mix(0.3).stroke_width(1)
                } else {
                    RGBColor(rgb.0, rgb.1, rgb.2).stroke_width(3)
                };
                chart.draw_series(LineSeries::new(pts, c)).map_err(err)?;
            }
            Style::Dashed { rgb } => {
                let c = RGBColor(rgb.0, rgb.1, rgb.2).stroke_width(2);
                chart
                    .draw_series(DashedLineSeries::new(pts, 8, 5, c))
                    .map_err(err)?;
            }
            Style::Dots { rgb } => {
                let c = RGBColor(rgb.0, rgb.1, rgb.2).filled();
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 4, c)))
                    .map_err(err)?;
            }
        }
    }
    Ok(())
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
