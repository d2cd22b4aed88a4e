//! One library call from Python: run on a worker thread with a progress [`Report`] and
//! a [`Cancel`] token of its own, while the calling thread (holding the GIL a moment
//! every 50 ms) shows the report through `strata._progress.Display` (a notebook cell's
//! output in Jupyter, stderr on a terminal) and checks for Ctrl-C
//! (`Python::check_signals`): a `KeyboardInterrupt` trips the token, the solvers stop at
//! their next iteration, the call's partial result is dropped and the interrupt raised.
//! Nothing is process-global: concurrent calls report and cancel apart.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pyo3::prelude::*;
use strata_engine::progress::{Report, scoped};
use strata_runtime::cancel::Cancel;

/// How often the calling thread looks at the call: signals and progress.
const POLL: Duration = Duration::from_millis(50);

/// Whether to show progress: `progress` if given, else `strata._progress.auto()` (in a
/// notebook, or stderr a terminal).
fn wanted(py: Python<'_>, progress: Option<bool>) -> PyResult<bool> {
    match progress {
        Some(b) => Ok(b),
        None => py
            .import("strata._progress")?
            .call_method0("auto")?
            .extract(),
    }
}

/// Hands the report's new lines and status to the display.
fn show(display: &Bound<'_, PyAny>, report: &Report) -> PyResult<()> {
    for line in report.take_lines() {
        display.call_method1("log", (line.text, line.warning))?;
    }
    if report.shows() {
        display.call_method1("update", (report.status(),))?;
    }
    Ok(())
}

/// Runs `f` (given the call's cancellation token) off the GIL on a worker thread, with
/// the progress asked for (`None`: automatic), and returns its result; Ctrl-C raises
/// `KeyboardInterrupt` here within about one solver iteration.
pub(crate) fn call<T: Send>(
    py: Python<'_>,
    progress: Option<bool>,
    f: impl FnOnce(&Cancel) -> T + Send,
) -> PyResult<T> {
    let report = Report::new(wanted(py, progress)?);
    let display = py
        .import("strata._progress")?
        .getattr("Display")?
        .call1((report.shows(), progress.is_none()))?;
    let cancel = Cancel::new();
    let done = Arc::new(AtomicBool::new(false));
    let (out, interrupted) = std::thread::scope(|s| {
        let worker = s.spawn(|| {
            let out = scoped(&report, || f(&cancel));
            done.store(true, Ordering::Release);
            out
        });
        let mut interrupted = None;
        loop {
            let d = Arc::clone(&done);
            let finished = py.detach(move || {
                // short naps: a fast call returns at once
                for _ in 0..10 {
                    if d.load(Ordering::Acquire) {
                        return true;
                    }
                    std::thread::sleep(POLL / 10);
                }
                d.load(Ordering::Acquire)
            });
            if finished {
                break;
            }
            if let Err(e) = py.check_signals() {
                cancel.cancel();
                interrupted = Some(e);
                break;
            }
            if let Err(e) = show(&display, &report) {
                // a broken display must not leave the solve running unseen
                cancel.cancel();
                interrupted = Some(e);
                break;
            }
        }
        // After an interrupt the worker stops at its next check.
        let out = py.detach(|| worker.join());
        (out, interrupted)
    });
    let logged = report
        .take_lines()
        .into_iter()
        .try_for_each(|l| display.call_method1("log", (l.text, l.warning)).map(drop));
    let status = report.shows().then(|| report.status()).flatten();
    display.call_method1("close", (interrupted.is_none(), status))?;
    if let Some(e) = interrupted {
        return Err(e);
    }
    logged?;
    out.map_err(|_| {
        pyo3::exceptions::PyRuntimeError::new_err(
            "strata: the library panicked (a bug: please report it with the input that caused it)",
        )
    })
}
