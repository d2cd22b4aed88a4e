//! The frictionless normal problem on the [`TractionKernel`]'s A_zz, with an imposed
//! extra displacement (the normal displacement that a tangential traction causes through
//! S_zL): Polonsky & Keer's constrained conjugate gradient (Wear 231, 1999), force or
//! flat-position control.
//!
//! With the heights z (m, positive out of the solid), the flat at height c and the
//! deflection w = A_zz p + w_e (w_e the imposed part), the gap g = w − z + c obeys
//! g ≥ 0, p ≥ 0, p g = 0. The error is the crate's
//! ε = max(max_{p>0} |g|, max_{p=0} max(−g, 0))/σ_z (σ_z the RMS height about the mean).

use super::{TangentialError, TractionKernel};

/// The normal load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NormalLoad {
    /// The mean pressure P/(Lx Ly) (Pa); the flat's height follows.
    MeanPressure(f64),
    /// The flat's height c (m), in the heights' frame (the deflection has zero mean on
    /// an elastic base).
    Flat(f64),
}

/// A solved normal problem.
#[derive(Debug, Clone)]
pub struct NormalSolution {
    /// The pressure (Pa), row-major.
    pub pressure: Vec<f64>,
    /// The deflection w = A_zz p + w_e (m).
    pub deflection: Vec<f64>,
    /// The flat's height c (m).
    pub flat: f64,
    /// The conjugate-gradient iterations.
    pub iterations: usize,
    /// The final error ε.
    pub error: f64,
}

impl NormalSolution {
    /// The number of points in contact (p > 0).
    pub fn contact_points(&self) -> usize {
        self.pressure.iter().filter(|&&p| p > 0.0).count()
    }
}

/// Solves the normal problem (module docs) to the error `tol`, from the pressure `start`
/// if given; `extra` is the imposed deflection w_e.
pub fn solve_normal(
    kernel: &TractionKernel,
    heights: &[f64],
    extra: Option<&[f64]>,
    load: NormalLoad,
    start: Option<&[f64]>,
    tol: f64,
    max_iterations: usize,
) -> Result<NormalSolution, TangentialError> {
    let (ny, nx) = kernel.grid();
    let n = ny * nx;
    for f in [Some(heights), extra, start].into_iter().flatten() {
        if f.len() != n {
            return Err(TangentialError::Length {
                got: f.len(),
                expected: n,
            });
        }
    }
    let mean_z = heights.iter().sum::<f64>() / n as f64;
    let sigma = (heights.iter().map(|z| (z - mean_z).powi(2)).sum::<f64>() / n as f64).sqrt();
    let sigma = if sigma > 0.0 { sigma } else { 1.0 };
    let z_max = heights.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let (force, mut c) = match load {
        NormalLoad::MeanPressure(p) if p.is_finite() && p > 0.0 => (Some(p * n as f64), 0.0),
        NormalLoad::Flat(c) if c.is_finite() => (None, c),
        NormalLoad::MeanPressure(v) => {
            return Err(TangentialError::Load {
                what: "mean pressure",
                value: v,
                extra: " and > 0",
            });
        }
        NormalLoad::Flat(v) => {
            return Err(TangentialError::Load {
                what: "flat height",
                value: v,
                extra: "",
            });
        }
    };
    let mut p: Vec<f64> = match (start, force) {
        (Some(s), _) => s.iter().map(|v| v.max(0.0)).collect(),
        (None, Some(f)) => vec![f / n as f64; n],
        (None, None) => heights
            .iter()
            .map(|&z| if z > c { 1e-3 } else { 0.0 })
            .collect(),
    };
    if let Some(f) = force {
        let s: f64 = p.iter().sum();
        if s > 0.0 {
            p.iter_mut().for_each(|v| *v *= f / s);
        } else {
            p.iter_mut().for_each(|v| *v = f / n as f64);
        }
    }
    if force.is_none() && p.iter().all(|&v| v == 0.0) && z_max <= c {
        return Ok(NormalSolution {
            pressure: p,
            deflection: extra.map_or_else(|| vec![0.0; n], |e| e.to_vec()),
            flat: c,
            iterations: 0,
            error: 0.0,
        });
    }
    let mut work = kernel.work();
    let mut w = vec![0.0; n];
    let mut g = vec![0.0; n];
    let mut t = vec![0.0; n];
    let mut r = vec![0.0; n];
    let mut g_old = 1.0;
    let mut conjugate = false;
    let mut error = f64::INFINITY;
    for it in 0..max_iterations {
        kernel.apply(
            [None, None, Some(&p)],
            [None, None, Some(&mut w)],
            &mut work,
        )?;
        if let Some(e) = extra {
            w.iter_mut().zip(e).for_each(|(w, e)| *w += e);
        }
        let mut count = 0usize;
        let mut sum = 0.0;
        for i in 0..n {
            g[i] = w[i] - heights[i];
            if p[i] > 0.0 {
                count += 1;
                sum += g[i];
            }
        }
        if force.is_some() {
            if count == 0 {
                return Err(TangentialError::NoContact);
            }
            c = -sum / count as f64;
        }
        g.iter_mut().for_each(|g| *g += c);
        error = 0.0;
        for i in 0..n {
            let e = if p[i] > 0.0 {
                g[i].abs()
            } else {
                (-g[i]).max(0.0)
            };
            error = f64::max(error, e);
        }
        error /= sigma;
        if error <= tol {
            return Ok(NormalSolution {
                pressure: p,
                deflection: w,
                flat: c,
                iterations: it,
                error,
            });
        }
        let gg: f64 = (0..n).filter(|&i| p[i] > 0.0).map(|i| g[i] * g[i]).sum();
        let beta = if conjugate { gg / g_old } else { 0.0 };
        for i in 0..n {
            t[i] = if p[i] > 0.0 { g[i] + beta * t[i] } else { 0.0 };
        }
        g_old = gg;
        kernel.apply(
            [None, None, Some(&t)],
            [None, None, Some(&mut r)],
            &mut work,
        )?;
        if force.is_some() {
            let rm = (0..n).filter(|&i| p[i] > 0.0).map(|i| r[i]).sum::<f64>() / count as f64;
            r.iter_mut().for_each(|r| *r -= rm);
        }
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            if p[i] > 0.0 {
                num += g[i] * t[i];
                den += r[i] * t[i];
            }
        }
        let tau = if den > 0.0 { num / den } else { 0.0 };
        let mut overlap = false;
        for i in 0..n {
            if p[i] > 0.0 {
                p[i] = (p[i] - tau * t[i]).max(0.0);
            } else if g[i] < 0.0 {
                p[i] -= tau * g[i];
                overlap = true;
            }
        }
        conjugate = !overlap;
        if let Some(f) = force {
            let s: f64 = p.iter().sum();
            if s <= 0.0 {
                return Err(TangentialError::NoContact);
            }
            p.iter_mut().for_each(|v| *v *= f / s);
        }
    }
    Err(TangentialError::NotConverged {
        what: "normal",
        iterations: max_iterations,
        error,
    })
}
