//! The N and I models' interface conductance at solved steps (physics.md
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
//! 8 solves per decade of a/h₁, interpolated in log a to ≤ 1.2e−6 of direct solves,
//! validation.md; built in memory here, the same values as the command's cached table).
//!
//! The I model ([`SpotSum::interacting`]) adds the spots' thermal interactions through
//! both bodies' point-source fields: Σ_j (δ_ij/G_i + I_ij) Q_j = ΔT,
//! h_c = Σ Q_i/(ΔT A₀) ([`strata_runtime::rough::conductance`]). Both come from
//! [`strata_tablegen::spot_pair::SpotPair`], the command's own implementation.

use strata_runtime::Stack;
use strata_runtime::conduction::ConductionKind;
use strata_runtime::rough::{Images, Step};
use strata_runtime::summits::Summit;
use strata_tablegen::spot::{Spot, SpotError};
use strata_tablegen::spot_pair::{SpotPair, SpotPairError, SpotSide};
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
    /// The ψ table, the I model's kernel or one of its spot networks.
    #[error("{0}")]
    Solve(#[from] SpotPairError),
}

/// Both bodies' spot conductances for one kind of conduction: the shared [`SpotPair`]
/// (ψ tables in memory).
pub struct SpotSum(SpotPair);

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
        Ok(SpotSum(SpotPair::new(SpotSide::of(a), b)))
    }

    /// h_c = Σ G(aᵢ)/A₀ of every step (W/(m²·K) or S/m²), `area` = A₀ (m²).
    pub fn conductances(&self, steps: &[Step], area: f64) -> Result<Vec<f64>, SpotSumError> {
        Ok(self
            .0
            .conductances(steps, area)
            .map_err(SpotPairError::from)?)
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
        Ok(self.0.interacting(steps, summits, extent, images)?.0)
    }
}
