//! The accuracy–cost study behind `strata study`: what each knob of the
//! solvers buys in accuracy and costs in time, measured in one run on this machine.
//!
//! Eight stages, each a module:
//! * [`fredholm`]: the full asperity solver (Nyström and product integration), force
//!   error against node count and time per solve;
//! * [`tables`]: surrogate tables, interpolation error against grid density and
//!   interpolation order, with build time, file size and lookup time;
//! * [`approx`]: the second-order approximation against the full solution, force
//!   error against a/h₁;
//! * [`rough`]: rough contact, N and I models and the FFT-BEM at several grids and
//!   tolerances, pressure error against the finest BEM and time per load curve;
//! * [`scaling`]: the I model at scale;
//! * [`plasticity`]: yielding tips, the three models capped at a hardness against the
//!   capped BEM on the finest grid;
//! * [`conductance`]: interface conductance, the N and I models' and the BEM's at
//!   several grids against the BEM on the finest grid, with the conductance's own time;
//! * [`friction`]: the tangential stiffness, the disc-stiffness table's node count
//!   against its error vs direct Fredholm solves and its build cost in solves.
//!
//! Conventions shared by every stage:
//! * **Errors are deterministic.** Every value that enters an error is computed once
//!   on a dedicated one-thread rayon pool ([`Runner::exact`]), so that parallel
//!   reductions (the product-integration moments) sum in a fixed order and a second
//!   run gives bit-identical errors. No randomness except fixed-seed point sets.
//! * **Times are medians** of repeated runs on the global thread pool (all cores):
//!   as many runs as fit in a per-item budget, at least `min_runs` and at most
//!   `max_runs` of the mode ([`Reps`]); each row states its run count.
//! * **Pareto front** ([`pareto`]): a point is on the front when no other point is at
//!   least as fast and at least as accurate (and strictly better in one). Errors
//!   within 10 % of each other, and errors below a stage's floor (the accuracy of its
//!   reference), count as equal. A point's
//!   *time factor* is its time over that of the fastest point at least as accurate;
//!   1 is on the front, ≤ [`pareto::NEAR`] is "near".

pub mod approx;
pub mod conductance;
mod defaults;
mod figures;
pub mod fredholm;
pub mod friction;
mod harness;
pub mod machine;
pub mod pareto;
pub mod plasticity;
pub mod report;
pub mod rough;
pub mod scaling;
pub mod tables;

use std::time::Instant;

use anyhow::{Context, Result};

pub use harness::{
    Errors, Inputs, Mode, Reps, Runner, Timing, fmt_err, fmt_time, median, median_time,
};

/// The results of every stage.
pub struct Study {
    pub mode: Mode,
    pub fredholm: fredholm::Results,
    pub tables: tables::Results,
    pub approx: approx::Results,
    pub rough: rough::Results,
    pub scaling: scaling::Results,
    pub plasticity: plasticity::Results,
    pub conductance: conductance::Results,
    pub friction: friction::Results,
    pub errors: Errors,
    pub timings: Vec<(String, String, Timing)>,
    pub machine: machine::Machine,
    pub seconds: f64,
}

/// Runs every stage. Progress lines go to stderr.
pub fn run(mode: Mode, inputs: &Inputs, machine: machine::Machine) -> Result<Study> {
    let t0 = Instant::now();
    let mut runner = Runner::new(mode)?;
    let mut errors = Errors::default();
    // Every input file first: a bad --table or --scene fails before the first stage.
    strata_runtime::table::Table::load(&inputs.table)
        .with_context(|| format!("--table {}", inputs.table.display()))?;
    rough::inputs(inputs)?;
    let stage = |name: &str| crate::progress::log(format!("study ({}): {name} …", mode.name()));
    stage("Fredholm solver");
    let fredholm = fredholm::run(&mut runner, &mut errors).context("Fredholm stage")?;
    stage("tables");
    let tables = tables::run(&mut runner, &mut errors).context("tables stage")?;
    stage("second-order approximation");
    let approx = approx::run(&mut runner, &mut errors, inputs).context("approximation stage")?;
    stage("rough contact");
    let rough = rough::run(&mut runner, &mut errors, inputs).context("rough-contact stage")?;
    stage("I model at scale");
    let scaling = scaling::run(mode, inputs).context("I model at scale stage")?;
    stage("yielding tips");
    let plasticity =
        plasticity::run(&mut runner, &mut errors, inputs).context("yielding tips stage")?;
    stage("interface conductance");
    let conductance = conductance::run(&mut runner, &mut errors, inputs)
        .context("interface conductance stage")?;
    stage("tangential stiffness");
    let friction =
        friction::run(&mut runner, &mut errors, inputs).context("tangential stiffness stage")?;
    let seconds = t0.elapsed().as_secs_f64();
    crate::progress::log(format!("study ({}): done in {seconds:.1} s", mode.name()));
    Ok(Study {
        mode,
        fredholm,
        tables,
        approx,
        rough,
        scaling,
        plasticity,
        conductance,
        friction,
        errors,
        timings: runner.log,
        machine,
        seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn runs_respect_bounds() {
        let reps = Reps {
            min_runs: 3,
            max_runs: 5,
            budget: 1e-9,
        };
        let mut n = 0;
        let ((), t) = median_time(
            reps,
            || {},
            || {
                n += 1;
                Ok(())
            },
        )
        .unwrap();
        assert_eq!(t.runs, 3);
        assert_eq!(n, 3);
    }

    #[test]
    fn formats() {
        assert_eq!(fmt_err(0.0), "0");
        assert_eq!(fmt_err(1.234e-7), "1.23e-7");
        assert_eq!(fmt_time(2.5e-8), "25.0 ns");
        assert_eq!(fmt_time(0.0123), "12.30 ms");
    }
}
