//! Rough-contact solver speed (the performance targets, 2 cores): a 20-step load curve on the
//! paper's surface (n = 512, generated as in scenes/paper-E2E1-5-interacting.toml) with
//! the I model < 0.5 s at k_M = 10 and < 3 s at k_M = 40, and the N model < 20 ms.
//!
//! * `curve/<law>/km<k_M>/<model>`: 20 approaches up to 0.87 (z_M − z̄), warm-started
//!   along the path (`RoughContact::curve`), on the homogeneous half-space and on the
//!   shipped family table `tables/paper-two-layer.strata` for the paper's stack with
//!   E2/E1 = 5 and 1; models N (summits found once), I isolated and I with 5×5
//!   periodic images (I: from a fresh `RoughContact` each time, so summit detection,
//!   the far-field model build and the pair geometry are included).
//! * `energy-gradient/<law>/km<k_M>/<images>[/exact]`: one evaluation of the I-model
//!   complementary energy U_E and its gradient (`Interaction::energy_gradient`) at the
//!   solved state of the last step, with the default far-field tolerance or with exact
//!   pair-by-pair image sums (`/exact`) — the solver's hot path.
//!
//! * `stall/<stack>/<case>` (requirement: every step of the elastic-base stay/stall cases
//!   of tests/it/stalls.rs in < 1 s): one cold I-model step (problem preparation
//!   included) on the stacks A (50 µm, 4 GPa, ν 0.15 on 12 GPa) and B (50 µm, 10 MPa,
//!   ν 0.49 on 2 MPa), tables built here, on a generated surface (512², k 2…10, seeds
//!   4242 and 1); `stall/<stack>/path60/<images>`: the 60-step path to 1.5 (z_M − z_min)
//!   (divide by 60 for a step).
//! * `control/<stack>/<images>/{separation,pressure}`: one cold separation-controlled
//!   step at δ = 0.8 (z_M − z̄) and one pressure-controlled step to the mean pressure it
//!   gives (they must cost about the same), side by side in one run.
//!
//! * `scaling/table-E2E1=5/periodic5x5/grid<n>-km<k_M>`: the I-model
//!   20-step curve against the number of summits N on generated surfaces (L = 1 mm,
//!   D_f = 2.4, k_m = 2) of about 1e3, 4e3 and 1e4 summits, cold as above: above
//!   `Params::dense_pair_limit` loaded asperities the far field runs on the FFT grid
//!   with sparse near corrections and conjugate-gradient Newton steps. The 1e5-summit
//!   point (grid 2048, k_M = 840) runs only with `STRATA_BENCH_LARGE=1` (about a minute per
//!   sample). Peak memory and the fitted exponents: `strata study` ("I model at scale").
//!
//! Run: `cargo bench -p strata-benches --bench rough` (`-- stall`, `-- control`,
//! `-- scaling` for the groups above).

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::rough::{Images, Model, RoughContact};
use strata_runtime::surface::{GenerateParams, Surface};

fn surface(k_max: f64) -> Surface {
    surface_on(512, k_max)
}

fn surface_on(grid: usize, k_max: f64) -> Surface {
    Surface::generate(&GenerateParams::paper(grid, k_max)).expect("surface")
}

/// 20 approaches up to g_n ≈ 0.13 (z_M − z̄), as in the paper's curves.
fn deltas(rc: &RoughContact) -> Vec<f64> {
    let top = rc.top_to_mean();
    (1..=20).map(|i| 0.87 * top * i as f64 / 20.0).collect()
}

fn curves(c: &mut Criterion, name: &str, law: &dyn AsperityLaw, s: &Surface, models: &[&str]) {
    let warm = RoughContact::from_surface(law, s).expect("summits");
    let d = deltas(&warm);
    for &label in models {
        let id = format!("curve/{name}/{label}");
        let model = match label {
            "N" => {
                // the N model alone (summits found once)
                c.bench_function(&id, |b| {
                    b.iter(|| black_box(warm.curve(Model::Independent, black_box(&d))))
                });
                continue;
            }
            "I-isolated" => Model::Interacting(Images::Isolated),
            _ => Model::Interacting(Images::Periodic(2)),
        };
        // cold: a fresh RoughContact per iteration (summit detection, far-field model
        // build, pair geometry and the 20 solves)
        c.bench_function(&id, |b| {
            b.iter(|| {
                let rc = RoughContact::from_surface(law, black_box(s)).expect("summits");
                black_box(rc.curve(model, black_box(&d)).expect("solve"))
            })
        });
    }
}

fn energy_gradient(c: &mut Criterion, name: &str, law: &dyn AsperityLaw, s: &Surface, exact: bool) {
    let rc = RoughContact::from_surface(law, s).expect("summits");
    let rc = if exact {
        rc.with_far_field_tolerance(0.0)
    } else {
        rc
    };
    let d = deltas(&rc);
    let images = Images::Periodic(2);
    let state = rc
        .curve(Model::Interacting(images), &d)
        .expect("solve")
        .pop()
        .expect("steps")
        .radii;
    let it = rc.interaction(images, d[19]).expect("interaction");
    let mut grad = vec![0.0; state.len()];
    let tag = if exact { "/exact" } else { "" };
    c.bench_function(&format!("energy-gradient/{name}/periodic5x5{tag}"), |b| {
        b.iter(|| {
            black_box(
                it.energy_gradient(black_box(&state), &mut grad)
                    .expect("energy"),
            )
        })
    });
}

fn benches(c: &mut Criterion) {
    let s10 = surface(10.0);
    let s40 = surface(40.0);
    let all = ["N", "I-isolated", "I-periodic5x5"];
    let hom = Homogeneous { e_star: 4.092e9 };
    curves(c, "homogeneous/km10", &hom, &s10, &all);
    curves(c, "homogeneous/km40", &hom, &s40, &all);
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables/paper-two-layer.strata");
    let table = strata_runtime::table::Table::load(&path).expect("shipped table");
    for ratio in [5.0, 1.0] {
        let stack = strata_runtime::Stack::paper_two_layer(ratio).expect("stack");
        let law = table.law_for(&stack).expect("law");
        let tag = format!("table-E2E1={ratio}");
        curves(c, &format!("{tag}/km10"), &law, &s10, &all);
        curves(c, &format!("{tag}/km40"), &law, &s40, &all[1..]);
        if ratio == 5.0 {
            energy_gradient(c, &format!("{tag}/km10"), &law, &s10, false);
            energy_gradient(c, &format!("{tag}/km40"), &law, &s40, false);
            energy_gradient(c, &format!("{tag}/km10"), &law, &s10, true);
        }
    }
}

/// A 50 µm layer (E, ν) on an elastic half-space (E_b, ν 0.3) and its law from a table
/// built here (as tests/it/stalls.rs).
fn elastic_base_law(young: f64, poisson: f64, base: f64) -> strata_runtime::table::TableLaw {
    use strata_runtime::stack::{Base, Layer};
    let st = strata_runtime::Stack::new(
        vec![Layer {
            thickness: 50e-6,
            young,
            poisson,
        }],
        Base::Elastic {
            young: base,
            poisson: 0.3,
        },
    )
    .expect("stack");
    let opts = strata_tablegen::tablebuild::BuildOptions {
        x_range: (1e-3, 1e2),
        nx: 81,
        check_points: 0,
        ..Default::default()
    };
    strata_tablegen::tablebuild::build(&st, &opts)
        .expect("table")
        .law_for(&st)
        .expect("law")
}

fn seeded(seed: u64) -> Surface {
    Surface::generate(&GenerateParams {
        size: 1e-3,
        grid: 512,
        fractal_dimension: 2.4,
        k_min: 2.0,
        k_max: 10.0,
        rms: 3.4e-6,
        seed,
    })
    .expect("surface")
}

fn stalls(c: &mut Criterion) {
    let a = elastic_base_law(4e9, 0.15, 12e9);
    let b = elastic_base_law(10e6, 0.49, 2e6);
    let (s4242, s1) = (seeded(4242), seeded(1));
    let per = Images::Periodic(2);
    // (id, law, surface, images, δ (m) or fraction of z_M − z_min)
    let cases: [(&str, &dyn AsperityLaw, &Surface, Images, f64, bool); 8] = [
        ("A/4242/periodic/5um", &a, &s4242, per, 5e-6, false),
        ("A/4242/periodic/7um", &a, &s4242, per, 7e-6, false),
        ("A/4242/periodic/9um", &a, &s4242, per, 9e-6, false),
        ("A/1/periodic/27of40pv", &a, &s1, per, 27.0 / 40.0, true),
        ("A/1/isolated/pv", &a, &s1, Images::Isolated, 1.0, true),
        ("B/4242/periodic/3um", &b, &s4242, per, 3e-6, false),
        ("B/4242/periodic/5um", &b, &s4242, per, 5e-6, false),
        ("B/4242/periodic/9um", &b, &s4242, per, 9e-6, false),
    ];
    for (id, law, s, images, x, frac) in cases {
        let rc = RoughContact::from_surface(law, s).expect("summits");
        let d = if frac { x * rc.max_delta() } else { x };
        let m = Model::Interacting(images);
        c.bench_function(&format!("stall/{id}"), |bch| {
            bch.iter(|| black_box(rc.solve(m, black_box(d), &[]).expect("solve")))
        });
    }
    for (name, law) in [("A", &a as &dyn AsperityLaw), ("B", &b)] {
        let rc = RoughContact::from_surface(law, &s1).expect("summits");
        let ds: Vec<f64> = (1..=60).map(|i| rc.max_delta() * i as f64 / 40.0).collect();
        for (tag, images) in [("periodic", per), ("isolated", Images::Isolated)] {
            let m = Model::Interacting(images);
            c.bench_function(&format!("stall/{name}/path60/{tag}"), |bch| {
                bch.iter(|| black_box(rc.curve(m, black_box(&ds)).expect("path")))
            });
        }
    }
    for (name, law) in [("A", &a as &dyn AsperityLaw), ("B", &b)] {
        let rc = RoughContact::from_surface(law, &s4242).expect("summits");
        let d = 0.8 * rc.top_to_mean();
        for (tag, images) in [("periodic", per), ("isolated", Images::Isolated)] {
            let m = Model::Interacting(images);
            let p = rc.solve(m, d, &[]).expect("solve").mean_pressure;
            c.bench_function(&format!("control/{name}/{tag}/separation"), |bch| {
                bch.iter(|| black_box(rc.solve(m, black_box(d), &[]).expect("solve")))
            });
            c.bench_function(&format!("control/{name}/{tag}/pressure"), |bch| {
                bch.iter(|| black_box(rc.solve_pressure(m, black_box(p), &[]).expect("solve")))
            });
        }
    }
}

/// The I-model curve against N (module docs).
fn scaling(c: &mut Criterion, law: &dyn AsperityLaw) {
    let mut sizes = vec![(512, 64.0), (512, 128.0), (1024, 200.0)];
    if std::env::var("STRATA_BENCH_LARGE").is_ok() {
        sizes.push((2048, 840.0));
    }
    for (grid, km) in sizes {
        let s = surface_on(grid, km);
        let n = RoughContact::from_surface(law, &s)
            .expect("summits")
            .summits()
            .len();
        let d = deltas(&RoughContact::from_surface(law, &s).expect("summits"));
        let id = format!("scaling/table-E2E1=5/periodic5x5/grid{grid}-km{km}-N{n}");
        c.bench_function(&id, |b| {
            b.iter(|| {
                let rc = RoughContact::from_surface(law, black_box(&s)).expect("summits");
                black_box(
                    rc.curve(Model::Interacting(Images::Periodic(2)), black_box(&d))
                        .expect("solve"),
                )
            })
        });
    }
}

fn scaling_benches(c: &mut Criterion) {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables/paper-two-layer.strata");
    let table = strata_runtime::table::Table::load(&path).expect("shipped table");
    let stack = strata_runtime::Stack::paper_two_layer(5.0).expect("stack");
    let law = table.law_for(&stack).expect("law");
    scaling(c, &law);
}

criterion_group! {
    name = scale;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_secs(1));
    targets = scaling_benches
}

criterion_group! {
    name = rough;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = benches, stalls
}
criterion_main!(rough, scale);
