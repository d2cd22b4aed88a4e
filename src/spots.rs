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
//! ([`Interactions`]: the same h_c as filling each step's network afresh, bit for bit).

use std::path::PathBuf;
use std::sync::Mutex;

use anyhow::{Context, Result};
use strata_runtime::rough::conductance::{Body, Interactions, Kernel, KernelInfo};
use strata_runtime::rough::{Images, Step};
use strata_runtime::summits::Summit;
use strata_tablegen::psi_table::CacheUse;
use strata_tablegen::spot::Spot;
use strata_tablegen::spot_pair::{SpotSide, spot_conductances};

use crate::scene::{ConductanceSpec, CounterfaceConduction, Scene};

/// The N model's spot conductances for one scene.
pub struct SpotSum {
    a: SpotSide,
    b: SpotSide,
    /// The table cache directory of the ψ tables (None: built in memory).
    cache: Option<PathBuf>,
    /// What the cache did, per layered side and call.
    cache_log: Mutex<Vec<CacheUse>>,
}

impl SpotSum {
    /// Both bodies' spot conductances from the scene's `[conductance]` (the first body's
    /// stack, the counterface's conduction).
    pub fn new(scene: &Scene, spec: &ConductanceSpec) -> Result<SpotSum> {
        let counterface = match (spec.counterface, scene.stack.counterface()) {
            (CounterfaceConduction::Stack, Some(c)) => {
                SpotSide::of(Spot::new(c, spec.kind).context("counterface")?)
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
            Some(k) => SpotSide::Homogeneous(k),
            None => SpotSide::Perfect,
        };
        Self::with_counterface(&stack.body(), kind, b)
    }

    fn rigid(counterface: CounterfaceConduction) -> SpotSide {
        match counterface {
            CounterfaceConduction::HalfSpace(k) => SpotSide::Homogeneous(k),
            _ => SpotSide::Perfect,
        }
    }

    fn with_counterface(
        stack: &strata_runtime::Stack,
        kind: strata_runtime::conduction::ConductionKind,
        b: SpotSide,
    ) -> Result<SpotSum> {
        let body = Spot::new(stack, kind).context("stack")?;
        Ok(SpotSum {
            a: SpotSide::of(body),
            b,
            cache: None,
            cache_log: Mutex::new(vec![]),
        })
    }

    /// Keeps the ψ tables in the table cache `dir` ([`strata_tablegen::psi_table::cached`]):
    /// the same h_c bit for bit as without it.
    pub fn with_cache(mut self, dir: Option<PathBuf>) -> SpotSum {
        self.cache = dir;
        self
    }

    /// What the table cache did with the ψ tables so far (read, written, or not written
    /// and why), per layered side and load path.
    pub fn cache_log(&self) -> Vec<CacheUse> {
        self.cache_log.lock().map(|l| l.clone()).unwrap_or_default()
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
        let (g, uses) = spot_conductances(&self.a, &self.b, steps, self.cache.as_deref())?;
        if let Ok(mut log) = self.cache_log.lock() {
            log.extend(uses);
        }
        Ok(g)
    }

    /// The two bodies as the I model's conduction kernel sees them.
    fn bodies(&self) -> [Body<'_>; 2] {
        [&self.a, &self.b].map(|s| match s {
            SpotSide::Perfect => Body::Perfect,
            SpotSide::Homogeneous(k) => Body::HalfSpace(*k),
            SpotSide::Layered(spot) => Body::Layered(spot.compliance()),
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
        let r = |s: &SpotSide| -> Result<f64> {
            Ok(match s {
                SpotSide::Perfect => 0.0,
                SpotSide::Homogeneous(k) => 1.0 / (4.0 * k * a),
                SpotSide::Layered(spot) => 1.0 / spot.conductance(a)?.conductance,
            })
        };
        Ok(1.0 / (r(&self.a)? + r(&self.b)?))
    }
}
