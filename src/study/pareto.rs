//! Pareto fronts of (time, error) points.
//!
//! Error e is clamped to the stage's floor f (the accuracy of its reference):
//! e' = max(e, f), and errors within a factor [`SAME`] of each other count as equal
//! ("j is at least as accurate as i" means e'_j ≤ SAME·e'_i). Point i is **on the
//! front** when no point j is at least as fast and at least as accurate, and strictly
//! better in one (t_j < t_i, or SAME·e'_j < e'_i). Its **time factor** is
//! t_i / min{t_j : j at least as accurate as i}: 1 on the front, > 1 when a point at
//! least as accurate is that many times faster.

/// Time factor up to which a point counts as "near" the front.
pub const NEAR: f64 = 2.0;
/// Errors within this factor of each other count as equal.
pub const SAME: f64 = 1.1;

/// A point of a front: time (s) and error (dimensionless), both ≥ 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    pub time: f64,
    pub error: f64,
}

fn clamp(e: f64, floor: f64) -> f64 {
    if e.is_finite() { e.max(floor) } else { e }
}

/// Which points are on the front.
pub fn on_front(points: &[Point], floor: f64) -> Vec<bool> {
    (0..points.len())
        .map(|i| {
            let (ti, ei) = (points[i].time, clamp(points[i].error, floor));
            if !(ti.is_finite() && ei.is_finite()) {
                return false;
            }
            !points.iter().enumerate().any(|(j, p)| {
                let ej = clamp(p.error, floor);
                j != i && p.time <= ti && ej <= SAME * ei && (p.time < ti || SAME * ej < ei)
            })
        })
        .collect()
}

/// t_i over the time of the fastest point at least as accurate as i (≥ 1).
pub fn time_factor(points: &[Point], i: usize, floor: f64) -> f64 {
    let ei = clamp(points[i].error, floor);
    let best = points
        .iter()
        .filter(|p| clamp(p.error, floor) <= SAME * ei && p.time.is_finite())
        .map(|p| p.time)
        .fold(f64::INFINITY, f64::min);
    points[i].time / best
}

/// The fastest point at least as accurate as i (its index), if it is not i.
pub fn better(points: &[Point], i: usize, floor: f64) -> Option<usize> {
    let ei = clamp(points[i].error, floor);
    let mut best: Option<usize> = None;
    for (j, p) in points.iter().enumerate() {
        if clamp(p.error, floor) <= SAME * ei
            && p.time.is_finite()
            && best.is_none_or(|b| p.time < points[b].time)
        {
            best = Some(j);
        }
    }
    best.filter(|&j| j != i && points[j].time < points[i].time)
}

/// "on the front", "near the front (1.4×)" or "off the front (3.2×)" with the
/// time factor.
pub fn status(points: &[Point], i: usize, floor: f64) -> String {
    let front = on_front(points, floor);
    let f = time_factor(points, i, floor);
    if front[i] {
        "**on the front**".into()
    } else if f <= NEAR {
        format!("near the front ({f:.2}× the time of the fastest point as accurate)")
    } else {
        format!("**off the front** ({f:.1}× the time of the fastest point as accurate)")
    }
}

/// Short form for table cells: "on", "near (1.4×)", "off (3.2×)".
pub fn short_status(points: &[Point], i: usize, floor: f64) -> String {
    let front = on_front(points, floor);
    let f = time_factor(points, i, floor);
    if front[i] {
        "on".into()
    } else if f <= NEAR {
        format!("near ({f:.2}×)")
    } else {
        format!("off ({f:.1}×)")
    }
}

/// The front as a staircase polyline (time ascending) for plots: from each front
/// point horizontally to the next one's time, then down.
pub fn staircase(points: &[Point], floor: f64) -> Vec<(f64, f64)> {
    let front = on_front(points, floor);
    let mut f: Vec<(f64, f64)> = points
        .iter()
        .zip(&front)
        .filter(|(_, on)| **on)
        .map(|(p, _)| (p.time, clamp(p.error, floor)))
        .collect();
    f.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = Vec::new();
    for (k, &(t, e)) in f.iter().enumerate() {
        if k > 0 {
            out.push((t, f[k - 1].1));
        }
        out.push((t, e));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pts(v: &[(f64, f64)]) -> Vec<Point> {
        v.iter()
            .map(|&(time, error)| Point { time, error })
            .collect()
    }

    /// A hand-checked set: (1, 1e-2) and (2, 1e-4) and (8, 1e-9) are on the front;
    /// (3, 1e-3) is beaten by (2, 1e-4); below the floor 1e-8, (8, 1e-9) and
    /// (9, 1e-12) tie in error, so the slower one is off the front.
    #[test]
    fn front_and_factors() {
        let p = pts(&[
            (1.0, 1e-2),
            (2.0, 1e-4),
            (3.0, 1e-3),
            (8.0, 1e-9),
            (9.0, 1e-12),
        ]);
        assert_eq!(on_front(&p, 0.0), vec![true, true, false, true, true]);
        assert_eq!(on_front(&p, 1e-8), vec![true, true, false, true, false]);
        assert_eq!(time_factor(&p, 2, 1e-8), 1.5);
        assert_eq!(time_factor(&p, 4, 1e-8), 9.0 / 8.0);
        assert_eq!(better(&p, 2, 0.0), Some(1));
        assert_eq!(better(&p, 1, 0.0), None);
        assert!(status(&p, 2, 0.0).starts_with("near"));
        assert!(status(&p, 1, 0.0).contains("on the front"));
        assert_eq!(short_status(&p, 2, 0.0), "near (1.50×)");
        assert_eq!(short_status(&p, 4, 1e-8), "near (1.12×)");
        assert_eq!(short_status(&p, 0, 0.0), "on");
        let s = staircase(&p, 0.0);
        assert_eq!(s.first(), Some(&(1.0, 1e-2)));
        assert_eq!(s.last(), Some(&(9.0, 1e-12)));
        assert_eq!(s.len(), 7);
    }

    /// Errors within 10 % are equal: (1, 1.05e-3) beats (2, 1e-3) (factor 2), while
    /// (3, 1e-4) is ten times more accurate and stays on the front.
    #[test]
    fn nearly_equal_errors_count_as_equal() {
        let p = pts(&[(1.0, 1.05e-3), (2.0, 1e-3), (3.0, 1e-4)]);
        assert_eq!(on_front(&p, 0.0), vec![true, false, true]);
        assert_eq!(time_factor(&p, 1, 0.0), 2.0);
        assert_eq!(better(&p, 1, 0.0), Some(0));
        assert_eq!(short_status(&p, 1, 0.0), "near (2.00×)");
    }

    #[test]
    fn non_finite_points_are_never_on_the_front() {
        let p = pts(&[(1.0, f64::NAN), (2.0, 1e-3)]);
        assert_eq!(on_front(&p, 0.0), vec![false, true]);
    }
}
