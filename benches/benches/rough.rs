//! Rough-contact solver speed (issue 5 targets, 2 cores): a 20-step load curve on the
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
//! * `scaling/table-E2E1=5/periodic5x5/grid<n>-km<k_M>` (issue 20): the I-model
//!   20-step curve against the number of summits N on generated surfaces (L = 1 mm,
//!   D_f = 2.4, k_m = 2) of about 1e3, 4e3 and 1e4 summits, cold as above: above
//!   `Params::dense_pair_limit` loaded asperities the far field runs on the FFT grid
//!   with sparse near corrections and conjugate-gradient Newton steps. The 1e5-summit
//!   point (grid 2048, k_M = 840) runs only with `STRATA_BENCH_LARGE=1` (minutes per
//!   sample). Peak memory and the fitted exponents: `strata study` ("I model at scale").
//!
//! Run: `cargo bench -p strata-benches --bench rough`.

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
    targets = benches
}
criterion_main!(rough, scale);
