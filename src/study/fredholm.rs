//! Stage 1: the full asperity solver (strata-tablegen `asperity`, paper §3).
//!
//! For the paper's stacks (h₁ = 100 µm, E₁ = 4 GPa, ν = 0.15, second layer E₂ to a
//! rigid base at 1 mm) and a paraboloid of radius R = 100 µm at contact radii
//! a = (a/h₁)·h₁, the force P and approach δ of `Asperity::paraboloid_at_radius` are
//! computed with fixed discretisations — Gauss–Legendre Nyström with N nodes, and
//! product integration on N intervals with Richardson extrapolation — and compared
//! with a converged solution:
//!
//! ```text
//!   force error = |P_N − P_ref| / P_ref,   δ error = |δ_N − δ_ref| / δ_ref
//! ```
//!
//! The reference is Nyström at [`Settings::ref_nodes`] nodes for a ≤ 4h₁ (where
//! Nyström converges spectrally) and product integration at
//! [`Settings::ref_intervals`] intervals beyond; its uncertainty is estimated by the
//! same method one step coarser (and the other method is shown as a cross-check).
//! Time per solve: kernel quadrature, assembly, LU and two right-hand sides, with a
//! 2-interval profile grid (no profile output). The default (`Options::default()`,
//! method Auto) is measured at every a/h₁ and placed on the front.

use anyhow::{Context, Result};
use strata_runtime::Stack;
use strata_tablegen::asperity::{Asperity, Method, Options};
use strata_tablegen::fredholm::Discretisation;

use super::pareto::Point;
use super::{Errors, Mode, Runner, Timing};

/// Paraboloid radius R (m).
pub const RADIUS: f64 = 1e-4;
/// Top-layer thickness of the paper's stacks (m).
pub const H1: f64 = 1e-4;

/// What is measured in a mode.
#[derive(Debug, Clone)]
pub struct Settings {
    pub ratios: Vec<f64>,
    pub a_over_h: Vec<f64>,
    pub nystrom: Vec<usize>,
    pub product: Vec<usize>,
    pub ref_nodes: usize,
    pub ref_intervals: usize,
}

impl Settings {
    pub fn for_mode(mode: Mode) -> Settings {
        match mode {
            Mode::Tiny => Settings {
                ratios: vec![5.0],
                a_over_h: vec![1.0, 10.0],
                nystrom: vec![8, 16, 32],
                product: vec![32, 64, 128],
                ref_nodes: 96,
                ref_intervals: 512,
            },
            Mode::Quick => Settings {
                ratios: vec![0.2, 5.0],
                a_over_h: vec![0.5, 2.0, 4.0, 10.0, 30.0],
                nystrom: vec![8, 12, 16, 24, 32, 48, 64, 96, 128],
                product: vec![32, 64, 128, 256, 512, 1024],
                ref_nodes: 192,
                ref_intervals: 2048,
            },
            Mode::Full => Settings {
                ratios: vec![0.2, 1.0, 5.0],
                a_over_h: vec![0.5, 1.0, 2.0, 4.0, 10.0, 30.0, 100.0],
                nystrom: vec![8, 12, 16, 24, 32, 48, 64, 96, 128, 192],
                product: vec![32, 64, 128, 256, 512, 1024, 2048],
                ref_nodes: 256,
                ref_intervals: 4096,
            },
        }
    }
}

/// One measured discretisation.
#[derive(Debug, Clone)]
pub struct Row {
    pub disc: Discretisation,
    pub force_error: f64,
    pub delta_error: f64,
    pub timing: Timing,
    pub is_default: bool,
}

/// All rows of one (stack, a/h₁).
#[derive(Debug, Clone)]
pub struct Case {
    pub ratio: f64,
    pub a_over_h: f64,
    pub reference: Discretisation,
    /// |P_ref − P_ref'|/P_ref with ref' the same method one step coarser.
    pub ref_uncertainty: f64,
    /// The other method's finest solve against the reference.
    pub cross_check: (Discretisation, f64),
    /// Errors below this count as equal on the front.
    pub floor: f64,
    pub rows: Vec<Row>,
}

impl Case {
    pub fn points(&self) -> Vec<Point> {
        self.rows
            .iter()
            .map(|r| Point {
                time: r.timing.median,
                error: r.force_error,
            })
            .collect()
    }

    pub fn default_index(&self) -> Option<usize> {
        self.rows.iter().position(|r| r.is_default)
    }
}

pub struct Results {
    pub settings: Settings,
    pub cases: Vec<Case>,
}

/// "Nyström 64" / "product 256 + R".
pub fn label(d: Discretisation) -> String {
    match d {
        Discretisation::Nystrom { nodes } => format!("Nyström {nodes}"),
        Discretisation::Product {
            intervals,
            richardson,
        } => format!(
            "product {intervals}{}",
            if richardson { " + Richardson" } else { "" }
        ),
    }
}

fn key(d: Discretisation) -> String {
    match d {
        Discretisation::Nystrom { nodes } => format!("nystrom-{nodes}"),
        Discretisation::Product {
            intervals,
            richardson,
        } => format!("product-{intervals}{}", if richardson { "-r" } else { "" }),
    }
}

fn solver(stack: &Stack, d: Discretisation) -> Result<Asperity> {
    Ok(Asperity::new(
        stack,
        Options {
            method: Method::Fixed(d),
            profile_grid: 2,
        },
    )?)
}

/// (P, δ) of the paraboloid at contact radius a, computed deterministically.
fn exact(runner: &Runner, stack: &Stack, d: Discretisation, a: f64) -> Result<(f64, f64)> {
    let asp = solver(stack, d)?;
    let s = runner
        .exact(|| asp.paraboloid_at_radius(a, RADIUS))
        .with_context(|| format!("{} at a = {a:e} m", label(d)))?;
    Ok((s.force, s.delta))
}

fn rel(x: f64, r: f64) -> f64 {
    ((x - r) / r).abs()
}

pub fn run(runner: &mut Runner, errors: &mut Errors) -> Result<Results> {
    let set = Settings::for_mode(runner.mode);
    let mut cases = Vec::new();
    for &ratio in &set.ratios {
        let stack = Stack::paper_two_layer(ratio)?;
        let default = Asperity::new(
            &stack,
            Options {
                profile_grid: 2,
                ..Options::default()
            },
        )?;
        for &ah in &set.a_over_h {
            let a = ah * H1;
            let nys_ref = Discretisation::Nystrom {
                nodes: set.ref_nodes,
            };
            let prod_ref = Discretisation::Product {
                intervals: set.ref_intervals,
                richardson: true,
            };
            let nystrom_side = ah <= strata_tablegen::asperity::NYSTROM_MAX_A_OVER_H;
            let (reference, coarser, other) = if nystrom_side {
                (
                    nys_ref,
                    Discretisation::Nystrom {
                        nodes: set.ref_nodes * 5 / 6,
                    },
                    prod_ref,
                )
            } else {
                (
                    prod_ref,
                    Discretisation::Product {
                        intervals: set.ref_intervals / 2,
                        richardson: true,
                    },
                    nys_ref,
                )
            };
            let (p_ref, d_ref) = exact(runner, &stack, reference, a)?;
            let (p_c, _) = exact(runner, &stack, coarser, a)?;
            let (p_o, _) = exact(runner, &stack, other, a)?;
            let ref_uncertainty = rel(p_c, p_ref);
            let floor = ref_uncertainty.max(1e-14);
            let case_key = format!("E2/E1={ratio},a/h={ah}");
            errors.push(
                "fredholm",
                &case_key,
                "reference uncertainty",
                ref_uncertainty,
            );
            errors.push("fredholm", &case_key, "cross-check", rel(p_o, p_ref));
            let mut discs: Vec<Discretisation> = set
                .nystrom
                .iter()
                .map(|&nodes| Discretisation::Nystrom { nodes })
                .chain(
                    set.product
                        .iter()
                        .map(|&intervals| Discretisation::Product {
                            intervals,
                            richardson: true,
                        }),
                )
                .collect();
            let d_default = default.discretisation(a);
            if !discs.contains(&d_default) {
                discs.push(d_default);
            }
            let mut rows = Vec::new();
            for d in discs {
                let (p, dl) = exact(runner, &stack, d, a)?;
                let asp = solver(&stack, d)?;
                let timing = runner.time("fredholm", &format!("{case_key},{}", key(d)), || {
                    Ok(asp.paraboloid_at_radius(a, RADIUS)?)
                })?;
                let row = Row {
                    disc: d,
                    force_error: rel(p, p_ref),
                    delta_error: rel(dl, d_ref),
                    timing,
                    is_default: d == d_default,
                };
                let ck = format!("{case_key},{}", key(d));
                errors.push("fredholm", &ck, "force error", row.force_error);
                errors.push("fredholm", &ck, "delta error", row.delta_error);
                rows.push(row);
            }
            cases.push(Case {
                ratio,
                a_over_h: ah,
                reference,
                ref_uncertainty,
                cross_check: (other, rel(p_o, p_ref)),
                floor,
                rows,
            });
        }
    }
    Ok(Results {
        settings: set,
        cases,
    })
}
