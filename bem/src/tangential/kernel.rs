//! The 3 × 3 surface influence operator of a layered solid on a periodic grid: the
//! displacement (u_x, u_y, w) of the surface under the traction (q_x, q_y, p).
//!
//! For a traction that varies as e^{ik·x}, k = ρ(cos θ, sin θ), the compliances of
//! [`strata_runtime::compliance::tangential`] give, in the frame (L along k, T across
//! it), u_L = (2/(E*ρ))(S_LL q_L + i S_zL p), w = (2/(E*ρ))(−i S_zL q_L + S_zz p),
//! u_T = S_TT q_T/(μρ). Rotated to (x, y) with q_L = q_x cos θ + q_y sin θ and
//! q_T = −q_x sin θ + q_y cos θ:
//!
//! ```text
//!   ũ_x = A_xx q̃_x + A_xy q̃_y + i C_x p̃,      A_xx = a cos²θ + b sin²θ,
//!   ũ_y = A_xy q̃_x + A_yy q̃_y + i C_y p̃,      A_yy = a sin²θ + b cos²θ,
//!   w̃   = −i C_x q̃_x − i C_y q̃_y + A_zz p̃,    A_xy = (a − b) cos θ sin θ,
//! ```
//!
//! with a = 2S_LL/(E*ρ), b = S_TT/(μρ), A_zz = 2S_zz/(E*ρ), C_x = 2S_zL cos θ/(E*ρ),
//! C_y = 2S_zL sin θ/(E*ρ) (m/Pa). The operator is Hermitian, so real tractions give real
//! displacements; the odd entries (A_xy, C_x, C_y) are set to zero on the Nyquist lines
//! kx = nx/2 and ky = ny/2, where k and −k are the same grid point and an odd term has no
//! real counterpart. On a half-space (S = 1, S_zL = β = (1−2ν)/(2(1−ν))) this is the
//! Fourier transform of the Boussinesq–Cerruti point-force solution (Johnson, Contact
//! Mechanics, eqs. 3.19 and 3.22):
//! A_xx = (1 − ν cos²θ)/(Gρ), A_xy = −ν cos θ sin θ/(Gρ), C_x = (1−2ν) cos θ/(2Gρ).
//!
//! The k = 0 entry is the uniform-mode compliance: 0 on an elastic base (the zero-mean
//! convention of the normal solver, [`crate`] docs), Σhᵢ/Mᵢ normally and Σhᵢ/Gᵢ
//! tangentially on a rigid base (no coupling). [`Coupling::Uncoupled`] drops S_zL (the
//! "β = 0" approximation of Cattaneo–Mindlin and Ciavarella–Jäger).

use std::collections::HashMap;

use strata_runtime::compliance::tangential::{Compliances, TangentialCompliance};
use strata_runtime::fft::{Complex, Fft2Work, RealFft2, signed_index};
use strata_runtime::stack::{Base, Solid, Stack, shear_modulus};

use super::TangentialError;
use crate::uniform_compliance;

/// Whether the normal–tangential coupling S_zL is kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coupling {
    /// S_zL = 0: the normal and tangential problems are independent.
    Uncoupled,
    /// S_zL as the stack gives it.
    Coupled,
}

/// Entries of the operator at one wavevector (m/Pa, without the FFT normalisation).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct KernelEntry {
    /// u_x per q_x.
    pub xx: f64,
    /// u_x per q_y = u_y per q_x.
    pub xy: f64,
    /// u_y per q_y.
    pub yy: f64,
    /// w per p.
    pub zz: f64,
    /// u_x per p is i·`cx`, w per q_x is −i·`cx`.
    pub cx: f64,
    /// u_y per p is i·`cy`, w per q_y is −i·`cy`.
    pub cy: f64,
}

/// The 3 × 3 operator on a periodic ny × nx grid of sides ly × lx (row index = y).
pub struct TractionKernel {
    fft: RealFft2,
    ny: usize,
    nx: usize,
    /// Half-spectrum entries, index kx·ny + ky.
    entries: Vec<KernelEntry>,
    coupling: Coupling,
}

/// Buffers of one [`TractionKernel::apply`] (three spectra).
pub struct KernelWork {
    w: [Fft2Work; 3],
}

impl TractionKernel {
    /// The operator of a solid (one stack, or a stack and its counterface) on a periodic
    /// cell of `grid` = (ny, nx) points and sides `size` = (ly, lx) (m).
    pub fn periodic<S: Solid + ?Sized>(
        solid: &S,
        grid: (usize, usize),
        size: (f64, f64),
        coupling: Coupling,
    ) -> Result<Self, TangentialError> {
        let tc = TangentialCompliance::new(solid);
        let uniform = match (uniform_compliance(solid), uniform_shear_compliance(solid)) {
            (Some(n), Some(t)) => [n, t],
            _ => [0.0, 0.0],
        };
        Self::from_compliances(
            grid,
            size,
            tc.plane_strain_modulus(),
            tc.shear_modulus(),
            |rho| tc.eval(rho),
            uniform,
            coupling,
        )
    }

    /// The operator from a compliance function S(ρ) normalised by E* (S_zz, S_LL, S_zL)
    /// and μ (S_TT), and the uniform-mode compliances `uniform` = [normal, tangential]
    /// (m/Pa).
    pub fn from_compliances(
        grid: (usize, usize),
        size: (f64, f64),
        e_star: f64,
        mu: f64,
        s: impl Fn(f64) -> Compliances,
        uniform: [f64; 2],
        coupling: Coupling,
    ) -> Result<Self, TangentialError> {
        let (ny, nx) = grid;
        let (ly, lx) = size;
        if ny < 4 || nx < 4 || ny % 2 != 0 || nx % 2 != 0 {
            return Err(TangentialError::Grid { rows: ny, cols: nx });
        }
        if !(ly.is_finite() && ly > 0.0 && lx.is_finite() && lx > 0.0) {
            return Err(TangentialError::Size { ly, lx });
        }
        if !(e_star.is_finite() && e_star > 0.0 && mu.is_finite() && mu > 0.0) {
            return Err(TangentialError::Modulus { e_star, mu });
        }
        let fft = RealFft2::new(ny, nx)?;
        let half = nx / 2 + 1;
        let mut cache: HashMap<u64, Compliances> = HashMap::new();
        let mut entries = vec![KernelEntry::default(); half * ny];
        let tau = std::f64::consts::TAU;
        for kx in 0..half {
            for ky in 0..ny {
                let e = &mut entries[kx * ny + ky];
                if kx == 0 && ky == 0 {
                    *e = KernelEntry {
                        xx: uniform[1],
                        yy: uniform[1],
                        zz: uniform[0],
                        ..KernelEntry::default()
                    };
                    continue;
                }
                let fx = tau * kx as f64 / lx;
                let fy = tau * signed_index(ky, ny) as f64 / ly;
                let rho = fx.hypot(fy);
                let c = *cache.entry(rho.to_bits()).or_insert_with(|| s(rho));
                let (cos, sin) = (fx / rho, fy / rho);
                let a = 2.0 * c.s_ll / (e_star * rho);
                let b = c.s_tt / (mu * rho);
                let nyquist = kx == nx / 2 || ky == ny / 2;
                let odd = if nyquist { 0.0 } else { 1.0 };
                let zl = match coupling {
                    Coupling::Coupled => 2.0 * c.s_zl / (e_star * rho),
                    Coupling::Uncoupled => 0.0,
                };
                *e = KernelEntry {
                    xx: a * cos * cos + b * sin * sin,
                    yy: a * sin * sin + b * cos * cos,
                    xy: odd * (a - b) * cos * sin,
                    zz: 2.0 * c.s_zz / (e_star * rho),
                    cx: odd * zl * cos,
                    cy: odd * zl * sin,
                };
            }
        }
        Ok(TractionKernel {
            fft,
            ny,
            nx,
            entries,
            coupling,
        })
    }

    /// The grid (ny, nx).
    pub fn grid(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    /// Whether S_zL is kept.
    pub fn coupling(&self) -> Coupling {
        self.coupling
    }

    /// The entry at the half-spectrum index (kx ∈ 0..=nx/2, ky ∈ 0..ny), m/Pa.
    pub fn entry(&self, kx: usize, ky: usize) -> KernelEntry {
        self.entries[kx * self.ny + ky]
    }

    /// Buffers for [`Self::apply`].
    pub fn work(&self) -> KernelWork {
        KernelWork {
            w: [self.fft.work(), self.fft.work(), self.fft.work()],
        }
    }

    /// (u_x, u_y, w) = K (q_x, q_y, p) on the grid (row-major ny × nx fields, Pa → m).
    /// A `None` traction component is zero; only the requested outputs are written.
    pub fn apply(
        &self,
        t: [Option<&[f64]>; 3],
        u: [Option<&mut [f64]>; 3],
        work: &mut KernelWork,
    ) -> Result<(), TangentialError> {
        let n = self.ny * self.nx;
        let present = [t[0].is_some(), t[1].is_some(), t[2].is_some()];
        for (c, ti) in t.iter().enumerate() {
            if let Some(f) = ti {
                if f.len() != n {
                    return Err(TangentialError::Length {
                        got: f.len(),
                        expected: n,
                    });
                }
                self.fft.forward(f, &mut work.w[c])?;
            }
        }
        let scale = 1.0 / n as f64;
        let zero = Complex::new(0.0, 0.0);
        let i = Complex::new(0.0, 1.0);
        let [w0, w1, w2] = &mut work.w;
        for (idx, e) in self.entries.iter().enumerate() {
            let qx = if present[0] { w0.spec[idx] } else { zero };
            let qy = if present[1] { w1.spec[idx] } else { zero };
            let p = if present[2] { w2.spec[idx] } else { zero };
            let ux = qx * e.xx + qy * e.xy + i * p * e.cx;
            let uy = qx * e.xy + qy * e.yy + i * p * e.cy;
            let w = p * e.zz - i * (qx * e.cx + qy * e.cy);
            w0.spec[idx] = ux * scale;
            w1.spec[idx] = uy * scale;
            w2.spec[idx] = w * scale;
        }
        for (c, ui) in u.into_iter().enumerate() {
            if let Some(out) = ui {
                if out.len() != n {
                    return Err(TangentialError::Length {
                        got: out.len(),
                        expected: n,
                    });
                }
                self.fft.inverse(out, &mut work.w[c])?;
            }
        }
        Ok(())
    }
}

/// The tangential uniform-mode compliance of a solid on rigid bases, Σhᵢ/Gᵢ (m/Pa; the
/// bodies' values add), or `None` on an elastic base (infinite).
pub fn uniform_shear_compliance<S: Solid + ?Sized>(solid: &S) -> Option<f64> {
    fn one(stack: &Stack) -> Option<f64> {
        match stack.base() {
            Base::Elastic { .. } => None,
            Base::Rigid => Some(
                stack
                    .layers()
                    .iter()
                    .map(|l| l.thickness / shear_modulus(l.young, l.poisson))
                    .sum(),
            ),
        }
    }
    match solid.elastic_counterface() {
        Some(c) => Some(one(solid.first())? + one(c)?),
        None => one(solid.first()),
    }
}
