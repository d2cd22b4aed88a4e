//! Spectral synthesis of self-affine random surfaces (feature `spectral`).

use rand::{RngExt, SeedableRng};

use super::{Surface, SurfaceError, invalid};
use crate::fft::{Complex, RealFft2};

/// Parameters of a generated self-affine surface (physics.md §5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GenerateParams {
    /// Side length L (m) of the square sample.
    pub size: f64,
    /// Grid points per side n (≥ 4).
    pub grid: usize,
    /// Fractal dimension D_f in [2, 3); Hurst exponent H = 3 − D_f.
    pub fractal_dimension: f64,
    /// Lowest wavenumber, in units of 2π/L (> 0).
    pub k_min: f64,
    /// Highest wavenumber, in units of 2π/L (≥ k_min, ≤ n/2).
    pub k_max: f64,
    /// RMS height (m, > 0).
    pub rms: f64,
    /// Seed of the ChaCha8 generator.
    pub seed: u64,
}

impl GenerateParams {
    /// The paper's surface family (physics.md §5; scenes/paper-E2E1-5-interacting.toml):
    /// L = 1 mm, D_f = 2.4, k_m = 2, RMS 3.4 µm, seed 20240611, on an n = `grid` grid up
    /// to k_M = `k_max` (the benches, the study and the scale tests grow both).
    pub fn paper(grid: usize, k_max: f64) -> GenerateParams {
        GenerateParams {
            size: 1e-3,
            grid,
            fractal_dimension: 2.4,
            k_min: 2.0,
            k_max,
            rms: 3.4e-6,
            seed: 20240611,
        }
    }
}

/// Bytes per grid point that generating a surface holds at its peak: the complex
/// spectrum and its transform (16 + 16), the heights (8).
pub const GENERATE_BYTES_PER_POINT: u64 = 40;

impl Surface {
    /// Generates a self-affine surface (physics.md §5). Amplitudes |ẑ(k)| ∝ |k|^(−(1+H))
    /// for k_min ≤ |k|L/(2π) ≤ k_max (k integer multiples of 2π/L), uniform random
    /// phases; the real part of the inverse FFT is rescaled to zero mean and the RMS.
    /// Under the machine's memory limit ([`crate::resources::MemoryLimit::of_machine`]);
    /// [`Surface::generate_within`] takes one.
    pub fn generate(p: &GenerateParams) -> Result<Self, SurfaceError> {
        Self::generate_within(p, &crate::resources::MemoryLimit::default())
    }

    /// [`Surface::generate`], what it allocates checked against `memory` first
    /// ([`GENERATE_BYTES_PER_POINT`] per grid point).
    pub fn generate_within(
        p: &GenerateParams,
        memory: &crate::resources::MemoryLimit,
    ) -> Result<Self, SurfaceError> {
        p.check_size()?;
        // before allocating: every entry point (CLI, Python, the C ABI) is bounded
        let n = p.grid as u64;
        memory.check(
            format!("generating the {0}×{0} surface (generate.grid)", p.grid),
            crate::resources::bytes_for(n.saturating_mul(n), GENERATE_BYTES_PER_POINT),
        )?;
        p.check()?;
        let n = p.grid;
        let fft_failed = || invalid("generate.grid", n as f64, "internal error of the 2-D FFT");
        let plan = RealFft2::new(n, n).map_err(|_| fft_failed())?;
        // The whole half spectrum, handed to the transform as its buffer (no copy).
        let mut work = plan.convolution_work();
        work.spec = p.half_spectrum_lines(0..plan.half())?;
        let mut z = vec![0.0; n * n];
        plan.inverse(&mut z, &mut work).map_err(|_| fft_failed())?;
        drop(work);
        let mean = z.iter().sum::<f64>() / z.len() as f64;
        z.iter_mut().for_each(|v| *v -= mean);
        let sq = z.iter().map(|v| v * v).sum::<f64>();
        let s = p.scale(sq, z.len())?;
        z.iter_mut().for_each(|v| *v *= s);
        Surface::new(z, n, n, p.size, true)
    }
}

impl GenerateParams {
    /// Checks `size` and `grid` (the fields that size the allocations).
    pub fn check_size(&self) -> Result<(), SurfaceError> {
        if !(self.size.is_finite() && self.size > 0.0) {
            return Err(invalid("generate.size", self.size, "must be > 0 (m)"));
        }
        if self.grid < 4 || self.grid > 16384 {
            return Err(invalid(
                "generate.grid",
                self.grid as f64,
                "must be in [4, 16384]",
            ));
        }
        Ok(())
    }

    /// Checks every field (the error names it).
    pub fn check(&self) -> Result<(), SurfaceError> {
        self.check_size()?;
        if !(2.0..3.0).contains(&self.fractal_dimension) {
            return Err(invalid(
                "generate.fractal_dimension",
                self.fractal_dimension,
                "must be in [2, 3)",
            ));
        }
        if !(self.k_min.is_finite() && self.k_min > 0.0) {
            return Err(invalid(
                "generate.k_min",
                self.k_min,
                "must be > 0 (units of 2π/L)",
            ));
        }
        if !(self.k_max.is_finite()
            && self.k_max >= self.k_min
            && self.k_max <= self.grid as f64 / 2.0)
        {
            return Err(invalid(
                "generate.k_max",
                self.k_max,
                "must satisfy k_min ≤ k_max ≤ grid/2",
            ));
        }
        if !(self.rms.is_finite() && self.rms > 0.0) {
            return Err(invalid("generate.rms", self.rms, "must be > 0 (m)"));
        }
        Ok(())
    }

    /// The kx lines `cols` (kx ∈ 0..=n/2) of the half spectrum whose real inverse 2-D
    /// transform ([`RealFft2::inverse`], unnormalised) is the surface before its mean is
    /// removed and its RMS set: `lines[(kx − cols.start)·n + ky]` (the layout of
    /// [`RealFft2`]'s transposed spectrum, cut to those lines).
    ///
    /// The spectrum is spec(i, j) = |k|^(−(1+H)) e^{iφ_{ij}} for k_min ≤ |k| ≤ k_max, |k|
    /// = hypot(i, j) of the signed indices, else 0, with the phases φ = 2π·u drawn from
    /// ChaCha8 (seed `seed`) one per mode in row-major order (i the first axis, j the
    /// second), whatever the band; z = Re Σ spec(k) e^{ik·x} is the real inverse
    /// transform of its Hermitian part (spec(i, j) + conj spec(−i, −j))/2 at (kx = j,
    /// ky = i). Every line is computed from the same draws with the same operations
    /// whatever `cols`, so the lines of a cut equal those of the whole spectrum bit for
    /// bit: a process that owns some kx columns draws the whole stream (O(n²) time) and
    /// keeps only what its lines need (32·n·|cols| bytes at the peak, the lines and
    /// their mirror images −kx).
    pub fn half_spectrum_lines(
        &self,
        cols: std::ops::Range<usize>,
    ) -> Result<Vec<Complex<f64>>, SurfaceError> {
        let n = self.grid;
        let half = n / 2 + 1;
        let cols = cols.start.min(half)..cols.end.min(half);
        let (c0, nc) = (cols.start, cols.len());
        let hurst = 3.0 - self.fractal_dimension;
        let signed = |i: usize| -> f64 {
            if i <= n / 2 {
                i as f64
            } else {
                i as f64 - n as f64
            }
        };
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(self.seed);
        // own[(kx − c0)·n + i] = spec(i, kx); mirror[(kx − c0)·n + i] = spec(i, −kx).
        let mut own = vec![Complex::new(0.0, 0.0); nc * n];
        let mut mirror = vec![Complex::new(0.0, 0.0); nc * n];
        let mut any = false;
        for i in 0..n {
            for j in 0..n {
                // Draw the phase for every mode so the stream does not depend on k range.
                let phase: f64 = rng.random::<f64>() * std::f64::consts::TAU;
                let minus_j = (n - j) % n;
                let (mine, mirrored) = (cols.contains(&j), cols.contains(&minus_j));
                if !(mine || mirrored || !any) {
                    continue;
                }
                let k = signed(i).hypot(signed(j));
                if k >= self.k_min && k <= self.k_max {
                    any = true;
                    if mine || mirrored {
                        let v = Complex::from_polar(k.powf(-(1.0 + hurst)), phase);
                        if mine {
                            own[(j - c0) * n + i] = v;
                        }
                        if mirrored {
                            mirror[(minus_j - c0) * n + i] = v;
                        }
                    }
                }
            }
        }
        if !any {
            return Err(invalid(
                "generate.k_max",
                self.k_max,
                "no wavevector lies in [k_min, k_max]",
            ));
        }
        // H(kx, ky) = (spec(ky, kx) + conj spec(−ky, −kx))/2, in place of `own`.
        for (line, back) in own.chunks_mut(n).zip(mirror.chunks(n)) {
            for (ky, h) in line.iter_mut().enumerate() {
                let b = back[(n - ky) % n].conj();
                *h = (*h + b) * 0.5;
            }
        }
        Ok(own)
    }

    /// The factor that gives the zero-mean heights whose squares sum to `squares` over
    /// `points` points the RMS `rms`; an error if they are flat.
    pub fn scale(&self, squares: f64, points: usize) -> Result<f64, SurfaceError> {
        let rms = (squares / points as f64).sqrt();
        if rms.is_nan() || rms <= 0.0 {
            return Err(invalid(
                "generate.rms",
                self.rms,
                "generated surface is flat",
            ));
        }
        Ok(self.rms / rms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The real inverse transform of the Hermitian part gives the same surface as the
    /// definition z = Re Σ_k spec(k) e^{ik·x} (the complex inverse FFT the generator used
    /// before), to round-off: shipped scenes and seeds keep their surfaces.
    #[test]
    fn same_surface_as_the_complex_synthesis() {
        for n in [16usize, 15] {
            let p = GenerateParams {
                size: 1e-3,
                grid: n,
                fractal_dimension: 2.4,
                k_min: 1.0,
                k_max: 6.0,
                rms: 3.4e-6,
                seed: 20240611,
            };
            let s = Surface::generate(&p).unwrap();
            // The same random stream, by definition.
            let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(p.seed);
            let signed = |i: usize| -> f64 {
                if i <= n / 2 {
                    i as f64
                } else {
                    i as f64 - n as f64
                }
            };
            let mut spec = vec![Complex::new(0.0, 0.0); n * n];
            for i in 0..n {
                for j in 0..n {
                    let phase: f64 = rng.random::<f64>() * std::f64::consts::TAU;
                    let k = signed(i).hypot(signed(j));
                    if k >= p.k_min && k <= p.k_max {
                        spec[i * n + j] = Complex::from_polar(k.powf(-1.6), phase);
                    }
                }
            }
            let mut z = vec![0.0; n * n];
            for a in 0..n {
                for b in 0..n {
                    let mut acc = 0.0;
                    for i in 0..n {
                        for j in 0..n {
                            let ph = std::f64::consts::TAU * ((i * a) as f64 + (j * b) as f64)
                                / n as f64;
                            acc += (spec[i * n + j] * Complex::from_polar(1.0, ph)).re;
                        }
                    }
                    z[a * n + b] = acc;
                }
            }
            let mean = z.iter().sum::<f64>() / z.len() as f64;
            z.iter_mut().for_each(|v| *v -= mean);
            let rms = (z.iter().map(|v| v * v).sum::<f64>() / z.len() as f64).sqrt();
            for (a, b) in s.heights().iter().zip(&z) {
                assert!(
                    (a - b * p.rms / rms).abs() < 1e-12 * p.rms,
                    "n {n}: {a} vs {b}"
                );
            }
        }
    }
}
