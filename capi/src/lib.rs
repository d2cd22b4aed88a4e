//! # strata-capi: the C ABI of the strata runtime
//!
//! Builds the contact law of a rough layered interface (module
//! `strata_runtime::interface`) from C: load a surrogate table, read a stack (a TOML
//! file, or arrays: `strata_stack_new`), load, generate or pass a surface (a height
//! buffer: `strata_surface_new`), solve the load curve once, then query the mean contact
//! pressure p(g) (Pa), the real contact-area fraction A(g)/A₀ and the tangent dp/dg
//! (Pa/m) at any mean-plane separation g (m), one at a time or all three at once
//! (`strata_law_eval`, `strata_law_eval_array`). SI units throughout. The header's
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

use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;

use strata_runtime::interface::{InterfaceError, InterfaceLaw, SampleOptions};
use strata_runtime::law::{AsperityLaw, Homogeneous};
use strata_runtime::resources::ResourceError;
use strata_runtime::rough::{Images, Model, Params, RoughContact, RoughError};
use strata_runtime::stack::{Stack, StackError};
use strata_runtime::surface::{
    Detrend, GenerateParams, HeightUnit, ReadOptions, Repair, Spacing, Surface, SurfaceError,
};
use strata_runtime::table::{Table, TableError};
use thiserror::Error;

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

/// A surrogate table of χ, ζ, g (opaque).
pub struct StrataTable {
    table: Table,
}

/// A material stack: elastic layers on a rigid or elastic base (opaque).
pub struct StrataStack {
    stack: Stack,
}

/// A rough surface: heights on a square grid (opaque).
pub struct StrataSurface {
    surface: Surface,
}

/// The sampled contact law p(g), A(g)/A₀, dp/dg of one interface (opaque).
pub struct StrataLaw {
    law: InterfaceLaw,
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
}

/// `argument `young[1]`: …`: the element's error without a second `argument` prefix.
fn element_message(name: &str, index: usize, error: &CapiError) -> String {
    match error {
        CapiError::Invalid { reason, .. } => format!("argument `{name}[{index}]`: {reason}"),
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
        let q = l.law.eval(gap)?;
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

/// The surface of `strata_surface_new`: `nx × ny` heights (m), row-major with x the
/// first (slow) index, pixel sizes `dx`, `dy` (m). Checked as a surface file's heights
/// are (non-finite values and spikes refused with their row and column): the same
/// surface as the `.npy` of these heights read with the same pixel sizes.
pub fn surface_from_heights(
    heights: &[f64],
    nx: usize,
    ny: usize,
    dx: f64,
    dy: f64,
    periodic: bool,
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
            unsafe { put("out", out, StrataStack { stack }) }
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
            let table = Table::load(&p)?;
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
            let surface = if npy {
                Surface::read_npy(&p, size, periodic)?
            } else {
                Surface::read_text(&p, size, periodic)?
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
            strata_runtime::resources::check_memory(
                "surface from a height buffer",
                strata_runtime::resources::bytes_for(n as u64, 8),
            )?;
            let h = unsafe { slice_arg("heights", heights, n) }?;
            if out.is_null() {
                return Err(CapiError::Null("out"));
            }
            let surface = surface_from_heights(h, nx, ny, dx, dy, periodic)?;
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
            let surface = Surface::generate(&params)?;
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
            let stack = Stack::from_toml_file(&sp)?;
            let law = build_law_with(table, &stack, surface, model, min_gap, samples, params)?;
            unsafe { put("out", out, StrataLaw { law }) }
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
            let law = build_law_with(table, stack, surface, model, min_gap, samples, params)?;
            unsafe { put("out", out, StrataLaw { law }) }
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
            let q = l.law.eval(gap)?;
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
            eval_into(&l.law, g, p, a, d)
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
            unsafe { out_f64("out", out, l.law.first_contact_gap()) }
        })
    }

    /// Smallest sampled separation g_min (m).
    #[unsafe(no_mangle)]
    pub unsafe extern "C" fn strata_law_min_gap(law: *const StrataLaw, out: *mut f64) -> i32 {
        guard(|| {
            let l = unsafe { get("law", law) }?;
            unsafe { out_f64("out", out, l.law.min_gap()) }
        })
    }

    /// Writes the sampled law to `path` (atomically): `STRATA_FORMAT_CSV` (full
    /// precision) or `STRATA_FORMAT_ABAQUS` (the block `strata law --format abaqus`
    /// writes: every number in at most 20 characters, what Abaqus and CalculiX read).
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
                STRATA_FORMAT_CSV => l.law.csv(),
                STRATA_FORMAT_ABAQUS => l.law.abaqus_block(&[
                    "strata (C ABI): pressure-overclosure law of a rough layered interface".into(),
                ]),
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

/// [`build_law`] with the solver parameters `params` (`strata_law_new_with_options`).
pub fn build_law_with(
    table: Option<&StrataTable>,
    stack: &Stack,
    surface: &Surface,
    model: Model,
    min_gap: f64,
    samples: usize,
    params: Params,
) -> Result<InterfaceLaw, CapiError> {
    let law: Box<dyn AsperityLaw> = if stack.is_homogeneous() {
        Box::new(Homogeneous {
            e_star: stack.contact_modulus(),
        })
    } else {
        let t = table.ok_or_else(|| CapiError::Invalid {
            name: "table",
            reason: "is NULL but the stack is layered: load the table serving it".into(),
        })?;
        Box::new(t.table.law_for(stack)?)
    };
    let rc = RoughContact::from_surface(law.as_ref(), surface)?.with_params(params);
    let opts = SampleOptions { samples, min_gap };
    Ok(InterfaceLaw::sample(&rc, model, &opts)?)
}
