//! A tangential loading path at a fixed pressure (the uncoupled problem, or the coupled
//! one with the normal solution frozen), with history, and the full-stick tangential
//! stiffness.
//!
//! Each step solves [`solve_slip`] from the history h = u_prev − s_prev of the last step
//! (h = 0 from a fresh contact), so that sticking points keep their relative position
//! and slipping points slip along the step's slip increment Δv = Δs − Δu. The energy
//! dissipated in a step is D = A_px Σ q·Δv (J; A_px the pixel area), which Coulomb's law
//! makes ≥ 0 point by point; the path's total is the hysteresis of a loading–unloading
//! cycle.

use super::{SlipSolution, TangentialError, TangentialLoad, TractionKernel, solve_slip};

/// One step of a [`TangentialPath`].
#[derive(Debug, Clone)]
pub struct PathStep {
    /// The step's solution.
    pub solution: SlipSolution,
    /// The energy dissipated by slip in the step (J).
    pub dissipation: f64,
}

/// A tangential path at a fixed pressure on one kernel.
pub struct TangentialPath<'a> {
    kernel: &'a TractionKernel,
    pressure: Vec<f64>,
    mu: f64,
    pixel_area: f64,
    tol: f64,
    max_iterations: usize,
    /// u_prev (K_tt q of the last step) and s_prev.
    u: [Vec<f64>; 2],
    s: [f64; 2],
    q: Option<[Vec<f64>; 2]>,
}

impl<'a> TangentialPath<'a> {
    /// A fresh contact (q = 0) at the pressure `pressure` (Pa) with the friction
    /// coefficient `mu`, on a cell of area `cell_area` (m²).
    pub fn new(
        kernel: &'a TractionKernel,
        pressure: Vec<f64>,
        mu: f64,
        cell_area: f64,
        tol: f64,
        max_iterations: usize,
    ) -> Self {
        let (ny, nx) = kernel.grid();
        let n = ny * nx;
        TangentialPath {
            kernel,
            pressure,
            mu,
            pixel_area: cell_area / n as f64,
            tol,
            max_iterations,
            u: [vec![0.0; n], vec![0.0; n]],
            s: [0.0; 2],
            q: None,
        }
    }

    /// Loads to `load` from the current state.
    pub fn step(&mut self, load: TangentialLoad) -> Result<PathStep, TangentialError> {
        let n = self.u[0].len();
        let h: [Vec<f64>; 2] =
            std::array::from_fn(|c| self.u[c].iter().map(|u| u - self.s[c]).collect());
        let solution = solve_slip(
            self.kernel,
            &self.pressure,
            self.mu,
            Some([&h[0], &h[1]]),
            load,
            self.q.as_ref().map(|q| [q[0].as_slice(), q[1].as_slice()]),
            self.tol,
            self.max_iterations,
        )?;
        let mut d = 0.0;
        for i in 0..n {
            for c in 0..2 {
                let dv =
                    (solution.shift[c] - self.s[c]) - (solution.displacement[c][i] - self.u[c][i]);
                d += solution.traction[c][i] * dv;
            }
        }
        self.u = solution.displacement.clone();
        self.s = solution.shift;
        self.q = Some(solution.traction.clone());
        Ok(PathStep {
            solution,
            dissipation: d * self.pixel_area,
        })
    }
}

/// The full-stick tangential stiffness K_t = Q/s_x (N/m) of the contact set {p > 0} of
/// the pressure `pressure` on a cell of area `cell_area` (m²): the linear problem
/// K_tt q = s on the contact set, q = 0 elsewhere, loaded along x (its x component; the
/// y one equals it on an isotropic solid up to the contact set's shape).
pub fn full_stick_stiffness(
    kernel: &TractionKernel,
    pressure: &[f64],
    cell_area: f64,
    tol: f64,
    max_iterations: usize,
) -> Result<f64, TangentialError> {
    let q_mean = 1.0;
    let sol = solve_slip(
        kernel,
        pressure,
        f64::INFINITY,
        None,
        TangentialLoad::Force([q_mean, 0.0]),
        None,
        tol,
        max_iterations,
    )?;
    Ok(q_mean * cell_area / sol.shift[0])
}
