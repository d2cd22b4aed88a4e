//! One interpolation mechanism for every table: a tensor product of C¹ cubic Hermite
//! pieces on uniform grids, with node slopes from fourth-order finite differences
//! (five-point stencils, one-sided at the ends). In one dimension the value on a cell
//! is a fixed linear combination of at most six neighbouring nodes, so a lookup costs
//! 6 (1-D) or 36 (2-D) multiply–adds after computing the weights. The error is O(Δ⁴)
//! for smooth data; the derivative of the interpolant is exact (continuous).

use serde::{Deserialize, Serialize};

/// A uniform grid of `n` nodes from `lo` to `hi` (inclusive) in some coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    /// First node.
    pub lo: f64,
    /// Last node.
    pub hi: f64,
    /// Number of nodes (≥ 6, or exactly 1 for a degenerate axis).
    pub n: usize,
}

/// Interpolation weights along one axis: the value is `Σ w[k]·f[start + k]` and the
/// derivative with respect to the coordinate is `Σ dw[k]·f[start + k]`, k < len.
#[derive(Debug, Clone, Copy)]
pub struct Weights {
    pub start: usize,
    pub len: usize,
    pub w: [f64; 6],
    pub dw: [f64; 6],
}

impl Axis {
    /// Minimum number of nodes of a non-degenerate axis.
    pub const MIN_NODES: usize = 6;

    /// Grid spacing (0 for n = 1).
    pub fn step(&self) -> f64 {
        if self.n <= 1 {
            0.0
        } else {
            (self.hi - self.lo) / (self.n - 1) as f64
        }
    }

    /// Node i.
    pub fn node(&self, i: usize) -> f64 {
        if i + 1 == self.n {
            self.hi
        } else {
            self.lo + self.step() * i as f64
        }
    }

    /// All nodes.
    pub fn nodes(&self) -> Vec<f64> {
        (0..self.n).map(|i| self.node(i)).collect()
    }

    /// True when the axis is well formed: finite, lo < hi and n ≥ 6, or n = 1.
    pub fn is_valid(&self) -> bool {
        self.lo.is_finite()
            && self.hi.is_finite()
            && ((self.n == 1 && self.lo == self.hi)
                || (self.n >= Self::MIN_NODES && self.lo < self.hi && self.n < 1 << 24))
    }

    /// Whether c lies in [lo, hi] (with a relative slack of 1e-12 of the span).
    pub fn contains(&self, c: f64) -> bool {
        let slack = 1e-12 * (self.hi - self.lo).abs().max(self.lo.abs().max(1.0) * 1e-3);
        c >= self.lo - slack && c <= self.hi + slack
    }

    /// Weights at coordinate c (clamped to the axis range).
    #[inline]
    pub fn weights(&self, c: f64) -> Weights {
        let n = self.n;
        if n < Self::MIN_NODES {
            return Weights {
                start: 0,
                len: 1,
                w: [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                dw: [0.0; 6],
            };
        }
        let step = self.step();
        let pos = ((c - self.lo) / step).clamp(0.0, (n - 1) as f64);
        let i = (pos as usize).min(n - 2);
        let t = pos - i as f64;
        let start = i.saturating_sub(2).min(n - 6);
        let (t2, t3) = (t * t, t * t * t);
        let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
        let h10 = t3 - 2.0 * t2 + t;
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h11 = t3 - t2;
        let d00 = (6.0 * t2 - 6.0 * t) / step;
        let d10 = (3.0 * t2 - 4.0 * t + 1.0) / step;
        let d01 = (-6.0 * t2 + 6.0 * t) / step;
        let d11 = (3.0 * t2 - 2.0 * t) / step;
        let mut w = [0.0; 6];
        let mut dw = [0.0; 6];
        w[i - start] += h00;
        dw[i - start] += d00;
        w[i + 1 - start] += h01;
        dw[i + 1 - start] += d01;
        let (s0, c0) = slope_stencil(i, n);
        for (k, c) in c0.iter().enumerate() {
            w[s0 + k - start] += h10 * c;
            dw[s0 + k - start] += d10 * c;
        }
        let (s1, c1) = slope_stencil(i + 1, n);
        for (k, c) in c1.iter().enumerate() {
            w[s1 + k - start] += h11 * c;
            dw[s1 + k - start] += d11 * c;
        }
        Weights {
            start,
            len: 6,
            w,
            dw,
        }
    }
}

/// Five-point stencil of Δ·f′ at node k of n (fourth order): (first node, coefficients).
#[inline]
fn slope_stencil(k: usize, n: usize) -> (usize, [f64; 5]) {
    const C: f64 = 1.0 / 12.0;
    if k == 0 {
        (0, [-25.0 * C, 48.0 * C, -36.0 * C, 16.0 * C, -3.0 * C])
    } else if k == 1 {
        (0, [-3.0 * C, -10.0 * C, 18.0 * C, -6.0 * C, C])
    } else if k + 2 == n {
        (n - 5, [-C, 6.0 * C, -18.0 * C, 10.0 * C, 3.0 * C])
    } else if k + 1 == n {
        (n - 5, [3.0 * C, -16.0 * C, 36.0 * C, -48.0 * C, 25.0 * C])
    } else {
        (k - 2, [C, -8.0 * C, 0.0, 8.0 * C, -C])
    }
}

/// 1-D lookup: (value, derivative) of the data `f` (length axis.n, stride `stride`
/// starting at `offset`) at coordinate c.
#[inline]
pub(crate) fn eval1(axis: &Axis, f: &[f64], c: f64) -> (f64, f64) {
    let wt = axis.weights(c);
    let mut v = 0.0;
    let mut d = 0.0;
    for k in 0..wt.len {
        let x = f[wt.start + k];
        v += wt.w[k] * x;
        d += wt.dw[k] * x;
    }
    (v, d)
}

#[cfg(test)]
/// 2-D lookup of row-major data f[i * ny + j] on axes (ax, ay) at (cx, cy): value only.
#[inline]
pub(crate) fn eval2(ax: &Axis, ay: &Axis, f: &[f64], cx: f64, cy: f64) -> f64 {
    let wx = ax.weights(cx);
    let wy = ay.weights(cy);
    let ny = ay.n;
    let mut v = 0.0;
    for i in 0..wx.len {
        let row = &f[(wx.start + i) * ny + wy.start..];
        let s: f64 = wy.w[..wy.len]
            .iter()
            .zip(&row[..wy.len])
            .map(|(w, x)| w * x)
            .sum();
        v += wx.w[i] * s;
    }
    v
}

/// Interpolates along a leading (slowest) axis: `out[k] = Σ w_i f[(start+i)·block + k]`.
pub fn slice_leading(axis: &Axis, f: &[f64], block: usize, c: f64) -> Vec<f64> {
    let wt = axis.weights(c);
    let mut out = vec![0.0; block];
    for i in 0..wt.len {
        let src = &f[(wt.start + i) * block..(wt.start + i + 1) * block];
        for (o, s) in out.iter_mut().zip(src) {
            *o += wt.w[i] * s;
        }
    }
    out
}

/// Node slopes m_k = Δ·f′_k of the interpolant (the five-point stencils above),
/// for fast lookups that need only the two cell nodes and their slopes.
pub fn node_slopes(n: usize, f: impl Fn(usize) -> f64) -> Vec<f64> {
    if n < Axis::MIN_NODES {
        return vec![0.0; n];
    }
    (0..n)
        .map(|k| {
            let (s, c) = slope_stencil(k, n);
            c.iter().enumerate().map(|(j, c)| c * f(s + j)).sum()
        })
        .collect()
}

/// [`node_slopes`] of data even about the first node, f(c₀ − t) = f(c₀ + t): the
/// central stencil with the mirrored values f(−k) = f(k) at the first two nodes, so the
/// slope at the first node is exactly 0 (the interpolant stays even there).
pub(crate) fn node_slopes_even(n: usize, f: impl Fn(usize) -> f64) -> Vec<f64> {
    let mut m = node_slopes(n, &f);
    if n >= Axis::MIN_NODES {
        let (_, c) = slope_stencil(2, n);
        m[0] = 0.0;
        m[1] = c[0] * f(1) + c[1] * f(0) + c[3] * f(2) + c[4] * f(3);
    }
    m
}

/// Cell index, local coordinate t ∈ [0, 1] and the Hermite basis (value and d/dt) at c.
#[inline]
pub fn cell(axis: &Axis, c: f64) -> (usize, [f64; 4], [f64; 4]) {
    let n = axis.n;
    let pos = ((c - axis.lo) / axis.step()).clamp(0.0, (n - 1) as f64);
    let i = (pos as usize).min(n - 2);
    let t = pos - i as f64;
    let (t2, t3) = (t * t, t * t * t);
    (
        i,
        [
            2.0 * t3 - 3.0 * t2 + 1.0,
            t3 - 2.0 * t2 + t,
            -2.0 * t3 + 3.0 * t2,
            t3 - t2,
        ],
        [
            6.0 * t2 - 6.0 * t,
            3.0 * t2 - 4.0 * t + 1.0,
            -6.0 * t2 + 6.0 * t,
            3.0 * t2 - 2.0 * t,
        ],
    )
}

/// Precomputed 1-D interpolant of two arrays on one axis (values and slopes
/// interleaved per node): the same interpolant as `eval1`, 4 terms per array.
#[derive(Debug, Clone)]
pub struct Pair1 {
    axis: Axis,
    /// [f, m_f, g, m_g] per node.
    data: Vec<[f64; 4]>,
}

impl Pair1 {
    /// From two arrays of length axis.n (axis.n ≥ 6).
    pub fn new(axis: Axis, f: &[f64], g: &[f64]) -> Self {
        let mf = node_slopes(axis.n, |k| f[k]);
        let mg = node_slopes(axis.n, |k| g[k]);
        let data = (0..axis.n).map(|k| [f[k], mf[k], g[k], mg[k]]).collect();
        Pair1 { axis, data }
    }

    /// (f, df/dc, g, dg/dc) at coordinate c (clamped to the axis).
    #[inline]
    pub fn eval(&self, c: f64) -> (f64, f64, f64, f64) {
        let (i, h, d) = cell(&self.axis, c);
        let (p, q) = (&self.data[i], &self.data[i + 1]);
        let inv = 1.0 / self.axis.step();
        (
            h[0] * p[0] + h[1] * p[1] + h[2] * q[0] + h[3] * q[1],
            (d[0] * p[0] + d[1] * p[1] + d[2] * q[0] + d[3] * q[1]) * inv,
            h[0] * p[2] + h[1] * p[3] + h[2] * q[2] + h[3] * q[3],
            (d[0] * p[2] + d[1] * p[3] + d[2] * q[2] + d[3] * q[3]) * inv,
        )
    }

    /// f only.
    #[inline]
    pub fn first(&self, c: f64) -> f64 {
        let (i, h, _) = cell(&self.axis, c);
        let (p, q) = (&self.data[i], &self.data[i + 1]);
        h[0] * p[0] + h[1] * p[1] + h[2] * q[0] + h[3] * q[1]
    }

    /// g only.
    #[inline]
    pub fn second(&self, c: f64) -> f64 {
        let (i, h, _) = cell(&self.axis, c);
        let (p, q) = (&self.data[i], &self.data[i + 1]);
        h[0] * p[2] + h[1] * p[3] + h[2] * q[2] + h[3] * q[3]
    }
}

/// Precomputed bicubic Hermite interpolant of row-major data on (ax, ay): the same
/// interpolant as `eval2`, 16 terms per lookup.
#[derive(Debug, Clone)]
pub(crate) struct Grid2 {
    ax: Axis,
    ay: Axis,
    /// [f, m_x, m_y, m_xy] per node.
    data: Vec<[f64; 4]>,
}

impl Grid2 {
    #[cfg(test)]
    /// From f[i * ay.n + j] (both axes ≥ 6 nodes).
    pub fn new(ax: Axis, ay: Axis, f: &[f64]) -> Self {
        Self::build(ax, ay, f, false)
    }

    /// From f[i * ay.n + j] even in y about ay.lo (f(x, y₀ − t) = f(x, y₀ + t)): the
    /// y slopes at the first y node are 0 (`node_slopes_even`), so the interpolant is
    /// even there too, without the spurious linear term a one-sided stencil leaves.
    pub(crate) fn even_in_y(ax: Axis, ay: Axis, f: &[f64]) -> Self {
        Self::build(ax, ay, f, true)
    }

    fn build(ax: Axis, ay: Axis, f: &[f64], even_y: bool) -> Self {
        let slopes_y = |g: &dyn Fn(usize) -> f64| {
            if even_y {
                node_slopes_even(ay.n, g)
            } else {
                node_slopes(ay.n, g)
            }
        };
        let (nx, ny) = (ax.n, ay.n);
        let mut mx = vec![0.0; nx * ny];
        let mut my = vec![0.0; nx * ny];
        let mut mxy = vec![0.0; nx * ny];
        for j in 0..ny {
            let col = node_slopes(nx, |i| f[i * ny + j]);
            for i in 0..nx {
                mx[i * ny + j] = col[i];
            }
        }
        for i in 0..nx {
            let row = slopes_y(&|j| f[i * ny + j]);
            my[i * ny..(i + 1) * ny].copy_from_slice(&row);
            let rowx = slopes_y(&|j| mx[i * ny + j]);
            mxy[i * ny..(i + 1) * ny].copy_from_slice(&rowx);
        }
        let data = (0..nx * ny).map(|k| [f[k], mx[k], my[k], mxy[k]]).collect();
        Grid2 { ax, ay, data }
    }

    /// Value at (cx, cy) (clamped to the axes).
    #[inline]
    pub fn eval(&self, cx: f64, cy: f64) -> f64 {
        let (i, hx, _) = cell(&self.ax, cx);
        let (j, hy, _) = cell(&self.ay, cy);
        let ny = self.ay.n;
        let mut v = 0.0;
        for (a, (bx, sx)) in [(i, (hx[0], hx[1])), (i + 1, (hx[2], hx[3]))] {
            let row = &self.data[a * ny + j..a * ny + j + 2];
            for (p, (by, sy)) in row.iter().zip([(hy[0], hy[1]), (hy[2], hy[3])]) {
                v += bx * by * p[0] + sx * by * p[1] + bx * sy * p[2] + sx * sy * p[3];
            }
        }
        v
    }
}

#[cfg(test)]
mod fast_tests {
    use super::*;

    /// The precomputed forms are the same interpolants as eval1/eval2.
    #[test]
    fn precomputed_equals_stencil_form() {
        let ax = Axis {
            lo: 0.0,
            hi: 2.0,
            n: 9,
        };
        let ay = Axis {
            lo: -1.0,
            hi: 1.0,
            n: 7,
        };
        let f: Vec<f64> = (0..63)
            .map(|k| (((k * 37) % 11) as f64 * 0.3).sin())
            .collect();
        let g2 = Grid2::new(ax, ay, &f);
        let f1: Vec<f64> = f[..9].to_vec();
        let g1: Vec<f64> = f[9..18].to_vec();
        let p = Pair1::new(ax, &f1, &g1);
        for (cx, cy) in [
            (0.0, -1.0),
            (0.31, 0.77),
            (1.99, 0.0),
            (2.0, 1.0),
            (1.234, -0.5),
        ] {
            assert!((g2.eval(cx, cy) - eval2(&ax, &ay, &f, cx, cy)).abs() < 1e-13);
            let (a, da, b, db) = p.eval(cx);
            let (ea, eda) = eval1(&ax, &f1, cx);
            let (eb, edb) = eval1(&ax, &g1, cx);
            assert!((a - ea).abs() < 1e-13 && (da - eda).abs() < 1e-12);
            assert!((b - eb).abs() < 1e-13 && (db - edb).abs() < 1e-12);
            assert_eq!(p.first(cx), a);
            assert_eq!(p.second(cx), b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reproduces cubics exactly away from the ends (the 5-point slopes are exact for
    /// quartics), converges like Δ⁴ on a smooth function, and the derivative is the
    /// derivative of the interpolant (checked by finite differences).
    #[test]
    fn accuracy_and_derivative() {
        let f = |x: f64| (1.3 * x).sin() + 0.2 * x * x;
        let df = |x: f64| 1.3 * (1.3 * x).cos() + 0.4 * x;
        let mut errs = Vec::new();
        for n in [21, 41, 81] {
            let ax = Axis {
                lo: -2.0,
                hi: 3.0,
                n,
            };
            let data: Vec<f64> = ax.nodes().iter().map(|&x| f(x)).collect();
            let mut worst: f64 = 0.0;
            for k in 0..=1000 {
                let x = -2.0 + 5.0 * k as f64 / 1000.0;
                let (v, d) = eval1(&ax, &data, x);
                worst = worst.max((v - f(x)).abs());
                assert!((d - df(x)).abs() < 50.0 * ax.step().powi(3), "{n} {x}");
            }
            errs.push(worst);
        }
        assert!(
            errs[0] / errs[1] > 12.0 && errs[1] / errs[2] > 12.0,
            "{errs:?}"
        );
        // Exact at nodes; cubic exact.
        let ax = Axis {
            lo: 0.0,
            hi: 1.0,
            n: 9,
        };
        let cubic: Vec<f64> = ax.nodes().iter().map(|x| x * x * x - x).collect();
        for x in [0.0, 0.13, 0.5, 0.77, 1.0] {
            let (v, d) = eval1(&ax, &cubic, x);
            assert!((v - (x * x * x - x)).abs() < 1e-14);
            assert!((d - (3.0 * x * x - 1.0)).abs() < 1e-12);
        }
        // Derivative consistent with the interpolant itself.
        let ax = Axis {
            lo: 0.0,
            hi: 1.0,
            n: 7,
        };
        let data = [0.3, -1.0, 2.0, 0.5, 0.1, 4.0, -2.0];
        for x in [0.05, 0.4, 0.93] {
            let h = 1e-6;
            let fd = (eval1(&ax, &data, x + h).0 - eval1(&ax, &data, x - h).0) / (2.0 * h);
            assert!((fd - eval1(&ax, &data, x).1).abs() < 1e-6);
        }
    }

    #[test]
    fn two_d_matches_nested_one_d() {
        let ax = Axis {
            lo: 0.0,
            hi: 2.0,
            n: 8,
        };
        let ay = Axis {
            lo: -1.0,
            hi: 1.0,
            n: 6,
        };
        let f: Vec<f64> = (0..48).map(|k| ((k * 37) % 11) as f64 * 0.1).collect();
        let (cx, cy) = (0.77, 0.31);
        let col: Vec<f64> = (0..8)
            .map(|i| eval1(&ay, &f[i * 6..i * 6 + 6], cy).0)
            .collect();
        let nested = eval1(&ax, &col, cx).0;
        assert!((eval2(&ax, &ay, &f, cx, cy) - nested).abs() < 1e-14);
        let sl = slice_leading(&ax, &f, 6, cx);
        assert!((eval1(&ay, &sl, cy).0 - nested).abs() < 1e-14);
    }
}
