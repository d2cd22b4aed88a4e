//! The workspace's numerical building blocks, each written once: Gauss–Legendre
//! quadrature ([`gauss_legendre`]), monotone piecewise-cubic Hermite interpolation
//! (PCHIP: [`pchip_slopes`], [`fritsch_carlson`], [`hermite`]) and a bracketing root
//! finder ([`bracketed`]: safeguarded Newton where a slope is known, regula falsi (Illinois
//! or halving, [`Falsi`]) where not, bisection whenever a step leaves the bracket; [`bisect_adjacent`]
//! narrows a bracket to adjacent floats). The runtime, `strata-tablegen` and
//! `strata-bem` call these; no crate keeps a copy of its own.

use std::f64::consts::PI;

/// Gauss–Legendre nodes x_i and weights w_i on [−1, 1] (Newton on P_n from Tricomi's
/// guess cos(π(i + 3/4)/(n + 1/2)), to round-off; nodes mirrored, so x_{n−1−i} = −x_i
/// exactly): ∫₋₁¹ f dx ≈ Σ w_i f(x_i), exact for polynomials of degree ≤ 2n − 1.
/// Nodes ascending.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        let mut z = (PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            dp = nf * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        w[i] = wi;
        w[n - 1 - i] = wi;
    }
    (x, w)
}

/// [`gauss_legendre`] as (node, weight) pairs, nodes ascending.
pub fn gauss_legendre_pairs(n: usize) -> Vec<(f64, f64)> {
    let (x, w) = gauss_legendre(n);
    x.into_iter().zip(w).collect()
}

/// The 4-point rule as tabulated to 16–17 significant digits (Abramowitz & Stegun,
/// table 25.4): within 2 ulp of [`gauss_legendre`]'s Newton iterates.
#[cfg(feature = "spectral")]
const GL4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_85),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_85),
];
/// The 8-point rule, tabulated as [`GL4`] (within 5 ulp of the Newton iterates).
#[cfg(feature = "spectral")]
const GL8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];

/// The small fixed rules of inner loops (the I model's remainder sums, the conduction
/// kernel's panels), n ≤ 64: the tabulated [`GL4`] and [`GL8`] for n = 4 and 8 (the
/// values these sums were calibrated and recorded with, so their results stay bit for
/// bit), otherwise the rule of [`gauss_legendre_pairs`] computed once per process
/// (callers pass constants; an empty rule above 64).
#[cfg(feature = "spectral")]
pub(crate) fn gauss_legendre_cached(n: usize) -> &'static [(f64, f64)] {
    use std::sync::OnceLock;
    const MAX: usize = 64;
    debug_assert!(n <= MAX, "gauss_legendre_cached({n}): at most {MAX} points");
    match n {
        4 => return &GL4,
        8 => return &GL8,
        _ => {}
    }
    static RULES: [OnceLock<Vec<(f64, f64)>>; MAX + 1] = [const { OnceLock::new() }; MAX + 1];
    match RULES.get(n) {
        Some(cell) => cell.get_or_init(|| gauss_legendre_pairs(n)),
        None => &[],
    }
}

/// Cubic Hermite on one interval [x₀, x₁] (the first two entries of `x`) with values
/// `y` and slopes `m` there, at `at`: (value, slope). With t = (at − x₀)/h, h = x₁ − x₀,
/// v = h₀₀(t)y₀ + h₁₀(t)h m₀ + h₀₁(t)y₁ + h₁₁(t)h m₁ (the Hermite basis).
pub fn hermite(x: &[f64], y: &[f64], m: &[f64], at: f64) -> (f64, f64) {
    let h = x[1] - x[0];
    let t = (at - x[0]) / h;
    let (t2, t3) = (t * t, t * t * t);
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + t;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    let v = h00 * y[0] + h10 * h * m[0] + h01 * y[1] + h11 * h * m[1];
    let d = (6.0 * t2 - 6.0 * t) / h * (y[0] - y[1])
        + (3.0 * t2 - 4.0 * t + 1.0) * m[0]
        + (3.0 * t2 - 2.0 * t) * m[1];
    (v, d)
}

/// Fritsch–Carlson (1980) limiter on given node slopes `m` of monotone data (x
/// ascending): slopes of the wrong sign become 0, a flat interval gets flat ends, and
/// (α, β) = (m_k, m_{k+1})/secant outside the circle α² + β² ≤ 9 is scaled onto it.
/// Returns how many slopes changed.
pub fn fritsch_carlson(x: &[f64], y: &[f64], m: &mut [f64]) -> usize {
    let mut changed = vec![false; m.len()];
    for k in 0..x.len().saturating_sub(1) {
        let d = (y[k + 1] - y[k]) / (x[k + 1] - x[k]);
        if d == 0.0 {
            for j in [k, k + 1] {
                if m[j] != 0.0 {
                    m[j] = 0.0;
                    changed[j] = true;
                }
            }
            continue;
        }
        for j in [k, k + 1] {
            if m[j] / d < 0.0 {
                m[j] = 0.0;
                changed[j] = true;
            }
        }
        let (a, b) = (m[k] / d, m[k + 1] / d);
        let r = a * a + b * b;
        if r > 9.0 {
            let tau = 3.0 / r.sqrt();
            m[k] = tau * a * d;
            m[k + 1] = tau * b * d;
            changed[k] = true;
            changed[k + 1] = true;
        }
    }
    changed.iter().filter(|c| **c).count()
}

/// PCHIP slopes (Fritsch–Butland weighted harmonic mean inside, the three-point
/// shape-preserving rule at the ends), as in SciPy's `PchipInterpolator`; `x` strictly
/// ascending, at least two points.
pub fn pchip_slopes(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    let d: Vec<f64> = (0..n - 1).map(|k| (y[k + 1] - y[k]) / h[k]).collect();
    if n == 2 {
        return vec![d[0], d[0]];
    }
    let mut m = vec![0.0; n];
    for k in 1..n - 1 {
        if d[k - 1] * d[k] > 0.0 {
            let w1 = 2.0 * h[k] + h[k - 1];
            let w2 = h[k] + 2.0 * h[k - 1];
            m[k] = (w1 + w2) / (w1 / d[k - 1] + w2 / d[k]);
        }
    }
    let edge = |h0: f64, h1: f64, d0: f64, d1: f64| {
        let s = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
        if s.signum() != d0.signum() || d0 == 0.0 {
            0.0
        } else if d0.signum() != d1.signum() && s.abs() > 3.0 * d0.abs() {
            3.0 * d0
        } else {
            s
        }
    };
    m[0] = edge(h[0], h[1], d[0], d[1]);
    m[n - 1] = edge(h[n - 2], h[n - 3], d[n - 2], d[n - 3]);
    m
}

/// How a regula-falsi step of [`bracketed`] (no slope given) damps the end of the bracket
/// it keeps, so that a convex or concave f cannot pin one end for ever.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Falsi {
    /// Illinois: the kept end's value is halved when the same end is kept twice in a row;
    /// the secant through (x₋, f₋), (x₊, f₊) is x = (x₋f₊ − x₊f₋)/(f₊ − f₋).
    #[default]
    Illinois,
    /// The kept end's value is halved at every step (a stronger damping for the I model's
    /// strongly convex δ_I(a)); the secant is written x = x₊ − f₊(x₊ − x₋)/(f₊ − f₋), and
    /// the width tests apply to the bracket the new point lies in, before it is narrowed.
    Halving,
}

/// When [`bracketed`] stops (a zero disables a test), and its falsi rule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// |f(x)| ≤ `f` (units of f).
    pub f: f64,
    /// A step |x_{k+1} − x_k| ≤ `step`·|x_k| (relative): the step's end is the root.
    pub step: f64,
    /// A bracket |hi − lo| ≤ `width`·max(|lo|, |hi|) (relative).
    pub width: f64,
    /// A bracket |hi − lo| ≤ `width_abs` (units of x).
    pub width_abs: f64,
    /// The regula-falsi rule when no slope is given.
    pub falsi: Falsi,
}

/// A root found by [`bracketed`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Root {
    /// The root (the last point, or the last step's end).
    pub x: f64,
    /// f at the last point evaluated (NaN: not finite there, the search stopped).
    pub f: f64,
    /// Evaluations of f.
    pub evaluations: usize,
    /// A tolerance was met (false: `max_evaluations` ran out or f was not finite).
    pub converged: bool,
}

/// A root of f on a bracket: `neg` = (x, f(x)) with f ≤ 0 and `pos` = (x, f(x)) with
/// f ≥ 0 (either may be the left end). `f` returns f(x) and, where known, f′(x).
///
/// From `start` (None: the regula-falsi point of the bracket) each step is Newton's
/// x − f/f′ where f returns a slope, else the Illinois regula falsi
/// x = (x₋f₊ − x₊f₋)/(f₊ − f₋) (the end kept twice in a row has its f halved, which
/// makes the convergence superlinear, order ≈ 1.44), and bisection of the bracket
/// whenever the step would leave it; every evaluation shrinks the bracket, so the
/// search converges for any continuous f. Stops when a [`Tolerance`] is met, when f is
/// not finite (`f` NaN, not converged) or after `max_evaluations`.
///
/// A half-open bracket (one end at ±∞, its f a placeholder, e.g. `(f64::INFINITY,
/// 1.0)`) must lie on one side of zero and extend away from it, and needs a `start`:
/// a step that would leave it doubles x (towards the open end) until an evaluation
/// closes it, so the search also finds the bracket of a monotone f on [0, ∞). It stops
/// not converged, with f at the last point (finite) and fewer than `max_evaluations`
/// evaluations, where doubling overflows.
pub fn bracketed<E>(
    mut f: impl FnMut(f64) -> Result<(f64, Option<f64>), E>,
    neg: (f64, f64),
    pos: (f64, f64),
    start: Option<f64>,
    tol: Tolerance,
    max_evaluations: usize,
) -> Result<Root, E> {
    let ((mut xn, mut fn_), (mut xp, mut fp)) = (neg, pos);
    let inside = |x: f64, a: f64, b: f64| x > a.min(b) && x < a.max(b);
    let falsi = |xn: f64, fn_: f64, xp: f64, fp: f64| {
        let x = match tol.falsi {
            Falsi::Illinois => (xn * fp - xp * fn_) / (fp - fn_),
            Falsi::Halving => xp - fp * (xp - xn) / (fp - fn_),
        };
        if inside(x, xn, xp) {
            x
        } else {
            0.5 * (xn + xp)
        }
    };
    let mut x = match start {
        Some(x) if inside(x, xn, xp) => x,
        _ => {
            if fn_ == 0.0 {
                xn
            } else if fp == 0.0 {
                xp
            } else {
                falsi(xn, fn_, xp, fp)
            }
        }
    };
    let mut side = 0i8;
    let mut evaluations = 0;
    let mut last = f64::NAN;
    while evaluations < max_evaluations {
        let (v, slope) = f(x)?;
        evaluations += 1;
        last = v;
        let done = |converged| Root {
            x,
            f: v,
            evaluations,
            converged,
        };
        if !v.is_finite() {
            return Ok(Root {
                f: f64::NAN,
                ..done(false)
            });
        }
        if v.abs() <= tol.f {
            return Ok(done(true));
        }
        // Falsi::Halving tests the bracket x lies in, before it is narrowed to x; the
        // other rules the narrowed one (below)
        let width = (xp - xn).abs();
        if tol.falsi == Falsi::Halving
            && (width <= tol.width * xn.abs().max(xp.abs()) || width <= tol.width_abs)
        {
            return Ok(done(true));
        }
        let halve = |same_side: bool| match tol.falsi {
            Falsi::Illinois => same_side,
            Falsi::Halving => true,
        };
        if v < 0.0 {
            (xn, fn_) = (x, v);
            if halve(side == -1) {
                fp *= 0.5;
            }
            side = -1;
        } else {
            (xp, fp) = (x, v);
            if halve(side == 1) {
                fn_ *= 0.5;
            }
            side = 1;
        }
        let width = (xp - xn).abs();
        let closed = width.is_finite();
        if tol.falsi != Falsi::Halving
            && closed
            && (width <= tol.width * xn.abs().max(xp.abs()) || width <= tol.width_abs)
        {
            return Ok(done(true));
        }
        let mut next = match slope {
            Some(d) => x - v / d,
            None => falsi(xn, fn_, xp, fp),
        };
        if !(next.is_finite() && inside(next, xn, xp)) {
            next = if closed { 0.5 * (xn + xp) } else { 2.0 * x };
            if !next.is_finite() {
                return Ok(done(false));
            }
        }
        if tol.step > 0.0 && (next - x).abs() <= tol.step * x.abs() {
            return Ok(Root {
                x: next,
                ..done(true)
            });
        }
        x = next;
    }
    Ok(Root {
        x,
        f: last,
        evaluations,
        converged: false,
    })
}

/// The largest float x in [lo, hi) at which `below` holds, given that it holds at `lo`,
/// fails at `hi` and changes once between them: bisection to adjacent floats (at most
/// ~64 + 11 halvings).
pub fn bisect_adjacent(mut below: impl FnMut(f64) -> bool, mut lo: f64, mut hi: f64) -> f64 {
    loop {
        let mid = lo + 0.5 * (hi - lo);
        if mid <= lo || mid >= hi {
            return lo;
        }
        if below(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gauss–Legendre integrates x^k exactly for k ≤ 2n − 1 (∫₋₁¹ x^k = 2/(k+1) for even
    /// k, 0 for odd) for n = 1…64 (docs/validation.md).
    #[test]
    fn gauss_legendre_integrates_polynomials() {
        let mut worst = 0.0f64;
        for n in 1..=64 {
            let (x, w) = gauss_legendre(n);
            assert!(
                x.windows(2).all(|p| p[0] < p[1]),
                "n = {n}: nodes ascending"
            );
            for k in 0..2 * n {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
                let exact = if k % 2 == 0 {
                    2.0 / (k as f64 + 1.0)
                } else {
                    0.0
                };
                worst = worst.max((q - exact).abs());
            }
        }
        eprintln!("Gauss–Legendre n = 1…64, monomials to degree 2n − 1: worst {worst:.1e}");
        assert!(worst < 2.5e-14, "worst {worst:e}");
        // a smooth non-polynomial: ∫₋₁¹ eˣ = e − 1/e at 16 points to round-off
        let (x, w) = gauss_legendre(16);
        let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.exp()).sum();
        let exact = std::f64::consts::E - 1.0 / std::f64::consts::E;
        assert!((q - exact).abs() < 5e-15, "{:e}", q - exact);
        // the cached rules: computed ones equal gauss_legendre's; the tabulated 4- and
        // 8-point ones within 6e-16 of it (measured 5.3e-16, a weight of the 8-point rule)
        // and exact on monomials to degree 2n − 1
        #[cfg(feature = "spectral")]
        {
            assert_eq!(
                gauss_legendre_cached(16),
                gauss_legendre_pairs(16).as_slice()
            );
            for n in [4, 8] {
                let (tab, newton) = (gauss_legendre_cached(n), gauss_legendre_pairs(n));
                let dev = tab
                    .iter()
                    .zip(&newton)
                    .map(|(a, b)| (a.0 - b.0).abs().max((a.1 - b.1).abs()))
                    .fold(0.0, f64::max);
                assert!(dev < 6e-16, "{n} points: tabulated vs Newton {dev:e}");
                for k in 0..2 * n as i32 {
                    let q: f64 = tab.iter().map(|(x, w)| w * x.powi(k)).sum();
                    let exact = if k % 2 == 1 {
                        0.0
                    } else {
                        2.0 / (k as f64 + 1.0)
                    };
                    assert!((q - exact).abs() < 3e-15, "{n} points, x^{k}: {q:e}");
                }
            }
        }
    }

    /// PCHIP reproduces a straight line exactly (slopes = its slope, Hermite = the line)
    /// and stays monotone on data with a flat step.
    #[test]
    fn pchip_line_and_monotone() {
        let x = [0.0, 0.3, 1.0, 1.5, 4.0];
        let y: Vec<f64> = x.iter().map(|x| 2.0 * x - 1.0).collect();
        let m = pchip_slopes(&x, &y);
        assert!(m.iter().all(|m| (m - 2.0).abs() < 1e-14), "{m:?}");
        let (v, d) = hermite(&x[1..], &y[1..], &m[1..], 0.7);
        assert!((v - 0.4).abs() < 1e-14 && (d - 2.0).abs() < 1e-14);
        let y = [0.0, 1.0, 1.0, 3.0, 3.5];
        let m = pchip_slopes(&x, &y);
        let mut prev = f64::NEG_INFINITY;
        for k in 0..4 {
            for j in 0..=50 {
                let at = x[k] + (x[k + 1] - x[k]) * j as f64 / 50.0;
                let (v, _) = hermite(&x[k..], &y[k..], &m[k..], at);
                assert!(v >= prev - 1e-15, "not monotone at {at}");
                prev = v;
            }
        }
    }

    /// The root finder against closed forms: x³ = 2 (Illinois and Newton), cos x = x
    /// (Dottie number 0.739 085 133 215 160 6), to 1 ulp-scale tolerances.
    #[test]
    fn bracketed_roots() {
        let tol = Tolerance {
            f: 0.0,
            step: 1e-15,
            width: 1e-15,
            width_abs: 0.0,
            falsi: Falsi::Illinois,
        };
        let cube = |x: f64| Ok::<_, ()>((x * x * x - 2.0, None));
        let r = bracketed(cube, (0.0, -2.0), (2.0, 6.0), None, tol, 200).unwrap();
        assert!(r.converged && (r.x - 2f64.cbrt()).abs() < 4e-16, "{r:?}");
        assert!(r.evaluations < 40, "{r:?}");
        let newton = |x: f64| Ok::<_, ()>((x * x * x - 2.0, Some(3.0 * x * x)));
        let r = bracketed(newton, (0.0, -2.0), (2.0, 6.0), Some(1.0), tol, 200).unwrap();
        assert!(r.converged && (r.x - 2f64.cbrt()).abs() < 4e-16, "{r:?}");
        assert!(r.evaluations < 12, "{r:?}");
        // decreasing f: the negative end on the right
        let dottie = |x: f64| Ok::<_, ()>((x.cos() - x, None));
        let r = bracketed(dottie, (1.0, 1f64.cos() - 1.0), (0.0, 1.0), None, tol, 200).unwrap();
        assert!((r.x - 0.739_085_133_215_160_6).abs() < 3e-16, "{r:?}");
        // not finite: stops, not converged
        let nan = |_x: f64| Ok::<_, ()>((f64::NAN, None));
        let r = bracketed(nan, (0.0, -1.0), (1.0, 1.0), None, tol, 200).unwrap();
        assert!(!r.converged && r.f.is_nan());
        // a half-open bracket [0, ∞) from x = 10⁻³: doubling closes it (at 2.048), then
        // Illinois or Newton as on a closed bracket
        let open = (f64::INFINITY, 1.0);
        let r = bracketed(cube, (0.0, -2.0), open, Some(1e-3), tol, 200).unwrap();
        assert!(r.converged && (r.x - 2f64.cbrt()).abs() < 4e-16, "{r:?}");
        let r = bracketed(newton, (0.0, -2.0), open, Some(1e-3), tol, 200).unwrap();
        assert!(r.converged && (r.x - 2f64.cbrt()).abs() < 4e-16, "{r:?}");
        // never closed: stops where doubling overflows (2¹⁰²⁴), f finite, not converged
        let below = |_x: f64| Ok::<_, ()>((-1.0, None));
        let r = bracketed(below, (0.0, -1.0), open, Some(1.0), tol, 2000).unwrap();
        assert!(
            !r.converged && r.f == -1.0 && r.evaluations == 1024,
            "{r:?}"
        );
        // adjacent floats: the largest x with x² ≤ 2 is √2 rounded down
        let x = bisect_adjacent(|x| x * x <= 2.0, 1.0, 2.0);
        assert!(x * x <= 2.0 && x.next_up() * x.next_up() > 2.0);
    }
}
