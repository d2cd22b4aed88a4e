//! The load-path driver of `model.kind = "bem"` on a slab decomposition over several
//! processes (ranks; `mpirun -np P strata solve` with the `mpi` build): the
//! distributed boundary-element solve of [`strata_bem::SlabSolver`], each rank holding
//! and iterating on its own rows of the grid (heights, pressure and the iteration's
//! fields), the influence operator the distributed FFT product, every sum a global
//! reduction. Every rank calls [`solve`] together and gets the same load curve; the
//! caller's rank 0 writes it.
//!
//! The curve is the serial driver's ([`super::bem`]): the same load steps, the stiffness
//! dP/dδ probed after each step by one extra solve at δ + dδ warm-started from the
//! step's pressure ([`crate::effects::stiffness::StiffnessProbe`]), `contacts` the
//! number of contact patches (counted across the slab borders,
//! [`strata_bem::distributed::patch_sizes`]), and curve.json's resolution record
//! (median and largest patch, peak pressure). The iteration is Polonsky & Keer's
//! reference iteration, preconditioned ([`strata_bem::distributed`]), not the serial
//! solver's accelerated one: both stop on the same error ε ≤ `solver.tolerance`, so the
//! two curves agree to about the tolerance (to round-off once it is near 1e-13).
//!
//! Not distributed (refused, naming the scene field): `[plasticity]` (the capped
//! solve), `[conductance]`, `[friction]` and `[output] maps` (no rank holds a whole
//! map). The surface is read or generated whole on every rank, cut to the rank's rows
//! and dropped before the solver allocates its fields.

use std::time::Instant;

use crate::effects::stiffness::StiffnessProbe;
use crate::error::{Context, EngineError, Result};
use crate::progress;
use crate::scene::{MapsSpec, Scene};
use crate::setup::{
    EngineOptions, Observer, counterface_summary, load_surface, log, stack_description,
    surface_report,
};
use crate::solution::{CurveUnits, PartialSummary, SceneSolution, Summary};
use strata_bem::decomp::{self, Decomposition};
use strata_bem::{BemLoad, BemOptions, Geometry, SlabSolver};
use strata_runtime::Solid;
use strata_runtime::rough::Step;

use super::bem::{StepResolution, loads, resolution_summary, resolution_warnings, step_failure};

/// The scene fields the distributed solve does not handle, if `scene` has one: its
/// name and why (the first of `[plasticity]`, `[conductance]`, `[friction]`,
/// `[output] maps`).
pub fn not_distributed(scene: &Scene) -> Option<&'static str> {
    if scene.plasticity.is_some() {
        Some(
            "plasticity: the capped BEM ([plasticity]) is not distributed in this version; \
             solve the scene on one process (strata solve without mpirun, or mpirun -np 1)",
        )
    } else if scene.conductance.is_some() {
        Some(
            "conductance: the BEM's conductance ([conductance]) is not distributed in this \
             version; solve the scene on one process (strata solve without mpirun, or mpirun -np 1)",
        )
    } else if scene.friction.is_some() {
        Some(
            "friction: [friction] is computed by the asperity models only; the distributed \
             BEM has no tangential contact",
        )
    } else if scene.output.maps != MapsSpec::None {
        Some(
            "output.maps: the distributed BEM writes no maps (no rank holds a whole map); \
             remove [output] maps or solve the scene on one process (without mpirun)",
        )
    } else {
        None
    }
}

/// The BEM's solution of `scene` distributed over the ranks of `comm` (see the module
/// docs); every rank calls it together with the same scene and options, and gets the
/// same solution. Log lines go to `obs` (give rank 0 the console, the others a quiet
/// observer).
pub fn solve(
    scene: &Scene,
    comm: &dyn Decomposition,
    opts: &EngineOptions,
    obs: &mut dyn Observer,
) -> Result<SceneSolution> {
    if let Some(why) = not_distributed(scene) {
        return Err(EngineError::Input(why.to_string()));
    }
    let (ranks, rank) = (comm.size(), comm.rank());
    let surface = load_surface(scene, &opts.memory)?;
    if let Some(e) = surface.nothing_left() {
        return Err(e.into());
    }
    let (surface_report, mut warnings) = if rank == 0 {
        surface_report(&surface, obs)
    } else {
        (crate::solution::SurfaceReport::of(&surface), Vec::new())
    };
    let (n0, n1) = surface.shape();
    let periodic = surface.is_periodic();
    let (rows_side, cols_side) = surface.extent();
    let z_max = surface.heights().iter().copied().fold(f64::MIN, f64::max);
    let top_to_mean = z_max - surface.mean();
    let probe = StiffnessProbe::new(surface.rms());
    let geometry = Geometry {
        lx: cols_side,
        ly: rows_side,
        periodic,
    };
    // This rank's rows; the whole grid is dropped before the solver allocates.
    let mine = decomp::slab(n0, ranks, rank);
    let own: Vec<f64> = surface.heights()[mine.start * n1..mine.end * n1].to_vec();
    drop(surface);
    let stack = &scene.bodies;
    let t0 = Instant::now();
    let bem_options = BemOptions {
        memory: opts.memory,
        ..scene.solver.bem_options(opts.bem.unwrap_or_default())
    };
    let solver = SlabSolver::new(comm, (n0, n1), geometry, stack, bem_options, |i, row| {
        let r = i - mine.start;
        row.copy_from_slice(&own[r * n1..(r + 1) * n1]);
    })
    .context("model.kind = \"bem\"")?;
    drop(own);
    let solid = if stack.is_homogeneous() {
        "homogeneous solid (kernel 2/(E*|k|))".to_string()
    } else {
        format!(
            "layered solid ({} layers; kernel 2S(|k|)/(E*₁|k|) with S computed from the stack)",
            stack.first.layers().len()
        )
    };
    let kind = if periodic {
        "periodic".to_string()
    } else {
        "non-periodic (isolated sample on an unbounded solid: zero-padded convolution with pixel influence coefficients)".to_string()
    };
    let described = format!(
        "full-field boundary elements on the {n0}×{n1} grid, {kind}, distributed over {ranks} MPI ranks (slabs of rows)"
    );
    log!(obs, "simulating: {described}; {solid}");
    log!(
        obs,
        "distributed BEM: rank 0 holds rows {}..{} of {n0}; not distributed (refused): [plasticity], [conductance], [friction], [output] maps",
        mine.start,
        mine.end
    );
    let loads = loads(scene, top_to_mean)?;
    let area = solver.area();
    let e_star = solver.e_star1();
    let total = loads.len();
    let bar = (!obs.quiet()).then(|| {
        progress::bar(
            total as u64,
            format!("BEM {n0}×{n1} on {ranks} ranks: load steps"),
        )
    });
    let mut steps: Vec<Step> = Vec::with_capacity(total);
    let mut resolution: Vec<StepResolution> = Vec::with_capacity(total);
    let mut worst_error = 0.0f64;
    let mut failed = None;
    let mut p = vec![0.0; mine.len() * n1];
    let mut warm = false;
    for (k, (name, load)) in loads.into_iter().enumerate() {
        opts.cancel.check()?;
        let mut one_step = || -> Result<()> {
            let step = solver
                .solve_step(load, &mut p, warm)
                .with_context(|| name.clone())?;
            // The stiffness probe: δ + dδ from the step's pressure.
            let dd = probe.increment(step.approach);
            let mut q = p.clone();
            let next = solver
                .solve_step(BemLoad::Approach(step.approach + dd), &mut q, true)
                .with_context(|| format!("{name}: stiffness"))?;
            drop(q);
            let (load_now, load_next) = (step.mean_pressure * area, next.mean_pressure * area);
            let sizes = solver.patch_sizes(&p);
            let mut peak = [p.iter().copied().fold(0.0, f64::max)];
            decomp::max(comm, &mut peak);
            resolution.push(StepResolution {
                median_patch_pixels: strata_bem::median_patch_size(&sizes),
                largest_patch_pixels: sizes.iter().copied().max().unwrap_or(0),
                peak_pressure: peak[0],
            });
            worst_error = worst_error.max(step.error).max(next.error);
            let mut st = Step::default();
            st.delta = step.approach;
            st.gap = step.separation;
            st.load = load_now;
            st.mean_pressure = step.mean_pressure;
            st.pressure_ratio = step.mean_pressure / e_star;
            st.area_fraction = step.area_fraction;
            st.contacts = sizes.len();
            st.stiffness = (load_next - load_now) / dd;
            st.iterations = step.iterations;
            steps.push(st);
            warm = step.contact_points > 0;
            Ok(())
        };
        match one_step() {
            Ok(()) => {}
            Err(e) if opts.cancel.is_cancelled() || k == 0 || !opts.keep_partial => {
                return Err(e);
            }
            Err(e) => {
                steps.truncate(k);
                resolution.truncate(k);
                failed = Some(step_failure(obs, &name, k, load, top_to_mean, &e));
                break;
            }
        }
        if let Some(b) = &bar {
            b.inc();
        }
    }
    drop(bar);
    let seconds = t0.elapsed().as_secs_f64();
    log!(obs, "BEM: largest final CG error {worst_error:.2e}");
    for w in resolution_warnings(&resolution, e_star, false) {
        if rank == 0 {
            progress::warn(format_args!("{w}"));
        }
        warnings.push(w);
    }
    let summary = Summary {
        scene: String::new(),
        model: described,
        model_short: "BEM".into(),
        stack: stack_description(stack),
        solid,
        e_star_1: e_star,
        nominal_area: area,
        summits: None,
        z_max_minus_mean: top_to_mean,
        surface: surface_report,
        warnings,
        bem_final_error: Some(worst_error),
        seconds,
        units: CurveUnits::bem(),
        resolution: Some(resolution_summary(&resolution, e_star)),
        counterface: counterface_summary(scene),
        plasticity: None,
        conductance: None,
        friction: None,
        partial: failed.as_ref().map(PartialSummary::of),
    };
    Ok(SceneSolution {
        steps,
        plastic: None,
        conductance: None,
        tangential: None,
        tangential_path: None,
        summary,
        seconds,
        failed,
    })
}
