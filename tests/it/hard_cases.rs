//! End-to-end hard cases. Every case checks accuracy against an independent
//! truth — a closed-form limit, a second method, or convergence under refinement —
//! not only finiteness, so a wrong answer fails. Measured values are printed (run with
//! `--nocapture`) and quoted in the comments; docs/validation.md's hard-case table lists them.
//!
//! Cost: ~25 s in the test profile on 2 shared cores. The slowest limits (a/h = 1000,
//! 10–17 s) stay in strata-tablegen's own tests and are cited, not repeated.
//!
//! Sections: `asperity` (full Fredholm solution on hard stacks), `rough` (asperity
//! models and FFT-BEM on hard surfaces and loads), `cli` (measured data and extreme
//! loads through `strata solve`), `outputs` (safe writing of results).

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use ndarray::Array2;
use strata_bem::{BemLoad, BemOptions, BemSolver};
use strata_runtime::{Base, Layer, Stack};
use strata_tablegen::asperity::{Asperity, Method, Options};
use strata_tablegen::fredholm::Discretisation;

fn layer(h: f64, e: f64, nu: f64) -> Layer {
    Layer {
        thickness: h,
        young: e,
        poisson: nu,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// Oedometric (P-wave) modulus M = E(1−ν)/((1+ν)(1−2ν)) (Pa).
fn oedometric(e: f64, nu: f64) -> f64 {
    e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))
}

fn fixed_product(n: usize) -> Options {
    Options {
        method: Method::Fixed(Discretisation::Product {
            intervals: n,
            richardson: true,
        }),
        ..Options::default()
    }
}

mod asperity {
    use super::*;

    /// Thin bonded layer on a rigid base (physics.md §3, Johnson §5.9): for a ≫ h,
    /// P → πMa⁴/(4Rh) and δ → a²/(2R). The deviation is O(h/a) with a fixed constant:
    /// (P/P_lim − 1)·a/h = 0.50, 0.49, 0.486, 0.48 and (δ/δ_lim − 1)·a/h = 0.26, 0.25,
    /// 0.244, 0.240 at a/h = 10, 30, 100, 300 (ν = 0.3). a/h = 1000 (1 %, 10–17 s) is
    /// tested in strata-tablegen (`asperity::tests::extreme_a_over_h`).
    #[test]
    fn thin_layer_on_rigid_base_tends_to_the_oedometric_limit() {
        let (h, e, nu, rr) = (1e-6, 1e9, 0.3, 1e-2);
        let st = Stack::new(vec![layer(h, e, nu)], Base::Rigid).unwrap();
        let asp = Asperity::new(&st, Options::default()).unwrap();
        let m = oedometric(e, nu);
        for ah in [10.0, 30.0, 100.0, 300.0] {
            let a = ah * h;
            let s = asp.paraboloid_at_radius(a, rr).unwrap();
            let cp = (s.force / (PI * m * a.powi(4) / (4.0 * rr * h)) - 1.0) * ah;
            let cd = (s.delta / (a * a / (2.0 * rr)) - 1.0) * ah;
            eprintln!(
                "thin layer a/h = {ah}: (P/P_lim - 1)·a/h = {cp:.4}, (δ/δ_lim - 1)·a/h = {cd:.4}"
            );
            assert!((0.45..0.55).contains(&cp), "a/h {ah}: {cp}");
            assert!((0.22..0.28).contains(&cd), "a/h {ah}: {cd}");
        }
    }

    /// Incompressible (ν = 0.5) thin layer bonded to a rigid base under a frictionless
    /// paraboloid: the thin-layer (lubrication) limit ∇²p = −3μw/h³ with p = ∂p/∂r = 0
    /// at r = a gives p = (3μ/(32Rh³))(a² − r²)², P = πμa⁶/(32Rh³), δ = a²/(4R) — a
    /// different power law from the compressible limit. The full solution approaches
    /// it like h/a: (P/P_lim − 1)·a/h = 9.9 and 9.1, (δ/δ_lim − 1)·a/h = 2.8 and 2.9 at
    /// a/h = 30 and 100 (the adaptive default grid reaches N = 4096 at a/h = 100).
    #[test]
    fn incompressible_thin_layer_limit() {
        let (h, e, rr) = (1e-6, 1e9, 1e-2);
        let mu = e / 3.0;
        let st = Stack::new(vec![layer(h, e, 0.5)], Base::Rigid).unwrap();
        for (ah, opts) in [(30.0, Options::default()), (100.0, Options::default())] {
            let a = ah * h;
            let s = Asperity::new(&st, opts)
                .unwrap()
                .paraboloid_at_radius(a, rr)
                .unwrap();
            let cp = (s.force / (PI * mu * a.powi(6) / (32.0 * rr * h.powi(3))) - 1.0) * ah;
            let cd = (s.delta / (a * a / (4.0 * rr)) - 1.0) * ah;
            eprintln!(
                "incompressible a/h = {ah}: (P/P_lim - 1)·a/h = {cp:.3}, (δ/δ_lim - 1)·a/h = {cd:.3}"
            );
            assert!((8.0..11.0).contains(&cp), "a/h {ah}: {cp}");
            assert!((2.4..3.3).contains(&cd), "a/h {ah}: {cd}");
        }
    }

    /// The default (adaptive) product grid resolves nearly incompressible layers on a
    /// rigid base at large a/h. With the fixed N = 2a/h (≥ 256) the force was off by
    /// 1.9 % at ν = 0.499 and 20 % at ν = 0.5 at a/h = 100 (against N = 4096); the
    /// default now doubles N while successive Richardson extrapolations differ by more
    /// than 5e-4 (ν = 0.49 → N = 512, 0.499 → 1024, 0.5 → 4096).
    #[test]
    fn default_discretisation_resolves_near_incompressible_layers() {
        let (h, e, rr) = (1e-6, 1e9, 1e-2);
        for nu in [0.499, 0.5] {
            let st = Stack::new(vec![layer(h, e, nu)], Base::Rigid).unwrap();
            let a = 100.0 * h;
            let d = Asperity::new(&st, Options::default())
                .unwrap()
                .paraboloid_at_radius(a, rr)
                .unwrap();
            let f = Asperity::new(&st, fixed_product(4096))
                .unwrap()
                .paraboloid_at_radius(a, rr)
                .unwrap();
            assert!(
                rel(d.force, f.force) < 1e-3,
                "ν {nu}: {}",
                rel(d.force, f.force)
            );
        }
    }

    /// ν = 0.4999 next to the exactly incompressible ν = 0.5 (which the transfer-matrix
    /// formulation handles without a special case): the solution is smooth and linear in
    /// 1 − 2ν, so P(0.4999) − P(0.5) is one tenth of P(0.499) − P(0.5). Two-layer stacks
    /// (h₂ = 9h₁) on a rigid base (E₂/E₁ = 5) and on an elastic base (E₂/E₁ = 0.2,
    /// E_b = E₂, ν_b = 0.3), a/h = 1 (Nyström) and 10 (product integration). Measured
    /// ratio 9.87–10.0; |P(0.4999)/P(0.5) − 1| ≤ 5.7e-4.
    #[test]
    fn near_incompressible_layers_are_continuous() {
        let (h, e1, rr) = (1e-6, 1e9, 1e-2);
        for (ratio, rigid) in [(5.0, true), (0.2, false)] {
            let force = |nu: f64, a: f64| {
                let base = if rigid {
                    Base::Rigid
                } else {
                    Base::Elastic {
                        young: e1 * ratio,
                        poisson: 0.3,
                    }
                };
                let st = Stack::new(vec![layer(h, e1, nu), layer(9.0 * h, e1 * ratio, nu)], base)
                    .unwrap();
                Asperity::new(&st, Options::default())
                    .unwrap()
                    .paraboloid_at_radius(a, rr)
                    .unwrap()
                    .force
            };
            for ah in [1.0, 10.0] {
                let a = ah * h;
                let (p5, p4, p3) = (force(0.5, a), force(0.4999, a), force(0.499, a));
                let linear = (p3 - p5) / (p4 - p5);
                eprintln!(
                    "ν → 0.5, rigid {rigid}, a/h {ah}: P(.4999)/P(.5) - 1 = {:.3e}, ratio of differences {linear:.3}",
                    p4 / p5 - 1.0
                );
                assert!((9.5..10.5).contains(&linear), "{linear}");
                assert!(rel(p4, p5) < 2e-3);
            }
        }
    }

    /// Identical layers (ν = 0.4999) on an identical base, through the layered code path
    /// (the base differs by 1e-12 so the stack is not flagged homogeneous): Hertz,
    /// P = (4/3)E*a³/R and δ = a²/R, to 1e-8 at a/h = 0.1 and 10.
    #[test]
    fn identical_layers_are_a_half_space() {
        let (h, e, nu, rr) = (1e-5, 2e9, 0.4999, 1e-2);
        let st = Stack::new(
            vec![
                layer(h, e, nu),
                layer(2.0 * h, e, nu),
                layer(3.0 * h, e, nu),
            ],
            Base::Elastic {
                young: e * (1.0 + 1e-12),
                poisson: nu,
            },
        )
        .unwrap();
        assert!(!st.is_homogeneous());
        let es = e / (1.0 - nu * nu);
        let asp = Asperity::new(&st, Options::default()).unwrap();
        for ah in [0.1, 10.0] {
            let a = ah * h;
            let s = asp.paraboloid_at_radius(a, rr).unwrap();
            let (dp, dd) = (
                rel(s.force, 4.0 / 3.0 * es * a.powi(3) / rr),
                rel(s.delta, a * a / rr),
            );
            eprintln!("identical layers a/h {ah}: force {dp:.1e}, approach {dd:.1e}");
            assert!(dp < 1e-8 && dd < 1e-8, "{dp} {dd}");
        }
    }

    /// One layer on an elastic base with E_b/E₁ = 1e4 (soft layer on a stiff base) and
    /// 1e-4 (stiff layer on a soft base). Small contacts see the top layer only: the
    /// force tends to Hertz with E*₁, its deviation shrinking like (a/h)³ (the O(a)
    /// part of the kernel is a rigid shift absorbed by δ). Measured |P/P_H(E*₁) − 1| at
    /// a/h = 1e-2: 5.3e-7 (1e4), 4.7e-6 (1e-4); ratio to a/h = 0.1: 1.0e-3.
    #[test]
    fn extreme_contrasts_small_contacts_see_the_top_layer() {
        let (h, e1, nu, rr) = (1e-6, 1e9, 0.3, 1e-2);
        let es1 = e1 / (1.0 - nu * nu);
        for ratio in [1e4, 1e-4] {
            let st = Stack::new(
                vec![layer(h, e1, nu)],
                Base::Elastic {
                    young: e1 * ratio,
                    poisson: nu,
                },
            )
            .unwrap();
            let asp = Asperity::new(&st, Options::default()).unwrap();
            let dev = |ah: f64| {
                let a = ah * h;
                asp.paraboloid_at_radius(a, rr).unwrap().force / (4.0 / 3.0 * es1 * a.powi(3) / rr)
                    - 1.0
            };
            let (d1, d2) = (dev(1e-2), dev(1e-1));
            eprintln!("E_b/E1 = {ratio:e}: P/P_H(E1) - 1 = {d1:.3e} (a/h 0.01), {d2:.3e} (0.1)");
            assert!(d1.abs() < 1e-5, "{d1}");
            assert!((8e-4..1.2e-3).contains(&(d1 / d2)), "{d1} {d2}");
        }
    }

    /// Soft layer on a 1e4 times stiffer base at a ≫ h: the rigid-base solution plus the
    /// base's own compliance, a relative correction of order (a/h)·M₁/E*_b. Measured
    /// (P_elastic/P_rigid − 1)/((a/h)M₁/E*_b) = −0.63, −0.66, −0.67 at a/h = 10, 30, 100.
    /// Second method at a/h = 30: the FFT-BEM on the same layered kernel, at the
    /// Fredholm force, gives the same contact radius (measured 0.05 %; the BEM area is
    /// a count of grid points, 32 per radius: tolerance 1 %).
    #[test]
    fn soft_layer_on_a_very_stiff_base() {
        let (h, e1, nu, rr) = (1e-6, 4e9, 0.3, 1e-3);
        let elastic = Stack::new(
            vec![layer(h, e1, nu)],
            Base::Elastic {
                young: 1e4 * e1,
                poisson: nu,
            },
        )
        .unwrap();
        let rigid = Stack::new(vec![layer(h, e1, nu)], Base::Rigid).unwrap();
        let (ae, ar) = (
            Asperity::new(&elastic, Options::default()).unwrap(),
            Asperity::new(&rigid, Options::default()).unwrap(),
        );
        let scale = oedometric(e1, nu) / (1e4 * e1 / (1.0 - nu * nu));
        for ah in [10.0, 30.0, 100.0] {
            let a = ah * h;
            let (pe, pr) = (
                ae.paraboloid_at_radius(a, rr).unwrap().force,
                ar.paraboloid_at_radius(a, rr).unwrap().force,
            );
            let c = (pe / pr - 1.0) / (ah * scale);
            eprintln!("E_b/E1 = 1e4, a/h {ah}: (P/P_rigid - 1)/((a/h) M1/E*_b) = {c:.3}");
            assert!((-0.75..-0.55).contains(&c), "{c}");
        }
        let a = 30.0 * h;
        let s = ae.paraboloid_at_radius(a, rr).unwrap();
        let (a_bem, _) = bem_single_bump(&elastic, s.force, 256, 8.0 * a, rr);
        eprintln!(
            "E_b/E1 = 1e4, a/h 30: a_BEM/a - 1 = {:.2e}",
            a_bem / a - 1.0
        );
        assert!(rel(a_bem, a) < 0.01);
    }

    /// Stiff layer on a 1e4 times softer base (a plate on a soft foundation). Second
    /// method at a/h = 10: the FFT-BEM at the Fredholm force, on 128² and 256² grids of
    /// a 32a cell (4 and 8 points per radius; the soft base makes the CG slow, so no
    /// finer grid in CI). Contact radius within 2.9 % (area quantised by the grid;
    /// 0.5 % at 512²), central pressure −30 %, −8.9 % (−1.7 % at 512²), second-order
    /// grid convergence, extrapolated to −1.8 % (tolerance 3 %).
    /// Large contacts tend to Hertz with the base modulus from above, slowly (plate
    /// bending): P/P_H(E*_b) − 1 = 2.26, 0.57 at a/h = 30, 100.
    #[test]
    fn stiff_layer_on_a_very_soft_base() {
        let (h, e1, nu, rr) = (1e-6, 4e9, 0.3, 1e-3);
        let st = Stack::new(
            vec![layer(h, e1, nu)],
            Base::Elastic {
                young: 1e-4 * e1,
                poisson: nu,
            },
        )
        .unwrap();
        let asp = Asperity::new(&st, Options::default()).unwrap();
        let a = 10.0 * h;
        let s = asp.paraboloid_at_radius(a, rr).unwrap();
        let p0 = s.pressure(&[0.0])[0];
        let (_, p128) = bem_single_bump(&st, s.force, 128, 32.0 * a, rr);
        let (a_bem, p256) = bem_single_bump(&st, s.force, 256, 32.0 * a, rr);
        let p_rich = p256 + (p256 - p128) / 3.0;
        eprintln!(
            "E_b/E1 = 1e-4, a/h 10: a_BEM/a - 1 = {:.2e}; p0_BEM/p0 - 1 = {:.2e} (128²), {:.2e} (256²), {:.2e} (extrapolated)",
            a_bem / a - 1.0,
            p128 / p0 - 1.0,
            p256 / p0 - 1.0,
            p_rich / p0 - 1.0
        );
        assert!(rel(a_bem, a) < 0.04);
        assert!(rel(p256, p0) < 0.5 * rel(p128, p0));
        assert!(rel(p_rich, p0) < 0.03);
        let esb = 1e-4 * e1 / (1.0 - nu * nu);
        let dev = |ah: f64| {
            let a = ah * h;
            asp.paraboloid_at_radius(a, rr).unwrap().force / (4.0 / 3.0 * esb * a.powi(3) / rr)
                - 1.0
        };
        let (d30, d100) = (dev(30.0), dev(100.0));
        eprintln!("E_b/E1 = 1e-4: P/P_H(E_b) - 1 = {d30:.3} (a/h 30), {d100:.3} (100)");
        assert!(
            d100 > 0.0 && d100 < 0.35 * d30 && d100 < 0.7,
            "{d30} {d100}"
        );
    }

    /// A paraboloid (radius `rr`) centred in an n×n periodic cell of side `cell` under
    /// total force `p`, by FFT-BEM: the equivalent contact radius √(A/π) and the
    /// pressure at the apex.
    pub fn bem_single_bump(stack: &Stack, p: f64, n: usize, cell: f64, rr: f64) -> (f64, f64) {
        let dx = cell / n as f64;
        let c = (n / 2) as f64;
        let heights = Array2::from_shape_fn((n, n), |(i, j)| {
            let (x, y) = ((i as f64 - c) * dx, (j as f64 - c) * dx);
            -(x * x + y * y) / (2.0 * rr)
        });
        let solver = BemSolver::new(&heights, cell, stack, BemOptions::default()).unwrap();
        let sol = solver
            .solve(BemLoad::MeanPressure(p / (cell * cell)))
            .unwrap();
        (
            (sol.area_fraction * cell * cell / PI).sqrt(),
            sol.pressure[[n / 2, n / 2]],
        )
    }

    /// A graded coating: E rising linearly from 4 GPa at the surface to 200 GPa at depth
    /// D = 1 mm on a 200 GPa half-space, cut into n homogeneous layers (midpoint
    /// moduli). The force at a = 0.1 D (R = 10 mm) converges at second order in 1/n:
    /// successive differences for n = 125, 250, 500 shrink by 3.5 (→ 4); the 500-layer
    /// force is within 1e-3 of the Richardson limit, and it lies between Hertz with the
    /// surface modulus and Hertz with the base modulus (2.6× the former).
    #[test]
    fn graded_500_layer_stack_converges() {
        let (d, rr, nu) = (1e-3, 1e-2, 0.3);
        let graded = |n: usize| {
            let h = d / n as f64;
            let layers = (0..n)
                .map(|i| layer(h, 4e9 + (2e11 - 4e9) * (i as f64 + 0.5) / n as f64, nu))
                .collect();
            Stack::new(
                layers,
                Base::Elastic {
                    young: 2e11,
                    poisson: nu,
                },
            )
            .unwrap()
        };
        let a = 0.1 * d;
        let p: Vec<f64> = [125, 250, 500]
            .iter()
            .map(|&n| {
                Asperity::new(&graded(n), Options::default())
                    .unwrap()
                    .paraboloid_at_radius(a, rr)
                    .unwrap()
                    .force
            })
            .collect();
        let ratio = (p[0] - p[1]) / (p[1] - p[2]);
        let limit = p[2] - (p[1] - p[2]) / (ratio - 1.0);
        let hertz = |e: f64| 4.0 / 3.0 * e / (1.0 - nu * nu) * a.powi(3) / rr;
        eprintln!(
            "graded: P(125, 250, 500) = {p:?}, difference ratio {ratio:.3}, P500/limit - 1 = {:.2e}, P500/P_H(E_top) = {:.3}",
            p[2] / limit - 1.0,
            p[2] / hertz(4e9)
        );
        assert!((3.0..5.0).contains(&ratio), "{ratio}");
        assert!(rel(p[2], limit) < 1e-3);
        assert!(p[2] > hertz(4e9) && p[2] < hertz(2e11));
    }
}

mod rough {
    use super::*;
    use strata_runtime::law::Homogeneous;
    use strata_runtime::rough::{Images, Model, RoughContact, RoughError};
    use strata_runtime::surface::Surface;

    /// Paraboloids of radius `r` (apex height 0) centred at grid points, over a flat
    /// floor: the largest of them at every point of an n×n grid of side l.
    pub fn bumps(n: usize, l: f64, centres: &[(usize, usize)], r: f64, floor: f64) -> Vec<f64> {
        let d = l / n as f64;
        let mut z = vec![floor; n * n];
        for i in 0..n {
            for j in 0..n {
                for &(ci, cj) in centres {
                    let (x, y) = ((i as f64 - ci as f64) * d, (j as f64 - cj as f64) * d);
                    z[i * n + j] = z[i * n + j].max(-(x * x + y * y) / (2.0 * r));
                }
            }
        }
        z
    }

    const N: usize = 256;
    const L: f64 = 1e-3;
    const R: f64 = 1e-3;
    const E: f64 = 1e9;
    const NU: f64 = 0.3;

    fn floor() -> f64 {
        -(0.25 * L).powi(2) / (2.0 * R)
    }

    /// A single summit (one paraboloid on a 256² periodic cell, homogeneous half-space).
    /// Summit detection finds exactly it with its exact radius (central differences are
    /// exact on a quadratic); the N model is Hertz to round-off, the isolated I model to
    /// its Newton tolerance (measured 1.5e-12, asserted 1e-10); the I model with periodic images (5×5 cells) agrees with the FFT-BEM of
    /// the whole surface at the same mean pressure: contact radius within 0.35 %,
    /// 0.82 %, 0.56 % at δ = 1, 4, 10 µm (7 to 21 grid points per radius; tolerance
    /// 1.5 %), although the images cut the load at given δ by up to 1.8×.
    #[test]
    fn single_summit() {
        let es = E / (1.0 - NU * NU);
        let law = Homogeneous { e_star: es };
        let z = bumps(N, L, &[(128, 128)], R, floor());
        let surf = Surface::new(z.clone(), N, N, L, true).unwrap();
        let rc = RoughContact::from_surface(&law, &surf).unwrap();
        assert_eq!(rc.summits().len(), 1);
        assert!(rel(rc.summits()[0].radius, R) < 1e-12);
        let bem = BemSolver::new(
            &Array2::from_shape_vec((N, N), z).unwrap(),
            L,
            &Stack::half_space(E, NU).unwrap(),
            BemOptions::default(),
        )
        .unwrap();
        for delta in [1e-6, 4e-6, 1e-5] {
            let hertz_a = (R * delta).sqrt();
            let hertz_p = 4.0 / 3.0 * es * hertz_a.powi(3) / R;
            for model in [Model::Independent, Model::Interacting(Images::Isolated)] {
                let s = rc.solve(model, delta, &[]).unwrap();
                eprintln!(
                    "single summit {model:?} δ = {delta:e}: a/a_H - 1 = {:.1e}, P/P_H - 1 = {:.1e}",
                    s.radii[0] / hertz_a - 1.0,
                    s.load / hertz_p - 1.0
                );
                assert!(rel(s.radii[0], hertz_a) < 1e-10 && rel(s.load, hertz_p) < 1e-10);
            }
            let s = rc
                .solve(Model::Interacting(Images::Periodic(2)), delta, &[])
                .unwrap();
            let b = bem.solve(BemLoad::MeanPressure(s.mean_pressure)).unwrap();
            let a_bem = (b.area_fraction * L * L / PI).sqrt();
            eprintln!(
                "single summit δ = {delta:e}: a_I/a_BEM - 1 = {:.2e}, P_N/P_I = {:.3}",
                s.radii[0] / a_bem - 1.0,
                hertz_p / s.load
            );
            assert!(rel(s.radii[0], a_bem) < 0.015);
            assert_eq!(b.patches, 1);
        }
    }

    /// The I model's energy (P22) for two identical summits at distance d on a
    /// homogeneous solid, as a function of their common contact radius a (< d):
    /// U ∝ Q(a)[G(a, d) + (6/5)a²/R − 2δ], Q = a³/R, G the Hertz displacement outside a
    /// contact. Minimised by a golden-section search: an implementation independent of
    /// the solver's gradient, Jacobian and active-set logic.
    fn pair_energy_minimiser(d: f64, delta: f64) -> f64 {
        let u = |a: f64| {
            let g =
                ((2.0 * a * a - d * d) * (a / d).asin() + a * (d * d - a * a).sqrt()) / (PI * R);
            a.powi(3) / R * (g + 1.2 * a * a / R - 2.0 * delta)
        };
        let (mut lo, mut hi) = (0.0, (R * delta).sqrt().min(0.999 * d));
        let phi = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..200 {
            let (x1, x2) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
            if u(x1) < u(x2) {
                hi = x2;
            } else {
                lo = x1;
            }
        }
        0.5 * (lo + hi)
    }

    /// Two summits nearly touching, then coalescing (apexes d = 16 grid points = 62.5 µm
    /// apart; 40 points = 156 µm for "nearby"). (i) The isolated I model equals an
    /// independent minimisation of its energy to 1e-6, also once the contact circles
    /// overlap (2a > d). (ii) Against the FFT-BEM of the whole surface at equal mean
    /// pressure, the periodic I model's contact radius is within 0.6 % and 0.95 %
    /// (d = 62.5 µm, δ = 1 and 4 µm) and 0.9 %, 0.2 % (d = 156 µm, δ = 4, 10 µm) while
    /// the BEM shows two patches; the N model, blind to the interaction, is off by 23 %
    /// to 42 %. (iii) At δ = 10 µm the BEM patches merge into one; the I model stays
    /// converged (KKT < 1e-8) with its load increasing, but it is outside the paper's
    /// model, which assumes separate circular contacts: its radius is 31 % below the
    /// BEM's equivalent radius (and below its own value at δ = 4 µm). Reported, not a
    /// tolerance.
    #[test]
    fn two_summits_nearly_touching_then_coalescing() {
        let es = E / (1.0 - NU * NU);
        let law = Homogeneous { e_star: es };
        let stack = Stack::half_space(E, NU).unwrap();
        for (k, checks) in [
            (8usize, vec![(1e-6, true), (4e-6, true), (1e-5, false)]),
            (20, vec![(4e-6, true), (1e-5, true)]),
        ] {
            let d = 2.0 * k as f64 * L / N as f64;
            let z = bumps(N, L, &[(128 - k, 128), (128 + k, 128)], R, floor());
            let surf = Surface::new(z.clone(), N, N, L, true).unwrap();
            // Two identical summits: at equal mean pressure P fixes a, whatever the
            // periodic images' convention; the raw image sums keep the loads (δ) this
            // test was measured at (with the mean displacement removed, δ = 1 µm is
            // already 2a/d = 0.96).
            let rc = RoughContact::from_surface(&law, &surf)
                .unwrap()
                .with_params({
                    let mut p = strata_runtime::rough::Params::default();
                    p.zero_mean_images = false;
                    p
                });
            assert_eq!(rc.summits().len(), 2);
            let bem = BemSolver::new(
                &Array2::from_shape_vec((N, N), z).unwrap(),
                L,
                &stack,
                BemOptions::default(),
            )
            .unwrap();
            let mut last_load = 0.0;
            for (delta, separate) in checks {
                let iso = rc
                    .solve(Model::Interacting(Images::Isolated), delta, &[])
                    .unwrap();
                let a_iso = iso.radii[0];
                if a_iso < 0.999 * d {
                    let a_ref = pair_energy_minimiser(d, delta);
                    eprintln!(
                        "pair d = {d:.3e} m, δ = {delta:e}: isolated I model vs energy minimiser {:.1e}",
                        a_iso / a_ref - 1.0
                    );
                    assert!(rel(a_iso, a_ref) < 1e-6, "{a_iso} {a_ref}");
                }
                let s = rc
                    .solve(Model::Interacting(Images::Periodic(2)), delta, &[])
                    .unwrap();
                assert!(s.kkt_residual.unwrap() < 1e-8);
                assert!(s.load > last_load);
                last_load = s.load;
                let b = bem.solve(BemLoad::MeanPressure(s.mean_pressure)).unwrap();
                let a_bem = (b.area_fraction * L * L / (2.0 * PI)).sqrt();
                let a_n = (R * delta).sqrt();
                eprintln!(
                    "pair d = {d:.3e} m, δ = {delta:e}: 2a_I/d = {:.2}, a_I/a_BEM - 1 = {:.3e}, a_N/a_BEM - 1 = {:.3e}, BEM patches {}",
                    2.0 * s.radii[0] / d,
                    s.radii[0] / a_bem - 1.0,
                    a_n / a_bem - 1.0,
                    b.patches
                );
                if separate {
                    assert_eq!(b.patches, 2);
                    assert!(rel(s.radii[0], a_bem) < 0.015);
                } else {
                    assert_eq!(b.patches, 1, "contacts should have coalesced");
                }
            }
        }
    }

    /// Full contact at high load, FFT-BEM, a sinusoid z = A cos(2πx/λ) on a 128² cell
    /// (λ = L). Full contact holds exactly when p̄ ≥ p* = πE*₁A/(λS(2π/λ)) (Johnson's
    /// p* = πE*A/λ on a half-space; S from the layered compliance), and then
    /// p = p̄ + p* cos(2πx/λ): asserted to 1e-8 of p* at 1.01 p*, and A/A₀ < 1 at
    /// 0.99 p*, on a half-space and on a 100 µm layer on a rigid base (S = 0.26).
    /// Partial contact on the half-space follows Johnson's A/A₀ = (2/π) asin √(p̄/p*)
    /// to the grid resolution (1.5/n) at p̄/p* = 0.25, 0.5, 0.75.
    #[test]
    fn full_contact_at_high_load() {
        let (n, amp) = (128usize, 1e-6);
        let es = E / (1.0 - NU * NU);
        let k = 2.0 * PI / L;
        let heights =
            Array2::from_shape_fn((n, n), |(i, _)| amp * (k * L * i as f64 / n as f64).cos());
        for stack in [
            Stack::half_space(E, NU).unwrap(),
            Stack::new(vec![layer(1e-4, E, NU)], Base::Rigid).unwrap(),
        ] {
            let s = strata_runtime::Compliance::new(&stack).s(k);
            let pstar = PI * es * amp / (L * s);
            let bem = BemSolver::new(&heights, L, &stack, BemOptions::default()).unwrap();
            let full = bem.solve(BemLoad::MeanPressure(1.01 * pstar)).unwrap();
            assert_eq!(full.area_fraction, 1.0);
            let worst = full
                .pressure
                .indexed_iter()
                .map(|((i, _), &p)| {
                    (p - 1.01 * pstar - pstar * (k * L * i as f64 / n as f64).cos()).abs()
                })
                .fold(0.0, f64::max);
            let part = bem.solve(BemLoad::MeanPressure(0.99 * pstar)).unwrap();
            eprintln!(
                "full contact, S = {s:.4}: |p - exact|/p* = {:.1e} at 1.01 p*, A/A0 = {} at 0.99 p*",
                worst / pstar,
                part.area_fraction
            );
            assert!(worst < 1e-8 * pstar);
            assert!(part.area_fraction < 1.0);
            if s == 1.0 {
                for f in [0.25f64, 0.5, 0.75] {
                    let b = bem.solve(BemLoad::MeanPressure(f * pstar)).unwrap();
                    let johnson = 2.0 / PI * f.sqrt().asin();
                    eprintln!(
                        "Johnson p/p* = {f}: A/A0 = {} vs {johnson:.4}",
                        b.area_fraction
                    );
                    assert!((b.area_fraction - johnson).abs() < 1.5 / n as f64);
                }
            }
        }
    }

    /// Zero load: δ = 0 touches the highest summit only, so P = 0, A = 0 and no contact
    /// in both asperity models; the BEM at zero approach carries no pressure, and a
    /// zero or negative mean pressure is refused with a message naming it.
    #[test]
    fn zero_load() {
        let law = Homogeneous {
            e_star: E / (1.0 - NU * NU),
        };
        let z = bumps(64, L, &[(20, 20), (40, 44)], R, floor());
        let surf = Surface::new(z.clone(), 64, 64, L, true).unwrap();
        let rc = RoughContact::from_surface(&law, &surf).unwrap();
        for model in [
            Model::Independent,
            Model::Interacting(Images::Isolated),
            Model::Interacting(Images::Periodic(2)),
        ] {
            let s = rc.solve(model, 0.0, &[]).unwrap();
            assert_eq!((s.load, s.area_fraction, s.contacts), (0.0, 0.0, 0));
            assert!(rc.solve_pressure(model, 0.0, &[]).is_err());
        }
        let bem = BemSolver::new(
            &Array2::from_shape_vec((64, 64), z).unwrap(),
            L,
            &Stack::new(vec![layer(1e-4, E, NU)], Base::Rigid).unwrap(),
            BemOptions::default(),
        )
        .unwrap();
        let s = bem.solve(BemLoad::Approach(0.0)).unwrap();
        assert!(s.mean_pressure.abs() < 1e-9 * E && s.contact_points <= 1);
        for p in [0.0, -1.0] {
            let e = bem.solve(BemLoad::MeanPressure(p)).unwrap_err().to_string();
            assert!(e.contains("mean pressure"), "{e}");
        }
    }

    /// At the peak-to-valley approach z_M − z_min every summit is in contact, with
    /// finite results; beyond it the approach is solved, not refused, and
    /// the step is flagged: load increasing, every summit loaded, KKT < 1e-8.
    #[test]
    fn asperity_models_at_full_approach() {
        let law = Homogeneous {
            e_star: E / (1.0 - NU * NU),
        };
        let z = bumps(64, L, &[(20, 20), (40, 44), (50, 10)], R, floor());
        let surf = Surface::new(z, 64, 64, L, true).unwrap();
        let rc = RoughContact::from_surface(&law, &surf).unwrap();
        for model in [Model::Independent, Model::Interacting(Images::Isolated)] {
            let s = rc.solve(model, rc.max_delta(), &[]).unwrap();
            assert_eq!(s.contacts, rc.summits().len());
            assert!(s.load.is_finite() && s.load > 0.0);
            let b = rc.solve(model, 1.01 * rc.max_delta(), &[]).unwrap();
            assert!(b.load > s.load && b.validity.beyond_deepest_valley, "{b:?}");
            if let Some(k) = b.kkt_residual {
                assert!(k < 1e-8);
            }
            let e = rc.solve(model, -1e-9, &[]).unwrap_err();
            assert!(matches!(e, RoughError::LoadOutOfRange { .. }), "{e}");
        }
    }

    /// A flat surface has no summit: the asperity models refuse it (no summits), the
    /// BEM refuses it (flat surface).
    #[test]
    fn flat_surface_has_no_summit() {
        let law = Homogeneous { e_star: 1e9 };
        let surf = Surface::new(vec![1e-6; 64], 8, 8, L, true).unwrap();
        assert!(matches!(
            RoughContact::from_surface(&law, &surf),
            Err(RoughError::NoSummits)
        ));
        let e = BemSolver::new(
            &Array2::from_elem((8, 8), 1e-6),
            L,
            &Stack::half_space(E, NU).unwrap(),
            BemOptions::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("flat"), "{e}");
    }
}

fn strata(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .output()
        .expect("run strata")
}

fn tmp(name: &str) -> PathBuf {
    let d = crate::support::scratch().join(format!("hard-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// A 64² generated surface (heights in m, row-major) for the command-line cases.
fn rough_heights() -> Vec<f64> {
    strata_runtime::surface::Surface::generate(&strata_runtime::surface::GenerateParams {
        size: 1e-3,
        grid: 64,
        fractal_dimension: 2.4,
        k_min: 2.0,
        k_max: 8.0,
        rms: 3.4e-6,
        seed: 3,
    })
    .expect("surface")
    .heights()
    .to_vec()
}

/// Writes an n×n little-endian f64 .npy file (format 1.0, C order).
fn write_npy(path: &Path, z: &[f64], n: usize) {
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({n}, {n}), }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    for v in z {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, bytes).expect("write .npy");
}

fn write_text_surface(path: &Path, z: &[String], n: usize) {
    let rows: Vec<String> = z.chunks(n).map(|r| r.join(" ")).collect();
    std::fs::write(path, rows.join("\n") + "\n").expect("surface file");
}

/// A homogeneous scene on `surface` (file name relative to the scene), independent
/// model, with `load` and extra `[surface]` lines.
fn scene(dir: &Path, surface: &str, surface_extra: &str, kind: &str, load: &str) -> PathBuf {
    let text = format!(
        "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
         [surface]\nfile = \"{surface}\"\nsize = 1e-3\nperiodic = true\n{surface_extra}\n\
         [model]\nkind = \"{kind}\"\n[load]\n{load}\n"
    );
    let p = dir.join(format!("scene-{kind}.toml"));
    std::fs::write(&p, text).expect("scene");
    p
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn curve_rows(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .expect("curve.csv")
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect()
}

mod cli {
    use super::*;

    const LOAD: &str = "approach = { from = 1e-6, to = 6e-6, steps = 4 }";

    /// Measured data with a NaN (text) or an infinity (.npy) is refused with the file
    /// and the grid index of the first bad value; `repair = "median"` interpolates it
    /// and the run succeeds, saying so.
    #[test]
    fn non_finite_heights_are_refused_or_repaired_on_request() {
        let d = tmp("nan");
        let z = rough_heights();
        let mut text: Vec<String> = z.iter().map(|v| format!("{v:e}")).collect();
        text[5 * 64 + 7] = "nan".into();
        write_text_surface(&d.join("nan.txt"), &text, 64);
        let sc = scene(&d, "nan.txt", "", "independent", LOAD);
        let o = strata(&[
            "solve",
            sc.to_str().unwrap(),
            "--out",
            d.join("o1").to_str().unwrap(),
        ]);
        let e = stderr(&o);
        assert!(!o.status.success());
        assert!(
            e.contains("nan.txt") && e.contains("row 5, column 7"),
            "{e}"
        );
        assert!(!e.contains("panicked"), "{e}");

        let mut zi = z.clone();
        zi[63 * 64] = f64::INFINITY;
        write_npy(&d.join("inf.npy"), &zi, 64);
        let sc = scene(&d, "inf.npy", "", "bem", LOAD);
        let o = strata(&[
            "solve",
            sc.to_str().unwrap(),
            "--out",
            d.join("o2").to_str().unwrap(),
        ]);
        let e = stderr(&o);
        assert!(!o.status.success());
        assert!(
            e.contains("inf.npy") && e.contains("row 63, column 0"),
            "{e}"
        );

        let sc = scene(&d, "nan.txt", "repair = \"median\"", "independent", LOAD);
        let out = d.join("o3");
        let o = strata(&[
            "solve",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--no-plots",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stderr(&o).contains("1 points"), "{}", stderr(&o));
        assert_eq!(curve_rows(&out.join("curve.csv")).len(), 4);
    }

    /// A spike (one pixel 100 µm above the highest point of a 3.4 µm RMS surface, like
    /// an instrument glitch) would become the highest summit and shift every separation
    /// by 100 µm: it is refused, naming the file and the index. With `repair =
    /// "median"` it is replaced by its prediction from its neighbours, and the load curve at
    /// given approaches equals that of the clean surface to 1e-12 (the glitch sits on
    /// the lowest point, away from every summit; only the mean height, hence the gap
    /// column, moves, by < 1e-9 m).
    #[test]
    fn spikes_are_refused_or_repaired_on_request() {
        let d = tmp("spike");
        let z = rough_heights();
        let clean: Vec<String> = z.iter().map(|v| format!("{v:e}")).collect();
        write_text_surface(&d.join("clean.txt"), &clean, 64);
        // Choose a point that is not a summit nor next to one: the lowest point.
        let k = (0..z.len()).min_by(|&a, &b| z[a].total_cmp(&z[b])).unwrap();
        let z_max = z.iter().copied().fold(f64::MIN, f64::max);
        let mut spiky = clean.clone();
        spiky[k] = format!("{:e}", z_max + 1e-4);
        write_text_surface(&d.join("spike.txt"), &spiky, 64);
        let sc = scene(&d, "spike.txt", "", "independent", LOAD);
        let o = strata(&[
            "solve",
            sc.to_str().unwrap(),
            "--out",
            d.join("o1").to_str().unwrap(),
        ]);
        let e = stderr(&o);
        assert!(!o.status.success());
        assert!(
            e.contains("spike.txt")
                && e.contains("spike")
                && e.contains(&format!("row {}, column {}", k / 64, k % 64)),
            "{e}"
        );

        let run = |file: &str, extra: &str, out: &str| {
            let sc = scene(&d, file, extra, "independent", LOAD);
            let o = strata(&[
                "solve",
                sc.to_str().unwrap(),
                "--out",
                d.join(out).to_str().unwrap(),
                "--no-plots",
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
            curve_rows(&d.join(out).join("curve.csv"))
        };
        let repaired = run("spike.txt", "repair = \"median\"", "o2");
        let reference = run("clean.txt", "", "o3");
        assert_eq!(repaired.len(), reference.len());
        for (a, b) in repaired.iter().zip(&reference) {
            for (c, (x, y)) in a.iter().zip(b).enumerate() {
                if c == 1 {
                    assert!((x - y).abs() < 1e-9, "gap {x} {y}");
                } else {
                    assert!((x - y).abs() <= 1e-12 * y.abs(), "column {c}: {a:?} {b:?}");
                }
            }
        }
    }

    /// A flat measured surface: no summit for the asperity models, a flat surface for
    /// the BEM — both refused with a message, never a panic.
    #[test]
    fn flat_surface_is_refused() {
        let d = tmp("flat");
        let flat = vec!["1e-6".to_string(); 64];
        write_text_surface(&d.join("flat.txt"), &flat, 8);
        for (kind, needle) in [
            ("independent", "no summits"),
            ("interacting", "no summits"),
            ("bem", "flat"),
        ] {
            let sc = scene(
                &d,
                "flat.txt",
                "",
                kind,
                "approach = { from = 0, to = 0, steps = 1 }",
            );
            let o = strata(&[
                "solve",
                sc.to_str().unwrap(),
                "--out",
                d.join(kind).to_str().unwrap(),
            ]);
            let e = stderr(&o);
            assert!(!o.status.success());
            assert!(e.contains(needle) && !e.contains("panicked"), "{kind}: {e}");
        }
    }

    /// Zero load end to end: an approach of 0 gives one row with zero pressure, area and
    /// contacts (exit 0, no plots of nothing); a zero mean pressure is refused, naming
    /// `load.mean_pressures[0]`.
    #[test]
    fn zero_load_through_the_command() {
        let d = tmp("zero");
        let z: Vec<String> = rough_heights().iter().map(|v| format!("{v:e}")).collect();
        write_text_surface(&d.join("s.txt"), &z, 64);
        for kind in ["independent", "interacting", "bem"] {
            let sc = scene(
                &d,
                "s.txt",
                "",
                kind,
                "approach = { from = 0, to = 0, steps = 1 }",
            );
            let out = d.join(kind);
            let o = strata(&[
                "solve",
                sc.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{kind}: {}", stderr(&o));
            let rows = curve_rows(&out.join("curve.csv"));
            assert_eq!(rows.len(), 1);
            // delta, gap, mean_pressure, pressure_ratio, area_fraction, contacts
            assert!(rows[0][0].abs() < 1e-15, "{kind}: {:?}", rows[0]);
            assert!(
                rows[0][2].abs() < 1e-6 && rows[0][4] <= 1.0 / 4096.0,
                "{kind}: {:?}",
                rows[0]
            );
        }
        let sc = scene(&d, "s.txt", "", "independent", "mean_pressures = [0]");
        let o = strata(&[
            "solve",
            sc.to_str().unwrap(),
            "--out",
            d.join("p0").to_str().unwrap(),
        ]);
        assert!(!o.status.success());
        assert!(
            stderr(&o).contains("load.mean_pressures[0]"),
            "{}",
            stderr(&o)
        );
    }
}

mod outputs {
    use super::*;

    const LOAD: &str = "approach = { from = 1e-6, to = 6e-6, steps = 4 }";

    fn setup(name: &str) -> (PathBuf, PathBuf) {
        let d = tmp(name);
        let z: Vec<String> = rough_heights().iter().map(|v| format!("{v:e}")).collect();
        write_text_surface(&d.join("s.txt"), &z, 64);
        (d.clone(), scene(&d, "s.txt", "", "independent", LOAD))
    }

    fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
        let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.path().is_file())
            .map(|e| {
                (
                    e.file_name().to_string_lossy().into_owned(),
                    std::fs::read(e.path()).unwrap(),
                )
            })
            .collect();
        v.sort();
        v
    }

    fn no_temporaries(dir: &Path) {
        for e in std::fs::read_dir(dir).unwrap().filter_map(|e| e.ok()) {
            let n = e.file_name().to_string_lossy().into_owned();
            assert!(!n.contains(".tmp-"), "temporary file left: {n}");
        }
    }

    /// A non-empty output directory is refused without --force and left byte for byte
    /// as it was; with --force the run replaces the outputs and leaves no temporary.
    #[test]
    fn existing_outputs_are_not_overwritten_unless_asked() {
        let (d, sc) = setup("refuse");
        let out = d.join("out");
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(out.join("curve.csv"), "precious\n").unwrap();
        std::fs::write(out.join("notes.txt"), "mine\n").unwrap();
        let before = snapshot(&out);
        let o = strata(&[
            "solve",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!o.status.success());
        assert!(stderr(&o).contains("--force"), "{}", stderr(&o));
        assert_eq!(snapshot(&out), before);
        let o = strata(&[
            "solve",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--force",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(curve_rows(&out.join("curve.csv")).len(), 4);
        assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"mine\n");
        no_temporaries(&out);
    }

    /// A run that fails (a load out of range, found after the directory check) leaves
    /// the existing results intact, even with --force.
    #[test]
    fn a_failing_run_leaves_existing_results_intact() {
        let (d, _) = setup("failing");
        let out = d.join("out");
        let good = scene(&d, "s.txt", "", "interacting", LOAD);
        let o = strata(&[
            "solve",
            good.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let before = snapshot(&out);
        assert!(before.iter().any(|(n, _)| n == "curve.csv"));
        let bad = scene(
            &d,
            "s.txt",
            "",
            "independent",
            "approach = { from = 1e-6, to = -1e-6, steps = 3 }",
        );
        let o = strata(&[
            "solve",
            bad.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--force",
        ]);
        assert!(!o.status.success());
        assert!(stderr(&o).contains("load.approach.to"), "{}", stderr(&o));
        assert_eq!(snapshot(&out), before);
        no_temporaries(&out);
    }

    /// Outputs are written into a staging directory and swapped in as a whole, so an
    /// entry in the way of an output (a directory named curve.json) no longer fails a
    /// run half-way: with --force the new set replaces it, the user's other files stay,
    /// and nothing is left beside the target (interrupted and failing writes: module
    /// `outputs` of the integration tests).
    #[test]
    fn entries_in_the_way_are_replaced_with_the_set() {
        let (d, sc) = setup("midwrite");
        let out = d.join("out");
        std::fs::create_dir_all(out.join("curve.json")).unwrap();
        std::fs::write(out.join("curve.csv"), "old curve\n").unwrap();
        std::fs::write(out.join("mine.txt"), "mine\n").unwrap();
        let o = strata(&[
            "solve",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--force",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(out.join("curve.json").is_file());
        assert_eq!(curve_rows(&out.join("curve.csv")).len(), 4);
        assert_eq!(std::fs::read(out.join("mine.txt")).unwrap(), b"mine\n");
        no_temporaries(&out);
        for e in std::fs::read_dir(&d).unwrap().filter_map(|e| e.ok()) {
            let n = e.file_name().to_string_lossy().into_owned();
            assert!(
                !n.ends_with(".strata-new") && !n.ends_with(".strata-old"),
                "staging left: {n}"
            );
        }
    }
}

/// A ν = 0.5 layer on a rigid base solved from a scene without a table. The
/// cached table's default 97×49 grid misses its tolerance (ζ 1.2e−4 > 1e−4), so the
/// cache refines the grid (here to 129×65) and the solve succeeds; `table check`
/// re-measures the cached table within its tolerance (measured: ζ 2.9e−5, χ 1.9e−6,
/// g 2.1e−6). Slow tier (two table builds and a check, ~30 s).
#[test]
#[ignore = "slow tier: cargo test --workspace -- --ignored slow_"]
fn slow_incompressible_layer_solves_from_a_scene() {
    let d = crate::support::fresh_dir("hard_cases", "nu-half");
    std::fs::write(
        d.join("stack.toml"),
        "[[layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 0.5\n[base]\nkind = \"rigid\"\n",
    )
    .unwrap();
    let scene = "[stack]\nfile = \"stack.toml\"\n[surface]\nperiodic = true\n\
                 [surface.generate]\nsize = 1e-3\ngrid = 64\nfractal_dimension = 2.4\n\
                 k_min = 2\nk_max = 8\nrms = 3.4e-6\nseed = 5\n[model]\nkind = \"interacting\"\n\
                 [load]\napproach = { from = 1e-6, to = 4e-6, steps = 3 }\n";
    std::fs::write(d.join("s.toml"), scene).unwrap();
    let cache = d.join("cache");
    let o = crate::support::strata_in(&cache)
        .current_dir(&d)
        .args(["solve", "s.toml", "--out", "out", "--no-plots"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("building again on a 129×65 grid"), "{err}");
    let table = std::fs::read_dir(&cache)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|x| x == "strata"))
        .expect("a cached table");
    let o = crate::support::strata_in(&cache)
        .args(["table", "check"])
        .arg(&table)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
