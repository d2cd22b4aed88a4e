//! The N and I models' interface conductance at solved steps (issue 34, physics.md
//! §6.2), as `strata law` computes it (the `strata` crate's `spots` module, which this
//! follows operation for operation so that the C ABI's h_c equals the command's CSV
//! bit for bit; `capi/tests/c_example.rs` checks it):
//!
//! ```text
//!   h_c = Σᵢ G(aᵢ) / A₀,   1/G(a) = 1/G_A(a) + 1/G_B(a),   G_X(a) = 4 k₁,X a ψ_X(a),
//! ```
//!
//! aᵢ the contact radii of a step's summits (m), A₀ the nominal area (m²); h_c in
//! W/(m²·K) (thermal) or S/m² (electrical). Each spot is an isothermal disc on each
//! body, the two bodies in series (a perfect conductor: 1/G_B = 0; a conducting rigid
//! flat: a homogeneous half-space, G_B = 4k_B a). ψ ≡ 1 on a homogeneous body; on a
//! layered one it comes from the Fredholm spot solver ([`strata_tablegen::spot`])
//! through the table `strata law` reads too ([`strata_tablegen::psi_table::PsiTable`]:
//! 8 solves per decade of a over the steps' radii, interpolated in ln a to ≤ 1.2e−6 of
//! direct solves, validation.md).
//!
//! The I model ([`SpotSum::interacting`]) adds the spots' thermal interactions through
//! both bodies' point-source fields: Σ_j (δ_ij/G_i + I_ij) Q_j = ΔT,
//! h_c = Σ Q_i/(ΔT A₀) ([`strata_runtime::rough::conductance`]).

use strata_runtime::Stack;
use strata_runtime::conduction::ConductionKind;
use strata_runtime::rough::conductance::{
    Body, ConductanceError, Kernel, Spot as NetSpot, interface_conductance,
};
use strata_runtime::rough::{Images, Step};
use strata_runtime::summits::Summit;
use strata_tablegen::psi_table::PsiError;
use strata_tablegen::spot::{Spot, SpotError};
use strata_tablegen::spot_pair::{SpotSide, spot_conductances};
use thiserror::Error;

/// How the second body (the counterface) conducts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Counterface<'a> {
    /// A perfect conductor (1/G_B = 0).
    Perfect,
    /// A homogeneous conducting half-space of this conductivity (W/(m·K) or S/m).
    HalfSpace(f64),
    /// The elastic counterface's stack, conducting through its own conductivities.
    Stack(&'a Stack),
}

/// Errors of the spot conductances.
#[derive(Debug, Error)]
pub enum SpotSumError {
    /// The first body's stack lacks a conductivity of the kind (or the spot solver
    /// failed on it).
    #[error("{0}")]
    Body(SpotError),
    /// The counterface's stack lacks a conductivity of the kind.
    #[error("{0}")]
    Counterface(SpotError),
    /// The ψ table (a Fredholm solve of ψ failed, or the radii are out of reach).
    #[error("{0}")]
    Psi(PsiError),
    /// The I model's spot network.
    #[error("load step {step}: the I model's spot network: {error}")]
    Network {
        step: usize,
        error: ConductanceError,
    },
    /// The I model's conduction kernel.
    #[error("the I model's conduction kernel: {0}")]
    Kernel(ConductanceError),
}

/// Both bodies' spot conductances for one kind of conduction.
pub struct SpotSum {
    a: SpotSide,
    b: SpotSide,
}

impl SpotSum {
    /// The first body `body` (its counterface not included) and the counterface's
    /// conduction `counterface`, for `kind`. A missing conductivity is named (layer,
    /// field).
    pub fn new(
        body: &Stack,
        counterface: Counterface<'_>,
        kind: ConductionKind,
    ) -> Result<SpotSum, SpotSumError> {
        let a = Spot::new(body, kind).map_err(SpotSumError::Body)?;
        let b = match counterface {
            Counterface::Perfect => SpotSide::Perfect,
            Counterface::HalfSpace(k) => SpotSide::Homogeneous(k),
            Counterface::Stack(c) => {
                SpotSide::of(Spot::new(c, kind).map_err(SpotSumError::Counterface)?)
            }
        };
        Ok(SpotSum {
            a: SpotSide::of(a),
            b,
        })
    }

    /// h_c = Σ G(aᵢ)/A₀ of every step (W/(m²·K) or S/m²), `area` = A₀ (m²).
    pub fn conductances(&self, steps: &[Step], area: f64) -> Result<Vec<f64>, SpotSumError> {
        Ok(self
            .spot_conductances(steps)?
            .iter()
            .map(|g| g.iter().sum::<f64>() / area)
            .collect())
    }

    /// G(aᵢ) of every summit of every step (W/K or S; 0 out of contact), both bodies in
    /// series, ψ from one table over all the steps' radii.
    fn spot_conductances(&self, steps: &[Step]) -> Result<Vec<Vec<f64>>, SpotSumError> {
        spot_conductances(&self.a, &self.b, steps, None)
            .map(|(g, _)| g)
            .map_err(SpotSumError::Psi)
    }

    /// The two bodies as the I model's conduction kernel sees them.
    fn bodies(&self) -> [Body<'_>; 2] {
        [&self.a, &self.b].map(|s| match s {
            SpotSide::Perfect => Body::Perfect,
            SpotSide::Homogeneous(k) => Body::HalfSpace(*k),
            SpotSide::Layered(spot) => Body::Layered(spot.compliance()),
        })
    }

    /// The I model's h_c of every step (W/(m²·K) or S/m²): the spots of each step (the
    /// summits in contact, at their positions, with their G(aᵢ)) heat each other
    /// through both bodies, periodically on a cell of sides `extent` (m) or isolated.
    pub fn interacting(
        &self,
        steps: &[Step],
        summits: &[Summit],
        extent: (f64, f64),
        images: Images,
    ) -> Result<Vec<f64>, SpotSumError> {
        let [a, b] = self.bodies();
        let kernel = match images {
            Images::Periodic(_) => Kernel::periodic(a, b, extent),
            Images::Isolated => Kernel::isolated(a, b),
        }
        .map_err(SpotSumError::Kernel)?;
        let area = extent.0 * extent.1;
        let g = self.spot_conductances(steps)?;
        g.iter()
            .enumerate()
            .map(|(step, gs)| {
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
                    .map_err(|error| SpotSumError::Network { step, error })
            })
            .collect()
    }
}
