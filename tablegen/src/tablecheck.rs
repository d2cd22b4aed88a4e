//! Measuring a table against direct quadrature ([`crate::approx`]): the
//! interpolation error at random off-grid points ([`check`]) and the error of the far
//! field of g beyond the tabulated range ([`far_field_error`], [`choose_far_field`]).
//!
//! Errors are stated like the table's tolerance: χ and ζ relative, g absolute in
//! units of the outside displacement's scale (4/3)a³/r.

use rayon::prelude::*;
use strata_runtime::table::far::{FAR_TERMS, FarField};
use strata_runtime::table::{Axis, InterpError, Table};
use strata_runtime::{Bodies, Compliance, Solid};

use crate::approx::{Approx, ApproxError};
use crate::error::BuildError;
use crate::progress::bar;

/// SplitMix64: a tiny deterministic generator for reproducible check points
/// (uniform in [0, 1) with 53 random bits).
pub struct SplitMix(pub u64);
impl SplitMix {
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Every fourth check point also samples the far field.
const FAR_EVERY: usize = 4;
/// Far-field check points lie at w ∈ [w_max, w_max + FAR_SPAN]: r − a up to
/// ~e^{2·FAR_SPAN} ≈ 20 × the join distance.
const FAR_SPAN: f64 = 1.5;

/// Compares the table's interpolated χ, ζ and g with fresh direct solves at `points`
/// random points (uniform in ln(a/h₁), w ∈ [0, w_max] and the family coordinate;
/// seed `seed`), and its far field of g with direct solves at every fourth point
/// moved beyond the join (w ∈ [w_max, w_max + 1.5]). Returns max |χ_t/χ − 1|,
/// max |ζ_t/ζ − 1|, max |g_t − g|/((4/3)a³/r) inside and beyond the join.
pub fn check(
    table: &Table,
    points: usize,
    seed: u64,
    progress: bool,
) -> Result<InterpError, BuildError> {
    check_with(
        table,
        points,
        seed,
        &bar(points, progress, None, "checking table"),
    )
}

/// [`check`] advancing the caller's progress bar `pb` by one per point.
pub fn check_with(
    table: &Table,
    points: usize,
    seed: u64,
    pb: &indicatif::ProgressBar,
) -> Result<InterpError, BuildError> {
    let h = &table.header;
    let mut rng = SplitMix(seed);
    let fam = h.family.map(|f| f.ratio);
    let pts: Vec<(f64, f64, f64, f64)> = (0..points)
        .map(|_| {
            let c = fam.map_or(0.0, |f| f.lo + (f.hi - f.lo) * rng.next_f64());
            let cx = h.x.lo + (h.x.hi - h.x.lo) * rng.next_f64();
            let w = h.w.hi * rng.next_f64();
            let wf = h.w.hi + FAR_SPAN * rng.next_f64();
            (c, cx, w, wf)
        })
        .collect();
    let errs: Vec<Result<[f64; 4], BuildError>> = pts
        .par_iter()
        .enumerate()
        .map(|(i, &(c, cx, w, wf))| {
            let member = table.member_stack(c)?;
            let law = table.law_for(&member)?;
            let ap = Approx::new(&member);
            let h1 = member.top_thickness().unwrap_or(1.0);
            let a = h1 * cx.exp();
            let r = a + h1 * w.sinh().powi(2);
            let (chi, zeta) = ap.chi_zeta(a)?;
            let (tc, tz) = law.try_chi_zeta(a)?;
            let g = ap.g(a, r)?;
            let tg = law.try_g(a, r)?;
            let mut far = 0.0;
            if i % FAR_EVERY == 0 {
                let rf = a + h1 * wf.sinh().powi(2);
                far = (law.try_g(a, rf)? - ap.g(a, rf)?).abs() / scale(a, rf);
            }
            pb.inc(1);
            Ok([
                (tc / chi - 1.0).abs(),
                (tz / zeta - 1.0).abs(),
                (tg - g).abs() / scale(a, r),
                far,
            ])
        })
        .collect();
    pb.finish_and_clear();
    let mut out = InterpError {
        points,
        seed,
        chi: 0.0,
        zeta: 0.0,
        g: 0.0,
        far: 0.0,
    };
    for e in errs {
        let [c, z, g, f] = e?;
        out.chi = out.chi.max(c);
        out.zeta = out.zeta.max(z);
        out.g = out.g.max(g);
        out.far = out.far.max(f);
    }
    Ok(out)
}

/// (4/3)a³/r (m²): the scale of g errors.
pub(crate) fn scale(a: f64, r: f64) -> f64 {
    4.0 / 3.0 * a * a * a / r
}

/// The far field of g of `stack` with all [`FAR_TERMS`] correction terms (the
/// leading term only on a rigid base, where it is exact: module docs of
/// [`strata_runtime::table::far`]).
pub fn far_field_of(stack: &(impl Solid + ?Sized)) -> FarField {
    let comp = Compliance::new(stack);
    if stack.on_rigid_bases() {
        return FarField::leading(comp.s_at_zero() - 1.0);
    }
    FarField::new(&comp, stack.total_thickness())
}

/// Probe contact radii: 9 values spread over the x axis (ln(a/h₁)), ends included.
const PROBE_A: usize = 9;
/// Probe distances r − a in units of the join distance.
const PROBE_R: [f64; 3] = [1.0, 2.0, 4.0];

/// Far-field error of each truncation m = 0 … FAR_TERMS of `far` against direct
/// quadrature, max over the probes (a over `x`, r − a = 1, 2, 4 × `join` (m)):
/// max |g_direct − Σ_{k≤m} k_{2k}Φ_k|/((4/3)a³/r).
pub fn far_field_error(
    stack: &(impl Solid + ?Sized),
    far: &FarField,
    x: &Axis,
    join: f64,
) -> Result<Vec<f64>, ApproxError> {
    let ap = Approx::new(stack);
    let h1 = ap.h1();
    // Truncations beyond the available coefficients (rigid base: one) equal the full one.
    let mut worst = vec![0.0_f64; FAR_TERMS + 1];
    for i in 0..PROBE_A {
        let a = h1 * (x.lo + (x.hi - x.lo) * i as f64 / (PROBE_A - 1) as f64).exp();
        for f in PROBE_R {
            let r = a + f * join;
            let g = ap.g(a, r)?;
            for (m, w) in worst.iter_mut().enumerate() {
                let part = FarField {
                    coeffs: far.coeffs[..=m.min(far.coeffs.len() - 1)].to_vec(),
                };
                let e = (g - part.g(a, r)).abs() / scale(a, r);
                // A NaN (never expected) must count as a failure, not vanish in max.
                *w = if e.is_nan() { f64::INFINITY } else { w.max(e) };
            }
        }
    }
    Ok(worst)
}

/// The far field a table uses: the join distance (m) and the number of correction
/// terms, with the measured error (max over members and probes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FarChoice {
    /// r − a beyond which g is the far field (m): h₁ sinh²(w_max).
    pub join: f64,
    /// Correction terms beyond k_z(0)·HS (0 … FAR_TERMS).
    pub terms: usize,
    /// Measured max |g_direct − g_far|/((4/3)a³/r).
    pub error: f64,
}

/// Chooses the far field of a table of `members`: starting at `join` (m), the number
/// of terms with the smallest error over every member; while that error exceeds
/// `tol`, doubles the join distance up to `join_max` (m), as long as each doubling at
/// least halves the error. Returns the first choice within `tol`, or the last one
/// measured (the caller refuses it).
pub fn choose_far_field(
    members: &[Bodies],
    x: &Axis,
    mut join: f64,
    join_max: f64,
    tol: f64,
) -> Result<FarChoice, ApproxError> {
    let fars: Vec<FarField> = members.iter().map(far_field_of).collect();
    let mut last: Option<f64> = None;
    loop {
        let errs: Vec<Result<Vec<f64>, ApproxError>> = members
            .par_iter()
            .zip(&fars)
            .map(|(st, far)| far_field_error(st, far, x, join))
            .collect();
        let mut worst = [0.0_f64; FAR_TERMS + 1];
        for e in errs {
            for (m, v) in e?.into_iter().enumerate() {
                worst[m] = worst[m].max(v);
            }
        }
        // Rigid bases have the leading term only: their entries beyond m = 0 stay 0
        // and do not restrict the choice.
        let (terms, error) =
            worst
                .iter()
                .copied()
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |best, (m, e)| {
                        if e < best.1 { (m, e) } else { best }
                    },
                );
        let choice = FarChoice { join, terms, error };
        // Stop when within tolerance, at the farthest join, or when moving out no
        // longer helps (the error is then the quadrature's, e.g. on a rigid base).
        let stalled = last.is_some_and(|e| error > 0.5 * e);
        if error <= tol || stalled || 2.0 * join > join_max * (1.0 + 1e-12) {
            return Ok(choice);
        }
        last = Some(error);
        join *= 2.0;
    }
}
