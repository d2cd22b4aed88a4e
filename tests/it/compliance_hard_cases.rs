//! Hard cases for the layered compliance S(ρ): every case asserts accuracy against a
//! limit or a second computation, not only finiteness. Measured accuracies are
//! stated per test.

use strata_runtime::stack::plane_strain_modulus;
use strata_runtime::{Base, Compliance, Layer, Stack};

fn layer(h: f64, e: f64, nu: f64) -> Layer {
    Layer {
        thickness: h,
        young: e,
        poisson: nu,
    }
}

fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| (lo.ln() + (hi / lo).ln() * i as f64 / (n - 1) as f64).exp())
        .collect()
}

/// S over ρh₁ ∈ [1e-4, 1e4]: all finite, and the tail → 1.
fn sweep(stack: &Stack) -> Vec<(f64, f64)> {
    let h1 = stack.top_thickness().unwrap();
    let c = Compliance::new(stack);
    log_grid(1e-4, 1e4, 241)
        .into_iter()
        .map(|t| {
            let s = c.s(t / h1);
            assert!(s.is_finite(), "S not finite at rho h1 = {t}");
            (t, s)
        })
        .collect()
}

fn assert_monotone(v: &[(f64, f64)], increasing: bool, slack: f64) {
    for w in v.windows(2) {
        let d = w[1].1 - w[0].1;
        let ok = if increasing { d >= -slack } else { d <= slack };
        assert!(
            ok,
            "not monotone between rho h1 = {} and {}: {} -> {}",
            w[0].0, w[1].0, w[0].1, w[1].1
        );
    }
}

/// A graded layer: E rising linearly from E_top to E_bot over depth D, cut into n
/// layers (midpoint values), on an elastic base of E_bot.
fn graded(n: usize, e_top: f64, e_bot: f64, depth: f64, nu: f64) -> Stack {
    let h = depth / n as f64;
    let layers = (0..n)
        .map(|i| layer(h, e_top + (e_bot - e_top) * (i as f64 + 0.5) / n as f64, nu))
        .collect();
    Stack::new(
        layers,
        Base::Elastic {
            young: e_bot,
            poisson: nu,
        },
    )
    .unwrap()
}

/// 1000-layer graded stack (E 4 GPa → 200 GPa over 1 mm): finite everywhere, monotone
/// (stiffening with depth ⇒ S rises from E*₁/E*_b to 1), S(0) limit exact, and the
/// discretisation converges like 1/n² (the 500→1000 difference is 4× the 1000→2000
/// one).
#[test]
fn thousand_layer_graded_stack_converges() {
    let depth = 1e-3;
    let (s500, s1000, s2000) = (
        graded(500, 4e9, 2e11, depth, 0.3),
        graded(1000, 4e9, 2e11, depth, 0.3),
        graded(2000, 4e9, 2e11, depth, 0.3),
    );
    // Compare the physical compliance 2S/(E*₁ρ) (E*₁ differs between
    // discretisations: each top layer takes its midpoint modulus) on a common ρ grid
    // where the sublayers resolve the gradient (ρ·D/n ≤ 0.1 for n = 1000).
    let rhos: Vec<f64> = log_grid(1e-1, 1e5, 121);
    let scale = |s: &Stack| plane_strain_modulus(4e9, 0.3) / s.top_plane_strain_modulus();
    let (c500, c1000, c2000) = (
        Compliance::new(&s500),
        Compliance::new(&s1000),
        Compliance::new(&s2000),
    );
    let (mut d1, mut d2) = (0.0f64, 0.0f64);
    let mut prev = 0.0;
    for &r in &rhos {
        let (a, b, c) = (
            c500.s(r) * scale(&s500),
            c1000.s(r) * scale(&s1000),
            c2000.s(r) * scale(&s2000),
        );
        assert!(a.is_finite() && b.is_finite() && c.is_finite());
        assert!(b >= prev - 1e-14, "monotone at rho = {r}");
        prev = b;
        d1 = d1.max((a - b).abs());
        d2 = d2.max((b - c).abs());
    }
    eprintln!("d1 {d1:e} d2 {d2:e} ratio {}", d1 / d2);
    // Second order: the 500→1000 change is 4× the 1000→2000 one (measured 3.97), so the
    // 1000-layer stack is within d2·4/3 ≈ 1.2e-4 (relative to 2/(E*(0)ρ)) of the
    // continuous gradient up to ρD = 100, and 8e-7 up to ρD = 1.
    assert!(d2 < 1.5e-4, "1000 vs 2000 layers: {d2:e}");
    let ratio = d1 / d2;
    assert!(
        (3.8..4.2).contains(&ratio),
        "convergence ratio {ratio} (d1 {d1:e}, d2 {d2:e})"
    );
    // The whole ρh₁ range for the 1000-layer stack, up to ρh₁ = 1e4.
    let v = sweep(&s1000);
    assert_monotone(&v, true, 1e-14);
    let s0 =
        plane_strain_modulus(4e9 + 196e9 * 0.5 / 1000.0, 0.3) / plane_strain_modulus(2e11, 0.3);
    assert!((c1000.s_at_zero() - s0).abs() < 1e-15);
    assert!((v.last().unwrap().1 - 1.0).abs() < 1e-14);
}

/// ν = 0.4999, 0 and −0.5 (and the exactly incompressible 0.5): finite, monotone,
/// S → 1, and ν = 0.4999 is within 1e-3 of ν = 0.5 (continuity at the incompressible
/// limit; measured 2.6e-4).
#[test]
fn extreme_poisson_ratios() {
    let mut curves = Vec::new();
    for &nu in &[0.4999, 0.5, 0.0, -0.5] {
        let s = Stack::new(
            vec![layer(1e-4, 4e9, nu), layer(9e-4, 2e10, nu)],
            Base::Rigid,
        )
        .unwrap();
        let v = sweep(&s);
        assert_monotone(&v, true, 1e-14);
        assert!(
            v[0].1 > 0.0 && v[0].1 < 1e-2,
            "nu {nu}: S(1e-4) = {}",
            v[0].1
        );
        assert!((v.last().unwrap().1 - 1.0).abs() < 1e-14);
        curves.push(v);
    }
    let gap = curves[0]
        .iter()
        .zip(&curves[1])
        .map(|(a, b)| (a.1 - b.1).abs())
        .fold(0.0, f64::max);
    assert!(gap < 1e-3, "nu 0.4999 vs 0.5: {gap:e}");
}

/// Neighbouring moduli in ratio 1e-4 and 1e4 (soft under stiff and stiff under soft):
/// finite, monotone, S(0) = E*₁/E*_b reached at small ρ (linear approach, 1e-3
/// relative at ρh₁ = 1e-8), S → 1.
#[test]
fn extreme_modulus_ratios() {
    for &ratio in &[1e-4, 1e4] {
        let s = Stack::new(
            vec![layer(1e-4, 4e9, 0.3), layer(1e-4, 4e9 * ratio, 0.3)],
            Base::Elastic {
                young: 4e9 * ratio,
                poisson: 0.3,
            },
        )
        .unwrap();
        let v = sweep(&s);
        // Stiff base (ratio 1e4): S rises from 1e-4 to 1; soft base: falls from 1e4.
        assert_monotone(&v, ratio > 1.0, 1e-14 * v[0].1.max(1.0));
        let c = Compliance::new(&s);
        let s0 = 1.0 / ratio;
        assert!(((c.s(1e-8 / 1e-4) - s0) / s0).abs() < 1e-3, "ratio {ratio}");
        assert!((v.last().unwrap().1 - 1.0).abs() < 1e-12);
        // Three layers alternating 1e4 up and down: finite and positive everywhere.
        let alt = Stack::new(
            vec![
                layer(1e-4, 4e9, 0.3),
                layer(1e-4, 4e9 * ratio, 0.3),
                layer(1e-4, 4e9, 0.3),
            ],
            Base::Elastic {
                young: 4e9 * ratio,
                poisson: 0.3,
            },
        )
        .unwrap();
        for (t, sv) in sweep(&alt) {
            assert!(sv > 0.0, "S({t}) = {sv}");
        }
    }
}

/// A layer 1e-6 as thick as its neighbour changes S by at most ~its relative
/// thickness: inserting a 1e-10 m interlayer of a 10× stiffer material between two
/// 100 µm layers moves S by < 1e-5 (measured 2e-6) at every ρh₁ up to 1e4.
#[test]
fn very_thin_layer_between_thick_ones() {
    let without = Stack::new(
        vec![layer(1e-4, 4e9, 0.2), layer(1e-4, 8e9, 0.25)],
        Base::Rigid,
    )
    .unwrap();
    let with = Stack::new(
        vec![
            layer(1e-4, 4e9, 0.2),
            layer(1e-10, 4e10, 0.3),
            layer(1e-4, 8e9, 0.25),
        ],
        Base::Rigid,
    )
    .unwrap();
    let (a, b) = (sweep(&without), sweep(&with));
    let d = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x.1 - y.1).abs() / x.1)
        .fold(0.0, f64::max);
    assert!(d < 1e-5, "max relative change {d:e}");
    // And as the top layer: 1e-10 m of the same material as layer 2 on top of it.
    let thin_top = Stack::new(
        vec![layer(1e-10, 8e9, 0.25), layer(1e-4, 8e9, 0.25)],
        Base::Rigid,
    )
    .unwrap();
    let reference = Stack::new(vec![layer(1e-4 + 1e-10, 8e9, 0.25)], Base::Rigid).unwrap();
    let (ct, cr) = (Compliance::new(&thin_top), Compliance::new(&reference));
    for rho in log_grid(1.0, 1e14, 200) {
        let (x, y) = (ct.s(rho), cr.s(rho));
        assert!(((x - y) / y).abs() < 1e-12, "rho {rho}: {x} vs {y}");
    }
}

/// ρh₁ up to 1e4 on the paper's stack on a rigid base: finite, monotone from 0 to 1,
/// and equal to 1 to round-off beyond ρh₁ = 20 (the second layer is then invisible
/// and the top layer's own reflection is e^{−40}).
#[test]
fn large_rho_h_is_stable() {
    let s = Stack::new(
        vec![layer(1e-4, 4e9, 0.15), layer(9e-4, 2e10, 0.15)],
        Base::Rigid,
    )
    .unwrap();
    let v = sweep(&s);
    assert_monotone(&v, true, 1e-15);
    assert!(v[0].1 > 0.0 && v[0].1 < 1e-3);
    for (t, sv) in v {
        assert!(
            sv <= 1.0 + 1e-15,
            "S({t}) = {sv} > 1 on a stiffer substrate"
        );
        if t > 20.0 {
            assert!((sv - 1.0).abs() < 1e-14, "S({t}) = {sv}");
        }
    }
}
