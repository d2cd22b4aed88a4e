//! The library's progress and log lines during a call from Python: on stderr or
//! silenced.

/// Runs `f` with the progress and log lines of the `strata` library on stderr
/// (`progress`) or silenced.
pub(crate) fn with_progress<T>(progress: bool, f: impl FnOnce() -> T) -> T {
    strata::progress::set_quiet(!progress);
    let out = f();
    strata::progress::set_quiet(false);
    out
}
