//! Time to build the shipped family table (the paper's stack, E2/E1 = 0.1 … 10, 21
//! members, default resolution, no interpolation check). Target: < 60 s on 2 cores.
//! Run: `cargo bench -p strata-benches --bench tablebuild`.
//!
//! `family33` (printed, one run; `cargo bench -p strata-benches --bench tablebuild --
//! family33`): the 33-member family (E2/E1 = 0.1 … 10) as `strata table
//! build --vary 2:0.1:10:33` builds it — far-field checks and the 1000-point
//! interpolation check included — wall seconds, process CPU seconds and CPU seconds per
//! member.

use std::path::Path;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use strata_runtime::Stack;
use strata_runtime::table::Vary;
use strata_tablegen::tablebuild::{BuildOptions, build};

fn family33(_: &mut Criterion) {
    if !strata_benches::filter_matches("family33") {
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let stack =
        Stack::from_toml_file(&root.join("tables/stacks/paper-two-layer.toml")).expect("stack");
    let opts = BuildOptions {
        family: Some((Vary::Layer(2), 0.1, 10.0, 33)),
        ..BuildOptions::default()
    };
    let (t0, c0) = (std::time::Instant::now(), strata_benches::cpu_seconds());
    build(&stack, &opts).expect("build");
    let (wall, cpu) = (
        t0.elapsed().as_secs_f64(),
        strata_benches::cpu_seconds() - c0,
    );
    println!(
        "family33: 33 members, checks included: {wall:.1} s wall, {cpu:.1} CPU-s, {:.2} CPU-s per member, {} threads",
        cpu / 33.0,
        rayon::current_num_threads()
    );
}

fn bench(c: &mut Criterion) {
    if !strata_benches::filter_matches("tablebuild") {
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let stack =
        Stack::from_toml_file(&root.join("tables/stacks/paper-two-layer.toml")).expect("stack");
    let opts = BuildOptions {
        family: Some((Vary::Layer(2), 0.1, 10.0, 21)),
        check_points: 0,
        ..BuildOptions::default()
    };
    let mut g = c.benchmark_group("tablebuild");
    g.sample_size(10).measurement_time(Duration::from_secs(60));
    g.bench_function("paper family table", |b| {
        b.iter(|| build(&stack, &opts).expect("build"))
    });
    g.finish();
}

criterion_group!(benches, bench, family33);
criterion_main!(benches);
