//! Surrogate tables of the second-order asperity law (physics.md §4): χ(a), ζ(a),
//! g(a, r) and S(ρ) of one material stack or of a family of stacks, stored in
//! nondimensional form and interpolated in nanoseconds.
//!
//! # Contents and axes
//! * `x` axis: c_x = ln(a/h₁), uniform (h₁ = top layer thickness).
//! * optional family axis: c_f = ln(E_v/E₁), uniform, where E_v is the Young modulus of
//!   one chosen layer (`Vary::Layer(i)`, 1-based, i ≥ 2) or of the elastic base.
//! * χ, ζ: arrays `[member][x]`, dimensionless.
//! * g: stored as g·r/a³ (dimensionless, bounded: → (4/3)k_z(0) far away) over
//!   (x, w) with w = asinh(√((r − a)/h₁)). This coordinate (rather than a/r, which
//!   physics.md suggests) keeps the data smooth where it matters: near the contact
//!   edge the half-space part behaves like (r − a)^{3/2}, a polynomial in w; the
//!   kernel's scales h₁ … H sit at fixed w ≈ 1 … 2.5 whatever a is (on the a/r axis
//!   they crowd into a/r → 0 for small a — measured errors ~1e-3 there), and w grows
//!   like ½ ln r far away. g is analytic in r at the edge (k_z decays exponentially),
//!   so g·r/a³ is even in w: its interpolant takes zero w-slope at w = 0
//!   (`interp::Grid2::even_in_y`); a one-sided slope there would add a spurious
//!   √(r − a) term whose a-derivative diverges at the edge (the I model differentiates
//!   g in a and r there). For r − a > h₁ sinh²(w_max) (the join: 20 H by default,
//!   farther out when the builder needs it) g is the far field of [`far`]:
//!   k_z(0)·HS(a, r) plus `far_terms` Laplacian corrections k_{2m}(−Δ_r)^m HS from the
//!   even Taylor coefficients of k_z (exact to all orders on a rigid base with none).
//!   Its error is measured by the builder at 1, 2 and 4 × the join and stored in the
//!   header (`far_field_error`); `strata table check` re-measures it beyond the join.
//! * S: arrays `[member][s]` over c_s = ln(ρ h₁).
//!
//! A table is nondimensional: a stack whose thicknesses are all scaled by one factor
//! and whose moduli are all scaled by another is served by the same table.
//!
//! # Out of range
//! * a/h₁ below the x range: χ = 1 + (χ_lo − 1)(x/x_lo)³, ζ = 1 + (ζ_lo − 1)(x/x_lo)
//!   (the leading small-a orders: I₀ − I₁ = O(a³), I₀ = O(a)); g = (a/a_lo)³ g(a_lo, r)
//!   (c(au) → 2/3), both with relative error O(x_lo).
//! * a/h₁ above the x range: elastic base, χ → E*_b/E*₁ and ζ → 1 with the 1/x
//!   approach continued from the last node; rigid base, the C¹ power-law continuation
//!   of the last node (χ grows like the thin-layer limit up to a logarithm). g is the
//!   far field beyond the join, k_z(0)·HS closer in. These continuations are approximate; use
//!   [`TableLaw::try_chi_zeta`] / [`TableLaw::try_g`] to refuse instead.
//! * ρh₁ below the S range: linear approach to S(0); above: S = 1 (|S − 1| < 1e-30).
//!
//! # Stated tolerance
//! Every table states a tolerance (`Header::tolerance`, default 1e-4): χ and ζ
//! relative, g absolute in units of (4/3)a³/r, both tabulated and far field. The
//! builder measures the errors against direct quadrature and refuses a table above it.
//!
//! The file format lives in [`codec`] (bincode 2.0.1, serde), and interpolation in
//! [`interp`] (one mechanism for every array).
//!
//! # Why not the `splines` crate
//! In one dimension the interpolant is representable exactly by `splines` 5.0: a C¹
//! cubic Hermite piece on a uniform grid is the cubic Bézier with control points
//! p_k + m_k/3 and p_{k+1} − m_{k+1}/3, i.e. `Interpolation::Bezier(p_k + m_k/3)` keys
//! with mirrored tangents (m = Δ·f′, the node slopes of [`interp::node_slopes`]).
//! `cargo bench -p strata-benches --bench table` builds exactly that spline on the χ
//! nodes of the shipped table's E₂/E₁ = 5 member, asserts it agrees with
//! [`interp::Pair1`] to 1.5e-15, and times both in one run. Measured side by side
//! (2 cores, load ≈ 12, two runs): hand-written 40.0 / 31.2 ns, `splines` 74.2 /
//! 68.6 ns per lookup: 1.9–2.2× slower (its binary search over the keys against our
//! O(1) cell index on a uniform grid), beyond the 1.5× allowed. It also lacks what the
//! runtime needs: the 2-D g table (bicubic tensor product; `splines` is 1-D keyframes
//! only), the exact derivatives dχ/da, dζ/da for the Newton solvers, and a panic-free
//! lookup (`sample` unwraps a float comparison, so a NaN argument panics). So the
//! hand-written scheme stays; `splines` would have cost no crate budget (no
//! dependencies with `default-features = false`), so the crate count is not the reason.

pub mod codec;
#[cfg(feature = "npy")]
pub mod export;
pub mod far;
pub mod interp;
pub mod lobatto;

use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::law::{AsperityLaw, half_space_bracket};
use crate::stack::{Base, Bodies, Counterface, Solid, Stack, StackError};
pub use interp::Axis;

/// Version of the table format written by this build.
pub const FORMAT_VERSION: u32 = 2;

/// Default stated tolerance of a table ([`Header::tolerance`]).
pub const DEFAULT_TOLERANCE: f64 = 1e-4;

/// Errors reading, validating or using a table.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum TableError {
    #[error("cannot access table file {path}: {message}")]
    Io { path: String, message: String },
    #[error("not a strata table file (bad signature)")]
    NotATable,
    #[error(
        "table file format version {found} is not supported (this strata reads version {expected}); rebuild the table with `strata table build`"
    )]
    WrongVersion { found: u32, expected: u32 },
    #[error("table file is truncated: expected {expected} bytes, found {found}")]
    Truncated { expected: u64, found: u64 },
    #[error("table file is corrupt: {0}")]
    Corrupt(String),
    #[error("table is inconsistent: {0}")]
    Invalid(String),
    /// The message includes the stack's; no `source` (a chain would print it twice).
    #[error("table stack is invalid: {0}")]
    Stack(StackError),
    #[error("stack is not served by this table: {0}")]
    NotInFamily(String),
    #[error("{what} = {value} is outside the table range [{lo}, {hi}]")]
    OutOfRange {
        what: &'static str,
        value: f64,
        lo: f64,
        hi: f64,
    },
}

impl From<StackError> for TableError {
    fn from(e: StackError) -> Self {
        TableError::Stack(e)
    }
}

/// Which modulus varies along a family axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Vary {
    /// Layer i (1-based, i ≥ 2).
    Layer(usize),
    /// The elastic base.
    Base,
}

impl std::fmt::Display for Vary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Vary::Layer(i) => write!(f, "layer {i}"),
            Vary::Base => write!(f, "base"),
        }
    }
}

/// A family of stacks differing only in one Young modulus.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Family {
    /// The varied modulus.
    pub vary: Vary,
    /// Axis of ln(E_v/E₁).
    pub ratio: Axis,
}

/// Interpolation error measured against direct solves at random off-grid points.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InterpError {
    /// Number of random points.
    pub points: usize,
    /// Seed of the point generator.
    pub seed: u64,
    /// max |χ_table/χ_direct − 1|.
    pub chi: f64,
    /// max |ζ_table/ζ_direct − 1|.
    pub zeta: f64,
    /// max |g_table − g_direct| / ((4/3) a³/r), r − a inside the tabulated range.
    pub g: f64,
    /// max |g_far − g_direct| / ((4/3) a³/r) at random points beyond the tabulated
    /// range (r − a from the join out to ~20× the join).
    pub far: f64,
}

impl InterpError {
    /// The first measured error above `tol`, as (what, measured), if any.
    pub fn exceeds(&self, tol: f64) -> Option<(&'static str, f64)> {
        [
            ("chi interpolation (relative)", self.chi),
            ("zeta interpolation (relative)", self.zeta),
            ("g interpolation (of (4/3)a^3/r)", self.g),
            ("g far field (of (4/3)a^3/r)", self.far),
        ]
        .into_iter()
        .find(|&(_, e)| e.is_nan() || e > tol)
    }
}

/// Table header.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// [`FORMAT_VERSION`] at build time.
    pub format_version: u32,
    /// Version of strata that built the table.
    pub strata_version: String,
    /// Build time, seconds since the Unix epoch (SOURCE_DATE_EPOCH when set, so a
    /// rebuild reproduces the file byte for byte).
    pub build_time: u64,
    /// The first body (for a family: the member given to the builder; the varied
    /// modulus is replaced along the family axis).
    pub stack: Stack,
    /// What the first body is pressed against: a rigid flat, or the elastic
    /// counterface of a pair table. Not in the header's serde form: the file stores
    /// an elastic counterface beside the table (`table::codec`).
    #[serde(skip)]
    pub counterface: Counterface,
    /// Family axis, if any.
    pub family: Option<Family>,
    /// ln(a/h₁) axis.
    pub x: Axis,
    /// w = asinh(√((r − a)/h₁)) axis.
    pub w: Axis,
    /// ln(ρh₁) axis of S.
    pub s: Axis,
    /// max |g_direct − g_far|/((4/3)a³/r) measured at build over every member at
    /// r − a = 1, 2 and 4 × the join distance h₁ sinh²(w_max) (a spread over the x axis).
    pub far_field_error: f64,
    /// Number of correction terms of the far field beyond k_z(0)·HS ([`far`]), chosen
    /// at build (0 on a rigid base, where the leading term is exact).
    pub far_terms: usize,
    /// The stated tolerance: χ, ζ (relative) and g (of (4/3)a³/r, tabulated and far
    /// field) must be within it; `strata table build` and `check` fail otherwise.
    pub tolerance: f64,
    /// Interpolation error measured at build time.
    pub interp_error: Option<InterpError>,
}

/// The table's solid: its first body and counterface.
impl Solid for Header {
    fn first(&self) -> &Stack {
        &self.stack
    }

    fn elastic_counterface(&self) -> Option<&Stack> {
        self.counterface.stack()
    }
}

/// A surrogate table: header and arrays (row-major, member slowest).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Table {
    pub header: Header,
    /// χ `[member][x]`.
    pub chi: Vec<f64>,
    /// ζ `[member][x]`.
    pub zeta: Vec<f64>,
    /// g·r/a³ `[member][x][w]`.
    pub g: Vec<f64>,
    /// S `[member][s]`.
    pub s: Vec<f64>,
    /// k_z(0) per member.
    pub k0: Vec<f64>,
}

/// E_v/E₁ of `stack` for the varied modulus, if it exists.
fn varied_ratio(stack: &Stack, vary: Vary) -> Option<f64> {
    let e1 = stack.layers().first()?.young;
    match vary {
        Vary::Layer(i) if i >= 2 => stack.layers().get(i - 1).map(|l| l.young / e1),
        Vary::Layer(_) => None,
        Vary::Base => match stack.base() {
            Base::Elastic { young, .. } => Some(young / e1),
            Base::Rigid => None,
        },
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}

impl Table {
    /// Number of family members (1 without a family).
    pub fn members(&self) -> usize {
        self.header.family.map_or(1, |f| f.ratio.n)
    }

    /// The member at family coordinate ln(E_v/E₁) = c (the header stack with the
    /// varied modulus replaced, against a rigid flat); the header's bodies themselves
    /// (a pair table's too) without a family.
    pub fn member_stack(&self, c: f64) -> Result<Bodies, TableError> {
        let st = &self.header.stack;
        let Some(fam) = self.header.family else {
            return Ok(self.header.bodies());
        };
        let e1 = st.layers()[0].young;
        let ev = e1 * c.exp();
        let mut layers = st.layers().to_vec();
        let mut base = st.base();
        match fam.vary {
            Vary::Layer(i) => layers[i - 1].young = ev,
            Vary::Base => {
                if let Base::Elastic { poisson, .. } = base {
                    base = Base::Elastic { young: ev, poisson };
                }
            }
        }
        let mut s = Stack::new(layers, base)?;
        s.name = st.name.clone();
        Ok(Bodies::rigid(s))
    }

    /// Checks the header and array sizes, finiteness and the stack.
    pub fn validate(&self) -> Result<(), TableError> {
        let h = &self.header;
        if h.format_version != FORMAT_VERSION {
            return Err(TableError::WrongVersion {
                found: h.format_version,
                expected: FORMAT_VERSION,
            });
        }
        // Re-validate the stack: deserialisation bypasses Stack::new.
        Stack::new(h.stack.layers().to_vec(), h.stack.base())?;
        if let Some(c) = h.counterface.stack() {
            // (the codec re-validated it on decoding; a table built in memory too)
            Stack::new(c.layers().to_vec(), c.base())?;
            if h.family.is_some() {
                return Err(TableError::Invalid(
                    "a table of a stack and its counterface has no family axis".into(),
                ));
            }
        }
        if h.top_thickness().is_none() {
            return Err(TableError::Invalid("the stack has no layers".into()));
        }
        for (name, ax) in [("x", h.x), ("w", h.w), ("s", h.s)] {
            if !ax.is_valid() || ax.n < Axis::MIN_NODES {
                return Err(TableError::Invalid(format!(
                    "axis {name} is malformed: {ax:?}"
                )));
            }
        }
        if !(h.tolerance.is_finite() && h.tolerance > 0.0) {
            return Err(TableError::Invalid(format!(
                "tolerance must be finite and > 0, got {}",
                h.tolerance
            )));
        }
        if h.far_terms > far::FAR_TERMS {
            return Err(TableError::Invalid(format!(
                "far_terms = {} exceeds the {} correction terms this strata knows",
                h.far_terms,
                far::FAR_TERMS
            )));
        }
        if h.w.lo != 0.0 {
            return Err(TableError::Invalid("axis w must start at 0".into()));
        }
        if let Some(f) = h.family {
            if !f.ratio.is_valid() {
                return Err(TableError::Invalid(format!(
                    "family axis is malformed: {:?}",
                    f.ratio
                )));
            }
            if varied_ratio(&h.stack, f.vary).is_none() {
                return Err(TableError::Invalid(format!(
                    "family varies {} which the stack does not have",
                    f.vary
                )));
            }
        }
        let m = self.members();
        let (nx, nw, ns) = (h.x.n, h.w.n, h.s.n);
        // Saturating: a damaged header with huge axes must fail the size check, not
        // overflow (found by tests/table_fuzz.rs).
        let sizes = [
            ("chi", self.chi.len(), m.saturating_mul(nx)),
            ("zeta", self.zeta.len(), m.saturating_mul(nx)),
            ("g", self.g.len(), m.saturating_mul(nx).saturating_mul(nw)),
            ("s", self.s.len(), m.saturating_mul(ns)),
            ("k0", self.k0.len(), m),
        ];
        for (name, have, want) in sizes {
            if have != want {
                return Err(TableError::Invalid(format!(
                    "array {name} has {have} values, expected {want}"
                )));
            }
        }
        for (name, v) in [
            ("chi", &self.chi),
            ("zeta", &self.zeta),
            ("g", &self.g),
            ("s", &self.s),
            ("k0", &self.k0),
        ] {
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(TableError::Invalid(format!(
                    "array {name} has a non-finite value at index {i}"
                )));
            }
        }
        Ok(())
    }

    /// Loads a table file, checking signature, version, length, checksum and contents;
    /// a file larger than the machine's memory limit is refused ([`Table::load_within`]
    /// takes a limit).
    pub fn load(path: &Path) -> Result<Self, TableError> {
        Self::load_within(path, &crate::resources::MemoryLimit::default())
    }

    /// [`Table::load`] of a file no larger than `memory`.
    pub fn load_within(
        path: &Path,
        memory: &crate::resources::MemoryLimit,
    ) -> Result<Self, TableError> {
        let bytes = crate::resources::read_data_file(path, "a table", memory).map_err(|e| {
            TableError::Io {
                path: path.display().to_string(),
                message: e.to_string(),
            }
        })?;
        Self::from_bytes(&bytes)
    }

    /// Writes the table atomically (temporary file in the same directory, then rename).
    pub fn save(&self, path: &Path) -> Result<(), TableError> {
        use std::io::Write;
        let bytes = self.to_bytes()?;
        let io = |e: std::io::Error, p: &Path| TableError::Io {
            path: p.display().to_string(),
            message: e.to_string(),
        };
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "table".into());
        let tmp = path.with_file_name(format!(".{name}.tmp.{}", std::process::id()));
        let result = (|| {
            let mut f = std::fs::File::create(&tmp).map_err(|e| io(e, &tmp))?;
            f.write_all(&bytes).map_err(|e| io(e, &tmp))?;
            f.sync_all().map_err(|e| io(e, &tmp))?;
            std::fs::rename(&tmp, path).map_err(|e| io(e, path))
        })();
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        result
    }

    /// Family coordinate ln(E_v/E₁) of `stack` if the table serves it (same layer
    /// count, base kind, Poisson ratios, thickness ratios h_i/h₁ and modulus ratios
    /// E_i/E₁ except the varied one, which must lie in the family range).
    pub fn family_coordinate<S: Solid + ?Sized>(&self, stack: &S) -> Result<f64, TableError> {
        let t = &self.header;
        let nf = |m: String| TableError::NotInFamily(m);
        match (stack.canonical_pair(), t.canonical_pair()) {
            (None, None) => {}
            (Some((sa, sb)), Some((ta, tb))) => {
                // Both bodies in canonical order (a pair and its swap share a table),
                // each nondimensionalised by the pair's h₁ and E*.
                let rs = (
                    stack.top_thickness().unwrap_or(1.0),
                    stack.contact_modulus(),
                );
                let rt = (t.top_thickness().unwrap_or(1.0), t.contact_modulus());
                let scaled_same = [(&sa, &ta), (&sb, &tb)]
                    .iter()
                    .all(|(s, tt)| same_body(s, tt, rs, rt).is_ok());
                if !scaled_same {
                    return Err(nf(pair_difference(stack, t, rs, rt)));
                }
                return Ok(0.0);
            }
            (Some(_), None) => {
                return Err(nf(
                    "it is pressed against an elastic counterface; the table is of the stack \
                     against a rigid flat (build a table for the pair)"
                        .into(),
                ));
            }
            (None, Some(_)) => {
                return Err(nf(
                    "the table is of a stack against an elastic counterface; this stack is \
                     pressed by a rigid flat"
                        .into(),
                ));
            }
        }
        let (stack, t) = (stack.first(), &t.stack);
        if stack.layers().len() != t.layers().len() {
            return Err(nf(format!(
                "it has {} layers, the table's stack has {}",
                stack.layers().len(),
                t.layers().len()
            )));
        }
        let vary = self.header.family.map(|f| f.vary);
        let (h1s, h1t) = (stack.layers()[0].thickness, t.layers()[0].thickness);
        let (e1s, e1t) = (stack.layers()[0].young, t.layers()[0].young);
        for (i, (ls, lt)) in stack.layers().iter().zip(t.layers()).enumerate() {
            let n = i + 1;
            if !close(ls.thickness / h1s, lt.thickness / h1t) {
                return Err(nf(format!(
                    "layer {n}: thickness ratio h{n}/h1 = {} differs from the table's {}",
                    ls.thickness / h1s,
                    lt.thickness / h1t
                )));
            }
            if (ls.poisson - lt.poisson).abs() > 1e-12 {
                return Err(nf(format!(
                    "layer {n}: poisson = {} differs from the table's {}",
                    ls.poisson, lt.poisson
                )));
            }
            if vary != Some(Vary::Layer(n)) && !close(ls.young / e1s, lt.young / e1t) {
                return Err(nf(format!(
                    "layer {n}: modulus ratio E{n}/E1 = {} differs from the table's {}",
                    ls.young / e1s,
                    lt.young / e1t
                )));
            }
        }
        match (stack.base(), t.base()) {
            (Base::Rigid, Base::Rigid) => {}
            (
                Base::Elastic {
                    young: ys,
                    poisson: ps,
                },
                Base::Elastic {
                    young: yt,
                    poisson: pt,
                },
            ) => {
                if (ps - pt).abs() > 1e-12 {
                    return Err(nf(format!(
                        "base: poisson = {ps} differs from the table's {pt}"
                    )));
                }
                if vary != Some(Vary::Base) && !close(ys / e1s, yt / e1t) {
                    return Err(nf(format!(
                        "base: modulus ratio Eb/E1 = {} differs from the table's {}",
                        ys / e1s,
                        yt / e1t
                    )));
                }
            }
            _ => {
                return Err(nf(
                    "its base kind (rigid/elastic) differs from the table's".into()
                ));
            }
        }
        let Some(fam) = self.header.family else {
            return Ok(0.0);
        };
        let ratio =
            varied_ratio(stack, fam.vary).ok_or_else(|| nf(format!("it has no {}", fam.vary)))?;
        let c = ratio.ln();
        if !fam.ratio.contains(c) {
            return Err(nf(format!(
                "{} modulus ratio {ratio} is outside the table's family range [{}, {}]",
                fam.vary,
                fam.ratio.lo.exp(),
                fam.ratio.hi.exp()
            )));
        }
        Ok(c.clamp(fam.ratio.lo, fam.ratio.hi))
    }

    /// The far-field expansion of g for `stack` (a member of this table's family)
    /// with the header's number of terms: the leading term only on a rigid base.
    pub fn far_field<S: Solid + ?Sized>(&self, stack: &S, k0: f64) -> far::FarField {
        let m = self.header.far_terms;
        if m == 0 || stack.on_rigid_bases() {
            return far::FarField::leading(k0);
        }
        let comp = crate::Compliance::new(stack);
        let mut f = far::FarField::new(&comp, stack.total_thickness());
        f.coeffs.truncate(m + 1);
        f
    }

    /// The asperity law of `stack`, a member of this table's family (interpolated
    /// along the family axis once, here). Refuses stacks the table does not serve.
    pub fn law_for<S: Solid + ?Sized>(&self, stack: &S) -> Result<TableLaw, TableError> {
        let c = self.family_coordinate(stack)?;
        let h = &self.header;
        let (nx, nw, ns) = (h.x.n, h.w.n, h.s.n);
        let (chi, zeta, g, s, k0) = match h.family {
            None => (
                self.chi.clone(),
                self.zeta.clone(),
                self.g.clone(),
                self.s.clone(),
                self.k0[0],
            ),
            Some(f) => (
                interp::slice_leading(&f.ratio, &self.chi, nx, c),
                interp::slice_leading(&f.ratio, &self.zeta, nx, c),
                interp::slice_leading(&f.ratio, &self.g, nx * nw, c),
                interp::slice_leading(&f.ratio, &self.s, ns, c),
                crate::Compliance::new(stack).s(0.0) - 1.0,
            ),
        };
        let h1 = stack
            .top_thickness()
            .ok_or_else(|| TableError::NotInFamily("it has no layers".into()))?;
        Ok(TableLaw {
            e_star: stack.contact_modulus(),
            h1,
            k0,
            point_force: crate::law::PointForce::of_stack(stack),
            far: self.far_field(stack, k0),
            rigid: stack.on_rigid_bases(),
            x: h.x,
            w: h.w,
            s_axis: h.s,
            cz: interp::Pair1::new(h.x, &chi, &zeta),
            g: interp::Grid2::even_in_y(h.x, h.w, &g),
            s,
        })
    }
}

/// Whether body `s` equals body `t` up to the scalings `rs` = (h, E) of its pair and
/// `rt` of the table's: thicknesses h_i/h, moduli E_i/E, Poisson ratios, base.
fn same_body(s: &Stack, t: &Stack, rs: (f64, f64), rt: (f64, f64)) -> Result<(), String> {
    if s.layers().len() != t.layers().len() {
        return Err(format!(
            "it has {} layers, the table's has {}",
            s.layers().len(),
            t.layers().len()
        ));
    }
    for (i, (ls, lt)) in s.layers().iter().zip(t.layers()).enumerate() {
        let n = i + 1;
        if !close(ls.thickness / rs.0, lt.thickness / rt.0)
            || !close(ls.young / rs.1, lt.young / rt.1)
            || (ls.poisson - lt.poisson).abs() > 1e-12
        {
            return Err(format!(
                "layer {n} (h, E, ν) = ({:e} m, {:e} Pa, {}) is not the table's ({:e} m, {:e} Pa, {}) \
                 scaled",
                ls.thickness, ls.young, ls.poisson, lt.thickness, lt.young, lt.poisson
            ));
        }
    }
    match (s.base(), t.base()) {
        (Base::Rigid, Base::Rigid) => Ok(()),
        (
            Base::Elastic {
                young: ys,
                poisson: ps,
            },
            Base::Elastic {
                young: yt,
                poisson: pt,
            },
        ) if (ps - pt).abs() <= 1e-12 && close(ys / rs.1, yt / rt.1) => Ok(()),
        _ => Err("its base differs from the table's".into()),
    }
}

/// The parts of `s` that differ physically from `t` (layers by number, the base), each
/// with both values; empty when the two bodies are the same.
fn physical_differences(s: &Stack, t: &Stack) -> Vec<String> {
    if s.layers().len() != t.layers().len() {
        return vec![format!(
            "it has {} layers, the table's has {}",
            s.layers().len(),
            t.layers().len()
        )];
    }
    let mut out = Vec::new();
    for (i, (ls, lt)) in s.layers().iter().zip(t.layers()).enumerate() {
        if !close(ls.thickness, lt.thickness)
            || !close(ls.young, lt.young)
            || (ls.poisson - lt.poisson).abs() > 1e-12
        {
            out.push(format!(
                "layer {} (h, E, ν) = ({:e} m, {:e} Pa, {}), the table's ({:e} m, {:e} Pa, {})",
                i + 1,
                ls.thickness,
                ls.young,
                ls.poisson,
                lt.thickness,
                lt.young,
                lt.poisson
            ));
        }
    }
    let base = |b: Base| match b {
        Base::Rigid => "rigid".to_string(),
        Base::Elastic { young, poisson } => format!("(E, ν) = ({young:e} Pa, {poisson})"),
    };
    let same_base = match (s.base(), t.base()) {
        (Base::Rigid, Base::Rigid) => true,
        (
            Base::Elastic {
                young: ys,
                poisson: ps,
            },
            Base::Elastic {
                young: yt,
                poisson: pt,
            },
        ) => close(ys, yt) && (ps - pt).abs() <= 1e-12,
        _ => false,
    };
    if !same_base {
        out.push(format!(
            "base {}, the table's {}",
            base(s.base()),
            base(t.base())
        ));
    }
    out
}

/// Why a pair `stack` is not the pair of table stack `t` (which did not match scaled by
/// `rs`, `rt`): the body or counterface and the layer or base that differ, matched
/// against the table's two bodies in whichever order differs least (a pair and its swap
/// share a table); the scaled comparison's message when no part differs in physical
/// units (a pair scaled unevenly).
fn pair_difference<A: Solid + ?Sized, B: Solid + ?Sized>(
    stack: &A,
    t: &B,
    rs: (f64, f64),
    rt: (f64, f64),
) -> String {
    let (Some(sb), Some(tb)) = (stack.elastic_counterface(), t.elastic_counterface()) else {
        return "the table is not of this pair".into();
    };
    let (sa, ta) = (stack.first().clone(), t.first().clone());
    let order = |x: &Stack, y: &Stack| (physical_differences(&sa, x), physical_differences(sb, y));
    let (d1, d2) = (order(&ta, tb), order(tb, &ta));
    let (body, counter) = if d1.0.len() + d1.1.len() <= d2.0.len() + d2.1.len() {
        d1
    } else {
        d2
    };
    let mut parts = Vec::new();
    if !body.is_empty() {
        parts.push(format!("the first body's {}", body.join("; ")));
    }
    if !counter.is_empty() {
        parts.push(format!("the counterface's {}", counter.join("; ")));
    }
    if parts.is_empty() {
        // same bodies physically: the pair differs only by a scaling the table cannot take
        let (ca, cb) = stack.canonical_pair().unwrap_or((sa.clone(), sb.clone()));
        let (ka, kb) = t.canonical_pair().unwrap_or((ta.clone(), tb.clone()));
        for (what, s, tt) in [("body", &ca, &ka), ("counterface", &cb, &kb)] {
            if let Err(m) = same_body(s, tt, rs, rt) {
                return format!("pair's {what}: {m}");
            }
        }
        return "the table is not of this pair".into();
    }
    format!("the table is of another pair: {}", parts.join("; "))
}

/// χ, ζ, g, S of one stack from a table ([`Table::law_for`]).
#[derive(Debug, Clone)]
pub struct TableLaw {
    e_star: f64,
    h1: f64,
    k0: f64,
    /// S(0), S′(0), k₂ of the stack (periodic image sums).
    point_force: crate::law::PointForce,
    /// Far field of g beyond the tabulated range (r − a > h₁ sinh²(w_max)).
    far: far::FarField,
    rigid: bool,
    x: Axis,
    w: Axis,
    s_axis: Axis,
    /// χ and ζ against ln(a/h₁).
    cz: interp::Pair1,
    /// g·r/a³ against (ln(a/h₁), w).
    g: interp::Grid2,
    s: Vec<f64>,
}

impl TableLaw {
    /// Range of contact radii (m) covered by the table.
    pub fn a_range(&self) -> (f64, f64) {
        (self.h1 * self.x.lo.exp(), self.h1 * self.x.hi.exp())
    }

    /// k_z(0) of the stack.
    pub fn k0(&self) -> f64 {
        self.k0
    }

    /// The join distance (m): g is tabulated for r − a ≤ h₁ sinh²(w_max) and is the
    /// far field ([`far`]) beyond.
    pub fn join(&self) -> f64 {
        self.h1 * self.w.hi.sinh().powi(2)
    }

    /// The far-field expansion used beyond [`TableLaw::join`].
    pub fn far_field(&self) -> &far::FarField {
        &self.far
    }

    /// (χ, dχ/da, ζ, dζ/da) with the out-of-range rules of the module documentation.
    /// a in m; a ≤ 0 gives the a → 0 limit (1, 0, 1, 0).
    pub fn chi_zeta_with_derivs(&self, a: f64) -> (f64, f64, f64, f64) {
        if a.is_nan() {
            return (f64::NAN, f64::NAN, f64::NAN, f64::NAN);
        }
        if a <= 0.0 {
            return (1.0, 0.0, 1.0, 0.0);
        }
        let c = (a / self.h1).ln();
        if c < self.x.lo {
            let q = (c - self.x.lo).exp(); // x/x_lo
            let (c0, _, z0, _) = self.cz.eval(self.x.lo);
            let (c0, z0) = (c0 - 1.0, z0 - 1.0);
            return (
                1.0 + c0 * q * q * q,
                3.0 * c0 * q * q * q / a,
                1.0 + z0 * q,
                z0 * q / a,
            );
        }
        if c > self.x.hi {
            let (ch, dch, zh, dzh) = self.cz.eval(self.x.hi);
            let q = (self.x.hi - c).exp(); // x_hi/x
            if self.rigid {
                // Power-law continuation, C¹ in ln x.
                let (pc, pz) = (dch / ch, dzh / zh);
                let (cv, zv) = (ch * q.powf(-pc), zh * q.powf(-pz));
                return (cv, pc * cv / a, zv, pz * zv / a);
            }
            let cinf = 1.0 / (1.0 + self.k0);
            let (cv, zv) = (cinf + (ch - cinf) * q, 1.0 + (zh - 1.0) * q);
            return (cv, -(ch - cinf) * q / a, zv, -(zh - 1.0) * q / a);
        }
        let (cv, dc, zv, dz) = self.cz.eval(c);
        (cv, dc / a, zv, dz / a)
    }

    /// (χ, ζ), refusing a outside the table's range.
    pub fn try_chi_zeta(&self, a: f64) -> Result<(f64, f64), TableError> {
        let c = (a / self.h1).ln();
        if !(a > 0.0 && self.x.contains(c)) {
            let (lo, hi) = self.a_range();
            return Err(TableError::OutOfRange {
                what: "contact radius a (m)",
                value: a,
                lo,
                hi,
            });
        }
        let (cv, _, zv, _) = self.chi_zeta_with_derivs(a);
        Ok((cv, zv))
    }

    fn g_inside(&self, a: f64, r: f64) -> f64 {
        let c = (a / self.h1).ln();
        let r = r.max(a);
        let w = ((r - a) / self.h1).sqrt().asinh();
        if w > self.w.hi {
            return self.far.g(a, r);
        }
        self.g.eval(c, w) * a * a * a / r
    }

    /// g(a, r) (m²) with the out-of-range rules of the module documentation. For
    /// r ≤ a returns g(a, a).
    pub fn g_value(&self, a: f64, r: f64) -> f64 {
        if a.is_nan() || r.is_nan() {
            return f64::NAN;
        }
        if a <= 0.0 {
            return 0.0;
        }
        let c = (a / self.h1).ln();
        if c < self.x.lo {
            let a_lo = self.h1 * self.x.lo.exp();
            let q = a / a_lo;
            return q * q * q * self.g_inside(a_lo, r.max(a_lo));
        }
        if c > self.x.hi {
            // Beyond the a range: the far field where it holds, else its leading term.
            let r = r.max(a);
            if r - a > self.join() {
                return self.far.g(a, r);
            }
            return self.k0 * half_space_bracket(a, r);
        }
        self.g_inside(a, r)
    }

    /// g(a, r), refusing a outside the table's range or r < a.
    pub fn try_g(&self, a: f64, r: f64) -> Result<f64, TableError> {
        self.try_chi_zeta(a)?;
        if r.is_nan() || r < a {
            return Err(TableError::OutOfRange {
                what: "distance r (m; at least the contact radius a, the range's lower end)",
                value: r,
                lo: a,
                hi: f64::INFINITY,
            });
        }
        Ok(self.g_value(a, r))
    }

    /// S(ρ) (ρ in 1/m) from the table (physics.md §2).
    pub fn s(&self, rho: f64) -> f64 {
        let rho = rho.abs();
        let t = rho * self.h1;
        if t == 0.0 {
            return 1.0 + self.k0;
        }
        let c = t.ln();
        if c < self.s_axis.lo {
            let s0 = 1.0 + self.k0;
            return s0 + (self.s[0] - s0) * (c - self.s_axis.lo).exp();
        }
        if c > self.s_axis.hi {
            return 1.0;
        }
        interp::eval1(&self.s_axis, &self.s, c).0
    }
}

impl AsperityLaw for TableLaw {
    fn e_star(&self) -> f64 {
        self.e_star
    }
    fn chi(&self, a: f64) -> f64 {
        if a > 0.0 {
            let c = (a / self.h1).ln();
            if c >= self.x.lo && c <= self.x.hi {
                return self.cz.first(c);
            }
        }
        self.chi_zeta_with_derivs(a).0
    }
    fn zeta(&self, a: f64) -> f64 {
        if a > 0.0 {
            let c = (a / self.h1).ln();
            if c >= self.x.lo && c <= self.x.hi {
                return self.cz.second(c);
            }
        }
        self.chi_zeta_with_derivs(a).2
    }
    fn g(&self, a: f64, r: f64) -> f64 {
        self.g_value(a, r)
    }
    fn point_force(&self) -> crate::law::PointForce {
        self.point_force
    }
    fn chi_zeta_derivs(&self, a: f64) -> (f64, f64, f64, f64) {
        self.chi_zeta_with_derivs(a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stack::Layer;

    /// A pair table asked for a pair whose counterface differs (steel → aluminium):
    /// the error names the counterface and its base, not the first body's identical
    /// layer 1 (the scaled comparison blamed it, E* having changed); a swapped first body
    /// is named as such.
    #[test]
    fn a_wrong_pair_names_the_body_and_part_that_differ() {
        let body = Stack::paper_two_layer(5.0).unwrap();
        let steel = Stack::half_space(210e9, 0.3).unwrap();
        let mut t = synthetic();
        t.header.family = None;
        t.header.stack = body.clone();
        t.header.counterface = Counterface::elastic(steel.clone());
        let alu = Stack::half_space(70e9, 0.3).unwrap();
        let e = t
            .family_coordinate(&body.clone().against(alu))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(
                "the counterface's base (E, ν) = (7e10 Pa, 0.3), the table's (E, ν) = (2.1e11 Pa, 0.3)"
            ) && !e.contains("layer 1"),
            "{e}"
        );
        let other = Stack::paper_two_layer(2.0).unwrap();
        let e = t
            .family_coordinate(&other.against(steel.clone()))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("the first body's layer 2") && !e.contains("counterface's"),
            "{e}"
        );
        // the pair itself and its swap are served
        assert!(
            t.family_coordinate(&body.clone().against(steel.clone()))
                .is_ok()
        );
        assert!(t.family_coordinate(&steel.against(body)).is_ok());
    }

    /// A small synthetic two-layer family table with analytic contents (for format and
    /// lookup tests; the physics of the contents is tested in strata-tablegen).
    pub(crate) fn synthetic() -> Table {
        let stack = Stack::paper_two_layer(5.0).unwrap();
        let x = Axis {
            lo: -3.0,
            hi: 3.0,
            n: 13,
        };
        let w = Axis {
            lo: 0.0,
            hi: 2.0,
            n: 9,
        };
        let s = Axis {
            lo: -4.0,
            hi: 3.0,
            n: 8,
        };
        let ratio = Axis {
            lo: 0.1f64.ln(),
            hi: 10f64.ln(),
            n: 7,
        };
        let f = |c: f64, cx: f64| 1.0 + 0.1 * c + 0.05 * cx * cx;
        let mut t = Table {
            header: Header {
                format_version: FORMAT_VERSION,
                strata_version: "test".into(),
                build_time: 0,
                stack,
                counterface: Counterface::default(),
                family: Some(Family {
                    vary: Vary::Layer(2),
                    ratio,
                }),
                x,
                w,
                s,
                far_field_error: 0.0,
                far_terms: 0,
                tolerance: DEFAULT_TOLERANCE,
                interp_error: None,
            },
            chi: vec![],
            zeta: vec![],
            g: vec![],
            s: vec![],
            k0: vec![],
        };
        for c in ratio.nodes() {
            for cx in x.nodes() {
                t.chi.push(f(c, cx));
                t.zeta.push(1.0 - 0.01 * cx);
                for wv in w.nodes() {
                    t.g.push(-(1.0 + c) * (1.0 - 0.1 * wv));
                }
            }
            t.s.extend(s.nodes().iter().map(|v| 1.0 / (1.0 + (-v).exp())));
            t.k0.push(-1.0);
        }
        t
    }

    #[test]
    fn round_trip_and_lookup() {
        let t = synthetic();
        let bytes = t.to_bytes().unwrap();
        let back = Table::from_bytes(&bytes).unwrap();
        assert_eq!(t, back);
        let member = back.member_stack(2f64.ln()).unwrap();
        let law = back.law_for(&member).unwrap();
        // Quadratic data in (c, ln x): reproduced exactly by the cubic.
        let a = 1e-4 * 0.7f64.exp();
        let expect = 1.0 + 0.1 * 2f64.ln() + 0.05 * 0.49;
        assert!((law.chi(a) - expect).abs() < 1e-13, "{}", law.chi(a));
        let (_, dchi, _, dzeta) = law.chi_zeta_derivs(a);
        assert!((dchi - 0.1 * 0.7 / a).abs() < 1e-9 / a);
        assert!((dzeta + 0.01 / a).abs() < 1e-12 / a);
        // Below the range: χ, ζ → 1.
        assert!((law.chi(1e-12) - 1.0).abs() < 1e-9 && (law.zeta(1e-12) - 1.0).abs() < 1e-6);
        assert!(law.try_chi_zeta(1e-12).is_err());
        assert!(law.try_chi_zeta(1.0).is_err());
        // g far field beyond w_max and no NaN anywhere reasonable.
        for (a, r) in [
            (1e-6, 1e-6),
            (1e-6, 1.0),
            (1e-9, 1e-3),
            (1.0, 2.0),
            (1e-5, 3e-5),
        ] {
            assert!(law.g(a, r).is_finite(), "{a} {r}");
        }
        assert!((law.s(0.0) - 0.0).abs() < 1e-15 && (law.s(1e9) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn bad_files_give_clear_errors() {
        let t = synthetic();
        let bytes = t.to_bytes().unwrap();
        // Truncated anywhere: never a panic, always an error.
        for cut in [0, 4, 8, 20, 27, 28, 100, bytes.len() - 1] {
            let e = Table::from_bytes(&bytes[..cut]).unwrap_err();
            assert!(
                matches!(e, TableError::NotATable | TableError::Truncated { .. }),
                "{cut}: {e}"
            );
        }
        // A table of the previous format (1: no stated tolerance, leading far field
        // only) is refused with the way out.
        let mut old = bytes.clone();
        old[8] = 1;
        let e = Table::from_bytes(&old).unwrap_err().to_string();
        assert!(e.contains("version 1") && e.contains("rebuild"), "{e}");
        let mut wrong = bytes.clone();
        wrong[8] = 99;
        let e = Table::from_bytes(&wrong).unwrap_err();
        assert!(matches!(e, TableError::WrongVersion { found: 99, .. }));
        assert!(e.to_string().contains("version 99"));
        let mut flipped = bytes.clone();
        let k = bytes.len() / 2;
        flipped[k] ^= 0x40;
        assert!(matches!(
            Table::from_bytes(&flipped).unwrap_err(),
            TableError::Corrupt(_)
        ));
        let mut junk = b"GARBAGE!".to_vec();
        junk.extend_from_slice(&bytes[8..]);
        assert_eq!(Table::from_bytes(&junk).unwrap_err(), TableError::NotATable);
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(matches!(
            Table::from_bytes(&longer).unwrap_err(),
            TableError::Corrupt(_)
        ));
        // Inconsistent contents are refused at save time and load time.
        let mut bad = t.clone();
        bad.g.pop();
        assert!(matches!(
            bad.to_bytes().unwrap_err(),
            TableError::Invalid(_)
        ));
        let mut nan = t.clone();
        nan.chi[3] = f64::NAN;
        assert!(nan.to_bytes().unwrap_err().to_string().contains("chi"));
        // Missing file names the path.
        let e = Table::load(Path::new("/nonexistent/x.strata")).unwrap_err();
        assert!(e.to_string().contains("/nonexistent/x.strata"));
    }

    #[test]
    fn wrong_stack_refused() {
        let t = synthetic();
        let other = Stack::new(
            vec![Layer {
                thickness: 1e-4,
                young: 4e9,
                poisson: 0.15,
            }],
            Base::Rigid,
        )
        .unwrap();
        let e = t.law_for(&other).unwrap_err();
        assert!(e.to_string().contains("layers"), "{e}");
        let out = t.member_stack(100f64.ln()).unwrap();
        let e = t.law_for(&out).unwrap_err();
        assert!(e.to_string().contains("outside"), "{e}");
    }

    #[test]
    fn save_is_atomic_and_loadable() {
        let t = synthetic();
        let dir = std::env::temp_dir().join(format!("strata-table-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("t.strata");
        t.save(&p).unwrap();
        assert_eq!(Table::load(&p).unwrap(), t);
        let leftovers = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(leftovers, 1);
        let files = export::export_npy(&t, &dir.join("npy")).unwrap();
        assert_eq!(files.len(), 9);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
