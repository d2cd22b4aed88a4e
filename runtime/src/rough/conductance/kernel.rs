//! The interaction resistance of two contact spots (conductance module docs, physics.md
//! §6.2): the surface temperature rise at one spot per unit heat into the other, through
//! both bodies' layered point-source fields, periodic (every spot repeated over the
//! cells, the uniform k = 0 mode excluded as in the BEM) or isolated.
//!
//! # Periodic: an Ewald split
//! A point source Q on body X raises its surface temperature by T̂ = C_X(|k|) Q with
//! C_X(ρ) = S_th,X(ρ)/(k₁,X ρ) (1/(k|k|) on a homogeneous conductor, 0 on a perfect one).
//! The periodic zero-mean field of a unit source at offset d, summed over both bodies, is
//!
//! ```text
//!   G(d) = (1/A₀) Σ_{k ≠ 0} C(|k|) e^{ik·d},   C = C_A + C_B   (K/W, or Ω).
//! ```
//!
//! With c = Σ_X 1/k₁,X and σ = min(Lx, Ly)/4, C splits into c·erf(ρσ/2)/ρ, whose real-space
//! form s(r) = c·erfc(r/σ)/(2πr) is short-ranged (Gaussian) and singular, and a smooth
//! rest R̂(ρ) = Σ_X [k_th,X(ρ) + erfc(ρσ/2)]/(k₁,X ρ) (k_th = S_th − 1), which decays
//! like e^{−2ρh₁} and a Gaussian. By Poisson's summation
//!
//! ```text
//!   G(d) = Σ_{n ∈ {−1,0,1}²} s(|d + nL|) − cσ/(√π A₀) + R(d),
//!   R(d) = (1/A₀) Σ_{k ≠ 0} R̂(|k|) e^{ik·d},
//! ```
//!
//! d reduced to the nearest image (|dx| ≤ Lx/2, |dy| ≤ Ly/2): the images left out are at
//! least 1.5 min(Lx, Ly) = 6σ away (erfc(6) = 2e−17). R is tabulated once by one inverse
//! FFT on a grid whose Nyquist wavenumber is `OVERSAMPLE` times the wavenumber ρ_max
//! beyond which |R̂|·k₁ < `SPECTRUM_TOL` (so the top layer must be resolved: on a 1 mm
//! cell a 20 µm coating takes 1024², the cap `MAX_GRID` per side holds layers down to
//! ~5 µm), and interpolated by 6-point Lagrange polynomials along each axis (measured
//! against direct sums in the tests).
//!
//! A spot's own images: the regular part of G at d → 0 with the isolated layered field
//! subtracted (its singular 1/(2πk₁r) and its layered part at r = 0,
//! w₀ = Σ_X ∫₀^∞ k_th,X(ρ) dρ /(2πk₁,X), both in the isolated spot conductance already):
//!
//! ```text
//!   G_self = Σ_{n ≠ 0} s(|nL|) − c/(π^{3/2}σ) − cσ/(√π A₀) + R(0) − w₀.
//! ```
//!
//! # Isolated
//! The point-source fields of unbounded bodies, summed:
//!
//! ```text
//!   G(r) = c/(2πr) + Σ_X [k₀,X/√(r² + h₁,X²) + J_X(r)] / (2πk₁,X),
//! ```
//!
//! the layered part the Hankel transform of k_th,X ([`crate::hankel::Remainder`]: the
//! closed form of k₀e^{−h₁ρ} with k₀ = S_th(0) − 1, and the smooth rest J tabulated
//! once); c/(2πr) alone on homogeneous conductors. Nothing on the diagonal: the layered
//! part at r = 0 is in the isolated spot conductance (ψ) already.

use strata_fft::RealFft2;

use super::{Body, ConductanceError};
use crate::hankel::{Remainder, tail_start};
use crate::resources::{MemoryLimit, bytes_for};

/// Ratio of the table grid's Nyquist wavenumber to the spectrum's extent ρ_max.
pub(crate) const OVERSAMPLE: f64 = 3.0;
/// The smooth rest's spectrum is cut where |k_th| + erfc(ρσ/2) falls below this.
pub(crate) const SPECTRUM_TOL: f64 = 1e-13;
/// Largest table grid per side.
pub(crate) const MAX_GRID: usize = 4096;
/// σ = min(Lx, Ly) / this.
const SIGMA_DIVISOR: f64 = 4.0;

/// erfc(x), libm's (FreeBSD msun's rational approximations, < 1 ulp): ~20 ns against
/// ~300 ns of the series and 80-term continued fraction it replaced, which made the
/// short-range sum (9 images per pair) most of the I model's network fill.
pub fn erfc(x: f64) -> f64 {
    libm::erfc(x)
}

/// The interaction resistance between spots (module docs).
pub struct Kernel {
    kind: Kind,
    /// c = Σ_X 1/k₁,X (m·K/W, or m·Ω).
    c: f64,
}

enum Kind {
    /// Per layered body: 1/(2πk₁) and its layered remainder.
    Isolated(Vec<(f64, Remainder)>),
    Periodic(Box<Periodic>),
}

/// The periodic kernel's parts.
struct Periodic {
    lx: f64,
    ly: f64,
    sigma: f64,
    /// −cσ/(√π A₀): the uniform mode of the short-range part.
    mean: f64,
    /// R on the nx × ny grid, row-major (row = y).
    table: Vec<f64>,
    nx: usize,
    ny: usize,
    /// G_self (K/W).
    self_images: f64,
    /// ρ_max of the smooth rest (1/m).
    rho_max: f64,
}

/// What the kernel is, for logs and curve.json.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KernelInfo {
    /// Table grid (nx, ny); (0, 0) isolated.
    pub grid: (usize, usize),
    /// Ewald width σ (m); 0 isolated.
    pub sigma: f64,
    /// Extent ρ_max of the smooth rest's spectrum (1/m); 0 isolated.
    pub rho_max: f64,
    /// A spot's own images G_self (K/W, or Ω); 0 isolated.
    pub self_images: f64,
}

/// c·(1/k₁,X) of each conducting body and their sum.
fn conductivity_sum(bodies: [Body<'_>; 2]) -> Result<f64, ConductanceError> {
    let mut c = 0.0;
    for b in bodies {
        match b {
            Body::Perfect => {}
            Body::HalfSpace(k) => {
                if !(k.is_finite() && k > 0.0) {
                    return Err(ConductanceError::Input {
                        field: "conductivity",
                        value: k,
                        reason: "must be finite and > 0".into(),
                    });
                }
                c += 1.0 / k;
            }
            Body::Layered(cc) => c += 1.0 / cc.top_conductivity(),
        }
    }
    if c == 0.0 {
        return Err(ConductanceError::BothPerfect);
    }
    Ok(c)
}

/// k_th,X(ρ)/k₁,X summed over the layered bodies (m·K/W).
fn layered_rest(bodies: [Body<'_>; 2], rho: f64) -> f64 {
    bodies
        .iter()
        .map(|b| match b {
            Body::Layered(c) => c.k_th(rho) / c.top_conductivity(),
            _ => 0.0,
        })
        .sum()
}

/// w₀ = Σ_X ∫₀^∞ k_th,X(ρ) dρ /(2πk₁,X) (K/W): 8-point Gauss–Legendre on panels in ln ρ
/// (ratio 1.25) from `lo` to `hi` plus ρ_lo·k_th(0) below.
fn layered_at_zero(bodies: [Body<'_>; 2], lo: f64, hi: f64) -> f64 {
    // the positive half of the 8-point rule (mirrored below)
    let gl8 = &crate::numerics::gauss_legendre_cached(8)[4..];
    let f = |rho: f64| layered_rest(bodies, rho);
    let mut sum = lo * f(0.0);
    let (mut a, step) = (lo.ln(), 1.25f64.ln());
    while a < hi.ln() {
        let (c, h) = (a + 0.5 * step, 0.5 * step);
        for &(x, w) in gl8 {
            for u in [c - h * x, c + h * x] {
                let rho = u.exp();
                sum += w * h * f(rho) * rho;
            }
        }
        a += step;
    }
    sum / (2.0 * std::f64::consts::PI)
}

impl Kernel {
    /// The isolated kernel (module docs) of a sample of sides `extent` (m): c/(2πr) plus
    /// each layered body's layered part, tabulated over the sample's diagonal (or to
    /// where it is its 1/r³ tail).
    pub fn isolated(
        a: Body<'_>,
        b: Body<'_>,
        extent: (f64, f64),
    ) -> Result<Kernel, ConductanceError> {
        let diag = extent.0.hypot(extent.1);
        if !(diag.is_finite() && diag > 0.0) {
            return Err(ConductanceError::Input {
                field: "extent",
                value: diag,
                reason: "the sample's sides must be finite and > 0 (m)".into(),
            });
        }
        let c = conductivity_sum([a, b])?;
        let mut layered = Vec::new();
        for x in [a, b] {
            let Body::Layered(cc) = x else { continue };
            let Some(h1) = cc.top_thickness().filter(|_| !cc.is_homogeneous()) else {
                continue;
            };
            let depth = cc.total_thickness();
            let r_tab = diag.min(tail_start(depth, cc.contrast()));
            let rem = Remainder::new(cc.s_at_zero() - 1.0, h1, depth, r_tab, |rho| cc.k_th(rho))
                .map_err(|e| ConductanceError::Layered(e.to_string()))?;
            layered.push((
                1.0 / (2.0 * std::f64::consts::PI * cc.top_conductivity()),
                rem,
            ));
        }
        Ok(Kernel {
            kind: Kind::Isolated(layered),
            c,
        })
    }

    /// Checks, before any work, that the periodic kernel of a cell of sides `extent` (m)
    /// can be built: its table within `MAX_GRID` per side and the memory it takes
    /// within `memory` (the scan of the spectrum only, no table). Returns the table grid
    /// (nx, ny).
    pub fn check_periodic(
        a: Body<'_>,
        b: Body<'_>,
        extent: (f64, f64),
        memory: &MemoryLimit,
    ) -> Result<(usize, usize), ConductanceError> {
        let g = PeriodicGrid::new([a, b], extent, memory)?;
        Ok((g.nx, g.ny))
    }

    /// The periodic kernel on a cell of sides `extent` (m), its table checked against
    /// `memory` first.
    pub fn periodic(
        a: Body<'_>,
        b: Body<'_>,
        extent: (f64, f64),
        memory: &MemoryLimit,
    ) -> Result<Kernel, ConductanceError> {
        let bodies = [a, b];
        let PeriodicGrid {
            c,
            lx,
            ly,
            sigma,
            rho_max,
            nx,
            ny,
        } = PeriodicGrid::new(bodies, extent, memory)?;
        let area = lx * ly;
        let fft = RealFft2::new(ny, nx).map_err(|e| ConductanceError::Fft(e.to_string()))?;
        let mut work = fft.work();
        let half = nx / 2 + 1;
        let (dkx, dky) = (std::f64::consts::TAU / lx, std::f64::consts::TAU / ly);
        for kx in 0..half {
            for ky in 0..ny {
                let sy = strata_fft::signed_index(ky, ny) as f64;
                let r = (kx as f64 * dkx).hypot(sy * dky);
                let v = if r == 0.0 {
                    0.0
                } else {
                    (layered_rest(bodies, r) + c * erfc(0.5 * r * sigma)) / (r * area)
                };
                work.spec[kx * ny + ky] = strata_fft::Complex::new(v, 0.0);
            }
        }
        let mut table = vec![0.0; nx * ny];
        fft.inverse(&mut table, &mut work)
            .map_err(|e| ConductanceError::Fft(e.to_string()))?;
        let mean = -c * sigma / (std::f64::consts::PI.sqrt() * area);
        let mut p = Periodic {
            lx,
            ly,
            sigma,
            mean,
            table,
            nx,
            ny,
            self_images: 0.0,
            rho_max,
        };
        let pi = std::f64::consts::PI;
        let mut images = 0.0;
        for sx in -1i32..=1 {
            for sy in -1i32..=1 {
                if (sx, sy) != (0, 0) {
                    images += short(c, sigma, (sx as f64 * lx).hypot(sy as f64 * ly));
                }
            }
        }
        let w0 = layered_at_zero(bodies, 1e-6 / lx.max(ly), 1e3 * rho_max);
        p.self_images = images - c / (pi.powf(1.5) * sigma) + mean + p.rest(0.0, 0.0) - w0;
        Ok(Kernel {
            kind: Kind::Periodic(Box::new(p)),
            c,
        })
    }

    /// The interaction resistance (K/W, or Ω) of two distinct spots at offset (dx, dy) (m):
    /// the temperature rise at one per unit heat into the other. d = 0 is singular (∞).
    pub fn between(&self, dx: f64, dy: f64) -> f64 {
        match &self.kind {
            Kind::Isolated(layered) => {
                let r = dx.hypot(dy);
                self.c / (2.0 * std::f64::consts::PI * r)
                    + layered
                        .iter()
                        .map(|(w, rem)| w * rem.layered(r))
                        .sum::<f64>()
            }
            Kind::Periodic(p) => {
                let dx = dx - p.lx * (dx / p.lx).round();
                let dy = dy - p.ly * (dy / p.ly).round();
                let mut s = 0.0;
                for sx in -1i32..=1 {
                    for sy in -1i32..=1 {
                        s += short(
                            self.c,
                            p.sigma,
                            (dx + sx as f64 * p.lx).hypot(dy + sy as f64 * p.ly),
                        );
                    }
                }
                s + p.mean + p.rest(dx, dy)
            }
        }
    }

    /// A spot's interaction with its own periodic images (K/W, or Ω; module docs): 0
    /// isolated.
    pub fn self_images(&self) -> f64 {
        match &self.kind {
            Kind::Isolated(_) => 0.0,
            Kind::Periodic(p) => p.self_images,
        }
    }

    /// The kernel's parameters.
    pub fn info(&self) -> KernelInfo {
        match &self.kind {
            Kind::Isolated(_) => KernelInfo {
                grid: (0, 0),
                sigma: 0.0,
                rho_max: 0.0,
                self_images: 0.0,
            },
            Kind::Periodic(p) => KernelInfo {
                grid: (p.nx, p.ny),
                sigma: p.sigma,
                rho_max: p.rho_max,
                self_images: p.self_images,
            },
        }
    }

    /// The periodic zero-mean field G(d) by its Fourier series summed directly over
    /// |k| ≤ `rho_cut` (1/m): the tests' reference.
    #[cfg(test)]
    pub(crate) fn direct_sum(
        bodies: [Body<'_>; 2],
        extent: (f64, f64),
        d: (f64, f64),
        rho_cut: f64,
    ) -> f64 {
        let (lx, ly) = extent;
        let (dkx, dky) = (std::f64::consts::TAU / lx, std::f64::consts::TAU / ly);
        let (mx, my) = ((rho_cut / dkx) as i64, (rho_cut / dky) as i64);
        let mut s = 0.0;
        for i in -mx..=mx {
            for j in -my..=my {
                let (kx, ky) = (i as f64 * dkx, j as f64 * dky);
                let r = kx.hypot(ky);
                if r == 0.0 || r > rho_cut {
                    continue;
                }
                let cr: f64 = bodies
                    .iter()
                    .map(|b| match b {
                        Body::Perfect => 0.0,
                        Body::HalfSpace(k) => 1.0 / (k * r),
                        Body::Layered(c) => c.s(r) / (c.top_conductivity() * r),
                    })
                    .sum();
                s += cr * (kx * d.0 + ky * d.1).cos();
            }
        }
        s / (lx * ly)
    }
}

/// The periodic kernel's set-up: c, the cell, σ, ρ_max and the table grid, checked
/// against `MAX_GRID` and a memory limit.
struct PeriodicGrid {
    c: f64,
    lx: f64,
    ly: f64,
    sigma: f64,
    rho_max: f64,
    nx: usize,
    ny: usize,
}

impl PeriodicGrid {
    fn new(
        bodies: [Body<'_>; 2],
        extent: (f64, f64),
        memory: &MemoryLimit,
    ) -> Result<Self, ConductanceError> {
        let c = conductivity_sum(bodies)?;
        let (lx, ly) = extent;
        for v in [lx, ly] {
            if !(v.is_finite() && v > 0.0) {
                return Err(ConductanceError::Input {
                    field: "extent",
                    value: v,
                    reason: "the cell's sides must be finite and > 0 (m)".into(),
                });
            }
        }
        let lmin = lx.min(ly);
        let sigma = lmin / SIGMA_DIVISOR;
        // ρ_max: the largest scanned ρ (ratio 1.1 up to 1e9/L) where the rest's spectrum
        // is above the tolerance (k₁-scaled).
        let kmax = bodies.iter().fold(0.0f64, |m, b| match b {
            Body::Layered(cc) => m.max(cc.top_conductivity()),
            Body::HalfSpace(k) => m.max(*k),
            Body::Perfect => m,
        });
        let mut rho_max = 1.0 / lmin;
        let mut rho = 1.0 / lmin;
        while rho < 1e9 / lmin {
            let v = (layered_rest(bodies, rho) * kmax).abs() + erfc(0.5 * rho * sigma);
            if v >= SPECTRUM_TOL {
                rho_max = rho * 1.1;
            }
            rho *= 1.1;
        }
        let side = |l: f64| -> usize {
            let n = (OVERSAMPLE * rho_max * l / std::f64::consts::PI).ceil() as usize;
            n.next_power_of_two().max(32)
        };
        let (nx, ny) = (side(lx), side(ly));
        if nx > MAX_GRID || ny > MAX_GRID {
            return Err(ConductanceError::Grid {
                nx,
                ny,
                cap: MAX_GRID,
                rho_max,
            });
        }
        memory.check(
            format!("I-model conduction kernel: a {nx}×{ny} table and its spectrum"),
            bytes_for((nx * ny) as u64, 8 * 4),
        )?;
        Ok(PeriodicGrid {
            c,
            lx,
            ly,
            sigma,
            rho_max,
            nx,
            ny,
        })
    }
}

/// The short-range part s(r) = c·erfc(r/σ)/(2πr) (K/W).
fn short(c: f64, sigma: f64, r: f64) -> f64 {
    c * erfc(r / sigma) / (2.0 * std::f64::consts::PI * r)
}

impl Periodic {
    /// R(d) by `POINTS`-point Lagrange interpolation along each axis of the periodic
    /// table, |dx| ≤ Lx/2, |dy| ≤ Ly/2.
    fn rest(&self, dx: f64, dy: f64) -> f64 {
        let (ux, uy) = (dx / self.lx * self.nx as f64, dy / self.ly * self.ny as f64);
        let (ix, wx) = stencil(ux);
        let (iy, wy) = stencil(uy);
        let mut s = 0.0;
        for (a, &wyv) in wy.iter().enumerate() {
            let row = (iy + a as i64).rem_euclid(self.ny as i64) as usize * self.nx;
            let mut r = 0.0;
            for (b, &wxv) in wx.iter().enumerate() {
                r += wxv * self.table[row + (ix + b as i64).rem_euclid(self.nx as i64) as usize];
            }
            s += wyv * r;
        }
        s
    }
}

/// Nodes of the interpolating polynomial along each axis (degree 5).
pub(crate) const POINTS: usize = 6;

/// The first node and the weights of the polynomial through the `POINTS` nodes
/// around u (table units).
fn stencil(u: f64) -> (i64, [f64; POINTS]) {
    let first = u.floor() as i64 - (POINTS as i64 / 2 - 1);
    let mut w = [1.0; POINTS];
    for (j, wj) in w.iter_mut().enumerate() {
        let xj = (first + j as i64) as f64;
        for m in 0..POINTS {
            if m != j {
                let xm = (first + m as i64) as f64;
                *wj *= (u - xm) / (xj - xm);
            }
        }
    }
    (first, w)
}
