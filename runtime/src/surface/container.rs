//! contact.engineering's published containers (feature `container`): a zip holding
//! `meta.yml` (or `index.json`, the same structure in JSON, written by SurfaceTopography
//! ≥ 1.20) and the topography files it names. Layout (SurfaceTopography's `CEReader`):
//!
//! ```yaml
//! surfaces:
//!   - name: ...
//!     topographies:
//!       - name: scan.opd
//!         datafile: {original: scan.opd, squeezed-netcdf: topography0.nc}
//!         size: [Lx, Ly]          # in `unit`; optional when the data file gives it
//!         unit: µm
//!         is_periodic: false
//!         height_scale: 1.0       # pipeline of `original` (applied in the squeezed file)
//!         detrend_mode: center
//! ```
//!
//! Topographies are numbered across surfaces in file order from 0 (or picked by name).
//! The squeezed NetCDF file (heights after contact.engineering's pipeline, with its sizes,
//! unit and periodic flag) is read when present, else the original when strata reads its
//! format (`.nc`, `.npy`, `.x3p`, text) and its pipeline is the identity. The metadata's
//! sizes, unit and periodic flag are honoured where the data file has none, and checked
//! against it where it has (a difference is a warning, as SurfaceTopography warns).
//! The member is copied to a temporary file for the readers and removed after.

use std::io::{Read, Seek};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use yaml_rust2::{Yaml, YamlLoader};

use super::read::{FileKind, HeightUnit, ReadOptions};
use super::{Spacing, Surface, SurfaceError};
use crate::resources::MemoryLimit;

/// Which topography of a container: its number (across surfaces, from 0) or its name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Pick {
    Index(usize),
    Name(String),
}

impl std::fmt::Display for Pick {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Pick::Index(i) => write!(f, "topography {i}"),
            Pick::Name(n) => write!(f, "topography `{n}`"),
        }
    }
}

/// One topography listed in a container's metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// Its number across the container's surfaces, from 0.
    pub index: usize,
    /// The surface it belongs to (`surfaces[].name`).
    pub surface: String,
    /// Its name (`name`, else the data file's).
    pub name: String,
    /// The member to read and its key: `squeezed-netcdf` or `original`.
    pub datafile: String,
    pub key: &'static str,
    /// Physical sizes (Lx, Ly) in `unit`, when given.
    pub size: Option<(f64, f64)>,
    /// The unit of sizes and heights, as written.
    pub unit: Option<String>,
    /// `is_periodic`, when given.
    pub periodic: Option<bool>,
    /// `height_scale` of the original's pipeline, when given.
    pub height_scale: Option<f64>,
    /// `detrend_mode` of the original's pipeline, when given.
    pub detrend_mode: Option<String>,
}

fn format_error(path: &Path, message: impl Into<String>) -> SurfaceError {
    SurfaceError::Format {
        path: path.display().to_string(),
        message: message.into(),
    }
}

fn open(path: &Path) -> Result<zip::ZipArchive<std::fs::File>, SurfaceError> {
    let f = std::fs::File::open(path).map_err(|e| SurfaceError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    zip::ZipArchive::new(f).map_err(|e| {
        format_error(
            path,
            format!("not a readable zip archive ({e}); a contact.engineering container is a zip holding meta.yml"),
        )
    })
}

/// The bytes of member `name` (checked against `memory`).
fn member<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    name: &str,
    path: &Path,
    memory: &MemoryLimit,
) -> Result<Vec<u8>, SurfaceError> {
    let mut f = zip
        .by_name(name)
        .map_err(|e| format_error(path, format!("the archive has no readable `{name}`: {e}")))?;
    memory.check(format!("{name} of {}", path.display()), f.size())?;
    let mut v = Vec::with_capacity(f.size() as usize);
    f.read_to_end(&mut v)
        .map_err(|e| format_error(path, format!("cannot decompress `{name}`: {e}")))?;
    Ok(v)
}

/// A number (integer or real) of the YAML document.
fn num(y: &Yaml) -> Option<f64> {
    match y {
        Yaml::Real(_) | Yaml::Integer(_) => y.as_f64().or_else(|| y.as_i64().map(|i| i as f64)),
        _ => None,
    }
}

fn text(y: &Yaml) -> Option<String> {
    y.as_str().map(str::to_string)
}

/// The topographies of the metadata `doc` (a parsed meta.yml or index.json).
fn entries(doc: &Yaml, path: &Path, meta: &str) -> Result<Vec<Entry>, SurfaceError> {
    let bad = |m: String| format_error(path, format!("{meta}: {m}"));
    let surfaces = doc["surfaces"]
        .as_vec()
        .ok_or_else(|| bad("no list `surfaces` (contact.engineering's container layout)".into()))?;
    let mut out = Vec::new();
    for (si, s) in surfaces.iter().enumerate() {
        let surface = text(&s["name"]).unwrap_or_else(|| format!("surface{si}"));
        let topos = s["topographies"]
            .as_vec()
            .ok_or_else(|| bad(format!("surfaces[{si}]: no list `topographies`")))?;
        for (ti, t) in topos.iter().enumerate() {
            let field = format!("surfaces[{si}].topographies[{ti}]");
            let df = &t["datafile"];
            let (key, datafile) = [
                ("squeezed-netcdf", "squeezed-netcdf"),
                ("original", "original"),
            ]
            .iter()
            .find_map(|(k, name)| text(&df[*name]).map(|f| (*k, f)))
            .ok_or_else(|| {
                bad(format!(
                    "{field}.datafile: neither `squeezed-netcdf` nor `original` names a data file"
                ))
            })?;
            let size = match &t["size"] {
                Yaml::BadValue | Yaml::Null => None,
                Yaml::Array(v) if v.len() == 2 => match (num(&v[0]), num(&v[1])) {
                    (Some(a), Some(b)) if a.is_finite() && b.is_finite() && a > 0.0 && b > 0.0 => {
                        Some((a, b))
                    }
                    _ => {
                        return Err(bad(format!(
                            "{field}.size: two finite lengths > 0 expected"
                        )));
                    }
                },
                _ => {
                    return Err(bad(format!(
                        "{field}.size: [Lx, Ly] expected (a line scan is not a 2-D topography)"
                    )));
                }
            };
            let periodic = match &t["is_periodic"] {
                Yaml::Boolean(b) => Some(*b),
                Yaml::BadValue | Yaml::Null => None,
                _ => return Err(bad(format!("{field}.is_periodic: true or false expected"))),
            };
            let height_scale = match &t["height_scale"] {
                Yaml::BadValue | Yaml::Null => None,
                y => Some(num(y).filter(|v| v.is_finite()).ok_or_else(|| {
                    bad(format!("{field}.height_scale: a finite number expected"))
                })?),
            };
            out.push(Entry {
                index: out.len(),
                surface: surface.clone(),
                name: text(&t["name"]).unwrap_or_else(|| {
                    Path::new(&datafile)
                        .file_name()
                        .map(|n| n.to_string_lossy().into_owned())
                        .unwrap_or_else(|| datafile.clone())
                }),
                datafile,
                key,
                size,
                unit: text(&t["unit"]),
                periodic,
                height_scale,
                detrend_mode: text(&t["detrend_mode"]),
            });
        }
    }
    if out.is_empty() {
        return Err(bad("the container holds no topography".into()));
    }
    Ok(out)
}

/// The most YAML nodes a container's metadata may expand to (aliases counted at their
/// expanded size): a contact.engineering `meta.yml` has some tens of nodes per topography,
/// so a million is thousands of topographies. A "billion laughs" document (9 levels of 9
/// aliases, 21 kB) expands to 9⁹ ≈ 3.9·10⁸ nodes and is refused here, before the loader
/// copies them.
pub const MAX_YAML_NODES: u64 = 1_000_000;

/// Bytes the loader holds per expanded node (its `Yaml` value and container slot).
const YAML_NODE_BYTES: u64 = 64;

/// Counts the nodes `text` expands to (each alias at the size of the node it names) in
/// one pass of the event parser, and refuses more than [`MAX_YAML_NODES`] or than
/// `memory` allows.
fn check_yaml_expansion(
    text: &str,
    path: &Path,
    meta: &str,
    memory: &MemoryLimit,
) -> Result<(), SurfaceError> {
    use std::collections::HashMap;
    use yaml_rust2::parser::{Event, MarkedEventReceiver, Parser};
    use yaml_rust2::scanner::Marker;

    #[derive(Default)]
    struct Count {
        /// Expanded size (nodes, scalar bytes) of each anchor.
        anchors: HashMap<usize, (u64, u64)>,
        /// Open collections: their anchor id and the running total where they began
        /// (a collection's size is the total's growth until it ends).
        open: Vec<(usize, (u64, u64))>,
        total: (u64, u64),
    }
    impl Count {
        fn add(&mut self, nodes: u64, bytes: u64) {
            self.total.0 = self.total.0.saturating_add(nodes);
            self.total.1 = self.total.1.saturating_add(bytes);
        }
    }
    impl MarkedEventReceiver for Count {
        fn on_event(&mut self, ev: Event, _mark: Marker) {
            match ev {
                Event::Scalar(v, _, anchor, _) => {
                    let b = v.len() as u64;
                    if anchor > 0 {
                        self.anchors.insert(anchor, (1, b));
                    }
                    self.add(1, b);
                }
                Event::Alias(id) => {
                    let (n, b) = self.anchors.get(&id).copied().unwrap_or((1, 0));
                    self.add(n, b);
                }
                Event::SequenceStart(anchor, _) | Event::MappingStart(anchor, _) => {
                    self.open.push((anchor, self.total));
                    self.add(1, 0);
                }
                Event::SequenceEnd | Event::MappingEnd => {
                    if let Some((anchor, (n0, b0))) = self.open.pop()
                        && anchor > 0
                    {
                        let size = (self.total.0 - n0, self.total.1 - b0);
                        self.anchors.insert(anchor, size);
                    }
                }
                _ => {}
            }
        }
    }
    let mut count = Count::default();
    // Syntax errors are left to the loader's own message.
    if Parser::new_from_str(text).load(&mut count, true).is_err() {
        return Ok(());
    }
    let (nodes, bytes) = count.total;
    if nodes > MAX_YAML_NODES {
        return Err(format_error(
            path,
            format!(
                "{meta} expands to {nodes} YAML nodes through its aliases, more than the cap of \
                 {MAX_YAML_NODES} (an alias bomb?); not loaded"
            ),
        ));
    }
    memory.check(
        format!(
            "{meta} of {} (expanded through its aliases)",
            path.display()
        ),
        nodes.saturating_mul(YAML_NODE_BYTES).saturating_add(bytes),
    )?;
    Ok(())
}

/// The topographies a container lists, in order (`meta.yml`, else `index.json`); the
/// metadata's size checked against `memory` before it is read.
pub fn list(path: &Path, memory: &MemoryLimit) -> Result<Vec<Entry>, SurfaceError> {
    let mut zip = open(path)?;
    list_in(&mut zip, path, memory)
}

fn list_in<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    path: &Path,
    memory: &MemoryLimit,
) -> Result<Vec<Entry>, SurfaceError> {
    let names: Vec<String> = zip
        .file_names()
        .filter_map(Result::ok)
        .map(|n| n.into_owned())
        .collect();
    let meta = ["meta.yml", "index.json"]
        .into_iter()
        .find(|m| names.iter().any(|n| n == m))
        .ok_or_else(|| {
            format_error(
                path,
                "no meta.yml (nor index.json): not a contact.engineering container",
            )
        })?;
    let bytes = member(zip, meta, path, memory)?;
    let text = String::from_utf8(bytes)
        .map_err(|e| format_error(path, format!("{meta} is not UTF-8 text: {e}")))?;
    check_yaml_expansion(&text, path, meta, memory)?;
    let docs = YamlLoader::load_from_str(&text)
        .map_err(|e| format_error(path, format!("{meta} is not valid YAML: {e}")))?;
    let doc = docs
        .first()
        .ok_or_else(|| format_error(path, format!("{meta} is empty")))?;
    entries(doc, path, meta)
}

/// The entry `pick` names, or an error listing the container's topographies
/// ([`list`] under `memory`).
pub fn find(path: &Path, pick: &Pick, memory: &MemoryLimit) -> Result<Entry, SurfaceError> {
    select(list(path, memory)?, pick, path)
}

fn select(list: Vec<Entry>, pick: &Pick, path: &Path) -> Result<Entry, SurfaceError> {
    let found = match pick {
        Pick::Index(i) => list.get(*i).cloned(),
        Pick::Name(n) => list.iter().find(|e| &e.name == n).cloned(),
    };
    found.ok_or_else(|| {
        let names: Vec<String> = list
            .iter()
            .map(|e| format!("{} `{}`", e.index, e.name))
            .collect();
        format_error(
            path,
            format!(
                "no {pick} in the container; it holds {} topograph{}: {}",
                list.len(),
                if list.len() == 1 { "y" } else { "ies" },
                names.join(", ")
            ),
        )
    })
}

/// Metres per unit of a SurfaceTopography unit string.
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

/// A member copied to a temporary file, removed on drop.
struct Extracted(PathBuf);

impl Drop for Extracted {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn extract(bytes: &[u8], member: &str, path: &Path) -> Result<Extracted, SurfaceError> {
    static COUNT: AtomicUsize = AtomicUsize::new(0);
    let base = Path::new(member)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "member".into());
    let tmp = std::env::temp_dir().join(format!(
        "strata-container-{}-{}-{base}",
        std::process::id(),
        COUNT.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::write(&tmp, bytes).map_err(|e| SurfaceError::Io {
        path: path.display().to_string(),
        message: format!(
            "cannot copy `{member}` to the temporary file {}: {e}",
            tmp.display()
        ),
    })?;
    Ok(Extracted(tmp))
}

/// An error of the member's reader, naming the container and the member instead of the
/// temporary copy.
fn rename(e: SurfaceError, tmp: &Path, shown: &str) -> SurfaceError {
    let fix = |s: String| s.replace(&tmp.display().to_string(), shown);
    match e {
        SurfaceError::Io { path, message } => SurfaceError::Io {
            path: fix(path),
            message: fix(message),
        },
        SurfaceError::Format { path, message } => SurfaceError::Format {
            path: fix(path),
            message: fix(message),
        },
        SurfaceError::Unsupported(m) => SurfaceError::Unsupported(fix(m)),
        other => other,
    }
}

/// Reads topography `pick` of the container at `path`: its data file by the readers of
/// [`Surface::read`] with the metadata's sizes, unit and periodic flag (see the module
/// docs). `opts` as for [`Surface::read`]: sizes and a height unit only where neither
/// the data file nor the metadata gives them; `periodic` or the metadata's flag; every
/// allocation checked against `opts.memory`.
pub fn read_container(
    path: &Path,
    pick: &Pick,
    opts: &ReadOptions,
) -> Result<Surface, SurfaceError> {
    let mut zip = open(path)?;
    let e = select(list_in(&mut zip, path, &opts.memory)?, pick, path)?;
    let shown = format!("{} (member {})", path.display(), e.datafile);
    let refuse = |m: String| format_error(path, format!("{pick} (`{}`): {m}", e.name));
    let bytes = member(&mut zip, &e.datafile, path, &opts.memory)?;
    let tmp = extract(&bytes, &e.datafile, path)?;
    drop(bytes);
    let kind = FileKind::of(&tmp.0);
    if e.key == "original" {
        if !matches!(kind, FileKind::NetCdf | FileKind::Npy | FileKind::X3p)
            && !e.datafile.to_ascii_lowercase().ends_with(".txt")
            && !e.datafile.to_ascii_lowercase().ends_with(".asc")
        {
            return Err(refuse(format!(
                "its data file `{}` is in a format strata does not read and the container has no \
                 squeezed NetCDF copy (datafile.squeezed-netcdf); export the topography as NetCDF",
                e.datafile
            )));
        }
        if e.height_scale.is_some_and(|s| s != 1.0) {
            return Err(refuse(format!(
                "height_scale = {} applies to the original data file and the container has no \
                 squeezed NetCDF copy (datafile.squeezed-netcdf), whose heights are scaled",
                e.height_scale.unwrap_or(1.0)
            )));
        }
    }
    let metres = match &e.unit {
        Some(u) => Some(unit_metres(u).ok_or_else(|| {
            refuse(format!(
                "unit `{u}` is not one of m, cm, mm, um (µm), nm, pm, A (Å), km"
            ))
        })?),
        None => None,
    };
    let meta_spacing = e.size.zip(metres).map(|((lx, ly), f)| (lx * f, ly * f));
    // What the data file itself gives (a NetCDF file: sizes and unit; .x3p: sizes, m).
    let (file_lengths, file_unit) = match kind {
        FileKind::NetCdf => {
            let t = super::netcdf::read_netcdf_topography(&tmp.0, &opts.memory)
                .map_err(|err| rename(err, &tmp.0, &shown))?;
            (t.lengths.is_some(), t.unit.is_some())
        }
        FileKind::X3p => (true, true),
        _ => (false, false),
    };
    let mut inner = *opts;
    inner.periodic = opts.periodic || e.periodic.unwrap_or(false);
    let mut log = vec![format!(
        "contact.engineering container: {pick} `{}` of surface `{}`, data file `{}` ({})",
        e.name, e.surface, e.datafile, e.key
    )];
    if let (false, Some((lx, ly))) = (file_lengths, meta_spacing) {
        if opts.spacing.is_some() {
            return Err(refuse(
                "the container gives its physical sizes (`size`): do not set size or pixel_size"
                    .into(),
            ));
        }
        inner.spacing = Some(Spacing::Extent(lx, ly));
        log.push(format!(
            "physical sizes {lx:e} × {ly:e} m (the container's `size`)"
        ));
    }
    if let (false, Some(u), Some(f)) = (file_unit, &e.unit, metres) {
        if opts.height_unit.is_some_and(|h| h.metres() != f) {
            return Err(refuse(format!(
                "the container gives its unit (`{u}`): do not set height_unit"
            )));
        }
        let unit = [
            HeightUnit::M,
            HeightUnit::Mm,
            HeightUnit::Um,
            HeightUnit::Nm,
        ]
        .into_iter()
        .find(|h| h.metres() == f)
        .ok_or_else(|| refuse(format!("heights in `{u}` are read from NetCDF files only")))?;
        inner.height_unit = Some(unit);
        log.push(format!("heights in {u} (the container's `unit`)"));
    }
    let mut s = Surface::read_file(&tmp.0, &inner).map_err(|err| rename(err, &tmp.0, &shown))?;
    s.unit_from_file |= file_unit || e.unit.is_some();
    if let Some((lx, ly)) = meta_spacing.filter(|_| file_lengths) {
        let (ex, ey) = s.extent();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-4 * a.abs().max(b.abs());
        if !(close(lx, ex) && close(ly, ey)) {
            s.warnings.push(format!(
                "{pick}: the container's size {lx:e} × {ly:e} m differs from the data file's \
                 {ex:e} × {ey:e} m (the data file's is used)"
            ));
        }
    }
    if let Some(p) = e.periodic.filter(|&p| p != s.is_periodic()) {
        s.warnings.push(format!(
            "{pick}: the container says is_periodic = {p}, the surface is read as periodic = {}",
            s.is_periodic()
        ));
    }
    log.extend(
        s.log
            .drain(..)
            .map(|l| l.replace(&tmp.0.display().to_string(), &shown)),
    );
    s.log = log;
    Ok(s)
}
