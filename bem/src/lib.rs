//! Full-field reference: an FFT boundary-element solver for the frictionless normal
//! contact of a rigid flat and a rough surface on a layered elastic solid, on periodic
//! cells and on isolated (non-periodic) samples, square or rectangular.
//!
//! # Equations (physics.md §1, §2, §5)
//! The rough surface z(x) (m, ny×nx samples of a sample of sides Lx × Ly; row index = y,
//! column index = x) lies on the layered solid of [`Stack`]. A rigid flat at height c
//! presses on it; the surface deflects by w(x) ≥ 0 into the solid under the contact
//! pressure p(x) ≥ 0 (Pa). The gap is
//!
//! ```text
//!   g(x) = c − (z(x) − w(x)) = w(x) − z(x) + c,
//! ```
//!
//! and contact obeys the complementarity conditions g ≥ 0, p ≥ 0, p·g = 0.
//!
//! * **Periodic cell** ([`Geometry::periodic`]): the deflection follows from the layered
//!   kernel in Fourier space (the plane-wave form of ŵ = 2S/(E*₁ρ) p̂),
//!
//!   ```text
//!     w̃(k) = 2 S(|k|) / (E*₁ |k|) · p̃(k),   k = (2π i/Lx, 2π j/Ly)  (rad/m),
//!   ```
//!
//!   with S from [`Compliance::s`](strata_runtime::compliance::Compliance::s), evaluated
//!   once per distinct |k| (S ≡ 1 on a homogeneous stack), sampled on the (kx, ky) grid
//!   (the spectral, "Westergaard" discretisation of Tamaas and ContactMechanics).
//! * **Non-periodic sample**: zero pressure outside the sample, the solid unbounded;
//!   w = Σ G p by linear (zero-padded) convolution with the real-space coefficients G of
//!   a uniformly loaded pixel, Love's closed form plus the Hankel transform of k_z = S − 1
//!   ([`influence`]).
//!
//! ## The uniform (k = 0) mode of a periodic cell
//! * **Rigid base**: a uniform pressure p̄ compresses every layer in uniaxial strain, so
//!   the k = 0 compliance is finite, w̄ = C₀ p̄ with C₀ = Σᵢ hᵢ/Mᵢ = lim_{k→0} 2S(k)/(E*₁k),
//!   Mᵢ = Eᵢ(1−νᵢ)/((1+νᵢ)(1−2νᵢ)) (the P-wave modulus). The rigid flat's approach δ is
//!   then physical: c = z_M − δ (z_M the highest point of the undeformed surface), for
//!   any δ ≥ 0 — beyond the peak-to-valley height too, where the layers compress as a
//!   whole while the contact is still partial.
//! * **Elastic base** (and the homogeneous half-space): the k = 0 compliance is infinite
//!   and the mean deflection is undefined. As Polonsky & Keer (and Tamaas) do, the
//!   deflection is taken with zero mean; the flat's position follows from the load
//!   condition, and the approach is measured from the mean plane of the deformed
//!   surface: δ = z_M − z̄ − ḡ, ḡ the mean gap (so δ < z_M − z̄).
//!
//! In both cases the reported mean gap is ḡ = mean of g, and δ = z_M − z̄ − ḡ + w̄ with
//! w̄ = C₀p̄ on a rigid base and w̄ = 0 on an elastic base ([`BemSolution::mean_deflection`]).
//! On a non-periodic sample δ = z_M − c exactly (the free solid's deflection is absolute).
//!
//! # Loads ([`BemLoad`])
//! * `MeanGap(ḡ)`: displacement control through the mean gap (periodic cells);
//! * `Approach(δ)`: the flat at c = z_M − δ (rigid base, non-periodic) or
//!   ḡ = z_M − z̄ − δ (periodic, elastic base);
//! * `MeanPressure(p̄)`: force control, p̄ = P/(Lx Ly) (Pa);
//! * `Separation(g_n)`: the asperity models' nominal separation g_n = z_M − z̄ − δ (P26),
//!   i.e. an approach (the scene `load` separations map here).
//!
//! The shared reference (`rough_h100um_E2E1_1.csv`, two layers on a rigid base) uses
//! the rigid-base convention above: its `gap` column is g_n, not the mean gap.
//!
//! # Method
//! Polonsky & Keer's constrained conjugate gradient (module `cg`), preconditioned by
//! default with the inverse influence operator on the whole cell (Vollebregt, J. Comput.
//! Phys. 257, 2014; module `pcg`: y = P_C M⁻¹ P_C g, M⁻¹ = 1/K̂ in Fourier space), which
//! makes the iteration count nearly independent of the grid (19–28 per cold load step
//! from 512² to 2048², against 181–808 plain); convolutions by real-to-complex FFTs with
//! the kernel applied in place ([`strata_runtime::fft`]), the vector operations fused
//! into the FFT's row passes, 4 points per instruction where the CPU has AVX2 (module
//! `kernels`: the form is chosen once per solver, the scalar rules otherwise), and run on all cores; the correction of the
//! displacement where only a few points changed the contact set summed in real space
//! (module `update`); warm starts along a load path
//! ([`BemSolver::solve_curve`]: the field extrapolated from the last two steps) and a
//! coarse-to-fine start on large grids. The error
//!
//! ```text
//!   ε = max( max_{p>0} |g|,  max_{p=0} max(−g, 0) ) / σ_z
//! ```
//!
//! (the largest gap on the contact set and the largest interpenetration outside it;
//! σ_z the RMS height) must fall below the tolerance. The default ε ≤ 1e-10 reproduces the shared reference BEM,
//! Tamaas and ContactMechanics to ~1e-10 in mean pressure (tests/it/bem_reference.rs).
//!
//! # Outputs ([`BemSolution`])
//! Mean pressure p̄ (Pa), p̄/E*₁, real contact area fraction A/A₀ (the fraction of grid
//! points with p > 0), the number of contact patches (connected components of the
//! contact set, 4-connected, wrapped on a periodic cell), the mean gap, the approach,
//! the pressure, gap and deflection maps (writable as .npy with
//! [`BemSolution::write_maps`], and as contact.engineering's NetCDF `results.nc` with
//! [`BemSolution::write_netcdf`]).
//!
//! # Conduction ([`conduction`])
//! The interface conductance of a solved contact set (physics.md §6.2): with a unit
//! temperature (potential) jump on the set, (C_A + C_B) q = 1 there, q = 0 elsewhere,
//! C_X = S_th,X/(k₁,X|k|), the k = 0 mode excluded; h_c = mean(q)
//! ([`ConductanceSolver`], periodic cells).
//!
//! Memory is estimated before the grids are allocated and checked against
//! the limit of the solve's options ([`BemOptions::memory`], [`BemSolver::memory_needed`]).

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]
// Index loops run over several parallel arrays (p, u, z, t); indices are clearer.
#![allow(clippy::needless_range_loop)]

mod capped;
mod cg;
pub mod conduction;
pub mod decomp;
pub mod distributed;
mod error;
pub mod influence;
mod iteration;
mod kernels;
mod maps;
#[cfg(feature = "mpi")]
pub mod mpi;
pub mod netcdf;
mod operator;
mod pcg;
pub mod plastic;
mod reference;
pub mod slab;
mod solver;
mod state;
pub mod tangent;
pub mod tangential;
#[cfg(test)]
mod tests;
mod update;

pub use conduction::{Conductance, ConductanceOptions, ConductanceSolver, Conductor};
pub use decomp::{Decomposition, Serial};
pub use distributed::{SlabSolver, SlabStep};
pub use error::BemError;
pub use maps::{
    BemSolution, count_patches, median_patch_size, patch_sizes, read_heights_npy, resample_rect,
    resample_spectral,
};
pub use ndarray::Array2;
pub use netcdf::NETCDF_MAP_VARIABLES;
pub use plastic::{PlasticInfo, PlasticPath};
pub use solver::{BemSolver, Geometry, uniform_compliance};
pub use strata_runtime::stack::Stack;
pub use tangent::Tangent;

/// Solver settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BemOptions {
    /// Convergence tolerance on the error ε (see the crate docs), in (0, 1).
    pub tolerance: f64,
    /// Iteration cap per load; exceeding it is an error ([`BemError::NotConverged`]).
    pub max_iterations: usize,
    /// Precondition the iteration with the inverse influence operator (module `pcg`:
    /// ~4–30× fewer iterations at two convolutions each); `false` runs the plain
    /// Polonsky–Keer iteration (one convolution per iteration while the contact set
    /// stays put). Both stop on the same error ε.
    pub preconditioner: bool,
    /// The memory limit the grid ([`BemSolver::memory_needed`]) is checked against
    /// before anything is allocated. Default: 75 % of the machine's memory.
    pub memory: strata_runtime::resources::MemoryLimit,
}

impl Default for BemOptions {
    fn default() -> Self {
        BemOptions {
            tolerance: 1e-10,
            max_iterations: 20_000,
            preconditioner: true,
            memory: Default::default(),
        }
    }
}

/// The load condition of one solve (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BemLoad {
    /// Mean gap ḡ (m) between the flat and the deformed surface, > 0 (periodic cells).
    MeanGap(f64),
    /// Approach δ (m) of the flat measured from first touch of the undeformed surface
    /// (the flat at z_M − δ; see the crate docs for the elastic-base convention).
    Approach(f64),
    /// Mean (nominal) pressure p̄ = P/A₀ (Pa), > 0.
    MeanPressure(f64),
    /// Nominal separation g_n = (z_M − z̄) − δ (m) of the asperity models (physics.md
    /// §5, P26): the same as `Approach(z_M − z̄ − g_n)`. Scenes' separations map here.
    Separation(f64),
}
