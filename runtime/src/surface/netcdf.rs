//! SurfaceTopography's NetCDF topography files (feature `netcdf`): NetCDF-3, classic or
//! 64-bit offset (what `Topography.to_netcdf` writes, through scipy), read with the
//! pure-Rust `netcdf3` crate.
//!
//! Layout (SurfaceTopography's `NCReader`): a variable `heights` on dimensions (x, y),
//! x first; optional coordinate variables `x` and `y` whose attribute `length` is the
//! physical size along that axis, `periodic` (non-zero: periodic) and the unit of
//! lengths and heights, `unit` (SurfaceTopography ≥ 1.0) or `length_unit` (older files);
//! `heights` may carry `unit` too, and `_FillValue` / `missing_value` for missing data.
//! The unit is text in UTF-8 or Latin-1 (older writers store "µm" as the one byte 0xB5);
//! a unit attribute that is a number or unreadable is refused naming it.
//! NetCDF-4 (HDF5) files are refused with a message saying so.

use std::path::Path;

use netcdf3::{Attribute, DataVector, FileReader};

use super::SurfaceError;

/// What a SurfaceTopography NetCDF file says, before units are applied.
#[derive(Debug, Clone, PartialEq)]
pub struct NetcdfTopography {
    /// Heights in the file's unit (missing values as NaN), row-major n0 × n1, x first.
    pub heights: Vec<f64>,
    /// Points along x (first axis) and y.
    pub n0: usize,
    pub n1: usize,
    /// Physical sizes (Lx, Ly) in the file's unit, when the file gives both.
    pub lengths: Option<(f64, f64)>,
    /// The `periodic` flag of `x` (or `y`), when given.
    pub periodic: Option<bool>,
    /// The unit of heights and lengths (`unit` or `length_unit`), as written.
    pub unit: Option<String>,
}

fn format_error(path: &Path, message: impl Into<String>) -> SurfaceError {
    SurfaceError::Format {
        path: path.display().to_string(),
        message: message.into(),
    }
}

/// The first number of a numeric attribute.
fn number(a: &Attribute) -> Option<f64> {
    a.get_f64()
        .and_then(|v| v.first().copied())
        .or_else(|| a.get_f32().and_then(|v| v.first().map(|&x| f64::from(x))))
        .or_else(|| a.get_i32().and_then(|v| v.first().map(|&x| f64::from(x))))
        .or_else(|| a.get_i16().and_then(|v| v.first().map(|&x| f64::from(x))))
        .or_else(|| a.get_i8().and_then(|v| v.first().map(|&x| f64::from(x))))
}

/// Opens the file's header; a NetCDF-4/HDF5 or other file is a clear error.
fn open(path: &Path) -> Result<FileReader, SurfaceError> {
    let mut magic = [0u8; 4];
    {
        use std::io::Read;
        let mut f = std::fs::File::open(path).map_err(|e| SurfaceError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let _ = f.read(&mut magic);
    }
    if &magic[1..4] == b"HDF" {
        return Err(format_error(
            path,
            "a NetCDF-4 (HDF5) file: strata reads NetCDF-3 (classic or 64-bit offset, what \
             SurfaceTopography's to_netcdf writes); convert it with `nccopy -k nc6 IN OUT`",
        ));
    }
    if &magic[..3] != b"CDF" {
        return Err(format_error(
            path,
            "not a NetCDF-3 file (no `CDF` signature)",
        ));
    }
    FileReader::open(path)
        .map_err(|e| format_error(path, format!("not a valid NetCDF-3 file: {e}")))
}

/// The `periodic` flag of a SurfaceTopography NetCDF file (`x` or `y` attribute
/// `periodic`), read from its header only; `None` when the file does not say.
pub fn netcdf_periodic(path: &Path) -> Result<Option<bool>, SurfaceError> {
    let f = open(path)?;
    Ok(periodic_flag(f.data_set()))
}

fn periodic_flag(d: &netcdf3::DataSet) -> Option<bool> {
    ["x", "y"]
        .iter()
        .filter_map(|v| d.get_var_attr(v, "periodic").and_then(number))
        .map(|p| p != 0.0)
        .reduce(|a, b| a || b)
}

/// Text of a char attribute: UTF-8, else Latin-1 (ISO 8859-1, one byte per character,
/// as older writers store "µm": byte 0xB5), trailing NULs and blanks trimmed. `None`
/// when the bytes are neither (a Latin-1 reading that holds control characters).
fn attribute_text(bytes: &[u8]) -> Option<String> {
    let text = match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => {
            // Latin-1's printable characters: 0x20–0x7E and 0xA0–0xFF (0x80–0x9F are C1
            // controls, which no unit name holds).
            if bytes
                .iter()
                .any(|&b| b != 0 && !(0x20..=0x7e).contains(&b) && b < 0xa0)
            {
                return None;
            }
            bytes.iter().map(|&b| char::from(b)).collect()
        }
    };
    Some(text.trim_end_matches('\0').trim().to_string())
}

/// The unit of heights and lengths: the first of `heights:unit`, `x:unit`,
/// `x:length_unit`, `heights:length_unit` the file has. One that is not text (a number),
/// or text in neither UTF-8 nor Latin-1, is refused naming the file, variable and
/// attribute: read as "no unit" it would silently be metres (a ×1e6 on a scan in µm).
fn unit_attribute(path: &Path, d: &netcdf3::DataSet) -> Result<Option<String>, SurfaceError> {
    for (v, a) in [
        ("heights", "unit"),
        ("x", "unit"),
        ("x", "length_unit"),
        ("heights", "length_unit"),
    ] {
        let Some(attr) = d.get_var_attr(v, a) else {
            continue;
        };
        let Some(bytes) = attr.get_u8() else {
            return Err(format_error(
                path,
                format!(
                    "attribute `{a}` of variable `{v}` is not text ({:?}): the unit of heights \
                     and lengths must be a string such as \"um\"",
                    attr.data_type()
                ),
            ));
        };
        let text = attribute_text(bytes).ok_or_else(|| {
            format_error(
                path,
                format!(
                    "attribute `{a}` of variable `{v}` is not readable text (neither UTF-8 nor \
                     Latin-1: bytes {bytes:02x?}): the unit of heights and lengths must be a \
                     string such as \"um\""
                ),
            )
        })?;
        if !text.is_empty() {
            return Ok(Some(text));
        }
    }
    Ok(None)
}

/// Reads a SurfaceTopography NetCDF topography (see the module docs), its size checked
/// against `memory` before the heights are read.
pub fn read_netcdf_topography(
    path: &Path,
    memory: &crate::resources::MemoryLimit,
) -> Result<NetcdfTopography, SurfaceError> {
    let len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    let mut f = open(path)?;
    let d = f.data_set();
    let var = d.get_var("heights").ok_or_else(|| {
        format_error(
            path,
            "no variable `heights` (SurfaceTopography's layout: heights(x, y), optional x(x) and \
             y(y) with attributes length, periodic, unit)",
        )
    })?;
    let dims = var.dim_names();
    if dims != ["x", "y"] {
        return Err(format_error(
            path,
            format!(
                "`heights` has dimensions ({}), expected (x, y): a 2-D topography (line scans are not supported)",
                dims.join(", ")
            ),
        ));
    }
    let (n0, n1) = (d.dim_size("x").unwrap_or(0), d.dim_size("y").unwrap_or(0));
    let attr = |v: &str, a: &str| d.get_var_attr(v, a);
    let unit = unit_attribute(path, d)?;
    let lengths = match (
        attr("x", "length").and_then(number),
        attr("y", "length").and_then(number),
    ) {
        (Some(lx), Some(ly)) => Some((lx, ly)),
        _ => None,
    };
    let periodic = periodic_flag(d);
    let fill: Vec<f64> = ["_FillValue", "missing_value"]
        .iter()
        .filter_map(|a| attr("heights", a).and_then(number))
        .collect();
    // The data, after its size is known to fit (about three copies are held).
    memory.check(
        format!("reading a {n0}×{n1} NetCDF height map"),
        (n0 as u64)
            .saturating_mul(n1 as u64)
            .saturating_mul(8 * 3)
            .max(len),
    )?;
    let data = f
        .read_var("heights")
        .map_err(|e| format_error(path, format!("variable `heights`: {e}")))?;
    let mut heights: Vec<f64> = match data {
        DataVector::F64(v) => v,
        DataVector::F32(v) => v.into_iter().map(f64::from).collect(),
        DataVector::I32(v) => v.into_iter().map(f64::from).collect(),
        DataVector::I16(v) => v.into_iter().map(f64::from).collect(),
        DataVector::I8(v) => v.into_iter().map(f64::from).collect(),
        DataVector::U8(_) => {
            return Err(format_error(path, "`heights` is text (char), not numbers"));
        }
    };
    if heights.len() != n0 * n1 {
        return Err(format_error(
            path,
            format!("`heights` holds {} values, not {n0}×{n1}", heights.len()),
        ));
    }
    for h in heights.iter_mut() {
        if fill.contains(h) {
            *h = f64::NAN;
        }
    }
    Ok(NetcdfTopography {
        heights,
        n0,
        n1,
        lengths,
        periodic,
        unit,
    })
}
