//! The measurement harness every stage shares: the mode and its repetition counts,
//! the inputs, the runner (deterministic errors on one thread, median times on all
//! cores), the deterministic error rows and the number formats.

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use strata_tablegen::fredholm::clear_upper_simd;

/// How much to measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Seconds: for the end-to-end test (coarse everything).
    Tiny,
    /// Under 3 minutes on 2 cores: the committed report.
    Quick,
    /// The full study (finer grids, BEM reference at n = 512).
    Full,
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Tiny => "tiny",
            Mode::Quick => "quick",
            Mode::Full => "full",
        }
    }

    /// The command line that runs this mode.
    pub fn flag(self) -> &'static str {
        match self {
            Mode::Tiny => " --tiny",
            Mode::Quick => " --quick",
            Mode::Full => "",
        }
    }

    /// Repetitions of timed runs.
    pub fn reps(self) -> Reps {
        match self {
            Mode::Tiny => Reps {
                min_runs: 1,
                max_runs: 3,
                budget: 0.05,
            },
            Mode::Quick => Reps {
                min_runs: 3,
                max_runs: 7,
                budget: 0.5,
            },
            Mode::Full => Reps {
                min_runs: 5,
                max_runs: 15,
                budget: 3.0,
            },
        }
    }
}

/// Inputs of the study (files of the repository).
#[derive(Debug, Clone)]
pub struct Inputs {
    /// Scene of the rough-contact stage (surface, stack E₂/E₁ = 1, table).
    pub scene: PathBuf,
    /// Family table of the paper's stacks (approximation stage; the scene's table).
    pub table: PathBuf,
    /// The memory limit of the inputs' reading (`--memory-limit`, else
    /// `STRATA_MEMORY_LIMIT`, else 75 % of the machine's memory).
    pub memory: strata_runtime::resources::MemoryLimit,
}

/// Timed repetitions: `min_runs ≤ runs ≤ max_runs`, as many as fit in `budget` s
/// (estimated from the first run).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reps {
    pub min_runs: usize,
    pub max_runs: usize,
    pub budget: f64,
}

/// A measured wall time: median of `runs` runs, and the fastest and slowest (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    pub median: f64,
    pub runs: usize,
    pub min: f64,
    pub max: f64,
}

impl Timing {
    /// (max − min)/median: the spread of the runs.
    pub fn spread(&self) -> f64 {
        (self.max - self.min) / self.median
    }
}

/// Runs computations for values (deterministically) and for times (all cores).
pub struct Runner {
    pub mode: Mode,
    pub reps: Reps,
    single: rayon::ThreadPool,
    /// Every timing taken, for `timings.csv`: (stage, case, timing).
    pub log: Vec<(String, String, Timing)>,
}

impl Runner {
    pub fn new(mode: Mode) -> Result<Self> {
        let single = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .context("creating the one-thread pool for deterministic values")?;
        Ok(Runner {
            mode,
            reps: mode.reps(),
            single,
            log: Vec::new(),
        })
    }

    /// Runs `f` on the one-thread pool: parallel reductions inside sum in a fixed
    /// order, so the value is the same on every run (the errors of the report).
    pub fn exact<T: Send>(&self, f: impl FnOnce() -> T + Send) -> T {
        self.single.install(f)
    }

    /// Clears the upper SIMD register state on every thread that runs study code
    /// (this one, the global rayon workers and the one-thread pool).
    ///
    /// Why: see [`clear_upper_simd`] (the Fredholm solver clears the state after its
    /// own parallel LUs; clearing it again before every timed run times each item as in
    /// a fresh process, whatever ran before it).
    pub fn reset_simd(&self) {
        clear_upper_simd();
        rayon::broadcast(|_| clear_upper_simd());
        self.single.broadcast(|_| clear_upper_simd());
    }

    /// Median wall time of `f` on the global pool (all cores), with the mode's
    /// repetitions; recorded under (stage, case).
    pub fn time<T>(
        &mut self,
        stage: &str,
        case: &str,
        f: impl FnMut() -> Result<T>,
    ) -> Result<Timing> {
        Ok(self.time_value(stage, case, f)?.1)
    }

    /// As [`Runner::time`], returning the value of the first run too (for computations
    /// that are deterministic on any pool, such as table builds).
    pub fn time_value<T>(
        &mut self,
        stage: &str,
        case: &str,
        f: impl FnMut() -> Result<T>,
    ) -> Result<(T, Timing)> {
        self.time_value_with(self.reps, stage, case, f)
    }

    /// As [`Runner::time_value`] with other repetitions (for items of many seconds).
    pub fn time_value_with<T>(
        &mut self,
        reps: Reps,
        stage: &str,
        case: &str,
        f: impl FnMut() -> Result<T>,
    ) -> Result<(T, Timing)> {
        let (v, t) = median_time(reps, || self.reset_simd(), f)?;
        self.log.push((stage.to_string(), case.to_string(), t));
        Ok((v, t))
    }

    /// Time per call (s) of a fast `f`, measured over batches of `batch` calls.
    pub fn time_batch<T>(
        &mut self,
        stage: &str,
        case: &str,
        batch: usize,
        mut f: impl FnMut(usize) -> T,
    ) -> Result<Timing> {
        let reps = Reps {
            min_runs: self.reps.min_runs.max(5),
            max_runs: self.reps.max_runs.max(5),
            budget: self.reps.budget.min(0.2),
        };
        let ((), t) = median_time(
            reps,
            || self.reset_simd(),
            || {
                for i in 0..batch {
                    black_box(f(black_box(i)));
                }
                Ok(())
            },
        )?;
        let b = batch.max(1) as f64;
        let per = Timing {
            median: t.median / b,
            runs: t.runs,
            min: t.min / b,
            max: t.max / b,
        };
        self.log.push((stage.to_string(), case.to_string(), per));
        Ok(per)
    }
}

/// Median wall time (s) of `f` and the value of its first run: the first run
/// estimates how many runs fit in the budget; all runs count. `prepare` runs before
/// each run, outside the timed region.
pub fn median_time<T>(
    reps: Reps,
    prepare: impl Fn(),
    mut f: impl FnMut() -> Result<T>,
) -> Result<(T, Timing)> {
    prepare();
    let t0 = Instant::now();
    let value = f()?;
    let first = t0.elapsed().as_secs_f64();
    let want = if first > 0.0 {
        ((reps.budget / first).floor() as usize).clamp(reps.min_runs, reps.max_runs)
    } else {
        reps.max_runs
    };
    let mut times = vec![first];
    while times.len() < want.max(1) {
        prepare();
        let t = Instant::now();
        black_box(f()?);
        times.push(t.elapsed().as_secs_f64());
    }
    Ok((
        value,
        Timing {
            median: median(&mut times),
            runs: times.len(),
            min: times.iter().copied().fold(f64::INFINITY, f64::min),
            max: times.iter().copied().fold(0.0, f64::max),
        },
    ))
}

/// Median of a non-empty slice (sorts it).
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Deterministic rows of `errors.csv`: (stage, case, quantity, value).
#[derive(Debug, Default)]
pub struct Errors {
    pub rows: Vec<(String, String, String, f64)>,
}

impl Errors {
    pub fn push(&mut self, stage: &str, case: &str, quantity: &str, value: f64) {
        self.rows
            .push((stage.into(), case.into(), quantity.into(), value));
    }

    /// CSV `stage,case,quantity,value` (quoted where needed), values with 10
    /// significant digits.
    pub fn csv(&self) -> Result<String> {
        Ok(crate::csv_out::text(
            ["stage", "case", "quantity", "value"],
            self.rows.iter().map(|(st, c, q, v)| {
                [
                    st.to_string(),
                    c.to_string(),
                    q.to_string(),
                    format!("{v:.9e}"),
                ]
            }),
        )?)
    }
}

/// Formats a relative error with 3 significant digits ("0" for exact zero).
pub fn fmt_err(e: f64) -> String {
    if e == 0.0 {
        "0".into()
    } else if !e.is_finite() {
        "—".into()
    } else {
        format!("{e:.2e}")
    }
}

/// Formats a time (s) in a readable unit.
pub fn fmt_time(t: f64) -> String {
    if !t.is_finite() {
        "—".into()
    } else if t < 1e-6 {
        format!("{:.1} ns", t * 1e9)
    } else if t < 1e-3 {
        format!("{:.2} µs", t * 1e6)
    } else if t < 1.0 {
        format!("{:.2} ms", t * 1e3)
    } else {
        format!("{t:.2} s")
    }
}
