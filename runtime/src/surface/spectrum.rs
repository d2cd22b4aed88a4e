//! What a surface looks like before contact, as contact.engineering users read it: the
//! radially averaged power spectral density and the height and slope distributions.
//!
//! PSD convention (Jacobs, Junge & Pastewka, Surf. Topogr. 5, 2017): with
//! h̃(q) = Σ h(x) e^{−iq·x} dx dy over the sample of area A,
//!
//! ```text
//!   C(q) = |h̃(q)|² / A      (m⁴),      Σ_q C(q) Δq_x Δq_y / (2π)² = ⟨h²⟩ − h̄²,
//! ```
//!
//! q = (2π i/Lx, 2π j/Ly). A non-periodic sample is multiplied by a Hann window
//! (normalised to keep ⟨h²⟩) so its edges do not leak into the high wavenumbers; the
//! mean is removed first. C(q) is averaged over annuli of width Δq = 2π/max(Lx, Ly).

use super::Surface;

/// One bin of the radially averaged PSD.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PsdBin {
    /// Mean |q| of the bin (1/m).
    pub q: f64,
    /// Mean C(q) (m⁴).
    pub c: f64,
    /// Wavevectors averaged.
    pub count: usize,
}

/// A histogram normalised to a probability density.
#[derive(Debug, Clone, PartialEq)]
pub struct Density {
    /// Bin centres.
    pub x: Vec<f64>,
    /// Density (1/unit of x).
    pub p: Vec<f64>,
}

fn density(values: &[f64], bins: usize) -> Density {
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(*v), h.max(*v))
        });
    let bins = bins.max(1);
    let w = if hi > lo {
        (hi - lo) / bins as f64
    } else {
        1.0
    };
    let mut count = vec![0usize; bins];
    for v in values {
        let k = (((v - lo) / w) as usize).min(bins - 1);
        count[k] += 1;
    }
    let n = values.len().max(1) as f64;
    Density {
        x: (0..bins).map(|k| lo + (k as f64 + 0.5) * w).collect(),
        p: count.iter().map(|c| *c as f64 / (n * w)).collect(),
    }
}

impl Surface {
    /// The radially averaged PSD C(|q|) (module docs), bins of width 2π/max(Lx, Ly)
    /// from the first non-zero wavenumber; empty bins are left out.
    pub fn radial_psd(&self) -> Result<Vec<PsdBin>, super::SurfaceError> {
        use crate::fft::RealFft2;
        let (n0, n1) = self.shape();
        let (dx, dy) = self.pixel_size();
        let (lx, ly) = (n0 as f64 * dx, n1 as f64 * dy);
        let mean = self.mean();
        // rows of the FFT along the first axis (n0, the x axis), columns n1
        let mut h: Vec<f64> = self.heights().iter().map(|z| z - mean).collect();
        if !self.is_periodic() {
            let hann = |k: usize, n: usize| {
                (std::f64::consts::PI * (k as f64 + 0.5) / n as f64)
                    .sin()
                    .powi(2)
            };
            // mean of w² over the grid: 3/8 per axis
            let norm = 1.0 / (0.375f64 * 0.375).sqrt();
            for i in 0..n0 {
                for j in 0..n1 {
                    h[i * n1 + j] *= norm * hann(i, n0) * hann(j, n1);
                }
            }
        }
        let plan = RealFft2::new(n0, n1)
            .map_err(|e| super::SurfaceError::Unsupported(format!("PSD: {e}")))?;
        let mut work = plan.work();
        plan.forward(&h, &mut work)
            .map_err(|e| super::SurfaceError::Unsupported(format!("PSD: {e}")))?;
        let area = lx * ly;
        let dq = std::f64::consts::TAU / lx.max(ly);
        let half = n1 / 2 + 1;
        let mut sums: Vec<(f64, f64, usize)> = Vec::new();
        for kx in 0..half {
            // the half spectrum along the second axis: entries 1 … n1/2 − 1 stand for two
            let weight = if kx == 0 || (n1 % 2 == 0 && kx == n1 / 2) {
                1
            } else {
                2
            };
            for ky in 0..n0 {
                if kx == 0 && ky == 0 {
                    continue;
                }
                let sy = if ky <= n0 / 2 {
                    ky as f64
                } else {
                    ky as f64 - n0 as f64
                };
                let q =
                    (std::f64::consts::TAU * kx as f64 / ly).hypot(std::f64::consts::TAU * sy / lx);
                let z = work.spec[kx * n0 + ky];
                let c = (z.re * z.re + z.im * z.im) * (dx * dy) * (dx * dy) / area;
                let b = ((q / dq).round() as usize).max(1) - 1;
                if sums.len() <= b {
                    sums.resize(b + 1, (0.0, 0.0, 0));
                }
                sums[b].0 += q * weight as f64;
                sums[b].1 += c * weight as f64;
                sums[b].2 += weight;
            }
        }
        Ok(sums
            .into_iter()
            .filter(|s| s.2 > 0)
            .map(|(q, c, n)| PsdBin {
                q: q / n as f64,
                c: c / n as f64,
                count: n,
            })
            .collect())
    }

    /// Probability densities of the heights (about the mean, m) and of the slopes
    /// ∂h/∂x and ∂h/∂y together (central differences; one-sided at a non-periodic
    /// sample's edges), `bins` bins each.
    pub fn distributions(&self, bins: usize) -> (Density, Density) {
        let (n0, n1) = self.shape();
        let (dx, dy) = self.pixel_size();
        let mean = self.mean();
        let heights: Vec<f64> = self.heights().iter().map(|z| z - mean).collect();
        let z = |i: usize, j: usize| self.z(i, j);
        let per = self.is_periodic();
        let mut slopes = Vec::with_capacity(2 * n0 * n1);
        for i in 0..n0 {
            for j in 0..n1 {
                let (ip, im) = if per {
                    ((i + 1) % n0, (i + n0 - 1) % n0)
                } else {
                    ((i + 1).min(n0 - 1), i.saturating_sub(1))
                };
                let (jp, jm) = if per {
                    ((j + 1) % n1, (j + n1 - 1) % n1)
                } else {
                    ((j + 1).min(n1 - 1), j.saturating_sub(1))
                };
                let sx = if per { 2.0 } else { (ip - im) as f64 };
                let sy = if per { 2.0 } else { (jp - jm) as f64 };
                slopes.push((z(ip, j) - z(im, j)) / (sx * dx));
                slopes.push((z(i, jp) - z(i, jm)) / (sy * dy));
            }
        }
        (density(&heights, bins), density(&slopes, bins))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::GenerateParams;

    /// Parseval: the binned PSD integrates to the height variance of a periodic
    /// surface (each bin's mean times its wavevector count).
    #[test]
    fn psd_integrates_to_the_variance() {
        let s = Surface::generate(&GenerateParams {
            size: 1e-3,
            grid: 64,
            fractal_dimension: 2.4,
            k_min: 2.0,
            k_max: 16.0,
            rms: 2e-6,
            seed: 3,
        })
        .unwrap();
        let psd = s.radial_psd().unwrap();
        let dq = std::f64::consts::TAU / 1e-3;
        let var: f64 = psd.iter().map(|b| b.c * b.count as f64).sum::<f64>() * dq * dq
            / (std::f64::consts::TAU * std::f64::consts::TAU);
        assert!(
            (var.sqrt() / s.rms() - 1.0).abs() < 1e-12,
            "{} vs {}",
            var.sqrt(),
            s.rms()
        );
        // the band k = 2 … 16 (units of 2π/L): nothing outside it
        for b in &psd {
            if b.q > 17.0 * dq {
                assert!(b.c < 1e-20 * psd[2].c, "q = {}: {}", b.q, b.c);
            }
        }
    }

    /// Densities integrate to 1; a plane of slope 0.01 along x puts half the slopes at
    /// 0.01 and half at 0.
    #[test]
    fn densities() {
        let (n0, n1) = (20, 30);
        let z: Vec<f64> = (0..n0 * n1)
            .map(|k| 0.01 * (k / n1) as f64 * 1e-6)
            .collect();
        let s = Surface::with_spacing(z, n0, n1, super::super::Spacing::Pixel(1e-6, 1e-6), false)
            .unwrap();
        let (h, sl) = s.distributions(10);
        let w = |d: &Density| d.x[1] - d.x[0];
        let total: f64 = h.p.iter().sum::<f64>() * w(&h);
        assert!((total - 1.0).abs() < 1e-12);
        let near = |x: f64| {
            sl.x.iter()
                .zip(&sl.p)
                .filter(|(c, _)| (*c - x).abs() < 0.6 * w(&sl))
                .map(|(_, p)| p * w(&sl))
                .sum::<f64>()
        };
        assert!((near(0.01) - 0.5).abs() < 1e-12 && (near(0.0) - 0.5).abs() < 1e-12);
    }
}
