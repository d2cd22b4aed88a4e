//! The check for an optional external tool (ccx, gfortran), shared by the workspace's
//! integration tests and capi/tests (included there by path).

/// An optional external tool (`program version_arg` can be started), or None after
/// saying so on the terminal itself (test output capture does not hide it): such
/// tests never pass silently. With `STRATA_REQUIRE_TOOLS=1` (CI) a missing tool fails.
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
