//! Time to build the shipped family table (the paper's stack, E2/E1 = 0.1 … 10, 21
//! members, default resolution, no interpolation check). Target: < 60 s on 2 cores.
//! Run: `cargo bench -p strata-tablegen --bench tablebuild`.

use std::path::Path;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use strata_runtime::Stack;
use strata_runtime::table::Vary;
use strata_tablegen::tablebuild::{BuildOptions, build};

fn bench(c: &mut Criterion) {
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

criterion_group!(benches, bench);
criterion_main!(benches);
