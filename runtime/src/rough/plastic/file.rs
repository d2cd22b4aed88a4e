//! The file form of the capped asperity's response table ([`PlasticResponse`],
//! physics.md §9), so that the table cache keeps it (`strata_tablegen`'s
//! `plastic_asperity::cached_response`, file `capped-<hex>.strata`): a table is solved
//! once per stack and hardness (13–18 CPU-s of ring solves on a layered stack) and read
//! by every later `strata solve`, `law` and `compare`.
//!
//! # File form (little endian)
//! ```text
//!   bytes 0..8    magic "STRATAPR"
//!   bytes 8..12   format version (u32, [`FORMAT_VERSION`])
//!   bytes 12..20  key (u64): the writer's fingerprint of the stack, hardness and grid
//!   bytes 20..28  E* (f64, Pa)
//!   bytes 28..36  H (f64, Pa)
//!   bytes 36..40  1 when h₁ is given (layered), 0 on a homogeneous solid (u32)
//!   bytes 40..48  h₁ (f64, m; 0 when not given)
//!   bytes 48..68  x axis: ln lo, ln hi (f64), nodes n_x (u32)
//!   bytes 68..88  y axis: ln lo, ln hi (f64), nodes n_y (u32)
//!   bytes 88..    ln F, ln G, Φ: n_x·n_y f64 each, index j·n_x + i
//!   last 8 bytes  FNV-1a 64 of everything before them
//! ```

use thiserror::Error;

use super::{LogAxis, PlasticResponse};
use crate::hash::fnv1a;

/// Version of the file form written by this build.
pub const FORMAT_VERSION: u32 = 1;

/// File signature.
pub const MAGIC: &[u8; 8] = b"STRATAPR";

const HEADER: usize = 88;

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
    #[error(
        "capped asperity table is truncated or has trailing bytes: expected {expected} bytes, found {found}"
    )]
    Length { expected: u128, found: u64 },
    #[error("capped asperity table checksum mismatch (the file was modified or damaged)")]
    Checksum,
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
        let n = self.ln_f.len() + self.ln_g.len() + self.phi.len();
        let mut out = Vec::with_capacity(HEADER + 8 * n + 8);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&key.to_le_bytes());
        out.extend_from_slice(&self.e_star.to_le_bytes());
        out.extend_from_slice(&self.hardness.to_le_bytes());
        out.extend_from_slice(&u32::from(self.h1.is_some()).to_le_bytes());
        out.extend_from_slice(&self.h1.unwrap_or(0.0).to_le_bytes());
        for a in [self.x, self.y] {
            out.extend_from_slice(&a.lo.to_le_bytes());
            out.extend_from_slice(&a.hi.to_le_bytes());
            out.extend_from_slice(&(a.n as u32).to_le_bytes());
        }
        for v in self.ln_f.iter().chain(&self.ln_g).chain(&self.phi) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        let sum = fnv1a(&out);
        out.extend_from_slice(&sum.to_le_bytes());
        out
    }

    /// Parses and validates the file form: the writer's key and the table. Never
    /// panics; refuses a wrong signature or version, a wrong length, a checksum
    /// mismatch and inconsistent contents (non-finite values, array lengths that do
    /// not match the axes, Φ outside [0, 1]).
    pub fn from_bytes(b: &[u8]) -> Result<(u64, PlasticResponse), ResponseFileError> {
        if b.len() < MAGIC.len() || &b[..MAGIC.len()] != MAGIC {
            return Err(ResponseFileError::NotATable);
        }
        if b.len() < HEADER + 8 {
            return Err(ResponseFileError::Length {
                expected: (HEADER + 8) as u128,
                found: b.len() as u64,
            });
        }
        let word = |at: usize| -> [u8; 8] {
            let mut w = [0u8; 8];
            w.copy_from_slice(&b[at..at + 8]);
            w
        };
        let half = |at: usize| -> u32 {
            let mut w = [0u8; 4];
            w.copy_from_slice(&b[at..at + 4]);
            u32::from_le_bytes(w)
        };
        let real = |at: usize| f64::from_le_bytes(word(at));
        let version = half(8);
        if version != FORMAT_VERSION {
            return Err(ResponseFileError::WrongVersion { found: version });
        }
        let (nx, ny) = (half(64), half(84));
        let n = u128::from(nx) * u128::from(ny);
        let expected = HEADER as u128 + 3 * 8 * n + 8;
        if b.len() as u128 != expected {
            return Err(ResponseFileError::Length {
                expected,
                found: b.len() as u64,
            });
        }
        let body = b.len() - 8;
        if fnv1a(&b[..body]) != u64::from_le_bytes(word(body)) {
            return Err(ResponseFileError::Checksum);
        }
        // the length matched: n values of each array lie in the file
        let n = n as usize;
        let array =
            |k: usize| -> Vec<f64> { (0..n).map(|i| real(HEADER + 8 * (k * n + i))).collect() };
        let h1 = match half(36) {
            0 => None,
            1 => Some(real(40)),
            f => {
                return Err(ResponseFileError::Invalid(format!("h1 flag {f} (0 or 1)")));
            }
        };
        let axis = |at: usize, n: u32| LogAxis {
            lo: real(at),
            hi: real(at + 8),
            n: n as usize,
        };
        let r = PlasticResponse {
            e_star: real(20),
            hardness: real(28),
            h1,
            x: axis(48, nx),
            y: axis(68, ny),
            ln_f: array(0),
            ln_g: array(1),
            phi: array(2),
        };
        check(&r).map_err(ResponseFileError::Invalid)?;
        Ok((u64::from_le_bytes(word(12)), r))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
                    matches!(e, ResponseFileError::Length { .. })
                };
                assert!(want, "cut at {cut}: {e:?}");
            }
            let mut long = b.clone();
            long.push(0);
            assert!(matches!(
                PlasticResponse::from_bytes(&long),
                Err(ResponseFileError::Length { .. })
            ));
            // any flipped byte after the header's counts is caught by the checksum
            for at in (12..64).chain(68..84).chain(88..b.len()) {
                let mut f = b.clone();
                f[at] ^= 0x04;
                assert_eq!(
                    PlasticResponse::from_bytes(&f),
                    Err(ResponseFileError::Checksum),
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
            // a count changed: the length no longer matches, whatever the count
            for big in [0u32, 5, u32::MAX] {
                let mut c = b.clone();
                c[64..68].copy_from_slice(&big.to_le_bytes());
                assert!(matches!(
                    PlasticResponse::from_bytes(&c),
                    Err(ResponseFileError::Length { .. })
                ));
            }
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
        let mut b = table(None).to_bytes(1);
        b[36] = 7;
        let body = b.len() - 8;
        let sum = fnv1a(&b[..body]);
        b[body..].copy_from_slice(&sum.to_le_bytes());
        assert!(matches!(
            PlasticResponse::from_bytes(&b),
            Err(ResponseFileError::Invalid(_))
        ));
    }
}
