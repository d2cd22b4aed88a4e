//! The `.x3p` writer: the layout of the parent module, with incremental CX/CY axes
//! (Increment = dx, dy), an absolute CZ axis and the points in `bindata/data.bin`.
//!
//! `D` (float64) stores every height exactly (a strata round trip is lossless). `F`
//! rounds to float32. The integer types store v = round((z − Offset)/Increment) with
//! Offset = (z_max + z_min)/2 and Increment = (z_max − z_min)/(2·v_max), v_max = 32767
//! (`I`) or 2147483647 (`L`): the error is at most Increment/2 per height.

use std::io::{Cursor, Write};
use std::path::Path;

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

use super::DataType;
use crate::resources::{MemoryLimit, bytes_for};
use crate::surface::{Surface, SurfaceError};

/// How [`Surface::write_x3p`] stores the heights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct X3pWriteOptions {
    /// CZ data type (default `D`, lossless).
    pub data_type: DataType,
    /// `Record2/Comment` (e.g. where the surface came from).
    pub comment: Option<String>,
    /// The memory limit the encoded file is checked against before it is built.
    pub memory: MemoryLimit,
}

/// XML text escaping (&, <, >, ", ').
fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            c if (c as u32) < 0x20 && !matches!(c, '\n' | '\r' | '\t') => {}
            c => o.push(c),
        }
    }
    o
}

/// UTC date and time `YYYY-MM-DDThh:mm:ssZ` (xsd:dateTime) of `secs` since 1970
/// (civil-from-days, proleptic Gregorian calendar).
fn utc_datetime(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
}

impl Surface {
    /// The `.x3p` container of this surface as bytes (module docs).
    pub fn to_x3p_bytes(&self, opts: &X3pWriteOptions) -> Result<Vec<u8>, SurfaceError> {
        let (nx, ny) = self.shape();
        let (dx, dy) = self.pixel_size();
        let t = opts.data_type;
        let n = nx * ny;
        opts.memory.check(
            format!("writing the {nx}×{ny} grid as .x3p"),
            bytes_for(n as u64, 2 * t.bytes() as u64 + 8),
        )?;
        let (lo, hi) = self
            .heights()
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &z| {
                (a.min(z), b.max(z))
            });
        let top = lo.abs().max(hi.abs());
        if t == DataType::F && top > f32::MAX as f64 {
            return Err(SurfaceError::Unsupported(format!(
                "heights up to {top:e} m do not fit the .x3p data type F (float32, up to {:e}); \
                 write them as D (float64)",
                f32::MAX
            )));
        }
        let vmax = match t {
            DataType::I => Some(i16::MAX as f64),
            DataType::L => Some(i32::MAX as f64),
            _ => None,
        };
        let (offset, increment) = match vmax {
            Some(v) if hi > lo => (0.5 * (hi + lo), (hi - lo) / (2.0 * v)),
            Some(_) => (lo, 1.0),
            None => (0.0, 1.0),
        };
        let mut data = Vec::with_capacity(n * t.bytes());
        for j in 0..ny {
            for i in 0..nx {
                let z = self.z(i, j);
                match t {
                    DataType::D => data.extend_from_slice(&z.to_le_bytes()),
                    DataType::F => data.extend_from_slice(&(z as f32).to_le_bytes()),
                    DataType::I => {
                        let v = ((z - offset) / increment).round().clamp(-32767.0, 32767.0);
                        data.extend_from_slice(&(v as i16).to_le_bytes())
                    }
                    DataType::L => {
                        let v = ((z - offset) / increment)
                            .round()
                            .clamp(-2_147_483_647.0, 2_147_483_647.0);
                        data.extend_from_slice(&(v as i32).to_le_bytes())
                    }
                }
            }
        }
        let data_md5 = format!("{:x}", md5::compute(&data));
        let now = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0);
        let comment = opts
            .comment
            .as_deref()
            .map(|c| format!("\n    <Comment>{}</Comment>", escape(c)))
            .unwrap_or_default();
        let main = format!(
            r#"<?xml version="1.0" encoding="UTF-8" standalone="no" ?>
<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:schemaLocation="http://www.opengps.eu/2008/ISO5436_2 http://www.opengps.eu/2008/ISO5436_2/ISO5436_2.xsd">
  <Record1>
    <Revision>ISO5436 - 2000</Revision>
    <FeatureType>SUR</FeatureType>
    <Axes>
      <CX>
        <AxisType>I</AxisType>
        <DataType>D</DataType>
        <Increment>{dx:e}</Increment>
        <Offset>0</Offset>
      </CX>
      <CY>
        <AxisType>I</AxisType>
        <DataType>D</DataType>
        <Increment>{dy:e}</Increment>
        <Offset>0</Offset>
      </CY>
      <CZ>
        <AxisType>A</AxisType>
        <DataType>{code}</DataType>
        <Increment>{increment:e}</Increment>
        <Offset>{offset:e}</Offset>
      </CZ>
    </Axes>
  </Record1>
  <Record2>
    <Date>{date}</Date>
    <Instrument>
      <Manufacturer>strata</Manufacturer>
      <Model>strata-runtime</Model>
      <Serial>not available</Serial>
      <Version>{version}</Version>
    </Instrument>
    <ProbingSystem>
      <Type>Software</Type>
      <Identification>strata surface export</Identification>
    </ProbingSystem>{comment}
  </Record2>
  <Record3>
    <MatrixDimension>
      <SizeX>{nx}</SizeX>
      <SizeY>{ny}</SizeY>
      <SizeZ>1</SizeZ>
    </MatrixDimension>
    <DataLink>
      <PointDataLink>bindata/data.bin</PointDataLink>
      <MD5ChecksumPointData>{data_md5}</MD5ChecksumPointData>
    </DataLink>
  </Record3>
  <Record4>
    <ChecksumFile>md5checksum.hex</ChecksumFile>
  </Record4>
</p:ISO5436_2>
"#,
            code = t.code(),
            date = utc_datetime(now),
            version = env!("CARGO_PKG_VERSION"),
        );
        let main_md5 = format!("{:x}", md5::compute(main.as_bytes()));
        let io = |e: std::io::Error| SurfaceError::Io {
            path: "x3p container".into(),
            message: e.to_string(),
        };
        let zerr = |e: zip::result::ZipError| io(std::io::Error::other(e));
        let opt = SimpleFileOptions::default()
            .compression_method(CompressionMethod::Deflated)
            .large_file(data.len() as u64 >= u32::MAX as u64);
        let mut zip = ZipWriter::new(Cursor::new(Vec::with_capacity(data.len() / 2 + 4096)));
        zip.start_file("main.xml", opt).map_err(zerr)?;
        zip.write_all(main.as_bytes()).map_err(io)?;
        zip.start_file("bindata/data.bin", opt).map_err(zerr)?;
        zip.write_all(&data).map_err(io)?;
        zip.start_file("md5checksum.hex", opt).map_err(zerr)?;
        zip.write_all(format!("{main_md5} *main.xml\n").as_bytes())
            .map_err(io)?;
        Ok(zip.finish().map_err(zerr)?.into_inner())
    }

    /// Writes this surface as an ISO 25178-72 `.x3p` file (module docs), atomically.
    pub fn write_x3p(&self, path: &Path, opts: &X3pWriteOptions) -> Result<(), SurfaceError> {
        let bytes = self.to_x3p_bytes(opts)?;
        crate::output::write_atomic(path, &bytes).map_err(|e| SurfaceError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::parse_x3p;
    use super::*;
    use crate::surface::Spacing;

    #[test]
    fn dates() {
        assert_eq!(utc_datetime(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc_datetime(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc_datetime(1_700_000_000), "2023-11-14T22:13:20Z");
        assert_eq!(escape("a<&>\"'b\u{1}"), "a&lt;&amp;&gt;&quot;&apos;b");
    }

    fn sample() -> Surface {
        let (n0, n1) = (7, 5);
        let z = (0..n0 * n1)
            .map(|k| 1e-6 * ((k as f64 * 0.37).sin() + 0.1 * (k / n1) as f64))
            .collect();
        Surface::with_spacing(z, n0, n1, Spacing::Pixel(1.5e-6, 2.25e-6), false).unwrap()
    }

    /// D round trip is exact (heights, grid, pixel sizes); F to float32 rounding; I/L
    /// within Increment/2; the container verifies (no warnings).
    #[test]
    fn round_trip_all_types() {
        let s = sample();
        for t in [DataType::D, DataType::F, DataType::L, DataType::I] {
            let bytes = s
                .to_x3p_bytes(&X3pWriteOptions {
                    data_type: t,
                    comment: Some("test <surface> & co".into()),
                    ..X3pWriteOptions::default()
                })
                .unwrap();
            let x = parse_x3p(Cursor::new(bytes), "mem", &MemoryLimit::default()).unwrap();
            assert!(x.warnings.is_empty(), "{:?}", x.warnings);
            assert_eq!((x.nx, x.ny, x.dx, x.dy), (7, 5, 1.5e-6, 2.25e-6));
            assert_eq!(x.data_type, t);
            assert_eq!(x.comment.as_deref(), Some("test <surface> & co"));
            let (lo, hi) = (
                s.heights().iter().copied().fold(f64::MAX, f64::min),
                s.heights().iter().copied().fold(f64::MIN, f64::max),
            );
            let tol = match t {
                DataType::D => 0.0,
                DataType::F => 1e-7 * hi.abs().max(lo.abs()),
                DataType::L => 0.5 * (hi - lo) / (2.0 * i32::MAX as f64) * 1.000001,
                DataType::I => 0.5 * (hi - lo) / (2.0 * i16::MAX as f64) * 1.000001,
            };
            for (a, b) in x.heights.iter().zip(s.heights()) {
                assert!((a - b).abs() <= tol, "{t:?}: {a:e} {b:e} tol {tol:e}");
            }
        }
    }
}
