//! Progress and log lines on stderr, one mechanism for every command (indicatif).
//!
//! Three modes for the process (the command line), chosen once:
//! - **bar** (stderr is a terminal): indicatif bars drawn in place; log lines are
//!   printed above them;
//! - **log** (stderr is a file or a pipe: batch jobs, CI): no bars; every running
//!   operation prints one line every [`log_interval`] (default 5 s) with its count, the
//!   elapsed time and the time left, and a last line when it ends;
//! - **off** (`--quiet`): neither progress nor log lines; errors are still printed.
//!
//! A library caller (the Python package) instead collects what one call reports in a
//! [`Report`] of its own ([`scoped`]): its log lines, warnings and bars go there, not to
//! stderr, and the caller shows them where its user looks (a notebook cell) or drops
//! them. Nothing is process-global then: two calls on two threads report apart.
//!
//! `STRATA_PROGRESS=bar|log|off` overrides the choice; `STRATA_LOG_INTERVAL` (seconds,
//! ≥ 0.05) sets the interval of the log mode. Long operations take a [`Progress`]
//! ([`bar`] with a count, [`spinner`] without); plain messages go through [`log`], so
//! that they never tear a bar apart.

use std::borrow::Cow;
use std::cell::RefCell;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::stdio::eprint_line;

/// How progress is shown (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Bars drawn in place on a terminal.
    Bar,
    /// Periodic log lines (stderr is not a terminal).
    Log,
    /// Nothing (`--quiet`).
    Off,
}

static MODE: OnceLock<Mode> = OnceLock::new();
static MULTI: OnceLock<MultiProgress> = OnceLock::new();

/// The command line's `--quiet`, once at start: no progress and no log lines for the
/// rest of the process (errors are still printed). Without it the mode is chosen on
/// first use ([`mode`]).
pub fn init(quiet: bool) {
    if quiet {
        // A second call cannot change the mode: a process has one command line.
        let _ = MODE.set(Mode::Off);
    }
}

/// The process's mode: `Off` after [`init`]`(true)`, else `STRATA_PROGRESS`, else `Bar`
/// on a terminal and `Log` otherwise. Calls inside [`scoped`] report to their
/// [`Report`] whatever the mode.
pub fn mode() -> Mode {
    *MODE.get_or_init(|| match std::env::var("STRATA_PROGRESS").as_deref() {
        Ok("bar") => Mode::Bar,
        Ok("log") => Mode::Log,
        Ok("off") => Mode::Off,
        _ if std::io::stderr().is_terminal() => Mode::Bar,
        _ => Mode::Log,
    })
}

/// Interval of the log mode's lines: `STRATA_LOG_INTERVAL` seconds (at least 0.05),
/// default 5 s.
pub fn log_interval() -> Duration {
    let s = std::env::var("STRATA_LOG_INTERVAL")
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|v| v.is_finite())
        .unwrap_or(5.0)
        .clamp(0.05, 3600.0);
    Duration::from_secs_f64(s)
}

fn multi() -> &'static MultiProgress {
    MULTI.get_or_init(|| MultiProgress::with_draw_target(ProgressDrawTarget::stderr()))
}

/// One line of a [`Report`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Line {
    /// The text, without a newline.
    pub text: String,
    /// A warning ([`warn`]): kept even when the report shows no progress.
    pub warning: bool,
}

/// What one call reports, for its caller to show: the log lines and warnings in order
/// and the bars of its operations (read with [`Report::status`]). Made per call and
/// installed on the calling thread by [`scoped`]; `show = false` keeps only warnings.
#[derive(Debug)]
pub struct Report {
    show: bool,
    lines: Mutex<Vec<Line>>,
    bars: Mutex<Vec<ProgressBar>>,
}

impl Report {
    /// A report that keeps progress and log lines (`show`) or only warnings.
    pub fn new(show: bool) -> Arc<Self> {
        Arc::new(Report {
            show,
            lines: Mutex::new(Vec::new()),
            bars: Mutex::new(Vec::new()),
        })
    }

    /// Whether progress and log lines are kept.
    pub fn shows(&self) -> bool {
        self.show
    }

    /// The lines reported since the last call, in order.
    pub fn take_lines(&self) -> Vec<Line> {
        self.lines
            .lock()
            .map(|mut l| std::mem::take(&mut *l))
            .unwrap_or_default()
    }

    /// The [`status_line`] of the newest running operation, else of the newest one
    /// that ended (its last state), else `None`.
    pub fn status(&self) -> Option<String> {
        let bars = self.bars.lock().ok()?;
        let pb = bars
            .iter()
            .rev()
            .find(|b| !b.is_finished())
            .or_else(|| bars.last())?;
        Some(status_line(pb))
    }

    fn push(&self, text: String, warning: bool) {
        if let Ok(mut l) = self.lines.lock() {
            l.push(Line { text, warning });
        }
    }

    fn add_bar(&self, pb: &ProgressBar) {
        if let Ok(mut b) = self.bars.lock() {
            b.push(pb.clone());
        }
    }
}

thread_local! {
    /// The report of the call running on this thread ([`scoped`]).
    static CURRENT: RefCell<Option<Arc<Report>>> = const { RefCell::new(None) };
}

/// Restores the thread's previous report when [`scoped`] ends (by return or panic).
struct Restore(Option<Arc<Report>>);

impl Drop for Restore {
    fn drop(&mut self) {
        let prev = self.0.take();
        CURRENT.with(|c| *c.borrow_mut() = prev);
    }
}

/// Runs `f` with `report` receiving the log lines, warnings and bars of this thread
/// (the library's calls from `f`), instead of stderr. Per call: other threads, and this
/// one after `f`, are unaffected.
pub fn scoped<T>(report: &Arc<Report>, f: impl FnOnce() -> T) -> T {
    let prev = CURRENT.with(|c| c.borrow_mut().replace(Arc::clone(report)));
    let _restore = Restore(prev);
    f()
}

fn current() -> Option<Arc<Report>> {
    CURRENT.with(|c| c.borrow().clone())
}

/// A warning: to the thread's [`Report`] if any (kept even without progress), else on
/// stderr as `WARNING: <line>` whatever the mode.
pub fn warn(line: impl std::fmt::Display) {
    match current() {
        Some(r) => r.push(format!("WARNING: {line}"), true),
        None => eprint_line(format_args!("WARNING: {line}")),
    }
}

/// Prints one log line on stderr (above any bar); nothing when quiet. A line stderr
/// cannot take (a full disk) is dropped ([`eprint_line`]). Inside [`scoped`] the line
/// goes to the call's [`Report`] (if it shows progress).
pub fn log(line: impl std::fmt::Display) {
    if let Some(r) = current() {
        if r.show {
            r.push(line.to_string(), false);
        }
        return;
    }
    match mode() {
        Mode::Off => {}
        Mode::Bar => multi().suspend(|| eprint_line(line)),
        Mode::Log => eprint_line(line),
    }
}

/// Seconds in a short human form: `4.2 s`, `3 min 05 s`, `1 h 02 min`.
pub fn human_duration(d: Duration) -> String {
    let s = d.as_secs_f64();
    if s < 60.0 {
        format!("{s:.1} s")
    } else if s < 3600.0 {
        format!("{} min {:02} s", (s / 60.0) as u64, (s % 60.0) as u64)
    } else {
        format!(
            "{} h {:02} min",
            (s / 3600.0) as u64,
            ((s % 3600.0) / 60.0) as u64
        )
    }
}

/// Time left after `k` of `n` steps in `elapsed`: the mean rate of the whole run so far,
/// t·(n − k)/k. Steps of a load curve differ in cost (the first carries the coarse-to-fine
/// start, contact grows), so a rate from the last few steps (indicatif's estimator) swung
/// by orders of magnitude between lines (7 min to 42 h on one run); the mean moves by at
/// most the ratio of a step's cost to the mean between two lines, and a long step in
/// progress raises it (its time is in `elapsed`). `None` before the first step or after
/// the last.
pub fn eta(elapsed: Duration, k: u64, n: u64) -> Option<Duration> {
    (k > 0 && k < n).then(|| elapsed.mul_f64((n - k) as f64 / k as f64))
}

/// The log-mode line of a bar: `what: 12/97 (12 %), 4.2 s elapsed, about 30.1 s left`
/// (a spinner: `what: 4.2 s elapsed`). A bar that ended before its count (an error, an
/// interrupt) says where it stopped: `what: stopped at 12/97 (12 %), 4.2 s elapsed`.
pub fn status_line(pb: &ProgressBar) -> String {
    let what = pb.message();
    let elapsed = human_duration(pb.elapsed());
    match pb.length() {
        Some(n) if n > 0 => {
            let k = pb.position().min(n);
            let percent = 100 * k / n;
            if pb.is_finished() && k < n {
                return format!("{what}: stopped at {k}/{n} ({percent} %), {elapsed} elapsed");
            }
            let left = match eta(pb.elapsed(), k, n) {
                Some(t) => format!(", about {} left", human_duration(t)),
                None => String::new(),
            };
            format!("{what}: {k}/{n} ({percent} %), {elapsed} elapsed{left}")
        }
        _ => format!("{what}: {elapsed} elapsed"),
    }
}

/// One line every `interval` while the bar runs, and a last one when it ends (if it
/// ran for at least one interval).
fn spawn_logger(pb: &ProgressBar, interval: Duration, ended: Arc<AtomicBool>) {
    let weak = pb.downgrade();
    let spawned = std::thread::Builder::new()
        .name("strata-progress".into())
        .spawn(move || {
            let step = interval.min(Duration::from_millis(50));
            let mut last = Instant::now();
            loop {
                std::thread::sleep(step);
                let Some(pb) = weak.upgrade() else { return };
                if pb.is_finished() {
                    last_line(&pb, interval, &ended);
                    return;
                }
                if last.elapsed() >= interval {
                    last = Instant::now();
                    eprint_line(status_line(&pb));
                }
            }
        });
    // Without a thread the work goes on silently; that is no reason to fail it.
    drop(spawned);
}

/// The last line of a logged operation (once, and only if it ran for at least one
/// interval): `(done)` when it reached its count, else its [`status_line`] says where it
/// stopped.
fn last_line(pb: &ProgressBar, interval: Duration, ended: &AtomicBool) {
    if pb.elapsed() >= interval && !ended.swap(true, Ordering::SeqCst) {
        let line = status_line(pb);
        if stopped_early(pb) {
            eprint_line(line);
        } else {
            eprint_line(format!("{line} (done)"));
        }
    }
}

/// A counted bar that ended before its count.
fn stopped_early(pb: &ProgressBar) -> bool {
    pb.length().is_some_and(|n| pb.position() < n)
}

fn make(len: Option<u64>, what: Cow<'static, str>, ended: Arc<AtomicBool>) -> ProgressBar {
    if let Some(r) = current() {
        if !r.show {
            return ProgressBar::hidden();
        }
        let pb =
            ProgressBar::with_draw_target(len, ProgressDrawTarget::hidden()).with_message(what);
        r.add_bar(&pb);
        return pb;
    }
    match mode() {
        Mode::Off => ProgressBar::hidden(),
        Mode::Log => {
            let pb =
                ProgressBar::with_draw_target(len, ProgressDrawTarget::hidden()).with_message(what);
            spawn_logger(&pb, log_interval(), ended);
            pb
        }
        Mode::Bar => {
            let template = if len.is_some() {
                "{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} (eta {eta})"
            } else {
                "{spinner} {msg} [{elapsed_precise}]"
            };
            let pb = ProgressBar::with_draw_target(len, ProgressDrawTarget::hidden());
            if let Ok(style) = ProgressStyle::with_template(template) {
                pb.set_style(style);
            }
            let pb = multi().add(pb.with_message(what));
            if len.is_none() {
                pb.enable_steady_tick(Duration::from_millis(120));
            }
            pb
        }
    }
}

/// A raw indicatif bar of `len` steps following the mode (for crates that take a bar
/// factory, such as `strata_tablegen`'s table builds).
pub fn raw_bar(len: u64, what: &'static str) -> ProgressBar {
    make(Some(len), Cow::Borrowed(what), Arc::default())
}

/// A running operation; the bar (or the log lines) ends when it is dropped.
#[derive(Debug)]
pub struct Progress {
    pb: ProgressBar,
    /// The last log line was printed (by the drop or the logger thread).
    ended: Arc<AtomicBool>,
    /// Made in the log mode (not for a [`Report`]): the drop prints the last line.
    logged: bool,
}

impl Progress {
    /// One more step done.
    pub fn inc(&self) {
        self.pb.inc(1);
    }

    /// `k` steps done.
    pub fn set_position(&self, k: u64) {
        self.pb.set_position(k);
    }

    /// Changes the description.
    pub fn set_message(&self, what: impl Into<Cow<'static, str>>) {
        self.pb.set_message(what);
    }

    /// The underlying bar (for `par_iter().progress_with(...)`).
    pub fn bar(&self) -> &ProgressBar {
        &self.pb
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        // A bar that did not reach its count (an error, Ctrl-C) keeps its position: the
        // last line and the caller's status say where it stopped, not 100 %
        // (`finish_and_clear` moves the position to the count).
        if stopped_early(&self.pb) {
            self.pb.abandon();
        } else {
            self.pb.finish_and_clear();
        }
        // Here rather than in the logger thread, which the process may outrun.
        if self.logged {
            last_line(&self.pb, log_interval(), &self.ended);
        }
    }
}

fn progress(len: Option<u64>, what: Cow<'static, str>) -> Progress {
    let ended = Arc::new(AtomicBool::new(false));
    let logged = current().is_none() && mode() == Mode::Log;
    Progress {
        pb: make(len, what, Arc::clone(&ended)),
        ended,
        logged,
    }
}

/// An operation of `len` counted steps described by `what` (`"BEM: load steps"`).
pub fn bar(len: u64, what: impl Into<Cow<'static, str>>) -> Progress {
    progress(Some(len), what.into())
}

/// An operation without a count: a spinner with the elapsed time.
pub fn spinner(what: impl Into<Cow<'static, str>>) -> Progress {
    progress(None, what.into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_lines_count_and_time() {
        let pb = ProgressBar::with_draw_target(Some(40), ProgressDrawTarget::hidden())
            .with_message("BEM: load steps");
        pb.set_position(10);
        let s = status_line(&pb);
        assert!(s.starts_with("BEM: load steps: 10/40 (25 %), "), "{s}");
        assert!(s.contains("elapsed") && s.contains("left"), "{s}");
        let sp = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden())
            .with_message("I model");
        assert!(status_line(&sp).starts_with("I model: 0.0 s elapsed"));
        assert_eq!(human_duration(Duration::from_secs(185)), "3 min 05 s");
        assert_eq!(human_duration(Duration::from_secs(3720)), "1 h 02 min");
    }

    /// The time left is the whole run's mean rate: t·(n − k)/k. On a run whose step costs
    /// grow tenfold from the first step to the last (1, 2, … 10 units, as contact grows),
    /// the estimate after each step stays within a factor 10 of the true time left and
    /// moves by less than ×2.5 between consecutive steps.
    #[test]
    fn time_left_is_the_mean_rate_and_does_not_swing() {
        let s = |x: f64| Duration::from_secs_f64(x);
        assert_eq!(eta(s(30.0), 3, 10), Some(s(70.0)));
        assert_eq!(eta(s(30.0), 0, 10), None);
        assert_eq!(eta(s(30.0), 10, 10), None);
        let cost: Vec<f64> = (1..=10).map(f64::from).collect();
        let total: f64 = cost.iter().sum();
        let mut done = 0.0;
        let mut previous: Option<f64> = None;
        for (k, c) in cost.iter().enumerate().take(9) {
            done += c;
            let left = eta(s(done), k as u64 + 1, 10).unwrap().as_secs_f64();
            let truth = total - done;
            assert!(
                left / truth < 10.0 && truth / left < 10.0,
                "{k}: {left} vs {truth}"
            );
            if let Some(p) = previous {
                let r = left / p;
                assert!(r < 2.5 && 1.0 / r < 2.5, "{k}: {p} → {left}");
            }
            previous = Some(left);
        }
    }

    #[test]
    fn a_scoped_report_takes_this_threads_lines_and_bars_only() {
        let loud = Report::new(true);
        let silent = Report::new(false);
        let other = std::thread::spawn({
            let silent = Arc::clone(&silent);
            move || {
                scoped(&silent, || {
                    log("not kept");
                    let b = bar(3, "hidden");
                    b.inc();
                    warn("kept");
                })
            }
        });
        scoped(&loud, || {
            log("simulating: x");
            let b = bar(4, "BEM: load steps");
            b.inc();
            assert_eq!(
                loud.status()
                    .map(|s| s.starts_with("BEM: load steps: 1/4 (25 %)")),
                Some(true)
            );
        });
        other.join().unwrap();
        let lines = loud.take_lines();
        assert_eq!(lines.len(), 1);
        assert_eq!(lines[0].text, "simulating: x");
        assert!(loud.take_lines().is_empty());
        // A bar dropped before its count (an error or an interrupt ended the call) is
        // still the status, and says where it stopped: not 4/4 (100 %), as it did.
        let status = loud.status().unwrap();
        assert!(
            status.starts_with("BEM: load steps: stopped at 1/4 (25 %)"),
            "{status}"
        );
        scoped(&loud, || {
            let b = bar(4, "BEM: load steps");
            (0..4).for_each(|_| b.inc());
        });
        let status = loud.status().unwrap();
        assert!(
            status.starts_with("BEM: load steps: 4/4 (100 %)") && !status.contains("left"),
            "{status}"
        );
        let quiet_lines = silent.take_lines();
        assert_eq!(
            quiet_lines,
            vec![Line {
                text: "WARNING: kept".into(),
                warning: true
            }]
        );
        assert!(silent.status().is_none());
        // outside the scope this thread has no report again
        assert!(current().is_none());
    }
}
