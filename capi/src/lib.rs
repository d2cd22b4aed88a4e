//! # strata-capi: the C ABI of the strata runtime
//!
//! Builds the contact law of a rough layered interface (module
//! `strata_runtime::interface`) from C: load a surrogate table, read a stack (a TOML
//! file, or arrays: `strata_stack_new`), load, generate or pass a surface (a height
//! buffer: `strata_surface_new`), solve the load curve once, then query the mean contact
//! pressure p(g) (Pa), the real contact-area fraction A(g)/A₀ and the tangent dp/dg
//! (Pa/m) at any mean-plane separation g (m), one at a time or all three at once
//! (`strata_law_eval`, `strata_law_eval_array`). With `strata_law_new_with_law_options`
//! the law carries its two effects: a hardness caps the asperity tips, and the interface
//! conductance h_c(g) is solved at the samples ([`conductance_curve`] between them).
//! Every law is sampled by the engine `strata law` runs (`strata_engine::law_build`: the
//! same spot sums, capped curves and table caches as the command), from the arguments
//! stated as the engine's inputs. SI units throughout. The header's
//! `STRATA_VERSION_MAJOR`/`MINOR`/`PATCH` are the library's version at compile time;
//! `strata_version()` the one linked.
//!
//! Conventions of every function:
//! - returns `STRATA_OK` (0) or a positive `STRATA_ERR_*` code; on error,
//!   `strata_last_error_message()` gives a one-line message naming the offending
//!   argument (thread-local, valid until the next failing call on the same thread);
//! - outputs go through pointer arguments, written only on success;
//! - NULL pointers and non-finite numbers are errors (`STRATA_ERR_NULL`,
//!   `STRATA_ERR_INVALID_ARGUMENT`), never undefined behaviour on the Rust side;
//! - no Rust panic crosses the boundary: every entry point runs under `catch_unwind`
//!   and turns a panic into `STRATA_ERR_PANIC`;
//! - sizes are capped (`STRATA_MAX_SAMPLES`) and large allocations are estimated first
//!   and checked against the memory limit (`STRATA_ERR_RESOURCE`), so an absurd request
//!   comes back as an error code instead of aborting the host;
//! - Fortran: the module `capi/fortran/strata.f90` binds every function (constants,
//!   interfaces, wrappers taking Fortran strings and returning messages as strings);
//! - handles are freed with their `strata_*_free` function (NULL is a no-op); a law
//!   does not borrow the table or surface it was built from;
//! - a built law is immutable: queries may run concurrently from several threads.
//!
//! The header `capi/include/strata.h` is generated from this file by cbindgen (build.rs).

#![allow(clippy::missing_safety_doc)]

/// The law's effects (a hardness, a conductance): the engine's.
pub use strata_engine::law_build::LawEffects;
/// How the counterface conducts (`StrataLawOptions.counterface_conduction`): the
/// engine's, as a scene's `[counterface]` states it.
pub use strata_engine::scene::CounterfaceConduction;
/// A law's conductance: its kind and how the counterface conducts (the engine's).
pub use strata_engine::scene::{ConductanceSpec, FrictionSpec};
/// h_c(g), h_c(p) between a law's samples: the runtime's, shared with the Python package.
pub use strata_runtime::interface::conductance_curve;

use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::Arc;

use strata_engine::contact_law::{ContactLaw, ContactLawError};
use strata_engine::error::EngineError;
use strata_engine::law_build::{LawInputs, UncoveredSummit, sample_asperity_law};
use strata_engine::progress::{Report, scoped};
use strata_engine::spots::{SpotSum, SpotSumError};
use strata_runtime::conduction::ConductionKind;
use strata_runtime::interface::{InterfaceError, InterfaceLaw};
use strata_runtime::law::Homogeneous;
use strata_runtime::resources::{MemoryLimit, ResourceError};
use strata_runtime::rough::{Images, Model, Params, RoughContact, RoughError};
use strata_runtime::stack::{Bodies, Solid, Stack, StackError};
use strata_runtime::surface::{
    Detrend, GenerateParams, HeightUnit, ReadOptions, Repair, Spacing, Surface, SurfaceError,
};
use strata_runtime::table::{Table, TableError};
use thiserror::Error;

use conductance_curve::{ConductanceCurve, CurveError};
use strata_runtime::rough::plastic::asperity::PlasticAsperityError;

/// Success.
pub const STRATA_OK: i32 = 0;
/// A required pointer argument was NULL.
pub const STRATA_ERR_NULL: i32 = 1;
/// An argument is out of its domain: non-finite number, unknown model or format,
/// path not UTF-8, a layered stack without a table, too few samples, a bad min_gap.
pub const STRATA_ERR_INVALID_ARGUMENT: i32 = 2;
/// The table file is missing, unreadable, corrupt, or does not serve the stack.
pub const STRATA_ERR_TABLE: i32 = 3;
/// The stack file is missing, unreadable or invalid, or a value given to
/// `strata_stack_new` is out of its domain (the message names the array element).
pub const STRATA_ERR_STACK: i32 = 4;
/// The surface file is missing or invalid, or its generation parameters are invalid.
pub const STRATA_ERR_SURFACE: i32 = 5;
/// The rough-contact solve failed (no summits, no convergence…).
pub const STRATA_ERR_SOLVE: i32 = 6;
/// A query below the smallest sampled separation of the law.
pub const STRATA_ERR_OUT_OF_RANGE: i32 = 7;
/// Writing an output file failed.
pub const STRATA_ERR_IO: i32 = 8;
/// A request whose estimated memory exceeds the limit (`STRATA_MEMORY_LIMIT`, bytes
/// or with a k/M/G/T suffix; default 75 % of the machine's memory): refused before
/// allocating, so the host process never aborts on an allocation the library can foresee.
pub const STRATA_ERR_RESOURCE: i32 = 9;
/// An internal error (a Rust panic caught at the boundary): please report it.
pub const STRATA_ERR_PANIC: i32 = 99;

/// Largest `samples` of `strata_law_new` (as the command line's `--samples`); more is
/// `STRATA_ERR_INVALID_ARGUMENT`. CalculiX uses at most 200 lines of a table.
pub const STRATA_MAX_SAMPLES: usize = 100000;
const _: () = assert!(STRATA_MAX_SAMPLES == strata_runtime::interface::MAX_SAMPLES);

/// N model: independent asperities.
pub const STRATA_MODEL_INDEPENDENT: i32 = 0;
/// I model: interacting asperities, interactions inside the sample only.
pub const STRATA_MODEL_INTERACTING_ISOLATED: i32 = 1;
/// I model: interacting asperities, the sample repeated periodically (5×5 cells).
pub const STRATA_MODEL_INTERACTING_PERIODIC: i32 = 2;

/// Major version of the library this header belongs to (`strata_version()` at run time).
pub const STRATA_VERSION_MAJOR: i32 = 0;
/// Minor version.
pub const STRATA_VERSION_MINOR: i32 = 1;
/// Patch version.
pub const STRATA_VERSION_PATCH: i32 = 0;

/// A decimal number of a version string, at compile time.
const fn version_part(s: &str) -> i32 {
    let b = s.as_bytes();
    let mut i = 0;
    let mut v = 0;
    while i < b.len() {
        v = v * 10 + (b[i] - b'0') as i32;
        i += 1;
    }
    v
}
// The macros are literals (cbindgen writes them into the header): the build fails when
// they drift from the crate's version.
const _: () = assert!(
    STRATA_VERSION_MAJOR == version_part(env!("CARGO_PKG_VERSION_MAJOR"))
        && STRATA_VERSION_MINOR == version_part(env!("CARGO_PKG_VERSION_MINOR"))
        && STRATA_VERSION_PATCH == version_part(env!("CARGO_PKG_VERSION_PATCH"))
);

/// `strata_stack_new`: the last layer is bonded to a rigid base.
pub const STRATA_BASE_RIGID: i32 = 0;
/// `strata_stack_new`: the layers lie on an elastic half-space.
pub const STRATA_BASE_ELASTIC: i32 = 1;

/// `strata_law_write`: CSV `gap,overclosure,mean_pressure,area_fraction,dp_dg,valid`.
pub const STRATA_FORMAT_CSV: i32 = 0;
/// `strata_law_write`: Abaqus `*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR` block.
pub const STRATA_FORMAT_ABAQUS: i32 = 1;

/// `StrataLawOptions.conductance_kind`: no conductance (the default).
pub const STRATA_CONDUCTANCE_NONE: i32 = 0;
/// Thermal interface conductance h_c (W/(m²·K)) from the `thermal_conductivity` values.
pub const STRATA_CONDUCTANCE_THERMAL: i32 = 1;
/// Electrical interface conductance h_c (S/m²) from the `electrical_conductivity` values.
pub const STRATA_CONDUCTANCE_ELECTRICAL: i32 = 2;

/// `StrataLawOptions.counterface_conduction`: the elastic counterface of the stack (its
/// file's `[counterface]`) conducts through its own conductivities (the default; a
/// stack pressed by a rigid flat must say how the flat conducts instead).
pub const STRATA_COUNTERFACE_CONDUCTION_STACK: i32 = 0;
/// The counterface is a perfect conductor.
pub const STRATA_COUNTERFACE_CONDUCTION_PERFECT: i32 = 1;
/// The rigid flat is a conducting half-space of `counterface_conductivity`.
pub const STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE: i32 = 2;

/// `strata_stack_set_conductivities`: the base is a conducting half-space of
/// `base_conductivity`.
pub const STRATA_BASE_CONDUCTION_HALF_SPACE: i32 = 0;
/// `strata_stack_set_conductivities`: an isothermal (equipotential) sink at the bottom of
/// the last layer (`[base] conduction = "isothermal"`).
pub const STRATA_BASE_CONDUCTION_ISOTHERMAL: i32 = 1;

/// A surrogate table of χ, ζ, g (opaque).
pub struct StrataTable {
    table: Arc<Table>,
}

/// A material stack: elastic layers on a rigid or elastic base (opaque).
pub struct StrataStack {
    /// The first body and, read from a stack file's `[counterface]`, its elastic
    /// counterface.
    stack: Bodies,
}

/// A rough surface: heights on a square grid (opaque).
pub struct StrataSurface {
    surface: Surface,
}

/// The sampled contact law p(g), A(g)/A₀, dp/dg of one interface (opaque), with the
/// interface conductance h_c and the hardness when built with them
/// (`strata_law_new_with_law_options`).
pub struct StrataLaw {
    /// p(g), A(g)/A₀, dp/dg and h_c(g), h_c(p): the engine's one contact law, the one
    /// `strata compare`, `strata law` and Python interpolate with.
    contact: ContactLaw,
    /// The hardness H (Pa) of a capped law.
    hardness: Option<f64>,
}

impl StrataLaw {
    /// The sampled law p(g), A(g)/A₀, dp/dg.
    pub fn law(&self) -> &InterfaceLaw {
        self.contact.law()
    }
}

/// Budgets and tolerances of the rough-contact solve of `strata_law_new_with_options`:
/// the `[solver]` keys of a scene that the asperity models use, under the same names
/// (error messages name the field to raise). Fill it with
/// `strata_solver_options_default`, then change what is needed. Every budget counts
/// work, never time: the law does not depend on the machine's load.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrataSolverOptions {
    /// I model: most Newton steps of one load step (default 20000), ≥ 1.
    pub max_step_newton_steps: usize,
    /// I model: most energy evaluations of one load step (default 100000), ≥ 1.
    pub max_step_evaluations: usize,
    /// I model: KKT acceptance relative to the largest interference (default 1e-8),
    /// in (0, 1).
    pub kkt_tolerance: f64,
    /// Most solves of a mean-pressure search (default 200), ≥ 1.
    pub max_pressure_iterations: usize,
}

impl Default for StrataSolverOptions {
    fn default() -> Self {
        let d = Params::default();
        StrataSolverOptions {
            max_step_newton_steps: d.max_step_newton_steps,
            max_step_evaluations: d.max_step_evaluations,
            kkt_tolerance: d.kkt_tolerance,
            max_pressure_iterations: d.max_pressure_iterations,
        }
    }
}

impl StrataSolverOptions {
    /// The solver parameters, after checking every field (the error names it).
    pub fn params(&self) -> Result<Params, CapiError> {
        let count = |name: &'static str, v: usize| {
            if v >= 1 {
                Ok(v)
            } else {
                Err(CapiError::Invalid {
                    name,
                    reason: "must be ≥ 1".into(),
                })
            }
        };
        let tol = self.kkt_tolerance;
        if !(tol > 0.0 && tol < 1.0) {
            return Err(CapiError::Invalid {
                name: "options.kkt_tolerance",
                reason: format!("{tol} must be in (0, 1)"),
            });
        }
        let mut p = Params::default();
        p.max_step_newton_steps =
            count("options.max_step_newton_steps", self.max_step_newton_steps)?;
        p.max_step_evaluations = count("options.max_step_evaluations", self.max_step_evaluations)?;
        p.kkt_tolerance = tol;
        p.max_pressure_iterations = count(
            "options.max_pressure_iterations",
            self.max_pressure_iterations,
        )?;
        Ok(p)
    }
}

/// The contact law's optional effects for `strata_law_new_with_law_options`: the
/// hardness of the asperity tips and the interface conductance.
/// Fill it with `strata_law_options_default` (which sets `size`; the defaults are the
/// elastic law without conductance, `strata_law_new_from_stack`'s), then change what is
/// needed. A field out of its domain is `STRATA_ERR_INVALID_ARGUMENT`, naming it
/// (`options.hardness`).
///
/// Versioned by `size`: the library reads the first `size` bytes. Fields a later
/// version appends take their defaults when an older caller's `size` ends before them;
/// a `size` beyond this library's struct is accepted when the extra bytes are 0.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrataLawOptions {
    /// `sizeof(StrataLawOptions)` of the caller's header (set by
    /// `strata_law_options_default`).
    pub size: usize,
    /// Hardness H of the top layer (Pa): the contact pressure of every asperity tip is
    /// capped at H (elastic–perfectly plastic tips, physics.md §6.3), and the law is the
    /// loading curve of the capped N or I model (as `strata law` on a scene with
    /// `[plasticity] hardness = H`). 0 or `INFINITY` (the default): elastic tips.
    pub hardness: f64,
    /// `STRATA_CONDUCTANCE_*`: the interface conductance h_c to solve at every sample
    /// (default `STRATA_CONDUCTANCE_NONE`). The stack needs the kind's conductivity on
    /// every layer and on a half-space base (a stack file's `thermal_conductivity` or
    /// `electrical_conductivity`, or `strata_stack_set_conductivities`).
    pub conductance_kind: i32,
    /// `STRATA_COUNTERFACE_CONDUCTION_*`: how the counterface conducts (with a
    /// conductance only). A rigid flat: `PERFECT` or `HALF_SPACE`; an elastic
    /// counterface (the stack file's `[counterface]`): `STACK` (the default) or
    /// `PERFECT`.
    pub counterface_conduction: i32,
    /// The rigid flat's conductivity (W/(m·K) or S/m, in [1e-30, 1e30]) with
    /// `STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE`; ignored otherwise.
    pub counterface_conductivity: f64,
    /// The coefficient of friction μ (> 0, finite): the law then carries the full-stick
    /// tangential stiffness K_t of the sample at every sample (N/m; `strata law` on a
    /// scene with `[friction] coefficient = μ`), read with
    /// `strata_law_tangential_stiffness`. 0 (the default): none.
    pub friction_coefficient: f64,
}

impl Default for StrataLawOptions {
    fn default() -> Self {
        StrataLawOptions {
            size: std::mem::size_of::<StrataLawOptions>(),
            hardness: f64::INFINITY,
            conductance_kind: STRATA_CONDUCTANCE_NONE,
            counterface_conduction: STRATA_COUNTERFACE_CONDUCTION_STACK,
            counterface_conductivity: 0.0,
            friction_coefficient: 0.0,
        }
    }
}

impl StrataLawOptions {
    /// The effects, after checking every field (the error names it). The counterface
    /// choice is checked against the stack when the law is built.
    pub fn effects(&self) -> Result<LawEffects, CapiError> {
        let invalid = |name: &'static str, reason: String| CapiError::Invalid { name, reason };
        let h = self.hardness;
        let hardness = if h == 0.0 || h == f64::INFINITY {
            None
        } else if let Some(why) = strata_runtime::rough::plastic::hardness_problem(h) {
            return Err(invalid(
                "options.hardness",
                format!("{why} (0 or INFINITY: elastic tips)"),
            ));
        } else {
            Some(h)
        };
        let kind = match self.conductance_kind {
            STRATA_CONDUCTANCE_NONE => None,
            STRATA_CONDUCTANCE_THERMAL => Some(ConductionKind::Thermal),
            STRATA_CONDUCTANCE_ELECTRICAL => Some(ConductionKind::Electrical),
            k => {
                return Err(invalid(
                    "options.conductance_kind",
                    format!(
                        "{k} is not a STRATA_CONDUCTANCE_* value (0 none, 1 thermal, 2 electrical)"
                    ),
                ));
            }
        };
        let counterface = match self.counterface_conduction {
            STRATA_COUNTERFACE_CONDUCTION_STACK => CounterfaceConduction::Stack,
            STRATA_COUNTERFACE_CONDUCTION_PERFECT => CounterfaceConduction::Perfect,
            STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE => {
                let k = self.counterface_conductivity;
                let (lo, hi) = strata_runtime::stack::CONDUCTIVITY_RANGE;
                if !(k.is_finite() && (lo..=hi).contains(&k)) {
                    return Err(invalid(
                        "options.counterface_conductivity",
                        format!(
                            "{k} must be a conductivity in [{lo:e}, {hi:e}] (W/(m·K) or S/m) with \
                             STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE"
                        ),
                    ));
                }
                CounterfaceConduction::HalfSpace(k)
            }
            c => {
                return Err(invalid(
                    "options.counterface_conduction",
                    format!(
                        "{c} is not a STRATA_COUNTERFACE_CONDUCTION_* value (0 stack, 1 perfect, 2 half-space)"
                    ),
                ));
            }
        };
        let mu = self.friction_coefficient;
        let friction = if mu == 0.0 {
            None
        } else if mu.is_finite() && mu > 0.0 {
            Some(FrictionSpec { coefficient: mu })
        } else {
            return Err(invalid(
                "options.friction_coefficient",
                format!("{mu} must be finite and > 0 (0: no tangential stiffness)"),
            ));
        };
        Ok(LawEffects {
            hardness,
            conductance: kind.map(|kind| ConductanceSpec { kind, counterface }),
            friction,
        })
    }
}

/// The options behind a `StrataLawOptions` pointer (NULL: the defaults), read by their
/// `size` (the struct's docs): a `size` below this version's is refused, as is one
/// beyond it whose extra bytes are not 0 (or beyond 4096 bytes: not initialised?).
///
/// # Safety
/// `p` is NULL or points to at least `p->size` readable bytes.
pub unsafe fn law_options_arg(p: *const StrataLawOptions) -> Result<StrataLawOptions, CapiError> {
    if p.is_null() {
        return Ok(StrataLawOptions::default());
    }
    let ours = std::mem::size_of::<StrataLawOptions>();
    // SAFETY: non-NULL; the first field is a size_t.
    let size = unsafe { std::ptr::read_unaligned(p.cast::<usize>()) };
    let refuse = |reason: String| CapiError::Invalid {
        name: "options.size",
        reason,
    };
    if size < ours || size > 4096 {
        return Err(refuse(format!(
            "{size} is not the size of a StrataLawOptions (this library's is {ours} bytes): \
             fill the struct with strata_law_options_default first"
        )));
    }
    if size > ours {
        // SAFETY: the caller's struct holds `size` readable bytes.
        let extra = unsafe { std::slice::from_raw_parts(p.cast::<u8>().add(ours), size - ours) };
        if extra.iter().any(|&b| b != 0) {
            return Err(refuse(format!(
                "{size} bytes with fields beyond this library's {ours} set: a newer header than \
                 the library linked (strata_version())"
            )));
        }
    }
    // SAFETY: at least `ours` readable bytes (checked above), repr(C).
    let mut o = unsafe { std::ptr::read_unaligned(p) };
    o.size = ours;
    Ok(o)
}

/// Errors of the C ABI; each maps to one `STRATA_ERR_*` code.
#[derive(Debug, Error)]
pub enum CapiError {
    #[error("argument `{0}` is NULL")]
    Null(&'static str),
    #[error("argument `{name}`: {reason}")]
    Invalid { name: &'static str, reason: String },
    /// An error at one element of an array argument (`gaps[3]`, `young[1]`): the code
    /// is the element's error's.
    #[error("{}", element_message(name, *index, error))]
    Element {
        name: &'static str,
        index: usize,
        error: Box<CapiError>,
    },
    #[error("table: {0}")]
    Table(#[from] TableError),
    #[error("stack: {0}")]
    Stack(#[from] StackError),
    #[error("{0}")]
    Surface(#[from] SurfaceError),
    #[error("{0}")]
    Rough(#[from] RoughError),
    #[error("{0}")]
    Interface(#[from] InterfaceError),
    #[error("cannot write {path}: {message}")]
    Io { path: String, message: String },
    #[error("{0}")]
    Resource(#[from] ResourceError),
    /// A stack that cannot serve the request (a missing conductivity): the argument and
    /// why (`STRATA_ERR_STACK`).
    #[error("argument `{name}`: {reason}")]
    StackField { name: &'static str, reason: String },
    /// A solve of the law's effects failed (`STRATA_ERR_SOLVE`).
    #[error("{0}")]
    Solve(String),
    /// A conductance query (`STRATA_ERR_OUT_OF_RANGE` outside the sampled range).
    #[error("argument `{name}`: {error}")]
    Curve {
        name: &'static str,
        error: CurveError,
    },
}

/// `argument `young[1]`: …`: the element's error without a second `argument` prefix.
fn element_message(name: &str, index: usize, error: &CapiError) -> String {
    match error {
        CapiError::Invalid { reason, .. } => format!("argument `{name}[{index}]`: {reason}"),
        CapiError::Curve { error, .. } => format!("argument `{name}[{index}]`: {error}"),
        e => format!("argument `{name}[{index}]`: {e}"),
    }
}

impl CapiError {
    /// The `STRATA_ERR_*` code of this error.
    pub fn code(&self) -> i32 {
        match self {
            CapiError::Null(_) => STRATA_ERR_NULL,
            CapiError::Invalid { .. } => STRATA_ERR_INVALID_ARGUMENT,
            CapiError::Element { error, .. } => error.code(),
            CapiError::Table(_) => STRATA_ERR_TABLE,
            CapiError::Stack(_) => STRATA_ERR_STACK,
            CapiError::Surface(_) => STRATA_ERR_SURFACE,
            CapiError::Rough(_) => STRATA_ERR_SOLVE,
            CapiError::Interface(e) => match e {
                InterfaceError::BelowSampledRange { .. } => STRATA_ERR_OUT_OF_RANGE,
                InterfaceError::Rough(_) => STRATA_ERR_SOLVE,
                InterfaceError::Resource(_) => STRATA_ERR_RESOURCE,
                _ => STRATA_ERR_INVALID_ARGUMENT,
            },
            CapiError::Io { .. } => STRATA_ERR_IO,
            CapiError::Resource(_) => STRATA_ERR_RESOURCE,
            CapiError::StackField { .. } => STRATA_ERR_STACK,
            CapiError::Solve(_) => STRATA_ERR_SOLVE,
            CapiError::Curve { error, .. } => match error {
                CurveError::Invalid { .. } => STRATA_ERR_INVALID_ARGUMENT,
                _ => STRATA_ERR_OUT_OF_RANGE,
            },
        }
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: String) {
    let c = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// Runs `f` under `catch_unwind`; records the message of an error or panic.
fn guard(f: impl FnOnce() -> Result<(), CapiError>) -> i32 {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => STRATA_OK,
        Ok(Err(e)) => {
            set_last_error(e.to_string());
            e.code()
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".into());
            set_last_error(format!("internal error (panic: {what}); please report it"));
            STRATA_ERR_PANIC
        }
    }
}

/// A UTF-8 path from a C string.
unsafe fn path_arg(name: &'static str, p: *const c_char) -> Result<PathBuf, CapiError> {
    if p.is_null() {
        return Err(CapiError::Null(name));
    }
    // SAFETY: the caller passes a NUL-terminated string (checked non-NULL above).
    let s = unsafe { CStr::from_ptr(p) };
    let s = s.to_str().map_err(|_| CapiError::Invalid {
        name,
        reason: "path is not valid UTF-8".into(),
    })?;
    Ok(PathBuf::from(s))
}

/// An optional UTF-8 string argument: NULL or `""` is None.
unsafe fn str_arg(name: &'static str, p: *const c_char) -> Result<Option<String>, CapiError> {
    if p.is_null() {
        return Ok(None);
    }
    // SAFETY: the caller passes a NUL-terminated string (checked non-NULL above).
    let s = unsafe { CStr::from_ptr(p) };
    let s = s.to_str().map_err(|_| CapiError::Invalid {
        name,
        reason: "not valid UTF-8".into(),
    })?;
    Ok((!s.is_empty()).then(|| s.to_string()))
}

fn finite(name: &'static str, v: f64) -> Result<f64, CapiError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(CapiError::Invalid {
            name,
            reason: format!("{v} is not a finite number"),
        })
    }
}

/// A C boolean argument that must be 0 or 1 (`periodic = 7` was taken as true).
fn flag(name: &'static str, v: i32) -> Result<bool, CapiError> {
    match v {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(CapiError::Invalid {
            name,
            reason: format!("{v} is not 0 or 1"),
        }),
    }
}

/// Writes a boxed handle to `out`.
unsafe fn put<T>(name: &'static str, out: *mut *mut T, v: T) -> Result<(), CapiError> {
    if out.is_null() {
        return Err(CapiError::Null(name));
    }
    // SAFETY: `out` is non-NULL and, per the API contract, points to writable storage.
    unsafe { *out = Box::into_raw(Box::new(v)) };
    Ok(())
}

/// A shared reference from a handle.
unsafe fn get<'a, T>(name: &'static str, p: *const T) -> Result<&'a T, CapiError> {
    // SAFETY: non-NULL handles come from `put` and live until their `_free`.
    unsafe { p.as_ref() }.ok_or(CapiError::Null(name))
}

/// Writes a scalar output.
unsafe fn out_f64(name: &'static str, out: *mut f64, v: f64) -> Result<(), CapiError> {
    if out.is_null() {
        return Err(CapiError::Null(name));
    }
    // SAFETY: non-NULL, writable per the API contract.
    unsafe { *out = v };
    Ok(())
}

unsafe fn query(
    law: *const StrataLaw,
    gap: f64,
    out: *mut f64,
    pick: impl Fn(strata_runtime::interface::LawPoint) -> f64,
) -> i32 {
    guard(|| {
        // SAFETY: see `get` and `out_f64`.
        let l = unsafe { get("law", law) }?;
        if out.is_null() {
            return Err(CapiError::Null("out"));
        }
        let q = l.law().eval(gap)?;
        unsafe { out_f64("out", out, pick(q)) }
    })
}

/// A `STRATA_MODEL_*` value.
fn model_arg(model: i32) -> Result<Model, CapiError> {
    Ok(match model {
        STRATA_MODEL_INDEPENDENT => Model::Independent,
        STRATA_MODEL_INTERACTING_ISOLATED => Model::Interacting(Images::Isolated),
        STRATA_MODEL_INTERACTING_PERIODIC => Model::Interacting(Images::Periodic(2)),
        m => {
            return Err(CapiError::Invalid {
                name: "model",
                reason: format!("{m} is not a STRATA_MODEL_* value (0, 1 or 2)"),
            });
        }
    })
}

/// The cap on `samples` of `strata_law_new`, checked before any file is read.
fn samples_arg(samples: usize) -> Result<(), CapiError> {
    if samples <= STRATA_MAX_SAMPLES {
        return Ok(());
    }
    let hint = if samples > isize::MAX as usize {
        " (a negative count converted to size_t?)"
    } else {
        ""
    };
    Err(CapiError::Invalid {
        name: "samples",
        reason: format!("{samples} exceeds STRATA_MAX_SAMPLES = {STRATA_MAX_SAMPLES}{hint}"),
    })
}

/// `n` values from a C array (NULL is allowed only when `n` is 0).
unsafe fn slice_arg<'a>(
    name: &'static str,
    p: *const f64,
    n: usize,
) -> Result<&'a [f64], CapiError> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(CapiError::Null(name));
    }
    if n > isize::MAX as usize / std::mem::size_of::<f64>() {
        return Err(CapiError::Invalid {
            name,
            reason: format!(
                "length {n} is impossibly large (a negative count converted to size_t?)"
            ),
        });
    }
    // SAFETY: non-NULL and, per the API contract, `n` readable doubles.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// A writable C array of `n` doubles (NULL is allowed only when `n` is 0).
unsafe fn slice_out<'a>(
    name: &'static str,
    p: *mut f64,
    n: usize,
) -> Result<&'a mut [f64], CapiError> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err(CapiError::Null(name));
    }
    // SAFETY: non-NULL and, per the API contract, `n` writable doubles (the length was
    // checked on the input array of the same call).
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// The stack of `strata_stack_new`: layers from the arrays (top first), each value
/// checked finite first and then by the runtime's validation, an error naming the
/// array element (`young[1]`, 0-based as in C) or the base argument.
pub fn stack_from_arrays(
    thickness: &[f64],
    young: &[f64],
    poisson: &[f64],
    base_kind: i32,
    base_young: f64,
    base_poisson: f64,
) -> Result<Stack, CapiError> {
    use strata_runtime::stack::{Base, Layer, Location};
    let element = |name: &'static str, index: usize, reason: String| CapiError::Element {
        name,
        index,
        error: Box::new(CapiError::Invalid { name, reason }),
    };
    let mut layers = Vec::with_capacity(thickness.len());
    for i in 0..thickness.len() {
        for (name, v) in [
            ("thickness", thickness[i]),
            ("young", young[i]),
            ("poisson", poisson[i]),
        ] {
            if !v.is_finite() {
                return Err(element(name, i, format!("{v} is not a finite number")));
            }
        }
        layers.push(Layer {
            thickness: thickness[i],
            young: young[i],
            poisson: poisson[i],
        });
    }
    let base = match base_kind {
        STRATA_BASE_RIGID => Base::Rigid,
        STRATA_BASE_ELASTIC => Base::Elastic {
            young: finite("base_young", base_young)?,
            poisson: finite("base_poisson", base_poisson)?,
        },
        k => {
            return Err(CapiError::Invalid {
                name: "base_kind",
                reason: format!("{k} is not a STRATA_BASE_* value (0 rigid, 1 elastic)"),
            });
        }
    };
    Stack::new(layers, base).map_err(|e| match &e {
        StackError::Invalid {
            location: Location::Layer(l),
            field,
            ..
        } => {
            let name = match *field {
                "young" => "young",
                "poisson" => "poisson",
                _ => "thickness",
            };
            CapiError::Element {
                name,
                index: l - 1,
                error: Box::new(CapiError::Stack(e.clone())),
            }
        }
        StackError::Invalid {
            location: Location::Base,
            field,
            ..
        } => CapiError::Invalid {
            name: if *field == "poisson" {
                "base_poisson"
            } else {
                "base_young"
            },
            reason: e.to_string(),
        },
        StackError::NoLayersOnRigid => CapiError::Invalid {
            name: "n_layers",
            reason: "is 0 but the base is rigid: a rigid base needs at least one layer".into(),
        },
        _ => CapiError::Stack(e),
    })
}

/// The memory limit of a call (the C ABI's edge, read at every call that allocates in
/// proportion to its input, so a host may change it between calls): the environment
/// variable `STRATA_MEMORY_LIMIT`, else 75 % of the machine's memory. A bad value is
/// `STRATA_ERR_RESOURCE` naming the variable.
pub fn memory_limit() -> Result<MemoryLimit, CapiError> {
    let value = std::env::var(MemoryLimit::ENV_VAR).ok();
    Ok(MemoryLimit::from_setting(value.as_deref())?)
}

/// The surface of `strata_surface_new`: `nx × ny` heights (m), row-major with x the
/// first (slow) index, pixel sizes `dx`, `dy` (m). Checked as a surface file's heights
/// are (non-finite values and spikes refused with their row and column): the same
/// surface as the `.npy` of these heights read with the same pixel sizes. What the
/// checks allocate is checked against `memory` first.
pub fn surface_from_heights(
    heights: &[f64],
    nx: usize,
    ny: usize,
    dx: f64,
    dy: f64,
    periodic: bool,
    memory: &MemoryLimit,
) -> Result<Surface, CapiError> {
    for (name, n) in [("nx", nx), ("ny", ny)] {
        if n < 3 {
            return Err(CapiError::Invalid {
                name,
                reason: format!("{n} points: a surface needs at least 3 along each axis"),
            });
        }
    }
    let dx = finite("dx", dx)?;
    let dy = finite("dy", dy)?;
    for (name, d) in [("dx", dx), ("dy", dy)] {
        if d <= 0.0 {
            return Err(CapiError::Invalid {
                name,
                reason: format!("{d} must be > 0 (the pixel size in metres)"),
            });
        }
    }
    Ok(Surface::measured_with(
        heights.to_vec(),
        nx,
        ny,
        Spacing::Pixel(dx, dy),
        periodic,
        Repair::Refuse,
        memory,
    )?)
}

/// p, A/A₀ and dp/dg at `gaps` into the three outputs (all or nothing: an error at
/// one gap names it and leaves the outputs untouched).
pub fn eval_into(
    law: &InterfaceLaw,
    gaps: &[f64],
    pressure: &mut [f64],
    area_fraction: &mut [f64],
    dp_dg: &mut [f64],
) -> Result<(), CapiError> {
    let mut points = Vec::with_capacity(gaps.len());
    for (i, &g) in gaps.iter().enumerate() {
        points.push(law.eval(g).map_err(|e| CapiError::Element {
            name: "gaps",
            index: i,
            error: Box::new(CapiError::Interface(e)),
        })?);
    }
    for (i, q) in points.iter().enumerate() {
        pressure[i] = q.pressure;
        area_fraction[i] = q.area_fraction;
        dp_dg[i] = q.dp_dg;
    }
    Ok(())
}

/// The stack of `strata_stack_set_conductivities`: `stack` with the conductivities of
/// `kind` set on every layer (`layer_conductivity`, top first, one per layer) and the base
/// (`base_conduction` a `STRATA_BASE_CONDUCTION_*`: a half-space of `base_conductivity`,
/// or an isothermal sink, `base_conductivity` ignored), the other kind's values kept.
/// Validated like a stack file's; an error names the array element
/// (`conductivity[1]`, 0-based) or argument.
pub fn stack_with_conductivities(
    stack: &Stack,
    kind: i32,
    layer_conductivity: &[f64],
    base_conduction: i32,
    base_conductivity: f64,
) -> Result<Stack, CapiError> {
    use strata_runtime::stack::{BaseConduction, Conductivity, Location};
    let kind = match kind {
        STRATA_CONDUCTANCE_THERMAL => ConductionKind::Thermal,
        STRATA_CONDUCTANCE_ELECTRICAL => ConductionKind::Electrical,
        k => {
            return Err(CapiError::Invalid {
                name: "kind",
                reason: format!(
                    "{k} is not STRATA_CONDUCTANCE_THERMAL (1) or STRATA_CONDUCTANCE_ELECTRICAL (2)"
                ),
            });
        }
    };
    let n = stack.layers().len();
    if layer_conductivity.len() != n {
        return Err(CapiError::Invalid {
            name: "n_layers",
            reason: format!(
                "{} conductivities given to a stack of {n} layer(s): one per layer, top first",
                layer_conductivity.len()
            ),
        });
    }
    let element = |index: usize, reason: String| CapiError::Element {
        name: "conductivity",
        index,
        error: Box::new(CapiError::Invalid {
            name: "conductivity",
            reason,
        }),
    };
    for (i, &k) in layer_conductivity.iter().enumerate() {
        if !k.is_finite() {
            return Err(element(i, format!("{k} is not a finite number")));
        }
    }
    let base_kind = match base_conduction {
        STRATA_BASE_CONDUCTION_HALF_SPACE => BaseConduction::HalfSpace,
        STRATA_BASE_CONDUCTION_ISOTHERMAL => BaseConduction::Isothermal,
        b => {
            return Err(CapiError::Invalid {
                name: "base_conduction",
                reason: format!(
                    "{b} is not a STRATA_BASE_CONDUCTION_* value (0 half-space, 1 isothermal)"
                ),
            });
        }
    };
    let set = |c: &mut Conductivity, v: Option<f64>| match kind {
        ConductionKind::Thermal => c.thermal = v,
        ConductionKind::Electrical => c.electrical = v,
    };
    let old = stack.conduction();
    let mut layers: Vec<Conductivity> = (0..n).map(|i| stack.layer_conductivity(i)).collect();
    for (c, &k) in layers.iter_mut().zip(layer_conductivity) {
        set(c, Some(k));
    }
    let mut base = old.base;
    match base_kind {
        BaseConduction::HalfSpace => set(
            &mut base,
            Some(finite("base_conductivity", base_conductivity)?),
        ),
        BaseConduction::Isothermal => set(&mut base, None),
    }
    stack
        .clone()
        .with_conduction(layers, base, base_kind)
        .map_err(|e| match &e {
            StackError::Invalid {
                location: Location::Layer(l),
                ..
            } => CapiError::Element {
                name: "conductivity",
                index: l - 1,
                error: Box::new(CapiError::Stack(e.clone())),
            },
            StackError::Invalid {
                location: Location::Base,
                ..
            } => CapiError::Invalid {
                name: "base_conductivity",
                reason: e.to_string(),
            },
            StackError::IsothermalWithConductivity { .. } => CapiError::Invalid {
                name: "base_conduction",
                reason: format!(
                    "{e}: the base keeps the other kind's conductivity set earlier; an isothermal \
                     base is isothermal for both kinds"
                ),
            },
            StackError::NoLayersOnIsothermal => CapiError::Invalid {
                name: "base_conduction",
                reason: e.to_string(),
            },
            _ => CapiError::Stack(e),
        })
}

/// The table of `stack` for the engine: none for a homogeneous stack (Hertz
/// asperities), else `table`, which a layered stack needs (the engine would build one
/// into the table cache, minutes of solves: refused here instead).
fn law_table(
    table: Option<&StrataTable>,
    stack: &(impl Solid + ?Sized),
) -> Result<Option<Arc<Table>>, CapiError> {
    if stack.is_homogeneous() {
        return Ok(None);
    }
    let t = table.ok_or_else(|| CapiError::Invalid {
        name: "table",
        reason: "is NULL but the stack is layered: load the table serving it".into(),
    })?;
    Ok(Some(Arc::clone(&t.table)))
}

/// Checks the conduction set-up of `spec` against `stack` before any solve, with the
/// engine's spot sums ([`SpotSum::of_stack`]): errors name the option or the stack's
/// missing conductivity.
fn check_conduction(
    stack: &(impl Solid + ?Sized),
    spec: &ConductanceSpec,
) -> Result<(), CapiError> {
    let kind = spec.kind;
    match (spec.counterface, stack.elastic_counterface()) {
        (CounterfaceConduction::Stack, None) => {
            return Err(CapiError::Invalid {
                name: "options.counterface_conduction",
                reason: format!(
                    "STRATA_COUNTERFACE_CONDUCTION_STACK, but the stack is pressed by a rigid flat \
                     (no [counterface]): say how the flat conducts, \
                     STRATA_COUNTERFACE_CONDUCTION_PERFECT or STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE \
                     with options.counterface_conductivity ({})",
                    kind.conductivity_unit()
                ),
            });
        }
        (CounterfaceConduction::HalfSpace(_), Some(_)) => {
            return Err(CapiError::Invalid {
                name: "options.counterface_conduction",
                reason: "STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE, but the stack's counterface is \
                         elastic: it conducts through its own stack's conductivities \
                         (STRATA_COUNTERFACE_CONDUCTION_STACK) or perfectly"
                    .into(),
            });
        }
        _ => {}
    }
    let needs = format!(
        "options.conductance_kind = STRATA_CONDUCTANCE_{} needs it (the stack file's `{}`, or \
         strata_stack_set_conductivities)",
        kind.name().to_uppercase(),
        kind.field()
    );
    match SpotSum::of_stack(stack, kind, spec.counterface) {
        Ok(_) => Ok(()),
        Err(SpotSumError::Body(e)) => Err(CapiError::StackField {
            name: "stack",
            reason: format!("{e}; {needs}"),
        }),
        Err(SpotSumError::Counterface(e)) => Err(CapiError::StackField {
            name: "stack",
            reason: format!(
                "counterface: {e}; {needs}, or options.counterface_conduction = \
                 STRATA_COUNTERFACE_CONDUCTION_PERFECT"
            ),
        }),
        Err(e) => Err(CapiError::Invalid {
            name: "options.counterface_conduction",
            reason: e.to_string(),
        }),
    }
}

/// The C ABI's error for an error of the engine: the first error of a known kind in
/// its chain, with that error's own code and message (the engine's context names the
/// command line's flags and scene keys, not the C arguments); any other is
/// `STRATA_ERR_SOLVE` with the whole chain.
fn engine_error(e: EngineError) -> CapiError {
    for cause in e.causes() {
        if let Some(x) = cause.downcast_ref::<ResourceError>() {
            return CapiError::Resource(x.clone());
        }
        if let Some(x) = cause.downcast_ref::<InterfaceError>() {
            return CapiError::Interface(x.clone());
        }
        if let Some(x) = cause.downcast_ref::<TableError>() {
            return CapiError::Table(x.clone());
        }
        if let Some(x) = cause.downcast_ref::<UncoveredSummit>() {
            return CapiError::Invalid {
                name: "options.hardness",
                reason: format!(
                    "a summit of radius {:e} m is loaded past 0.01 δ_c (δ_c = (πH/2E*)²R, the \
                     capped asperity's table's lower end) and yields at a contact radius \
                     a_c = πHR/(2E*) of {:.3e} h1, outside the capped asperity's table (a_c/h1 \
                     in [{:e}, {:e}]): the hardness is too high for this stack's top layer to be \
                     treated this way",
                    x.radius,
                    x.y,
                    strata_runtime::rough::plastic::asperity::RESPONSE_Y.0,
                    strata_runtime::rough::plastic::asperity::RESPONSE_Y.1
                ),
            };
        }
        if let Some(x) = cause.downcast_ref::<PlasticAsperityError>() {
            return CapiError::Invalid {
                name: "options.hardness",
                reason: x.to_string(),
            };
        }
    }
    CapiError::Solve(format!("{:#}", anyhow::Error::from(e)))
}

/// What `strata_law_new_with_law_options` computes: the law of `surface` on `stack` by
/// `model` with the effects of `effects`, sampled by the engine
/// ([`strata_engine::law_build::sample_asperity_law`], `strata law`'s sampler): with a
/// hardness the capped model's loading curve, with a conductance h_c at every sample.
/// The arguments are checked first (the error names the argument), then the engine's
/// errors are given their codes (`engine_error`). Its log lines are dropped; the
/// capped asperity's response tables and the ψ tables are kept in the table cache
/// (`STRATA_CACHE_DIR`, else `$XDG_CACHE_HOME/strata` or `$HOME/.cache/strata`).
#[allow(clippy::too_many_arguments)]
pub fn build_law_with_effects(
    table: Option<&StrataTable>,
    stack: &(impl Solid + ?Sized),
    surface: &Surface,
    model: Model,
    min_gap: f64,
    samples: usize,
    params: Params,
    effects: LawEffects,
) -> Result<StrataLaw, CapiError> {
    // the C ABI's edge: the limit of the environment (or the machine)
    let mut params = params;
    params.memory = memory_limit()?;
    // the conduction set-up and the table are checked before any solve
    if let Some(spec) = &effects.conductance {
        check_conduction(stack, spec)?;
    }
    let table = law_table(table, stack)?;
    if samples < 2 {
        return Err(CapiError::Interface(InterfaceError::TooFewSamples(samples)));
    }
    if effects.hardness.is_some() {
        // the capped law's first contact: the highest summit, whatever the law
        let hom = Homogeneous {
            e_star: stack.contact_modulus(),
        };
        let g0 = RoughContact::from_surface(&hom, surface)?.top_to_mean();
        if min_gap.is_nan() || min_gap >= g0 {
            return Err(CapiError::Invalid {
                name: "min_gap",
                reason: format!(
                    "{min_gap:e} m must lie below the first-contact separation {g0:e} m"
                ),
            });
        }
    }
    let bodies = stack.bodies();
    let inputs = LawInputs {
        stack: &bodies,
        surface: surface.clone(),
        table,
        model,
        params,
    };
    let report = Report::new(false);
    let sampled = scoped(&report, || {
        sample_asperity_law(inputs, &effects, samples, min_gap, None)
    })
    .map_err(engine_error)?;
    let h = sampled
        .conductance
        .as_ref()
        .map(|(k, h)| (*k, h.as_slice()));
    let contact = ContactLaw::new(sampled.law, h).map_err(|e| match e {
        ContactLawError::InfiniteConductance => CapiError::Solve(format!(
            "conductance: the samples' h_c {:?} are not finite and ≥ 0",
            sampled.conductance.as_ref().map(|(_, h)| h)
        )),
        e => CapiError::Solve(e.to_string()),
    })?;
    let contact = match &sampled.tangential_stiffness {
        Some(k) => contact
            .with_tangential_stiffness(k)
            .map_err(|e| CapiError::Solve(format!("friction: {e}")))?,
        None => contact,
    };
    Ok(StrataLaw {
        contact,
        hardness: effects.hardness,
    })
}

/// The conductance curve of a law, or an error naming `law` when it has none.
fn conductance_of(l: &StrataLaw) -> Result<&ConductanceCurve, CapiError> {
    l.contact
        .conductance()
        .map(|(_, c)| c)
        .ok_or_else(|| CapiError::Invalid {
            name: "law",
            reason: "was built without a conductance: build it with \
                     strata_law_new_with_law_options and options.conductance_kind = \
                     STRATA_CONDUCTANCE_THERMAL or STRATA_CONDUCTANCE_ELECTRICAL"
                .into(),
        })
}

/// h_c at `gaps` (m) into `out` (all or nothing; an error names the element).
pub fn conductance_into(
    l: &StrataLaw,
    name: &'static str,
    at: &[f64],
    by_pressure: bool,
    out: &mut [f64],
) -> Result<(), CapiError> {
    conductance_of(l)?;
    let mut v = Vec::with_capacity(at.len());
    for (i, &x) in at.iter().enumerate() {
        v.push(
            conductance_at(l, name, x, by_pressure).map_err(|e| CapiError::Element {
                name,
                index: i,
                error: Box::new(e),
            })?,
        );
    }
    out[..v.len()].copy_from_slice(&v);
    Ok(())
}

/// h_c of `l` at a separation or, with `by_pressure`, at a mean pressure: the
/// engine's [`ContactLaw`] (PCHIP in g; h_c(p) by bisection on p(g)).
fn conductance_at(
    l: &StrataLaw,
    name: &'static str,
    x: f64,
    by_pressure: bool,
) -> Result<f64, CapiError> {
    let r = if by_pressure {
        l.contact.conductance_at_pressure(x)
    } else {
        l.contact.conductance_at_gap(x)
    };
    r.map_err(|e| match e {
        ContactLawError::Conductance(error) => CapiError::Curve { name, error },
        e => CapiError::Solve(format!("{name}: {e}")),
    })
}

/// The law as CSV, as `strata law --format csv` writes it: the samples
/// (`InterfaceLaw::csv`) and, with a conductance, the column `conductance`; with
/// friction, the column `tangential_stiffness`; with a
/// hardness, the column `branch` (`loading`: the asperity models give the loading curve
/// only).
pub fn law_csv(l: &StrataLaw) -> String {
    let base = l.law().csv();
    let kt: Option<Vec<f64>> = l
        .contact
        .tangential_stiffness()
        .map(|c| c.samples().collect());
    if l.contact.conductance().is_none() && l.hardness.is_none() && kt.is_none() {
        return base;
    }
    let h: Option<Vec<f64>> = l.contact.conductance().map(|(_, c)| c.samples().collect());
    let mut out = String::with_capacity(base.len() * 2);
    for (i, line) in base.lines().enumerate() {
        out.push_str(line);
        if let Some(h) = &h {
            match i {
                0 => out.push_str(",conductance"),
                _ => match h.get(i - 1) {
                    Some(v) if v.is_finite() => out.push_str(&format!(",{v:e}")),
                    _ => out.push(','),
                },
            }
        }
        if let Some(k) = &kt {
            match i {
                0 => out.push_str(",tangential_stiffness"),
                _ => match k.get(i - 1) {
                    Some(v) => out.push_str(&format!(",{v:e}")),
                    None => out.push(','),
                },
            }
        }
        if l.hardness.is_some() {
            out.push_str(if i == 0 { ",branch" } else { ",loading" });
        }
        out.push('\n');
    }
    out
}

/// The law's Abaqus/CalculiX block: the pressure–overclosure table and, with a
/// hardness, `**` lines saying it is the loading curve; with a conductance, a
/// `*GAP CONDUCTANCE, PRESSURE` table (`conductance, pressure` at the samples, the
/// pressures strictly increasing from `0., 0.`), as `strata law --format abaqus`
/// (whose comments say what CalculiX reads of it: docs/guide/conductance.md).
pub fn law_abaqus(l: &StrataLaw) -> String {
    use strata_runtime::interface::abaqus_real;
    let mut s = l.law().abaqus_block(&[
        "strata (C ABI): pressure-overclosure law of a rough layered interface".into(),
    ]);
    if let Some(h) = l.hardness {
        s.push_str(&format!(
            "** PLASTIC INTERFACE: the asperity tips were capped at the hardness H = {} Pa. The\n\
             **   table above is the LOADING curve; Abaqus and CalculiX tabular laws are elastic\n\
             **   (unloading retraces loading), while the flattened tips do not spring back.\n",
            abaqus_real(h)
        ));
    }
    if let Some((kind, c)) = l.contact.conductance() {
        let mut lines = String::new();
        let mut last = f64::NEG_INFINITY;
        for ((_, p, _, _), hc) in l.law().samples().zip(c.samples()) {
            if p.is_nan() || p <= last || !hc.is_finite() {
                continue;
            }
            last = p;
            lines.push_str(&format!("{}, {}\n", abaqus_real(hc), abaqus_real(p)));
        }
        s.push_str(&format!(
            "** strata (C ABI): {} gap conductance h_c ({}) of the rough interface against the\n\
             **   mean contact pressure (Pa) of the table above, at its samples: the interface\n\
             **   (constriction) conductance per nominal area, the bulk 1-D resistance of both\n\
             **   bodies excluded. Data lines: conductance, pressure.\n\
             *GAP CONDUCTANCE, PRESSURE\n{lines}",
            kind.name(),
            kind.interface_conductance_unit()
        ));
    }
    s
}

#[cfg(feature = "capi")]
mod exported {
    use super::*;

    /// The message of the most recent failing call on this thread ("" if none). The
    /// pointer stays valid until the next failing call on the same thread.
    #[unsafe(no_mangle)]
    pub extern "C" fn strata_last_error_message() -> *const c_char {
        catch_unwind(|| LAST_ERROR.with(|e| e.borrow().as_ptr()))
            .unwrap_or(c"internal error".as_ptr())
    }

    /// The library version, e.g. "0.1.0" (static string).
    #[unsafe(no_mangle)]
    pub extern "C" fn strata_version() -> *const c_char {
        concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
    }

    /// Builds a stack from arrays, as a stack file's `[[layer]]` tables and `[base]`:
    /// `n_layers` layers, top first, of thickness `thickness[i]` (m), Young modulus
    /// `young[i]` (Pa) and Poisson ratio `poisson[i]`, on a base of kind
    /// `STRATA_BASE_RIGID` (`base_young`, `base_poisson` ignored) or
    /// `STRATA_BASE_ELASTIC` (a half-space of `base_young`, `base_poisson`; with
    /// `n_layers = 0` the homogeneous half-space). Validated like a stack file; an error
    /// names the array element (`young[1]`, 0-based) or argument. The arrays may be
    /// NULL when `n_layers` is 0. `*out` receives a handle to free with
    /// `strata_stack_free`. (A counterface or conduction properties need a stack file.)
    #[unsafe(no_mangle)]
    #[allow(clippy::too_many_arguments)]
    pub unsafe extern "C" fn strata_stack_new(
        n_layers: usize,
        thickness: *const f64,
        young: *const f64,
        poisson: *const f64,
        base_kind: i32,
        base_young: f64,
        base_poisson: f64,
        out: *mut *mut StrataStack,
    ) -> i32 {
        guard(|| {
            let t = unsafe { slice_arg("thickness", thickness, n_layers) }?;
            let y = unsafe { slice_arg("young", young, n_layers) }?;
            let p = unsafe { slice_arg("poisson", poisson, n_layers) }?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let stack = stack_from_arrays(t, y, p, base_kind, base_young, base_poisson)?;
            unsafe {
                put(
                    "out",
                    out,
                    StrataStack {
                        stack: Bodies::rigid(stack),
                    },
                )
            }
        })
    }

    /// Frees a stack (NULL is a no-op).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_stack_free(stack: *mut StrataStack) {
        if !stack.is_null() {
            // SAFETY: created by `strata_stack_new`, freed once.
            let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(stack) })));
        }
    }

    /// Loads a surrogate table file (`strata table build`). `*out` receives a handle to
    /// free with `strata_table_free`.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_table_load(
        path: *const c_char,
        out: *mut *mut StrataTable,
    ) -> i32 {
        guard(|| {
            let p = unsafe { path_arg("path", path) }?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let table = Arc::new(Table::load_within(&p, &memory_limit()?)?);
            unsafe { put("out", out, StrataTable { table }) }
        })
    }

    /// Frees a table (NULL is a no-op).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_table_free(table: *mut StrataTable) {
        if !table.is_null() {
            // SAFETY: created by `strata_table_load`, freed once.
            let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(table) })));
        }
    }

    /// Loads a surface height map (m): a 2-D f64 `.npy` file by extension, otherwise a
    /// plain-text matrix (one grid row per line). `size` is the physical length L (m)
    /// of the first axis; `periodic` (0/1) whether the sample repeats periodically.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_surface_load(
        path: *const c_char,
        size: f64,
        periodic: i32,
        out: *mut *mut StrataSurface,
    ) -> i32 {
        guard(|| {
            let p = unsafe { path_arg("path", path) }?;
            let size = finite("size", size)?;
            let periodic = flag("periodic", periodic)?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let npy = p.extension().is_some_and(|e| e.eq_ignore_ascii_case("npy"));
            let memory = memory_limit()?;
            let surface = if npy {
                Surface::read_npy_with(&p, size, periodic, Repair::Refuse, &memory)?
            } else {
                Surface::read_text_with(&p, size, periodic, Repair::Refuse, &memory)?
            };
            unsafe { put("out", out, StrataSurface { surface }) }
        })
    }

    /// A surface from a height buffer in memory: `nx × ny` heights (m), row-major with
    /// x the first index (`heights[i*ny + j]` at x = i·dx, y = j·dy; a Fortran array
    /// `h(ny, nx)` in column order has this layout), pixel sizes `dx`, `dy` (m, > 0),
    /// `periodic` (0/1). The heights are copied; non-finite values and spikes are
    /// refused with their row and column (as when reading a file): the surface equals
    /// the `.npy` file of these heights read with the same pixel sizes.
    #[unsafe(no_mangle)]
    #[allow(clippy::too_many_arguments)]
    pub unsafe extern "C" fn strata_surface_new(
        heights: *const f64,
        nx: usize,
        ny: usize,
        dx: f64,
        dy: f64,
        periodic: i32,
        out: *mut *mut StrataSurface,
    ) -> i32 {
        guard(|| {
            let periodic = flag("periodic", periodic)?;
            let n = nx.checked_mul(ny).ok_or_else(|| CapiError::Invalid {
                name: "nx",
                reason: format!("nx·ny = {nx}·{ny} overflows"),
            })?;
            // A grid too large for memory is refused before the copy.
            let memory = memory_limit()?;
            memory.check(
                "surface from a height buffer",
                strata_runtime::resources::bytes_for(n as u64, 8),
            )?;
            let h = unsafe { slice_arg("heights", heights, n) }?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let surface = surface_from_heights(h, nx, ny, dx, dy, periodic, &memory)?;
            unsafe { put("out", out, StrataSurface { surface }) }
        })
    }

    /// Reads a measured surface in any format strata knows, as a scene's `[surface]`
    /// with `file = path` does: ISO 25178-72 `.x3p` (pixel sizes and metres from the
    /// file: pass `dx = dy = 0`), SurfaceTopography's NetCDF `.nc` (sizes, unit and
    /// periodic flag from the file: `dx = dy = 0`, `height_unit` NULL; a periodic file is
    /// periodic), a 2-D f64 `.npy`, or a plain-text matrix (one grid row
    /// per line; first axis = x). For `.npy`/text, `dx`, `dy` are the pixel sizes (m,
    /// both > 0); `height_unit` is `"m"`, `"mm"`, `"um"` or `"nm"` (NULL or `""`: metres;
    /// `.x3p` accepts only metres). `detrend` is `"none"`, `"plane"` or `"curvature"`
    /// (NULL or `""`: none): the least-squares form removed after reading. `periodic`
    /// (0/1): whether the sample repeats periodically. Non-finite heights and invalid
    /// points are refused with their row and column.
    #[unsafe(no_mangle)]
    #[allow(clippy::too_many_arguments)]
    pub unsafe extern "C" fn strata_surface_read(
        path: *const c_char,
        dx: f64,
        dy: f64,
        height_unit: *const c_char,
        detrend: *const c_char,
        periodic: i32,
        out: *mut *mut StrataSurface,
    ) -> i32 {
        guard(|| {
            let p = unsafe { path_arg("path", path) }?;
            let dx = finite("dx", dx)?;
            let dy = finite("dy", dy)?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let unit = match unsafe { str_arg("height_unit", height_unit) }? {
                None => None,
                Some(u) => Some(HeightUnit::parse(&u).ok_or_else(|| CapiError::Invalid {
                    name: "height_unit",
                    reason: format!("`{u}` is not one of \"m\", \"mm\", \"um\", \"nm\""),
                })?),
            };
            let detrend = match unsafe { str_arg("detrend", detrend) }? {
                None => Detrend::None,
                Some(d) => Detrend::parse(&d).ok_or_else(|| CapiError::Invalid {
                    name: "detrend",
                    reason: format!("`{d}` is not one of \"none\", \"plane\", \"curvature\""),
                })?,
            };
            let spacing = if dx == 0.0 && dy == 0.0 {
                None
            } else {
                Some(Spacing::Pixel(dx, dy))
            };
            let opts = ReadOptions {
                spacing,
                periodic: flag("periodic", periodic)?,
                repair: Repair::Refuse,
                height_unit: unit,
                detrend,
                memory: memory_limit()?,
            };
            let surface = Surface::read(&p, &opts)?;
            unsafe { put("out", out, StrataSurface { surface }) }
        })
    }

    /// The grid and extent of a surface: `nx × ny` points (first axis = x), pixel
    /// sizes `dx`, `dy` (m) and the RMS height about the mean (m).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_surface_info(
        surface: *const StrataSurface,
        nx: *mut usize,
        ny: *mut usize,
        dx: *mut f64,
        dy: *mut f64,
        rms: *mut f64,
    ) -> i32 {
        guard(|| {
            let s = &unsafe { get("surface", surface) }?.surface;
            for (name, null) in [
                ("nx", nx.is_null()),
                ("ny", ny.is_null()),
                ("dx", dx.is_null()),
                ("dy", dy.is_null()),
                ("rms", rms.is_null()),
            ] {
                if null {
                    return Err(CapiError::Null(name));
                }
            }
            let (n0, n1) = s.shape();
            let (px, py) = s.pixel_size();
            // SAFETY: every pointer is non-NULL (checked above) and, per the API
            // contract, writable.
            unsafe {
                *nx = n0;
                *ny = n1;
                *dx = px;
                *dy = py;
                *rms = s.rms();
            }
            Ok(())
        })
    }

    /// Generates a periodic self-affine surface, exactly as a scene's
    /// `[surface.generate]` (physics.md §5): side `size` (m), `grid` points per side,
    /// fractal dimension D_f ∈ [2, 3), wavenumbers `k_min`…`k_max` in units of 2π/L,
    /// RMS height `rms` (m), ChaCha8 `seed`.
    #[unsafe(no_mangle)]
    #[allow(clippy::too_many_arguments)]
    pub unsafe extern "C" fn strata_surface_generate(
        size: f64,
        grid: usize,
        fractal_dimension: f64,
        k_min: f64,
        k_max: f64,
        rms: f64,
        seed: u64,
        out: *mut *mut StrataSurface,
    ) -> i32 {
        guard(|| {
            let params = GenerateParams {
                size: finite("size", size)?,
                grid,
                fractal_dimension: finite("fractal_dimension", fractal_dimension)?,
                k_min: finite("k_min", k_min)?,
                k_max: finite("k_max", k_max)?,
                rms: finite("rms", rms)?,
                seed,
            };
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let surface = Surface::generate_within(&params, &memory_limit()?)?;
            unsafe { put("out", out, StrataSurface { surface }) }
        })
    }

    /// Frees a surface (NULL is a no-op).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_surface_free(surface: *mut StrataSurface) {
        if !surface.is_null() {
            // SAFETY: created by a `strata_surface_*` constructor, freed once.
            let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(surface) })));
        }
    }

    /// Builds the contact law of `surface` pressed against a rigid flat on the stack
    /// of the TOML file `stack_path` (against a second elastic body instead when the
    /// file has a `[counterface]` table: the two compliances add): solves the load curve with `model`
    /// (`STRATA_MODEL_*`) at `samples` separations (2 to `STRATA_MAX_SAMPLES`) evenly
    /// spaced from first contact g₀ = z_M − z̄ down to `min_gap` (m), and interpolates it
    /// monotonically (see `strata_runtime::interface`). A homogeneous stack uses Hertz
    /// asperities and ignores `table` (may be NULL); a layered stack needs a `table`
    /// serving it. More samples than the cap is `STRATA_ERR_INVALID_ARGUMENT`; a law
    /// whose memory estimate exceeds the limit is `STRATA_ERR_RESOURCE` (nothing is
    /// allocated in either case).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_new(
        table: *const StrataTable,
        stack_path: *const c_char,
        surface: *const StrataSurface,
        model: i32,
        min_gap: f64,
        samples: usize,
        out: *mut *mut StrataLaw,
    ) -> i32 {
        let options = StrataSolverOptions::default();
        unsafe {
            law_new(
                table, stack_path, surface, model, min_gap, samples, options, out,
            )
        }
    }

    /// `strata_law_new` and `strata_law_new_with_options`.
    #[allow(clippy::too_many_arguments)]
    unsafe fn law_new(
        table: *const StrataTable,
        stack_path: *const c_char,
        surface: *const StrataSurface,
        model: i32,
        min_gap: f64,
        samples: usize,
        options: StrataSolverOptions,
        out: *mut *mut StrataLaw,
    ) -> i32 {
        guard(|| {
            let params = options.params()?;
            let sp = unsafe { path_arg("stack_path", stack_path) }?;
            let surface = &unsafe { get("surface", surface) }?.surface;
            let table = unsafe { table.as_ref() };
            let model = model_arg(model)?;
            let min_gap = finite("min_gap", min_gap)?;
            samples_arg(samples)?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let stack = Bodies::from_toml_file(&sp)?;
            let effects = LawEffects::default();
            let law = build_law_with_effects(
                table, &stack, surface, model, min_gap, samples, params, effects,
            )?;
            unsafe { put("out", out, law) }
        })
    }

    /// Writes the default solver options (those `strata_law_new` uses) to `out`.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_solver_options_default(out: *mut StrataSolverOptions) -> i32 {
        guard(|| {
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            // SAFETY: non-NULL, writable per the API contract.
            unsafe { *out = StrataSolverOptions::default() };
            Ok(())
        })
    }

    /// `strata_law_new` with the solver's budgets and tolerances from `options` (NULL:
    /// the defaults): raise a budget an error message names here. A field out of its
    /// range is `STRATA_ERR_INVALID_ARGUMENT`, naming it.
    #[unsafe(no_mangle)]
    #[allow(clippy::too_many_arguments)]
    pub unsafe extern "C" fn strata_law_new_with_options(
        table: *const StrataTable,
        stack_path: *const c_char,
        surface: *const StrataSurface,
        model: i32,
        min_gap: f64,
        samples: usize,
        options: *const StrataSolverOptions,
        out: *mut *mut StrataLaw,
    ) -> i32 {
        // SAFETY: NULL or a pointer to a valid StrataSolverOptions, per the contract.
        let options = unsafe { options.as_ref() }.copied().unwrap_or_default();
        unsafe {
            law_new(
                table, stack_path, surface, model, min_gap, samples, options, out,
            )
        }
    }

    /// `strata_law_new_with_options` on a stack built in memory (`strata_stack_new`)
    /// instead of a stack file: the same law, bit for bit, as from the file with the
    /// same values. `options` NULL: the defaults; `table` may be NULL for a homogeneous
    /// stack.
    #[unsafe(no_mangle)]
    #[allow(clippy::too_many_arguments)]
    pub unsafe extern "C" fn strata_law_new_from_stack(
        table: *const StrataTable,
        stack: *const StrataStack,
        surface: *const StrataSurface,
        model: i32,
        min_gap: f64,
        samples: usize,
        options: *const StrataSolverOptions,
        out: *mut *mut StrataLaw,
    ) -> i32 {
        guard(|| {
            // SAFETY: NULL or a pointer to a valid StrataSolverOptions, per the contract.
            let options = unsafe { options.as_ref() }.copied().unwrap_or_default();
            let params = options.params()?;
            let stack = &unsafe { get("stack", stack) }?.stack;
            let surface = &unsafe { get("surface", surface) }?.surface;
            let table = unsafe { table.as_ref() };
            let model = model_arg(model)?;
            let min_gap = finite("min_gap", min_gap)?;
            samples_arg(samples)?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let effects = LawEffects::default();
            let law = build_law_with_effects(
                table, stack, surface, model, min_gap, samples, params, effects,
            )?;
            unsafe { put("out", out, law) }
        })
    }

    /// p(g) (Pa), A(g)/A₀ and dp/dg (Pa/m) at separation `gap` (m) in one call: the
    /// values `strata_law_pressure`, `strata_law_area_fraction` and `strata_law_dp_dg`
    /// give, bit for bit. All three outputs are required and written only on success.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_eval(
        law: *const StrataLaw,
        gap: f64,
        pressure: *mut f64,
        area_fraction: *mut f64,
        dp_dg: *mut f64,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            for (name, p) in [
                ("pressure", pressure),
                ("area_fraction", area_fraction),
                ("dp_dg", dp_dg),
            ] {
                if p.is_null() {
                    return Err(CapiError::Null(name));
                }
            }
            let q = l.law().eval(gap)?;
            // SAFETY: non-NULL (checked above), writable per the API contract.
            unsafe {
                *pressure = q.pressure;
                *area_fraction = q.area_fraction;
                *dp_dg = q.dp_dg;
            }
            Ok(())
        })
    }

    /// `strata_law_eval` at `n` separations `gaps[i]` (m) into the arrays `pressure`,
    /// `area_fraction`, `dp_dg` of `n` doubles each (an FE code's integration points in
    /// one call). All or nothing: an error at one gap (`STRATA_ERR_OUT_OF_RANGE`,
    /// `STRATA_ERR_INVALID_ARGUMENT`) names it (`gaps[7]`) and leaves the outputs
    /// untouched. The pointers may be NULL when `n` is 0.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_eval_array(
        law: *const StrataLaw,
        n: usize,
        gaps: *const f64,
        pressure: *mut f64,
        area_fraction: *mut f64,
        dp_dg: *mut f64,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            let g = unsafe { slice_arg("gaps", gaps, n) }?;
            let p = unsafe { slice_out("pressure", pressure, n) }?;
            let a = unsafe { slice_out("area_fraction", area_fraction, n) }?;
            let d = unsafe { slice_out("dp_dg", dp_dg, n) }?;
            eval_into(l.law(), g, p, a, d)
        })
    }

    /// Mean contact pressure p(g) (Pa) at separation `gap` (m); 0 at or above first
    /// contact, `STRATA_ERR_OUT_OF_RANGE` below the smallest sampled separation.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_pressure(
        law: *const StrataLaw,
        gap: f64,
        out: *mut f64,
    ) -> i32 {
        unsafe { query(law, gap, out, |q| q.pressure) }
    }

    /// Real contact-area fraction A(g)/A₀ (-) at separation `gap` (m).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_area_fraction(
        law: *const StrataLaw,
        gap: f64,
        out: *mut f64,
    ) -> i32 {
        unsafe { query(law, gap, out, |q| q.area_fraction) }
    }

    /// Tangent dp/dg (Pa/m, ≤ 0) at separation `gap` (m): the derivative of the
    /// interpolated p(g) (equal to −(dP/dδ)/A₀ of the solver at the samples).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_dp_dg(
        law: *const StrataLaw,
        gap: f64,
        out: *mut f64,
    ) -> i32 {
        unsafe { query(law, gap, out, |q| q.dp_dg) }
    }

    /// First-contact separation g₀ = z_M − z̄ (m).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_first_contact_gap(
        law: *const StrataLaw,
        out: *mut f64,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            unsafe { out_f64("out", out, l.law().first_contact_gap()) }
        })
    }

    /// Smallest sampled separation g_min (m).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_min_gap(law: *const StrataLaw, out: *mut f64) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            unsafe { out_f64("out", out, l.law().min_gap()) }
        })
    }

    /// Writes the sampled law to `path` (atomically): `STRATA_FORMAT_CSV` (full
    /// precision) or `STRATA_FORMAT_ABAQUS` (the block `strata law --format abaqus`
    /// writes: every number in at most 20 characters, what Abaqus and CalculiX read).
    /// A law with a conductance adds the CSV column `conductance` and the Abaqus
    /// `*GAP CONDUCTANCE, PRESSURE` table; a capped law (a hardness) the CSV column
    /// `branch` (`loading`) and a note that the table is the loading curve: the CSV is
    /// then `strata law --format csv`'s of the same scene.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_write(
        law: *const StrataLaw,
        path: *const c_char,
        format: i32,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            let p = unsafe { path_arg("path", path) }?;
            let text = match format {
                STRATA_FORMAT_CSV => law_csv(l),
                STRATA_FORMAT_ABAQUS => law_abaqus(l),
                f => {
                    return Err(CapiError::Invalid {
                        name: "format",
                        reason: format!("{f} is not a STRATA_FORMAT_* value (0 or 1)"),
                    });
                }
            };
            strata_runtime::output::write_atomic(&p, text.as_bytes()).map_err(|e| CapiError::Io {
                path: p.display().to_string(),
                message: e.to_string(),
            })
        })
    }

    /// Reads a stack file (TOML: layers, base, an optional `[counterface]`, conduction
    /// properties) into a handle for `strata_law_new_from_stack` and
    /// `strata_law_new_with_law_options`: the stack `strata_law_new` reads from the same
    /// file. `*out` receives a handle to free with `strata_stack_free`.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_stack_load(
        path: *const c_char,
        out: *mut *mut StrataStack,
    ) -> i32 {
        guard(|| {
            let p = unsafe { path_arg("path", path) }?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let stack = Bodies::from_toml_file(&p)?;
            unsafe { put("out", out, StrataStack { stack }) }
        })
    }

    /// Sets the conductivities of one kind on a stack (as a stack file's
    /// `thermal_conductivity` or `electrical_conductivity` fields, physics.md §6.2):
    /// `kind` `STRATA_CONDUCTANCE_THERMAL` (W/(m·K)) or `STRATA_CONDUCTANCE_ELECTRICAL`
    /// (S/m); `n_layers` values `conductivity[i]`, top layer first, one per layer of the
    /// stack (NULL when it has none); the base `base_conduction`:
    /// `STRATA_BASE_CONDUCTION_HALF_SPACE` (a conducting half-space of
    /// `base_conductivity`) or `STRATA_BASE_CONDUCTION_ISOTHERMAL` (an isothermal sink
    /// under the last layer, `base_conductivity` ignored; then for both kinds). The other
    /// kind's values are kept; an elastic counterface read from a stack file keeps its
    /// own. Validated like a stack file's values (each in [1e-30, 1e30]); an error names
    /// the element (`conductivity[1]`, 0-based) or argument and leaves the stack
    /// unchanged.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_stack_set_conductivities(
        stack: *mut StrataStack,
        kind: i32,
        n_layers: usize,
        conductivity: *const f64,
        base_conduction: i32,
        base_conductivity: f64,
    ) -> i32 {
        guard(|| {
            // SAFETY: non-NULL handles come from a constructor and live until freed.
            let s = unsafe { stack.as_mut() }.ok_or(CapiError::Null("stack"))?;
            let k = unsafe { slice_arg("conductivity", conductivity, n_layers) }?;
            s.stack.first = stack_with_conductivities(
                &s.stack.first,
                kind,
                k,
                base_conduction,
                base_conductivity,
            )?;
            Ok(())
        })
    }

    /// Writes the default law options (the elastic law without conductance) to `out`,
    /// `out->size` included.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_options_default(out: *mut StrataLawOptions) -> i32 {
        guard(|| {
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            // SAFETY: non-NULL, writable per the API contract.
            unsafe { *out = StrataLawOptions::default() };
            Ok(())
        })
    }

    /// `strata_law_new_from_stack` with the law's effects from `law_options` (NULL: the
    /// defaults, the same law bit for bit): with `hardness` the loading curve of the N or
    /// I model with capped asperity tips (`strata law` on a scene with
    /// `[plasticity] hardness`; the response table's ring solves take ~20 CPU-s on a
    /// layered stack, once: the table is kept in the table cache, `STRATA_CACHE_DIR` or
    /// `$HOME/.cache/strata`, as the command keeps it); with `conductance_kind` the interface conductance h_c at every
    /// sample (`strata law` on a scene with `[conductance]`: the CSV's `conductance`
    /// column), queried with `strata_law_conductance*`; with both, h_c of the capped
    /// tips' spots. `solver_options` NULL: the defaults. A field out of its domain is `STRATA_ERR_INVALID_ARGUMENT` naming it
    /// (`options.hardness`); a stack without the conductivity the kind needs is
    /// `STRATA_ERR_STACK` naming the layer and field.
    #[unsafe(no_mangle)]
    #[allow(clippy::too_many_arguments)]
    pub unsafe extern "C" fn strata_law_new_with_law_options(
        table: *const StrataTable,
        stack: *const StrataStack,
        surface: *const StrataSurface,
        model: i32,
        min_gap: f64,
        samples: usize,
        solver_options: *const StrataSolverOptions,
        law_options: *const StrataLawOptions,
        out: *mut *mut StrataLaw,
    ) -> i32 {
        guard(|| {
            // SAFETY: NULL or a pointer to a valid StrataSolverOptions, per the contract.
            let solver = unsafe { solver_options.as_ref() }
                .copied()
                .unwrap_or_default();
            let params = solver.params()?;
            let effects = unsafe { law_options_arg(law_options) }?.effects()?;
            let stack = &unsafe { get("stack", stack) }?.stack;
            let surface = &unsafe { get("surface", surface) }?.surface;
            let table = unsafe { table.as_ref() };
            let model = model_arg(model)?;
            let min_gap = finite("min_gap", min_gap)?;
            samples_arg(samples)?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let law = build_law_with_effects(
                table, stack, surface, model, min_gap, samples, params, effects,
            )?;
            unsafe { put("out", out, law) }
        })
    }

    /// The law's conductance kind: `STRATA_CONDUCTANCE_NONE`, `_THERMAL` or
    /// `_ELECTRICAL`.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_conductance_kind(
        law: *const StrataLaw,
        out: *mut i32,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let k = match l.contact.conductance_kind() {
                None => STRATA_CONDUCTANCE_NONE,
                Some(ConductionKind::Thermal) => STRATA_CONDUCTANCE_THERMAL,
                Some(ConductionKind::Electrical) => STRATA_CONDUCTANCE_ELECTRICAL,
            };
            // SAFETY: non-NULL, writable per the API contract.
            unsafe { *out = k };
            Ok(())
        })
    }

    /// The hardness H (Pa) the law's asperity tips were capped at; `INFINITY` for an
    /// elastic law.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_hardness(law: *const StrataLaw, out: *mut f64) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            unsafe { out_f64("out", out, l.hardness.unwrap_or(f64::INFINITY)) }
        })
    }

    /// The full-stick tangential stiffness K_t of the sample (N/m) at separation `gap`
    /// (m), for a law built with `options.friction_coefficient` > 0: the solved value at
    /// the samples (each contact disc's K_t summed, `strata solve`'s
    /// `tangential_stiffness`), monotone cubic between them (∝ √δ next to first
    /// contact), 0 at and above first contact, `STRATA_ERR_OUT_OF_RANGE` below the
    /// smallest sampled separation. A law built without friction is
    /// `STRATA_ERR_INVALID_ARGUMENT`.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_tangential_stiffness(
        law: *const StrataLaw,
        gap: f64,
        out: *mut f64,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            if !l.contact.has_tangential_stiffness() {
                return Err(CapiError::Invalid {
                    name: "law",
                    reason: "was built without friction: build it with \
                             strata_law_new_with_law_options and options.friction_coefficient > 0"
                        .into(),
                });
            }
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let v = l
                .contact
                .tangential_stiffness_at_gap(gap)
                .map_err(|e| match e {
                    ContactLawError::Conductance(error) => CapiError::Curve { name: "gap", error },
                    e => CapiError::Solve(format!("gap: {e}")),
                })?;
            unsafe { out_f64("out", out, v) }
        })
    }

    /// The interface conductance h_c(g) (W/(m²·K) or S/m²; physics.md §6.2) at
    /// separation `gap` (m): the solved value at the samples, monotone cubic between
    /// them (∝ √δ next to first contact), 0 at and above first contact,
    /// `STRATA_ERR_OUT_OF_RANGE` below the smallest sampled separation. A law built
    /// without a conductance is `STRATA_ERR_INVALID_ARGUMENT`.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_conductance(
        law: *const StrataLaw,
        gap: f64,
        out: *mut f64,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            conductance_of(l)?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let v = conductance_at(l, "gap", gap, false)?;
            unsafe { out_f64("out", out, v) }
        })
    }

    /// `strata_law_conductance` at `n` separations `gaps[i]` (m) into `out` (`n`
    /// doubles). All or nothing: an error names the element (`gaps[7]`) and leaves `out`
    /// untouched. The pointers may be NULL when `n` is 0.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_conductance_array(
        law: *const StrataLaw,
        n: usize,
        gaps: *const f64,
        out: *mut f64,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            let g = unsafe { slice_arg("gaps", gaps, n) }?;
            let o = unsafe { slice_out("out", out, n) }?;
            conductance_into(l, "gaps", g, false, o)
        })
    }

    /// The interface conductance at mean contact pressure `pressure` (Pa, ≥ 0): h_c at
    /// the separation where the law's p(g) reaches `pressure` on loading (FE codes
    /// tabulate the gap conductance against the contact pressure); a sample's pressure
    /// gives the sample's h_c exactly. 0 at p = 0; `STRATA_ERR_OUT_OF_RANGE` above the
    /// largest sampled pressure.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_conductance_at_pressure(
        law: *const StrataLaw,
        pressure: f64,
        out: *mut f64,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            conductance_of(l)?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let v = conductance_at(l, "pressure", pressure, true)?;
            unsafe { out_f64("out", out, v) }
        })
    }

    /// `strata_law_conductance_at_pressure` at `n` pressures `pressures[i]` (Pa) into
    /// `out` (all or nothing, as `strata_law_conductance_array`).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_conductance_at_pressure_array(
        law: *const StrataLaw,
        n: usize,
        pressures: *const f64,
        out: *mut f64,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            let p = unsafe { slice_arg("pressures", pressures, n) }?;
            let o = unsafe { slice_out("out", out, n) }?;
            conductance_into(l, "pressures", p, true, o)
        })
    }

    /// `strata_law_eval` and `strata_law_conductance` at `gap` (m) in one call: p (Pa),
    /// A/A₀, dp/dg (Pa/m) and h_c (W/(m²·K) or S/m²), each bit for bit what the single
    /// queries give. All four outputs are required and written only on success.
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_eval_with_conductance(
        law: *const StrataLaw,
        gap: f64,
        pressure: *mut f64,
        area_fraction: *mut f64,
        dp_dg: *mut f64,
        conductance: *mut f64,
    ) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            conductance_of(l)?;
            for (name, p) in [
                ("pressure", pressure),
                ("area_fraction", area_fraction),
                ("dp_dg", dp_dg),
                ("conductance", conductance),
            ] {
                if p.is_null() {
                    return Err(CapiError::Null(name));
                }
            }
            let q = l.law().eval(gap)?;
            let h = conductance_at(l, "gap", gap, false)?;
            // SAFETY: non-NULL (checked above), writable per the API contract.
            unsafe {
                *pressure = q.pressure;
                *area_fraction = q.area_fraction;
                *dp_dg = q.dp_dg;
                *conductance = h;
            }
            Ok(())
        })
    }

    /// Frees a law (NULL is a no-op).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_free(law: *mut StrataLaw) {
        if !law.is_null() {
            // SAFETY: created by `strata_law_new`, freed once.
            let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(law) })));
        }
    }
}

#[cfg(feature = "capi")]
pub use exported::*;

/// What `strata_law_new` computes, in Rust: the asperity law of `stack` (Hertz when
/// homogeneous, else from `table`), the summits of `surface`, and the sampled
/// [`InterfaceLaw`]. The C test compares against the runtime API called directly.
pub fn build_law(
    table: Option<&StrataTable>,
    stack: &Stack,
    surface: &Surface,
    model: Model,
    min_gap: f64,
    samples: usize,
) -> Result<InterfaceLaw, CapiError> {
    build_law_with(
        table,
        stack,
        surface,
        model,
        min_gap,
        samples,
        Params::default(),
    )
}

/// [`build_law`] with the solver parameters `params` (`strata_law_new_with_options`):
/// [`build_law_with_effects`] without effects.
pub fn build_law_with(
    table: Option<&StrataTable>,
    stack: &(impl Solid + ?Sized),
    surface: &Surface,
    model: Model,
    min_gap: f64,
    samples: usize,
    params: Params,
) -> Result<InterfaceLaw, CapiError> {
    let effects = LawEffects::default();
    Ok(build_law_with_effects(
        table, stack, surface, model, min_gap, samples, params, effects,
    )?
    .law()
    .clone())
}
