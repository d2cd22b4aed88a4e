//! Image geometry of the I model: which image pairs of the candidate asperities are
//! summed exactly (closer than the far-field cut-off r_c, or all of them without a
//! far-field model) and the far-field coefficient sums N_kl,j = Σ_far images c_j(r) of
//! every pair (interacting module docs). With [`Images::Periodic`]`(m)` every source is
//! repeated on the (2m+1)² block of cells around the sample, its own images included;
//! [`Images::Isolated`] uses plain distances.

use super::far_field::{FarModel, NB, Vb};
use crate::resources::{ResourceError, bytes_for, check_memory};
use crate::rough::Images;
use crate::summits::Summit;

/// The interaction geometry of a set of candidate asperities under one image
/// convention: far-field coefficient sums per pair and the exact (near) image distances.
pub(crate) struct Prepared {
    /// Candidate summit indices (local index → summit).
    pub cand: Vec<usize>,
    /// Radius R of each local index (m).
    pub radius: Vec<f64>,
    pub far: Option<FarModel>,
    /// N_kl,j = Σ_far images c_j(r), the Chebyshev coefficients of Σ_far images W(·, r)
    /// (1/m; m×m row-major, symmetric; the diagonal holds the far self-images); empty
    /// without a far model.
    pub nf: Vec<Vb>,
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
    /// image pair exact).
    pub fn new(
        summits: &[Summit],
        extent: (f64, f64),
        images: Images,
        cand: Vec<usize>,
        far: Option<FarModel>,
    ) -> Result<Prepared, ResourceError> {
        let (lx, ly) = extent;
        let m = cells(images);
        let (r_c, r_top) = far
            .as_ref()
            .map_or((f64::INFINITY, 0.0), |f| (f.r_c, f.r_hi));
        let is_far = |r: f64| r >= r_c && r <= r_top;
        let n = cand.len();
        check_memory(
            format!(
                "I model: pair coefficients of {n} loaded asperities ({} bytes per pair, dense Jacobian included)",
                PAIR_BYTES
            ),
            bytes_for((n as u64).saturating_mul(n as u64), PAIR_BYTES),
        )?;
        let mut nf = Vec::new();
        let mut self_far = [0.0; NB];
        let mut near_self = Vec::new();
        let mut far_pairs = 0;
        for sx in -m..=m {
            for sy in -m..=m {
                if (sx, sy) != (0, 0) {
                    let r = (sx as f64 * lx).hypot(sy as f64 * ly);
                    match &far {
                        Some(f) if is_far(r) => f.accumulate(r, &mut self_far),
                        _ => near_self.push(r),
                    }
                }
            }
        }
        if far.is_some() {
            nf = vec![[0.0; NB]; n * n];
            for p in 0..n {
                nf[p * n + p] = self_far;
            }
            far_pairs += n * ((2 * m + 1) * (2 * m + 1) - 1) as usize - n * near_self.len();
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
        let mut near_of = vec![Vec::new(); n];
        for (i, &(p, q, _)) in near.iter().enumerate() {
            near_of[p].push(i);
            near_of[q].push(i);
        }
        let a_valid = far.as_ref().map_or(f64::INFINITY, |f| f.a_max);
        Ok(Prepared {
            radius: cand.iter().map(|&k| summits[k].radius).collect(),
            cand,
            far,
            nf,
            near,
            near_of,
            near_self,
            a_valid,
            far_pairs,
        })
    }

    /// Number of candidates.
    pub fn n(&self) -> usize {
        self.cand.len()
    }
}
