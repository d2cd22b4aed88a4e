//! Solver parameters ([`Params`]) and per-solve diagnostics ([`Diagnostics`]) of the
//! rough-contact models. Every tolerance of the solvers is a field here; the defaults
//! are the values the accuracy tests and the README figures were measured with.

/// Tolerances and limits of the rough-contact solvers. Relative tolerances of the I
/// model are in units of the largest interference δ_max = max_k δ_k of the step (m).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Params {
    /// Far-field model of the interaction sums: largest error of every modelled G and
    /// ∂G/∂a relative to the point-force displacement (4/3)χa³/(πRr) and its
    /// a-derivative (interacting module docs). 0 sums every image pair exactly.
    /// Default 3e-5: half the accuracy of the surrogate tables' g itself (~6e-5 of that
    /// scale, their `interp_error.g`), whose C¹ interpolant is smooth in a only to ~1e-5
    /// (on the shipped table a 12-node interpolant in a meets 5e-6 only beyond
    /// r ≈ 5A, 1.5e-5 at every r ≥ 1.1A).
    pub far_field_tolerance: f64,
    /// Periodic images on an elastic base: remove the uniform mode of the image sums as
    /// the periodic BEM does (physics.md §5, `rough::interacting::uniform`), so that the
    /// I model's pressure converges as the image block grows and δ is the mean-plane
    /// approach; summits below the rigid plane become candidates (the surface between
    /// contacts rises) and a contact radius past half the cell is refused
    /// ([`NewtonError::CoversCell`](crate::rough::NewtonError::CoversCell)). Rigid
    /// bases are unaffected (their sums converge). Default true; false gives the raw
    /// image sums of earlier releases, which depend on the block's size.
    pub zero_mean_images: bool,
    /// Bound A of the far-field model as a multiple of the largest N-model (or warm
    /// start) contact radius of the solve (interactions shrink contacts). Default 1.2.
    pub far_field_bound_factor: f64,
    /// Loaded asperities above which the I model holds its far-field pair sums on an
    /// FFT grid with sparse near corrections (memory O(N), Newton steps by conjugate
    /// gradients) instead of the dense per-pair coefficients and Jacobian (memory
    /// O(N²)); below it the dense path is faster. Needs the `spectral` feature (else
    /// always dense). Default 1500.
    pub dense_pair_limit: usize,
    /// How often a solve may rebuild the far-field model with a larger bound A when a
    /// contact radius leaves it before the last rebuild sums exactly. Default 3.
    pub far_field_rebuilds: usize,
    /// KKT acceptance: a step is converged when every active |F_k| and every inactive
    /// −F_k(0⁺) is below this × δ_max. Default 1e-8.
    pub kkt_tolerance: f64,
    /// Newton target: |F_k| ≤ this × δ_max on the active set ends a Newton round.
    /// Default 1e-11.
    pub newton_tolerance: f64,
    /// Newton target of the grid path (Newton steps by conjugate gradients, above
    /// [`Params::dense_pair_limit`]), where the last Newton step of a round costs tens of
    /// evaluations of the interaction sums: |F_k| ≤ this × δ_max. Default 1e-9 (ten
    /// times below the KKT acceptance; the stiffness solve is unchanged).
    pub iterative_newton_tolerance: f64,
    /// Round-off floor: when |F| ≤ this × δ_max and no step decreases the merit, the
    /// Newton round stops instead of crawling (differenced derivatives limit F). Default
    /// 1e-9.
    pub round_off_floor: f64,
    /// Activation rounds (activate violated asperities, then Newton) per search.
    /// Default 100.
    pub max_activation_rounds: usize,
    /// Newton steps per activation round. Default 100.
    pub max_newton_steps: usize,
    /// Line-search halvings per Newton step. Default 40.
    pub max_backtracks: usize,
    /// Armijo constant of the line search on U_E (and on Σ F² in the restart).
    /// Default 1e-4.
    pub armijo: f64,
    /// A trial radius below this fraction of its previous value leaves the contact.
    /// Default 1e-9.
    pub drop_fraction: f64,
    /// An inactive asperity's F_k(0⁺) is evaluated at this fraction of its Hertz radius
    /// √(R_k δ_k). Default 1e-6.
    pub activation_probe: f64,
    /// Smallest start radius of an activated asperity, as a fraction of √(R_k δ_k).
    /// Default 1e-3.
    pub activation_start: f64,
    /// Relative step of the central differences of g in a (∂g/∂a, ∂²g/∂a²).
    /// Default 1e-5.
    pub g_difference_step: f64,
    /// Relative step of the central differences of the Jacobian diagonal. Default 1e-6.
    pub jacobian_difference_step: f64,
    /// Budget of one I-model step: most Newton steps over all rounds and searches
    /// (beyond it the step fails with [`crate::rough::NewtonError::Budget`] instead of
    /// crawling). Default 20 000 (the most two searches of
    /// [`Params::max_activation_rounds`] × [`Params::max_newton_steps`] can take; converged
    /// steps take 1–30, a step on overlapping contacts up to a few thousand).
    pub max_step_newton_steps: usize,
    /// Budget of one I-model step: most evaluations of the energy state (F, U_E) over
    /// all rounds, line searches and searches (beyond it the step fails with
    /// [`crate::rough::NewtonError::Budget`]). Counted work, not time: a solve gives the
    /// same result, and fails at the same point, on a loaded machine as on an idle one
    /// (it replaces the wall-clock `step_time_budget` of earlier releases, which failed
    /// valid steps on loaded machines). Default 100 000 (5 per Newton step of
    /// [`Params::max_step_newton_steps`]); [`Diagnostics::evaluations`] says what a step
    /// used.
    pub max_step_evaluations: usize,
    /// Pressure control of the I model: relative tolerance on the mean pressure.
    /// Default 1e-8: the I-model solve itself is accurate to its KKT acceptance
    /// ([`Params::kkt_tolerance`], 1e-8 of δ_max), which moves p_n by a few 1e-9.
    pub pressure_tolerance: f64,
    /// Pressure control of the N model (cheap and exact to round-off): relative tolerance
    /// on the mean pressure, tighter so that its steps reproduce the target for
    /// comparisons at equal pressure. Default 1e-13.
    pub independent_pressure_tolerance: f64,
    /// Pressure control: most solves of the search. Default 200.
    pub max_pressure_iterations: usize,
    /// Cooperative cancellation, checked before every load step and Newton step of
    /// the I model ([`crate::cancel`]). Default: never cancelled. Carries no physics.
    pub cancel: crate::cancel::Cancel,
    /// The memory limit the I model's pair storage and conduction network are checked
    /// against before they are allocated ([`crate::resources`]). Default: 75 % of the
    /// machine's memory. Carries no physics.
    pub memory: crate::resources::MemoryLimit,
}

/// A solver parameter outside its range ([`Params::validate`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("solver parameter `{field}` = {value}: must be {requirement}")]
#[non_exhaustive]
pub struct ParamsError {
    /// The field of [`Params`].
    pub field: &'static str,
    /// Its value (counts as reals).
    pub value: f64,
    /// The range it must lie in.
    pub requirement: &'static str,
}

impl Params {
    /// Checks every field against its range, naming the first that is outside it:
    /// tolerances, the Armijo constant and the difference steps in (0, 1) (the far-field
    /// tolerance and the drop fraction in [0, 1): 0 means exact sums, never dropping);
    /// the activation probe and start in (0, 1]; the far-field bound factor finite and
    /// ≥ 1 (A bounds the N-model radii); every iteration cap and budget ≥ 1. The
    /// defaults pass. The solvers do not call it: an embedder that sets fields calls it
    /// once, before solving.
    pub fn validate(&self) -> Result<(), ParamsError> {
        let bad = |field, value, requirement| {
            Err(ParamsError {
                field,
                value,
                requirement,
            })
        };
        let open01 = "in (0, 1)";
        for (field, v) in [
            ("kkt_tolerance", self.kkt_tolerance),
            ("newton_tolerance", self.newton_tolerance),
            (
                "iterative_newton_tolerance",
                self.iterative_newton_tolerance,
            ),
            ("round_off_floor", self.round_off_floor),
            ("armijo", self.armijo),
            ("g_difference_step", self.g_difference_step),
            ("jacobian_difference_step", self.jacobian_difference_step),
            ("pressure_tolerance", self.pressure_tolerance),
            (
                "independent_pressure_tolerance",
                self.independent_pressure_tolerance,
            ),
        ] {
            if !(v > 0.0 && v < 1.0) {
                return bad(field, v, open01);
            }
        }
        for (field, v) in [
            ("far_field_tolerance", self.far_field_tolerance),
            ("drop_fraction", self.drop_fraction),
        ] {
            if !(0.0..1.0).contains(&v) {
                return bad(field, v, "in [0, 1)");
            }
        }
        for (field, v) in [
            ("activation_probe", self.activation_probe),
            ("activation_start", self.activation_start),
        ] {
            if !(v > 0.0 && v <= 1.0) {
                return bad(field, v, "in (0, 1]");
            }
        }
        let b = self.far_field_bound_factor;
        if !(b.is_finite() && b >= 1.0) {
            return bad("far_field_bound_factor", b, "finite and >= 1");
        }
        for (field, v) in [
            ("max_activation_rounds", self.max_activation_rounds),
            ("max_newton_steps", self.max_newton_steps),
            ("max_step_newton_steps", self.max_step_newton_steps),
            ("max_step_evaluations", self.max_step_evaluations),
            ("max_pressure_iterations", self.max_pressure_iterations),
        ] {
            if v == 0 {
                return bad(field, v as f64, ">= 1");
            }
        }
        Ok(())
    }
}

impl Default for Params {
    fn default() -> Self {
        Params {
            far_field_tolerance: 3e-5,
            zero_mean_images: true,
            far_field_bound_factor: 1.2,
            dense_pair_limit: 1500,
            far_field_rebuilds: 3,
            kkt_tolerance: 1e-8,
            newton_tolerance: 1e-11,
            iterative_newton_tolerance: 1e-9,
            round_off_floor: 1e-9,
            max_activation_rounds: 100,
            max_newton_steps: 100,
            max_backtracks: 40,
            armijo: 1e-4,
            drop_fraction: 1e-9,
            activation_probe: 1e-6,
            activation_start: 1e-3,
            g_difference_step: 1e-5,
            jacobian_difference_step: 1e-6,
            max_step_newton_steps: 20_000,
            max_step_evaluations: 100_000,
            pressure_tolerance: 1e-8,
            independent_pressure_tolerance: 1e-13,
            max_pressure_iterations: 200,
            cancel: crate::cancel::Cancel::default(),
            memory: crate::resources::MemoryLimit::default(),
        }
    }
}

/// The far-field model a solve used (interacting module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FarFieldInfo {
    /// Bound A on the contact radii (m).
    pub bound: f64,
    /// Cut-off r_c (m): image pairs closer than this are summed exactly.
    pub cutoff: f64,
    /// Largest error measured when the model was built (point-force units).
    pub measured_error: f64,
    /// Image pairs summed exactly.
    pub exact_pairs: usize,
    /// Image pairs summed by the far-field model.
    pub modelled_pairs: usize,
    /// Cells (x, y) of the FFT grid carrying the far field ((0, 0): dense pair sums,
    /// [`Params::dense_pair_limit`]).
    pub grid_cells: (usize, usize),
    /// Radius (m) within which the grid's pairs are corrected exactly (0: dense).
    pub near_radius: f64,
}

/// What one solve did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Diagnostics {
    /// Newton steps (all rounds, all searches).
    pub newton_steps: usize,
    /// Activation rounds.
    pub activation_rounds: usize,
    /// Line-search halvings.
    pub backtracks: usize,
    /// Evaluations of the energy state (F, U_E).
    pub evaluations: usize,
    /// Searches restarted from the N-model radii on the merit Σ F².
    pub restarts: usize,
    /// Far-field models built for this step (rebuilds with a larger bound included).
    pub far_field_builds: usize,
    /// The far-field model of the final solve (None: exact sums).
    pub far_field: Option<FarFieldInfo>,
    /// Wall time of the step (s): reported only, never a limit (budgets count work).
    pub seconds: f64,
}

/// How a user raises the solver parameter `key` (a field of [`Params`] or a scene's
/// `[solver]` key): the scene key, the Python keyword and the C option, for the error
/// messages of budgets and tolerances. `c` is false where the C ABI has no such option.
pub(crate) fn raise_advice(key: &str, c: bool) -> String {
    let c = if c {
        format!("; C: StrataSolverOptions.{key} with strata_law_new_with_options")
    } else {
        String::new()
    };
    format!("[solver] {key} in the scene (Python: Scene(..., solver={{\"{key}\": ...}}){c})")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validate_accepts_the_defaults_and_names_a_bad_field() {
        assert_eq!(Params::default().validate(), Ok(()));
        let exact = Params {
            far_field_tolerance: 0.0,
            ..Params::default()
        };
        assert_eq!(exact.validate(), Ok(()));
        for (p, field) in [
            (
                Params {
                    kkt_tolerance: 0.0,
                    ..Params::default()
                },
                "kkt_tolerance",
            ),
            (
                Params {
                    armijo: f64::NAN,
                    ..Params::default()
                },
                "armijo",
            ),
            (
                Params {
                    far_field_tolerance: -1e-5,
                    ..Params::default()
                },
                "far_field_tolerance",
            ),
            (
                Params {
                    far_field_bound_factor: 0.9,
                    ..Params::default()
                },
                "far_field_bound_factor",
            ),
            (
                Params {
                    max_step_evaluations: 0,
                    ..Params::default()
                },
                "max_step_evaluations",
            ),
        ] {
            let e = p.validate().unwrap_err();
            assert_eq!(e.field, field);
            assert!(e.to_string().contains(field), "{e}");
        }
    }
}
