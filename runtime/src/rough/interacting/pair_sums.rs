//! The far-field pair sums of the I model behind one trait, [`PairSums`]: per
//! candidate k, over the image pairs the far model carries (module docs),
//!
//! ```text
//!   out_d[k] = Σ_{l≠k} N_kl·src[l],   out_u[k] = Σ_{l≠k} N_kl sc[l]   (N_kl in 1/m)
//! ```
//!
//! held either densely ([`DenseSums`]: N_kl of every pair, O(N²) memory, the dense
//! Jacobian and LU) or on an FFT grid with sparse near corrections (`near::FastSums`,
//! feature `spectral`: O(N) memory, Newton steps by conjugate gradients). The solver
//! asks the trait, never which path it holds.

use std::any::Any;

use super::far_field::{NB, Vb, dot};

/// Leading far-field coefficients kept per near pair of the grid path (the
/// preconditioner of its Newton steps).
pub(crate) const LEAD: usize = 3;

/// The FFT grid of the grid path, for the diagnostics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GridInfo {
    /// Cells (x, y) of the periodic grid.
    pub cells: (usize, usize),
    /// Radius (m) within which the grid's pairs are corrected exactly.
    pub near_radius: f64,
    /// Largest error of the grid measured when it was planned (point-force units).
    pub worst: f64,
}

/// The grid path's near pairs (p, q) and each pair's [`LEAD`] leading coefficients.
pub(crate) type NearPairs<'s> = (&'s [(u32, u32)], &'s [[f32; LEAD]]);

/// A workspace an evaluation keeps between calls (one per energy state), made by the
/// path on first use.
pub(crate) type Work = Option<Box<dyn Any + Send>>;

/// The sources of one evaluation: y_l = Q_l ℓ(a_l)/π and Q_l (zero where a_l = 0; `src[l]`
/// must be zero where `sc[l]` is).
#[derive(Clone, Copy)]
pub(crate) struct Sources<'s> {
    pub src: &'s [Vb],
    pub sc: &'s [f64],
}

/// The rows a dense evaluation may skip (zero): those with `deltas[k]` ≤ `from` (m;
/// not loaded). The grid path computes every row.
#[derive(Clone, Copy)]
pub(crate) struct Rows<'d> {
    pub deltas: &'d [f64],
    pub from: f64,
}

/// The two ways of holding the far pair sums.
pub(crate) trait PairSums: Send + Sync {
    /// `out_d[k] = Σ_{l≠k} N_kl·src[l]`, `out_u[k] = Σ_{l≠k} N_kl sc[l]` for every k
    /// (the self images excluded: they go through `Prepared::self_far`).
    /// `sources_only`: the outputs of non-sources (sc = 0) may be left at zero
    /// (Jacobian–vector products). Errors are the grid's (its FFTs).
    fn apply(
        &self,
        sources: Sources,
        rows: Rows,
        out: (&mut [f64], &mut [Vb]),
        work: &mut Work,
        sources_only: bool,
    ) -> Result<(), String>;

    /// The per-pair coefficients N_kl (row-major, n×n) where they are held densely.
    fn dense(&self) -> Option<&[Vb]> {
        None
    }

    /// The grid, where the sums run on one.
    fn grid(&self) -> Option<GridInfo> {
        None
    }

    /// The grid path's near pairs (p, q), p < q (local indices, sorted by (q, p)), with
    /// each pair's [`LEAD`] leading far-field coefficients over its images at r ≥ r_c.
    fn near_pairs(&self) -> Option<NearPairs<'_>> {
        None
    }
}

/// The dense sums: N_kl of every pair of the n candidates (1/m; n×n row-major,
/// symmetric; the diagonal holds the far self images, skipped by the sums).
pub(crate) struct DenseSums {
    pub nf: Vec<Vb>,
    pub n: usize,
}

impl PairSums for DenseSums {
    fn apply(
        &self,
        Sources { src, sc }: Sources,
        rows: Rows,
        (out_d, out_u): (&mut [f64], &mut [Vb]),
        _: &mut Work,
        _: bool,
    ) -> Result<(), String> {
        let n = self.n;
        for k in 0..n {
            let row = &self.nf[k * n..(k + 1) * n];
            let mut d = 0.0;
            let mut u = [0.0; NB];
            if rows.deltas[k] <= rows.from {
                out_d[k] = d;
                out_u[k] = u;
                continue;
            }
            for (l, nkl) in row.iter().enumerate() {
                if l == k || sc[l] == 0.0 {
                    continue;
                }
                d += dot(nkl, &src[l]);
                for i in 0..NB {
                    u[i] += sc[l] * nkl[i];
                }
            }
            out_d[k] = d;
            out_u[k] = u;
        }
        Ok(())
    }

    fn dense(&self) -> Option<&[Vb]> {
        Some(&self.nf)
    }
}
