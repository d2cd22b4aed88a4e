//! The constriction factor ψ of one contact spot on a layered conductor, tabulated
//! against a/h₁ (physics.md §6.2): an isothermal disc of radius a (m) on the
//! body conducts
//!
//! ```text
//!   G(a) = 4 k₁ a ψ(a/h₁)   (W/K, or S),
//! ```
//!
//! k₁ the top material's conductivity and h₁ the top layer's thickness (m); ψ ≡ 1 on a
//! homogeneous body. ψ depends on the stack only through its thicknesses and
//! conductivity ratios ([`crate::conduction::ConductionCompliance::fingerprint`]), and is
//! solved by the Fredholm spot solver of `strata-tablegen` (which builds these tables);
//! this module holds the table, its interpolation and its file form, so that a table is
//! built once per conducting stack and read by every later load path (the N and I
//! models' conductance, physics.md §6.2).
//!
//! # Grid
//! A [`crate::table::lobatto`] table (shared with the disc's punch factors): pieces of
//! log₁₀(a/h₁) on one fixed partition: whole decades up to a/h₁ = 10 and half
//! decades above ([`piece_start`]: piece k spans [k, k + 1] for k ≤ 0 and [1 + (k − 1)/2,
//! 1 + k/2] for k ≥ 1), each holding [`PIECE_NODES`] Chebyshev–Lobatto nodes in
//! log₁₀(a/h₁) (neighbouring pieces share their end node), interpolated in barycentric
//! form. Above a/h₁ = 10 a node is a product-integration solve whose cost grows like
//! (a/h₁)^1.5 (0.24 s at 100, 7.9 s at 1000), so the half decades keep a table within
//! √10 of the largest radius it must cover. A node's radius depends on (h₁, k, j) alone
//! ([`node_radius`]), so two tables of one stack agree bit for bit wherever they
//! overlap: a table read from a file and one built for a single load path give the
//! same ψ.
//!
//! # File form
//! The framed form of every strata table file (`table::codec::frame`: magic
//! "STRATAPS", version [`FORMAT_VERSION`], payload length, FNV-1a 64 checksum), the
//! payload bincode of (the stack's fingerprint, h₁, first piece k₀, the 8·pieces + 1
//! node values).

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::table::codec::{FrameError, frame, from_payload, to_payload, unframe};
use crate::table::lobatto::{Grid, LobattoTable};

/// Chebyshev–Lobatto nodes per piece (the end nodes shared with the neighbours: 8 solves
/// per piece).
pub const PIECE_NODES: usize = 9;

/// Version of the file form written by this build (2: half decades above a/h₁ = 10).
pub const FORMAT_VERSION: u32 = 2;

/// File signature.
pub const MAGIC: &[u8; 8] = b"STRATAPS";

/// Most pieces a table may span (a/h₁ over some 40 decades at least: far beyond any
/// contact).
pub(crate) const MAX_PIECES: i32 = 80;

/// A ψ table that cannot be read or is inconsistent.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum PsiTableError {
    #[error("not a strata ψ table (bad signature)")]
    NotATable,
    #[error(
        "ψ table format version {found} is not supported (this strata reads version {FORMAT_VERSION})"
    )]
    WrongVersion { found: u32 },
    #[error("ψ table is damaged: {0}")]
    Damaged(String),
    #[error("ψ table is inconsistent: {0}")]
    Invalid(String),
}

/// The partition and nodes of a ψ table (module docs; [`crate::table::lobatto`]).
pub const GRID: Grid = Grid {
    nodes: PIECE_NODES,
    half_decades_from: Some(1),
    max_pieces: MAX_PIECES,
};

/// log₁₀(a/h₁) at the start of piece k: k for k ≤ 1 (whole decades), 1 + (k − 1)/2
/// above (half decades); exact in floating point.
pub fn piece_start(k: i32) -> f64 {
    GRID.piece_start(k)
}

/// The radius (m) of node j ∈ 0..[`PIECE_NODES`] of piece k of a stack whose top layer
/// is `h1` thick: a = h₁·10^(s + (e − s)(x_j + 1)/2), s and e the piece's ends
/// ([`piece_start`]). Node 8 of piece k and node 0 of piece k + 1 are the same bits.
pub fn node_radius(h1: f64, piece: i32, j: usize) -> f64 {
    GRID.node_radius(h1, piece, j)
}

/// The pieces [k₀, k₁) that cover radii `lo` ≤ `hi` (m) on a top layer `h1` thick, at
/// least one; None for radii that are not finite and positive or would span more than
/// `MAX_PIECES`.
pub fn pieces(h1: f64, lo: f64, hi: f64) -> Option<(i32, i32)> {
    if !(h1 > 0.0 && h1.is_finite() && lo > 0.0 && hi >= lo && hi.is_finite()) {
        return None;
    }
    let (l, h) = (
        GRID.piece_of((lo / h1).log10()),
        GRID.piece_end((hi / h1).log10()),
    );
    if !(l.is_finite() && h.is_finite()) || l < -1e3 || h > 1e3 {
        return None;
    }
    let (k0, k1) = (l as i32, (h as i32).max(l as i32 + 1));
    (k1 - k0 <= MAX_PIECES).then_some((k0, k1))
}

/// ψ of one layered conductor against a/h₁ over a range of pieces (module docs): read with
/// [`PsiTable::at`], filled by `strata-tablegen`'s `psi_table`. The values and their
/// interpolation are a [`LobattoTable`] of [`GRID`].
#[derive(Debug, Clone, PartialEq)]
pub struct PsiTable(LobattoTable<f64>);

impl PsiTable {
    /// A table of the stack with fingerprint `key` and top layer `h1` (m) from its node
    /// values over pieces first, first + 1, …: 8·pieces + 1 values, each finite and
    /// positive.
    pub fn from_nodes(key: u64, h1: f64, first: i32, psi: Vec<f64>) -> Result<Self, PsiTableError> {
        LobattoTable::from_nodes(GRID, key, h1, first, psi)
            .map(PsiTable)
            .map_err(PsiTableError::Invalid)
    }

    /// The stack's fingerprint the table was built for.
    pub fn key(&self) -> u64 {
        self.0.key()
    }

    /// h₁ (m).
    pub fn top_thickness(&self) -> f64 {
        self.0.top_thickness()
    }

    /// The pieces [k₀, k₁) held.
    pub fn pieces(&self) -> (i32, i32) {
        self.0.pieces()
    }

    /// The node values, piece by piece (shared ends once).
    pub fn nodes(&self) -> &[f64] {
        self.0.nodes()
    }

    /// True when the table holds every piece of [k₀, k₁).
    pub fn covers(&self, range: (i32, i32)) -> bool {
        self.0.covers(range)
    }

    /// ψ(a) at radius `a` (m) by the barycentric Lobatto interpolant of the piece
    /// holding a/h₁ (the end pieces extended for radii just outside; a table built for a
    /// load path covers all of its radii).
    pub fn at(&self, a: f64) -> f64 {
        self.0.at(a)
    }

    /// The file form (module docs).
    pub fn to_bytes(&self) -> Vec<u8> {
        let t = &self.0;
        // bincode cannot fail on these plain values; were it to, the empty payload
        // would read back as damaged and the table be solved again
        let payload =
            to_payload(&(t.key(), t.top_thickness(), t.first(), t.nodes())).unwrap_or_default();
        frame(MAGIC, FORMAT_VERSION, &payload)
    }

    /// Parses and validates the file form. Never panics.
    pub fn from_bytes(b: &[u8]) -> Result<Self, PsiTableError> {
        let (_, payload) = unframe(b, MAGIC, &[FORMAT_VERSION]).map_err(|e| match e {
            FrameError::Magic => PsiTableError::NotATable,
            FrameError::Version(found) => PsiTableError::WrongVersion { found },
            other => PsiTableError::Damaged(format!("{other:?}")),
        })?;
        let (key, h1, first, psi): (u64, f64, i32, Vec<f64>) =
            from_payload(payload).map_err(PsiTableError::Damaged)?;
        PsiTable::from_nodes(key, h1, first, psi)
    }
}

/// The file of a ψ table in the table cache `dir`: `psi-<key>.strata` (`key` the
/// stack's conduction fingerprint), beside the mechanics tables' `stack-<hex>.strata`.
pub fn cache_path(key: u64, dir: &Path) -> PathBuf {
    dir.join(format!("psi-{key:016x}.strata"))
}

/// The ψ table in the cache file `path` when it is a readable, undamaged table of the
/// stack `key` with top-layer thickness `h1` (m); None otherwise (missing, damaged or
/// foreign: the caller rebuilds it). A file larger than the machine's memory limit
/// counts as damaged (strata writes these files itself; they are a few kB).
pub fn read_cached(path: &Path, key: u64, h1: f64) -> Option<PsiTable> {
    let memory = crate::resources::MemoryLimit::of_machine();
    crate::resources::read_data_file(path, "a cache file", &memory)
        .ok()
        .and_then(|b| PsiTable::from_bytes(&b).ok())
        .filter(|t| t.key() == key && t.top_thickness() == h1)
}

/// One body's side of a contact spot, as its spot conductance G_X(a) enters the
/// series 1/G = 1/G_A + 1/G_B (physics.md §6.2).
#[derive(Debug, Clone, Copy)]
pub enum Side<'t> {
    /// A perfect conductor (1/G = 0).
    Perfect,
    /// G = 4 k a: a homogeneous conductor of conductivity k (W/(m·K) or S/m).
    Homogeneous(f64),
    /// G = 4 k₁ a ψ(a): a layered conductor of top conductivity k₁ and ψ table `table`
    /// (covering the radii asked for).
    Layered {
        /// k₁ (W/(m·K) or S/m).
        conductivity: f64,
        /// ψ(a) of the body.
        table: &'t PsiTable,
    },
}

impl Side<'_> {
    /// 1/G of this side at spot radius `r` (m): K/W or 1/S (0 for a perfect conductor).
    pub fn resistance(&self, r: f64) -> f64 {
        match self {
            Side::Perfect => 0.0,
            Side::Homogeneous(k) => 1.0 / (4.0 * k * r),
            Side::Layered {
                conductivity,
                table,
            } => 1.0 / (4.0 * conductivity * r * table.at(r)),
        }
    }
}

/// The smallest and largest positive, finite contact radius (m) over the steps of a
/// load path; None when no summit touches.
pub fn radius_range(steps: &[crate::rough::Step]) -> Option<(f64, f64)> {
    let (lo, hi) = steps
        .iter()
        .flat_map(|s| s.radii.iter().copied())
        .filter(|&a| a > 0.0 && a.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), a| {
            (lo.min(a), hi.max(a))
        });
    (hi > 0.0).then_some((lo, hi))
}

/// G(aᵢ) (W/K or S; 0 out of contact) of every summit of every step of a load path,
/// the sides `a` and `b` in series: 1/G = 1/G_A(aᵢ) + 1/G_B(aᵢ) (physics.md §6.2).
/// The N model's h_c is Σᵢ G(aᵢ)/A₀ per step; the I model's spot network takes these G.
pub fn series_conductances(
    a: &Side<'_>,
    b: &Side<'_>,
    steps: &[crate::rough::Step],
) -> Vec<Vec<f64>> {
    steps
        .iter()
        .map(|s| {
            s.radii
                .iter()
                .map(|&r| {
                    if r > 0.0 && r.is_finite() {
                        1.0 / (a.resistance(r) + b.resistance(r))
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth stand-in for ψ: 1 + x/(1 + x) with x = a/h₁ (analytic in ln a).
    fn f(x: f64) -> f64 {
        1.0 + x / (1.0 + x)
    }

    fn table(h1: f64, d0: i32, d1: i32) -> PsiTable {
        let mut psi = vec![];
        for d in d0..d1 {
            for j in 0..PIECE_NODES - usize::from(d + 1 < d1) {
                psi.push(f(node_radius(h1, d, j) / h1));
            }
        }
        PsiTable::from_nodes(7, h1, d0, psi).unwrap()
    }

    /// Shared end nodes are the same bits; the pieces cover the radii; the interpolant
    /// is exact at the nodes and close between them (measured 1.9e−7 on this f).
    #[test]
    fn grid_and_interpolation() {
        let h1 = 3e-5;
        for k in -3..6 {
            assert_eq!(node_radius(h1, k, 8), node_radius(h1, k + 1, 0));
        }
        // whole decades up to a/h₁ = 10, half decades above
        assert_eq!(
            (-1..5).map(piece_start).collect::<Vec<_>>(),
            [-1.0, 0.0, 1.0, 1.5, 2.0, 2.5]
        );
        assert_eq!(pieces(h1, 0.2 * h1, 30.0 * h1), Some((-1, 2)));
        assert_eq!(pieces(h1, 0.2 * h1, 40.0 * h1), Some((-1, 3)));
        assert_eq!(pieces(h1, 2.0 * h1, 3.0 * h1), Some((0, 1)));
        assert_eq!(pieces(h1, 150.0 * h1, 200.0 * h1), Some((3, 4)));
        assert_eq!(pieces(h1, 0.0, 3.0 * h1), None);
        assert_eq!(pieces(h1, 1e-60 * h1, 1e60 * h1), None);
        let t = table(h1, -3, 5);
        assert_eq!(t.pieces(), (-3, 5));
        assert!(t.covers((-2, 1)) && !t.covers((-4, 1)));
        let a3 = node_radius(h1, 0, 3);
        assert!((t.at(a3) / f(a3 / h1) - 1.0).abs() < 1e-14);
        let mut worst: f64 = 0.0;
        for i in 0..300 {
            let x = 10f64.powf(-3.0 + 6.0 * (i as f64 + 0.37) / 300.0);
            worst = worst.max((t.at(x * h1) / f(x) - 1.0).abs());
        }
        eprintln!("ψ stand-in interpolation: worst {worst:.2e}");
        // measured 1.94e-7
        assert!(worst < 2e-6, "{worst}");
    }

    /// The file form round-trips bit for bit; damage is refused with the right error,
    /// never a panic.
    #[test]
    fn file_form_round_trips_and_refuses_damage() {
        let t = table(1e-4, -2, 1);
        let b = t.to_bytes();
        assert_eq!(PsiTable::from_bytes(&b).unwrap(), t);
        assert_eq!(PsiTable::from_bytes(b"nope"), Err(PsiTableError::NotATable));
        for cut in 8..b.len() {
            assert!(matches!(
                PsiTable::from_bytes(&b[..cut]),
                Err(PsiTableError::Damaged(_))
            ));
        }
        for at in 12..b.len() {
            let mut flipped = b.clone();
            flipped[at] ^= 1;
            assert!(
                matches!(
                    PsiTable::from_bytes(&flipped),
                    Err(PsiTableError::Damaged(_))
                ),
                "byte {at}"
            );
        }
        let mut v = b.clone();
        v[8] = 9;
        assert_eq!(
            PsiTable::from_bytes(&v),
            Err(PsiTableError::WrongVersion { found: 9 })
        );
        assert!(PsiTable::from_nodes(1, 1e-4, 0, vec![1.0; 10]).is_err());
        assert!(PsiTable::from_nodes(1, 1e-4, 0, vec![f64::NAN; 9]).is_err());
    }
}
