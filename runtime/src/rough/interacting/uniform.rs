//! The uniform mode of the periodic image sums on an elastic base (physics.md §5).
//!
//! The periodic BEM takes the surface deflection with zero mean (on an elastic base the
//! uniform mode of a periodic load is unbounded), so its δ is the approach of the mean
//! planes. The I model's image block sums a source's field w over the (2m+1)² images
//! around the target; on an elastic base that sum grows with the block (w ~ S(0)/r), so
//! the same δ would mean something else for every m. With the target at offset d from
//! the source (cells of sides Lx, Ly, A₀ = LxLy, block Q_m(d): the union of the cells
//! centred on the summed images, half-sides R = (m + ½)L), Poisson's summation gives
//! the zero-mean periodic field as
//!
//! ```text
//! w_per(d) = Σ_{|n|≤m} w(d + nL) − (1/A₀) ∫_{Q_m(d)} w dA + Σ_{|n|>m} [w − cell mean of w],
//! ```
//!
//! every term finite. With w = S(0)/r + w₁ (physics.md §5, [`PointForce`](crate::law::PointForce)): the 1/r
//! part integrates in closed form over the rectangle ([`rect_inv_r`]) and its last sum
//! (w minus its cell mean, −(Lx²∂ₓₓ + Ly²∂ᵧᵧ)w/24 per cell) is −S(0) K/(24 A₀),
//! K = ∫_out (Lx²∂ₓₓ + Ly²∂ᵧᵧ)(1/r) dA ([`outside_moments`]); what is left of it is
//! O(R⁻³). The layered remainder w₁ (zero on a homogeneous solid) is integrated
//! numerically ([`Remainder`]): in polar coordinates ∫_{Q(d)} w₁ dA = ∫ Φ(ρ_d(θ)) dθ with
//! Φ(R) = ∫₀^R w₁ r dr and ρ_d(θ) the distance to the block's edge, and its cell-mean
//! tail from the edges. w₁ is taken from the law's own g (the a → 0 limit
//! g/a³ → (4/3)∫k_z J₀ dρ), the function the image sums add up, so the two agree; it is
//! not small beyond the cell on a soft base (a stiff 100 µm layer on a base 10× softer:
//! w₁ is −2.6 % of S(0)/r at 3 mm, and its asymptotic form −k₂/r³ holds only beyond
//! ~1 cm; over the plane it integrates to 2πS′(0), so Φ(∞) = S′(0)).
//! So the existing image sums get, per source l of the field G_l = (4/3)(Q_l/π) w, the
//! addition Q_l V(d) with
//!
//! ```text
//! V(d) = −4/(3π A₀) · [S(0) (J_m(d) + K/24) + ∫_{Q_m(d)} w₁ dA + T₁]   (1/m),
//! J_m(d) = ∫_{Q_m(d)} dA/r,   T₁ = ∫_out (Lx²∂ₓₓ + Ly²∂ᵧᵧ) w₁ dA / 24,
//! ```
//!
//! a smooth function of d on |dx| ≤ Lx, |dy| ≤ Ly (its nearest singularity, where the
//! block's edge passes through the source, is at |d| = R ≥ 1.5L). A rigid base has
//! S(0) = 0: its image sums converge, its mean displacement (the layers' compression) is
//! physical and kept, and nothing here applies.
//!
//! For every target at once, V is replaced by a Chebyshev interpolant in
//! (u, v) = (dx/Lx, dy/Ly) ∈ [−1, 1]² (even in each; degree chosen until its error,
//! measured against the direct evaluation, is below 1e-7 of the field S(0)/L of one image
//! at distance L), written as monomials: Σ_l w_l V(x_l − x_k) then needs only the
//! moments Σ_l w_l ξ_l^a η_l^b of the sources (ξ, η the centred coordinates in units
//! of L, in [−½, ½], so the binomial expansion does not cancel): O(n N²) per sum.

use crate::law::AsperityLaw;
use crate::numerics::gauss_legendre_pairs;

/// The n-point Gauss–Legendre rule with its nodes descending (x₁ > x₂ > …): the order
/// these sums add their terms in, so that their round-off is the one the shipped
/// scenes' results were recorded with.
fn gauss_legendre_descending(n: usize) -> Vec<(f64, f64)> {
    let mut rule = gauss_legendre_pairs(n);
    rule.reverse();
    rule
}

/// Degrees tried for the interpolant of V (even).
const DEGREES: [usize; 5] = [8, 12, 16, 24, 32];
/// Largest error of the interpolant, in units of S(0)/min(Lx, Ly)·4/(3π) (of
/// max(S(0), |k_z(0)|)/… when S(0) < ½, see [`ZeroMean::build`]): 300 times
/// below the far-field model's tolerance of one image (3e-5 of its point-force field).
/// On a layered solid V carries the table's interpolation noise (~3e-9 of this unit for
/// m = 1), which higher degrees fit no better.
const FIT_TOL: f64 = 1e-7;

/// x asinh(y/|x|) + y asinh(x/|y|): ∂²/∂x∂y of it is 1/√(x² + y²) (the two terms zero
/// where x or y is zero).
fn prim(x: f64, y: f64) -> f64 {
    let a = if x == 0.0 {
        0.0
    } else {
        x * (y / x.abs()).asinh()
    };
    let b = if y == 0.0 {
        0.0
    } else {
        y * (x / y.abs()).asinh()
    };
    a + b
}

/// ∫∫ dx dy / √(x² + y²) over [x1, x2] × [y1, y2] (m).
pub(crate) fn rect_inv_r(x1: f64, x2: f64, y1: f64, y2: f64) -> f64 {
    prim(x2, y2) - prim(x1, y2) - prim(x2, y1) + prim(x1, y1)
}

/// Over the plane outside the rectangle |x| ≤ rx, |y| ≤ ry: (I₃, Kxx, Kyy) =
/// ∫ r⁻³ dA, ∫ ∂ₓₓ(1/r) dA, ∫ ∂ᵧᵧ(1/r) dA (1/m), in polar coordinates with the boundary
/// at 1/ρ(θ) = max(|cos θ|/rx, |sin θ|/ry) (∂ₓₓ(1/r) = (2cos²θ − sin²θ)/r³).
pub(crate) fn outside_moments(rx: f64, ry: f64) -> (f64, f64, f64) {
    let tc = ry.atan2(rx);
    let (sc, cc) = tc.sin_cos();
    let i3 = 4.0 * (sc / rx + cc / ry);
    let kxx = 4.0 * ((2.0 * sc - sc.powi(3)) / rx + (cc.powi(3) - cc) / ry);
    let kyy = 4.0 * ((2.0 * cc - cc.powi(3)) / ry + (sc.powi(3) - sc) / rx);
    (i3, kxx, kyy)
}

/// The layered remainder w₁(r) = w(r) − S(0)/r of the point-force field (1/m, module
/// docs), from the law's g at its smallest contact radius, and Φ(R) = ∫₀^R w₁ r dr
/// (8-point Gauss–Legendre on segments growing by 10 % from 1e-6 of the cell).
pub(crate) struct Remainder<'l> {
    law: &'l dyn AsperityLaw,
    s0: f64,
    a0: f64,
    /// Segment ends r_k (m) and Φ(r_k) (m).
    cum: Vec<(f64, f64)>,
    gl: Vec<(f64, f64)>,
}

impl<'l> Remainder<'l> {
    /// The remainder of `law` (S(0) = `s0`) integrated out to `r_max` (m) from
    /// `r_min` (m, the first segment end).
    fn new(law: &'l dyn AsperityLaw, s0: f64, r_min: f64, r_max: f64) -> Remainder<'l> {
        let mut rem = Remainder {
            law,
            s0,
            a0: 1e-3 * r_min,
            cum: vec![(0.0, 0.0)],
            gl: gauss_legendre_descending(8),
        };
        let mut r = r_min;
        let mut phi = 0.0;
        let mut lo = 0.0;
        loop {
            phi += rem.segment(lo, r);
            rem.cum.push((r, phi));
            if r >= r_max {
                break;
            }
            lo = r;
            r *= 1.1;
        }
        rem
    }

    /// w₁(r) (1/m), r > 0.
    pub fn w1(&self, r: f64) -> f64 {
        let a = self.a0;
        let rr = r.max(1.0001 * a);
        0.75 * self.law.g(a, rr) / (a * a * a) - (self.s0 - 1.0) / r
    }

    /// ∫_lo^hi w₁ r dr.
    fn segment(&self, lo: f64, hi: f64) -> f64 {
        let (c, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        self.gl
            .iter()
            .map(|&(x, w)| {
                let r = c + h * x;
                w * h * self.w1(r) * r
            })
            .sum()
    }

    /// Φ(R) = ∫₀^R w₁ r dr (m), R within the integrated range.
    pub fn phi(&self, big_r: f64) -> f64 {
        let k = self.cum.partition_point(|&(r, _)| r < big_r).max(1);
        let (r0, p0) = self.cum[k - 1];
        p0 + self.segment(r0, big_r)
    }
}

/// ∫ over the block Q (half-sides `rx`, `ry`, centred at offset d) of w₁ (m), as
/// ∫ Φ(ρ_d(θ)) dθ with ρ_d(θ) the distance from the source to Q's edge along θ: one
/// Gauss–Legendre rule per edge (smooth between the corners).
fn block_integral(rem: &Remainder, rx: f64, ry: f64, d: (f64, f64)) -> f64 {
    let corners = [
        (d.0 + rx, d.1 + ry),
        (d.0 - rx, d.1 + ry),
        (d.0 - rx, d.1 - ry),
        (d.0 + rx, d.1 - ry),
    ];
    let gl = gauss_legendre_descending(24);
    let mut total = 0.0;
    for e in 0..4 {
        let (p, q) = (corners[e], corners[(e + 1) % 4]);
        let (t0, mut t1) = (p.1.atan2(p.0), q.1.atan2(q.0));
        if t1 < t0 {
            t1 += 2.0 * std::f64::consts::PI;
        }
        // the edge as the line n·x = c
        let (ex, ey) = (q.0 - p.0, q.1 - p.1);
        let len = ex.hypot(ey);
        let (nx, ny) = (ey / len, -ex / len);
        let c = (nx * p.0 + ny * p.1).abs();
        let (mid, half) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
        for &(x, w) in &gl {
            let th = mid + half * x;
            let rho = c / (nx * th.cos() + ny * th.sin()).abs();
            total += w * half * rem.phi(rho);
        }
    }
    total
}

/// T₁ of the module docs (m): the cell-mean tail of w₁ outside the block (half-sides
/// `rx`, `ry`, centred), ∫_out ∂ₓₓw₁ dA = −2 ∫ w₁′(r) rx/r dy along x = rx (and alike
/// in y), w₁′ by central differences.
fn remainder_tail(rem: &Remainder, extent: (f64, f64), rx: f64, ry: f64) -> f64 {
    let gl = gauss_legendre_descending(32);
    let dw = |r: f64| {
        let h = 1e-4 * r;
        (rem.w1(r + h) - rem.w1(r - h)) / (2.0 * h)
    };
    let edge = |across: f64, along: f64| -> f64 {
        gl.iter()
            .map(|&(x, w)| {
                let t = along * x;
                let r = across.hypot(t);
                w * along * dw(r) * across / r
            })
            .sum::<f64>()
    };
    let ixx = -2.0 * edge(rx, ry);
    let iyy = -2.0 * edge(ry, rx);
    (extent.0 * extent.0 * ixx + extent.1 * extent.1 * iyy) / 24.0
}

/// The geometry of one image block and what of the solid its correction needs.
pub(crate) struct Block<'l> {
    pub extent: (f64, f64),
    pub m: usize,
    pub s0: f64,
    /// The layered remainder (None on a homogeneous solid, where w₁ ≡ 0).
    pub rem: Option<Remainder<'l>>,
    /// T₁ (m).
    tail1: f64,
}

impl<'l> Block<'l> {
    /// The block of (2m+1)² cells of sides `extent` (m) on `law` (S(0) = `s0`).
    pub fn new(law: &'l dyn AsperityLaw, s0: f64, extent: (f64, f64), m: usize) -> Block<'l> {
        let (rx, ry) = ((m as f64 + 0.5) * extent.0, (m as f64 + 0.5) * extent.1);
        let rem = (!law.is_homogeneous()).then(|| {
            let r_max = 1.01 * (rx.hypot(ry) + extent.0.hypot(extent.1));
            Remainder::new(law, s0, 1e-6 * extent.0.min(extent.1), r_max)
        });
        let tail1 = rem
            .as_ref()
            .map_or(0.0, |r| remainder_tail(r, extent, rx, ry));
        Block {
            extent,
            m,
            s0,
            rem,
            tail1,
        }
    }
}

/// V(d) of the module docs (1/m): what one unit of Q = χa³/R of a source adds to the
/// displacement of a target at offset d = (dx, dy) (m) so that the (2m+1)² image sum
/// of the block becomes the zero-mean periodic one.
pub(crate) fn kernel(b: &Block, d: (f64, f64)) -> f64 {
    let (lx, ly) = b.extent;
    let (rx, ry) = ((b.m as f64 + 0.5) * lx, (b.m as f64 + 0.5) * ly);
    let j = rect_inv_r(d.0 - rx, d.0 + rx, d.1 - ry, d.1 + ry);
    let (_, kxx, kyy) = outside_moments(rx, ry);
    let k = lx * lx * kxx + ly * ly * kyy;
    let layered = b
        .rem
        .as_ref()
        .map_or(0.0, |r| block_integral(r, rx, ry, d) + b.tail1);
    let bracket = b.s0 * (j + k / 24.0) + layered;
    -4.0 / (3.0 * std::f64::consts::PI * lx * ly) * bracket
}

/// Monomial coefficients of the Chebyshev polynomials T_0 … T_n (row j: T_j).
fn chebyshev_monomials(n: usize) -> Vec<Vec<f64>> {
    let mut t = vec![vec![0.0; n + 1]; n + 1];
    t[0][0] = 1.0;
    if n >= 1 {
        t[1][1] = 1.0;
    }
    for j in 2..=n {
        for i in 0..=n {
            let up = if i > 0 { 2.0 * t[j - 1][i - 1] } else { 0.0 };
            t[j][i] = up - t[j - 2][i];
        }
    }
    t
}

/// The zero-mean correction of one image block (module docs): V as monomials in
/// (u, v) = (dx/Lx, dy/Ly).
#[derive(Debug, Clone)]
pub(crate) struct ZeroMean {
    /// Degree N.
    deg: usize,
    /// c[i(N+1) + j]: coefficient of u^i v^j.
    c: Vec<f64>,
    extent: (f64, f64),
    /// V(0) (1/m): the self term.
    pub v0: f64,
    /// Largest measured error of the interpolant (1/m).
    pub worst: f64,
}

impl ZeroMean {
    /// The correction for the (2m+1)² block of cells `extent` (m) on a solid with
    /// `pf`; None where none applies (a rigid base, S(0) = 0) or when no degree meets
    /// the tolerance (not seen for m ≥ 1: m = 1 needs N = 24).
    pub fn build(law: &dyn AsperityLaw, extent: (f64, f64), m: usize) -> Option<ZeroMean> {
        let s0 = law.point_force().s0;
        if s0.is_nan() || s0 <= 0.0 || m == 0 {
            return None;
        }
        let block = Block::new(law, s0, extent, m);
        let unit = 4.0 / (3.0 * std::f64::consts::PI) / extent.0.min(extent.1);
        let mut best: Option<ZeroMean> = None;
        for deg in DEGREES {
            let zm = Self::fit(&block, deg);
            if zm.worst <= FIT_TOL * s0 * unit {
                return Some(zm);
            }
            if best.as_ref().is_none_or(|b| zm.worst < b.worst) {
                best = Some(zm);
            }
        }
        // S(0) ≪ 1 (a soft layer on a much stiffer base, or a stack against a stiff
        // counterface): V carries the table's noise in the layered part, of size
        // |k_z(0)| = 1 − S(0), not S(0); the best degree is taken when it is within
        // FIT_TOL of that part (its error is then still ≤ 1e-7/S(0) of the S(0) field,
        // e.g. 5.4e-6 at S(0) = 0.0174, within the 3e-5 of the far-field model).
        best.filter(|b| b.worst <= FIT_TOL * (s0 - 1.0).abs().max(s0) * unit)
    }

    /// The degree-`deg` interpolant at the Chebyshev points, its error measured at the
    /// corners, the edges' midpoints and a 13 × 13 grid between the nodes.
    fn fit(block: &Block, deg: usize) -> ZeroMean {
        let extent = block.extent;
        let n = deg + 1;
        let node = |i: usize| (std::f64::consts::PI * (i as f64 + 0.5) / n as f64).cos();
        let vals: Vec<f64> = (0..n * n)
            .map(|ij| {
                let (u, v) = (node(ij / n), node(ij % n));
                kernel(block, (u * extent.0, v * extent.1))
            })
            .collect();
        // Chebyshev coefficients a_pq (discrete orthogonality), then monomials.
        let proj = |p: usize, i: usize| {
            let w = if p == 0 { 1.0 } else { 2.0 } / n as f64;
            w * (p as f64 * std::f64::consts::PI * (i as f64 + 0.5) / n as f64).cos()
        };
        let mut tmp = vec![0.0; n * n]; // [p][j]
        for p in 0..n {
            for j in 0..n {
                tmp[p * n + j] = (0..n).map(|i| proj(p, i) * vals[i * n + j]).sum();
            }
        }
        let mut a = vec![0.0; n * n]; // [p][q]
        for p in 0..n {
            for q in 0..n {
                a[p * n + q] = (0..n).map(|j| proj(q, j) * tmp[p * n + j]).sum();
            }
        }
        let t = chebyshev_monomials(deg);
        let mut c = vec![0.0; n * n];
        for p in (0..n).step_by(2) {
            for q in (0..n).step_by(2) {
                let apq = a[p * n + q];
                for i in (0..=p).step_by(2) {
                    for j in (0..=q).step_by(2) {
                        c[i * n + j] += apq * t[p][i] * t[q][j];
                    }
                }
            }
        }
        let mut zm = ZeroMean {
            deg,
            c,
            extent,
            v0: 0.0,
            worst: 0.0,
        };
        zm.v0 = zm.value(0.0, 0.0);
        let mut worst: f64 = (zm.v0 - kernel(block, (0.0, 0.0))).abs();
        let k = 12;
        for i in 0..=k {
            for j in 0..=k {
                let (u, v) = (
                    2.0 * i as f64 / k as f64 - 1.0,
                    2.0 * j as f64 / k as f64 - 1.0,
                );
                let (dx, dy) = (u * extent.0, v * extent.1);
                worst = worst.max((zm.value(dx, dy) - kernel(block, (dx, dy))).abs());
            }
        }
        zm.worst = worst;
        zm
    }

    /// The interpolant of V at offset (dx, dy) (m), |dx| ≤ Lx, |dy| ≤ Ly.
    pub fn value(&self, dx: f64, dy: f64) -> f64 {
        let n = self.deg + 1;
        let (u, v) = (dx / self.extent.0, dy / self.extent.1);
        let (u2, v2) = (u * u, v * v);
        let mut s = 0.0;
        let mut ui = 1.0;
        for i in (0..n).step_by(2) {
            let mut row = 0.0;
            let mut vj = 1.0;
            for j in (0..n).step_by(2) {
                row += self.c[i * n + j] * vj;
                vj *= v2;
            }
            s += row * ui;
            ui *= u2;
        }
        s
    }

    /// out[k] = Σ_l w[l] V(p_l − p_k) over every l (k itself included) at the points
    /// `pts` (m, inside one cell [0, Lx) × [0, Ly)), by the sources' moments (module
    /// docs): O(n N²).
    pub fn apply(&self, pts: &[(f64, f64)], w: &[f64], out: &mut [f64]) {
        let n = self.deg + 1;
        let (lx, ly) = self.extent;
        let centred = |p: &(f64, f64)| (p.0 / lx - 0.5, p.1 / ly - 0.5);
        // moments M_ab = Σ_l w_l ξ_l^a η_l^b
        let mut mom = vec![0.0; n * n];
        let mut xp = vec![0.0; n];
        let mut yp = vec![0.0; n];
        for (p, &wl) in pts.iter().zip(w) {
            if wl == 0.0 {
                continue;
            }
            let (xi, eta) = centred(p);
            powers(xi, &mut xp);
            powers(eta, &mut yp);
            for a in 0..n {
                let wa = wl * xp[a];
                let row = &mut mom[a * n..(a + 1) * n];
                for b in 0..n {
                    row[b] += wa * yp[b];
                }
            }
        }
        // B_pq = Σ_ab c_{a+p, b+q} C(a+p, a) C(b+q, b) M_ab, the coefficients of
        // (−ξ_k)^p (−η_k)^q
        let binom = binomials(n);
        let mut bq = vec![0.0; n * n];
        for p in 0..n {
            for q in 0..n {
                let mut s = 0.0;
                for a in 0..n - p {
                    for b in 0..n - q {
                        let cij = self.c[(a + p) * n + (b + q)];
                        if cij != 0.0 {
                            s += cij
                                * binom[(a + p) * n + a]
                                * binom[(b + q) * n + b]
                                * mom[a * n + b];
                        }
                    }
                }
                bq[p * n + q] = s;
            }
        }
        for (p, o) in pts.iter().zip(out.iter_mut()) {
            let (xi, eta) = centred(p);
            powers(-xi, &mut xp);
            powers(-eta, &mut yp);
            let mut s = 0.0;
            for a in 0..n {
                let row = &bq[a * n..(a + 1) * n];
                let mut r = 0.0;
                for b in 0..n {
                    r += row[b] * yp[b];
                }
                s += r * xp[a];
            }
            *o = s;
        }
    }
}

/// out[i] = x^i.
fn powers(x: f64, out: &mut [f64]) {
    let mut v = 1.0;
    for o in out.iter_mut() {
        *o = v;
        v *= x;
    }
}

/// C(i, j) at [i·n + j], i, j < n.
fn binomials(n: usize) -> Vec<f64> {
    let mut b = vec![0.0; n * n];
    for i in 0..n {
        b[i * n] = 1.0;
        for j in 1..=i {
            b[i * n + j] = b[(i - 1) * n + j - 1] + if j < i { b[(i - 1) * n + j] } else { 0.0 };
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::PointForce;

    /// A homogeneous-like law (w₁ ≡ 0) with a given S(0).
    struct Flat(f64);
    impl AsperityLaw for Flat {
        fn e_star(&self) -> f64 {
            1e9
        }
        fn chi(&self, _: f64) -> f64 {
            1.0
        }
        fn zeta(&self, _: f64) -> f64 {
            1.0
        }
        fn g(&self, _: f64, _: f64) -> f64 {
            0.0
        }
        fn point_force(&self) -> PointForce {
            PointForce { s0: self.0 }
        }
        fn is_homogeneous(&self) -> bool {
            true
        }
    }

    /// The closed-form rectangle integral of 1/r against a midpoint sum (off-centre, the
    /// singularity inside, each quarter's sum graded towards the singular corner): the
    /// sum at 1000² points is off by 1.9e-6 relative (its own error, O(1/n²)).
    #[test]
    fn rectangle_integral_of_inverse_r() {
        let (x1, x2, y1, y2) = (-0.7, 1.3, -0.4, 0.9);
        let exact = rect_inv_r(x1, x2, y1, y2);
        // split at the origin so that the singular point is a corner of four pieces:
        // on each, a graded midpoint sum in polar-free form converges
        let piece = |x2: f64, y2: f64| {
            // ∫∫ over [0, x2] × [0, y2] of 1/r (x2, y2 > 0): closed form by symmetry
            // checked against a product Gauss sum in (r-free) variables x = s t ...
            let n = 1000;
            let mut s = 0.0;
            for i in 0..n {
                for j in 0..n {
                    // substitution x = x2 (i+½)²/n², y = y2 (j+½)²/n² (graded to 0)
                    let (ti, tj) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                    let (x, y) = (x2 * ti * ti, y2 * tj * tj);
                    let jac = x2 * 2.0 * ti / n as f64 * y2 * 2.0 * tj / n as f64;
                    s += jac / x.hypot(y);
                }
            }
            s
        };
        let sum = piece(-x1, -y1) + piece(x2, -y1) + piece(-x1, y2) + piece(x2, y2);
        assert!((sum - exact).abs() < 5e-6 * exact, "{sum} vs {exact}");
    }

    /// Outside a square of half-side R: I₃ = 4√2/R and Kxx + Kyy = I₃ (∇²(1/r) = 1/r³);
    /// a rectangle's moments against a polar quadrature (1e-12).
    #[test]
    fn outside_moments_closed_forms() {
        let (i3, kxx, kyy) = outside_moments(2.0, 2.0);
        assert!((i3 - 4.0 * 2f64.sqrt() / 2.0).abs() < 1e-14);
        assert!((kxx + kyy - i3).abs() < 1e-14);
        let (rx, ry) = (1.5, 0.6);
        let (i3, kxx, kyy) = outside_moments(rx, ry);
        let n = 200_000;
        let (mut qi, mut qx, mut qy) = (0.0, 0.0, 0.0);
        for k in 0..n {
            let th = 2.0 * std::f64::consts::PI * (k as f64 + 0.5) / n as f64;
            let (s, c) = th.sin_cos();
            let inv = (c.abs() / rx).max(s.abs() / ry);
            let dth = 2.0 * std::f64::consts::PI / n as f64;
            qi += inv * dth;
            qx += (2.0 * c * c - s * s) * inv * dth;
            qy += (2.0 * s * s - c * c) * inv * dth;
        }
        for (a, b) in [(i3, qi), (kxx, qx), (kyy, qy)] {
            assert!((a - b).abs() < 1e-9 * i3, "{a} vs {b}");
        }
    }

    /// The image block plus V converges to the zero-mean periodic sum of 1/r as O(R⁻³)
    /// (the first neglected term of the cell means), on rectangular cells: measured
    /// |c(8) − c(64)| = 1.2e-4/L, |c(16) − c(64)| = 1.6e-5/L (an independent NumPy
    /// evaluation of the same sums agrees to 1e-13); the uncorrected sums grow without
    /// bound (by > 0.01/L from m = 8 to 64, ~1/m).
    #[test]
    fn corrected_image_sums_converge() {
        let (lx, ly) = (1.0e-3, 0.7e-3);
        let d = (0.31e-3, -0.52e-3);
        let law = Flat(1.0);
        let sum = |m: i64| {
            let mut s = 0.0;
            for i in -m..=m {
                for j in -m..=m {
                    s += 1.0 / (d.0 + i as f64 * lx).hypot(d.1 + j as f64 * ly);
                }
            }
            s
        };
        let k = 3.0 * std::f64::consts::PI / 4.0;
        let c = |m: i64| sum(m) + k * kernel(&Block::new(&law, 1.0, (lx, ly), m as usize), d);
        let (c8, c16, c64) = (c(8), c(16), c(64));
        let (e8, e16) = ((c8 - c64).abs() * lx, (c16 - c64).abs() * lx);
        assert!(e8 < 2.5e-4 && e8 > 0.0, "{e8}");
        assert!(e16 < e8 / 5.0, "{e16} vs {e8}");
        assert!((sum(64) - sum(8)) * lx > 0.01);
    }

    /// The interpolant meets its tolerance for m = 1…8 and square and flat cells, and the
    /// moment sums equal the direct pair sums (1e-12 of the largest term).
    #[test]
    fn moment_sums_equal_pair_sums() {
        let law = Flat(0.3);
        for (extent, m) in [
            ((1e-3, 1e-3), 1),
            ((1e-3, 1e-3), 2),
            ((2e-3, 0.5e-3), 4),
            ((1e-3, 1e-3), 8),
        ] {
            let zm = ZeroMean::build(&law, extent, m).expect("fit");
            let block = Block::new(&law, 0.3, extent, m);
            let scale = 4.0 / (3.0 * std::f64::consts::PI) * 0.3 / extent.0.min(extent.1);
            assert!(zm.worst <= FIT_TOL * scale);
            let pts: Vec<(f64, f64)> = (0..37)
                .map(|i| {
                    let t = i as f64 * 0.618_033_988_75;
                    ((t.fract()) * extent.0, ((t * 1.7).fract()) * extent.1)
                })
                .collect();
            let w: Vec<f64> = (0..37).map(|i| 1.0 + (i % 5) as f64).collect();
            let mut out = vec![0.0; pts.len()];
            zm.apply(&pts, &w, &mut out);
            let mut big: f64 = 0.0;
            for (k, pk) in pts.iter().enumerate() {
                let direct: f64 = pts
                    .iter()
                    .zip(&w)
                    .map(|(pl, wl)| wl * kernel(&block, (pl.0 - pk.0, pl.1 - pk.1)))
                    .sum();
                big = big.max(direct.abs());
                assert!(
                    (out[k] - direct).abs() < 1e-9 * direct.abs(),
                    "{m}: {} vs {direct}",
                    out[k]
                );
            }
            assert!(big > 0.0);
        }
    }

    /// A rigid base (S(0) = 0) gets no correction.
    #[test]
    fn rigid_base_has_none() {
        assert!(ZeroMean::build(&Flat(0.0), (1e-3, 1e-3), 2).is_none());
    }
}
