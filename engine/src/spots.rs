//! The N and I models' interface conductance (physics.md §6.2): the contact spots
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
//! comes from the Fredholm spot solver ([`strata_tablegen::spot`]) through one ψ table
//! covering the steps' radii ([`strata_tablegen::psi_table`]: whole decades of a/h₁, 8
//! solves per decade, interpolated in ln a to ≤ 1.2e−6 of direct solves), kept in the
//! table cache when the engine gives one ([`SpotSum::with_cache`]): a stack's table is
//! solved once and read by every later load path.
//!
//! The I model ([`SpotSum::interacting`]) adds the spots' thermal interactions: the same
//! G(aᵢ) on the diagonal of the spot network of [`strata_runtime::rough::conductance`],
//! Σ_j (δ_ij/G_i + I_ij) Q_j = ΔT, h_c = Σ Q_i/(ΔT A₀), the interactions I_ij of every
//! summit that touches at some step filled once for the whole path
//! ([`strata_runtime::rough::conductance::Interactions`]: the same h_c as filling each step's network afresh, bit for bit).

use std::path::PathBuf;

use crate::error::Result;
use strata_runtime::conduction::ConductionKind;
use strata_runtime::resources::MemoryLimit;
use strata_runtime::rough::Images;
use strata_runtime::rough::Step;
use strata_runtime::rough::conductance::KernelInfo;
use strata_runtime::summits::Summit;
use strata_runtime::{Solid, Stack};
use strata_tablegen::psi_table::CacheUse;
use strata_tablegen::spot::{Spot, SpotError};
use strata_tablegen::spot_pair::{SpotPair, SpotSide};
use thiserror::Error;

use crate::scene::{ConductanceSpec, CounterfaceConduction, Scene};

/// Why the spot conductances of a stack cannot be built: a body that cannot conduct
/// as asked (a missing conductivity, named with its layer and field by [`SpotError`]).
#[derive(Debug, Clone, PartialEq, Error)]

pub enum SpotSumError {
    /// The first body (its counterface not included).
    #[error("stack: {0}")]
    Body(SpotError),
    /// The elastic counterface's stack.
    #[error("counterface: {0}")]
    Counterface(SpotError),
    /// The counterface is to conduct through its own stack, but the body is pressed by
    /// a rigid flat.
    #[error(
        "counterface: conduction through the counterface's stack, but the body is pressed by a \
         rigid flat (no elastic counterface): the flat conducts perfectly or as a half-space"
    )]
    NoElasticCounterface,
}

/// The N and I models' spot conductances for one scene: the shared
/// [`SpotPair`] built from the scene's stack and `[conductance]`.
pub struct SpotSum(SpotPair);

impl SpotSum {
    /// Both bodies' spot conductances from the scene's `[conductance]` (the first body's
    /// stack, the counterface's conduction): [`SpotSum::of_stack`].
    pub fn new(scene: &Scene, spec: &ConductanceSpec) -> Result<SpotSum> {
        Ok(Self::of_stack(&scene.bodies, spec.kind, spec.counterface)?)
    }

    /// Both bodies' spot conductances for `kind` in memory: the first body of `stack`
    /// and the counterface conducting as `counterface` says — through the elastic
    /// counterface's own stack ([`strata_runtime::Counterface::Elastic`]), as a
    /// half-space of conductivity k_B (W/(m·K) or S/m), or perfectly. The scenes'
    /// `[conductance]` and the C ABI's `StrataLawOptions` both come here: the one place
    /// the spot solvers ([`SpotSide`], solver handles) are derived from the bodies.
    pub fn of_stack<S: Solid + ?Sized>(
        stack: &S,
        kind: ConductionKind,
        counterface: CounterfaceConduction,
    ) -> Result<SpotSum, SpotSumError> {
        let b = match (counterface, stack.elastic_counterface()) {
            (CounterfaceConduction::Stack, Some(c)) => {
                SpotSide::of(Spot::new(c, kind).map_err(SpotSumError::Counterface)?)
            }
            (CounterfaceConduction::Stack, None) => {
                return Err(SpotSumError::NoElasticCounterface);
            }
            (CounterfaceConduction::HalfSpace(k), _) => SpotSide::Homogeneous(k),
            (CounterfaceConduction::Perfect, _) => SpotSide::Perfect,
        };
        let a = Spot::new(stack.first(), kind).map_err(SpotSumError::Body)?;
        Ok(SpotSum(SpotPair::new(SpotSide::of(a), b)))
    }

    /// The body `stack` against a rigid flat: a conducting
    /// half-space of conductivity `flat` (W/(m·K) or S/m), or a perfect conductor (None).
    pub fn against_rigid(
        stack: &Stack,
        kind: ConductionKind,
        flat: Option<f64>,
    ) -> Result<SpotSum> {
        let b = match flat {
            Some(k) => CounterfaceConduction::HalfSpace(k),
            None => CounterfaceConduction::Perfect,
        };
        Ok(Self::of_stack(stack, kind, b)?)
    }

    /// Keeps the ψ tables in the table cache `dir` ([`strata_tablegen::psi_table::cached`]):
    /// the same h_c bit for bit as without it.
    pub fn with_cache(self, dir: Option<PathBuf>) -> SpotSum {
        SpotSum(self.0.with_cache(dir))
    }

    /// What the table cache did with the ψ tables so far (read, written, or not written
    /// and why), per layered side and load path.
    pub fn cache_log(&self) -> Vec<CacheUse> {
        self.0.cache_log()
    }

    /// h_c = Σ G(aᵢ)/A₀ of every step (W/(m²·K) or S/m²), `area` = A₀ (m²).
    pub fn conductances(&self, steps: &[Step], area: f64) -> Result<Vec<f64>> {
        Ok(self.0.conductances(steps, area)?)
    }

    /// G(aᵢ) of every summit of every step (W/K or S; 0 out of contact), both bodies in
    /// series, ψ from one table over all the steps' radii.
    pub fn spot_conductances(&self, steps: &[Step]) -> Result<Vec<Vec<f64>>> {
        Ok(self.0.spot_conductances(steps)?)
    }

    /// Checks, before the mechanical solve, that the I model's conduction kernel can be
    /// built on a sample of sides `extent` (m) ([`SpotPair::check_kernel`]).
    pub fn check_kernel(
        &self,
        extent: (f64, f64),
        images: Images,
        memory: &MemoryLimit,
    ) -> Result<()> {
        Ok(self.0.check_kernel(extent, images, memory)?)
    }

    /// The I model's interface conductance of every step ([`SpotPair::interacting`]):
    /// h_c per step (W/(m²·K) or S/m²) and the kernel's parameters.
    pub fn interacting(
        &self,
        steps: &[Step],
        summits: &[Summit],
        extent: (f64, f64),
        images: Images,
        memory: &MemoryLimit,
    ) -> Result<(Vec<f64>, KernelInfo)> {
        Ok(self.0.interacting(steps, summits, extent, images, memory)?)
    }

    /// G(a) of one spot with both bodies in series (W/K or S), ψ solved directly (no
    /// table): the reference of the tests.
    pub fn direct(&self, a: f64) -> Result<f64> {
        Ok(self.0.direct(a)?)
    }
}

// passed on by the engine with `?` (engine/src/error.rs)
crate::error::passed_on!(SpotSumError);
