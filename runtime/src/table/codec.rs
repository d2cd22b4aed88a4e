//! The on-disk format of a table — the ONLY module that touches bincode (2.0.1 is
//! unmaintained, RUSTSEC-2025-0141: the format can change here alone).
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
pub const MAX_PAYLOAD: u64 = 1 << 30;

/// Serialises a table (header and arrays) to bytes.
pub fn encode(table: &Table) -> Result<Vec<u8>, TableError> {
    let config = bincode::config::standard();
    let (version, payload) = match table.header.stack.counterface() {
        None => (FORMAT_VERSION, bincode::serde::encode_to_vec(table, config)),
        Some(c) => (
            PAIR_VERSION,
            bincode::serde::encode_to_vec((table, c), config),
        ),
    };
    let payload = payload.map_err(|e| TableError::Corrupt(format!("cannot encode table: {e}")))?;
    let mut out = Vec::with_capacity(PREFIX + payload.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&fnv1a(&payload).to_le_bytes());
    out.extend_from_slice(&payload);
    Ok(out)
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

/// Parses bytes into a table, checking magic, version, length and checksum, then
/// the table's own consistency ([`Table::validate`]). Never panics.
pub fn decode(bytes: &[u8]) -> Result<Table, TableError> {
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err(TableError::NotATable);
    }
    if bytes.len() < PREFIX {
        return Err(TableError::Truncated {
            expected: PREFIX as u64,
            found: bytes.len() as u64,
        });
    }
    let mut v = [0u8; 4];
    v.copy_from_slice(&bytes[8..12]);
    let version = u32::from_le_bytes(v);
    if version != FORMAT_VERSION && version != PAIR_VERSION {
        return Err(TableError::WrongVersion {
            found: version,
            expected: FORMAT_VERSION,
        });
    }
    let len = u64_at(bytes, 12);
    let sum = u64_at(bytes, 20);
    if len > MAX_PAYLOAD {
        return Err(TableError::Corrupt(format!(
            "payload length {len} bytes exceeds the {MAX_PAYLOAD}-byte limit"
        )));
    }
    let have = (bytes.len() - PREFIX) as u64;
    if have < len {
        return Err(TableError::Truncated {
            expected: PREFIX as u64 + len,
            found: bytes.len() as u64,
        });
    }
    if have > len {
        return Err(TableError::Corrupt(format!(
            "{} trailing bytes after the payload",
            have - len
        )));
    }
    let payload = &bytes[PREFIX..];
    if fnv1a(payload) != sum {
        return Err(TableError::Corrupt(
            "checksum mismatch (the file was modified or damaged)".into(),
        ));
    }
    let config = bincode::config::standard().with_limit::<{ MAX_PAYLOAD as usize }>();
    let bad =
        |e: bincode::error::DecodeError| TableError::Corrupt(format!("cannot decode payload: {e}"));
    let (table, used) = if version == FORMAT_VERSION {
        bincode::serde::decode_from_slice::<Table, _>(payload, config).map_err(bad)?
    } else {
        let ((mut table, counterface), used): ((Table, Stack), usize) =
            bincode::serde::decode_from_slice(payload, config).map_err(bad)?;
        // Deserialisation bypasses Stack::new: re-validate before attaching.
        let mut c = Stack::new(counterface.layers().to_vec(), counterface.base())?;
        c.name = counterface.name.clone();
        table.header.stack = table.header.stack.against(c)?;
        (table, used)
    };
    if used != payload.len() {
        return Err(TableError::Corrupt("payload has unread bytes".into()));
    }
    table.validate()?;
    Ok(table)
}
