//! Property tests of the solvers' inputs: random — including NaN, infinite,
//! negative, zero and huge — summits, approaches, pressures, radii, grids, sizes and
//! options into the rough-contact models (`RoughContact`), the boundary-element solver
//! (`BemSolver`) and the full asperity solver (`strata_tablegen::asperity::Asperity`).
//! No panic, no hang (every case is small and every loop is bounded), and every
//! outcome is either a finite, physically admissible result or a typed error with a
//! one-line message.
//!
//! Bounded for CI: fixed case counts and a fixed seed (~10 s in the test profile).
//! Longer run: `PROPTEST_CASES=20000 cargo test --test fuzz_solvers`.

use ndarray::Array2;
use proptest::prelude::*;
use strata_bem::{BemLoad, BemOptions, BemSolver};
use strata_runtime::law::Homogeneous;
use strata_runtime::rough::{Images, Model, RoughContact, contact_radius};
use strata_runtime::summits::Summit;
use strata_runtime::{Base, Layer, Stack};
use strata_tablegen::asperity::{Asperity, Options};

fn config(cases: u32) -> ProptestConfig {
    crate::support::fuzz_config(cases, 0x501e)
}

/// A number near `typical` (log-uniform over ±2 decades) or a hostile value.
fn num(typical: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => (-2.0f64..2.0).prop_map(move |e| typical * 10f64.powf(e)),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(0.0),
        1 => Just(-typical),
        1 => Just(1e300),
        1 => Just(f64::MIN_POSITIVE),
        1 => any::<f64>(),
    ]
}

/// Mostly sane numbers with an occasional hostile one.
fn mostly(typical: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        12 => (-1.0f64..1.0).prop_map(move |e| typical * 10f64.powf(e)),
        1 => num(typical),
    ]
}

fn one_line(e: &dyn std::error::Error) {
    let m = e.to_string();
    assert!(!m.is_empty() && !m.contains('\n'), "{m}");
}

fn summit() -> impl Strategy<Value = Summit> {
    (mostly(5e-4), mostly(5e-4), mostly(2e-6), mostly(1e-4)).prop_map(|(x, y, z, radius)| Summit {
        index: (0, 0),
        x,
        y,
        z,
        radius,
    })
}

fn step_ok(s: &strata_runtime::rough::Step) {
    assert!(s.load.is_finite() && s.load >= 0.0, "{s:?}");
    assert!(
        s.mean_pressure.is_finite() && s.mean_pressure >= 0.0,
        "{s:?}"
    );
    assert!(
        s.area_fraction.is_finite() && s.area_fraction >= 0.0,
        "{s:?}"
    );
    assert!(s.stiffness.is_finite(), "{s:?}");
}

proptest! {
    #![proptest_config(config(400))]

    /// The N and I models on random summits (positions, heights, radii), sample
    /// statistics, moduli and loads.
    #[test]
    fn rough_contact_never_panics(
        summits in proptest::collection::vec(summit(), 0..6),
        z_mean in mostly(-1e-6),
        z_min in mostly(-5e-6),
        ext in (mostly(1e-3), mostly(1e-3)),
        e_star in mostly(1e9),
        deltas in proptest::collection::vec(num(1e-6), 1..4),
        target in num(1e6),
        cells in 0usize..3,
    ) {
        let law = Homogeneous { e_star };
        let rc = match RoughContact::new(&law, summits, z_mean, z_min, ext) {
            Ok(rc) => rc,
            Err(e) => { one_line(&e); return Ok(()); }
        };
        for model in [
            Model::Independent,
            Model::Interacting(Images::Isolated),
            Model::Interacting(Images::Periodic(cells)),
        ] {
            for &d in &deltas {
                match rc.solve(model, d, &[]) {
                    Ok(s) => {
                        step_ok(&s);
                        prop_assert!(d.is_finite() && d >= 0.0);
                    }
                    Err(e) => one_line(&e),
                }
            }
            match rc.curve(model, &deltas) {
                Ok(v) => v.iter().for_each(step_ok),
                Err(e) => one_line(&e),
            }
            match rc.solve_pressure(model, target, &[]) {
                Ok(s) => step_ok(&s),
                Err(e) => one_line(&e),
            }
        }
        let _ = rc.delta_for_gap(deltas[0]);
    }

    /// The single-asperity inversion ζ(a)a²/R = δ: for a valid radius and approach the
    /// contact radius is finite and non-negative (RoughContact validates R before).
    #[test]
    fn contact_radius_never_panics(r in num(1e-4), d in num(1e-6), e_star in num(1e9)) {
        let law = Homogeneous { e_star };
        let a = contact_radius(&law, r, d);
        if r.is_finite() && r > 0.0 && d.is_finite() && d >= 0.0 && r * d < f64::MAX {
            prop_assert!(a.is_some_and(|a| a.is_finite() && a >= 0.0), "a = {a:?}");
        }
    }
}

fn grid_heights() -> impl Strategy<Value = Array2<f64>> {
    let dim = prop_oneof![Just(2usize), Just(3), Just(4), Just(6), Just(8), Just(16)];
    (dim.clone(), dim, 0u8..4, any::<u64>(), mostly(1e-6)).prop_map(|(r, c, kind, seed, amp)| {
        let c = if kind == 0 { c } else { r }; // mostly square
        let mut s = seed | 1;
        let mut next = move || {
            // xorshift: reproducible pseudo-random heights
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut h = Array2::from_shape_fn((r, c), |_| amp * next());
        match kind {
            1 => h[[r / 2, c / 2]] = f64::NAN,
            2 => h.fill(amp), // flat
            _ => {}
        }
        h
    })
}

fn stack() -> impl Strategy<Value = Stack> {
    prop_oneof![
        Just(Stack::half_space(1e9, 0.3).expect("valid")),
        (1e-6f64..1e-3, -4.0f64..4.0, -0.9f64..0.5, any::<bool>()).prop_map(
            |(h, lr, nu, rigid)| {
                let base = if rigid {
                    Base::Rigid
                } else {
                    Base::Elastic {
                        young: 1e9 * 10f64.powf(lr),
                        poisson: 0.3,
                    }
                };
                Stack::new(
                    vec![Layer {
                        thickness: h,
                        young: 1e9,
                        poisson: nu,
                    }],
                    base,
                )
                .expect("valid")
            }
        ),
    ]
}

fn bem_load() -> impl Strategy<Value = BemLoad> {
    prop_oneof![
        num(1e-7).prop_map(BemLoad::MeanGap),
        num(1e-7).prop_map(BemLoad::Approach),
        num(1e5).prop_map(BemLoad::MeanPressure),
        num(1e-7).prop_map(BemLoad::Separation),
    ]
}

proptest! {
    #![proptest_config(config(300))]

    /// The boundary-element solver on random small grids (square or not, with NaN,
    /// flat), sizes, stacks, options and loads.
    #[test]
    fn bem_never_panics(
        h in grid_heights(),
        size in mostly(1e-3),
        st in stack(),
        tol in prop_oneof![4 => Just(1e-10), 1 => num(1e-6)],
        iters in prop_oneof![4 => Just(2000usize), 1 => 0usize..5],
        loads in proptest::collection::vec(bem_load(), 1..4),
    ) {
        let opts = BemOptions { tolerance: tol, max_iterations: iters, ..Default::default() };
        let solver = match BemSolver::new(&h, size, &st, opts) {
            Ok(s) => s,
            Err(e) => { one_line(&e); return Ok(()); }
        };
        for &l in &loads {
            match solver.solve(l) {
                Ok(s) => {
                    prop_assert!(s.mean_pressure.is_finite() && s.mean_pressure >= 0.0);
                    prop_assert!((0.0..=1.0).contains(&s.area_fraction));
                    prop_assert!(s.pressure.iter().all(|p| p.is_finite() && *p >= 0.0));
                }
                Err(e) => one_line(&e),
            }
        }
        match solver.solve_curve(&loads) {
            Ok(v) => prop_assert_eq!(v.len(), loads.len()),
            Err(e) => one_line(&e),
        }
        let bad = [f64::NAN, -1.0];
        prop_assert!(solver.solve_from(BemLoad::MeanPressure(1e5), Some(&bad)).is_err());
    }
}

proptest! {
    #![proptest_config(config(48))]

    /// The full (Fredholm) asperity solver: random one-layer stacks and random contact
    /// radii (a ≤ 4h₁ so that every case is a fast Nyström solve), radii of curvature,
    /// approaches, cone angles and profile radii.
    #[test]
    fn asperity_never_panics(
        st in stack(),
        ah in prop_oneof![8 => -3.0f64..0.6, 1 => Just(f64::NAN), 1 => Just(-1.0)],
        radius in num(1e-3),
        delta_frac in num(1.0),
        angle in num(1.0),
        rs in proptest::collection::vec(num(1e-5), 0..4),
    ) {
        let asp = match Asperity::new(&st, Options::default()) {
            Ok(a) => a,
            Err(e) => { one_line(&e); return Ok(()); }
        };
        let h = st.top_thickness().unwrap_or(1e-4);
        let a = h * 10f64.powf(ah);
        let sols = [
            asp.paraboloid_at_radius(a, radius),
            asp.cone_at_radius(a, angle),
            asp.flat_punch(a, delta_frac * 1e-7),
            // δ up to about the Hertz value of a (a stays within the Nyström range).
            asp.paraboloid_at_delta(delta_frac.min(1.0) * a * a / radius, radius),
        ];
        for s in sols {
            match s {
                Ok(s) => {
                    prop_assert!(s.force.is_finite() && s.delta.is_finite() && s.a >= 0.0);
                    let p = s.pressure(&rs);
                    prop_assert_eq!(p.len(), rs.len());
                    match s.displacement(&rs) {
                        Ok(u) => prop_assert_eq!(u.len(), rs.len()),
                        Err(e) => one_line(&e),
                    }
                }
                Err(e) => one_line(&e),
            }
        }
        match asp.paraboloid_delta(a, radius) {
            Ok(d) => prop_assert!(d.is_finite()),
            Err(e) => one_line(&e),
        }
    }
}
