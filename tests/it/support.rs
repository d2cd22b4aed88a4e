//! Shared helpers of the integration tests: where the repository and its reference data
//! are, and the `strata` binary.

use std::path::PathBuf;

/// The repository root (the `strata` package's manifest directory).
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The independent reference data, `tests/reference/` (provenance in its README).
/// Panics with the path when the directory is missing: these tests never skip.
pub fn reference_dir() -> PathBuf {
    let dir = repo().join("tests/reference");
    assert!(
        dir.join("README.md").is_file(),
        "reference data missing: {} (part of the repository)",
        dir.display()
    );
    dir
}

/// One reference file; panics with its path when it is missing.
#[allow(dead_code)]
pub fn reference(name: &str) -> PathBuf {
    let p = reference_dir().join(name);
    assert!(p.is_file(), "reference file missing: {}", p.display());
    p
}
