//! The I model's periodic images on an elastic base with the uniform mode removed as the
//! periodic BEM removes it ([`Params::zero_mean_images`], physics.md §6.4,
//! `rough::interacting::uniform`). Issue: on an elastic base the raw image sums grow with
//! the block (w ~ S(0)/r), so the I model's pressure at a fixed approach fell without
//! limit as the block grew and sat 63–99 % below the BEM.
//!
//! Homogeneous half-space (E = 4 GPa, ν = 0.15), generated surface L = 1 mm, 512²,
//! D_f = 2.4, k = 2…20, RMS 3.4 µm (123 summits), 20 approaches 1…9 µm (A/A₀ up to 15 %
//! in the BEM). Measured (release build, 2026-11-27):
//! - last-load mean pressure, m = 4 → 8: −1.8e-4 with the correction (2.2994e7 →
//!   2.2997e7 Pa; m = 1, 2: 2.283e7, 2.297e7), −39 % without (1.3e6 → 0.79e6);
//! - against the periodic BEM at equal approach (δ from the highest point, a summit here),
//!   m = 4: median |p_I/p_BEM − 1| 21.7 %, largest 32.6 % (the N model: 21.9 %, 38.1 %),
//!   as on rigid bases (docs/validation.md).

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
    let params = Params {
        zero_mean_images: zero_mean,
        ..Params::default()
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

#[test]
fn image_sums_converge_with_the_block_on_a_half_space() {
    let s = surface();
    let law = Homogeneous {
        e_star: E / (1.0 - NU * NU),
    };
    let (p4, p8) = (curve(&law, &s, 4, true), curve(&law, &s, 8, true));
    let change = p8[19] / p4[19] - 1.0;
    eprintln!(
        "zero-mean images, last load: m = 4 {:.5e} Pa, m = 8 {:.5e} Pa ({change:.2e})",
        p4[19], p8[19]
    );
    assert!(change.abs() < 2e-3, "{change:e}");
    // the raw sums: the same pressure falls by a third from m = 4 to 8
    let (r4, r8) = (curve(&law, &s, 4, false), curve(&law, &s, 8, false));
    assert!(r8[19] / r4[19] - 1.0 < -0.3, "{} {}", r4[19], r8[19]);

    // against the periodic BEM at equal approach (both from the highest point)
    let n = s.shape().0;
    let z = Array2::from_shape_vec((n, n), s.heights().to_vec()).unwrap();
    let bem = BemSolver::new(
        &z,
        1e-3,
        &Stack::half_space(E, NU).unwrap(),
        BemOptions::default(),
    )
    .unwrap();
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
        "zero-mean I model (m = 4) against the BEM: median {median:.3}, largest {:.3}",
        err[19]
    );
    assert!(
        median < 0.25 && err[19] < 0.40,
        "median {median}, largest {}",
        err[19]
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
