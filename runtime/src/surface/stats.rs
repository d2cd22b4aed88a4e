//! Surface statistics and their plausibility.
//!
//! - RMS height S_q = √⟨(z − z̄)²⟩ (m);
//! - RMS slope S_dq = √(⟨(Δ_x z/dx)²⟩ + ⟨(Δ_y z/dy)²⟩) (dimensionless), with forward
//!   differences Δ_x z = z[i+1, j] − z[i, j] on the x spacing dx and Δ_y z on dy, each
//!   mean taken over the differences that exist: (n0 − 1)·n1 and n0·(n1 − 1) on a
//!   non-periodic sample, n0·n1 each (wrapping) on a periodic one;
//! - peak-to-valley S_z = max z − min z (m).
//!
//! Plausibility (the mistake it catches: heights in µm or nm read as metres, or
//! metres declared as nm): S_q > [`MAX_RMS_HEIGHT_FRACTION`] × the larger side of the
//! sample, S_dq > [`MAX_RMS_SLOPE`] (steeper than 45° on average: no measured
//! engineering surface, and outside the small-slope theory of the contact models), or
//! S_q < [`MIN_RMS_HEIGHT`] (below the atomic scale). Each is a warning naming the
//! statistic, its value and the limit, not an error: the caller decides.

use serde::Serialize;

use super::Surface;

/// Largest plausible RMS height as a fraction of the larger sample side.
pub const MAX_RMS_HEIGHT_FRACTION: f64 = 0.01;
/// Largest plausible RMS slope.
pub const MAX_RMS_SLOPE: f64 = 1.0;
/// Smallest plausible RMS height (m): 0.1 Å, below any atomic roughness.
pub const MIN_RMS_HEIGHT: f64 = 1e-11;

/// The usual statistics of a height map (SI units; module docs for definitions).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SurfaceStats {
    /// Grid points (n0 along x, n1 along y).
    pub shape: (usize, usize),
    /// Pixel sizes (dx, dy) (m).
    pub pixel_size: (f64, f64),
    /// Sides (Lx, Ly) = (n0·dx, n1·dy) (m).
    pub size: (f64, f64),
    /// Whether the sample is one cell of a periodic pattern.
    pub periodic: bool,
    /// Mean height z̄ (m).
    pub mean_height: f64,
    /// RMS height S_q (m).
    pub rms_height: f64,
    /// RMS slope S_dq (1).
    pub rms_slope: f64,
    /// Peak-to-valley S_z (m).
    pub peak_to_valley: f64,
}

impl Surface {
    /// RMS slope S_dq (module docs): forward differences on dx and dy.
    pub fn rms_slope(&self) -> f64 {
        let (n0, n1) = self.shape();
        let (dx, dy) = self.pixel_size();
        let p = self.is_periodic();
        let (mut sx, mut cx, mut sy, mut cy) = (0.0, 0usize, 0.0, 0usize);
        for i in 0..n0 {
            for j in 0..n1 {
                let z = self.z(i, j);
                if i + 1 < n0 || p {
                    let g = (self.z((i + 1) % n0, j) - z) / dx;
                    sx += g * g;
                    cx += 1;
                }
                if j + 1 < n1 || p {
                    let g = (self.z(i, (j + 1) % n1) - z) / dy;
                    sy += g * g;
                    cy += 1;
                }
            }
        }
        (sx / cx.max(1) as f64 + sy / cy.max(1) as f64).sqrt()
    }

    /// Peak-to-valley height S_z = max z − min z (m).
    pub fn peak_to_valley(&self) -> f64 {
        let (lo, hi) = self
            .heights()
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &z| {
                (a.min(z), b.max(z))
            });
        hi - lo
    }

    /// The statistics of this surface.
    pub fn stats(&self) -> SurfaceStats {
        SurfaceStats {
            shape: self.shape(),
            pixel_size: self.pixel_size(),
            size: self.extent(),
            periodic: self.is_periodic(),
            mean_height: self.mean(),
            rms_height: self.rms(),
            rms_slope: self.rms_slope(),
            peak_to_valley: self.peak_to_valley(),
        }
    }
}

impl Surface {
    /// The statistics over the points that were measured: the repaired points
    /// ([`Surface::filled_points`]) left out of the mean, RMS height and peak-to-valley,
    /// and every difference touching one left out of the RMS slope. Equal to
    /// [`Surface::stats`] when nothing was repaired.
    pub fn stats_over_valid(&self) -> SurfaceStats {
        let mut st = self.stats();
        if self.filled_points().is_empty() {
            return st;
        }
        let (n0, n1) = self.shape();
        let mut keep = vec![true; n0 * n1];
        for &k in self.filled_points() {
            keep[k] = false;
        }
        let z = self.heights();
        let kept: Vec<f64> = (0..z.len()).filter(|&k| keep[k]).map(|k| z[k]).collect();
        let n = kept.len().max(1) as f64;
        let mean = kept.iter().sum::<f64>() / n;
        st.mean_height = mean;
        st.rms_height = (kept.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt();
        let (lo, hi) = kept
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        st.peak_to_valley = hi - lo;
        let (dx, dy) = self.pixel_size();
        let p = self.is_periodic();
        let (mut sx, mut cx, mut sy, mut cy) = (0.0, 0usize, 0.0, 0usize);
        for i in 0..n0 {
            for j in 0..n1 {
                let k = i * n1 + j;
                if !keep[k] {
                    continue;
                }
                if i + 1 < n0 || p {
                    let m = ((i + 1) % n0) * n1 + j;
                    if keep[m] {
                        sx += ((z[m] - z[k]) / dx).powi(2);
                        cx += 1;
                    }
                }
                if j + 1 < n1 || p {
                    let m = i * n1 + (j + 1) % n1;
                    if keep[m] {
                        sy += ((z[m] - z[k]) / dy).powi(2);
                        cy += 1;
                    }
                }
            }
        }
        st.rms_slope = (sx / cx.max(1) as f64 + sy / cy.max(1) as f64).sqrt();
        st
    }

    /// The plausibility warnings of [`Surface::stats`] ([`SurfaceStats::plausibility`]);
    /// where the file gave the height unit (an .x3p, a NetCDF file or container with a
    /// unit, where `height_unit` is refused), without the advice to set it.
    pub fn plausibility(&self) -> Vec<String> {
        let mut w = self.stats().plausibility();
        if self.unit_from_file {
            for line in &mut w {
                if let Some(cut) = line.find(": are the heights in µm or nm") {
                    line.truncate(cut);
                    line.push_str(
                        ": the file gives its height unit; check the instrument's export \
                         (heights or lateral sizes in the wrong unit?)",
                    );
                }
                if let Some(cut) = line.find(": heights in metres declared as a smaller unit") {
                    line.truncate(cut);
                    line.push_str(
                        ": the file gives its height unit; check the instrument's export",
                    );
                }
            }
        }
        w
    }

    /// The refusal of a surface with nothing left after form removal: a form was
    /// removed when read and the remaining roughness has an RMS below
    /// [`MIN_RMS_HEIGHT`] (the heights were a plane or a quadric, to round-off); `None`
    /// otherwise. Solvers call it before any work.
    pub fn nothing_left(&self) -> Option<super::SurfaceError> {
        let f = self.form()?;
        (f.kind != super::Detrend::None && self.rms() < MIN_RMS_HEIGHT).then(|| {
            super::SurfaceError::NothingLeft {
                detrend: f.kind.name(),
                rms: self.rms(),
                limit: MIN_RMS_HEIGHT,
                form_rms: f.rms,
                slope_x: f.slope.0,
                slope_y: f.slope.1,
            }
        })
    }
}

impl SurfaceStats {
    /// Warnings for implausible values (module docs), each naming the statistic; empty
    /// when all is plausible.
    pub fn plausibility(&self) -> Vec<String> {
        let mut w = Vec::new();
        let side = self.size.0.max(self.size.1);
        if self.rms_height > MAX_RMS_HEIGHT_FRACTION * side {
            w.push(format!(
                "RMS height {:.3e} m is {:.3} % of the sample size {:.3e} m (plausible: at most {} %): \
                 are the heights in µm or nm but read as metres? Set [surface] height_unit",
                self.rms_height,
                100.0 * self.rms_height / side,
                side,
                100.0 * MAX_RMS_HEIGHT_FRACTION
            ));
        }
        if self.rms_slope > MAX_RMS_SLOPE {
            w.push(format!(
                "RMS slope {:.3e} exceeds {MAX_RMS_SLOPE} (steeper than 45° on average) for pixels \
                 {:.3e} × {:.3e} m: heights in the wrong unit, or the wrong size/pixel_size?",
                self.rms_slope, self.pixel_size.0, self.pixel_size.1
            ));
        }
        if self.rms_height < MIN_RMS_HEIGHT {
            w.push(format!(
                "RMS height {:.3e} m is below the atomic scale ({MIN_RMS_HEIGHT:e} m): heights in \
                 metres declared as a smaller unit (height_unit)?",
                self.rms_height
            ));
        }
        w
    }

    /// One log line: grid, pixel sizes, sides, periodicity and the statistics.
    pub fn describe(&self) -> String {
        format!(
            "{}×{} points, pixel {:.4e} × {:.4e} m, sample {:.4e} × {:.4e} m, {}; RMS height \
             {:.4e} m, RMS slope {:.4e}, peak-to-valley {:.4e} m",
            self.shape.0,
            self.shape.1,
            self.pixel_size.0,
            self.pixel_size.1,
            self.size.0,
            self.size.1,
            if self.periodic {
                "periodic"
            } else {
                "non-periodic"
            },
            self.rms_height,
            self.rms_slope,
            self.peak_to_valley
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::Spacing;
    use super::*;

    /// z = A sin(2πx/Lx) + B cos(2π·2y/Ly) on a periodic grid: forward differences give
    /// the closed forms ⟨(Δ_x z/dx)²⟩ = (A·2 sin(πdx/Lx)/dx)²/2 and the same in y with
    /// wavenumber 2; RMS height √(A²/2 + B²/2); peak-to-valley from the samples.
    #[test]
    fn rms_slope_closed_form_periodic_and_not() {
        let (n0, n1, dx, dy) = (48usize, 30usize, 2e-6, 3.5e-6);
        let (lx, ly) = (n0 as f64 * dx, n1 as f64 * dy);
        let (a, b) = (1e-6, 0.4e-6);
        let tau = std::f64::consts::TAU;
        let z: Vec<f64> = (0..n0 * n1)
            .map(|k| {
                let (x, y) = ((k / n1) as f64 * dx, (k % n1) as f64 * dy);
                a * (tau * x / lx).sin() + b * (tau * 2.0 * y / ly).cos()
            })
            .collect();
        let s = Surface::with_spacing(z.clone(), n0, n1, Spacing::Pixel(dx, dy), true).unwrap();
        let gx = a * 2.0 * (std::f64::consts::PI * dx / lx).sin() / dx;
        let gy = b * 2.0 * (std::f64::consts::PI * 2.0 * dy / ly).sin() / dy;
        let expect = (gx * gx / 2.0 + gy * gy / 2.0).sqrt();
        let st = s.stats();
        assert!(
            (st.rms_slope - expect).abs() < 1e-12 * expect,
            "{st:?} {expect}"
        );
        let rms = (a * a / 2.0 + b * b / 2.0).sqrt();
        assert!((st.rms_height - rms).abs() < 1e-12 * rms);
        assert_eq!(st.size, (lx, ly));
        assert_eq!(st.pixel_size, (dx, dy));
        // Non-periodic: the mean over the (n0−1)·n1 and n0·(n1−1) existing differences.
        let np = Surface::with_spacing(z.clone(), n0, n1, Spacing::Pixel(dx, dy), false).unwrap();
        let (mut sx, mut sy) = (0.0, 0.0);
        for i in 0..n0 {
            for j in 0..n1 {
                if i + 1 < n0 {
                    sx += ((z[(i + 1) * n1 + j] - z[i * n1 + j]) / dx).powi(2);
                }
                if j + 1 < n1 {
                    sy += ((z[i * n1 + j + 1] - z[i * n1 + j]) / dy).powi(2);
                }
            }
        }
        let direct = (sx / ((n0 - 1) * n1) as f64 + sy / (n0 * (n1 - 1)) as f64).sqrt();
        assert!((np.rms_slope() - direct).abs() < 1e-14 * direct);
        let (lo, hi) = z
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &v| (l.min(v), h.max(v)));
        assert_eq!(np.peak_to_valley(), hi - lo);
        assert!(st.plausibility().is_empty(), "{:?}", st.plausibility());
    }

    /// Heights in µm read as metres: both the height and the slope warnings fire and
    /// name their statistic; nm declared for metres: the atomic-scale warning.
    #[test]
    fn plausibility_names_the_statistic() {
        let n = 16;
        let z: Vec<f64> = (0..n * n)
            .map(|k| 3.4 * (((k / n) as f64 * 0.9).sin() + ((k % n) as f64 * 0.7).cos()))
            .collect();
        let s = Surface::new(z.clone(), n, n, 1e-3, false).unwrap();
        let w = s.stats().plausibility();
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w[0].starts_with("RMS height"), "{w:?}");
        assert!(w[1].starts_with("RMS slope"), "{w:?}");
        let tiny: Vec<f64> = z.iter().map(|v| v * 1e-6 * 1e-9).collect();
        let s = Surface::new(tiny, n, n, 1e-3, false).unwrap();
        let w = s.stats().plausibility();
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("atomic"), "{w:?}");
        let ok: Vec<f64> = z.iter().map(|v| v * 1e-6).collect();
        let s = Surface::new(ok, n, n, 1e-3, false).unwrap();
        assert!(s.stats().plausibility().is_empty());
    }
}
