//! CSV output through the `csv` crate (quoting, one record per line): numbers are
//! written in full precision as Rust's `{:e}` (shortest round trip, e.g. `3.4e-6`),
//! non-finite values as empty fields.

use std::io::Write;

use thiserror::Error;

/// A CSV that could not be written.
#[derive(Debug, Error)]
pub enum CsvError {
    #[error("writing CSV: {0}")]
    Io(std::io::Error),
    #[error("writing CSV: {0}")]
    Other(String),
}

/// For writers whose errors are I/O errors ([`crate::stdio::print`]): the I/O error
/// itself, anything else as an "other" error with this message.
impl From<CsvError> for std::io::Error {
    fn from(e: CsvError) -> Self {
        match e {
            CsvError::Io(io) => io,
            other => std::io::Error::other(other.to_string()),
        }
    }
}

impl From<csv::Error> for CsvError {
    fn from(e: csv::Error) -> Self {
        match e.into_kind() {
            csv::ErrorKind::Io(io) => CsvError::Io(io),
            other => CsvError::Other(format!("{other:?}")),
        }
    }
}

/// A number field: `{:e}` (full precision), empty when not finite.
pub fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:e}")
    } else {
        String::new()
    }
}

/// Writes the header and the records to `out`.
pub fn write<W: Write, H, R, I>(out: W, header: H, rows: R) -> Result<(), CsvError>
where
    H: IntoIterator,
    H::Item: AsRef<[u8]>,
    R: IntoIterator<Item = I>,
    I: IntoIterator,
    I::Item: AsRef<[u8]>,
{
    let mut w = csv::WriterBuilder::new().flexible(false).from_writer(out);
    w.write_record(header)?;
    for r in rows {
        w.write_record(r)?;
    }
    w.flush().map_err(CsvError::Io)
}

pub use strata_engine::engine::CURVE_HEADER;

/// The CSV text of the header and the records.
pub fn text<H, R, I>(header: H, rows: R) -> Result<String, CsvError>
where
    H: IntoIterator,
    H::Item: AsRef<[u8]>,
    R: IntoIterator<Item = I>,
    I: IntoIterator,
    I::Item: AsRef<[u8]>,
{
    let mut buf = Vec::new();
    write(&mut buf, header, rows)?;
    String::from_utf8(buf).map_err(|e| CsvError::Other(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quotes_and_numbers() {
        let t = text(
            &["panel", "x"],
            [
                vec!["a, b".to_string(), num(3.4e-6)],
                vec!["c".into(), num(f64::NAN)],
            ],
        )
        .unwrap();
        assert_eq!(t, "panel,x\n\"a, b\",3.4e-6\nc,\n");
        assert_eq!(num(1e300), "1e300");
    }
}
