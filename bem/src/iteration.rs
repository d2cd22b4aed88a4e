//! The iteration's buffers and the steps both conjugate gradients share: the problem
//! of one solve, the state (p, u, the direction t, its product r = K t, the pending
//! scale f and offset c), the start from an initial guess, the head of an iteration
//! (acceptance on the exact gap u = K p, refreshes against drift, the iteration cap),
//! the exact product and the step τ from a direction's sums. Built on `state` (the
//! values) and `kernels` (the row loops, chosen once per solver).

use rayon::prelude::*;
use strata_runtime::fft::{Fft2Work, Merge};

use crate::BemError;
use crate::kernels::Kernels;
use crate::operator::Operator;
use crate::state::{CHUNK, Control, Pending, REFRESH, Stats, StepSums, Sums};

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
    /// The preconditioner M⁻¹ ≈ K⁻¹ (module `pcg`); `None`: plain iteration.
    pub precond: Option<&'a Operator>,
    pub z: &'a [f64],
    pub z_rms: f64,
    /// Stiffness (Pa/m) for initial guesses.
    pub stiffness: f64,
    pub tolerance: f64,
    pub max_iterations: usize,
    /// The row loops, chosen once per solver ([`Kernels::detect`]).
    pub kernels: Kernels,
    /// Checked at the head of every iteration ([`crate::BemSolver::with_cancel`]).
    pub cancel: &'a strata_runtime::cancel::Cancel,
}

/// Buffers and scalars of the iteration (allocated once per solve, none per iteration).
/// The stored p and u are f times smaller than the true ones (the pending rescale of
/// pressure control, applied in the next pass that reads them).
pub(crate) struct State<'a> {
    pub(crate) pb: &'a Problem<'a>,
    pub(crate) control: Control,
    pub(crate) u: Vec<f64>,
    pub(crate) t: Vec<f64>,
    /// r = K t; in the preconditioned iteration also the preconditioned gap y between
    /// the preconditioner's product and the direction's (module `pcg`: the two are never
    /// needed at once).
    pub(crate) r: Vec<f64>,
    /// Δp off the step direction (zero except between an update and its correction).
    /// Plain iteration only: the preconditioned one keeps Δp in `r` (see
    /// [`Self::corr_buffer`]); empty until the plain iteration runs.
    pub(crate) corr: Vec<f64>,
    /// The gap on the contact set (0 elsewhere), the input of a fused iteration's
    /// product. Plain iteration only (the preconditioned one forms it row by row where
    /// it is needed); empty until the plain iteration runs.
    pub(crate) g: Vec<f64>,
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
            corr: Vec::new(),
            g: Vec::new(),
            work: pb.op.work(),
            f: 1.0,
            c: control.known_offset().unwrap_or(0.0),
            stats: Stats::default(),
            sz: 0.0,
            m: 0.0,
            products: 0,
        });
        if pb.precond.is_none() {
            s.plain_buffers();
        }
        s.exact(p)?;
        Ok(Start::Run(s))
    }

    /// The buffers only the plain iteration needs (g and Δp of its own), allocated
    /// when it runs: the preconditioned iteration holds four grid fields (p, u, t, r),
    /// the plain one six.
    pub(crate) fn plain_buffers(&mut self) {
        let n = self.u.len();
        if self.g.len() != n {
            self.g = vec![0.0; n];
        }
        if self.corr.len() != n {
            self.corr = vec![0.0; n];
        }
    }

    /// Where Δp (the correction's input) lives: `corr` in the plain iteration, `r` in the
    /// preconditioned one (r is read by the update before Δp is written over it, and
    /// the next r = K t is formed after the correction).
    pub(crate) fn corr_buffer(&mut self) -> &mut Vec<f64> {
        if self.corr.is_empty() {
            &mut self.r
        } else {
            &mut self.corr
        }
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
        pb.cancel.check()?;
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
            // The gap g = u − z + c written over u (the state ends here).
            let mut gap = std::mem::take(&mut self.u);
            gap.par_chunks_mut(CHUNK)
                .zip(pb.z.par_chunks(CHUNK))
                .for_each(|(g, z)| g.iter_mut().zip(z).for_each(|(g, z)| *g = *g - z + c));
            return Ok(Head::Done(CgOutcome {
                iterations: it0,
                products: self.products,
                error,
                offset: c,
                gap,
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

thread_local! {
    /// Per-thread rows for the row loops' scratch (`with_rows`).
    static ROWS: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Runs `f` on two zeroed scratch rows of `n` values each (per thread, reused).
pub(crate) fn with_rows<R>(n: usize, f: impl FnOnce(&mut [f64], &mut [f64]) -> R) -> R {
    ROWS.with(|cell| match cell.try_borrow_mut() {
        Ok(mut buf) => {
            buf.clear();
            buf.resize(2 * n, 0.0);
            let (a, b) = buf.split_at_mut(n);
            f(a, b)
        }
        Err(_) => {
            let mut buf = vec![0.0; 2 * n];
            let (a, b) = buf.split_at_mut(n);
            f(a, b)
        }
    })
}

/// The gap on the contact set of a row: g = f u − z + c where p > 0, 0 elsewhere (the
/// values the fills form: the same operations in the same order).
#[inline]
pub(crate) fn contact_gap(g: &mut [f64], p: &[f64], u: &[f64], z: &[f64], f: f64, c: f64) {
    for k in 0..g.len() {
        g[k] = if p[k] > 0.0 { f * u[k] - z[k] + c } else { 0.0 };
    }
}
