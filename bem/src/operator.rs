//! The influence operator u = K p of the boundary-element solver: one real-to-complex
//! 2-D FFT, the kernel multiply and one complex-to-real FFT per product
//! ([`strata_runtime::fft::RealFft2::convolve`]).
//!
//! * Periodic cell (physics.md §2, plane-wave form): ũ(k) = 2S(|k|)/(E*₁|k|) · p̃(k) on
//!   the (kx, ky) grid kx = 2π i/Lx, ky = 2π j/Ly; the k = 0 entry is the uniform-mode
//!   compliance C₀ (rigid base) or 0 (zero-mean convention, elastic base).
//! * Non-periodic sample: u_i = Σ_j G(x_i − x_j) p_j, the linear convolution with the
//!   real-space influence coefficients G of a uniformly loaded pixel ([`crate::influence`]),
//!   by circulant embedding on the zero-padded 2ny × 2nx grid.

use std::sync::Arc;

use strata_runtime::fft::{Fft2Work, Fields, Merge, Multiplier, RealFft2, RowPasses};

use crate::BemError;

/// The kernel of an operator in Fourier space.
#[derive(Clone)]
enum Kernel {
    /// The half-spectrum layout of [`RealFft2`] (`kernel[kx·NY + ky]`), normalisation
    /// included, the (0, 0) entry the value with the uniform mode (free boundary).
    Half(Vec<f64>),
    /// Periodic: K even in ky, held once per (kx, |ky|) as `table[kx·(ny/2 + 1) + fy]`
    /// (m/Pa, without the FFT's normalisation, which is applied as the kernel is used:
    /// a quarter of the grid, shared with the preconditioner, the inverse read from the
    /// same table, and with the coarse grid's operator); `table[0]` the uniform-mode
    /// value.
    Folded {
        table: Arc<Vec<f64>>,
        /// The normalisation 1/(ny·nx).
        scale: f64,
        /// The inverse operator 1/K̂ (the preconditioner).
        inverse: bool,
    },
}

impl Kernel {
    fn multiplier(&self) -> Multiplier<'_> {
        match self {
            Kernel::Half(k) => Multiplier::Half(k),
            Kernel::Folded {
                table,
                scale,
                inverse,
            } => Multiplier::Folded {
                table,
                scale: *scale,
                inverse: *inverse,
            },
        }
    }

    /// The multiplier's value for a stored entry.
    fn value(&self, x: f64) -> f64 {
        match self {
            Kernel::Half(_) => x,
            Kernel::Folded { scale, inverse, .. } => {
                let k = x * scale;
                if !inverse {
                    k
                } else if k > 0.0 {
                    scale * scale / k
                } else {
                    0.0
                }
            }
        }
    }

    fn stored(&self) -> &[f64] {
        match self {
            Kernel::Half(k) => k,
            Kernel::Folded { table, .. } => table,
        }
    }

    /// The (0, 0) entry.
    fn at_origin(&self) -> f64 {
        self.value(self.stored()[0])
    }

    /// The entries other than (0, 0) (each distinct wavevector's at least once).
    fn rest(&self) -> impl Iterator<Item = f64> + '_ {
        self.stored()[1..].iter().map(|&x| self.value(x))
    }
}

/// A convolution operator on an ny × nx field.
pub(crate) struct Operator {
    plan: RealFft2,
    kernel: Kernel,
    /// Periodic: the (0, 0) entry can be switched off (zero-mean convention).
    periodic: bool,
    /// The real-space response to a unit point load at the origin (the uniform mode
    /// excluded). Periodic: even in both offsets, held for 0 ≤ dy ≤ ny/2, 0 ≤ dx ≤ nx/2
    /// as `points[dy·(nx/2 + 1) + dx]` (offsets folded modulo the cell); free: G,
    /// `points[dy·nx + dx]` for 0 ≤ dy < ny, 0 ≤ dx < nx. Used by [`Self::add_points`].
    points: Vec<f64>,
}

impl Operator {
    /// Periodic operator from the kernel K(kx, ky) (m/Pa) given on the half spectrum:
    /// `kernel_of(i, j)` with i ∈ 0..=nx/2 the x index and j ∈ 0..=ny/2 the folded
    /// y index (K is even in ky); `k00` the uniform-mode value (m/Pa).
    pub(crate) fn periodic(
        ny: usize,
        nx: usize,
        k00: f64,
        mut kernel_of: impl FnMut(usize, usize) -> Result<f64, BemError>,
    ) -> Result<Self, BemError> {
        let plan = RealFft2::new(ny, nx)?;
        let hy = ny / 2 + 1;
        let mut table = vec![0.0; (nx / 2 + 1) * hy];
        for kx in 0..=nx / 2 {
            for fy in 0..hy {
                table[kx * hy + fy] = if kx == 0 && fy == 0 {
                    k00
                } else {
                    kernel_of(kx, fy)?
                };
            }
        }
        let mut op = Operator {
            plan,
            kernel: Kernel::Folded {
                table: Arc::new(table),
                scale: 1.0 / (ny * nx) as f64,
                inverse: false,
            },
            periodic: true,
            points: Vec::new(),
        };
        // The response to a unit load at the origin (zero-mean convention), kept on the
        // quarter of offsets it is even over.
        let mut unit = vec![0.0; ny * nx];
        unit[0] = 1.0;
        let mut full = vec![0.0; ny * nx];
        op.apply(&unit, &mut full, false, &mut op.work())?;
        drop(unit);
        let hx = nx / 2 + 1;
        let mut points = Vec::with_capacity(hy * hx);
        for dy in 0..hy {
            points.extend_from_slice(&full[dy * nx..dy * nx + hx]);
        }
        op.points = points;
        Ok(op)
    }

    /// The kernel table of a periodic operator (`table[i·(ny/2 + 1) + j]`, see
    /// [`Self::periodic`], m/Pa; `table[0]` the uniform-mode value); `None` when free.
    pub(crate) fn periodic_table(&self) -> Option<&[f64]> {
        match &self.kernel {
            Kernel::Folded { table, .. } => Some(table),
            Kernel::Half(_) => None,
        }
    }

    /// Free-boundary operator from real-space influence coefficients `g[dy * nx + dx]`
    /// (m/Pa, dy < ny, dx < nx; G is even in both offsets).
    pub(crate) fn free(ny: usize, nx: usize, g: &[f64]) -> Result<Self, BemError> {
        let (gy, gx) = (2 * ny, 2 * nx);
        let full = RealFft2::new(gy, gx)?;
        // Circulant embedding: offsets −(n−1)…(n−1) wrapped onto 0…2n−1; the unused
        // middle line (offset n) is zero.
        let mut c = vec![0.0; gy * gx];
        for i in 0..gy {
            let di = if i < ny {
                Some(i)
            } else if i > ny {
                Some(gy - i)
            } else {
                None
            };
            let Some(di) = di else { continue };
            for j in 0..gx {
                let dj = if j < nx {
                    j
                } else if j > nx {
                    gx - j
                } else {
                    continue;
                };
                c[i * gx + j] = g[di * nx + dj];
            }
        }
        let mut work = full.work();
        full.forward(&c, &mut work)?;
        drop(c);
        let norm = 1.0 / (gy * gx) as f64;
        // G is real and even: its transform is real (imaginary parts are round-off).
        let kernel: Vec<f64> = work.spec.iter().map(|z| z.re * norm).collect();
        drop(work);
        Ok(Operator {
            plan: RealFft2::padded((gy, gx), (ny, nx))?,
            kernel: Kernel::Half(kernel),
            periodic: false,
            points: g.to_vec(),
        })
    }

    /// The inverse operator, the Fourier multiplier 1/K̂ on the same grid (the
    /// preconditioner of [`crate::pcg`]); the uniform mode dropped where K̂(0) = 0.
    /// `None` if K̂ is not positive elsewhere (a zero-padded kernel may not be), when
    /// the inverse is no preconditioner. Periodic: read from the operator's own table
    /// (no memory of its own).
    pub(crate) fn inverse(&self) -> Option<Operator> {
        let (gy, gx) = self.plan.grid();
        let norm = 1.0 / (gy * gx) as f64;
        if self.kernel.rest().any(|k| !(k > 0.0 && k.is_finite())) {
            return None;
        }
        let kernel = match &self.kernel {
            Kernel::Half(k) => Kernel::Half(
                k.iter()
                    .map(|&k| if k > 0.0 { norm * norm / k } else { 0.0 })
                    .collect(),
            ),
            Kernel::Folded {
                table,
                scale,
                inverse,
            } => Kernel::Folded {
                table: Arc::clone(table),
                scale: *scale,
                inverse: !inverse,
            },
        };
        Some(Operator {
            plan: RealFft2::padded((gy, gx), self.plan.data()).ok()?,
            kernel,
            periodic: self.periodic,
            // The preconditioner is applied by FFT only.
            points: Vec::new(),
        })
    }

    /// An upper bound of the operator's norm ‖K‖₂ (m/Pa): the largest |eigenvalue| of
    /// the circulant K (periodic: exact; free: the circulant embedding's, which bounds
    /// its restriction to the sample). `uniform` as in [`Self::apply`].
    pub(crate) fn norm_bound(&self, uniform: bool) -> f64 {
        let (gy, gx) = self.plan.grid();
        let scale = (gy * gx) as f64;
        let rest = self.kernel.rest().fold(0.0_f64, |m, k| m.max(k.abs()));
        rest.max(self.dc(uniform).abs()) * scale
    }

    /// The buffers of a product (the row spectra, ≈ 8 bytes per point on a periodic grid).
    pub(crate) fn work(&self) -> Fft2Work {
        self.plan.convolution_work()
    }

    /// out = K · input. `uniform`: include the periodic k = 0 mode (no effect on a
    /// free-boundary operator, whose k = 0 entry is part of the linear convolution).
    pub(crate) fn apply(
        &self,
        input: &[f64],
        out: &mut [f64],
        uniform: bool,
        work: &mut Fft2Work,
    ) -> Result<(), BemError> {
        self.plan
            .convolve(input, out, self.kernel.multiplier(), self.dc(uniform), work)?;
        Ok(())
    }

    /// Columns nx of the field.
    pub(crate) fn nx(&self) -> usize {
        self.plan.data().1
    }

    /// `out ← drain(K · fill(data))` row by row ([`RealFft2::convolve_with`]): the
    /// per-row work of the solver fused into the FFT's row passes.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn apply_with<A: Merge, B: Merge>(
        &self,
        data: &mut [f64],
        out: &mut [f64],
        uniform: bool,
        work: &mut Fft2Work,
        fill: impl Fn(usize, &mut [f64], &mut [f64]) -> A + Sync,
        drain: impl Fn(usize, &[f64], &[f64], &mut [f64]) -> B + Sync,
    ) -> Result<(A, B), BemError> {
        let rows = RowPasses {
            data,
            out,
            kernel: self.kernel.multiplier(),
            dc: self.dc(uniform),
        };
        Ok(self.plan.convolve_with(rows, work, fill, drain)?)
    }

    /// `K · fill(fields)` with the per-row work of both passes fused, and a gate between
    /// them that may stop the product after the fill ([`RealFft2::convolve_fields`]).
    #[allow(clippy::type_complexity)]
    pub(crate) fn apply_fields<const K: usize, A: Merge, B: Merge, G: Sync>(
        &self,
        fields: [&mut [f64]; K],
        uniform: bool,
        work: &mut Fft2Work,
        fill: impl Fn(usize, [&mut [f64]; K], &mut [f64]) -> A + Sync,
        gate: impl FnOnce(&A) -> Option<G>,
        drain: impl Fn(&G, usize, [&mut [f64]; K], &[f64]) -> B + Sync,
    ) -> Result<(A, Option<B>), BemError> {
        let f = Fields {
            fields,
            kernel: self.kernel.multiplier(),
            dc: self.dc(uniform),
        };
        Ok(self.plan.convolve_fields(f, work, fill, gate, drain)?)
    }

    /// Row `i` of the response to point loads, added to `out` (nx values):
    ///
    /// ```text
    ///   out[x] += Σ_s c_s k(i − i_s, x − x_s)      (points = [(index i_s·nx + x_s, c_s)])
    /// ```
    ///
    /// with k the real-space kernel of [`Self::apply`] (periodic: offsets modulo the cell,
    /// plus the uniform mode if `uniform`; free: the linear convolution's G(|Δi|, |Δx|)).
    /// For a few points this costs far less than a product: one pass per point.
    pub(crate) fn add_points(
        &self,
        points: &[(u32, f64)],
        uniform: bool,
        i: usize,
        out: &mut [f64],
    ) {
        let (ny, nx) = self.plan.data();
        let shift = if self.periodic && uniform {
            self.kernel.at_origin()
        } else {
            0.0
        };
        for &(at, c) in points {
            let (si, sx) = (at as usize / nx, at as usize % nx);
            if self.periodic {
                // Offsets folded modulo the cell: d → min(d, n − d).
                let dy = (i + ny - si) % ny;
                let fy = dy.min(ny - dy);
                let hx = nx / 2 + 1;
                let krow = &self.points[fy * hx..(fy + 1) * hx];
                let k = |dx: usize| krow[dx.min(nx - dx)];
                // x ≥ sx: offset x − sx; x < sx: offset x − sx + nx.
                let (lo, hi) = out.split_at_mut(sx);
                for (dx, o) in hi.iter_mut().enumerate() {
                    *o += c * (k(dx) + shift);
                }
                for (x, o) in lo.iter_mut().enumerate() {
                    *o += c * (k(x + nx - sx) + shift);
                }
            } else {
                let dy = i.abs_diff(si);
                let krow = &self.points[dy * nx..(dy + 1) * nx];
                // x ≥ sx: offset x − sx; x < sx: offset sx − x (G is even).
                let (lo, hi) = out.split_at_mut(sx);
                for (o, &k) in hi.iter_mut().zip(&krow[..nx - sx]) {
                    *o += c * k;
                }
                for (o, &k) in lo.iter_mut().zip(krow[1..=sx].iter().rev()) {
                    *o += c * k;
                }
            }
        }
    }

    /// The (0, 0) kernel entry: 0 for a periodic operator without the uniform mode.
    fn dc(&self, uniform: bool) -> f64 {
        if self.periodic && !uniform {
            0.0
        } else {
            self.kernel.at_origin()
        }
    }

    /// Bytes the operator and one work set take for an ny × nx field (estimate for the
    /// memory check, before anything is allocated).
    pub(crate) fn bytes(ny: usize, nx: usize, periodic: bool) -> u64 {
        let (ny64, nx64) = (ny as u64, nx as u64);
        if periodic {
            let quarter = (nx64 / 2 + 1) * (ny64 / 2 + 1);
            // the kernel table and the point-load response (quarters), the row spectra
            return 8 * quarter + 8 * quarter + 16 * ny64 * (nx64 / 2 + 1);
        }
        let (gy, gx) = (2 * ny64, 2 * nx64);
        let half = (gx / 2 + 1) * gy;
        // kernel (f64), the row spectra (complex), the point-load response (ny·nx), the
        // set-up's circulant and its spectrum
        8 * half + 16 * ny64 * (gx / 2 + 1) + 8 * ny64 * nx64 + 8 * gy * gx + 16 * half
    }
}
