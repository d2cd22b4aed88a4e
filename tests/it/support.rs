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

/// An optional external tool (`program version_arg` can be started), or None after
/// saying so on the terminal itself (test output capture does not hide it): such
/// tests never pass silently. With `STRATA_REQUIRE_TOOLS=1` (CI) a missing tool fails.
#[allow(dead_code)]
pub fn optional_tool(program: &str, version_arg: &str, install: &str) -> Option<String> {
    // Found when it starts at all (`ccx -v` exits with 201 after printing its version).
    if std::process::Command::new(program)
        .arg(version_arg)
        .output()
        .is_ok()
    {
        return Some(program.to_string());
    }
    let msg = format!(
        "*** {program} not found: this test did NOT run. Install it ({install}) or set \
         STRATA_REQUIRE_TOOLS=1 to make its absence a failure (CI does)."
    );
    assert!(
        std::env::var_os("STRATA_REQUIRE_TOOLS").is_none_or(|v| v != "1"),
        "{msg}"
    );
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "\n{msg}\n");
    None
}
