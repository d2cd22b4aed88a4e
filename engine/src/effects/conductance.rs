//! The interface conductance h_c of a `[conductance]` scene (physics.md §6.2), thermal
//! (W/(m²·K)) or electrical (S/m²), per nominal area, as an observer of the load path:
//!
//! - **BEM** ([`BemConductance`]): after each step, a unit jump ΔT on the step's contact
//!   set (p > 0) and no flux elsewhere, solved on the grid by the conduction solver
//!   (`strata_bem::ConductanceSolver`) through both bodies; h_c = Σq/(N ΔT). Periodic
//!   samples exclude the k = 0 mode (the bulk 1-D resistance); isolated ones use the
//!   free-boundary kernel.
//! - **N and I models** ([`AsperityConductance`]): after the path, each contact spot an
//!   isothermal disc of the step's contact radius, G = 4k₁aψ(a) per body, the bodies in
//!   series; the N model's spots in parallel (h_c = ΣG/A₀), the I model's heating each
//!   other through both bodies' point-source fields ([`crate::spots::SpotSum`]).
//!
//! Its records are [`ConductanceInfo`] per step and a [`ConductanceSummary`].

use std::time::Instant;

use crate::error::{Context, EngineError, Result};
use strata_bem::{ConductanceOptions, ConductanceSolver, Conductor, Geometry};
use strata_runtime::rough::{Images, Model};
use strata_runtime::surface::Surface;

use super::observer::{AsperityPath, BemStep, StepObserver};
use crate::progress;
use crate::scene::{ConductanceSpec, CounterfaceConduction, Scene};
use crate::setup::{EngineOptions, Observer, log};
use crate::solution::{
    BemConductanceInfo, ConductanceInfo, ConductanceSummary, ConductanceUnits, KernelSummary,
    SceneSolution,
};
use crate::spots::SpotSum;

/// The counterface's conduction in words.
pub fn counterface_conduction(spec: &ConductanceSpec) -> String {
    match spec.counterface {
        CounterfaceConduction::Perfect => "the counterface a perfect conductor".into(),
        CounterfaceConduction::HalfSpace(k) => format!(
            "the rigid counterface a conducting half-space, {k:e} {}",
            spec.kind.conductivity_unit()
        ),
        CounterfaceConduction::Stack => "the counterface conducting through its stack".into(),
    }
}

/// The definition of h_c on a periodic BEM grid (the summary's default).
const PERIODIC_BEM: &str = "interface (constriction) conductance per nominal area h_c = mean(q)/dT for a uniform \
                       jump dT on the contact set (p > 0) and no flux elsewhere, the k = 0 mode (the bulk \
                       1-D resistance of both bodies) excluded (physics.md 6.2); infinite (null) at full contact";

/// The definition of h_c on an isolated BEM sample.
const ISOLATED_BEM: &str = "interface (spreading) conductance per nominal area h_c = sum(q)/(N dT) for a uniform jump dT \
                 on the contact set (p > 0) of the isolated sample and no flux elsewhere, both bodies unbounded \
                 (free-boundary kernel: zero-padded convolution with the pixel coefficients of the layered \
                 point-source field; no k = 0 mode to exclude) (physics.md 6.2)";

/// The definition of the N model's h_c.
const N_MODEL: &str = "N model: h_c = sum of the spots' conductances G(a_i) / A0, G = 4 k1 a psi(a) per body (an \
                 isothermal disc; psi = 1 on a homogeneous body, else the Fredholm spot solver, interpolated \
                 in ln a), the two bodies in series, no thermal interactions between the spots (physics.md 6.2)";

/// The definition of the I model's h_c.
const I_MODEL: &str = "I model: the spots (isothermal discs of conductance G(a_i) = 4 k1 a psi(a) per body, the two \
                 bodies in series) heat each other through both bodies' point-source fields: \
                 sum_j (delta_ij / G_i + I_ij) Q_j = dT, h_c = sum Q_i / (dT A0), I_ij the temperature rise \
                 at spot i per unit heat into spot j (periodic images with the uniform k = 0 mode excluded, \
                 or an isolated sample) (physics.md 6.2)";

/// curve.json's `conductance` entry: kind, unit, definition, the counterface.
fn summary(scene: &Scene, spec: &ConductanceSpec, definition: &'static str) -> ConductanceSummary {
    let top = spec
        .body(&scene.bodies.first)
        .map(|c| c.top_conductivity())
        .unwrap_or(f64::NAN);
    ConductanceSummary {
        kind: spec.kind.name(),
        counterface: counterface_conduction(spec),
        top_conductivity: top,
        definition,
        kernel: None,
        seconds: 0.0,
        units: ConductanceUnits {
            conductance: spec.kind.interface_conductance_unit(),
            top_conductivity: spec.kind.conductivity_unit(),
        },
    }
}

/// The BEM's conductance: one conduction solve per step on its contact set.
pub struct BemConductance {
    solver: ConductanceSolver,
    /// The previous step's flux (a start for the next solve).
    flux: Option<Vec<f64>>,
    records: Vec<ConductanceInfo>,
    summary: ConductanceSummary,
}

impl BemConductance {
    /// The conduction solver on the BEM's `n0 × n1` grid (physics.md §6.2): the first
    /// body's conduction compliance and the counterface's.
    pub fn prepare(
        scene: &Scene,
        spec: &ConductanceSpec,
        (n0, n1): (usize, usize),
        geometry: Geometry,
        opts: &EngineOptions,
        obs: &dyn Observer,
    ) -> Result<Self> {
        let body = spec.body(&scene.bodies.first)?;
        let other = spec.counterface_stack(&scene.bodies.counterface)?;
        let b = match (spec.counterface, &other) {
            (CounterfaceConduction::Perfect, _) => Conductor::Perfect,
            (CounterfaceConduction::HalfSpace(k), _) => Conductor::HalfSpace(k),
            (CounterfaceConduction::Stack, Some(c)) => Conductor::Layered(c),
            (CounterfaceConduction::Stack, None) => {
                return Err(EngineError::Internal("counterface (no stack)"));
            }
        };
        log!(
            obs,
            "conductance: {} interface conductance per nominal area on each step's contact set ({}; {})",
            spec.kind.name(),
            counterface_conduction(spec),
            if geometry.periodic {
                "k = 0 mode excluded"
            } else {
                "isolated sample on unbounded bodies: free-boundary kernel"
            }
        );
        let solver = ConductanceSolver::new(
            n0,
            n1,
            geometry,
            Conductor::Layered(&body),
            b,
            ConductanceOptions {
                memory: opts.memory,
                ..ConductanceOptions::default()
            },
        )
        .context("[conductance]")?;
        let definition = if geometry.periodic {
            PERIODIC_BEM
        } else {
            ISOLATED_BEM
        };
        Ok(BemConductance {
            solver,
            flux: None,
            records: Vec::new(),
            summary: summary(scene, spec, definition),
        })
    }
}

impl StepObserver for BemConductance {
    fn after_step(&mut self, step: &BemStep<'_>, _obs: &dyn Observer) -> Result<()> {
        // physics.md §6.2: a unit jump on this step's contact set (p > 0)
        let tc = Instant::now();
        let set: Vec<bool> = step.pressure.iter().map(|&p| p > 0.0).collect();
        // the start: the previous step's flux and this step's pressure rate dp/dδ (the
        // exact flux on homogeneous bodies by Barber's analogy), best combined
        let guesses: Vec<&[f64]> = self
            .flux
            .as_deref()
            .into_iter()
            .chain([step.pressure_rate])
            .collect();
        let h = self
            .solver
            .solve_from_guesses(&set, &guesses)
            .with_context(|| format!("{}: conductance", step.name))?;
        self.summary.seconds += tc.elapsed().as_secs_f64();
        self.records.push(ConductanceInfo {
            conductance: h.conductance,
            bem: Some(BemConductanceInfo {
                conductance_iterations: h.iterations,
                conductance_residual: h.residual,
            }),
        });
        self.flux = h.conductance.is_finite().then_some(h.flux);
        Ok(())
    }

    fn truncate(&mut self, n: usize) {
        self.records.truncate(n);
    }

    fn finish(self: Box<Self>, solution: &mut SceneSolution) {
        solution.conductance = Some(self.records);
        solution.summary.conductance = Some(self.summary);
    }
}

/// The N or I model's conductance: the spots of the path's steps, summed after it.
pub struct AsperityConductance<'s> {
    scene: &'s Scene,
    spec: &'s ConductanceSpec,
    records: Vec<ConductanceInfo>,
    summary: ConductanceSummary,
}

impl<'s> AsperityConductance<'s> {
    /// Checks the I model's conduction kernel (its table's cap and the memory limit)
    /// against the sample before any work: a refusal after the mechanical solve would
    /// waste it.
    pub fn prepare(
        scene: &'s Scene,
        spec: &'s ConductanceSpec,
        model: Model,
        surface: &Surface,
        opts: &EngineOptions,
    ) -> Result<Self> {
        if let Model::Interacting(images) = model {
            SpotSum::new(scene, spec)?
                .check_kernel(surface.extent(), images, &opts.memory)
                .context("[conductance]")?;
        }
        Ok(AsperityConductance {
            scene,
            spec,
            records: Vec::new(),
            summary: summary(scene, spec, PERIODIC_BEM),
        })
    }
}

impl StepObserver for AsperityConductance<'_> {
    /// The N or I model's interface conductance of the path's steps (physics.md §6.2):
    /// the N model's spots conduct in parallel, each body in series; the I model's heat
    /// each other through both bodies. The contact radii are the steps' own, elastic or
    /// capped (a capped tip's contact is a disc of its contact radius, whatever its
    /// pressure).
    fn after_path(
        &mut self,
        path: &AsperityPath<'_, '_>,
        opts: &EngineOptions,
        obs: &dyn Observer,
    ) -> Result<f64> {
        let (scene, spec) = (self.scene, self.spec);
        let rc = path.contact;
        // ψ tables of layered sides live in the table cache: solved once per stack
        let psi_cache = crate::cache::dir(opts.cache_dir.as_deref()).0;
        let sum = SpotSum::new(scene, spec)?.with_cache(Some(psi_cache));
        let tc = Instant::now();
        let h = match path.model {
            Model::Independent => {
                log!(
                    obs,
                    "conductance: {} conductance of the spots in parallel (Σ G(a)/A0, G = 4k1·a·ψ(a) per body, bodies in series; {}; no interactions)",
                    spec.kind.name(),
                    counterface_conduction(spec)
                );
                self.summary.definition = N_MODEL;
                sum.conductances(path.steps, rc.area())
                    .context("[conductance]")?
            }
            Model::Interacting(images) => {
                let t = Instant::now();
                let (h, info) = sum
                    .interacting(path.steps, rc.summits(), rc.extent(), images, &opts.memory)
                    .context("[conductance]")?;
                log!(
                    obs,
                    "conductance: {} conductance of interacting spots (Σ_j (δ_ij/G_i + I_ij) Q_j = ΔT, G = 4k1·a·ψ(a) per body, bodies in series, I_ij the layered point-source fields{}; {}) in {:.3} s",
                    spec.kind.name(),
                    match images {
                        Images::Periodic(_) => format!(
                            " with periodic images, k = 0 mode excluded, kernel table {}×{}",
                            info.grid.0, info.grid.1
                        ),
                        Images::Isolated => ", isolated sample".into(),
                    },
                    counterface_conduction(spec),
                    t.elapsed().as_secs_f64()
                );
                self.summary.definition = I_MODEL;
                self.summary.kernel = Some(KernelSummary {
                    grid: [info.grid.0, info.grid.1],
                    ewald_width: info.sigma,
                    spectrum_extent: info.rho_max,
                    self_images: info.self_images,
                });
                h
            }
        };
        let tcs = tc.elapsed().as_secs_f64();
        log_psi_cache(&sum.cache_log(), obs);
        self.summary.seconds = tcs;
        self.records = h
            .into_iter()
            .map(|conductance| ConductanceInfo {
                conductance,
                bem: None,
            })
            .collect();
        Ok(tcs)
    }

    fn truncate(&mut self, n: usize) {
        self.records.truncate(n);
    }

    fn finish(self: Box<Self>, solution: &mut SceneSolution) {
        solution.conductance = Some(self.records);
        solution.summary.conductance = Some(self.summary);
    }
}

/// One log line per ψ table of the conductance: read from the table cache, or built
/// (or extended) and written there; a table that could not be written is a warning
/// (the result is the same, the next run solves it again).
fn log_psi_cache(uses: &[strata_tablegen::psi_table::CacheUse], obs: &dyn Observer) {
    use strata_tablegen::psi_table::CacheUse;
    for u in uses {
        match u {
            CacheUse::Read => log!(obs, "conductance: ψ table read from the table cache"),
            CacheUse::Written { pieces: (k0, k1) } => log!(
                obs,
                "conductance: ψ table solved for a/h1 = {:.3e} … {:.3e} (8 Fredholm solves per decade, per half decade above 10) and kept in the table cache",
                10f64.powf(strata_runtime::constriction::piece_start(*k0)),
                10f64.powf(strata_runtime::constriction::piece_start(*k1))
            ),
            CacheUse::NotWritten(why) => progress::warn(format_args!(
                "conductance: the ψ table could not be kept in the table cache ({why}); it is solved again next time"
            )),
        }
    }
}
