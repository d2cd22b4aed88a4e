//! How an effect observes a load path: what it sees of a solved BEM step or asperity
//! path ([`BemStep`], [`AsperityPath`]) and the [`StepObserver`] interface, with the
//! two calls the drivers make over all observers ([`after_path`], [`finish`]). A leaf
//! under the drivers and the effects.

use crate::error::Result;
use strata_runtime::rough::{Model, RoughContact, Step};

use crate::setup::{EngineOptions, Observer};
use crate::solution::SceneSolution;

/// What an observer sees of one solved BEM step.
pub struct BemStep<'a> {
    /// The step's name for errors (`load step 3`, `load.mean_pressures[1]`).
    pub name: &'a str,
    /// The step's pressure map, row-major n0 × n1 (Pa).
    pub pressure: &'a [f64],
    /// The pressure rate Δp = dp/dδ on the step's contact set (Pa/m, row-major n0 × n1,
    /// 0 elsewhere): the tangent of [`crate::effects::stiffness`].
    pub pressure_rate: &'a [f64],
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
    /// After a BEM path whose every step converged (not after a partial one), before
    /// [`StepObserver::finish`]: the work on the path's last state (the tangential path
    /// of `[load] tangential`).
    fn after_bem_path(&mut self, _obs: &dyn Observer) -> Result<()> {
        Ok(())
    }
    /// The path stopped: only the first `n` steps stand.
    fn truncate(&mut self, _n: usize) {}
    /// Moves the records and the summary into the solution.
    fn finish(self: Box<Self>, solution: &mut SceneSolution);
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
