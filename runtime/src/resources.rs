//! Resource checks before large allocations: every solver that allocates in proportion
//! to its input (grids, summit pairs, tables, file headers) estimates the bytes it needs
//! and asks its [`MemoryLimit`] first ([`MemoryLimit::check`]), so that an impossible
//! request fails with a message naming the estimate and the limit instead of aborting
//! the process.
//!
//! The limit is a value passed in, a field of every solver's options (`rough::Params`,
//! `interface::SampleOptions`, `surface::ReadOptions`, …): two solves in one process
//! may run under two limits. Nothing here reads the environment; the front ends decide
//! the limit at their edge, in order of precedence:
//! 1. their own setting (the command line's `--memory-limit`): [`MemoryLimit::parse`]
//!    with [`MemoryLimit::SET_BY_CALLER`];
//! 2. the environment variable `STRATA_MEMORY_LIMIT` ([`MemoryLimit::ENV_VAR`]: bytes, or
//!    with a suffix `k`, `M`, `G`, `T`: powers of 1024; e.g. `STRATA_MEMORY_LIMIT=512M`),
//!    whose value the front end hands to [`MemoryLimit::from_setting`];
//! 3. `DEFAULT_FRACTION` of the machine's memory (`MemTotal` of `/proc/meminfo`;
//!    `FALLBACK_LIMIT` where that cannot be read): [`MemoryLimit::of_machine`], the
//!    [`Default`].

use thiserror::Error;

/// Fraction of the machine's memory a single request may take by default.
pub(crate) const DEFAULT_FRACTION: f64 = 0.75;
/// The default limit where the machine's memory cannot be read: 8 GiB.
pub(crate) const FALLBACK_LIMIT: u64 = 8 << 30;

/// A request above the memory limit, or an unreadable limit setting.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ResourceError {
    #[error(
        "{what} needs about {} but the memory limit is {} ({source_of_limit}); \
         reduce the problem or raise the limit (--memory-limit, STRATA_MEMORY_LIMIT)",
        human_bytes(*needed),
        human_bytes(*limit)
    )]
    Memory {
        what: String,
        needed: u64,
        limit: u64,
        source_of_limit: &'static str,
    },
    #[error(
        "memory limit `{0}` is invalid: expected bytes, optionally with k, M, G or T (powers of 1024), e.g. 512M"
    )]
    BadLimit(String),
    #[error(
        "STRATA_MEMORY_LIMIT = `{0}` is invalid: expected bytes, optionally with k, M, G or T (powers of 1024), e.g. 512M"
    )]
    BadEnvLimit(String),
}

/// Bytes in a readable unit (powers of 1024), e.g. `28.75 GiB`.
pub fn human_bytes(b: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.2} {}", UNITS[u])
    }
}

/// Parses a size such as `123456`, `512M`, `1.5G` (powers of 1024).
pub fn parse_bytes(text: &str) -> Result<u64, ResourceError> {
    let t = text.trim();
    let bad = || ResourceError::BadLimit(text.to_string());
    let (num, mul) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let m: u64 = match c.to_ascii_uppercase() {
                'K' => 1 << 10,
                'M' => 1 << 20,
                'G' => 1 << 30,
                'T' => 1 << 40,
                'B' => 1,
                _ => return Err(bad()),
            };
            (&t[..i], m)
        }
        _ => (t, 1),
    };
    let v: f64 = num.trim().parse().map_err(|_| bad())?;
    if !(v.is_finite() && v > 0.0) {
        return Err(bad());
    }
    let bytes = v * mul as f64;
    if bytes >= u64::MAX as f64 {
        return Err(bad());
    }
    Ok(bytes as u64)
}

/// Total memory of the machine (bytes) from `/proc/meminfo`, if readable (read once:
/// a fact of the machine, not a setting).
pub(crate) fn machine_memory() -> Option<u64> {
    static TOTAL: std::sync::OnceLock<Option<u64>> = std::sync::OnceLock::new();
    *TOTAL.get_or_init(read_machine_memory)
}

fn read_machine_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// The largest single allocation a solve may attempt (bytes) and where that figure
/// comes from (named in the refusal's message). A plain value: each solve carries its
/// own in its options.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryLimit {
    /// The limit (bytes, > 0).
    pub bytes: u64,
    /// Where the limit comes from, e.g. [`MemoryLimit::SET_BY_CALLER`],
    /// [`MemoryLimit::ENV_VAR`] or [`MemoryLimit::MACHINE`].
    pub source: &'static str,
}

impl MemoryLimit {
    /// The source of a limit given by the caller (`--memory-limit`).
    pub const SET_BY_CALLER: &'static str = "set by the caller";
    /// The environment variable the front ends read (and the source it names).
    pub const ENV_VAR: &'static str = "STRATA_MEMORY_LIMIT";
    /// The source of the machine default.
    pub const MACHINE: &'static str = "75 % of the machine's memory";

    /// A limit of `bytes` from `source`.
    pub const fn new(bytes: u64, source: &'static str) -> MemoryLimit {
        MemoryLimit { bytes, source }
    }

    /// 75 % of the machine's memory (`MemTotal` of `/proc/meminfo`), 8 GiB where that
    /// cannot be read.
    pub fn of_machine() -> MemoryLimit {
        match machine_memory() {
            Some(m) => MemoryLimit::new((m as f64 * DEFAULT_FRACTION) as u64, Self::MACHINE),
            None => MemoryLimit::new(FALLBACK_LIMIT, "default 8 GiB"),
        }
    }

    /// A size such as `123456`, `512M`, `1.5G` (powers of 1024; [`parse_bytes`]) from
    /// `source`; a bad size is [`ResourceError::BadLimit`].
    pub fn parse(text: &str, source: &'static str) -> Result<MemoryLimit, ResourceError> {
        Ok(MemoryLimit::new(parse_bytes(text)?, source))
    }

    /// The limit of the environment's setting: `value` is that of `STRATA_MEMORY_LIMIT`
    /// (which the front end reads); `None` gives [`MemoryLimit::of_machine`]. A bad value is
    /// [`ResourceError::BadEnvLimit`] (naming the variable).
    pub fn from_setting(value: Option<&str>) -> Result<MemoryLimit, ResourceError> {
        match value {
            Some(v) => MemoryLimit::parse(v, Self::ENV_VAR)
                .map_err(|_| ResourceError::BadEnvLimit(v.to_string())),
            None => Ok(MemoryLimit::of_machine()),
        }
    }

    /// Checks that `what` may allocate about `needed` bytes. Call it before the
    /// allocation, with an estimate from sizes known up front (grid points, pairs,
    /// header shapes).
    pub fn check(&self, what: impl Into<String>, needed: u64) -> Result<(), ResourceError> {
        if needed > self.bytes {
            return Err(ResourceError::Memory {
                what: what.into(),
                needed,
                limit: self.bytes,
                source_of_limit: self.source,
            });
        }
        Ok(())
    }
}

impl Default for MemoryLimit {
    /// [`MemoryLimit::of_machine`].
    fn default() -> Self {
        MemoryLimit::of_machine()
    }
}

/// `count × size` in bytes, saturating (an estimate never overflows into a small number).
pub fn bytes_for(count: u64, size: u64) -> u64 {
    count.saturating_mul(size)
}

/// The size cap on a text input file (stack, scene, sweep): 16 MiB. A thousand-layer
/// stack is about 100 kB; the cap stops an endless stream (`/dev/zero`, a FIFO) or a huge
/// file early instead of reading it into memory.
pub const TEXT_FILE_CAP: u64 = 16 << 20;

/// Reads the whole of a text input file (`what`: "a stack file", "a scene file", ...),
/// refusing one larger than `cap` bytes or than `limit`, whichever is smaller.
/// At most `cap + 1` bytes are read, so an endless stream is refused after that many.
/// The error names the cap (or limit); the caller names the file.
pub fn read_text_capped(
    path: &std::path::Path,
    cap: u64,
    what: &str,
    limit: &MemoryLimit,
) -> std::io::Result<String> {
    let bytes = read_capped(path, cap, what, limit)?;
    String::from_utf8(bytes).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("{what} must be UTF-8 text"),
        )
    })
}

/// Reads the whole of an input file as bytes, refusing one larger than `cap` bytes or
/// than `limit` (whichever is smaller); see [`read_text_capped`].
pub(crate) fn read_capped(
    path: &std::path::Path,
    cap: u64,
    what: &str,
    limit: &MemoryLimit,
) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let MemoryLimit {
        bytes: limit,
        source,
    } = *limit;
    let (bound, named) = if cap <= limit {
        (cap, format!("the {} cap on {what}", human_bytes(cap)))
    } else {
        (
            limit,
            format!("the memory limit {} ({source})", human_bytes(limit)),
        )
    };
    let too_big = || {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("larger than {named}; not read"),
        )
    };
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    if meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("a directory, not {what}"),
        ));
    }
    if meta.is_file() && meta.len() > bound {
        return Err(too_big());
    }
    let mut v = Vec::with_capacity(if meta.is_file() {
        meta.len() as usize
    } else {
        0
    });
    file.take(bound.saturating_add(1)).read_to_end(&mut v)?;
    if v.len() as u64 > bound {
        return Err(too_big());
    }
    Ok(v)
}

/// Reads the whole of a data file (a table, a cache file) that has no size cap of its
/// own: it must be a regular file (a device or FIFO can be an endless stream) and no
/// larger than `limit`.
pub fn read_data_file(
    path: &std::path::Path,
    what: &str,
    limit: &MemoryLimit,
) -> std::io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() && !meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("not a regular file (a device, FIFO or socket); {what} is read from a file"),
        ));
    }
    read_capped(path, u64::MAX, what, limit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_sizes_and_refuses_nonsense() {
        assert_eq!(parse_bytes("1024").unwrap(), 1024);
        assert_eq!(parse_bytes("512M").unwrap(), 512 << 20);
        assert_eq!(parse_bytes("1.5G").unwrap(), 3 << 29);
        assert_eq!(parse_bytes(" 2k ").unwrap(), 2048);
        for bad in ["", "-1", "0", "abc", "12Q", "1e400", "nan"] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn check_names_estimate_and_limit() {
        let limit = MemoryLimit::new(1 << 20, "test");
        let e = limit.check("BEM grid 16384²", 28 << 30).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("BEM grid 16384²"), "{msg}");
        assert!(msg.contains("28.00 GiB"), "{msg}");
        assert!(msg.contains("1.00 MiB"), "{msg}");
        assert!(limit.check("small", 1000).is_ok());
        assert_eq!(bytes_for(u64::MAX, 8), u64::MAX);
        assert_eq!(human_bytes(512), "512 B");
    }
}
