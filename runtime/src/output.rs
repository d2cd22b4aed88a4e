//! Safe output files: write to a temporary file beside the target, flush and sync,
//! then rename over the target. An interrupted or failed run never leaves a
//! half-written file that looks complete, and an existing file is replaced only by a
//! whole new one.
//!
//! The temporary file lives in the target's directory (a rename is atomic only within
//! one file system), is hidden (`.NAME.tmp-PID-N.EXT`) and keeps the target's
//! extension, so writers that choose a format by extension (plots, `.npy`) work
//! unchanged through [`write_atomic_with`]. It is removed when writing fails.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// The temporary path used for `path`: same directory, hidden, same extension.
fn temporary_for(path: &Path) -> std::io::Result<PathBuf> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::other(format!("{}: not a file path", path.display())))?
        .to_string_lossy();
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = match path.extension() {
        Some(ext) => format!(
            ".{name}.tmp-{}-{n}.{}",
            std::process::id(),
            ext.to_string_lossy()
        ),
        None => format!(".{name}.tmp-{}-{n}", std::process::id()),
    };
    Ok(dir.join(tmp))
}

/// Runs `write` on a temporary path beside `path` (see the module docs), syncs the
/// result to disk and renames it over `path`. On any error the temporary file is
/// removed and `path` is left as it was.
pub fn write_atomic_with<E: From<std::io::Error>>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E> {
    let tmp = temporary_for(path)?;
    let result = write(&tmp).and_then(|()| {
        let with_path =
            |e: std::io::Error| std::io::Error::new(e.kind(), format!("{}: {e}", path.display()));
        fs::File::open(&tmp)
            .and_then(|f| f.sync_all())
            .map_err(with_path)?;
        fs::rename(&tmp, path).map_err(with_path)?;
        Ok(())
    });
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Writes `bytes` to `path` atomically (temporary file + rename in the same
/// directory). Errors carry the path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_with(path, |tmp| {
        let mut f = fs::File::create(tmp)?;
        f.write_all(bytes)?;
        f.flush()
    })
    .map_err(|e| {
        let m = e.to_string();
        if m.starts_with(&path.display().to_string()) {
            e
        } else {
            std::io::Error::new(e.kind(), format!("{}: {m}", path.display()))
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temporaries(dir: &Path) -> Vec<String> {
        fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains(".tmp-"))
            .collect()
    }

    #[test]
    fn replaces_whole_file_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("strata-output-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let p = dir.join("curve.csv");
        write_atomic(&p, b"old\n").unwrap();
        write_atomic(&p, b"new contents\n").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"new contents\n");
        assert!(temporaries(&dir).is_empty());
        // A failing write (directory missing) leaves the target untouched.
        let e = write_atomic(&dir.join("missing/x.csv"), b"x").unwrap_err();
        assert!(e.to_string().contains("x.csv"), "{e}");
        assert_eq!(fs::read(&p).unwrap(), b"new contents\n");
        // The target is a directory: the rename fails, the temporary is removed.
        fs::create_dir_all(dir.join("taken.csv")).unwrap();
        let e = write_atomic(&dir.join("taken.csv"), b"x").unwrap_err();
        assert!(e.to_string().contains("taken.csv"), "{e}");
        assert!(temporaries(&dir).is_empty());
        fs::remove_dir_all(&dir).unwrap();
    }

    /// A writer that fails half-way leaves the previous file intact and no temporary;
    /// the temporary keeps the target's extension (format chosen by extension).
    #[test]
    fn failing_writer_keeps_previous_file() {
        let dir = std::env::temp_dir().join(format!("strata-output-w-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let p = dir.join("plot.svg");
        fs::write(&p, b"<svg>old</svg>").unwrap();
        let r: std::io::Result<()> = write_atomic_with(&p, |tmp| {
            assert_eq!(tmp.extension().unwrap(), "svg");
            assert_eq!(tmp.parent(), p.parent());
            fs::write(tmp, b"<svg>half")?;
            Err(std::io::Error::other("interrupted"))
        });
        assert!(r.is_err());
        assert_eq!(fs::read(&p).unwrap(), b"<svg>old</svg>");
        assert!(temporaries(&dir).is_empty());
        write_atomic_with(&p, |tmp| fs::write(tmp, b"<svg>new</svg>")).unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"<svg>new</svg>");
        fs::remove_dir_all(&dir).unwrap();
    }
}
