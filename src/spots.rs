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
//! comes from the Fredholm spot solver ([`strata_tablegen::spot`]), computed at nodes
//! 16 per decade of a over the step radii's range and interpolated by cubic Lagrange
//! polynomials in ln a (measured against direct solves in the tests).
//!
//! The I model ([`SpotSum::interacting`]) adds the spots' thermal interactions: the same
//! G(aᵢ) on the diagonal of the spot network of [`strata_runtime::rough::conductance`],
//! Σ_j (δ_ij/G_i + I_ij) Q_j = ΔT, h_c = Σ Q_i/(ΔT A₀).

use anyhow::{Context, Result};
use rayon::prelude::*;
use strata_runtime::rough::conductance::{
    Body, Kernel, KernelInfo, Spot as NetSpot, interface_conductance,
};
use strata_runtime::rough::{Images, Step};
use strata_runtime::summits::Summit;
use strata_tablegen::spot::Spot;

use crate::scene::{ConductanceSpec, CounterfaceConduction, Scene};

/// Nodes of ψ per decade of the spot radius.
pub const PSI_NODES_PER_DECADE: f64 = 16.0;

/// One body's spot conductance.
enum Side {
    Perfect,
    /// 4 k a (a homogeneous conductor of conductivity k).
    Homogeneous(f64),
    /// 4 k₁ a ψ(a) by the Fredholm solver.
    Layered(Box<Spot>),
}

impl Side {
    fn of(spot: Spot) -> Side {
        let c = spot.compliance();
        if c.is_homogeneous() {
            Side::Homogeneous(c.top_conductivity())
        } else {
            Side::Layered(Box::new(spot))
        }
    }
}

/// ψ of a layered body at nodes in u = ln a, interpolated.
struct PsiTable {
    u0: f64,
    du: f64,
    psi: Vec<f64>,
}

impl PsiTable {
    /// Nodes over [a_lo, a_hi] (m), at least 4, [`PSI_NODES_PER_DECADE`] per decade.
    fn new(spot: &Spot, a_lo: f64, a_hi: f64) -> Result<PsiTable> {
        let (u_lo, u_hi) = (a_lo.ln(), a_hi.ln());
        let n = (((u_hi - u_lo) / std::f64::consts::LN_10 * PSI_NODES_PER_DECADE).ceil() as usize
            + 1)
        .max(4);
        let du = (u_hi - u_lo).max(1e-3) / (n - 1) as f64;
        let psi = (0..n)
            .into_par_iter()
            .map(|i| {
                let a = (u_lo + du * i as f64).exp();
                spot.psi(a)
                    .with_context(|| format!("spot conductance at a = {a:e} m"))
            })
            .collect::<Result<Vec<f64>>>()?;
        Ok(PsiTable { u0: u_lo, du, psi })
    }

    /// ψ(a) by the cubic through the four nodes around ln a.
    fn at(&self, a: f64) -> f64 {
        let n = self.psi.len();
        let x = (a.ln() - self.u0) / self.du;
        let i0 = (x.floor() as isize - 1).clamp(0, n as isize - 4) as usize;
        let mut sum = 0.0;
        for j in 0..4 {
            let mut w = 1.0;
            for m in 0..4 {
                if m != j {
                    w *= (x - (i0 + m) as f64) / (j as f64 - m as f64);
                }
            }
            sum += w * self.psi[i0 + j];
        }
        sum
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
        let body = Spot::new(&scene.stack.body(), spec.kind).context("stack")?;
        let b = match (spec.counterface, scene.stack.counterface()) {
            (CounterfaceConduction::Perfect, _) => Side::Perfect,
            (CounterfaceConduction::HalfSpace(k), _) => Side::Homogeneous(k),
            (CounterfaceConduction::Stack, Some(c)) => {
                Side::of(Spot::new(c, spec.kind).context("counterface")?)
            }
            (CounterfaceConduction::Stack, None) => anyhow::bail!("counterface: internal error"),
        };
        Ok(SpotSum {
            a: Side::of(body),
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
                Side::Layered(spot) => Ok(Some(PsiTable::new(spot, lo, hi)?)),
                _ => Ok(None),
            }
        };
        let (ta, tb) = (table(&self.a)?, table(&self.b)?);
        // 1/G of one side at radius a (0 for a perfect conductor).
        let resistance = |s: &Side, t: &Option<PsiTable>, a: f64| match (s, t) {
            (Side::Perfect, _) => 0.0,
            (Side::Homogeneous(k), _) => 1.0 / (4.0 * k * a),
            (Side::Layered(spot), Some(t)) => {
                1.0 / (4.0 * spot.compliance().top_conductivity() * a * t.at(a))
            }
            (Side::Layered(_), None) => f64::NAN,
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
            Side::Layered(spot) => Body::Layered(spot.compliance()),
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
        let h = g
            .iter()
            .enumerate()
            .map(|(i, gs)| {
                let spots: Vec<NetSpot> = gs
                    .iter()
                    .zip(summits)
                    .filter(|(g, _)| **g > 0.0)
                    .map(|(&g, s)| NetSpot {
                        x: s.x,
                        y: s.y,
                        conductance: g,
                    })
                    .collect();
                interface_conductance(&kernel, &spots, area)
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
                Side::Layered(spot) => 1.0 / spot.conductance(a)?.conductance,
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

    /// The interpolated ψ against direct Fredholm solves between the nodes, over four
    /// decades of a/h₁ on a plating and an insulating layer.
    #[test]
    fn interpolated_psi_matches_direct_solves() {
        let k = Conductivity::thermal;
        let h = 1e-5;
        for (k1, kb) in [(200.0, 20.0), (0.5, 40.0)] {
            let stack = Stack::new(
                vec![Layer {
                    thickness: h,
                    young: 1e9,
                    poisson: 0.3,
                }],
                Base::Elastic {
                    young: 1e9,
                    poisson: 0.3,
                },
            )
            .unwrap()
            .with_conduction(vec![k(k1)], k(kb), BaseConduction::HalfSpace)
            .unwrap();
            let spot = Spot::new(&stack, ConductionKind::Thermal).unwrap();
            let t = PsiTable::new(&spot, 1e-2 * h, 1e2 * h).unwrap();
            let mut worst: f64 = 0.0;
            for i in 0..40 {
                let a = h * 10f64.powf(-2.0 + 4.0 * (i as f64 + 0.37) / 40.0);
                let exact = spot.psi(a).unwrap();
                worst = worst.max((t.at(a) / exact - 1.0).abs());
            }
            eprintln!("ψ table k1/kb = {}: worst {worst:.2e}", k1 / kb);
            // measured 3.2e-6, 4.4e-6
            assert!(worst < 5e-5, "{worst}");
        }
    }
}
