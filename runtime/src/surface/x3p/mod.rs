//! ISO 25178-72 / ISO 5436-2 `.x3p` files (feature `x3p`): a zip container holding
//! `main.xml` (the description, schema namespace `http://www.opengps.eu/2008/ISO5436_2`),
//! the binary point data (`Record3/DataLink/PointDataLink`, usually `bindata/data.bin`),
//! optionally a validity bit map (`ValidPointsLink`, usually `bindata/valid.bin`) and
//! `md5checksum.hex` (`Record4/ChecksumFile`: the MD5 of main.xml, `HEX *main.xml`).
//!
//! Read here (checked against the published schema and the openGPS reference library):
//! - `Record1`: `FeatureType` must be `SUR` (areal; `PRF` profiles and `PCL` point
//!   clouds are refused); `Axes/CX`, `CY` must be incremental (`AxisType` `I`) with
//!   `Increment` = pixel size (m) > 0 and an optional `Offset` (m, the position of the
//!   first point: reported, irrelevant to contact); `CZ` must be absolute (`A`) with
//!   `DataType` `I` (int16), `L` (int32), `F` (float32) or `D` (float64), optional
//!   `Increment` (default 1) and `Offset` (default 0): a height is
//!   z = Offset + Increment × value (m), which is how integer data carry their
//!   resolution. A `Rotation` other than the identity is reported and ignored.
//! - `Record3`: `MatrixDimension` SizeX × SizeY × SizeZ with SizeZ = 1 (one layer; a
//!   `ListDimension` is an unordered point list, refused); the points either in the
//!   binary file, little-endian, x fastest (point (i, j) at index j·SizeX + i), or as
//!   an XML `DataList` of `Datum` elements in the same order (an empty `Datum` is an
//!   invalid point). A binary file shorter or longer than SizeX × SizeY values is an
//!   error (the dimensions or the type do not describe it). `MD5ChecksumPointData` (and `MD5ChecksumValidPoints`) are checked:
//!   a mismatch is an error (the numbers are corrupt); a missing or malformed one is a
//!   warning. The main.xml checksum is a warning only, as in the reference library.
//! - Invalid points: NaN in `F`/`D` data (and ±inf, which some instruments write,
//!   e.g. an Alicona export), and every point whose bit in the validity map is 0 (bit k%8 of byte k/8, least significant first; 1 = valid). They come back
//!   as NaN, to be refused or repaired like any missing height.
//!
//! The grid is returned with the first axis x (`heights[i·SizeY + j]` = point (i, j)),
//! the [`Surface`](crate::surface::Surface) convention. Units are metres by the standard.
//!
//! [`Surface::write_x3p`](crate::surface::Surface::write_x3p) writes the same layout (submodule `write`).

mod write;

pub use write::X3pWriteOptions;

use std::io::Read;
use std::path::Path;

use super::SurfaceError;
use crate::resources::{MemoryLimit, bytes_for};

/// The data types of the `CZ` axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DataType {
    /// `I`: 16-bit signed integer.
    I,
    /// `L`: 32-bit signed integer.
    L,
    /// `F`: 32-bit IEEE float.
    F,
    /// `D`: 64-bit IEEE float (default: lossless).
    #[default]
    D,
}

impl DataType {
    /// Parses the schema's code `I`, `L`, `F` or `D`.
    pub fn parse(code: &str) -> Option<DataType> {
        match code {
            "I" => Some(DataType::I),
            "L" => Some(DataType::L),
            "F" => Some(DataType::F),
            "D" => Some(DataType::D),
            _ => None,
        }
    }
    /// The schema's code.
    pub fn code(self) -> &'static str {
        match self {
            DataType::I => "I",
            DataType::L => "L",
            DataType::F => "F",
            DataType::D => "D",
        }
    }
    /// Bytes per value in the binary file.
    pub fn bytes(self) -> usize {
        match self {
            DataType::I => 2,
            DataType::L | DataType::F => 4,
            DataType::D => 8,
        }
    }
    fn describe(self) -> &'static str {
        match self {
            DataType::I => "I (int16)",
            DataType::L => "L (int32)",
            DataType::F => "F (float32)",
            DataType::D => "D (float64)",
        }
    }
    /// Decodes value `k` of little-endian `bytes` (NaN stays NaN).
    fn decode(self, bytes: &[u8], k: usize) -> f64 {
        let b = &bytes[k * self.bytes()..(k + 1) * self.bytes()];
        match self {
            DataType::I => i16::from_le_bytes([b[0], b[1]]) as f64,
            DataType::L => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            DataType::F => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            DataType::D => f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]),
        }
    }
}

/// The contents of an `.x3p` file (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct X3pData {
    /// Heights z (m), `nx × ny` row-major with the first axis x; NaN = invalid point.
    pub heights: Vec<f64>,
    /// SizeX, SizeY.
    pub nx: usize,
    pub ny: usize,
    /// Pixel sizes: CX and CY `Increment` (m).
    pub dx: f64,
    pub dy: f64,
    /// `Offset` of CX, CY, CZ (m).
    pub offset: (f64, f64, f64),
    /// CZ `Increment` (m per stored value).
    pub z_increment: f64,
    pub data_type: DataType,
    /// Points marked invalid (validity map or NaN).
    pub invalid: usize,
    /// `Record1/Revision`.
    pub revision: String,
    /// Where the points were: the binary file's name, or "DataList" (XML).
    pub storage: String,
    /// `Record2`: instrument (manufacturer, model, version), date, comment, if given.
    pub instrument: Option<String>,
    pub date: Option<String>,
    pub comment: Option<String>,
    /// Non-fatal findings (main.xml checksum, rotation, missing data checksum…).
    pub warnings: Vec<String>,
}

impl X3pData {
    /// Log lines: grid, axes, data type, storage, invalid points, instrument.
    pub fn describe(&self) -> Vec<String> {
        let mut v = vec![format!(
            "x3p: {}×{} grid ({}, SUR), pixel {:e} × {:e} m (CX/CY Increment), x/y offset {:e}, {:e} m; \
             data type {} in {}; z = {:e} + {:e} × value (m); {} invalid point(s)",
            self.nx,
            self.ny,
            self.revision,
            self.dx,
            self.dy,
            self.offset.0,
            self.offset.1,
            self.data_type.describe(),
            self.storage,
            self.offset.2,
            self.z_increment,
            self.invalid
        )];
        let mut meta = Vec::new();
        if let Some(i) = &self.instrument {
            meta.push(format!("instrument {i}"));
        }
        if let Some(d) = &self.date {
            meta.push(format!("date {d}"));
        }
        if let Some(c) = &self.comment {
            meta.push(format!("comment \"{c}\""));
        }
        if !meta.is_empty() {
            v.push(format!("x3p: {}", meta.join("; ")));
        }
        v
    }
}

/// Reads an `.x3p` file (module docs), its sizes checked against `memory` before they
/// are allocated; errors name the file and what is wrong.
pub fn read_x3p(path: &Path, memory: &MemoryLimit) -> Result<X3pData, SurfaceError> {
    let p = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|e| SurfaceError::Io {
        path: p.clone(),
        message: e.to_string(),
    })?;
    parse_x3p(std::io::BufReader::new(file), &p, memory)
}

/// Reads an `.x3p` container from any seekable reader (`name` is used in errors), its
/// sizes checked against `memory`.
pub fn parse_x3p<R: std::io::Read + std::io::Seek>(
    reader: R,
    name: &str,
    memory: &MemoryLimit,
) -> Result<X3pData, SurfaceError> {
    let fail = |message: String| SurfaceError::Format {
        path: name.to_string(),
        message,
    };
    let mut zip = zip::ZipArchive::new(reader).map_err(|e| {
        fail(format!(
            "not a readable zip archive ({e}); an .x3p file is a zip holding main.xml"
        ))
    })?;
    let main = entry(&mut zip, "main.xml", name, memory)?;
    let mut warnings = Vec::new();
    let text =
        std::str::from_utf8(&main).map_err(|e| fail(format!("main.xml is not UTF-8 text: {e}")))?;
    let text = text.trim_start_matches('\u{feff}');
    let doc = roxmltree::Document::parse(text)
        .map_err(|e| fail(format!("main.xml is not well-formed XML: {e}")))?;
    let root = doc.root_element();
    if root.tag_name().name() != "ISO5436_2" {
        return Err(fail(format!(
            "main.xml: root element is <{}>, expected <ISO5436_2>",
            root.tag_name().name()
        )));
    }
    let x = Xml { name };
    // Record4: checksum of main.xml (a warning when it does not verify).
    match x.opt_text(root, &["Record4", "ChecksumFile"]) {
        None => warnings.push("main.xml: no Record4/ChecksumFile: main.xml not verified".into()),
        Some(f) => match entry(&mut zip, &f, name, memory) {
            Err(_) => warnings.push(format!("checksum file {f} missing: main.xml not verified")),
            Ok(sum) => {
                let stated = String::from_utf8_lossy(&sum)
                    .split_whitespace()
                    .next()
                    .unwrap_or("")
                    .to_ascii_lowercase();
                let actual = format!("{:x}", md5::compute(&main));
                if stated != actual {
                    warnings.push(format!(
                        "main.xml MD5 {actual} does not match {f} ({stated}): the description may have been edited"
                    ));
                }
            }
        },
    }
    // Record1.
    let revision = x
        .opt_text(root, &["Record1", "Revision"])
        .unwrap_or_default();
    let feature = x.text(root, &["Record1", "FeatureType"])?;
    match feature.as_str() {
        "SUR" => {}
        "PRF" => {
            return Err(fail(
                "Record1/FeatureType is PRF: a profile, not an areal surface".into(),
            ));
        }
        "PCL" => {
            return Err(fail(
                "Record1/FeatureType is PCL: an unordered point cloud, not a height map on a grid"
                    .into(),
            ));
        }
        other => {
            return Err(fail(format!(
                "Record1/FeatureType `{other}` is not SUR, PRF or PCL"
            )));
        }
    }
    let mut lateral = [(0.0, 0.0); 2];
    for (k, axis) in ["CX", "CY"].into_iter().enumerate() {
        let at = x.text(root, &["Record1", "Axes", axis, "AxisType"])?;
        if at != "I" {
            return Err(fail(format!(
                "Record1/Axes/{axis}/AxisType is `{at}`: only incremental (I) x and y axes, \
                 i.e. a regular grid, are supported (resample scattered points first)"
            )));
        }
        let inc = x.number(root, &["Record1", "Axes", axis, "Increment"])?;
        if !(inc.is_finite() && inc > 0.0) {
            return Err(fail(format!(
                "Record1/Axes/{axis}/Increment = {inc}: the pixel size must be finite and > 0 (m)"
            )));
        }
        let off = x
            .opt_number(root, &["Record1", "Axes", axis, "Offset"])?
            .unwrap_or(0.0);
        lateral[k] = (inc, off);
    }
    let at = x.text(root, &["Record1", "Axes", "CZ", "AxisType"])?;
    if at != "A" {
        return Err(fail(format!(
            "Record1/Axes/CZ/AxisType is `{at}`: the z axis must be absolute (A)"
        )));
    }
    let code = x.text(root, &["Record1", "Axes", "CZ", "DataType"])?;
    let data_type = DataType::parse(&code).ok_or_else(|| {
        fail(format!(
            "Record1/Axes/CZ/DataType `{code}` is not one of I, L, F, D"
        ))
    })?;
    let z_increment = x
        .opt_number(root, &["Record1", "Axes", "CZ", "Increment"])?
        .unwrap_or(1.0);
    if !(z_increment.is_finite() && z_increment != 0.0) {
        return Err(fail(format!(
            "Record1/Axes/CZ/Increment = {z_increment}: must be finite and nonzero"
        )));
    }
    let z_offset = x
        .opt_number(root, &["Record1", "Axes", "CZ", "Offset"])?
        .unwrap_or(0.0);
    if let Some(rot) = x.find(root, &["Record1", "Axes", "Rotation"]) {
        let mut identity = true;
        for (r, c) in [
            (1, 1),
            (1, 2),
            (1, 3),
            (2, 1),
            (2, 2),
            (2, 3),
            (3, 1),
            (3, 2),
            (3, 3),
        ] {
            let v = x.opt_number(rot, &[&format!("r{r}{c}")])?.unwrap_or(0.0);
            let want = if r == c { 1.0 } else { 0.0 };
            identity &= (v - want).abs() < 1e-12;
        }
        if !identity {
            warnings.push(
                "Record1/Axes/Rotation is not the identity: ignored (the grid is taken as measured)"
                    .into(),
            );
        }
    }
    // Record2 (optional).
    let instrument = x.find(root, &["Record2", "Instrument"]).map(|i| {
        ["Manufacturer", "Model", "Version"]
            .iter()
            .filter_map(|k| x.opt_text(i, &[k]))
            .collect::<Vec<_>>()
            .join(", ")
    });
    let date = x.opt_text(root, &["Record2", "Date"]);
    let comment = x
        .opt_text(root, &["Record2", "Comment"])
        .filter(|c| !c.is_empty());
    // Record3.
    if x.find(root, &["Record3", "ListDimension"]).is_some() {
        return Err(fail(
            "Record3/ListDimension: an unordered point list, not a matrix; only MatrixDimension grids are supported"
                .into(),
        ));
    }
    let size = |k: &str| -> Result<usize, SurfaceError> {
        let t = x.text(root, &["Record3", "MatrixDimension", k])?;
        t.parse::<usize>().map_err(|_| {
            fail(format!(
                "Record3/MatrixDimension/{k} = `{t}` is not a non-negative integer"
            ))
        })
    };
    let (nx, ny, nz) = (size("SizeX")?, size("SizeY")?, size("SizeZ")?);
    if nz != 1 {
        return Err(fail(format!(
            "Record3/MatrixDimension/SizeZ = {nz}: only single-layer height maps (SizeZ = 1) are supported"
        )));
    }
    let n = nx.checked_mul(ny).filter(|&n| n > 0).ok_or_else(|| {
        fail(format!(
            "Record3/MatrixDimension {nx}×{ny} is empty or too large"
        ))
    })?;
    memory.check(
        format!("reading the {nx}×{ny} grid of {name}"),
        bytes_for(n as u64, 3 * 8),
    )?;
    let mut raw = vec![f64::NAN; n];
    let storage;
    if let Some(link) = x.find(root, &["Record3", "DataLink"]) {
        let file = x.text(link, &["PointDataLink"])?;
        let data = entry(&mut zip, &file, name, memory)?;
        let need = n * data_type.bytes();
        if data.len() < need {
            return Err(fail(format!(
                "{file} holds {} bytes, but {nx}×{ny} values of type {} need {need}",
                data.len(),
                data_type.code()
            )));
        }
        if data.len() > need {
            // more data than the grid: the dimensions or the type do not describe the
            // file (read with a warning, such a file was solved as a surface of RMS 1.2e9 m)
            return Err(fail(format!(
                "{file} holds {} bytes, more than the {nx}×{ny} values of type {} need \
                 ({need}): Record3/MatrixDimension or the data type does not describe it",
                data.len(),
                data_type.code()
            )));
        }
        verify(
            &x,
            link,
            "MD5ChecksumPointData",
            &data,
            &file,
            &mut warnings,
        )?;
        for (k, r) in raw.iter_mut().enumerate() {
            *r = data_type.decode(&data, k);
        }
        if let Some(vfile) = x.opt_text(link, &["ValidPointsLink"]) {
            let valid = entry(&mut zip, &vfile, name, memory)?;
            if valid.len() < n.div_ceil(8) {
                return Err(fail(format!(
                    "{vfile} holds {} bytes, but {n} points need {} validity bytes",
                    valid.len(),
                    n.div_ceil(8)
                )));
            }
            verify(
                &x,
                link,
                "MD5ChecksumValidPoints",
                &valid,
                &vfile,
                &mut warnings,
            )?;
            for (k, r) in raw.iter_mut().enumerate() {
                if valid[k / 8] & (1u8 << (k % 8)) == 0 {
                    *r = f64::NAN;
                }
            }
        }
        storage = format!("{file} (binary, little-endian)");
    } else if let Some(list) = x.find(root, &["Record3", "DataList"]) {
        let data: Vec<_> = list
            .children()
            .filter(|c| c.is_element() && c.tag_name().name() == "Datum")
            .collect();
        if data.len() != n {
            return Err(fail(format!(
                "Record3/DataList has {} Datum elements, expected {nx}×{ny} = {n}",
                data.len()
            )));
        }
        for (k, d) in data.iter().enumerate() {
            let t = d.text().unwrap_or("").trim();
            if t.is_empty() {
                continue; // invalid point
            }
            raw[k] = t.parse::<f64>().map_err(|_| {
                fail(format!(
                    "Record3/DataList/Datum[{k}] = `{t}` is not one number (x and y are incremental)"
                ))
            })?;
        }
        storage = "Record3/DataList (XML)".to_string();
    } else {
        return Err(fail(
            "Record3 has neither a DataLink nor a DataList: no point data".into(),
        ));
    }
    // Transpose to the first axis x and scale to metres.
    let mut heights = vec![0.0; n];
    let mut invalid = 0;
    for j in 0..ny {
        for i in 0..nx {
            let r = raw[j * nx + i];
            let z = if !r.is_finite() {
                invalid += 1;
                f64::NAN
            } else {
                z_offset + z_increment * r
            };
            heights[i * ny + j] = z;
        }
    }
    Ok(X3pData {
        heights,
        nx,
        ny,
        dx: lateral[0].0,
        dy: lateral[1].0,
        offset: (lateral[0].1, lateral[1].1, z_offset),
        z_increment,
        data_type,
        invalid,
        revision,
        storage,
        instrument,
        date,
        comment,
        warnings,
    })
}

/// Checks `bytes` against the MD5 in `link/field`: mismatch → error, absent or
/// malformed → warning.
fn verify(
    x: &Xml,
    link: roxmltree::Node,
    field: &str,
    bytes: &[u8],
    file: &str,
    warnings: &mut Vec<String>,
) -> Result<(), SurfaceError> {
    let actual = format!("{:x}", md5::compute(bytes));
    match x.opt_text(link, &[field]) {
        Some(s) if s.len() == 32 && s.chars().all(|c| c.is_ascii_hexdigit()) => {
            if s.to_ascii_lowercase() != actual {
                return Err(SurfaceError::Format {
                    path: x.name.to_string(),
                    message: format!(
                        "{file}: MD5 {actual} does not match Record3/DataLink/{field} {s}: the data are corrupt"
                    ),
                });
            }
        }
        Some(s) => warnings.push(format!(
            "Record3/DataLink/{field} `{s}` is not an MD5 digest: {file} not verified"
        )),
        None => warnings.push(format!(
            "Record3/DataLink/{field} missing: {file} not verified"
        )),
    }
    Ok(())
}

/// The bytes of zip entry `entry` (checked against `memory`), or an error naming it.
fn entry<R: std::io::Read + std::io::Seek>(
    zip: &mut zip::ZipArchive<R>,
    entry: &str,
    name: &str,
    memory: &MemoryLimit,
) -> Result<Vec<u8>, SurfaceError> {
    let fail = |message: String| SurfaceError::Format {
        path: name.to_string(),
        message,
    };
    let mut f = zip
        .by_name(entry)
        .map_err(|e| fail(format!("the archive has no readable {entry}: {e}")))?;
    memory.check(format!("{entry} of {name}"), f.size())?;
    let mut v = Vec::with_capacity(f.size() as usize);
    f.read_to_end(&mut v)
        .map_err(|e| fail(format!("cannot decompress {entry}: {e}")))?;
    Ok(v)
}

/// Element look-ups by local name (namespaces ignored: the standard qualifies only
/// the root), with errors naming the element path.
struct Xml<'n> {
    name: &'n str,
}

impl Xml<'_> {
    fn find<'a, 'i>(
        &self,
        mut node: roxmltree::Node<'a, 'i>,
        path: &[&str],
    ) -> Option<roxmltree::Node<'a, 'i>> {
        for p in path {
            node = node
                .children()
                .find(|c| c.is_element() && c.tag_name().name() == *p)?;
        }
        Some(node)
    }
    fn opt_text(&self, node: roxmltree::Node, path: &[&str]) -> Option<String> {
        self.find(node, path)
            .map(|n| n.text().unwrap_or("").trim().to_string())
    }
    fn text(&self, node: roxmltree::Node, path: &[&str]) -> Result<String, SurfaceError> {
        self.opt_text(node, path)
            .ok_or_else(|| SurfaceError::Format {
                path: self.name.to_string(),
                message: format!("main.xml: element {} is missing", path.join("/")),
            })
    }
    fn opt_number(
        &self,
        node: roxmltree::Node,
        path: &[&str],
    ) -> Result<Option<f64>, SurfaceError> {
        match self.opt_text(node, path) {
            None => Ok(None),
            Some(t) => t
                .parse::<f64>()
                .map(Some)
                .map_err(|_| SurfaceError::Format {
                    path: self.name.to_string(),
                    message: format!("main.xml: {} = `{t}` is not a number", path.join("/")),
                }),
        }
    }
    fn number(&self, node: roxmltree::Node, path: &[&str]) -> Result<f64, SurfaceError> {
        self.text(node, path)?;
        self.opt_number(node, path).map(|v| v.unwrap_or(f64::NAN))
    }
}
