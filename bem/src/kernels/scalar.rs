//! The scalar row loops of the constrained conjugate gradient: the rules themselves,
//! on any CPU. `avx2` hands the blocks of 4 points where the contact set changes to
//! [`UpdateFill::points`] and [`UpdateStep::points`].

use crate::state::{StepSums, Sums, UpdateChunk, UpdateFill, UpdateStep};

/// Σ over the contact set (p > 0) of a step along t with product r, pressure f p
/// ([`StepSums::add`]; Σ g t is formed by the caller).
#[inline(always)]
pub(super) fn step_sums(f: f64, p: &[f64], t: &[f64], r: &[f64]) -> StepSums {
    let mut d = StepSums::default();
    for k in 0..p.len() {
        if p[k] > 0.0 {
            d.add(f * p[k], t[k], r[k]);
        }
    }
    d
}

/// The plain direction row: t = g + β t on the contact set with the gap
/// g = f u − z + c (m), 0 off it, written to `input` too; returns Σ g t.
#[inline(always)]
pub(super) fn direction_row(
    [f, c, beta]: [f64; 3],
    prow: &[f64],
    urow: &[f64],
    zrow: &[f64],
    trow: &mut [f64],
    input: &mut [f64],
) -> f64 {
    let mut acc = 0.0;
    for k in 0..prow.len() {
        trow[k] = if prow[k] > 0.0 {
            let g = f * urow[k] - zrow[k] + c;
            let v = g + beta * trow[k];
            acc += g * v;
            v
        } else {
            0.0
        };
    }
    input.copy_from_slice(trow);
    acc
}

/// The preconditioned direction row: t = (y − ȳ) + β t on the contact set, 0 off it,
/// written to `input` too; returns Σ g t.
#[inline(always)]
pub(super) fn direction_pc_row(
    [ybar, beta]: [f64; 2],
    prow: &[f64],
    y: &[f64],
    g: &[f64],
    t: &mut [f64],
    input: &mut [f64],
) -> f64 {
    let mut gt = 0.0;
    for k in 0..prow.len() {
        let v = if prow[k] > 0.0 {
            let v = y[k] - ybar + beta * t[k];
            gt += g[k] * v;
            v
        } else {
            0.0
        };
        t[k] = v;
        input[k] = v;
    }
    gt
}

/// The next direction of a fused iteration (the contact set unchanged): r′ = q + β r
/// everywhere; on the set (p > 0) t′ = g + β t; the sums of the step along t′ with the
/// pressure f′ p ([`StepSums`], Σ g t′ included).
#[inline(always)]
pub(super) fn next_direction(
    beta: f64,
    f2: f64,
    [p, g]: [&[f64]; 2],
    [t, r]: [&mut [f64]; 2],
    q: &[f64],
) -> StepSums {
    let mut d = StepSums::default();
    for k in 0..q.len() {
        let rn = q[k] + beta * r[k];
        r[k] = rn;
        if p[k] > 0.0 {
            let tn = g[k] + beta * t[k];
            t[k] = tn;
            d.add(f2 * p[k], tn, rn);
            d.gt += g[k] * tn;
        }
    }
    d
}

/// The preconditioner's drain: y = q on the contact set (p > 0), 0 off it; returns
/// [Σ g y, Σ y, Σ g, the count] over the set.
#[inline(always)]
pub(super) fn pc_drain(p: &[f64], g: &[f64], y: &mut [f64], q: &[f64]) -> [f64; 4] {
    let [mut gy, mut ys, mut gs, mut m] = [0.0; 4];
    for k in 0..q.len() {
        if p[k] > 0.0 {
            y[k] = q[k];
            gy += g[k] * q[k];
            ys += q[k];
            gs += g[k];
            m += 1.0;
        } else {
            y[k] = 0.0;
        }
    }
    [gy, ys, gs, m]
}

/// The update rule of a fused iteration (see [`UpdateFill`]).
impl UpdateFill<'_> {
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
}

/// The rule of an update pass (see [`UpdateStep`]).
impl UpdateStep {
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
