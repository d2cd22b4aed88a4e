//! Image geometry of the I model: which image pairs of the candidate asperities are
//! summed exactly (closer than the far-field cut-off r_c, or all of them without a
//! far-field model) and the far-field coefficient sums N_kl,j = Σ_far images c_j(r) of
//! every pair (interacting module docs). With [`Images::Periodic`]`(m)` every source is
//! repeated on the (2m+1)² block of cells around the sample, its own images included;
//! [`Images::Isolated`] uses plain distances.

use super::far_field::{FarModel, NB, Vb};
use super::pair_sums::{DenseSums, PairSums, Rows, Sources, Work};
use crate::resources::{MemoryLimit, bytes_for};
use crate::rough::{FarFieldError, Images, RoughError};
use crate::summits::Summit;

/// The interaction geometry of a set of candidate asperities under one image
/// convention: far-field coefficient sums per pair and the exact (near) image distances.
pub(crate) struct Prepared {
    /// Candidate summit indices (local index → summit).
    pub cand: Vec<usize>,
    /// Radius R of each local index (m).
    pub radius: Vec<f64>,
    /// Position (x, y) of each local index (m).
    pub pos: Vec<(f64, f64)>,
    pub far: Option<FarModel>,
    /// Near cross entries (p, q, r), p < q, one per image.
    pub near: Vec<(usize, usize, f64)>,
    /// Near cross entries of each local index.
    pub near_of: Vec<Vec<usize>>,
    /// Near self-image distances (m), the same for every local index.
    pub near_self: Vec<f64>,
    /// Contact-radius bound A of the far model (m; ∞ without one).
    pub a_valid: f64,
    /// Number of image pairs in the far-field model.
    pub far_pairs: usize,
    /// N_kk: the far self images of one asperity (the same for every asperity).
    pub self_far: Vb,
    /// The far pair sums: dense N_kl,j = Σ_far images c_j(r), the Chebyshev coefficients
    /// of Σ_far images W(·, r) (1/m; m×m row-major, symmetric; the diagonal holds the far
    /// self-images; empty without a far model), or the grid far field with near
    /// corrections.
    pub sums: Box<dyn PairSums>,
    /// The dense sums skip the rows of candidates with δ_k at or below this (m): 0
    /// (not loaded), −∞ with the zero-mean images (every candidate may touch).
    pub rows_from: f64,
}

/// How the far-field pair sums are held: chosen by [`Prepared::new`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sums {
    /// N_kl of every pair (O(N²) memory; the dense Jacobian).
    Dense,
    /// The grid far field and sparse near corrections (O(N); Krylov Newton steps),
    /// falling back to dense when no grid meets the tolerance.
    Grid,
}

/// Memory of one asperity pair: its far-field coefficients N_kl (NB × 8 bytes) and its
/// entries of the dense Jacobian and its LU copy (2 × 8 bytes).
pub(crate) const PAIR_BYTES: u64 = (NB as u64) * 8 + 16;

/// Image cells per side: m of (2m+1)² (0 for an isolated sample).
pub(crate) fn cells(images: Images) -> i64 {
    match images {
        Images::Isolated => 0,
        Images::Periodic(m) => m as i64,
    }
}

/// The largest image distance of a sample with sides `extent` (m) under `images`: the
/// far-field model must reach it.
pub(crate) fn reach(images: Images, extent: (f64, f64)) -> f64 {
    1.01 * (2 * cells(images) + 1) as f64 * extent.0.hypot(extent.1)
}

impl Prepared {
    /// The geometry of the candidates `cand` (summit indices) of `summits` on a sample of
    /// sides `extent` (m) under `images`, with the far-field model `far` (None: every
    /// image pair exact), its pair sums held as `sums` asks (tolerance `tol`); their
    /// storage checked against `memory` first.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        summits: &[Summit],
        extent: (f64, f64),
        images: Images,
        cand: Vec<usize>,
        far: Option<FarModel>,
        sums: Sums,
        tol: f64,
        memory: &MemoryLimit,
    ) -> Result<Prepared, RoughError> {
        let (lx, ly) = extent;
        let m = cells(images);
        let (r_c, r_top) = far
            .as_ref()
            .map_or((f64::INFINITY, 0.0), |f| (f.r_c, f.r_hi));
        let is_far = |r: f64| r >= r_c && r <= r_top;
        let n = cand.len();
        let (self_far, near_self) = self_images(extent, m, far.as_ref());
        #[cfg(not(feature = "spectral"))]
        let _ = (sums, tol);
        #[cfg(feature = "spectral")]
        if let (Sums::Grid, Some(f)) = (sums, far.as_ref()) {
            use super::near::{FastError, FastSums};
            match FastSums::build(summits, &cand, extent, m, f, tol, memory) {
                Ok(Some((fast, near))) => {
                    let far_pairs = fast.modelled_pairs + n * near_self_far(m, near_self.len());
                    let near_of = near_of(n, &near);
                    return Ok(Prepared {
                        radius: cand.iter().map(|&k| summits[k].radius).collect(),
                        pos: cand.iter().map(|&k| (summits[k].x, summits[k].y)).collect(),
                        cand,
                        a_valid: f.a_max,
                        far,
                        near,
                        near_of,
                        near_self,
                        far_pairs,
                        self_far,
                        sums: Box::new(fast),
                        rows_from: 0.0,
                    });
                }
                Ok(None) => {}
                Err(FastError::Memory(e)) => return Err(e.into()),
                Err(FastError::Fft(e)) => return Err(FarFieldError::Grid(e.to_string()).into()),
            }
        }
        memory.check(
            format!(
                "I model: pair coefficients of {n} loaded asperities ({} bytes per pair, dense Jacobian included)",
                PAIR_BYTES
            ),
            bytes_for((n as u64).saturating_mul(n as u64), PAIR_BYTES),
        )?;
        let mut nf = Vec::new();
        let mut far_pairs = 0;
        if far.is_some() {
            nf = vec![[0.0; NB]; n * n];
            for p in 0..n {
                nf[p * n + p] = self_far;
            }
            far_pairs += n * near_self_far(m, near_self.len());
        }
        let mut near = Vec::new();
        for p in 0..n {
            let a = &summits[cand[p]];
            for q in p + 1..n {
                let b = &summits[cand[q]];
                let mut acc = [0.0; NB];
                for sx in -m..=m {
                    for sy in -m..=m {
                        let dx = b.x + sx as f64 * lx - a.x;
                        let dy = b.y + sy as f64 * ly - a.y;
                        let r = (dx * dx + dy * dy).sqrt();
                        match &far {
                            Some(f) if is_far(r) => {
                                f.accumulate(r, &mut acc);
                                far_pairs += 1;
                            }
                            _ => near.push((p, q, r)),
                        }
                    }
                }
                if far.is_some() {
                    nf[p * n + q] = acc;
                    nf[q * n + p] = acc;
                }
            }
        }
        let near_of = near_of(n, &near);
        let a_valid = far.as_ref().map_or(f64::INFINITY, |f| f.a_max);
        Ok(Prepared {
            radius: cand.iter().map(|&k| summits[k].radius).collect(),
            pos: cand.iter().map(|&k| (summits[k].x, summits[k].y)).collect(),
            cand,
            far,
            sums: Box::new(DenseSums { nf, n }),
            near,
            near_of,
            near_self,
            a_valid,
            far_pairs,
            self_far,
            rows_from: 0.0,
        })
    }

    /// The far pair sums at every candidate k: `out_d[k] = Σ_{l≠k} N_kl·src[l]` and
    /// `out_u[k] = Σ_{l≠k} N_kl sc[l]` (the self images excluded: they go through
    /// `self_far`), by the grid or the dense N_kl. `src[l]` must be zero where
    /// `sc[l]` is. The dense sums skip (zero) the rows with `deltas[k]` ≤ `rows_from` (not
    /// loaded). Only with a far model. `sources_only`: the grid sums may leave the
    /// outputs of non-sources (sc = 0) at zero (Jacobian–vector products).
    #[allow(clippy::too_many_arguments)]
    pub fn interact(
        &self,
        src: &[Vb],
        sc: &[f64],
        deltas: &[f64],
        out_d: &mut [f64],
        out_u: &mut [Vb],
        work: &mut Work,
        sources_only: bool,
    ) -> Result<(), RoughError> {
        let rows = Rows {
            deltas,
            from: self.rows_from,
        };
        self.sums
            .apply(
                Sources { src, sc },
                rows,
                (out_d, out_u),
                work,
                sources_only,
            )
            .map_err(|e| FarFieldError::Grid(e).into())
    }

    /// Number of candidates.
    pub fn n(&self) -> usize {
        self.cand.len()
    }
}

/// Far self images per asperity: (2m+1)² − 1 minus the exact ones.
fn near_self_far(m: i64, exact: usize) -> usize {
    ((2 * m + 1) * (2 * m + 1) - 1) as usize - exact
}

/// The self images of one asperity: N_kk (the far-model sum of those at r ≥ r_c) and
/// the distances (m) of the others, summed exactly.
fn self_images(extent: (f64, f64), m: i64, far: Option<&FarModel>) -> (Vb, Vec<f64>) {
    let mut self_far = [0.0; NB];
    let mut near_self = Vec::new();
    for sx in -m..=m {
        for sy in -m..=m {
            if (sx, sy) != (0, 0) {
                let r = (sx as f64 * extent.0).hypot(sy as f64 * extent.1);
                match far {
                    Some(f) if r >= f.r_c && r <= f.r_hi => f.accumulate(r, &mut self_far),
                    _ => near_self.push(r),
                }
            }
        }
    }
    (self_far, near_self)
}

/// The near entries of each local index.
fn near_of(n: usize, near: &[(usize, usize, f64)]) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new(); n];
    for (i, &(p, q, _)) in near.iter().enumerate() {
        out[p].push(i);
        out[q].push(i);
    }
    out
}
