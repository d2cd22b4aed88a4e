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
}
