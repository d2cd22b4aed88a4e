use super::kernel::erfc;
use super::*;
use crate::conduction::{ConductionCompliance, ConductionKind};
use crate::resources::MemoryLimit;
use crate::stack::{Base, BaseConduction, Conductivity, Layer, Stack};

/// Z = 4ζ(½)β(½): the zero-mean lattice sum of 1/|n| over the unit square lattice
/// (Epstein's zeta at s = 1).
const Z: f64 = -3.900_264_920_001_955;
const TAU: f64 = std::f64::consts::TAU;

fn one_layer(h: f64, k1: f64, kb: Option<f64>) -> ConductionCompliance {
    let st = Stack::new(
        vec![Layer {
            thickness: h,
            young: 1e9,
            poisson: 0.3,
        }],
        Base::Rigid,
    )
    .unwrap();
    let st = match kb {
        Some(kb) => st.with_conduction(
            vec![Conductivity::thermal(k1)],
            Conductivity::thermal(kb),
            BaseConduction::HalfSpace,
        ),
        None => st.with_conduction(
            vec![Conductivity::thermal(k1)],
            Conductivity::default(),
            BaseConduction::Isothermal,
        ),
    }
    .unwrap();
    ConductionCompliance::new(&st, ConductionKind::Thermal).unwrap()
}

#[test]
fn erfc_against_reference_values() {
    // erfc at 0.5, 1, 2.4, 2.6, 3, 5, 6 (mpmath, 17 digits)
    for (x, v) in [
        (0.5, 0.479_500_122_186_953_5),
        (1.0, 0.157_299_207_050_285_13),
        (2.4, 6.885_138_966_450_786e-4),
        (2.6, 2.360_344_165_293_492e-4),
        (3.0, 2.209_049_699_858_544e-5),
        (5.0, 1.537_459_794_428_034_8e-12),
        (6.0, 2.151_973_671_249_891_3e-17),
    ] {
        let e = (erfc(x) / v - 1.0).abs();
        assert!(e < 1e-13, "erfc({x}) = {} vs {v}: {e:e}", erfc(x));
        assert!((erfc(-x) - (2.0 - v)).abs() < 1e-15);
    }
}

/// A homogeneous body in a square cell: a spot's own images are Z/(2πkL) (the lattice
/// constant the BEM's one-spot test also meets), and G(d) − 1/(2πkd) tends to it as
/// d → 0 (second order).
#[test]
fn homogeneous_self_images_are_the_lattice_constant() {
    let (l, k) = (1e-3, 20.0);
    for (a, b, c) in [
        (Body::HalfSpace(k), Body::Perfect, 1.0 / k),
        (
            Body::HalfSpace(k),
            Body::HalfSpace(3.0 * k),
            1.0 / k + 1.0 / (3.0 * k),
        ),
    ] {
        let kern = Kernel::periodic(a, b, (l, l), &MemoryLimit::default()).unwrap();
        let exact = c * Z / (TAU * l);
        let got = kern.self_images();
        eprintln!(
            "self images {got:e} vs {exact:e}: {:.2e} (grid {:?})",
            got / exact - 1.0,
            kern.info().grid
        );
        // measured 4.4e-16, 5.6e-16
        assert!((got / exact - 1.0).abs() < 1e-14, "{got} {exact}");
        let mut prev = f64::INFINITY;
        for d in [1e-2 * l, 1e-3 * l] {
            let e = (kern.between(d, 0.3 * d) - c / (TAU * d * 1.09f64.sqrt()) - got).abs();
            assert!(e < 0.1 * prev, "{d}: {e} after {prev}");
            prev = e;
        }
        // periodic, symmetric
        let g = kern.between(0.3 * l, 0.1 * l);
        for (x, y) in [(-0.3, -0.1), (0.7, 0.1), (0.3 - 2.0, 0.1 + 5.0)] {
            assert!((kern.between(x * l, y * l) - g).abs() < 1e-12 * g.abs());
        }
    }
}

/// Layered bodies: the kernel minus that of homogeneous bodies of the top materials is
/// R_layers(d) = (1/A₀) Σ_{k≠0} Σ_X k_th,X(|k|)/(k₁,X|k|) e^{ik·d}, which converges
/// exponentially: summed directly and compared at offsets across a rectangular cell;
/// the self term's layered part at r = 0 against the image series −ln(1 − Γ)/(2πk₁h).
#[test]
fn layered_kernel_against_direct_fourier_sums() {
    let (lx, ly) = (1e-3, 0.6e-3);
    let h = 1e-4;
    let plating = one_layer(h, 200.0, Some(20.0));
    let polymer = one_layer(h, 0.5, None);
    let insulating = one_layer(0.5 * h, 0.5, Some(40.0));
    for (a, b) in [
        (&plating, None),
        (&polymer, None),
        (&insulating, Some(&plating)),
    ] {
        let (body_b, hom_b) = match b {
            Some(c) => (Body::Layered(c), Body::HalfSpace(c.top_conductivity())),
            None => (Body::Perfect, Body::Perfect),
        };
        let lay =
            Kernel::periodic(Body::Layered(a), body_b, (lx, ly), &MemoryLimit::default()).unwrap();
        let hom = Kernel::periodic(
            Body::HalfSpace(a.top_conductivity()),
            hom_b,
            (lx, ly),
            &MemoryLimit::default(),
        )
        .unwrap();
        let scale = 1.0 / (TAU * a.top_conductivity() * lx);
        let mut worst: f64 = 0.0;
        for (x, y) in [
            (0.013, 0.0),
            (0.1, 0.05),
            (0.37, -0.21),
            (0.5, 0.5),
            (-0.05, 0.44),
        ] {
            let d = (x * lx, y * ly);
            let diff = lay.between(d.0, d.1) - hom.between(d.0, d.1);
            let direct =
                Kernel::direct_sum([Body::Layered(a), body_b], (lx, ly), d, 60.0 / (0.5 * h))
                    - Kernel::direct_sum(
                        [Body::HalfSpace(a.top_conductivity()), hom_b],
                        (lx, ly),
                        d,
                        60.0 / (0.5 * h),
                    );
            worst = worst.max((diff - direct).abs() / scale);
        }
        eprintln!("layered kernel vs direct sums: worst {worst:.2e} of 1/(2πk₁L)");
        // measured 1.0e-8, 1.1e-8, 1.1e-8 (the table's interpolation)
        assert!(worst < 1e-7, "{worst}");
    }
    // the self term's layered part at r = 0: −ln(1 − Γ)/(2πk₁h), Γ = (k₁ − k_b)/(k₁ + k_b)
    for (c, k1, kb) in [(&plating, 200.0, 20.0), (&polymer, 0.5, f64::INFINITY)] {
        let gamma = if kb.is_finite() {
            (k1 - kb) / (k1 + kb)
        } else {
            -1.0
        };
        let w0 = -(1.0 - gamma).ln() / (TAU * k1 * h);
        let lay = Kernel::periodic(
            Body::Layered(c),
            Body::Perfect,
            (lx, ly),
            &MemoryLimit::default(),
        )
        .unwrap();
        let hom = Kernel::periodic(
            Body::HalfSpace(k1),
            Body::Perfect,
            (lx, ly),
            &MemoryLimit::default(),
        )
        .unwrap();
        let d = Kernel::direct_sum(
            [Body::Layered(c), Body::Perfect],
            (lx, ly),
            (0.0, 0.0),
            120.0 / h,
        ) - Kernel::direct_sum(
            [Body::HalfSpace(k1), Body::Perfect],
            (lx, ly),
            (0.0, 0.0),
            120.0 / h,
        );
        let expected = d - w0;
        let got = lay.self_images() - hom.self_images();
        let e = (got - expected).abs() * TAU * k1 * lx;
        eprintln!("layered self term: {got:e} vs {expected:e}: {e:.2e} of 1/(2πk₁L)");
        // measured 3.5e-12, 1.8e-12
        assert!(e < 3e-11, "{e}");
    }
}

/// Two spots: the 2×2 network against Greenwood's two discs at leading order,
/// 2/(1/G + 1/(2πkd)) on an isolated homogeneous half-space; far apart the spots add.
#[test]
fn two_spots_isolated() {
    let k = 15.0;
    let a = 1e-5;
    let g = 4.0 * k * a;
    let kern = Kernel::isolated(Body::HalfSpace(k), Body::Perfect, (1.0, 1.0)).unwrap();
    for d in [4.0 * a, 10.0 * a, 1e3 * a, 1e9 * a] {
        let spots = [
            Spot {
                x: 0.0,
                y: 0.0,
                conductance: g,
            },
            Spot {
                x: 0.6 * d,
                y: 0.8 * d,
                conductance: g,
            },
        ];
        let net = interface_conductance(&kern, &spots, 1.0, &MemoryLimit::default()).unwrap();
        let exact = 2.0 / (1.0 / g + 1.0 / (TAU * k * d));
        assert!((net.conductance / exact - 1.0).abs() < 1e-14, "{d}");
        assert!((net.heat[0] - net.heat[1]).abs() < 1e-15 * net.heat[0]);
        if d > 1e8 * a {
            assert!((net.conductance / (2.0 * g) - 1.0).abs() < 1e-9);
        }
    }
    // unequal spots: Q = M⁻¹·1 of the 2×2 system in closed form
    let (g1, g2, i12) = (g, 3.0 * g, 1.0 / (TAU * k * 7.0 * a));
    let spots = [
        Spot {
            x: 0.0,
            y: 0.0,
            conductance: g1,
        },
        Spot {
            x: 7.0 * a,
            y: 0.0,
            conductance: g2,
        },
    ];
    let net = interface_conductance(&kern, &spots, 2.0, &MemoryLimit::default()).unwrap();
    let det = 1.0 / (g1 * g2) - i12 * i12;
    let total = (1.0 / g2 - i12 + 1.0 / g1 - i12) / det;
    assert!((net.conductance * 2.0 / total - 1.0).abs() < 1e-14);
    assert_eq!(
        Kernel::isolated(Body::Perfect, Body::Perfect, (1.0, 1.0)).err(),
        Some(ConductanceError::BothPerfect)
    );
    assert!(interface_conductance(&kern, &spots, 0.0, &MemoryLimit::default()).is_err());
    assert!(
        interface_conductance(&kern, &[], 1.0, &MemoryLimit::default())
            .unwrap()
            .conductance
            == 0.0
    );
}

/// A layer too thin for the table cap is refused with the reason.
#[test]
fn too_thin_a_layer_is_refused() {
    let c = one_layer(1e-7, 1.0, Some(50.0));
    let e = Kernel::periodic(
        Body::Layered(&c),
        Body::Perfect,
        (1e-3, 1e-3),
        &MemoryLimit::default(),
    )
    .err()
    .unwrap();
    assert!(matches!(e, ConductanceError::Grid { .. }), "{e}");
    assert!(e.to_string().contains("too thin"));
}

/// The interactions filled once and each step's network on a subset of them: the same h_c
/// and heats as `interface_conductance` of the same spots, bit for bit (the same matrix
/// entries, the same LU); a bad subset is refused.
#[test]
fn interactions_reused_on_subsets_equal_the_direct_network() {
    let l = 1e-3;
    let a = one_layer(1e-4, 0.5, None);
    let kern = Kernel::periodic(
        Body::Layered(&a),
        Body::HalfSpace(45.0),
        (l, l),
        &MemoryLimit::default(),
    )
    .unwrap();
    // 16 points on a jittered grid
    let points: Vec<(f64, f64)> = (0..16)
        .map(|i| {
            let (u, v) = ((i % 4) as f64, (i / 4) as f64);
            (
                l * (u + 0.5 + 0.3 * (1.7 * i as f64).sin()) / 4.0,
                l * (v + 0.5 + 0.3 * (2.3 * i as f64).cos()) / 4.0,
            )
        })
        .collect();
    let all = Interactions::new(&kern, &points, &MemoryLimit::default()).unwrap();
    for subset in [vec![0, 3, 4, 9, 15], (0..16).collect(), vec![7]] {
        let g = |i: usize| 1e-4 * (1.0 + 0.1 * i as f64);
        let spots: Vec<Spot> = subset
            .iter()
            .map(|&i| Spot {
                x: points[i].0,
                y: points[i].1,
                conductance: g(i),
            })
            .collect();
        let direct = interface_conductance(&kern, &spots, l * l, &MemoryLimit::default()).unwrap();
        let pairs: Vec<(usize, f64)> = subset.iter().map(|&i| (i, g(i))).collect();
        let reused = all.network(&pairs, l * l).unwrap();
        assert_eq!(direct, reused, "{subset:?}");
    }
    assert!(all.network(&[(3, 1e-4), (2, 1e-4)], l * l).is_err());
    assert!(all.network(&[(16, 1e-4)], l * l).is_err());
    assert!(all.network(&[(1, 0.0)], l * l).is_err());
    assert_eq!(all.network(&[], l * l).unwrap().conductance, 0.0);
}

/// The isolated kernel of a layered body against the method of images: one layer
/// (thickness h, conductivity k₁) on a half-space base (k_b) or an isothermal sink has
/// S_th = (1 + γe^{−2ρh})/(1 − γe^{−2ρh}), γ = (k₁ − k_b)/(k₁ + k_b) (−1 on a sink), so
/// a unit point source raises the surface temperature at r by
/// w(r) = [1/r + 2 Σ_{n≥1} γⁿ/√(r² + (2nh)²)]/(2πk₁) (the sums to 4·10⁵ terms, averaged
/// over the last two partial sums for γ = −1): an independent closed form of the
/// tabulated Hankel transform. Two spots on a coated body then follow Greenwood's
/// 2 × 2 network with that interaction.
#[test]
fn isolated_layered_kernel_is_the_image_series() {
    let h = 2e-5;
    let mut worst = 0.0f64;
    for (k1, kb) in [(2.0, Some(50.0)), (50.0, Some(2.0)), (3.0, None)] {
        let c = one_layer(h, k1, kb);
        let gamma = kb.map_or(-1.0, |kb| (k1 - kb) / (k1 + kb));
        let kern = Kernel::isolated(
            Body::Layered(&c),
            Body::HalfSpace(40.0),
            (100.0 * h, 60.0 * h),
        )
        .unwrap();
        for r in [0.05 * h, 0.3 * h, h, 3.7 * h, 20.0 * h, 100.0 * h] {
            let terms = 400_000usize;
            let (mut sum, mut prev) = (0.0, 0.0);
            let mut g = 1.0;
            for n in 1..=terms {
                g *= gamma;
                prev = sum;
                sum += g / r.hypot(2.0 * n as f64 * h);
            }
            let series = if gamma < 0.0 { 0.5 * (sum + prev) } else { sum };
            let exact = (1.0 / r + 2.0 * series) / (TAU * k1) + 1.0 / (TAU * 40.0 * r);
            let got = kern.between(0.6 * r, 0.8 * r);
            let e = (got / exact - 1.0).abs();
            worst = worst.max(e);
            eprintln!(
                "isolated layered k1 {k1} kb {kb:?} r/h {}: {got:e} vs {exact:e}: {e:.2e}",
                r / h
            );
        }
    }
    // measured 1.8e-6 (k₁/k_b = 25 near r = h: the cubic Hermite table stretched over
    // the sample's diagonal)
    assert!(worst < 2e-5, "{worst}");
    assert_eq!(
        Kernel::isolated(Body::Perfect, Body::Perfect, (1.0, 1.0)).err(),
        Some(ConductanceError::BothPerfect)
    );
}
