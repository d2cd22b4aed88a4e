//! A second, independent computation of S(ρ): the state-space ODE y' = A y of
//! physics.md §2.1 integrated by a numerical matrix exponential (scaling and
//! squaring of a Taylor series — no closed-form transfer matrix, no impedance
//! recursion), with the elastic base replaced by a thick slab of base material
//! (ρ·H_b = 30, so the neglected reflection is ~e^{−60}) bonded to a rigid bottom, and
//! the boundary-value problem solved globally: zero displacement at the bottom,
//! unit pressure at the surface.

use strata_runtime::stack::{plane_strain_modulus, shear_modulus};
use strata_runtime::{Base, Compliance, Layer, Stack};

type M4 = [[f64; 4]; 4];

fn mat_mul(a: &M4, b: &M4) -> M4 {
    let mut c = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..4 {
                c[i][j] += a[i][k] * b[k][j];
            }
        }
    }
    c
}

/// exp(M) by scaling and squaring with a 30-term Taylor series.
fn expm(m: &M4) -> M4 {
    let norm = m
        .iter()
        .map(|r| r.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let mut s = 0;
    while norm / 2f64.powi(s) > 0.25 {
        s += 1;
    }
    let f = 2f64.powi(-s);
    let ms: M4 = m.map(|r| r.map(|x| x * f));
    let mut result = [[0.0; 4]; 4];
    let mut term = [[0.0; 4]; 4];
    for i in 0..4 {
        result[i][i] = 1.0;
        term[i][i] = 1.0;
    }
    for k in 1..30 {
        term = mat_mul(&term, &ms).map(|r| r.map(|x| x / k as f64));
        for i in 0..4 {
            for j in 0..4 {
                result[i][j] += term[i][j];
            }
        }
    }
    for _ in 0..s {
        result = mat_mul(&result, &result);
    }
    result
}

/// The system matrix of physics.md §2.1 in the variables (ρU, ρW, T/μ₁, S/μ₁) and
/// the depth coordinate ρz.
fn system(mu: f64, nu: f64, mu1: f64) -> M4 {
    let q = 1.0 - nu;
    [
        [0.0, -1.0, mu1 / mu, 0.0],
        [nu / q, 0.0, 0.0, (mu1 / mu) * (1.0 - 2.0 * nu) / (2.0 * q)],
        [2.0 * mu / mu1 / q, 0.0, 0.0, -nu / q],
        [0.0, 0.0, 1.0, 0.0],
    ]
}

fn s_by_global_matrix(stack: &Stack, rho: f64) -> f64 {
    let (e1, nu1) = stack.top_material();
    let mu1 = shear_modulus(e1, nu1);
    let mut slabs: Vec<(f64, f64, f64)> = stack
        .layers()
        .iter()
        .map(|l| {
            (
                rho * l.thickness,
                shear_modulus(l.young, l.poisson),
                l.poisson,
            )
        })
        .collect();
    if let Base::Elastic { young, poisson } = stack.base() {
        slabs.push((30.0, shear_modulus(young, poisson), poisson));
    }
    // Propagator from the surface to the rigid bottom.
    let mut p: M4 = [[0.0; 4]; 4];
    for (i, row) in p.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for (t, mu, nu) in slabs {
        let a = system(mu, nu, mu1).map(|r| r.map(|x| x * t));
        p = mat_mul(&expm(&a), &p);
    }
    // Surface state (u, w, 0, −1): unit pressure; bottom displacement zero:
    // [p00 p01; p10 p11] (u, w) = (p03, p13).
    let (a, b, c, d) = (p[0][0], p[0][1], p[1][0], p[1][1]);
    let (r0, r1) = (p[0][3], p[1][3]);
    let det = a * d - b * c;
    let w = (a * r1 - c * r0) / det;
    // S = W·E*₁ρ/(2p) with ρW = w and p = μ₁: S = w·E*₁/(2μ₁) = w/(1−ν₁).
    let _ = plane_strain_modulus;
    w / (1.0 - nu1)
}

fn layer(h: f64, e: f64, nu: f64) -> Layer {
    Layer {
        thickness: h,
        young: e,
        poisson: nu,
    }
}

/// Three layers on an elastic base, two material sets: the impedance recursion and
/// the global matrix-exponential solution agree to 1e-10 relative (measured 2.4e-11,
/// the largest at ρh₁ = 10 where the unscaled propagator carries e^{ρH} ≈ e^{40}).
#[test]
fn three_layers_on_elastic_base_agree_with_global_matrix_exponential() {
    let stacks = [
        Stack::new(
            vec![
                layer(50e-6, 4e9, 0.15),
                layer(120e-6, 2e10, 0.3),
                layer(80e-6, 1e9, 0.45),
            ],
            Base::Elastic {
                young: 2.1e11,
                poisson: 0.3,
            },
        )
        .unwrap(),
        Stack::new(
            vec![
                layer(10e-6, 4e11, 0.22),
                layer(30e-6, 7e10, 0.33),
                layer(5e-6, 1e10, 0.0),
            ],
            Base::Elastic {
                young: 2e9,
                poisson: 0.4999,
            },
        )
        .unwrap(),
    ];
    let mut worst = 0.0f64;
    for stack in &stacks {
        let h1 = stack.top_thickness().unwrap();
        let c = Compliance::new(stack);
        for rh in [0.003, 0.01, 0.03, 0.1, 0.3, 1.0, 2.0, 5.0, 10.0] {
            let rho = rh / h1;
            let a = c.s(rho);
            let b = s_by_global_matrix(stack, rho);
            let rel = ((a - b) / b).abs();
            worst = worst.max(rel);
            assert!(
                rel < 1e-10,
                "rho h1 = {rh}: recursion {a} vs global {b} (rel {rel:e})"
            );
        }
    }
    eprintln!("max relative difference: {worst:e}");
}

/// The same independent method against the rigid-base closed-form-free case: two
/// layers bonded to a rigid base (the paper's stack).
#[test]
fn paper_stack_on_rigid_base_agrees_with_global_matrix_exponential() {
    let stack = Stack::new(
        vec![layer(100e-6, 4e9, 0.15), layer(900e-6, 2e10, 0.15)],
        Base::Rigid,
    )
    .unwrap();
    let c = Compliance::new(&stack);
    for rh in [0.01, 0.1, 1.0, 3.0] {
        let rho = rh / 100e-6;
        let (a, b) = (c.s(rho), s_by_global_matrix(&stack, rho));
        assert!(((a - b) / b).abs() < 1e-10, "rho h1 = {rh}: {a} vs {b}");
    }
}
