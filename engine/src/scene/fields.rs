//! File fields of scenes: a path resolved against the scene's directory, and the
//! check that it names an existing file.

use std::path::{Path, PathBuf};

use super::error::SceneError;

pub(super) fn resolve(dir: &Path, p: &str) -> PathBuf {
    let p = Path::new(p);
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        dir.join(p)
    }
}

/// Resolves the file field `field` = `value` against `dir` and requires the file.
pub(super) fn existing_file(
    dir: &Path,
    field: &'static str,
    value: &str,
    hint: &'static str,
) -> Result<PathBuf, SceneError> {
    let p = resolve(dir, value);
    if p.is_file() {
        return Ok(p);
    }
    let shown = if dir.as_os_str().is_empty() {
        ".".to_string()
    } else {
        dir.display().to_string()
    };
    Err(SceneError::MissingFile {
        field,
        what: if p.is_dir() {
            "a directory, not a file:"
        } else {
            "no such file"
        },
        value: value.to_string(),
        resolved: p.display().to_string(),
        dir: shown,
        hint,
    })
}
