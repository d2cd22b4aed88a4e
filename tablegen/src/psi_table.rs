//! ψ(a/h₁) tables of a layered conductor (physics.md §6.2): built from
//! [`crate::spot`]'s Fredholm solves, read by the N and I models' spot conductances
//! G(a) = 4k₁aψ(a) at every contact radius of a load path (the `strata` crate's `spots`
//! module and the C ABI's, which so give the same h_c bit for bit), and kept in the
//! table cache ([`cached`]) so that a stack's table is solved once.
//!
//! The table ([`PsiTable`], [`strata_runtime::constriction`]) holds pieces of a/h₁ —
//! whole decades up to a/h₁ = 10, half decades above — each interpolated through 9
//! Chebyshev–Lobatto nodes (8 solves per piece); a
//! node is solved by Gauss–Legendre Nyström with [`nystrom_nodes`] nodes up to a/h₁ =
//! [`PSI_NYSTROM_MAX_A_OVER_H`] (under half the spot solver's default, at round-off), by
//! the spot solver's automatic method beyond. Measured in the tests below and in
//! docs/validation.md; the cost in docs/performance.md.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use thiserror::Error;

pub use strata_runtime::constriction::PsiTable;
use strata_runtime::constriction::{self, PIECE_NODES, PsiTableError, node_radius, pieces};

use crate::asperity::Method;
use crate::fredholm::Discretisation;
use crate::spot::{Spot, SpotError};

/// A ψ table that cannot be built.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum PsiError {
    /// A node's Fredholm solve failed.
    #[error("spot conductance at a = {a:e} m: {error}")]
    Node {
        /// The node's radius (m).
        a: f64,
        error: SpotError,
    },
    /// Radii no table covers (not positive and finite, or over 80 pieces of a/h₁).
    #[error(
        "spot radii {lo:e} … {hi:e} m: a ψ table needs positive, finite radii within 80 pieces (some 40 decades) of a/h₁"
    )]
    Range { lo: f64, hi: f64 },
    #[error(transparent)]
    Table(#[from] PsiTableError),
}

/// a/h₁ up to which a table node is solved by Gauss–Legendre Nyström with
/// [`nystrom_nodes`] nodes (beyond: the spot solver's automatic choice).
pub const PSI_NYSTROM_MAX_A_OVER_H: f64 = 4.0;

/// Nyström nodes of a ψ table node at a/h₁ = `a_over_h` ≤ [`PSI_NYSTROM_MAX_A_OVER_H`]:
/// 6 + ⌈4a/h₁⌉ (7 up to a/h₁ = 1/4, 10 at 1, 22 at 4), under half the spot solver's
/// default 16 + 8⌈a/h₁⌉; the kernel K_a(s,t) is analytic in a strip of width ~h₁/a, so
/// the nodes needed grow with a/h₁ only. Measured against 128 nodes over
/// a/h₁ = 1e−3…4 on the paper's conducting stack, platings (k₁/k_b = 10, 1e4),
/// insulating layers (1e−4) on half-spaces and sinks: ≤ 2.4e−15 (the test below). A solve costs
/// ~linearly in the nodes (0.52 ms at 24, 0.17 ms at 6, paper stack, a/h₁ ≤ 1).
pub fn nystrom_nodes(a_over_h: f64) -> usize {
    6 + (4.0 * a_over_h).ceil().max(1.0) as usize
}

/// ψ(a) of one table node at radius `a` (m): Nyström with [`nystrom_nodes`] up to
/// [`PSI_NYSTROM_MAX_A_OVER_H`], else the spot solver's automatic method.
pub fn psi_node(spot: &Spot, a: f64) -> Result<f64, PsiError> {
    let ah = a / spot.top_thickness().unwrap_or(f64::INFINITY);
    let psi = if ah <= PSI_NYSTROM_MAX_A_OVER_H {
        spot.clone()
            .with_method(Method::Fixed(Discretisation::Nystrom {
                nodes: nystrom_nodes(ah),
            }))
            .psi(a)
    } else {
        spot.psi(a)
    };
    psi.map_err(|error| PsiError::Node { a, error })
}

/// The ψ table of the layered body `spot` (ψ against a/h₁ in pieces of a decade, half
/// a decade above a/h₁ = 10,
/// [`strata_runtime::constriction`]) covering the radii `lo` ≤ `hi` (m), nodes solved
/// in parallel. ψ is analytic in ln a, so the error falls geometrically with the nodes
/// of a piece: measured ≤ 1.2e−6 over four decades of a/h₁ on a plating and insulating
/// layers (the test below; the largest in the decades around a/h₁ = 1, ≤ 1.4e−8 away
/// from them), against 4.4e−6 of the cubic on 16 nodes per decade it replaced, with 8
/// solves per decade instead of 16.
pub fn build(spot: &Spot, lo: f64, hi: f64) -> Result<PsiTable, PsiError> {
    extend(None, spot, lo, hi)
}

/// `table` (a ψ table of `spot`, or None) extended to cover the radii `lo` ≤ `hi` (m):
/// the pieces it holds are kept bit for bit, the missing ones solved (in parallel).
/// A table of another stack (its fingerprint) is ignored and rebuilt.
pub fn extend(
    table: Option<&PsiTable>,
    spot: &Spot,
    lo: f64,
    hi: f64,
) -> Result<PsiTable, PsiError> {
    let key = spot.compliance().fingerprint();
    let h1 = spot.top_thickness().unwrap_or(1.0);
    let (mut d0, mut d1) = pieces(h1, lo, hi).ok_or(PsiError::Range { lo, hi })?;
    let old = table.filter(|t| t.key() == key && t.top_thickness() == h1);
    if let Some(t) = old {
        let (f, e) = t.pieces();
        // keep the table contiguous
        (d0, d1) = (d0.min(f), d1.max(e));
    }
    let m = PIECE_NODES - 1;
    let n = (d1 - d0) as usize * m + 1;
    let held = |i: usize| -> Option<f64> {
        let t = old?;
        let (f, _) = t.pieces();
        let at = i as i64 - i64::from(f - d0) * m as i64;
        (at >= 0)
            .then(|| t.nodes().get(at as usize).copied())
            .flatten()
    };
    let psi = (0..n)
        .into_par_iter()
        .map(|i| match held(i) {
            Some(v) => Ok(v),
            None => {
                let (d, j) = (d0 + (i / m) as i32, i % m);
                psi_node(spot, node_radius(h1, d, j))
            }
        })
        .collect::<Result<Vec<f64>, PsiError>>()?;
    Ok(PsiTable::from_nodes(key, h1, d0, psi)?)
}

/// The file of `spot`'s ψ table in the cache directory `dir`:
/// `psi-<fingerprint>.strata` ([`constriction::cache_path`]).
pub fn cache_path(spot: &Spot, dir: &Path) -> PathBuf {
    constriction::cache_path(spot.compliance().fingerprint(), dir)
}

/// What [`cached`] did with the cache file.
#[derive(Debug, Clone, PartialEq)]
pub enum CacheUse {
    /// The file held every piece needed.
    Read,
    /// The table was built (missing or unreadable file) or extended, and written.
    Written { pieces: (i32, i32) },
    /// Built or extended, but the file could not be written (the message): the table
    /// is used all the same.
    NotWritten(String),
}

/// `spot`'s ψ table covering the radii `lo` ≤ `hi` (m) from the cache directory `dir`:
/// read when the file there covers them, else built (or the file's table extended by
/// the missing pieces, [`extend`]) and written back atomically (a temporary file
/// renamed). An unreadable, damaged or foreign file is rebuilt; a directory that
/// cannot be written costs only the file ([`CacheUse::NotWritten`]). The values are
/// those of [`build`] bit for bit, cached or not.
pub fn cached(spot: &Spot, lo: f64, hi: f64, dir: &Path) -> Result<(PsiTable, CacheUse), PsiError> {
    let path = cache_path(spot, dir);
    let key = spot.compliance().fingerprint();
    let h1 = spot.top_thickness().unwrap_or(1.0);
    let need = pieces(h1, lo, hi).ok_or(PsiError::Range { lo, hi })?;
    let old = constriction::read_cached(&path, key, h1);
    let old = match old {
        Some(t) if t.covers(need) => return Ok((t, CacheUse::Read)),
        other => other,
    };
    let table = extend(old.as_ref(), spot, lo, hi)?;
    let used = match write_atomic(&path, &table.to_bytes()) {
        Ok(()) => CacheUse::Written {
            pieces: table.pieces(),
        },
        Err(e) => CacheUse::NotWritten(format!("{}: {e}", path.display())),
    };
    Ok((table, used))
}

/// Writes `bytes` to a temporary file beside `path` and renames it over `path`.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // unique per process and call: concurrent writers never share a temporary file
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = dir.join(format!(".{name}.tmp.{}.{call}", std::process::id()));
    let r = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path));
    if r.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_runtime::Stack;
    use strata_runtime::conduction::ConductionKind;
    use strata_runtime::stack::{Base, BaseConduction, Conductivity, Layer};

    /// One layer of thickness `h` and conductivity `k1` on a half-space of `kb` (Some) or
    /// an isothermal sink (None).
    fn one_layer(h: f64, k1: f64, kb: Option<f64>) -> Spot {
        let k = Conductivity::thermal;
        let stack = Stack::new(
            vec![Layer {
                thickness: h,
                young: 1e9,
                poisson: 0.3,
            }],
            Base::Rigid,
        )
        .unwrap();
        let stack = match kb {
            Some(kb) => stack.with_conduction(vec![k(k1)], k(kb), BaseConduction::HalfSpace),
            None => stack.with_conduction(
                vec![k(k1)],
                Conductivity::default(),
                BaseConduction::Isothermal,
            ),
        }
        .unwrap();
        Spot::new(&stack, ConductionKind::Thermal).unwrap()
    }

    /// The interpolated ψ against direct Fredholm solves (the spot solver's automatic
    /// method) between the nodes, over four decades of a/h₁ on a plating, an insulating
    /// layer on a half-space and one on an isothermal sink; a narrow range takes one
    /// piece, the same bits as the wide table's.
    #[test]
    fn interpolated_psi_matches_direct_solves() {
        let h = 1e-5;
        for (k1, kb) in [(200.0, Some(20.0)), (0.5, Some(40.0)), (0.5, None)] {
            let spot = one_layer(h, k1, kb);
            let t = build(&spot, 1.01e-2 * h, 0.99e2 * h).unwrap();
            // decades to a/h₁ = 10, then the half decades 10 … 31.6 … 100
            assert_eq!(t.pieces(), (-2, 3));
            assert_eq!(t.nodes().len(), 5 * (PIECE_NODES - 1) + 1);
            let mut worst: f64 = 0.0;
            for i in 0..40 {
                let a = h * 10f64.powf(-2.0 + 4.0 * (i as f64 + 0.37) / 40.0);
                let exact = spot.psi(a).unwrap();
                worst = worst.max((t.at(a) / exact - 1.0).abs());
            }
            let narrow = build(&spot, 0.3 * h, 0.5 * h).unwrap();
            assert_eq!(narrow.pieces(), (-1, 0));
            assert_eq!(narrow.nodes(), &t.nodes()[8..17]);
            eprintln!("ψ table k1/kb = {k1}/{kb:?}: worst {worst:.2e}");
            // measured 1.24e-6, 5.3e-7, 5.5e-7 (the pieces across a/h₁ = 0.1…10, where ψ
            // changes most)
            assert!(worst < 1.2e-5, "{worst}");
        }
    }

    /// A table extended by pieces, and the cache (written, read, extended, a damaged
    /// file rebuilt, an unwritable directory), give the bits of one direct build.
    #[test]
    fn extended_and_cached_tables_equal_a_direct_build() {
        let h = 2e-5;
        let spot = one_layer(h, 0.5, Some(40.0));
        let (lo, hi) = (0.05 * h, 30.0 * h);
        let direct = build(&spot, lo, hi).unwrap();
        let small = build(&spot, 0.5 * h, 0.6 * h).unwrap();
        assert_eq!(extend(Some(&small), &spot, lo, hi).unwrap(), direct);
        // a table of another stack is not reused
        let other = build(&one_layer(h, 0.6, Some(40.0)), 0.5 * h, 0.6 * h).unwrap();
        assert_eq!(extend(Some(&other), &spot, lo, hi).unwrap(), direct);

        let dir = std::env::temp_dir().join(format!("strata-psi-cache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let (t, u) = cached(&spot, 0.5 * h, 0.6 * h, &dir).unwrap();
        assert_eq!(
            (t, u),
            (small.clone(), CacheUse::Written { pieces: (-1, 0) })
        );
        let (t, u) = cached(&spot, 0.4 * h, 0.7 * h, &dir).unwrap();
        assert_eq!((t, u), (small, CacheUse::Read));
        let (t, u) = cached(&spot, lo, hi, &dir).unwrap();
        assert_eq!((&t, u), (&direct, CacheUse::Written { pieces: (-2, 2) }));
        assert_eq!(
            cached(&spot, lo, hi, &dir).unwrap(),
            (direct.clone(), CacheUse::Read)
        );
        let path = cache_path(&spot, &dir);
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[60] ^= 0x10;
        std::fs::write(&path, &bytes).unwrap();
        let (t, u) = cached(&spot, lo, hi, &dir).unwrap();
        assert_eq!((&t, u), (&direct, CacheUse::Written { pieces: (-2, 2) }));
        // a plain file where the directory should be: nothing written, same table
        let blocked = dir.join("plain-file");
        std::fs::write(&blocked, b"x").unwrap();
        let (t, u) = cached(&spot, lo, hi, &blocked.join("sub")).unwrap();
        assert_eq!(t, direct);
        assert!(matches!(u, CacheUse::NotWritten(_)), "{u:?}");
        assert_eq!(std::fs::read(&blocked).unwrap(), b"x");
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".tmp."))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(matches!(build(&spot, 0.0, hi), Err(PsiError::Range { .. })));
    }

    /// Hard cases: 200 graded layers (conductivity 1 … 1e4 over 1 mm, on a sink and on a
    /// 1e−4 W/(m·K) half-space) and a 1e4 contrast under one layer: the table over
    /// a/h₁ = 1e−3 … 10 is finite and positive and meets direct solves between its nodes.
    #[test]
    fn hard_stacks_tabulate() {
        let k = Conductivity::thermal;
        let mut worst: f64 = 0.0;
        for base in [None, Some(1e-4)] {
            let n = 200;
            let layers: Vec<Layer> = (0..n)
                .map(|_| Layer {
                    thickness: 5e-6,
                    young: 1e9,
                    poisson: 0.3,
                })
                .collect();
            let ks: Vec<Conductivity> = (0..n)
                .map(|i| k(10f64.powf(4.0 * i as f64 / (n - 1) as f64)))
                .collect();
            let stack = Stack::new(layers, Base::Rigid).unwrap();
            let stack = match base {
                Some(kb) => stack.with_conduction(ks, k(kb), BaseConduction::HalfSpace),
                None => {
                    stack.with_conduction(ks, Conductivity::default(), BaseConduction::Isothermal)
                }
            }
            .unwrap();
            let spots = [
                Spot::new(&stack, ConductionKind::Thermal).unwrap(),
                one_layer(5e-6, 1e4, Some(1.0)),
            ];
            for spot in spots {
                let h = 5e-6;
                let t = build(&spot, 1e-3 * h, 10.0 * h).unwrap();
                assert_eq!(t.pieces(), (-3, 1));
                assert!(t.nodes().iter().all(|v| v.is_finite() && *v > 0.0));
                for ah in [2.3e-3, 0.047, 0.61, 7.7] {
                    let e = spot.psi(ah * h).unwrap();
                    worst = worst.max((t.at(ah * h) / e - 1.0).abs());
                }
            }
        }
        eprintln!("hard stacks: ψ table vs direct, worst {worst:.1e}");
        // measured 1.2e-6
        assert!(worst < 1e-5, "{worst}");
    }

    /// The table nodes' Nyström rule against 128 nodes over a/h₁ = 1e−3…4 on platings,
    /// insulating layers, half-spaces and sinks (measured ≤ 2.4e−15).
    #[test]
    fn table_node_rule_is_at_round_off() {
        let h = 1e-4;
        let mut worst: f64 = 0.0;
        for (k1, kb) in [
            (1e4, Some(1.0)),
            (1.0, Some(1e4)),
            (1.0, None),
            (1e-4, None),
            (200.0, Some(20.0)),
        ] {
            let spot = one_layer(h, k1, kb);
            // a log grid, and a/h₁ = k/4: the largest a/h₁ of each node count
            let grid = (0..=12).map(|i| 10f64.powf(-3.0 + i as f64 * 2.0 / 12.0));
            for ah in grid.chain((1..=16).map(|k| k as f64 / 4.0)) {
                let a = ah * h;
                let r = spot
                    .clone()
                    .with_method(Method::Fixed(Discretisation::Nystrom { nodes: 128 }))
                    .psi(a)
                    .unwrap();
                let e = (psi_node(&spot, a).unwrap() / r - 1.0).abs();
                worst = worst.max(e);
            }
        }
        eprintln!("table node rule: worst {worst:.1e}");
        assert!(worst < 2.4e-14, "{worst}");
    }
}
