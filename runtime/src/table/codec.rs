//! The on-disk format of a table — the ONLY module that touches bincode (2.0.1 is
//! unmaintained, RUSTSEC-2025-0141: the format can change here alone). The framing
//! ([`frame`], `unframe`) and the payload codec (`to_payload`, `from_payload`) are
//! also the file form of the table cache's ψ tables ([`crate::constriction`]) and capped
//! response tables (`rough::plastic::file`), each with its own magic.
//!
//! Layout (little endian):
//!
//! ```text
//!   bytes 0..8    magic  "STRATATB"
//!   bytes 8..12   format version (u32)
//!   bytes 12..20  payload length in bytes (u64)
//!   bytes 20..28  FNV-1a 64 checksum of the payload (u64)
//!   bytes 28..    payload: bincode 2 (serde, standard config) of `Table`
//! ```
//!
//! A table of a stack pressed against an elastic counterface (physics.md §6.1) is
//! stored as version [`PAIR_VERSION`]: the same payload followed by the counterface's
//! stack, bincode of the tuple `(Table, Stack)`; a table without one keeps version
//! [`FORMAT_VERSION`] and its bytes.
//!
//! The version is read before the payload is decoded, so a file from another
//! format version is reported as such, not as corrupt.

use super::{FORMAT_VERSION, Table, TableError};
use crate::hash::fnv1a;
use crate::stack::Stack;

/// File version of a table whose stack has an elastic counterface: the
/// [`FORMAT_VERSION`] payload followed by the counterface stack.
pub const PAIR_VERSION: u32 = FORMAT_VERSION + 1;

/// File signature.
pub const MAGIC: &[u8; 8] = b"STRATATB";
const PREFIX: usize = 28;
/// Largest payload accepted (1 GiB; the shipped family table is under 1 MB). The
/// decoder runs with this limit, so a damaged length prefix inside the payload cannot
/// make bincode allocate more than this (it asked for 3e18 bytes and aborted before).
pub(crate) const MAX_PAYLOAD: u64 = 1 << 30;

/// The file form of a table (the table itself knows nothing of it: this module imports
/// `table`, never the other way).
impl Table {
    /// Serialises the table, validated first ([`encode`]).
    pub fn to_bytes(&self) -> Result<Vec<u8>, TableError> {
        self.validate()?;
        encode(self)
    }

    /// Parses and validates a table ([`decode`]).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, TableError> {
        decode(bytes)
    }
}

/// Serialises a table (header and arrays) to bytes.
pub fn encode(table: &Table) -> Result<Vec<u8>, TableError> {
    let (version, payload) = match table.header.counterface.stack() {
        None => (FORMAT_VERSION, to_payload(table)),
        Some(c) => (PAIR_VERSION, to_payload(&(table, c))),
    };
    let payload = payload.map_err(|e| TableError::Corrupt(format!("cannot encode table: {e}")))?;
    Ok(frame(MAGIC, version, &payload))
}

/// Why a framed file's bytes are refused before their payload is decoded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum FrameError {
    /// Not the expected signature.
    Magic,
    /// A format version the reader does not accept.
    Version(u32),
    /// Fewer bytes than the prefix or the payload length says.
    Truncated { expected: u64, found: u64 },
    /// The payload length exceeds `MAX_PAYLOAD`.
    TooLarge(u64),
    /// Bytes after the payload.
    Trailing(u64),
    /// The payload's checksum does not match.
    Checksum,
}

/// The framed file form of every strata file that keeps numbers (module docs): magic,
/// version, payload length, FNV-1a 64 of the payload, the payload. Also the form of the
/// table cache's ψ tables ([`crate::constriction`]) and capped response tables
/// ([`crate::rough::plastic`]).
pub fn frame(magic: &[u8; 8], version: u32, payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(PREFIX + payload.len());
    out.extend_from_slice(magic);
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&fnv1a(payload).to_le_bytes());
    out.extend_from_slice(payload);
    out
}

/// The version and payload of a framed file (see [`frame`]), checked in this order:
/// signature, prefix length, version (one of `versions`), payload length, checksum.
/// Never panics.
pub(crate) fn unframe<'a>(
    bytes: &'a [u8],
    magic: &[u8; 8],
    versions: &[u32],
) -> Result<(u32, &'a [u8]), FrameError> {
    if bytes.len() < magic.len() || &bytes[..magic.len()] != magic {
        return Err(FrameError::Magic);
    }
    if bytes.len() < PREFIX {
        return Err(FrameError::Truncated {
            expected: PREFIX as u64,
            found: bytes.len() as u64,
        });
    }
    let mut v = [0u8; 4];
    v.copy_from_slice(&bytes[8..12]);
    let version = u32::from_le_bytes(v);
    if !versions.contains(&version) {
        return Err(FrameError::Version(version));
    }
    let len = u64_at(bytes, 12);
    let sum = u64_at(bytes, 20);
    if len > MAX_PAYLOAD {
        return Err(FrameError::TooLarge(len));
    }
    let have = (bytes.len() - PREFIX) as u64;
    if have < len {
        return Err(FrameError::Truncated {
            expected: PREFIX as u64 + len,
            found: bytes.len() as u64,
        });
    }
    if have > len {
        return Err(FrameError::Trailing(have - len));
    }
    let payload = &bytes[PREFIX..];
    if fnv1a(payload) != sum {
        return Err(FrameError::Checksum);
    }
    Ok((version, payload))
}

/// bincode 2 (serde, standard config) of `value`: a framed file's payload.
pub(crate) fn to_payload<T: serde::Serialize>(value: &T) -> Result<Vec<u8>, String> {
    bincode::serde::encode_to_vec(value, bincode::config::standard()).map_err(|e| e.to_string())
}

/// A payload decoded by `to_payload`'s rules, every byte used, no allocation above
/// `MAX_PAYLOAD`. Never panics.
pub(crate) fn from_payload<T: serde::de::DeserializeOwned>(payload: &[u8]) -> Result<T, String> {
    let config = bincode::config::standard().with_limit::<{ MAX_PAYLOAD as usize }>();
    let (value, used) = bincode::serde::decode_from_slice::<T, _>(payload, config)
        .map_err(|e| format!("cannot decode payload: {e}"))?;
    if used != payload.len() {
        return Err("payload has unread bytes".into());
    }
    Ok(value)
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

/// Parses bytes into a table, checking magic, version, length and checksum, then
/// the table's own consistency ([`Table::validate`]). Never panics.
pub fn decode(bytes: &[u8]) -> Result<Table, TableError> {
    let (version, payload) =
        unframe(bytes, MAGIC, &[FORMAT_VERSION, PAIR_VERSION]).map_err(|e| match e {
            FrameError::Magic => TableError::NotATable,
            FrameError::Version(found) => TableError::WrongVersion {
                found,
                expected: FORMAT_VERSION,
            },
            FrameError::Truncated { expected, found } => TableError::Truncated { expected, found },
            FrameError::TooLarge(len) => TableError::Corrupt(format!(
                "payload length {len} bytes exceeds the {MAX_PAYLOAD}-byte limit"
            )),
            FrameError::Trailing(n) => {
                TableError::Corrupt(format!("{n} trailing bytes after the payload"))
            }
            FrameError::Checksum => {
                TableError::Corrupt("checksum mismatch (the file was modified or damaged)".into())
            }
        })?;
    let table = if version == FORMAT_VERSION {
        from_payload::<Table>(payload).map_err(TableError::Corrupt)?
    } else {
        let (mut table, counterface): (Table, Stack) =
            from_payload(payload).map_err(TableError::Corrupt)?;
        // Deserialisation bypasses Stack::new: re-validate before attaching.
        let mut c = Stack::new(counterface.layers().to_vec(), counterface.base())?;
        c.name = counterface.name.clone();
        table.header.counterface = crate::stack::Counterface::elastic(c);
        table
    };
    table.validate()?;
    Ok(table)
}
