//! The far field of the interaction sums on a coarse grid (interacting module docs,
//! "Far field at scale"): every source's Chebyshev vector is spread onto a uniform grid
//! of cell H with tensor 6-point Lagrange weights, convolved by FFT with the far-field
//! kernels c_j(r) sampled at the grid lags (the (2m+1)² image block summed into the
//! kernel, zero padding: a linear, never circular, convolution) and interpolated back
//! with the same weights. Pairs closer than [`FarGrid::r_near`] are corrected exactly
//! (the grid's own value of the pair subtracted, see [`FarGrid::pair`]), so the grid
//! only carries pairs at r ≥ r_near, where its interpolation error is measured when it
//! is built and kept below half the far-field tolerance.
//!
//! Cost per evaluation: (2M + 2) FFTs of the padded grid, M ≤ NB the Chebyshev terms
//! kept on the grid: those whose magnitude beyond about r_c + 7H (where the grid's own
//! pairs begin) can matter at the tolerance; the near corrections keep every term that
//! can matter beyond r_c. Memory O(grid + N).

use super::far_field::{FarModel, NB, Vb, dot};
use crate::fft::{Complex, FftError, RealFft2};
use rayon::prelude::*;

/// Distance beyond r_c (cells) from which the grid's truncation to fewer Chebyshev
/// terms than the near corrections is judged: about where the grid's interpolation
/// error lets its own pairs begin (r_near ≈ r_c + 7…9H, measured).
const GRID_REACH: f64 = 7.0;

/// Largest truncation error of the grid's Chebyshev terms beyond r_c + GRID_REACH·H, as
/// a fraction of the far-field tolerance (the grid's measured error, truncation
/// included, stays below half the tolerance).
const GRID_TRUNCATION: f64 = 0.3;

/// Lagrange points per direction of the spreading stencil.
pub(crate) const P: usize = 6;
/// Offset of the first stencil node from floor(x/H).
const LEFT: i64 = 2;
/// Half width (cells) of the correlation of two stencils: lags −(P−1)..=(P−1).
const HW: i64 = P as i64 - 1;

/// The stencil of one point: its first node (ix, iy) and the weights along x and y.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stencil {
    pub node: (i64, i64),
    pub wx: [f64; P],
    pub wy: [f64; P],
}

/// 6-point Lagrange weights at fractional position t ∈ [0, 1) for nodes −2..=3.
fn lagrange(t: f64) -> [f64; P] {
    let mut w = [1.0; P];
    for (i, wi) in w.iter_mut().enumerate() {
        let xi = i as f64 - LEFT as f64;
        for j in 0..P {
            if j != i {
                let xj = j as f64 - LEFT as f64;
                *wi *= (t - xj) / (xi - xj);
            }
        }
    }
    w
}

/// Correlation C[d + P − 1] = Σ_{b − a = d} u[a] v[b], d = −(P−1)..=(P−1).
fn correlate(u: &[f64; P], v: &[f64; P]) -> [f64; 2 * P - 1] {
    let mut c = [0.0; 2 * P - 1];
    for (a, ua) in u.iter().enumerate() {
        for (b, vb) in v.iter().enumerate() {
            c[b + P - 1 - a] += ua * vb;
        }
    }
    c
}

/// Next size ≥ n with no prime factor above 5 (fast FFT lengths).
fn smooth_size(n: usize) -> usize {
    let mut m = n.max(1);
    loop {
        let mut k = m;
        for p in [2, 3, 5] {
            while k.is_multiple_of(p) {
                k /= p;
            }
        }
        if k == 1 {
            return m;
        }
        m += 1;
    }
}

/// Check radii of the far model's range a ∈ [0, A] (as its own validation): the error
/// of a coefficient vector in point-force units.
struct Checks {
    basis: Vec<(f64, Vb, Vb)>,
}

impl Checks {
    fn new(far: &FarModel) -> Checks {
        let basis = (0..=2 * NB)
            .map(|k| {
                let x = (std::f64::consts::PI * k as f64 / (2 * NB) as f64).cos();
                let a = (far.a_max * (0.5 * (1.0 + x)).max(0.0).sqrt()).max(1e-4 * far.a_max);
                let (l, dl) = far.basis(a);
                (a, l, dl)
            })
            .collect();
        Checks { basis }
    }

    /// max over the check radii of |Σ_j dv_j T_j(a)| and |(a/3) Σ_j dv_j T_j'(a)|: the
    /// errors of (3r/4)W and (r/4) a ∂W/∂a for coefficient errors dv = (3r/4)Δc.
    fn error(&self, dv: &Vb) -> f64 {
        self.basis.iter().fold(0.0, |w, (a, l, dl)| {
            w.max(dot(dv, l).abs()).max((a / 3.0 * dot(dv, dl)).abs())
        })
    }
}

/// The grid part of the interaction sums (module docs).
pub(crate) struct FarGrid {
    /// Cell sizes (m).
    pub h: (f64, f64),
    /// Cells per side G (the sample is G cells; periodic images shift by G).
    cells: (i64, i64),
    /// Image cells m of the (2m+1)² block.
    m: i64,
    /// Data nodes per side, G + P − 1.
    nd: (usize, usize),
    plan: RealFft2,
    /// Spectral kernels of the kept Chebyshev terms (half-spectrum layout, 1/(NY·NX)
    /// included).
    spectra: Vec<Vec<f64>>,
    /// Chebyshev terms on the grid.
    pub terms: usize,
    /// Chebyshev terms of the near corrections (≥ `terms`).
    pub near_terms: usize,
    /// Pairs closer than this (m) are corrected exactly.
    pub r_near: f64,
    /// Single-image kernel at lags |dx|, |dy| ≤ win (cells), row-major (2win+1)².
    win: i64,
    single: Vec<Vb>,
    /// Image-summed kernel at lags |dx|, |dy| ≤ P − 1 (the self term).
    summed: Vec<Vb>,
    /// Largest measured error of the grid beyond r_near (point-force units).
    pub worst: f64,
}

/// Workspace of one grid evaluation: one field and one transform buffer per kept
/// Chebyshev term and one for the scalar sources (the terms run in parallel).
pub(crate) struct GridWork {
    ffts: Vec<crate::fft::Fft2Work>,
    /// Fields of the terms j < M, then the scalar field (row-major data blocks).
    fields: Vec<f64>,
    acc: Vec<Complex<f64>>,
    spec_q: Vec<Complex<f64>>,
}

impl FarGrid {
    /// The grid for a sample of sides `extent` (m) under `m` image cells, cell about `h`
    /// (m), for the far model `far` (regularised below its cut-off r_c), with the near
    /// radius grown until the measured error is below `tol`/2; None if it never is.
    pub fn build(
        far: &FarModel,
        extent: (f64, f64),
        m: i64,
        h: f64,
        tol: f64,
    ) -> Result<Option<FarGrid>, FftError> {
        let (lx, ly) = extent;
        let gx = ((lx / h).ceil() as i64).max(16);
        let gy = ((ly / h).ceil() as i64).max(16);
        let hh = (lx / gx as f64, ly / gy as f64);
        let hmax = hh.0.max(hh.1);
        let checks = Checks::new(far);
        // near terms: the fewest leading Chebyshev terms whose tail stays below tol/20 at
        // every sampled distance beyond r_c (the near corrections carry them); grid terms:
        // the same beyond r_c + GRID_REACH·H, where the grid's own pairs begin (its
        // interpolation error keeps r_near beyond that), at most the near terms. The
        // measured error below includes the truncation.
        let r_grid = far.r_c + GRID_REACH * hmax;
        let mut tails = [0.0f64; NB + 1];
        let mut tails_grid = [0.0f64; NB + 1];
        let mut r = far.r_c;
        while r <= far.r_hi {
            let mut acc = [0.0; NB];
            far.accumulate(r, &mut acc);
            let v = acc.map(|c| 0.75 * r * c);
            for m in 0..=NB {
                let mut dv = v;
                dv[..m.min(NB)].iter_mut().for_each(|x| *x = 0.0);
                let e = checks.error(&dv);
                tails[m] = tails[m].max(e);
                if r >= r_grid {
                    tails_grid[m] = tails_grid[m].max(e);
                }
            }
            r *= 1.05;
        }
        let near_terms = (1..=NB).find(|&m| tails[m] <= 0.05 * tol).unwrap_or(NB);
        let terms = (1..=near_terms)
            .find(|&m| tails_grid[m] <= GRID_TRUNCATION * tol)
            .unwrap_or(near_terms);
        let nd = ((gx + HW) as usize, (gy + HW) as usize);
        let ny = smooth_size(2 * nd.1 - 1);
        let nx = smooth_size(2 * nd.0 - 1);
        let plan = RealFft2::padded((ny, nx), (nd.1, nd.0))?.single_lane();
        let full = RealFft2::new(ny, nx)?;
        let mut work = full.work();
        let kernel = |dx: i64, dy: i64, images: bool| -> Vb {
            let mut acc = [0.0; NB];
            let s = if images { m } else { 0 };
            for sx in -s..=s {
                for sy in -s..=s {
                    let x = (dx + sx * gx) as f64 * hh.0;
                    let y = (dy + sy * gy) as f64 * hh.1;
                    far.accumulate(x.hypot(y).max(far.r_c), &mut acc);
                }
            }
            acc
        };
        let norm = 1.0 / (nx * ny) as f64;
        let mut lags = vec![[0.0; NB]; nx * ny];
        for iy in 0..ny {
            let dy = if iy < ny.div_ceil(2) {
                iy as i64
            } else {
                iy as i64 - ny as i64
            };
            for ix in 0..nx {
                let dx = if ix < nx.div_ceil(2) {
                    ix as i64
                } else {
                    ix as i64 - nx as i64
                };
                if dx.abs() < nd.0 as i64 && dy.abs() < nd.1 as i64 {
                    lags[iy * nx + ix] = kernel(dx, dy, true);
                }
            }
        }
        let mut spectra = Vec::with_capacity(terms);
        let mut real = vec![0.0; nx * ny];
        for j in 0..terms {
            for (v, l) in real.iter_mut().zip(&lags) {
                *v = l[j];
            }
            full.forward(&real, &mut work)?;
            spectra.push(work.spec.iter().map(|c| c.re * norm).collect());
        }
        drop(lags);
        let mut summed = Vec::with_capacity(((2 * HW + 1) * (2 * HW + 1)) as usize);
        for dy in -HW..=HW {
            for dx in -HW..=HW {
                summed.push(kernel(dx, dy, true));
            }
        }
        let mut grid = FarGrid {
            h: hh,
            cells: (gx, gy),
            m,
            nd,
            plan,
            spectra,
            terms,
            near_terms,
            r_near: far.r_c + 4.0 * hmax,
            win: 0,
            single: Vec::new(),
            summed,
            worst: 0.0,
        };
        while grid.r_near < Self::reach(extent, m) {
            grid.window(far);
            let e = grid.measure(far, &checks);
            if e <= 0.5 * tol {
                grid.worst = e;
                return Ok(Some(grid));
            }
            grid.r_near += hmax;
        }
        Ok(None)
    }

    /// The largest near radius (m) a grid may have: half the sample (with its images).
    pub fn reach(extent: (f64, f64), m: i64) -> f64 {
        0.5 * extent.0.min(extent.1) * (2 * m + 1) as f64
    }

    /// Fills the single-image kernel window for the current r_near.
    fn window(&mut self, far: &FarModel) {
        let (hmin, hmax) = (self.h.0.min(self.h.1), self.h.0.max(self.h.1));
        self.win = ((self.r_near + 3.0 * hmax) / hmin).ceil() as i64 + P as i64 + 2;
        let w = self.win;
        self.single.clear();
        for dy in -w..=w {
            for dx in -w..=w {
                let x = dx as f64 * self.h.0;
                let y = dy as f64 * self.h.1;
                let mut acc = [0.0; NB];
                far.accumulate(x.hypot(y).max(far.r_c), &mut acc);
                self.single.push(acc);
            }
        }
    }

    /// Largest error of the grid against the far model on a fixed sample of pairs at
    /// r_near … r_near + 2H (point-force units, [`Checks::error`]).
    fn measure(&self, far: &FarModel, checks: &Checks) -> f64 {
        let mut seed: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let hmax = self.h.0.max(self.h.1);
        let mut worst: f64 = 0.0;
        for _ in 0..400 {
            let x0 = (next() + 0.5 * self.cells.0 as f64) * self.h.0;
            let y0 = (next() + 0.5 * self.cells.1 as f64) * self.h.1;
            let r = self.r_near + 2.0 * hmax * next();
            let th = std::f64::consts::TAU * next();
            let (x1, y1) = (x0 + r * th.cos(), y0 + r * th.sin());
            let (a, b) = (
                self.stencil_in(x0, y0, false),
                self.stencil_in(x1, y1, false),
            );
            let g = self.pair(&a, &b, (0, 0));
            let mut exact = [0.0; NB];
            far.accumulate((x1 - x0).hypot(y1 - y0), &mut exact);
            let mut dv = [0.0; NB];
            for j in 0..NB {
                dv[j] = 0.75 * r * (g[j] - exact[j]);
            }
            worst = worst.max(checks.error(&dv));
        }
        worst
    }

    /// The stencil of the point (x, y) (m, inside the sample).
    pub fn stencil(&self, x: f64, y: f64) -> Stencil {
        self.stencil_in(x, y, true)
    }

    /// The stencil of (x, y), its first node kept inside the data grid when `clamp`.
    fn stencil_in(&self, x: f64, y: f64, clamp: bool) -> Stencil {
        let place = |v: f64, h: f64, g: i64| {
            let u = v / h;
            let i = u.floor() as i64;
            let i = if clamp { i.clamp(0, g - 1) } else { i };
            (i, lagrange(u - i as f64))
        };
        let (ix, wx) = place(x, self.h.0, self.cells.0);
        let (iy, wy) = place(y, self.h.1, self.cells.1);
        Stencil {
            node: (ix, iy),
            wx,
            wy,
        }
    }

    /// The grid's value (Chebyshev coefficients, 1/m; terms ≥ M are zero) of the pair
    /// target `a`, source `b` shifted by `shift` cells (a periodic image), single image.
    /// Every pair the near corrections touch lies within the window.
    pub fn pair(&self, a: &Stencil, b: &Stencil, shift: (i64, i64)) -> Vb {
        let cx = correlate(&a.wx, &b.wx);
        let cy = correlate(&a.wy, &b.wy);
        let lx = b.node.0 + shift.0 - a.node.0;
        let ly = b.node.1 + shift.1 - a.node.1;
        self.window_sum(&cx, &cy, (lx, ly), &self.single, self.win)
    }

    /// The grid's self term of a point: its stencil against itself under the
    /// image-summed kernel (every image, the point itself included).
    pub fn self_term(&self, a: &Stencil) -> Vb {
        let cx = correlate(&a.wx, &a.wx);
        let cy = correlate(&a.wy, &a.wy);
        self.window_sum(&cx, &cy, (0, 0), &self.summed, HW)
    }

    fn window_sum(
        &self,
        cx: &[f64; 2 * P - 1],
        cy: &[f64; 2 * P - 1],
        lag: (i64, i64),
        table: &[Vb],
        w: i64,
    ) -> Vb {
        let mut out = [0.0; NB];
        let side = 2 * w + 1;
        for (b, &vy) in cy.iter().enumerate() {
            let dy = lag.1 + b as i64 - HW;
            for (a, &vx) in cx.iter().enumerate() {
                let dx = lag.0 + a as i64 - HW;
                if dx.abs() > w || dy.abs() > w {
                    continue;
                }
                let k = &table[((dy + w) * side + dx + w) as usize];
                let c = vx * vy;
                for j in 0..self.terms {
                    out[j] += c * k[j];
                }
            }
        }
        out
    }

    /// Cells per side of the sample and image cells per side.
    pub fn period(&self) -> (i64, i64, i64) {
        (self.cells.0, self.cells.1, self.m)
    }

    /// Bytes held (kernels and windows) and per evaluation (workspace).
    pub fn bytes(&self) -> u64 {
        let spec = self.plan.spectrum_len() as u64;
        (self.spectra.len() as u64) * spec * 8
            + ((self.single.len() + self.summed.len()) as u64) * (NB as u64) * 8
            + spec * 16 * (self.terms as u64 + 3)
            + ((self.terms + 1) * self.nd.0 * self.nd.1) as u64 * 8
    }

    /// A workspace for [`apply`](Self::apply).
    pub fn work(&self) -> GridWork {
        let s = self.plan.spectrum_len();
        GridWork {
            ffts: (0..=self.terms).map(|_| self.plan.work()).collect(),
            fields: vec![0.0; (self.terms + 1) * self.nd.0 * self.nd.1],
            acc: vec![Complex::default(); s],
            spec_q: vec![Complex::default(); s],
        }
    }

    /// Adds the grid's sums to the outputs: `out_d[k] += Σ_l Σ_j K_j(k, l) src[l][j]`
    /// and `out_u[k][j] += Σ_l K_j(k, l) sc[l]` over every source l (k itself and all
    /// images included: the caller removes the self term and corrects near pairs), for
    /// the points with stencils `st`. The M + 1 fields are spread, transformed and
    /// gathered in parallel (rayon), one transform per field and direction.
    /// `sources_only`: gather only at the sources (sc ≠ 0).
    #[allow(clippy::too_many_arguments)]
    pub fn apply(
        &self,
        st: &[Stencil],
        src: &[Vb],
        sc: &[f64],
        out_d: &mut [f64],
        out_u: &mut [Vb],
        w: &mut GridWork,
        sources_only: bool,
    ) -> Result<(), FftError> {
        let (ndx, npts, terms) = (self.nd.0, self.nd.0 * self.nd.1, self.terms);
        let weights = |s: &Stencil| -> [[f64; P]; P] { s.wy.map(|wy| s.wx.map(|wx| wx * wy)) };
        let base = |s: &Stencil, b: usize| (s.node.1 as usize + b) * ndx + s.node.0 as usize;
        // spread field j < M (the sources' term j) or M (the scalar sources), and
        // transform it
        w.fields
            .par_chunks_mut(npts)
            .zip(w.ffts.par_iter_mut())
            .enumerate()
            .try_for_each(|(j, (field, fft))| {
                field.iter_mut().for_each(|v| *v = 0.0);
                for (l, s) in st.iter().enumerate() {
                    if sc[l] == 0.0 {
                        continue;
                    }
                    let y = if j < terms { src[l][j] } else { sc[l] };
                    for (b, row) in weights(s).iter().enumerate() {
                        let r0 = base(s, b);
                        for (v, c) in field[r0..r0 + P].iter_mut().zip(row) {
                            *v += y * c;
                        }
                    }
                }
                self.plan.forward(field, fft)
            })?;
        // D: Σ_j K_j · src_j in the spectrum; U: the scalar spectrum kept for every K_j
        {
            let specs: Vec<&[Complex<f64>]> = w.ffts.iter().map(|f| &f.spec[..]).collect();
            let kernels = &self.spectra;
            w.acc.par_chunks_mut(4096).enumerate().for_each(|(c, out)| {
                let o = c * 4096;
                for (i, acc) in out.iter_mut().enumerate() {
                    let mut v = Complex::default();
                    for j in 0..terms {
                        v += specs[j][o + i] * kernels[j][o + i];
                    }
                    *acc = v;
                }
            });
            w.spec_q.copy_from_slice(specs[terms]);
        }
        let (acc, spec_q) = (&w.acc, &w.spec_q);
        w.fields
            .par_chunks_mut(npts)
            .zip(w.ffts.par_iter_mut())
            .enumerate()
            .try_for_each(|(j, (field, fft))| {
                if j < terms {
                    for ((o, s), kv) in fft.spec.iter_mut().zip(spec_q).zip(&self.spectra[j]) {
                        *o = s * kv;
                    }
                } else {
                    fft.spec.copy_from_slice(acc);
                }
                self.plan.inverse(field, fft)
            })?;
        let fields = &w.fields;
        out_d
            .par_iter_mut()
            .zip(out_u.par_iter_mut())
            .zip(st.par_iter())
            .zip(sc.par_iter())
            .for_each(|(((od, ou), s), &q)| {
                if sources_only && q == 0.0 {
                    return;
                }
                let ww = weights(s);
                for (b, row) in ww.iter().enumerate() {
                    let r0 = base(s, b);
                    let at = |j: usize| &fields[j * npts + r0..j * npts + r0 + P];
                    *od += dot6(row, at(terms));
                    for (j, uj) in ou[..terms].iter_mut().enumerate() {
                        *uj += dot6(row, at(j));
                    }
                }
            });
        Ok(())
    }
}

/// Σ_i w_i f_i over one stencil row.
#[inline]
fn dot6(w: &[f64; P], f: &[f64]) -> f64 {
    w.iter().zip(f).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lagrange_reproduces_quintics() {
        for t in [0.0, 0.3, 0.77] {
            let w = lagrange(t);
            for p in 0..6 {
                let s: f64 = (0..6).map(|i| w[i] * (i as f64 - 2.0).powi(p)).sum();
                assert!((s - t.powi(p)).abs() < 1e-12, "{t} {p} {s}");
            }
        }
    }

    #[test]
    fn smooth_sizes() {
        assert_eq!(smooth_size(7), 8);
        assert_eq!(smooth_size(121), 125);
        assert_eq!(smooth_size(1), 1);
    }
}
