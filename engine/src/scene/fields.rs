//! TOML field readers of scenes: each checks one key's type and range and names the
//! offending field (`surface.size`, `load.approach.steps`, …) in its [`SceneError`].

use std::path::{Path, PathBuf};

use toml::{Table, Value};

use strata_runtime::surface::{FileKind, HeightUnit, Spacing};

use super::error::SceneError;

pub(super) fn check_keys(
    t: &Table,
    prefix: &str,
    allowed: &[&str],
    expected: &'static str,
) -> Result<(), SceneError> {
    for k in t.keys() {
        if !allowed.contains(&k.as_str()) {
            return Err(SceneError::UnknownKey {
                key: format!("{prefix}{k}"),
                expected,
            });
        }
    }
    Ok(())
}

pub(super) fn table<'a>(t: &'a Table, key: &str, field: &str) -> Result<&'a Table, SceneError> {
    match t.get(key) {
        None => Err(SceneError::Missing(field.into())),
        Some(Value::Table(x)) => Ok(x),
        Some(_) => Err(SceneError::WrongType {
            field: field.into(),
            expected: "a table",
        }),
    }
}

pub(super) fn number(v: &Value, field: &str) -> Result<f64, SceneError> {
    let x = match v {
        Value::Float(f) => *f,
        Value::Integer(i) => *i as f64,
        _ => {
            return Err(SceneError::WrongType {
                field: field.into(),
                expected: "a number",
            });
        }
    };
    if !x.is_finite() {
        return Err(SceneError::Invalid {
            field: field.into(),
            reason: format!("{x} is not finite"),
        });
    }
    Ok(x)
}

pub(super) fn positive(t: &Table, key: &str, field: &str) -> Result<f64, SceneError> {
    let v = t
        .get(key)
        .ok_or_else(|| SceneError::Missing(field.into()))?;
    let x = number(v, field)?;
    if x <= 0.0 {
        return Err(SceneError::Invalid {
            field: field.into(),
            reason: format!("{x} must be > 0"),
        });
    }
    Ok(x)
}

pub(super) fn integer(t: &Table, key: &str, field: &str) -> Result<i64, SceneError> {
    match t.get(key) {
        None => Err(SceneError::Missing(field.into())),
        Some(Value::Integer(i)) => Ok(*i),
        Some(_) => Err(SceneError::WrongType {
            field: field.into(),
            expected: "an integer",
        }),
    }
}

pub(super) fn string<'a>(
    t: &'a Table,
    key: &str,
    field: &str,
) -> Result<Option<&'a str>, SceneError> {
    match t.get(key) {
        None => Ok(None),
        Some(Value::String(s)) => Ok(Some(s)),
        Some(_) => Err(SceneError::WrongType {
            field: field.into(),
            expected: "a string",
        }),
    }
}

pub(super) fn boolean(t: &Table, key: &str, field: &str) -> Result<Option<bool>, SceneError> {
    match t.get(key) {
        None => Ok(None),
        Some(Value::Boolean(b)) => Ok(Some(*b)),
        Some(_) => Err(SceneError::WrongType {
            field: field.into(),
            expected: "true or false",
        }),
    }
}

pub(super) fn numbers(v: &Value, field: &str) -> Result<Vec<f64>, SceneError> {
    let arr = v.as_array().ok_or_else(|| SceneError::WrongType {
        field: field.into(),
        expected: "an array of numbers",
    })?;
    if arr.is_empty() {
        return Err(SceneError::Invalid {
            field: field.into(),
            reason: "must not be empty".into(),
        });
    }
    arr.iter()
        .enumerate()
        .map(|(i, x)| number(x, &format!("{field}[{i}]")))
        .collect()
}

/// A length or a pair of lengths (m), each > 0: (x, None) or (x, Some(y)).
pub(super) fn lengths(v: &Value, field: &str) -> Result<(f64, Option<f64>), SceneError> {
    let wrong = || SceneError::WrongType {
        field: field.into(),
        expected: "a length (m) or an array [x, y] of two lengths (m)",
    };
    let xs = match v {
        Value::Array(a) if a.len() == 2 => a
            .iter()
            .enumerate()
            .map(|(i, x)| {
                Ok((
                    number(x, &format!("{field}[{i}]"))?,
                    format!("{field}[{i}]"),
                ))
            })
            .collect::<Result<Vec<_>, SceneError>>()?,
        Value::Array(_) => return Err(wrong()),
        Value::Float(_) | Value::Integer(_) => vec![(number(v, field)?, field.to_string())],
        _ => return Err(wrong()),
    };
    let xs: Vec<f64> = xs
        .into_iter()
        .map(|(x, f)| {
            if x > 0.0 {
                Ok(x)
            } else {
                Err(SceneError::Invalid {
                    field: f,
                    reason: format!("{x} must be > 0 (m)"),
                })
            }
        })
        .collect::<Result<_, _>>()?;
    Ok((xs[0], xs.get(1).copied()))
}

/// The lateral scale and height unit of a surface file: from `size` or `pixel_size`
/// and `height_unit` for `.npy`/text; none of them for `.x3p` (from the file); for a
/// NetCDF topography optional (the file usually gives its sizes and unit).
pub(super) fn file_scale(
    sf: &Table,
    kind: FileKind,
) -> Result<(Option<Spacing>, Option<HeightUnit>), SceneError> {
    if kind == FileKind::X3p {
        for key in ["size", "pixel_size", "height_unit"] {
            if sf.contains_key(key) {
                return Err(SceneError::Invalid {
                    field: format!("surface.{key}"),
                    reason: "an .x3p file gives its own pixel sizes and is in metres (ISO 25178-72): remove this key".into(),
                });
            }
        }
        return Ok((None, None));
    }
    let spacing = match (sf.get("size"), sf.get("pixel_size")) {
        (Some(_), Some(_)) => {
            return Err(SceneError::Invalid {
                field: "surface.pixel_size".into(),
                reason: "give either size or pixel_size, not both".into(),
            });
        }
        // A NetCDF topography usually gives its physical sizes (the reader says when not).
        (None, None) if matches!(kind, FileKind::NetCdf | FileKind::Container) => {
            let unit = match string(sf, "height_unit", "surface.height_unit")? {
                None => None,
                Some(u) => Some(HeightUnit::parse(u).ok_or_else(|| SceneError::Invalid {
                    field: "surface.height_unit".into(),
                    reason: format!("`{u}` is not one of \"m\", \"mm\", \"um\", \"nm\""),
                })?),
            };
            return Ok((None, unit));
        }
        (None, None) => {
            return Err(SceneError::Missing(
                "surface.size (the first axis' length L or [Lx, Ly] in m; or surface.pixel_size = [dx, dy])"
                    .into(),
            ));
        }
        (Some(v), None) => match lengths(v, "surface.size")? {
            (l, None) => Spacing::Size(l),
            (lx, Some(ly)) => Spacing::Extent(lx, ly),
        },
        (None, Some(v)) => match lengths(v, "surface.pixel_size")? {
            (d, None) => Spacing::Pixel(d, d),
            (dx, Some(dy)) => Spacing::Pixel(dx, dy),
        },
    };
    let unit = match string(sf, "height_unit", "surface.height_unit")? {
        None => None,
        Some(u) => Some(HeightUnit::parse(u).ok_or_else(|| SceneError::Invalid {
            field: "surface.height_unit".into(),
            reason: format!("`{u}` is not one of \"m\", \"mm\", \"um\", \"nm\""),
        })?),
    };
    Ok((Some(spacing), unit))
}

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
