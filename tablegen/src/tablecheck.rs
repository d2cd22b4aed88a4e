//! Measuring a table against direct quadrature ([`crate::approx`]): the
//! interpolation error at random off-grid points ([`check`]) and the error of the far
//! field of g beyond the tabulated range ([`far_field_error`], [`choose_far_field`]).
//!
//! Errors are stated like the table's tolerance: χ and ζ relative, g absolute in
//! units of the outside displacement's scale (4/3)a³/r.

use rayon::prelude::*;
use strata_runtime::table::far::{FAR_TERMS, FarField};
use strata_runtime::table::{Axis, InterpError, Table};
use strata_runtime::{Compliance, Stack};

use crate::approx::{Approx, ApproxError};
use crate::tablebuild::{BuildError, bar};

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
fn scale(a: f64, r: f64) -> f64 {
    4.0 / 3.0 * a * a * a / r
}

/// The far field of g of `stack` with all [`FAR_TERMS`] correction terms (the
/// leading term only on a rigid base, where it is exact: module docs of
/// [`strata_runtime::table::far`]).
pub fn far_field_of(stack: &Stack) -> FarField {
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
    stack: &Stack,
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
    members: &[Stack],
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tablebuild::{BuildOptions, build};
    use strata_runtime::law::AsperityLaw;
    use strata_runtime::{Base, Layer};

    fn one_layer(e1: f64, nu1: f64, base: Base) -> Stack {
        Stack::new(
            vec![Layer {
                thickness: 50e-6,
                young: e1,
                poisson: nu1,
            }],
            base,
        )
        .unwrap()
    }

    fn elastic(young: f64, poisson: f64) -> Base {
        Base::Elastic { young, poisson }
    }

    /// max |g_table − g_direct|/((4/3)a³/r) well beyond the join: r − a = 1.01, 1.5,
    /// 3, 10 and 30 × the join, a/h₁ = 1e-2, 1, 1e2 (an independent sample of the far
    /// field, not the builder's probes).
    fn far_error_beyond_join(table: &Table, stack: &Stack) -> f64 {
        let law = table.law_for(stack).unwrap();
        let ap = Approx::new(stack);
        let h1 = stack.layers()[0].thickness;
        let mut worst: f64 = 0.0;
        for x in [1e-2, 1.0, 1e2] {
            let a = x * h1;
            for f in [1.01, 1.5, 3.0, 10.0, 30.0] {
                let r = a + f * law.join();
                let e = (law.g(a, r) - ap.g(a, r).unwrap()).abs() / scale(a, r);
                assert!(e.is_finite(), "a {a} r {r}");
                worst = worst.max(e);
            }
        }
        worst
    }

    fn opts(check_points: usize) -> BuildOptions {
        BuildOptions {
            x_range: (1e-2, 1e2),
            nx: 65,
            check_points,
            ..BuildOptions::default()
        }
    }

    /// The soft-base stack of issue 19 (50 µm, 10 MPa, ν 0.49 on a 2 MPa, ν 0.3
    /// half-space): the leading far field k_z(0)·HS alone is off by ~9e-2 of (4/3)a³/r
    /// at the old join (20 H); the table's far field (correction terms, join moved out)
    /// is within 1e-4, asserted at the builder's probes and independently out to 30 ×
    /// the join. The 4 GPa on 12 GPa stack keeps the 20 H join with < 1e-6.
    #[test]
    fn soft_base_far_field_within_tolerance() {
        let soft = one_layer(10e6, 0.49, elastic(2e6, 0.3));
        let x = Axis {
            lo: 1e-2f64.ln(),
            hi: 1e2f64.ln(),
            n: 65,
        };
        let lead =
            far_field_error(&soft, &FarField::leading(4.98763), &x, 20.0 * 50e-6).unwrap()[0];
        eprintln!("soft base: leading term only at 20 H: {lead:e}");
        assert!(lead > 5e-2, "{lead}");
        let t = build(&soft, &opts(200)).unwrap();
        let h = &t.header;
        let beyond = far_error_beyond_join(&t, &soft);
        eprintln!(
            "soft base: join {:.0} H, {} terms, build far error {:e}, beyond the join {beyond:e}, check {:?}",
            t.law_for(&soft).unwrap().join() / 50e-6,
            h.far_terms,
            h.far_field_error,
            h.interp_error
        );
        assert!(h.far_field_error <= 1e-4 && beyond <= 1e-4, "{beyond}");
        let e = h.interp_error.unwrap();
        assert!(e.exceeds(1e-4).is_none(), "{e:?}");

        let stiff = one_layer(4e9, 0.15, elastic(12e9, 0.3));
        let t = build(&stiff, &opts(0)).unwrap();
        let beyond = far_error_beyond_join(&t, &stiff);
        let join = t.law_for(&stiff).unwrap().join();
        eprintln!(
            "4 GPa on 12 GPa: join {:.0} H, {} terms, far error {:e}, beyond {beyond:e}",
            join / 50e-6,
            t.header.far_terms,
            t.header.far_field_error
        );
        assert!((join / (20.0 * 50e-6) - 1.0).abs() < 1e-9);
        assert!(t.header.far_field_error < 1e-6 && beyond < 1e-6, "{beyond}");
    }

    /// ν → −1 (hard cases): a ν = −0.999 layer on a ν = −0.999 base five times
    /// stiffer, a ν = 0.3 layer on a ν = −0.999 base, and a ν = −0.999 layer on a
    /// rigid base: the builds pass their stated tolerance 1e-4 (χ, ζ, g at 200 random
    /// points and the far field), every value is finite, and the far field holds out
    /// to 30 × the join against direct quadrature.
    #[test]
    fn poisson_near_minus_one() {
        for (name, st) in [
            (
                "-0.999 on -0.999 (1:5)",
                one_layer(1e9, -0.999, elastic(5e9, -0.999)),
            ),
            (
                "0.3 on -0.999 (1:1)",
                one_layer(1e9, 0.3, elastic(1e9, -0.999)),
            ),
            ("-0.999 on rigid", one_layer(1e9, -0.999, Base::Rigid)),
        ] {
            let t = build(&st, &opts(200)).unwrap();
            assert!(
                t.chi
                    .iter()
                    .chain(&t.zeta)
                    .chain(&t.g)
                    .all(|v| v.is_finite())
            );
            let beyond = far_error_beyond_join(&t, &st);
            eprintln!(
                "{name}: far terms {}, far error {:e}, beyond the join {beyond:e}, check {:?}",
                t.header.far_terms, t.header.far_field_error, t.header.interp_error
            );
            assert!(t.header.far_field_error <= 1e-4 && beyond <= 1e-4, "{name}");
        }
    }

    /// A stack whose k_z varies on scales far beyond H (a ν = −0.999 layer on an
    /// equally stiff ν = 0.3 base: k_z(0) = 454 and k₂ ≈ 3e7 H², a plate-like length
    /// ≫ H) has no accurate far field within reach of the direct quadrature: the build
    /// is refused with the measured error and the tolerance, not shipped 20× off.
    #[test]
    fn far_field_out_of_reach_is_refused() {
        let st = one_layer(1e9, -0.999, elastic(1e9, 0.3));
        let o = BuildOptions {
            far_max: 320.0,
            ..opts(0)
        };
        let e = build(&st, &o).unwrap_err();
        let msg = e.to_string();
        eprintln!("{msg}");
        assert!(
            matches!(e, BuildError::Tolerance { measured, tolerance, .. } if measured > tolerance)
        );
        assert!(msg.contains("far field") && msg.contains("exceeds the stated tolerance 1.000e-4"));
    }

    /// A deliberately coarse grid is refused by the interpolation check, naming the
    /// error and the tolerance; a too tight tolerance likewise.
    #[test]
    fn coarse_grid_or_tight_tolerance_refused() {
        let st = Stack::paper_two_layer(5.0).unwrap();
        let coarse = BuildOptions {
            nx: 7,
            nw: 7,
            ns: 9,
            check_points: 40,
            ..BuildOptions::default()
        };
        let e = build(&st, &coarse).unwrap_err();
        eprintln!("{e}");
        assert!(matches!(e, BuildError::Tolerance { .. }), "{e}");
        assert!(e.to_string().contains("chi interpolation"), "{e}");
        let tight = BuildOptions {
            nx: 25,
            nw: 13,
            ns: 9,
            check_points: 40,
            tolerance: 1e-12,
            ..BuildOptions::default()
        };
        let e = build(&st, &tight).unwrap_err().to_string();
        assert!(e.contains("exceeds the stated tolerance 1.000e-12"), "{e}");
    }
}
