//! The I model's periodic images on an elastic base with the uniform mode removed as the
//! periodic BEM removes it ([`Params::zero_mean_images`], physics.md §5,
//! `rough::interacting::uniform`). Issue: on an elastic base the raw image sums grow with
//! the block (w ~ S(0)/r), so the I model's pressure at a fixed approach fell without
//! limit as the block grew and sat 63–99 % below the BEM.
//!
//! Generated surface L = 1 mm, 512², D_f = 2.4, k = 2…20, RMS 3.4 µm (123 summits), 20
//! approaches 1…9 µm (A/A₀ up to 15 % in the BEM). Measured (2026-11-27):
//! - homogeneous half-space (E = 4 GPa, ν = 0.15): last-load mean pressure m = 4 → 8
//!   +2.0e-4 with the correction (2.3121e7 → 2.3126e7 Pa), −39.5 % with the raw sums;
//!   against the periodic BEM at equal approach (δ from the highest point, a summit
//!   here), m = 4: median |p_I/p_BEM − 1| 21.7 %, largest 32.2 % (the N model: 21.9 %,
//!   38.1 %);
//! - the soft base below: +1.6e-3 (raw −43.7 %), median 14.4 %, largest 27.7 %.
//!
//! The requirement: < 0.5 % from m = 4 to 8, median ≤ 25 %.

use strata_bem::{Array2, BemLoad, BemOptions, BemSolver};
use strata_runtime::Stack;
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::rough::{Images, Model, Params, RoughContact};
use strata_runtime::surface::{GenerateParams, Surface};

const E: f64 = 4e9;
const NU: f64 = 0.15;

fn surface() -> Surface {
    Surface::generate(&GenerateParams {
        size: 1e-3,
        grid: 512,
        fractal_dimension: 2.4,
        k_min: 2.0,
        k_max: 20.0,
        rms: 3.4e-6,
        seed: 20240611,
    })
    .unwrap()
}

fn deltas() -> Vec<f64> {
    (0..20).map(|i| 1e-6 + 8e-6 * i as f64 / 19.0).collect()
}

/// Mean pressures of the I-model curve with periodic images on m cells per side.
fn curve(law: &dyn AsperityLaw, s: &Surface, m: usize, zero_mean: bool) -> Vec<f64> {
    let params = {
        let mut p = Params::default();
        p.zero_mean_images = zero_mean;
        p
    };
    let rc = RoughContact::from_surface(law, s)
        .unwrap()
        .with_params(params);
    rc.curve(Model::Interacting(Images::Periodic(m)), &deltas())
        .unwrap()
        .iter()
        .map(|st| st.mean_pressure)
        .collect()
}

/// Last-load change from m = 4 to 8 (zero-mean), the same for the raw sums, and the
/// median and largest |p_I/p_BEM − 1| (m = 4) over the 20 steps at equal approach.
fn against_the_bem(
    law: &dyn AsperityLaw,
    stack: &(impl strata_runtime::Solid + ?Sized),
) -> (f64, f64, f64, f64) {
    let s = surface();
    let (p4, p8) = (curve(law, &s, 4, true), curve(law, &s, 8, true));
    let change = p8[19] / p4[19] - 1.0;
    let (r4, r8) = (curve(law, &s, 4, false), curve(law, &s, 8, false));
    let raw = r8[19] / r4[19] - 1.0;
    // the periodic BEM at equal approach (both from the highest point, a summit here)
    let n = s.shape().0;
    let z = Array2::from_shape_vec((n, n), s.heights().to_vec()).unwrap();
    let bem = BemSolver::new(&z, 1e-3, stack, BemOptions::default()).unwrap();
    let loads: Vec<BemLoad> = deltas().into_iter().map(BemLoad::Approach).collect();
    let b = bem.solve_curve(&loads).unwrap();
    let mut err: Vec<f64> = p4
        .iter()
        .zip(&b)
        .map(|(p, b)| (p / b.mean_pressure - 1.0).abs())
        .collect();
    err.sort_by(f64::total_cmp);
    let median = 0.5 * (err[9] + err[10]);
    eprintln!(
        "zero-mean images: last load m = 4 {:.5e} Pa, m = 8 {:.5e} Pa ({change:.2e}; raw sums {raw:.2e}); \
         against the BEM (m = 4): median {median:.3}, largest {:.3}",
        p4[19], p8[19], err[19]
    );
    (change, raw, median, err[19])
}

/// The table law of `stack` on a short x range (1e-3 … 1e2, 81 nodes), built here.
fn table_law(stack: &(impl strata_runtime::Solid + ?Sized)) -> strata_runtime::table::TableLaw {
    let opts = strata_tablegen::tablebuild::BuildOptions {
        x_range: (1e-3, 1e2),
        nx: 81,
        check_points: 0,
        ..Default::default()
    };
    strata_tablegen::tablebuild::build(stack, &opts)
        .unwrap()
        .law_for(stack)
        .unwrap()
}

#[test]
fn image_sums_converge_with_the_block_on_a_half_space() {
    let law = Homogeneous {
        e_star: E / (1.0 - NU * NU),
    };
    let (change, raw, median, largest) = against_the_bem(&law, &Stack::half_space(E, NU).unwrap());
    assert!(change.abs() < 2e-3, "{change:e}");
    assert!(raw < -0.3, "{raw}");
    assert!(
        median < 0.25 && largest < 0.40,
        "median {median}, largest {largest}"
    );
}

/// A soft base: a 100 µm, 4 GPa layer (ν 0.15) on a 0.4 GPa (ν 0.15)
/// half-space, S(0) = 10, table built here. Measured: m = 4 → 8 +1.6e-3 (raw −0.44);
/// median 14.4 %, largest 27.7 % from the BEM (the N model: 31.8 %, 54.7 %).
#[test]
fn image_sums_converge_with_the_block_on_a_soft_base() {
    use strata_runtime::stack::{Base, Layer};
    let stack = Stack::new(
        vec![Layer {
            thickness: 100e-6,
            young: 4e9,
            poisson: 0.15,
        }],
        Base::Elastic {
            young: 0.4e9,
            poisson: 0.15,
        },
    )
    .unwrap();
    let law = table_law(&stack);
    assert!((law.point_force().s0 - 10.0).abs() < 1e-9);
    let (change, raw, median, largest) = against_the_bem(&law, &stack);
    assert!(change.abs() < 5e-3, "{change:e}");
    assert!(raw < -0.3, "{raw}");
    assert!(
        median < 0.25 && largest < 0.40,
        "median {median}, largest {largest}"
    );
}

/// On a rigid base S(0) = 0: the image sums converge by themselves, the correction is
/// not built and the curve is the same bit for bit.
#[test]
fn rigid_base_curves_are_unchanged() {
    let table = strata_runtime::table::Table::load(
        &crate::support::repo().join("tables/paper-two-layer.strata"),
    )
    .unwrap();
    let law = table
        .law_for(&Stack::paper_two_layer(5.0).unwrap())
        .unwrap();
    assert_eq!(law.point_force().s0, 0.0);
    let s = surface();
    assert_eq!(curve(&law, &s, 2, true), curve(&law, &s, 2, false));
}

/// The zero-mean periodic lattice sum of 1/|d + n·L| over the rectangular lattice
/// (Lx, Ly), by Ewald summation (an independent second method): with the split
/// 1/r = erfc(αr)/r + erf(αr)/r and the 2-D transform of erf(αr)/r, (2π/k) erfc(k/2α),
///
/// K(d) = Σ_n erfc(α r_n)/r_n + (2π/A₀) Σ_{k≠0} erfc(|k|/2α)/|k| cos(k·d) − 2√π/(α A₀),
///
/// the last term the mean of the short-range part (the k = 0 mode removed whole).
/// `self_term`: the n = 0 term excluded (d = 0), its regular limit −2α/√π kept.
fn ewald(d: (f64, f64), lx: f64, ly: f64, self_term: bool) -> f64 {
    let a0 = lx * ly;
    let alpha = 4.0 / lx.min(ly);
    let pi = std::f64::consts::PI;
    let mut s = 0.0;
    let nr = 8;
    for i in -nr..=nr {
        for j in -nr..=nr {
            if self_term && (i, j) == (0, 0) {
                s -= 2.0 * alpha / pi.sqrt();
                continue;
            }
            let r = (d.0 + i as f64 * lx).hypot(d.1 + j as f64 * ly);
            s += libm::erfc(alpha * r) / r;
        }
    }
    let nk = 24;
    for i in -nk..=nk {
        for j in -nk..=nk {
            if (i, j) == (0, 0) {
                continue;
            }
            let (kx, ky) = (2.0 * pi * i as f64 / lx, 2.0 * pi * j as f64 / ly);
            let k = kx.hypot(ky);
            s += 2.0 * pi / a0 * libm::erfc(k / (2.0 * alpha)) / k * (kx * d.0 + ky * d.1).cos();
        }
    }
    s - 2.0 * pi.sqrt() / (alpha * a0)
}

/// Hertz: G(r) = [(2a² − r²) asin(a/r) + a√(r² − a²)]/(πR) and ∂G/∂a = 4a asin(a/r)/(πR),
/// r > a (m, -).
fn hertz(a: f64, radius: f64, r: f64) -> (f64, f64) {
    let pi = std::f64::consts::PI;
    let q = (a / r).asin();
    (
        ((2.0 * a * a - r * r) * q + a * (r * r - a * a).sqrt()) / (pi * radius),
        4.0 * a * q / (pi * radius),
    )
}

/// The I model's KKT conditions (physics.md §5) of the infinite zero-mean periodic
/// problem on a homogeneous half-space, evaluated independently: each pair's image sum
/// to |n| ≤ 12 with its point-force part 4Q/(3πr) replaced by the Ewald sum of the whole
/// lattice, F_k = D_k + 2a_k²/R_k − 2δ_k + X_k. Returns max |F| (active) and max −F
/// (inactive) over the largest interference.
fn kkt_ewald(rc: &RoughContact, radii: &[f64], delta: f64) -> f64 {
    let sm = rc.summits();
    let (lx, ly) = rc.extent();
    let pi = std::f64::consts::PI;
    let z_max = sm.iter().map(|s| s.z).fold(f64::MIN, f64::max);
    // signed: a summit below the rigid plane touches only if the surface rises to it
    let dk = |k: usize| delta - (z_max - sm[k].z);
    let scale = (0..sm.len()).map(dk).fold(0.0, f64::max);
    let m = 12i64;
    let mut worst = 0.0f64;
    for k in 0..sm.len() {
        let (ak, rk) = (radii[k], sm[k].radius);
        let (mut d, mut x) = (0.0, 0.0);
        for l in 0..sm.len() {
            if radii[l] <= 0.0 {
                continue;
            }
            let ql = radii[l].powi(3) / sm[l].radius;
            let off = (sm[l].x - sm[k].x, sm[l].y - sm[k].y);
            for sx in -m..=m {
                for sy in -m..=m {
                    if l == k && (sx, sy) == (0, 0) {
                        continue;
                    }
                    let r = (off.0 + sx as f64 * lx).hypot(off.1 + sy as f64 * ly);
                    let point = 4.0 * ql / (3.0 * pi * r);
                    d += hertz(radii[l], sm[l].radius, r).0 - point;
                    if ak > 0.0 {
                        x += ql * hertz(ak, rk, r).1 / (3.0 * ak * ak / rk) - point;
                    }
                }
            }
            let per = 4.0 * ql / (3.0 * pi) * ewald(off, lx, ly, l == k);
            d += per;
            x += per;
        }
        let f = d + 2.0 * ak * ak / rk - 2.0 * dk(k) + x;
        worst = worst.max(if ak > 0.0 { f.abs() } else { -f });
    }
    worst / scale
}

/// On a rectangular cell (0.96 × 1.28 mm, 96 × 64 points), the I model with zero-mean
/// images meets the KKT conditions of the infinite zero-mean periodic problem, computed
/// by Ewald summation: residual 1.9e-2 (m = 1), 3.3e-3 (m = 2), 7.3e-4 (m = 4) of the
/// largest interference, falling with the truncated block (×4.5–6 per doubling); 21
/// contacts, summits below the rigid plane included (the surface between contacts
/// rises). The raw image sums (m = 4, 8 contacts) are off by 1.28. The Ewald sum itself
/// equals the block sums with the closed-form mean to 3e-7 at m = 64 (NumPy).
#[test]
fn zero_mean_images_meet_the_ewald_kkt_conditions() {
    let (n0, n1, dx, dy) = (96usize, 64usize, 1e-5, 2e-5);
    let z = crate::support::rectangular_cosines(n0, n1, dx, dy);
    let s = Surface::with_spacing(
        z,
        n0,
        n1,
        strata_runtime::surface::Spacing::Pixel(dx, dy),
        true,
    )
    .unwrap();
    let law = Homogeneous {
        e_star: E / (1.0 - NU * NU),
    };
    let mut res = Vec::new();
    for (m, zero_mean) in [(1, true), (2, true), (4, true), (4, false)] {
        let params = {
            let mut p = Params::default();
            p.zero_mean_images = zero_mean;
            p
        };
        let rc = RoughContact::from_surface(&law, &s)
            .unwrap()
            .with_params(params);
        let delta = 0.5 * rc.max_delta();
        let st = rc
            .solve(Model::Interacting(Images::Periodic(m)), delta, &[])
            .unwrap();
        assert!(st.contacts >= 3, "{}", st.contacts);
        let r = kkt_ewald(&rc, &st.radii, delta);
        eprintln!(
            "m = {m}, zero mean {zero_mean}: {} contacts, Ewald KKT residual {r:.2e}",
            st.contacts
        );
        res.push(r);
    }
    assert!(res[0] < 0.2 && res[1] < 0.033 && res[2] < 7.3e-3, "{res:?}");
    assert!(res[2] < res[1] / 3.0 && res[1] < res[0] / 3.0, "{res:?}");
    assert!(res[3] > 0.5, "{res:?}");
}

/// S(0) ≪ 1: the paper's stack (E2/E1 = 5, rigid base) pressed against a steel
/// half-space (an elastic counterface, S(0) = 1 − E*/E*₁ = 0.0174). The correction's
/// interpolant could not meet a tolerance scaled by S(0) (the table's noise sits in
/// the layered part, |k_z(0)| ≈ 1); now scaled by max(S(0), |k_z(0)|) when S(0) < ½.
#[test]
fn image_sums_converge_against_a_stiff_counterface() {
    let stack = Stack::paper_two_layer(5.0)
        .unwrap()
        .against(Stack::half_space(210e9, 0.3).unwrap());
    let law = table_law(&stack);
    let s0 = law.point_force().s0;
    assert!((s0 - 0.0174).abs() < 1e-3, "S(0) = {s0}");
    // Measured: m = 4 → 8 +3.4e-6 (raw sums −12.4 %); against the BEM median 24.8 %,
    // largest 34.9 % (the asperity model's own error on this stack, not the images').
    let (change, raw, median, largest) = against_the_bem(&law, &stack);
    assert!(change.abs() < 5e-5, "{change:e}");
    assert!(raw < -0.05, "{raw}");
    assert!(
        median < 0.30 && largest < 0.45,
        "median {median}, largest {largest}"
    );
}
