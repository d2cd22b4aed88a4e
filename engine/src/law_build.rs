//! The N and I models' contact law from inputs in memory — a stack, a surface, a table,
//! the model, the solver's parameters and the law's effects (a hardness, a
//! conductance) — for front ends that hold no scene file (the C ABI). It states them as
//! the engine's input, a [`Scene`] ([`scene_of`]), and samples the law with the function
//! behind `strata law` ([`crate::sampled_law::solve_asperities`]): the same spot sums,
//! capped curves, caches and numbers as the command, because they are the same code.

use std::sync::Arc;

use crate::error::Result;
use strata_runtime::rough::{Images, Model, Params};
use strata_runtime::surface::{ReadOptions, Surface};
use strata_runtime::table::Table;
use strata_runtime::{Bodies, Solid};

use crate::sampled_law::SampledLaw;
use crate::scene::{
    ConductanceSpec, FrictionSpec, LoadSpec, ModelKind, ModelSpec, OutputSpec, PlasticitySpec,
    Scene, SolverSpec, SurfaceSource, SurfaceSpec,
};
use crate::setup::EngineOptions;

/// What the law's solution is named as in its summary (there is no scene file).
pub const IN_MEMORY: &str = "(inputs in memory)";

/// The effects of a law beyond the elastic asperity models.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LawEffects {
    /// The hardness H (Pa) that caps every asperity tip's contact pressure
    /// (elastic–perfectly plastic tips, physics.md §6.3); `None` for elastic tips.
    pub hardness: Option<f64>,
    /// The interface conductance h_c to solve at every sample (physics.md §6.2): its kind
    /// and how the counterface conducts.
    pub conductance: Option<ConductanceSpec>,
    /// The coefficient of friction: with it, the full-stick tangential stiffness K_t of
    /// the sample at every sample (the engine's `effects::friction`).
    pub friction: Option<FrictionSpec>,
}

/// A law's inputs in memory.
#[derive(Debug, Clone)]
pub struct LawInputs<'a> {
    /// The first body and its counterface ([`Bodies`]; its mechanics: how a rigid flat
    /// conducts is the effects' [`ConductanceSpec`]).
    pub stack: &'a Bodies,
    /// The rough surface (heights as the first body sees them).
    pub surface: Surface,
    /// The surrogate table serving a layered stack (the pair's, with an elastic
    /// counterface); `None` for a homogeneous one (Hertz asperities). A layered stack
    /// without a table has one built into the table cache (minutes).
    pub table: Option<Arc<Table>>,
    /// The N or I model.
    pub model: Model,
    /// The asperity models' budgets and tolerances, and the cancellation token.
    pub params: Params,
}

pub use crate::effects::plasticity::UncoveredSummit;

/// The scene that states `inputs` (but the surface and the table, which are passed
/// in memory) with `effects`: the model and its images, the solver's parameters, the
/// `[plasticity]` and `[conductance]` of the effects, and the separations `load` (the
/// sampler replaces them with its own). No file is named: the surface is never read
/// from the scene, and its summary names the inputs [`IN_MEMORY`].
pub fn scene_of(
    stack: &Bodies,
    model: Model,
    params: &Params,
    effects: &LawEffects,
    load: LoadSpec,
) -> Scene {
    let (kind, images) = match model {
        Model::Independent => (ModelKind::Independent, Images::Periodic(2)),
        Model::Interacting(images) => (ModelKind::Interacting, images),
    };
    Scene {
        bodies: stack.bodies(),
        stack_file: None,
        counterface_file: None,
        table: None,
        surface: SurfaceSpec {
            source: SurfaceSource::File(IN_MEMORY.into()),
            read: ReadOptions::default(),
            topography: None,
        },
        model: ModelSpec { kind, images },
        load,
        output: OutputSpec::default(),
        solver: SolverSpec {
            max_step_newton_steps: Some(params.max_step_newton_steps),
            max_step_evaluations: Some(params.max_step_evaluations),
            kkt_tolerance: Some(params.kkt_tolerance),
            max_pressure_iterations: Some(params.max_pressure_iterations),
            bem_max_iterations: None,
            bem_tolerance: None,
        },
        plasticity: effects.hardness.map(|hardness| PlasticitySpec { hardness }),
        unload: false,
        conductance: effects.conductance,
        friction: effects.friction,
        tangential: None,
    }
}

/// The contact law of `inputs` with `effects`: `samples` separations from first contact
/// down to `min_gap` (m), by the N or I model — `strata law`'s sampler on the scene
/// [`scene_of`] states: with a hardness the capped model's loading curve, with a
/// conductance h_c at every sample (the capped tips' spots with both). The capped
/// asperity's response tables and the ψ tables of layered conducting stacks are kept in
/// the table cache `cache_dir` (`None`: [`crate::cache::dir`]'s default), as the
/// command keeps them. Quiet (`EngineOptions::quiet`); the sampler's few remaining log
/// lines and warnings go through [`crate::progress`], so a caller collects or drops them
/// with [`crate::progress::scoped`] (the C ABI drops them).
pub fn sample_asperity_law(
    inputs: LawInputs<'_>,
    effects: &LawEffects,
    samples: usize,
    min_gap: f64,
    cache_dir: Option<std::path::PathBuf>,
) -> Result<SampledLaw> {
    let scene = scene_of(
        inputs.stack,
        inputs.model,
        &inputs.params,
        effects,
        LoadSpec::Separations(vec![min_gap]),
    );
    let opts = EngineOptions {
        cache_dir,
        table: inputs.table,
        cancel: inputs.params.cancel.clone(),
        memory: inputs.params.memory,
        ..Default::default()
    };
    crate::sampled_law::solve_asperities(
        &scene,
        inputs.surface,
        &opts,
        &mut crate::setup::Quiet,
        inputs.model,
        samples,
        Some(min_gap),
    )
}
