//! Resource checks before large allocations: every solver that allocates in proportion
//! to its input (grids, summit pairs, tables, file headers) estimates the bytes it needs
//! and asks [`check_memory`] first, so that an impossible request fails with a message
//! naming the estimate and the limit instead of aborting the process.
//!
//! The limit, in order of precedence:
//! 1. [`set_memory_limit`] (the command line's `--memory-limit`, the C ABI, Python);
//! 2. the environment variable `STRATA_MEMORY_LIMIT` (bytes, or with a suffix
//!    `k`, `M`, `G`, `T`: powers of 1024; e.g. `STRATA_MEMORY_LIMIT=512M`);
//! 3. `DEFAULT_FRACTION` of the machine's memory (`MemTotal` of `/proc/meminfo`;
//!    `FALLBACK_LIMIT` where that cannot be read).

use std::sync::atomic::{AtomicU64, Ordering};

use thiserror::Error;

/// Fraction of the machine's memory a single request may take by default.
pub(crate) const DEFAULT_FRACTION: f64 = 0.75;
/// The default limit where the machine's memory cannot be read: 8 GiB.
pub(crate) const FALLBACK_LIMIT: u64 = 8 << 30;

/// 0 = not set (use the environment or the machine).
static LIMIT: AtomicU64 = AtomicU64::new(0);

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

/// Sets the process-wide limit (bytes); 0 returns to the environment/machine default.
pub fn set_memory_limit(bytes: u64) {
    LIMIT.store(bytes, Ordering::Relaxed);
}

/// Total memory of the machine (bytes) from `/proc/meminfo`, if readable.
pub(crate) fn machine_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// The limit in force (bytes) and where it comes from.
pub fn memory_limit() -> Result<(u64, &'static str), ResourceError> {
    let set = LIMIT.load(Ordering::Relaxed);
    if set > 0 {
        return Ok((set, "set by the caller"));
    }
    if let Ok(v) = std::env::var("STRATA_MEMORY_LIMIT") {
        let limit = parse_bytes(&v).map_err(|_| ResourceError::BadEnvLimit(v.clone()))?;
        return Ok((limit, "STRATA_MEMORY_LIMIT"));
    }
    Ok(match machine_memory() {
        Some(m) => (
            (m as f64 * DEFAULT_FRACTION) as u64,
            "75 % of the machine's memory",
        ),
        None => (FALLBACK_LIMIT, "default 8 GiB"),
    })
}

/// Checks that `what` may allocate about `needed` bytes. Call it before the allocation,
/// with an estimate from sizes known up front (grid points, pairs, header shapes).
pub fn check_memory(what: impl Into<String>, needed: u64) -> Result<(), ResourceError> {
    check_against(what, needed, memory_limit()?)
}

/// [`check_memory`] against an explicit `(limit, where the limit comes from)`.
pub fn check_against(
    what: impl Into<String>,
    needed: u64,
    (limit, source_of_limit): (u64, &'static str),
) -> Result<(), ResourceError> {
    if needed > limit {
        return Err(ResourceError::Memory {
            what: what.into(),
            needed,
            limit,
            source_of_limit,
        });
    }
    Ok(())
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
/// refusing one larger than `cap` bytes or than the memory limit, whichever is smaller.
/// At most `cap + 1` bytes are read, so an endless stream is refused after that many.
/// The error names the cap (or limit); the caller names the file.
pub fn read_text_capped(path: &std::path::Path, cap: u64, what: &str) -> std::io::Result<String> {
    let bytes = read_capped(path, cap, what)?;
    String::from_utf8(bytes).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("{what} must be UTF-8 text"),
        )
    })
}

/// Reads the whole of an input file as bytes, refusing one larger than `cap` bytes or
/// than the memory limit (whichever is smaller); see [`read_text_capped`].
pub(crate) fn read_capped(
    path: &std::path::Path,
    cap: u64,
    what: &str,
) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let (limit, source) = memory_limit().map_err(std::io::Error::other)?;
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
/// larger than the memory limit.
pub fn read_data_file(path: &std::path::Path, what: &str) -> std::io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() && !meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("not a regular file (a device, FIFO or socket); {what} is read from a file"),
        ));
    }
    read_capped(path, u64::MAX, what)
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
        let limit = (1 << 20, "test");
        let e = check_against("BEM grid 16384²", 28 << 30, limit).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("BEM grid 16384²"), "{msg}");
        assert!(msg.contains("28.00 GiB"), "{msg}");
        assert!(msg.contains("1.00 MiB"), "{msg}");
        assert!(check_against("small", 1000, limit).is_ok());
        assert_eq!(bytes_for(u64::MAX, 8), u64::MAX);
        assert_eq!(human_bytes(512), "512 B");
    }
}
