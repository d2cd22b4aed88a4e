//! File readers: [`Surface::read`] by extension (`.x3p`, `.npy`, `.nc`, else text), the
//! `.npy` (feature `npy`), SurfaceTopography NetCDF (feature `netcdf`) and plain-text
//! readers, and the `.npy` writer.

use std::path::Path;

#[cfg(feature = "npy")]
use ndarray::Array2;
#[cfg(feature = "npy")]
use ndarray_npy::{ReadNpyError, ReadNpyExt};

use super::{Detrend, Repair, Spacing, Surface, SurfaceError};
use crate::resources::MemoryLimit;

/// The unit of the heights in a `.npy` or text file (scene `height_unit`); `.x3p`
/// files are in metres by the standard.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HeightUnit {
    /// Metres (default).
    #[default]
    M,
    /// Millimetres.
    Mm,
    /// Micrometres.
    Um,
    /// Nanometres.
    Nm,
}

impl HeightUnit {
    /// Parses `"m" | "mm" | "um" | "µm" | "nm"`.
    pub fn parse(s: &str) -> Option<HeightUnit> {
        match s {
            "m" => Some(HeightUnit::M),
            "mm" => Some(HeightUnit::Mm),
            "um" | "µm" | "μm" => Some(HeightUnit::Um),
            "nm" => Some(HeightUnit::Nm),
            _ => None,
        }
    }
    /// Metres per unit.
    pub fn metres(self) -> f64 {
        match self {
            HeightUnit::M => 1.0,
            HeightUnit::Mm => 1e-3,
            HeightUnit::Um => 1e-6,
            HeightUnit::Nm => 1e-9,
        }
    }
    /// The scene value.
    pub fn name(self) -> &'static str {
        match self {
            HeightUnit::M => "m",
            HeightUnit::Mm => "mm",
            HeightUnit::Um => "um",
            HeightUnit::Nm => "nm",
        }
    }
}

/// How [`Surface::read`] interprets a file.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReadOptions {
    /// Lateral scale; required for `.npy`/text, refused for `.x3p` (the file has it).
    pub spacing: Option<Spacing>,
    /// Whether the sample is one cell of a periodic pattern.
    pub periodic: bool,
    /// Non-finite heights, invalid points and spikes: refuse or repair.
    pub repair: Repair,
    /// Unit of the heights in `.npy`/text (default metres); `.x3p` accepts only metres.
    pub height_unit: Option<HeightUnit>,
    /// Form removed after reading (and repairing); refused on a periodic sample (a
    /// plane is not periodic). Scenes default to [`Detrend::Plane`] for non-periodic
    /// files; this struct's default is [`Detrend::None`].
    pub detrend: Detrend,
    /// The memory limit the file's sizes (header, grid, archive members) are checked
    /// against before they are allocated. Default: 75 % of the machine's memory.
    pub memory: MemoryLimit,
}

/// The file formats [`Surface::read`] knows, by extension (case-insensitive).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    X3p,
    Npy,
    /// SurfaceTopography's NetCDF-3 topography (`.nc`; feature `netcdf`).
    NetCdf,
    /// contact.engineering's container (`.zip`: meta.yml and its topography files;
    /// feature `container`).
    Container,
    Text,
}

impl FileKind {
    pub fn of(path: &Path) -> FileKind {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "x3p" => FileKind::X3p,
            "npy" => FileKind::Npy,
            "nc" => FileKind::NetCdf,
            "zip" => FileKind::Container,
            _ => FileKind::Text,
        }
    }
}

fn format_err(path: &Path, e: SurfaceError) -> SurfaceError {
    match e {
        e @ (SurfaceError::Io { .. } | SurfaceError::Format { .. }) => e,
        other => SurfaceError::Format {
            path: path.display().to_string(),
            message: other.to_string(),
        },
    }
}

impl Surface {
    /// [`Surface::read`] of every kind but a container (module `open`).
    pub(super) fn read_file(path: &Path, opts: &ReadOptions) -> Result<Surface, SurfaceError> {
        if opts.periodic && opts.detrend != Detrend::None {
            return Err(SurfaceError::Unsupported(format!(
                "detrend = \"{}\" on a periodic sample: a tilt or a curvature is not periodic \
                 (the sample's edges would no longer meet); set detrend = \"none\" or periodic = false",
                opts.detrend.name()
            )));
        }
        let kind = FileKind::of(path);
        let mut periodic = opts.periodic;
        let mut detrend = opts.detrend;
        let (z, n0, n1, spacing, mut log, warnings) = match kind {
            FileKind::X3p => read_x3p_raw(path, opts)?,
            FileKind::NetCdf => {
                let (raw, file_periodic) = read_netcdf_raw(path, opts)?;
                if file_periodic && !periodic {
                    periodic = true;
                    if detrend != Detrend::None {
                        detrend = Detrend::None;
                        let mut raw = raw;
                        raw.4.push(
                            "not detrended: the file says periodic (a tilt or a curvature is not periodic)"
                                .into(),
                        );
                        raw
                    } else {
                        raw
                    }
                } else {
                    raw
                }
            }
            FileKind::Container => {
                return Err(SurfaceError::Unsupported(format!(
                    "{}: a container (.zip) here: read it with Surface::read",
                    path.display()
                )));
            }
            FileKind::Npy | FileKind::Text => {
                let spacing = opts.spacing.ok_or_else(|| SurfaceError::Format {
                    path: path.display().to_string(),
                    message: "the lateral size is missing: give size = L, size = [Lx, Ly] or \
                              pixel_size = [dx, dy] (m)"
                        .into(),
                })?;
                let (mut z, n0, n1) = if kind == FileKind::Npy {
                    read_npy_raw(path, &opts.memory)?
                } else {
                    read_text_raw(path, &opts.memory)?
                };
                let unit = opts.height_unit.unwrap_or_default();
                let f = unit.metres();
                if f != 1.0 {
                    z.iter_mut().for_each(|v| *v *= f);
                }
                let line = if opts.height_unit.is_some() {
                    format!(
                        "heights read in {} (height_unit = \"{}\"), converted to metres (× {f:e})",
                        unit.name(),
                        unit.name()
                    )
                } else {
                    "heights read as metres (the default; set height_unit = \"mm\", \"um\" or \"nm\" otherwise)".to_string()
                };
                (z, n0, n1, spacing, vec![line], Vec::new())
            }
        };
        // spikes are judged on the heights less the form to be removed (a plane when
        // none is: a tilt must not decide what is a spike)
        let judge = match detrend {
            Detrend::None => Detrend::Plane,
            k => k,
        };
        let unit_from_file = match kind {
            FileKind::X3p => true,
            FileKind::NetCdf => log.iter().any(|l| l.contains("(the file's unit)")),
            _ => false,
        };
        let seam = if periodic {
            seam_warning(&z, n0, n1)
        } else {
            None
        };
        let mut s = Surface::measured_judged(
            z,
            n0,
            n1,
            spacing,
            periodic,
            opts.repair,
            judge,
            &opts.memory,
        )
        .map_err(|e| format_err(path, e))?;
        if let Some(r) = s.repair_report() {
            log.push(format!("checked: {}", r.found()));
            if r.repaired > 0 {
                log.push(r.describe());
            }
        }
        s.log = log;
        s.warnings = warnings;
        s.warnings.extend(seam);
        s.unit_from_file = unit_from_file;
        match detrend {
            Detrend::None => s.warnings.extend(s.kept_form_warning()),
            kind => {
                let form = s.detrend(kind);
                s.warnings.extend(form.dominance_warning());
            }
        }
        Ok(s)
    }

    #[cfg(feature = "npy")]
    /// Reads a 2-D f64 `.npy` height map (m), `size` the length of its first axis
    /// (square pixels). Wrong dtype or dimensionality, non-finite heights and spikes
    /// are errors naming the file (and the grid index). Under the machine's memory
    /// limit ([`MemoryLimit::of_machine`]).
    pub fn read_npy(path: &Path, size: f64, periodic: bool) -> Result<Self, SurfaceError> {
        Self::read_npy_with(
            path,
            size,
            periodic,
            Repair::Refuse,
            &MemoryLimit::default(),
        )
    }

    #[cfg(feature = "npy")]
    /// [`Surface::read_npy`] with a choice of [`Repair`], the header's size checked
    /// against `memory`.
    pub fn read_npy_with(
        path: &Path,
        size: f64,
        periodic: bool,
        repair: Repair,
        memory: &MemoryLimit,
    ) -> Result<Self, SurfaceError> {
        Self::read_as(path, FileKind::Npy, size, periodic, repair, memory)
    }

    /// Reads a plain-text matrix of heights (m): one grid row per line, values
    /// separated by whitespace and/or commas, `#` comments and blank lines ignored;
    /// `size` the length of the first axis (square pixels). `nan`/`inf` entries and
    /// spikes are errors naming the file and the grid index. Under the machine's memory
    /// limit ([`MemoryLimit::of_machine`]).
    pub fn read_text(path: &Path, size: f64, periodic: bool) -> Result<Self, SurfaceError> {
        Self::read_text_with(
            path,
            size,
            periodic,
            Repair::Refuse,
            &MemoryLimit::default(),
        )
    }

    /// [`Surface::read_text`] with a choice of [`Repair`], the file no larger than
    /// `memory`.
    pub fn read_text_with(
        path: &Path,
        size: f64,
        periodic: bool,
        repair: Repair,
        memory: &MemoryLimit,
    ) -> Result<Self, SurfaceError> {
        Self::read_as(path, FileKind::Text, size, periodic, repair, memory)
    }

    fn read_as(
        path: &Path,
        kind: FileKind,
        size: f64,
        periodic: bool,
        repair: Repair,
        memory: &MemoryLimit,
    ) -> Result<Self, SurfaceError> {
        let (z, n0, n1) = if kind == FileKind::Npy {
            read_npy_raw(path, memory)?
        } else {
            read_text_raw(path, memory)?
        };
        Surface::measured_with(z, n0, n1, Spacing::Size(size), periodic, repair, memory)
            .map_err(|e| format_err(path, e))
    }

    /// Writes the heights (m) as a 2-D little-endian f64 `.npy` array n0 × n1 (first
    /// axis x), atomically (feature `npy`).
    #[cfg(feature = "npy")]
    pub fn write_npy(&self, path: &Path) -> Result<(), SurfaceError> {
        let p = path.display().to_string();
        let io = |e: std::io::Error| SurfaceError::Write {
            path: p.clone(),
            message: e.to_string(),
        };
        let arr = Array2::from_shape_vec((self.n0, self.n1), self.z.clone())
            .map_err(|e| io(std::io::Error::other(e)))?;
        crate::output::write_atomic_with(path, |tmp| {
            ndarray_npy::write_npy(tmp, &arr).map_err(std::io::Error::other)
        })
        .map_err(io)
    }
}

/// Checks a `.npy` header's shape against the file's length and `memory`
/// before ndarray-npy allocates the array it claims (a 928-byte file may claim
/// 100000×100000). Float64 data; the reader holds about three copies (array, heights,
/// surface). Headers it cannot parse are left to ndarray-npy's own errors.
#[cfg(feature = "npy")]
fn check_npy_size(path: &Path, memory: &MemoryLimit) -> Result<(), String> {
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
        Some(bytes) if bytes <= data => memory
            .check(
                format!("reading a {shown} height map"),
                bytes.saturating_mul(3),
            )
            .map_err(|e| e.to_string()),
        _ => Err(format!(
            "the header claims a {shown} array of float64 but the file holds only {data} bytes of data: truncated, or not a valid .npy file"
        )),
    }
}

/// What a reader returns: heights, shape (n0, n1), pixel sizes, log and warnings.
type Raw = (Vec<f64>, usize, usize, Spacing, Vec<String>, Vec<String>);

#[cfg(feature = "x3p")]
fn read_x3p_raw(path: &Path, opts: &ReadOptions) -> Result<Raw, SurfaceError> {
    regular_file(path)?;
    let refuse = |message: &str| SurfaceError::Format {
        path: path.display().to_string(),
        message: message.into(),
    };
    if opts.spacing.is_some() {
        return Err(refuse(
            "an .x3p file gives its own pixel sizes (CX/CY Increment): do not set size or pixel_size",
        ));
    }
    if opts.height_unit.is_some_and(|u| u != HeightUnit::M) {
        return Err(refuse(
            "an .x3p file is in metres by the standard: do not set height_unit",
        ));
    }
    let x = super::x3p::read_x3p(path, &opts.memory)?;
    let mut log = x.describe();
    log.push("heights in metres (ISO 25178-72)".into());
    Ok((
        x.heights,
        x.nx,
        x.ny,
        Spacing::Pixel(x.dx, x.dy),
        log,
        x.warnings,
    ))
}

#[cfg(not(feature = "x3p"))]
fn read_x3p_raw(path: &Path, _: &ReadOptions) -> Result<Raw, SurfaceError> {
    Err(SurfaceError::Unsupported(format!(
        "{}: .x3p files need the runtime feature `x3p`",
        path.display()
    )))
}

/// Largest ratio of the RMS height step across a periodic sample's seams to the RMS
/// step between neighbours inside it before [`seam_warning`] speaks: for a sample that
/// really is one cell of a periodic pattern the seam is a step like any other (ratio
/// near 1); a measured scan's edges do not meet (a tilt, a form, uncorrelated heights).
pub const SEAM_RATIO: f64 = 3.0;

/// The warning for heights declared periodic whose opposite edges do not meet: the
/// RMS step across the x (y) seam, z[0, j] − z[n0 − 1, j], exceeds [`SEAM_RATIO`] ×
/// the RMS step between x (y) neighbours inside the grid. Non-finite heights are left
/// out.
pub(super) fn seam_warning(z: &[f64], n0: usize, n1: usize) -> Option<String> {
    let rms = |pairs: &mut dyn Iterator<Item = (usize, usize)>| {
        let (mut s, mut c) = (0.0, 0usize);
        for (a, b) in pairs {
            let d = z[a] - z[b];
            if d.is_finite() {
                s += d * d;
                c += 1;
            }
        }
        (s / c.max(1) as f64).sqrt()
    };
    let mut found = Vec::new();
    for (axis, seam, inside) in [
        (
            "x",
            rms(&mut (0..n1).map(|j| (j, (n0 - 1) * n1 + j))),
            rms(&mut (0..(n0 - 1) * n1).map(|k| (k, k + n1))),
        ),
        (
            "y",
            rms(&mut (0..n0).map(|i| (i * n1, i * n1 + n1 - 1))),
            rms(&mut (0..n0 * n1).filter(|k| k % n1 + 1 < n1).map(|k| (k, k + 1))),
        ),
    ] {
        if seam > SEAM_RATIO * inside {
            found.push(format!(
                "{axis}: RMS step {seam:.3e} m across the seam, {:.1} × the {inside:.3e} m between neighbours inside",
                seam / inside.max(f64::MIN_POSITIVE)
            ));
        }
    }
    (!found.is_empty()).then(|| {
        format!(
            "the heights are declared periodic (periodic = true) but the opposite edges do not meet \
             ({}; warning above {SEAM_RATIO} ×): a measured scan is not one cell of a periodic \
             pattern, and its seams act as steps in the contact; set periodic = false (the \
             contact is then solved on the non-periodic sample)",
            found.join("; ")
        )
    })
}

/// Metres per unit of a SurfaceTopography unit string.
#[cfg(feature = "netcdf")]
fn unit_metres(u: &str) -> Option<f64> {
    Some(match u {
        "m" => 1.0,
        "cm" => 1e-2,
        "mm" => 1e-3,
        "um" | "µm" | "μm" | "micron" => 1e-6,
        "nm" => 1e-9,
        "pm" => 1e-12,
        "A" | "Å" | "angstrom" => 1e-10,
        "km" => 1e3,
        _ => return None,
    })
}

/// A SurfaceTopography NetCDF file: heights in metres, the spacing from the file's
/// lengths (or the options when it has none), and its periodic flag.
#[cfg(feature = "netcdf")]
fn read_netcdf_raw(path: &Path, opts: &ReadOptions) -> Result<(Raw, bool), SurfaceError> {
    regular_file(path)?;
    let refuse = |message: String| SurfaceError::Format {
        path: path.display().to_string(),
        message,
    };
    let t = super::netcdf::read_netcdf_topography(path, &opts.memory)?;
    let mut log = vec![format!(
        "NetCDF topography (SurfaceTopography layout): {}×{} points, heights(x, y)",
        t.n0, t.n1
    )];
    let f = match &t.unit {
        Some(u) => {
            let f = unit_metres(u).ok_or_else(|| {
                refuse(format!(
                    "unit `{u}` is not one of m, cm, mm, um (µm), nm, pm, A (Å), km"
                ))
            })?;
            if let Some(h) = opts.height_unit
                && h.metres() != f
            {
                return Err(refuse(format!(
                    "the file gives its unit (`{u}`): do not set height_unit (\"{}\")",
                    h.name()
                )));
            }
            log.push(format!(
                "heights and lengths in {u} (the file's unit), converted to metres (× {f:e})"
            ));
            f
        }
        None => {
            let unit = opts.height_unit.unwrap_or_default();
            log.push(format!(
                "the file names no unit: heights read in {} (height_unit), converted to metres (× {:e})",
                unit.name(),
                unit.metres()
            ));
            unit.metres()
        }
    };
    let spacing = match (t.lengths, opts.spacing) {
        (Some(_), Some(_)) => {
            return Err(refuse(
                "the file gives its physical sizes (`length` of x and y): do not set size or pixel_size"
                    .into(),
            ));
        }
        (Some((lx, ly)), None) => {
            log.push(format!(
                "physical sizes {:e} × {:e} m (the file's `length` of x and y)",
                lx * f,
                ly * f
            ));
            Spacing::Extent(lx * f, ly * f)
        }
        (None, Some(s)) => s,
        (None, None) => {
            return Err(refuse(
                "the file gives no physical sizes (no `length` of x and y): give size = L, \
                 size = [Lx, Ly] or pixel_size = [dx, dy] (m)"
                    .into(),
            ));
        }
    };
    let periodic = t.periodic.unwrap_or(false);
    match t.periodic {
        Some(p) => log.push(format!("periodic = {p} (the file's flag)")),
        None => log.push("the file has no periodic flag".into()),
    }
    let mut z = t.heights;
    if f != 1.0 {
        z.iter_mut().for_each(|v| *v *= f);
    }
    Ok(((z, t.n0, t.n1, spacing, log, Vec::new()), periodic))
}

#[cfg(not(feature = "netcdf"))]
fn read_netcdf_raw(path: &Path, _: &ReadOptions) -> Result<(Raw, bool), SurfaceError> {
    Err(SurfaceError::Unsupported(format!(
        "{}: NetCDF (.nc) files need the runtime feature `netcdf`",
        path.display()
    )))
}

/// Heights and shape of a 2-D f64 `.npy` (C order).
#[cfg(feature = "npy")]
fn read_npy_raw(
    path: &Path,
    memory: &MemoryLimit,
) -> Result<(Vec<f64>, usize, usize), SurfaceError> {
    regular_file(path)?;
    let p = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|e| SurfaceError::Io {
        path: p.clone(),
        message: e.to_string(),
    })?;
    check_npy_size(path, memory).map_err(|message| SurfaceError::Format {
        path: p.clone(),
        message,
    })?;
    let arr = Array2::<f64>::read_npy(std::io::BufReader::new(file)).map_err(|e| {
        let message = match e {
            ReadNpyError::WrongNdim(_, got) => {
                format!("wrong shape: expected a 2-D array, found {got} dimension(s)")
            }
            ReadNpyError::WrongDescriptor(d) => {
                format!("wrong dtype: expected little-endian float64 ('<f8'), found {d}")
            }
            // One line: the header parser's message spans several (source excerpt, caret).
            other => {
                let text = other.to_string();
                let first = text.lines().next().unwrap_or("");
                let first = first.split(" -->").next().unwrap_or(first);
                let first = first.trim_end().trim_end_matches(':');
                format!("not a valid .npy file: {first}")
            }
        };
        SurfaceError::Format { path: p, message }
    })?;
    let (n0, n1) = arr.dim();
    // the heights in logical (C) order: the array's own buffer when the file is in C
    // order (no second copy of the grid), else a copy in that order
    let z = if arr.is_standard_layout() {
        let (z, offset) = arr.into_raw_vec_and_offset();
        debug_assert_eq!(offset.unwrap_or(0), 0);
        z
    } else {
        arr.iter().copied().collect()
    };
    Ok((z, n0, n1))
}

#[cfg(not(feature = "npy"))]
fn read_npy_raw(path: &Path, _: &MemoryLimit) -> Result<(Vec<f64>, usize, usize), SurfaceError> {
    Err(SurfaceError::Unsupported(format!(
        "{}: .npy files need the runtime feature `npy`",
        path.display()
    )))
}

/// Refuses a surface "file" that is not a regular file (through links): a device, FIFO or
/// socket can be an endless stream (a link to /dev/zero grew without bound under a 1 GB
/// memory limit). A missing file passes (its reader names it).
fn regular_file(path: &Path) -> Result<(), SurfaceError> {
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => Err(SurfaceError::Io {
            path: path.display().to_string(),
            message:
                "not a regular file (a device, FIFO or socket): strata reads height maps from files"
                    .into(),
        }),
        _ => Ok(()),
    }
}

/// Heights and shape of a plain-text matrix (one grid row per line).
fn read_text_raw(
    path: &Path,
    memory: &MemoryLimit,
) -> Result<(Vec<f64>, usize, usize), SurfaceError> {
    regular_file(path)?;
    let p = path.display().to_string();
    let text = crate::resources::read_data_file(path, "a height map", memory)
        .and_then(|b| {
            String::from_utf8(b)
                .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
        })
        .map_err(|e| SurfaceError::Io {
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
    if let Some((a, b)) = triplet_grid(&z, n0, n1) {
        return Err(SurfaceError::Format {
            path: p,
            message: format!(
                "{n0} lines of 3 values look like `x y z` triplets (x takes {a} values and \
                 y {b}, every pair once), not a height matrix: strata reads one grid row of \
                 heights per line; write the heights as a {a}×{b} matrix (NumPy: \
                 np.savetxt(out, z.reshape({a}, {b})) with the rows sorted by x, then y)"
            ),
        });
    }
    Ok((z, n0, n1))
}

/// `Some((a, b))` when an n0 × 3 matrix is `x y z` triplets on a full grid: its first two
/// columns take a ≥ 2 and b ≥ 2 distinct values with a·b = n0, each (x, y) pair once.
/// A height matrix three points wide has (almost surely) no such repetition.
fn triplet_grid(z: &[f64], n0: usize, n1: usize) -> Option<(usize, usize)> {
    if n1 != 3 || n0 < 4 {
        return None;
    }
    let distinct = |c: usize| {
        let mut v: Vec<f64> = (0..n0).map(|r| z[3 * r + c]).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v.len()
    };
    let (a, b) = (distinct(0), distinct(1));
    if a < 2 || b < 2 || a * b != n0 {
        return None;
    }
    let mut pairs: Vec<(u64, u64)> = (0..n0)
        .map(|r| (z[3 * r].to_bits(), z[3 * r + 1].to_bits()))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    (pairs.len() == n0).then_some((a, b))
}
