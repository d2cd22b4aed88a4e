//! Tables of the disc stiffnesses against a/h₁ ([`crate::stiffness`]), so that a load
//! path's many contact radii cost an interpolation each (microseconds) instead of three
//! Fredholm solves: this module fills the runtime's table
//! ([`strata_runtime::disc_stiffness`], its grid, interpolation and file form) and keeps
//! it in the table cache ([`cached`]), so that a stack's table is solved once.
//!
//! The three punch factors ψ_zz, ψ_LL, ψ_TT depend on a only through a/h₁ and are held on
//! whole decades of log₁₀(a/h₁), each with [`NODES`] Chebyshev–Lobatto nodes
//! (neighbouring decades share their end node) and interpolated in barycentric form; a
//! node's radius depends on (h₁, decade, node) alone. At a radius a the table gives
//!
//! ```text
//!   K_n = 2E*₁ a ψ_zz,   K_t = 2K_LK_T/(K_L + K_T),   K_L = 2E*₁ a ψ_LL,   K_T = 4μ₁ a ψ_TT,
//! ```
//!
//! the solver's formulas on interpolated factors (a half-space needs no table: ψ ≡ 1).
//! 17 nodes a decade, not the spot conductance's 9: ψ_zz of a nearly incompressible
//! layer on a rigid base (ν = 0.45) was 1.2e-5 off with 9 (the test below).
//! Measured against direct solves in the tests below and in docs/validation.md.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use thiserror::Error;

use strata_runtime::disc_stiffness::{self as kt, PunchFactors, StiffnessTableError as FileError};
pub use strata_runtime::disc_stiffness::{
    MAX_DECADES, NODES, StiffnessNodes, StiffnessTable, node_radius,
};

use crate::stiffness::{Stiffness, StiffnessError};

/// A stiffness table that cannot be built.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum StiffnessTableError {
    /// A node's solve failed.
    #[error("disc stiffness at a = {a:e} m: {error}")]
    Node { a: f64, error: StiffnessError },
    /// Radii no table covers.
    #[error(
        "disc radii {lo:e} … {hi:e} m: a stiffness table needs positive, finite radii within {MAX_DECADES} decades of a/h1"
    )]
    Range { lo: f64, hi: f64 },
    /// The nodes do not make a table (cannot happen for solved nodes).
    #[error(transparent)]
    Table(#[from] FileError),
}

/// The table of `solver`'s stack covering the radii `lo` ≤ `hi` (m), its nodes solved
/// in parallel.
pub fn build(solver: &Stiffness, lo: f64, hi: f64) -> Result<StiffnessTable, StiffnessTableError> {
    extend(None, solver, lo, hi)
}

/// The punch factors of `table` (a table of `solver`'s stack, or None) extended to
/// cover the radii `lo` ≤ `hi` (m): the decades it holds are kept bit for bit, the
/// missing ones solved (in parallel). A table of another stack (its fingerprint or h₁)
/// is ignored and rebuilt.
pub fn extend(
    table: Option<&StiffnessNodes>,
    solver: &Stiffness,
    lo: f64,
    hi: f64,
) -> Result<StiffnessTable, StiffnessTableError> {
    let range = StiffnessTableError::Range { lo, hi };
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return Err(range);
    }
    let half_space =
        || StiffnessTable::half_space(solver.plane_strain_modulus(), solver.shear_modulus());
    let Some(h1) = solver.top_thickness() else {
        return Ok(half_space());
    };
    let key = solver.fingerprint();
    let (mut d0, mut d1) = kt::decades(h1, lo, hi).ok_or(range.clone())?;
    let old = table.filter(|t| t.key() == key && t.top_thickness() == h1);
    if let Some(t) = old {
        let (f, e) = t.decades();
        // keep the table contiguous
        (d0, d1) = (d0.min(f), d1.max(e));
        if d1 - d0 > MAX_DECADES {
            return Err(range);
        }
    }
    let m = NODES - 1;
    let n = (d1 - d0) as usize * m + 1;
    let held = |i: usize| -> Option<PunchFactors> {
        let t = old?;
        let at = i as i64 - i64::from(t.decades().0 - d0) * m as i64;
        (at >= 0)
            .then(|| t.nodes().get(at as usize).copied())
            .flatten()
    };
    let psi: Vec<PunchFactors> = (0..n)
        .into_par_iter()
        .map(|i| match held(i) {
            Some(v) => Ok(v),
            None => {
                let (d, j) = if i == n - 1 {
                    (d1 - 1, m)
                } else {
                    (d0 + (i / m) as i32, i % m)
                };
                let a = node_radius(h1, d, j);
                solver
                    .factors(a)
                    .map_err(|error| StiffnessTableError::Node { a, error })
            }
        })
        .collect::<Result<_, _>>()?;
    let nodes = StiffnessNodes::from_nodes(key, h1, d0, psi)?;
    Ok(StiffnessTable::from_parts(
        Some(nodes),
        solver.plane_strain_modulus(),
        solver.shear_modulus(),
    ))
}

/// The file of `solver`'s table in the cache directory `dir`:
/// `kt-<fingerprint>.strata` ([`strata_runtime::disc_stiffness::cache_path`]).
pub fn cache_path(solver: &Stiffness, dir: &Path) -> PathBuf {
    kt::cache_path(solver.fingerprint(), dir)
}

/// What [`cached`] did with the cache file.
#[derive(Debug, Clone, PartialEq)]
pub enum CacheUse {
    /// A half-space: no table, no file.
    HalfSpace,
    /// The file held every decade needed.
    Read(PathBuf),
    /// The table was built (missing or unreadable file) or extended, and written.
    Written { path: PathBuf, decades: (i32, i32) },
    /// Built or extended, but the file could not be written (the message): the table
    /// is used all the same.
    NotWritten(String),
}

/// `solver`'s table covering the radii `lo` ≤ `hi` (m) from the cache directory `dir`:
/// read when the file there covers them, else built (or the file's table extended by
/// the missing decades, [`extend`]) and written back atomically (a temporary file
/// renamed). An unreadable, damaged or foreign file is rebuilt; a directory that
/// cannot be written costs only the file ([`CacheUse::NotWritten`]). The values are
/// those of [`build`] bit for bit, cached or not.
pub fn cached(
    solver: &Stiffness,
    lo: f64,
    hi: f64,
    dir: &Path,
) -> Result<(StiffnessTable, CacheUse), StiffnessTableError> {
    let range = StiffnessTableError::Range { lo, hi };
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return Err(range);
    }
    let Some(h1) = solver.top_thickness() else {
        return Ok((build(solver, lo, hi)?, CacheUse::HalfSpace));
    };
    let path = cache_path(solver, dir);
    let need = kt::decades(h1, lo, hi).ok_or(range)?;
    let old = kt::read_cached(&path, solver.fingerprint(), h1);
    let old = match old {
        Some(t) if t.covers(need) => {
            let table = StiffnessTable::from_parts(
                Some(t),
                solver.plane_strain_modulus(),
                solver.shear_modulus(),
            );
            return Ok((table, CacheUse::Read(path)));
        }
        other => other,
    };
    let table = extend(old.as_ref(), solver, lo, hi)?;
    let Some(nodes) = table.nodes() else {
        return Err(StiffnessTableError::Table(FileError::Invalid(
            "a layered stack without nodes".into(),
        )));
    };
    let used = match crate::psi_table::write_atomic(&path, &nodes.to_bytes()) {
        Ok(()) => CacheUse::Written {
            decades: nodes.decades(),
            path,
        },
        Err(e) => CacheUse::NotWritten(format!("{}: {e}", path.display())),
    };
    Ok((table, used))
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_runtime::{Base, Layer, Stack};

    const H: f64 = 1e-4;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    fn stacks() -> [Stack; 2] {
        [
            Stack::new(
                vec![Layer {
                    thickness: H,
                    young: 10e9,
                    poisson: 0.25,
                }],
                Base::Elastic {
                    young: 2e9,
                    poisson: 0.35,
                },
            )
            .unwrap(),
            Stack::new(
                vec![Layer {
                    thickness: H,
                    young: 1e9,
                    poisson: 0.45,
                }],
                Base::Rigid,
            )
            .unwrap(),
        ]
    }

    /// The worst relative difference of K_n and K_t between the table of `st` over
    /// a/h₁ = 10^lo … 10^hi and direct solves at 24 off-grid radii (a fixed
    /// pseudo-random sample).
    fn worst_against_direct(st: &Stack, lo: f64, hi: f64) -> f64 {
        let s = Stiffness::new(st);
        let t = build(&s, 10f64.powf(lo) * H, 10f64.powf(hi) * H).unwrap();
        let mut worst = 0.0f64;
        let mut x = 0.5f64;
        for _ in 0..24 {
            // a/h₁ = 10^(lo + (hi − lo)x), x from a logistic-map sequence
            x = 3.9 * x * (1.0 - x);
            let a = H * 10f64.powf(lo + (hi - lo) * x);
            let (d, tab) = (s.at(a).unwrap(), t.at(a));
            let e = rel(tab.normal, d.normal).max(rel(tab.tangential, d.tangential));
            assert!(e < 1e-7, "a/h {}: {tab:?} vs {d:?}", a / H);
            worst = worst.max(e);
        }
        worst
    }

    /// The table against direct solves (requirement 1e-5) on a soft layer on a rigid
    /// base, a/h₁ = 1e-2 … 1 (the slow tier covers 1e-2 … 10 on two stacks).
    #[test]
    fn table_meets_direct_solves() {
        let w = worst_against_direct(&stacks()[1], -2.0, 0.0);
        eprintln!("stiffness table vs direct solves: worst {w:.1e}");
    }

    /// The table against direct solves at 24 off-grid radii over a/h₁ = 1e-2 … 10, K_n
    /// and K_t, on a coating over a softer base and a soft layer (ν = 0.45) on a rigid
    /// base: requirement 1e-5, measured 8.0e-9.
    #[test]
    #[ignore = "slow tier: CI runs `cargo test --workspace -- --ignored slow_`"]
    fn slow_table_meets_direct_solves() {
        let mut worst = 0.0f64;
        for st in &stacks() {
            worst = worst.max(worst_against_direct(st, -2.0, 1.0));
        }
        eprintln!("stiffness table vs direct solves: worst {worst:.1e}");
    }

    /// The cache (written, read, extended, a damaged file rebuilt, an unwritable
    /// directory) gives the bits of one direct build.
    #[test]
    fn cached_tables_equal_a_direct_build() {
        let st = &stacks()[1];
        let s = Stiffness::new(st);
        let (lo, hi) = (0.05 * H, 3.0 * H);
        let direct = build(&s, lo, hi).unwrap();
        let small = build(&s, 0.5 * H, 0.6 * H).unwrap();
        assert_eq!(small.decades(), Some((-1, 0)));
        assert_eq!(
            extend(small.nodes(), &s, lo, hi).unwrap(),
            direct,
            "extended by decades"
        );
        let dir = std::env::temp_dir().join(format!("strata-kt-cache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let path = cache_path(&s, &dir);
        let (t, u) = cached(&s, 0.5 * H, 0.6 * H, &dir).unwrap();
        assert_eq!(
            (&t, u),
            (
                &small,
                CacheUse::Written {
                    path: path.clone(),
                    decades: (-1, 0)
                }
            )
        );
        let (t, u) = cached(&s, 0.4 * H, 0.7 * H, &dir).unwrap();
        assert_eq!((&t, u), (&small, CacheUse::Read(path.clone())));
        let (t, u) = cached(&s, lo, hi, &dir).unwrap();
        assert_eq!(
            (&t, u),
            (
                &direct,
                CacheUse::Written {
                    path: path.clone(),
                    decades: (-2, 1)
                }
            )
        );
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[60] ^= 0x10;
        std::fs::write(&path, &bytes).unwrap();
        let (t, u) = cached(&s, lo, hi, &dir).unwrap();
        assert_eq!(
            (&t, u),
            (
                &direct,
                CacheUse::Written {
                    path: path.clone(),
                    decades: (-2, 1)
                }
            )
        );
        // the runtime reads the file without the solver
        let nodes = strata_runtime::disc_stiffness::read_cached(&path, s.fingerprint(), H).unwrap();
        assert_eq!(StiffnessTable::new(st, Some(nodes)).unwrap(), direct);
        // a plain file where the directory should be: nothing written, same table
        let blocked = dir.join("plain-file");
        std::fs::write(&blocked, b"x").unwrap();
        let (t, u) = cached(&s, lo, hi, &blocked.join("sub")).unwrap();
        assert_eq!(t, direct);
        assert!(matches!(u, CacheUse::NotWritten(_)), "{u:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A half-space needs no table; radii out of range are refused.
    #[test]
    fn half_space_and_range() {
        let hs = Stack::half_space(1e9, 0.3).unwrap();
        let s = Stiffness::new(&hs);
        let t = build(&s, 1e-6, 1e-3).unwrap();
        assert_eq!(t.decades(), None);
        assert_eq!(t.at(1e-4), s.at(1e-4).unwrap());
        let st = Stack::paper_two_layer(5.0).unwrap();
        let s = Stiffness::new(&st);
        assert!(matches!(
            cached(&Stiffness::new(&hs), 1e-6, 1e-3, Path::new("/nonexistent")),
            Ok((_, CacheUse::HalfSpace))
        ));
        assert!(matches!(
            build(&s, 0.0, 1e-3),
            Err(StiffnessTableError::Range { .. })
        ));
    }
}
