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
    /// A polyline in the given colour; `faint`: thin, translucent and without legend
    /// entry (one sample of many), else bold with a legend entry.
    Rgb { rgb: (u8, u8, u8), faint: bool },
    /// A hollow ring around each point (highlights points of other series).
    Ring,
    /// Nothing is drawn and no legend entry: the points only extend the axes (room
    /// for the legend).
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
    // Drawn to a temporary file (same extension) renamed over `path`: never half a plot.
    strata_runtime::output::write_atomic_with(path, |tmp| match ext.as_deref() {
        Some("svg") => {
            let root = SVGBackend::new(tmp, SIZE).into_drawing_area();
            draw_any(root, spec)
        }
        Some("png") => {
            let root = BitMapBackend::new(tmp, SIZE).into_drawing_area();
            draw_any(root, spec)
        }
        _ => bail!(
            "plot file {}: extension must be .svg or .png",
            path.display()
        ),
    })
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
            Style::Spacer => {}
            Style::Ring => {
                let style = color.stroke_width(2);
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 8, style)))
                    .map_err(err)?
                    .label(s.name.clone())
                    .legend(move |(x, y)| Circle::new((x + 10, y), 6, style));
            }
            Style::Rgb { rgb, faint: true } => {
                let c = RGBColor(rgb.0, rgb.1, rgb.2).mix(0.3).stroke_width(1);
                chart.draw_series(LineSeries::new(pts, c)).map_err(err)?;
            }
            Style::Rgb { rgb, faint: false } => {
                let c = RGBColor(rgb.0, rgb.1, rgb.2).stroke_width(3);
                chart
                    .draw_series(LineSeries::new(pts, c))
                    .map_err(err)?
                    .label(s.name.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
            }
            Style::Dashed { rgb } => {
                let c = RGBColor(rgb.0, rgb.1, rgb.2).stroke_width(2);
                chart
                    .draw_series(DashedLineSeries::new(pts, 8, 5, c))
                    .map_err(err)?
                    .label(s.name.clone())
                    .legend(move |(x, y)| {
                        EmptyElement::at((x, y))
                            + PathElement::new(vec![(0, 0), (7, 0)], c)
                            + PathElement::new(vec![(13, 0), (20, 0)], c)
                    });
            }
            Style::Dots { rgb } => {
                let c = RGBColor(rgb.0, rgb.1, rgb.2).filled();
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 4, c)))
                    .map_err(err)?
                    .label(s.name.clone())
                    .legend(move |(x, y)| Circle::new((x + 10, y), 4, c));
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

/// A colour-mapped picture of a field on an n0×n1 grid (pressure or gap maps).
#[derive(Debug, Clone, PartialEq)]
pub struct Heatmap<'a> {
    pub title: String,
    /// Label of the colour bar, with the unit (e.g. "p (Pa)").
    pub label: String,
    /// Row-major values, `values[i * n1 + j]`; row i is drawn as picture row i.
    pub values: &'a [f64],
    pub n0: usize,
    pub n1: usize,
    /// Draw exact zeros white (a pressure map: white outside the contact).
    pub zero_white: bool,
}

const HM_MARGIN: u32 = 10;
const HM_TITLE: u32 = 52;
const HM_BAR_GAP: u32 = 12;
const HM_BAR_W: u32 = 20;
const HM_LABELS: u32 = 110;

/// Pixel size of the map part of a [`heatmap`]: grids up to 512 are magnified by the
/// largest integer factor that keeps the longer side ≤ 512 px; grids up to 1024 are
/// drawn one pixel per point; larger grids are sampled down to a 1024 px longer side.
pub fn heatmap_map_size(n0: usize, n1: usize) -> (u32, u32) {
    let m = n0.max(n1).max(1);
    let (w, h) = if m <= 512 {
        let k = 512 / m;
        (n1 * k, n0 * k)
    } else if m <= 1024 {
        (n1, n0)
    } else {
        ((n1 * 1024).div_ceil(m), (n0 * 1024).div_ceil(m))
    };
    (w.max(1) as u32, h.max(1) as u32)
}

/// Size (width, height) in pixels of the PNG that [`heatmap`] writes: the map
/// ([`heatmap_map_size`]), a title band above, a colour bar with labels on the right.
pub fn heatmap_size(n0: usize, n1: usize) -> (u32, u32) {
    let (w, h) = heatmap_map_size(n0, n1);
    (
        HM_MARGIN + w + HM_BAR_GAP + HM_BAR_W + HM_LABELS,
        HM_TITLE + h + HM_MARGIN,
    )
}

/// The viridis colour map (matplotlib's default), `t` in [0, 1].
fn viridis(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 8] = [
        (68, 1, 84),
        (70, 50, 127),
        (54, 92, 141),
        (39, 127, 143),
        (31, 162, 136),
        (74, 194, 110),
        (160, 219, 57),
        (254, 232, 37),
    ];
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let mix = |a: u8, b: u8| (a as f64 + (b as f64 - a as f64) * f).round() as u8;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Writes `h` as a PNG picture (size [`heatmap_size`]): viridis, linear from the
/// smallest to the largest finite value (colour bar on the right); non-finite values
/// grey. Nearest-neighbour resampling to the picture's pixels.
pub fn heatmap(path: &Path, h: &Heatmap) -> Result<()> {
    REGISTER.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
    if h.n0 == 0 || h.n1 == 0 || h.values.len() != h.n0 * h.n1 {
        bail!(
            "picture {}: {} values for a {}×{} grid",
            path.display(),
            h.values.len(),
            h.n0,
            h.n1
        );
    }
    let (lo, hi) = h
        .values
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        bail!("picture {}: no finite values", path.display());
    }
    let span = if hi > lo { hi - lo } else { 1.0 };
    let (mw, mh) = heatmap_map_size(h.n0, h.n1);
    // Drawn to a temporary file (same extension) renamed over `path`: never half a picture.
    let draw = |tmp: &Path| -> Result<()> {
        let root = BitMapBackend::new(tmp, heatmap_size(h.n0, h.n1)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        root.draw_text(
            &h.title,
            &("sans-serif", 16).into_font().color(&BLACK),
            (HM_MARGIN as i32, 8),
        )
        .map_err(err)?;
        let grey = RGBColor(160, 160, 160);
        for y in 0..mh {
            let i = (y as usize * h.n0) / mh as usize;
            for x in 0..mw {
                let j = (x as usize * h.n1) / mw as usize;
                let v = h.values[i * h.n1 + j];
                let c = if !v.is_finite() {
                    grey
                } else if h.zero_white && v == 0.0 {
                    WHITE
                } else {
                    viridis((v - lo) / span)
                };
                root.draw_pixel(((HM_MARGIN + x) as i32, (HM_TITLE + y) as i32), &c)
                    .map_err(err)?;
            }
        }
        // Colour bar: top = largest value.
        let bx = (HM_MARGIN + mw + HM_BAR_GAP) as i32;
        for y in 0..mh {
            let t = 1.0 - y as f64 / (mh.max(2) - 1) as f64;
            let yy = (HM_TITLE + y) as i32;
            root.draw(&PathElement::new(
                vec![(bx, yy), (bx + HM_BAR_W as i32 - 1, yy)],
                viridis(t),
            ))
            .map_err(err)?;
        }
        let font = ("sans-serif", 13).into_font().color(&BLACK);
        let lx = bx + HM_BAR_W as i32 + 4;
        for (frac, v) in [(0.0, hi), (0.5, 0.5 * (lo + hi)), (1.0, lo)] {
            let yy = HM_TITLE as i32 + (frac * (mh as f64 - 14.0)) as i32;
            root.draw_text(&tick(v), &font, (lx, yy)).map_err(err)?;
        }
        root.draw_text(&h.label, &font, (bx, (HM_TITLE - 18) as i32))
            .map_err(err)?;
        root.present().map_err(err)?;
        Ok(())
    };
    strata_runtime::output::write_atomic_with(path, draw)
        .map_err(|e| e.context(format!("writing picture {}", path.display())))
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
    fn heatmap_png_has_the_documented_size() {
        let dir = std::env::temp_dir().join(format!("strata-heat-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let values: Vec<f64> = (0..48 * 64).map(|k| (k % 7) as f64).collect();
        let png = dir.join("h.png");
        let h = Heatmap {
            title: "test".into(),
            label: "p (Pa)".into(),
            values: &values,
            n0: 48,
            n1: 64,
            zero_white: true,
        };
        heatmap(&png, &h).unwrap();
        let b = std::fs::read(&png).unwrap();
        assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n");
        let be = |o: usize| u32::from_be_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
        assert_eq!((be(16), be(20)), heatmap_size(48, 64));
        assert_eq!(heatmap_map_size(48, 64), (512, 384));
        assert_eq!(heatmap_map_size(2048, 2048), (1024, 1024));
        assert!(heatmap(&png, &Heatmap { n0: 5, ..h }).is_err());
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(254, 232, 37));
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
