//! Stage 3: the second-order approximation (paper §4.1, physics.md §4) against the
//! full Fredholm solution (paper §3).
//!
//! For the paper's stacks E₂/E₁ = 0.2, 1, 5 and a paraboloid of radius R = 100 µm,
//! the full solution (`Asperity` with its default discretisation) at contact radius
//! a gives (δ, P). The approximation at the same approach δ solves ζ(a′)a′²/R = δ and
//! gives P′ = (4/3)E*₁χ(a′)a′³/R (P24). The force error at equal approach is
//!
//! ```text
//!   |P′/P − 1|
//! ```
//!
//! with χ, ζ from direct quadrature (the approximation alone) and from the shipped
//! family table (approximation + interpolation). Times: the full solve (median), one
//! direct χ, ζ quadrature, and one table evaluation of a′(δ) and P′.

use anyhow::{Context, Result, bail};
use strata_runtime::Stack;
use strata_runtime::law::{self, AsperityLaw};
use strata_runtime::table::Table;
use strata_tablegen::approx::Approx;
use strata_tablegen::asperity::{Asperity, Options};

use super::fredholm::{H1, RADIUS};
use super::{Errors, Inputs, Mode, Runner, Timing};

/// Error level quoted as the approximation's validity limit.
pub const LIMIT: f64 = 0.01;

#[derive(Debug, Clone)]
pub struct Settings {
    pub ratios: Vec<f64>,
    pub a_over_h: Vec<f64>,
}

impl Settings {
    pub fn for_mode(mode: Mode) -> Settings {
        let decades = |per: usize| -> Vec<f64> {
            let n = 4 * per;
            (0..=n)
                .map(|i| 10f64.powf(-2.0 + i as f64 / per as f64))
                .collect()
        };
        match mode {
            Mode::Tiny => Settings {
                ratios: vec![5.0],
                a_over_h: vec![0.1, 1.0],
            },
            Mode::Quick => Settings {
                ratios: vec![0.2, 1.0, 5.0],
                a_over_h: decades(2),
            },
            Mode::Full => Settings {
                ratios: vec![0.2, 1.0, 5.0],
                a_over_h: decades(4),
            },
        }
    }
}

#[derive(Debug, Clone)]
pub struct Row {
    pub ratio: f64,
    pub a_over_h: f64,
    pub delta: f64,
    pub force: f64,
    pub error_direct: f64,
    pub error_table: f64,
    pub full: Timing,
    pub direct: Timing,
    pub table: Timing,
}

pub struct Results {
    pub settings: Settings,
    pub table: String,
    pub rows: Vec<Row>,
}

impl Results {
    /// Per stack: the largest a/h₁ of the sweep up to which every direct-χ,ζ error
    /// is below [`LIMIT`] (None when already the first is above).
    pub fn limits(&self) -> Vec<(f64, Option<f64>)> {
        self.settings
            .ratios
            .iter()
            .map(|&ratio| {
                let mut last = None;
                for r in self.rows.iter().filter(|r| r.ratio == ratio) {
                    if r.error_direct < LIMIT {
                        last = Some(r.a_over_h);
                    } else {
                        break;
                    }
                }
                (ratio, last)
            })
            .collect()
    }
}

/// χ, ζ by direct quadrature as an asperity law (g is not needed here).
struct Direct<'a> {
    ap: &'a Approx,
    e_star: f64,
    point_force: law::PointForce,
}

impl AsperityLaw for Direct<'_> {
    fn e_star(&self) -> f64 {
        self.e_star
    }
    fn chi(&self, a: f64) -> f64 {
        self.ap.chi_zeta(a).map_or(f64::NAN, |v| v.0)
    }
    fn zeta(&self, a: f64) -> f64 {
        self.ap.chi_zeta(a).map_or(f64::NAN, |v| v.1)
    }
    fn g(&self, _a: f64, _r: f64) -> f64 {
        f64::NAN
    }
    fn point_force(&self) -> law::PointForce {
        self.point_force
    }
}

/// a′ with ζ(a′)a′²/R = δ ([`law::contact_radius`], to round-off).
fn radius_for(law: &dyn AsperityLaw, delta: f64) -> Result<f64> {
    match law::contact_radius(law, RADIUS, delta) {
        Some(a) if a.is_finite() => Ok(a),
        _ => bail!("cannot solve for the contact radius at δ = {delta:e} m"),
    }
}

pub fn run(runner: &mut Runner, errors: &mut Errors, inputs: &Inputs) -> Result<Results> {
    let set = Settings::for_mode(runner.mode);
    let table = Table::load(&inputs.table)
        .with_context(|| format!("--table {}", inputs.table.display()))?;
    let mut rows = Vec::new();
    for &ratio in &set.ratios {
        let stack = Stack::paper_two_layer(ratio)?;
        let e_star = stack.top_plane_strain_modulus();
        let tlaw = table.law_for(&stack).with_context(|| {
            format!(
                "--table {} does not serve E2/E1 = {ratio}",
                inputs.table.display()
            )
        })?;
        let a_max = set.a_over_h.iter().copied().fold(0.0, f64::max) * H1;
        let ap = Approx::with_cache(&stack, 2.0 * a_max);
        let direct = Direct {
            ap: &ap,
            e_star,
            point_force: law::PointForce::of_stack(&stack),
        };
        let full = Asperity::new(
            &stack,
            Options {
                profile_grid: 2,
                ..Options::default()
            },
        )?;
        for &ah in &set.a_over_h {
            let a = ah * H1;
            let s = runner
                .exact(|| full.paraboloid_at_radius(a, RADIUS))
                .with_context(|| format!("full solution at a/h = {ah}"))?;
            let ad = radius_for(&direct, s.delta)?;
            let pd = law::force(&direct, ad, RADIUS);
            let at = radius_for(&tlaw, s.delta)?;
            let pt = law::force(&tlaw, at, RADIUS);
            let case = format!("E2/E1={ratio},a/h={ah:.4}");
            let full_t = runner.time("approx", &format!("{case},full"), || {
                Ok(full.paraboloid_at_radius(a, RADIUS)?)
            })?;
            let direct_t =
                runner.time_batch("approx", &format!("{case},direct chi zeta"), 4, |_| {
                    ap.chi_zeta(a).map_or(f64::NAN, |v| v.0)
                })?;
            let delta = s.delta;
            let table_t = runner.time_batch("approx", &format!("{case},table"), 200, |i| {
                let d = delta * (1.0 + 1e-9 * (i % 7) as f64);
                let r = law::contact_radius(&tlaw, RADIUS, d).unwrap_or(0.0);
                law::force(&tlaw, r, RADIUS)
            })?;
            let row = Row {
                ratio,
                a_over_h: ah,
                delta: s.delta,
                force: s.force,
                error_direct: (pd / s.force - 1.0).abs(),
                error_table: (pt / s.force - 1.0).abs(),
                full: full_t,
                direct: direct_t,
                table: table_t,
            };
            errors.push("approx", &case, "force error (direct)", row.error_direct);
            errors.push("approx", &case, "force error (table)", row.error_table);
            rows.push(row);
        }
    }
    Ok(Results {
        settings: set,
        table: inputs
            .table
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        rows,
    })
}
