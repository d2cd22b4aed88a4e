//! The contact law of capped asperity tips (physics.md §6.3 and §9): the
//! loading curve of the N or I model whose summits are elastic–perfectly plastic
//! paraboloids (contact pressure ≤ the hardness H), as `strata law` samples a scene
//! with `[plasticity]` and model independent or interacting (the `strata` crate's
//! `sampled_law::solve_capped_asperities` and `engine::solve_plastic_asperities`,
//! followed operation for operation: the same law bit for bit, checked by
//! `capi/tests/c_example.rs`).
//!
//! The capped asperity's response table for the stack and H (ring solves,
//! `strata_tablegen::plastic_asperity::response`; ~18 CPU-s on a layered stack, less
//! than a second on a half-space) takes every summit through its response: the N model
//! summit by summit, the I model from the elastic I model's step at the same approach
//! with the interactions through the far field of the summits' actual loads (the
//! elastic step itself where no summit yields): `RoughContact::capped_curve`, the one
//! the engine runs. Loading only: the asperity models keep no unloading branch.

use strata_runtime::Stack;
use strata_runtime::interface::{InterfaceError, InterfaceLaw, sample_bytes, sample_gaps};
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::resources::{ResourceError, check_memory};
use strata_runtime::rough::plastic::hardness_problem;
use strata_runtime::rough::{Model, Params, RoughContact, RoughError, Step};
use strata_runtime::surface::Surface;
use strata_tablegen::plastic_asperity::{PlasticAsperityError, RESPONSE_Y, response};
use thiserror::Error;

/// Errors of the capped law.
#[derive(Debug, Error)]
pub enum CappedError {
    /// The hardness is refused by the capped asperity (or its ring solve failed).
    #[error("{0}")]
    Response(PlasticAsperityError),
    /// The hardness lies outside its admissible range.
    #[error("{0}")]
    Hardness(String),
    /// A summit loaded past the response table's lower end (x = δ/δ_c ≥ 0.01) yields
    /// outside its range of a_c/h₁.
    #[error(
        "a summit of radius {radius:e} m is loaded past 0.01 δ_c (δ_c = (πH/2E*)²R, the table's \
         lower end) and yields at a contact radius a_c = πHR/(2E*) of {y:.3e} h1, \
         outside the capped asperity's table (a_c/h1 in [{lo:e}, {hi:e}]): the hardness is too \
         high for this stack's top layer to be treated this way",
        lo = RESPONSE_Y.0,
        hi = RESPONSE_Y.1
    )]
    Uncovered { radius: f64, y: f64 },
    /// The smallest separation is not below first contact.
    #[error("{min_gap:e} m must lie below the first-contact separation {first_contact:e} m")]
    MinGap { min_gap: f64, first_contact: f64 },
    /// A rough-contact solve failed.
    #[error("{0}")]
    Rough(#[from] RoughError),
    /// A capped step failed.
    #[error("load step {step}: {error}")]
    Step { step: usize, error: RoughError },
    /// The samples do not make a law.
    #[error("capped load curve: {0}")]
    Interface(#[from] InterfaceError),
    /// The law's memory estimate exceeds the limit.
    #[error("{0}")]
    Resource(#[from] ResourceError),
}

/// A capped law with the steps it was sampled from.
pub struct CappedLaw {
    /// The loading curve.
    pub law: InterfaceLaw,
    /// The capped steps at the samples' separations, first contact first.
    pub steps: Vec<Step>,
    /// The samples' separations (m), in the steps' order.
    pub gaps: Vec<f64>,
}

/// The capped law of `surface` on `stack` with hardness `hardness` (Pa, finite > 0):
/// `samples` separations from first contact down to `min_gap` (m), by `model`; `law` is
/// the elastic asperity law of the stack (the I model's interactions and elastic
/// steps), `params` the solver's. The steps come with it (their contact radii are the
/// spots of the conductance, as `strata law` takes them).
pub fn capped_law(
    law: &dyn AsperityLaw,
    stack: &Stack,
    surface: &Surface,
    model: Model,
    hardness: f64,
    (min_gap, samples): (f64, usize),
    params: Params,
) -> Result<CappedLaw, CappedError> {
    // first contact and the area need no elastic law
    let hom = Homogeneous {
        e_star: stack.contact_modulus(),
    };
    let first = RoughContact::from_surface(&hom, surface)?;
    let (g0, nominal_area) = (first.top_to_mean(), first.area());
    if min_gap.is_nan() || min_gap >= g0 {
        return Err(CappedError::MinGap {
            min_gap,
            first_contact: g0,
        });
    }
    check_memory(
        format!(
            "the capped contact law ({samples} samples of {} summits)",
            first.summits().len()
        ),
        sample_bytes(samples, first.summits().len()),
    )?;
    let gaps = sample_gaps(g0, min_gap, samples);
    if let Some(why) = hardness_problem(hardness) {
        return Err(CappedError::Hardness(why));
    }
    // the elastic law: the I model's interactions, and every summit below the table
    let rc = RoughContact::from_surface(law, surface)?.with_params(params);
    let deltas: Vec<f64> = gaps.iter().map(|&g| rc.top_to_mean() - g).collect();
    let e_star = stack.contact_modulus();
    // every summit below the response table's range on the whole path: the elastic
    // model's curve is the capped one, no table needed (the engine's rule)
    if rc
        .first_summit_past_elastic(e_star, hardness, &deltas)
        .is_none()
    {
        let steps = match model {
            Model::Independent => Some(rc.curve(model, &deltas)?),
            Model::Interacting(_) => {
                let steps = rc.curve(model, &deltas)?;
                steps
                    .iter()
                    .all(|s| rc.elastic_i_step_below_table(s, e_star, hardness))
                    .then_some(steps)
            }
        };
        if let Some(steps) = steps {
            if let Some(s) = steps.iter().find(|s| s.area_fraction > 1.0) {
                return Err(CappedError::Rough(RoughError::AreaAboveNominal {
                    delta: s.delta,
                    area: s.area_fraction,
                    interacting: matches!(model, Model::Interacting(_)),
                }));
            }
            return Ok(CappedLaw {
                law: InterfaceLaw::from_steps(&steps, nominal_area)?,
                steps,
                gaps,
            });
        }
    }
    if let Some(h1) = stack.top_thickness().filter(|_| !stack.is_homogeneous()) {
        // a summit loaded past the table's lower end outside its y range: refused
        // before the table is built
        if let Some((radius, y)) = rc
            .summits_past_elastic(e_star, hardness, &deltas)
            .map(|(_, r)| (r, std::f64::consts::PI * hardness * r / (2.0 * e_star) / h1))
            .find(|&(_, y)| {
                !(RESPONSE_Y.0 * (1.0 - 1e-9)..=RESPONSE_Y.1 * (1.0 + 1e-9)).contains(&y)
            })
        {
            return Err(CappedError::Uncovered { radius, y });
        }
    }
    let resp = response(stack, hardness).map_err(CappedError::Response)?;
    let steps: Vec<_> = rc
        .capped_curve(&resp, model, &deltas)
        .map_err(|(step, error)| CappedError::Step { step, error })?
        .into_iter()
        .map(|(s, _)| s)
        .collect();
    Ok(CappedLaw {
        law: InterfaceLaw::from_steps(&steps, nominal_area)?,
        steps,
        gaps,
    })
}
