//! AVX2 forms of the iteration's hottest loops (the fused update and next direction of
//! `cg` and `pcg`, and the update pass of `update`), 4 points per instruction, with the sums in vector
//! accumulators (no serial dependency through one scalar sum or `max`). The crate's
//! baseline is SSE2 and the scalar loops, branchy, are not vectorised by the compiler:
//! these run where [`Kernels::detect`](super::Kernels::detect) found AVX2. A block of 4 points in
//! which the contact set changes is handed to the scalar rule, so the vector path only
//! ever sees the common case. Sums are formed in a different order than the scalar
//! loops (last bits only).

use core::arch::x86_64::*;

use crate::state::{StepSums, Sums, UpdateChunk, UpdateFill, UpdateStep};

/// Σ of the 4 lanes.
#[inline(always)]
unsafe fn hsum(v: __m256d) -> f64 {
    let a: [f64; 4] = unsafe { std::mem::transmute(v) };
    (a[0] + a[1]) + (a[2] + a[3])
}

/// The 4 lanes.
#[inline(always)]
unsafe fn lanes(v: __m256d) -> [f64; 4] {
    unsafe { std::mem::transmute(v) }
}

/// 4 consecutive values from point `k` of each slice.
///
/// # Safety
/// The CPU must support AVX2; k + 4 ≤ the length of every slice.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn load<const N: usize>(s: [&[f64]; N], k: usize) -> [__m256d; N] {
    debug_assert!(s.iter().all(|v| k + 4 <= v.len()));
    // SAFETY: k + 4 ≤ len (the caller's contract).
    s.map(|v| unsafe { _mm256_loadu_pd(v.as_ptr().add(k)) })
}

/// 4 points of a step p ← f p − τ t, u ← f u − τ r ([`UpdateFill`], [`UpdateStep`]): the
/// scaled displacement f u, the contact mask (f p > 0), f p − τ t, and whether the contact
/// set changes among them: a contact point reaches p ≤ 0 (p < 0 if `strict`) or a point
/// off the set has a negative gap f u − z + c (re-entry).
struct Step4 {
    ui: __m256d,
    contact: __m256d,
    along: __m256d,
    changes: bool,
}

/// [`Step4`] from the scale, offset and step `[f, c, τ]` and the points' `[p, u, t, z]`.
#[target_feature(enable = "avx2")]
#[inline]
fn step4([vf, vc, vtau]: [__m256d; 3], [pp, uu, tt, zz]: [__m256d; 4], strict: bool) -> Step4 {
    let zero = _mm256_setzero_pd();
    let pi = _mm256_mul_pd(vf, pp);
    let ui = _mm256_mul_pd(vf, uu);
    let contact = _mm256_cmp_pd::<_CMP_GT_OQ>(pi, zero);
    let along = _mm256_sub_pd(pi, _mm256_mul_pd(vtau, tt));
    let gap_old = _mm256_add_pd(_mm256_sub_pd(ui, zz), vc);
    let below = if strict {
        _mm256_cmp_pd::<_CMP_LT_OQ>(along, zero)
    } else {
        _mm256_cmp_pd::<_CMP_LE_OQ>(along, zero)
    };
    let leave = _mm256_and_pd(contact, below);
    let enter = _mm256_andnot_pd(contact, _mm256_cmp_pd::<_CMP_LT_OQ>(gap_old, zero));
    Step4 {
        ui,
        contact,
        along,
        changes: _mm256_movemask_pd(_mm256_or_pd(leave, enter)) != 0,
    }
}

/// Lane accumulators of a pass that changes u ([`Sums`]): Σ u, Σ z, the count and Σ p
/// over the contact set, and the error terms ([`crate::state::Stats`]).
struct SumsLanes {
    su: __m256d,
    sz: __m256d,
    m: __m256d,
    ps: __m256d,
    sp: __m256d,
    gg: __m256d,
    gmax: __m256d,
    pen: __m256d,
    /// Lanes where a gap was not finite.
    bad: __m256d,
}

impl SumsLanes {
    #[target_feature(enable = "avx2")]
    #[inline]
    fn new() -> Self {
        let z = _mm256_setzero_pd();
        SumsLanes {
            su: z,
            sz: z,
            m: z,
            ps: z,
            sp: z,
            gg: z,
            gmax: z,
            pen: z,
            bad: z,
        }
    }

    /// Points of the contact set `inside` (mask) with pressure `v` (0 off it),
    /// displacement `u` and height `z`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn contact(&mut self, inside: __m256d, v: __m256d, u: __m256d, z: __m256d) {
        self.su = _mm256_add_pd(self.su, _mm256_and_pd(inside, u));
        self.sz = _mm256_add_pd(self.sz, _mm256_and_pd(inside, z));
        self.m = _mm256_add_pd(self.m, _mm256_and_pd(inside, _mm256_set1_pd(1.0)));
        self.ps = _mm256_add_pd(self.ps, v);
    }

    /// The error terms of pressure `pv` (0 off the set) and gap `gap`: Σ p, Σ g² and
    /// max |g| on the set, max(−g) off it (`Stats::add`).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn error(&mut self, inside: __m256d, pv: __m256d, gap: __m256d) {
        let zero = _mm256_setzero_pd();
        let abs = _mm256_andnot_pd(_mm256_set1_pd(-0.0), gap);
        self.sp = _mm256_add_pd(self.sp, pv);
        self.gg = _mm256_add_pd(self.gg, _mm256_and_pd(inside, _mm256_mul_pd(gap, gap)));
        self.gmax = _mm256_max_pd(self.gmax, _mm256_and_pd(inside, abs));
        let below = _mm256_andnot_pd(inside, _mm256_sub_pd(zero, gap));
        self.pen = _mm256_max_pd(self.pen, below);
        self.bad = _mm256_or_pd(self.bad, _mm256_cmp_pd::<_CMP_UNORD_Q>(gap, gap));
    }

    /// Adds the lanes to `acc`; `error`: whether the error terms were formed. A gap that
    /// was not finite makes the error NaN (the solve stops).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn finish(self, acc: &mut Sums, error: bool) {
        // SAFETY: AVX2 (this function's feature).
        unsafe {
            acc.su += hsum(self.su);
            acc.sz += hsum(self.sz);
            acc.m += hsum(self.m);
            acc.psum += hsum(self.ps);
            if error {
                acc.stats.psum += hsum(self.sp);
                acc.stats.gg += hsum(self.gg);
                acc.stats.pen = lanes(self.pen).iter().fold(acc.stats.pen, |a, &b| a.max(b));
                acc.stats.gmax = lanes(self.gmax)
                    .iter()
                    .fold(acc.stats.gmax, |a, &b| a.max(b));
            }
        }
        if _mm256_movemask_pd(self.bad) != 0 {
            acc.stats.pen = f64::NAN;
        }
    }
}

/// Lane accumulators of [`StepSums`]: Σ g t, Σ r t, Σ t, Σ r, the count over the contact
/// set, min p / t over t > 0 on it.
struct StepLanes {
    gt: __m256d,
    rt: __m256d,
    t: __m256d,
    r: __m256d,
    m: __m256d,
    leave: __m256d,
}

impl StepLanes {
    #[target_feature(enable = "avx2")]
    #[inline]
    fn new() -> Self {
        let z = _mm256_setzero_pd();
        StepLanes {
            gt: z,
            rt: z,
            t: z,
            r: z,
            m: z,
            leave: _mm256_set1_pd(f64::INFINITY),
        }
    }

    /// Points of the contact set `inside` (mask) with pressure `p`, direction `t` and
    /// product `r` (`StepSums::add`).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn add(&mut self, inside: __m256d, p: __m256d, t: __m256d, r: __m256d) {
        self.rt = _mm256_add_pd(self.rt, _mm256_and_pd(inside, _mm256_mul_pd(r, t)));
        self.t = _mm256_add_pd(self.t, _mm256_and_pd(inside, t));
        self.r = _mm256_add_pd(self.r, _mm256_and_pd(inside, r));
        self.m = _mm256_add_pd(self.m, _mm256_and_pd(inside, _mm256_set1_pd(1.0)));
        let ahead = _mm256_and_pd(inside, _mm256_cmp_pd::<_CMP_GT_OQ>(t, _mm256_setzero_pd()));
        let ratio = _mm256_div_pd(p, t);
        let inf = _mm256_set1_pd(f64::INFINITY);
        self.leave = _mm256_min_pd(self.leave, _mm256_blendv_pd(inf, ratio, ahead));
    }

    /// Σ g t over the contact set.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn gt(&mut self, inside: __m256d, g: __m256d, t: __m256d) {
        self.gt = _mm256_add_pd(self.gt, _mm256_and_pd(inside, _mm256_mul_pd(g, t)));
    }

    /// Adds the lanes to `d`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn finish(self, d: &mut StepSums) {
        // SAFETY: AVX2 (this function's feature).
        unsafe {
            d.gt += hsum(self.gt);
            d.rt += hsum(self.rt);
            d.t += hsum(self.t);
            d.r += hsum(self.r);
            d.m += hsum(self.m);
            d.leave = lanes(self.leave).iter().fold(d.leave, |a, &b| a.min(b));
        }
    }
}

/// The fused update row of [`UpdateFill`] on AVX2: the pending step applied to row `i` of p and u, the new
/// gap on the contact set written to g and to the transform's input, and the sums.
///
/// # Safety
/// The CPU must support AVX2; the rows must hold the row length nx of the fill.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn update_fill_row(
    fill: &UpdateFill,
    i: usize,
    rows: [&mut [f64]; 6],
    input: &mut [f64],
) -> Sums {
    let ([f, c, tau, f2, c2], nx, z) = fill.consts();
    let [p, u, g, t, r, corr] = rows;
    let z = &z[i * nx..(i + 1) * nx];
    let (p, u, g, t, r, input) = (
        &mut p[..nx],
        &mut u[..nx],
        &mut g[..nx],
        &mut t[..nx],
        &mut r[..nx],
        &mut input[..nx],
    );
    let mut acc = Sums::default();
    let (vf, vc, vtau) = (_mm256_set1_pd(f), _mm256_set1_pd(c), _mm256_set1_pd(tau));
    let (vf2, vc2) = (_mm256_set1_pd(f2), _mm256_set1_pd(c2));
    let mut sums = SumsLanes::new();
    let whole = nx - nx % 4;
    let mut k = 0;
    while k < whole {
        // SAFETY: k + 4 ≤ nx and every row holds nx values.
        let [pp, uu, tt, rr, zz] = unsafe { load([&*p, &*u, &*t, &*r, z], k) };
        let Step4 {
            ui,
            contact,
            along,
            changes,
        } = step4([vf, vc, vtau], [pp, uu, tt, zz], false);
        if changes {
            // The set changes here: the scalar rule (projection, re-entry, Δ listed).
            let rows = [&mut *p, &mut *u, &mut *g, &mut *t, &mut *r, &mut *corr];
            fill.points(i, k..k + 4, rows, input, &mut acc);
            k += 4;
            continue;
        }
        // The set stays: p′ = f p − τ t on it (> 0), 0 off it.
        let v = _mm256_and_pd(contact, along);
        let un = _mm256_sub_pd(ui, _mm256_mul_pd(vtau, rr));
        let gap = _mm256_add_pd(_mm256_sub_pd(_mm256_mul_pd(vf2, un), zz), vc2);
        let gi = _mm256_and_pd(contact, gap);
        // SAFETY: as the loads.
        unsafe {
            _mm256_storeu_pd(p.as_mut_ptr().add(k), v);
            _mm256_storeu_pd(u.as_mut_ptr().add(k), un);
            _mm256_storeu_pd(g.as_mut_ptr().add(k), gi);
            _mm256_storeu_pd(input.as_mut_ptr().add(k), gi);
        }
        sums.contact(contact, v, un, zz);
        // Error terms (Stats::add with the pressure f′ p′).
        sums.error(contact, _mm256_mul_pd(vf2, v), gap);
        k += 4;
    }
    if whole < nx {
        let rows = [&mut *p, &mut *u, &mut *g, &mut *t, &mut *r, &mut *corr];
        fill.points(i, whole..nx, rows, input, &mut acc);
    }
    sums.finish(&mut acc, true);
    acc
}

/// The next direction of a fused iteration on AVX2 (the contact set unchanged):
/// r′ = q + β r everywhere; on the set (p > 0) t′ = g + β t; the sums of the step along
/// t′ with the pressure f′ p ([`StepSums`], Σ g t′ included).
///
/// # Safety
/// The CPU must support AVX2; p, g, t, r hold at least q.len() values.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn next_direction(
    beta: f64,
    f2: f64,
    [p, g]: [&[f64]; 2],
    [t, r]: [&mut [f64]; 2],
    q: &[f64],
) -> StepSums {
    let nx = q.len();
    let (p, g, t, r) = (&p[..nx], &g[..nx], &mut t[..nx], &mut r[..nx]);
    let vb = _mm256_set1_pd(beta);
    let vf2 = _mm256_set1_pd(f2);
    let zero = _mm256_setzero_pd();
    let mut sums = StepLanes::new();
    let whole = nx - nx % 4;
    let mut k = 0;
    while k < whole {
        // SAFETY: k + 4 ≤ nx and every slice holds nx values.
        let [pp, gv, tt, rr, qq] = unsafe { load([p, g, &*t, &*r, q], k) };
        let rn = _mm256_add_pd(qq, _mm256_mul_pd(vb, rr));
        let inside = _mm256_cmp_pd::<_CMP_GT_OQ>(pp, zero);
        let tn = _mm256_blendv_pd(tt, _mm256_add_pd(gv, _mm256_mul_pd(vb, tt)), inside);
        // SAFETY: as the loads.
        unsafe {
            _mm256_storeu_pd(r.as_mut_ptr().add(k), rn);
            _mm256_storeu_pd(t.as_mut_ptr().add(k), tn);
        }
        sums.add(inside, _mm256_mul_pd(vf2, pp), tn, rn);
        sums.gt(inside, gv, tn);
        k += 4;
    }
    let mut d = StepSums::default();
    for k in whole..nx {
        let rn = q[k] + beta * r[k];
        r[k] = rn;
        if p[k] > 0.0 {
            let tn = g[k] + beta * t[k];
            t[k] = tn;
            d.add(f2 * p[k], tn, rn);
            d.gt += g[k] * tn;
        }
    }
    sums.finish(&mut d);
    d
}

/// [`UpdateStep::chunk`] on AVX2: p ← max(f p − τ t, 0) with re-entry, u ← f u − τ r
/// on a chunk starting at point `first`, with the sums (and the error terms under
/// displacement control). Blocks in which a point leaves past p = 0 or re-enters go to
/// the scalar rule.
///
/// # Safety
/// The CPU must support AVX2; the chunk's slices have equal lengths.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn update_chunk(step: &UpdateStep, first: usize, mut ch: UpdateChunk) -> Sums {
    let n = ch.p.len();
    let mut acc = Sums::default();
    let (vf, vc, vtau) = (
        _mm256_set1_pd(step.f),
        _mm256_set1_pd(step.c),
        _mm256_set1_pd(step.tau),
    );
    let vk = _mm256_set1_pd(step.known.unwrap_or(0.0));
    let zero = _mm256_setzero_pd();
    let mut sums = SumsLanes::new();
    assert!(ch.u.len() == n && ch.t.len() == n && ch.r.len() == n && ch.z.len() == n);
    let whole = n - n % 4;
    let mut k = 0;
    while k < whole {
        let UpdateChunk { p, u, t, r, z, .. } = &mut ch;
        // SAFETY: k + 4 ≤ n and every slice holds n values (asserted).
        let [pp, uu, tt, rr, zz] = unsafe { load([p, u, t, r, z], k) };
        let Step4 {
            ui,
            contact,
            along,
            changes,
        } = step4([vf, vc, vtau], [pp, uu, tt, zz], true);
        if changes {
            step.points(first, k..k + 4, &mut ch, &mut acc);
            k += 4;
            continue;
        }
        // No projection, no re-entry: p′ = f p − τ t (≥ 0) on the set, 0 off it.
        let v = _mm256_and_pd(contact, along);
        let un = _mm256_sub_pd(ui, _mm256_mul_pd(vtau, rr));
        // SAFETY: as the loads.
        unsafe {
            _mm256_storeu_pd(p.as_mut_ptr().add(k), v);
            _mm256_storeu_pd(u.as_mut_ptr().add(k), un);
        }
        let inside = _mm256_cmp_pd::<_CMP_GT_OQ>(v, zero);
        sums.contact(inside, v, un, zz);
        if step.known.is_some() {
            sums.error(inside, v, _mm256_add_pd(_mm256_sub_pd(un, zz), vk));
        }
        k += 4;
    }
    if whole < n {
        step.points(first, whole..n, &mut ch, &mut acc);
    }
    sums.finish(&mut acc, step.known.is_some());
    acc
}

/// The sums of a step along t with product q on the contact set (p > 0) of pressure
/// f p ([`StepSums::add`]; Σ g t is formed by the caller), on AVX2.
///
/// # Safety
/// The CPU must support AVX2; p and t hold at least q.len() values.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn step_sums(f: f64, p: &[f64], t: &[f64], q: &[f64]) -> StepSums {
    let n = q.len();
    let (p, t) = (&p[..n], &t[..n]);
    let vf = _mm256_set1_pd(f);
    let zero = _mm256_setzero_pd();
    let mut sums = StepLanes::new();
    let whole = n - n % 4;
    let mut k = 0;
    while k < whole {
        // SAFETY: k + 4 ≤ n and every slice holds n values.
        let [pp, tt, qq] = unsafe { load([p, t, q], k) };
        let inside = _mm256_cmp_pd::<_CMP_GT_OQ>(pp, zero);
        sums.add(inside, _mm256_mul_pd(vf, pp), tt, qq);
        k += 4;
    }
    let mut d = StepSums::default();
    for k in whole..n {
        if p[k] > 0.0 {
            d.add(f * p[k], t[k], q[k]);
        }
    }
    sums.finish(&mut d);
    d
}

/// A conjugate direction row on AVX2: t = a + β t on the contact set (p > 0), 0 off
/// it, with a = `a(k)` given 4 points at a time; t also written to `input`; returns
/// Σ w t over the set with w = `w(k)`.
///
/// # Safety
/// The CPU must support AVX2; the slices hold p.len() values and `a`, `w` read within
/// them.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn conjugate_row(
    p: &[f64],
    t: &mut [f64],
    input: &mut [f64],
    beta: f64,
    a: impl Fn(usize) -> __m256d,
    w: impl Fn(usize) -> __m256d,
    scalar: impl Fn(usize) -> (f64, f64),
) -> f64 {
    let n = p.len();
    let (t, input) = (&mut t[..n], &mut input[..n]);
    let vb = _mm256_set1_pd(beta);
    let zero = _mm256_setzero_pd();
    let mut acc = zero;
    let whole = n - n % 4;
    let mut k = 0;
    while k < whole {
        // SAFETY: k + 4 ≤ n and every slice holds n values.
        let [pp, tt] = unsafe { load([p, t], k) };
        let inside = _mm256_cmp_pd::<_CMP_GT_OQ>(pp, zero);
        let v = _mm256_and_pd(inside, _mm256_add_pd(a(k), _mm256_mul_pd(vb, tt)));
        // SAFETY: as the loads.
        unsafe {
            _mm256_storeu_pd(t.as_mut_ptr().add(k), v);
            _mm256_storeu_pd(input.as_mut_ptr().add(k), v);
        }
        acc = _mm256_add_pd(acc, _mm256_and_pd(inside, _mm256_mul_pd(w(k), v)));
        k += 4;
    }
    let mut tail = 0.0;
    for k in whole..n {
        let v = if p[k] > 0.0 {
            let (a, w) = scalar(k);
            let v = a + beta * t[k];
            tail += w * v;
            v
        } else {
            0.0
        };
        t[k] = v;
        input[k] = v;
    }
    // SAFETY: AVX2 (the caller's feature).
    unsafe { hsum(acc) + tail }
}

/// The plain direction row on AVX2: t = g + β t on the contact set with the gap
/// g = f u − z + c, written to `input` too; returns Σ g t.
///
/// # Safety
/// The CPU must support AVX2; all slices hold p.len() values.
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
pub(crate) unsafe fn direction_row(
    [f, c, beta]: [f64; 3],
    p: &[f64],
    u: &[f64],
    z: &[f64],
    t: &mut [f64],
    input: &mut [f64],
) -> f64 {
    let n = p.len();
    let (u, z) = (&u[..n], &z[..n]);
    let (vf, vc) = (_mm256_set1_pd(f), _mm256_set1_pd(c));
    // SAFETY: the loads below stay within u and z (k + 4 ≤ n).
    let gap = |k: usize| unsafe {
        _mm256_add_pd(
            _mm256_sub_pd(
                _mm256_mul_pd(vf, _mm256_loadu_pd(u.as_ptr().add(k))),
                _mm256_loadu_pd(z.as_ptr().add(k)),
            ),
            vc,
        )
    };
    let scalar = |k: usize| {
        let g = f * u[k] - z[k] + c;
        (g, g)
    };
    // SAFETY: AVX2 (this function's feature); lengths as required.
    unsafe { conjugate_row(p, t, input, beta, gap, gap, scalar) }
}

/// The preconditioned direction row on AVX2: t = (y − ȳ) + β t on the contact set,
/// written to `input` too; returns Σ g t.
///
/// # Safety
/// The CPU must support AVX2; all slices hold p.len() values.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn direction_pc_row(
    [ybar, beta]: [f64; 2],
    p: &[f64],
    y: &[f64],
    g: &[f64],
    t: &mut [f64],
    input: &mut [f64],
) -> f64 {
    let n = p.len();
    let (y, g) = (&y[..n], &g[..n]);
    let vy = _mm256_set1_pd(ybar);
    // SAFETY: the loads stay within y and g (k + 4 ≤ n).
    let a = |k: usize| unsafe { _mm256_sub_pd(_mm256_loadu_pd(y.as_ptr().add(k)), vy) };
    // SAFETY: as above.
    let w = |k: usize| unsafe { _mm256_loadu_pd(g.as_ptr().add(k)) };
    let scalar = |k: usize| (y[k] - ybar, g[k]);
    // SAFETY: AVX2 (this function's feature); lengths as required.
    unsafe { conjugate_row(p, t, input, beta, a, w, scalar) }
}

/// The preconditioner's drain on AVX2: y = q on the contact set (p > 0), 0 off it, with
/// Σ g y, Σ y, Σ g and the count over the set.
///
/// # Safety
/// The CPU must support AVX2; p, g, y hold at least q.len() values.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn pc_drain(p: &[f64], g: &[f64], y: &mut [f64], q: &[f64]) -> [f64; 4] {
    let n = q.len();
    let (p, g, y) = (&p[..n], &g[..n], &mut y[..n]);
    let zero = _mm256_setzero_pd();
    let one = _mm256_set1_pd(1.0);
    let (mut gy, mut ys, mut gs, mut m) = (zero, zero, zero, zero);
    let whole = n - n % 4;
    let mut k = 0;
    while k < whole {
        // SAFETY: k + 4 ≤ n and every slice holds n values.
        let [pp, gg, qq] = unsafe { load([p, g, q], k) };
        let inside = _mm256_cmp_pd::<_CMP_GT_OQ>(pp, zero);
        let v = _mm256_and_pd(inside, qq);
        // SAFETY: as the loads.
        unsafe { _mm256_storeu_pd(y.as_mut_ptr().add(k), v) };
        gy = _mm256_add_pd(gy, _mm256_and_pd(inside, _mm256_mul_pd(gg, v)));
        ys = _mm256_add_pd(ys, v);
        gs = _mm256_add_pd(gs, _mm256_and_pd(inside, gg));
        m = _mm256_add_pd(m, _mm256_and_pd(inside, one));
        k += 4;
    }
    let mut out = [0.0; 4];
    for k in whole..n {
        if p[k] > 0.0 {
            y[k] = q[k];
            out[0] += g[k] * q[k];
            out[1] += q[k];
            out[2] += g[k];
            out[3] += 1.0;
        } else {
            y[k] = 0.0;
        }
    }
    // SAFETY: AVX2 (this function's feature).
    unsafe {
        [
            out[0] + hsum(gy),
            out[1] + hsum(ys),
            out[2] + hsum(gs),
            out[3] + hsum(m),
        ]
    }
}
