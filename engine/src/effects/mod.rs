//! The effects beyond the paper's elastic contact, one module each: how a load-path
//! driver (the engine's `asperity` and `bem` modules) takes them in without
//! holding their code.
//!
//! - [`plasticity`]: a solver variant, chosen once when the driver is built (the BEM's
//!   capped response, the asperity models' capped tips), never an `if` in a loop;
//! - [`conductance`]: a [`StepObserver`] ([`observer`]) — prepared before the first step, called after
//!   each BEM step or once after an asperity model's path, its records moved into the
//!   solution at the end;
//! - [`stiffness`]: the BEM's dP/dδ after each step, the tangent on its contact set;
//! - [`friction`]: a [`StepObserver`], the full-stick tangential stiffness of every
//!   step (the N and I models' from the contact radii, the BEM's from each step's
//!   contact set) and, with `[load] tangential`, the BEM's tangential path after the
//!   last step.
//!
//! A new effect is a module here plus a field of the solution
//! ([`crate::solution::SceneSolution`]).

pub mod conductance;
pub mod friction;
pub mod observer;
pub mod plasticity;
pub mod stiffness;

use crate::error::Result;
use strata_bem::Geometry;
use strata_runtime::rough::Model;
use strata_runtime::surface::Surface;

use crate::scene::Scene;
use crate::setup::{EngineOptions, Observer};
pub use observer::{AsperityPath, BemStep, StepObserver, after_path, finish};

/// The observers of a scene solved by the BEM on an `n0 × n1` grid of `geometry`.
pub fn for_bem<'s>(
    scene: &'s Scene,
    grid: (usize, usize),
    geometry: Geometry,
    opts: &EngineOptions,
    obs: &dyn Observer,
) -> Result<Vec<Box<dyn StepObserver + 's>>> {
    let mut out: Vec<Box<dyn StepObserver + 's>> = Vec::new();
    if let Some(spec) = &scene.conductance {
        out.push(Box::new(conductance::BemConductance::prepare(
            scene, spec, grid, geometry, opts, obs,
        )?));
    }
    if let Some(spec) = scene.friction {
        out.push(Box::new(friction::BemFriction::prepare(
            scene, spec, grid, geometry,
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
    opts: &EngineOptions,
) -> Result<Vec<Box<dyn StepObserver + 's>>> {
    let mut out: Vec<Box<dyn StepObserver + 's>> = Vec::new();
    if let Some(spec) = &scene.conductance {
        out.push(Box::new(conductance::AsperityConductance::prepare(
            scene, spec, model, surface, opts,
        )?));
    }
    if let Some(spec) = scene.friction {
        out.push(Box::new(friction::AsperityFriction::new(scene, spec)));
    }
    Ok(out)
}
