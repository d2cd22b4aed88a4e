//! The one 2-D FFT helper of the workspace, re-exported as `strata_runtime::fft` (feature
//! `spectral`): real-to-complex and complex-to-real transforms of real ny×nx row-major arrays,
//! realfft along the rows and rustfft along the columns, rows and columns in parallel (rayon)
//! on large grids.
//! Used by surface generation and by the boundary-element solver (strata-bem).
//!
//! # Layout and conventions
//! A plan [`RealFft2`] transforms on an `NY × NX` grid (any sizes ≥ 1). The half spectrum is
//! stored transposed, `spec[kx · NY + ky]`, kx ∈ 0..=NX/2, ky ∈ 0..NY, so that the column
//! transforms run on contiguous memory:
//!
//! ```text
//!   Z(kx, ky) = Σ_{i<NY, j<NX} z[i, j] · exp(−2πi (ky·i/NY + kx·j/NX))      (forward)
//!   z[i, j]   = Σ_{ky, all kx} Z(kx, ky) · exp(+2πi (ky·i/NY + kx·j/NX))    (inverse)
//! ```
//!
//! Neither direction is normalised (the inverse of the forward is NX·NY times the input).
//! The real input may occupy only the top-left `ny × nx` block of the grid (the rest is
//! zero, as in the zero-padded convolution of a non-periodic field): the rows that are
//! all zero are not transformed, and the inverse writes only that block.

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

use std::sync::Arc;

use rayon::prelude::*;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
pub use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

/// Grids with fewer points than this run on one thread (threads cost more than they save).
const PARALLEL_MIN_POINTS: usize = 128 * 128;
/// Columns transposed per block (cache lines of the row spectra).
const BLOCK: usize = 16;

/// A plan for 2-D real FFTs on an `NY × NX` grid with the data in the top-left
/// `ny × nx` block (see the module docs).
pub struct RealFft2 {
    grid: (usize, usize),
    data: (usize, usize),
    half: usize,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
    col_fwd: Arc<dyn Fft<f64>>,
    col_inv: Arc<dyn Fft<f64>>,
    lanes: usize,
}

impl std::fmt::Debug for RealFft2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RealFft2")
            .field("grid", &self.grid)
            .field("data", &self.data)
            .field("lanes", &self.lanes)
            .finish_non_exhaustive()
    }
}

/// Buffers of one transform; make one per thread of the caller with [`RealFft2::work`].
/// Holding it across calls means no allocation per transform.
pub struct Fft2Work {
    /// Row spectra, `ny × (NX/2 + 1)`: the one grid-sized buffer of a convolution (its
    /// column stage runs in place on them, a block of columns at a time).
    rows: Vec<Complex<f64>>,
    /// The transposed half spectrum, `(NX/2 + 1) × NY`, of [`RealFft2::forward`] and
    /// [`RealFft2::inverse`]; empty in the buffers of [`RealFft2::convolution_work`].
    pub spec: Vec<Complex<f64>>,
    lanes: Vec<Lane>,
}

/// Per-thread scratch of one chunk of rows or columns.
struct Lane {
    real: Vec<f64>,
    scratch: Vec<Complex<f64>>,
    /// [`BLOCK`] column lines (NY values each) gathered from the row spectra.
    lines: Vec<Complex<f64>>,
}

/// A real Fourier multiplier of a convolution, on the half spectrum.
#[derive(Clone, Copy, Debug)]
pub enum Multiplier<'a> {
    /// `kernel[kx · NY + ky]`, normalisation included.
    Half(&'a [f64]),
    /// A kernel even in ky held once for ky and NY − ky: `table[kx · (NY/2 + 1) + fy]`
    /// with fy = min(ky, NY − ky), half the memory of [`Multiplier::Half`]. The
    /// multiplier is s·t (`inverse` false) or s²/(s·t) where s·t > 0, else 0 (`inverse`
    /// true: the inverse operator from the same table), s = `scale`.
    Folded {
        /// The table, (NX/2 + 1)·(NY/2 + 1) values.
        table: &'a [f64],
        /// The factor s applied to each value (e.g. the normalisation 1/(NX·NY)).
        scale: f64,
        /// Whether the multiplier is the inverse s²/(s·t).
        inverse: bool,
    },
}

impl<'a> From<&'a [f64]> for Multiplier<'a> {
    fn from(kernel: &'a [f64]) -> Self {
        Multiplier::Half(kernel)
    }
}

impl<'a> From<&'a Vec<f64>> for Multiplier<'a> {
    fn from(kernel: &'a Vec<f64>) -> Self {
        Multiplier::Half(kernel)
    }
}

impl Multiplier<'_> {
    /// Values it holds for a grid with NY rows and NX/2 + 1 = `half` kx lines.
    fn expected_len(&self, gy: usize, half: usize) -> usize {
        match self {
            Multiplier::Half(_) => half * gy,
            Multiplier::Folded { .. } => half * (gy / 2 + 1),
        }
    }

    fn len(&self) -> usize {
        match self {
            Multiplier::Half(k) => k.len(),
            Multiplier::Folded { table, .. } => table.len(),
        }
    }

    /// Multiplies the kx line `line` (NY values) by the multiplier.
    #[inline(always)]
    fn apply(&self, kx: usize, line: &mut [Complex<f64>]) {
        let gy = line.len();
        match *self {
            Multiplier::Half(kernel) => {
                for (v, &kv) in line.iter_mut().zip(&kernel[kx * gy..(kx + 1) * gy]) {
                    *v *= kv;
                }
            }
            Multiplier::Folded {
                table,
                scale,
                inverse,
            } => {
                let hy = gy / 2 + 1;
                let t = &table[kx * hy..(kx + 1) * hy];
                let value = |x: f64| {
                    let k = x * scale;
                    if !inverse {
                        k
                    } else if k > 0.0 {
                        scale * scale / k
                    } else {
                        0.0
                    }
                };
                for (ky, v) in line.iter_mut().enumerate() {
                    let fy = if ky <= gy / 2 { ky } else { gy - ky };
                    *v *= value(t[fy]);
                }
            }
        }
    }
}

/// Errors of the plan: only wrong sizes (a bug of the caller), reported, never a panic.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FftError {
    #[error(
        "2-D FFT: grid {grid_rows}×{grid_cols} must have sides ≥ 1 holding the {rows}×{cols} data"
    )]
    Shape {
        grid_rows: usize,
        grid_cols: usize,
        rows: usize,
        cols: usize,
    },
    #[error("2-D FFT: buffer `{what}` has {got} values, expected {expected}")]
    Buffer {
        what: &'static str,
        got: usize,
        expected: usize,
    },
}

/// Splits each of K row-major arrays (ny·nx) into the row chunks of `lanes` lanes
/// (`rows` rows each, the last one shorter or empty).
fn lane_chunks<const K: usize>(
    fields: [&mut [f64]; K],
    rows: usize,
    nx: usize,
    lanes: usize,
) -> Vec<[&mut [f64]; K]> {
    let mut iters = fields.map(|f| f.chunks_mut((rows * nx).max(1)));
    (0..lanes)
        .map(|_| std::array::from_fn(|j| iters[j].next().unwrap_or(&mut [])))
        .collect()
}

/// A lane's index, its columns of every row of the row spectra, and its scratch.
type LaneCols<'a> = (usize, (Vec<&'a mut [Complex<f64>]>, &'a mut Lane));

/// A lane's row spectra, its chunks of the K fields, and its scratch.
type LaneRows<'a, const K: usize> = ((&'a mut [Complex<f64>], [&'a mut [f64]; K]), &'a mut Lane);

/// Row `r` (nx values) of each of a lane's K chunks.
fn row_of<'b, const K: usize>(
    chunks: &'b mut [&mut [f64]; K],
    r: usize,
    nx: usize,
) -> [&'b mut [f64]; K] {
    chunks.each_mut().map(|c| &mut c[r * nx..(r + 1) * nx])
}

/// Per-row accumulators of [`RealFft2::convolve_with`], combined over rows.
pub trait Merge: Default + Send {
    /// The combination of two partial results (e.g. sums and maxima).
    fn merge(self, other: Self) -> Self;
}

impl Merge for () {
    fn merge(self, _: Self) -> Self {}
}

impl Merge for f64 {
    fn merge(self, other: Self) -> Self {
        self + other
    }
}

impl<const N: usize> Merge for [f64; N]
where
    [f64; N]: Default,
{
    fn merge(mut self, other: Self) -> Self {
        for (a, b) in self.iter_mut().zip(other) {
            *a += b;
        }
        self
    }
}

/// The arrays of one [`RealFft2::convolve_with`]: `data` and `out` (ny·nx, row-major,
/// handed row by row to the fill and drain hooks), the kernel in the half-spectrum
/// layout (normalisation included) and its (0, 0) entry `dc`.
pub struct RowPasses<'a> {
    /// Row source of the fill hook (ny·nx), which may rewrite it.
    pub data: &'a mut [f64],
    /// Row destination of the drain hook (ny·nx).
    pub out: &'a mut [f64],
    /// The kernel ([`Multiplier`]).
    pub kernel: Multiplier<'a>,
    /// Value used in place of the (0, 0) kernel entry.
    pub dc: f64,
}

/// The arrays of one [`RealFft2::convolve_fields`]: K row-major ny·nx fields handed row
/// by row, all mutable, to both hooks; the kernel in the half-spectrum layout
/// (normalisation included) and its (0, 0) entry `dc`.
pub struct Fields<'a, const K: usize> {
    /// The fields (each ny·nx).
    pub fields: [&'a mut [f64]; K],
    /// The kernel ([`Multiplier`]).
    pub kernel: Multiplier<'a>,
    /// Value used in place of the (0, 0) kernel entry.
    pub dc: f64,
}

impl RealFft2 {
    /// A plan on the full `ny × nx` grid (periodic fields).
    pub fn new(ny: usize, nx: usize) -> Result<Self, FftError> {
        Self::padded((ny, nx), (ny, nx))
    }

    /// A plan on the `grid = (NY, NX)` grid for data in its top-left `data = (ny, nx)`
    /// block, the rest zero (zero-padded, non-periodic convolutions: NY = 2ny, NX = 2nx).
    pub fn padded(grid: (usize, usize), data: (usize, usize)) -> Result<Self, FftError> {
        let (gy, gx) = grid;
        let (ny, nx) = data;
        if ny == 0 || nx == 0 || ny > gy || nx > gx {
            return Err(FftError::Shape {
                grid_rows: gy,
                grid_cols: gx,
                rows: ny,
                cols: nx,
            });
        }
        let mut real = RealFftPlanner::<f64>::new();
        let mut cplx = FftPlanner::<f64>::new();
        let lanes = if gy * gx >= PARALLEL_MIN_POINTS {
            rayon::current_num_threads().max(1)
        } else {
            1
        };
        Ok(RealFft2 {
            grid,
            data,
            half: gx / 2 + 1,
            r2c: real.plan_fft_forward(gx),
            c2r: real.plan_fft_inverse(gx),
            col_fwd: cplx.plan_fft_forward(gy),
            col_inv: cplx.plan_fft_inverse(gy),
            lanes,
        })
    }

    /// The same plan on one thread: for callers that run several transforms in
    /// parallel themselves (one [`Fft2Work`] each).
    pub fn single_lane(mut self) -> Self {
        self.lanes = 1;
        self
    }

    /// The grid (NY, NX).
    pub fn grid(&self) -> (usize, usize) {
        self.grid
    }

    /// The data block (ny, nx).
    pub fn data(&self) -> (usize, usize) {
        self.data
    }

    /// Length of the half spectrum, (NX/2 + 1)·NY.
    pub fn spectrum_len(&self) -> usize {
        self.half * self.grid.0
    }

    /// Buffers for [`forward`](Self::forward), [`inverse`](Self::inverse) and
    /// [`convolve`](Self::convolve).
    pub fn work(&self) -> Fft2Work {
        let mut w = self.convolution_work();
        w.spec = vec![Complex::default(); self.spectrum_len()];
        w
    }

    /// Buffers for the convolutions only ([`convolve`](Self::convolve),
    /// [`convolve_with`](Self::convolve_with), [`convolve_fields`](Self::convolve_fields)):
    /// [`work`](Self::work) without the transposed spectrum, whose column stage runs in
    /// place on the row spectra: 16·ny·(NX/2 + 1) bytes (≈ 8 per data point on a
    /// periodic grid) against twice that and more on a padded one. The spectrum is never
    /// allocated (not even for a moment: it would count in the peak memory).
    pub fn convolution_work(&self) -> Fft2Work {
        let s = self
            .r2c
            .get_scratch_len()
            .max(self.c2r.get_scratch_len())
            .max(self.col_fwd.get_inplace_scratch_len())
            .max(self.col_inv.get_inplace_scratch_len());
        Fft2Work {
            rows: vec![Complex::default(); self.data.0 * self.half],
            spec: Vec::new(),
            lanes: (0..self.lanes)
                .map(|_| Lane {
                    real: vec![0.0; self.grid.1],
                    scratch: vec![Complex::default(); s],
                    lines: vec![Complex::default(); BLOCK * self.grid.0],
                })
                .collect(),
        }
    }

    fn check(&self, what: &'static str, got: usize, expected: usize) -> Result<(), FftError> {
        if got != expected {
            return Err(FftError::Buffer {
                what,
                got,
                expected,
            });
        }
        Ok(())
    }

    /// Forward transform of the `ny × nx` real data into `work.spec` (layout in the
    /// module docs).
    pub fn forward(&self, input: &[f64], work: &mut Fft2Work) -> Result<(), FftError> {
        self.check("input", input.len(), self.data.0 * self.data.1)?;
        self.check("spectrum", work.spec.len(), self.spectrum_len())?;
        self.rows_forward(input, work);
        self.transpose_in(work);
        self.columns(&mut work.spec, &mut work.lanes, |line, _, lane| {
            self.col_fwd.process_with_scratch(line, &mut lane.scratch);
        });
        Ok(())
    }

    /// Inverse transform of `work.spec` (destroyed) into the `ny × nx` block `out`.
    /// The spectrum must be that of a real field (Hermitian along kx = 0 and NX/2).
    pub fn inverse(&self, out: &mut [f64], work: &mut Fft2Work) -> Result<(), FftError> {
        self.check("output", out.len(), self.data.0 * self.data.1)?;
        self.check("spectrum", work.spec.len(), self.spectrum_len())?;
        self.columns(&mut work.spec, &mut work.lanes, |line, _, lane| {
            self.col_inv.process_with_scratch(line, &mut lane.scratch);
        });
        self.transpose_out(work);
        self.rows_inverse(out, work);
        Ok(())
    }

    /// Convolution by a real spectral kernel: `out = F⁻¹[K · F[input]]`, with the kernel
    /// a [`Multiplier`] (a `&[f64]` in the half-spectrum layout `kernel[kx · NY + ky]`,
    /// normalisation included) and its (0, 0) entry replaced by `dc`. The kernel multiply happens between the forward
    /// and inverse column transforms of each kx line, while it is in cache.
    pub fn convolve<'k>(
        &self,
        input: &[f64],
        out: &mut [f64],
        kernel: impl Into<Multiplier<'k>>,
        dc: f64,
        work: &mut Fft2Work,
    ) -> Result<(), FftError> {
        let kernel = kernel.into();
        let n = self.data.0 * self.data.1;
        self.check("input", input.len(), n)?;
        self.check("output", out.len(), n)?;
        self.check(
            "kernel",
            kernel.len(),
            kernel.expected_len(self.grid.0, self.half),
        )?;
        self.rows_forward(input, work);
        self.columns_in_rows(kernel, dc, work);
        self.rows_inverse_fields([out], work, &|_, [o]: [&mut [f64]; 1], result: &[f64]| {
            o.copy_from_slice(result)
        });
        Ok(())
    }

    /// [`convolve`](Self::convolve) with per-row work fused into the two row passes,
    /// while each row is in cache: `fill(i, data_row, input_row)` produces row `i` of
    /// the transform's input (`input_row`, nx values; it may also rewrite `data_row`,
    /// row `i` of `data`), and `drain(i, data_row, result_row, out_row)` consumes row `i`
    /// of the result `F⁻¹[K · F[input]]`, writing row `i` of `out` as it likes. Each
    /// returns a per-row accumulator, combined over the rows with [`Merge`]. Rows run
    /// on the plan's lanes in parallel.
    pub fn convolve_with<A, B>(
        &self,
        rows: RowPasses<'_>,
        work: &mut Fft2Work,
        fill: impl Fn(usize, &mut [f64], &mut [f64]) -> A + Sync,
        drain: impl Fn(usize, &[f64], &[f64], &mut [f64]) -> B + Sync,
    ) -> Result<(A, B), FftError>
    where
        A: Merge,
        B: Merge,
    {
        let RowPasses {
            data,
            out,
            kernel,
            dc,
        } = rows;
        let (a, b) = self.convolve_fields(
            Fields {
                fields: [data, out],
                kernel,
                dc,
            },
            work,
            |i, [d, _]: [&mut [f64]; 2], input: &mut [f64]| fill(i, d, input),
            |_| Some(()),
            |_, i, [d, o]: [&mut [f64]; 2], result: &[f64]| drain(i, d, result, o),
        )?;
        Ok((a, b.unwrap_or_default()))
    }

    /// The general fused convolution: K fields (each ny·nx) handed row by row to both
    /// hooks, mutable. `fill(i, rows, input_row)` produces row `i` of the transform's
    /// input (nx values) and may rewrite the fields' rows; then `gate` sees the combined
    /// fill accumulator and either stops the convolution there (`None`: the rest is not
    /// computed) or hands a value `g` to the drain: `drain(&g, i, rows, result_row)`
    /// consumes row `i` of `F⁻¹[K · F[input]]`. Rows run on the plan's lanes in parallel; each row index is
    /// handed to each hook exactly once.
    pub fn convolve_fields<const K: usize, A, B, G>(
        &self,
        fields: Fields<'_, K>,
        work: &mut Fft2Work,
        fill: impl Fn(usize, [&mut [f64]; K], &mut [f64]) -> A + Sync,
        gate: impl FnOnce(&A) -> Option<G>,
        drain: impl Fn(&G, usize, [&mut [f64]; K], &[f64]) -> B + Sync,
    ) -> Result<(A, Option<B>), FftError>
    where
        A: Merge,
        B: Merge,
        G: Sync,
    {
        let n = self.data.0 * self.data.1;
        let Fields {
            mut fields,
            kernel,
            dc,
        } = fields;
        for f in fields.iter() {
            self.check("field", f.len(), n)?;
        }
        self.check(
            "kernel",
            kernel.len(),
            kernel.expected_len(self.grid.0, self.half),
        )?;
        let a = self.rows_forward_fields(fields.each_mut().map(|f| &mut **f), work, &fill);
        let Some(g) = gate(&a) else {
            return Ok((a, None));
        };
        self.columns_in_rows(kernel, dc, work);
        let b =
            self.rows_inverse_fields(fields, work, &|i, rows, result| drain(&g, i, rows, result));
        Ok((a, Some(b)))
    }

    /// The column stage of a convolution, in place on the row spectra: each lane owns a
    /// range of kx columns, gathers them BLOCK lines at a time (zero below the data
    /// rows), transforms, multiplies by the kernel and transforms back each line while it
    /// is in cache, and scatters the data rows back.
    fn columns_in_rows(&self, kernel: Multiplier<'_>, dc: f64, work: &mut Fft2Work) {
        let (gy, ny, h) = (self.grid.0, self.data.0, self.half);
        let lanes = work.lanes.len();
        let chunk = h.div_ceil(lanes);
        // Each lane's columns of every row.
        let mut parts: Vec<Vec<&mut [Complex<f64>]>> =
            (0..lanes).map(|_| Vec::with_capacity(ny)).collect();
        for row in work.rows.chunks_mut(h) {
            let mut rest = row;
            for part in parts.iter_mut() {
                let take = chunk.min(rest.len());
                let (a, b) = std::mem::take(&mut rest).split_at_mut(take);
                part.push(a);
                rest = b;
            }
        }
        let run = |(c, (mut cols, lane)): LaneCols<'_>| {
            let k0 = c * chunk;
            let kn = cols.first().map_or(0, |r| r.len());
            for b in (0..kn).step_by(BLOCK) {
                let be = (b + BLOCK).min(kn);
                for (i, r) in cols.iter().enumerate() {
                    for (k, &v) in r[b..be].iter().enumerate() {
                        lane.lines[k * gy + i] = v;
                    }
                }
                for k in 0..be - b {
                    let line = &mut lane.lines[k * gy..(k + 1) * gy];
                    line[ny..].fill(Complex::default());
                    self.col_fwd.process_with_scratch(line, &mut lane.scratch);
                    let z0 = line[0];
                    let kx = k0 + b + k;
                    kernel.apply(kx, line);
                    if kx == 0 {
                        line[0] = z0 * dc;
                    }
                    self.col_inv.process_with_scratch(line, &mut lane.scratch);
                }
                for (i, r) in cols.iter_mut().enumerate() {
                    for (k, v) in r[b..be].iter_mut().enumerate() {
                        *v = lane.lines[k * gy + i];
                    }
                }
            }
        };
        if lanes > 1 {
            parts
                .into_par_iter()
                .zip(work.lanes.par_iter_mut())
                .enumerate()
                .for_each(run);
        } else if let Some(cols) = parts.pop() {
            run((0, (cols, &mut work.lanes[0])));
        }
    }

    /// Forward row transforms, each row produced by `fill` from the fields' rows.
    fn rows_forward_fields<const K: usize, A: Merge>(
        &self,
        fields: [&mut [f64]; K],
        work: &mut Fft2Work,
        fill: &(impl Fn(usize, [&mut [f64]; K], &mut [f64]) -> A + Sync),
    ) -> A {
        let (ny, nx) = self.data;
        let gx = self.grid.1;
        let h = self.half;
        let lanes = work.lanes.len();
        let chunk = ny.div_ceil(lanes);
        let r2c = &self.r2c;
        let parts = lane_chunks(fields, chunk, nx, lanes);
        let run = |((rows, mut part), lane): LaneRows<'_, K>, first: usize| {
            let mut acc = A::default();
            for (r, out) in rows.chunks_mut(h).enumerate() {
                acc = acc.merge(fill(
                    first + r,
                    row_of(&mut part, r, nx),
                    &mut lane.real[..nx],
                ));
                lane.real[nx..gx].fill(0.0);
                // Lengths are fixed by the plan: the only error is a wrong length.
                let _ = r2c.process_with_scratch(&mut lane.real, out, &mut lane.scratch);
            }
            acc
        };
        if lanes > 1 {
            work.rows
                .par_chunks_mut(chunk * h)
                .zip(parts.into_par_iter())
                .zip(work.lanes.par_iter_mut())
                .enumerate()
                .map(|(c, pair)| run(pair, c * chunk))
                .reduce(A::default, A::merge)
        } else {
            let (rows, lane) = (&mut work.rows, &mut work.lanes[0]);
            parts
                .into_iter()
                .map(|part| run(((&mut *rows, part), &mut *lane), 0))
                .fold(A::default(), A::merge)
        }
    }

    /// The inverse row stage of a convolution: each lane transforms its rows of the row
    /// spectra back and hands each result row, with the fields' rows, to `drain`.
    fn rows_inverse_fields<const K: usize, B: Merge>(
        &self,
        fields: [&mut [f64]; K],
        work: &mut Fft2Work,
        drain: &(impl Fn(usize, [&mut [f64]; K], &[f64]) -> B + Sync),
    ) -> B {
        let (ny, nx) = self.data;
        let h = self.half;
        let lanes = work.lanes.len();
        let chunk = ny.div_ceil(lanes);
        let c2r = &self.c2r;
        let even = self.grid.1.is_multiple_of(2);
        let parts = lane_chunks(fields, chunk, nx, lanes);
        let run = |(c, ((spec, mut part), lane)): (usize, LaneRows<'_, K>)| {
            let i0 = c * chunk;
            let Lane { real, scratch, .. } = lane;
            let mut acc = B::default();
            for (r, row) in spec.chunks_mut(h).enumerate() {
                // A real field's row spectrum has real DC and Nyquist terms; round-off
                // left there is dropped (realfft would report it).
                row[0].im = 0.0;
                if even {
                    row[h - 1].im = 0.0;
                }
                let _ = c2r.process_with_scratch(row, real, scratch);
                acc = acc.merge(drain(i0 + r, row_of(&mut part, r, nx), &real[..nx]));
            }
            acc
        };
        if lanes > 1 {
            work.rows
                .par_chunks_mut(chunk * h)
                .zip(parts.into_par_iter())
                .zip(work.lanes.par_iter_mut())
                .enumerate()
                .map(run)
                .reduce(B::default, B::merge)
        } else {
            let (rows, lane) = (&mut work.rows, &mut work.lanes[0]);
            parts
                .into_iter()
                .map(|part| run((0, ((&mut *rows, part), &mut *lane))))
                .fold(B::default(), B::merge)
        }
    }

    /// Row transforms of the data block into `work.rows`.
    fn rows_forward(&self, input: &[f64], work: &mut Fft2Work) {
        let (ny, nx) = self.data;
        let gx = self.grid.1;
        let h = self.half;
        let chunk = ny.div_ceil(work.lanes.len());
        let r2c = &self.r2c;
        let run = |(rows, lane): (&mut [Complex<f64>], &mut Lane), first: usize| {
            for (r, out) in rows.chunks_mut(h).enumerate() {
                let i = first + r;
                lane.real[..nx].copy_from_slice(&input[i * nx..(i + 1) * nx]);
                lane.real[nx..gx].fill(0.0);
                // Lengths are fixed by the plan: the only error is a wrong length.
                let _ = r2c.process_with_scratch(&mut lane.real, out, &mut lane.scratch);
            }
        };
        if work.lanes.len() > 1 {
            work.rows
                .par_chunks_mut(chunk * h)
                .zip(work.lanes.par_iter_mut())
                .enumerate()
                .for_each(|(c, pair)| run(pair, c * chunk));
        } else {
            run((&mut work.rows, &mut work.lanes[0]), 0);
        }
    }

    /// Inverse row transforms of `work.rows` into the data block.
    fn rows_inverse(&self, out: &mut [f64], work: &mut Fft2Work) {
        let (ny, nx) = self.data;
        let h = self.half;
        let chunk = ny.div_ceil(work.lanes.len());
        let c2r = &self.c2r;
        let even = self.grid.1.is_multiple_of(2);
        let run = |((rows, dst), lane): ((&mut [Complex<f64>], &mut [f64]), &mut Lane)| {
            for (row, o) in rows.chunks_mut(h).zip(dst.chunks_mut(nx)) {
                // A real field's row spectrum has real DC and Nyquist terms; round-off
                // left there is dropped (realfft would report it).
                row[0].im = 0.0;
                if even {
                    row[h - 1].im = 0.0;
                }
                let _ = c2r.process_with_scratch(row, &mut lane.real, &mut lane.scratch);
                o.copy_from_slice(&lane.real[..nx]);
            }
        };
        if work.lanes.len() > 1 {
            work.rows
                .par_chunks_mut(chunk * h)
                .zip(out.par_chunks_mut(chunk * nx))
                .zip(work.lanes.par_iter_mut())
                .for_each(run);
        } else {
            run(((&mut work.rows, out), &mut work.lanes[0]));
        }
    }

    /// Runs `f(line, kx, lane)` on every kx line (length NY) of the spectrum.
    fn columns(
        &self,
        spec: &mut [Complex<f64>],
        lanes: &mut [Lane],
        f: impl Fn(&mut [Complex<f64>], usize, &mut Lane) + Sync,
    ) {
        let gy = self.grid.0;
        let chunk = self.half.div_ceil(lanes.len());
        let run = |(c, (block, lane)): (usize, (&mut [Complex<f64>], &mut Lane))| {
            for (k, line) in block.chunks_mut(gy).enumerate() {
                f(line, c * chunk + k, lane);
            }
        };
        if lanes.len() > 1 {
            spec.par_chunks_mut(chunk * gy)
                .zip(lanes.par_iter_mut())
                .enumerate()
                .for_each(run);
        } else {
            run((0, (spec, &mut lanes[0])));
        }
    }

    /// `rows` (ny × h) → `spec` (h × NY, zero below row ny), blocked.
    fn transpose_in(&self, work: &mut Fft2Work) {
        let (gy, ny, h) = (self.grid.0, self.data.0, self.half);
        let rows = &work.rows;
        let chunk = h.div_ceil(work.lanes.len());
        let run = |(c, block): (usize, &mut [Complex<f64>])| {
            let k0 = c * chunk;
            let kn = block.len() / gy;
            for b in (0..kn).step_by(BLOCK) {
                let be = (b + BLOCK).min(kn);
                gather_columns(rows, block, [ny, h, gy], k0, b..be);
                for k in b..be {
                    block[k * gy + ny..(k + 1) * gy].fill(Complex::default());
                }
            }
        };
        if work.lanes.len() > 1 {
            work.spec
                .par_chunks_mut(chunk * gy)
                .enumerate()
                .for_each(run);
        } else {
            run((0, &mut work.spec));
        }
    }

    /// `spec` (h × NY) → `rows` (ny × h): only the data rows, blocked.
    fn transpose_out(&self, work: &mut Fft2Work) {
        let (gy, ny, h) = (self.grid.0, self.data.0, self.half);
        let spec = &work.spec;
        let chunk = ny.div_ceil(work.lanes.len());
        let run = |(c, block): (usize, &mut [Complex<f64>])| {
            let i0 = c * chunk;
            let rn = block.len() / h;
            for b in (0..h).step_by(BLOCK) {
                let be = (b + BLOCK).min(h);
                for r in 0..rn {
                    let row = &mut block[r * h + b..r * h + be];
                    for (k, slot) in row.iter_mut().enumerate() {
                        *slot = spec[(b + k) * gy + i0 + r];
                    }
                }
            }
        };
        if work.lanes.len() > 1 {
            work.rows
                .par_chunks_mut(chunk * h)
                .enumerate()
                .for_each(run);
        } else {
            run((0, &mut work.rows));
        }
    }
}

/// One thread's scratch of the slab pieces of [`RealFft2`] ([`RealFft2::slab_scratch`]):
/// a real row of NX values and the transforms' scratch.
pub struct SlabScratch {
    real: Vec<f64>,
    scratch: Vec<Complex<f64>>,
}

/// The pieces of a distributed (slab-decomposed) 2-D transform: a process that owns some
/// data rows transforms them along the rows, exchanges blocks of the row spectra so that
/// it owns some kx columns over all rows, transforms those along the columns, and back.
/// The caller does the exchange; each piece runs on the calling thread. The values are
/// those of [`RealFft2::convolve`] up to the order of the floating-point operations,
/// which is the same (the same 1-D transforms on the same lines).
impl RealFft2 {
    /// Scratch for [`Self::row_forward`], [`Self::row_inverse`] and
    /// [`Self::column_convolve`].
    pub fn slab_scratch(&self) -> SlabScratch {
        let s = self
            .r2c
            .get_scratch_len()
            .max(self.c2r.get_scratch_len())
            .max(self.col_fwd.get_inplace_scratch_len())
            .max(self.col_inv.get_inplace_scratch_len());
        SlabScratch {
            real: vec![0.0; self.grid.1],
            scratch: vec![Complex::default(); s],
        }
    }

    /// The spectrum (NX/2 + 1 values, `out`) of one data row (`row`, nx values, zero-padded
    /// to NX): the row stage of the forward transform.
    pub fn row_forward(
        &self,
        row: &[f64],
        out: &mut [Complex<f64>],
        s: &mut SlabScratch,
    ) -> Result<(), FftError> {
        let (nx, gx) = (self.data.1, self.grid.1);
        self.check("row", row.len(), nx)?;
        self.check("row spectrum", out.len(), self.half)?;
        s.real[..nx].copy_from_slice(row);
        s.real[nx..gx].fill(0.0);
        // Lengths are fixed by the plan: the only error is a wrong length.
        let _ = self
            .r2c
            .process_with_scratch(&mut s.real, out, &mut s.scratch);
        Ok(())
    }

    /// The data row (`out`, nx values) of a row spectrum (`spec`, NX/2 + 1 values,
    /// destroyed): the row stage of the inverse transform (unnormalised).
    pub fn row_inverse(
        &self,
        spec: &mut [Complex<f64>],
        out: &mut [f64],
        s: &mut SlabScratch,
    ) -> Result<(), FftError> {
        let (h, nx) = (self.half, self.data.1);
        self.check("row spectrum", spec.len(), h)?;
        self.check("row", out.len(), nx)?;
        spec[0].im = 0.0;
        if self.grid.1.is_multiple_of(2) {
            spec[h - 1].im = 0.0;
        }
        let _ = self
            .c2r
            .process_with_scratch(spec, &mut s.real, &mut s.scratch);
        out.copy_from_slice(&s.real[..nx]);
        Ok(())
    }

    /// The column stage of a convolution on one kx line (`line`, NY values, the data rows
    /// first and zeros below them): forward transform, multiplication by the kernel's
    /// line `at` of `kernel` (a multiplier holding the lines of this process's columns
    /// only is indexed by its own line number), the (0, 0) entry replaced by `dc` if
    /// given, inverse transform.
    pub fn column_convolve(
        &self,
        line: &mut [Complex<f64>],
        kernel: Multiplier<'_>,
        at: usize,
        dc: Option<f64>,
        s: &mut SlabScratch,
    ) -> Result<(), FftError> {
        let gy = self.grid.0;
        self.check("column", line.len(), gy)?;
        let need = kernel.expected_len(gy, at + 1);
        if kernel.len() < need {
            return Err(FftError::Buffer {
                what: "kernel",
                got: kernel.len(),
                expected: need,
            });
        }
        self.col_fwd.process_with_scratch(line, &mut s.scratch);
        let z0 = line[0];
        kernel.apply(at, line);
        if let Some(dc) = dc {
            line[0] = z0 * dc;
        }
        self.col_inv.process_with_scratch(line, &mut s.scratch);
        Ok(())
    }

    /// The forward column transform of one kx line (NY values, in place).
    pub fn column_forward(
        &self,
        line: &mut [Complex<f64>],
        s: &mut SlabScratch,
    ) -> Result<(), FftError> {
        self.check("column", line.len(), self.grid.0)?;
        self.col_fwd.process_with_scratch(line, &mut s.scratch);
        Ok(())
    }

    /// The inverse column transform of one kx line (NY values, in place, unnormalised):
    /// the column stage of [`Self::inverse`] on that line.
    pub fn column_inverse(
        &self,
        line: &mut [Complex<f64>],
        s: &mut SlabScratch,
    ) -> Result<(), FftError> {
        self.check("column", line.len(), self.grid.0)?;
        self.col_inv.process_with_scratch(line, &mut s.scratch);
        Ok(())
    }

    /// Values per row spectrum, NX/2 + 1.
    pub fn half(&self) -> usize {
        self.half
    }
}

/// Signed frequency index of `i` on a periodic axis of `n` points: i for i ≤ n/2,
/// i − n above (the Nyquist index n/2 counts as positive).
pub fn signed_index(i: usize, n: usize) -> i64 {
    if i <= n / 2 {
        i as i64
    } else {
        i as i64 - n as i64
    }
}

/// The column block `cols` (columns k0 + cols of the ny × h row spectra `rows`) gathered
/// into `dst` as lines of length gy (column k at dst[k·gy..], rows 0..ny): the blocked
/// transpose of the column pass.
#[inline(always)]
fn gather_columns(
    rows: &[Complex<f64>],
    dst: &mut [Complex<f64>],
    [ny, h, gy]: [usize; 3],
    k0: usize,
    cols: std::ops::Range<usize>,
) {
    let b = cols.start;
    for i in 0..ny {
        let src = &rows[i * h + k0 + b..i * h + k0 + cols.end];
        for (k, &v) in src.iter().enumerate() {
            dst[(b + k) * gy + i] = v;
        }
    }
}
