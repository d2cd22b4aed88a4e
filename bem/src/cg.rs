//! Polonsky–Keer constrained conjugate gradient (Wear 231, 1999; the form of Rey,
//! Anciaux & Molinari, Comput. Mech. 2017 for displacement control), with one
//! convolution per iteration and the vector operations fused into as few passes over
//! the grid as the algorithm's global reductions allow. This is the plain iteration
//! (`BemOptions::preconditioner = false`) and the common machinery (start, exact
//! refreshes, acceptance, the update and its correction) of the preconditioned one
//! ([`crate::pcg`], the default).
//!
//! The unknown is the pressure p ≥ 0 (Pa); the gap g = u − z + c with u = K p (m) and c
//! the flat's offset, known under displacement control, the Lagrange multiplier of the
//! mean pressure otherwise (c = −mean of u − z over the contact set). Per iteration:
//!
//! ```text
//!   t ← g + β t on the contact set (0 elsewhere),  β = Σg²/Σg²_old (0 after re-entry)
//!   r = K t                                           ← the one convolution
//!   τ = Σ g t / Σ r̃ t        (r̃ = r − mean_contact r under pressure control)
//!   p ← max(p − τ t, 0);  p ← −τ g where p = 0 and g < 0 (re-entry)
//!   u ← u − τ r  (+ K Δ if the projection or the re-entry changed p by Δ ≠ −τ t)
//!   p, u ← f p, f u,  f = p̄ / mean p               (pressure control)
//! ```
//!
//! so the gap is updated from the product that the step needs anyway; a second product
//! is spent only on iterations where the contact set changes at more than
//! [`crate::update::POINT_SUMS`] points (fewer: K Δ summed in real space, one pass per point), and u is
//! recomputed from p every [`REFRESH`] iterations and before the solution is accepted
//! (no drift).
//!
//! While the contact set stays put the update of p and u rides in the next iteration's
//! product (`State::fused`): the new gap g′ is formed as p and u are updated row by row,
//! the product is q = K g′, and t′ = g′ + β t, r′ = q + β r follow without another pass.
//!
//! # Passes over the grid per iteration (when the set changed)
//! 1. direction t, fused into the forward row FFTs (`RealFft2::convolve_with`);
//! 2. r = K t: the column FFTs with the kernel multiply;
//! 3. Σ r t, Σ t, Σ r on the contact set, fused into the inverse row FFTs as r is written;
//! 4. the update of p and u (the pending factor f of the previous step applied here,
//!    never in a pass of its own), with the sums that give the next f and c, and, under
//!    displacement control, the next error terms;
//! 5. under pressure control only: the error terms and Σg² once f and c are known.
//!
//! Stopping criterion on the physical error (σ_z the RMS height):
//!
//! ```text
//!   ε = max( max_{p>0} |g|,  max_{p=0} max(−g, 0) ) / σ_z
//! ```
//!
//! (the gap on the contact set, interpenetration outside it), evaluated on the exact
//! u = K p before a solution is accepted. Both are maxima over points: a gap weighted by
//! the pressure (Σ p|g| / Σ p, the complementarity) let points of small pressure at the
//! contact's edge stop with gaps of 1e-3 σ_z on a soft coating (1e4× softer than its
//! base: pressures 2e-4 of the peak off; `preconditioned_unloading_curves_on_extreme_coatings`);
//! the maximum costs ~10 % more iterations on the E2/E1 = 5 curve (348 → 387 at 512²).

use rayon::prelude::*;
use strata_runtime::fft::{Fft2Work, Merge};

use crate::BemError;
use crate::operator::Operator;
use crate::update::Changed;
pub(crate) use crate::update::UpdateFill;

/// Incremental gap updates between two exact products u = K p.
pub(crate) const REFRESH: usize = 64;
/// Points per parallel chunk of the vector passes.
pub(crate) const CHUNK: usize = 1 << 15;

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

/// Result of one constrained solve.
pub(crate) struct CgOutcome {
    pub iterations: usize,
    /// Applications of the operator K (convolutions) the solve spent.
    pub products: usize,
    pub error: f64,
    /// The offset c (m): g = K p − z + c.
    pub offset: f64,
    pub gap: Vec<f64>,
}

/// The problem data of one solve.
pub(crate) struct Problem<'a> {
    pub op: &'a Operator,
    /// The preconditioner M⁻¹ ≈ K⁻¹ (module [`crate::pcg`]); `None`: plain iteration.
    pub precond: Option<&'a Operator>,
    pub z: &'a [f64],
    pub z_rms: f64,
    /// Stiffness (Pa/m) for initial guesses.
    pub stiffness: f64,
    pub tolerance: f64,
    pub max_iterations: usize,
}

/// Error terms of a state: Σ p, Σ g² and the largest |g| on the contact set (p > 0),
/// the largest interpenetration max(−g) outside it.
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

    /// ε (see the module docs).
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

impl StepSums {
    /// The sums of one row: direction `t`, product `r`, stored pressure `p` (true
    /// pressure f p), all of one length; on AVX2 where the CPU has it.
    #[inline(always)]
    pub(crate) fn row(f: f64, p: &[f64], t: &[f64], r: &[f64]) -> Self {
        assert!(p.len() == r.len() && t.len() == r.len());
        #[cfg(target_arch = "x86_64")]
        if crate::avx2() {
            // SAFETY: the CPU has AVX2; p and t hold r.len() values (asserted).
            return unsafe { crate::simd::step_sums(f, p, t, r) };
        }
        let mut d = StepSums::default();
        for k in 0..p.len() {
            if p[k] > 0.0 {
                d.add(f * p[k], t[k], r[k]);
            }
        }
        d
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

/// Buffers and scalars of the iteration (allocated once per solve, none per iteration).
/// The stored p and u are f times smaller than the true ones (the pending rescale of
/// pressure control, applied in the next pass that reads them).
pub(crate) struct State<'a> {
    pub(crate) pb: &'a Problem<'a>,
    pub(crate) control: Control,
    pub(crate) u: Vec<f64>,
    pub(crate) t: Vec<f64>,
    pub(crate) r: Vec<f64>,
    /// Δp off the step direction (zero except between an update and its correction).
    pub(crate) corr: Vec<f64>,
    /// The gap on the contact set (0 elsewhere), the input of a fused iteration's product.
    pub(crate) g: Vec<f64>,
    /// The preconditioned gap (preconditioned iteration only; empty otherwise).
    pub(crate) y: Vec<f64>,
    pub(crate) work: Fft2Work,
    /// Pending scale of p and u.
    pub(crate) f: f64,
    /// Offset c of the current state.
    pub(crate) c: f64,
    pub(crate) stats: Stats,
    /// Σ z and the number of points over the contact set of the current state.
    pub(crate) sz: f64,
    pub(crate) m: f64,
    /// Operator applications so far.
    pub(crate) products: usize,
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

/// How a solve begins: already done (the flat does not touch), or a state to iterate.
pub(crate) enum Start<'a> {
    Done(CgOutcome),
    Run(Box<State<'a>>),
}

/// What the head of an iteration decided.
pub(crate) enum Head {
    /// Accepted (on the exact gap).
    Done(CgOutcome),
    /// The contact set was empty: restarted from the local estimate (conjugation off).
    Restarted,
    /// Go on.
    Go,
}

/// What a fused iteration did.
enum Fused {
    /// The update was clean and the next step is computed: it and Σg² of the new state.
    Stepped(Pending, f64),
    /// The update is applied but the iteration stopped before its product: the contact
    /// set changed (`changed` in the sums), the state converged, or a refresh is due.
    Stopped(Sums),
}

/// Solves; on return `p` holds the pressure. With a preconditioner in the problem the
/// preconditioned iteration runs ([`crate::pcg`]), the plain one otherwise or once the
/// preconditioned one stalls (see `pcg::Stall`).
pub(crate) fn solve(pb: &Problem, control: Control, p: &mut [f64]) -> Result<CgOutcome, BemError> {
    let mut s = match State::start(pb, control, p)? {
        Start::Done(out) => return Ok(out),
        Start::Run(s) => s,
    };
    let mut it = 0;
    if let Some(minv) = pb.precond {
        if let Some(out) = crate::pcg::run(&mut s, minv, p, &mut it)? {
            return Ok(out);
        }
        // Stalled (offset control only, see `pcg::Stall`): again from the cold guess,
        // in case a warm start pressed too hard; then with the plain iteration.
        s.cold(p)?;
        if let Some(out) = crate::pcg::run(&mut s, minv, p, &mut it)? {
            return Ok(out);
        }
        s.materialise(p);
        s.exact(p)?;
    }
    plain(&mut s, p, &mut it)
}

/// The plain iteration from an exact state `s`; `it` counts the iterations.
fn plain(s: &mut State, p: &mut [f64], it: &mut usize) -> Result<CgOutcome, BemError> {
    let pb = s.pb;
    let mut exact = true;
    let mut since_exact = 0usize;
    let mut g_old = 1.0;
    let mut conjugate = false;
    loop {
        match s.head(p, it, &mut exact, &mut since_exact)? {
            Head::Done(out) => return Ok(out),
            Head::Restarted => {
                conjugate = false;
                continue;
            }
            Head::Go => {}
        }
        let gg = s.stats.gg;
        let beta = if conjugate { gg / g_old } else { 0.0 };
        g_old = gg;
        let mut step = s.direction(p, beta)?;
        exact = false;
        since_exact += 1;
        // Apply the step. While it leaves the contact set as it is (no point reaches
        // p ≤ 0, none re-enters), the update is fused into the next iteration's product.
        loop {
            let clean = s.stats.pen == 0.0 && step.tau < step.leave;
            let sums = if clean {
                let go = *it < pb.max_iterations && since_exact < REFRESH;
                match s.fused(p, step, g_old, go)? {
                    Fused::Stepped(next, gg) => {
                        step = next;
                        g_old = gg;
                        *it += 1;
                        since_exact += 1;
                        continue;
                    }
                    Fused::Stopped(sums) => sums,
                }
            } else {
                s.update(p, step.tau)
            };
            conjugate = !s.finish(p, sums)?;
            break;
        }
    }
}

impl<'a> State<'a> {
    /// The initial guess (kept if given: a warm start), the buffers, and the exact gap
    /// of the guess.
    pub(crate) fn start(
        pb: &'a Problem<'a>,
        control: Control,
        p: &mut [f64],
    ) -> Result<Start<'a>, BemError> {
        let n = pb.z.len();
        let z = pb.z;
        // Initial guess.
        match control {
            Control::Offset { c, .. } => {
                if z.iter().all(|&zi| zi <= c) {
                    // No overlap: the flat does not touch.
                    p.fill(0.0);
                    return Ok(Start::Done(CgOutcome {
                        iterations: 0,
                        products: 0,
                        error: 0.0,
                        offset: c,
                        gap: z.iter().map(|zi| c - zi).collect(),
                    }));
                }
                if p.iter().all(|&v| v == 0.0) {
                    for i in 0..n {
                        p[i] = pb.stiffness * (z[i] - c).max(0.0);
                    }
                }
            }
            Control::Pressure(pbar) => {
                let mean = p.iter().sum::<f64>() / n as f64;
                if mean > 0.0 {
                    let f = pbar / mean;
                    p.iter_mut().for_each(|v| *v *= f);
                } else {
                    p.fill(pbar);
                }
            }
        }
        let mut s = Box::new(State {
            pb,
            control,
            u: vec![0.0; n],
            t: vec![0.0; n],
            r: vec![0.0; n],
            corr: vec![0.0; n],
            g: vec![0.0; n],
            y: if pb.precond.is_some() {
                vec![0.0; n]
            } else {
                Vec::new()
            },
            work: pb.op.work(),
            f: 1.0,
            c: control.known_offset().unwrap_or(0.0),
            stats: Stats::default(),
            sz: 0.0,
            m: 0.0,
            products: 0,
        });
        s.exact(p)?;
        Ok(Start::Run(s))
    }

    /// The head of an iteration: the error of the state; before accepting it, or when a
    /// refresh is due or the cap reached, u = K p is recomputed exactly; past the cap, the
    /// error [`BemError::NotConverged`]. Then the iteration count `it` goes up, and an
    /// empty contact set is restarted ([`Self::restart_if_empty`]).
    pub(crate) fn head(
        &mut self,
        p: &mut [f64],
        it: &mut usize,
        exact: &mut bool,
        since_exact: &mut usize,
    ) -> Result<Head, BemError> {
        let pb = self.pb;
        let it0 = *it;
        let mut error = self.stats.error(pb.z_rms);
        if !*exact && (error <= pb.tolerance || it0 >= pb.max_iterations || *since_exact >= REFRESH)
        {
            // Accept only on the exact gap; refresh it now and then against drift.
            self.exact(p)?;
            *since_exact = 0;
            error = self.stats.error(pb.z_rms);
        }
        if !error.is_finite() {
            return Err(BemError::NonFinite(it0));
        }
        if error <= pb.tolerance {
            let c = self.c;
            let gap = self.u.par_iter().zip(pb.z.par_iter());
            return Ok(Head::Done(CgOutcome {
                iterations: it0,
                products: self.products,
                error,
                offset: c,
                gap: gap.map(|(u, z)| u - z + c).collect(),
            }));
        }
        if it0 >= pb.max_iterations {
            return Err(BemError::NotConverged {
                iterations: pb.max_iterations,
                error,
                tolerance: pb.tolerance,
            });
        }
        *it += 1;
        if self.restart_if_empty(p)? {
            *exact = true;
            *since_exact = 0;
            return Ok(Head::Restarted);
        }
        Ok(Head::Go)
    }

    /// If the last step emptied the contact set (displacement control only): restart
    /// from the initial guess k (z − c)⁺ (with p = 0 the exact u is 0, whatever the
    /// incremental u drifted to); returns whether it did.
    fn restart_if_empty(&mut self, p: &mut [f64]) -> Result<bool, BemError> {
        if self.stats.psum != 0.0 {
            return Ok(false);
        }
        self.cold(p)?;
        Ok(true)
    }

    /// Displacement control: back to the cold guess p = k (z − c)⁺, exact u.
    pub(crate) fn cold(&mut self, p: &mut [f64]) -> Result<(), BemError> {
        self.f = 1.0;
        let (c, z, k) = (self.c, self.pb.z, self.pb.stiffness);
        for i in 0..p.len() {
            p[i] = k * (z[i] - c).max(0.0);
        }
        self.exact(p)
    }
}

impl<'a> State<'a> {
    /// Applies the pending scale to p and u.
    pub(crate) fn materialise(&mut self, p: &mut [f64]) {
        if self.f != 1.0 {
            let f = self.f;
            p.par_chunks_mut(CHUNK)
                .for_each(|c| c.iter_mut().for_each(|v| *v *= f));
            self.u
                .par_chunks_mut(CHUNK)
                .for_each(|c| c.iter_mut().for_each(|v| *v *= f));
            self.f = 1.0;
        }
    }

    /// u = K p exactly (the pending scale applied to p on the way), then the offset and
    /// the error terms.
    pub(crate) fn exact(&mut self, p: &mut [f64]) -> Result<(), BemError> {
        let (z, nx) = (self.pb.z, self.pb.op.nx());
        let f = self.f;
        let known = self.control.known_offset();
        self.products += 1;
        let ((), sums) = self.pb.op.apply_with(
            p,
            &mut self.u,
            self.control.uniform(),
            &mut self.work,
            |_, row, input| {
                if f != 1.0 {
                    row.iter_mut().for_each(|v| *v *= f);
                }
                input.copy_from_slice(row);
            },
            |i, prow, urow, out| {
                out.copy_from_slice(urow);
                let zrow = &z[i * nx..(i + 1) * nx];
                let mut acc = Sums::default();
                for k in 0..prow.len() {
                    if prow[k] > 0.0 {
                        acc.su += urow[k];
                        acc.sz += zrow[k];
                        acc.m += 1.0;
                    }
                    if let Some(c) = known {
                        acc.stats.add(prow[k], urow[k] - zrow[k] + c);
                    }
                }
                acc
            },
        )?;
        self.f = 1.0;
        self.settle(p, sums);
        Ok(())
    }

    /// After a pass that changed u: the offset, the pending scale and the error terms.
    pub(crate) fn settle(&mut self, p: &[f64], sums: Sums) {
        self.sz = sums.sz;
        self.m = sums.m;
        match self.control {
            Control::Offset { .. } => self.stats = sums.stats,
            Control::Pressure(_) => {
                // f is already in p and u for an exact state; a step leaves it pending.
                self.c = if sums.m > 0.0 {
                    -(self.f * sums.su - sums.sz) / sums.m
                } else {
                    0.0
                };
                self.stats = stats_pass(p, &self.u, self.pb.z, self.f, self.c);
            }
        }
    }

    /// The direction t = g + β t (on the contact set) and r = K t, one product, and the
    /// step τ = Σ g t / Σ r̃ t along it (r̃ = r − mean_contact r under pressure control).
    fn direction(&mut self, p: &[f64], beta: f64) -> Result<Pending, BemError> {
        let (z, nx) = (self.pb.z, self.pb.op.nx());
        let (f, c) = (self.f, self.c);
        let uniform = self.control.uniform();
        let u = &self.u;
        let wide = crate::avx2();
        self.products += 1;
        // Direction t (fused into the forward row FFTs) and r = K t, with the sums of τ
        // as r is written.
        let (gt, d) = self.pb.op.apply_with(
            &mut self.t,
            &mut self.r,
            uniform,
            &mut self.work,
            |i, trow, input| {
                let row = i * nx..(i + 1) * nx;
                let (prow, urow, zrow) = (&p[row.clone()], &u[row.clone()], &z[row]);
                #[cfg(target_arch = "x86_64")]
                if wide {
                    // SAFETY: the CPU has AVX2; the rows hold nx values.
                    return unsafe {
                        crate::simd::direction_row([f, c, beta], prow, urow, zrow, trow, input)
                    };
                }
                let mut acc = 0.0;
                for k in 0..nx {
                    trow[k] = if prow[k] > 0.0 {
                        let g = f * urow[k] - zrow[k] + c;
                        let v = g + beta * trow[k];
                        acc += g * v;
                        v
                    } else {
                        0.0
                    };
                }
                input.copy_from_slice(trow);
                acc
            },
            |i, trow, rrow, out| {
                out.copy_from_slice(rrow);
                StepSums::row(f, &p[i * nx..(i + 1) * nx], trow, rrow)
            },
        )?;
        Ok(self.pending(StepSums { gt, ..d }))
    }

    /// The step from the sums of a direction's product.
    pub(crate) fn pending(&self, d: StepSums) -> Pending {
        let den = match self.control {
            Control::Pressure(_) if d.m > 0.0 => d.rt - d.r / d.m * d.t,
            _ => d.rt,
        };
        Pending {
            tau: if den > 0.0 { d.gt / den } else { 0.0 },
            st: d.t,
            sr: d.r,
            leave: d.leave,
        }
    }

    /// A fused iteration: the pending step applied row by row as the rows of the next
    /// product are formed. Assuming the contact set stays as it is, the new state's
    /// scale f′ and offset c′ are known before the pass (pressure control:
    /// Σ p′ = p̄N − τ Σt, Σ u′ = Σz − c m − τ Σr over the unchanged set), so the pass
    /// also forms the new gap g′ on the contact set, its error terms and Σ g′². If the
    /// set did change, or the state converged, or `go` is false, the product stops
    /// there ([`Fused::Stopped`], the caller corrects u). Otherwise the product is
    /// q = K g′ and, the set unchanged, the new direction and its product follow without
    /// another convolution: t′ = g′ + β t, r′ = K t′ = q + β r, β = Σ g′² / `g_old`.
    fn fused(
        &mut self,
        p: &mut [f64],
        step: Pending,
        g_old: f64,
        go: bool,
    ) -> Result<Fused, BemError> {
        let nx = self.pb.op.nx();
        let fill = self.update_fill(step, p.len());
        let f2 = fill.f2;
        let (tol, z_rms) = (self.pb.tolerance, self.pb.z_rms);
        // Continue to the product with β = Σg′²/g_old unless the set changed or the new
        // state is converged (or `go` is false).
        let gate = |a: &Sums| {
            (go && !a.changed.any() && a.stats.error(z_rms) > tol).then(|| a.stats.gg / g_old)
        };
        let (sums, drained) = self.pb.op.apply_fields(
            [
                &mut *p,
                &mut self.u,
                &mut self.g,
                &mut self.t,
                &mut self.r,
                &mut self.corr,
            ],
            self.control.uniform(),
            &mut self.work,
            |i, rows, input| fill.row(i, rows, input),
            gate,
            |&beta, _, [p, _, g, t, r, _], q| {
                // The set is unchanged: t′ = g′ + β t, r′ = K g′ + β r.
                #[cfg(target_arch = "x86_64")]
                if crate::avx2() {
                    // SAFETY: the CPU has AVX2; the rows hold nx = q.len() values.
                    return unsafe { crate::simd::next_direction(beta, f2, [p, g], [t, r], q) };
                }
                let mut d = StepSums::default();
                for k in 0..nx {
                    let rn = q[k] + beta * r[k];
                    r[k] = rn;
                    if p[k] > 0.0 {
                        let tn = g[k] + beta * t[k];
                        t[k] = tn;
                        d.add(f2 * p[k], tn, rn);
                        d.gt += g[k] * tn;
                    }
                }
                d
            },
        )?;
        if drained.is_some() {
            self.products += 1;
        }
        if drained.is_some() || !sums.changed.any() {
            // The state is the new one: its scale, offset and error terms are known.
            self.f = f2;
            self.c = fill.c2;
            self.stats = sums.stats;
            self.sz = sums.sz;
            self.m = sums.m;
        }
        Ok(match drained {
            Some(d) => Fused::Stepped(self.pending(d), sums.stats.gg),
            None => Fused::Stopped(sums),
        })
    }

    /// After an update that was not fused (or stopped): u corrected by K Δ if the contact
    /// set changed, the pending scale (pressure control), the offset and error terms.
    /// Returns whether points re-entered the contact set (the conjugation restarts).
    pub(crate) fn finish(&mut self, p: &mut [f64], mut sums: Sums) -> Result<bool, BemError> {
        self.f = 1.0;
        if sums.changed.any() {
            // The contact set changed: add K Δ (the second product of this iteration,
            // or a sum in real space over a few points).
            sums = self.correct(p, sums)?;
        }
        let overlap = sums.overlap;
        if let Control::Pressure(pbar) = self.control {
            if sums.psum > 0.0 {
                self.f = pbar * p.len() as f64 / sums.psum;
            } else {
                // Every point left the contact: restart from the uniform pressure.
                p.fill(pbar);
                self.exact(p)?;
                return Ok(true);
            }
        }
        self.settle(p, sums);
        Ok(overlap)
    }
}

/// Error terms of the state (f p, f u) with offset c (pressure control: f and c are
/// known only after the update pass).
fn stats_pass(p: &[f64], u: &[f64], z: &[f64], f: f64, c: f64) -> Stats {
    p.par_chunks(CHUNK)
        .zip(u.par_chunks(CHUNK))
        .zip(z.par_chunks(CHUNK))
        .map(|((p, u), z)| {
            let mut a = Stats::default();
            for i in 0..p.len() {
                a.add(f * p[i], f * u[i] - z[i] + c);
            }
            a
        })
        .reduce(Stats::default, Stats::merge)
}
