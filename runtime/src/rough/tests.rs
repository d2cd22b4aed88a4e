//! Unit tests of the rough-contact models (N and I): closed forms, energy minima,
//! far-field error bounds and load paths on the shipped table.

use super::*;
use crate::law::{AsperityLaw, Homogeneous};
use crate::summits::Summit;
use crate::surface::Surface;

fn reference_surface() -> Option<Surface> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/reference/surface_km10.npy");
    Some(Surface::read_npy(&p, 1e-3, true).expect("reference surface readable"))
}

/// Homogeneous N model = Greenwood–Williamson sum of Hertz contacts, written out
/// directly: P = Σ (4/3)E*√R_k δ_k^{3/2}, A = π Σ R_k δ_k, dP/dδ = Σ 2E*√(R_k δ_k).
#[test]
fn n_model_is_greenwood_williamson() {
    let s = reference_surface().unwrap();
    let law = Homogeneous { e_star: 4.092e9 };
    let rc = RoughContact::from_surface(&law, &s).unwrap();
    let zm = rc.summits().iter().map(|s| s.z).fold(f64::MIN, f64::max);
    for delta in [1e-7, 2e-6, 7.3e-6, 1.1e-5] {
        let st = rc.solve_independent(delta).unwrap();
        let (mut p, mut a, mut k, mut c) = (0.0, 0.0, 0.0, 0);
        for sm in rc.summits() {
            let d = delta - (zm - sm.z);
            if d > 0.0 {
                p += 4.0 / 3.0 * 4.092e9 * sm.radius.sqrt() * d.powf(1.5);
                a += std::f64::consts::PI * sm.radius * d;
                k += 2.0 * 4.092e9 * (sm.radius * d).sqrt();
                c += 1;
            }
        }
        assert_eq!(st.contacts, c);
        assert!((st.load - p).abs() <= 1e-13 * p, "{} {p}", st.load);
        assert!((st.area_fraction * 1e-6 - a).abs() <= 1e-13 * a);
        assert!((st.stiffness - k).abs() <= 1e-13 * k);
        assert!((st.mean_pressure - p / 1e-6).abs() <= 1e-13 * p / 1e-6);
    }
}

fn summit(x: f64, y: f64, z: f64, r: f64) -> Summit {
    Summit {
        index: (0, 0),
        x,
        y,
        z,
        radius: r,
    }
}

/// U_E of eq. (P22) written out directly with `law::displacement` (independent of
/// the solver's G/∂G code), for an isolated set of summits.
fn u_e(law: &dyn AsperityLaw, sums: &[Summit], a: &[f64], dk: &[f64]) -> f64 {
    let c = 2.0 * law.e_star() / 3.0;
    let mut u = 0.0;
    for j in 0..sums.len() {
        if a[j] <= 0.0 {
            continue;
        }
        let mut inter = 0.0;
        for l in 0..sums.len() {
            if l != j && a[l] > 0.0 {
                let r = (sums[j].x - sums[l].x).hypot(sums[j].y - sums[l].y);
                inter += crate::law::displacement(law, a[l], sums[l].radius, r);
            }
        }
        let rj = sums[j].radius;
        let zj = law.zeta(a[j]);
        u += c * law.chi(a[j]) * a[j].powi(3) / rj
            * (inter + a[j] * a[j] / rj * (zj + 0.2) - 2.0 * dk[j]);
    }
    u
}

/// Two Hertz asperities at several distances: the solution is a stationary point
/// of U_E (central differences of the directly written U_E vanish to 1e-6 of the
/// gradient scale) and a minimum (U_E rises under ±1e-3 perturbations); far apart
/// the I model equals the N model; the stiffness equals dP/dδ by central differences.
#[test]
fn two_asperities_energy_minimum() {
    let law = Homogeneous { e_star: 1e9 };
    for dist in [3e-5, 5e-5, 1e-3, 1.0] {
        let sums = vec![
            summit(0.0, 0.0, 1e-6, 1e-4),
            summit(dist, 0.0, 0.8e-6, 2e-4),
        ];
        let rc = RoughContact::new(&law, sums.clone(), 0.0, -1e-5, (10.0, 10.0)).unwrap();
        let delta = 0.9e-6;
        let st = rc.solve_interacting(delta, Images::Isolated, &[]).unwrap();
        let dk = [delta, delta - 0.2e-6];
        let a = st.radii.clone();
        assert!(a[0] > 0.0 && a[1] > 0.0);
        let u0 = u_e(&law, &sums, &a, &dk);
        // gradient scale: c·(3a²/R)·δ
        let scale = 2.0 / 3.0 * 1e9 * 3.0 * a[0] * a[0] / 1e-4 * delta;
        for k in 0..2 {
            let h = 1e-6 * a[k];
            let mut ap = a.clone();
            let mut am = a.clone();
            ap[k] += h;
            am[k] -= h;
            let g = (u_e(&law, &sums, &ap, &dk) - u_e(&law, &sums, &am, &dk)) / (2.0 * h);
            assert!(
                g.abs() < 1e-6 * scale,
                "{dist} {k}: grad {g:e} scale {scale:e}"
            );
            for f in [1.001, 0.999] {
                let mut t = a.clone();
                t[k] *= f;
                assert!(u_e(&law, &sums, &t, &dk) > u0);
            }
        }
        assert!(st.kkt_residual.unwrap() < 1e-8);
        let n = rc.solve_independent(delta).unwrap();
        assert!(st.load < n.load);
        // Far apart the coupling is the point-force displacement ~ (4/3)a³/(πRr),
        // here ≈ 4e-12 m against δ ≈ 1e-6 m: I → N to that order.
        if dist >= 1.0 {
            assert!((st.load - n.load).abs() < 1e-5 * n.load);
        }
        let h = 1e-4 * delta;
        let sp = rc
            .solve_interacting(delta + h, Images::Isolated, &a)
            .unwrap();
        let sm = rc
            .solve_interacting(delta - h, Images::Isolated, &a)
            .unwrap();
        let fd = (sp.load - sm.load) / (2.0 * h);
        assert!(
            (st.stiffness - fd).abs() < 1e-5 * fd,
            "{} {fd}",
            st.stiffness
        );
    }
}

/// A shadowed asperity: its interference is smaller than the neighbour's
/// displacement, so the KKT conditions keep it out of contact.
#[test]
fn shadowed_asperity_stays_out() {
    let law = Homogeneous { e_star: 1e9 };
    let sums = vec![
        summit(0.0, 0.0, 1e-6, 1e-3),
        summit(3e-5, 0.0, 0.2e-6, 1e-4),
    ];
    let rc = RoughContact::new(&law, sums, 0.0, -1e-5, (1.0, 1.0)).unwrap();
    let st = rc.solve_interacting(1.0e-6, Images::Isolated, &[]).unwrap();
    let n = rc.solve_independent(1.0e-6).unwrap();
    assert_eq!(n.contacts, 2);
    assert_eq!(st.contacts, 1);
    assert_eq!(st.radii[1], 0.0);
    assert!(st.kkt_residual.unwrap() < 1e-8);
}

/// Whole reference surface, homogeneous: I model converges with KKT < 1e-8 on
/// a load path, is below the N model in load, and the raw periodic image sums lower it
/// further (their uniform part, growing with the block, pushes the whole surface down);
/// with that mode removed (the default, as the periodic BEM) the surface between contacts
/// rises and the periodic load is above the raw one.
#[test]
fn reference_surface_interacting_homogeneous() {
    let s = reference_surface().unwrap();
    let law = Homogeneous { e_star: 4.092e9 };
    let rc = RoughContact::from_surface(&law, &s).unwrap();
    let raw = RoughContact::from_surface(&law, &s)
        .unwrap()
        .with_params(Params {
            zero_mean_images: false,
            ..Params::default()
        });
    let deltas: Vec<f64> = (1..=10).map(|i| i as f64 * 1.1e-6).collect();
    let iso = rc
        .curve(Model::Interacting(Images::Isolated), &deltas)
        .unwrap();
    let per = raw
        .curve(Model::Interacting(Images::Periodic(2)), &deltas)
        .unwrap();
    let zm = rc
        .curve(Model::Interacting(Images::Periodic(2)), &deltas)
        .unwrap();
    let nm = rc.curve(Model::Independent, &deltas).unwrap();
    for (((i, p), z), n) in iso.iter().zip(&per).zip(&zm).zip(&nm) {
        assert!(i.kkt_residual.unwrap() < 1e-8);
        assert!(p.kkt_residual.unwrap() < 1e-8);
        assert!(z.kkt_residual.unwrap() < 1e-8);
        // (equal when a single contact has no neighbour: Newton tolerance 1e-11)
        assert!(i.load <= n.load * (1.0 + 1e-9));
        assert!(p.load <= i.load * (1.0 + 1e-9));
        assert!(z.load > p.load);
    }
}

#[test]
fn pressure_control_and_range_errors() {
    let s = reference_surface().unwrap();
    let law = Homogeneous { e_star: 4.092e9 };
    let rc = RoughContact::from_surface(&law, &s).unwrap();
    let st = rc.solve_independent(5e-6).unwrap();
    let back = rc
        .solve_pressure(Model::Independent, st.mean_pressure, &[])
        .unwrap();
    assert!((back.delta - 5e-6).abs() < 1e-9 * 5e-6);
    assert!(rc.solve_independent(-1e-9).is_err());
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = rc.solve_pressure(Model::Independent, bad, &[]).unwrap_err();
        assert!(e.to_string().contains("mean_pressures"), "{e}");
    }
}

/// Approaches beyond the peak-to-valley height z_M − z_min are solved, not
/// refused, by both models, and flagged: N model at 1.01×, 3× and 10× that height; the
/// I model (5×5 periodic, isolated) at 1.5× converges (KKT < 1e-8) with its load below
/// the N model's and above its own at z_M − z_min. Pressure control reaches a mean
/// pressure above the one at z_M − z_min (1.5× it) to its tolerance, beyond the valley.
#[test]
fn approaches_beyond_the_deepest_valley() {
    let s = reference_surface().unwrap();
    let law = Homogeneous { e_star: 4.092e9 };
    let rc = RoughContact::from_surface(&law, &s).unwrap();
    let top = rc.max_delta();
    for f in [1.01, 3.0, 10.0] {
        let st = rc.solve_independent(f * top).unwrap();
        assert_eq!(st.contacts, rc.summits().len());
        assert!(st.validity.beyond_deepest_valley && st.validity.below_mean_plane);
        assert!(!st.validity.is_valid() && !st.validity.describe().is_empty());
    }
    let ok = rc.solve_independent(0.5 * rc.top_to_mean()).unwrap();
    assert!(ok.validity.is_valid(), "{:?}", ok.validity);
    // the raw periodic sums and the isolated sample; with the mean displacement removed
    // (the default) the periodic contacts cover the cell there: refused, with the BEM
    // advice, after at most a few hundred Newton steps
    let e = rc
        .solve_interacting(1.5 * top, Images::Periodic(2), &[])
        .unwrap_err();
    assert!(
        matches!(e, RoughError::Newton(NewtonError::CoversCell { .. }))
            && e.to_string().contains("bem"),
        "{e}"
    );
    let rc = rc.with_params(Params {
        zero_mean_images: false,
        ..Params::default()
    });
    for im in [Images::Periodic(2), Images::Isolated] {
        let at = rc.solve_interacting(top, im, &[]).unwrap();
        let st = rc.solve_interacting(1.5 * top, im, &[]).unwrap();
        let n = rc.solve_independent(1.5 * top).unwrap();
        assert!(
            st.kkt_residual.unwrap() < 1e-8,
            "{im:?}: {:?}",
            st.kkt_residual
        );
        assert!(st.load < n.load && st.load > at.load, "{im:?}");
        assert!(st.validity.beyond_deepest_valley);
        let p = 1.5 * at.mean_pressure;
        let back = rc.solve_pressure(Model::Interacting(im), p, &[]).unwrap();
        assert!((back.mean_pressure / p - 1.0).abs() <= 1e-9, "{im:?}");
        assert!(back.delta > top, "{im:?}: δ = {:e}", back.delta);
    }
}

/// A step that cannot converge within its budget fails with an error that
/// names the budget and the parameter to raise, instead of running on.
#[test]
fn newton_budget_turns_a_stall_into_an_error() {
    let s = reference_surface().unwrap();
    let law = Homogeneous { e_star: 4.092e9 };
    let tight = Params {
        max_step_newton_steps: 0,
        ..Params::default()
    };
    let rc = RoughContact::from_surface(&law, &s)
        .unwrap()
        .with_params(tight);
    let e = rc
        .solve_interacting(0.8 * rc.top_to_mean(), Images::Periodic(2), &[])
        .unwrap_err();
    let m = e.to_string();
    assert!(
        matches!(e, RoughError::Newton(NewtonError::Budget { .. })),
        "{m}"
    );
    assert!(
        m.contains("max_step_newton_steps") && m.contains("stalled"),
        "{m}"
    );
    let slow = Params {
        max_step_evaluations: 0,
        ..Params::default()
    };
    let rc = RoughContact::from_surface(&law, &s)
        .unwrap()
        .with_params(slow);
    let m = rc
        .solve_interacting(0.8 * rc.top_to_mean(), Images::Periodic(2), &[])
        .unwrap_err()
        .to_string();
    assert!(m.contains("[solver] max_step_evaluations"), "{m}");
}

/// A budget that runs out while only the inner Newton target (here 1e-30,
/// never met) is missed, with the KKT acceptance (1e-8) already met, ends the step as
/// converged instead of "stalled".
#[test]
fn newton_budget_below_the_kkt_acceptance_is_converged() {
    let s = reference_surface().unwrap();
    let law = Homogeneous { e_star: 4.092e9 };
    let rc = RoughContact::from_surface(&law, &s).unwrap();
    let delta = 0.5 * rc.top_to_mean();
    let free = rc
        .solve_interacting(delta, Images::Periodic(2), &[])
        .unwrap();
    let n = free.diagnostics.newton_steps;
    let strict = Params {
        newton_tolerance: 1e-30,
        round_off_floor: 1e-30,
        max_step_newton_steps: n,
        ..Params::default()
    };
    let rc = RoughContact::from_surface(&law, &s)
        .unwrap()
        .with_params(strict);
    let st = rc
        .solve_interacting(delta, Images::Periodic(2), &[])
        .unwrap();
    assert!(st.kkt_residual.unwrap() < 1e-8, "{:?}", st.kkt_residual);
    assert!((st.load / free.load - 1.0).abs() < 1e-6);
}

/// Homogeneous solid: the far-field model (default tolerance) changes loads and areas
/// by less than 1e-6 relative and stiffnesses by less than 1e-5 against exact pair
/// sums (tolerance 0), periodic 5×5 and isolated.
#[test]
fn far_field_matches_exact_sums() {
    let s = reference_surface().unwrap();
    let law = Homogeneous { e_star: 4.092e9 };
    let fast = RoughContact::from_surface(&law, &s).unwrap();
    let exact = RoughContact::from_surface(&law, &s)
        .unwrap()
        .with_far_field_tolerance(0.0);
    let deltas: Vec<f64> = (1..=10).map(|i| i as f64 * 1.1e-6).collect();
    for im in [Images::Periodic(2), Images::Isolated] {
        let f = fast.curve(Model::Interacting(im), &deltas).unwrap();
        let e = exact.curve(Model::Interacting(im), &deltas).unwrap();
        for (x, y) in f.iter().zip(&e) {
            if y.load > 0.0 {
                assert!(
                    (x.load - y.load).abs() <= 1e-6 * y.load,
                    "{} {}",
                    x.load,
                    y.load
                );
                assert!((x.area_fraction - y.area_fraction).abs() <= 1e-6 * y.area_fraction);
                assert!((x.stiffness - y.stiffness).abs() <= 1e-5 * y.stiffness);
            }
        }
    }
}

/// The shipped family table (tables/paper-two-layer.strata) on the paper's stack
/// with E2/E1 = `ratio`.
pub(crate) fn paper_law(ratio: f64) -> crate::table::TableLaw {
    let p =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables/paper-two-layer.strata");
    let table = crate::table::Table::load(&p).expect("shipped table readable");
    let stack = crate::stack::Stack::paper_two_layer(ratio).expect("stack");
    table.law_for(&stack).expect("law")
}

/// The paper's surface (scenes/paper-E2E1-5-interacting.toml) with k_M = `k_max`.
fn paper_surface(k_max: f64) -> Surface {
    Surface::generate(&crate::surface::GenerateParams::paper(512, k_max)).expect("surface")
}

/// 20 approaches up to 0.87 (z_M − z̄), as the benches.
pub(crate) fn path(rc: &RoughContact) -> Vec<f64> {
    (1..=20)
        .map(|i| 0.87 * rc.top_to_mean() * i as f64 / 20.0)
        .collect()
}

/// The error control of the far field, stated as a bound and checked against the
/// exact pair-by-pair image sum (tolerance 0) on the layered table, k_M = 40, 5×5
/// periodic images (687k image pairs) and isolated, at the solved state of the last
/// step plus a perturbed one: every gradient component obeys
/// |Δ∂U_E/∂a_k| ≤ c Q'_k · 2 tol · P_k and |ΔU_E| ≤ c tol Σ_k Q_k P_k, where
/// P_k = Σ_{l, images} (4/3)Q_l/(π r) is the point-force displacement at k (each
/// modelled G and ∂G/∂a is within tol of its point-force scale); and the residual
/// F_k itself moves by less than 2e-7 δ (measured 3e-8 δ).
#[test]
fn far_field_error_bound_layered_km40() {
    let law = paper_law(5.0);
    let s = paper_surface(40.0);
    let fast = RoughContact::from_surface(&law, &s).unwrap();
    let exact = RoughContact::from_surface(&law, &s)
        .unwrap()
        .with_far_field_tolerance(0.0);
    let tol = 1e-5;
    let (lx, ly) = s.extent();
    let delta = path(&fast)[19];
    for (images, m) in [(Images::Periodic(2), 2i64), (Images::Isolated, 0)] {
        let st = fast.solve_interacting(delta, images, &[]).unwrap();
        let mut states = vec![st.radii.clone()];
        // a perturbed state (±5 %), off the minimum
        states.push(
            st.radii
                .iter()
                .enumerate()
                .map(|(k, a)| a * (1.0 + 0.05 * ((k % 3) as f64 - 1.0)))
                .collect(),
        );
        let fi = fast.interaction(images, delta).unwrap();
        let ei = exact.interaction(images, delta).unwrap();
        let (near, far) = fi.image_pairs();
        assert!(far > 2 * near, "far field barely used: {near} {far}");
        let c = 2.0 * law.e_star() / 3.0;
        for radii in &states {
            let ns = radii.len();
            let (mut gf, mut ge) = (vec![0.0; ns], vec![0.0; ns]);
            let uf = fi.energy_gradient(radii, &mut gf).unwrap();
            let ue = ei.energy_gradient(radii, &mut ge).unwrap();
            let sm = fast.summits();
            let q: Vec<f64> = (0..ns)
                .map(|k| law.chi(radii[k]) * radii[k].powi(3) / sm[k].radius)
                .collect();
            let mut bound_u = 0.0;
            let mut worst: f64 = 0.0;
            let mut worst_f: f64 = 0.0; // max |ΔF_k|/δ
            for k in 0..ns {
                if radii[k] <= 0.0 {
                    continue;
                }
                let mut pk = 0.0;
                for l in 0..ns {
                    for sx in -m..=m {
                        for sy in -m..=m {
                            let r = (sm[l].x + sx as f64 * lx - sm[k].x)
                                .hypot(sm[l].y + sy as f64 * ly - sm[k].y);
                            if r > 0.0 {
                                pk += 4.0 / 3.0 * q[l] / (std::f64::consts::PI * r);
                            }
                        }
                    }
                }
                let (_, dchi, _, _) = law.chi_zeta_derivs(radii[k]);
                let dq = (dchi * radii[k].powi(3) + 3.0 * law.chi(radii[k]) * radii[k].powi(2))
                    / sm[k].radius;
                let bound = c * dq * 2.0 * tol * pk;
                worst = worst.max((gf[k] - ge[k]).abs() / bound);
                worst_f = worst_f.max((gf[k] - ge[k]).abs() / (c * dq) / delta);
                bound_u += c * tol * q[k] * pk;
            }
            eprintln!(
                "{images:?}: gradient error / bound {worst:.2e}, energy error / bound {:.2e}, max |ΔF|/δ {worst_f:.2e}",
                (uf - ue).abs() / bound_u
            );
            assert!(worst <= 1.0, "{images:?}: gradient error / bound {worst:e}");
            // and in absolute terms (measured 3e-8): F moves by < 2e-7 δ
            assert!(worst_f <= 2e-7, "{images:?}: max |ΔF|/δ {worst_f:e}");
            assert!(
                (uf - ue).abs() <= bound_u,
                "{images:?}: energy error {:e} bound {bound_u:e}",
                (uf - ue).abs()
            );
        }
    }
}

/// The energy and gradient of [`Interaction`] are consistent (central differences of
/// U_E match ∂U_E/∂a_k to 1e-6 of the gradient scale) on the layered table with
/// periodic images, far field on.
#[test]
fn energy_gradient_consistent_layered() {
    let law = paper_law(5.0);
    let s = paper_surface(10.0);
    let rc = RoughContact::from_surface(&law, &s).unwrap();
    let delta = path(&rc)[15];
    let st = rc
        .solve_interacting(delta, Images::Periodic(2), &[])
        .unwrap();
    let it = rc.interaction(Images::Periodic(2), delta).unwrap();
    let radii: Vec<f64> = st.radii.iter().map(|a| a * 0.97).collect();
    let mut g = vec![0.0; radii.len()];
    let _ = it.energy_gradient(&radii, &mut g).unwrap();
    let scale = g.iter().map(|x| x.abs()).fold(0.0, f64::max);
    let mut dummy = vec![0.0; radii.len()];
    for k in (0..radii.len()).filter(|&k| radii[k] > 0.0) {
        let h = 1e-6 * radii[k];
        let (mut p, mut m) = (radii.clone(), radii.clone());
        p[k] += h;
        m[k] -= h;
        let fd = (it.energy_gradient(&p, &mut dummy).unwrap()
            - it.energy_gradient(&m, &mut dummy).unwrap())
            / (2.0 * h);
        assert!(
            (fd - g[k]).abs() <= 1e-6 * scale,
            "{k}: {fd:e} {:e} (scale {scale:e})",
            g[k]
        );
    }
}

/// k_M = 40, layered table (E2/E1 = 5 and 1), isolated and 5×5 periodic: the
/// 20-step load path converges with KKT residual < 1e-8 at every step, and at the
/// last step U_E is a local minimum (rises when any of 40 asperities' radius moves
/// by ±0.1 %, or an asperity out of contact enters). Isolated k_M = 40 and periodic
/// k_M = 10 agree with exact pair sums: loads and areas to 1e-6, stiffness to 1e-5.
#[test]
fn km40_paths_converge_and_match_exact() {
    for ratio in [5.0, 1.0] {
        let law = paper_law(ratio);
        for km in [40.0, 10.0] {
            let s = paper_surface(km);
            let rc = RoughContact::from_surface(&law, &s).unwrap();
            let deltas = path(&rc);
            for images in [Images::Isolated, Images::Periodic(2)] {
                let c = rc.curve(Model::Interacting(images), &deltas).unwrap();
                for st in &c {
                    assert!(st.kkt_residual.unwrap() < 1e-8, "{st:?}");
                }
                let last = c.last().unwrap();
                if km == 40.0 {
                    let it = rc.interaction(images, *deltas.last().unwrap()).unwrap();
                    let mut g = vec![0.0; last.radii.len()];
                    let u0 = it.energy_gradient(&last.radii, &mut g).unwrap();
                    let (inside, outside): (Vec<usize>, Vec<usize>) =
                        (0..last.radii.len()).partition(|&k| last.radii[k] > 0.0);
                    for &k in inside.iter().step_by((inside.len() / 40).max(1)) {
                        for f in [1.001, 0.999] {
                            let mut r = last.radii.clone();
                            r[k] *= f;
                            assert!(it.energy_gradient(&r, &mut g).unwrap() > u0);
                        }
                    }
                    let zm = rc.summits().iter().map(|s| s.z).fold(f64::MIN, f64::max);
                    let loaded = outside
                        .iter()
                        .filter(|&&k| rc.summits()[k].z > zm - deltas[19]);
                    for &k in loaded.take(20) {
                        let mut r = last.radii.clone();
                        r[k] = 1e-7;
                        assert!(it.energy_gradient(&r, &mut g).unwrap() > u0);
                    }
                }
                let compare = (km == 40.0 && images == Images::Isolated)
                    || (km == 10.0 && images == Images::Periodic(2));
                if compare {
                    let ex = RoughContact::from_surface(&law, &s)
                        .unwrap()
                        .with_far_field_tolerance(0.0)
                        .curve(Model::Interacting(images), &deltas)
                        .unwrap();
                    let mut worst = [0.0f64; 3];
                    for (x, y) in c.iter().zip(&ex) {
                        if y.load > 0.0 {
                            worst[0] = worst[0].max((x.load / y.load - 1.0).abs());
                            worst[1] =
                                worst[1].max((x.area_fraction / y.area_fraction - 1.0).abs());
                            worst[2] = worst[2].max((x.stiffness / y.stiffness - 1.0).abs());
                        }
                    }
                    eprintln!(
                        "E2/E1 = {ratio} k_M = {km} {images:?}: far field vs exact sums: load {:.1e}, area {:.1e}, stiffness {:.1e}",
                        worst[0], worst[1], worst[2]
                    );
                    assert!(worst[0] <= 1e-6 && worst[1] <= 1e-6 && worst[2] <= 1e-5);
                }
            }
        }
    }
}

#[test]
fn interaction_rejects_bad_input() {
    let law = Homogeneous { e_star: 1e9 };
    let sums = vec![
        summit(0.0, 0.0, 1e-6, 1e-4),
        summit(5e-5, 0.0, 0.8e-6, 2e-4),
    ];
    let rc = RoughContact::new(&law, sums, 0.0, -1e-5, (1e-3, 1e-3)).unwrap();
    let it = rc.interaction(Images::Isolated, 0.9e-6).unwrap();
    let mut g = vec![0.0; 2];
    let e = it.energy_gradient(&[1e-6], &mut g).unwrap_err();
    assert!(e.to_string().contains("radii"), "{e}");
    let e = it.energy_gradient(&[1e-6, f64::NAN], &mut g).unwrap_err();
    assert!(e.to_string().contains("radii"), "{e}");
    assert!(rc.interaction(Images::Isolated, -1.0).is_err());
}

/// G (the displacement an asperity causes at distance r) and ∂G/∂a are
/// continuous at the contact edge r = a, so U_E is C¹ and its minimum exists when one
/// contact grows over another asperity's centre. G: inside value at r = a against the
/// outside one at a(1 + 1e-12), to 1e-9. ∂G/∂a: inside against the outside limit r → a⁺
/// (extrapolated past the √(r − a) edge term of B₀), to 1e-5 of 2a/R on a homogeneous
/// solid (where inside G is eq. P18, `law::displacement`, to round-off) and 1e-4 on the
/// shipped table (E2/E1 = 0.2 and 5, a/h₁ = 0.01…10; measured ≤ 2.5e-5). Inside, ∂G/∂a
/// and ∂²G/∂a² match central differences of G to 1e-6 and 1e-3 of 2a/R and 2/R.
#[test]
fn g_continuous_at_the_contact_edge() {
    use super::interacting::energy::g_derivs;
    use super::local::Local;
    let hom = Homogeneous { e_star: 1e9 };
    let soft = paper_law(0.2);
    let stiff = paper_law(5.0);
    let laws: [(&str, &dyn AsperityLaw); 3] = [("hom", &hom), ("0.2", &soft), ("5", &stiff)];
    let radius = 1e-4;
    for (name, law) in laws {
        for x in [0.01, 0.3, 1.0, 3.0, 10.0] {
            let a = x * 1e-4;
            let l = Local::at(law, a, radius);
            let at = |r: f64| g_derivs(law, &l, a, radius, r, 1e-5);
            let (gi, go) = (at(a), at(a * (1.0 + 1e-12)));
            let slope = 2.0 * a / radius;
            // outside ∂G/∂a at r → a⁺: D(ε) = D₀ + c√ε + O(ε) (the edge term of B₀),
            // extrapolated from ε = 1e-6 and 4e-6
            let d0 = 2.0 * at(a * (1.0 + 1e-6))[1] - at(a * (1.0 + 4e-6))[1];
            let (e0, e1) = ((gi[0] - go[0]) / go[0], (gi[1] - d0) / slope);
            eprintln!("{name} a/h {x}: G jump {e0:+.2e}, dG/da jump {e1:+.2e}");
            assert!(e0.abs() < 1e-9, "{name} {x}: {e0:e}");
            let tol = if law.is_homogeneous() { 1e-5 } else { 1e-4 };
            assert!(e1.abs() < tol, "{name} {x}: {e1:e}");
            if law.is_homogeneous() {
                for r in [0.0, 0.5 * a, a] {
                    let p18 = crate::law::displacement(law, a, radius, r);
                    assert!((at(r)[0] / p18 - 1.0).abs() < 1e-13);
                }
            }
            // inside: derivatives in a against central differences of G at r = a/2
            let r = 0.5 * a;
            let g_of = |b: f64| g_derivs(law, &Local::at(law, b, radius), b, radius, r, 1e-5);
            let h = 1e-4 * a;
            let (gp, gm, g0) = (g_of(a + h), g_of(a - h), g_of(a));
            let d1 = (gp[0] - gm[0]) / (2.0 * h);
            let d2 = (gp[1] - gm[1]) / (2.0 * h);
            let (_, c1, _, _) = law.chi_zeta_derivs(a + h);
            let (_, c2, _, _) = law.chi_zeta_derivs(a - h);
            let g2 = g0[2] + g0[3] * (c1 - c2) / (2.0 * h);
            assert!(
                (g0[1] - d1).abs() < 1e-6 * slope,
                "{name} {x}: {} {d1}",
                g0[1]
            );
            assert!(
                (g2 - d2).abs() < 1e-3 * 2.0 / radius,
                "{name} {x}: {g2} {d2}"
            );
        }
    }
}
