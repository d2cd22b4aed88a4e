//! The load-path driver of the asperity models (N: independent, I: interacting
//! asperities, physics.md §§3–5): the scene's approaches (or mean pressures) through the
//! runtime's `RoughContact`, with the tips chosen once — elastic ([`super::elastic::ElasticTips`]) or
//! capped at the hardness ([`crate::effects::plasticity::CappedTips`]) — and the
//! effects that observe the path ([`crate::effects`]) after it. No effect code here.

use crate::error::{Result, bail_input};
use strata_runtime::rough::Model;
use strata_runtime::surface::Surface;

use super::elastic::{AsperityCurve, ElasticTips};
use crate::effects::observer::finish;
use crate::effects::plasticity::CappedTips;
use crate::scene::Scene;
use crate::setup::{EngineOptions, Observer, counterface_summary};
use crate::solution::{PartialSummary, SceneSolution};

/// The N or I model's solution of `scene` on `surface`: the effects' observers prepared
/// (the I model's conduction kernel checked before any work), the tips chosen once,
/// the path solved, the observers' records moved into the solution.
pub fn solve(
    scene: &Scene,
    surface: Surface,
    opts: &EngineOptions,
    obs: &mut dyn Observer,
    model: Model,
) -> Result<SceneSolution> {
    let obs: &dyn Observer = obs;
    let mut observers = crate::effects::for_asperities(scene, model, &surface, opts)?;
    if scene.unload {
        bail_input!(
            "load.unload is solved by the BEM in this version (model.kind = \"bem\"); the N and \
             I models with [plasticity] follow the loading path only"
        );
    }
    let tips: Box<dyn AsperityCurve> = match scene.plasticity {
        Some(pl) => Box::new(CappedTips {
            hardness: pl.hardness,
        }),
        None => Box::new(ElasticTips),
    };
    let mut sol = tips.solve(scene, surface, opts, obs, model, &mut observers)?;
    finish(observers, &mut sol);
    sol.summary.counterface = counterface_summary(scene);
    if let Some(f) = &sol.failed {
        sol.summary.partial = Some(PartialSummary::of(f));
    }
    Ok(sol)
}
