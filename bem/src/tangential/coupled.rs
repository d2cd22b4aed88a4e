//! The coupled normal–tangential solve at a mean pressure and a mean tangential traction
//! (force control of both): the normal problem with the deflection −i C·q̃ that the
//! traction causes, and the tangential problem with the displacement i C p̃ that the
//! pressure causes, alternated until neither changes (a block Gauss–Seidel iteration).
//!
//! With no history the traction is applied "in one step" with the pressure, as Tamaas'
//! PolonskyKeerTan loads (stick: u = s). The incremental path (frictionless normal
//! loading, then the tangential load) is the same solve from the history h = u_p of the
//! normal step (stick: u − u_p = s, so that only the change of displacement sticks).

use super::{
    NormalLoad, NormalSolution, SlipSolution, TangentialError, TangentialLoad, TractionKernel,
    solve_normal, solve_slip,
};

/// The solution of [`solve_coupled`].
#[derive(Debug, Clone)]
pub struct CoupledSolution {
    /// The normal problem (its deflection includes the traction's part).
    pub normal: NormalSolution,
    /// The tangential problem (its displacement is K_tt q, without the pressure's part).
    pub slip: SlipSolution,
    /// The alternations.
    pub outer_iterations: usize,
}

/// Solves the coupled problem (module docs) with both inner solves to `tol`, until the
/// largest change of p and q between alternations falls below `tol` times the largest
/// μp.
#[allow(clippy::too_many_arguments)]
pub fn solve_coupled(
    kernel: &TractionKernel,
    heights: &[f64],
    mean_pressure: f64,
    mean_traction: [f64; 2],
    mu: f64,
    history: Option<[&[f64]; 2]>,
    tol: f64,
    max_iterations: usize,
) -> Result<CoupledSolution, TangentialError> {
    let (ny, nx) = kernel.grid();
    let n = ny * nx;
    let mut work = kernel.work();
    let mut wq = vec![0.0; n];
    let mut up = [vec![0.0; n], vec![0.0; n]];
    let mut prev: Option<(Vec<f64>, [Vec<f64>; 2])> = None;
    let mut last_change = f64::INFINITY;
    for outer in 0..100 {
        let normal = solve_normal(
            kernel,
            heights,
            Some(&wq),
            NormalLoad::MeanPressure(mean_pressure),
            prev.as_ref().map(|(p, _)| p.as_slice()),
            tol,
            max_iterations,
        )?;
        {
            let [ux, uy] = &mut up;
            kernel.apply(
                [None, None, Some(&normal.pressure)],
                [Some(ux), Some(uy), None],
                &mut work,
            )?;
        }
        let h: [Vec<f64>; 2] = std::array::from_fn(|c| {
            (0..n)
                .map(|i| history.map_or(0.0, |hh| hh[c][i]) - up[c][i])
                .collect()
        });
        let slip = solve_slip(
            kernel,
            &normal.pressure,
            mu,
            Some([&h[0], &h[1]]),
            TangentialLoad::Force(mean_traction),
            prev.as_ref()
                .map(|(_, q)| [q[0].as_slice(), q[1].as_slice()]),
            tol,
            max_iterations,
        )?;
        let pmax = normal.pressure.iter().cloned().fold(0.0, f64::max);
        let change = match &prev {
            Some((p, q)) => {
                let mut c: f64 = 0.0;
                for i in 0..n {
                    c = c
                        .max((p[i] - normal.pressure[i]).abs())
                        .max((q[0][i] - slip.traction[0][i]).abs())
                        .max((q[1][i] - slip.traction[1][i]).abs());
                }
                c / (mu.min(1.0) * pmax).max(f64::MIN_POSITIVE)
            }
            None => f64::INFINITY,
        };
        last_change = change;
        if change <= tol || kernel.coupling() == super::Coupling::Uncoupled && outer > 0 {
            return Ok(CoupledSolution {
                normal,
                slip,
                outer_iterations: outer + 1,
            });
        }
        kernel.apply(
            [Some(&slip.traction[0]), Some(&slip.traction[1]), None],
            [None, None, Some(&mut wq)],
            &mut work,
        )?;
        prev = Some((normal.pressure, slip.traction));
    }
    Err(TangentialError::NotConverged {
        what: "coupled normal–tangential",
        iterations: 100,
        error: last_change,
    })
}
