//! File readers: `.npy` (feature `npy`) and plain-text height matrices.

use std::path::Path;

#[cfg(feature = "npy")]
use ndarray::Array2;
#[cfg(feature = "npy")]
use ndarray_npy::{ReadNpyError, ReadNpyExt};

use super::{Repair, Surface, SurfaceError};

impl Surface {
    #[cfg(feature = "npy")]
    /// Reads a 2-D f64 `.npy` height map (m). Wrong dtype or dimensionality, non-finite
    /// heights and spikes are errors naming the file (and the grid index).
    pub fn read_npy(path: &Path, size: f64, periodic: bool) -> Result<Self, SurfaceError> {
        Self::read_npy_with(path, size, periodic, Repair::Refuse)
    }

    #[cfg(feature = "npy")]
    /// [`Surface::read_npy`] with a choice of [`Repair`].
    pub fn read_npy_with(
        path: &Path,
        size: f64,
        periodic: bool,
        repair: Repair,
    ) -> Result<Self, SurfaceError> {
        let p = path.display().to_string();
        let file = std::fs::File::open(path).map_err(|e| SurfaceError::Io {
            path: p.clone(),
            message: e.to_string(),
        })?;
        check_npy_size(path).map_err(|message| SurfaceError::Format {
            path: p.clone(),
            message,
        })?;
        let arr = Array2::<f64>::read_npy(std::io::BufReader::new(file)).map_err(|e| {
            let message = match e {
                ReadNpyError::WrongNdim(exp, got) => format!(
                    "wrong shape: expected a 2-D array, found {got} dimension(s) (expected {exp:?})"
                ),
                ReadNpyError::WrongDescriptor(d) => {
                    format!("wrong dtype: expected little-endian float64 ('<f8'), found {d}")
                }
                other => format!("not a valid .npy file: {other}"),
            };
            SurfaceError::Format {
                path: p.clone(),
                message,
            }
        })?;
        let (n0, n1) = arr.dim();
        let z: Vec<f64> = arr.iter().copied().collect(); // logical (C) order
        Surface::measured(z, n0, n1, size, periodic, repair).map_err(|e| SurfaceError::Format {
            path: p,
            message: e.to_string(),
        })
    }

    /// Reads a plain-text matrix of heights (m): one grid row per line, values
    /// separated by whitespace and/or commas, `#` comments and blank lines ignored.
    /// `nan`/`inf` entries and spikes are errors naming the file and the grid index.
    pub fn read_text(path: &Path, size: f64, periodic: bool) -> Result<Self, SurfaceError> {
        Self::read_text_with(path, size, periodic, Repair::Refuse)
    }

    /// [`Surface::read_text`] with a choice of [`Repair`].
    pub fn read_text_with(
        path: &Path,
        size: f64,
        periodic: bool,
        repair: Repair,
    ) -> Result<Self, SurfaceError> {
        let p = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SurfaceError::Io {
            path: p.clone(),
            message: e.to_string(),
        })?;
        let mut z = Vec::new();
        let (mut n0, mut n1) = (0usize, 0usize);
        for (ln, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let mut count = 0;
            for tok in line
                .split(|c: char| c == ',' || c.is_whitespace())
                .filter(|t| !t.is_empty())
            {
                let v: f64 = tok.parse().map_err(|_| SurfaceError::Format {
                    path: p.clone(),
                    message: format!("line {}: `{tok}` is not a number", ln + 1),
                })?;
                z.push(v);
                count += 1;
            }
            if n0 == 0 {
                n1 = count;
            } else if count != n1 {
                return Err(SurfaceError::Format {
                    path: p,
                    message: format!(
                        "line {}: {count} values but the first row has {n1} (ragged matrix)",
                        ln + 1
                    ),
                });
            }
            n0 += 1;
        }
        Surface::measured(z, n0, n1, size, periodic, repair).map_err(|e| SurfaceError::Format {
            path: p,
            message: e.to_string(),
        })
    }
}

/// Checks a `.npy` header's shape against the file's length and the memory limit
/// before ndarray-npy allocates the array it claims (a 928-byte file may claim
/// 100000×100000). Float64 data; the reader holds about three copies (array, heights,
/// surface). Headers it cannot parse are left to ndarray-npy's own errors.
#[cfg(feature = "npy")]
fn check_npy_size(path: &Path) -> Result<(), String> {
    use std::io::Read;
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let len = file.metadata().map_err(|e| e.to_string())?.len();
    let mut head = Vec::new();
    file.take(65_536 + 12)
        .read_to_end(&mut head)
        .map_err(|e| e.to_string())?;
    if head.len() < 10 || &head[..6] != b"\x93NUMPY" {
        return Ok(());
    }
    let (start, hlen) = if head[6] == 1 {
        (10, u16::from_le_bytes([head[8], head[9]]) as usize)
    } else if head.len() >= 12 {
        (
            12,
            u32::from_le_bytes([head[8], head[9], head[10], head[11]]) as usize,
        )
    } else {
        return Ok(());
    };
    let Some(text) = head.get(start..start + hlen).map(String::from_utf8_lossy) else {
        return Ok(());
    };
    if !text.contains("f8'") {
        return Ok(()); // another dtype: ndarray-npy refuses it before allocating
    }
    let Some(shape) = text
        .split_once("'shape'")
        .and_then(|(_, r)| r.split_once('('))
        .and_then(|(_, r)| r.split_once(')'))
        .map(|(inside, _)| inside)
    else {
        return Ok(());
    };
    let dims: Vec<u64> = shape
        .split(',')
        .map(str::trim)
        .filter(|d| !d.is_empty())
        .filter_map(|d| d.parse().ok())
        .collect();
    let count = dims.iter().try_fold(1u64, |n, &d| n.checked_mul(d));
    let data = len.saturating_sub((start + hlen) as u64);
    let shown = dims
        .iter()
        .map(u64::to_string)
        .collect::<Vec<_>>()
        .join("×");
    match count.and_then(|c| c.checked_mul(8)) {
        Some(bytes) if bytes <= data => crate::resources::check_memory(
            format!("reading a {shown} height map"),
            bytes.saturating_mul(3),
        )
        .map_err(|e| e.to_string()),
        _ => Err(format!(
            "the header claims a {shown} array of float64 but the file holds only {data} bytes of data: truncated, or not a valid .npy file"
        )),
    }
}
