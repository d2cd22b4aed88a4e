//! Tangential contact on the FFT-BEM: the 3 × 3 layered kernel, Coulomb partial slip
//! (force or displacement control, with history), the coupled normal–tangential solve
//! and the full-stick tangential stiffness, on periodic cells.
//!
//! # Equations
//! The rigid flat (or the counterface) presses with the pressure p(x) ≥ 0 and pulls with
//! the tangential traction q(x) = (q_x, q_y) (Pa) on the surface of the layered solid;
//! the surface displaces by (u_x, u_y, w) = K (q_x, q_y, p) ([`kernel`]). The flat moves
//! tangentially by the rigid shift s (m). Coulomb's law on the slip increment of a load
//! step, Δv = Δs − Δu, is written per step as (module [`slip`]):
//!
//! ```text
//!   |q| ≤ μp;  stick (|q| < μp):  u = s + h;   slip (|q| = μp):  s + h − u = λ q/|q|, λ ≥ 0,
//! ```
//!
//! where the history field h = u_prev − s_prev carries the stick/slip state of the last
//! step (h = 0 from a fresh contact): each step's problem is the minimum of the
//! complementary energy ½⟨q, K_tt q⟩ − ⟨q, h⟩ over the friction discs, with Σq fixed
//! (force control, s its Lagrange multiplier) or s given (displacement control). The
//! uncoupled problem (S_zL = 0) keeps the normal solution fixed; the coupled one
//! ([`coupled`]) alternates normal and tangential solves until both hold.
//!
//! # Method
//! With friction, an accelerated projected gradient (FISTA with gradient restart; Beck &
//! Teboulle 2009, O'Donoghue & Candès 2015) on the complementary energy: each step moves
//! along −(K_tt q − h − s) and projects onto the friction discs |q| ≤ μp, under force
//! control onto the discs intersected with the plane Σq = N Q̄ (a two-component
//! multiplier found by Newton steps, no FFT). Every iterate is admissible and the
//! iteration converges for any grid (a sphere's partial slip: 151–214 products by K_tt at
//! 128², 338–493 at 256², 851–1 404 at 512²). Full stick is the linear problem on the
//! contact set, solved by conjugate gradients.

pub mod coupled;
pub mod kernel;
pub mod normal;
pub mod path;
pub mod slip;
#[cfg(test)]
mod tests;

pub use coupled::{CoupledSolution, solve_coupled};
pub use kernel::{Coupling, KernelEntry, KernelWork, TractionKernel, uniform_shear_compliance};
pub use normal::{NormalLoad, NormalSolution, solve_normal};
pub use path::{PathStep, TangentialPath, full_stick_stiffness};
pub use slip::{SlipSolution, TangentialLoad, solve_slip};

/// Errors of the tangential solvers.
#[derive(Debug, thiserror::Error)]
pub enum TangentialError {
    #[error("grid: the tangential BEM needs an even grid of at least 4×4, got {rows}×{cols}")]
    Grid { rows: usize, cols: usize },
    #[error("size: the sample sides must be finite and > 0 (m), got {ly} × {lx}")]
    Size { ly: f64, lx: f64 },
    #[error("moduli: E* and μ must be finite and > 0 (Pa), got {e_star} and {mu}")]
    Modulus { e_star: f64, mu: f64 },
    #[error("field length {got} does not match the grid ({expected} points)")]
    Length { got: usize, expected: usize },
    #[error("friction coefficient must be finite and > 0, got {0}")]
    Friction(f64),
    #[error(
        "tangential load: the mean traction {q:e} Pa exceeds μ times the mean pressure ({limit:e} Pa): the contact slides as a whole"
    )]
    Sliding { q: f64, limit: f64 },
    #[error("load: {what} = {value} is invalid (must be finite{extra})")]
    Load {
        what: &'static str,
        value: f64,
        extra: &'static str,
    },
    #[error("there is no contact (p = 0 everywhere): no tangential traction can be carried")]
    NoContact,
    #[error("the {what} iteration did not converge in {iterations} iterations (error {error:e})")]
    NotConverged {
        what: &'static str,
        iterations: usize,
        error: f64,
    },
    #[error(transparent)]
    Fft(#[from] strata_runtime::fft::FftError),
}
