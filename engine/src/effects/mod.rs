//! The effects beyond the paper's elastic contact, one module each: how a load-path
//! driver ([`crate::engine::asperity`], [`crate::engine::bem`]) takes them in without
//! holding their code.
//!
//! - [`plasticity`]: a solver variant, chosen once when the driver is built (the BEM's
//!   capped response, the asperity models' capped tips), never an `if` in a loop;
//! - [`conductance`]: a [`StepObserver`] — prepared before the first step, called after
//!   each BEM step or once after an asperity model's path, its records moved into the
//!   solution at the end;
//! - [`stiffness`]: the BEM's dP/dδ probe after each step.
//!
//! A new effect is a module here plus a field of the solution
//! ([`crate::solution::SceneSolution`]).

pub mod conductance;
pub mod plasticity;
pub mod stiffness;

use anyhow::Result;
use strata_bem::{BemSolution, Geometry};
use strata_runtime::rough::{Model, RoughContact, Step};
use strata_runtime::surface::Surface;

use crate::engine::{EngineOptions, Observer};
use crate::scene::Scene;
use crate::solution::SceneSolution;

/// What an observer sees of one solved BEM step.
pub struct BemStep<'a> {
    /// The step's name for errors (`load step 3`, `load.mean_pressures[1]`).
    pub name: &'a str,
    /// The step's pressure map, row-major n0 × n1 (Pa).
    pub pressure: &'a [f64],
    /// The stiffness probe's solution at δ + dδ ([`stiffness`]), warm-started from this
    /// step.
    pub probe: &'a BemSolution,
}

/// What an observer sees of an asperity model's solved load path.
pub struct AsperityPath<'a, 'l> {
    /// The solved steps (their contact radii, elastic or capped).
    pub steps: &'a [Step],
    /// The rough contact that solved them (summits, nominal area, extent).
    pub contact: &'a RoughContact<'l>,
    /// The N or I model.
    pub model: Model,
}

/// An effect that observes a load path.
pub trait StepObserver {
    /// After one solved BEM step (called in step order).
    fn after_step(&mut self, _step: &BemStep<'_>, _obs: &dyn Observer) -> Result<()> {
        Ok(())
    }
    /// After an asperity model's whole path; returns the time it took (s), counted in
    /// the solve's time.
    fn after_path(
        &mut self,
        _path: &AsperityPath<'_, '_>,
        _opts: &EngineOptions,
        _obs: &dyn Observer,
    ) -> Result<f64> {
        Ok(0.0)
    }
    /// The path stopped: only the first `n` steps stand.
    fn truncate(&mut self, _n: usize) {}
    /// Moves the records and the summary into the solution.
    fn finish(self: Box<Self>, solution: &mut SceneSolution);
}

/// The observers of a scene solved by the BEM on an `n0 × n1` grid of `geometry`.
pub fn for_bem<'s>(
    scene: &'s Scene,
    grid: (usize, usize),
    geometry: Geometry,
    obs: &dyn Observer,
) -> Result<Vec<Box<dyn StepObserver + 's>>> {
    let mut out: Vec<Box<dyn StepObserver + 's>> = Vec::new();
    if let Some(spec) = &scene.conductance {
        out.push(Box::new(conductance::BemConductance::prepare(
            scene, spec, grid, geometry, obs,
        )?));
    }
    Ok(out)
}

/// The observers of a scene solved by the N or I model, checked before any work (the I
/// model's conduction kernel against the sample).
pub fn for_asperities<'s>(
    scene: &'s Scene,
    model: Model,
    surface: &Surface,
) -> Result<Vec<Box<dyn StepObserver + 's>>> {
    let mut out: Vec<Box<dyn StepObserver + 's>> = Vec::new();
    if let Some(spec) = &scene.conductance {
        out.push(Box::new(conductance::AsperityConductance::prepare(
            scene, spec, model, surface,
        )?));
    }
    Ok(out)
}

/// Every observer after an asperity model's path; the total time (s).
pub fn after_path(
    observers: &mut [Box<dyn StepObserver + '_>],
    path: &AsperityPath<'_, '_>,
    opts: &EngineOptions,
    obs: &dyn Observer,
) -> Result<f64> {
    let mut seconds = 0.0;
    for o in observers.iter_mut() {
        seconds += o.after_path(path, opts, obs)?;
    }
    Ok(seconds)
}

/// Every observer's records into the solution.
pub fn finish(observers: Vec<Box<dyn StepObserver + '_>>, solution: &mut SceneSolution) {
    for o in observers {
        o.finish(solution);
    }
}
