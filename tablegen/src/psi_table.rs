//! ψ(a) of a layered conductor over a range of spot radii (issue 34, physics.md §6.2): the
//! table the N and I models' spot conductances G(a) = 4k₁aψ(a) read at every contact
//! radius of a load path (the `strata` crate's `spots` module and the C ABI's, which so
//! give the same h_c bit for bit), built from [`crate::spot`]'s Fredholm solves.
//!
//! The range of the radii is cut into equal pieces of at most [`PSI_PIECE_DECADES`] in
//! ln a, each interpolated through [`PSI_PIECE_NODES`] Chebyshev–Lobatto nodes (8 solves
//! per decade); a node is solved by Gauss–Legendre Nyström with [`nystrom_nodes`] nodes up
//! to a/h₁ = [`PSI_NYSTROM_MAX_A_OVER_H`] (under half the spot solver's default, at
//! round-off), by the spot solver's automatic method beyond. Measured in the tests below
//! and in docs/validation.md; the cost in docs/performance.md (issue 34).

use rayon::prelude::*;
use thiserror::Error;

use crate::asperity::Method;
use crate::fredholm::Discretisation;
use crate::spot::{Spot, SpotError};

/// A failed node of the table.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("spot conductance at a = {a:e} m: {error}")]
pub struct PsiError {
    /// The node's radius (m).
    pub a: f64,
    pub error: SpotError,
}

/// Chebyshev–Lobatto nodes of ψ per piece of the table (a piece spans at most
/// [`PSI_PIECE_DECADES`] of the spot radius; neighbouring pieces share their end node).
pub const PSI_PIECE_NODES: usize = 9;

/// The widest piece of the ψ table, in decades of a.
pub const PSI_PIECE_DECADES: f64 = 1.0;

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
    psi.map_err(|error| PsiError { a, error })
}

/// ψ of a layered body, piecewise polynomial in u = ln a: the radii's range cut into
/// equal pieces of at most [`PSI_PIECE_DECADES`], each interpolated through
/// [`PSI_PIECE_NODES`] Chebyshev–Lobatto nodes (barycentric form). ψ is analytic in
/// ln a, so the error falls geometrically with the nodes: measured ≤ 1.2e−6 over four
/// decades of a/h₁ on a plating and insulating layers (the test below; the largest in
/// the decades around a/h₁ = 1, ≤ 1.4e−8 away from them, 2e−12 on a narrow range),
/// against 4.4e−6 of the cubic on 16 nodes per decade it replaces, with 8 solves per
/// decade instead of 16.
#[derive(Debug, Clone)]
pub struct PsiTable {
    u0: f64,
    /// Width of a piece in u.
    du: f64,
    pieces: usize,
    /// The Lobatto points of [−1, 1].
    x: Vec<f64>,
    /// Node values, piece p at p·(n − 1) … p·(n − 1) + n − 1.
    psi: Vec<f64>,
}

/// The Chebyshev–Lobatto points of [−1, 1], x_j = −cos(πj/(n − 1)).
fn lobatto(n: usize) -> Vec<f64> {
    (0..n)
        .map(|j| -(std::f64::consts::PI * j as f64 / (n - 1) as f64).cos())
        .collect()
}

impl PsiTable {
    /// The table over [a_lo, a_hi] (m), 0 < a_lo ≤ a_hi, of the body `spot` (nodes solved
    /// in parallel).
    pub fn new(spot: &Spot, a_lo: f64, a_hi: f64) -> Result<PsiTable, PsiError> {
        let (u_lo, u_hi) = (a_lo.ln(), a_hi.ln());
        let span = (u_hi - u_lo).max(1e-3);
        let pieces =
            ((span / (PSI_PIECE_DECADES * std::f64::consts::LN_10)).ceil() as usize).max(1);
        let du = span / pieces as f64;
        let n = PSI_PIECE_NODES;
        let x = lobatto(n);
        let us: Vec<f64> = (0..pieces * (n - 1) + 1)
            .map(|i| {
                let (p, j) = if i == pieces * (n - 1) {
                    (pieces - 1, n - 1)
                } else {
                    (i / (n - 1), i % (n - 1))
                };
                u_lo + du * (p as f64 + 0.5 * (x[j] + 1.0))
            })
            .collect();
        let psi = us
            .into_par_iter()
            .map(|u| psi_node(spot, u.exp()))
            .collect::<Result<Vec<f64>, PsiError>>()?;
        Ok(PsiTable {
            u0: u_lo,
            du,
            pieces,
            x,
            psi,
        })
    }

    /// ψ(a) by the barycentric Lobatto interpolant of the piece holding ln a (the end
    /// pieces extended for radii just outside the range).
    pub fn at(&self, a: f64) -> f64 {
        let n = PSI_PIECE_NODES;
        let t = (a.ln() - self.u0) / self.du;
        let p = (t.floor().max(0.0) as usize).min(self.pieces - 1);
        let x = 2.0 * (t - p as f64) - 1.0;
        let v = &self.psi[p * (n - 1)..p * (n - 1) + n];
        let (mut num, mut den) = (0.0, 0.0);
        for (j, &xj) in self.x.iter().enumerate() {
            let d = x - xj;
            if d == 0.0 {
                return v[j];
            }
            // weights (−1)^j, halved at the ends
            let w =
                if j % 2 == 0 { 1.0 } else { -1.0 } * if j == 0 || j == n - 1 { 0.5 } else { 1.0 };
            num += w / d * v[j];
            den += w / d;
        }
        num / den
    }

    /// The number of nodes (solves).
    pub fn len(&self) -> usize {
        self.psi.len()
    }

    /// True when the table has no node (never, for a built table).
    pub fn is_empty(&self) -> bool {
        self.psi.is_empty()
    }
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
    /// layer on a half-space and one on an isothermal sink; and a table over a narrow
    /// range (one piece).
    #[test]
    fn interpolated_psi_matches_direct_solves() {
        let h = 1e-5;
        for (k1, kb) in [(200.0, Some(20.0)), (0.5, Some(40.0)), (0.5, None)] {
            let spot = one_layer(h, k1, kb);
            let t = PsiTable::new(&spot, 1e-2 * h, 1e2 * h).unwrap();
            assert_eq!(t.len(), 4 * (PSI_PIECE_NODES - 1) + 1);
            let mut worst: f64 = 0.0;
            for i in 0..40 {
                let a = h * 10f64.powf(-2.0 + 4.0 * (i as f64 + 0.37) / 40.0);
                let exact = spot.psi(a).unwrap();
                worst = worst.max((t.at(a) / exact - 1.0).abs());
            }
            let narrow = PsiTable::new(&spot, 0.3 * h, 0.5 * h).unwrap();
            assert_eq!(narrow.len(), PSI_PIECE_NODES);
            let mut worst_narrow: f64 = 0.0;
            for i in 0..10 {
                let a = h * (0.3 + 0.2 * (i as f64 + 0.41) / 10.0);
                worst_narrow = worst_narrow.max((narrow.at(a) / spot.psi(a).unwrap() - 1.0).abs());
            }
            eprintln!("ψ table k1/kb = {k1}/{kb:?}: worst {worst:.2e}, narrow {worst_narrow:.2e}");
            // measured 1.24e-6, 1.17e-6, 5.5e-7 (the pieces across a/h₁ = 0.1…10, where ψ
            // changes most), 2.0e-12 (narrow)
            assert!(
                worst < 1.2e-5 && worst_narrow < 3e-11,
                "{worst} {worst_narrow}"
            );
        }
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
