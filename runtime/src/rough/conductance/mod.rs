//! The I model's interface conductance (physics.md §6.2): the contact spots
//! conduct in parallel and heat each other through both bodies.
//!
//! Every spot i is an isothermal disc of conductance G_i (both bodies in series, its
//! layered ψ included: the caller's spot solver) carrying the heat Q_i; the other spots
//! raise its temperature through the layered point-source field of each body, periodic
//! images included ([`Kernel`]). With one temperature jump ΔT on every spot,
//!
//! ```text
//!   Σ_j (δ_ij/G_i + I_ij) Q_j = ΔT,   h_c = Σ_i Q_i / (ΔT A₀),
//! ```
//!
//! I_ij (K/W, or Ω) the temperature rise at spot i per unit heat into spot j
//! ([`Kernel::between`] of their offset) and, on the diagonal, the spot's own periodic
//! images ([`Kernel::self_images`]; 0 for an isolated sample). The kernel is that of
//! point sources: exact to leading order in a/d, Greenwood's (1966) two-spot result
//! 1/G + 1/(2πkd) for a homogeneous body. h_c is in W/(m²·K) (or S/m²) and, as the
//! BEM's, excludes the bodies' bulk 1-D resistance (the k = 0 mode). The system is
//! solved by dense LU ([`interface_conductance`]).

pub(crate) mod kernel;

use thiserror::Error;

pub use kernel::{Kernel, KernelInfo};

use crate::conduction::ConductionCompliance;
use crate::resources::{MemoryLimit, ResourceError, bytes_for};

/// One body's conduction as the spots see it.
#[derive(Debug, Clone, Copy)]
pub enum Body<'a> {
    /// A perfect conductor: no temperature rise.
    Perfect,
    /// A homogeneous conducting half-space of conductivity k (W/(m·K), or S/m).
    HalfSpace(f64),
    /// A layered conductor.
    Layered(&'a ConductionCompliance),
}

/// Errors of the I model's conductance.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ConductanceError {
    #[error("{field}: value {value} out of range: {reason}")]
    Input {
        field: &'static str,
        value: f64,
        reason: String,
    },
    #[error("both bodies are perfect conductors: no constriction resistance")]
    BothPerfect,
    /// The layered point-source field of an isolated sample could not be tabulated.
    #[error("the I model's isolated conduction kernel of a layered body: {0}")]
    Layered(String),
    #[error(
        "the I model's conduction kernel needs a {nx}×{ny} table to resolve the layers (its \
         spectrum reaches ρ = {rho_max:.3e} 1/m), above the cap of {cap} per side: the top layer \
         is too thin against the cell; use model.kind = \"bem\" or \"independent\""
    )]
    Grid {
        nx: usize,
        ny: usize,
        cap: usize,
        rho_max: f64,
    },
    #[error("I-model conduction kernel: {0}")]
    Fft(String),
    #[error(transparent)]
    Memory(#[from] ResourceError),
    #[error(
        "the I model's spot network is singular with {spots} spots (spots closer than their \
         radii make the point-source interactions meaningless)"
    )]
    Singular { spots: usize },
}

/// One conducting spot: position (m) and its isolated conductance G (W/K, or S).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spot {
    pub x: f64,
    pub y: f64,
    pub conductance: f64,
}

/// The network's solution with ΔT = 1 K (or 1 V).
#[derive(Debug, Clone, PartialEq)]
pub struct Network {
    /// h_c = Σ Q_i / A₀ (W/(m²·K), or S/m²).
    pub conductance: f64,
    /// The heat Q_i through each spot (W/K, or S), in the order given.
    pub heat: Vec<f64>,
}

/// Solves the spot network (module docs) for h_c on nominal area `area` (m²), its
/// matrix checked against `memory` first. No spot: h_c = 0.
pub fn interface_conductance(
    kernel: &Kernel,
    spots: &[Spot],
    area: f64,
    memory: &MemoryLimit,
) -> Result<Network, ConductanceError> {
    if !(area.is_finite() && area > 0.0) {
        return Err(ConductanceError::Input {
            field: "area",
            value: area,
            reason: "the nominal area must be finite and > 0 (m²)".into(),
        });
    }
    for s in spots {
        if !(s.conductance.is_finite() && s.conductance > 0.0) {
            return Err(ConductanceError::Input {
                field: "spot conductance",
                value: s.conductance,
                reason: "must be finite and > 0 (W/K or S)".into(),
            });
        }
        for v in [s.x, s.y] {
            if !v.is_finite() {
                return Err(ConductanceError::Input {
                    field: "spot position",
                    value: v,
                    reason: "must be finite (m)".into(),
                });
            }
        }
    }
    let n = spots.len();
    if n == 0 {
        return Ok(Network {
            conductance: 0.0,
            heat: Vec::new(),
        });
    }
    memory.check(
        format!("I-model conduction: the {n}×{n} spot network"),
        bytes_for((n as u64).saturating_mul(n as u64), 8),
    )?;
    let own = kernel.self_images();
    let mut m = vec![0.0; n * n];
    fill(&mut m, n, |i, j| {
        if i == j {
            1.0 / spots[i].conductance + own
        } else {
            kernel.between(spots[j].x - spots[i].x, spots[j].y - spots[i].y)
        }
    });
    let mut rhs = vec![1.0; n];
    let heat = crate::rough::interacting::lu::lu_solve(&mut m, &mut rhs, n)
        .ok_or(ConductanceError::Singular { spots: n })?;
    Ok(Network {
        conductance: heat.iter().sum::<f64>() / area,
        heat,
    })
}

/// The interactions I_ij between a fixed set of points (m), filled once: a load path's
/// spots are the summits in contact at each step, and I_ij depends on the positions only,
/// so the I model fills the matrix of every summit that touches at some step and solves
/// each step's network on its subset ([`Interactions::network`]) — the same matrix
/// entries and the same LU as [`interface_conductance`], so the same h_c bit for bit,
/// without filling the pairs again at every step (the fill, ~3 µs per pair, is most of
/// the network's time).
#[derive(Debug, Clone)]
pub struct Interactions {
    n: usize,
    /// I_ij for i ≠ j (row-major n × n; 0 on the diagonal).
    m: Vec<f64>,
    /// A spot's interaction with its own images.
    own: f64,
}

impl Interactions {
    /// The interactions of `points` (x, y in m) through `kernel`, the matrix checked
    /// against `memory` first.
    pub fn new(
        kernel: &Kernel,
        points: &[(f64, f64)],
        memory: &MemoryLimit,
    ) -> Result<Self, ConductanceError> {
        for &(x, y) in points {
            for v in [x, y] {
                if !v.is_finite() {
                    return Err(ConductanceError::Input {
                        field: "spot position",
                        value: v,
                        reason: "must be finite (m)".into(),
                    });
                }
            }
        }
        let n = points.len();
        memory.check(
            format!("I-model conduction: the {n}×{n} interactions of the summits in contact"),
            bytes_for((n as u64).saturating_mul(n as u64), 8),
        )?;
        let mut m = vec![0.0; n * n];
        fill(&mut m, n, |i, j| {
            if i == j {
                0.0
            } else {
                kernel.between(points[j].0 - points[i].0, points[j].1 - points[i].1)
            }
        });
        Ok(Interactions {
            n,
            m,
            own: kernel.self_images(),
        })
    }

    /// The network of `spots` — (index into the points, conductance G in W/K or S),
    /// indices strictly increasing — on nominal area `area` (m²), as
    /// [`interface_conductance`] of the same spots in the same order.
    pub fn network(&self, spots: &[(usize, f64)], area: f64) -> Result<Network, ConductanceError> {
        if !(area.is_finite() && area > 0.0) {
            return Err(ConductanceError::Input {
                field: "area",
                value: area,
                reason: "the nominal area must be finite and > 0 (m²)".into(),
            });
        }
        for (k, &(i, g)) in spots.iter().enumerate() {
            if !(g.is_finite() && g > 0.0) {
                return Err(ConductanceError::Input {
                    field: "spot conductance",
                    value: g,
                    reason: "must be finite and > 0 (W/K or S)".into(),
                });
            }
            if i >= self.n || (k > 0 && i <= spots[k - 1].0) {
                return Err(ConductanceError::Input {
                    field: "spot index",
                    value: i as f64,
                    reason: format!("must increase and be below {}", self.n),
                });
            }
        }
        let n = spots.len();
        if n == 0 {
            return Ok(Network {
                conductance: 0.0,
                heat: Vec::new(),
            });
        }
        let mut m = vec![0.0; n * n];
        for (r, &(i, g)) in spots.iter().enumerate() {
            let row = &self.m[i * self.n..(i + 1) * self.n];
            for (c, &(j, _)) in spots.iter().enumerate() {
                m[r * n + c] = if r == c { 1.0 / g + self.own } else { row[j] };
            }
        }
        let mut rhs = vec![1.0; n];
        let heat = crate::rough::interacting::lu::lu_solve(&mut m, &mut rhs, n)
            .ok_or(ConductanceError::Singular { spots: n })?;
        Ok(Network {
            conductance: heat.iter().sum::<f64>() / area,
            heat,
        })
    }
}

/// m[i, j] = f(i, j) for j ≥ i, mirrored (rows in parallel).
fn fill(m: &mut [f64], n: usize, f: impl Fn(usize, usize) -> f64 + Sync) {
    use rayon::prelude::*;
    m.par_chunks_mut(n).enumerate().for_each(|(i, row)| {
        for (j, v) in row.iter_mut().enumerate().skip(i) {
            *v = f(i, j);
        }
    });
    for i in 0..n {
        for j in 0..i {
            m[i * n + j] = m[j * n + i];
        }
    }
}

/// A failed spot network of a load path ([`path_conductances`]).
#[derive(Debug, Error)]
pub enum PathError {
    /// The interactions of the summits that touch.
    #[error("{0}")]
    Interactions(ConductanceError),
    /// The spot network of one load step.
    #[error("load step {step}: {error}")]
    Step {
        /// The step (from 0).
        step: usize,
        error: ConductanceError,
    },
}

/// The I model's interface conductance of every step of a load path (physics.md §6.2):
/// the spots of each step (the summits in contact, at their positions `points` (m),
/// with their conductances `g[step][summit]` (W/K or S, 0 out of contact, e.g.
/// [`crate::constriction::series_conductances`])) heat each other through both bodies
/// of `kernel`, Σ_j (δ_ij/G_i + I_ij) Q_j = ΔT, h_c = Σ Q_i/(ΔT A₀), `area` = A₀ (m²).
/// The interactions of every summit that touches at some step are filled once for the
/// path ([`Interactions`]: the same h_c as filling each step's network afresh, bit for
/// bit), checked against `memory` first. h_c per step (W/(m²·K) or S/m²).
pub fn path_conductances(
    kernel: &Kernel,
    g: &[Vec<f64>],
    points: &[(f64, f64)],
    area: f64,
    memory: &MemoryLimit,
) -> Result<Vec<f64>, PathError> {
    // the summits in contact at some step: their interactions filled once
    let touching: Vec<usize> = (0..points.len())
        .filter(|&k| g.iter().any(|gs| gs.get(k).is_some_and(|&g| g > 0.0)))
        .collect();
    let at: Vec<(f64, f64)> = touching.iter().map(|&k| points[k]).collect();
    let net = Interactions::new(kernel, &at, memory).map_err(PathError::Interactions)?;
    g.iter()
        .enumerate()
        .map(|(step, gs)| {
            let spots: Vec<(usize, f64)> = touching
                .iter()
                .enumerate()
                .filter_map(|(r, &k)| gs.get(k).filter(|&&g| g > 0.0).map(|&g| (r, g)))
                .collect();
            net.network(&spots, area)
                .map(|n| n.conductance)
                .map_err(|error| PathError::Step { step, error })
        })
        .collect()
}

#[cfg(test)]
mod tests;
