//! Colour-mapped pictures of fields on a grid (BEM pressure and gap maps), as PNG:
//! viridis, a colour bar with its unit, spatial axes in mm (or µm for samples below
//! 1 mm) with labelled ticks, and a scale bar.

use std::path::Path;

use anyhow::{Result, bail};
use plotters::prelude::*;

use super::ticks::{length, nice_step, tick};
use super::{err, register_font};

/// A colour-mapped picture of a field on an n0×n1 grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Heatmap<'a> {
    pub title: String,
    /// Label of the colour bar, with the unit (e.g. "p (MPa)").
    pub label: String,
    /// Row-major values, `values[i * n1 + j]`; row i is drawn as picture row i (top
    /// first), column j as picture column j.
    pub values: &'a [f64],
    pub n0: usize,
    pub n1: usize,
    /// Draw exact zeros white (a pressure map: white outside the contact).
    pub zero_white: bool,
    /// Physical length of the first axis (rows, n0 points), m; the grid spacing is the
    /// same along both axes.
    pub size: f64,
}

const MARGIN: u32 = 10;
const LEFT: u32 = 70;
const TITLE: u32 = 52;
const BOTTOM: u32 = 78;
const BAR_GAP: u32 = 14;
const BAR_W: u32 = 20;
const LABELS: u32 = 110;

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
/// ([`heatmap_map_size`]) with its axes, a title band above, a colour bar with labels
/// on the right, the x axis and the scale bar below.
pub fn heatmap_size(n0: usize, n1: usize) -> (u32, u32) {
    let (w, h) = heatmap_map_size(n0, n1);
    (
        LEFT + w + BAR_GAP + BAR_W + LABELS,
        TITLE + h + BOTTOM + MARGIN,
    )
}

/// The viridis colour map (matplotlib's default), `t` in [0, 1].
pub fn viridis(t: f64) -> RGBColor {
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

/// The unit of a map's axes: mm for samples of 1 mm and more, else µm.
fn axis_unit(size: f64) -> (f64, &'static str) {
    if size >= 1e-3 {
        (1e3, "mm")
    } else {
        (1e6, "µm")
    }
}

/// Writes `h` as a PNG picture (size [`heatmap_size`]): viridis, linear from the
/// smallest to the largest finite value (colour bar on the right); non-finite values
/// grey. Nearest-neighbour resampling to the picture's pixels.
pub fn heatmap(path: &Path, h: &Heatmap) -> Result<()> {
    register_font();
    if h.n0 == 0 || h.n1 == 0 || h.values.len() != h.n0 * h.n1 {
        bail!(
            "picture {}: {} values for a {}×{} grid",
            path.display(),
            h.values.len(),
            h.n0,
            h.n1
        );
    }
    if !(h.size.is_finite() && h.size > 0.0) {
        bail!("picture {}: sample size {} m", path.display(), h.size);
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
    // Drawn to a temporary file (same extension) renamed over `path`: never half a picture.
    strata_runtime::output::write_atomic_with(path, |tmp| draw(tmp, h, lo, hi))
        .map_err(|e| e.context(format!("writing picture {}", path.display())))
}

fn draw(tmp: &Path, h: &Heatmap, lo: f64, hi: f64) -> Result<()> {
    let span = if hi > lo { hi - lo } else { 1.0 };
    let (mw, mh) = heatmap_map_size(h.n0, h.n1);
    let root = BitMapBackend::new(tmp, heatmap_size(h.n0, h.n1)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let black = |px| ("sans-serif", px).into_font().color(&BLACK);
    root.draw_text(&h.title, &black(16), (MARGIN as i32, 8))
        .map_err(err)?;
    let (x0, y0) = (LEFT as i32, TITLE as i32);
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
            root.draw_pixel((x0 + x as i32, y0 + y as i32), &c)
                .map_err(err)?;
        }
    }
    root.draw(&Rectangle::new(
        [(x0 - 1, y0 - 1), (x0 + mw as i32, y0 + mh as i32)],
        BLACK.stroke_width(1),
    ))
    .map_err(err)?;
    // Spatial axes: x along columns (left to right), y along rows (top to bottom).
    let (scale, unit) = axis_unit(h.size);
    let (ly, lx) = (h.size, h.size * h.n1 as f64 / h.n0 as f64);
    let font = black(13);
    let step = nice_step(lx.max(ly) * scale, 5.0);
    let mut t = 0.0;
    while t <= lx * scale * (1.0 + 1e-9) {
        let px = x0 + (t / (lx * scale) * mw as f64).round() as i32;
        let yb = y0 + mh as i32;
        root.draw(&PathElement::new(vec![(px, yb), (px, yb + 5)], BLACK))
            .map_err(err)?;
        root.draw_text(&tick(t), &font, (px - 8, yb + 8))
            .map_err(err)?;
        t += step;
    }
    root.draw_text(
        &format!("x ({unit})"),
        &font,
        (x0 + mw as i32 / 2 - 15, y0 + mh as i32 + 26),
    )
    .map_err(err)?;
    let mut t = 0.0;
    while t <= ly * scale * (1.0 + 1e-9) {
        let py = y0 + (t / (ly * scale) * mh as f64).round() as i32;
        root.draw(&PathElement::new(vec![(x0 - 5, py), (x0, py)], BLACK))
            .map_err(err)?;
        root.draw_text(&tick(t), &font, (x0 - 45, py - 7))
            .map_err(err)?;
        t += step;
    }
    root.draw_text(&format!("y ({unit})"), &font, (8, y0 - 18))
        .map_err(err)?;
    // Scale bar under the map, right-aligned: about a fifth of the width.
    let bar_len = nice_step(lx, 5.0).min(lx);
    let bar_px = (bar_len / lx * mw as f64).round() as i32;
    let (bx1, by) = (x0 + mw as i32, y0 + mh as i32 + 56);
    root.draw(&Rectangle::new(
        [(bx1 - bar_px, by), (bx1, by + 6)],
        BLACK.filled(),
    ))
    .map_err(err)?;
    root.draw_text(&length(bar_len), &font, (bx1 - bar_px - 70, by - 4))
        .map_err(err)?;
    // Colour bar: top = largest value.
    let bx = x0 + (mw + BAR_GAP) as i32;
    for y in 0..mh {
        let t = 1.0 - y as f64 / (mh.max(2) - 1) as f64;
        let yy = y0 + y as i32;
        root.draw(&PathElement::new(
            vec![(bx, yy), (bx + BAR_W as i32 - 1, yy)],
            viridis(t),
        ))
        .map_err(err)?;
    }
    // Colour-bar labels at round values (about five), the bar's ends in between.
    let lxb = bx + BAR_W as i32 + 4;
    let step = nice_step(hi - lo, 5.0);
    let mut v = (lo / step).ceil() * step;
    while v <= hi + 1e-9 * step && hi > lo {
        let frac = (hi - v) / (hi - lo);
        let yy = y0 + (frac * (mh as f64 - 1.0)) as i32;
        root.draw(&PathElement::new(
            vec![(bx + BAR_W as i32, yy), (lxb, yy)],
            BLACK,
        ))
        .map_err(err)?;
        root.draw_text(&tick(v), &font, (lxb + 2, yy - 7))
            .map_err(err)?;
        v += step;
    }
    if hi <= lo {
        root.draw_text(&tick(lo), &font, (lxb, y0)).map_err(err)?;
    }
    root.draw_text(&h.label, &font, (bx, y0 - 18))
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heatmap_png_has_the_documented_size() {
        let dir = std::env::temp_dir().join(format!("strata-heat-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let values: Vec<f64> = (0..48 * 64).map(|k| (k % 7) as f64).collect();
        let png = dir.join("h.png");
        let h = Heatmap {
            title: "test".into(),
            label: "p (MPa)".into(),
            values: &values,
            n0: 48,
            n1: 64,
            zero_white: true,
            size: 1e-3,
        };
        heatmap(&png, &h).unwrap();
        let b = std::fs::read(&png).unwrap();
        assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n");
        let be = |o: usize| u32::from_be_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
        assert_eq!((be(16), be(20)), heatmap_size(48, 64));
        assert_eq!(heatmap_map_size(48, 64), (512, 384));
        assert_eq!(heatmap_map_size(2048, 2048), (1024, 1024));
        assert!(heatmap(&png, &Heatmap { n0: 5, ..h.clone() }).is_err());
        assert!(heatmap(&png, &Heatmap { size: 0.0, ..h }).is_err());
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(254, 232, 37));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
