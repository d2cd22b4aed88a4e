//! Multi-asperity rough contact: the N model (independent asperities) and the I model
//! (interacting asperities, complementary-energy minimisation), physics.md §5, paper
//! §4.2 and eqs. (P19)–(P26).
//!
//! Notation (SI): asperity k has height z_k (m), radius R_k (m), contact radius a_k (m).
//! A rigid flat approaching by δ (m) from first contact with the highest summit z_M gives
//! the interference δ_k = ⟨δ − (z_M − z_k)⟩ (P20) and the separation
//! g_n = (z_M − z̄) − δ (P26). The total load is P = (4/3)E*₁ Σ χ(a_k)a_k³/R_k (N, P24),
//! the real contact area A = π Σ a_k² (m², P25), p_n = P/A₀ (Pa). The normal stiffness
//! is dP/dδ of the whole sample (N/m), computed analytically (N model: chain rule on
//! P(a) and δ(a); I model: implicit differentiation of the stationarity system).
//!
//! The I model minimises over a ≥ 0 (P22)
//!
//! ```text
//! U_E = c Σ_j Q_j [ Σ_{l≠j} G_l(r_lj) + s_j − 2δ_j ],  c = −4α/3 = 2E*₁/3,
//! Q_j = χ(a_j)a_j³/R_j,  s_j = (a_j²/R_j)(ζ(a_j) + 1/5),
//! ```
//!
//! G_l(r) = a_l²ζ(a_l)/R_l for r ≤ a_l and the outside displacement of physics.md §4 for
//! r > a_l. Its gradient, scaled by the positive c·Q_k'(a_k), is
//!
//! ```text
//! F_k = D_k + s_k − 2δ_k + (Q_k s_k' + Σ_j Q_j ∂G_k(r_kj)/∂a_k) / Q_k',   D_k = Σ_{l≠k} G_l(r_lk)
//! ```
//!
//! (homogeneous solid: F_k = 2(a_k²/R_k − δ_k + D_k)). KKT: F_k = 0 where a_k > 0 and
//! F_k(0⁺) ≥ 0 where a_k = 0. The solver is an active-set Newton method on F with
//! projection onto a ≥ 0, warm-started from the previous load step; the residual of
//! both conditions, relative to the largest interference, is returned with each step.
//! With periodic images, every source asperity is repeated on a (2m+1)² block of cells
//! (its own images included); isolated means plain distances inside the sample.

use crate::law::AsperityLaw;
use crate::summits::Summit;
use thiserror::Error;

/// Errors of the rough-contact solvers.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RoughError {
    #[error("no summits: the surface has no asperity to load")]
    NoSummits,
    #[error("{field}: value {value} out of range: {reason}")]
    LoadOutOfRange {
        field: &'static str,
        value: f64,
        reason: String,
    },
    #[error("asperity {index}: cannot solve ζ(a)a²/R = δ for a (δ = {delta}, R = {radius})")]
    NoRoot {
        index: usize,
        delta: f64,
        radius: f64,
    },
    #[error("I model did not converge at δ = {delta}: KKT residual {residual:e}")]
    NotConverged { delta: f64, residual: f64 },
    #[error("non-finite value in {0}")]
    NonFinite(&'static str),
}

/// How interactions treat the sample boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Images {
    /// Interactions stop at the sample edge (plain distances).
    Isolated,
    /// The sample is one cell of a periodic pattern; sources are repeated on the
    /// (2m+1)×(2m+1) block of cells around it (m = 2: the 5×5 sum).
    Periodic(usize),
}

/// Which model a solve uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    /// N model: independent asperities.
    Independent,
    /// I model: interacting asperities with the given image convention.
    Interacting(Images),
}

/// Results of one load step.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// Approach δ (m).
    pub delta: f64,
    /// Separation g_n = (z_M − z̄) − δ (m).
    pub gap: f64,
    /// Total load P (N).
    pub load: f64,
    /// Mean pressure p_n = P/A₀ (Pa).
    pub mean_pressure: f64,
    /// p_n/E*₁ (-).
    pub pressure_ratio: f64,
    /// Real contact area fraction A/A₀ (-).
    pub area_fraction: f64,
    /// Number of asperities in contact.
    pub contacts: usize,
    /// Normal stiffness dP/dδ of the sample (N/m).
    pub stiffness: f64,
    /// I model only: KKT residual relative to the largest interference.
    pub kkt_residual: Option<f64>,
    /// Newton iterations (I model only; 0 otherwise).
    pub iterations: usize,
    /// Contact radius of every summit (m), 0 when out of contact.
    pub radii: Vec<f64>,
}

/// A rough surface reduced to its summits, on a given material law.
pub struct RoughContact<'a> {
    law: &'a dyn AsperityLaw,
    summits: Vec<Summit>,
    z_max: f64,
    z_mean: f64,
    z_min: f64,
    extent: (f64, f64),
    /// Relative tolerance of the far-field (point-force) interaction; 0 disables it.
    far_tol: f64,
    /// γ(r)·r of the layered far field, tabulated lazily (layered laws only).
    gamma: std::sync::OnceLock<Option<GammaTable>>,
}

/// γ(r) = lim_{a→0} g(a, r)/a³ (1/m), stored as γ·r on a uniform ln r grid and
/// interpolated by Catmull–Rom cubics (checked at the midpoints at build time).
struct GammaTable {
    ln_lo: f64,
    step: f64,
    v: Vec<f64>,
}

impl GammaTable {
    fn eval_raw(law: &dyn AsperityLaw, r: f64) -> f64 {
        let a = 1e-4 * r;
        law.g(a, r) / a.powi(3) * r
    }
    fn build(law: &dyn AsperityLaw, lo: f64, hi: f64) -> Option<GammaTable> {
        let mut n = 1024;
        while n <= 65536 {
            let (ln_lo, ln_hi) = (lo.ln(), hi.ln());
            let step = (ln_hi - ln_lo) / (n - 1) as f64;
            let v: Vec<f64> = (0..n)
                .map(|i| Self::eval_raw(law, (ln_lo + step * i as f64).exp()))
                .collect();
            if v.iter().any(|x| !x.is_finite()) {
                return None;
            }
            let t = GammaTable { ln_lo, step, v };
            let worst = (0..n - 1)
                .map(|i| {
                    let r = (ln_lo + step * (i as f64 + 0.5)).exp();
                    (t.eval(r) * r - Self::eval_raw(law, r)).abs()
                })
                .fold(0.0, f64::max);
            // relative to the half-space point force (4/3)/r, i.e. 4/3 in γ·r units
            if worst <= 1e-8 * 4.0 / 3.0 {
                return Some(t);
            }
            n *= 2;
        }
        None
    }
    /// γ(r) (1/m).
    fn eval(&self, r: f64) -> f64 {
        let n = self.v.len();
        let u = (r.ln() - self.ln_lo) / self.step;
        let i = (u.floor() as isize).clamp(1, n as isize - 3) as usize;
        let t = u - i as f64;
        let (p0, p1, p2, p3) = (self.v[i - 1], self.v[i], self.v[i + 1], self.v[i + 2]);
        let y = p1
            + 0.5
                * t
                * (p2 - p0
                    + t * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + t * (3.0 * (p1 - p2) + p3 - p0)));
        y / r
    }
}

/// Solves ζ(a)a²/R = δ for a ≥ 0 (m): homogeneous a = √(Rδ); otherwise safeguarded
/// Newton on a bracket grown from the Hertz value.
pub fn contact_radius(law: &dyn AsperityLaw, radius: f64, delta: f64) -> Option<f64> {
    if delta.is_nan() || delta <= 0.0 {
        return Some(0.0);
    }
    let hertz = (radius * delta).sqrt();
    if law.is_homogeneous() {
        return Some(hertz);
    }
    let f = |a: f64| law.zeta(a) * a * a / radius - delta;
    let (mut lo, mut hi) = (0.0, hertz);
    let mut k = 0;
    while f(hi) < 0.0 {
        lo = hi;
        hi *= 2.0;
        k += 1;
        if k > 60 || !hi.is_finite() {
            return None;
        }
    }
    let mut a = 0.5 * (lo + hi);
    for _ in 0..200 {
        let (_, _, z, dz) = law.chi_zeta_derivs(a);
        let v = z * a * a / radius - delta;
        if !v.is_finite() {
            return None;
        }
        if v.abs() <= 1e-15 * delta {
            return Some(a);
        }
        if v < 0.0 {
            lo = a;
        } else {
            hi = a;
        }
        let d = (dz * a * a + 2.0 * z * a) / radius;
        let mut next = a - v / d;
        if !next.is_finite() || next <= lo || next >= hi {
            next = 0.5 * (lo + hi);
        }
        if (next - a).abs() <= 1e-15 * a {
            return Some(next);
        }
        a = next;
    }
    Some(a)
}

/// Local (single-asperity) quantities at contact radius a.
#[derive(Debug, Clone, Copy, Default)]
struct Local {
    q: f64,
    dq: f64,
    s: f64,
    ds: f64,
    zeta: f64,
    dzeta: f64,
    chi: f64,
    dchi: f64,
}

fn local(law: &dyn AsperityLaw, a: f64, r: f64) -> Local {
    let (chi, dchi, zeta, dzeta) = law.chi_zeta_derivs(a);
    Local {
        q: chi * a.powi(3) / r,
        dq: (dchi * a.powi(3) + 3.0 * chi * a * a) / r,
        s: a * a / r * (zeta + 0.2),
        ds: (2.0 * a * (zeta + 0.2) + a * a * dzeta) / r,
        zeta,
        dzeta,
        chi,
        dchi,
    }
}

/// G(r) and ∂G/∂a of an asperity (contact radius a, radius R) at distance r (P19).
fn g_and_da(law: &dyn AsperityLaw, l: &Local, a: f64, radius: f64, r: f64) -> (f64, f64) {
    if a <= 0.0 {
        return (0.0, 0.0);
    }
    if r <= a {
        return (
            a * a * l.zeta / radius,
            (2.0 * a * l.zeta + a * a * l.dzeta) / radius,
        );
    }
    let x = a / r;
    let asin = x.asin();
    let b = (2.0 * a * a - r * r) * asin + a * (r * r - a * a).sqrt();
    let db = 4.0 * a * asin;
    let (g, dg) = if law.is_homogeneous() {
        (0.0, 0.0)
    } else {
        let h = 1e-5 * a;
        // keep a + h < r so that g stays on its r > a branch
        let h = h.min(0.5 * (r - a));
        let gp = law.g(a + h, r);
        let gm = law.g(a - h, r);
        (law.g(a, r), (gp - gm) / (2.0 * h))
    };
    let k = 1.0 / (std::f64::consts::PI * radius);
    (
        l.chi * k * (b + g),
        k * (l.dchi * (b + g) + l.chi * (db + dg)),
    )
}

/// Geometry of the candidate asperities: image distances of every pair.
struct Geometry {
    /// Candidate summit indices.
    cand: Vec<usize>,
    /// Unordered pairs (p, q) of local indices with the start of their distances.
    pairs: Vec<(usize, usize, usize, usize)>,
    /// Self-image distances of each local index (start, end).
    selfs: Vec<(usize, usize)>,
    /// Pairs (indices into `pairs`) each local index belongs to.
    adj: Vec<Vec<usize>>,
    dist: Vec<f64>,
    /// Far-field kernels Σ_images K1(r), Σ_images K3(r) (dense m×m; empty when no
    /// pair is far).
    k1: Vec<f64>,
    k3: Vec<f64>,
    /// Near/far cut-off distance (m); kept for diagnostics.
    #[allow(dead_code)]
    cutoff: f64,
}

/// Far-field (point-force plus next order) kernels of a source at distance r:
/// G ≈ Q·K1(r) + Q a²·K3(r), K1 = ((4/3)/r + γ(r))/π, K3 = (2/15)/(π r³), from
/// (2a² − r²)asin(a/r) + a√(r² − a²) = (4/3)a³/r + (2/15)a⁵/r³ + O(a⁷/r⁵) and
/// g(a, r) = a³γ(r) + O(a⁵).
fn far_kernels(gamma: Option<&GammaTable>, r: f64) -> (f64, f64) {
    let g = gamma.map_or(0.0, |t| t.eval(r));
    (
        (4.0 / 3.0 / r + g) / std::f64::consts::PI,
        2.0 / 15.0 / (std::f64::consts::PI * r.powi(3)),
    )
}

impl<'a> RoughContact<'a> {
    /// Reduces a surface (its summits, z̄, z_min and extent (m)) on a law.
    pub fn new(
        law: &'a dyn AsperityLaw,
        summits: Vec<Summit>,
        z_mean: f64,
        z_min: f64,
        extent: (f64, f64),
    ) -> Result<Self, RoughError> {
        let z_max = summits
            .iter()
            .map(|s| s.z)
            .fold(f64::NEG_INFINITY, f64::max);
        if summits.is_empty() {
            return Err(RoughError::NoSummits);
        }
        Ok(RoughContact {
            law,
            summits,
            z_max,
            z_mean,
            z_min,
            extent,
            far_tol: 1e-6,
            gamma: std::sync::OnceLock::new(),
        })
    }

    /// Convenience: from a surface.
    pub fn from_surface(
        law: &'a dyn AsperityLaw,
        surface: &crate::surface::Surface,
    ) -> Result<Self, RoughError> {
        let s = crate::summits::find_summits(surface);
        let z_min = surface
            .heights()
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        Self::new(law, s.summits, surface.mean(), z_min, surface.extent())
    }

    /// Sets the relative tolerance of the far-field (point-force) treatment of distant
    /// pairs (default 1e-6, relative to the point-force displacement (4/3)χa³/(πRr));
    /// 0 evaluates every interaction exactly.
    pub fn with_far_field_tolerance(mut self, tol: f64) -> Self {
        self.far_tol = tol.max(0.0);
        self
    }

    fn clone_with_tol(&self, tol: f64) -> RoughContact<'a> {
        RoughContact {
            law: self.law,
            summits: self.summits.clone(),
            z_max: self.z_max,
            z_mean: self.z_mean,
            z_min: self.z_min,
            extent: self.extent,
            far_tol: tol,
            gamma: std::sync::OnceLock::new(),
        }
    }

    /// The summits.
    pub fn summits(&self) -> &[Summit] {
        &self.summits
    }
    /// z_M − z̄ (m): the approach at which g_n = 0.
    pub fn top_to_mean(&self) -> f64 {
        self.z_max - self.z_mean
    }
    /// Largest meaningful approach z_M − z_min (m).
    pub fn max_delta(&self) -> f64 {
        self.z_max - self.z_min
    }
    /// Nominal area A₀ (m²).
    pub fn area(&self) -> f64 {
        self.extent.0 * self.extent.1
    }
    /// Approach δ (m) for a separation g_n (m) (P26).
    pub fn delta_for_gap(&self, gap: f64) -> f64 {
        self.top_to_mean() - gap
    }

    fn check_delta(&self, delta: f64) -> Result<(), RoughError> {
        if !delta.is_finite() || delta < 0.0 || delta > self.max_delta() {
            return Err(RoughError::LoadOutOfRange {
                field: "load",
                value: delta,
                reason: format!(
                    "the approach δ must lie in [0, z_M − z_min] = [0, {:e}] m (separation in [{:e}, {:e}] m)",
                    self.max_delta(),
                    self.top_to_mean() - self.max_delta(),
                    self.top_to_mean()
                ),
            });
        }
        Ok(())
    }

    fn interference(&self, k: usize, delta: f64) -> f64 {
        (delta - (self.z_max - self.summits[k].z)).max(0.0)
    }

    fn finish(
        &self,
        delta: f64,
        radii: Vec<f64>,
        stiffness: f64,
        kkt: Option<f64>,
        iterations: usize,
    ) -> Result<Step, RoughError> {
        let e = self.law.e_star();
        let mut load = 0.0;
        let mut area = 0.0;
        let mut contacts = 0;
        for (s, &a) in self.summits.iter().zip(&radii) {
            if a > 0.0 {
                load += 4.0 / 3.0 * e * self.law.chi(a) * a.powi(3) / s.radius;
                area += std::f64::consts::PI * a * a;
                contacts += 1;
            }
        }
        let a0 = self.area();
        let step = Step {
            delta,
            gap: self.top_to_mean() - delta,
            load,
            mean_pressure: load / a0,
            pressure_ratio: load / a0 / e,
            area_fraction: area / a0,
            contacts,
            stiffness,
            kkt_residual: kkt,
            iterations,
            radii,
        };
        if !(step.load.is_finite() && step.stiffness.is_finite() && step.area_fraction.is_finite())
        {
            return Err(RoughError::NonFinite("step results"));
        }
        Ok(step)
    }

    /// N model at approach δ (m): every asperity alone, ζ(a_k)a_k²/R_k = δ_k.
    pub fn solve_independent(&self, delta: f64) -> Result<Step, RoughError> {
        self.check_delta(delta)?;
        let e = self.law.e_star();
        let mut radii = vec![0.0; self.summits.len()];
        let mut stiffness = 0.0;
        for (k, s) in self.summits.iter().enumerate() {
            let dk = self.interference(k, delta);
            if dk <= 0.0 {
                continue;
            }
            let a = contact_radius(self.law, s.radius, dk).ok_or(RoughError::NoRoot {
                index: k,
                delta: dk,
                radius: s.radius,
            })?;
            radii[k] = a;
            let l = local(self.law, a, s.radius);
            // dP/dδ_k = (dP/da)/(dδ_k/da), dδ_k/da = (ζ'a² + 2ζa)/R
            let dd = (l.dzeta * a * a + 2.0 * l.zeta * a) / s.radius;
            stiffness += 4.0 / 3.0 * e * l.dq / dd;
        }
        self.finish(delta, radii, stiffness, None, 0)
    }

    /// Smallest distance beyond which the far-field model of a source (radius a ≤
    /// a_max) is within `far_tol` of the exact G and ∂G/∂a, relative to the point-force
    /// scale (4/3)χa³/(πRr); checked at r_c·{1, 1.5, 2, 3, 5, 10}. ∞ when disabled or
    /// not reached below `r_max`.
    fn far_cutoff(&self, a_max: f64, r_max: f64) -> f64 {
        if self.far_tol.is_nan() || self.far_tol <= 0.0 || a_max.is_nan() || a_max <= 0.0 {
            return f64::INFINITY;
        }
        let gamma = self.gamma_table();
        if !self.law.is_homogeneous() && gamma.is_none() {
            return f64::INFINITY;
        }
        let l = local(self.law, a_max, 1.0);
        let err = |r: f64| -> f64 {
            let (g, h) = g_and_da(self.law, &l, a_max, 1.0, r);
            let (k1, k3) = far_kernels(gamma, r);
            let gf = l.q * k1 + l.q * a_max * a_max * k3;
            let hf = l.dq * k1 + (l.dq * a_max * a_max + 2.0 * a_max * l.q) * k3;
            let sg = 4.0 / 3.0 * l.q / (std::f64::consts::PI * r);
            let sh = 4.0 / 3.0 * l.dq / (std::f64::consts::PI * r);
            ((g - gf) / sg).abs().max(((h - hf) / sh).abs())
        };
        let mut rc = 3.0 * a_max;
        while rc < r_max {
            if [1.0, 1.5, 2.0, 3.0, 5.0, 10.0]
                .iter()
                .all(|f| err(rc * f) <= self.far_tol)
            {
                return rc;
            }
            rc *= 1.25;
        }
        f64::INFINITY
    }

    fn gamma_table(&self) -> Option<&GammaTable> {
        if self.law.is_homogeneous() {
            return None;
        }
        self.gamma
            .get_or_init(|| {
                let (lx, ly) = self.extent;
                GammaTable::build(self.law, 1e-4 * lx.min(ly), 100.0 * lx.max(ly))
            })
            .as_ref()
    }

    fn geometry(&self, cand: Vec<usize>, images: Images, a_max: f64) -> Geometry {
        let (lx, ly) = self.extent;
        let m = match images {
            Images::Isolated => 0i64,
            Images::Periodic(m) => m as i64,
        };
        let n = cand.len();
        let r_max = (2 * m + 2) as f64 * lx.hypot(ly);
        let rc = self.far_cutoff(a_max, r_max);
        let gamma = self.gamma_table();
        let mut k1 = Vec::new();
        let mut k3 = Vec::new();
        let has_far = rc.is_finite();
        if has_far {
            k1 = vec![0.0; n * n];
            k3 = vec![0.0; n * n];
        }
        let mut dist = Vec::new();
        let mut selfs = Vec::with_capacity(n);
        for p in 0..n {
            let st = dist.len();
            for sx in -m..=m {
                for sy in -m..=m {
                    if (sx, sy) != (0, 0) {
                        let r = (sx as f64 * lx).hypot(sy as f64 * ly);
                        if r < rc {
                            dist.push(r);
                        } else {
                            let (a1, a3) = far_kernels(gamma, r);
                            k1[p * n + p] += a1;
                            k3[p * n + p] += a3;
                        }
                    }
                }
            }
            selfs.push((st, dist.len()));
        }
        let mut pairs = Vec::new();
        for p in 0..n {
            for q in p + 1..n {
                let (a, b) = (&self.summits[cand[p]], &self.summits[cand[q]]);
                let st = dist.len();
                let (mut s1, mut s3) = (0.0, 0.0);
                for sx in -m..=m {
                    for sy in -m..=m {
                        let dx = b.x + sx as f64 * lx - a.x;
                        let dy = b.y + sy as f64 * ly - a.y;
                        let r = dx.hypot(dy);
                        if r < rc {
                            dist.push(r);
                        } else {
                            let (a1, a3) = far_kernels(gamma, r);
                            s1 += a1;
                            s3 += a3;
                        }
                    }
                }
                if has_far {
                    k1[p * n + q] = s1;
                    k1[q * n + p] = s1;
                    k3[p * n + q] = s3;
                    k3[q * n + p] = s3;
                }
                if dist.len() > st {
                    pairs.push((p, q, st, dist.len()));
                }
            }
        }
        let mut adj = vec![Vec::new(); n];
        for (i, &(p, q, _, _)) in pairs.iter().enumerate() {
            adj[p].push(i);
            adj[q].push(i);
        }
        Geometry {
            cand,
            pairs,
            selfs,
            adj,
            dist,
            k1,
            k3,
            cutoff: rc,
        }
    }

    fn locals(&self, geo: &Geometry, a: &[f64]) -> Vec<Local> {
        (0..geo.cand.len())
            .map(|p| {
                if a[p] > 0.0 {
                    local(self.law, a[p], self.summits[geo.cand[p]].radius)
                } else {
                    Local::default()
                }
            })
            .collect()
    }

    /// F (length m) of every local index at contact radii `a` (NaN where a = 0), and
    /// optionally the off-diagonal Jacobian (row-major m×m, diagonal left 0).
    fn residual(
        &self,
        geo: &Geometry,
        a: &[f64],
        loc: &[Local],
        deltas: &[f64],
        jac: Option<&mut Vec<f64>>,
    ) -> Vec<f64> {
        let n = geo.cand.len();
        let mut d = vec![0.0; n];
        let mut e = vec![0.0; n];
        let mut jac = jac;
        if let Some(j) = jac.as_deref_mut() {
            j.clear();
            j.resize(n * n, 0.0);
        }
        for &(p, q, st, en) in &geo.pairs {
            let (rp, rq) = (
                self.summits[geo.cand[p]].radius,
                self.summits[geo.cand[q]].radius,
            );
            let (mut gp, mut hp, mut gq, mut hq) = (0.0, 0.0, 0.0, 0.0);
            for &r in &geo.dist[st..en] {
                let (g1, h1) = g_and_da(self.law, &loc[p], a[p], rp, r);
                let (g2, h2) = g_and_da(self.law, &loc[q], a[q], rq, r);
                gp += g1;
                hp += h1;
                gq += g2;
                hq += h2;
            }
            d[q] += gp;
            d[p] += gq;
            e[p] += loc[q].q * hp;
            e[q] += loc[p].q * hq;
            if let Some(j) = jac.as_deref_mut() {
                if loc[q].dq > 0.0 {
                    j[q * n + p] = hp + loc[p].dq * hq / loc[q].dq;
                }
                if loc[p].dq > 0.0 {
                    j[p * n + q] = hq + loc[q].dq * hp / loc[p].dq;
                }
            }
        }
        for p in 0..n {
            let rp = self.summits[geo.cand[p]].radius;
            let (st, en) = geo.selfs[p];
            for &r in &geo.dist[st..en] {
                let (g1, h1) = g_and_da(self.law, &loc[p], a[p], rp, r);
                d[p] += g1;
                e[p] += loc[p].q * h1;
            }
        }
        if !geo.k1.is_empty() {
            // Far field: G = Q K1 + Q a² K3, ∂G/∂a = Q' K1 + (Q a²)' K3.
            let qa2: Vec<f64> = (0..n).map(|l| loc[l].q * a[l] * a[l]).collect();
            let dqa2: Vec<f64> = (0..n)
                .map(|l| loc[l].dq * a[l] * a[l] + 2.0 * a[l] * loc[l].q)
                .collect();
            for k in 0..n {
                let row1 = &geo.k1[k * n..(k + 1) * n];
                let row3 = &geo.k3[k * n..(k + 1) * n];
                let (mut f1, mut f3a, mut f3) = (0.0, 0.0, 0.0);
                for l in 0..n {
                    f1 += row1[l] * loc[l].q;
                    f3a += row3[l] * qa2[l];
                    f3 += row3[l] * loc[l].q;
                }
                d[k] += f1 + f3a;
                e[k] += loc[k].dq * f1 + dqa2[k] * f3;
                if let Some(j) = jac.as_deref_mut()
                    && loc[k].dq > 0.0
                {
                    let ratio = dqa2[k] / loc[k].dq;
                    for l in 0..n {
                        if l != k {
                            j[k * n + l] += 2.0 * loc[l].dq * row1[l]
                                + dqa2[l] * row3[l]
                                + ratio * loc[l].dq * row3[l];
                        }
                    }
                }
            }
        }
        (0..n)
            .map(|p| {
                let l = &loc[p];
                if a[p] > 0.0 {
                    d[p] + l.s - 2.0 * deltas[p] + (l.q * l.ds + e[p]) / l.dq
                } else {
                    f64::NAN
                }
            })
            .collect()
    }

    /// The Jacobian of the residual restricted to the active set `act` (row-major
    /// |act|²): off-diagonal entries from the assembled `jac` (n×n), diagonal entries by
    /// central differences of [`Self::row`] with relative step 1e-6.
    fn active_jacobian(
        &self,
        geo: &Geometry,
        a: &[f64],
        loc: &[Local],
        deltas: &[f64],
        jac: &[f64],
        act: &[usize],
    ) -> Vec<f64> {
        let (n, m) = (a.len(), act.len());
        let mut jm = vec![0.0; m * m];
        for (ii, &p) in act.iter().enumerate() {
            for (jj, &q) in act.iter().enumerate() {
                jm[ii * m + jj] = jac[p * n + q];
            }
            let h = 1e-6 * a[p];
            let fp = self.row(geo, a, loc, deltas, p, a[p] + h, false);
            let fm = self.row(geo, a, loc, deltas, p, a[p] - h, false);
            jm[ii * m + ii] = (fp - fm) / (2.0 * h);
        }
        jm
    }

    /// F_k as a function of a_k alone, the other radii (and their `loc`) fixed: the
    /// Jacobian diagonal and F_k(0⁺) of inactive asperities. With `full = false` the
    /// near-field displacement of the others (constant in a_k) is left out: enough for
    /// differences in a_k, at half the cost.
    #[allow(clippy::too_many_arguments)]
    fn row(
        &self,
        geo: &Geometry,
        a: &[f64],
        loc: &[Local],
        deltas: &[f64],
        p: usize,
        ap: f64,
        full: bool,
    ) -> f64 {
        let rp = self.summits[geo.cand[p]].radius;
        let lp = local(self.law, ap, rp);
        let mut d = 0.0;
        let mut e = 0.0;
        for &pi in &geo.adj[p] {
            let (i, j, st, en) = geo.pairs[pi];
            let other = if i == p { j } else { i };
            if a[other] <= 0.0 {
                continue;
            }
            let ro = self.summits[geo.cand[other]].radius;
            let lo = &loc[other];
            for &r in &geo.dist[st..en] {
                if full {
                    d += g_and_da(self.law, lo, a[other], ro, r).0;
                }
                let (_, h2) = g_and_da(self.law, &lp, ap, rp, r);
                e += lo.q * h2;
            }
        }
        let (st, en) = geo.selfs[p];
        for &r in &geo.dist[st..en] {
            let (g1, h1) = g_and_da(self.law, &lp, ap, rp, r);
            d += g1;
            e += lp.q * h1;
        }
        if !geo.k1.is_empty() {
            let n = geo.cand.len();
            let row1 = &geo.k1[p * n..(p + 1) * n];
            let row3 = &geo.k3[p * n..(p + 1) * n];
            let (mut f1, mut f3a, mut f3) = (0.0, 0.0, 0.0);
            for l in 0..n {
                let (q, aa) = if l == p { (lp.q, ap) } else { (loc[l].q, a[l]) };
                f1 += row1[l] * q;
                f3a += row3[l] * q * aa * aa;
                f3 += row3[l] * q;
            }
            d += f1 + f3a;
            e += lp.dq * f1 + (lp.dq * ap * ap + 2.0 * ap * lp.q) * f3;
        }
        d + lp.s - 2.0 * deltas[p] + (lp.q * lp.ds + e) / lp.dq
    }

    /// I model at approach δ (m), warm-started from `warm` (contact radii of every
    /// summit, m; empty for a cold start).
    pub fn solve_interacting(
        &self,
        delta: f64,
        images: Images,
        warm: &[f64],
    ) -> Result<Step, RoughError> {
        self.check_delta(delta)?;
        let cand: Vec<usize> = (0..self.summits.len())
            .filter(|&k| self.interference(k, delta) > 0.0)
            .collect();
        if cand.is_empty() {
            return self.finish(delta, vec![0.0; self.summits.len()], 0.0, Some(0.0), 0);
        }
        let n = cand.len();
        let deltas: Vec<f64> = cand.iter().map(|&k| self.interference(k, delta)).collect();
        let scale = deltas.iter().copied().fold(0.0, f64::max);
        // Newton target; the KKT acceptance threshold is 1e-8 (relative).
        let tol = 1e-11 * scale;
        // Start: previous radii where positive, else the N-model radius.
        let n_model: Vec<f64> = (0..n)
            .map(|p| {
                contact_radius(self.law, self.summits[cand[p]].radius, deltas[p]).unwrap_or(0.0)
            })
            .collect();
        let mut a: Vec<f64> = (0..n)
            .map(|p| {
                let w = warm.get(cand[p]).copied().unwrap_or(0.0);
                if w > 0.0 { w } else { n_model[p] }
            })
            .collect();
        // Interactions only shrink contacts, so the N-model radii bound a (the far-field
        // cut-off is chosen for that bound; re-checked after the solve).
        let a_bound = 1.2 * n_model.iter().chain(a.iter()).copied().fold(0.0, f64::max);
        let geo = self.geometry(cand, images, a_bound);
        let mut jac = Vec::new();
        let mut iterations = 0;
        let mut kkt = f64::INFINITY;
        for _outer in 0..50 {
            // Newton on the active set.
            for _ in 0..100 {
                iterations += 1;
                let loc = self.locals(&geo, &a);
                let f = self.residual(&geo, &a, &loc, &deltas, Some(&mut jac));
                let act: Vec<usize> = (0..n).filter(|&p| a[p] > 0.0).collect();
                let fmax = act.iter().map(|&p| f[p].abs()).fold(0.0, f64::max);
                let f2: f64 = act.iter().map(|&p| f[p] * f[p]).sum();
                if !fmax.is_finite() {
                    return Err(RoughError::NonFinite("I-model residual"));
                }
                if fmax <= tol || act.is_empty() {
                    break;
                }
                let m = act.len();
                let mut jm = self.active_jacobian(&geo, &a, &loc, &deltas, &jac, &act);
                let mut rhs: Vec<f64> = act.iter().map(|&p| -f[p]).collect();
                let step = lu_solve(&mut jm, &mut rhs, m)
                    .ok_or(RoughError::NonFinite("I-model Jacobian (singular)"))?;
                // Damped, projected step on the merit max|F|.
                let mut t = 1.0;
                let mut accepted = false;
                for _ in 0..12 {
                    let mut trial = a.clone();
                    for (ii, &p) in act.iter().enumerate() {
                        let v = a[p] + t * step[ii];
                        trial[p] = if v <= 1e-9 * a[p] { 0.0 } else { v };
                    }
                    let lt = self.locals(&geo, &trial);
                    let ft = self.residual(&geo, &trial, &lt, &deltas, None);
                    let ft2: f64 = (0..n)
                        .filter(|&p| trial[p] > 0.0)
                        .map(|p| ft[p] * ft[p])
                        .sum();
                    let dropped = act.iter().any(|&p| trial[p] == 0.0);
                    // Sufficient decrease of Σ F²; tiny steps are taken anyway so that
                    // the iteration moves off a kink (G jumps where contacts overlap).
                    if dropped || ft2 < (1.0 - 1e-4 * t) * f2 || t < 1e-3 {
                        a = trial;
                        accepted = true;
                        break;
                    }
                    t *= 0.5;
                }
                if !accepted {
                    break;
                }
            }
            // KKT check: active F = 0, inactive F(0⁺) ≥ 0.
            let loc = self.locals(&geo, &a);
            let f = self.residual(&geo, &a, &loc, &deltas, None);
            let mut worst_act: f64 = 0.0;
            let mut worst_inact = (0.0f64, None);
            for p in 0..n {
                if a[p] > 0.0 {
                    worst_act = worst_act.max(f[p].abs());
                } else {
                    let tiny = 1e-6 * (self.summits[geo.cand[p]].radius * deltas[p]).sqrt();
                    let f0 = self.row(&geo, &a, &loc, &deltas, p, tiny, true);
                    if -f0 > worst_inact.0 {
                        worst_inact = (-f0, Some(p));
                    }
                }
            }
            kkt = worst_act.max(worst_inact.0) / scale;
            match worst_inact.1 {
                Some(p) if worst_inact.0 > tol => {
                    // Activate the most violated asperity from its N-model radius
                    // reduced by the others' displacement.
                    let f0 = worst_inact.0 / 2.0;
                    let r = self.summits[geo.cand[p]].radius;
                    a[p] = contact_radius(self.law, r, f0.min(deltas[p]))
                        .unwrap_or(0.0)
                        .max(1e-3 * (r * deltas[p]).sqrt());
                }
                // No violated inactive constraint: done when the active set is solved
                // (else Newton restarts from here; the KKT residual is checked below).
                _ => {
                    if worst_act <= 1e-9 * scale {
                        break;
                    }
                }
            }
        }
        if kkt.is_nan() || kkt >= 1e-8 {
            return Err(RoughError::NotConverged {
                delta,
                residual: kkt,
            });
        }
        // Stiffness: J da/dδ = 2·1 on the active set; dP/dδ = (4/3)E* Σ Q'_k da_k/dδ.
        if a.iter().any(|&x| x > a_bound) {
            // Outside the far-field error bound: redo with the exact interactions.
            return self
                .clone_with_tol(0.0)
                .solve_interacting(delta, images, warm);
        }
        let loc = self.locals(&geo, &a);
        let _ = self.residual(&geo, &a, &loc, &deltas, Some(&mut jac));
        let act: Vec<usize> = (0..n).filter(|&p| a[p] > 0.0).collect();
        let m = act.len();
        let mut jm = self.active_jacobian(&geo, &a, &loc, &deltas, &jac, &act);
        let mut rhs = vec![2.0; m];
        let dadd = lu_solve(&mut jm, &mut rhs, m)
            .ok_or(RoughError::NonFinite("I-model Jacobian (singular)"))?;
        let e = self.law.e_star();
        let mut stiffness = 0.0;
        for (ii, &p) in act.iter().enumerate() {
            let l = local(self.law, a[p], self.summits[geo.cand[p]].radius);
            stiffness += 4.0 / 3.0 * e * l.dq * dadd[ii];
        }
        let mut radii = vec![0.0; self.summits.len()];
        for p in 0..n {
            radii[geo.cand[p]] = a[p];
        }
        self.finish(delta, radii, stiffness, Some(kkt), iterations)
    }

    /// Solves one step of `model` at approach δ (m); `warm` as in
    /// [`solve_interacting`](Self::solve_interacting).
    pub fn solve(&self, model: Model, delta: f64, warm: &[f64]) -> Result<Step, RoughError> {
        match model {
            Model::Independent => self.solve_independent(delta),
            Model::Interacting(im) => self.solve_interacting(delta, im, warm),
        }
    }

    /// A load path: one step per approach, warm-started in order.
    pub fn curve(&self, model: Model, deltas: &[f64]) -> Result<Vec<Step>, RoughError> {
        let mut out: Vec<Step> = Vec::with_capacity(deltas.len());
        let mut warm: Vec<f64> = Vec::new();
        for &d in deltas {
            let s = self.solve(model, d, &warm)?;
            warm = s.radii.clone();
            out.push(s);
        }
        Ok(out)
    }

    /// Finds the approach giving mean pressure `target` (Pa) by safeguarded Newton
    /// (the stiffness is dP/dδ) on the bracket [0, z_M − z_min]; relative tolerance 1e-10.
    pub fn solve_pressure(
        &self,
        model: Model,
        target: f64,
        warm: &[f64],
    ) -> Result<Step, RoughError> {
        let hi_step = self.solve(model, self.max_delta(), warm)?;
        if target.is_nan() || target <= 0.0 || target > hi_step.mean_pressure {
            return Err(RoughError::LoadOutOfRange {
                field: "load.mean_pressures",
                value: target,
                reason: format!(
                    "must lie in (0, {:e}] Pa (the mean pressure at full approach z_M − z_min)",
                    hi_step.mean_pressure
                ),
            });
        }
        let (mut lo, mut hi) = (0.0, self.max_delta());
        let mut d = 0.5 * hi;
        let mut w = warm.to_vec();
        for _ in 0..200 {
            let s = self.solve(model, d, &w)?;
            let err = s.mean_pressure - target;
            if err.abs() <= 1e-10 * target {
                return Ok(s);
            }
            if err < 0.0 {
                lo = d;
            } else {
                hi = d;
            }
            let slope = s.stiffness / self.area();
            let mut next = d - err / slope;
            if !next.is_finite() || next <= lo || next >= hi {
                next = 0.5 * (lo + hi);
            }
            if (hi - lo) <= 1e-15 * self.max_delta() {
                return Ok(s);
            }
            w = s.radii;
            d = next;
        }
        Err(RoughError::LoadOutOfRange {
            field: "load.mean_pressures",
            value: target,
            reason: "no convergence of the pressure search".into(),
        })
    }
}

/// Dense LU solve with partial pivoting (row-major m×m); None when singular.
fn lu_solve(a: &mut [f64], b: &mut [f64], m: usize) -> Option<Vec<f64>> {
    for k in 0..m {
        let piv = (k..m).max_by(|&i, &j| {
            a[i * m + k]
                .abs()
                .partial_cmp(&a[j * m + k].abs())
                .unwrap_or(std::cmp::Ordering::Equal)
        })?;
        if a[piv * m + k].is_nan() || a[piv * m + k] == 0.0 {
            return None;
        }
        if piv != k {
            for c in 0..m {
                a.swap(k * m + c, piv * m + c);
            }
            b.swap(k, piv);
        }
        let d = a[k * m + k];
        for i in k + 1..m {
            let f = a[i * m + k] / d;
            if f != 0.0 {
                for c in k..m {
                    a[i * m + c] -= f * a[k * m + c];
                }
                b[i] -= f * b[k];
            }
        }
    }
    let mut x = vec![0.0; m];
    for i in (0..m).rev() {
        let mut s = b[i];
        for c in i + 1..m {
            s -= a[i * m + c] * x[c];
        }
        x[i] = s / a[i * m + i];
    }
    if x.iter().all(|v| v.is_finite()) {
        Some(x)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::Homogeneous;
    use crate::surface::Surface;

    fn reference_surface() -> Option<Surface> {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../shared/reference/surface_km10.npy");
        Some(Surface::read_npy(&p, 1e-3, true).expect("reference surface readable"))
    }

    /// Homogeneous N model = Greenwood–Williamson sum of Hertz contacts, written out
    /// directly: P = Σ (4/3)E*√R_k δ_k^{3/2}, A = π Σ R_k δ_k, dP/dδ = Σ 2E*√(R_k δ_k).
    #[test]
    fn n_model_is_greenwood_williamson() {
        let s = reference_surface().unwrap();
        let law = Homogeneous { e_star: 4.092e9 };
        let rc = RoughContact::from_surface(&law, &s).unwrap();
        let zm = rc.summits().iter().map(|s| s.z).fold(f64::MIN, f64::max);
        for delta in [1e-7, 2e-6, 7.3e-6, 1.1e-5] {
            let st = rc.solve_independent(delta).unwrap();
            let (mut p, mut a, mut k, mut c) = (0.0, 0.0, 0.0, 0);
            for sm in rc.summits() {
                let d = delta - (zm - sm.z);
                if d > 0.0 {
                    p += 4.0 / 3.0 * 4.092e9 * sm.radius.sqrt() * d.powf(1.5);
                    a += std::f64::consts::PI * sm.radius * d;
                    k += 2.0 * 4.092e9 * (sm.radius * d).sqrt();
                    c += 1;
                }
            }
            assert_eq!(st.contacts, c);
            assert!((st.load - p).abs() <= 1e-13 * p, "{} {p}", st.load);
            assert!((st.area_fraction * 1e-6 - a).abs() <= 1e-13 * a);
            assert!((st.stiffness - k).abs() <= 1e-13 * k);
            assert!((st.mean_pressure - p / 1e-6).abs() <= 1e-13 * p / 1e-6);
        }
    }

    fn summit(x: f64, y: f64, z: f64, r: f64) -> Summit {
        Summit {
            index: (0, 0),
            x,
            y,
            z,
            radius: r,
        }
    }

    /// U_E of eq. (P22) written out directly with `law::displacement` (independent of
    /// the solver's G/∂G code), for an isolated set of summits.
    fn u_e(law: &dyn AsperityLaw, sums: &[Summit], a: &[f64], dk: &[f64]) -> f64 {
        let c = 2.0 * law.e_star() / 3.0;
        let mut u = 0.0;
        for j in 0..sums.len() {
            if a[j] <= 0.0 {
                continue;
            }
            let mut inter = 0.0;
            for l in 0..sums.len() {
                if l != j && a[l] > 0.0 {
                    let r = (sums[j].x - sums[l].x).hypot(sums[j].y - sums[l].y);
                    inter += crate::law::displacement(law, a[l], sums[l].radius, r);
                }
            }
            let rj = sums[j].radius;
            let zj = law.zeta(a[j]);
            u += c * law.chi(a[j]) * a[j].powi(3) / rj
                * (inter + a[j] * a[j] / rj * (zj + 0.2) - 2.0 * dk[j]);
        }
        u
    }

    /// Two Hertz asperities at several distances: the solution is a stationary point
    /// of U_E (central differences of the directly written U_E vanish to 1e-6 of the
    /// gradient scale) and a minimum (U_E rises under ±1e-3 perturbations); far apart
    /// the I model equals the N model; the stiffness equals dP/dδ by central differences.
    #[test]
    fn two_asperities_energy_minimum() {
        let law = Homogeneous { e_star: 1e9 };
        for dist in [3e-5, 5e-5, 1e-3, 1.0] {
            let sums = vec![
                summit(0.0, 0.0, 1e-6, 1e-4),
                summit(dist, 0.0, 0.8e-6, 2e-4),
            ];
            let rc = RoughContact::new(&law, sums.clone(), 0.0, -1e-5, (10.0, 10.0)).unwrap();
            let delta = 0.9e-6;
            let st = rc.solve_interacting(delta, Images::Isolated, &[]).unwrap();
            let dk = [delta, delta - 0.2e-6];
            let a = st.radii.clone();
            assert!(a[0] > 0.0 && a[1] > 0.0);
            let u0 = u_e(&law, &sums, &a, &dk);
            // gradient scale: c·(3a²/R)·δ
            let scale = 2.0 / 3.0 * 1e9 * 3.0 * a[0] * a[0] / 1e-4 * delta;
            for k in 0..2 {
                let h = 1e-6 * a[k];
                let mut ap = a.clone();
                let mut am = a.clone();
                ap[k] += h;
                am[k] -= h;
                let g = (u_e(&law, &sums, &ap, &dk) - u_e(&law, &sums, &am, &dk)) / (2.0 * h);
                assert!(
                    g.abs() < 1e-6 * scale,
                    "{dist} {k}: grad {g:e} scale {scale:e}"
                );
                for f in [1.001, 0.999] {
                    let mut t = a.clone();
                    t[k] *= f;
                    assert!(u_e(&law, &sums, &t, &dk) > u0);
                }
            }
            assert!(st.kkt_residual.unwrap() < 1e-8);
            let n = rc.solve_independent(delta).unwrap();
            assert!(st.load < n.load);
            // Far apart the coupling is the point-force displacement ~ (4/3)a³/(πRr),
            // here ≈ 4e-12 m against δ ≈ 1e-6 m: I → N to that order.
            if dist >= 1.0 {
                assert!((st.load - n.load).abs() < 1e-5 * n.load);
            }
            let h = 1e-4 * delta;
            let sp = rc
                .solve_interacting(delta + h, Images::Isolated, &a)
                .unwrap();
            let sm = rc
                .solve_interacting(delta - h, Images::Isolated, &a)
                .unwrap();
            let fd = (sp.load - sm.load) / (2.0 * h);
            assert!(
                (st.stiffness - fd).abs() < 1e-5 * fd,
                "{} {fd}",
                st.stiffness
            );
        }
    }

    /// A shadowed asperity: its interference is smaller than the neighbour's
    /// displacement, so the KKT conditions keep it out of contact.
    #[test]
    fn shadowed_asperity_stays_out() {
        let law = Homogeneous { e_star: 1e9 };
        let sums = vec![
            summit(0.0, 0.0, 1e-6, 1e-3),
            summit(3e-5, 0.0, 0.2e-6, 1e-4),
        ];
        let rc = RoughContact::new(&law, sums, 0.0, -1e-5, (1.0, 1.0)).unwrap();
        let st = rc.solve_interacting(1.0e-6, Images::Isolated, &[]).unwrap();
        let n = rc.solve_independent(1.0e-6).unwrap();
        assert_eq!(n.contacts, 2);
        assert_eq!(st.contacts, 1);
        assert_eq!(st.radii[1], 0.0);
        assert!(st.kkt_residual.unwrap() < 1e-8);
    }

    /// Whole reference surface, homogeneous: I model converges with KKT < 1e-8 on
    /// a load path, is below the N model in load, and periodic images lower it further.
    #[test]
    fn reference_surface_interacting_homogeneous() {
        let s = reference_surface().unwrap();
        let law = Homogeneous { e_star: 4.092e9 };
        let rc = RoughContact::from_surface(&law, &s).unwrap();
        let deltas: Vec<f64> = (1..=10).map(|i| i as f64 * 1.1e-6).collect();
        let iso = rc
            .curve(Model::Interacting(Images::Isolated), &deltas)
            .unwrap();
        let per = rc
            .curve(Model::Interacting(Images::Periodic(2)), &deltas)
            .unwrap();
        let nm = rc.curve(Model::Independent, &deltas).unwrap();
        for ((i, p), n) in iso.iter().zip(&per).zip(&nm) {
            assert!(i.kkt_residual.unwrap() < 1e-8);
            assert!(p.kkt_residual.unwrap() < 1e-8);
            // (equal when a single contact has no neighbour: Newton tolerance 1e-11)
            assert!(i.load <= n.load * (1.0 + 1e-9));
            assert!(p.load <= i.load * (1.0 + 1e-9));
        }
    }

    #[test]
    fn pressure_control_and_range_errors() {
        let s = reference_surface().unwrap();
        let law = Homogeneous { e_star: 4.092e9 };
        let rc = RoughContact::from_surface(&law, &s).unwrap();
        let st = rc.solve_independent(5e-6).unwrap();
        let back = rc
            .solve_pressure(Model::Independent, st.mean_pressure, &[])
            .unwrap();
        assert!((back.delta - 5e-6).abs() < 1e-9 * 5e-6);
        assert!(rc.solve_independent(-1e-9).is_err());
        assert!(rc.solve_independent(1.0).is_err());
        let e = rc
            .solve_pressure(Model::Independent, 1e12, &[])
            .unwrap_err();
        assert!(e.to_string().contains("mean_pressures"), "{e}");
    }

    /// The far-field (point-force) acceleration changes loads and areas by less than
    /// 1e-6 relative against exact pair sums (tolerance 0), periodic 5×5 and isolated.
    #[test]
    fn far_field_matches_exact_sums() {
        let s = reference_surface().unwrap();
        let law = Homogeneous { e_star: 4.092e9 };
        let fast = RoughContact::from_surface(&law, &s).unwrap();
        let exact = RoughContact::from_surface(&law, &s)
            .unwrap()
            .with_far_field_tolerance(0.0);
        let deltas: Vec<f64> = (1..=10).map(|i| i as f64 * 1.1e-6).collect();
        for im in [Images::Periodic(2), Images::Isolated] {
            let f = fast.curve(Model::Interacting(im), &deltas).unwrap();
            let e = exact.curve(Model::Interacting(im), &deltas).unwrap();
            for (x, y) in f.iter().zip(&e) {
                if y.load > 0.0 {
                    assert!(
                        (x.load - y.load).abs() <= 1e-6 * y.load,
                        "{} {}",
                        x.load,
                        y.load
                    );
                    assert!((x.area_fraction - y.area_fraction).abs() <= 1e-6 * y.area_fraction);
                    assert!((x.stiffness - y.stiffness).abs() <= 1e-5 * y.stiffness);
                }
            }
        }
    }
}
