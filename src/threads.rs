//! Worker threads: one cap for every command. The global rayon pool (what `solve`,
//! `table build`, `asperity`, … run their parallel loops on) is built once at start-up
//! ([`init_global_pool`], from [`crate::cli::main`]) with `RAYON_NUM_THREADS` threads
//! (default: one per core); `sweep --threads` sizes a pool of its own with
//! [`thread_count`]. Either count is
//! refused above [`THREADS_PER_CORE`] per core: the work is CPU-bound, more threads only
//! add memory and contention, and `RAYON_NUM_THREADS=100000` would otherwise spawn
//! threads until the process or the machine gives out.

use thiserror::Error;

/// Most worker threads per core that `--threads` or `RAYON_NUM_THREADS` may ask for.
pub const THREADS_PER_CORE: usize = 4;

/// A thread count that is refused, or a pool that could not be started.
#[derive(Debug, Error)]
pub enum ThreadsError {
    #[error("RAYON_NUM_THREADS = `{0}`: not a number of threads")]
    NotANumber(String),
    #[error(
        "{from} {n}: at most {cap} worker threads ({THREADS_PER_CORE} per core, {cores} core(s) here)"
    )]
    TooMany {
        from: &'static str,
        n: usize,
        cap: usize,
        cores: usize,
    },
    #[error("{from}: cannot start the worker threads: {error}")]
    Start {
        from: &'static str,
        error: rayon::ThreadPoolBuildError,
    },
}

/// The number of cores (logical CPUs this process may use; 1 when unknown).
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The worker-thread count: `flag` (its name and value, e.g. `("--threads", 8)`), else
/// `RAYON_NUM_THREADS`, else 0 (one per core); refused above [`THREADS_PER_CORE`] per
/// core. Also returns where the count came from, for messages.
pub fn thread_count(
    flag: Option<(&'static str, usize)>,
) -> Result<(usize, &'static str), ThreadsError> {
    let cores = cores();
    let cap = THREADS_PER_CORE * cores;
    let (n, from) = match flag {
        Some((name, n)) => (n, name),
        None => match std::env::var("RAYON_NUM_THREADS") {
            Ok(v) => (
                v.trim()
                    .parse()
                    .map_err(|_| ThreadsError::NotANumber(v.clone()))?,
                "RAYON_NUM_THREADS",
            ),
            Err(_) => (0, "default"),
        },
    };
    if n > cap {
        return Err(ThreadsError::TooMany {
            from,
            n,
            cap,
            cores,
        });
    }
    Ok((n, from))
}

/// Builds the global rayon pool with [`thread_count`]`(None)` threads (0: one per
/// core). Call once, before anything runs in parallel; returns the pool's size.
pub fn init_global_pool() -> Result<usize, ThreadsError> {
    let (n, from) = thread_count(None)?;
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .map_err(|error| ThreadsError::Start { from, error })?;
    Ok(rayon::current_num_threads())
}
