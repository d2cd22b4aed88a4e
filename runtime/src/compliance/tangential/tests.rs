use super::*;
use crate::compliance::{Compliance, global_solve};
use crate::stack::{Base, Layer, Stack};

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

fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| (lo.ln() + (hi / lo).ln() * i as f64 / (n - 1) as f64).exp())
        .collect()
}

fn all(c: &Compliances) -> [f64; 4] {
    [c.s_zz, c.s_ll, c.s_tt, c.s_zl]
}

/// Stacks for the comparisons: layers on elastic and rigid bases, contrasts up and
/// down, ν from 0 to 0.4999.
fn stacks() -> Vec<Stack> {
    vec![
        Stack::new(vec![layer(1e-5, 2e11, 0.3)], elastic(7e10, 0.33)).unwrap(),
        Stack::new(vec![layer(1e-5, 4e9, 0.4999)], Base::Rigid).unwrap(),
        Stack::new(vec![layer(2e-6, 4e11, 0.2)], elastic(4e9, 0.45)).unwrap(),
        Stack::new(
            vec![
                layer(1e-5, 4e9, 0.15),
                layer(3e-5, 2e11, 0.0),
                layer(5e-6, 7e10, 0.4999),
            ],
            elastic(2e10, 0.25),
        )
        .unwrap(),
        Stack::new(
            vec![layer(1e-5, 1e9, 0.35), layer(2e-5, 1e11, 0.28)],
            Base::Rigid,
        )
        .unwrap(),
    ]
}

/// The half-space: S_zz = S_LL = S_TT = 1 and S_zL = (1−2ν)/(2(1−ν)) at every ρ.
/// Measured: exact to the last bit but for S_zL (≤ 1 ulp); asserted 1e-15.
#[test]
fn half_space_closed_forms() {
    for nu in [0.0, 0.15, 0.3, 0.45, 0.4999, 0.5, -0.5] {
        let c = TangentialCompliance::new(&Stack::half_space(7e10, nu).unwrap());
        let beta = (1.0 - 2.0 * nu) / (2.0 * (1.0 - nu));
        for rho in log_grid(1e-3, 1e9, 25)
            .into_iter()
            .chain([0.0, f64::INFINITY])
        {
            let v = c.eval(rho);
            for (got, want) in all(&v).into_iter().zip([1.0, 1.0, 1.0, beta]) {
                assert!((got - want).abs() < 1e-15, "ν {nu} ρ {rho}: {v:?}");
            }
        }
    }
}

/// S_zz is today's S = 1 + k_z, bit for bit, on every test stack, pairs included.
#[test]
fn s_zz_is_the_normal_compliance_bit_for_bit() {
    let mut all_stacks: Vec<crate::Bodies> =
        stacks().into_iter().map(crate::Bodies::rigid).collect();
    all_stacks.push(stacks()[0].clone().against(stacks()[3].clone()));
    all_stacks.push(stacks()[4].clone().against(stacks()[1].clone()));
    for s in &all_stacks {
        let (n, t) = (Compliance::new(s), TangentialCompliance::new(s));
        let h = crate::Solid::top_thickness(s).unwrap();
        for x in log_grid(1e-300, 1e5, 200)
            .into_iter()
            .chain([0.0, f64::INFINITY])
        {
            assert_eq!(
                n.s(x / h).to_bits(),
                t.eval(x / h).s_zz.to_bits(),
                "ρh {x:e}"
            );
        }
    }
}

/// Against the global boundary-value solve (a second method, global_solve.rs) at
/// ρh₁ from 1e-2 to 5, five stacks (contrasts 1/50 to 50, ν 0 to 0.4999, elastic and
/// rigid bases). Measured: max difference 4e-13 relative to max(|S|, 1e-3); asserted
/// 4e-12.
#[test]
fn matches_the_global_solve() {
    let mut worst = 0.0f64;
    for s in stacks() {
        let c = TangentialCompliance::new(&s);
        let h = s.layers()[0].thickness;
        for x in log_grid(1e-2, 5.0, 31) {
            let a = all(&c.eval(x / h));
            let b = all(&global_solve::compliances(&s, x / h));
            for (p, q) in a.into_iter().zip(b) {
                let e = (p - q).abs() / q.abs().max(1e-3);
                worst = worst.max(e);
                assert!(e < 4e-12, "{s:?} ρh {x}: {a:?} vs {b:?}");
            }
        }
    }
}

/// The global solve's Papkovich solutions satisfy Navier's equations and Hooke's law
/// (central differences, ν = 0.3): the second method's basis is right.
#[test]
fn global_solve_basis_satisfies_navier() {
    let (nu, mu, rho) = (0.3, 1.0, 1.0);
    let lambda = 2.0 * mu * nu / (1.0 - 2.0 * nu);
    for kind in 0..4 {
        let f = |z: f64| global_solve::psv_basis(kind, z, 1.0, nu, 1.0);
        for z in [0.1, 0.5, 0.9] {
            let d = 1e-5;
            let (p, m, v) = (f(z + d), f(z - d), f(z));
            let der = |q: usize| (p[q] - m[q]) / (2.0 * d);
            // Scaled state (ρU, ρW, T/μ, S/μ) with ρ = μ = 1.
            let (u, w, t, s) = (v[0], v[1], v[2], v[3]);
            // Hooke: T = μ(U′ + ρW), S = (λ+2μ)W′ − λρU.
            assert!((t - mu * (der(0) + rho * w)).abs() < 1e-8, "kind {kind}");
            assert!((s - ((lambda + 2.0 * mu) * der(1) - lambda * rho * u)).abs() < 1e-8);
            // Equilibrium: T′ + ρσ_xx = 0, σ_xx = λ(−ρU + W′) − 2μρU; S′ = ρT.
            let sxx = lambda * (-rho * u + der(1)) - 2.0 * mu * rho * u;
            assert!((der(2) + rho * sxx).abs() < 1e-8, "kind {kind}");
            assert!((der(3) - rho * t).abs() < 1e-8, "kind {kind}");
        }
    }
}

/// Reciprocity: the P-SV block is symmetric, −Ĝ_US = −Ĝ_WT, in the recursion and in
/// the global solve, over ρh₁ from 1e-3 to 1e4 (1e-1 to 3 for the global solve).
/// Measured: |difference| ≤ 4.4e-15 (recursion) and ≤ 1e-14·max(|S_zL|, 1) (global
/// solve); asserted 4e-14 and 1e-13·max(|S_zL|, 1).
#[test]
fn coupling_is_symmetric() {
    let (mut w1, mut w2) = (0.0f64, 0.0f64);
    for s in stacks() {
        let c = TangentialCompliance::new(&s);
        let h = s.layers()[0].thickness;
        for x in log_grid(1e-3, 1e4, 40) {
            let (a, b) = (c.eval(x / h).s_zl, c.a.s_zl_transpose(x / h));
            w1 = w1.max((a - b).abs());
            assert!((a - b).abs() < 4e-14, "ρh {x}: {a} {b}");
        }
        for x in [0.1, 1.0, 3.0] {
            let (a, b) = (
                global_solve::compliances(&s, x / h).s_zl,
                global_solve::s_zl_transpose(&s, x / h),
            );
            w2 = w2.max((a - b).abs() / a.abs().max(1.0));
            assert!(
                (a - b).abs() < 1e-13 * a.abs().max(1.0),
                "global ρh {x}: {a} {b}"
            );
        }
    }
}

/// One layer on a rigid base, ρh → 0: the slab limits u = qh/μ, w = ph/M, and the
/// coupling (ρh)²(1−4ν)/(4(1−ν)²) (a thin-slab expansion of Hooke and equilibrium),
/// each with a relative excess O((ρh)²). Measured at ρh = 1e-4: ≤ 1.7e-5 (S_zz at
/// ν = 0.4999, where M/μ is large), ≤ 2.3e-8 otherwise, falling 100× from ρh = 1e-3;
/// asserted 2e-4 at ρh = 1e-4 and a fall of at least 90× per decade.
#[test]
fn thin_layer_on_rigid_base_is_a_slab() {
    for nu in [0.0, 0.15, 0.3, 0.45, 0.4999] {
        let (h, e) = (1e-5, 2e11);
        let s = Stack::new(vec![layer(h, e, nu)], Base::Rigid).unwrap();
        let c = TangentialCompliance::new(&s);
        let (mu, es) = (shear_modulus(e, nu), plane_strain_modulus(e, nu));
        let m = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let err = |t: f64| {
            let v = c.eval(t / h);
            let want = [
                t * es / (2.0 * m),
                t * es / (2.0 * mu),
                t,
                t * t * (1.0 - 4.0 * nu) / (4.0 * (1.0 - nu).powi(2)),
            ];
            let mut out = [0.0; 4];
            for (k, (g, w)) in all(&v).into_iter().zip(want).enumerate() {
                out[k] = ((g - w) / w).abs();
            }
            out
        };
        let (e3, e4) = (err(1e-3), err(1e-4));
        for k in 0..4 {
            assert!(e4[k] < 2e-4, "ν {nu} k {k}: {e4:?}");
            assert!(
                e4[k] < 1e-12 || e3[k] / e4[k] > 90.0,
                "ν {nu} k {k}: {e3:?} {e4:?}"
            );
        }
    }
}

/// Several layers on a rigid base: S_LL → (ρE*₁/2)Σh/μ, S_zz → (ρE*₁/2)Σh/M,
/// S_TT → ρμ₁Σh/μ. Measured ≤ 8e-12 relative at ρh₁ = 1e-6; asserted 1e-10.
#[test]
fn thin_stack_on_rigid_base_is_a_slab() {
    let ls = vec![
        layer(1e-6, 4e9, 0.4),
        layer(3e-6, 2e11, 0.3),
        layer(2e-6, 7e10, 0.15),
    ];
    let s = Stack::new(ls.clone(), Base::Rigid).unwrap();
    let c = TangentialCompliance::new(&s);
    let rho = 1e-6 / 1e-6;
    let v = c.eval(rho);
    let sum_mu: f64 = ls
        .iter()
        .map(|l| l.thickness / shear_modulus(l.young, l.poisson))
        .sum();
    let sum_m: f64 = ls
        .iter()
        .map(|l| {
            let m = l.young * (1.0 - l.poisson) / ((1.0 + l.poisson) * (1.0 - 2.0 * l.poisson));
            l.thickness / m
        })
        .sum();
    let es = plane_strain_modulus(4e9, 0.4);
    let mu1 = shear_modulus(4e9, 0.4);
    for (g, w) in [
        (v.s_ll, rho * es / 2.0 * sum_mu),
        (v.s_zz, rho * es / 2.0 * sum_m),
        (v.s_tt, rho * mu1 * sum_mu),
    ] {
        assert!(((g - w) / w).abs() < 1e-10, "{g} vs {w}");
    }
}

/// ρ → 0 on an elastic base: S_zz, S_LL → E*₁/E*_b, S_TT → μ₁/μ_b,
/// S_zL → (E*₁/E*_b)β_b; the deviation falls linearly in ρ.
#[test]
fn limits_at_small_rho_on_an_elastic_base() {
    let s = Stack::new(
        vec![layer(1e-5, 4e9, 0.15), layer(2e-5, 4e11, 0.3)],
        elastic(2e10, 0.45),
    )
    .unwrap();
    let c = TangentialCompliance::new(&s);
    let r = plane_strain_modulus(4e9, 0.15) / plane_strain_modulus(2e10, 0.45);
    let want = [
        r,
        r,
        shear_modulus(4e9, 0.15) / shear_modulus(2e10, 0.45),
        r * (1.0 - 0.9) / (2.0 * 0.55),
    ];
    let z = all(&c.at_zero());
    for k in 0..4 {
        assert!(((z[k] - want[k]) / want[k]).abs() < 1e-15, "{z:?}");
        let d = |t: f64| (all(&c.eval(t / 1e-5))[k] - want[k]) / want[k];
        assert!(d(1e-10).abs() < 1e-8, "k {k}: {}", d(1e-10));
        assert!((d(1e-7) / d(1e-9) - 100.0).abs() < 0.1, "k {k}");
    }
}

/// The SH chain against closed forms: one layer on a rigid base S_TT = tanh ρh; on a
/// half-space (μ₁ + μ_b t)/(μ_b + μ₁ t), t = tanh ρh. Measured ≤ 3.5e-16; asserted
/// 4e-15.
#[test]
fn sh_closed_forms() {
    let (e1, nu1, eb, nub) = (4e9, 0.3, 2e11, 0.25);
    let rigid =
        TangentialCompliance::new(&Stack::new(vec![layer(1e-5, e1, nu1)], Base::Rigid).unwrap());
    let soft = TangentialCompliance::new(
        &Stack::new(vec![layer(1e-5, e1, nu1)], elastic(eb, nub)).unwrap(),
    );
    let (m1, mb) = (shear_modulus(e1, nu1), shear_modulus(eb, nub));
    for x in log_grid(1e-6, 1e3, 40) {
        let t = x.tanh();
        let a = rigid.eval(x / 1e-5).s_tt;
        assert!(((a - t) / t).abs() < 4e-15, "{x}: {a} {t}");
        let want = (m1 + mb * t) / (mb + m1 * t);
        let b = soft.eval(x / 1e-5).s_tt;
        assert!(((b - want) / want).abs() < 4e-15, "{x}: {b} {want}");
    }
}

/// Identical layers on an identical base: exactly the half-space values at every ρh
/// (S_TT to the bit, the P-SV entries to round-off), 1 and 300 layers.
#[test]
fn identical_layers_are_a_half_space() {
    for n in [1usize, 300] {
        for nu in [0.15, 0.4999] {
            let s = Stack::new(vec![layer(1e-6, 4e9, nu); n], elastic(4e9, nu)).unwrap();
            let c = TangentialCompliance::new(&s);
            let beta = (1.0 - 2.0 * nu) / (2.0 * (1.0 - nu));
            for x in log_grid(1e-4, 1e4, 41) {
                let v = c.eval(x / 1e-6);
                assert_eq!(v.s_tt, 1.0);
                for (g, w) in all(&v).into_iter().zip([1.0, 1.0, 1.0, beta]) {
                    assert!((g - w).abs() < 1e-12, "n {n} ν {nu} ρh {x}: {v:?}");
                }
            }
        }
    }
}

/// Hard cases: ρh₁ from 1e-300 to 1e4, contrasts 1e±4, 300 layers, ν = 0.4999: every
/// value finite, S_zz, S_LL, S_TT ≥ 0, and the ρ → ∞ values reached at ρh₁ = 1e4.
#[test]
fn hard_cases_are_finite() {
    let mut ls = Vec::new();
    for i in 0..300 {
        let e = if i % 2 == 0 { 4e7 } else { 4e11 };
        let nu = if i % 3 == 0 { 0.4999 } else { 0.2 };
        ls.push(layer(1e-6 * (1.0 + (i % 7) as f64), e, nu));
    }
    let cases = vec![
        Stack::new(ls.clone(), Base::Rigid).unwrap(),
        Stack::new(ls, elastic(4e5, 0.4999)).unwrap(),
        Stack::new(vec![layer(1e-6, 4e11, 0.3)], elastic(4e7, 0.4999)).unwrap(),
        Stack::new(vec![layer(1e-6, 4e7, 0.4999)], elastic(4e11, 0.3)).unwrap(),
        Stack::new(vec![layer(1e-6, 4e7, 0.4999)], Base::Rigid).unwrap(),
        Stack::new(vec![layer(1e-4, 1e-3, 0.3)], elastic(1e15, 0.3)).unwrap(),
        Stack::new(vec![layer(1e-4, 1e15, 0.3)], elastic(1e-3, 0.3)).unwrap(),
    ];
    for s in cases {
        let c = TangentialCompliance::new(&s);
        let h = s.layers()[0].thickness;
        let (_, nu1) = s.top_material();
        for x in log_grid(1e-300, 1e4, 400) {
            let v = c.eval(x / h);
            for g in all(&v) {
                assert!(g.is_finite(), "ρh {x:e}: {v:?}");
            }
            assert!(
                v.s_zz >= 0.0 && v.s_ll >= 0.0 && v.s_tt >= 0.0,
                "ρh {x:e}: {v:?}"
            );
        }
        let v = c.eval(1e4 / h);
        let beta = (1.0 - 2.0 * nu1) / (2.0 * (1.0 - nu1));
        for (g, w) in all(&v).into_iter().zip([1.0, 1.0, 1.0, beta]) {
            assert!((g - w).abs() < 1e-12, "{v:?}");
        }
    }
}

/// Two bodies: identical bodies have S_zL = 0 exactly; swapping the bodies keeps
/// S_zz, S_LL, S_TT to the bit and negates S_zL; two half-spaces give S_LL = S_TT = 1
/// and S_zL = Dundurs' β, [μ_B(1−2ν_A) − μ_A(1−2ν_B)]/[2μ_B(1−ν_A) + 2μ_A(1−ν_B)]
/// (measured 2.8e-17, asserted 3e-16); the pair is the weighted sum of the
/// bodies (module docs).
#[test]
fn pairs() {
    let ss = stacks();
    for s in &ss {
        let pair = s.clone().against(s.clone());
        let c = TangentialCompliance::new(&pair);
        for x in log_grid(1e-3, 1e4, 30) {
            assert_eq!(c.eval(x / 1e-5).s_zl, 0.0);
        }
    }
    let (a, b) = (ss[3].clone(), ss[4].clone());
    let ab = TangentialCompliance::new(&a.clone().against(b.clone()));
    let ba = TangentialCompliance::new(&b.clone().against(a.clone()));
    let (ca, cb) = (TangentialCompliance::new(&a), TangentialCompliance::new(&b));
    let (ea, eb) = (ca.plane_strain_modulus(), cb.plane_strain_modulus());
    let (ma, mb) = (ca.shear_modulus(), cb.shear_modulus());
    let e = 1.0 / (1.0 / ea + 1.0 / eb);
    let m = 1.0 / (1.0 / ma + 1.0 / mb);
    assert!((ab.plane_strain_modulus() - e).abs() < 1e-15 * e);
    assert!((ab.shear_modulus() - m).abs() < 1e-15 * m);
    for x in log_grid(1e-3, 1e4, 30) {
        let rho = x / 1e-5;
        let (p, q) = (ab.eval(rho), ba.eval(rho));
        assert_eq!(p.s_zz.to_bits(), q.s_zz.to_bits());
        assert_eq!(p.s_ll.to_bits(), q.s_ll.to_bits());
        assert_eq!(p.s_tt.to_bits(), q.s_tt.to_bits());
        assert_eq!(p.s_zl, -q.s_zl);
        let (va, vb) = (ca.eval(rho), cb.eval(rho));
        let want = [
            e * (va.s_zz / ea + vb.s_zz / eb),
            e * (va.s_ll / ea + vb.s_ll / eb),
            m * (va.s_tt / ma + vb.s_tt / mb),
            e * (va.s_zl / ea - vb.s_zl / eb),
        ];
        for (g, w) in all(&p).into_iter().zip(want) {
            assert!(
                (g - w).abs() < 1e-14 * w.abs().max(1e-3),
                "ρh {x}: {p:?} {want:?}"
            );
        }
    }
    let (na, nb) = (0.3, 0.45);
    let two = Stack::half_space(2e11, na)
        .unwrap()
        .against(Stack::half_space(4e9, nb).unwrap());
    let c = TangentialCompliance::new(&two);
    let (mua, mub) = (shear_modulus(2e11, na), shear_modulus(4e9, nb));
    let beta = (mub * (1.0 - 2.0 * na) - mua * (1.0 - 2.0 * nb))
        / (2.0 * mub * (1.0 - na) + 2.0 * mua * (1.0 - nb));
    for rho in [1.0, 1e5, 1e9] {
        let v = c.eval(rho);
        assert!((v.s_ll - 1.0).abs() < 1e-15 && (v.s_tt - 1.0).abs() < 1e-15);
        assert!((v.s_zl - beta).abs() < 3e-16, "{} vs {beta}", v.s_zl);
    }
}
