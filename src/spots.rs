//! The N and I models' interface conductance (issue 34, physics.md §6.2): the contact spots
//! conduct independently,
//!
//! ```text
//!   h_c = Σᵢ G(aᵢ) / A₀,   1/G(a) = 1/G_A(a) + 1/G_B(a),   G_X(a) = 4 k₁,X a ψ_X(a),
//! ```
//!
//! aᵢ the contact radii of the step's summits (m), A₀ the nominal area (m²); h_c in
//! W/(m²·K) (thermal) or S/m² (electrical). Each spot is an isothermal disc on each body,
//! the two bodies in series (a perfect conductor: 1/G_B = 0; a conducting rigid flat: a
//! homogeneous half-space, G_B = 4k_B a). ψ ≡ 1 on a homogeneous body; on a layered one it
//! comes from the Fredholm spot solver ([`strata_tablegen::spot`]), computed at 8 nodes
//! per decade of a over the step radii's range (Chebyshev–Lobatto nodes of pieces of at
//! most a decade, solved by Nyström with [`nystrom_nodes`] up to a/h₁ = 4) and
//! interpolated by the pieces' polynomials in ln a (measured against direct solves in
//! the tests: ≤ 1.2e−6).
//!
//! The I model ([`SpotSum::interacting`]) adds the spots' thermal interactions: the same
//! G(aᵢ) on the diagonal of the spot network of [`strata_runtime::rough::conductance`],
//! Σ_j (δ_ij/G_i + I_ij) Q_j = ΔT, h_c = Σ Q_i/(ΔT A₀), the interactions I_ij of every
//! summit that touches at some step filled once for the whole path
//! ([`Interactions`]: the same h_c as filling each step's network afresh, bit for bit).

use anyhow::{Context, Result};
use rayon::prelude::*;
use strata_runtime::rough::conductance::{Body, Interactions, Kernel, KernelInfo};
use strata_runtime::rough::{Images, Step};
use strata_runtime::summits::Summit;
use strata_tablegen::asperity::Method;
use strata_tablegen::fredholm::Discretisation;
use strata_tablegen::spot::Spot;

use crate::scene::{ConductanceSpec, CounterfaceConduction, Scene};

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

/// ψ(a) of one table node: Nyström with [`nystrom_nodes`] up to
/// [`PSI_NYSTROM_MAX_A_OVER_H`], else the spot solver's automatic method.
fn psi_node(spot: &Spot, h1: f64, a: f64) -> Result<f64> {
    let ah = a / h1;
    let psi = if ah <= PSI_NYSTROM_MAX_A_OVER_H {
        spot.clone()
            .with_method(Method::Fixed(Discretisation::Nystrom {
                nodes: nystrom_nodes(ah),
            }))
            .psi(a)
    } else {
        spot.psi(a)
    };
    psi.with_context(|| format!("spot conductance at a = {a:e} m"))
}

/// ψ of a layered body, piecewise polynomial in u = ln a: the radii's range cut into
/// equal pieces of at most [`PSI_PIECE_DECADES`], each interpolated through
/// [`PSI_PIECE_NODES`] Chebyshev–Lobatto nodes (barycentric form). ψ is analytic in
/// ln a, so the error falls geometrically with the nodes: measured ≤ 1.2e−6 over four
/// decades of a/h₁ on a plating and insulating layers (the test below; the largest in
/// the decades around a/h₁ = 1, ≤ 1.4e−8 away from them, 2e−12 on a narrow range),
/// against 4.4e−6 of the cubic on 16 nodes per decade it replaces, with 8 solves per
/// decade instead of 16.
struct PsiTable {
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
    /// The table over [a_lo, a_hi] (m) of the body `spot` with top layer thickness `h1` (m).
    fn new(spot: &Spot, h1: f64, a_lo: f64, a_hi: f64) -> Result<PsiTable> {
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
            .map(|u| psi_node(spot, h1, u.exp()))
            .collect::<Result<Vec<f64>>>()?;
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
    fn at(&self, a: f64) -> f64 {
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
    #[cfg(test)]
    fn len(&self) -> usize {
        self.psi.len()
    }
}

/// One body's spot conductance.
enum Side {
    Perfect,
    /// 4 k a (a homogeneous conductor of conductivity k).
    Homogeneous(f64),
    /// 4 k₁ a ψ(a) by the Fredholm solver; h₁ the top layer's thickness (m).
    Layered(Box<Spot>, f64),
}

impl Side {
    /// The body of `stack` as `spot` solves it.
    fn of(spot: Spot, stack: &strata_runtime::Stack) -> Side {
        let c = spot.compliance();
        match stack.top_thickness() {
            Some(h1) if !c.is_homogeneous() => Side::Layered(Box::new(spot), h1),
            _ => Side::Homogeneous(c.top_conductivity()),
        }
    }
}

/// The N model's spot conductances for one scene.
pub struct SpotSum {
    a: Side,
    b: Side,
}

impl SpotSum {
    /// Both bodies' spot conductances from the scene's `[conductance]` (the first body's
    /// stack, the counterface's conduction).
    pub fn new(scene: &Scene, spec: &ConductanceSpec) -> Result<SpotSum> {
        let counterface = match (spec.counterface, scene.stack.counterface()) {
            (CounterfaceConduction::Stack, Some(c)) => {
                Side::of(Spot::new(c, spec.kind).context("counterface")?, c)
            }
            (CounterfaceConduction::Stack, None) => anyhow::bail!("counterface: internal error"),
            (other, _) => Self::rigid(other),
        };
        Self::with_counterface(&scene.stack.body(), spec.kind, counterface)
    }

    /// The body `stack` (its counterface ignored) against a rigid flat: a conducting
    /// half-space of conductivity `flat` (W/(m·K) or S/m), or a perfect conductor (None).
    pub fn against_rigid(
        stack: &strata_runtime::Stack,
        kind: strata_runtime::conduction::ConductionKind,
        flat: Option<f64>,
    ) -> Result<SpotSum> {
        let b = match flat {
            Some(k) => Side::Homogeneous(k),
            None => Side::Perfect,
        };
        Self::with_counterface(&stack.body(), kind, b)
    }

    fn rigid(counterface: CounterfaceConduction) -> Side {
        match counterface {
            CounterfaceConduction::HalfSpace(k) => Side::Homogeneous(k),
            _ => Side::Perfect,
        }
    }

    fn with_counterface(
        stack: &strata_runtime::Stack,
        kind: strata_runtime::conduction::ConductionKind,
        b: Side,
    ) -> Result<SpotSum> {
        let body = Spot::new(stack, kind).context("stack")?;
        Ok(SpotSum {
            a: Side::of(body, stack),
            b,
        })
    }

    /// h_c = Σ G(aᵢ)/A₀ of every step (W/(m²·K) or S/m²), `area` = A₀ (m²).
    pub fn conductances(&self, steps: &[Step], area: f64) -> Result<Vec<f64>> {
        Ok(self
            .spot_conductances(steps)?
            .iter()
            .map(|g| g.iter().sum::<f64>() / area)
            .collect())
    }

    /// G(aᵢ) of every summit of every step (W/K or S; 0 out of contact), both bodies in
    /// series, ψ from one table over all the steps' radii.
    pub fn spot_conductances(&self, steps: &[Step]) -> Result<Vec<Vec<f64>>> {
        let (lo, hi) = steps
            .iter()
            .flat_map(|s| s.radii.iter().copied())
            .filter(|&a| a > 0.0 && a.is_finite())
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), a| {
                (lo.min(a), hi.max(a))
            });
        if hi == 0.0 {
            return Ok(steps.iter().map(|s| vec![0.0; s.radii.len()]).collect());
        }
        let table = |s: &Side| -> Result<Option<PsiTable>> {
            match s {
                Side::Layered(spot, h1) => Ok(Some(PsiTable::new(spot, *h1, lo, hi)?)),
                _ => Ok(None),
            }
        };
        let (ta, tb) = (table(&self.a)?, table(&self.b)?);
        // 1/G of one side at radius a (0 for a perfect conductor).
        let resistance = |s: &Side, t: &Option<PsiTable>, a: f64| match (s, t) {
            (Side::Perfect, _) => 0.0,
            (Side::Homogeneous(k), _) => 1.0 / (4.0 * k * a),
            (Side::Layered(spot, _), Some(t)) => {
                1.0 / (4.0 * spot.compliance().top_conductivity() * a * t.at(a))
            }
            (Side::Layered(..), None) => f64::NAN,
        };
        Ok(steps
            .iter()
            .map(|s| {
                s.radii
                    .iter()
                    .map(|&a| {
                        if a > 0.0 && a.is_finite() {
                            1.0 / (resistance(&self.a, &ta, a) + resistance(&self.b, &tb, a))
                        } else {
                            0.0
                        }
                    })
                    .collect()
            })
            .collect())
    }

    /// The two bodies as the I model's conduction kernel sees them.
    fn bodies(&self) -> [Body<'_>; 2] {
        [&self.a, &self.b].map(|s| match s {
            Side::Perfect => Body::Perfect,
            Side::Homogeneous(k) => Body::HalfSpace(*k),
            Side::Layered(spot, _) => Body::Layered(spot.compliance()),
        })
    }

    /// The I model's interface conductance of every step (physics.md §6.2,
    /// [`strata_runtime::rough::conductance`]): the spots of each step (the summits in
    /// contact, at their positions, with their G(aᵢ)) heat each other through both
    /// bodies, periodically on a cell of sides `extent` (m) or isolated; h_c per step
    /// (W/(m²·K) or S/m²) and the kernel's parameters.
    pub fn interacting(
        &self,
        steps: &[Step],
        summits: &[Summit],
        extent: (f64, f64),
        images: Images,
    ) -> Result<(Vec<f64>, KernelInfo)> {
        let [a, b] = self.bodies();
        let kernel = match images {
            Images::Periodic(_) => Kernel::periodic(a, b, extent)?,
            Images::Isolated => Kernel::isolated(a, b)?,
        };
        let area = extent.0 * extent.1;
        let g = self.spot_conductances(steps)?;
        // the summits in contact at some step: their interactions filled once
        let touching: Vec<usize> = (0..summits.len())
            .filter(|&k| g.iter().any(|gs| gs.get(k).is_some_and(|&g| g > 0.0)))
            .collect();
        let points: Vec<(f64, f64)> = touching
            .iter()
            .map(|&k| (summits[k].x, summits[k].y))
            .collect();
        let net = Interactions::new(&kernel, &points)?;
        let h = g
            .iter()
            .enumerate()
            .map(|(i, gs)| {
                let spots: Vec<(usize, f64)> = touching
                    .iter()
                    .enumerate()
                    .filter_map(|(r, &k)| gs.get(k).filter(|&&g| g > 0.0).map(|&g| (r, g)))
                    .collect();
                net.network(&spots, area)
                    .map(|n| n.conductance)
                    .with_context(|| format!("load step {i}: the I model's spot network"))
            })
            .collect::<Result<Vec<f64>>>()?;
        Ok((h, kernel.info()))
    }

    /// G(a) of one spot with both bodies in series (W/K or S), ψ solved directly (no
    /// table): the reference of the tests.
    pub fn direct(&self, a: f64) -> Result<f64> {
        let r = |s: &Side| -> Result<f64> {
            Ok(match s {
                Side::Perfect => 0.0,
                Side::Homogeneous(k) => 1.0 / (4.0 * k * a),
                Side::Layered(spot, _) => 1.0 / spot.conductance(a)?.conductance,
            })
        };
        Ok(1.0 / (r(&self.a)? + r(&self.b)?))
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
            let t = PsiTable::new(&spot, h, 1e-2 * h, 1e2 * h).unwrap();
            assert_eq!(t.len(), 4 * (PSI_PIECE_NODES - 1) + 1);
            let mut worst: f64 = 0.0;
            for i in 0..40 {
                let a = h * 10f64.powf(-2.0 + 4.0 * (i as f64 + 0.37) / 40.0);
                let exact = spot.psi(a).unwrap();
                worst = worst.max((t.at(a) / exact - 1.0).abs());
            }
            let narrow = PsiTable::new(&spot, h, 0.3 * h, 0.5 * h).unwrap();
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
                let e = (psi_node(&spot, h, a).unwrap() / r - 1.0).abs();
                worst = worst.max(e);
            }
        }
        eprintln!("table node rule: worst {worst:.1e}");
        assert!(worst < 2.4e-14, "{worst}");
    }
}
