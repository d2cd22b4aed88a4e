//! # strata-runtime
//!
//! The light, embeddable half of strata: material stacks, the layered surface
//! compliance S(ρ), surrogate tables of the asperity law (χ, ζ, g), summits of a rough
//! surface, the rough-contact models (N: independent asperities, I: interacting
//! asperities) and the sampled contact law p(g) of an interface for structural codes.
//! No dense linear algebra, no FFT-BEM, no scene files, no plotting: those live in
//! `strata-tablegen`, `strata-bem` and the `strata` command.
//!
//! ## Features
//! `default = ["toml", "npy", "spectral"]`: stack files (TOML), `.npy` surfaces and
//! table export, generated surfaces and the 2-D FFT helper. An embedding that loads a
//! table and evaluates the law needs none of them (`default-features = false`: 14
//! crates in all).
//!
//! ## Conventions
//! The equations are stated in `docs/physics.md` of the repository, which every
//! `physics.md §n` in these docs refers to; "(P22)" is the paper's equation number.
//! - **Units**: SI throughout — m, Pa, N, N/m; wavenumbers ρ in rad/m.
//! - **Signs**: z points into the solid; contact pressure p ≥ 0 is compressive;
//!   deflections w ≥ 0 point into the solid; loads are positive in compression.
//!   Surface heights z(x) are positive towards the rigid flat.
//! - **Approach and separation**: the flat's approach δ ≥ 0 is measured from first
//!   touch of the highest summit z_M; asperity k interferes by δ_k = ⟨δ − (z_M − z_k)⟩
//!   (P20); the nominal separation is g_n = (z_M − z̄) − δ (P26), z̄ the mean height.
//!   The contact law p(g) of [`interface`] uses that g.
//! - **Compliance**: S(ρ) = 1 + k_z(ρ) is the layered deflection relative to a
//!   half-space of layer-1 material, ŵ = 2S p̂/(E*₁ρ) (physics.md §2).
//! - **Images**: an isolated sample's asperities interact with plain distances inside
//!   the sample; a periodic sample is one cell of an infinite pattern and its
//!   asperities also feel the periodic images of every asperity ([`rough::Images`]).
//!
//! ## Embedding the contact law
//! Load a table, check that it serves the stack, reduce a surface to its summits, solve
//! the load curve once and query the law at any separation:
//!
//! ```
//! use strata_runtime::interface::{InterfaceLaw, SampleOptions};
//! use strata_runtime::rough::{Images, Model, RoughContact};
//! use strata_runtime::surface::{GenerateParams, Surface};
//! use strata_runtime::{Stack, table::Table};
//!
//! let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
//! let stack = Stack::from_toml_file(format!("{root}/tables/stacks/paper-two-layer.toml").as_ref())?;
//! let table = Table::load(format!("{root}/tables/paper-two-layer.strata").as_ref())?;
//! let law = table.law_for(&stack)?; // refuses a table built for another stack
//! let surface = Surface::generate(&GenerateParams {
//!     size: 1e-3, grid: 128, fractal_dimension: 2.4, k_min: 2.0, k_max: 10.0,
//!     rms: 3.4e-6, seed: 1,
//! })?;
//! let contact = RoughContact::from_surface(&law, &surface)?;
//! let g0 = contact.top_to_mean(); // first-contact separation (m)
//! let opts = SampleOptions { samples: 20, min_gap: g0 - 5e-6 };
//! let interface = InterfaceLaw::sample(&contact, Model::Interacting(Images::Periodic(2)), &opts)?;
//! let point = interface.eval(g0 - 3e-6)?;
//! assert!(point.pressure > 0.0 && point.dp_dg < 0.0);
//! assert!(point.area_fraction > 0.0 && point.area_fraction < 1.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Library code never calls `unwrap`/`expect` (user-controlled data must come back as
//! typed errors); the lint below enforces it outside tests.

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod bounded;
pub mod cancel;
pub mod compliance;
pub mod conduction;
pub mod constriction;
pub mod disc_stiffness;
/// The one 2-D FFT helper of the workspace (crate `strata-fft`, re-exported).
#[cfg(feature = "spectral")]
pub use strata_fft as fft;
#[cfg(feature = "spectral")]
pub mod hankel;
pub mod hash;
pub mod interface;
pub mod law;
pub mod numerics;
pub mod output;
pub mod resources;
#[cfg(feature = "capped")]
pub mod rings;
pub mod rough;
pub mod stack;
pub mod summits;
pub mod surface;
pub mod table;

pub use compliance::Compliance;
pub use conduction::{ConductionCompliance, ConductionKind};
pub use stack::{Base, Bodies, Counterface, Layer, Solid, Stack, StackError};
