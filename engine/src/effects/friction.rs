//! The full-stick tangential stiffness K_t of the sample (N/m) of a `[friction]` scene
//! solved by the N or I model, as an observer of the load path ([`AsperityFriction`]):
//! after the path, every contacting asperity a bonded disc of the step's contact radius
//! a_i displaced tangentially without slip, and
//!
//! ```text
//!   K_t = Σ_i K_t(a_i),   K_t(a) = 2K_LK_T/(K_L + K_T),   K_L = 2E*₁aψ_LL(a/h₁),   K_T = 4μ₁aψ_TT(a/h₁)
//! ```
//!
//! (`strata_runtime::disc_stiffness`; Mindlin's 8μa/(2 − ν) on a half-space), the punch
//! factors read from the stack's disc-stiffness table in the table cache (built by
//! Fredholm solves when missing, [`crate::cache::disc_stiffness`]). The asperities'
//! tangential interactions are ignored in both models (Mindlin per asperity, the discs
//! in parallel); the I model sums its own, interacting contact radii, the N model its
//! independent ones. The normal–tangential coupling S_zL is ignored, as in Mindlin's
//! solution. A capped tip (`[plasticity]`) is a bonded disc of its contact radius too.
//! The coefficient μ itself enters no per-step value: it is what a friction card
//! carries beside K_t.
//!
//! Its records are [`TangentialInfo`] per step and a [`FrictionSummary`].

use std::time::Instant;

use crate::error::{Context, Result};
use strata_runtime::rough::{Model, Step};

use super::observer::{AsperityPath, StepObserver};
use crate::scene::{FrictionSpec, Scene, TangentialPathSpec};
use crate::setup::{EngineOptions, Observer, log};
use crate::solution::{
    FrictionSummary, FrictionUnits, SceneSolution, TangentialCurve, TangentialCurveUnits,
    TangentialInfo, TangentialPoint,
};

/// The definition of the asperity models' tangential stiffness.
const DEFINITION: &str = "full-stick tangential stiffness of the sample K_t = sum_i K_t(a_i) (N/m): each \
     contacting asperity a bonded disc of its contact radius a_i (the I model's interacting radii, \
     the N model's independent ones), K_t(a) = 2 K_L K_T/(K_L + K_T), K_L = 2 E*1 a psi_LL(a/h1), \
     K_T = 4 mu1 a psi_TT(a/h1) (8 mu a/(2 - nu) on a half-space, Mindlin), the discs in parallel: \
     tangential interactions between asperities and the normal-tangential coupling ignored";

/// The smallest and largest contact radius over the path's steps (m), None without
/// contact.
pub fn radius_range(steps: &[Step]) -> Option<(f64, f64)> {
    steps
        .iter()
        .flat_map(|s| s.radii.iter().copied())
        .filter(|a| *a > 0.0)
        .fold(None, |r, a| match r {
            None => Some((a, a)),
            Some((lo, hi)) => Some((f64::min(lo, a), f64::max(hi, a))),
        })
}

/// The N or I model's tangential stiffness: the contact discs of the path's steps,
/// summed after it.
pub struct AsperityFriction<'s> {
    scene: &'s Scene,
    spec: FrictionSpec,
    records: Vec<TangentialInfo>,
    summary: FrictionSummary,
}

impl<'s> AsperityFriction<'s> {
    /// The observer of `scene`'s path.
    pub fn new(scene: &'s Scene, spec: FrictionSpec) -> Self {
        AsperityFriction {
            scene,
            spec,
            records: Vec::new(),
            summary: FrictionSummary {
                coefficient: spec.coefficient,
                definition: DEFINITION,
                table_decades: None,
                seconds: 0.0,
                units: FrictionUnits {
                    coefficient: "1",
                    tangential_stiffness: "N/m (over the sample, full stick)",
                },
            },
        }
    }
}

impl StepObserver for AsperityFriction<'_> {
    fn after_path(
        &mut self,
        path: &AsperityPath<'_, '_>,
        opts: &EngineOptions,
        obs: &dyn Observer,
    ) -> Result<f64> {
        let t0 = Instant::now();
        let records: Vec<TangentialInfo> = match radius_range(path.steps) {
            None => path
                .steps
                .iter()
                .map(|_| TangentialInfo {
                    tangential_stiffness: 0.0,
                })
                .collect(),
            Some((lo, hi)) => {
                let dir = crate::cache::dir(opts.cache_dir.as_deref()).0;
                let table =
                    crate::cache::disc_stiffness(&self.scene.bodies, lo, hi, &dir, obs.quiet())
                        .context("[friction]")?;
                self.summary.table_decades = table.decades().map(|(a, b)| [a, b]);
                path.steps
                    .iter()
                    .map(|s| TangentialInfo {
                        tangential_stiffness: s
                            .radii
                            .iter()
                            .filter(|a| **a > 0.0)
                            .map(|&a| table.tangential(a))
                            // from +0: an empty f64 `sum()` is −0, printed `-0e0`
                            .fold(0.0, |k, ka| k + ka),
                    })
                    .collect()
            }
        };
        let seconds = t0.elapsed().as_secs_f64();
        log!(
            obs,
            "friction: μ = {}; full-stick tangential stiffness of the {} contact discs (Σ K_t(a_i), Mindlin per asperity, no tangential interactions) in {seconds:.3} s",
            self.spec.coefficient,
            match path.model {
                Model::Independent => "N model's",
                Model::Interacting(_) => "I model's (interacting radii)",
            }
        );
        self.summary.seconds = seconds;
        self.records = records;
        Ok(seconds)
    }

    fn truncate(&mut self, n: usize) {
        self.records.truncate(n);
    }

    fn finish(self: Box<Self>, solution: &mut SceneSolution) {
        solution.tangential = Some(self.records);
        solution.summary.friction = Some(self.summary);
    }
}

/// The definition of the BEM's tangential stiffness.
const BEM_DEFINITION: &str = "full-stick tangential stiffness of the cell K_t = Q/s (N/m): the \
     BEM's contact set at each step stuck to the flat, displaced tangentially by s along x under \
     the total tangential force Q (strata_bem::tangential, the 3 x 3 layered kernel without the \
     normal-tangential coupling); the periodic cell's displacements have zero mean, as in the \
     normal BEM";

/// The definition of the BEM's tangential path.
const PATH_DEFINITION: &str = "Coulomb partial slip of the last load step's contact at its fixed \
     pressure (strata_bem::tangential::TangentialPath, the 3 x 3 layered kernel without the \
     normal-tangential coupling): the tangential force Q = (Q/muP) mu P along x applied in the \
     path's steps (force control), the first from the fresh contact, each next from the last \
     one's stick/slip state; tangential_displacement is the flat's rigid shift along x (the \
     periodic cell's displacements have zero mean), stick_fraction the points with |q| < mu p \
     over the points with p > 0";

/// The BEM's tangential stiffness: the full-stick linear solve on each step's contact set
/// ([`strata_bem::tangential::full_stick_stiffness`]), periodic cells only; with
/// `[load] tangential`, the tangential path at the last step's pressure
/// ([`strata_bem::tangential::TangentialPath`]) after the load path.
pub struct BemFriction {
    kernel: strata_bem::tangential::TractionKernel,
    area: f64,
    tolerance: f64,
    coefficient: f64,
    records: Vec<TangentialInfo>,
    summary: FrictionSummary,
    /// `[load] tangential`, and the last step's pressure map it starts from.
    path: Option<TangentialPathSpec>,
    last_pressure: Option<Vec<f64>>,
    curve: Option<TangentialCurve>,
}

/// The most iterations of one full-stick or partial-slip solve.
const MAX_ITERATIONS: usize = 100_000;

impl BemFriction {
    /// The observer of a BEM path on a periodic cell of `grid` = (rows, columns) and
    /// `geometry`; an isolated (non-periodic) sample is refused.
    pub fn prepare(
        scene: &Scene,
        spec: FrictionSpec,
        grid: (usize, usize),
        geometry: strata_bem::Geometry,
    ) -> Result<Self> {
        if !geometry.periodic {
            crate::error::bail_input!(
                "friction: the BEM's tangential stiffness needs a periodic cell \
                 (surface.periodic = true); an isolated sample is not supported"
            );
        }
        let kernel = strata_bem::tangential::TractionKernel::periodic(
            &scene.bodies,
            grid,
            (geometry.ly, geometry.lx),
            strata_bem::tangential::Coupling::Uncoupled,
        )
        .context("[friction]")?;
        Ok(BemFriction {
            kernel,
            area: geometry.lx * geometry.ly,
            tolerance: 1e-8,
            coefficient: spec.coefficient,
            records: Vec::new(),
            summary: FrictionSummary {
                coefficient: spec.coefficient,
                definition: BEM_DEFINITION,
                table_decades: None,
                seconds: 0.0,
                units: FrictionUnits {
                    coefficient: "1",
                    tangential_stiffness: "N/m (over the sample, full stick)",
                },
            },
            path: scene.tangential,
            last_pressure: None,
            curve: None,
        })
    }

    /// The tangential path `spec` at the pressure map `pressure` (Pa).
    fn run_path(
        &self,
        spec: &TangentialPathSpec,
        pressure: Vec<f64>,
        obs: &dyn Observer,
    ) -> Result<TangentialCurve> {
        let t0 = Instant::now();
        let n = pressure.len();
        let pixel = self.area / n as f64;
        let mean_pressure = pressure.iter().sum::<f64>() / n as f64;
        let normal_force = mean_pressure * self.area;
        if !pressure.iter().any(|&p| p > 0.0) {
            crate::error::bail_input!(
                "load.tangential: the last load step has no contact (P = 0): no tangential \
                 force can be carried"
            );
        }
        let mu = self.coefficient;
        let mut path = strata_bem::tangential::TangentialPath::new(
            &self.kernel,
            pressure,
            mu,
            self.area,
            self.tolerance,
            MAX_ITERATIONS,
        );
        let mut steps = Vec::with_capacity(spec.steps);
        let mut dissipation = 0.0;
        for ratio in spec.ratios() {
            let step = path
                .step(strata_bem::tangential::TangentialLoad::Force([
                    ratio * mu * mean_pressure,
                    0.0,
                ]))
                .with_context(|| format!("load.tangential: the step at Q/(μP) = {ratio}"))?;
            let sol = &step.solution;
            dissipation += step.dissipation;
            steps.push(TangentialPoint {
                force_ratio: ratio,
                tangential_force: sol.traction[0].iter().sum::<f64>() * pixel,
                tangential_displacement: sol.shift[0],
                stick_fraction: sol.stick_fraction(),
                dissipation: step.dissipation,
                iterations: sol.iterations,
                error: sol.error,
            });
        }
        let seconds = t0.elapsed().as_secs_f64();
        log!(
            obs,
            "friction: tangential path at the last step (P = {normal_force:e} N, μ = {mu}): {} steps of Q/(μP) from {} to {}, Coulomb partial slip, in {seconds:.3} s",
            spec.steps,
            spec.from,
            spec.to
        );
        Ok(TangentialCurve {
            coefficient: mu,
            normal_force,
            definition: PATH_DEFINITION,
            steps,
            dissipation,
            seconds,
            units: TangentialCurveUnits::si(),
        })
    }
}

impl StepObserver for BemFriction {
    fn after_step(
        &mut self,
        step: &super::observer::BemStep<'_>,
        _obs: &dyn Observer,
    ) -> Result<()> {
        let t0 = Instant::now();
        let k = if step.pressure.iter().any(|&p| p > 0.0) {
            strata_bem::tangential::full_stick_stiffness(
                &self.kernel,
                step.pressure,
                self.area,
                self.tolerance,
                MAX_ITERATIONS,
            )
            .with_context(|| format!("[friction] {}", step.name))?
        } else {
            0.0
        };
        self.records.push(TangentialInfo {
            tangential_stiffness: k,
        });
        if self.path.is_some() {
            // the path's start: the latest step's pressure (one map kept)
            match &mut self.last_pressure {
                Some(p) => p.copy_from_slice(step.pressure),
                None => self.last_pressure = Some(step.pressure.to_vec()),
            }
        }
        self.summary.seconds += t0.elapsed().as_secs_f64();
        Ok(())
    }

    fn after_bem_path(&mut self, obs: &dyn Observer) -> Result<()> {
        if let (Some(spec), Some(p)) = (self.path, self.last_pressure.take()) {
            self.curve = Some(self.run_path(&spec, p, obs)?);
        }
        Ok(())
    }

    fn truncate(&mut self, n: usize) {
        self.records.truncate(n);
    }

    fn finish(self: Box<Self>, solution: &mut SceneSolution) {
        solution.tangential = Some(self.records);
        solution.tangential_path = self.curve;
        solution.summary.friction = Some(self.summary);
    }
}
