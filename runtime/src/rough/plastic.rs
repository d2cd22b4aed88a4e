//! The N model with capped asperity tips (physics.md §9): every summit alone, each an
//! elastic–perfectly plastic paraboloid (pressure ≤ H) on the layered solid, through a
//! response table built from the capped asperity on rings ([`asperity::response`],
//! feature `capped`).
//!
//! # Scaling
//! A summit of radius R yields (on a half-space) at δ_c = (πH/2E*)² R, with contact
//! radius a_c = πHR/(2E*) and load P_c = (4/3) E* a_c³/R. In x = δ/δ_c and y = a_c/h₁
//! (h₁ the top layer's thickness) the response is P = P_c F(x, y), a = a_c G(x, y), the
//! plastic radius a_p = a Φ(x, y); on a homogeneous solid F, G, Φ do not depend on y
//! (and F = x^{3/2}, G = x^{1/2}, Φ = 0 for x ≤ 1, Hertz). The table holds ln F, ln G and
//! Φ on a grid uniform in (ln x, ln y), bilinear; below its x range the elastic
//! power law F ∝ x^{3/2}, G ∝ x^{1/2} continues the first node, above it the last
//! cell's log–log slopes; y is clamped to its range.
//!
//! # Elastic summits
//! Below x = [`ELASTIC_X`] (peak pressure 0.1 H on a half-space) a summit is taken as
//! elastic and answered by the elastic asperity law itself, whatever y: a scene whose
//! summits all stay below it on its whole load path is the elastic model exactly (no
//! table is needed, so H → ∞ is the elastic model on every stack), and only a summit
//! loaded past it needs the table's range of y.
//!
//! The table's file form (the table cache keeps it) is in [`file`](mod@file).

#[cfg(feature = "capped")]
pub mod asperity;
pub mod file;

use super::{Diagnostics, IndependentError, Model, RoughContact, RoughError, Step, Validity};
use crate::law::{AsperityLaw, contact_radius, force};
use crate::rough::local::Local;

/// Admissible hardnesses H (Pa), inclusive: the Young moduli's range
/// ([`YOUNG_RANGE`](crate::stack::YOUNG_RANGE)), from far below the softest gels to far
/// above diamond (H ≈ 1e11 Pa). Below it a capped contact is fully plastic at any
/// approach and its scales δ_c = (πH/2E*)²R underflow beside the surface's heights
/// (1e-30 Pa gave A/A₀ = 4294; 1e-100 … 1e-305 empty cells or a hang); 1e15 Pa is an
/// uncapped contact on every admissible stack (H → ∞).
pub const HARDNESS_RANGE: (f64, f64) = (1e-3, 1e15);

/// Why `hardness` (Pa) is not admissible ([`HARDNESS_RANGE`]), if it is not.
pub fn hardness_problem(hardness: f64) -> Option<String> {
    let (lo, hi) = HARDNESS_RANGE;
    (!(hardness.is_finite() && (lo..=hi).contains(&hardness))).then(|| {
        format!("{hardness:e} Pa: the hardness must lie in [{lo:e}, {hi:e}] Pa (the Young moduli's range)")
    })
}

/// The smallest x = δ/δ_c of the capped model's response table: below it a summit is
/// elastic (module docs). On a half-space its peak pressure is √x·H = 0.1 H there.
pub const ELASTIC_X: f64 = 1e-2;

/// The yield scale δ_c = (πH/2E*)² R (m) of a summit of radius `radius` (m) for the
/// contact modulus `e_star` and hardness `hardness` (Pa): a half-space's yield onset.
pub fn yield_interference(e_star: f64, hardness: f64, radius: f64) -> f64 {
    let c = std::f64::consts::PI * hardness / (2.0 * e_star);
    c * c * radius
}

/// Whether a summit of radius `radius` (m) at interference `delta` (m) is below the
/// response table's range, x = δ/δ_c < [`ELASTIC_X`] (elastic, module docs).
pub fn below_table(e_star: f64, hardness: f64, delta: f64, radius: f64) -> bool {
    delta < ELASTIC_X * yield_interference(e_star, hardness, radius)
}

/// A uniform axis in ln of its variable: `n` nodes from `lo` to `hi` (ln values).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LogAxis {
    pub lo: f64,
    pub hi: f64,
    pub n: usize,
}

impl LogAxis {
    fn step(&self) -> f64 {
        if self.n > 1 {
            (self.hi - self.lo) / (self.n - 1) as f64
        } else {
            1.0
        }
    }
    /// Node k's ln value.
    pub fn node(&self, k: usize) -> f64 {
        self.lo + self.step() * k as f64
    }
    /// (cell, fraction) of ln value `t`, clamped to the axis.
    fn locate(&self, t: f64) -> (usize, f64) {
        if self.n < 2 {
            return (0, 0.0);
        }
        let s = ((t - self.lo) / self.step()).clamp(0.0, (self.n - 1) as f64);
        let k = (s.floor() as usize).min(self.n - 2);
        (k, s - k as f64)
    }
}

/// The capped asperity's response F, G, Φ over (x, y) (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlasticResponse {
    /// The pair's contact modulus E* (Pa).
    pub e_star: f64,
    /// The hardness H (Pa).
    pub hardness: f64,
    /// h₁ (m); `None` on a homogeneous solid (y unused).
    pub h1: Option<f64>,
    pub x: LogAxis,
    pub y: LogAxis,
    /// ln F, ln G and Φ at node (i along x, j along y), index j·nx + i.
    pub ln_f: Vec<f64>,
    pub ln_g: Vec<f64>,
    pub phi: Vec<f64>,
}

/// One summit's capped response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CappedContact {
    /// Contact radius a (m).
    pub a: f64,
    /// Load P (N).
    pub force: f64,
    /// dP/dδ (N/m).
    pub stiffness: f64,
    /// Plastic radius a_p (m).
    pub a_plastic: f64,
}

impl PlasticResponse {
    /// The bilinear value and its ln x slope of table `v` at (ln x, ln y).
    fn lookup(&self, v: &[f64], lx: f64, ly: f64) -> (f64, f64) {
        let (i, fx) = self.x.locate(lx);
        let (j, fy) = self.y.locate(ly);
        let nx = self.x.n;
        let at = |ii: usize, jj: usize| v[jj.min(self.y.n - 1) * nx + ii];
        let j1 = if self.y.n > 1 { j + 1 } else { j };
        let v0 = at(i, j) * (1.0 - fy) + at(i, j1) * fy;
        let v1 = at(i + 1, j) * (1.0 - fy) + at(i + 1, j1) * fy;
        let slope = (v1 - v0) / self.x.step();
        (v0 + (v1 - v0) * fx, slope)
    }

    /// y = a_c/h₁ of a summit of radius `radius` (m) if the table does not cover it
    /// (layered solids only; a homogeneous one covers every radius).
    pub fn uncovered(&self, radius: f64) -> Option<f64> {
        let h = self.h1?;
        let y = std::f64::consts::PI * self.hardness * radius / (2.0 * self.e_star) / h;
        let ly = y.ln();
        (!(ly >= self.y.lo - 1e-9 && ly <= self.y.hi + 1e-9)).then_some(y)
    }

    /// The response of a summit of radius `radius` (m) at interference `delta` (m).
    pub fn at(&self, delta: f64, radius: f64) -> CappedContact {
        if delta.is_nan() || delta <= 0.0 {
            return CappedContact {
                a: 0.0,
                force: 0.0,
                stiffness: 0.0,
                a_plastic: 0.0,
            };
        }
        let e = self.e_star;
        let ac = std::f64::consts::PI * self.hardness * radius / (2.0 * e);
        let dc = ac * ac / radius;
        let pc = 4.0 / 3.0 * e * ac.powi(3) / radius;
        let lx = (delta / dc).ln();
        let ly = self.h1.map_or(0.0, |h| (ac / h).ln());
        // below the table: the elastic power laws from its first node
        let (lxq, extra_f, extra_g, slope_f) = if lx < self.x.lo {
            let d = lx - self.x.lo;
            (self.x.lo, 1.5 * d, 0.5 * d, Some(1.5))
        } else {
            (lx, 0.0, 0.0, None)
        };
        let (lf, sf) = self.lookup(&self.ln_f, lxq.min(self.x.hi), ly);
        let (lg, sg) = self.lookup(&self.ln_g, lxq.min(self.x.hi), ly);
        let (ph, _) = self.lookup(&self.phi, lxq.min(self.x.hi), ly);
        // above the table: the last cell's log–log slopes
        let over = (lx - self.x.hi).max(0.0);
        let ln_f = lf + extra_f + sf * over;
        let ln_g = lg + extra_g + sg * over;
        let force = pc * ln_f.exp();
        let a = ac * ln_g.exp();
        // dP/dδ = (P/δ) d ln F/d ln x
        let stiffness = force / delta * slope_f.unwrap_or(sf);
        CappedContact {
            a,
            force,
            stiffness,
            a_plastic: a * ph.clamp(0.0, 1.0),
        }
    }
}

/// An elastic summit of radius `radius` at interference `delta` (m) through the elastic
/// law, as the elastic N model takes it: a from ζ(a)a²/R = δ, P = (4/3)E*χ(a)a³/R,
/// dP/dδ = (4/3)E* Q′/δ′.
fn elastic_summit(law: &dyn AsperityLaw, delta: f64, radius: f64) -> Option<CappedContact> {
    let a = contact_radius(law, radius, delta)?;
    let l = Local::at(law, a, radius);
    Some(CappedContact {
        a,
        force: force(law, a, radius),
        stiffness: 4.0 / 3.0 * law.e_star() * l.dq / l.ddelta(a, radius),
        a_plastic: 0.0,
    })
}

impl RoughContact<'_> {
    /// The first summit (index, radius) that some approach of `deltas` (m) loads past
    /// the response table's lower end x = [`ELASTIC_X`] (by its geometric interference,
    /// the N model's), for contact modulus `e_star` and hardness `hardness` (Pa); `None`
    /// when every summit stays elastic on the whole path (module docs). The largest
    /// approach decides: interference grows with it.
    pub fn first_summit_past_elastic(
        &self,
        e_star: f64,
        hardness: f64,
        deltas: &[f64],
    ) -> Option<(usize, f64)> {
        self.summits_past_elastic(e_star, hardness, deltas).next()
    }

    /// Every summit (index, radius) loaded past x = [`ELASTIC_X`] on the path `deltas`
    /// ([`first_summit_past_elastic`](Self::first_summit_past_elastic)).
    pub fn summits_past_elastic(
        &self,
        e_star: f64,
        hardness: f64,
        deltas: &[f64],
    ) -> impl Iterator<Item = (usize, f64)> + '_ {
        let max = deltas
            .iter()
            .copied()
            .filter(|d| d.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        (0..self.summits.len())
            .filter(move |&k| {
                let dk = self.interference(k, max);
                dk > 0.0 && !below_table(e_star, hardness, dk, self.summits[k].radius)
            })
            .map(|k| (k, self.summits[k].radius))
    }

    /// The first summit (index, radius, y = a_c/h₁) loaded past the table's lower end on
    /// the path `deltas` (m) whose y lies outside the table `resp` ([`PlasticResponse::
    /// uncovered`]): the capped model cannot answer it.
    pub fn first_uncovered_loaded(
        &self,
        resp: &PlasticResponse,
        deltas: &[f64],
    ) -> Option<(usize, f64, f64)> {
        let max = deltas
            .iter()
            .copied()
            .filter(|d| d.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        self.summits.iter().enumerate().find_map(|(k, s)| {
            let dk = self.interference(k, max);
            if dk <= 0.0 || below_table(resp.e_star, resp.hardness, dk, s.radius) {
                return None;
            }
            resp.uncovered(s.radius).map(|y| (k, s.radius, y))
        })
    }

    /// The capped N or I model along the approaches `deltas` (m): every step and its
    /// plastic area fraction, or the first failure with its step's index. The I model
    /// solves its elastic curve first (a load path, as an elastic scene does) and caps
    /// each step from it (`capped_from_elastic`: where no summit yields, the elastic step
    /// bit for bit); the N model takes every summit through `resp` at each approach
    /// (summits below the table's range through the elastic law). A step whose contact
    /// areas sum to more than the nominal area is refused
    /// ([`RoughError::AreaAboveNominal`]), as the elastic models refuse it.
    pub fn capped_curve(
        &self,
        resp: &PlasticResponse,
        model: Model,
        deltas: &[f64],
    ) -> Result<Vec<(Step, f64)>, (usize, RoughError)> {
        let steps = self.capped_steps(resp, model, deltas)?;
        // more real contact than the nominal area: refused, as the elastic models refuse it
        if let Some((i, (s, _))) = steps
            .iter()
            .enumerate()
            .find(|(_, (s, _))| s.area_fraction > 1.0)
        {
            return Err((
                i,
                RoughError::AreaAboveNominal {
                    delta: s.delta,
                    area: s.area_fraction,
                    interacting: matches!(model, Model::Interacting(_)),
                },
            ));
        }
        Ok(steps)
    }

    fn capped_steps(
        &self,
        resp: &PlasticResponse,
        model: Model,
        deltas: &[f64],
    ) -> Result<Vec<(Step, f64)>, (usize, RoughError)> {
        match model {
            Model::Interacting(images) => {
                let (elastic, stop) = self.curve_partial(model, deltas);
                if let Some(failed) = stop {
                    return Err(failed);
                }
                elastic
                    .into_iter()
                    .enumerate()
                    .map(|(i, e)| {
                        self.capped_from_elastic(resp, images, e, false)
                            .map_err(|e| (i, e))
                    })
                    .collect()
            }
            Model::Independent => deltas
                .iter()
                .enumerate()
                .map(|(i, &d)| self.solve_independent_plastic(resp, d).map_err(|e| (i, e)))
                .collect(),
        }
    }

    /// The N model with capped tips at approach δ (m): every summit through `resp`.
    /// Returns the step (its `radii` the contact radii) and the plastic area fraction
    /// Σ π a_p²/A₀.
    pub fn solve_independent_plastic(
        &self,
        resp: &PlasticResponse,
        delta: f64,
    ) -> Result<(Step, f64), RoughError> {
        self.check_delta(delta)?;
        let mut radii = vec![0.0; self.summits.len()];
        let (mut load, mut area, mut plastic, mut stiffness, mut contacts) =
            (0.0, 0.0, 0.0, 0.0, 0);
        for (k, s) in self.summits.iter().enumerate() {
            let dk = self.interference(k, delta);
            if dk <= 0.0 {
                continue;
            }
            let c = if below_table(resp.e_star, resp.hardness, dk, s.radius) {
                elastic_summit(self.law, dk, s.radius).ok_or(IndependentError::NoRoot {
                    index: k,
                    delta: dk,
                    radius: s.radius,
                })?
            } else {
                resp.at(dk, s.radius)
            };
            radii[k] = c.a;
            load += c.force;
            stiffness += c.stiffness;
            area += std::f64::consts::PI * c.a * c.a;
            plastic += std::f64::consts::PI * c.a_plastic * c.a_plastic;
            contacts += 1;
        }
        let a0 = self.area();
        let mean_pressure = load / a0;
        let step = Step {
            delta,
            gap: self.top_to_mean() - delta,
            load,
            mean_pressure,
            pressure_ratio: mean_pressure / resp.e_star,
            area_fraction: area / a0,
            contacts,
            stiffness,
            kkt_residual: None,
            iterations: 0,
            radii,
            diagnostics: Diagnostics::default(),
            validity: Validity {
                below_mean_plane: delta > self.top_to_mean(),
                beyond_deepest_valley: delta > self.max_delta(),
                area_above_nominal: area > a0,
                overlapping_contacts: 0,
            },
        };
        Ok((step, plastic / a0))
    }
}
