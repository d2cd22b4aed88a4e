//! Safe output files: write to a temporary file beside the target, flush and sync,
//! then rename over the target. An interrupted or failed run never leaves a
//! half-written file that looks complete, and an existing file is replaced only by a
//! whole new one.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically (temporary file + rename in the same
/// directory). Errors carry the path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::other(format!("{}: not a file path", path.display())))?;
    let tmp = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", path.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_whole_file_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("strata-output-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let p = dir.join("curve.csv");
        write_atomic(&p, b"old\n").unwrap();
        write_atomic(&p, b"new contents\n").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"new contents\n");
        let leftovers: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
            .collect();
        assert!(leftovers.is_empty());
        // A failing write (directory missing) leaves the target untouched.
        assert!(write_atomic(&dir.join("missing/x.csv"), b"x").is_err());
        assert_eq!(fs::read(&p).unwrap(), b"new contents\n");
        fs::remove_dir_all(&dir).unwrap();
    }
}
