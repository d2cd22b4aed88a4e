//! Scene solving shared by every front end (`solve`, `law`, `sweep`, `compare`, `study`,
//! the Python package): a validated [`Scene`] in, a typed [`SceneSolution`] out — the
//! load curve ([`Step`]s), one record per step for each effect the scene asked for, and
//! the summary that `curve.json` holds. No files are written and no JSON is made here;
//! the callers own their outputs.
//!
//! One entry, [`solve`], dispatches once on the model kind to a load-path driver:
//! [`asperity`] (the N and I models) or [`bem`] (the full-field solver). The drivers
//! hold no effect code: plasticity is a solver variant chosen when the driver is built
//! ([`crate::effects::plasticity`]), conductance observes each step and the BEM's
//! stiffness is its tangent ([`crate::effects::conductance`], [`crate::effects::stiffness`]). Logging,
//! progress and the BEM maps go to an [`Observer`].
//!
//! Only what the scene needs is computed: a homogeneous stack loads no table
//! (χ = ζ = 1, g = 0); a layered stack loads `stack.table` or builds the table once
//! into the cache and says so; the independent model forms no pairs; the BEM needs no
//! table (S is computed from the stack). The log (stderr, unless quiet) says which
//! effects were simulated.

pub mod asperity;
pub mod bem;
pub mod distributed;
pub mod elastic;
pub mod rows;

use crate::error::Result;
use strata_runtime::rough::Model;
use strata_runtime::surface::Surface;

use crate::scene::{ModelKind, Scene};
pub use crate::setup::*;

/// Solves a scene with the model it names on `surface` (or the scene's own surface,
/// read or generated now, when `None`: the Python package passes surfaces built in
/// memory). The one entry of every front end: it dispatches once on the model kind to
/// the load-path driver ([`asperity::solve`] for the N and I models, [`bem::solve`]).
/// The summary's `scene` is left empty for the front end to name.
pub fn solve(
    scene: &Scene,
    surface: Option<Surface>,
    opts: &EngineOptions,
    obs: &mut dyn Observer,
) -> Result<SceneSolution> {
    let surface = match surface {
        Some(s) => s,
        None => load_surface(scene, &opts.memory)?,
    };
    if let Some(e) = surface.nothing_left() {
        return Err(e.into());
    }
    match scene.model.kind {
        ModelKind::Independent => asperity::solve(scene, surface, opts, obs, Model::Independent),
        ModelKind::Interacting => asperity::solve(
            scene,
            surface,
            opts,
            obs,
            Model::Interacting(scene.model.images),
        ),
        ModelKind::Bem => bem::solve(scene, surface, opts, obs),
    }
}
