//! Box-constrained convex quadratic programmes by MPRGP: minimise
//!
//! ```text
//!   f(x) = ½ xᵀA x − bᵀx      over 0 ≤ x ≤ U,
//! ```
//!
//! A symmetric positive (semi)definite, given only as a product x ↦ A x. The contact
//! pressure capped by a hardness H is this problem (physics.md §6.3): x = p, U = H,
//! A the influence operator, b = z_e − c, so that the gradient g = A x − b is the
//! elastic gap; its optimality (KKT) conditions are the contact conditions of the capped
//! surface (g ≥ 0 where x = 0, g = 0 inside, g ≤ 0 where x = U). The full-field BEM
//! (`strata_bem::plastic`, A by FFT) and the axisymmetric asperity (tablegen, A a dense
//! ring matrix) both solve it here.
//!
//! # Method
//! Dostál's modified proportioning with reduced gradient projections (Dostál &
//! Schöberl, Comput. Optim. Appl. 30, 2005; Dostál, *Optimal Quadratic Programming
//! Algorithms*, 2009, ch. 7–8): with the free gradient φ (g where 0 < x < U, else 0),
//! the chopped gradient β (the components that would move a bound point inside) and the
//! reduced free gradient φ̃ (φ limited by the distance to the bounds over ᾱ),
//! * while ‖β‖² ≤ Γ² φ̃ᵀφ (proportional iterate): a conjugate-gradient step on the free
//!   set if it stays in the box, else an expansion step (the feasible CG step, then a
//!   projected gradient step of length ᾱ);
//! * otherwise a proportioning step along −β.
//!
//! For ᾱ ∈ (0, 2/‖A‖] and a strictly convex f the iterates converge R-linearly to the
//! unique minimiser whatever the number of bound components (no rescaling of x: the
//! iteration cannot stall with the whole set just below U). ‖A‖ comes from
//! [`norm_estimate`] (power iteration with a margin). Γ = 1.
//!
//! Stopping: the largest KKT violation (the ∞-norm of the projected gradient φ + β)
//! below `tol`, evaluated on g = A x − b recomputed from x (every `refresh` iterations
//! and before acceptance, so incremental updates cannot drift).

use thiserror::Error;

/// The product y = A x, or an error of the caller's.
type Apply<'a, E> = dyn FnMut(&[f64], &mut [f64]) -> Result<(), E> + 'a;

/// MPRGP's proportioning constant Γ.
const GAMMA: f64 = 1.0;

/// Errors of a bounded solve; `E` is the operator's error.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum BoundedError<E: std::fmt::Display> {
    /// The iteration budget ran out above the tolerance.
    #[error(
        "not converged after {iterations} iterations (KKT violation {violation:e} > tolerance {tolerance:e})"
    )]
    NotConverged {
        iterations: usize,
        violation: f64,
        tolerance: f64,
    },
    /// A non-finite value appeared (an ill-posed operator or data).
    #[error("the bounded solve became non-finite at iteration {0}")]
    NonFinite(usize),
    /// The operator failed.
    #[error("{0}")]
    Operator(E),
}

/// Settings of one bounded solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mprgp {
    /// The upper bound U (the lower bound is 0); `f64::INFINITY` for none.
    pub upper: f64,
    /// Projected-gradient step ᾱ, in (0, 2/‖A‖].
    pub alpha: f64,
    /// Acceptance: largest KKT violation (units of g).
    pub tol: f64,
    /// Iteration budget.
    pub max_iterations: usize,
    /// Exact gradients g = A x − b at least every this many iterations.
    pub refresh: usize,
}

/// What a bounded solve did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    pub iterations: usize,
    /// Products with A.
    pub products: usize,
    /// Largest KKT violation at acceptance (units of g).
    pub violation: f64,
}

/// g = A x − b.
fn exact<E: std::fmt::Display>(
    apply: &mut Apply<'_, E>,
    b: &[f64],
    x: &[f64],
    g: &mut [f64],
    products: &mut usize,
) -> Result<(), BoundedError<E>> {
    apply(x, g).map_err(BoundedError::Operator)?;
    *products += 1;
    for (gi, bi) in g.iter_mut().zip(b) {
        *gi -= bi;
    }
    Ok(())
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Mprgp {
    /// φ, β; returns φ̃ᵀφ, ‖β‖² and the largest KKT violation.
    fn split(&self, x: &[f64], g: &[f64], phi: &mut [f64], beta: &mut [f64]) -> (f64, f64, f64) {
        let (u, a) = (self.upper, self.alpha);
        let (mut pt, mut bb, mut worst) = (0.0, 0.0, 0.0_f64);
        for i in 0..x.len() {
            let (xi, gi) = (x[i], g[i]);
            if xi <= 0.0 {
                phi[i] = 0.0;
                beta[i] = gi.min(0.0);
            } else if xi >= u {
                phi[i] = 0.0;
                beta[i] = gi.max(0.0);
            } else {
                phi[i] = gi;
                beta[i] = 0.0;
                let reduced = if gi > 0.0 {
                    (xi / a).min(gi)
                } else {
                    ((xi - u) / a).max(gi)
                };
                pt += reduced * gi;
            }
            bb += beta[i] * beta[i];
            worst = worst.max(phi[i].abs()).max(beta[i].abs());
        }
        (pt, bb, worst)
    }

    /// Largest step a ≥ 0 with 0 ≤ x − a d ≤ U.
    fn feasible(&self, x: &[f64], d: &[f64]) -> f64 {
        let mut a_f = f64::INFINITY;
        for (xi, di) in x.iter().zip(d) {
            if *di > 0.0 {
                a_f = a_f.min(xi / di);
            } else if *di < 0.0 {
                a_f = a_f.min((xi - self.upper) / di);
            }
        }
        a_f
    }

    /// Solves from `x` (projected into the box first); `g` receives the exact gradient
    /// A x − b of the solution. `apply(v, out)` writes A v.
    pub fn solve<E: std::fmt::Display>(
        &self,
        apply: &mut Apply<'_, E>,
        b: &[f64],
        x: &mut [f64],
        g: &mut [f64],
    ) -> Result<Outcome, BoundedError<E>> {
        let n = x.len();
        let u = self.upper;
        for v in x.iter_mut() {
            *v = v.clamp(0.0, u);
        }
        let (mut phi, mut beta) = (vec![0.0; n], vec![0.0; n]);
        let (mut dir, mut ad) = (vec![0.0; n], vec![0.0; n]);
        let mut products = 0;
        exact(apply, b, x, g, &mut products)?;
        let mut since_exact = 0;
        let mut fresh = true;
        let mut last = f64::NAN;
        for it in 0..=self.max_iterations {
            let (pt, bb, mut worst) = self.split(x, g, &mut phi, &mut beta);
            if worst <= self.tol && since_exact > 0 {
                exact(apply, b, x, g, &mut products)?;
                since_exact = 0;
                worst = self.split(x, g, &mut phi, &mut beta).2;
            }
            if !worst.is_finite() {
                return Err(BoundedError::NonFinite(it));
            }
            last = worst;
            if worst <= self.tol {
                return Ok(Outcome {
                    iterations: it,
                    products,
                    violation: worst,
                });
            }
            if it == self.max_iterations {
                break;
            }
            if since_exact >= self.refresh {
                exact(apply, b, x, g, &mut products)?;
                since_exact = 0;
                fresh = true;
                continue;
            }
            since_exact += 1;
            if bb <= GAMMA * GAMMA * pt {
                // Proportional: a conjugate-gradient step on the free set.
                if fresh {
                    dir.copy_from_slice(&phi);
                    fresh = false;
                }
                apply(&dir, &mut ad).map_err(BoundedError::Operator)?;
                products += 1;
                let dad = dot(&dir, &ad);
                if dad.is_nan() || dad <= 0.0 {
                    // A direction in A's null space (a zero-mean mode): project instead.
                    self.projected_step(x, &phi);
                    exact(apply, b, x, g, &mut products)?;
                    since_exact = 0;
                    fresh = true;
                    continue;
                }
                let a_cg = dot(g, &dir) / dad;
                let a_f = self.feasible(x, &dir);
                if a_cg <= a_f {
                    for i in 0..n {
                        x[i] -= a_cg * dir[i];
                        g[i] -= a_cg * ad[i];
                    }
                    self.split(x, g, &mut phi, &mut beta);
                    let gam = dot(&phi, &ad) / dad;
                    for i in 0..n {
                        dir[i] = phi[i] - gam * dir[i];
                    }
                } else {
                    // Expansion: the feasible step, then a projected gradient step.
                    for i in 0..n {
                        x[i] = (x[i] - a_f * dir[i]).clamp(0.0, u);
                        g[i] -= a_f * ad[i];
                    }
                    self.split(x, g, &mut phi, &mut beta);
                    self.projected_step(x, &phi);
                    exact(apply, b, x, g, &mut products)?;
                    since_exact = 0;
                    fresh = true;
                }
            } else {
                // Proportioning: release bound components along −β (not past the
                // opposite bound).
                apply(&beta, &mut ad).map_err(BoundedError::Operator)?;
                products += 1;
                let bab = dot(&beta, &ad);
                let a = if bab > 0.0 { bb / bab } else { self.alpha };
                let a = a.min(self.feasible(x, &beta));
                for i in 0..n {
                    x[i] = (x[i] - a * beta[i]).clamp(0.0, u);
                    g[i] -= a * ad[i];
                }
                fresh = true;
            }
        }
        Err(BoundedError::NotConverged {
            iterations: self.max_iterations,
            violation: last,
            tolerance: self.tol,
        })
    }

    /// x ← P(x − ᾱ φ).
    fn projected_step(&self, x: &mut [f64], phi: &[f64]) {
        for (xi, f) in x.iter_mut().zip(phi) {
            *xi = (*xi - self.alpha * f).clamp(0.0, self.upper);
        }
    }
}

/// An upper estimate of ‖A‖ (its largest eigenvalue): 40 power iterations from a
/// smooth positive start, times 1.25.
pub fn norm_estimate<E: std::fmt::Display>(
    apply: &mut Apply<'_, E>,
    n: usize,
) -> Result<f64, BoundedError<E>> {
    let mut v: Vec<f64> = (0..n)
        .map(|i| 1.0 + 0.5 * ((i * 7919) % 1013) as f64 / 1013.0)
        .collect();
    let mut av = vec![0.0; n];
    let mut lambda = 0.0;
    for _ in 0..40 {
        let norm = dot(&v, &v).sqrt();
        if norm.is_nan() || norm <= 0.0 {
            break;
        }
        v.iter_mut().for_each(|x| *x /= norm);
        apply(&v, &mut av).map_err(BoundedError::Operator)?;
        lambda = dot(&v, &av);
        std::mem::swap(&mut v, &mut av);
    }
    if !(lambda.is_finite() && lambda > 0.0) {
        return Err(BoundedError::NonFinite(0));
    }
    Ok(1.25 * lambda)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dense SPD matrix (a 1-D Laplacian plus a shift) with bounds that bind at both
    /// ends: the KKT conditions hold at the solution, and U = ∞ solves A x = b where the
    /// solution is positive.
    #[test]
    fn dense_box_qp() {
        let n = 50;
        let a = |i: usize, j: usize| -> f64 {
            if i == j {
                2.5
            } else if i.abs_diff(j) == 1 {
                -1.0
            } else {
                0.0
            }
        };
        let mut apply = |x: &[f64], y: &mut [f64]| -> Result<(), String> {
            for (i, yi) in y.iter_mut().enumerate().take(n) {
                *yi = (0..n).map(|j| a(i, j) * x[j]).sum();
            }
            Ok(())
        };
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin() * 2.0).collect();
        let norm = norm_estimate(&mut apply, n).unwrap();
        assert!((4.4..6.0).contains(&norm), "{norm}");
        let m = Mprgp {
            upper: 0.5,
            alpha: 1.0 / norm,
            tol: 1e-13,
            max_iterations: 10_000,
            refresh: 50,
        };
        let (mut x, mut g) = (vec![0.0; n], vec![0.0; n]);
        m.solve(&mut apply, &b, &mut x, &mut g).unwrap();
        let (mut lower, mut upper, mut free) = (0, 0, 0);
        for i in 0..n {
            if x[i] <= 0.0 {
                assert!(g[i] >= -1e-12);
                lower += 1;
            } else if x[i] >= 0.5 {
                assert!(g[i] <= 1e-12);
                upper += 1;
            } else {
                assert!(g[i].abs() <= 1e-12);
                free += 1;
            }
        }
        assert!(lower > 0 && upper > 0 && free > 0, "{lower} {upper} {free}");
    }
}
