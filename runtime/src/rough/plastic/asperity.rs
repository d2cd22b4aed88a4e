//! One paraboloidal asperity with an elastic–perfectly plastic tip on a layered solid
//! (physics.md §6.3): the contact pressure is capped by the hardness H, so a
//! plastic core r < a_p carries p = H (its elastic overlap flattened) around which an
//! elastic annulus a_p < r < a conforms to the paraboloid.
//!
//! With a rigid paraboloid of radius R at interference δ, the pressure p(r) minimises
//!
//! ```text
//!   ½ ∫ p u dA − ∫ p (δ − r²/2R) dA      over 0 ≤ p ≤ H,
//! ```
//!
//! u = the layered solid's surface displacement. p is piecewise constant on N rings
//! on [0, √(2Rδ)] (the geometric intersection radius bounds the contact), u from the
//! ring influence matrix of [`crate::rings`] (Boussinesq's disc in closed form plus the
//! Hankel integral of k_z), and the box-constrained quadratic programme (symmetrised
//! with the ring areas) is solved by MPRGP ([`crate::bounded`]). Outputs: the
//! load P = Σ p_j A_j, the contact radius a (the outer edge of the last loaded ring,
//! refined by the linear zero of p) and the plastic radius a_p (the outer edge of the
//! last ring at H).
//!
//! Checks (tests): H → ∞ is the elastic asperity (Hertz on a half-space; the
//! Abel–Fredholm solution on a layered stack, tested in `strata-tablegen` where that
//! solver lives) to the rings' discretisation error; no
//! plasticity below the Hertz yield onset δ_c = (πH/2E*)² R on a half-space and a
//! plastic core above it; P ≤ Hπa² always and P/(Hπa²) → 1 as δ grows; the 3-D BEM
//! of one capped paraboloid converges to it with the grid.

use std::path::{Path, PathBuf};

use thiserror::Error;

#[cfg(test)]
use crate::Stack;
use crate::bounded::{BoundedError, Mprgp, norm_estimate};
use crate::hash::Fnv1a;
use crate::rough::plastic::PlasticResponse;
use crate::{Bodies, Solid};

/// Errors of the capped asperity.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum PlasticAsperityError {
    #[error("{name} = {value:e} is invalid: {reason}")]
    Invalid {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error("capped asperity: {0}")]
    Bounded(String),
}

/// The capped asperity's solution at one interference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlasticContact {
    /// Interference δ (m).
    pub delta: f64,
    /// Contact radius a (m).
    pub a: f64,
    /// Radius of the plastic core a_p (m), 0 when the contact is elastic.
    pub a_plastic: f64,
    /// Load P (N).
    pub force: f64,
    /// MPRGP iterations.
    pub iterations: usize,
}

/// The solver for one stack and hardness.
#[derive(Debug, Clone)]
pub struct PlasticAsperity {
    stack: Bodies,
    e_star: f64,
    hardness: f64,
    /// Rings (default 400).
    pub rings: usize,
}

impl PlasticAsperity {
    /// The capped asperity on `stack` (with its counterface, if any) with hardness
    /// `hardness` (Pa, > 0; `f64::INFINITY` for the elastic asperity).
    pub fn new<S: Solid + ?Sized>(stack: &S, hardness: f64) -> Result<Self, PlasticAsperityError> {
        if hardness.is_nan() || hardness <= 0.0 {
            return Err(PlasticAsperityError::Invalid {
                name: "hardness",
                value: hardness,
                reason: "must be > 0 Pa",
            });
        }
        Ok(PlasticAsperity {
            stack: stack.bodies(),
            e_star: stack.contact_modulus(),
            hardness,
            rings: 400,
        })
    }

    /// The solution for a paraboloid of radius `radius` (m) at interference `delta` (m).
    pub fn at_delta(
        &self,
        delta: f64,
        radius: f64,
    ) -> Result<PlasticContact, PlasticAsperityError> {
        for (name, value) in [("delta", delta), ("radius", radius)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(PlasticAsperityError::Invalid {
                    name,
                    value,
                    reason: "must be finite and > 0 m",
                });
            }
        }
        let n = self.rings.max(8);
        let r_max = (2.0 * radius * delta).sqrt();
        let edges: Vec<f64> = (0..=n).map(|j| r_max * j as f64 / n as f64).collect();
        let mids: Vec<f64> = (0..n)
            .map(|j| r_max * (j as f64 + 0.5) / n as f64)
            .collect();
        let area: Vec<f64> = (0..n)
            .map(|j| std::f64::consts::PI * (edges[j + 1].powi(2) - edges[j].powi(2)))
            .collect();
        let m = if self.stack.is_homogeneous() {
            crate::rings::ring_matrix(&edges, &mids, None, 1.0)
        } else {
            let comp = crate::Compliance::new(&self.stack);
            let h = self.stack.top_thickness().unwrap_or(r_max);
            let k = move |u: f64| comp.kz(u);
            crate::rings::ring_matrix(&edges, &mids, Some(&k), h)
        };
        // u = (2/E*) M p; the energy's Hessian A_ij = ½(A_i M_ij + A_j M_ji)·2/E*,
        // its linear term A_i (δ − r_i²/2R).
        let scale = 2.0 / self.e_star;
        let a: Vec<f64> = (0..n * n)
            .map(|ij| {
                let (i, j) = (ij / n, ij % n);
                0.5 * scale * (area[i] * m[i * n + j] + area[j] * m[j * n + i])
            })
            .collect();
        let b: Vec<f64> = (0..n)
            .map(|i| area[i] * (delta - mids[i] * mids[i] / (2.0 * radius)))
            .collect();
        let mut apply = |x: &[f64], y: &mut [f64]| -> Result<(), String> {
            for i in 0..n {
                y[i] = a[i * n..(i + 1) * n]
                    .iter()
                    .zip(x)
                    .map(|(p, q)| p * q)
                    .sum();
            }
            Ok(())
        };
        let bad = |e: BoundedError<String>| PlasticAsperityError::Bounded(e.to_string());
        let norm = norm_estimate(&mut apply, n).map_err(bad)?;
        let area_max = area.iter().fold(0.0_f64, |x, y| x.max(*y));
        let solver = Mprgp {
            upper: self.hardness,
            alpha: 1.0 / norm,
            // KKT violation in units of A_i·m: 1e-13 of the interference on the
            // largest ring
            tol: 1e-13 * delta * area_max,
            max_iterations: 200_000,
            refresh: 50,
        };
        let (mut p, mut g) = (vec![0.0; n], vec![0.0; n]);
        let out = solver.solve(&mut apply, &b, &mut p, &mut g).map_err(bad)?;
        let force: f64 = p.iter().zip(&area).map(|(x, y)| x * y).sum();
        let last = p.iter().rposition(|&x| x > 0.0);
        let a_c = match last {
            None => 0.0,
            // the linear zero of p beyond the last loaded ring's mid-radius
            Some(j) if j > 0 && p[j - 1] > p[j] => {
                let slope = (p[j - 1] - p[j]) / (mids[j] - mids[j - 1]);
                (mids[j] + p[j] / slope).min(edges[j + 1])
            }
            Some(j) => edges[j + 1],
        };
        let a_plastic = p
            .iter()
            .rposition(|&x| x >= self.hardness)
            .map_or(0.0, |j| edges[j + 1]);
        Ok(PlasticContact {
            delta,
            a: a_c,
            a_plastic,
            force,
            iterations: out.iterations,
        })
    }
}

/// The response table's axes: x = δ/δ_c from 1e-2 to 1e2 (6 nodes per decade), y =
/// a_c/h₁ from 1e-3 to 3 (3 per decade; one node on a homogeneous solid), 200 rings
/// per node. The rings' ρ-rule grows like a/h₁ (panels of 1/a up to 25/h₁), which
/// bounds y: summits of R ≲ 100 µm with H/E* ≲ 0.1 on layers h₁ ≳ 3 µm lie inside.
pub(crate) const RESPONSE_X: (f64, f64, usize) = (1e-2, 1e2, 25);
/// See `RESPONSE_X`.
pub const RESPONSE_Y: (f64, f64, usize) = (1e-3, 3.0, 11);
/// Rings of each node's solve of the response table (see `RESPONSE_X`).
pub(crate) const RESPONSE_RINGS: usize = 200;

/// The capped asperity's response table of `stack` and `hardness` for the N model
/// ([`super`]): F = P/P_c, G = a/a_c and Φ = a_p/a at every
/// node (x, y), each from one ring solve (in parallel).
pub fn response<S: Solid + ?Sized>(
    stack: &S,
    hardness: f64,
) -> Result<PlasticResponse, PlasticAsperityError> {
    use crate::rough::plastic::LogAxis;
    let mut solver = PlasticAsperity::new(stack, hardness)?;
    solver.rings = RESPONSE_RINGS;
    let e = solver.e_star;
    let h1 = if stack.is_homogeneous() {
        None
    } else {
        stack.top_thickness()
    };
    let x = LogAxis {
        lo: RESPONSE_X.0.ln(),
        hi: RESPONSE_X.1.ln(),
        n: RESPONSE_X.2,
    };
    let y = match h1 {
        None => LogAxis {
            lo: 0.0,
            hi: 0.0,
            n: 1,
        },
        Some(_) => LogAxis {
            lo: RESPONSE_Y.0.ln(),
            hi: RESPONSE_Y.1.ln(),
            n: RESPONSE_Y.2,
        },
    };
    let nodes: Vec<(usize, usize)> = (0..y.n)
        .flat_map(|j| (0..x.n).map(move |i| (i, j)))
        .collect();
    use rayon::prelude::*;
    let values: Vec<Result<(f64, f64, f64), PlasticAsperityError>> = nodes
        .par_iter()
        .map(|&(i, j)| {
            // R with a_c = y h₁ (any R on a homogeneous solid), δ = x δ_c
            // a half-space is Hertz up to the yield onset x = 1, exactly
            if h1.is_none() && x.node(i) <= 0.0 {
                return Ok((1.5 * x.node(i), 0.5 * x.node(i), 0.0));
            }
            let ac = h1.map_or(1e-6, |h| y.node(j).exp() * h);
            let radius = 2.0 * e * ac / (std::f64::consts::PI * hardness);
            let dc = ac * ac / radius;
            let pc = 4.0 / 3.0 * e * ac.powi(3) / radius;
            let c = solver.at_delta(x.node(i).exp() * dc, radius)?;
            let phi = if c.a > 0.0 { c.a_plastic / c.a } else { 0.0 };
            Ok(((c.force / pc).ln(), (c.a / ac).ln(), phi))
        })
        .collect();
    let mut out = PlasticResponse {
        e_star: e,
        hardness,
        h1,
        x,
        y,
        ln_f: Vec::with_capacity(nodes.len()),
        ln_g: Vec::with_capacity(nodes.len()),
        phi: Vec::with_capacity(nodes.len()),
    };
    for v in values {
        let (f, g, p) = v?;
        out.ln_f.push(f);
        out.ln_g.push(g);
        out.phi.push(p);
    }
    Ok(out)
}

/// The key of `stack`'s response table at `hardness`: FNV-1a 64 over the exact bits of
/// everything [`response`] reads — every layer's thickness, Young modulus and Poisson
/// ratio, the base, the counterface's likewise (in the order given), the hardness and
/// the table's grid (`RESPONSE_X`, [`RESPONSE_Y`], `RESPONSE_RINGS`). Unlike the
/// mechanics tables' nondimensional fingerprint, nothing is scaled: a cached table is
/// the one [`response`] would build, bit for bit. The stack's name and conduction
/// properties do not enter.
pub(crate) fn response_key<S: Solid + ?Sized>(stack: &S, hardness: f64) -> u64 {
    let mut h = Fnv1a::default();
    h.part(b"strata capped asperity response");
    let mut eat = |v: f64| {
        h.update(&v.to_le_bytes());
    };
    for v in [RESPONSE_X.0, RESPONSE_X.1, RESPONSE_Y.0, RESPONSE_Y.1] {
        eat(v);
    }
    for n in [RESPONSE_X.2, RESPONSE_Y.2, RESPONSE_RINGS] {
        eat(n as f64);
    }
    eat(hardness);
    let bodies = std::iter::once(stack.first()).chain(stack.elastic_counterface());
    for (i, body) in bodies.enumerate() {
        // a separator that no value hashes as: NaN for the counterface, −2 for a body
        eat(if i > 0 { f64::NAN } else { -2.0 });
        eat(body.layers().len() as f64);
        for l in body.layers() {
            eat(l.thickness);
            eat(l.young);
            eat(l.poisson);
        }
        match body.base() {
            crate::Base::Rigid => eat(-1.0),
            crate::Base::Elastic { young, poisson } => {
                eat(young);
                eat(poisson);
            }
        }
    }
    h.finish()
}

/// The file of `stack`'s response table at `hardness` in the cache directory `dir`:
/// `capped-<key>.strata` (`response_key`), beside the mechanics tables'
/// `stack-<hex>.strata` and the ψ tables' `psi-<hex>.strata`.
pub(crate) fn response_cache_path<S: Solid + ?Sized>(
    stack: &S,
    hardness: f64,
    dir: &Path,
) -> PathBuf {
    dir.join(format!(
        "capped-{:016x}.strata",
        response_key(stack, hardness)
    ))
}

/// What [`cached_response`] did with the cache file.
#[derive(Debug, Clone, PartialEq)]
pub enum ResponseCacheUse {
    /// The table was read from the file (the path).
    Read(PathBuf),
    /// The table was built (no file, or an unreadable, damaged or foreign one) and
    /// written to the file (the path).
    Written(PathBuf),
    /// The table was built but the file could not be written (the message): the
    /// table is used all the same.
    NotWritten(String),
}

/// `stack`'s response table at `hardness` from the cache directory `dir`: read from
/// `response_cache_path` when that file holds a valid table of this key, stack and
/// hardness; else built by [`response`] and written atomically (a temporary file of
/// its own, renamed). A damaged or foreign file is rebuilt; a directory that cannot be
/// written costs only the file ([`ResponseCacheUse::NotWritten`]). The table is that of
/// [`response`] bit for bit, cached or not.
pub fn cached_response<S: Solid + ?Sized>(
    stack: &S,
    hardness: f64,
    dir: &Path,
) -> Result<(PlasticResponse, ResponseCacheUse), PlasticAsperityError> {
    let key = response_key(stack, hardness);
    let path = response_cache_path(stack, hardness, dir);
    let h1 = (!stack.is_homogeneous())
        .then(|| stack.top_thickness())
        .flatten();
    let same = |r: &PlasticResponse| {
        r.e_star.to_bits() == stack.contact_modulus().to_bits()
            && r.hardness.to_bits() == hardness.to_bits()
            && r.h1.map(f64::to_bits) == h1.map(f64::to_bits)
    };
    // a file larger than the machine's memory limit counts as damaged (rebuilt)
    let memory = crate::resources::MemoryLimit::of_machine();
    let held = crate::resources::read_data_file(&path, "a cache file", &memory)
        .ok()
        .and_then(|b| PlasticResponse::from_bytes(&b).ok())
        .filter(|(k, r)| *k == key && same(r));
    if let Some((_, r)) = held {
        return Ok((r, ResponseCacheUse::Read(path)));
    }
    let table = response(stack, hardness)?;
    let written = std::fs::create_dir_all(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))
        .and_then(|()| {
            // (the error names the path)
            crate::output::write_atomic(&path, &table.to_bytes(key)).map_err(|e| e.to_string())
        });
    let used = match written {
        Ok(()) => ResponseCacheUse::Written(path),
        Err(e) => ResponseCacheUse::NotWritten(e),
    };
    Ok((table, used))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / a.abs().max(b.abs())
    }

    /// H = ∞ on a half-space is Hertz: P = (4/3) E* √R δ^{3/2}, a = √(Rδ).
    #[test]
    fn infinite_hardness_is_hertz() {
        let st = Stack::half_space(210e9, 0.3).unwrap();
        let e = st.contact_modulus();
        let s = PlasticAsperity::new(&st, f64::INFINITY).unwrap();
        let (r, mut worst, mut worst_a) = (1e-4, 0.0_f64, 0.0_f64);
        for d in [1e-9, 1e-7, 1e-5] {
            let c = s.at_delta(d, r).unwrap();
            let hertz = 4.0 / 3.0 * e * r.sqrt() * d.powf(1.5);
            worst = worst.max(rel(c.force, hertz));
            worst_a = worst_a.max(rel(c.a, (r * d).sqrt()));
            assert_eq!(c.a_plastic, 0.0);
        }
        eprintln!("rings (400) vs Hertz: worst {worst:.1e}, contact radius {worst_a:.1e}");
        assert!(worst < 3e-5, "{worst:e}");
        assert!(worst_a < 5e-3, "{worst_a:e}");
    }

    /// Below the Hertz yield onset δ_c = (πH/2E*)² R: elastic; above: a plastic core;
    /// P ≤ Hπa² and P/(Hπa²) grows towards 1.
    #[test]
    fn yield_onset_and_full_plasticity() {
        let st = Stack::half_space(4e9, 0.15).unwrap();
        let e = st.contact_modulus();
        let h = 0.2e9;
        let r = 1e-4;
        let s = PlasticAsperity::new(&st, h).unwrap();
        let dc = (std::f64::consts::PI * h / (2.0 * e)).powi(2) * r;
        let below = s.at_delta(0.8 * dc, r).unwrap();
        assert_eq!(below.a_plastic, 0.0);
        let mut last = 0.0;
        for f in [2.0, 10.0, 100.0, 1000.0] {
            let c = s.at_delta(f * dc, r).unwrap();
            assert!(c.a_plastic > 0.0, "δ = {f} δ_c");
            let ratio = c.force / (h * std::f64::consts::PI * c.a * c.a);
            eprintln!(
                "δ = {f} δ_c: a_p/a {:.3}, P/(Hπa²) {ratio:.4}",
                c.a_plastic / c.a
            );
            assert!(ratio <= 1.0 + 1e-12 && ratio >= last - 1e-12, "{ratio}");
            last = ratio;
        }
        assert!(last > 0.999, "{last}");
    }

    /// The response table against direct ring solves at points between its nodes
    /// (homogeneous and the paper's layered stack): the N model's interpolation error.
    #[test]
    fn response_table_interpolates_the_rings() {
        let h = 0.2e9;
        let mut worst: f64 = 0.0;
        for st in [
            Stack::half_space(4e9, 0.15).unwrap(),
            Stack::paper_two_layer(5.0).unwrap(),
        ] {
            let table = response(&st, h).unwrap();
            let s = PlasticAsperity::new(&st, h).unwrap();
            let e = st.contact_modulus();
            for (radius, x) in [(2e-5, 0.37), (5e-5, 3.3), (1e-4, 17.0), (3e-5, 55.0)] {
                let ac = std::f64::consts::PI * h * radius / (2.0 * e);
                let delta = x * ac * ac / radius;
                let (t, d) = (table.at(delta, radius), s.at_delta(delta, radius).unwrap());
                worst = worst.max(rel(t.force, d.force)).max(rel(t.a, d.a));
            }
        }
        eprintln!("response table vs rings: worst {worst:.1e}");
        assert!(worst < 2.5e-2, "{worst:e}");
    }

    /// The cache gives the bits of a direct build: written, then read; a damaged file
    /// rebuilt; an unwritable directory costs only the file; no temporary file left.
    #[test]
    fn cached_response_equals_a_direct_build() {
        // a homogeneous pair (cheap: one y node, Hertz below the yield onset)
        let st = Stack::half_space(4e9, 0.15)
            .unwrap()
            .against(Stack::half_space(210e9, 0.3).unwrap());
        let h = 0.2e9;
        let direct = response(&st, h).unwrap();
        let dir = std::env::temp_dir().join(format!("strata-capped-cache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let path = response_cache_path(&st, h, &dir);
        assert!(
            path.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("capped-")
        );
        let (t, u) = cached_response(&st, h, &dir).unwrap();
        assert_eq!((&t, u), (&direct, ResponseCacheUse::Written(path.clone())));
        let (t, u) = cached_response(&st, h, &dir).unwrap();
        assert_eq!((&t, u), (&direct, ResponseCacheUse::Read(path.clone())));
        // bit for bit, not merely ==: the file holds the same bits
        let bits = |r: &PlasticResponse| -> Vec<u64> {
            r.ln_f
                .iter()
                .chain(&r.ln_g)
                .chain(&r.phi)
                .map(|v| v.to_bits())
                .collect()
        };
        assert_eq!(bits(&t), bits(&direct));
        // another hardness is another file
        assert_ne!(response_cache_path(&st, 0.3e9, &dir), path);
        // a damaged file is rebuilt (and written again)
        let mut bytes = std::fs::read(&path).unwrap();
        let mid = bytes.len() / 2;
        bytes[mid] ^= 0x10;
        std::fs::write(&path, &bytes).unwrap();
        let (t, u) = cached_response(&st, h, &dir).unwrap();
        assert_eq!((&t, u), (&direct, ResponseCacheUse::Written(path.clone())));
        std::fs::write(&path, &bytes[..100]).unwrap();
        let (t, u) = cached_response(&st, h, &dir).unwrap();
        assert_eq!((&t, u), (&direct, ResponseCacheUse::Written(path.clone())));
        // a valid file of another key under this name is not used
        let other = response(&Stack::half_space(4e9, 0.15).unwrap(), h).unwrap();
        std::fs::write(&path, other.to_bytes(response_key(&st, h) ^ 1)).unwrap();
        let (t, u) = cached_response(&st, h, &dir).unwrap();
        assert_eq!((&t, u), (&direct, ResponseCacheUse::Written(path.clone())));
        // a plain file where the directory should be: nothing written, same table
        let blocked = dir.join("plain-file");
        std::fs::write(&blocked, b"x").unwrap();
        let (t, u) = cached_response(&st, h, &blocked.join("sub")).unwrap();
        assert_eq!(t, direct);
        assert!(matches!(u, ResponseCacheUse::NotWritten(_)), "{u:?}");
        assert_eq!(std::fs::read(&blocked).unwrap(), b"x");
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        let file = path.file_name().unwrap().to_string_lossy().into_owned();
        assert_eq!(names, [file, "plain-file".to_string()]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The key changes with every input of the table (each layer's thickness, modulus
    /// and Poisson ratio, the base, the counterface, the hardness) and with no other.
    #[test]
    fn response_key_covers_the_stack_and_hardness() {
        use crate::stack::{Base, Layer};
        let layer = |thickness, young, poisson| Layer {
            thickness,
            young,
            poisson,
        };
        let make = |l: Vec<Layer>, b: Base| Stack::new(l, b).unwrap();
        let base = Base::Elastic {
            young: 2e11,
            poisson: 0.3,
        };
        let two = |h2: f64, e2: f64, nu2: f64| {
            make(vec![layer(5e-6, 1e9, 0.3), layer(h2, e2, nu2)], base)
        };
        let st = two(1e-5, 3e9, 0.35);
        let k = response_key(&st, 1e8);
        let steel = Stack::half_space(2.1e11, 0.3).unwrap();
        let variants = [
            response_key(&st, 1.0000001e8),
            response_key(&two(1.0000001e-5, 3e9, 0.35), 1e8),
            response_key(&two(1e-5, 3.0000001e9, 0.35), 1e8),
            response_key(&two(1e-5, 3e9, 0.3500001), 1e8),
            response_key(
                &make(
                    vec![layer(5e-6, 1e9, 0.3), layer(1e-5, 3e9, 0.35)],
                    Base::Rigid,
                ),
                1e8,
            ),
            response_key(
                &make(
                    vec![layer(5e-6, 1e9, 0.3), layer(1e-5, 3e9, 0.35)],
                    Base::Elastic {
                        young: 2e11,
                        poisson: 0.31,
                    },
                ),
                1e8,
            ),
            response_key(&st.clone().against(steel.clone()), 1e8),
            response_key(
                &st.clone().against(Stack::half_space(2.1e11, 0.29).unwrap()),
                1e8,
            ),
            response_key(&steel.clone().against(st.clone()), 1e8),
        ];
        for (i, v) in variants.iter().enumerate() {
            assert_ne!(*v, k, "variant {i}");
        }
        let named = st.clone().with_name("x");
        assert_eq!(response_key(&named, 1e8), k);
        use crate::stack::{BaseConduction, Conductivity};
        let k1 = Conductivity::thermal;
        let conducting = named
            .with_conduction(vec![k1(0.3), k1(20.0)], k1(50.0), BaseConduction::HalfSpace)
            .unwrap();
        assert_eq!(response_key(&conducting, 1e8), k);
    }
}
