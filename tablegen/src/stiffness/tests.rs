use super::reference::ritz_tangential;
use super::*;
use crate::asperity::{Asperity, Options};
use strata_runtime::stack::shear_modulus;
use strata_runtime::{Base, Layer};

const H: f64 = 1e-4;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn layer(h: f64, e: f64, nu: f64) -> Layer {
    Layer {
        thickness: h,
        young: e,
        poisson: nu,
    }
}

fn elastic(young: f64, poisson: f64) -> Base {
    Base::Elastic { young, poisson }
}

/// Mindlin's 8μa/(2−ν) and the flat punch's 2aE* on a half-space: the zero-layer stack
/// (closed form) and three identical layers on an identical half-space, which go
/// through the kernels and the Fredholm solves (k ≡ 0 to round-off) at a/h₁ from 1e-3
/// to 30 (Nyström and product integration).
#[test]
fn half_space_meets_mindlin_and_punch() {
    for nu in [0.0, 0.3, 0.5] {
        let e = 2e11;
        let mu = shear_modulus(e, nu);
        let es = e / (1.0 - nu * nu);
        let hs = Stack::half_space(e, nu).unwrap();
        let st = Stack::new(
            vec![
                layer(H, e, nu),
                layer(2.0 * H, e, nu),
                layer(0.5 * H, e, nu),
            ],
            elastic(e, nu),
        )
        .unwrap();
        let mut worst = 0.0f64;
        for (s, ahs) in [(&hs, &[1e-3, 1.0][..]), (&st, &[1e-3, 1.0, 30.0][..])] {
            let k = Stiffness::new(s);
            for &ah in ahs {
                let a = ah * H;
                let d = k.at(a).unwrap();
                let (mindlin, punch) = (8.0 * mu * a / (2.0 - nu), 2.0 * a * es);
                worst = worst
                    .max(rel(d.tangential, mindlin))
                    .max(rel(d.normal, punch));
                assert!(
                    rel(d.tangential, mindlin) < 1e-6 && rel(d.normal, punch) < 1e-6,
                    "nu {nu} a/h {ah}: {d:?} vs {mindlin}, {punch}"
                );
            }
        }
        eprintln!("half-space nu {nu}: worst relative error {worst:.1e}");
    }
}

/// The thin-layer limits on a rigid base: K_t → πa²/Σ(h/μ), K_n → πa²/Σ(h/M), from
/// above, with a relative excess that falls like h/a: (excess · a/h) changes by less
/// than 25 % between a/h = 10, 30 and 100 while the excess itself falls tenfold.
#[test]
fn thin_layer_limits() {
    for (layers, name) in [
        (vec![layer(H, 1e9, 0.3)], "one layer, nu 0.3"),
        (
            vec![layer(H, 1e9, 0.15), layer(2.0 * H, 5e9, 0.4)],
            "two layers",
        ),
    ] {
        let st = Stack::new(layers.clone(), Base::Rigid).unwrap();
        let sum_mu: f64 = layers
            .iter()
            .map(|l| l.thickness / shear_modulus(l.young, l.poisson))
            .sum();
        let sum_m: f64 = layers
            .iter()
            .map(|l| {
                let (e, nu) = (l.young, l.poisson);
                l.thickness * (1.0 + nu) * (1.0 - 2.0 * nu) / (e * (1.0 - nu))
            })
            .sum();
        let k = Stiffness::new(&st);
        let mut prev: Option<(f64, f64)> = None;
        for ah in [10.0, 30.0, 100.0] {
            let a = ah * H;
            let d = k.at(a).unwrap();
            let et = d.tangential / (PI * a * a / sum_mu) - 1.0;
            let en = d.normal / (PI * a * a / sum_m) - 1.0;
            eprintln!(
                "{name} a/h {ah}: excess K_t {et:.4e} (x a/h {:.4}), K_n {en:.4e} (x a/h {:.4})",
                et * ah,
                en * ah
            );
            assert!(et > 0.0 && en > 0.0, "{name} a/h {ah}: {et} {en}");
            if let Some((pt, pn)) = prev {
                assert!(rel(et * ah, pt) < 0.25 && rel(en * ah, pn) < 0.25, "{name}");
            }
            prev = Some((et * ah, en * ah));
        }
    }
}

use std::f64::consts::PI;

/// The normal punch against the existing asperity solver's flat punch (P/δ).
#[test]
fn normal_matches_asperity_flat_punch() {
    let st = Stack::new(
        vec![layer(H, 4e9, 0.15), layer(9.0 * H, 20e9, 0.15)],
        Base::Rigid,
    )
    .unwrap();
    let k = Stiffness::new(&st);
    let asp = Asperity::new(&st, Options::default()).unwrap();
    for ah in [0.01, 1.0, 10.0] {
        let a = ah * H;
        let kn = k.at(a).unwrap().normal;
        let p = asp.flat_punch(a, 1e-7).unwrap().force / 1e-7;
        eprintln!("flat punch a/h {ah}: {kn} vs {p} ({:.1e})", rel(kn, p));
        assert!(rel(kn, p) < 1e-6, "a/h {ah}: {kn} vs {p}");
    }
}

/// Stacks between the limits for the second method (not used to tune the solver).
fn hidden_stacks() -> Vec<(&'static str, Stack)> {
    vec![
        (
            "coating on a base 5x softer",
            Stack::new(vec![layer(H, 10e9, 0.25)], elastic(2e9, 0.35)).unwrap(),
        ),
        (
            "soft layer on a rigid base",
            Stack::new(vec![layer(H, 1e9, 0.42)], Base::Rigid).unwrap(),
        ),
        (
            "hard coating on a soft substrate",
            Stack::new(
                vec![layer(0.2 * H, 200e9, 0.3), layer(H, 5e9, 0.35)],
                elastic(1e9, 0.45),
            )
            .unwrap(),
        ),
        (
            "layer on a stiffer half-space",
            Stack::new(vec![layer(H, 3e9, 0.1)], elastic(30e9, 0.2)).unwrap(),
        ),
    ]
}

/// The second method (the Ritz solution of the coupled problem, [`super::reference`])
/// against the solver (harmonic mean of the two punches) between the limits,
/// a/h₁ = 0.1 … 3: requirement 1e-5 relative, measured 6.5e-9 (the Ritz values' own
/// convergence at a/h₁ = 3 on the hard coating; n = 12 against 16 is printed).
#[test]
fn second_method_agrees() {
    let mut worst = 0.0f64;
    for (name, st) in hidden_stacks() {
        let k = Stiffness::new(&st);
        for ah in [0.1, 0.5, 1.0, 3.0] {
            let a = ah * H;
            let ours = k.at(a).unwrap().tangential;
            let r16 = ritz_tangential(&st, a, 16);
            let r12 = ritz_tangential(&st, a, 12);
            eprintln!(
                "{name} a/h {ah}: solver {ours:.10e}, Ritz16 {r16:.10e} ({:.1e}), Ritz12 ({:.1e})",
                rel(r16, ours),
                rel(r12, ours)
            );
            worst = worst.max(rel(r16, ours));
        }
    }
    eprintln!("second method: worst {worst:.1e}");
    assert!(worst < 1e-7, "{worst}");
}

/// The Ritz method alone on a half-space: Mindlin from the first function, and the
/// full span changes nothing (the half-space integrals decouple f₀ from the rest).
#[test]
fn ritz_half_space_is_mindlin() {
    let (e, nu) = (1e9, 0.3);
    let hs = Stack::half_space(e, nu).unwrap();
    let mindlin = 8.0 * shear_modulus(e, nu) * 1e-3 / (2.0 - nu);
    for n in [1, 6] {
        let r = ritz_tangential(&hs, 1e-3, n);
        assert!(rel(r, mindlin) < 1e-12, "n {n}: {r} vs {mindlin}");
    }
}

/// Hard cases: ν → 0.5, modulus contrasts 1e±4, a/h₁ from 1e-3 to 1e3: every value
/// finite and positive, K_t/K_n between the slab's (1−2ν)/(2(1−ν)) bound region and
/// the membrane's (printed), and a/h₁ → 0 at the top layer's Mindlin value.
#[test]
fn hard_cases_are_finite() {
    let stacks = [
        (
            "nu 0.5 on rigid",
            Stack::new(vec![layer(H, 1e9, 0.5)], Base::Rigid).unwrap(),
        ),
        (
            "nu 0.4999 on stiff",
            Stack::new(vec![layer(H, 1e9, 0.4999)], elastic(1e13, 0.3)).unwrap(),
        ),
        (
            "1e4 stiffer coating",
            Stack::new(vec![layer(H, 1e13, 0.3)], elastic(1e9, 0.3)).unwrap(),
        ),
        (
            "1e4 softer coating",
            Stack::new(vec![layer(H, 1e9, 0.3)], elastic(1e13, 0.3)).unwrap(),
        ),
    ];
    for (name, st) in stacks {
        let k = Stiffness::new(&st);
        let (e, nu) = st.top_material();
        let mu = shear_modulus(e, nu);
        for ah in [1e-3, 1.0, 100.0] {
            let a = ah * H;
            let d = k.at(a).unwrap();
            eprintln!(
                "{name} a/h {ah}: K_n {:.6e}, K_t {:.6e}, K_t/K_n {:.4}",
                d.normal,
                d.tangential,
                d.tangential / d.normal
            );
            assert!(d.normal.is_finite() && d.normal > 0.0, "{name} {ah}");
            assert!(
                d.tangential.is_finite() && d.tangential > 0.0,
                "{name} {ah}"
            );
            if ah == 1e-3 {
                let mindlin = 8.0 * mu * a / (2.0 - nu);
                assert!(rel(d.tangential, mindlin) < 1e-2, "{name}: {d:?}");
            }
        }
    }
}

/// Bad radii are typed errors.
#[test]
fn bad_radius_refused() {
    let k = Stiffness::new(&Stack::paper_two_layer(5.0).unwrap());
    for a in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(k.at(a), Err(StiffnessError::BadRadius(_))));
    }
}

/// Slow tier, the hard ends of a/h₁: at a/h₁ = 1e−3 the top material's Mindlin value
/// 8μ₁a/(2 − ν₁) (ν₁ = 0.5 and 0.4999, coatings 1e4 times stiffer and softer than their
/// base); at a/h₁ = 1e3 on a rigid base the slab's πa²μ/h (ν = 0.3 and ν = 0.5, where the
/// normal slab is infinitely stiff but the tangential one is not). Each asserts the limit
/// with a tolerance about 10× the measured distance (printed; docs/validation.md):
/// measured 4.41e−4, 4.41e−4, 5.38e−3 (the stiff skin's membrane reaches farther), 4.53e−4
/// at a/h₁ = 1e−3; excess 1.173e−3 and 1.437e−3 at a/h₁ = 1e3.
#[test]
#[ignore = "slow tier: CI runs `cargo test --workspace -- --ignored slow_`"]
fn slow_hard_ends_meet_their_limits() {
    let small = [
        (
            "nu 0.5 on rigid",
            Stack::new(vec![layer(H, 1e9, 0.5)], Base::Rigid).unwrap(),
            4e-3,
        ),
        (
            "nu 0.4999 on 1e4 stiffer",
            Stack::new(vec![layer(H, 1e9, 0.4999)], elastic(1e13, 0.3)).unwrap(),
            4.5e-3,
        ),
        (
            "1e4 stiffer coating",
            Stack::new(vec![layer(H, 1e13, 0.3)], elastic(1e9, 0.3)).unwrap(),
            5e-2,
        ),
        (
            "1e4 softer coating",
            Stack::new(vec![layer(H, 1e9, 0.3)], elastic(1e13, 0.3)).unwrap(),
            4.5e-3,
        ),
    ];
    let mut failed = Vec::new();
    for (name, st, tol) in small {
        let (e, nu) = st.top_material();
        let mu = shear_modulus(e, nu);
        let a = 1e-3 * H;
        let d = Stiffness::new(&st).at(a).unwrap();
        let err = rel(d.tangential, 8.0 * mu * a / (2.0 - nu));
        eprintln!("{name}, a/h1 = 1e-3: K_t against Mindlin {err:.2e}");
        if err >= tol {
            failed.push(format!("{name}: {err}"));
        }
    }
    for (nu, tol) in [(0.3, 1.2e-2), (0.5, 1.4e-2)] {
        let st = Stack::new(vec![layer(H, 1e9, nu)], Base::Rigid).unwrap();
        let mu = shear_modulus(1e9, nu);
        let a = 1e3 * H;
        let d = Stiffness::new(&st).at(a).unwrap();
        let err = d.tangential / (PI * a * a * mu / H) - 1.0;
        eprintln!(
            "nu {nu} on rigid, a/h1 = 1e3: K_t against the slab's pi a^2 mu/h, excess {err:.3e}"
        );
        if !(err > 0.0 && err < tol) {
            failed.push(format!("nu {nu}: {err}"));
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
}
