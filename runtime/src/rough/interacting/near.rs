//! Interaction sums at scale (interacting module docs, "Far field at scale"): the grid
//! far field ([`FarGrid`]) plus a sparse list of near corrections found with a uniform
//! cell list (periodic-aware: every image of the (2m+1)² block is searched). Memory is
//! O(N) at a fixed density: the grid, one stencil and self term per asperity, and the
//! pairs closer than r_near.
//!
//! For a pair image at distance r the sums hold, with G(r) the grid's value of the pair:
//! r ≥ r_near: G(r) (grid); r_c ≤ r < r_near: c(r) (the far model, exact Chebyshev
//! coefficients) − G(r) + G(r); r < r_c: law.g summed exactly (the exact near list,
//! as on the dense path) − G(r) + G(r). Each asperity's own stencil term (every image)
//! is removed from the grid sum: its self images go through the self part as before.

use super::far_field::{FarModel, NB, Vb, dot};
use super::far_grid::{FarGrid, Stencil};
use super::pair_sums::{GridInfo, LEAD, NearPairs, PairSums, Rows, Sources, Work};
use crate::fft::FftError;
use crate::resources::{MemoryLimit, ResourceError, bytes_for};
use crate::summits::Summit;
use rayon::prelude::*;

/// Memory of one near correction (image pair closer than r_near), bytes: stored once
/// (two indices, at most NB single-precision coefficients and the [`LEAD`] of the
/// preconditioner) and a margin for the exact list; the pairs of [`BUILD_BLOCK`]
/// sources in assembly come on top ([`FastSums::build`]).
pub(crate) const ENTRY_BYTES: u64 = 8 + 4 * (NB + LEAD) as u64 + 16;

/// Sources whose near pairs are assembled at once (in parallel) when the sums are built.
const BUILD_BLOCK: usize = 2048;
/// Memory per loaded asperity of the fast sums and of a Newton step on them (stencil,
/// self term, the energy state's vectors, the Krylov vectors), bytes.
pub(crate) const POINT_BYTES: u64 = 1024;

/// Errors of building the fast sums.
#[derive(Debug, thiserror::Error)]
pub(crate) enum FastError {
    #[error(transparent)]
    Memory(#[from] ResourceError),
    #[error(transparent)]
    Fft(#[from] FftError),
}

/// The grid far field and the near corrections of a set of candidates.
pub(crate) struct FastSums {
    pub grid: FarGrid,
    stencils: Vec<Stencil>,
    /// The corrections, one entry per pair p < q (images of a pair merged, sorted by
    /// (q, p)): the two indices and the M coefficients the grid keeps (`coef[e·M..(e+1)·M]`, single
    /// precision: rounding 6e-8 relative per pair, far below the far-field tolerance).
    pair: Vec<(u32, u32)>,
    coef: Vec<f32>,
    /// Per pair the far model's first [`LEAD`] coefficients summed over its images at
    /// r ≥ r_c (the pair's far-field N_kl to ~1e-3, for the preconditioner).
    lead: Vec<[f32; LEAD]>,
    /// The grid's self term of each asperity (removed from the grid sum).
    gself: Vec<Vb>,
    /// Image pairs carried by the grid or by the far model.
    pub modelled_pairs: usize,
}

/// Workspace of one evaluation of the fast sums: the grid's, and per thread the
/// partial sums of the near corrections.
pub(crate) struct GridWork {
    grid: super::far_grid::GridWork,
    parts: Vec<(Vec<f64>, Vec<Vb>)>,
}

/// What the builder returns besides the sums: the exact near list (p < q, r < r_c,
/// one entry per image, sorted by (q, p)).
pub(crate) type Exact = Vec<(usize, usize, f64)>;

/// Cell size of the grid: the minimiser of an estimate of the per-evaluation cost
/// (flops), near corrections (≈ 30 per directed entry, N ρ π r_near² entries with
/// r_near ≈ r_c + 12H, above the measured reach of the grid's error, 8–9H) against the FFTs
/// ((2NB + 2) padded transforms of (2L/H)² points, ≈ 1.5 log₂ flops per point).
/// H is at most a fifteenth of what is left of `reach` (m, the grid's largest near
/// radius) beyond r_c.
fn cell_size(n: usize, extent: (f64, f64), r_c: f64, reach: f64) -> f64 {
    let (lx, ly) = extent;
    let rho = n as f64 / (lx * ly);
    let top = (lx.max(ly) / 16.0).min((reach - r_c) / 15.0);
    let mut best = (f64::INFINITY, top);
    let mut h = top;
    while h > lx.max(ly) / 2048.0 {
        let rn = r_c + 12.0 * h;
        let near = NEAR_COST * n as f64 * rho * std::f64::consts::PI * rn * rn;
        let pts = 4.0 * (lx / h + 6.0) * (ly / h + 6.0);
        let fft = (2 * NB + 2) as f64 * pts * pts.log2() * 1.5;
        let cost = near + fft + 2.0 * 36.0 * NB as f64 * n as f64;
        if cost < best.0 {
            best = (cost, h);
        }
        h /= 1.1;
    }
    best.1
}

/// A uniform cell list of points in the sample (bucket side ≥ the search radius).
struct Buckets {
    side: (f64, f64),
    count: (i64, i64),
    start: Vec<usize>,
    items: Vec<usize>,
}

impl Buckets {
    fn new(pts: &[(f64, f64)], extent: (f64, f64), radius: f64) -> Buckets {
        let bx = ((extent.0 / radius).floor() as i64).clamp(1, 4096);
        let by = ((extent.1 / radius).floor() as i64).clamp(1, 4096);
        let side = (extent.0 / bx as f64, extent.1 / by as f64);
        let cell = |p: &(f64, f64)| {
            let i = ((p.0 / side.0).floor() as i64).clamp(0, bx - 1);
            let j = ((p.1 / side.1).floor() as i64).clamp(0, by - 1);
            (j * bx + i) as usize
        };
        let mut start = vec![0usize; (bx * by) as usize + 1];
        for p in pts {
            start[cell(p) + 1] += 1;
        }
        for i in 0..(bx * by) as usize {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut items = vec![0; pts.len()];
        for (k, p) in pts.iter().enumerate() {
            let c = cell(p);
            items[fill[c]] = k;
            fill[c] += 1;
        }
        Buckets {
            side,
            count: (bx, by),
            start,
            items,
        }
    }

    /// Calls `f(p)` for every point p in the buckets touching the disc (c, radius).
    fn around(&self, c: (f64, f64), radius: f64, mut f: impl FnMut(usize)) {
        let lo = |v: f64, s: f64| ((v - radius) / s).floor() as i64;
        let hi = |v: f64, s: f64| ((v + radius) / s).floor() as i64;
        let (i0, i1) = (
            lo(c.0, self.side.0).max(0),
            hi(c.0, self.side.0).min(self.count.0 - 1),
        );
        let (j0, j1) = (
            lo(c.1, self.side.1).max(0),
            hi(c.1, self.side.1).min(self.count.1 - 1),
        );
        for j in j0..=j1 {
            for i in i0..=i1 {
                let b = (j * self.count.0 + i) as usize;
                for &p in &self.items[self.start[b]..self.start[b + 1]] {
                    f(p);
                }
            }
        }
    }
}

impl FastSums {
    /// The fast sums of the candidates at `pts` (m) on a sample of sides `extent` (m)
    /// with `m` image cells, far model `far`, tolerance `tol` (module docs); None when no
    /// grid meets the tolerance (the caller sums densely). The exact near list is
    /// returned alongside. The storage is checked against `memory` first.
    pub fn build(
        summits: &[Summit],
        cand: &[usize],
        extent: (f64, f64),
        m: i64,
        far: &FarModel,
        tol: f64,
        memory: &MemoryLimit,
    ) -> Result<Option<(FastSums, Exact)>, FastError> {
        let n = cand.len();
        let pts: Vec<(f64, f64)> = cand.iter().map(|&k| (summits[k].x, summits[k].y)).collect();
        let h = cell_size(n, extent, far.r_c, FarGrid::reach(extent, m));
        let Some(grid) = FarGrid::build(far, extent, m, h, tol)? else {
            return Ok(None);
        };
        let (gx, gy, _) = grid.period();
        let (lx, ly) = extent;
        let rn = grid.r_near;
        let buckets = Buckets::new(&pts, extent, rn);
        // every image pair (p < q, shift s) closer than r_near, in order of q
        let visit = |q: usize, f: &mut dyn FnMut(usize, (i64, i64), f64)| {
            let (xq, yq) = pts[q];
            for sx in -m..=m {
                for sy in -m..=m {
                    let c = (xq + sx as f64 * lx, yq + sy as f64 * ly);
                    if c.0 < -rn || c.0 > lx + rn || c.1 < -rn || c.1 > ly + rn {
                        continue;
                    }
                    buckets.around(c, rn, |p| {
                        if p < q {
                            let r = (c.0 - pts[p].0).hypot(c.1 - pts[p].1);
                            if r < rn {
                                f(p, (sx, sy), r);
                            }
                        }
                    });
                }
            }
        };
        let mut count = 0u64;
        for q in 0..n {
            visit(q, &mut |_, _, _| count += 1);
        }
        memory.check(
            format!(
                "I model: grid far field ({} × {} cells) and {count} near corrections of {n} loaded asperities",
                gx, gy
            ),
            grid.bytes()
                .saturating_add(bytes_for(count, ENTRY_BYTES))
                .saturating_add(bytes_for(
                    // the rows of one block of sources in assembly (images separate)
                    (count / n.max(1) as u64 + 1) * BUILD_BLOCK as u64 * 2,
                    (4 + 8 * (NB + LEAD)) as u64,
                ))
                .saturating_add(bytes_for(n as u64, POINT_BYTES)),
        )?;
        let stencils: Vec<Stencil> = pts.iter().map(|&(x, y)| grid.stencil(x, y)).collect();
        let gself: Vec<Vb> = stencils.iter().map(|s| grid.self_term(s)).collect();
        // every pair p < q closer than r_near, by source q (in parallel, a block of
        // sources at a time): the correction c − G and the far model's leading
        // coefficients (images at r ≥ r_c) summed over its images, and the images closer
        // than r_c (the exact list). Pairs and exact entries come out sorted by (q, p).
        let mt = grid.near_terms;
        let mut pair: Vec<(u32, u32)> = Vec::with_capacity(count as usize);
        let mut coef: Vec<f32> = Vec::with_capacity(count as usize * mt);
        let mut lead: Vec<[f32; LEAD]> = Vec::with_capacity(count as usize);
        let mut exact = Vec::new();
        type Row = (Vec<(u32, Vb, [f64; LEAD])>, Vec<(usize, f64)>);
        for q0 in (0..n).step_by(BUILD_BLOCK) {
            let rows: Vec<Row> = (q0..(q0 + BUILD_BLOCK).min(n))
                .into_par_iter()
                .map(|q| {
                    let mut row: Vec<(u32, Vb, [f64; LEAD])> = Vec::new();
                    let mut ex = Vec::new();
                    visit(q, &mut |p, (sx, sy), r| {
                        // the pair seen from target p, source q shifted by s
                        let g = grid.pair(&stencils[p], &stencils[q], (sx * gx, sy * gy));
                        let mut c = [0.0; NB];
                        let mut l = [0.0; LEAD];
                        if r >= far.r_c {
                            far.accumulate(r, &mut c);
                            l.copy_from_slice(&c[..LEAD]);
                        } else {
                            ex.push((p, r));
                        }
                        for j in 0..NB {
                            c[j] -= g[j];
                        }
                        row.push((p as u32, c, l));
                    });
                    row.sort_unstable_by_key(|e| e.0);
                    row.dedup_by(|b, a| {
                        if a.0 == b.0 {
                            for j in 0..NB {
                                a.1[j] += b.1[j];
                            }
                            for j in 0..LEAD {
                                a.2[j] += b.2[j];
                            }
                            true
                        } else {
                            false
                        }
                    });
                    ex.sort_unstable_by_key(|a| a.0);
                    (row, ex)
                })
                .collect();
            for (i, (row, ex)) in rows.into_iter().enumerate() {
                let q = q0 + i;
                for (p, c, l) in row {
                    pair.push((p, q as u32));
                    coef.extend(c[..mt].iter().map(|&v| v as f32));
                    lead.push(l.map(|v| v as f32));
                }
                exact.extend(ex.into_iter().map(|(p, r)| (p, q, r)));
            }
        }
        let blocks = ((2 * m + 1) * (2 * m + 1)) as usize;
        let modelled_pairs = (n * n.saturating_sub(1) / 2) * blocks - exact.len();
        Ok(Some((
            FastSums {
                grid,
                stencils,
                pair,
                coef,
                lead,
                gself,
                modelled_pairs,
            },
            exact,
        )))
    }

    /// A workspace for [`apply_grid`](Self::apply_grid).
    fn work(&self) -> GridWork {
        let n = self.stencils.len();
        GridWork {
            grid: self.grid.work(),
            parts: (0..rayon::current_num_threads().clamp(1, 8))
                .map(|_| (vec![0.0; n], vec![[0.0; NB]; n]))
                .collect(),
        }
    }

    /// out_d[k] = Σ_{l≠k} N_kl·src[l] and out_u[k] = Σ_{l≠k} N_kl sc[l] over every
    /// image pair not in the exact near list (N_kl: the far-field Chebyshev sums of the
    /// pair, interacting module docs), for every k. Sources with sc[l] = 0 must have
    /// src[l] = 0. The pair list is split in one part per thread, each summed into its
    /// own outputs (every pair read once, for both of its directions). `sources_only`:
    /// only the outputs of the sources (sc[k] ≠ 0) are wanted (a Jacobian–vector
    /// product on the active set); the others are left at zero.
    fn apply_grid(
        &self,
        src: &[Vb],
        sc: &[f64],
        out_d: &mut [f64],
        out_u: &mut [Vb],
        w: &mut GridWork,
        sources_only: bool,
    ) -> Result<(), FftError> {
        out_d.iter_mut().for_each(|v| *v = 0.0);
        out_u.iter_mut().for_each(|v| *v = [0.0; NB]);
        self.grid.apply(
            &self.stencils,
            src,
            sc,
            out_d,
            out_u,
            &mut w.grid,
            sources_only,
        )?;
        let mt = self.grid.near_terms;
        let chunk = self.pair.len().div_ceil(w.parts.len()).max(1);
        w.parts
            .par_iter_mut()
            .zip(self.pair.par_chunks(chunk))
            .zip(self.coef.par_chunks(chunk * mt))
            .for_each(|(((pd, pu), pairs), coef)| {
                pd.iter_mut().for_each(|v| *v = 0.0);
                pu.iter_mut().for_each(|v| *v = [0.0; NB]);
                macro_rules! sums {
                    ($($m:literal)*) => {
                        match mt {
                            $($m => pair_sums::<$m>(pairs, coef, src, sc, pd, pu, sources_only),)*
                            _ => {}
                        }
                    };
                }
                // a kernel per count of coefficients (mt ∈ 1..=NB, NB = 12)
                sums!(1 2 3 4 5 6 7 8 9 10 11 12);
            });
        let parts = &w.parts;
        out_d
            .par_iter_mut()
            .zip(out_u.par_iter_mut())
            .enumerate()
            .for_each(|(k, (od, ou))| {
                if sources_only && sc[k] == 0.0 {
                    return;
                }
                if sc[k] != 0.0 {
                    let gs = &self.gself[k];
                    *od -= dot(gs, &src[k]);
                    for j in 0..NB {
                        ou[j] -= sc[k] * gs[j];
                    }
                }
                for (pd, pu) in parts {
                    *od += pd[k];
                    for j in 0..self.grid.near_terms {
                        ou[j] += pu[k][j];
                    }
                }
            });
        Ok(())
    }
}

/// The grid path of the pair sums.
impl PairSums for FastSums {
    fn apply(
        &self,
        Sources { src, sc }: Sources,
        _: Rows,
        (out_d, out_u): (&mut [f64], &mut [Vb]),
        work: &mut Work,
        sources_only: bool,
    ) -> Result<(), String> {
        let w = work
            .get_or_insert_with(|| Box::new(self.work()))
            .downcast_mut::<GridWork>()
            .ok_or("the workspace of another pair-sum path")?;
        self.apply_grid(src, sc, out_d, out_u, w, sources_only)
            .map_err(|e| e.to_string())
    }

    fn grid(&self) -> Option<GridInfo> {
        let (gx, gy, _) = self.grid.period();
        Some(GridInfo {
            cells: (gx as usize, gy as usize),
            near_radius: self.grid.r_near,
            worst: self.grid.worst,
        })
    }

    fn near_pairs(&self) -> Option<NearPairs<'_>> {
        Some((&self.pair, &self.lead))
    }
}

/// The near corrections of one part of the pair list for both directions of every pair
/// (M coefficients per pair): pd[k] += Σ c·src[l], pu[k] += sc[l] c. With
/// `sources_only` the outputs of asperities that are not sources are skipped.
#[inline(never)]
fn pair_sums<const M: usize>(
    pairs: &[(u32, u32)],
    coef: &[f32],
    src: &[Vb],
    sc: &[f64],
    pd: &mut [f64],
    pu: &mut [Vb],
    sources_only: bool,
) {
    for (&(p, q), c) in pairs.iter().zip(coef.chunks_exact(M)) {
        let (p, q) = (p as usize, q as usize);
        let (sp, sq) = (sc[p], sc[q]);
        if sp == 0.0 && sq == 0.0 {
            continue;
        }
        let c: [f64; M] = std::array::from_fn(|j| f64::from(c[j]));
        // target p from source q, then target q from source p
        for (t, s, y, own) in [(p, sq, &src[q], sp), (q, sp, &src[p], sq)] {
            if s == 0.0 || (sources_only && own == 0.0) {
                continue;
            }
            let mut d = 0.0;
            for j in 0..M {
                d += c[j] * y[j];
                pu[t][j] += s * c[j];
            }
            pd[t] += d;
        }
    }
}

const _: () = assert!(NB == 12, "pair_sums dispatch covers 1..=12 coefficients");

/// Cost of one directed near entry in flop-equivalents for [`cell_size`].
const NEAR_COST: f64 = 30.0;
