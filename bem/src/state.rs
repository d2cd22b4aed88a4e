//! The values the constrained conjugate gradient's passes share (the bottom layer of
//! the solver: it imports nothing of the crate). The control (what the iteration holds
//! fixed), the sums a pass over the grid returns (error terms, contact-set sums, step
//! sums, the points where the contact set changed), a computed step, and the parameters
//! of the two update rules. The row loops that form them are in `kernels`; the buffers
//! and the iteration around them in `iteration`, `update`, `pcg` and `cg`.

use strata_runtime::fft::Merge;

/// Incremental gap updates between two exact products u = K p.
pub(crate) const REFRESH: usize = 64;
/// Points per parallel chunk of the vector passes.
pub(crate) const CHUNK: usize = 1 << 15;

/// The most changed points whose correction K Δ is summed in real space (one pass over
/// the grid per point, ~1/12 of a product's time at 512² on the 2-core machine) rather
/// than by a product. Along the bench's 512² curve (plain iteration) about half the
/// corrections have ≤ 12 points: products per iteration 1.48 → 1.25.
pub(crate) const POINT_SUMS: usize = 12;

/// What the constrained CG holds fixed.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Control {
    /// g = K p − z + c with c known; `uniform`: the periodic k = 0 mode is included.
    Offset { c: f64, uniform: bool },
    /// Mean pressure p̄ (Pa); the offset is the Lagrange multiplier.
    Pressure(f64),
}

impl Control {
    pub(crate) fn uniform(self) -> bool {
        match self {
            Control::Offset { uniform, .. } => uniform,
            Control::Pressure(_) => false,
        }
    }

    /// The known offset (displacement control).
    pub(crate) fn known_offset(self) -> Option<f64> {
        match self {
            Control::Offset { c, .. } => Some(c),
            Control::Pressure(_) => None,
        }
    }
}

/// Error terms of a state: Σ p, Σ g² and the largest |g| on the contact set (p > 0),
/// the largest interpenetration max(−g) outside it; ε = max(|g|ₘₐₓ, pen)/σ_z.
#[derive(Default, Clone, Copy, Debug)]
pub(crate) struct Stats {
    pub(crate) psum: f64,
    pub(crate) gg: f64,
    pub(crate) gmax: f64,
    pub(crate) pen: f64,
}

impl Stats {
    #[inline(always)]
    pub(crate) fn add(&mut self, p: f64, g: f64) {
        if p > 0.0 {
            self.psum += p;
            self.gg += g * g;
            self.gmax = self.gmax.max(g.abs());
        } else {
            self.pen = self.pen.max(-g);
        }
    }

    /// ε = max(max_{p>0} |g|, max_{p=0} max(−g, 0)) / σ_z (dimensionless; gaps and σ_z
    /// in m).
    pub(crate) fn error(&self, z_rms: f64) -> f64 {
        self.gmax.max(self.pen) / z_rms
    }
}

impl Merge for Stats {
    fn merge(self, o: Self) -> Self {
        Stats {
            psum: self.psum + o.psum,
            gg: self.gg + o.gg,
            gmax: self.gmax.max(o.gmax),
            pen: self.pen.max(o.pen),
        }
    }
}

/// Sums of a pass that changes u (update, correction, exact product): the contact-set
/// sums Σ u and Σ z (for the offset c = −mean(u − z) of pressure control), the count,
/// Σ p, the points where p changed off the step direction, whether some re-entered, and
/// the next error terms when the offset is known.
#[derive(Default, Clone, Copy, Debug)]
pub(crate) struct Sums {
    pub(crate) su: f64,
    pub(crate) sz: f64,
    pub(crate) m: f64,
    pub(crate) psum: f64,
    pub(crate) changed: Changed,
    pub(crate) overlap: bool,
    pub(crate) stats: Stats,
}

impl Merge for Sums {
    fn merge(self, o: Self) -> Self {
        Sums {
            su: self.su + o.su,
            sz: self.sz + o.sz,
            m: self.m + o.m,
            psum: self.psum + o.psum,
            changed: self.changed.merge(o.changed),
            overlap: self.overlap || o.overlap,
            stats: self.stats.merge(o.stats),
        }
    }
}

/// Sums over the contact set of a direction t and its product r = K t: Σ g t, Σ r t,
/// Σ t, Σ r, the count, and the smallest step that takes a point to p ≤ 0
/// (min f p / t over t > 0; +∞ if none).
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepSums {
    pub(crate) gt: f64,
    pub(crate) rt: f64,
    pub(crate) t: f64,
    pub(crate) r: f64,
    pub(crate) m: f64,
    pub(crate) leave: f64,
}

impl Default for StepSums {
    fn default() -> Self {
        StepSums {
            gt: 0.0,
            rt: 0.0,
            t: 0.0,
            r: 0.0,
            m: 0.0,
            leave: f64::INFINITY,
        }
    }
}

impl StepSums {
    /// A contact point with (true) pressure `p`, direction `t` and product `r`.
    #[inline(always)]
    pub(crate) fn add(&mut self, p: f64, t: f64, r: f64) {
        self.rt += r * t;
        self.t += t;
        self.r += r;
        self.m += 1.0;
        if t > 0.0 {
            self.leave = self.leave.min(p / t);
        }
    }
}

impl Merge for StepSums {
    fn merge(self, o: Self) -> Self {
        StepSums {
            gt: self.gt + o.gt,
            rt: self.rt + o.rt,
            t: self.t + o.t,
            r: self.r + o.r,
            m: self.m + o.m,
            leave: self.leave.min(o.leave),
        }
    }
}

/// A step computed but not yet applied: p ← f p − τ t, u ← f u − τ r.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pending {
    pub(crate) tau: f64,
    /// Σ t and Σ r over the contact set.
    pub(crate) st: f64,
    pub(crate) sr: f64,
    /// The smallest step that takes a contact point to p ≤ 0: min f p / t over t > 0.
    pub(crate) leave: f64,
}

/// The points where a pass changed p off the step direction (left the contact set past
/// p = 0, or re-entered it): their number and, up to [`Changed::CAP`] of them, their
/// indices, so that the correction K Δ of a few points can be summed in real space.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Changed {
    n: usize,
    at: [u32; Changed::CAP],
}

impl Default for Changed {
    fn default() -> Self {
        Changed {
            n: 0,
            at: [0; Changed::CAP],
        }
    }
}

impl Changed {
    /// Indices kept; past this only the count.
    pub(crate) const CAP: usize = POINT_SUMS;

    #[inline(always)]
    pub(crate) fn push(&mut self, i: usize) {
        if self.n < Self::CAP {
            self.at[self.n] = i as u32;
        }
        self.n += 1;
    }

    /// Whether any point changed.
    pub(crate) fn any(&self) -> bool {
        self.n > 0
    }

    /// The indices, if all were kept.
    pub(crate) fn points(&self) -> Option<&[u32]> {
        (self.n <= Self::CAP).then(|| &self.at[..self.n])
    }

    pub(crate) fn merge(mut self, o: Self) -> Self {
        let total = self.n + o.n;
        if total <= Self::CAP {
            self.at[self.n..total].copy_from_slice(&o.at[..o.n]);
        }
        self.n = total;
        self
    }
}

/// The fill of a fused iteration (see `State::fused` in `cg`): the pending step applied to
/// a row, the new gap on the contact set written to `g` and to the transform's input.
pub(crate) struct UpdateFill<'a> {
    pub(crate) z: &'a [f64],
    pub(crate) nx: usize,
    /// The state's scale and offset, the step.
    pub(crate) f: f64,
    pub(crate) c: f64,
    pub(crate) tau: f64,
    /// The new state's scale and offset, the contact set unchanged.
    pub(crate) f2: f64,
    pub(crate) c2: f64,
}

impl<'a> UpdateFill<'a> {
    /// A fill from its parts (tests of the vector form against the scalar rule).
    #[cfg(test)]
    pub(crate) fn from_parts(z: &'a [f64], nx: usize, [f, c, tau, f2, c2]: [f64; 5]) -> Self {
        UpdateFill {
            z,
            nx,
            f,
            c,
            tau,
            f2,
            c2,
        }
    }

    /// The step and scales: (f, c, τ, f′, c′), and the row length and heights.
    pub(crate) fn consts(&self) -> ([f64; 5], usize, &[f64]) {
        (
            [self.f, self.c, self.tau, self.f2, self.c2],
            self.nx,
            self.z,
        )
    }
}

/// The step of an update pass (`State::update` in `update`): the pending scale f, the offset c,
/// the step τ, and the offset if it is known (displacement control: the error terms
/// follow).
#[derive(Clone, Copy)]
pub(crate) struct UpdateStep {
    pub(crate) f: f64,
    pub(crate) c: f64,
    pub(crate) tau: f64,
    pub(crate) known: Option<f64>,
}

/// One chunk of an update pass: p, u and `corr` updated, t, r and z read.
pub(crate) struct UpdateChunk<'s> {
    pub(crate) p: &'s mut [f64],
    pub(crate) u: &'s mut [f64],
    pub(crate) corr: &'s mut [f64],
    pub(crate) t: &'s [f64],
    pub(crate) r: &'s [f64],
    pub(crate) z: &'s [f64],
}
