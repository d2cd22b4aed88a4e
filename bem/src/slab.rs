//! The influence operator u = K p on a slab decomposition ([`crate::decomp`]): each rank
//! holds the rows `rows` of p and u (and of every other field of the iteration) and the kx
//! columns `cols` of the kernel; no rank holds a whole grid.
//!
//! One product, on P ranks:
//!
//! ```text
//!   row FFTs of the rank's data rows        (m·(NX/2+1) complex values)
//!   per chunk of a sixteenth of the columns:
//!     all-to-all: block (my rows × q's columns of the chunk) to rank q
//!     per owned kx line of the chunk: column FFT, × K̂(kx, ky), inverse column FFT
//!     all-to-all back: block (q's rows × my columns of the chunk) to rank q
//!   inverse row FFTs into the rank's rows of u
//! ```
//!
//! The 1-D transforms are [`RealFft2`]'s, on the same lines with the same values as the
//! serial product's (the operator of [`crate::BemSolver`]): the product is the serial one
//! bit for bit, whatever P (tested). Each exchange sends, per rank, its m data rows'
//! spectra less the block it keeps: 16·m·(NX/2+1)·(P−1)/P bytes, twice per product (in
//! sixteen chunks each).
//!
//! Memory per rank: the kernel's columns (periodic: (NX/2+1)(NY/2+1)/P values; free:
//! (NX/2+1)·NY/P), the rows' spectra, P·⌈m⌉·⌈(NX/2+1)/P⌉ complex values (≈ 8 bytes per
//! owned point on a periodic grid), two buffers of one exchange chunk (a sixteenth of that
//! each) and one column line.

use std::ops::Range;
use std::sync::Arc;

use strata_runtime::fft::{Complex, Multiplier, RealFft2, SlabScratch};

use crate::BemError;
use crate::decomp::{Decomposition, slab, slab_max};

/// The rank's columns of the kernel.
enum SlabKernel {
    /// Periodic: `table[(kx − c0)·(NY/2 + 1) + fy]` (m/Pa), scaled by `scale` = 1/(ny·nx)
    /// as it is used (the layout of the serial operator's table, cut by columns);
    /// `inverse`: the multiplier is 1/K̂ from the same table (the preconditioner).
    Folded {
        table: Arc<Vec<f64>>,
        scale: f64,
        inverse: bool,
    },
    /// Free: the half spectrum `kernel[(kx − c0)·NY + ky]`, normalisation included.
    Half(Vec<f64>),
}

/// A convolution operator on a slab decomposition (see the module docs).
pub struct SlabOperator<'c> {
    comm: &'c dyn Decomposition,
    plan: RealFft2,
    rows: Range<usize>,
    cols: Range<usize>,
    kernel: SlabKernel,
    periodic: bool,
}

/// The column chunks each exchange is cut into: the product holds its rows' spectra
/// whole (≈ 8 bytes per owned point) and two buffers of one chunk (≈ 0.5 each), not two
/// whole exchange buffers (16 bytes per owned point).
const EXCHANGE_CHUNKS: usize = 16;

/// Columns per exchange chunk when a rank owns at most `cm` columns: ⌈cm / 16⌉.
pub(crate) fn chunk_columns(cm: usize) -> usize {
    cm.div_ceil(EXCHANGE_CHUNKS.min(cm).max(1)).max(1)
}

/// The buffers of a product on one rank.
pub struct SlabWork {
    /// The rows' spectra: P blocks (my rows × q's columns).
    a: Vec<f64>,
    /// One column chunk of the blocks, sent and received (two buffers).
    send: Vec<f64>,
    recv: Vec<f64>,
    line: Vec<Complex<f64>>,
    row: Vec<Complex<f64>>,
    scratch: SlabScratch,
}

impl<'c> SlabOperator<'c> {
    /// Periodic operator on the ny × nx cell from the kernel K(kx, ky) (m/Pa):
    /// `kernel_of(i, j)` with i ∈ 0..=nx/2 and the folded j ∈ 0..=ny/2, `k00` the
    /// uniform-mode value; each rank evaluates its own columns only.
    pub fn periodic(
        comm: &'c dyn Decomposition,
        ny: usize,
        nx: usize,
        k00: f64,
        mut kernel_of: impl FnMut(usize, usize) -> Result<f64, BemError>,
    ) -> Result<Self, BemError> {
        let plan = RealFft2::new(ny, nx)?;
        let (p, q) = (comm.size(), comm.rank());
        let cols = slab(plan.half(), p, q);
        let hy = ny / 2 + 1;
        let mut table = Vec::with_capacity(cols.len() * hy);
        for kx in cols.clone() {
            for fy in 0..hy {
                table.push(if kx == 0 && fy == 0 {
                    k00
                } else {
                    kernel_of(kx, fy)?
                });
            }
        }
        Ok(SlabOperator {
            comm,
            rows: slab(ny, p, q),
            cols,
            plan,
            kernel: SlabKernel::Folded {
                table: Arc::new(table),
                scale: 1.0 / (ny * nx) as f64,
                inverse: false,
            },
            periodic: true,
        })
    }

    /// Free-boundary operator on an ny × nx sample from the real-space influence
    /// coefficients `g[dy·nx + dx]` (m/Pa, all offsets: the set-up holds them whole), by
    /// circulant embedding on the 2ny × 2nx grid as the serial operator. Each rank
    /// transforms every row of the embedding and keeps its own columns of the spectrum.
    pub fn free(
        comm: &'c dyn Decomposition,
        ny: usize,
        nx: usize,
        g: &[f64],
    ) -> Result<Self, BemError> {
        let (gy, gx) = (2 * ny, 2 * nx);
        let full = RealFft2::new(gy, gx)?;
        let (p, q) = (comm.size(), comm.rank());
        let cols = slab(full.half(), p, q);
        let nc = cols.len();
        let mut s = full.slab_scratch();
        let mut row = vec![0.0; gx];
        let mut spec = vec![Complex::default(); full.half()];
        let mut lines = vec![Complex::default(); nc * gy];
        for i in 0..gy {
            row.fill(0.0);
            let di = if i < ny {
                Some(i)
            } else if i > ny {
                Some(gy - i)
            } else {
                None
            };
            if let Some(di) = di {
                for j in 0..gx {
                    let dj = if j < nx {
                        j
                    } else if j > nx {
                        gx - j
                    } else {
                        continue;
                    };
                    row[j] = g[di * nx + dj];
                }
            }
            full.row_forward(&row, &mut spec, &mut s)?;
            for (k, kx) in cols.clone().enumerate() {
                lines[k * gy + i] = spec[kx];
            }
        }
        let norm = 1.0 / (gy * gx) as f64;
        let mut kernel = Vec::with_capacity(nc * gy);
        for line in lines.chunks_mut(gy) {
            full.column_forward(line, &mut s)?;
            kernel.extend(line.iter().map(|z| z.re * norm));
        }
        Ok(SlabOperator {
            comm,
            rows: slab(ny, p, q),
            cols,
            plan: RealFft2::padded((gy, gx), (ny, nx))?,
            kernel: SlabKernel::Half(kernel),
            periodic: false,
        })
    }

    /// The inverse operator, the Fourier multiplier 1/K̂ on the same grid (the
    /// preconditioner), as the serial operator's inverse:
    /// `None` on every rank if K̂ is not positive and finite off (0, 0) on any rank.
    /// Periodic: read from the same table (no memory of its own).
    pub fn inverse(&self) -> Option<SlabOperator<'c>> {
        let (gy, gx) = self.plan.grid();
        let norm = 1.0 / (gy * gx) as f64;
        // The entries other than the global (0, 0) one, as the multiplier uses them.
        let skip = usize::from(self.cols.start == 0);
        let bad = match &self.kernel {
            SlabKernel::Folded { table, scale, .. } => table
                .iter()
                .skip(skip)
                .any(|&t| !(t * scale > 0.0 && (t * scale).is_finite())),
            SlabKernel::Half(k) => k.iter().skip(skip).any(|&k| !(k > 0.0 && k.is_finite())),
        };
        if crate::decomp::any(self.comm, bad) {
            return None;
        }
        let kernel = match &self.kernel {
            SlabKernel::Folded {
                table,
                scale,
                inverse,
            } => SlabKernel::Folded {
                table: Arc::clone(table),
                scale: *scale,
                inverse: !inverse,
            },
            SlabKernel::Half(k) => SlabKernel::Half(
                k.iter()
                    .map(|&k| if k > 0.0 { norm * norm / k } else { 0.0 })
                    .collect(),
            ),
        };
        Some(SlabOperator {
            comm: self.comm,
            plan: RealFft2::padded((gy, gx), self.plan.data()).ok()?,
            rows: self.rows.clone(),
            cols: self.cols.clone(),
            kernel,
            periodic: self.periodic,
        })
    }

    /// This rank's data rows.
    #[cfg(test)]
    pub fn rows(&self) -> Range<usize> {
        self.rows.clone()
    }

    /// Values of one exchange block (complex values as two reals).
    fn block(&self) -> usize {
        let p = self.comm.size();
        2 * slab_max(self.plan.data().0, p) * slab_max(self.plan.half(), p)
    }

    /// Columns per exchange chunk ([`chunk_columns`]).
    fn chunk(&self) -> usize {
        chunk_columns(slab_max(self.plan.half(), self.comm.size()))
    }

    /// Values of one block of an exchange chunk (complex values as two reals).
    fn chunk_block(&self) -> usize {
        2 * slab_max(self.plan.data().0, self.comm.size()) * self.chunk()
    }

    /// The buffers of a product.
    pub fn work(&self) -> SlabWork {
        let n = self.comm.size() * self.block();
        let c = self.comm.size() * self.chunk_block();
        SlabWork {
            a: vec![0.0; n],
            send: vec![0.0; c],
            recv: vec![0.0; c],
            line: vec![Complex::default(); self.plan.grid().0],
            row: vec![Complex::default(); self.plan.half()],
            scratch: self.plan.slab_scratch(),
        }
    }

    /// Bytes the operator and one work set take on one rank (kernel columns, the rows'
    /// spectra and the two exchange chunks).
    pub fn bytes(&self) -> u64 {
        let kernel = match &self.kernel {
            SlabKernel::Folded { table, .. } => table.len(),
            SlabKernel::Half(k) => k.len(),
        };
        8 * (kernel + self.comm.size() * (self.block() + 2 * self.chunk_block())) as u64
    }

    /// The multiplier of this rank's columns and the (0, 0) entry's replacement on the
    /// rank that holds kx = 0: the uniform-mode value, or 0 on a periodic cell without
    /// the uniform mode.
    fn multiplier(&self, uniform: bool) -> (Multiplier<'_>, Option<f64>) {
        let (m, origin) = match &self.kernel {
            SlabKernel::Folded {
                table,
                scale,
                inverse,
            } => (
                Multiplier::Folded {
                    table,
                    scale: *scale,
                    inverse: *inverse,
                },
                table.first().map(|&t| {
                    let k = t * scale;
                    if !inverse {
                        k
                    } else if k > 0.0 {
                        scale * scale / k
                    } else {
                        0.0
                    }
                }),
            ),
            SlabKernel::Half(k) => (Multiplier::Half(k), k.first().copied()),
        };
        let dc = if self.cols.start != 0 {
            None
        } else if self.periodic && !uniform {
            Some(0.0)
        } else {
            origin
        };
        (m, dc)
    }

    /// out = K · input on this rank's rows (m·nx values each); every rank calls it
    /// together. `uniform`: include the periodic k = 0 mode.
    pub fn apply(
        &self,
        input: &[f64],
        out: &mut [f64],
        uniform: bool,
        w: &mut SlabWork,
    ) -> Result<(), BemError> {
        let p = self.comm.size();
        let (ny, nx) = self.plan.data();
        let (gy, h) = (self.plan.grid().0, self.plan.half());
        let m = self.rows.len();
        let cm = slab_max(h, p);
        let blk = self.block();
        for (what, got) in [("input", input.len()), ("output", out.len())] {
            if got != m * nx {
                return Err(strata_runtime::fft::FftError::Buffer {
                    what,
                    got,
                    expected: m * nx,
                }
                .into());
            }
        }
        // Row transforms, scattered into the blocks for the column owners.
        for r in 0..m {
            self.plan
                .row_forward(&input[r * nx..(r + 1) * nx], &mut w.row, &mut w.scratch)?;
            for q in 0..p {
                let cq = slab(h, p, q);
                let dst = &mut w.a[q * blk + 2 * r * cm..];
                for (k, v) in w.row[cq].iter().enumerate() {
                    dst[2 * k] = v.re;
                    dst[2 * k + 1] = v.im;
                }
            }
        }
        // The owned kx lines over all rows, a chunk of columns at a time: the chunk's
        // part of every block exchanged, its lines gathered, convolved and put back,
        // exchanged back into the blocks' places (sent already, free).
        let (kernel, dc) = self.multiplier(uniform);
        let (cc, cblk) = (self.chunk(), self.chunk_block());
        let mut k0 = 0;
        while k0 < cm {
            let k1 = (k0 + cc).min(cm);
            for q in 0..p {
                for r in 0..m {
                    let from = q * blk + 2 * (r * cm + k0);
                    let to = q * cblk + 2 * r * cc;
                    w.send[to..to + 2 * (k1 - k0)]
                        .copy_from_slice(&w.a[from..from + 2 * (k1 - k0)]);
                }
            }
            self.comm.all_to_all(&w.send, &mut w.recv);
            for k in k0..k1.min(self.cols.len()) {
                for q in 0..p {
                    let rq = slab(ny, p, q);
                    let src = &w.recv[q * cblk..];
                    for r in 0..rq.len() {
                        let at = 2 * (r * cc + k - k0);
                        w.line[rq.start + r] = Complex::new(src[at], src[at + 1]);
                    }
                }
                w.line[ny..gy].fill(Complex::default());
                let dc = if k == 0 { dc } else { None };
                self.plan
                    .column_convolve(&mut w.line, kernel, k, dc, &mut w.scratch)?;
                for q in 0..p {
                    let rq = slab(ny, p, q);
                    let dst = &mut w.recv[q * cblk..];
                    for r in 0..rq.len() {
                        let at = 2 * (r * cc + k - k0);
                        let v = w.line[rq.start + r];
                        dst[at] = v.re;
                        dst[at + 1] = v.im;
                    }
                }
            }
            self.comm.all_to_all(&w.recv, &mut w.send);
            for q in 0..p {
                for r in 0..m {
                    let to = q * blk + 2 * (r * cm + k0);
                    let from = q * cblk + 2 * r * cc;
                    w.a[to..to + 2 * (k1 - k0)]
                        .copy_from_slice(&w.send[from..from + 2 * (k1 - k0)]);
                }
            }
            k0 = k1;
        }
        // Inverse row transforms of the rows' spectra gathered from the column owners.
        for r in 0..m {
            for q in 0..p {
                let cq = slab(h, p, q);
                let src = &w.a[q * blk + 2 * r * cm..];
                for (k, v) in w.row[cq].iter_mut().enumerate() {
                    *v = Complex::new(src[2 * k], src[2 * k + 1]);
                }
            }
            self.plan
                .row_inverse(&mut w.row, &mut out[r * nx..(r + 1) * nx], &mut w.scratch)?;
        }
        Ok(())
    }
}

/// The distributed inverse of [`RealFft2::inverse`] on a periodic ny × nx grid: this
/// rank's kx lines of the transposed half spectrum (`lines[(kx − c0)·ny + ky]` for kx
/// in [`slab`]`(nx/2 + 1, P, rank)`, destroyed) in, this rank's rows of the real field
/// ([`slab`]`(ny, P, rank)`, `out`, m·nx values, unnormalised) out. Every rank calls
/// it together:
///
/// ```text
///   per owned kx line: inverse column FFT
///   all-to-all: block (q's rows × my columns) to rank q
///   inverse row FFTs into the rank's rows
/// ```
///
/// The same 1-D transforms on the same lines with the same values as the serial
/// [`RealFft2::inverse`]: the rows equal the serial field's bit for bit, whatever P.
/// Memory per rank: the lines (16·|cols|·ny bytes, freed once sent) and two exchange
/// buffers of P·⌈m⌉·⌈(nx/2 + 1)/P⌉ complex values (≈ 8 bytes per owned point each).
pub fn inverse_to_rows(
    comm: &dyn Decomposition,
    plan: &RealFft2,
    mut lines: Vec<Complex<f64>>,
    out: &mut [f64],
) -> Result<(), BemError> {
    let (p, q) = (comm.size(), comm.rank());
    let (ny, nx) = plan.data();
    let h = plan.half();
    let (rows, cols) = (slab(ny, p, q), slab(h, p, q));
    let (m, cm) = (rows.len(), slab_max(h, p));
    let blk = 2 * slab_max(ny, p) * cm;
    for (what, got, expected) in [
        ("spectrum lines", lines.len(), cols.len() * ny),
        ("rows", out.len(), m * nx),
    ] {
        if got != expected {
            return Err(strata_runtime::fft::FftError::Buffer {
                what,
                got,
                expected,
            }
            .into());
        }
    }
    let mut s = plan.slab_scratch();
    let mut a = vec![0.0; p * blk];
    for (k, line) in lines.chunks_mut(ny).enumerate() {
        plan.column_inverse(line, &mut s)?;
        for r in 0..p {
            let rq = slab(ny, p, r);
            let dst = &mut a[r * blk..];
            for (i, v) in line[rq].iter().enumerate() {
                let at = 2 * (i * cm + k);
                dst[at] = v.re;
                dst[at + 1] = v.im;
            }
        }
    }
    drop(lines);
    let mut b = vec![0.0; p * blk];
    comm.all_to_all(&a, &mut b);
    drop(a);
    let mut row = vec![Complex::default(); h];
    for (i, o) in out.chunks_mut(nx).enumerate() {
        for r in 0..p {
            let cq = slab(h, p, r);
            let src = &b[r * blk + 2 * i * cm..];
            for (k, v) in row[cq].iter_mut().enumerate() {
                *v = Complex::new(src[2 * k], src[2 * k + 1]);
            }
        }
        plan.row_inverse(&mut row, o, &mut s)?;
    }
    Ok(())
}
