//! The update of p and u along a step of the constrained conjugate gradient
//! ([`crate::cg`]): p ← max(f p − τ t, 0) with re-entry where the gap is negative,
//! u ← f u − τ r, fused into the next product's row pass while the contact set stays put
//! ([`UpdateFill`]) or as a pass of its own; and the correction u += K Δ where the
//! projection or the re-entry moved p off the step (Δ ≠ −τ t): by a product, or in real
//! space when at most [`POINT_SUMS`] points changed.

use rayon::prelude::*;
use strata_runtime::fft::Merge;

use crate::BemError;
use crate::cg::{CHUNK, Control, Pending, State, Sums};

/// The points where a pass changed p off the step direction (left the contact set past
/// p = 0, or re-entered it): their number and, up to [`Changed::CAP`] of them, their
/// indices, so that the correction K Δ of a few points can be summed in real space.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Changed {
    n: usize,
    at: [u32; Changed::CAP],
}

impl Default for Changed {
    fn default() -> Self {
        Changed {
            n: 0,
            at: [0; Changed::CAP],
        }
    }
}

impl Changed {
    /// Indices kept; past this only the count.
    pub(crate) const CAP: usize = POINT_SUMS;

    #[inline(always)]
    fn push(&mut self, i: usize) {
        if self.n < Self::CAP {
            self.at[self.n] = i as u32;
        }
        self.n += 1;
    }

    /// Whether any point changed.
    pub(crate) fn any(&self) -> bool {
        self.n > 0
    }

    /// The indices, if all were kept.
    pub(crate) fn points(&self) -> Option<&[u32]> {
        (self.n <= Self::CAP).then(|| &self.at[..self.n])
    }

    pub(crate) fn merge(mut self, o: Self) -> Self {
        let total = self.n + o.n;
        if total <= Self::CAP {
            self.at[self.n..total].copy_from_slice(&o.at[..o.n]);
        }
        self.n = total;
        self
    }
}

/// The fill of a fused iteration (see `State::fused` in [`crate::cg`]): the pending step applied to
/// a row, the new gap on the contact set written to `g` and to the transform's input.
pub(crate) struct UpdateFill<'a> {
    z: &'a [f64],
    nx: usize,
    /// The state's scale and offset, the step.
    f: f64,
    c: f64,
    tau: f64,
    /// The new state's scale and offset, the contact set unchanged.
    pub(crate) f2: f64,
    pub(crate) c2: f64,
}

impl<'a> UpdateFill<'a> {
    /// Row `i`: `rows` = [p, u, g, t, r, corr]; vectorised where the CPU allows
    /// ([`crate::simd`]).
    pub(crate) fn row(&self, i: usize, rows: [&mut [f64]; 6], input: &mut [f64]) -> Sums {
        #[cfg(target_arch = "x86_64")]
        if crate::avx2() {
            // SAFETY: the CPU has AVX2 (checked at run time).
            return unsafe { crate::simd::update_fill_row(self, i, rows, input) };
        }
        let mut acc = Sums::default();
        self.points(i, 0..self.nx, rows, input, &mut acc);
        acc
    }

    /// Points `ks` of row `i` (the scalar rule), added to `acc`.
    #[inline(always)]
    pub(crate) fn points(
        &self,
        i: usize,
        ks: std::ops::Range<usize>,
        rows: [&mut [f64]; 6],
        input: &mut [f64],
        acc: &mut Sums,
    ) {
        let [p, u, g, t, r, corr] = rows;
        let (f, c, tau, f2, c2, nx) = (self.f, self.c, self.tau, self.f2, self.c2, self.nx);
        let zrow = &self.z[i * nx..(i + 1) * nx];
        for k in ks {
            let (pi, ui) = (f * p[k], f * u[k]);
            let v = if pi > 0.0 {
                let v = pi - tau * t[k];
                if v <= 0.0 {
                    acc.changed.push(i * nx + k);
                    if v < 0.0 {
                        corr[k] = -v;
                    }
                    0.0
                } else {
                    v
                }
            } else {
                let g = ui - zrow[k] + c;
                if g < 0.0 {
                    acc.changed.push(i * nx + k);
                    acc.overlap = true;
                    corr[k] = -tau * g;
                    -tau * g
                } else {
                    0.0
                }
            };
            p[k] = v;
            let un = ui - tau * r[k];
            u[k] = un;
            let gap = f2 * un - zrow[k] + c2;
            let gi = if v > 0.0 {
                acc.su += un;
                acc.sz += zrow[k];
                acc.m += 1.0;
                acc.psum += v;
                gap
            } else {
                0.0
            };
            g[k] = gi;
            input[k] = gi;
            acc.stats.add(f2 * v, gap);
        }
    }

    /// A fill from its parts (tests of the vector form against the scalar rule).
    #[cfg(test)]
    pub(crate) fn from_parts(z: &'a [f64], nx: usize, [f, c, tau, f2, c2]: [f64; 5]) -> Self {
        UpdateFill {
            z,
            nx,
            f,
            c,
            tau,
            f2,
            c2,
        }
    }

    /// The step and scales: (f, c, τ, f′, c′), and the row length and heights.
    pub(crate) fn consts(&self) -> ([f64; 5], usize, &[f64]) {
        (
            [self.f, self.c, self.tau, self.f2, self.c2],
            self.nx,
            self.z,
        )
    }
}

/// The step of an update pass ([`State::update`]): the pending scale f, the offset c,
/// the step τ, and the offset if it is known (displacement control: the error terms
/// follow).
#[derive(Clone, Copy)]
pub(crate) struct UpdateStep {
    pub(crate) f: f64,
    pub(crate) c: f64,
    pub(crate) tau: f64,
    pub(crate) known: Option<f64>,
}

/// One chunk of an update pass: p, u and `corr` updated, t, r and z read.
pub(crate) struct UpdateChunk<'s> {
    pub(crate) p: &'s mut [f64],
    pub(crate) u: &'s mut [f64],
    pub(crate) corr: &'s mut [f64],
    pub(crate) t: &'s [f64],
    pub(crate) r: &'s [f64],
    pub(crate) z: &'s [f64],
}

impl UpdateStep {
    /// The chunk starting at point `first`; vectorised where the CPU allows
    /// ([`crate::simd`]).
    pub(crate) fn chunk(&self, first: usize, mut ch: UpdateChunk) -> Sums {
        #[cfg(target_arch = "x86_64")]
        if crate::avx2() {
            // SAFETY: the CPU has AVX2 (checked at run time).
            return unsafe { crate::simd::update_chunk(self, first, ch) };
        }
        let mut acc = Sums::default();
        self.points(first, 0..ch.p.len(), &mut ch, &mut acc);
        acc
    }

    /// Points `ks` of the chunk (the scalar rule), added to `acc`.
    #[inline(always)]
    pub(crate) fn points(
        &self,
        first: usize,
        ks: std::ops::Range<usize>,
        ch: &mut UpdateChunk,
        acc: &mut Sums,
    ) {
        let UpdateStep { f, c, tau, known } = *self;
        let UpdateChunk {
            p,
            u,
            corr,
            t,
            r,
            z,
        } = ch;
        for i in ks {
            let pi = f * p[i];
            let ui = f * u[i];
            let mut k = 0.0;
            let v = if pi > 0.0 {
                let v = pi - tau * t[i];
                if v < 0.0 {
                    k = -v;
                    0.0
                } else {
                    v
                }
            } else {
                let g = ui - z[i] + c;
                if g < 0.0 {
                    k = -tau * g;
                    acc.overlap = true;
                    k
                } else {
                    0.0
                }
            };
            p[i] = v;
            let un = ui - tau * r[i];
            u[i] = un;
            if k != 0.0 {
                acc.changed.push(first + i);
                corr[i] = k;
            }
            if v > 0.0 {
                acc.su += un;
                acc.sz += z[i];
                acc.m += 1.0;
                acc.psum += v;
            }
            if let Some(c) = known {
                acc.stats.add(v, un - z[i] + c);
            }
        }
    }
}

impl<'a> State<'a> {
    /// The fill of a fused iteration applying `step` (n points): the new state's scale
    /// f′ and offset c′ predicted for an unchanged contact set (pressure control:
    /// Σ p′ = p̄N − τ Σt, Σ u′ = Σz − c m − τ Σr over the set).
    pub(crate) fn update_fill(&self, step: Pending, n: usize) -> UpdateFill<'a> {
        let (f, c) = (self.f, self.c);
        let Pending { tau, st, sr, .. } = step;
        let (f2, c2) = match self.control {
            Control::Offset { c, .. } => (1.0, c),
            Control::Pressure(pbar) => {
                let total = pbar * n as f64;
                let psum = total - tau * st;
                let f2 = if psum > 0.0 { total / psum } else { 1.0 };
                let su = self.sz - c * self.m - tau * sr;
                let c2 = if self.m > 0.0 {
                    -(f2 * su - self.sz) / self.m
                } else {
                    0.0
                };
                (f2, c2)
            }
        };
        UpdateFill {
            z: self.pb.z,
            nx: self.pb.op.nx(),
            f,
            c,
            tau,
            f2,
            c2,
        }
    }

    /// p ← max(f p − τ t, 0) with re-entry, u ← f u − τ r; the changes off −τ t go to
    /// `corr`.
    pub(crate) fn update(&mut self, p: &mut [f64], tau: f64) -> Sums {
        let step = UpdateStep {
            f: self.f,
            c: self.c,
            tau,
            known: self.control.known_offset(),
        };
        p.par_chunks_mut(CHUNK)
            .enumerate()
            .zip(self.u.par_chunks_mut(CHUNK))
            .zip(self.corr.par_chunks_mut(CHUNK))
            .zip(self.t.par_chunks(CHUNK))
            .zip(self.r.par_chunks(CHUNK))
            .zip(self.pb.z.par_chunks(CHUNK))
            .map(|((((((chunk, p), u), corr), t), r), z)| {
                step.chunk(
                    chunk * CHUNK,
                    UpdateChunk {
                        p,
                        u,
                        corr,
                        t,
                        r,
                        z,
                    },
                )
            })
            .reduce(Sums::default, Sums::merge)
    }

    /// u += K corr (corr zeroed on the way); the contact-set sums follow. The correction
    /// of at most [`POINT_SUMS`] points is summed in real space ([`Self::correct_points`]),
    /// a larger one by a product.
    pub(crate) fn correct(&mut self, p: &[f64], before: Sums) -> Result<Sums, BemError> {
        // Listed (at most POINT_SUMS points): in real space.
        if let Some(at) = before.changed.points() {
            return Ok(self.correct_points(p, at, before));
        }
        let (z, nx) = (self.pb.z, self.pb.op.nx());
        let known = self.control.known_offset();
        self.products += 1;
        let ((), add) = self.pb.op.apply_with(
            &mut self.corr,
            &mut self.u,
            self.control.uniform(),
            &mut self.work,
            |_, row, input| {
                input.copy_from_slice(row);
                row.fill(0.0);
            },
            |i, _, du, urow| {
                let row = i * nx..(i + 1) * nx;
                add_correction(du, urow, &p[row.clone()], &z[row], known)
            },
        )?;
        Ok(Sums {
            su: before.su + add.su,
            stats: add.stats,
            ..before
        })
    }
}

/// The most changed points whose correction K Δ is summed in real space (one pass over
/// the grid per point, ~1/12 of a product's time at 512² on the 2-core machine) rather
/// than by a product. Along the bench's 512² curve (plain iteration) about half the
/// corrections have ≤ 12 points: products per iteration 1.48 → 1.25.
pub(crate) const POINT_SUMS: usize = 12;

impl State<'_> {
    /// [`Self::correct`] for the changed points `at`, in real space:
    ///
    /// ```text
    ///   u(x) += Σ_j k(x − x_j) Δ_j        ([`Operator::add_points`])
    /// ```
    ///
    /// row by row, with the contact-set sums of the pass.
    fn correct_points(&mut self, p: &[f64], at: &[u32], before: Sums) -> Sums {
        let (z, op, nx) = (self.pb.z, self.pb.op, self.pb.op.nx());
        let known = self.control.known_offset();
        let uniform = self.control.uniform();
        let mut loads = [(0u32, 0.0); Changed::CAP];
        let mut m = 0;
        for &i in at {
            let c = std::mem::take(&mut self.corr[i as usize]);
            if c != 0.0 {
                loads[m] = (i, c);
                m += 1;
            }
        }
        let loads = &loads[..m];
        let rows = (CHUNK / nx).max(1);
        let add = self
            .u
            .par_chunks_mut(rows * nx)
            .enumerate()
            .map_init(
                || vec![0.0; nx],
                |du, (c, uc)| {
                    let mut acc = Sums::default();
                    for (r, urow) in uc.chunks_mut(nx).enumerate() {
                        let i = c * rows + r;
                        du.fill(0.0);
                        op.add_points(loads, uniform, i, du);
                        let row = i * nx..(i + 1) * nx;
                        acc = acc.merge(add_correction(du, urow, &p[row.clone()], &z[row], known));
                    }
                    acc
                },
            )
            .reduce(Sums::default, Sums::merge);
        Sums {
            su: before.su + add.su,
            stats: add.stats,
            ..before
        }
    }
}

/// u += Δu on a row, with Σ Δu over the contact set (p > 0) and, if the offset c is
/// known, the error terms of the corrected gap u − z + c.
fn add_correction(du: &[f64], u: &mut [f64], p: &[f64], z: &[f64], known: Option<f64>) -> Sums {
    let mut acc = Sums::default();
    for k in 0..u.len() {
        u[k] += du[k];
        if p[k] > 0.0 {
            acc.su += du[k];
        }
        if let Some(c) = known {
            acc.stats.add(p[k], u[k] - z[k] + c);
        }
    }
    acc
}
