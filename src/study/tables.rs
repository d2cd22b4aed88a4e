//! Stage 2: surrogate tables (strata-tablegen `tablebuild`, runtime `table`).
//!
//! Single-stack tables of the paper's stack E₂/E₁ = 5 are built at several grid
//! densities (n_x nodes on ln(a/h₁) ∈ [ln 1e−3, ln 1e3], n_w nodes on
//! w = asinh(√((r − a)/h₁)) ∈ [0, w_max]; the S axis at its default). At a fixed set of
//! random points (uniform in ln(a/h₁) and w, SplitMix64 seed 1, as `table check`)
//! the interpolated χ, ζ, g are compared with direct quadrature (strata-tablegen
//! `approx`, accurate to ~1e−10):
//!
//! ```text
//!   χ error = max |χ_t/χ − 1|,  ζ error = max |ζ_t/ζ − 1|,
//!   g error = max |g_t − g| / ((4/3) a³/r),   table error = the largest of the three
//! ```
//!
//! for two interpolation orders: the runtime's C¹ cubic Hermite (order 3, the
//! default; `TableLaw`) and multilinear interpolation of the same nodes (order 1,
//! implemented here on the table's arrays, so the file format is unchanged).
//! Costs: build time (median of runs, all cores, no interpolation check), file size
//! (bytes of the encoded table) and lookup time (one χ, ζ and g at the check points,
//! median per lookup).

use anyhow::Result;
use rayon::prelude::*;
use strata_runtime::Stack;
use strata_runtime::law::AsperityLaw;
use strata_runtime::table::{Axis, Table};
use strata_tablegen::approx::Approx;
use strata_tablegen::tablebuild::SplitMix;
use strata_tablegen::tablebuild::{BuildOptions, build};

use super::pareto::Point;
use super::{Errors, Mode, Reps, Runner, Timing};

/// Interpolation order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    /// Multilinear (order 1).
    Linear,
    /// C¹ cubic Hermite with fourth-order node slopes (order 3): the runtime's.
    Cubic,
}

impl Order {
    pub fn name(self) -> &'static str {
        match self {
            Order::Linear => "linear",
            Order::Cubic => "cubic Hermite",
        }
    }
}

/// E₂/E₁ of the stack whose tables are built.
pub const RATIO: f64 = 5.0;
/// Seed of the check points.
pub const SEED: u64 = 1;
/// Errors below this are at the accuracy of the direct quadrature.
pub const FLOOR: f64 = 1e-9;

#[derive(Debug, Clone)]
pub struct Settings {
    pub grids: Vec<(usize, usize)>,
    pub points: usize,
    /// Measure the default grid too (not in the tiny mode: it takes seconds).
    pub with_default: bool,
    /// Repetitions of a build (builds take seconds: fewer runs than other items).
    pub reps: Reps,
}

impl Settings {
    pub fn for_mode(mode: Mode) -> Settings {
        match mode {
            Mode::Tiny => Settings {
                grids: vec![(13, 7)],
                points: 60,
                with_default: false,
                reps: Reps {
                    min_runs: 1,
                    max_runs: 1,
                    budget: 0.0,
                },
            },
            Mode::Quick => Settings {
                grids: vec![(25, 13), (37, 19), (49, 25), (73, 37), (97, 49)],
                points: 500,
                with_default: true,
                reps: Reps {
                    min_runs: 3,
                    max_runs: 5,
                    budget: 6.0,
                },
            },
            Mode::Full => Settings {
                grids: vec![
                    (25, 13),
                    (37, 19),
                    (49, 25),
                    (73, 37),
                    (97, 49),
                    (145, 73),
                    (193, 97),
                ],
                points: 2000,
                with_default: true,
                reps: Reps {
                    min_runs: 3,
                    max_runs: 5,
                    budget: 60.0,
                },
            },
        }
    }
}

#[derive(Debug, Clone)]
pub struct Row {
    pub nx: usize,
    pub nw: usize,
    pub order: Order,
    pub chi: f64,
    pub zeta: f64,
    pub g: f64,
    pub build: Timing,
    pub bytes: usize,
    pub lookup: Timing,
    pub is_default: bool,
}

impl Row {
    pub fn error(&self) -> f64 {
        self.chi.max(self.zeta).max(self.g)
    }
}

pub struct Results {
    pub settings: Settings,
    pub rows: Vec<Row>,
}

impl Results {
    /// (build time, table error) of every row.
    pub fn build_points(&self) -> Vec<Point> {
        self.rows
            .iter()
            .map(|r| Point {
                time: r.build.median,
                error: r.error(),
            })
            .collect()
    }

    /// (lookup time, table error) of every row.
    pub fn lookup_points(&self) -> Vec<Point> {
        self.rows
            .iter()
            .map(|r| Point {
                time: r.lookup.median,
                error: r.error(),
            })
            .collect()
    }

    pub fn default_index(&self) -> Option<usize> {
        self.rows.iter().position(|r| r.is_default)
    }
}

/// Multilinear interpolation of a single-stack table's χ, ζ and g·r/a³ (in range).
struct Linear {
    h1: f64,
    x: Axis,
    w: Axis,
    chi: Vec<f64>,
    zeta: Vec<f64>,
    g: Vec<f64>,
}

fn cell(ax: &Axis, c: f64) -> (usize, f64) {
    let pos = ((c - ax.lo) / ax.step()).clamp(0.0, (ax.n - 1) as f64);
    let i = (pos as usize).min(ax.n - 2);
    (i, pos - i as f64)
}

impl Linear {
    fn new(t: &Table) -> Linear {
        Linear {
            h1: t.header.stack.layers()[0].thickness,
            x: t.header.x,
            w: t.header.w,
            chi: t.chi.clone(),
            zeta: t.zeta.clone(),
            g: t.g.clone(),
        }
    }

    fn chi_zeta(&self, a: f64) -> (f64, f64) {
        let (i, t) = cell(&self.x, (a / self.h1).ln());
        (
            (1.0 - t) * self.chi[i] + t * self.chi[i + 1],
            (1.0 - t) * self.zeta[i] + t * self.zeta[i + 1],
        )
    }

    fn g(&self, a: f64, r: f64) -> f64 {
        let (i, s) = cell(&self.x, (a / self.h1).ln());
        let w = ((r - a).max(0.0) / self.h1).sqrt().asinh();
        let (j, t) = cell(&self.w, w);
        let n = self.w.n;
        let f = |i: usize, j: usize| self.g[i * n + j];
        let v = (1.0 - s) * ((1.0 - t) * f(i, j) + t * f(i, j + 1))
            + s * ((1.0 - t) * f(i + 1, j) + t * f(i + 1, j + 1));
        v * a * a * a / r
    }
}

/// A check point with its direct values.
struct Check {
    a: f64,
    r: f64,
    chi: f64,
    zeta: f64,
    g: f64,
}

fn errors_of(
    pts: &[Check],
    cz: impl Fn(f64) -> (f64, f64),
    g: impl Fn(f64, f64) -> f64,
) -> (f64, f64, f64) {
    let (mut ec, mut ez, mut eg) = (0.0f64, 0.0f64, 0.0f64);
    for p in pts {
        let (c, z) = cz(p.a);
        ec = ec.max((c / p.chi - 1.0).abs());
        ez = ez.max((z / p.zeta - 1.0).abs());
        eg = eg.max((g(p.a, p.r) - p.g).abs() / (4.0 / 3.0 * p.a.powi(3) / p.r));
    }
    (ec, ez, eg)
}

pub fn run(runner: &mut Runner, errors: &mut Errors) -> Result<Results> {
    let set = Settings::for_mode(runner.mode);
    let stack = Stack::paper_two_layer(RATIO)?;
    let defaults = BuildOptions::default();
    let default_grid = (defaults.nx, defaults.nw);
    let mut grids = set.grids.clone();
    if set.with_default && !grids.contains(&default_grid) {
        grids.push(default_grid);
    }
    let h1 = stack.layers()[0].thickness;
    let mut rows = Vec::new();
    let mut checks: Option<Vec<Check>> = None;
    for (nx, nw) in grids {
        let opts = BuildOptions {
            nx,
            nw,
            check_points: 0,
            progress: false,
            ..BuildOptions::default()
        };
        let case = format!("nx={nx},nw={nw}");
        let (table, build_t) =
            runner.time_value_with(set.reps, "tables", &format!("{case},build"), || {
                Ok(build(&stack, &opts)?)
            })?;
        let bytes = table.to_bytes()?.len();
        // Check points (same for every grid: the axes' ranges do not depend on it).
        if checks.is_none() {
            let hd = &table.header;
            let mut rng = SplitMix(SEED);
            let raw: Vec<(f64, f64)> = (0..set.points)
                .map(|_| {
                    let cx = hd.x.lo + (hd.x.hi - hd.x.lo) * rng.next_f64();
                    let w = hd.w.hi * rng.next_f64();
                    let a = h1 * cx.exp();
                    (a, a + h1 * w.sinh().powi(2))
                })
                .collect();
            let a_max = h1 * hd.x.hi.exp();
            let ap = Approx::with_cache(&stack, 2.0 * a_max + h1 * hd.w.hi.sinh().powi(2));
            let direct: Result<Vec<Check>> = raw
                .par_iter()
                .map(|&(a, r)| {
                    let (chi, zeta) = ap.chi_zeta(a)?;
                    Ok(Check {
                        a,
                        r,
                        chi,
                        zeta,
                        g: ap.g(a, r)?,
                    })
                })
                .collect();
            checks = Some(direct?);
        }
        let pts = checks.as_deref().unwrap_or_default();
        let law = table.law_for(&stack)?;
        let lin = Linear::new(&table);
        for order in [Order::Cubic, Order::Linear] {
            let (chi, zeta, g) = match order {
                Order::Cubic => errors_of(pts, |a| (law.chi(a), law.zeta(a)), |a, r| law.g(a, r)),
                Order::Linear => errors_of(pts, |a| lin.chi_zeta(a), |a, r| lin.g(a, r)),
            };
            let n = pts.len().max(1);
            let lookup = match order {
                Order::Cubic => runner.time_batch(
                    "tables",
                    &format!("{case},{},lookup", order.name()),
                    n,
                    |i| {
                        let p = &pts[i % pts.len()];
                        law.chi(p.a) + law.zeta(p.a) + law.g(p.a, p.r)
                    },
                )?,
                Order::Linear => runner.time_batch(
                    "tables",
                    &format!("{case},{},lookup", order.name()),
                    n,
                    |i| {
                        let p = &pts[i % pts.len()];
                        let (c, z) = lin.chi_zeta(p.a);
                        c + z + lin.g(p.a, p.r)
                    },
                )?,
            };
            let ck = format!("{case},{}", order.name());
            errors.push("tables", &ck, "chi error", chi);
            errors.push("tables", &ck, "zeta error", zeta);
            errors.push("tables", &ck, "g error", g);
            errors.push("tables", &ck, "file bytes", bytes as f64);
            rows.push(Row {
                nx,
                nw,
                order,
                chi,
                zeta,
                g,
                build: build_t,
                bytes,
                lookup,
                is_default: (nx, nw) == default_grid && order == Order::Cubic,
            });
        }
    }
    Ok(Results {
        settings: set,
        rows,
    })
}
