//! Stage 8: what the tangential stiffness's accuracy costs (`[friction]`, the N and I
//! models' K_t = Σ K_t(aᵢ)): the disc-stiffness table of the scene's stack
//! (`strata_runtime::disc_stiffness`: Chebyshev–Lobatto nodes a decade of a/h₁,
//! barycentric interpolation of the punch factors ψ_zz, ψ_LL, ψ_TT) at several node
//! counts a decade, against direct Fredholm solves of the disc (`strata_tablegen::
//! stiffness`) at radii that are no table's nodes. The error of a node count is the
//! largest |K/K_direct − 1| over those radii, for K_t (the full-stick disc) and K_n (the
//! frictionless flat punch); its build cost is counted in Fredholm solves (N − 1 a decade
//! and one more: neighbouring decades share their end node) and in time (the count times
//! the median time of one direct solve). The shipped table has
//! [`strata_runtime::disc_stiffness::NODES`] nodes a decade.
//!
//! The node sets are nested (N − 1 = 4, 8, 16, 32 divide 32), so one set of solves at the
//! finest count serves every count: 32 solves a decade and 5 test solves. The tiny mode
//! (a smoke test) takes two decades (a/h₁ = 0.1 … 10) and node counts up to 17 (43
//! solves); the quick mode three (1e−2 … 10, 112 solves), the full mode four (1e−2 … 1e2,
//! 149 solves), node counts up to 33.

use anyhow::{Context, Result};
use strata_runtime::disc_stiffness::PunchFactors;
use strata_tablegen::stiffness::Stiffness;

use super::{Errors, Inputs, Mode, Reps, Runner, Timing};

/// One node count's row.
#[derive(Debug, Clone)]
pub struct Row {
    /// Chebyshev–Lobatto nodes a decade.
    pub nodes: usize,
    /// Fredholm solves to build the table over the stage's decades.
    pub solves: usize,
    /// max |K_t/K_t,direct − 1| over the test radii.
    pub kt_error: f64,
    /// max |K_n/K_n,direct − 1| over the test radii.
    pub kn_error: f64,
    /// Whether this is the shipped table's node count.
    pub is_default: bool,
}

pub struct Results {
    /// The stack's description.
    pub stack: String,
    /// The decades [k₀, k₁) of log₁₀(a/h₁).
    pub decades: (i32, i32),
    /// Test radii (count).
    pub tests: usize,
    pub rows: Vec<Row>,
    /// One direct solve (median over the finest node set's solves).
    pub solve_timing: Timing,
}

/// Node j of n on [−1, 1]: −cos(πj/(n − 1)) (the runtime's grid for n = 17).
fn lobatto(j: usize, n: usize) -> f64 {
    if 2 * j == n - 1 {
        0.0
    } else {
        -(std::f64::consts::PI * j as f64 / (n - 1) as f64).cos()
    }
}

/// The barycentric Lobatto interpolant at x ∈ [−1, 1] of `v` (n values at the n nodes).
fn interpolate(v: &[PunchFactors], x: f64) -> PunchFactors {
    let n = v.len();
    let (mut num, mut den) = ([0.0; 3], 0.0);
    for (j, vj) in v.iter().enumerate() {
        let d = x - lobatto(j, n);
        if d == 0.0 {
            return *vj;
        }
        let w = if j % 2 == 0 { 1.0 } else { -1.0 } * if j == 0 || j == n - 1 { 0.5 } else { 1.0 };
        let c = w / d;
        num[0] += c * vj.normal;
        num[1] += c * vj.along;
        num[2] += c * vj.across;
        den += c;
    }
    PunchFactors {
        normal: num[0] / den,
        along: num[1] / den,
        across: num[2] / den,
    }
}

pub fn run(runner: &mut Runner, errors: &mut Errors, inputs: &Inputs) -> Result<Results> {
    let mode = runner.mode;
    let (scene, _, _, _) = super::rough::inputs(inputs)?;
    let bodies = &scene.bodies;
    let solver = Stiffness::new(bodies);
    let h1 = bodies
        .first
        .top_thickness()
        .context("the study's scene needs a layered stack (a top layer h1)")?;
    let (decades, counts): ((i32, i32), &[usize]) = match mode {
        Mode::Tiny => ((-1, 1), &[5, 9, 17]),
        Mode::Quick => ((-2, 1), &[5, 9, 17, 33]),
        Mode::Full => ((-2, 2), &[5, 9, 17, 33]),
    };
    let finest = *counts.last().unwrap_or(&17);
    let radius = |k: i32, x: f64| h1 * 10f64.powf(f64::from(k) + 0.5 * (x + 1.0));
    // the finest node set, decade by decade (end nodes shared)
    let n_dec = (decades.1 - decades.0) as usize;
    let once = Reps {
        min_runs: 1,
        max_runs: 1,
        budget: 0.0,
    };
    let (nodes, all): (Vec<PunchFactors>, Timing) =
        runner.time_value_with(once, "friction", "disc-stiffness nodes", || {
            let mut out = Vec::with_capacity(n_dec * (finest - 1) + 1);
            for (i, k) in (decades.0..decades.1).enumerate() {
                for j in usize::from(i > 0)..finest {
                    out.push(solver.factors(radius(k, lobatto(j, finest)))?);
                }
            }
            Ok(out)
        })?;
    let per_solve = Timing {
        median: all.median / nodes.len() as f64,
        min: all.min / nodes.len() as f64,
        max: all.max / nodes.len() as f64,
        runs: all.runs,
    };
    // test radii: 5 a decade, at no count's node
    let xs: Vec<f64> = (0..5).map(|i| -0.9 + 0.37 * i as f64 + 0.011).collect();
    let mut direct = Vec::new();
    for k in decades.0..decades.1 {
        for &x in &xs {
            let a = radius(k, x);
            direct.push((k, x, a, runner.exact(|| solver.at(a))?));
        }
    }
    let mut rows = Vec::new();
    for &n in counts {
        let step = (finest - 1) / (n - 1);
        let (mut kt, mut kn) = (0.0f64, 0.0f64);
        for (k, x, a, d) in &direct {
            let p = (k - decades.0) as usize * (finest - 1);
            let v: Vec<PunchFactors> = (0..n).map(|j| nodes[p + j * step]).collect();
            let s = solver.from_factors(*a, interpolate(&v, *x));
            kt = kt.max((s.tangential / d.tangential - 1.0).abs());
            kn = kn.max((s.normal / d.normal - 1.0).abs());
        }
        let label = format!("{n} nodes a decade");
        errors.push("friction", &label, "K_t error", kt);
        errors.push("friction", &label, "K_n error", kn);
        rows.push(Row {
            nodes: n,
            solves: n_dec * (n - 1) + 1,
            kt_error: kt,
            kn_error: kn,
            is_default: n == strata_runtime::disc_stiffness::NODES,
        });
    }
    Ok(Results {
        stack: format!(
            "the scene's stack, {} layer(s), h1 = {h1:e} m",
            bodies.first.layers().len()
        ),
        decades,
        tests: direct.len(),
        rows,
        solve_timing: per_solve,
    })
}

pub fn markdown(r: &Results) -> String {
    use std::fmt::Write;
    let mut w = String::new();
    let _ = writeln!(
        w,
        "## 8. Tangential stiffness (`[friction]`)\n\nThe N and I models' K_t = Σ K_t(aᵢ) reads \
         the disc-stiffness table of the stack ({}): Chebyshev–Lobatto nodes a decade of a/h₁, \
         the punch factors interpolated. Below, the table at several node counts over a/h₁ = \
         1e{} … 1e{} against {} direct Fredholm solves at radii that are no node; its build \
         counted in solves (one direct solve: {}). The shipped table has {} nodes a decade.\n",
        r.stack,
        r.decades.0,
        r.decades.1,
        r.tests,
        super::fmt_time(r.solve_timing.median),
        strata_runtime::disc_stiffness::NODES
    );
    let _ = writeln!(
        w,
        "| nodes a decade | K_t error | K_n error | build (solves) | build time |\n|---|---|---|---|---|"
    );
    for row in &r.rows {
        let _ = writeln!(
            w,
            "| {}{} | {} | {} | {} | {} |",
            row.nodes,
            if row.is_default { " (default)" } else { "" },
            super::fmt_err(row.kt_error),
            super::fmt_err(row.kn_error),
            row.solves,
            super::fmt_time(row.solves as f64 * r.solve_timing.median)
        );
    }
    let _ = writeln!(w);
    w
}

/// One summary line: the default node count's error and cost.
pub fn summary(r: &Results) -> Option<String> {
    let d = r.rows.iter().find(|x| x.is_default)?;
    Some(format!(
        "Tangential stiffness: the disc-stiffness table ({} nodes a decade) within {} of direct \
         solves (K_t), built in {} solves for {} decades.",
        d.nodes,
        super::fmt_err(d.kt_error),
        d.solves,
        r.decades.1 - r.decades.0
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The barycentric Lobatto interpolant is exact on polynomials of degree n − 1, and
    /// the n-node sets are nested in the 33-node one.
    #[test]
    fn friction_stage_interpolant_and_nested_nodes() {
        for n in [5usize, 9, 17, 33] {
            let f = |x: f64| 1.0 + x - 0.5 * x.powi((n - 1) as i32);
            let v: Vec<PunchFactors> = (0..n)
                .map(|j| {
                    let y = f(lobatto(j, n));
                    PunchFactors {
                        normal: y,
                        along: 2.0 * y,
                        across: 3.0 * y,
                    }
                })
                .collect();
            for x in [-0.77, 0.013, 0.5] {
                let p = interpolate(&v, x);
                assert!((p.normal - f(x)).abs() < 1e-12, "n = {n}, x = {x}");
                assert!((p.across - 3.0 * f(x)).abs() < 1e-12);
            }
            let step = 32 / (n - 1);
            for j in 0..n {
                assert!((lobatto(j, n) - lobatto(j * step, 33)).abs() < 1e-15);
            }
        }
    }
}
