//! Two bodies' spot conductances in series (physics.md §6.2): one summit's contact of
//! radius a conducts G(a) with 1/G = 1/G_A(a) + 1/G_B(a), G_X(a) = 4 k₁,X a ψ_X(a) on a
//! layered body (ψ from one [`PsiTable`] covering the radii of a load path, from the
//! table cache when there is one), 4 k a on a
//! homogeneous one and ∞ on a perfect conductor; and the interface they make
//! ([`SpotPair`]): the N model's spots in parallel and the I model's spot network. The
//! one implementation behind the N and I models' conductance of `strata` and of the C ABI.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use strata_runtime::constriction::{Side, radius_range, series_conductances};
use strata_runtime::resources::MemoryLimit;
use strata_runtime::rough::conductance::{
    Body, ConductanceError, Kernel, KernelInfo, PathError, path_conductances,
};
use strata_runtime::rough::{Images, Step};
use strata_runtime::summits::Summit;

use crate::psi_table::{CacheUse, PsiError, PsiTable, build, cached};
use crate::spot::{Spot, SpotError};

/// One body's spot conductance.
pub enum SpotSide {
    /// A perfect conductor (1/G = 0).
    Perfect,
    /// 4 k a (a homogeneous conductor of conductivity k, W/(m·K) or S/m).
    Homogeneous(f64),
    /// 4 k₁ a ψ(a) by the Fredholm solver.
    Layered(Box<Spot>),
}

impl SpotSide {
    /// The side of a body's spot solver: homogeneous where its stack is.
    pub fn of(spot: Spot) -> SpotSide {
        let c = spot.compliance();
        if c.is_homogeneous() {
            SpotSide::Homogeneous(c.top_conductivity())
        } else {
            SpotSide::Layered(Box::new(spot))
        }
    }
}

/// G(aᵢ) (W/K or S; 0 out of contact) of every summit of every step, the sides `a` and
/// `b` in series, ψ from one table per layered side covering all the steps' radii: read
/// from (or built into) the table cache `cache` when given ([`cached`]), else built
/// ([`build`]) — the same bits either way. Also what the cache did, per layered side.
pub fn spot_conductances(
    a: &SpotSide,
    b: &SpotSide,
    steps: &[Step],
    cache: Option<&Path>,
) -> Result<(Vec<Vec<f64>>, Vec<CacheUse>), PsiError> {
    let Some((lo, hi)) = radius_range(steps) else {
        let g = steps.iter().map(|s| vec![0.0; s.radii.len()]).collect();
        return Ok((g, vec![]));
    };
    let mut uses = vec![];
    let mut table = |s: &SpotSide| -> Result<Option<PsiTable>, PsiError> {
        let SpotSide::Layered(spot) = s else {
            return Ok(None);
        };
        Ok(Some(match cache {
            Some(dir) => {
                let (t, u) = cached(spot, lo, hi, dir)?;
                uses.push(u);
                t
            }
            None => build(spot, lo, hi)?,
        }))
    };
    let (ta, tb) = (table(a)?, table(b)?);
    let (Some(sa), Some(sb)) = (side(a, &ta), side(b, &tb)) else {
        return Err(PsiError::Range { lo, hi });
    };
    Ok((series_conductances(&sa, &sb, steps), uses))
}

/// The runtime's view of the side `s` with its ψ table `t` (None for a layered side
/// without one; a layered side always has its table).
fn side<'t>(s: &SpotSide, t: &'t Option<PsiTable>) -> Option<Side<'t>> {
    Some(match s {
        SpotSide::Perfect => Side::Perfect,
        SpotSide::Homogeneous(k) => Side::Homogeneous(*k),
        SpotSide::Layered(spot) => Side::Layered {
            conductivity: spot.compliance().top_conductivity(),
            table: t.as_ref()?,
        },
    })
}

/// A failed N- or I-model conductance of a load path.
#[derive(Debug, thiserror::Error)]
pub enum SpotPairError {
    /// The ψ table of a layered side.
    #[error("{0}")]
    Psi(#[from] PsiError),
    /// The I model's conduction kernel.
    #[error("the I model's conduction kernel: {0}")]
    Kernel(ConductanceError),
    /// The I model's spot network of one load step.
    #[error("load step {step}: the I model's spot network: {error}")]
    Network {
        step: usize,
        error: ConductanceError,
    },
}

/// The two bodies of an interface as their spots conduct (physics.md §6.2): the N
/// model's spots in parallel ([`SpotPair::conductances`]) and the I model's spot network
/// ([`SpotPair::interacting`]) — the one implementation of `strata` and the C ABI, which
/// so give the same h_c bit for bit.
pub struct SpotPair {
    a: SpotSide,
    b: SpotSide,
    /// The table cache directory of the ψ tables (None: built in memory).
    cache: Option<PathBuf>,
    /// What the cache did, per layered side and load path.
    cache_log: Mutex<Vec<CacheUse>>,
}

impl SpotPair {
    /// The first body's side `a` and the counterface's `b`, ψ tables in memory.
    pub fn new(a: SpotSide, b: SpotSide) -> SpotPair {
        SpotPair {
            a,
            b,
            cache: None,
            cache_log: Mutex::new(vec![]),
        }
    }

    /// Keeps the ψ tables in the table cache `dir` ([`cached`]): the same h_c bit for bit.
    pub fn with_cache(mut self, dir: Option<PathBuf>) -> SpotPair {
        self.cache = dir;
        self
    }

    /// What the table cache did with the ψ tables so far, per layered side and load path.
    pub fn cache_log(&self) -> Vec<CacheUse> {
        self.cache_log.lock().map(|l| l.clone()).unwrap_or_default()
    }

    /// G(aᵢ) of every summit of every step (W/K or S; 0 out of contact), both bodies in
    /// series ([`spot_conductances`]).
    pub fn spot_conductances(&self, steps: &[Step]) -> Result<Vec<Vec<f64>>, PsiError> {
        let (g, uses) = spot_conductances(&self.a, &self.b, steps, self.cache.as_deref())?;
        if let Ok(mut log) = self.cache_log.lock() {
            log.extend(uses);
        }
        Ok(g)
    }

    /// The N model: h_c = Σ G(aᵢ)/A₀ of every step (W/(m²·K) or S/m²), `area` = A₀ (m²).
    pub fn conductances(&self, steps: &[Step], area: f64) -> Result<Vec<f64>, PsiError> {
        Ok(self
            .spot_conductances(steps)?
            .iter()
            .map(|g| g.iter().sum::<f64>() / area)
            .collect())
    }

    /// The two bodies as the I model's conduction kernel sees them.
    fn bodies(&self) -> [Body<'_>; 2] {
        [&self.a, &self.b].map(|s| match s {
            SpotSide::Perfect => Body::Perfect,
            SpotSide::Homogeneous(k) => Body::HalfSpace(*k),
            SpotSide::Layered(spot) => Body::Layered(spot.compliance()),
        })
    }

    /// Checks, before any work, that the I model's conduction kernel of a sample of
    /// sides `extent` (m) can be built (periodic images: its table within the cap and
    /// `memory`, [`Kernel::check_periodic`]; isolated: nothing to check).
    pub fn check_kernel(
        &self,
        extent: (f64, f64),
        images: Images,
        memory: &MemoryLimit,
    ) -> Result<(), SpotPairError> {
        let [a, b] = self.bodies();
        match images {
            Images::Periodic(_) => Kernel::check_periodic(a, b, extent, memory)
                .map(|_| ())
                .map_err(SpotPairError::Kernel),
            Images::Isolated => Ok(()),
        }
    }

    /// The I model's interface conductance of every step (physics.md §6.2,
    /// [`strata_runtime::rough::conductance`]): the spots of each step (the summits in
    /// contact, at their positions, with their G(aᵢ)) heat each other through both
    /// bodies, Σ_j (δ_ij/G_i + I_ij) Q_j = ΔT, h_c = Σ Q_i/(ΔT A₀), periodically on a
    /// cell of sides `extent` (m) or isolated; the interactions of every summit that
    /// touches at some step filled once for the path ([`strata_runtime::rough::conductance::Interactions`]: the same h_c as
    /// filling each step's network afresh, bit for bit). h_c per step (W/(m²·K) or S/m²)
    /// and the kernel's parameters. The kernel's table and the interactions are checked
    /// against `memory` before they are allocated.
    pub fn interacting(
        &self,
        steps: &[Step],
        summits: &[Summit],
        extent: (f64, f64),
        images: Images,
        memory: &MemoryLimit,
    ) -> Result<(Vec<f64>, KernelInfo), SpotPairError> {
        let [a, b] = self.bodies();
        let kernel = match images {
            Images::Periodic(_) => Kernel::periodic(a, b, extent, memory),
            Images::Isolated => Kernel::isolated(a, b, extent),
        }
        .map_err(SpotPairError::Kernel)?;
        let area = extent.0 * extent.1;
        let g = self.spot_conductances(steps)?;
        let points: Vec<(f64, f64)> = summits.iter().map(|s| (s.x, s.y)).collect();
        let h = path_conductances(&kernel, &g, &points, area, memory).map_err(|e| match e {
            PathError::Step { step, error } => SpotPairError::Network { step, error },
            PathError::Interactions(e) => SpotPairError::Kernel(e),
        })?;
        Ok((h, kernel.info()))
    }

    /// G(a) of one spot with both bodies in series (W/K or S), ψ solved directly (no
    /// table): the reference of the tests.
    pub fn direct(&self, a: f64) -> Result<f64, SpotError> {
        let r = |s: &SpotSide| -> Result<f64, SpotError> {
            Ok(match s {
                SpotSide::Perfect => 0.0,
                SpotSide::Homogeneous(k) => 1.0 / (4.0 * k * a),
                SpotSide::Layered(spot) => 1.0 / spot.conductance(a)?.conductance,
            })
        };
        Ok(1.0 / (r(&self.a)? + r(&self.b)?))
    }
}
