//! The file form of the capped asperity's response table ([`PlasticResponse`],
//! physics.md §9), so that the table cache keeps it (`asperity::cached_response`, file
//! `capped-<hex>.strata`): a table is solved
//! once per stack and hardness (13–18 CPU-s of ring solves on a layered stack) and read
//! by every later `strata solve`, `law` and `compare`.
//!
//! # File form
//! The framed form of every strata table file (`table::codec::frame`: magic
//! "STRATAPR", version [`FORMAT_VERSION`], payload length, FNV-1a 64 checksum), the
//! payload bincode of (the writer's key: its fingerprint of the stack, hardness and
//! grid; the table).

use thiserror::Error;

use super::PlasticResponse;
use crate::table::codec::{FrameError, frame, from_payload, to_payload, unframe};

/// Version of the file form written by this build.
pub const FORMAT_VERSION: u32 = 1;

/// File signature.
pub const MAGIC: &[u8; 8] = b"STRATAPR";

/// A response table file that cannot be read or is inconsistent.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ResponseFileError {
    #[error("not a strata capped asperity table (bad signature)")]
    NotATable,
    #[error(
        "capped asperity table format version {found} is not supported (this strata reads version {FORMAT_VERSION})"
    )]
    WrongVersion { found: u32 },
    #[error("capped asperity table is damaged: {0}")]
    Damaged(String),
    #[error("capped asperity table is inconsistent: {0}")]
    Invalid(String),
}

/// The problems of a table's scalars, axes and arrays, if any (every value finite, the
/// moduli and h₁ positive, Φ ∈ [0, 1], n_x·n_y values per array, one y node without h₁).
fn check(r: &PlasticResponse) -> Result<(), String> {
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if !positive(r.e_star) {
        return Err(format!("E* = {:e} Pa", r.e_star));
    }
    if !positive(r.hardness) {
        return Err(format!("H = {:e} Pa", r.hardness));
    }
    match r.h1 {
        Some(h) if !positive(h) => return Err(format!("h1 = {h:e} m")),
        None if r.y.n != 1 => return Err(format!("{} y nodes without h1", r.y.n)),
        _ => {}
    }
    for (name, a) in [("x", r.x), ("y", r.y)] {
        let spans = if a.n > 1 { a.hi > a.lo } else { a.hi >= a.lo };
        if a.n == 0 || !(a.lo.is_finite() && a.hi.is_finite() && spans) {
            return Err(format!(
                "{name} axis ln {} … {} with {} nodes",
                a.lo, a.hi, a.n
            ));
        }
    }
    let n = r.x.n.checked_mul(r.y.n).ok_or("too many nodes")?;
    for (name, v) in [("ln F", &r.ln_f), ("ln G", &r.ln_g), ("Φ", &r.phi)] {
        if v.len() != n {
            return Err(format!("{} {name} values for {n} nodes", v.len()));
        }
        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
            return Err(format!("{name} value {x}"));
        }
    }
    if let Some(x) = r.phi.iter().find(|x| !(0.0..=1.0).contains(*x)) {
        return Err(format!("Φ = a_p/a = {x} outside [0, 1]"));
    }
    Ok(())
}

impl PlasticResponse {
    /// The file form (module docs) with the writer's `key`.
    pub fn to_bytes(&self, key: u64) -> Vec<u8> {
        // bincode cannot fail on these plain values; were it to, the empty payload
        // would read back as damaged and the table be solved again
        let payload = to_payload(&(key, self)).unwrap_or_default();
        frame(MAGIC, FORMAT_VERSION, &payload)
    }

    /// Parses and validates the file form: the writer's key and the table. Never
    /// panics; refuses a wrong signature or version, damage (length, checksum, an
    /// undecodable payload) and inconsistent contents (non-finite values, array lengths
    /// that do not match the axes, Φ outside [0, 1]).
    pub fn from_bytes(b: &[u8]) -> Result<(u64, PlasticResponse), ResponseFileError> {
        let (_, payload) = unframe(b, MAGIC, &[FORMAT_VERSION]).map_err(|e| match e {
            FrameError::Magic => ResponseFileError::NotATable,
            FrameError::Version(found) => ResponseFileError::WrongVersion { found },
            other => ResponseFileError::Damaged(format!("{other:?}")),
        })?;
        let (key, r): (u64, PlasticResponse) =
            from_payload(payload).map_err(ResponseFileError::Damaged)?;
        check(&r).map_err(ResponseFileError::Invalid)?;
        Ok((key, r))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rough::plastic::LogAxis;

    /// A small layered table with smooth made-up values (2 × 3 nodes).
    fn table(h1: Option<f64>) -> PlasticResponse {
        let ny = if h1.is_some() { 3 } else { 1 };
        let n = 4 * ny;
        PlasticResponse {
            e_star: 2.3e9,
            hardness: 0.2e9,
            h1,
            x: LogAxis {
                lo: -4.6,
                hi: 4.6,
                n: 4,
            },
            y: LogAxis {
                lo: -6.9,
                hi: if ny > 1 { 1.1 } else { -6.9 },
                n: ny,
            },
            ln_f: (0..n).map(|k| 0.3 * k as f64 - 1.0).collect(),
            ln_g: (0..n).map(|k| -0.1 * k as f64).collect(),
            phi: (0..n).map(|k| k as f64 / n as f64).collect(),
        }
    }

    /// The file form round-trips bit for bit (layered and homogeneous); damage is
    /// refused with the right error, never a panic.
    #[test]
    fn file_form_round_trips_and_refuses_damage() {
        for t in [table(Some(5e-6)), table(None)] {
            let b = t.to_bytes(0xfeed);
            assert_eq!(
                PlasticResponse::from_bytes(&b).unwrap(),
                (0xfeed, t.clone())
            );
            // every truncation, and a trailing byte
            for cut in 0..b.len() {
                let e = PlasticResponse::from_bytes(&b[..cut]).unwrap_err();
                let want = if cut < MAGIC.len() {
                    matches!(e, ResponseFileError::NotATable)
                } else {
                    matches!(e, ResponseFileError::Damaged(_))
                };
                assert!(want, "cut at {cut}: {e:?}");
            }
            let mut long = b.clone();
            long.push(0);
            assert!(matches!(
                PlasticResponse::from_bytes(&long),
                Err(ResponseFileError::Damaged(_))
            ));
            // any flipped byte after the version: the length or the checksum
            for at in 12..b.len() {
                let mut f = b.clone();
                f[at] ^= 0x04;
                assert!(
                    matches!(
                        PlasticResponse::from_bytes(&f),
                        Err(ResponseFileError::Damaged(_))
                    ),
                    "byte {at}"
                );
            }
            let mut v = b.clone();
            v[8] = 2;
            assert_eq!(
                PlasticResponse::from_bytes(&v),
                Err(ResponseFileError::WrongVersion { found: 2 })
            );
            let mut m = b.clone();
            m[0] = b'X';
            assert_eq!(
                PlasticResponse::from_bytes(&m),
                Err(ResponseFileError::NotATable)
            );
        }
    }

    /// Well-formed files of inconsistent tables are refused (a correct checksum over
    /// wrong contents).
    #[test]
    fn inconsistent_tables_are_refused() {
        let damaged: [fn(&mut PlasticResponse); 6] = [
            |t| t.ln_f[2] = f64::NAN,
            |t| t.phi[1] = 1.5,
            |t| t.e_star = -1.0,
            |t| t.h1 = Some(f64::INFINITY),
            |t| t.h1 = None,
            |t| t.x.hi = t.x.lo,
        ];
        for f in damaged {
            let mut t = table(Some(5e-6));
            f(&mut t);
            assert!(
                matches!(
                    PlasticResponse::from_bytes(&t.to_bytes(1)),
                    Err(ResponseFileError::Invalid(_))
                ),
                "{t:?}"
            );
        }
        // a payload that decodes to another type's bytes: refused as damaged
        let other = crate::table::codec::frame(
            MAGIC,
            FORMAT_VERSION,
            &crate::table::codec::to_payload(&(1u64, 2.0f64)).unwrap(),
        );
        assert!(matches!(
            PlasticResponse::from_bytes(&other),
            Err(ResponseFileError::Damaged(_))
        ));
    }
}
