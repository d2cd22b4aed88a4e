//! The boundary-element solve on a slab decomposition ([`crate::decomp`]): each rank
//! generates, holds and iterates on its own rows of the grid (heights, pressure, gap and
//! the iteration's fields), the influence operator is the distributed product of
//! [`crate::slab`], and every sum and maximum of the iteration is a global reduction in
//! rank order. No rank holds a whole grid.
//!
//! The iteration is Polonsky & Keer's as published (the reference path,
//! [`crate::BemSolver::solve_reference`]: two products per iteration, the stop on the
//! error ε of the crate docs), preconditioned by default (`BemOptions::preconditioner`)
//! with the inverse operator as the fast path's (a third product per iteration), and
//! warm-started along a load path from the previous step's pressure. On one rank
//! ([`Serial`](crate::decomp::Serial)) it runs the serial operator of
//! [`crate::BemSolver`] and the serial sums: without the preconditioner a one-load solve
//! is `BemSolver::solve_reference` bit for bit (tested). On P ranks the products are the
//! serial ones bit for bit and the sums differ by the order of the partial sums only.
//!
//! Outputs are scalars per load ([`SlabStep`], the columns of a load curve), the same on
//! every rank; whoever writes them (rank 0) writes what a serial run writes.

use strata_runtime::compliance::Compliance;
use strata_runtime::resources::bytes_for;
use strata_runtime::stack::Solid;

use crate::decomp::{self, Decomposition};
use crate::operator::Operator;
use crate::reference::{self, Apply, Settings};
use crate::slab::SlabOperator;
use crate::solver::{Geometry, load_control, uniform_compliance};
use crate::{BemError, BemLoad, BemOptions};

/// The operator of a rank: the serial one on one rank, the slab product on several.
enum Product<'c> {
    Serial(Box<Operator>),
    Slab(SlabOperator<'c>),
}

/// One surface on one stack, distributed by rows; build once, solve a load path.
pub struct SlabSolver<'c> {
    comm: &'c dyn Decomposition,
    ny: usize,
    nx: usize,
    geometry: Geometry,
    rows: std::ops::Range<usize>,
    /// This rank's rows of the heights (m).
    z: Vec<f64>,
    z_max: f64,
    z_mean: f64,
    z_rms: f64,
    e_star1: f64,
    stiffness: f64,
    c0: Option<f64>,
    product: Product<'c>,
    /// The preconditioner M⁻¹ = K̂⁻¹ (`BemOptions::preconditioner`; `None` where the
    /// operator's spectrum is not positive).
    precond: Option<Product<'c>>,
    options: BemOptions,
}

/// The scalars of one solved load (SI units), the same on every rank.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlabStep {
    pub load: BemLoad,
    /// Mean pressure p̄ (Pa).
    pub mean_pressure: f64,
    /// Real contact area fraction A/A₀.
    pub area_fraction: f64,
    /// Grid points in contact (p > 0).
    pub contact_points: usize,
    /// Mean gap ḡ (m).
    pub mean_gap: f64,
    /// Approach δ (m) (crate docs).
    pub approach: f64,
    /// Nominal separation z_M − z̄ − δ (m).
    pub separation: f64,
    /// Iterations and operator products of the solve.
    pub iterations: usize,
    pub products: usize,
    /// The error ε at the stop.
    pub error: f64,
}

impl SlabStep {
    /// The header of [`Self::csv_row`].
    pub const CSV_HEADER: &'static str = "separation_m,approach_m,mean_pressure_pa,area_fraction,contact_points,mean_gap_m,iterations,error";

    /// The step as a CSV row, every value to 17 significant digits.
    pub fn csv_row(&self) -> String {
        format!(
            "{:.16e},{:.16e},{:.16e},{:.16e},{},{:.16e},{},{:.3e}",
            self.separation,
            self.approach,
            self.mean_pressure,
            self.area_fraction,
            self.contact_points,
            self.mean_gap,
            self.iterations,
            self.error
        )
    }
}

impl<'c> SlabSolver<'c> {
    /// Bytes rank `rank` of `ranks` needs for an ny × nx grid: its rows of six fields
    /// (48 bytes per owned point: z, p and the iteration's u, g, t, r, or z, p and the
    /// tangent stiffness's Δp, r, d, q, [`Self::tangent`]); its columns of the kernel
    /// (periodic: (NX/2+1)/P columns of NY/2+1 values, the preconditioner reading the
    /// same table; free: 2NX/2+1 … of 2NY values, twice, the inverse's own), the
    /// product's rows' spectra (P blocks of ⌈m⌉·⌈(NX/2+1)/P⌉ complex values) and its two
    /// exchange chunks (a sixteenth of that each). Free: plus the influence coefficients
    /// of every offset (ny·nx values), which the operator's set-up holds whole on every
    /// rank.
    pub fn memory_needed(
        (ny, nx): (usize, usize),
        periodic: bool,
        ranks: usize,
        rank: usize,
    ) -> u64 {
        let ranks = ranks.max(1);
        let m = decomp::slab(ny, ranks, rank).len() as u64;
        let owned = m.saturating_mul(nx as u64);
        let (gy, gx) = if periodic { (ny, nx) } else { (2 * ny, 2 * nx) };
        let half = gx / 2 + 1;
        let cols = decomp::slab(half, ranks, rank).len() as u64;
        let kernel = if periodic {
            cols.saturating_mul(ny as u64 / 2 + 1)
        } else {
            2 * cols.saturating_mul(gy as u64) + (ny as u64).saturating_mul(nx as u64)
        };
        let cm = decomp::slab_max(half, ranks);
        let rows = decomp::slab_max(ny, ranks) as u64;
        let block = 2 * rows * cm as u64;
        let chunk = 2 * rows * crate::slab::chunk_columns(cm) as u64;
        let exchange = (ranks as u64).saturating_mul(block + 2 * chunk);
        bytes_for(owned, 8 * 6)
            .saturating_add(bytes_for(kernel, 8))
            .saturating_add(bytes_for(exchange, 8))
    }

    /// The solver of an ny × nx grid with sides and boundary condition `geometry` on
    /// `stack`, the heights of each of this rank's rows written by `row(i, z_row)` (global
    /// row index i, nx values, m). Every rank calls it together. Each rank checks its
    /// own share ([`Self::memory_needed`]) against `options.memory` before it allocates;
    /// if any rank's share is over its limit every rank returns an error (the rank over
    /// it: [`BemError::Memory`] naming the grid and the rank).
    pub fn new(
        comm: &'c dyn Decomposition,
        (ny, nx): (usize, usize),
        geometry: Geometry,
        stack: &(impl Solid + ?Sized),
        options: BemOptions,
        mut row: impl FnMut(usize, &mut [f64]),
    ) -> Result<Self, BemError> {
        let min = if geometry.periodic { 4 } else { 2 };
        if ny < min || nx < min {
            return Err(BemError::Grid { rows: ny, cols: nx });
        }
        if ny < comm.size() {
            return Err(BemError::Ranks {
                rows: ny,
                ranks: comm.size(),
            });
        }
        for (what, value) in [("Lx", geometry.lx), ("Ly", geometry.ly)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(BemError::Size { what, value });
            }
        }
        let (p, q) = (comm.size(), comm.rank());
        let mine = decomp::slab(ny, p, q);
        let kind = if geometry.periodic {
            ""
        } else {
            " (non-periodic)"
        };
        let checked = options.memory.check(
            format!(
                "BEM grid {ny}×{nx}{kind}, rank {q} of {p} (rows {}..{})",
                mine.start, mine.end
            ),
            Self::memory_needed((ny, nx), geometry.periodic, p, q),
        );
        if decomp::any(comm, checked.is_err()) {
            return Err(match checked {
                Err(e) => e.into(),
                Ok(()) => BemError::OtherRank {
                    what: format!("the memory check of the BEM grid {ny}×{nx}"),
                },
            });
        }
        let rows = decomp::slab(ny, comm.size(), comm.rank());
        let mut z = vec![0.0; rows.len() * nx];
        for (r, zr) in z.chunks_mut(nx).enumerate() {
            row(rows.start + r, zr);
        }
        let [z_max, z_mean, z_rms] = heights_stats(comm, &z, rows.start, (ny, nx))?;
        let e_star1 = stack.contact_modulus();
        if !(e_star1.is_finite() && e_star1 > 0.0) {
            return Err(BemError::Modulus(e_star1));
        }
        let comp = Compliance::new(stack);
        let homogeneous = stack.is_homogeneous();
        let s_of_k = |k: f64| if homogeneous { 1.0 } else { comp.s(k) };
        let c0 = if geometry.periodic {
            uniform_compliance(stack)
        } else {
            None
        };
        let product = if geometry.periodic {
            let (dkx, dky) = (
                std::f64::consts::TAU / geometry.lx,
                std::f64::consts::TAU / geometry.ly,
            );
            let kernel_of = |i: usize, j: usize| {
                let k = (dkx * i as f64).hypot(dky * j as f64);
                let s = s_of_k(k);
                if !(s.is_finite() && s >= 0.0) {
                    return Err(BemError::Kernel { k, s });
                }
                Ok(2.0 * s / (e_star1 * k))
            };
            let k00 = c0.unwrap_or(0.0);
            if comm.size() == 1 {
                Product::Serial(Box::new(Operator::periodic(ny, nx, k00, kernel_of)?))
            } else {
                Product::Slab(SlabOperator::periodic(comm, ny, nx, k00, kernel_of)?)
            }
        } else {
            let g = crate::influence::coefficients(
                stack,
                ny,
                nx,
                geometry.lx / nx as f64,
                geometry.ly / ny as f64,
            )?;
            if comm.size() == 1 {
                Product::Serial(Box::new(Operator::free(ny, nx, &g)?))
            } else {
                Product::Slab(SlabOperator::free(comm, ny, nx, &g)?)
            }
        };
        // As the serial solver: S(k₁) of the stack (its table-free value off a periodic cell).
        let s1 = if geometry.periodic {
            s_of_k(geometry.fundamental())
        } else {
            comp.s(geometry.fundamental())
        };
        let s1 = if s1.is_finite() && s1 > 0.0 { s1 } else { 1.0 };
        let precond = if !options.preconditioner {
            None
        } else {
            match &product {
                Product::Serial(op) => op.inverse().map(|m| Product::Serial(Box::new(m))),
                Product::Slab(op) => op.inverse().map(Product::Slab),
            }
        };
        Ok(SlabSolver {
            comm,
            precond,
            ny,
            nx,
            geometry,
            rows,
            z,
            z_max,
            z_mean,
            z_rms,
            e_star1,
            stiffness: 0.5 * e_star1 * geometry.fundamental() / s1,
            c0,
            product,
            options,
        })
    }

    /// This rank's rows of the grid.
    pub fn rows(&self) -> std::ops::Range<usize> {
        self.rows.clone()
    }

    /// z_M − z̄ (m): the separation at first touch.
    pub fn max_separation(&self) -> f64 {
        self.z_max - self.z_mean
    }

    /// Bytes of the operator's kernel and exchange buffers on this rank (0 on one rank:
    /// the serial operator).
    pub fn operator_bytes(&self) -> u64 {
        match &self.product {
            Product::Serial(_) => 0,
            Product::Slab(s) => s.bytes(),
        }
    }

    /// Solves the loads in order, each from the previous one's pressure (the first
    /// cold). Every rank calls it together; the steps are the same on every rank.
    pub fn solve_curve(&self, loads: &[BemLoad]) -> Result<Vec<SlabStep>, BemError> {
        let m = self.z.len();
        let mut p = vec![0.0; m];
        let mut out = Vec::with_capacity(loads.len());
        let mut warm = false;
        for &load in loads {
            let step = self.solve_step(load, &mut p, warm)?;
            warm = step.contact_points > 0;
            out.push(step);
        }
        Ok(out)
    }

    /// Solves one load on this rank's rows of `p` (Pa): from `p` itself when `warm`
    /// (rescaled to the mean pressure under pressure control), else from the cold guess.
    /// On return `p` holds the rank's rows of the solution. Every rank calls it together;
    /// the step is the same on every rank.
    pub fn solve_step(
        &self,
        load: BemLoad,
        p: &mut [f64],
        warm: bool,
    ) -> Result<SlabStep, BemError> {
        let control = load_control(
            load,
            self.geometry.periodic,
            self.c0,
            [self.z_max, self.z_mean],
        )?;
        let n2 = self.ny * self.nx;
        let settings = Settings {
            z_rms: self.z_rms,
            stiffness: self.stiffness,
            tolerance: self.options.tolerance,
            max_iterations: self.options.max_iterations,
            points: n2,
            warm,
            precondition: false,
        };
        let settings = Settings {
            precondition: self.precond.is_some(),
            ..settings
        };
        let out = match (&self.product, &self.precond) {
            (Product::Serial(op), minv) => {
                let minv = match minv {
                    Some(Product::Serial(m)) => Some(m),
                    _ => None,
                };
                let mut work = op.work();
                let product =
                    |which: Apply, i: &[f64], o: &mut [f64], uniform: bool| match (which, minv) {
                        (Apply::Inverse, Some(m)) => m.apply(i, o, uniform, &mut work),
                        _ => op.apply(i, o, uniform, &mut work),
                    };
                reference::run(self.comm, product, &self.z, settings, control, p)?
            }
            (Product::Slab(op), minv) => {
                let minv = match minv {
                    Some(Product::Slab(m)) => Some(m),
                    _ => None,
                };
                // One set of exchange buffers for both operators (same grid).
                let mut work = op.work();
                let product =
                    |which: Apply, i: &[f64], o: &mut [f64], uniform: bool| match (which, minv) {
                        (Apply::Inverse, Some(m)) => m.apply(i, o, uniform, &mut work),
                        _ => op.apply(i, o, uniform, &mut work),
                    };
                reference::run(self.comm, product, &self.z, settings, control, p)?
            }
        };
        let mut sums = [
            p.iter().sum::<f64>(),
            out.gap.iter().sum::<f64>(),
            p.iter().filter(|&&v| v > 0.0).count() as f64,
        ];
        decomp::sum(self.comm, &mut sums);
        let [psum, gsum, contact] = sums;
        let mean_pressure = psum / n2 as f64;
        let mean_gap = gsum / n2 as f64;
        let approach = if self.geometry.periodic {
            let w = self.c0.map_or(0.0, |c0| c0 * mean_pressure);
            self.max_separation() - mean_gap + w
        } else {
            self.z_max - out.offset
        };
        if !(mean_pressure.is_finite() && mean_gap.is_finite() && approach.is_finite()) {
            return Err(BemError::NonFinite(out.iterations));
        }
        Ok(SlabStep {
            load,
            mean_pressure,
            area_fraction: contact / n2 as f64,
            contact_points: contact as usize,
            mean_gap,
            approach,
            separation: self.max_separation() - approach,
            iterations: out.iterations,
            products: out.products,
            error: out.error,
        })
    }

    /// The tangent stiffness dP/dδ (N/m) of the solved load whose pressure on this
    /// rank's rows is `p` (Pa): K_AA Δp = 1 on the contact set A (p > 0) held fixed,
    /// dP/dδ = (Lx·Ly/(ny·nx)) Σ_A Δp, the iteration of [`crate::BemSolver::tangent`]
    /// (module [`crate::tangent`]) on the slabs: four fields of the rank's rows (Δp,
    /// returned as `pressure_rate`, and three buffers), the sums global. Every rank
    /// calls it together; the stiffness is the same on every rank.
    pub fn tangent(&self, p: &[f64]) -> Result<crate::Tangent, BemError> {
        let m = self.z.len();
        if p.len() != m {
            return Err(BemError::Initial {
                expected: m,
                got: p.len(),
            });
        }
        let set = crate::tangent::Set::of(p, None);
        let (mut dp, mut r, mut d, mut q) =
            (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let fields = crate::tangent::Fields {
            dp: &mut dp,
            r: &mut r,
            d: &mut d,
            q: &mut q,
        };
        let uniform = self.geometry.periodic && self.c0.is_some();
        let precondition = self.precond.is_some();
        let max_iterations = self.options.max_iterations;
        let none = || Ok(());
        let out = match (&self.product, &self.precond) {
            (Product::Serial(op), minv) => {
                let minv = match minv {
                    Some(Product::Serial(m)) => Some(m),
                    _ => None,
                };
                let mut work = op.work();
                let product =
                    |which: Apply, i: &[f64], o: &mut [f64], uniform: bool| match (which, minv) {
                        (Apply::Inverse, Some(m)) => m.apply(i, o, uniform, &mut work),
                        _ => op.apply(i, o, uniform, &mut work),
                    };
                crate::tangent::run(
                    self.comm,
                    product,
                    &set,
                    uniform,
                    precondition,
                    max_iterations,
                    none,
                    fields,
                )?
            }
            (Product::Slab(op), minv) => {
                let minv = match minv {
                    Some(Product::Slab(m)) => Some(m),
                    _ => None,
                };
                let mut work = op.work();
                let product =
                    |which: Apply, i: &[f64], o: &mut [f64], uniform: bool| match (which, minv) {
                        (Apply::Inverse, Some(m)) => m.apply(i, o, uniform, &mut work),
                        _ => op.apply(i, o, uniform, &mut work),
                    };
                crate::tangent::run(
                    self.comm,
                    product,
                    &set,
                    uniform,
                    precondition,
                    max_iterations,
                    none,
                    fields,
                )?
            }
        };
        drop((r, d, q));
        Ok(crate::Tangent {
            stiffness: self.area() / (self.ny * self.nx) as f64 * out.sum,
            pressure_rate: dp,
            points: out.points,
            iterations: out.iterations,
            products: out.products,
            residual: out.residual,
        })
    }

    /// E*₁ of the top material (Pa).
    pub fn e_star1(&self) -> f64 {
        self.e_star1
    }

    /// Nominal area Lx·Ly (m²).
    pub fn area(&self) -> f64 {
        self.geometry.lx * self.geometry.ly
    }

    /// The grid (rows ny, columns nx).
    pub fn shape(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    /// The sizes (points) of the contact patches (p > 0, 4-connected, across the cell's
    /// edges when periodic) of the pressure whose rows on this rank are `p`, the same on
    /// every rank ([`patch_sizes`]).
    pub fn patch_sizes(&self, p: &[f64]) -> Vec<usize> {
        let mask: Vec<bool> = p.iter().map(|&v| v > 0.0).collect();
        patch_sizes(self.comm, &mask, (self.ny, self.nx), self.geometry.periodic)
    }
}

/// The contact patches of a mask held by rows (`mask` this rank's rows of the ny × nx
/// grid, [`decomp::slab`]'s cut): their sizes (points, in no particular order), the same
/// on every rank and the same multiset as [`crate::patch_sizes`] of the whole mask.
/// 4-connected, across the cell's edges when `periodic`.
///
/// Each rank labels the patches of its own rows (union-find within its slab); the ranks
/// then exchange their patch sizes and the labels of their first and last rows, and
/// every rank joins the labels that meet across the slab borders (the last row of rank q
/// against the first of rank q + 1, and of the last rank against rank 0 when periodic).
/// Communication: the ranks' patch counts, 2·nx labels and the patch sizes per rank; no
/// rank holds the mask of another.
pub fn patch_sizes(
    comm: &dyn Decomposition,
    mask: &[bool],
    (ny, nx): (usize, usize),
    periodic: bool,
) -> Vec<usize> {
    let (np, q) = (comm.size(), comm.rank());
    let m = decomp::slab(ny, np, q).len();
    debug_assert_eq!(mask.len(), m * nx);
    // Union-find within the slab: right neighbours (across the x edge when periodic)
    // and down neighbours inside the slab.
    let mut parent: Vec<usize> = (0..mask.len()).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for i in 0..m {
        for j in 0..nx {
            let a = i * nx + j;
            if !mask[a] {
                continue;
            }
            let right = (j + 1 < nx || periodic).then(|| i * nx + (j + 1) % nx);
            let down = (i + 1 < m).then(|| (i + 1) * nx + j);
            for b in [right, down].into_iter().flatten() {
                if mask[b] {
                    let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                    if ra != rb {
                        parent[ra] = rb;
                    }
                }
            }
        }
    }
    // Local labels 0..count in order of their roots (`root_label`), and their sizes;
    // then each point's label in `parent` (usize::MAX outside the mask).
    let mut root_label = vec![usize::MAX; mask.len()];
    let mut sizes: Vec<f64> = Vec::new();
    for a in 0..mask.len() {
        if mask[a] {
            let r = find(&mut parent, a);
            if root_label[r] == usize::MAX {
                root_label[r] = sizes.len();
                sizes.push(0.0);
            }
            sizes[root_label[r]] += 1.0;
        }
    }
    let edge_labels = |i: usize, parent: &mut [usize]| -> Vec<f64> {
        (0..nx)
            .map(|j| {
                let a = i * nx + j;
                if mask[a] {
                    root_label[find(parent, a)] as f64
                } else {
                    -1.0
                }
            })
            .collect()
    };
    let mut first_last = edge_labels(0, &mut parent);
    first_last.extend(edge_labels(m - 1, &mut parent));
    drop(parent);
    drop(root_label);
    // Counts, then the sizes padded to the largest count, then the edge rows.
    let mut counts = vec![0.0; np];
    comm.all_gather(&[sizes.len() as f64], &mut counts);
    let counts: Vec<usize> = counts.iter().map(|&c| c as usize).collect();
    let most = counts.iter().copied().max().unwrap_or(0);
    let mut padded = sizes;
    padded.resize(most, 0.0);
    let mut all_sizes = vec![0.0; most * np];
    comm.all_gather(&padded, &mut all_sizes);
    drop(padded);
    let mut edges = vec![0.0; 2 * nx * np];
    comm.all_gather(&first_last, &mut edges);
    // Global labels: rank r's label k is offset[r] + k.
    let mut offset = vec![0usize; np + 1];
    for r in 0..np {
        offset[r + 1] = offset[r] + counts[r];
    }
    let mut size = vec![0usize; offset[np]];
    let mut up: Vec<usize> = (0..offset[np]).collect();
    for r in 0..np {
        for k in 0..counts[r] {
            size[offset[r] + k] = all_sizes[r * most + k] as usize;
        }
    }
    drop(all_sizes);
    for r in 0..np {
        if r + 1 == np && !periodic {
            break;
        }
        let s = (r + 1) % np;
        let last = &edges[r * 2 * nx + nx..(r + 1) * 2 * nx];
        let first = &edges[s * 2 * nx..s * 2 * nx + nx];
        for (&a, &b) in last.iter().zip(first) {
            if a >= 0.0 && b >= 0.0 {
                let (ga, gb) = (offset[r] + a as usize, offset[s] + b as usize);
                let (ra, rb) = (find(&mut up, ga), find(&mut up, gb));
                if ra != rb {
                    up[ra] = rb;
                    size[rb] += size[ra];
                }
            }
        }
    }
    (0..up.len())
        .filter(|&k| find(&mut up, k) == k)
        .map(|k| size[k])
        .collect()
}

/// The maximum, mean and RMS of the heights over all ranks (`z` this rank's rows, the
/// first `row0`), checked finite and not flat as the serial solver checks them.
fn heights_stats(
    comm: &dyn Decomposition,
    z: &[f64],
    row0: usize,
    (ny, nx): (usize, usize),
) -> Result<[f64; 3], BemError> {
    // The first non-finite height, on the lowest rank that has one: its (row, column,
    // value) handed to every rank (the others add zeros).
    let bad = z.iter().position(|v| !v.is_finite());
    let mut lowest = [bad.map_or(f64::NEG_INFINITY, |_| -(comm.rank() as f64))];
    decomp::max(comm, &mut lowest);
    if lowest[0] > f64::NEG_INFINITY {
        let mine = -lowest[0] == comm.rank() as f64;
        let mut at = match bad {
            Some(k) if mine => [(row0 + k / nx) as f64, (k % nx) as f64, z[k]],
            _ => [0.0; 3],
        };
        decomp::sum(comm, &mut at);
        return Err(BemError::NonFiniteHeight {
            row: at[0] as usize,
            col: at[1] as usize,
            value: at[2],
        });
    }
    let n = (ny * nx) as f64;
    let mut s = [z.iter().sum::<f64>()];
    decomp::sum(comm, &mut s);
    let mean = s[0] / n;
    let mut v = [z.iter().map(|v| (v - mean).powi(2)).sum::<f64>()];
    decomp::sum(comm, &mut v);
    let rms = (v[0] / n).sqrt();
    let mut mx = [z.iter().cloned().fold(f64::NEG_INFINITY, f64::max)];
    decomp::max(comm, &mut mx);
    if !rms.is_finite() {
        let mut big = [z.iter().fold(0.0f64, |m, v| m.max(v.abs()))];
        decomp::max(comm, &mut big);
        return Err(BemError::HeightRange(big[0]));
    }
    if rms <= 0.0 || rms <= 1e-14 * mean.abs() {
        return Err(BemError::FlatSurface);
    }
    Ok([mx[0], mean, rms])
}

#[cfg(test)]
mod tests {
    use std::sync::{Arc, Barrier, Mutex};

    use super::*;
    use crate::decomp::Serial;
    use crate::slab::SlabOperator;
    use strata_runtime::stack::{Base, Layer, Stack};

    /// P ranks as P threads of one process: the collectives through shared slots.
    struct Threads {
        rank: usize,
        size: usize,
        slots: Arc<Mutex<Vec<Vec<f64>>>>,
        barrier: Arc<Barrier>,
    }

    impl Threads {
        fn exchange(&self, send: &[f64]) -> Vec<Vec<f64>> {
            self.slots.lock().unwrap()[self.rank] = send.to_vec();
            self.barrier.wait();
            let all = self.slots.lock().unwrap().clone();
            self.barrier.wait();
            all
        }
    }

    impl Decomposition for Threads {
        fn rank(&self) -> usize {
            self.rank
        }
        fn size(&self) -> usize {
            self.size
        }
        fn all_to_all(&self, send: &[f64], recv: &mut [f64]) {
            let all = self.exchange(send);
            let b = send.len() / self.size;
            for (q, from) in all.iter().enumerate() {
                recv[q * b..(q + 1) * b].copy_from_slice(&from[self.rank * b..(self.rank + 1) * b]);
            }
        }
        fn all_gather(&self, send: &[f64], recv: &mut [f64]) {
            let all = self.exchange(send);
            for (q, from) in all.iter().enumerate() {
                recv[q * send.len()..(q + 1) * send.len()].copy_from_slice(from);
            }
        }
        fn bytes_sent(&self) -> u64 {
            0
        }
    }

    /// Runs `f(comm)` on P thread-ranks; the results in rank order.
    fn on_ranks<T: Send>(p: usize, f: impl Fn(&dyn Decomposition) -> T + Sync) -> Vec<T> {
        let slots = Arc::new(Mutex::new(vec![Vec::new(); p]));
        let barrier = Arc::new(Barrier::new(p));
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..p)
                .map(|rank| {
                    let comm = Threads {
                        rank,
                        size: p,
                        slots: Arc::clone(&slots),
                        barrier: Arc::clone(&barrier),
                    };
                    let f = &f;
                    s.spawn(move || f(&comm))
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        })
    }

    fn field(ny: usize, nx: usize) -> Vec<f64> {
        (0..ny * nx)
            .map(|k| ((k * 7919) % 613) as f64 / 613.0 - 0.3 + (k as f64 * 0.37).sin())
            .collect()
    }

    /// The slab product is the serial product bit for bit, on even and odd grids, with
    /// and without the uniform mode, periodic and free, the operator and its inverse, on
    /// 1 to 4 ranks.
    #[test]
    fn slab_product_is_the_serial_product_bit_for_bit() {
        for (ny, nx) in [(12, 10), (9, 7), (16, 5)] {
            let input = field(ny, nx);
            let kernel = |i: usize, j: usize| Ok(1.0 / (1.0 + (i * i + 3 * j * j) as f64));
            // A Gaussian (positive spectrum: the inverse exists) on the first grid.
            let g: Vec<f64> = (0..ny * nx)
                .map(|k| {
                    let (dy, dx) = ((k / nx) as f64, (k % nx) as f64);
                    if ny == 12 {
                        (-(dy * dy + dx * dx) / 2.0).exp()
                    } else {
                        1.0 / (1.0 + dy + dx)
                    }
                })
                .collect();
            for (periodic, inverse) in [(true, false), (false, false), (true, true), (false, true)]
            {
                let op = if periodic {
                    Operator::periodic(ny, nx, 0.25, kernel).unwrap()
                } else {
                    Operator::free(ny, nx, &g).unwrap()
                };
                let op = match (inverse, op.inverse()) {
                    (false, _) => op,
                    (true, Some(m)) => m,
                    (true, None) => {
                        // No inverse (K̂ not positive): none on any rank either. (The
                        // Gaussian's and the periodic kernel's exist.)
                        assert!(ny != 12 && !periodic, "{ny}×{nx}: no inverse");
                        let none = on_ranks(3, |comm| {
                            let s = if periodic {
                                SlabOperator::periodic(comm, ny, nx, 0.25, kernel).unwrap()
                            } else {
                                SlabOperator::free(comm, ny, nx, &g).unwrap()
                            };
                            s.inverse().is_none()
                        });
                        assert!(none.iter().all(|&n| n), "{ny}×{nx} periodic {periodic}");
                        continue;
                    }
                };
                for uniform in [false, true] {
                    let mut want = vec![0.0; ny * nx];
                    op.apply(&input, &mut want, uniform, &mut op.work())
                        .unwrap();
                    for p in 1..=4 {
                        let parts = on_ranks(p, |comm| {
                            let s = if periodic {
                                SlabOperator::periodic(comm, ny, nx, 0.25, kernel).unwrap()
                            } else {
                                SlabOperator::free(comm, ny, nx, &g).unwrap()
                            };
                            let s = if inverse { s.inverse().unwrap() } else { s };
                            let rows = s.rows();
                            let mut out = vec![0.0; rows.len() * nx];
                            s.apply(
                                &input[rows.start * nx..rows.end * nx],
                                &mut out,
                                uniform,
                                &mut s.work(),
                            )
                            .unwrap();
                            out
                        });
                        let got: Vec<f64> = parts.concat();
                        let same = got
                            .iter()
                            .zip(&want)
                            .all(|(a, b)| a.to_bits() == b.to_bits());
                        assert!(
                            same,
                            "{ny}×{nx} periodic {periodic} inverse {inverse} uniform {uniform} P {p}"
                        );
                    }
                }
            }
        }
    }

    fn surface(i: usize, j: usize, (ny, nx): (usize, usize)) -> f64 {
        let (y, x) = (i as f64 / ny as f64, j as f64 / nx as f64);
        1e-6 * ((std::f64::consts::TAU * x).cos()
            + 0.5 * (std::f64::consts::TAU * (2.0 * x + y) + 0.3).cos()
            + 0.3 * (std::f64::consts::TAU * 3.0 * y + 1.0).sin()
            + 0.05 * (((i * nx + j) * 2_654_435_761) % 1000) as f64 / 1000.0)
    }

    fn layered() -> Stack {
        Stack::new(
            vec![
                Layer {
                    thickness: 5e-5,
                    young: 1e10,
                    poisson: 0.3,
                },
                Layer {
                    thickness: 2e-4,
                    young: 2e11,
                    poisson: 0.3,
                },
            ],
            Base::Rigid,
        )
        .unwrap()
    }

    /// One rank without the preconditioner is the serial reference path: the first
    /// (cold) load of a curve is `BemSolver::solve_reference` bit for bit.
    #[test]
    fn one_rank_is_the_serial_reference_solve() {
        let (ny, nx) = (32, 24);
        let g = Geometry {
            lx: 1e-3,
            ly: 1e-3 * 32.0 / 24.0,
            periodic: true,
        };
        let stack = layered();
        // The reference path is the plain iteration.
        let options = BemOptions {
            preconditioner: false,
            ..BemOptions::default()
        };
        let z = ndarray::Array2::from_shape_fn((ny, nx), |(i, j)| surface(i, j, (ny, nx)));
        let serial = crate::BemSolver::with_geometry(&z, g, &stack, options).unwrap();
        let load = BemLoad::Approach(0.4 * serial.max_separation());
        let want = serial.solve_reference(load).unwrap();
        let slab = SlabSolver::new(&Serial, (ny, nx), g, &stack, options, |i, row| {
            for (j, v) in row.iter_mut().enumerate() {
                *v = surface(i, j, (ny, nx));
            }
        })
        .unwrap();
        let got = slab.solve_curve(&[load]).unwrap()[0];
        assert_eq!(got.mean_pressure.to_bits(), want.mean_pressure.to_bits());
        assert_eq!(got.mean_gap.to_bits(), want.mean_gap.to_bits());
        assert_eq!(got.contact_points, want.contact_points);
        assert_eq!(got.iterations, want.iterations);
    }

    /// Bad input on a slab: a non-finite height on one rank is reported by every rank
    /// with its global place; more ranks than rows are refused.
    #[test]
    fn bad_heights_are_named_on_every_rank() {
        let g = Geometry::square(1e-3);
        let stack = layered();
        let errs = on_ranks(3, |comm| {
            SlabSolver::new(comm, (8, 8), g, &stack, BemOptions::default(), |i, row| {
                for (j, v) in row.iter_mut().enumerate() {
                    *v = if (i, j) == (6, 5) {
                        f64::NAN
                    } else {
                        surface(i, j, (8, 8))
                    };
                }
            })
            .err()
        });
        for e in errs {
            match e {
                Some(BemError::NonFiniteHeight {
                    row: 6,
                    col: 5,
                    value,
                }) => assert!(value.is_nan()),
                other => panic!("{other:?}"),
            }
        }
        let errs = on_ranks(5, |comm| {
            SlabSolver::new(comm, (4, 8), g, &stack, BemOptions::default(), |i, row| {
                for (j, v) in row.iter_mut().enumerate() {
                    *v = surface(i, j, (4, 8));
                }
            })
            .err()
        });
        assert!(
            errs.iter()
                .all(|e| matches!(e, Some(BemError::Ranks { rows: 4, ranks: 5 })))
        );
    }

    /// The patches of a mask held by slabs are those of the whole mask (as a multiset of
    /// sizes), periodic or not, on 1 to 4 ranks: patches that cross slab borders, the
    /// periodic edges, one-row slabs and an empty mask.
    #[test]
    fn slab_patches_are_the_whole_mask_patches() {
        for (ny, nx) in [(9, 7), (16, 12), (4, 5)] {
            for density in [0.0, 0.3, 0.55, 0.8] {
                let mask: Vec<bool> = (0..ny * nx)
                    .map(|k| {
                        let h = (k as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 40;
                        (h as f64 / (1u64 << 24) as f64) < density
                    })
                    .collect();
                for periodic in [false, true] {
                    let mut want = crate::patch_sizes(&mask, ny, nx, periodic);
                    want.sort_unstable();
                    for p in 1..=4 {
                        let got = on_ranks(p, |comm| {
                            let rows = decomp::slab(ny, p, comm.rank());
                            let mut s = patch_sizes(
                                comm,
                                &mask[rows.start * nx..rows.end * nx],
                                (ny, nx),
                                periodic,
                            );
                            s.sort_unstable();
                            s
                        });
                        for (rank, s) in got.iter().enumerate() {
                            assert_eq!(
                                s, &want,
                                "{ny}×{nx} density {density} periodic {periodic} P {p} rank {rank}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// Each rank checks its own share against the memory limit before allocating; a
    /// limit between rank 1's share and rank 0's (rank 0 has the extra rows) stops every
    /// rank: rank 0 with the error naming the grid and itself, the others saying another
    /// rank failed.
    #[test]
    fn each_rank_checks_its_share_of_memory() {
        let (ny, nx) = (9, 8);
        let need = |q| SlabSolver::memory_needed((ny, nx), true, 2, q);
        assert!(need(0) > need(1));
        // About half the one-rank figure each.
        let one = SlabSolver::memory_needed((ny, nx), true, 1, 0);
        assert!(
            need(0) < one && need(1) < one,
            "{one} {} {}",
            need(0),
            need(1)
        );
        let options = BemOptions {
            memory: strata_runtime::resources::MemoryLimit::new(need(1), "test"),
            ..BemOptions::default()
        };
        let stack = layered();
        let errs = on_ranks(2, |comm| {
            SlabSolver::new(
                comm,
                (ny, nx),
                Geometry::square(1e-3),
                &stack,
                options,
                |i, row| {
                    for (j, v) in row.iter_mut().enumerate() {
                        *v = surface(i, j, (ny, nx));
                    }
                },
            )
            .err()
            .map(|e| e.to_string())
        });
        let e0 = errs[0].as_deref().expect("rank 0 over its limit");
        assert!(e0.contains("9×8") && e0.contains("rank 0 of 2"), "{e0}");
        let e1 = errs[1].as_deref().expect("rank 1 stops too");
        assert!(e1.contains("another rank"), "{e1}");
    }

    /// The tangent stiffness of one pressure field (a serial solve's) on the slabs of 1
    /// to 4 ranks against the serial solver's: the same iteration, the sums in another
    /// order; the stiffness to round-off and Δp row by row (periodic layered with the
    /// uniform mode, and an isolated sample).
    #[test]
    fn slab_tangent_is_the_serial_tangent() {
        for periodic in [true, false] {
            let (ny, nx) = (24, 20);
            let g = Geometry {
                lx: 1e-3,
                ly: 1.2e-3,
                periodic,
            };
            let stack = layered();
            let heights =
                ndarray::Array2::from_shape_fn((ny, nx), |(i, j)| surface(i, j, (ny, nx)));
            let serial =
                crate::BemSolver::with_geometry(&heights, g, &stack, BemOptions::default())
                    .unwrap();
            let mut sol = serial
                .solve(BemLoad::Approach(0.4 * serial.max_separation()))
                .unwrap();
            let want = serial.tangent(&mut sol, None).unwrap();
            assert!(want.stiffness > 0.0 && want.residual <= crate::tangent::TOLERANCE);
            let p: Vec<f64> = sol.pressure.iter().copied().collect();
            for ranks in 1..=4 {
                let got = on_ranks(ranks, |comm| {
                    let s = SlabSolver::new(
                        comm,
                        (ny, nx),
                        g,
                        &stack,
                        BemOptions::default(),
                        |i, row| {
                            for (j, v) in row.iter_mut().enumerate() {
                                *v = surface(i, j, (ny, nx));
                            }
                        },
                    )
                    .unwrap();
                    let rows = s.rows();
                    s.tangent(&p[rows.start * nx..rows.end * nx]).unwrap()
                });
                let rate: Vec<f64> = got.iter().flat_map(|t| t.pressure_rate.clone()).collect();
                let worst = rate
                    .iter()
                    .zip(&want.pressure_rate)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
                    / want
                        .pressure_rate
                        .iter()
                        .fold(0.0f64, |m, v| m.max(v.abs()));
                for (rank, t) in got.iter().enumerate() {
                    let d = (t.stiffness / want.stiffness - 1.0).abs();
                    if rank > 0 {
                        assert!(d <= 2e-15, "periodic {periodic} P {ranks}: {d:e}");
                        continue;
                    }
                    println!(
                        "periodic {periodic}, {ranks} ranks: dP/dδ {:e} vs serial {d:.1e}, Δp {worst:.1e}; {} iterations (serial {})",
                        t.stiffness, t.iterations, want.iterations
                    );
                    // measured ≤ 2.2e-16 (Δp 2.3e-16 of its largest value)
                    assert!(d <= 2e-15, "periodic {periodic} P {ranks}: {d:e}");
                    assert_eq!(t.points, want.points);
                }
                assert!(
                    worst <= 3e-15,
                    "periodic {periodic} P {ranks}: Δp {worst:e}"
                );
            }
        }
    }

    /// 2 and 3 ranks give the one-rank curve to round-off (periodic layered, and an
    /// isolated sample under pressure control).
    #[test]
    fn ranks_give_the_one_rank_curve() {
        for periodic in [true, false] {
            let (ny, nx) = (24, 20);
            let g = Geometry {
                lx: 1e-3,
                ly: 1.2e-3,
                periodic,
            };
            let stack = layered();
            let curve = |comm: &dyn Decomposition| {
                let s = SlabSolver::new(
                    comm,
                    (ny, nx),
                    g,
                    &stack,
                    BemOptions::default(),
                    |i, row| {
                        for (j, v) in row.iter_mut().enumerate() {
                            *v = surface(i, j, (ny, nx));
                        }
                    },
                )
                .unwrap();
                let loads: Vec<BemLoad> = if periodic {
                    [0.3, 0.4, 0.5]
                        .iter()
                        .map(|f| BemLoad::Approach(f * s.max_separation()))
                        .collect()
                } else {
                    [1e-3, 2e-3, 4e-3]
                        .iter()
                        .map(|f| BemLoad::MeanPressure(f * s.e_star1()))
                        .collect()
                };
                s.solve_curve(&loads).unwrap()
            };
            let one = curve(&Serial);
            for p in [2, 3] {
                let many = on_ranks(p, curve);
                for rank in &many {
                    for (a, b) in one.iter().zip(rank) {
                        for (x, y) in [
                            (a.mean_pressure, b.mean_pressure),
                            (a.mean_gap, b.mean_gap),
                            (a.approach, b.approach),
                            (a.area_fraction, b.area_fraction),
                        ] {
                            assert!(
                                (x - y).abs() <= 1e-12 * x.abs(),
                                "periodic {periodic} P {p}: {x} vs {y}"
                            );
                        }
                    }
                }
            }
        }
    }
}
