//! Asperity (summit) detection, exactly as physics.md §5 defines it.
//!
//! A summit is a grid point strictly higher than its 8 neighbours. On a periodic
//! surface the neighbourhood wraps around; on a non-periodic one the border rows and
//! columns (which lack neighbours) are never summits. Its curvature is
//!
//! ```text
//!   κ = −(z_xx + z_yy)/2,  z_xx = (z[i+1,j] − 2z[i,j] + z[i−1,j])/dx²,
//!                          z_yy = (z[i,j+1] − 2z[i,j] + z[i,j−1])/dy²   (1/m)
//! ```
//!
//! by central differences, each on its own axis' pixel size (dx along the first array
//! axis, dy along the second; rectangular pixels and grids are fine), and its radius
//! R = 1/κ (m). The summit sits at (x, y) = (i·dx, j·dy). Summits with κ ≤ 0 (possible
//! only on a saddle-like strict maximum) are dropped and counted.

use crate::surface::Surface;

/// One asperity: position (m), height (m), radius of curvature (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summit {
    /// Grid indices (i along x, j along y).
    pub index: (usize, usize),
    /// x = i·dx (m).
    pub x: f64,
    /// y = j·dy (m).
    pub y: f64,
    /// Height z (m).
    pub z: f64,
    /// Radius of curvature R = 1/κ (m), > 0.
    pub radius: f64,
}

/// The summits of a surface and how many strict maxima were dropped for κ ≤ 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Summits {
    pub summits: Vec<Summit>,
    pub dropped_nonpositive_curvature: usize,
}

/// Finds the summits of `s` (physics.md §5), in row-major grid order.
pub fn find_summits(s: &Surface) -> Summits {
    let (n0, n1) = s.shape();
    let (dx, dy) = s.pixel_size();
    let periodic = s.is_periodic();
    let mut out = Vec::new();
    let mut dropped = 0;
    let (i_range, j_range) = if periodic {
        (0..n0, 0..n1)
    } else {
        (1..n0 - 1, 1..n1 - 1)
    };
    for i in i_range {
        let im = (i + n0 - 1) % n0;
        let ip = (i + 1) % n0;
        for j in j_range.clone() {
            let jm = (j + n1 - 1) % n1;
            let jp = (j + 1) % n1;
            let z = s.z(i, j);
            let mut is_max = true;
            'n: for &a in &[im, i, ip] {
                for &b in &[jm, j, jp] {
                    if (a, b) != (i, j) && s.z(a, b) >= z {
                        is_max = false;
                        break 'n;
                    }
                }
            }
            if !is_max {
                continue;
            }
            let zxx = (s.z(ip, j) - 2.0 * z + s.z(im, j)) / (dx * dx);
            let zyy = (s.z(i, jp) - 2.0 * z + s.z(i, jm)) / (dy * dy);
            let kappa = -(zxx + zyy) / 2.0;
            if kappa.is_nan() || kappa <= 0.0 {
                dropped += 1;
                continue;
            }
            out.push(Summit {
                index: (i, j),
                x: i as f64 * dx,
                y: j as f64 * dy,
                z,
                radius: 1.0 / kappa,
            });
        }
    }
    Summits {
        summits: out,
        dropped_nonpositive_curvature: dropped,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A single paraboloid bump z = −(x²+y²)/(2R) sampled on a grid: one summit at
    /// its apex with the exact radius (central differences are exact on quadratics).
    #[test]
    fn paraboloid_bump() {
        let n = 33;
        let d = 1e-6;
        let r = 2e-4;
        let z: Vec<f64> = (0..n * n)
            .map(|k| {
                let (i, j) = ((k / n) as f64 - 16.0, (k % n) as f64 - 16.0);
                -((i * d).powi(2) + (j * d).powi(2)) / (2.0 * r)
            })
            .collect();
        let s = Surface::new(z, n, n, n as f64 * d, false).unwrap();
        let f = find_summits(&s);
        assert_eq!(f.summits.len(), 1);
        let sm = f.summits[0];
        assert_eq!(sm.index, (16, 16));
        assert!((sm.radius - r).abs() < 1e-9 * r);
    }

    /// A rectangular grid (n0 ≠ n1) with rectangular pixels (dx ≠ dy), non-periodic and
    /// periodic: the summits and radii equal a direct computation written out here
    /// (strict 8-neighbour maxima, κ = −(z_xx/dx² + z_yy/dy²)/2 with the raw second
    /// differences); an elliptic paraboloid z = −x²/(2R_x) − y²/(2R_y) sampled on it
    /// has its apex curvature (1/R_x + 1/R_y)/2 exactly.
    #[test]
    fn rectangular_grid_direct() {
        use crate::surface::Spacing;
        let (n0, n1, dx, dy) = (41usize, 23usize, 1.1e-6, 2.7e-6);
        let z: Vec<f64> = (0..n0 * n1)
            .map(|k| {
                let (i, j) = ((k / n1) as f64, (k % n1) as f64);
                1e-6 * ((0.9 * i).sin() * (1.3 * j).cos() + 0.3 * (0.41 * i + 0.77 * j).sin())
            })
            .collect();
        for periodic in [false, true] {
            let s =
                Surface::with_spacing(z.clone(), n0, n1, Spacing::Pixel(dx, dy), periodic).unwrap();
            let at = |i: isize, j: isize| {
                z[(i.rem_euclid(n0 as isize) as usize) * n1 + j.rem_euclid(n1 as isize) as usize]
            };
            let mut expect = Vec::new();
            for i in 0..n0 as isize {
                for j in 0..n1 as isize {
                    let inner = i > 0 && j > 0 && i < n0 as isize - 1 && j < n1 as isize - 1;
                    if !periodic && !inner {
                        continue;
                    }
                    let c = at(i, j);
                    let mut max = true;
                    for di in -1..=1 {
                        for dj in -1..=1 {
                            if (di, dj) != (0, 0) && at(i + di, j + dj) >= c {
                                max = false;
                            }
                        }
                    }
                    let k = -((at(i + 1, j) - 2.0 * c + at(i - 1, j)) / (dx * dx)
                        + (at(i, j + 1) - 2.0 * c + at(i, j - 1)) / (dy * dy))
                        / 2.0;
                    if max && k > 0.0 {
                        expect.push((
                            i as usize,
                            j as usize,
                            i as f64 * dx,
                            j as f64 * dy,
                            1.0 / k,
                        ));
                    }
                }
            }
            let got = find_summits(&s);
            assert!(expect.len() > 10, "{}", expect.len());
            assert_eq!(got.summits.len(), expect.len());
            for (g, e) in got.summits.iter().zip(&expect) {
                assert_eq!(g.index, (e.0, e.1));
                assert_eq!((g.x, g.y), (e.2, e.3));
                assert!((g.radius - e.4).abs() <= 1e-14 * e.4, "{g:?} {e:?}");
            }
        }
        let (rx, ry) = (2e-4, 7e-5);
        let z: Vec<f64> = (0..n0 * n1)
            .map(|k| {
                let x = ((k / n1) as f64 - 20.0) * dx;
                let y = ((k % n1) as f64 - 11.0) * dy;
                -x * x / (2.0 * rx) - y * y / (2.0 * ry)
            })
            .collect();
        let s = Surface::with_spacing(z, n0, n1, Spacing::Pixel(dx, dy), false).unwrap();
        let f = find_summits(&s);
        assert_eq!(f.summits.len(), 1);
        assert_eq!(f.summits[0].index, (20, 11));
        let r = 2.0 / (1.0 / rx + 1.0 / ry);
        assert!((f.summits[0].radius - r).abs() < 1e-9 * r);
    }

    /// Plateaus (equal neighbours) are not strict maxima; wrap-around matters on a
    /// periodic surface only.
    #[test]
    fn strictness_and_wrap() {
        let mut z = vec![0.0; 25];
        z[0] = 1.0; // corner: a summit only with wrap
        z[12] = 2.0;
        z[13] = 2.0; // plateau: no summit
        let p = Surface::new(z.clone(), 5, 5, 1.0, true).unwrap();
        let f = find_summits(&p);
        assert_eq!(f.summits.len(), 1);
        assert_eq!(f.summits[0].index, (0, 0));
        let np = Surface::new(z, 5, 5, 1.0, false).unwrap();
        assert!(find_summits(&np).summits.is_empty());
    }

    /// The shared reference: summits of surface_km10.npy equal summits_km10.csv
    /// (positions exact, z and R to 1e-9 relative), none dropped there.
    #[test]
    fn reference_summits_km10() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/reference");
        let p = dir.join("surface_km10.npy");
        let s =
            Surface::read_npy(&p, 1e-3, true).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let text = std::fs::read_to_string(dir.join("summits_km10.csv")).unwrap();
        let mut expect: Vec<[f64; 4]> = text
            .lines()
            .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
            .map(|l| {
                let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
                [v[0], v[1], v[2], v[3]]
            })
            .collect();
        let found = find_summits(&s);
        assert_eq!(found.summits.len(), expect.len());
        let mut got: Vec<[f64; 4]> = found
            .summits
            .iter()
            .map(|m| [m.x, m.y, m.z, m.radius])
            .collect();
        let key = |v: &[f64; 4]| (v[0].to_bits(), v[1].to_bits());
        got.sort_by_key(key);
        expect.sort_by_key(key);
        for (g, e) in got.iter().zip(&expect) {
            // exact positions: grid multiples of L/n printed with 11 digits
            assert!(
                (g[0] - e[0]).abs() < 1e-15 && (g[1] - e[1]).abs() < 1e-15,
                "{g:?} {e:?}"
            );
            assert!((g[2] - e[2]).abs() <= 1e-9 * e[2].abs(), "{g:?} {e:?}");
            assert!((g[3] - e[3]).abs() <= 1e-9 * e[3], "{g:?} {e:?}");
        }
    }
}
