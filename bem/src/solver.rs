//! [`BemSolver`]: one surface on one stack, many loads.

use ndarray::Array2;
use strata_runtime::cancel::Cancel;
use strata_runtime::compliance::Compliance;
use strata_runtime::resources::bytes_for;
use strata_runtime::stack::{Base, Bodies, Solid};

use crate::cg;
use crate::iteration::Problem;
use crate::kernels::Kernels;
use crate::maps::{BemSolution, count_patches};
use crate::operator::Operator;
use crate::state::Control;
use crate::{BemError, BemLoad, BemOptions};

/// The sample: sides (m) and boundary condition. Heights are given as an ny × nx array,
/// row index = y, column index = x; the pixel is (Lx/nx) × (Ly/ny).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// Side along x (columns), m.
    pub lx: f64,
    /// Side along y (rows), m.
    pub ly: f64,
    /// `true`: one cell of a periodic pattern (spectral kernel); `false`: an isolated
    /// sample on an unbounded solid, zero pressure outside (free-boundary kernel).
    pub periodic: bool,
}

impl Geometry {
    /// A periodic square cell of side `l` (m).
    pub fn square(l: f64) -> Self {
        Geometry {
            lx: l,
            ly: l,
            periodic: true,
        }
    }

    /// The wavenumber of the longest wave of the sample, k₁ = 2π/max(Lx, Ly) (rad/m).
    pub fn fundamental(&self) -> f64 {
        std::f64::consts::TAU / self.lx.max(self.ly)
    }
}

/// Grids below this (on either side) are solved directly; larger ones start from the
/// solution on the half grid (coarse-to-fine) when no initial pressure is given.
const COARSE_MIN: usize = 256;

/// Uniform-mode compliance of a stack on a rigid base, C₀ = Σ hᵢ/Mᵢ (m/Pa), with the
/// P-wave modulus Mᵢ = Eᵢ(1−νᵢ)/((1+νᵢ)(1−2νᵢ)); `None` on an elastic base (infinite).
/// Equals lim_{k→0} 2S(k)/(E*k). With a counterface the two bodies' C₀ add (both on
/// rigid bases), else `None` (physics.md §6.1).
pub fn uniform_compliance<S: Solid + ?Sized>(stack: &S) -> Option<f64> {
    if let Some(c) = stack.elastic_counterface() {
        return Some(uniform_compliance(stack.first())? + uniform_compliance(c)?);
    }
    let stack = stack.first();
    match stack.base() {
        Base::Elastic { .. } => None,
        Base::Rigid => Some(
            stack
                .layers()
                .iter()
                .map(|l| {
                    l.thickness * (1.0 + l.poisson) * (1.0 - 2.0 * l.poisson)
                        / (l.young * (1.0 - l.poisson))
                })
                .sum(),
        ),
    }
}

/// The FFT-BEM for one surface on one stack. Build once, solve many loads.
pub struct BemSolver {
    ny: usize,
    nx: usize,
    geometry: Geometry,
    /// Heights, row-major ny×nx (m).
    z: Vec<f64>,
    z_max: f64,
    z_mean: f64,
    z_rms: f64,
    e_star1: f64,
    /// S(k₁) at the longest wave of the sample, k₁ = 2π/max(Lx, Ly) (initial guesses).
    s1: f64,
    /// C₀ (m/Pa) of a periodic cell on a rigid base.
    c0: Option<f64>,
    op: Operator,
    /// The preconditioner M⁻¹ = K̂⁻¹ (`BemOptions::preconditioner`; `None` where the
    /// operator's spectrum is not positive).
    precond: Option<Operator>,
    options: BemOptions,
    /// The row loops (scalar or AVX2), chosen once when the solver is built.
    kernels: Kernels,
    /// How to build the operator of the half grid (coarse-to-fine start; the half-grid
    /// solver is built for each cold start and dropped after it, not kept).
    source: KernelSource,
    /// Checked at the head of every iteration ([`Self::with_cancel`]).
    cancel: Cancel,
}

/// What the operator was built from (for the coarse grid).
#[derive(Clone)]
enum KernelSource {
    /// Periodic: the operator's own kernel table, K per distinct (i, |j|) wavevector of
    /// this grid (the half grid's wavevectors are among them).
    Spectral,
    /// Non-periodic: the stack.
    Stack(Box<Bodies>),
}

impl std::fmt::Debug for BemSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BemSolver")
            .field("grid", &(self.ny, self.nx))
            .field("geometry", &self.geometry)
            .field("e_star1", &self.e_star1)
            .field("c0", &self.c0)
            .field("options", &self.options)
            .finish_non_exhaustive()
    }
}

/// Validated heights and their statistics.
struct Heights {
    z: Vec<f64>,
    mean: f64,
    rms: f64,
    max: f64,
}

/// The first iterate of a solve: a borrowed pressure map (copied) or an owned one (the
/// iteration's own buffer).
enum Start<'a> {
    Borrowed(&'a [f64]),
    Owned(Vec<f64>),
}

impl Start<'_> {
    fn values(&self) -> &[f64] {
        match self {
            Start::Borrowed(p) => p,
            Start::Owned(p) => p,
        }
    }
}

/// The entries of a field other than +0.0 (its contact points, for a pressure map; a
/// −0.0 is kept too): flat index and value, given back as the dense field bit for bit.
struct ContactPoints {
    at: Vec<u32>,
    value: Vec<f64>,
}

impl ContactPoints {
    /// Of `p` with `count` entries other than +0.0 (indices below 2³²).
    fn of(p: &[f64], count: usize) -> Self {
        let mut at = Vec::with_capacity(count);
        let mut value = Vec::with_capacity(count);
        for (k, &v) in p.iter().enumerate() {
            if v.to_bits() != 0 {
                at.push(k as u32);
                value.push(v);
            }
        }
        ContactPoints { at, value }
    }

    /// The dense field of `n` entries (+0.0 elsewhere).
    fn dense(&self, n: usize) -> Vec<f64> {
        let mut p = vec![0.0; n];
        for (&k, &v) in self.at.iter().zip(&self.value) {
            p[k as usize] = v;
        }
        p
    }
}

/// The heights of a new solver: borrowed (copied once) or owned (moved in, no copy).
enum HeightsIn<'a> {
    Borrowed(&'a Array2<f64>),
    Owned(Array2<f64>),
}

impl HeightsIn<'_> {
    fn dim(&self) -> (usize, usize) {
        match self {
            HeightsIn::Borrowed(h) => h.dim(),
            HeightsIn::Owned(h) => h.dim(),
        }
    }

    /// The heights row-major, checked, with their statistics.
    fn validate(self, periodic: bool) -> Result<Heights, BemError> {
        let (rows, cols) = self.dim();
        let min = if periodic { 4 } else { 2 };
        if rows < min || cols < min {
            return Err(BemError::Grid { rows, cols });
        }
        let z = match self {
            HeightsIn::Owned(h) if h.is_standard_layout() => {
                // contiguous, row-major: the values from the buffer's offset on
                let (mut z, offset) = h.into_raw_vec_and_offset();
                z.drain(..offset.unwrap_or(0).min(z.len()));
                z.truncate(rows * cols);
                z
            }
            HeightsIn::Owned(h) => h.iter().copied().collect(),
            HeightsIn::Borrowed(h) => h.iter().copied().collect(),
        };
        validate_heights_flat(z, cols)
    }
}

/// Row-major heights (`cols` a row) checked finite and not flat, with their statistics.
fn validate_heights_flat(z: Vec<f64>, cols: usize) -> Result<Heights, BemError> {
    if let Some((k, &value)) = z.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(BemError::NonFiniteHeight {
            row: k / cols,
            col: k % cols,
            value,
        });
    }
    let n = z.len() as f64;
    let mean = z.iter().sum::<f64>() / n;
    let rms = (z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    if !rms.is_finite() {
        let big = z.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        return Err(BemError::HeightRange(big));
    }
    if rms <= 0.0 || rms <= 1e-14 * mean.abs() {
        return Err(BemError::FlatSurface);
    }
    let max = z.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    Ok(Heights { z, mean, rms, max })
}

fn check_geometry(g: &Geometry) -> Result<(), BemError> {
    for (what, value) in [("Lx", g.lx), ("Ly", g.ly)] {
        if !(value.is_finite() && value > 0.0) {
            return Err(BemError::Size { what, value });
        }
    }
    Ok(())
}

fn check_options(options: &BemOptions) -> Result<(), BemError> {
    if !(options.tolerance.is_finite() && options.tolerance > 0.0 && options.tolerance < 1.0) {
        return Err(BemError::Tolerance(options.tolerance));
    }
    if options.max_iterations == 0 {
        return Err(BemError::MaxIterations);
    }
    Ok(())
}

impl BemSolver {
    /// Bytes a solver needs for an ny × nx grid (heights, pressure, gap and CG vectors,
    /// kernel and FFT buffers; the padded grid when non-periodic): the estimate checked
    /// against [`BemOptions::memory`] before anything is allocated.
    pub fn memory_needed(ny: usize, nx: usize, periodic: bool) -> u64 {
        let points = (ny as u64).saturating_mul(nx as u64);
        // The largest set alive at once: z, the iteration's p, u, t and r (or the
        // tangent stiffness's Δp, r, d and q), and a second pressure map (the warm start
        // being moved in; a step's beside its tangent is kept as its contact points):
        // six fields; the operator with its row spectra and, non-periodic,
        // its inverse (the preconditioner's kernel; periodic, it is read from the
        // operator's table). The cold start's half grid (≈ 36 B/pt with the fine z and
        // p) and the maps formed after a step (z, p, the warm start, gap, deflection and
        // the row spectra) stay below it; the plain iteration's g and Δp (+16 B/pt, only
        // where the preconditioned iteration gives way to it) are not counted.
        let inverse = if periodic {
            0
        } else {
            8 * (nx as u64 + 1).saturating_mul(2 * ny as u64)
        };
        bytes_for(points, 8 * 6)
            .saturating_add(Operator::bytes(ny, nx, periodic))
            .saturating_add(inverse)
    }

    /// A periodic square cell: `heights` (n×n, m; row index = y, column index = x) of
    /// side `size` = L (m) on `stack`.
    pub fn new(
        heights: &Array2<f64>,
        size: f64,
        stack: &(impl Solid + ?Sized),
        options: BemOptions,
    ) -> Result<Self, BemError> {
        Self::with_geometry(heights, Geometry::square(size), stack, options)
    }

    /// Any sample: `heights` (ny × nx, m) with sides and boundary condition `geometry`.
    /// Periodic: the kernel 2S(|k|)/(E*₁|k|) on the (kx, ky) grid, S evaluated once per
    /// distinct |k|. Non-periodic: the pixel influence coefficients of
    /// [`crate::influence`] (Love's closed form plus the Hankel transform of k_z).
    pub fn with_geometry(
        heights: &Array2<f64>,
        geometry: Geometry,
        stack: &(impl Solid + ?Sized),
        options: BemOptions,
    ) -> Result<Self, BemError> {
        Self::build(HeightsIn::Borrowed(heights), geometry, stack, options)
    }

    /// [`with_geometry`](Self::with_geometry) taking the heights by value: they become
    /// the solver's own (no copy of the grid; the way to build a solver on a grid near
    /// the memory's limit).
    pub fn with_geometry_owned(
        heights: Array2<f64>,
        geometry: Geometry,
        stack: &(impl Solid + ?Sized),
        options: BemOptions,
    ) -> Result<Self, BemError> {
        Self::build(HeightsIn::Owned(heights), geometry, stack, options)
    }

    fn build(
        heights: HeightsIn<'_>,
        geometry: Geometry,
        stack: &(impl Solid + ?Sized),
        options: BemOptions,
    ) -> Result<Self, BemError> {
        if geometry.periodic {
            let homogeneous = stack.is_homogeneous();
            let comp = Compliance::new(stack);
            return Self::periodic(
                heights,
                geometry,
                stack.contact_modulus(),
                uniform_compliance(stack),
                |k| if homogeneous { 1.0 } else { comp.s(k) },
                options,
            );
        }
        check_geometry(&geometry)?;
        check_options(&options)?;
        let (ny, nx) = heights.dim();
        let h = heights.validate(false)?;
        options.memory.check(
            format!("BEM grid {ny}×{nx} (non-periodic)"),
            Self::memory_needed(ny, nx, false),
        )?;
        let e_star1 = stack.contact_modulus();
        if !(e_star1.is_finite() && e_star1 > 0.0) {
            return Err(BemError::Modulus(e_star1));
        }
        let g = crate::influence::coefficients(
            stack,
            ny,
            nx,
            geometry.lx / nx as f64,
            geometry.ly / ny as f64,
        )?;
        let op = Operator::free(ny, nx, &g)?;
        let s1 = Compliance::new(stack).s(geometry.fundamental());
        Ok(Self::assemble(
            ny,
            nx,
            geometry,
            h,
            (e_star1, s1),
            None,
            op,
            options,
            KernelSource::Stack(Box::new(stack.bodies())),
        ))
    }

    /// A periodic square cell with the normalised compliance S(k) (k in rad/m) given as a
    /// function (e.g. interpolated from a table), the top material's E*₁ (Pa), and the
    /// uniform-mode compliance C₀ (m/Pa; `Some` on a rigid base, `None` when infinite).
    pub fn with_compliance(
        heights: &Array2<f64>,
        size: f64,
        e_star1: f64,
        c0: Option<f64>,
        s_of_k: impl Fn(f64) -> f64,
        options: BemOptions,
    ) -> Result<Self, BemError> {
        Self::periodic(
            HeightsIn::Borrowed(heights),
            Geometry::square(size),
            e_star1,
            c0,
            s_of_k,
            options,
        )
    }

    fn periodic(
        heights: HeightsIn<'_>,
        geometry: Geometry,
        e_star1: f64,
        c0: Option<f64>,
        s_of_k: impl Fn(f64) -> f64,
        options: BemOptions,
    ) -> Result<Self, BemError> {
        check_geometry(&geometry)?;
        if !(e_star1.is_finite() && e_star1 > 0.0) {
            return Err(BemError::Modulus(e_star1));
        }
        if let Some(c) = c0.filter(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(BemError::UniformCompliance(c));
        }
        check_options(&options)?;
        let (ny, nx) = heights.dim();
        let h = heights.validate(true)?;
        options.memory.check(
            format!("BEM grid {ny}×{nx}"),
            Self::memory_needed(ny, nx, true),
        )?;
        // S per distinct wavevector (i ≤ nx/2, j ≤ ny/2), computed once.
        let (hx, hy) = (nx / 2, ny / 2);
        let (dkx, dky) = (
            std::f64::consts::TAU / geometry.lx,
            std::f64::consts::TAU / geometry.ly,
        );
        let square = nx == ny && geometry.lx == geometry.ly;
        let mut s_tab = vec![f64::NAN; (hx + 1) * (hy + 1)];
        for i in 0..=hx {
            for j in 0..=hy {
                if i == 0 && j == 0 {
                    continue;
                }
                if square && j < i {
                    // |k| symmetric in (i, j) on a square grid.
                    s_tab[i * (hy + 1) + j] = s_tab[j * (hy + 1) + i];
                    continue;
                }
                let k = (dkx * i as f64).hypot(dky * j as f64);
                let s = s_of_k(k);
                if !(s.is_finite() && s >= 0.0) {
                    return Err(BemError::Kernel { k, s });
                }
                s_tab[i * (hy + 1) + j] = s;
            }
        }
        let op = Self::spectral_operator(ny, nx, &geometry, e_star1, c0, &s_tab)?;
        drop(s_tab);
        let s1 = s_of_k(geometry.fundamental());
        Ok(Self::assemble(
            ny,
            nx,
            geometry,
            h,
            (e_star1, s1),
            c0,
            op,
            options,
            KernelSource::Spectral,
        ))
    }

    /// The periodic operator on the ny × nx grid from S tabulated per distinct
    /// wavevector (`s_tab[i·(ny/2 + 1) + j]`, i ≤ nx/2, j ≤ ny/2).
    fn spectral_operator(
        ny: usize,
        nx: usize,
        g: &Geometry,
        e_star1: f64,
        c0: Option<f64>,
        s_tab: &[f64],
    ) -> Result<Operator, BemError> {
        let (dkx, dky) = (std::f64::consts::TAU / g.lx, std::f64::consts::TAU / g.ly);
        let hy = ny / 2;
        Operator::periodic(ny, nx, c0.unwrap_or(0.0), |i, j| {
            let k = (dkx * i as f64).hypot(dky * j as f64);
            Ok(2.0 * s_tab[i * (hy + 1) + j] / (e_star1 * k))
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn assemble(
        ny: usize,
        nx: usize,
        geometry: Geometry,
        h: Heights,
        (e_star1, s1): (f64, f64),
        c0: Option<f64>,
        op: Operator,
        options: BemOptions,
        source: KernelSource,
    ) -> Self {
        let precond = if options.preconditioner {
            op.inverse()
        } else {
            None
        };
        BemSolver {
            ny,
            nx,
            geometry,
            precond,
            z: h.z,
            z_max: h.max,
            z_mean: h.mean,
            z_rms: h.rms,
            e_star1,
            s1,
            c0,
            op,
            options,
            kernels: Kernels::detect(),
            source,
            cancel: Cancel::default(),
        }
    }

    /// Whether the iteration is preconditioned (`BemOptions::preconditioner` and an
    /// operator whose spectrum is positive, see the `pcg` module).
    pub fn preconditioned(&self) -> bool {
        self.precond.is_some()
    }

    /// Grid size n (rows; = columns on a square grid).
    pub fn n(&self) -> usize {
        self.ny
    }

    /// Grid (rows ny, columns nx).
    pub fn shape(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    /// Cell side along x, Lx (m).
    pub fn size(&self) -> f64 {
        self.geometry.lx
    }

    /// Sides and boundary condition.
    pub fn geometry(&self) -> Geometry {
        self.geometry
    }

    /// Nominal area Lx·Ly (m²).
    pub fn area(&self) -> f64 {
        self.geometry.lx * self.geometry.ly
    }

    /// E*₁ of the top material (Pa).
    pub fn e_star1(&self) -> f64 {
        self.e_star1
    }

    /// z_M − z̄ (m): the separation at first touch.
    pub fn max_separation(&self) -> f64 {
        self.z_max - self.z_mean
    }

    /// Solves one load from a default initial guess (the half-grid solution on grids
    /// from 256 points a side).
    pub fn solve(&self, load: BemLoad) -> Result<BemSolution, BemError> {
        self.solve_from(load, None)
    }

    /// Solves a sequence of loads, each warm-started from the previous ones: the last
    /// pressure field extrapolated linearly in the load parameter from the last two
    /// solutions (clipped at 0), which predicts both the field and the contact set.
    pub fn solve_curve(&self, loads: &[BemLoad]) -> Result<Vec<BemSolution>, BemError> {
        let mut out: Vec<BemSolution> = Vec::with_capacity(loads.len());
        let mut guess = Vec::new();
        for &load in loads {
            let init = match out.as_slice() {
                [.., a, b] if b.contact_points > 0 && a.contact_points > 0 => {
                    extrapolate(a, b, load, &mut guess);
                    Some(guess.as_slice())
                }
                [.., b] if b.contact_points > 0 => {
                    guess.clear();
                    guess.extend(b.pressure.iter());
                    Some(guess.as_slice())
                }
                _ => None,
            };
            let s = self.solve_from(load, init)?;
            out.push(s);
        }
        Ok(out)
    }

    /// Solves one load, starting from `initial` pressures (row-major ny·nx, Pa) if given.
    pub fn solve_from(
        &self,
        load: BemLoad,
        initial: Option<&[f64]>,
    ) -> Result<BemSolution, BemError> {
        self.solve_maps(load, initial.map(Start::Borrowed), true)
    }

    /// [`solve_from`](Self::solve_from) keeping only the pressure map: the solution's
    /// `gap` and `displacement` are left empty (0×0), its scalars are those of
    /// `solve_from`. [`complete_maps`](Self::complete_maps) computes the two maps later
    /// from the pressure (one convolution; the same values). A load step then holds the
    /// pressure alone (8 bytes per point) while, e.g., its tangent stiffness is solved.
    pub fn solve_pressure_only(
        &self,
        load: BemLoad,
        initial: Option<&[f64]>,
    ) -> Result<BemSolution, BemError> {
        self.solve_maps(load, initial.map(Start::Borrowed), false)
    }

    /// [`solve_pressure_only`](Self::solve_pressure_only) from `initial` taken by value:
    /// its buffer becomes the iteration's pressure and the solution's (no copy of the
    /// grid beside it). The same solution as from `Some(&initial)`.
    pub fn solve_pressure_only_in(
        &self,
        load: BemLoad,
        initial: Vec<f64>,
    ) -> Result<BemSolution, BemError> {
        self.solve_maps(load, Some(Start::Owned(initial)), false)
    }

    /// [`solve_pressure_only`](Self::solve_pressure_only) warm-started from the pressure of
    /// `start` (a solution of this solver), which lends its pressure map to the iteration
    /// as its first iterate and keeps meanwhile its contact points alone (index and
    /// value: 12 bytes per point in contact instead of 8 per grid point; a copy where
    /// that is not smaller). `start.pressure` is given back bit for bit, also when the
    /// solve fails. The same solution as
    /// `solve_pressure_only(load, Some(start.pressure))`: a second solve after a step (a
    /// finite-difference probe of it) holds one full pressure map, not two.
    pub fn solve_lent(
        &self,
        load: BemLoad,
        start: &mut BemSolution,
    ) -> Result<BemSolution, BemError> {
        let n2 = self.ny * self.nx;
        let shape = start.pressure.dim();
        let Some(p) = start.pressure.as_slice().filter(|p| p.len() == n2) else {
            let init: Vec<f64> = start.pressure.iter().copied().collect();
            return self.solve_pressure_only(load, Some(&init));
        };
        let contact = p.iter().filter(|v| v.to_bits() != 0).count();
        if 12 * contact >= 8 * n2 || u32::try_from(n2).is_err() {
            return self.solve_pressure_only(load, Some(p));
        }
        let kept = ContactPoints::of(p, contact);
        let lent = std::mem::take(&mut start.pressure);
        let (lent, offset) = lent.into_raw_vec_and_offset();
        debug_assert_eq!(offset.unwrap_or(0), 0);
        let out = self.solve_pressure_only_in(load, lent);
        start.pressure = Array2::from_shape_vec(shape, kept.dense(n2)).unwrap_or_default();
        out
    }

    /// The tangent stiffness dP/dδ (N/m) of `solution` (a solution of this solver; of a
    /// [`crate::PlasticPath`] on it: [`crate::PlasticPath::tangent`]): K_AA Δp = 1 on
    /// the contact set A held fixed (the points p > 0 below `below`, Pa, if given: a
    /// capped solution's elastic contact), dP/dδ = (Lx·Ly/(ny·nx)) Σ_A Δp, solved to the relative residual
    /// [`crate::tangent::TOLERANCE`] (module [`crate::tangent`]). The iteration's four
    /// fields are Δp (returned) and three buffers, one of them `solution`'s pressure map,
    /// lent as in [`solve_lent`](Self::solve_lent) (its contact points kept meanwhile,
    /// given back bit for bit, also when the solve fails): beside a step's pressure the
    /// tangent holds as many grid fields as the step's iteration.
    pub fn tangent(
        &self,
        solution: &mut BemSolution,
        below: Option<f64>,
    ) -> Result<crate::Tangent, BemError> {
        let n2 = self.ny * self.nx;
        let shape = solution.pressure.dim();
        let owned: Vec<f64>;
        let p: &[f64] = match solution.pressure.as_slice() {
            Some(p) => p,
            None => {
                owned = solution.pressure.iter().copied().collect();
                &owned
            }
        };
        if p.len() != n2 {
            return Err(BemError::Initial {
                expected: n2,
                got: p.len(),
            });
        }
        let set = crate::tangent::Set::of(p, below);
        let contact = p.iter().filter(|v| v.to_bits() != 0).count();
        let lend = 12 * contact < 8 * n2 && u32::try_from(n2).is_ok();
        let (kept, mut q) = if lend && solution.pressure.as_slice().is_some() {
            let kept = ContactPoints::of(p, contact);
            let lent = std::mem::take(&mut solution.pressure);
            let (lent, _) = lent.into_raw_vec_and_offset();
            (Some(kept), lent)
        } else {
            (None, vec![0.0; n2])
        };
        let mut dp = vec![0.0; n2];
        let (mut r, mut d) = (vec![0.0; n2], vec![0.0; n2]);
        let uniform = self.geometry.periodic && self.c0.is_some();
        let mut work = self.op.work();
        let (op, minv) = (&self.op, self.precond.as_ref());
        let product = |which, input: &[f64], out: &mut [f64], uniform| match (which, minv) {
            (crate::reference::Apply::Inverse, Some(m)) => m.apply(input, out, uniform, &mut work),
            _ => op.apply(input, out, uniform, &mut work),
        };
        let out = crate::tangent::run(
            &crate::decomp::Serial,
            product,
            &set,
            uniform,
            minv.is_some(),
            self.options.max_iterations,
            || Ok(self.cancel.check()?),
            crate::tangent::Fields {
                dp: &mut dp,
                r: &mut r,
                d: &mut d,
                q: &mut q,
            },
        );
        drop((r, d));
        if let Some(kept) = kept {
            // the step's pressure back in its own buffer
            q.fill(0.0);
            for (&k, &v) in kept.at.iter().zip(&kept.value) {
                q[k as usize] = v;
            }
            solution.pressure = Array2::from_shape_vec(shape, q).unwrap_or_default();
        }
        let out = out?;
        Ok(crate::Tangent {
            stiffness: self.area() / n2 as f64 * out.sum,
            pressure_rate: dp,
            points: out.points,
            iterations: out.iterations,
            products: out.products,
            residual: out.residual,
        })
    }

    /// The gap and displacement maps of a solution from
    /// [`solve_pressure_only`](Self::solve_pressure_only) (of this solver), from its
    /// pressure and offset: u = K p, g = u − z + c, the values `solve_from` returns. A
    /// solution that has them is left as it is.
    pub fn complete_maps(&self, sol: &mut BemSolution) -> Result<(), BemError> {
        let n2 = self.ny * self.nx;
        if sol.gap.len() == n2 && sol.displacement.len() == n2 {
            return Ok(());
        }
        let control = self.control(sol.load)?;
        let p = sol.pressure.as_standard_layout();
        if p.len() != n2 {
            return Err(BemError::Initial {
                expected: n2,
                got: p.len(),
            });
        }
        let mut gap = vec![0.0; n2];
        let p = p.as_slice().unwrap_or_default();
        self.op
            .apply(p, &mut gap, control.uniform(), &mut self.op.work())?;
        let c = sol.offset;
        gap.iter_mut()
            .zip(&self.z)
            .for_each(|(g, z)| *g = *g - z + c);
        let displacement = crate::maps::deflection(
            &gap,
            &self.z,
            c,
            self.geometry.periodic.then_some(sol.mean_deflection),
        );
        let shape = (self.ny, self.nx);
        sol.gap = Array2::from_shape_vec(shape, gap).unwrap_or_default();
        sol.displacement = Array2::from_shape_vec(shape, displacement).unwrap_or_default();
        Ok(())
    }

    fn solve_maps(
        &self,
        load: BemLoad,
        initial: Option<Start<'_>>,
        maps: bool,
    ) -> Result<BemSolution, BemError> {
        let n2 = self.ny * self.nx;
        let control = self.control(load)?;
        if let Some(init) = &initial {
            let init = init.values();
            if init.len() != n2 || init.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(BemError::Initial {
                    expected: n2,
                    got: init.len(),
                });
            }
        }
        let mut p = match initial {
            Some(Start::Owned(p)) => p,
            Some(Start::Borrowed(init)) => init.to_vec(),
            None => {
                let mut p = vec![0.0; n2];
                self.coarse_start(control, &mut p);
                p
            }
        };
        let out = cg::solve(&self.problem(), control, &mut p)?;
        let s = self.summarise(load, control, p, out, maps);
        // Absurd loads (an approach of 1e300 m on a rigid base) overflow the sums.
        if !(s.mean_pressure.is_finite() && s.mean_gap.is_finite() && s.approach.is_finite()) {
            return Err(BemError::NonFinite(s.iterations));
        }
        Ok(s)
    }

    /// Solves one load on the unaccelerated reference path (module `reference`): Polonsky
    /// & Keer's iteration as published, two convolutions per iteration (the gap recomputed
    /// from the pressure every time), a cold start on the full grid, the same error ε and
    /// tolerance. Much slower than [`solve`](Self::solve); it exists to check the fast
    /// path (warm starts, coarse-to-fine start, incremental gap, fused passes) against.
    pub fn solve_reference(&self, load: BemLoad) -> Result<BemSolution, BemError> {
        let control = self.control(load)?;
        let mut p = vec![0.0; self.ny * self.nx];
        let out = crate::reference::solve(&self.problem(), control, &mut p)?;
        Ok(self.summarise(load, control, p, out, true))
    }

    fn problem(&self) -> Problem<'_> {
        Problem {
            op: &self.op,
            precond: self.precond.as_ref(),
            z: &self.z,
            z_rms: self.z_rms,
            stiffness: self.local_stiffness(),
            tolerance: self.options.tolerance,
            max_iterations: self.options.max_iterations,
            kernels: self.kernels,
            cancel: &self.cancel,
        }
    }

    /// The same solver stopping with [`BemError::Cancelled`] at the head of the first
    /// iteration after `cancel` is tripped (every solve, the coarse start's too; a
    /// 1024² iteration takes ~0.1 s). Nothing is returned of a cancelled solve.
    pub fn with_cancel(mut self, cancel: Cancel) -> Self {
        self.cancel = cancel;
        self
    }

    /// The same solver with the row loops `kernels` (tests of the scalar rules against
    /// the vector forms on whole solves; before any solve, so the coarse grid's solver
    /// inherits them).
    #[cfg(test)]
    pub(crate) fn with_kernels(mut self, kernels: Kernels) -> Self {
        self.kernels = kernels;
        self
    }

    /// The CG control of a load.
    fn control(&self, load: BemLoad) -> Result<Control, BemError> {
        load_control(
            load,
            self.geometry.periodic,
            self.c0,
            [self.z_max, self.z_mean],
        )
    }

    /// The influence operator (module `plastic`).
    pub(crate) fn operator(&self) -> &Operator {
        &self.op
    }

    /// The heights, row-major (m), and their maximum, mean and RMS (module `plastic`).
    pub(crate) fn heights_and_stats(&self) -> (&[f64], [f64; 3]) {
        (&self.z, [self.z_max, self.z_mean, self.z_rms])
    }

    /// C₀ of a periodic cell on a rigid base, and the solver's options (module `plastic`).
    pub(crate) fn uniform_and_options(&self) -> (Option<f64>, BemOptions) {
        (self.c0, self.options)
    }

    /// The elastic iteration on the heights `z` instead of the solver's (same operator,
    /// preconditioner, statistics and options) under `control`, from `p`: the inner
    /// solve of module `plastic`'s active-set steps. Returns the offset and the gap.
    pub(crate) fn solve_on(
        &self,
        z: &[f64],
        control: Control,
        p: &mut [f64],
    ) -> Result<(f64, Vec<f64>, usize), BemError> {
        let mut pb = self.problem();
        pb.z = z;
        let out = cg::solve(&pb, control, p)?;
        Ok((out.offset, out.gap, out.products))
    }

    /// The cancellation token (module `plastic`).
    pub(crate) fn cancel_token(&self) -> &Cancel {
        &self.cancel
    }

    /// The preconditioner M⁻¹, if the iteration is preconditioned (module `plastic`).
    pub(crate) fn preconditioner(&self) -> Option<&Operator> {
        self.precond.as_ref()
    }

    /// The cold start of a solve under `control`: the coarse-to-fine start on large
    /// grids, zero otherwise (module `plastic`).
    pub(crate) fn start_guess(&self, control: Control, p: &mut [f64]) {
        self.coarse_start(control, p);
    }

    /// The control of `load` (module `plastic`).
    pub(crate) fn control_of(&self, load: BemLoad) -> Result<Control, BemError> {
        self.control(load)
    }

    /// The half grid's solver (the same cell and solid, the heights on 2×2 blocks), its
    /// tolerance this one's or 1e−6 if looser, and this one's cancellation: the start of
    /// a capped step ([`crate::PlasticPath`]). `None` below 256² or on grids not
    /// divisible by 4.
    pub(crate) fn half_grid(&self) -> Option<Box<BemSolver>> {
        let mut coarse = self.build_coarse()?;
        coarse.options.tolerance = coarse.options.tolerance.max(1e-6);
        coarse.cancel = self.cancel.clone();
        Some(coarse)
    }

    /// `p` on [`Self::half_grid`]: the means of its 2×2 blocks.
    pub(crate) fn restrict_half(&self, p: &[f64]) -> Vec<f64> {
        let (my, mx, nx) = (self.ny / 2, self.nx / 2, self.nx);
        let mut pc = Vec::with_capacity(my * mx);
        for i in 0..my {
            for j in 0..mx {
                let (a, b) = (2 * i * nx + 2 * j, (2 * i + 1) * nx + 2 * j);
                pc.push(0.25 * (p[a] + p[a + 1] + p[b] + p[b + 1]));
            }
        }
        pc
    }

    /// `pc`, a field of [`Self::half_grid`], injected into `p` on 2×2 blocks.
    pub(crate) fn inject_half(&self, pc: &[f64], p: &mut [f64]) {
        let mx = self.nx / 2;
        for i in 0..self.ny {
            for j in 0..self.nx {
                p[i * self.nx + j] = pc[(i / 2) * mx + j / 2];
            }
        }
    }

    /// Coarse-to-fine start: the same load solved on the half grid (loosely), its
    /// pressure injected on 2×2 blocks. Only on large even grids.
    fn coarse_start(&self, control: Control, p: &mut [f64]) {
        let Some(coarse) = self.build_coarse() else {
            return;
        };
        let mut pc = vec![0.0; coarse.ny * coarse.nx];
        coarse.coarse_start(control, &mut pc);
        let pb = Problem {
            tolerance: self.options.tolerance.max(1e-6),
            cancel: &self.cancel,
            ..coarse.problem()
        };
        if cg::solve(&pb, control, &mut pc).is_err() {
            return;
        }
        for i in 0..self.ny {
            for j in 0..self.nx {
                p[i * self.nx + j] = pc[(i / 2) * coarse.nx + j / 2];
            }
        }
    }

    fn build_coarse(&self) -> Option<Box<BemSolver>> {
        let (ny, nx) = (self.ny, self.nx);
        if ny < COARSE_MIN || nx < COARSE_MIN || !ny.is_multiple_of(4) || !nx.is_multiple_of(4) {
            return None;
        }
        let (my, mx) = (ny / 2, nx / 2);
        let z = &self.z;
        let zc = if self.geometry.periodic {
            crate::maps::resample_flat(z, (ny, nx), my, mx).ok()?
        } else {
            let mut zc = Vec::with_capacity(my * mx);
            for i in 0..my {
                for j in 0..mx {
                    zc.push(
                        0.25 * (z[2 * i * nx + 2 * j]
                            + z[(2 * i + 1) * nx + 2 * j]
                            + z[2 * i * nx + 2 * j + 1]
                            + z[(2 * i + 1) * nx + 2 * j + 1]),
                    );
                }
            }
            zc
        };
        let zc = Array2::from_shape_vec((my, mx), zc).ok()?;
        let h = HeightsIn::Owned(zc).validate(self.geometry.periodic).ok()?;
        let op = match &self.source {
            KernelSource::Spectral => {
                // The half grid's wavevectors are this grid's (same cell): its kernel
                // entries are this table's.
                let table = self.op.periodic_table()?;
                let hy = ny / 2 + 1;
                Operator::periodic(my, mx, table[0], |i, j| Ok(table[i * hy + j])).ok()?
            }
            KernelSource::Stack(stack) => {
                let g = crate::influence::coefficients(
                    stack.as_ref(),
                    my,
                    mx,
                    self.geometry.lx / mx as f64,
                    self.geometry.ly / my as f64,
                )
                .ok()?;
                Operator::free(my, mx, &g).ok()?
            }
        };
        let mut coarse = Self::assemble(
            my,
            mx,
            self.geometry,
            h,
            (self.e_star1, self.s1),
            self.c0,
            op,
            self.options,
            self.source.clone(),
        );
        coarse.kernels = self.kernels;
        Some(Box::new(coarse))
    }

    /// A stiffness (Pa/m) for initial guesses: that of the longest wave of the sample,
    /// E*₁k₁/(2S(k₁)) with k₁ = 2π/L (the kernel 2S(k)/(E*₁k) inverted). On a stiff
    /// coating over a soft base S(k₁) ≫ 1: the long waves load the base, and a guess with
    /// the top material's stiffness would press 1/S(k₁) times too hard (a start the
    /// preconditioned iteration sheds slowly under mean-gap control, see [`crate::pcg`]).
    fn local_stiffness(&self) -> f64 {
        let s1 = if self.s1.is_finite() && self.s1 > 0.0 {
            self.s1
        } else {
            1.0
        };
        0.5 * self.e_star1 * self.geometry.fundamental() / s1
    }

    fn summarise(
        &self,
        load: BemLoad,
        control: Control,
        p: Vec<f64>,
        out: crate::iteration::CgOutcome,
        maps: bool,
    ) -> BemSolution {
        let (ny, nx) = (self.ny, self.nx);
        let n2 = (ny * nx) as f64;
        let mean_pressure = p.iter().sum::<f64>() / n2;
        let contact: Vec<bool> = p.iter().map(|&v| v > 0.0).collect();
        let contact_points = contact.iter().filter(|&&c| c).count();
        let mean_gap = out.gap.iter().sum::<f64>() / n2;
        let (approach, mean_deflection) = if self.geometry.periodic {
            // w̄ = C₀p̄ on a rigid base (zero-mean deflection otherwise).
            let w = self.c0.map_or(0.0, |c0| c0 * mean_pressure);
            (self.max_separation() - mean_gap + w, w)
        } else {
            // The free solid: g = w − z + c exactly, c = z_M − δ.
            let _ = control;
            let approach = self.z_max - out.offset;
            (approach, mean_gap - (out.offset - self.z_mean))
        };
        let shape = (ny, nx);
        let (gap, displacement) = if maps {
            let w = crate::maps::deflection(
                &out.gap,
                &self.z,
                out.offset,
                self.geometry.periodic.then_some(mean_deflection),
            );
            (
                Array2::from_shape_vec(shape, out.gap).unwrap_or_default(),
                Array2::from_shape_vec(shape, w).unwrap_or_default(),
            )
        } else {
            drop(out.gap);
            (Array2::zeros((0, 0)), Array2::zeros((0, 0)))
        };
        BemSolution {
            load,
            mean_pressure,
            pressure_ratio: mean_pressure / self.e_star1,
            area_fraction: contact_points as f64 / n2,
            contact_points,
            patches: count_patches(&contact, ny, nx, self.geometry.periodic),
            mean_gap,
            approach,
            separation: self.max_separation() - approach,
            total_load: mean_pressure * self.area(),
            mean_deflection,
            iterations: out.iterations,
            products: out.products,
            error: out.error,
            pressure: Array2::from_shape_vec(shape, p).unwrap_or_default(),
            displacement,
            gap,
            plastic_depth: None,
            sides: [self.geometry.lx, self.geometry.ly],
            periodic: self.geometry.periodic,
            offset: out.offset,
        }
    }
}

/// Linear extrapolation of the pressure from solutions `a`, `b` (in that order) to
/// `load`, in the load's own parameter; clipped at 0. Falls back to `b`'s field.
fn extrapolate(a: &BemSolution, b: &BemSolution, load: BemLoad, out: &mut Vec<f64>) {
    let param = |s: &BemSolution| match load {
        BemLoad::MeanPressure(_) => s.mean_pressure,
        BemLoad::MeanGap(_) => s.mean_gap,
        BemLoad::Approach(_) | BemLoad::Separation(_) => s.approach,
    };
    let target = match load {
        BemLoad::MeanPressure(p) => p,
        BemLoad::MeanGap(g) => g,
        BemLoad::Approach(d) => d,
        BemLoad::Separation(g) => b.approach + b.separation - g,
    };
    let (pa, pb) = (param(a), param(b));
    let f = if (pb - pa).abs() > 0.0 {
        ((target - pb) / (pb - pa)).clamp(-1.0, 2.0)
    } else {
        0.0
    };
    out.clear();
    out.extend(
        a.pressure
            .iter()
            .zip(b.pressure.iter())
            .map(|(&x, &y)| (y + f * (y - x)).max(0.0)),
    );
}

/// The CG control of a load on a sample (`periodic` or not) with the uniform-mode
/// compliance `c0` (m/Pa; a periodic cell on a rigid base) and the heights' maximum and
/// mean (m): the flat's offset c or the mean pressure (crate docs, "Loads").
pub(crate) fn load_control(
    load: BemLoad,
    periodic: bool,
    c0: Option<f64>,
    [z_max, z_mean]: [f64; 2],
) -> Result<Control, BemError> {
    let bad = |what, value, reason: &str| BemError::Load {
        what,
        value,
        reason: reason.to_string(),
    };
    let (approach, what) = match load {
        BemLoad::Approach(d) => (d, "approach"),
        // A separation is an approach: δ = (z_M − z̄) − g_n.
        BemLoad::Separation(gn) => ((z_max - z_mean) - gn, "separation"),
        BemLoad::MeanGap(g) => {
            if !periodic {
                return Err(bad(
                    "mean gap",
                    g,
                    "is not a load of a non-periodic sample (the mean deflection depends on the unbounded solid); give an approach, a separation or a mean pressure",
                ));
            }
            if !(g.is_finite() && g > 0.0) {
                return Err(bad(
                    "mean gap",
                    g,
                    "must be finite and > 0 m (a zero mean gap is full contact)",
                ));
            }
            return Ok(Control::Offset {
                c: g + z_mean,
                uniform: false,
            });
        }
        BemLoad::MeanPressure(p) => {
            if !(p.is_finite() && p > 0.0) {
                return Err(bad("mean pressure", p, "must be finite and > 0 Pa"));
            }
            return Ok(Control::Pressure(p));
        }
    };
    if !approach.is_finite() {
        return Err(bad(what, approach, "must be finite (m)"));
    }
    if !periodic || c0.is_some() {
        // The flat at c = z_M − δ: any δ (beyond the peak-to-valley height too; the
        // layers or the unbounded solid compress as a whole).
        return Ok(Control::Offset {
            c: z_max - approach,
            uniform: c0.is_some(),
        });
    }
    let g = (z_max - z_mean) - approach;
    if g <= 0.0 {
        return Err(bad(
            what,
            approach,
            "on an elastic base the approach of a periodic cell must be < z_M − z̄, the separation > 0 (the uniform mode is unbounded: full contact)",
        ));
    }
    Ok(Control::Offset {
        c: g + z_mean,
        uniform: false,
    })
}
