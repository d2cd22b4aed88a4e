//! Criterion benchmarks of strata; see `benches/` and the README ("Benchmarks").
