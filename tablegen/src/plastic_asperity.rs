//! One paraboloidal asperity with an elastic–perfectly plastic tip on a layered solid
//! (issue 35, physics.md §6.3): the contact pressure is capped by the hardness H, so a
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
//! with the ring areas) is solved by MPRGP ([`strata_runtime::bounded`]). Outputs: the
//! load P = Σ p_j A_j, the contact radius a (the outer edge of the last loaded ring,
//! refined by the linear zero of p) and the plastic radius a_p (the outer edge of the
//! last ring at H).
//!
//! Checks (tests): H → ∞ is the elastic asperity (Hertz on a half-space; the
//! Abel–Fredholm solution on a layered stack) to the rings' discretisation error; no
//! plasticity below the Hertz yield onset δ_c = (πH/2E*)² R on a half-space and a
//! plastic core above it; P ≤ Hπa² always and P/(Hπa²) → 1 as δ grows; the 3-D BEM
//! of one capped paraboloid converges to it with the grid.

use strata_runtime::Stack;
use strata_runtime::bounded::{BoundedError, Mprgp, norm_estimate};
use thiserror::Error;

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
    stack: Stack,
    e_star: f64,
    hardness: f64,
    /// Rings (default 400).
    pub rings: usize,
}

impl PlasticAsperity {
    /// The capped asperity on `stack` (with its counterface, if any) with hardness
    /// `hardness` (Pa, > 0; `f64::INFINITY` for the elastic asperity).
    pub fn new(stack: &Stack, hardness: f64) -> Result<Self, PlasticAsperityError> {
        if hardness.is_nan() || hardness <= 0.0 {
            return Err(PlasticAsperityError::Invalid {
                name: "hardness",
                value: hardness,
                reason: "must be > 0 Pa",
            });
        }
        Ok(PlasticAsperity {
            stack: stack.clone(),
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
            let comp = strata_runtime::Compliance::new(&self.stack);
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
pub const RESPONSE_X: (f64, f64, usize) = (1e-2, 1e2, 25);
/// See [`RESPONSE_X`].
pub const RESPONSE_Y: (f64, f64, usize) = (1e-3, 3.0, 11);

/// The capped asperity's response table of `stack` and `hardness` for the N model
/// (`strata_runtime::rough::plastic`): F = P/P_c, G = a/a_c and Φ = a_p/a at every
/// node (x, y), each from one ring solve (in parallel).
pub fn response(
    stack: &Stack,
    hardness: f64,
) -> Result<strata_runtime::rough::plastic::PlasticResponse, PlasticAsperityError> {
    use strata_runtime::rough::plastic::{LogAxis, PlasticResponse};
    let mut solver = PlasticAsperity::new(stack, hardness)?;
    solver.rings = 200;
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

    /// H = ∞ on the paper's layered stack (and against a steel counterface) is the
    /// Abel–Fredholm asperity (`asperity::Asperity`, a second method) to the rings'
    /// discretisation error.
    #[test]
    fn infinite_hardness_is_the_fredholm_asperity() {
        let paper = Stack::paper_two_layer(5.0).unwrap();
        let pair = paper
            .clone()
            .against(Stack::half_space(210e9, 0.3).unwrap())
            .unwrap();
        let mut worst: f64 = 0.0;
        for st in [paper, pair] {
            let full =
                crate::asperity::Asperity::new(&st, crate::asperity::Options::default()).unwrap();
            let s = PlasticAsperity::new(&st, f64::INFINITY).unwrap();
            for d in [1e-8, 1e-6, 2e-5] {
                let (x, y) = (
                    s.at_delta(d, 1e-4).unwrap(),
                    full.paraboloid_at_delta(d, 1e-4).unwrap(),
                );
                worst = worst.max(rel(x.force, y.force));
            }
        }
        eprintln!("rings (400) vs Fredholm, layered: worst {worst:.1e}");
        assert!(worst < 3e-5, "{worst:e}");
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
}
