//! The update of p and u along a step of the constrained conjugate gradient
//! (`cg` and `pcg`): p ← max(f p − τ t, 0) with re-entry where the gap is negative,
//! u ← f u − τ r, fused into the next product's row pass while the contact set stays put
//! (`UpdateFill`, row loops in `kernels`) or as a pass of its own; and the correction u += K Δ where the
//! projection or the re-entry moved p off the step (Δ ≠ −τ t): by a product, or in real
//! space when at most [`POINT_SUMS`](crate::state::POINT_SUMS) points changed; and the end of a step that was not
//! fused ([`State::finish`]).

use rayon::prelude::*;
use strata_runtime::fft::Merge;

use crate::BemError;
use crate::iteration::{State, with_rows};
use crate::state::{CHUNK, Changed, Control, Pending, Sums, UpdateChunk, UpdateFill, UpdateStep};

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
        let kernels = self.pb.kernels;
        let step = UpdateStep {
            f: self.f,
            c: self.c,
            tau,
            known: self.control.known_offset(),
        };
        if !self.corr.is_empty() {
            return p
                .par_chunks_mut(CHUNK)
                .enumerate()
                .zip(self.u.par_chunks_mut(CHUNK))
                .zip(self.corr.par_chunks_mut(CHUNK))
                .zip(self.t.par_chunks(CHUNK))
                .zip(self.r.par_chunks(CHUNK))
                .zip(self.pb.z.par_chunks(CHUNK))
                .map(|((((((chunk, p), u), corr), t), r), z)| {
                    kernels.update_chunk(
                        &step,
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
                .reduce(Sums::default, Sums::merge);
        }
        // Preconditioned: Δp written over r, each chunk once the update has read it.
        p.par_chunks_mut(CHUNK)
            .enumerate()
            .zip(self.u.par_chunks_mut(CHUNK))
            .zip(self.r.par_chunks_mut(CHUNK))
            .zip(self.t.par_chunks(CHUNK))
            .zip(self.pb.z.par_chunks(CHUNK))
            .map(|(((((chunk, p), u), r), t), z)| {
                with_rows(r.len(), |corr, _| {
                    let sums = kernels.update_chunk(
                        &step,
                        chunk * CHUNK,
                        UpdateChunk {
                            p,
                            u,
                            corr: &mut *corr,
                            t,
                            r: &*r,
                            z,
                        },
                    );
                    r.copy_from_slice(corr);
                    sums
                })
            })
            .reduce(Sums::default, Sums::merge)
    }

    /// u += K corr (corr zeroed on the way); the contact-set sums follow. The correction
    /// of at most [`POINT_SUMS`](crate::state::POINT_SUMS) points is summed in real space ([`Self::correct_points`]),
    /// a larger one by a product.
    pub(crate) fn correct(&mut self, p: &[f64], before: Sums) -> Result<Sums, BemError> {
        // Listed (at most POINT_SUMS points): in real space.
        if let Some(at) = before.changed.points() {
            return Ok(self.correct_points(p, at, before));
        }
        let (z, nx) = (self.pb.z, self.pb.op.nx());
        let known = self.control.known_offset();
        self.products += 1;
        let corr = if self.corr.is_empty() {
            &mut self.r
        } else {
            &mut self.corr
        };
        let ((), add) = self.pb.op.apply_with(
            corr,
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
            let c = std::mem::take(&mut self.corr_buffer()[i as usize]);
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

impl State<'_> {
    /// After an update that was not fused (or stopped): u corrected by K Δ if the contact
    /// set changed, the pending scale (pressure control), the offset and error terms.
    /// Returns whether points re-entered the contact set (the conjugation restarts).
    pub(crate) fn finish(&mut self, p: &mut [f64], mut sums: Sums) -> Result<bool, BemError> {
        self.f = 1.0;
        if sums.changed.any() {
            // The contact set changed: add K Δ (the second product of this iteration,
            // or a sum in real space over a few points).
            sums = self.correct(p, sums)?;
        }
        let overlap = sums.overlap;
        if let Control::Pressure(pbar) = self.control {
            if sums.psum > 0.0 {
                self.f = pbar * p.len() as f64 / sums.psum;
            } else {
                // Every point left the contact: restart from the uniform pressure.
                p.fill(pbar);
                self.exact(p)?;
                return Ok(true);
            }
        }
        self.settle(p, sums);
        Ok(overlap)
    }
}
