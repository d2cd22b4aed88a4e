//! Interface conductance of a solved contact set (physics.md §6.2): heat (or current)
//! through the contact spots of a periodic cell.
//!
//! # Equations
//! Each body X (A: the rough body, B: the counterface) answers a surface flux q into it
//! (W/m², or A/m²) with the surface temperature (potential) T̂_X(k) = C_X(|k|) q̂(k),
//!
//! ```text
//!   C_X(|k|) = S_th,X(|k|) / (k₁,X |k|)   (m²·K/W, or m²·Ω),
//! ```
//!
//! S_th,X from [`ConductionCompliance::s`] (≡ 1 on a homogeneous conductor), k₁,X its
//! top conductivity; a perfect conductor has C ≡ 0 and a rigid conducting half-space of
//! conductivity k has C = 1/(k|k|). Temperatures are continuous across the contact set
//! I, and no flux crosses the rest of the interface, so with a uniform jump ΔT imposed
//! on I the flux solves
//!
//! ```text
//!   Σ_{k ≠ 0} (C_A + C_B)(|k|) q̂(k) e^{ik·x} = ΔT   on I,   q = 0 off I,
//!   h_c = mean(q) / ΔT   (W/(m²·K), or S/m²),
//! ```
//!
//! the k = 0 mode excluded: it is the bulk 1-D resistance of both bodies (Σ hᵢ/kᵢ on an
//! isothermal sink, unbounded on a half-space), which perfect contact has too, so 1/h_c
//! is the constriction resistance alone, in series with it. Barber's analogy is exact on
//! the grid: for homogeneous bodies C_A + C_B = E*/(2k_s) · 2/(E*|k|) with
//! 1/k_s = 1/k_A + 1/k_B, so h_c = 2k_s (dP/dδ)/(E* A₀) with dP/dδ the stiffness at
//! fixed contact set of the zero-mean elastic operator.
//!
//! # Method
//! The operator restricted to I is symmetric positive definite (its null space, the
//! uniform field, is not supported on a proper subset of the grid): conjugate gradients
//! on I, one FFT convolution per iteration, preconditioned by the inverse operator
//! restricted to I (y = P_I K̂⁻¹ P_I r, Vollebregt's choice for the elastic problem),
//! which keeps the iteration count small on large grids. Convergence:
//! ‖K q − ΔT‖₂ on I ≤ `tolerance` · ‖ΔT‖₂ (the final residual recomputed from q).
//! An empty set gives h_c = 0; the whole grid in contact gives h_c = ∞ (no
//! constriction left).
//!
//! # Non-periodic samples
//! An isolated sample on unbounded bodies (a measured scan): q = 0 outside the sample,
//! and the temperature is the linear convolution T_i = Σ_j G(x_i − x_j) q_j with the
//! real-space coefficients of a uniformly heated pixel, summed over both bodies,
//!
//! ```text
//!   G_X(X, Y) = 1/(2π k₁,X) [ Λ₀(X, Y) + k₀,X Λ_b(X, Y) + ∬_pixel J_X ],
//! ```
//!
//! the elastic free-boundary coefficients of [`crate::influence`] with 2/E*₁ → 1/k₁ and
//! the elastic compliance S → S_th (k₀ = S_th(0) − 1, b = h₁, J the Hankel transform of
//! k_th − k₀e^{−bρ}: [`strata_runtime::hankel`]); 1/(2πk) Λ₀ on a homogeneous
//! half-space, nothing on a perfect conductor. The operator is applied by circulant
//! embedding on the zero-padded 2ny × 2nx grid, as the elastic one. It has no k = 0 mode
//! to exclude: 1/h_c is the spreading resistance into the unbounded bodies (on an
//! isothermal sink it includes the layers' 1-D resistance under the contact), and the
//! whole sample in contact has a finite conductance. Barber's analogy is again exact on
//! the grid for homogeneous bodies: G_th = E*/(2k_s) · G_el.

use rayon::prelude::*;
use strata_runtime::conduction::ConductionCompliance;
use strata_runtime::fft::Fft2Work;

use crate::BemError;
use crate::operator::Operator;
use crate::solver::Geometry;

/// Points per parallel chunk of the vector passes.
const CHUNK: usize = 4096;

/// The sum of per-chunk partial sums in chunk order (deterministic).
fn ordered_sum(parts: Vec<f64>) -> f64 {
    parts.iter().sum()
}

/// One body's conduction as the interface sees it.
#[derive(Debug, Clone, Copy)]
pub enum Conductor<'a> {
    /// A perfect conductor: C ≡ 0 (no temperature rise).
    Perfect,
    /// A homogeneous conducting half-space of conductivity k (W/(m·K) or S/m):
    /// C = 1/(k|k|) (a rigid flat that conducts).
    HalfSpace(f64),
    /// A layered conductor: C = S_th/(k₁|k|).
    Layered(&'a ConductionCompliance),
}

impl Conductor<'_> {
    /// C(|k|) (m²·K/W, or m²·Ω) at wavenumber k > 0 (rad/m).
    pub fn compliance(&self, k: f64) -> f64 {
        match self {
            Conductor::Perfect => 0.0,
            Conductor::HalfSpace(c) => 1.0 / (c * k),
            Conductor::Layered(c) => c.s(k) / (c.top_conductivity() * k),
        }
    }
}

/// Settings of the conduction solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConductanceOptions {
    /// Relative residual ‖K q − ΔT‖₂/‖ΔT‖₂ on the contact set, in (0, 1). The default
    /// 1e−8 gives h_c to 2.6e−9 of a 1e−10 solve on the paper's 512² scene (measured),
    /// far inside the grid's own error (~1e−2), in 12 iterations per step instead of 17.
    pub tolerance: f64,
    /// Iteration cap; exceeding it is [`BemError::NotConverged`].
    pub max_iterations: usize,
    /// Precondition with the inverse operator on the contact set.
    pub preconditioner: bool,
    /// The memory limit the grid is checked against before it is allocated. Default:
    /// 75 % of the machine's memory.
    pub memory: strata_runtime::resources::MemoryLimit,
}

impl Default for ConductanceOptions {
    fn default() -> Self {
        ConductanceOptions {
            tolerance: 1e-8,
            max_iterations: 10_000,
            preconditioner: true,
            memory: Default::default(),
        }
    }
}

/// The result of one conduction solve with ΔT = 1 K (or 1 V).
#[derive(Debug, Clone, PartialEq)]
pub struct Conductance {
    /// h_c = mean(q)/ΔT (W/(m²·K), or S/m²); 0 on an empty set, ∞ on full contact.
    pub conductance: f64,
    /// The flux q per unit ΔT (W/(m²·K), or S/m²), row-major ny × nx, 0 off the set.
    pub flux: Vec<f64>,
    /// CG iterations.
    pub iterations: usize,
    /// Final relative residual ‖K q − ΔT‖₂/‖ΔT‖₂ on the set (recomputed).
    pub residual: f64,
}

/// The conduction operator (periodic: C_A + C_B without its k = 0 mode; non-periodic:
/// the free-boundary coefficients) of one grid, built once and solved on any number of
/// contact sets.
pub struct ConductanceSolver {
    ny: usize,
    nx: usize,
    periodic: bool,
    op: Operator,
    precond: Option<Operator>,
    options: ConductanceOptions,
}

impl std::fmt::Debug for ConductanceSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ConductanceSolver")
            .field("grid", &(self.ny, self.nx))
            .field("periodic", &self.periodic)
            .field("options", &self.options)
            .finish_non_exhaustive()
    }
}

impl ConductanceSolver {
    /// The two bodies `a` and `b` on the ny × nx grid of `geometry` (row index = y):
    /// a periodic cell, or a non-periodic sample on unbounded bodies (module docs).
    /// Refuses two perfect conductors.
    pub fn new(
        ny: usize,
        nx: usize,
        geometry: Geometry,
        a: Conductor<'_>,
        b: Conductor<'_>,
        options: ConductanceOptions,
    ) -> Result<Self, BemError> {
        if matches!((a, b), (Conductor::Perfect, Conductor::Perfect)) {
            return Err(BemError::Conduction(
                "both bodies are perfect conductors: no constriction resistance".into(),
            ));
        }
        for c in [a, b] {
            if let Conductor::HalfSpace(k) = c
                && !(k.is_finite() && k > 0.0)
            {
                return Err(BemError::Conduction(format!(
                    "a conductivity must be finite and > 0, got {k}"
                )));
            }
        }
        if !geometry.periodic {
            return Self::free(ny, nx, geometry, a, b, options);
        }
        Self::with_compliance(
            ny,
            nx,
            geometry,
            |k| a.compliance(k) + b.compliance(k),
            options,
        )
    }

    /// The non-periodic sample (module docs): the free-boundary coefficients of both
    /// bodies, zero-padded convolution.
    fn free(
        ny: usize,
        nx: usize,
        geometry: Geometry,
        a: Conductor<'_>,
        b: Conductor<'_>,
        options: ConductanceOptions,
    ) -> Result<Self, BemError> {
        check_common(ny, nx, 2, geometry, options)?;
        options.memory.check(
            format!("BEM conduction grid {ny}×{nx} (non-periodic)"),
            crate::operator::Operator::bytes(ny, nx, false),
        )?;
        let g = coefficients(
            a,
            b,
            ny,
            nx,
            geometry.lx / nx as f64,
            geometry.ly / ny as f64,
        )?;
        let op = Operator::free(ny, nx, &g)?;
        let precond = if options.preconditioner {
            op.inverse()
        } else {
            None
        };
        Ok(ConductanceSolver {
            ny,
            nx,
            periodic: false,
            op,
            precond,
            options,
        })
    }

    /// Any compliance C(|k|) (m²·K/W; finite and > 0 for k > 0) on the periodic ny × nx
    /// grid of `geometry` (a non-periodic geometry is [`BemError::ConductionNonPeriodic`]),
    /// evaluated once per distinct wavevector (i ≤ nx/2, j ≤ ny/2).
    /// With C = 2/(E*|k|) this is the zero-mean elastic operator: its "conductance" is
    /// then the stiffness at fixed contact set per nominal area, (dP/dδ)/A₀ (Pa/m).
    pub fn with_compliance(
        ny: usize,
        nx: usize,
        geometry: Geometry,
        compliance: impl Fn(f64) -> f64,
        options: ConductanceOptions,
    ) -> Result<Self, BemError> {
        if !geometry.periodic {
            return Err(BemError::ConductionNonPeriodic);
        }
        check_common(ny, nx, 4, geometry, options)?;
        let (hx, hy) = (nx / 2, ny / 2);
        let (dkx, dky) = (
            std::f64::consts::TAU / geometry.lx,
            std::f64::consts::TAU / geometry.ly,
        );
        let square = nx == ny && geometry.lx == geometry.ly;
        let mut tab = vec![f64::NAN; (hx + 1) * (hy + 1)];
        for i in 0..=hx {
            for j in 0..=hy {
                if i == 0 && j == 0 {
                    continue;
                }
                if square && j < i {
                    tab[i * (hy + 1) + j] = tab[j * (hy + 1) + i];
                    continue;
                }
                let k = (dkx * i as f64).hypot(dky * j as f64);
                let c = compliance(k);
                if !(c.is_finite() && c > 0.0) {
                    return Err(BemError::Conduction(format!(
                        "the conduction compliance C(|k| = {k:e} 1/m) = {c} is not finite and positive"
                    )));
                }
                tab[i * (hy + 1) + j] = c;
            }
        }
        let op = Operator::periodic(ny, nx, 0.0, |i, j| Ok(tab[i * (hy + 1) + j]))?;
        let precond = if options.preconditioner {
            op.inverse()
        } else {
            None
        };
        Ok(ConductanceSolver {
            ny,
            nx,
            periodic: true,
            op,
            precond,
            options,
        })
    }

    /// Grid (ny, nx).
    pub fn shape(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    /// Solves on the contact set `contact` (row-major ny × nx, true in contact) with a
    /// unit jump; see the module docs.
    pub fn solve(&self, contact: &[bool]) -> Result<Conductance, BemError> {
        self.solve_from(contact, None)
    }

    /// [`Self::solve`] started from `initial` (a flux per unit ΔT, e.g. the previous
    /// step's; taken on the set only), scaled optimally ([`Self::solve_from_guesses`]).
    pub fn solve_from(
        &self,
        contact: &[bool],
        initial: Option<&[f64]>,
    ) -> Result<Conductance, BemError> {
        self.solve_from_guesses(contact, initial.as_slice())
    }

    /// [`Self::solve`] started from the best combination of `guesses` (fields on the
    /// grid, taken on the set only; non-finite values read as 0): q₀ = Σ cᵢ vᵢ with
    /// Σⱼ (vᵢ·K vⱼ) cⱼ = Σ_I vᵢ, the Ritz–Galerkin minimiser of CG's own energy
    /// ½ q·Kq − Σ_I q over their span (one product per guess; a guess dependent on the
    /// others is dropped). Good guesses: the previous load step's flux, and the step's
    /// own pressure increment dp/dδ, which Barber's analogy makes the exact flux on
    /// homogeneous bodies (physics.md §6.2) and a close one on layered bodies whose
    /// kernels differ only at the layers' scales.
    pub fn solve_from_guesses(
        &self,
        contact: &[bool],
        guesses: &[&[f64]],
    ) -> Result<Conductance, BemError> {
        let n = self.ny * self.nx;
        if contact.len() != n {
            return Err(BemError::Conduction(format!(
                "the contact set has {} points, the grid {}×{}",
                contact.len(),
                self.ny,
                self.nx
            )));
        }
        if let Some(x0) = guesses.iter().find(|g| g.len() != n) {
            return Err(BemError::Initial {
                expected: n,
                got: x0.len(),
            });
        }
        let set = contact.iter().filter(|&&c| c).count();
        if set == 0 {
            return Ok(Conductance {
                conductance: 0.0,
                flux: vec![0.0; n],
                iterations: 0,
                residual: 0.0,
            });
        }
        if set == n && self.periodic {
            return Ok(Conductance {
                conductance: f64::INFINITY,
                flux: vec![f64::INFINITY; n],
                iterations: 0,
                residual: 0.0,
            });
        }
        let mut work = self.op.work();
        let dot = |a: &[f64], b: &[f64]| -> f64 { a.iter().zip(b).map(|(x, y)| x * y).sum() };
        let b_norm = (set as f64).sqrt();
        let mut q = vec![0.0; n];
        let mut kq = vec![0.0; n];
        let mut r = vec![0.0; n];
        // The start: Ritz–Galerkin over the guesses (each masked to the set), its
        // product K q₀ = Σ cᵢ K vᵢ from the guesses' own products.
        let mut basis: Vec<(Vec<f64>, Vec<f64>)> = Vec::with_capacity(guesses.len());
        for g in guesses {
            let v: Vec<f64> = (0..n)
                .map(|i| {
                    if contact[i] && g[i].is_finite() {
                        g[i]
                    } else {
                        0.0
                    }
                })
                .collect();
            if v.iter().all(|&x| x == 0.0) {
                continue;
            }
            let mut kv = vec![0.0; n];
            self.op.apply(&v, &mut kv, false, &mut work)?;
            basis.push((v, kv));
        }
        if let Some(c) = ritz(&basis, contact) {
            for ((v, kv), c) in basis.iter().zip(c) {
                for i in 0..n {
                    q[i] += c * v[i];
                    kq[i] += c * kv[i];
                }
            }
        }
        for i in 0..n {
            r[i] = if contact[i] { 1.0 - kq[i] } else { 0.0 };
        }
        let mut res = dot(&r, &r).sqrt() / b_norm;
        // r = 1 − K q on the set.
        let residual = |q: &[f64], kq: &mut [f64], r: &mut [f64], work: &mut Fft2Work| {
            self.op.apply(q, kq, false, work)?;
            for i in 0..n {
                r[i] = if contact[i] { 1.0 - kq[i] } else { 0.0 };
            }
            Ok::<f64, BemError>(dot(r, r).sqrt() / b_norm)
        };
        let tol = self.options.tolerance;
        let mut z = vec![0.0; n];
        // z = P_I M⁻¹ r (or r), returning Σ r z: one fused pass after the product.
        let precondition = |r: &[f64], z: &mut [f64], work: &mut Fft2Work| {
            if let Some(m) = &self.precond {
                m.apply(r, z, false, work)?;
            } else {
                z.copy_from_slice(r);
            }
            Ok::<f64, BemError>(ordered_sum(
                z.par_chunks_mut(CHUNK)
                    .zip(r.par_chunks(CHUNK))
                    .zip(contact.par_chunks(CHUNK))
                    .map(|((z, r), c)| {
                        let mut s = 0.0;
                        for j in 0..z.len() {
                            if c[j] {
                                s += r[j] * z[j];
                            } else {
                                z[j] = 0.0;
                            }
                        }
                        s
                    })
                    .collect(),
            ))
        };
        let mut iterations = 0;
        // Restarted CG: the recursive residual is checked against the true one before
        // acceptance; a mismatch (round-off on long runs) restarts from the true one.
        // Each iteration: two products (K d, and the preconditioner's) and four fused
        // passes; the partial sums are added in a fixed order (the same result on any
        // number of threads).
        'outer: while res > tol {
            let mut rz = precondition(&r, &mut z, &mut work)?;
            let mut d = z.clone();
            let mut kd = vec![0.0; n];
            loop {
                if iterations >= self.options.max_iterations {
                    return Err(BemError::NotConverged {
                        iterations,
                        error: res,
                        tolerance: tol,
                    });
                }
                iterations += 1;
                self.op.apply(&d, &mut kd, false, &mut work)?;
                // kd ← P_I K d, with Σ d·kd
                let dkd = ordered_sum(
                    kd.par_chunks_mut(CHUNK)
                        .zip(d.par_chunks(CHUNK))
                        .zip(contact.par_chunks(CHUNK))
                        .map(|((k, d), c)| {
                            let mut s = 0.0;
                            for j in 0..k.len() {
                                if c[j] {
                                    s += d[j] * k[j];
                                } else {
                                    k[j] = 0.0;
                                }
                            }
                            s
                        })
                        .collect(),
                );
                if !(dkd > 0.0 && dkd.is_finite()) {
                    return Err(BemError::NonFinite(iterations));
                }
                let alpha = rz / dkd;
                // q += α d, r −= α kd, with Σ r²
                let rr = ordered_sum(
                    q.par_chunks_mut(CHUNK)
                        .zip(r.par_chunks_mut(CHUNK))
                        .zip(d.par_chunks(CHUNK))
                        .zip(kd.par_chunks(CHUNK))
                        .map(|(((q, r), d), k)| {
                            let mut s = 0.0;
                            for j in 0..q.len() {
                                q[j] += alpha * d[j];
                                r[j] -= alpha * k[j];
                                s += r[j] * r[j];
                            }
                            s
                        })
                        .collect(),
                );
                if rr.sqrt() / b_norm <= tol {
                    res = residual(&q, &mut kq, &mut r, &mut work)?;
                    continue 'outer;
                }
                let rz_new = precondition(&r, &mut z, &mut work)?;
                let beta = rz_new / rz;
                rz = rz_new;
                d.par_chunks_mut(CHUNK)
                    .zip(z.par_chunks(CHUNK))
                    .for_each(|(d, z)| {
                        for j in 0..d.len() {
                            d[j] = z[j] + beta * d[j];
                        }
                    });
            }
        }
        let conductance = q.iter().sum::<f64>() / n as f64;
        if !conductance.is_finite() {
            return Err(BemError::NonFinite(iterations));
        }
        Ok(Conductance {
            conductance,
            flux: q,
            iterations,
            residual: res,
        })
    }
}

/// The checks shared by both geometries: sides, grid (at least `min` per side), options.
fn check_common(
    ny: usize,
    nx: usize,
    min: usize,
    geometry: Geometry,
    options: ConductanceOptions,
) -> Result<(), BemError> {
    for (what, value) in [("Lx", geometry.lx), ("Ly", geometry.ly)] {
        if !(value.is_finite() && value > 0.0) {
            return Err(BemError::Size { what, value });
        }
    }
    if ny < min || nx < min {
        return Err(BemError::Grid { rows: ny, cols: nx });
    }
    if !(options.tolerance > 0.0 && options.tolerance < 1.0) {
        return Err(BemError::Tolerance(options.tolerance));
    }
    if options.max_iterations == 0 {
        return Err(BemError::MaxIterations);
    }
    Ok(())
}

/// Free-boundary conduction coefficients G[dy·nx + dx] (K·m²/W, or Ω·m²) of both bodies
/// for offsets 0 ≤ dy < ny, 0 ≤ dx < nx of pixels `px` × `py` (m): the temperature rise
/// at offset (dx·px, dy·py) from a pixel carrying a unit flux (module docs).
pub fn coefficients(
    a: Conductor<'_>,
    b: Conductor<'_>,
    ny: usize,
    nx: usize,
    px: f64,
    py: f64,
) -> Result<Vec<f64>, BemError> {
    use strata_runtime::hankel::{HankelError, Remainder, pixel_integral, tail_start};
    let diag = (nx as f64 * px).hypot(ny as f64 * py);
    // per body: 1/(2πk₁) and the layered remainder (None: homogeneous)
    let mut bodies: Vec<(f64, Option<Remainder>)> = Vec::new();
    for c in [a, b] {
        match c {
            Conductor::Perfect => {}
            Conductor::HalfSpace(k) => bodies.push((1.0 / (std::f64::consts::TAU * k), None)),
            Conductor::Layered(cc) => {
                let rem = match (cc.is_homogeneous(), cc.top_thickness()) {
                    (false, Some(h1)) => Some(
                        Remainder::new(
                            cc.s_at_zero() - 1.0,
                            h1,
                            cc.total_thickness(),
                            diag.min(tail_start(cc.total_thickness(), cc.contrast())),
                            |rho| cc.k_th(rho),
                        )
                        .map_err(|e| match e {
                            HankelError::NonFinite { rho, value } => BemError::Conduction(
                                format!("the conduction compliance S_th(ρ = {rho:e} 1/m) = {value} is not finite"),
                            ),
                            other => BemError::Conduction(other.to_string()),
                        })?,
                    ),
                    _ => None,
                };
                bodies.push((1.0 / (std::f64::consts::TAU * cc.top_conductivity()), rem));
            }
        }
    }
    let mut g = vec![0.0; ny * nx];
    g.par_chunks_mut(nx).enumerate().for_each(|(i, row)| {
        let y = i as f64 * py;
        for (j, slot) in row.iter_mut().enumerate() {
            let x = j as f64 * px;
            let love = pixel_integral(x, y, px, py, 0.0);
            *slot = bodies
                .iter()
                .map(|(c, rem)| {
                    c * (love + rem.as_ref().map_or(0.0, |r| r.pixel_layered(x, y, px, py)))
                })
                .sum();
        }
    });
    if let Some((k, v)) = g.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(BemError::Conduction(format!(
            "the free-boundary coefficient at offset ({}, {}) is {v}",
            k / nx,
            k % nx
        )));
    }
    Ok(g)
}

/// The Ritz–Galerkin coefficients of the start of [`ConductanceSolver::solve_from_guesses`]:
/// Σⱼ (vᵢ·K vⱼ) cⱼ = Σ_I vᵢ over `basis` = [(vᵢ, K vᵢ)] (K vᵢ read on the set), by
/// Gaussian elimination with the guesses whose pivot falls below 1e−10 of their own
/// energy dropped (dependent on the others: coefficient 0). None when no guess is left.
fn ritz(basis: &[(Vec<f64>, Vec<f64>)], contact: &[bool]) -> Option<Vec<f64>> {
    let m = basis.len();
    let on = |a: &[f64], b: &[f64]| -> f64 {
        a.iter()
            .zip(b)
            .zip(contact)
            .filter(|(_, c)| **c)
            .map(|((x, y), _)| x * y)
            .sum()
    };
    let mut a: Vec<Vec<f64>> = (0..m)
        .map(|i| (0..m).map(|j| on(&basis[i].0, &basis[j].1)).collect())
        .collect();
    let mut b: Vec<f64> = basis
        .iter()
        .map(|(v, _)| {
            v.iter()
                .zip(contact)
                .filter(|(_, c)| **c)
                .map(|(x, _)| x)
                .sum()
        })
        .collect();
    let diag: Vec<f64> = (0..m).map(|i| a[i][i]).collect();
    let mut keep = vec![false; m];
    for k in 0..m {
        if !(a[k][k] > 1e-10 * diag[k] && a[k][k].is_finite()) {
            continue;
        }
        keep[k] = true;
        for i in k + 1..m {
            let f = a[i][k] / a[k][k];
            for j in k..m {
                a[i][j] -= f * a[k][j];
            }
            b[i] -= f * b[k];
        }
    }
    if !keep.iter().any(|&k| k) {
        return None;
    }
    let mut c = vec![0.0; m];
    for k in (0..m).rev() {
        if keep[k] {
            let s: f64 = (k + 1..m).map(|j| a[k][j] * c[j]).sum();
            c[k] = (b[k] - s) / a[k][k];
        }
    }
    c.iter().all(|x| x.is_finite()).then_some(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BemLoad, BemOptions, BemSolver};
    use ndarray::Array2;
    use strata_runtime::conduction::ConductionKind;
    use strata_runtime::stack::{Base, BaseConduction, Conductivity, Layer, Solid, Stack};

    fn thermal(k: f64) -> Conductivity {
        Conductivity::thermal(k)
    }

    fn tight() -> ConductanceOptions {
        ConductanceOptions {
            tolerance: 1e-13,
            ..Default::default()
        }
    }

    /// A disc of radius `a` (m) centred in the n × n cell of side `l`.
    fn disc(n: usize, l: f64, a: f64) -> Vec<bool> {
        let dx = l / n as f64;
        let c = (n as f64 - 1.0) / 2.0;
        (0..n * n)
            .map(|i| {
                let (y, x) = ((i / n) as f64 - c, (i % n) as f64 - c);
                (x * x + y * y).sqrt() * dx <= a
            })
            .collect()
    }

    /// A periodic rough surface (a few waves), n × n, heights in m.
    fn waves(n: usize) -> Array2<f64> {
        let t = std::f64::consts::TAU / n as f64;
        Array2::from_shape_fn((n, n), |(i, j)| {
            let (y, x) = (i as f64 * t, j as f64 * t);
            1e-6 * ((x + 0.3).cos()
                + 0.7 * (2.0 * y - 1.0).cos()
                + 0.4 * (3.0 * x + 2.0 * y).sin()
                + 0.25 * (5.0 * x - 4.0 * y + 0.5).cos()
                + 0.15 * (7.0 * y + 3.0 * x).sin())
        })
    }

    /// The zero-mean periodic kernel 2/(E*|k|) in real space by a direct (slow) Fourier
    /// sum, the dense matrix on the set and its Cholesky solve with a unit right-hand
    /// side: (dP/dδ)/A₀ at fixed contact set, independent of the FFT and the CG.
    fn dense_stiffness(n: usize, l: f64, e_star: f64, set: &[bool]) -> f64 {
        let dk = std::f64::consts::TAU / l;
        let idx: Vec<usize> = (0..n * n).filter(|&i| set[i]).collect();
        let mut g = vec![0.0; n * n];
        for dy in 0..n {
            for dx in 0..n {
                let mut s = 0.0;
                for ky in 0..n {
                    for kx in 0..n {
                        if kx == 0 && ky == 0 {
                            continue;
                        }
                        let fy = if ky <= n / 2 {
                            ky as f64
                        } else {
                            ky as f64 - n as f64
                        };
                        let fx = if kx <= n / 2 {
                            kx as f64
                        } else {
                            kx as f64 - n as f64
                        };
                        let k = dk * fx.hypot(fy);
                        let ph =
                            std::f64::consts::TAU * (fx * dx as f64 + fy * dy as f64) / n as f64;
                        s += 2.0 / (e_star * k) * ph.cos();
                    }
                }
                g[dy * n + dx] = s / (n * n) as f64;
            }
        }
        let m = idx.len();
        let mut a = vec![0.0; m * m];
        for (r, &i) in idx.iter().enumerate() {
            for (c, &j) in idx.iter().enumerate() {
                let dy = ((i / n) + n - (j / n)) % n;
                let dx = ((i % n) + n - (j % n)) % n;
                a[r * m + c] = g[dy * n + dx];
            }
        }
        // Cholesky A = L Lᵀ, then L Lᵀ p = 1
        cholesky_sum_of_solution(a, m) / (n * n) as f64
    }

    /// Barber's analogy on the BEM's own contact set: two homogeneous bodies,
    /// h_c = 2 k_s (dP/dδ)/(E* A₀), 1/k_s = 1/k_A + 1/k_B, with dP/dδ at fixed contact set
    /// from a dense Cholesky solve of the real-space elastic kernel.
    #[test]
    fn barber_analogy_on_the_bem_contact_set() {
        let (n, l) = (32, 1e-3);
        let (ea, eb) = (2e11, 7e10);
        let stack = Stack::half_space(ea, 0.3)
            .unwrap()
            .against(Stack::half_space(eb, 0.25).unwrap());
        let e_star = stack.contact_modulus();
        let bem = BemSolver::new(&waves(n), l, &stack, BemOptions::default()).unwrap();
        let sol = bem.solve(BemLoad::MeanPressure(1e8)).unwrap();
        let set: Vec<bool> = sol.pressure.iter().map(|&p| p > 0.0).collect();
        let count = set.iter().filter(|&&c| c).count();
        assert!(count > 50 && count < n * n / 2, "{count}");
        let stiffness = dense_stiffness(n, l, e_star, &set);
        let g = Geometry::square(l);
        assert_barber((n, n), g, &set, stiffness, e_star, "barber");
        let (ka, kb) = (50.0, 15.0);
        let ks = 1.0 / (1.0 / ka + 1.0 / kb);
        // A layered body of uniform conductivity is the same conductor.
        let layered = Stack::new(
            vec![Layer {
                thickness: 1e-5,
                young: 1e9,
                poisson: 0.3,
            }],
            Base::Elastic {
                young: 1e9,
                poisson: 0.3,
            },
        )
        .unwrap()
        .with_conduction(vec![thermal(ka)], thermal(ka), BaseConduction::HalfSpace)
        .unwrap();
        let cc = ConductionCompliance::new(&layered, ConductionKind::Thermal).unwrap();
        let s = ConductanceSolver::new(
            n,
            n,
            g,
            Conductor::Layered(&cc),
            Conductor::HalfSpace(kb),
            tight(),
        )
        .unwrap();
        let h = s.solve(&set).unwrap().conductance;
        let barber = 2.0 * ks * stiffness / e_star;
        assert!((h - barber).abs() < 1e-10 * barber, "{h} {barber}");
    }

    /// Barber's analogy on `set` for two half-spaces (k_A = 50, k_B = 15) and for either
    /// against a perfect conductor: h_c = 2 k_s (dP/dδ)/(E* A₀) to 1e−10, with the
    /// contact stiffness per area `stiffness` (dP/dδ/A₀) from a dense solve.
    fn assert_barber(
        (ny, nx): (usize, usize),
        geometry: Geometry,
        set: &[bool],
        stiffness: f64,
        e_star: f64,
        what: &str,
    ) {
        let (ka, kb) = (50.0, 15.0);
        let ks = 1.0 / (1.0 / ka + 1.0 / kb);
        for (a, b, k) in [
            (Conductor::HalfSpace(ka), Conductor::HalfSpace(kb), ks),
            (Conductor::HalfSpace(ka), Conductor::Perfect, ka),
            (Conductor::Perfect, Conductor::HalfSpace(kb), kb),
        ] {
            let s = ConductanceSolver::new(ny, nx, geometry, a, b, tight()).unwrap();
            let h = s.solve(set).unwrap();
            let barber = 2.0 * k * stiffness / e_star;
            let rel = (h.conductance - barber).abs() / barber;
            eprintln!(
                "{what}: h_c {:e} vs {barber:e}: {rel:.2e} ({} iterations)",
                h.conductance, h.iterations
            );
            assert!(rel < 1e-10, "{rel}");
        }
    }

    /// Solves the dense symmetric positive definite m × m system A y = 1 by Cholesky
    /// (row-major `a`, overwritten) and returns Σ y.
    fn cholesky_sum_of_solution(mut a: Vec<f64>, m: usize) -> f64 {
        for j in 0..m {
            let mut d = a[j * m + j];
            for k in 0..j {
                d -= a[j * m + k] * a[j * m + k];
            }
            assert!(d > 0.0, "not positive definite at {j}");
            let d = d.sqrt();
            a[j * m + j] = d;
            for i in j + 1..m {
                let mut s = a[i * m + j];
                for k in 0..j {
                    s -= a[i * m + k] * a[j * m + k];
                }
                a[i * m + j] = s / d;
            }
        }
        let mut y = vec![1.0; m];
        for i in 0..m {
            for k in 0..i {
                y[i] -= a[i * m + k] * y[k];
            }
            y[i] /= a[i * m + i];
        }
        for i in (0..m).rev() {
            for k in i + 1..m {
                y[i] -= a[k * m + i] * y[k];
            }
            y[i] /= a[i * m + i];
        }
        y.iter().sum()
    }

    /// Barber's analogy on a non-periodic sample (the free-boundary kernels), on the
    /// BEM's own contact set: two homogeneous half-spaces, h_c = 2k_s (dP/dδ)/(E* A₀)
    /// with dP/dδ at fixed contact set from a dense Cholesky solve of Love's closed-form
    /// pixel coefficients (Johnson eq. 3.25: no FFT, no zero padding, no CG), on a
    /// rectangular grid with rectangular pixels.
    #[test]
    fn barber_analogy_on_a_non_periodic_sample() {
        use crate::influence::love;
        let (ny, nx, lx, ly) = (24, 40, 1.2e-3, 0.9e-3);
        let (ea, eb) = (2e11, 7e10);
        let stack = Stack::half_space(ea, 0.3)
            .unwrap()
            .against(Stack::half_space(eb, 0.25).unwrap());
        let e_star = stack.contact_modulus();
        let t = std::f64::consts::TAU;
        let z = Array2::from_shape_fn((ny, nx), |(i, j)| {
            let (y, x) = (t * i as f64 / ny as f64, t * j as f64 / nx as f64);
            1e-6 * ((x + 0.3).cos() + 0.7 * (1.3 * y - 1.0).cos() + 0.4 * (2.6 * x + 1.7 * y).sin())
        });
        let geometry = Geometry {
            lx,
            ly,
            periodic: false,
        };
        let bem = BemSolver::with_geometry(&z, geometry, &stack, BemOptions::default()).unwrap();
        let sol = bem.solve(BemLoad::MeanPressure(1e8)).unwrap();
        let set: Vec<bool> = sol.pressure.iter().map(|&p| p > 0.0).collect();
        let count = set.iter().filter(|&&c| c).count();
        assert!(count > 30 && count < ny * nx / 2, "{count}");
        let (px, py) = (lx / nx as f64, ly / ny as f64);
        let idx: Vec<usize> = (0..ny * nx).filter(|&i| set[i]).collect();
        let m = idx.len();
        let mut a = vec![0.0; m * m];
        for (r, &i) in idx.iter().enumerate() {
            for (c, &j) in idx.iter().enumerate() {
                let dy = (i / nx).abs_diff(j / nx) as f64 * py;
                let dx = (i % nx).abs_diff(j % nx) as f64 * px;
                a[r * m + c] = love(dx, dy, px, py, e_star);
            }
        }
        let stiffness = cholesky_sum_of_solution(a, m) / (ny * nx) as f64;
        assert_barber(
            (ny, nx),
            geometry,
            &set,
            stiffness,
            e_star,
            "non-periodic Barber",
        );
        let ka = 50.0;
        // the whole sample in contact conducts finitely (no k = 0 mode to exclude)
        let s = ConductanceSolver::new(
            ny,
            nx,
            geometry,
            Conductor::HalfSpace(ka),
            Conductor::Perfect,
            tight(),
        )
        .unwrap();
        let full = s.solve(&vec![true; ny * nx]).unwrap().conductance;
        assert!(full.is_finite() && full > 0.0, "{full}");
        // a compliance given as C(|k|) defines a periodic operator only
        assert_eq!(
            ConductanceSolver::with_compliance(ny, nx, geometry, |k| 1.0 / k, tight()).unwrap_err(),
            BemError::ConductionNonPeriodic
        );
    }

    /// Holm's single spot on a non-periodic grid: an isothermal disc on two homogeneous
    /// half-spaces conducts G = 4 k_s a (1/k_s = 1/k_A + 1/k_B; 2ka for two equal
    /// bodies), with no cell correction (the bodies are unbounded); a the radius of the
    /// disc's pixel area. The error is first order in the pixel.
    #[test]
    fn one_spot_on_a_free_grid_is_4ksa() {
        let (ka, kb) = (20.0, 60.0);
        let ks = 1.0 / (1.0 / ka + 1.0 / kb);
        let mut errors = Vec::new();
        for a_dx in [4usize, 8, 16, 32] {
            let n = 2 * a_dx + 4;
            let dx = 1e-5;
            let l = n as f64 * dx;
            let a = a_dx as f64 * dx;
            let s = ConductanceSolver::new(
                n,
                n,
                Geometry {
                    lx: l,
                    ly: l,
                    periodic: false,
                },
                Conductor::HalfSpace(ka),
                Conductor::HalfSpace(kb),
                ConductanceOptions::default(),
            )
            .unwrap();
            let set = disc(n, l, a);
            let pts = set.iter().filter(|&&c| c).count() as f64;
            let a_eq = (pts / std::f64::consts::PI).sqrt() * dx;
            let h = s.solve(&set).unwrap();
            let g = h.conductance * l * l;
            let e = g / (4.0 * ks * a_eq) - 1.0;
            eprintln!(
                "free spot a/dx {a_dx}: G {g:e} vs 4k_s a {:e}: {e:.3e} ({} iterations)",
                4.0 * ks * a_eq,
                h.iterations
            );
            errors.push(e);
        }
        // measured −3.17e-2, −1.54e-2, −7.52e-3, −3.58e-3 at a/dx = 4 … 32 (e·a/dx from
        // −0.127 to −0.115); Richardson 2e(2n) − e(n): 3.1e-4, 3.6e-4
        for (e, a_dx) in errors.iter().zip([4.0, 8.0, 16.0, 32.0]) {
            assert!(*e < 0.0 && -e * a_dx < 0.15, "{errors:?}");
        }
        for w in errors.windows(2) {
            assert!((1.9..2.2).contains(&(w[0] / w[1])), "{errors:?}");
        }
        for w in errors.windows(2).skip(1) {
            assert!((2.0 * w[1] - w[0]).abs() < 4e-3, "{errors:?}");
        }
    }

    /// The Ritz start of `solve_from_guesses` (homogeneous bodies, the BEM's contact
    /// set): the pressure increment of a neighbouring solve is, by Barber's analogy, the
    /// flux up to the few points where the set moves, so CG starts near the answer;
    /// the answer is the cold start's within the tolerance, a repeated (dependent) guess
    /// is dropped, and a wrong-length guess is refused.
    #[test]
    fn barber_start_saves_iterations() {
        let (n, l) = (64, 1e-3);
        let stack = Stack::half_space(2e11, 0.3)
            .unwrap()
            .against(Stack::half_space(7e10, 0.25).unwrap());
        let bem = BemSolver::new(&waves(n), l, &stack, BemOptions::default()).unwrap();
        let sol = bem.solve(BemLoad::MeanPressure(1e8)).unwrap();
        let flat: Vec<f64> = sol.pressure.iter().copied().collect();
        let next = bem
            .solve_from(BemLoad::MeanPressure(1e8 * (1.0 + 1e-4)), Some(&flat))
            .unwrap();
        let dp: Vec<f64> = next
            .pressure
            .iter()
            .zip(&flat)
            .map(|(a, b)| a - b)
            .collect();
        let set: Vec<bool> = flat.iter().map(|&p| p > 0.0).collect();
        let opts = ConductanceOptions {
            tolerance: 1e-10,
            ..Default::default()
        };
        let s = ConductanceSolver::new(
            n,
            n,
            Geometry::square(l),
            Conductor::HalfSpace(50.0),
            Conductor::HalfSpace(15.0),
            opts,
        )
        .unwrap();
        let cold = s.solve(&set).unwrap();
        let warm = s.solve_from_guesses(&set, &[&dp]).unwrap();
        let twice = s.solve_from_guesses(&set, &[&dp, &dp]).unwrap();
        let rel = |h: &Conductance| (h.conductance / cold.conductance - 1.0).abs();
        eprintln!(
            "Barber start: {} iterations cold, {} from dp/dδ ({:.1e}), {} from it twice ({:.1e})",
            cold.iterations,
            warm.iterations,
            rel(&warm),
            twice.iterations,
            rel(&twice)
        );
        // measured 3.4e-12 (both)
        assert!(rel(&warm) < 3e-11 && rel(&twice) < 3e-11);
        assert!(
            2 * warm.iterations <= cold.iterations,
            "{} {}",
            warm.iterations,
            cold.iterations
        );
        assert_eq!(twice.iterations, warm.iterations);
        assert!(matches!(
            s.solve_from_guesses(&set, &[&dp[1..]]),
            Err(BemError::Initial { .. })
        ));
    }

    /// One isothermal disc in a large periodic cell on a homogeneous half-space (the
    /// other side perfect): G = 4ka, with the cell's first-order correction
    /// 1/G = 1/(4ka) + Z/(2πkL), Z = 4ζ(1/2)β(1/2) = −3.900265 (the zero-mean lattice
    /// sum of the images), a the radius of the disc's pixel area. The error is first
    /// order in the pixel, e ≈ −0.17 dx/a (measured 4.22e-2, 2.08e-2, 1.05e-2, 5.31e-3
    /// at a/dx = 4 … 32), and its Richardson extrapolation 2e(2n) − e(n) is ~1.5e-4 (the
    /// cell's O((a/L)³) term).
    #[test]
    fn one_spot_in_a_periodic_cell_is_4ka() {
        let (l, k) = (1e-3, 20.0);
        let z = -3.900_264_920_001_955;
        let a = l / 16.0;
        let mut errors = Vec::new();
        for n in [64, 128, 256, 512] {
            let s = ConductanceSolver::new(
                n,
                n,
                Geometry::square(l),
                Conductor::HalfSpace(k),
                Conductor::Perfect,
                ConductanceOptions::default(),
            )
            .unwrap();
            let set = disc(n, l, a);
            let pts = set.iter().filter(|&&c| c).count() as f64;
            let a_eq = (pts / std::f64::consts::PI).sqrt() * l / n as f64;
            let h = s.solve(&set).unwrap();
            let g = h.conductance * l * l;
            let exact = 1.0 / (1.0 / (4.0 * k * a_eq) + z / (std::f64::consts::TAU * k * l));
            let e = g / exact - 1.0;
            let a_dx = a * n as f64 / l;
            eprintln!(
                "spot a/dx {a_dx}: G {g:e} vs {exact:e}: {e:.3e} ({} iterations)",
                h.iterations
            );
            assert!(e < 0.0 && -e * a_dx < 0.2, "a/dx {a_dx}: {e}");
            errors.push(e);
        }
        for w in errors.windows(2) {
            let ratio = w[0] / w[1];
            assert!((1.9..2.1).contains(&ratio), "{errors:?}");
            let extrapolated = 2.0 * w[1] - w[0];
            assert!(extrapolated.abs() < 2e-3, "{errors:?}");
        }
    }

    /// A thin resistive layer (h ≪ pixel) on a far better conductor: the kernel is
    /// h/k₁ at every wavevector, and with the k = 0 mode excluded the conductance is the
    /// layer's 1-D conductance over the contact, h_c = (k₁/h) φ/(1 − φ) (φ = A/A₀): in
    /// series with the excluded bulk term h/k₁ the total is the 1-D series resistance
    /// h/(k₁φ), → h/k₁ as the contact becomes full.
    #[test]
    fn thin_resistive_layer_is_one_dimensional() {
        let (n, l) = (64, 1e-3);
        let h1 = l / n as f64 / 100.0;
        let (k1, kb) = (0.2, 2e5);
        let stack = Stack::new(
            vec![Layer {
                thickness: h1,
                young: 1e9,
                poisson: 0.3,
            }],
            Base::Rigid,
        )
        .unwrap()
        .with_conduction(vec![thermal(k1)], thermal(kb), BaseConduction::HalfSpace)
        .unwrap();
        let cc = ConductionCompliance::new(&stack, ConductionKind::Thermal).unwrap();
        let s = ConductanceSolver::new(
            n,
            n,
            Geometry::square(l),
            Conductor::Layered(&cc),
            Conductor::Perfect,
            ConductanceOptions::default(),
        )
        .unwrap();
        let z = waves(n);
        for level in [-1.5e-6, -0.5e-6, 0.5e-6, 1.5e-6] {
            let set: Vec<bool> = z.iter().map(|&v| v > level).collect();
            let phi = set.iter().filter(|&&c| c).count() as f64 / (n * n) as f64;
            let h = s.solve(&set).unwrap();
            let one_d = k1 / h1 * phi / (1.0 - phi);
            let rel = h.conductance / one_d - 1.0;
            eprintln!(
                "thin layer φ = {phi:.3}: h_c {:e} vs 1-D {one_d:e}: {rel:.3e}",
                h.conductance
            );
            // measured 3e-4 … 6e-4 (tanh(|k|h) ≠ |k|h, k₁/k_b ≠ 0)
            assert!(rel.abs() < 5e-3, "φ = {phi}: {rel}");
            // the total resistance: the layer's 1-D resistance over the contact area
            let total = 1.0 / h.conductance + h1 / k1;
            assert!((total * k1 * phi / h1 - 1.0).abs() < 5e-3);
        }
    }

    /// Edge cases and refusals; the preconditioned, plain and warm-started solves agree.
    #[test]
    fn edge_cases_and_variants() {
        let (n, l) = (32, 1e-3);
        let g = Geometry::square(l);
        let mk = |pc: bool| {
            ConductanceSolver::new(
                n,
                n,
                g,
                Conductor::HalfSpace(3.0),
                Conductor::HalfSpace(7.0),
                ConductanceOptions {
                    preconditioner: pc,
                    ..tight()
                },
            )
            .unwrap()
        };
        let s = mk(true);
        assert_eq!(s.solve(&vec![false; n * n]).unwrap().conductance, 0.0);
        assert_eq!(
            s.solve(&vec![true; n * n]).unwrap().conductance,
            f64::INFINITY
        );
        assert!(s.solve(&[true; 10]).is_err());
        let set: Vec<bool> = waves(n).iter().map(|&z| z > 0.8e-6).collect();
        let a = s.solve(&set).unwrap();
        let b = mk(false).solve(&set).unwrap();
        assert!((a.conductance / b.conductance - 1.0).abs() < 1e-11);
        let c = s.solve_from(&set, Some(&a.flux)).unwrap();
        assert!(c.iterations <= 1 && (c.conductance / a.conductance - 1.0).abs() < 1e-11);
        assert!(a.residual <= 1e-13 && a.flux.iter().all(|q| q.is_finite()));
        let free = Geometry {
            periodic: false,
            ..g
        };
        let e = ConductanceSolver::with_compliance(n, n, free, |k| 1.0 / (3.0 * k), tight())
            .unwrap_err();
        assert_eq!(e, BemError::ConductionNonPeriodic);
        assert!(
            ConductanceSolver::new(
                n,
                n,
                free,
                Conductor::HalfSpace(3.0),
                Conductor::Perfect,
                tight()
            )
            .is_ok()
        );
        assert!(
            ConductanceSolver::new(n, n, g, Conductor::Perfect, Conductor::Perfect, tight())
                .is_err()
        );
        assert!(
            ConductanceSolver::new(
                n,
                n,
                g,
                Conductor::HalfSpace(-1.0),
                Conductor::Perfect,
                tight()
            )
            .is_err()
        );
    }
}
