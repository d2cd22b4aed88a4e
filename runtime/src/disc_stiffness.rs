//! The normal and tangential stiffness of one contact disc of radius a (m) on a layered
//! solid, tabulated against a/h₁: the frictionless flat punch K_n and the bonded,
//! full-stick disc K_t (normal–tangential coupling ignored, as in Mindlin's solution),
//!
//! ```text
//!   K_n = 2E*₁ a ψ_zz,   K_t = 2K_LK_T/(K_L + K_T),   K_L = 2E*₁ a ψ_LL,   K_T = 4μ₁ a ψ_TT,
//! ```
//!
//! (N/m) with E*₁ and μ₁ the top material's plane-strain and shear moduli (a pair's E*
//! and μ* with an elastic counterface, physics.md §6.1) and the three punch factors ψ
//! (dimensionless, ≡ 1 on a half-space: then K_t = 8μa/(2 − ν), Mindlin's). The factors
//! are Fredholm solves of `strata-tablegen`'s `stiffness` module, which builds these
//! tables; this module holds the table, its interpolation and its file form, so that the
//! asperity models read K_t at every contact radius of a load path without the solver
//! (the engine's `[friction]` effect).
//!
//! # Grid
//! A [`crate::table::lobatto`] table (shared with conduction's ψ): whole decades of
//! log₁₀(a/h₁), each with [`NODES`] Chebyshev–Lobatto nodes
//! (neighbouring decades share their end node), interpolated in barycentric form. A
//! node's radius depends on (h₁, decade, node) alone ([`node_radius`]), so two tables
//! of one stack agree bit for bit where they overlap: a table read from a file, one
//! extended by decades and one built for a single load path give the same K_t.
//!
//! # File form
//! The framed form of every strata table file (`table::codec::frame`: magic
//! "STRATAKT", version [`FORMAT_VERSION`], payload length, FNV-1a 64 checksum), the
//! payload bincode of (the stack's fingerprint [`fingerprint`], h₁, the first decade
//! k₀, the 16·decades + 1 node triples (ψ_zz, ψ_LL, ψ_TT)). Kept in the table cache as
//! `kt-<fingerprint>.strata` ([`cache_path`]), beside the χ/ζ tables
//! (`stack-<hex>.strata`) and the ψ tables of conduction (`psi-<hex>.strata`).

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::Solid;
use crate::compliance::tangential::TangentialCompliance;
use crate::table::codec::{FrameError, frame, from_payload, to_payload, unframe};
use crate::table::lobatto::{Grid, LobattoTable, NodeValue};

/// Chebyshev–Lobatto nodes per decade of a/h₁ (16 solves a decade; 9, the ψ table's,
/// left ψ_zz of a ν = 0.45 layer on a rigid base 1.2e−5 off).
pub const NODES: usize = 17;

/// Most decades a table may span.
pub const MAX_DECADES: i32 = 40;

/// Version of the file form written by this build.
pub const FORMAT_VERSION: u32 = 1;

/// File signature.
pub const MAGIC: &[u8; 8] = b"STRATAKT";

/// A disc-stiffness table that cannot be read or is inconsistent.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum StiffnessTableError {
    #[error("not a strata disc-stiffness table (bad signature)")]
    NotATable,
    #[error(
        "disc-stiffness table format version {found} is not supported (this strata reads version {FORMAT_VERSION})"
    )]
    WrongVersion { found: u32 },
    #[error("disc-stiffness table is damaged: {0}")]
    Damaged(String),
    #[error("disc-stiffness table is inconsistent: {0}")]
    Invalid(String),
}

/// The three punch factors ψ (dimensionless, 1 on a half-space) at one radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PunchFactors {
    /// ψ_zz: the normal flat punch, K_n = 2E*₁aψ_zz.
    pub normal: f64,
    /// ψ_LL: the in-plane mode along the wavevector, K_L = 2E*₁aψ_LL.
    pub along: f64,
    /// ψ_TT: the antiplane mode across it, K_T = 4μ₁aψ_TT.
    pub across: f64,
}

impl PunchFactors {
    /// The half-space's factors, all 1.
    pub const HALF_SPACE: PunchFactors = PunchFactors {
        normal: 1.0,
        along: 1.0,
        across: 1.0,
    };
}

/// The stiffnesses of one disc (N/m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscStiffness {
    /// Disc radius a (m).
    pub a: f64,
    /// K_n = P/δ of the frictionless flat punch.
    pub normal: f64,
    /// K_t = Q/δ of the full-stick disc (coupling ignored).
    pub tangential: f64,
    /// The punch factors behind them.
    pub psi: PunchFactors,
}

/// K_t = 2K_LK_T/(K_L + K_T) from the two modes' punch stiffnesses (N/m).
pub fn harmonic_mean(k_l: f64, k_t: f64) -> f64 {
    2.0 * k_l * k_t / (k_l + k_t)
}

/// K_n and K_t (N/m) of the disc of radius `a` (m) from its punch factors, with E*₁
/// `e_star` and μ₁ `mu_star` (Pa).
pub fn disc_stiffness(a: f64, psi: PunchFactors, e_star: f64, mu_star: f64) -> DiscStiffness {
    let k_l = 2.0 * e_star * a * psi.along;
    let k_t = 4.0 * mu_star * a * psi.across;
    DiscStiffness {
        a,
        normal: 2.0 * e_star * a * psi.normal,
        tangential: harmonic_mean(k_l, k_t),
        psi,
    }
}

/// The partition and nodes of a disc-stiffness table (module docs;
/// [`crate::table::lobatto`]): whole decades, [`NODES`] a decade.
pub const GRID: Grid = Grid {
    nodes: NODES,
    half_decades_from: None,
    max_pieces: MAX_DECADES,
};

/// The radius (m) of node j of decade k: h₁·10^(k + (x_j + 1)/2).
pub fn node_radius(h1: f64, decade: i32, j: usize) -> f64 {
    GRID.node_radius(h1, decade, j)
}

/// The decades [k₀, k₁) of log₁₀(a/h₁) that cover the radii `lo` ≤ `hi` (m) on a top
/// layer `h1` thick; None for radii that are not positive and finite or would span
/// more than [`MAX_DECADES`].
pub fn decades(h1: f64, lo: f64, hi: f64) -> Option<(i32, i32)> {
    if !(h1 > 0.0 && h1.is_finite() && lo > 0.0 && hi >= lo && hi.is_finite()) {
        return None;
    }
    let (d0, d1) = ((lo / h1).log10().floor(), (hi / h1).log10().floor() + 1.0);
    if !(d0.is_finite() && d1.is_finite() && d0 > -1e3 && d1 < 1e3) {
        return None;
    }
    (d1 - d0 <= f64::from(MAX_DECADES)).then_some((d0 as i32, d1 as i32))
}

/// A fingerprint of what the punch factors depend on: FNV-1a 64 of the bodies'
/// thickness ratios to h₁ ([`Solid::top_thickness`]), modulus ratios to the first
/// (canonical) body's top Young modulus and Poisson ratios, and the bases, bit for bit
/// (a pair in canonical order, so a pair and its swap share a table). Two solids with
/// the same fingerprint and h₁ have the same ψ(a).
pub fn fingerprint<S: Solid + ?Sized>(solid: &S) -> u64 {
    let mut h = crate::hash::Fnv1a::default();
    h.part(b"strata disc stiffness v1");
    let h1 = solid.top_thickness().unwrap_or(1.0);
    let bodies = match solid.canonical_pair() {
        None => vec![solid.first().clone()],
        Some((a, b)) => vec![a, b],
    };
    let e1 = bodies[0].top_material().0;
    for (i, body) in bodies.iter().enumerate() {
        h.part(&[i as u8]);
        for l in body.layers() {
            h.update(&(l.thickness / h1).to_le_bytes())
                .update(&(l.young / e1).to_le_bytes())
                .part(&l.poisson.to_le_bytes());
        }
        match body.base() {
            crate::Base::Rigid => h.part(b"rigid"),
            crate::Base::Elastic { young, poisson } => h
                .update(&(young / e1).to_le_bytes())
                .part(&poisson.to_le_bytes()),
        };
    }
    h.finish()
}

impl NodeValue for PunchFactors {
    fn zero() -> Self {
        PunchFactors {
            normal: 0.0,
            along: 0.0,
            across: 0.0,
        }
    }

    fn add_scaled(&mut self, c: f64, v: &Self) {
        self.normal += c * v.normal;
        self.along += c * v.along;
        self.across += c * v.across;
    }

    fn divided(self, d: f64) -> Self {
        PunchFactors {
            normal: self.normal / d,
            along: self.along / d,
            across: self.across / d,
        }
    }

    fn finite_positive(&self) -> bool {
        [self.normal, self.along, self.across]
            .iter()
            .all(|x| x.is_finite() && *x > 0.0)
    }
}

/// The punch factors of one stack against a/h₁ over whole decades (module docs): read
/// with [`StiffnessNodes::factors`], filled by `strata-tablegen`'s `stiffness_table`.
/// The values and their interpolation are a [`LobattoTable`] of [`GRID`].
#[derive(Debug, Clone, PartialEq)]
pub struct StiffnessNodes(LobattoTable<PunchFactors>);

impl StiffnessNodes {
    /// A table of the stack with fingerprint `key` and top layer `h1` (m) from its node
    /// factors over decades first, first + 1, …: 16·decades + 1 triples, each finite
    /// and positive.
    pub fn from_nodes(
        key: u64,
        h1: f64,
        first: i32,
        psi: Vec<PunchFactors>,
    ) -> Result<Self, StiffnessTableError> {
        LobattoTable::from_nodes(GRID, key, h1, first, psi)
            .map(StiffnessNodes)
            .map_err(StiffnessTableError::Invalid)
    }

    /// The stack's fingerprint the table was built for.
    pub fn key(&self) -> u64 {
        self.0.key()
    }

    /// h₁ (m).
    pub fn top_thickness(&self) -> f64 {
        self.0.top_thickness()
    }

    /// The decades [k₀, k₁) of log₁₀(a/h₁) held.
    pub fn decades(&self) -> (i32, i32) {
        self.0.pieces()
    }

    /// The node factors, decade by decade (shared ends once).
    pub fn nodes(&self) -> &[PunchFactors] {
        self.0.nodes()
    }

    /// True when the table holds every decade of [k₀, k₁).
    pub fn covers(&self, range: (i32, i32)) -> bool {
        self.0.covers(range)
    }

    /// The interpolated punch factors at radius `a` (m): the barycentric Lobatto
    /// interpolant of the decade holding a/h₁ (the end decades extended for radii just
    /// outside; a table built for a load path covers all of its radii).
    pub fn factors(&self, a: f64) -> PunchFactors {
        self.0.at(a)
    }

    /// The file form (module docs).
    pub fn to_bytes(&self) -> Vec<u8> {
        let t = &self.0;
        let flat: Vec<[f64; 3]> = t
            .nodes()
            .iter()
            .map(|p| [p.normal, p.along, p.across])
            .collect();
        // bincode cannot fail on these plain values; were it to, the empty payload
        // would read back as damaged and the table be solved again
        let payload =
            to_payload(&(t.key(), t.top_thickness(), t.first(), &flat)).unwrap_or_default();
        frame(MAGIC, FORMAT_VERSION, &payload)
    }

    /// Parses and validates the file form. Never panics.
    pub fn from_bytes(b: &[u8]) -> Result<Self, StiffnessTableError> {
        let (_, payload) = unframe(b, MAGIC, &[FORMAT_VERSION]).map_err(|e| match e {
            FrameError::Magic => StiffnessTableError::NotATable,
            FrameError::Version(found) => StiffnessTableError::WrongVersion { found },
            other => StiffnessTableError::Damaged(format!("{other:?}")),
        })?;
        let (key, h1, first, flat): (u64, f64, i32, Vec<[f64; 3]>) =
            from_payload(payload).map_err(StiffnessTableError::Damaged)?;
        let psi = flat
            .into_iter()
            .map(|[normal, along, across]| PunchFactors {
                normal,
                along,
                across,
            })
            .collect();
        StiffnessNodes::from_nodes(key, h1, first, psi)
    }
}

/// The file of a disc-stiffness table in the table cache `dir`: `kt-<key>.strata`
/// (`key` the stack's [`fingerprint`]).
pub fn cache_path(key: u64, dir: &Path) -> PathBuf {
    dir.join(format!("kt-{key:016x}.strata"))
}

/// The table in the cache file `path` when it is a readable, undamaged table of the
/// stack `key` with top-layer thickness `h1` (m); None otherwise (missing, damaged or
/// foreign: the caller rebuilds it). A file larger than the machine's memory limit
/// counts as damaged (strata writes these files itself; they are a few kB).
pub fn read_cached(path: &Path, key: u64, h1: f64) -> Option<StiffnessNodes> {
    let memory = crate::resources::MemoryLimit::of_machine();
    crate::resources::read_data_file(path, "a cache file", &memory)
        .ok()
        .and_then(|b| StiffnessNodes::from_bytes(&b).ok())
        .filter(|t| t.key() == key && t.top_thickness() == h1)
}

/// K_n(a) and K_t(a) of one solid (module docs): the moduli, and the tabulated punch
/// factors of a layered one (none on a half-space, where ψ ≡ 1).
#[derive(Debug, Clone, PartialEq)]
pub struct StiffnessTable {
    nodes: Option<StiffnessNodes>,
    e_star: f64,
    mu_star: f64,
}

impl StiffnessTable {
    /// The table of a half-space (or two) of plane-strain modulus E* `e_star` and shear
    /// modulus μ `mu_star` (Pa; a pair's E* and μ*).
    pub fn half_space(e_star: f64, mu_star: f64) -> Self {
        StiffnessTable {
            nodes: None,
            e_star,
            mu_star,
        }
    }

    /// The table of `solid` from its punch factors `nodes` (None for a half-space);
    /// refused when they are another stack's.
    pub fn new<S: Solid + ?Sized>(
        solid: &S,
        nodes: Option<StiffnessNodes>,
    ) -> Result<Self, StiffnessTableError> {
        let tc = TangentialCompliance::new(solid);
        let (e_star, mu_star) = (tc.plane_strain_modulus(), tc.shear_modulus());
        match (solid.top_thickness(), &nodes) {
            (None, None) => Ok(Self::half_space(e_star, mu_star)),
            (Some(h1), Some(n)) if n.key() == fingerprint(solid) && n.top_thickness() == h1 => {
                Ok(StiffnessTable {
                    nodes,
                    e_star,
                    mu_star,
                })
            }
            (None, Some(_)) => Err(StiffnessTableError::Invalid(
                "punch factors given for a half-space".into(),
            )),
            (Some(_), None) => Err(StiffnessTableError::Invalid(
                "a layered solid needs its punch factors".into(),
            )),
            (Some(_), Some(_)) => Err(StiffnessTableError::Invalid(
                "the punch factors are another stack's (fingerprint or h1)".into(),
            )),
        }
    }

    /// A table from its parts as the builder made them: the punch factors (None on a
    /// half-space) and the moduli E*₁ `e_star`, μ₁ `mu_star` (Pa) of the same solid
    /// (unchecked: [`StiffnessTable::new`] checks the factors against a solid).
    pub fn from_parts(nodes: Option<StiffnessNodes>, e_star: f64, mu_star: f64) -> Self {
        StiffnessTable {
            nodes,
            e_star,
            mu_star,
        }
    }

    /// The tabulated punch factors (None on a half-space).
    pub fn nodes(&self) -> Option<&StiffnessNodes> {
        self.nodes.as_ref()
    }

    /// The decades [k₀, k₁) of log₁₀(a/h₁) held (None on a half-space).
    pub fn decades(&self) -> Option<(i32, i32)> {
        self.nodes.as_ref().map(StiffnessNodes::decades)
    }

    /// E*₁ (Pa; a pair's E*) that scales K_n and K_L.
    pub fn plane_strain_modulus(&self) -> f64 {
        self.e_star
    }

    /// μ₁ (Pa; a pair's μ*) that scales K_T.
    pub fn shear_modulus(&self) -> f64 {
        self.mu_star
    }

    /// The interpolated punch factors at radius `a` (m), all 1 on a half-space.
    pub fn factors(&self, a: f64) -> PunchFactors {
        self.nodes
            .as_ref()
            .map_or(PunchFactors::HALF_SPACE, |n| n.factors(a))
    }

    /// K_n and K_t (N/m) of the disc of radius `a` (m) from the table.
    pub fn at(&self, a: f64) -> DiscStiffness {
        disc_stiffness(a, self.factors(a), self.e_star, self.mu_star)
    }

    /// K_t (N/m) of the full-stick disc of radius `a` (m).
    pub fn tangential(&self, a: f64) -> f64 {
        self.at(a).tangential
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Base, Layer, Stack};

    fn layer() -> Stack {
        Stack::new(
            vec![Layer {
                thickness: 1e-5,
                young: 1e9,
                poisson: 0.45,
            }],
            Base::Rigid,
        )
        .unwrap()
    }

    /// The file form reads back bit for bit; a damaged, foreign or newer file is
    /// refused without a panic; inconsistent nodes are refused.
    #[test]
    fn file_form_round_trip_and_refusals() {
        let st = layer();
        let key = fingerprint(&st);
        let psi: Vec<PunchFactors> = (0..2 * (NODES - 1) + 1)
            .map(|i| PunchFactors {
                normal: 1.0 + i as f64,
                along: 2.0 + i as f64,
                across: 0.5 + i as f64,
            })
            .collect();
        let t = StiffnessNodes::from_nodes(key, 1e-5, -2, psi.clone()).unwrap();
        assert_eq!(t.decades(), (-2, 0));
        let b = t.to_bytes();
        assert_eq!(StiffnessNodes::from_bytes(&b).unwrap(), t);
        for i in [0, 9, 20, b.len() - 1] {
            let mut d = b.clone();
            d[i] ^= 0x04;
            assert!(StiffnessNodes::from_bytes(&d).is_err(), "byte {i}");
        }
        assert!(StiffnessNodes::from_bytes(&b[..b.len() / 2]).is_err());
        assert!(StiffnessNodes::from_bytes(b"").is_err());
        let mut bad = psi.clone();
        bad[3].across = f64::NAN;
        assert!(StiffnessNodes::from_nodes(key, 1e-5, -2, bad).is_err());
        assert!(StiffnessNodes::from_nodes(key, 1e-5, -2, psi[..5].to_vec()).is_err());
        // the table of another stack or thickness is refused by the solid
        assert!(StiffnessTable::new(&st, Some(t.clone())).is_ok());
        let other = Stack::new(
            vec![Layer {
                thickness: 1e-5,
                young: 1e9,
                poisson: 0.4,
            }],
            Base::Rigid,
        )
        .unwrap();
        assert_ne!(fingerprint(&other), key);
        assert!(StiffnessTable::new(&other, Some(t.clone())).is_err());
        assert!(StiffnessTable::new(&st, None).is_err());
        // interpolation returns node values at the nodes (to the round-off of log₁₀)
        let at = t.factors(node_radius(1e-5, -1, 4));
        let want = psi[16 + 4];
        for (x, y) in [
            (at.normal, want.normal),
            (at.along, want.along),
            (at.across, want.across),
        ] {
            assert!((x / y - 1.0).abs() < 1e-13, "{at:?} {want:?}");
        }
    }

    /// On a half-space, K_t is Mindlin's 8μa/(2 − ν) and K_t/K_n = 2(1 − ν)/(2 − ν).
    #[test]
    fn half_space_is_mindlin() {
        let (e, nu) = (3e9, 0.3);
        let hs = Stack::half_space(e, nu).unwrap();
        let t = StiffnessTable::new(&hs, None).unwrap();
        let mu = e / (2.0 * (1.0 + nu));
        let a = 3e-6;
        let d = t.at(a);
        assert!((d.tangential / (8.0 * mu * a / (2.0 - nu)) - 1.0).abs() < 1e-14);
        assert!((d.tangential / d.normal - 2.0 * (1.0 - nu) / (2.0 - nu)).abs() < 1e-14);
    }
}
