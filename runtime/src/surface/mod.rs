//! Rough surfaces: height maps on a regular grid (physics.md §5).
//!
//! A [`Surface`] holds heights z (m, positive up, i.e. towards the rigid flat) on an
//! `n0 × n1` grid stored row-major (`z[i * n1 + j]`). Grid point (i, j) sits at
//! x = i·dx, y = j·dy: the FIRST array axis is x. This matches the shared reference
//! (`summits_km10.csv` lists x from the first .npy axis) and the x3p convention (x is
//! the fastest index of `data.bin`, transposed on reading). Pixels may be rectangular
//! (dx ≠ dy) and the grid non-square (n0 ≠ n1); the lateral scale is given as a
//! [`Spacing`]: the first axis' length L (square pixels, Δ = L/n0, the historical
//! `size`), the sides (Lx, Ly), or the pixel sizes (dx, dy).
//!
//! Sources:
//! - [`Surface::generate`]: self-affine random surface, PSD ∝ |k|^(−2(1+H)), H = 3 − D_f,
//!   nonzero for k_min ≤ |k|·L/(2π) ≤ k_max, random phases from a seeded ChaCha8
//!   generator (reproducible), scaled to the given RMS height, zero mean.
//! - [`Surface::read`]: a file by its extension, with [`ReadOptions`] (spacing, height
//!   unit, periodic flag, repair, form removal): `.x3p` (ISO 25178-72, feature `x3p`:
//!   sizes and metres from the file), `.npy` (2-D little-endian f64, feature `npy`) or
//!   a plain-text matrix, one grid row per line, numbers separated by whitespace or
//!   commas, `#` starting a comment.
//!
//! Measured data (every reader) is checked, not trusted, in one order
//! ([`Surface::measured_judged`]): invalid points marked, the form fitted on the valid
//! points, spikes judged on the heights less that form, then filled or refused. A
//! non-finite height (NaN or ±inf, e.g. a dropout, or a point an .x3p file marks
//! invalid) and a spike are refused with the file and the grid index of the first one. A spike is a height further than
//! [`SPIKE_LIMIT`] robust standard deviations σ_r from its smooth prediction: the median
//! over the x, y and diagonal directions of the linear interpolation between its two
//! neighbours (linear extrapolation from one side at a non-periodic edge), σ_r = 1.4826
//! × the median absolute deviation of those residuals over the map (at least 1e-3 × the
//! RMS height). Smooth profiles, tilts and lays are predicted to second order (an
//! extruded sine stays near 1 σ_r, edges included) and random rough surfaces stay a few
//! σ_r; one outlier pixel does not (and spoils at most one direction of its
//! neighbours' predictions). With [`Repair::Median`] (scene key `[surface] repair =
//! "median"`) such points, in clusters of any size, are filled by harmonic interpolation
//! (module `repair`: Laplace's equation on the points to fill), and
//! [`Surface::repair_report`] says what was found and filled.
//!
//! What a reader did (units, repairs, form removal, the file's metadata) is kept as log
//! lines ([`Surface::log`]); what looks wrong but is not fatal (an .x3p whose main.xml
//! checksum does not match) as [`Surface::warnings`]. [`Surface::stats`] gives the
//! usual statistics and their plausibility warnings (module `stats`).

#[cfg(feature = "container")]
pub mod container;
mod detrend;
mod form;
#[cfg(feature = "spectral")]
mod generate;
#[cfg(feature = "netcdf")]
pub mod netcdf;
mod open;
mod read;
mod repair;
#[cfg(feature = "spectral")]
mod spectrum;
mod stats;
#[cfg(feature = "x3p")]
pub mod x3p;

pub use form::{Detrend, Form, KEPT_FORM_FRACTION, REMOVED_FORM_RATIO};
#[cfg(feature = "spectral")]
pub use generate::{GENERATE_BYTES_PER_POINT, GenerateParams};
pub use read::{FileKind, HeightUnit, ReadOptions};
pub use repair::{FILL_TOLERANCE, MAX_FILL_FRACTION, RepairReport};
#[cfg(feature = "spectral")]
pub use spectrum::{Density, PsdBin};
pub use stats::{MAX_RMS_HEIGHT_FRACTION, MAX_RMS_SLOPE, MIN_RMS_HEIGHT, SurfaceStats};

use thiserror::Error;

use crate::resources::MemoryLimit;

/// Errors from building or reading a surface. Each names the field or file.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SurfaceError {
    #[error("cannot read surface file {path}: {message}")]
    Io { path: String, message: String },
    #[error("cannot write surface file {path}: {message}")]
    Write { path: String, message: String },
    #[error("surface file {path}: {message}")]
    Format { path: String, message: String },
    #[error("surface: field `{field}` = {} is invalid: {reason}", shown(*value))]
    Invalid {
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error("surface: {0}")]
    Unsupported(String),
    #[error(
        "surface: height at row {row}, column {col} (0-based) is {value}: missing or invalid \
         data (to interpolate it, set [surface] repair = \"median\" in the scene)"
    )]
    NonFinite { row: usize, col: usize, value: f64 },
    #[error(
        "surface: height {value:e} m at row {row}, column {col} (0-based) is a spike, \
         {sigmas:.1} robust standard deviations from the smooth surface through its neighbours (limit \
         {SPIKE_LIMIT}); remove it or set [surface] repair = \"median\" in the scene"
    )]
    Spike {
        row: usize,
        col: usize,
        value: f64,
        sigmas: f64,
    },
    /// More of the map is invalid (or spikes) than repair fills.
    #[error(
        "surface: {:.1} % of the points are invalid (NaN/inf) or spikes: too little is measured \
         to mean anything (repair fills at most {:.0} % of a map)",
        100.0 * fraction,
        100.0 * limit
    )]
    TooLittleValid { fraction: f64, limit: f64 },
    /// Nothing is left after form removal: the heights were (to round-off) the form.
    #[error(
        "surface: nothing is left after removing the form (detrend = \"{detrend}\"): the remaining \
         roughness has an RMS of {rms:e} m, below the atomic scale ({limit:e} m), after a removed \
         form of RMS {form_rms:e} m (slopes z_x = {slope_x:e}, z_y = {slope_y:e}); the file is a \
         plane or a quadric, not a rough surface"
    )]
    NothingLeft {
        detrend: &'static str,
        rms: f64,
        limit: f64,
        form_rms: f64,
        slope_x: f64,
        slope_y: f64,
    },
    /// The message includes the limit's; no `source` (a chain would print it twice).
    #[error("surface: {0}")]
    Resources(crate::resources::ResourceError),
    /// Two surfaces whose heights cannot be added point by point.
    #[error(
        "counterface surface: its {what} ({other}) differs from the first body's ({this}); \
         the two height maps must share the grid, pixel size and periodicity"
    )]
    Mismatch {
        what: &'static str,
        this: String,
        other: String,
    },
}

impl From<crate::resources::ResourceError> for SurfaceError {
    fn from(e: crate::resources::ResourceError) -> Self {
        SurfaceError::Resources(e)
    }
}

/// Spike limit in robust standard deviations of the prediction residuals (see the
/// module documentation).
pub const SPIKE_LIMIT: f64 = 20.0;

/// Bytes per grid point that judging a measured surface allocates beside its heights
/// ([`Surface::measured_judged`] up to its spike list): the invalid and valid masks (1 + 1),
/// the fitted form and the heights less it (8 + 8; neither on a periodic grid, whose form
/// is zero), the prediction residuals and their finite copy for the median (8 + 8; the
/// absolute deviations overwrite that copy). Counted, and held to by a test that measures
/// the allocations (runtime/tests/surface_memory.rs).
pub(crate) const JUDGE_BYTES_PER_POINT: u64 = 34;

/// Bytes per grid point that repairing allocates beside the heights, whatever is filled:
/// the four masks (invalid, spike, fill, kept: 4), the form (8), the heights less it (8)
/// and the fill's index of unknowns (8).
pub(crate) const REPAIR_BYTES_PER_POINT: u64 = 28;

/// Bytes per filled point of the harmonic fill: its list of unknowns and the
/// conjugate-gradient vectors (diagonal, right-hand side, x, Ax, r, z, p, Ap): 9 × 8.
pub(crate) const REPAIR_BYTES_PER_FILLED_POINT: u64 = 72;

/// What the file readers do with non-finite heights and spikes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Repair {
    /// Refuse them with the file and the grid index (default).
    #[default]
    Refuse,
    /// Fill them, clusters of any size included, by harmonic interpolation from the
    /// valid points around them (module `repair`; scene `repair = "median"` or
    /// `"harmonic"`, the same fill).
    Median,
}

/// The lateral scale of an `n0 × n1` height map (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spacing {
    /// Physical length L of the FIRST axis; square pixels dx = dy = L/n0 (scene
    /// `size = L`).
    Size(f64),
    /// Sides (Lx, Ly): dx = Lx/n0, dy = Ly/n1 (scene `size = [Lx, Ly]`).
    Extent(f64, f64),
    /// Pixel sizes (dx, dy) (scene `pixel_size = [dx, dy]`).
    Pixel(f64, f64),
}

impl Spacing {
    /// The pixel sizes (dx, dy) (m) of an `n0 × n1` grid; each given length must be
    /// finite and > 0 (the error names `size` or `pixel_size`).
    pub fn pixel(self, n0: usize, n1: usize) -> Result<(f64, f64), SurfaceError> {
        let check = |field: &'static str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(invalid(field, v, "must be a finite length > 0 (m)"))
            }
        };
        let (n0f, n1f) = (n0.max(1) as f64, n1.max(1) as f64);
        let (dx, dy) = match self {
            Spacing::Size(l) => {
                let d = check("size", l)? / n0f;
                (d, d)
            }
            Spacing::Extent(lx, ly) => (check("size", lx)? / n0f, check("size", ly)? / n1f),
            Spacing::Pixel(dx, dy) => (check("pixel_size", dx)?, check("pixel_size", dy)?),
        };
        if !(dx.is_normal() && dy.is_normal()) {
            return Err(invalid(
                "pixel_size",
                dx.min(dy),
                "pixel sizes underflow (too small a sample for the grid)",
            ));
        }
        Ok((dx, dy))
    }
}

/// A height map on a regular grid with pixels dx × dy.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    z: Vec<f64>,
    n0: usize,
    n1: usize,
    dx: f64,
    dy: f64,
    periodic: bool,
    /// Points replaced by [`Repair::Median`] when read.
    repaired: usize,
    /// What the reader did (units, repairs, form removal, file metadata).
    log: Vec<String>,
    /// Non-fatal problems found while reading.
    warnings: Vec<String>,
    /// The form removed when read ([`Surface::detrend`]).
    form: Option<Form>,
    /// What checking the measured heights found and what was filled.
    report: Option<RepairReport>,
    /// Flat indices of the filled points.
    filled: Vec<usize>,
    /// Whether the file gave the height unit (.x3p, a NetCDF or container with a unit).
    unit_from_file: bool,
}

/// A value as a person reads it: plain between 1e−4 and 1e15, else in exponent form
/// (never 300 digits).
fn shown(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

fn invalid(field: &'static str, value: f64, reason: &'static str) -> SurfaceError {
    SurfaceError::Invalid {
        field,
        value,
        reason,
    }
}

impl Surface {
    /// Builds a surface from row-major heights `z` (m) of shape `n0 × n1`; `size` is
    /// the physical length L (m) of the first axis, so dx = dy = L/n0.
    pub fn new(
        z: Vec<f64>,
        n0: usize,
        n1: usize,
        size: f64,
        periodic: bool,
    ) -> Result<Self, SurfaceError> {
        Self::with_spacing(z, n0, n1, Spacing::Size(size), periodic)
    }

    /// Builds a surface from row-major heights `z` (m) of shape `n0 × n1` (n0 along x)
    /// with the lateral scale `spacing`.
    pub fn with_spacing(
        z: Vec<f64>,
        n0: usize,
        n1: usize,
        spacing: Spacing,
        periodic: bool,
    ) -> Result<Self, SurfaceError> {
        let (dx, dy) = spacing.pixel(n0, n1)?;
        if n0 < 3 || n1 < 3 {
            return Err(invalid(
                "grid",
                n0.min(n1) as f64,
                "needs at least 3 points along each axis",
            ));
        }
        if z.len() != n0 * n1 {
            return Err(invalid("grid", z.len() as f64, "height count is not n0·n1"));
        }
        if let Some(k) = z.iter().position(|v| !v.is_finite()) {
            return Err(SurfaceError::NonFinite {
                row: k / n1,
                col: k % n1,
                value: z[k],
            });
        }
        let s = Surface {
            z,
            n0,
            n1,
            dx,
            dy,
            periodic,
            repaired: 0,
            log: Vec::new(),
            warnings: Vec::new(),
            form: None,
            report: None,
            filled: Vec::new(),
            unit_from_file: false,
        };
        // Finite heights whose statistics overflow (|z| ~ 1e300 m, or a pixel of 1e−300 m)
        // would reach the models as RMS = inf and give contradictory curves: refused here,
        // for every solver and command alike.
        if !s.rms().is_finite() {
            let top = s.z.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            return Err(invalid(
                "heights",
                top,
                "the largest |height| (m) is too large: the RMS height overflows; heights are in metres",
            ));
        }
        if !s.rms_slope().is_finite() {
            return Err(invalid(
                "pixel_size",
                dx.min(dy),
                "the RMS slope overflows: the pixel (m) is too small for these heights; lengths are in metres",
            ));
        }
        Ok(s)
    }

    /// Checks (or repairs, with [`Repair::Median`]) measured heights: non-finite values
    /// and spikes (module documentation), then builds the surface (square pixels, L =
    /// `size` along the first axis), under the machine's memory limit
    /// ([`MemoryLimit::of_machine`]; [`Surface::measured_with`] takes one).
    pub fn measured(
        z: Vec<f64>,
        n0: usize,
        n1: usize,
        size: f64,
        periodic: bool,
        repair: Repair,
    ) -> Result<Self, SurfaceError> {
        Self::measured_with(
            z,
            n0,
            n1,
            Spacing::Size(size),
            periodic,
            repair,
            &MemoryLimit::default(),
        )
    }

    /// Checks, against `memory` ([`crate::resources`]), what judging a measured n0 × n1
    /// surface allocates beside the heights handed in (`JUDGE_BYTES_PER_POINT`, 34 B per
    /// point): every entry point (file readers, Python arrays, the C ABI) calls it before
    /// copying, so a huge array is refused by name instead of aborting the host process.
    /// A repair checks what it needs when it knows how many points it fills.
    pub fn check_measured_memory(
        n0: usize,
        n1: usize,
        memory: &MemoryLimit,
    ) -> Result<(), SurfaceError> {
        memory.check(
            format!("checking and building a {n0}×{n1} measured surface"),
            crate::resources::bytes_for(
                (n0 as u64).saturating_mul(n1 as u64),
                JUDGE_BYTES_PER_POINT,
            ),
        )?;
        Ok(())
    }

    /// [`Surface::measured`] with any [`Spacing`]; spikes are judged on the heights less
    /// their least-squares plane (none on a periodic grid), see
    /// [`Surface::measured_judged`]; what they allocate checked against `memory`.
    pub fn measured_with(
        z: Vec<f64>,
        n0: usize,
        n1: usize,
        spacing: Spacing,
        periodic: bool,
        repair: Repair,
        memory: &MemoryLimit,
    ) -> Result<Self, SurfaceError> {
        Self::measured_judged(z, n0, n1, spacing, periodic, repair, Detrend::Plane, memory)
    }

    /// Checks (or repairs) measured heights in one order: mark the invalid points
    /// (non-finite) → fit the form `judge` on the valid points (none on a periodic grid)
    /// → judge spikes on the heights less that form → refit the form without the spikes
    /// → fill invalid points and spikes harmonically (module `repair`) on the heights
    /// less the form, and add the form back. Everything after the first step sees the
    /// heights less a least-squares form, so adding a plane (or, with `judge =
    /// Curvature`, a quadric) to z changes nothing but that form, to round-off.
    /// [`Repair::Refuse`] refuses the first non-finite height, else the worst spike; more
    /// than [`MAX_FILL_FRACTION`] of the map to fill is refused. What was found and
    /// filled is in [`Surface::repair_report`]. What the checks allocate is checked
    /// against `memory` first ([`Surface::check_measured_memory`]).
    #[allow(clippy::too_many_arguments)]
    pub fn measured_judged(
        mut z: Vec<f64>,
        n0: usize,
        n1: usize,
        spacing: Spacing,
        periodic: bool,
        repair: Repair,
        judge: Detrend,
        memory: &MemoryLimit,
    ) -> Result<Self, SurfaceError> {
        if z.len() != n0 * n1 || n0 < 3 || n1 < 3 {
            return Surface::with_spacing(z, n0, n1, spacing, periodic);
        }
        Self::check_measured_memory(n0, n1, memory)?;
        let (dx, dy) = spacing.pixel(n0, n1)?;
        let judge = if periodic { Detrend::None } else { judge };
        let invalid: Vec<bool> = z.iter().map(|v| !v.is_finite()).collect();
        let n_invalid = invalid.iter().filter(|&&b| b).count();
        if repair == Repair::Refuse
            && let Some(k) = invalid.iter().position(|&b| b)
        {
            return Err(SurfaceError::NonFinite {
                row: k / n1,
                col: k % n1,
                value: z[k],
            });
        }
        let total = z.len() as f64;
        if n_invalid as f64 > MAX_FILL_FRACTION * total {
            return Err(SurfaceError::TooLittleValid {
                fraction: n_invalid as f64 / total,
                limit: MAX_FILL_FRACTION,
            });
        }
        let valid: Vec<bool> = invalid.iter().map(|b| !b).collect();
        // The form is zero on a periodic grid (`judge` None): no form and no copy of the
        // heights less it are held then (z − 0 is z, bit for bit).
        let fit = |z: &[f64], keep: &[bool]| {
            (judge != Detrend::None).then(|| form::fit_form(z, keep, n0, n1, judge))
        };
        let residual = |form: &Option<Vec<f64>>| -> std::borrow::Cow<'_, [f64]> {
            match form {
                Some(f) => z.iter().zip(f).map(|(a, f)| a - f).collect(),
                None => std::borrow::Cow::Borrowed(&z[..]),
            }
        };
        let form = fit(&z, &valid);
        drop(valid);
        // round-off of the heights: 1e-12 × the largest |z| (a plane of 1e-5 m leaves
        // ~1e-21 m of noise after its removal; 1e-17 m is no roughness)
        // and the heights' quantum (an instrument's integer heights times its step): a
        // smooth form less its fit leaves residuals of a few steps, which are no spikes
        let floor = (1e-12
            * z.iter()
                .filter(|v| v.is_finite())
                .fold(0.0_f64, |m, v| m.max(v.abs())))
        .max(height_quantum(&z));
        let bad = suspect_points(&residual(&form), n0, n1, periodic, floor);
        if repair == Repair::Refuse {
            // the worst spike: a spike also disturbs its neighbours' predictions a little
            let worst = bad.iter().fold(None::<(usize, f64)>, |w, &(k, s)| match w {
                Some((_, ws)) if ws >= s => w,
                _ => Some((k, s)),
            });
            if let Some((k, sigmas)) = worst {
                return Err(SurfaceError::Spike {
                    row: k / n1,
                    col: k % n1,
                    value: z[k],
                    sigmas,
                });
            }
            return Surface::with_spacing(z, n0, n1, spacing, periodic);
        }
        let mut spike = vec![false; z.len()];
        for &(k, _) in &bad {
            spike[k] = !invalid[k];
        }
        drop(bad);
        let fill: Vec<bool> = invalid.iter().zip(&spike).map(|(a, b)| *a || *b).collect();
        let n_fill = fill.iter().filter(|&&b| b).count();
        let mut fill_iterations = 0;
        if n_fill as f64 > MAX_FILL_FRACTION * total {
            return Err(SurfaceError::TooLittleValid {
                fraction: n_fill as f64 / total,
                limit: MAX_FILL_FRACTION,
            });
        }
        if n_fill > 0 {
            memory.check(
                format!("repairing {n_fill} points of a {n0}×{n1} measured surface"),
                crate::resources::bytes_for(
                    (n0 as u64).saturating_mul(n1 as u64),
                    REPAIR_BYTES_PER_POINT,
                )
                .saturating_add(crate::resources::bytes_for(
                    n_fill as u64,
                    REPAIR_BYTES_PER_FILLED_POINT,
                )),
            )?;
            let form = if n_fill > n_invalid {
                drop(form);
                let kept: Vec<bool> = fill.iter().map(|b| !b).collect();
                fit(&z, &kept)
            } else {
                form
            };
            let mut r = residual(&form).into_owned();
            let iterations = repair::harmonic_fill(&mut r, &fill, n0, n1, (dx, dy), periodic)
                .map_err(|e| match e {
                    repair::FillError::NothingValid => SurfaceError::TooLittleValid {
                        fraction: 1.0,
                        limit: MAX_FILL_FRACTION,
                    },
                    repair::FillError::NotConverged {
                        points,
                        iterations,
                        residual,
                    } => SurfaceError::Unsupported(format!(
                        "repair: the harmonic fill of {points} points did not converge in \
                         {iterations} conjugate-gradient iterations (relative residual {residual:e})"
                    )),
                })?;
            for k in (0..z.len()).filter(|&k| fill[k]) {
                z[k] = r[k] + form.as_ref().map_or(0.0, |f| f[k]);
            }
            fill_iterations = iterations;
        }
        let (ic, il) = repair::clusters(&invalid, n0, n1, periodic);
        let (sc, sl) = repair::clusters(&spike, n0, n1, periodic);
        let (fc, fl) = repair::clusters(&fill, n0, n1, periodic);
        let report = RepairReport {
            invalid: n_invalid,
            invalid_clusters: ic,
            invalid_largest: il,
            spikes: n_fill - n_invalid,
            spike_clusters: sc,
            spike_largest: sl,
            repaired: n_fill,
            clusters: fc,
            largest: fl,
            fraction: n_fill as f64 / total,
            iterations: fill_iterations,
        };
        let mut s = Surface::with_spacing(z, n0, n1, spacing, periodic)?;
        s.repaired = n_fill;
        s.report = Some(report);
        s.filled = (0..fill.len()).filter(|&k| fill[k]).collect();
        Ok(s)
    }

    /// What checking the measured heights found and what repair filled (`None` for a
    /// surface not read with [`Repair::Median`]).
    pub fn repair_report(&self) -> Option<&RepairReport> {
        self.report.as_ref()
    }

    /// Flat indices (row-major) of the points repair filled.
    pub fn filled_points(&self) -> &[usize] {
        &self.filled
    }

    /// Number of points replaced when the surface was read with [`Repair::Median`].
    pub fn repaired(&self) -> usize {
        self.repaired
    }

    /// The composite surface of two rough bodies: heights h = h_A + h_B at the same
    /// in-plane points (physics.md §6.1: frictionless small-slope contact of two rough
    /// surfaces is that of their sum against a smooth one), `counterface` given as
    /// seen from this body. Refuses different grids, pixel sizes (relative 1e-9) or
    /// periodicity. The log and warnings keep this surface's, plus one line.
    pub fn plus_counterface(&self, counterface: &Surface) -> Result<Surface, SurfaceError> {
        let c = counterface;
        let differs =
            |what, this: String, other: String| SurfaceError::Mismatch { what, this, other };
        if self.shape() != c.shape() {
            return Err(differs(
                "grid",
                format!("{}×{}", self.n0, self.n1),
                format!("{}×{}", c.n0, c.n1),
            ));
        }
        let near = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
        if !(near(self.dx, c.dx) && near(self.dy, c.dy)) {
            return Err(differs(
                "pixel size",
                format!("{:e} × {:e} m", self.dx, self.dy),
                format!("{:e} × {:e} m", c.dx, c.dy),
            ));
        }
        if self.periodic != c.periodic {
            return Err(differs(
                "periodicity",
                format!("periodic = {}", self.periodic),
                format!("periodic = {}", c.periodic),
            ));
        }
        let z = self.z.iter().zip(&c.z).map(|(a, b)| a + b).collect();
        let mut s = Surface::with_spacing(
            z,
            self.n0,
            self.n1,
            Spacing::Pixel(self.dx, self.dy),
            self.periodic,
        )?;
        s.repaired = self.repaired + c.repaired;
        s.report = self.report;
        let mut filled: Vec<usize> = self.filled.iter().chain(&c.filled).copied().collect();
        filled.sort_unstable();
        filled.dedup();
        s.filled = filled;
        s.unit_from_file = self.unit_from_file && c.unit_from_file;
        s.log = self.log.clone();
        s.log
            .extend(c.log.iter().map(|l| format!("counterface: {l}")));
        s.log.push(format!(
            "counterface heights added point by point (its RMS {:e} m): the composite surface h_A + h_B is solved against a smooth counterface",
            c.rms()
        ));
        s.warnings = self.warnings.clone();
        s.warnings
            .extend(c.warnings.iter().map(|w| format!("counterface: {w}")));
        s.form = self.form;
        Ok(s)
    }
    /// What the reader did, one line each (units, repairs, form removal, metadata).
    pub fn log(&self) -> &[String] {
        &self.log
    }
    /// Non-fatal problems found while reading (plausibility: [`Surface::stats`]).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }
    pub(crate) fn note(&mut self, line: String) {
        self.log.push(line);
    }

    /// Height at grid point (i, j) (m).
    pub fn z(&self, i: usize, j: usize) -> f64 {
        self.z[i * self.n1 + j]
    }
    /// All heights, row-major (m).
    pub fn heights(&self) -> &[f64] {
        &self.z
    }
    /// The heights, row-major (m), taken out of the surface (no copy: a solver that
    /// keeps its own heights takes them this way).
    pub fn into_heights(self) -> Vec<f64> {
        self.z
    }
    /// Grid shape (n0, n1); n0 runs along x.
    pub fn shape(&self) -> (usize, usize) {
        (self.n0, self.n1)
    }
    /// Pixel sizes (dx, dy) (m): grid point (i, j) sits at (i·dx, j·dy).
    pub fn pixel_size(&self) -> (f64, f64) {
        (self.dx, self.dy)
    }
    /// Physical extent (Lx, Ly) = (n0·dx, n1·dy) (m).
    pub fn extent(&self) -> (f64, f64) {
        (self.n0 as f64 * self.dx, self.n1 as f64 * self.dy)
    }
    /// Nominal area A₀ = Lx·Ly (m²).
    pub fn area(&self) -> f64 {
        let (a, b) = self.extent();
        a * b
    }
    /// Whether the surface is one cell of a periodic pattern.
    pub fn is_periodic(&self) -> bool {
        self.periodic
    }
    /// Mean height z̄ (m).
    pub fn mean(&self) -> f64 {
        self.z.iter().sum::<f64>() / self.z.len() as f64
    }
    /// RMS height about the mean (m).
    pub fn rms(&self) -> f64 {
        let m = self.mean();
        (self.z.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / self.z.len() as f64).sqrt()
    }
}

fn median(v: &mut [f64]) -> f64 {
    let m = v.len() / 2;
    let (_, x, _) = v.select_nth_unstable_by(m, f64::total_cmp);
    let x = *x;
    if v.len() % 2 == 1 {
        x
    } else {
        let lo = v[..m].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lo + x)
    }
}

/// The smooth prediction of height k from its neighbours (m): the median over the four
/// directions (x, y and the two diagonals) of the linear interpolation between the two
/// neighbours along that direction, or, at a non-periodic edge, the linear
/// extrapolation from the two on one side. Only points with `usable` take part; None
/// without any direction. A smooth surface, a tilt or a lay is predicted to second order
/// in the pixel size; one outlier among the neighbours spoils one direction at most.
fn predict(
    z: &[f64],
    n0: usize,
    n1: usize,
    periodic: bool,
    k: usize,
    usable: &dyn Fn(usize) -> bool,
) -> Option<f64> {
    let (i, j) = ((k / n1) as isize, (k % n1) as isize);
    let (n0i, n1i) = (n0 as isize, n1 as isize);
    let at = |a: isize, b: isize| -> Option<f64> {
        let m = if periodic {
            (a.rem_euclid(n0i) * n1i + b.rem_euclid(n1i)) as usize
        } else if (0..n0i).contains(&a) && (0..n1i).contains(&b) {
            (a * n1i + b) as usize
        } else {
            return None;
        };
        (m != k && usable(m) && z[m].is_finite()).then_some(z[m])
    };
    let mut p = [0.0; 4];
    let mut n = 0;
    for (di, dj) in [(1, 0), (0, 1), (1, 1), (1, -1)] {
        let v = match (at(i - di, j - dj), at(i + di, j + dj)) {
            (Some(a), Some(b)) => Some(0.5 * (a + b)),
            (None, Some(b)) => at(i + 2 * di, j + 2 * dj).map(|c| 2.0 * b - c),
            (Some(a), None) => at(i - 2 * di, j - 2 * dj).map(|c| 2.0 * a - c),
            (None, None) => None,
        };
        if let Some(v) = v {
            p[n] = v;
            n += 1;
        }
    }
    (n > 0).then(|| median(&mut p[..n]))
}

/// The smallest positive difference between two of the finite heights `z` (m): the
/// height step of an instrument that stores integers (0 when all are equal). On
/// floating-point heights it is far below any roughness.
fn height_quantum(z: &[f64]) -> f64 {
    let mut v: Vec<f64> = z.iter().copied().filter(|v| v.is_finite()).collect();
    v.sort_unstable_by(f64::total_cmp);
    let step = v
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|&d| d > 0.0)
        .fold(f64::INFINITY, f64::min);
    if step.is_finite() { step } else { 0.0 }
}

/// Non-finite heights and spikes (module documentation), in row-major order, each
/// with its distance from its smooth prediction ([`predict`]) in robust standard
/// deviations of those residuals over the map (∞ for a non-finite height).
///
/// σ_r is at least `floor` (m): the round-off of the heights the residuals were taken
/// from (a form subtracted from large heights leaves noise of ~1e-16 × their size,
/// which is not a spike).
fn suspect_points(
    z: &[f64],
    n0: usize,
    n1: usize,
    periodic: bool,
    floor: f64,
) -> Vec<(usize, f64)> {
    // the finite heights' mean and RMS, summed in order without a copy of them
    let finite = || z.iter().copied().filter(|v| v.is_finite());
    let nf = finite().count().max(1) as f64;
    let mean = finite().sum::<f64>() / nf;
    let rms = (finite().map(|v| (v - mean) * (v - mean)).sum::<f64>() / nf).sqrt();
    let all = |_: usize| true;
    let res: Vec<f64> = (0..z.len())
        .map(|k| match predict(z, n0, n1, periodic, k, &all) {
            Some(p) if z[k].is_finite() => z[k] - p,
            _ => f64::NAN,
        })
        .collect();
    let mut r: Vec<f64> = res.iter().copied().filter(|v| v.is_finite()).collect();
    let sigma = if r.is_empty() {
        0.0
    } else {
        let c = median(&mut r);
        // the absolute deviations overwrite the residuals' copy (the median of a set
        // does not depend on its order)
        r.iter_mut().for_each(|v| *v = (*v - c).abs());
        1.4826 * median(&mut r)
    }
    .max(1e-3 * rms)
    .max(floor);
    let mut out = Vec::new();
    for k in 0..z.len() {
        if !z[k].is_finite() {
            out.push((k, f64::INFINITY));
            continue;
        }
        let dev = res[k].abs();
        if dev > SPIKE_LIMIT * sigma {
            out.push((
                k,
                if sigma > 0.0 {
                    dev / sigma
                } else {
                    f64::INFINITY
                },
            ));
        }
    }
    out
}

#[cfg(all(test, feature = "npy", feature = "spectral"))]
mod tests {
    use super::*;
    use ndarray::Array2;

    fn params() -> GenerateParams {
        GenerateParams {
            size: 1e-3,
            grid: 128,
            fractal_dimension: 2.4,
            k_min: 2.0,
            k_max: 10.0,
            rms: 3.4e-6,
            seed: 7,
        }
    }

    /// Reproducible, zero mean, exact RMS, and the spectrum is confined to the band:
    /// a forward FFT of the result has no power outside k_min ≤ |k| ≤ k_max.
    #[test]
    fn generated_surface_band_and_rms() {
        let s = Surface::generate(&params()).unwrap();
        let s2 = Surface::generate(&params()).unwrap();
        assert_eq!(s, s2);
        assert!(s.mean().abs() < 1e-18);
        assert!((s.rms() - 3.4e-6).abs() < 1e-12 * 3.4e-6);
        let n = 128;
        let plan = crate::fft::RealFft2::new(n, n).unwrap();
        let mut work = plan.work();
        plan.forward(s.heights(), &mut work).unwrap();
        let (mut inside, mut outside) = (0.0, 0.0);
        for kx in 0..=n / 2 {
            for ky in 0..n {
                let k = (kx as f64).hypot(crate::fft::signed_index(ky, n) as f64);
                let p = work.spec[kx * n + ky].norm_sqr();
                if (2.0..=10.0).contains(&k) {
                    inside += p;
                } else {
                    outside += p;
                }
            }
        }
        assert!(outside < 1e-20 * inside, "{outside} {inside}");
        let other = Surface::generate(&GenerateParams {
            seed: 8,
            ..params()
        })
        .unwrap();
        assert_ne!(s, other);
    }

    #[test]
    fn bad_parameters_name_the_field() {
        let e = Surface::generate(&GenerateParams {
            size: -1.0,
            ..params()
        })
        .unwrap_err();
        assert!(e.to_string().contains("generate.size"), "{e}");
        let e = Surface::generate(&GenerateParams {
            k_max: 1.0,
            ..params()
        })
        .unwrap_err();
        assert!(e.to_string().contains("generate.k_max"), "{e}");
        let e = Surface::generate(&GenerateParams {
            rms: 0.0,
            ..params()
        })
        .unwrap_err();
        assert!(e.to_string().contains("generate.rms"), "{e}");
        assert!(Surface::new(vec![0.0; 9], 3, 3, -1.0, true).is_err());
        assert!(Surface::new(vec![f64::NAN; 9], 3, 3, 1.0, true).is_err());
    }

    #[test]
    fn text_reader_roundtrip_and_errors() {
        let dir = std::env::temp_dir().join(format!("strata-surface-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("s.txt");
        std::fs::write(
            &f,
            "# heights\n1e-6 2e-6 3e-6\n4e-6,5e-6,6E-6\n\n7e-6 8e-6 9e-6\n",
        )
        .unwrap();
        let s = Surface::read_text(&f, 3e-3, false).unwrap();
        assert_eq!(s.shape(), (3, 3));
        assert_eq!(s.z(1, 2), 6e-6);
        assert_eq!(s.z(2, 2), 9e-6);
        assert!((s.pixel_size().0 - 1e-3).abs() < 1e-18 && s.pixel_size().0 == s.pixel_size().1);
        std::fs::write(&f, "1 2 3\n4 5\n6 7 8\n").unwrap();
        let e = Surface::read_text(&f, 1.0, false).unwrap_err();
        assert!(e.to_string().contains("ragged"), "{e}");
        std::fs::write(&f, "1 2 x\n4 5 6\n6 7 8\n").unwrap();
        assert!(Surface::read_text(&f, 1.0, false).is_err());
        let e = Surface::read_text(&dir.join("missing.txt"), 1.0, false).unwrap_err();
        assert!(e.to_string().contains("missing.txt"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Spikes and non-finite heights: refused with their index, or repaired on request;
    /// no false alarm on rough surfaces with content up to the Nyquist wavenumber
    /// (D_f = 2.0, 2.4, 2.9 on 256²: no point flagged).
    #[test]
    fn spikes_and_missing_values() {
        let n = 16;
        let base: Vec<f64> = (0..n * n)
            .map(|k| 1e-6 * (((k / n) as f64 * 0.7).sin() + ((k % n) as f64 * 0.4).cos()))
            .collect();
        let mut z = base.clone();
        z[3 * n + 9] += 1e-4;
        let e = Surface::measured(z.clone(), n, n, 1e-3, true, Repair::Refuse).unwrap_err();
        assert!(
            matches!(e, SurfaceError::Spike { row: 3, col: 9, .. }),
            "{e}"
        );
        let s = Surface::measured(z, n, n, 1e-3, true, Repair::Median).unwrap();
        assert_eq!(s.repaired(), 1);
        assert!((s.z(3, 9) - base[3 * n + 9]).abs() < 1e-6);
        let mut z = base.clone();
        z[5] = f64::NAN;
        z[n * n - 1] = f64::NEG_INFINITY;
        let e = Surface::measured(z.clone(), n, n, 1e-3, false, Repair::Refuse).unwrap_err();
        assert!(
            matches!(e, SurfaceError::NonFinite { row: 0, col: 5, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("row 0, column 5"), "{e}");
        let s = Surface::measured(z, n, n, 1e-3, false, Repair::Median).unwrap();
        assert_eq!(s.repaired(), 2);
        assert!(s.heights().iter().all(|v| v.is_finite()));
        let mut z = base.clone();
        for i in 4..7 {
            for j in 4..7 {
                z[i * n + j] = f64::NAN;
            }
        }
        // a 3 × 3 cluster (refused before: its centre had no valid neighbour) is filled
        let s = Surface::measured(z.clone(), n, n, 1e-3, false, Repair::Median).unwrap();
        let r = s.repair_report().unwrap();
        assert_eq!((r.repaired, r.clusters, r.largest), (9, 1, 9), "{r:?}");
        let err = (0..n * n)
            .map(|k| (s.heights()[k] - base[k]).abs())
            .fold(0.0, f64::max);
        // maximum principle: |error| ≤ max|∇²z| a²/4 with a = 2 pixels from the hole's
        // centre to its valid boundary, max|∇²z| = 1e-6 (0.7² + 0.4²) per pixel²:
        // 6.5e-7 m (measured 3.0e-7 m)
        assert!(err < 1e-6 * (0.49 + 0.16) * 4.0 / 4.0, "{err:e}");
        // more than half of the map invalid: refused, naming the fraction
        let mut z = base.clone();
        z[..n * n / 2 + 1].fill(f64::NAN);
        let e = Surface::measured(z, n, n, 1e-3, false, Repair::Median).unwrap_err();
        assert!(
            matches!(e, SurfaceError::TooLittleValid { .. }) && e.to_string().contains("50.4 %"),
            "{e}"
        );
        // Flat: nothing to flag.
        assert!(Surface::measured(vec![2.0; 16], 4, 4, 1.0, true, Repair::Refuse).is_ok());
        // Rough surfaces with content up to the Nyquist wavenumber: no false alarm.
        for d in [2.0, 2.4, 2.9] {
            let s = Surface::generate(&GenerateParams {
                grid: 256,
                fractal_dimension: d,
                k_max: 128.0,
                k_min: 1.0,
                ..params()
            })
            .unwrap();
            let worst = suspect_points(s.heights(), 256, 256, true, 0.0);
            assert!(worst.is_empty(), "D_f {d}: {worst:?}");
        }
    }

    /// Smooth non-periodic profiles with a lay (an extruded sine, 27.5–227 σ
    /// before) and tilted ones raise no false alarm, edges included; a spike on them is
    /// the only point flagged, and its repair touches that point alone (the edge rows
    /// were rewritten before).
    #[test]
    fn lays_and_tilts_are_not_spikes() {
        let (n0, n1) = (64, 48);
        let tau = std::f64::consts::TAU;
        let lay = |i: usize, _j: usize| 1e-6 * (tau * i as f64 / 10.0).sin();
        let tilt = |i: usize, j: usize| 2e-7 * i as f64 - 5e-8 * j as f64;
        let sharp = |i: usize, j: usize| 1e-6 * (tau * (i as f64 / 3.1 + j as f64 / 17.0)).sin();
        let field = |f: &dyn Fn(usize, usize) -> f64| -> Vec<f64> {
            (0..n0 * n1)
                .map(|k| f(k / n1, k % n1) + tilt(k / n1, k % n1))
                .collect()
        };
        // no false alarm, even 3.1 pixels per period
        for (name, f) in [
            ("lay", &lay as &dyn Fn(usize, usize) -> f64),
            ("tilt", &tilt),
            ("sharp lay", &sharp),
        ] {
            let worst = suspect_points(&field(f), n0, n1, false, 0.0);
            assert!(
                worst.is_empty(),
                "{name}: {:?}",
                &worst[..worst.len().min(5)]
            );
        }
        // spikes of 20 µm, one on an edge row, one in a corner column: those alone are
        // flagged and repaired, to the second-order error of the linear prediction
        // (lay: (2π/10)² × 1 µm = 3.9e-7 m at an edge; measured 3.6e-7; tilt: exact)
        for (name, f, bound) in [
            (
                "lay",
                &lay as &dyn Fn(usize, usize) -> f64,
                (tau / 10.0).powi(2) * 1e-6,
            ),
            ("tilt", &tilt, 1e-18),
        ] {
            let z = field(f);
            let mut zs = z.clone();
            for k in [7 * n1 + 11, 5, n1 * (n0 - 1) + 20] {
                zs[k] += 2e-5;
            }
            let flagged: Vec<usize> = suspect_points(&zs, n0, n1, false, 0.0)
                .iter()
                .map(|b| b.0)
                .collect();
            assert_eq!(flagged, vec![5, 7 * n1 + 11, n1 * (n0 - 1) + 20], "{name}");
            let s = Surface::measured(zs, n0, n1, 1e-3, false, Repair::Median).unwrap();
            assert_eq!(s.repaired(), 3, "{name}");
            let err = s
                .heights()
                .iter()
                .zip(&z)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            eprintln!("{name}: repaired to within {err:e} m of the profile");
            assert!(
                err < bound,
                "{name}: repaired to within {err:e} m of the profile"
            );
        }
    }

    /// Wrong dtype and wrong dimensionality of a .npy are reported as such.
    #[test]
    fn npy_errors() {
        use ndarray_npy::WriteNpyExt;
        let dir = std::env::temp_dir().join(format!("strata-npy-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f32file = dir.join("f32.npy");
        let a = Array2::<f32>::zeros((4, 4));
        a.write_npy(std::fs::File::create(&f32file).unwrap())
            .unwrap();
        let e = Surface::read_npy(&f32file, 1e-3, true).unwrap_err();
        assert!(e.to_string().contains("dtype"), "{e}");
        let onedim = dir.join("1d.npy");
        let b = ndarray::Array1::<f64>::zeros(16);
        b.write_npy(std::fs::File::create(&onedim).unwrap())
            .unwrap();
        let e = Surface::read_npy(&onedim, 1e-3, true).unwrap_err();
        assert!(e.to_string().contains("shape"), "{e}");
        let good = dir.join("good.npy");
        let c = Array2::<f64>::from_shape_fn((4, 5), |(i, j)| (i * 10 + j) as f64);
        c.write_npy(std::fs::File::create(&good).unwrap()).unwrap();
        let s = Surface::read_npy(&good, 4e-3, true).unwrap();
        assert_eq!(s.shape(), (4, 5));
        assert_eq!(s.z(2, 3), 23.0);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
