//! The table type of the per-stack factors tabulated against the contact radius: values
//! at Chebyshev–Lobatto nodes of log₁₀(a/h₁) on pieces of one fixed partition,
//! interpolated in barycentric form. The constriction factor ψ of conduction
//! ([`crate::constriction::PsiTable`]) and the disc's punch factors
//! ([`crate::disc_stiffness::StiffnessNodes`]) are such tables; they differ in the node
//! count, the partition and the values per node ([`Grid`], [`NodeValue`]).
//!
//! # Grid
//! Piece k of log₁₀(a/h₁) spans [s_k, s_{k+1}]: whole decades (s_k = k), or, above a
//! split k_s, half decades (s_k = k_s + (k − k_s)/2) ([`Grid::piece_start`]). Each piece
//! holds [`Grid::nodes`] Lobatto nodes x_j = −cos(πj/(nodes − 1)) of [−1, 1] (the ends
//! exact), neighbouring pieces sharing their end node:
//!
//! ```text
//!   a_kj = h₁·10^(s_k + (s_{k+1} − s_k)(x_j + 1)/2)       (m)
//! ```
//!
//! A node's radius depends on (h₁, k, j) alone ([`Grid::node_radius`]), so two tables
//! of one stack agree bit for bit where they overlap. Interpolation: the barycentric
//! Lobatto interpolant of the piece holding a/h₁ (weights (−1)^j, halved at the ends;
//! the end pieces extended for radii just outside), exact at the nodes.

/// One fixed partition of log₁₀(a/h₁) into pieces and the nodes per piece.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grid {
    /// Lobatto nodes per piece (ends shared with the neighbours).
    pub nodes: usize,
    /// Pieces above this one are half decades (None: whole decades throughout).
    pub half_decades_from: Option<i32>,
    /// Most pieces a table may span.
    pub max_pieces: i32,
}

impl Grid {
    /// The Lobatto point j of [−1, 1], x_j = −cos(πj/(nodes − 1)) (the ends exact).
    pub fn lobatto(&self, j: usize) -> f64 {
        if j == 0 {
            -1.0
        } else if j >= self.nodes - 1 {
            1.0
        } else {
            -(std::f64::consts::PI * j as f64 / (self.nodes - 1) as f64).cos()
        }
    }

    /// log₁₀(a/h₁) at the start of piece k (exact in floating point).
    pub fn piece_start(&self, k: i32) -> f64 {
        match self.half_decades_from {
            Some(s) if k > s => f64::from(s) + f64::from(k - s) / 2.0,
            _ => f64::from(k),
        }
    }

    /// The piece holding u = log₁₀(a/h₁) (its start ≤ u), as a float (callers
    /// range-check).
    pub fn piece_of(&self, u: f64) -> f64 {
        match self.half_decades_from {
            Some(s) if u >= f64::from(s) => f64::from(s) + (2.0 * (u - f64::from(s))).floor(),
            _ => u.floor(),
        }
    }

    /// The first piece whose start is ≥ u: the end of a range reaching u.
    pub fn piece_end(&self, u: f64) -> f64 {
        match self.half_decades_from {
            Some(s) if u > f64::from(s) => f64::from(s) + (2.0 * (u - f64::from(s))).ceil(),
            _ => u.ceil(),
        }
    }

    /// The radius (m) of node j of piece k on a top layer `h1` thick (module docs); node
    /// nodes − 1 of piece k and node 0 of piece k + 1 are the same bits.
    pub fn node_radius(&self, h1: f64, piece: i32, j: usize) -> f64 {
        let x = self.lobatto(j);
        let (s, e) = (self.piece_start(piece), self.piece_start(piece + 1));
        h1 * 10f64.powf(s + (e - s) * 0.5 * (x + 1.0))
    }
}

/// The values a table holds at one node: combined linearly by the interpolant.
pub trait NodeValue: Copy + PartialEq + std::fmt::Debug {
    /// The zero value (the interpolant's accumulator).
    fn zero() -> Self;
    /// self += c · v, component by component.
    fn add_scaled(&mut self, c: f64, v: &Self);
    /// self / d, component by component.
    fn divided(self, d: f64) -> Self;
    /// Whether every component is finite and positive (the factors' range).
    fn finite_positive(&self) -> bool;
}

impl NodeValue for f64 {
    fn zero() -> Self {
        0.0
    }

    fn add_scaled(&mut self, c: f64, v: &Self) {
        *self += c * v;
    }

    fn divided(self, d: f64) -> Self {
        self / d
    }

    fn finite_positive(&self) -> bool {
        self.is_finite() && *self > 0.0
    }
}

/// Values of one stack at the nodes of a [`Grid`] over the pieces first, first + 1, …
/// (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct LobattoTable<V> {
    grid: Grid,
    key: u64,
    h1: f64,
    first: i32,
    /// Node values, piece p (piece first + p) at (nodes − 1)p … (nodes − 1)(p + 1).
    values: Vec<V>,
}

impl<V: NodeValue> LobattoTable<V> {
    /// A table of the stack with fingerprint `key` and top layer `h1` (m) from its node
    /// values over pieces first, first + 1, …: (nodes − 1)·pieces + 1 values, each
    /// finite and positive; the reason in words otherwise.
    pub fn from_nodes(
        grid: Grid,
        key: u64,
        h1: f64,
        first: i32,
        values: Vec<V>,
    ) -> Result<Self, String> {
        let n = values.len();
        let m = grid.nodes - 1;
        if n < grid.nodes || !(n - 1).is_multiple_of(m) {
            return Err(format!(
                "{n} nodes (need {m}·pieces + 1, at least one piece)"
            ));
        }
        if (n / m) as i64 > i64::from(grid.max_pieces) {
            return Err(format!("{} pieces (at most {})", n / m, grid.max_pieces));
        }
        if !(h1 > 0.0 && h1.is_finite()) {
            return Err(format!("top layer thickness {h1:e} m"));
        }
        if first.unsigned_abs() > 1000 {
            return Err(format!("first piece {first}"));
        }
        if let Some(v) = values.iter().find(|v| !v.finite_positive()) {
            return Err(format!("node value {v:?} (must be finite and positive)"));
        }
        Ok(LobattoTable {
            grid,
            key,
            h1,
            first,
            values,
        })
    }

    /// The stack's fingerprint the table was built for.
    pub fn key(&self) -> u64 {
        self.key
    }

    /// h₁ (m).
    pub fn top_thickness(&self) -> f64 {
        self.h1
    }

    /// The first piece held.
    pub fn first(&self) -> i32 {
        self.first
    }

    /// The partition and nodes.
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// The pieces [k₀, k₁) held.
    pub fn pieces(&self) -> (i32, i32) {
        let pieces = ((self.values.len() - 1) / (self.grid.nodes - 1)) as i32;
        (self.first, self.first + pieces)
    }

    /// The node values, piece by piece (shared ends once).
    pub fn nodes(&self) -> &[V] {
        &self.values
    }

    /// True when the table holds every piece of [k₀, k₁).
    pub fn covers(&self, (k0, k1): (i32, i32)) -> bool {
        let (f, e) = self.pieces();
        f <= k0 && k1 <= e
    }

    /// The values at radius `a` (m): the barycentric Lobatto interpolant of the piece
    /// holding a/h₁ (the end pieces extended for radii just outside).
    pub fn at(&self, a: f64) -> V {
        let g = &self.grid;
        let (f, e) = self.pieces();
        let u = (a / self.h1).log10();
        let k = g.piece_of(u).clamp(f64::from(f), f64::from(e - 1)) as i32;
        let (s, end) = (g.piece_start(k), g.piece_start(k + 1));
        let x = 2.0 * (u - s) / (end - s) - 1.0;
        let n = g.nodes;
        let p = (k - f) as usize;
        let v = &self.values[p * (n - 1)..p * (n - 1) + n];
        let (mut num, mut den) = (V::zero(), 0.0);
        for (j, vj) in v.iter().enumerate() {
            let d = x - g.lobatto(j);
            if d == 0.0 {
                return *vj;
            }
            // weights (−1)^j, halved at the ends
            let w =
                if j % 2 == 0 { 1.0 } else { -1.0 } * if j == 0 || j == n - 1 { 0.5 } else { 1.0 };
            let c = w / d;
            num.add_scaled(c, vj);
            den += c;
        }
        num.divided(den)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two partitions in use: whole decades, and whole decades up to a split with
    /// half decades above; shared end nodes are the same bits; pieces of a range.
    #[test]
    fn partitions_and_shared_nodes() {
        let decades = Grid {
            nodes: 17,
            half_decades_from: None,
            max_pieces: 40,
        };
        let split = Grid {
            nodes: 9,
            half_decades_from: Some(1),
            max_pieces: 80,
        };
        assert_eq!(
            (-1..5).map(|k| split.piece_start(k)).collect::<Vec<_>>(),
            [-1.0, 0.0, 1.0, 1.5, 2.0, 2.5]
        );
        assert_eq!(
            (-1..3).map(|k| decades.piece_start(k)).collect::<Vec<_>>(),
            [-1.0, 0.0, 1.0, 2.0]
        );
        assert_eq!(split.piece_of(1.7), 2.0);
        assert_eq!(split.piece_end(1.7), 3.0);
        assert_eq!(decades.piece_of(1.7), 1.0);
        for g in [decades, split] {
            assert_eq!(g.lobatto(0), -1.0);
            assert_eq!(g.lobatto(g.nodes - 1), 1.0);
            for k in -3..6 {
                assert_eq!(
                    g.node_radius(3e-5, k, g.nodes - 1),
                    g.node_radius(3e-5, k + 1, 0)
                );
            }
        }
        // a table returns its node values at the nodes (to the round-off of log₁₀) and
        // refuses bad nodes
        let vals: Vec<f64> = (0..2 * 8 + 1).map(|i| 1.0 + i as f64).collect();
        let t = LobattoTable::from_nodes(split, 1, 1e-5, 0, vals.clone()).unwrap();
        assert!((t.at(split.node_radius(1e-5, 1, 3)) / vals[8 + 3] - 1.0).abs() < 1e-13);
        assert!(LobattoTable::from_nodes(split, 1, 1e-5, 0, vals[..10].to_vec()).is_err());
        assert!(LobattoTable::from_nodes(split, 1, 1e-5, 0, vec![f64::NAN; 9]).is_err());
    }
}
