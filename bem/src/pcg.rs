//! The preconditioned constrained conjugate gradient: Polonsky & Keer's iteration
//! ([`crate::cg`]) with the FFT-based preconditioner of Vollebregt (J. Comput. Phys. 257,
//! 2014): the residual is the gap g on the contact set C, preconditioned by the inverse
//! of the influence operator on the whole cell, restricted to C again,
//!
//! ```text
//!   y = P_C M⁻¹ P_C g,   M⁻¹ = F⁻¹ diag(1/K̂(k)) F    (periodic: 2|k|E*/(2S(|k|)) …)
//!   y ← y − mean_C y                                   (pressure control)
//!   t ← y + β t on C,  β = Σ_C g y / (Σ_C g y)_old    (0 after re-entry)
//!   r = K t;  τ = Σ_C g t / Σ_C r̃ t                   (as the plain iteration)
//! ```
//!
//! The operator K ~ 1/|k| has its small eigenvalues at short wavelengths, where the
//! plain iteration converges slowly (condition ~ n); M⁻¹ ~ |k| flattens the spectrum on
//! the contact set, and the iteration count becomes nearly independent of the grid
//! (512²: 80 → 21 per load step along a curve, 2048² under mean-pressure control:
//! 808 → 28). Each iteration costs two convolutions, M⁻¹ and K: the update of p and u
//! is fused into the preconditioner's product while the contact set stays put (as in the
//! plain iteration), and a third product corrects u when it changes at more than a few
//! points (fewer: summed in real space, [`crate::state::POINT_SUMS`]). The stopping
//! criterion, the exact refreshes and the acceptance on u = K p are those of `cg`.

use strata_runtime::fft::Merge;

use crate::BemError;
use crate::iteration::{CgOutcome, Head, State, contact_gap, with_rows};
use crate::kernels::Kernels;
use crate::operator::Operator;
use crate::state::{Control, Pending, REFRESH, Sums};

/// The preconditioned gap of a state: δ = Σ_C g y and the mean ȳ removed from y
/// (pressure control; 0 otherwise).
#[derive(Clone, Copy, Debug)]
struct Precond {
    delta: f64,
    ybar: f64,
}

/// Sums of a preconditioner product over C: Σ g y, Σ y, Σ g, the count.
#[derive(Default, Clone, Copy, Debug)]
struct PcSums {
    gy: f64,
    y: f64,
    g: f64,
    m: f64,
}

impl Merge for PcSums {
    fn merge(self, o: Self) -> Self {
        PcSums {
            gy: self.gy + o.gy,
            y: self.y + o.y,
            g: self.g + o.g,
            m: self.m + o.m,
        }
    }
}

impl PcSums {
    /// y = q on the contact set (p > 0), 0 elsewhere, with the sums.
    #[inline(always)]
    fn drain(kernels: Kernels, p: &[f64], g: &[f64], y: &mut [f64], q: &[f64]) -> Self {
        let [gy, y, g, m] = kernels.pc_drain(p, g, y, q);
        PcSums { gy, y, g, m }
    }

    fn precond(self, control: Control) -> Precond {
        let ybar = match control {
            Control::Pressure(_) if self.m > 0.0 => self.y / self.m,
            _ => 0.0,
        };
        Precond {
            delta: self.gy - ybar * self.g,
            ybar,
        }
    }
}

/// Iterations without the error halving after which the iteration counts as stalled.
const STALL: usize = 24;

/// Watches the error for a stall of the preconditioned iteration. Under offset control
/// without the uniform mode (a periodic cell on an elastic base: approach, separation or
/// mean-gap control) the energy is linear along a uniform change of pressure on a
/// contact set that covers the cell, and M⁻¹ has no uniform mode: from a start that
/// presses too hard (a warm start while unloading, a stiff coating on a soft base) the
/// preconditioned direction cannot shed the excess load, and the iteration stalls with
/// the contact over the whole cell and a uniform gap. The solve then starts again from
/// the cold guess k₁-stiffness × (z − c)⁺ (a warm start may have pressed too hard), and
/// if that stalls too, goes on with the plain direction, the gap itself, which has the
/// uniform component (`cg::solve`). Under other controls the watch is off.
struct Stall {
    on: bool,
    best: f64,
    since: usize,
}

impl Stall {
    fn new(control: Control) -> Self {
        Stall {
            on: matches!(control, Control::Offset { uniform: false, .. }),
            best: f64::INFINITY,
            since: 0,
        }
    }

    /// Records the error of an iteration; true once the iteration has stalled.
    fn watch(&mut self, error: f64) -> bool {
        if !self.on {
            return false;
        }
        if error < 0.5 * self.best {
            self.best = error;
            self.since = 0;
        } else {
            self.since += 1;
        }
        self.since >= STALL
    }
}

/// What a fused iteration did.
enum Fused {
    /// The update was clean; the new state's preconditioned gap.
    Stepped(Precond),
    /// The update is applied but the preconditioner's product was not computed: the
    /// contact set changed, the state converged, or a refresh is due.
    Stopped(Sums),
}

/// Runs the preconditioned iteration on the exact state `s` (`it` counts the
/// iterations); `None` if it stalled (see [`Stall`]), the state then left as it is.
pub(crate) fn run(
    s: &mut State,
    minv: &Operator,
    p: &mut [f64],
    it: &mut usize,
) -> Result<Option<CgOutcome>, BemError> {
    let pb = s.pb;
    let mut stall = Stall::new(s.control);
    let mut exact = true;
    let mut since_exact = 0usize;
    let mut d_old = 1.0;
    let mut conjugate = false;
    loop {
        match s.head(p, it, &mut exact, &mut since_exact)? {
            Head::Done(out) => return Ok(Some(out)),
            Head::Restarted => {
                conjugate = false;
                continue;
            }
            Head::Go => {}
        }
        let mut pre = s.precondition(p, minv)?;
        loop {
            if stall.watch(s.stats.error(pb.z_rms)) {
                return Ok(None);
            }
            let beta = if conjugate && d_old > 0.0 {
                pre.delta / d_old
            } else {
                0.0
            };
            d_old = pre.delta;
            let step = s.direction_pc(p, beta, pre.ybar)?;
            exact = false;
            since_exact += 1;
            // Apply the step: fused into the next preconditioner product while the
            // contact set stays put.
            let sums = if s.stats.pen == 0.0 && step.tau < step.leave {
                let go = *it < pb.max_iterations && since_exact < REFRESH;
                match s.fused_pc(p, step, minv, go)? {
                    Fused::Stepped(next) => {
                        pre = next;
                        *it += 1;
                        conjugate = true;
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

impl State<'_> {
    /// y = P_C M⁻¹ P_C g of the current state (one product), y written to `r` (see
    /// [`State::r`]); g on C formed row by row where it is read.
    fn precondition(&mut self, p: &[f64], minv: &Operator) -> Result<Precond, BemError> {
        let (z, nx) = (self.pb.z, self.pb.op.nx());
        let (f, c) = (self.f, self.c);
        let u = &self.u;
        let kernels = self.pb.kernels;
        self.products += 1;
        // y is written to `r` (free until the direction's product, which reads y in its
        // fill before it writes r in its drain).
        let ((), sums) = minv.apply_fields(
            [&mut self.r],
            self.control.uniform(),
            &mut self.work,
            |i, _, input| {
                let row = i * nx..(i + 1) * nx;
                contact_gap(input, &p[row.clone()], &u[row.clone()], &z[row], f, c);
            },
            |_| Some(()),
            |_, i, [y], q| {
                let row = i * nx..(i + 1) * nx;
                let (prow, urow, zrow) = (&p[row.clone()], &u[row.clone()], &z[row]);
                with_rows(nx, |g, _| {
                    contact_gap(g, prow, urow, zrow, f, c);
                    PcSums::drain(kernels, prow, g, y, q)
                })
            },
        )?;
        Ok(sums.unwrap_or_default().precond(self.control))
    }

    /// The direction t = (y − ȳ) + β t on C and r = K t (one product), the step τ.
    fn direction_pc(&mut self, p: &[f64], beta: f64, ybar: f64) -> Result<Pending, BemError> {
        let (z, nx) = (self.pb.z, self.pb.op.nx());
        let (f, c) = (self.f, self.c);
        let u = &self.u;
        let kernels = self.pb.kernels;
        self.products += 1;
        // `r` holds y until every row's fill has read it; the drain then writes r = K t.
        let (gt, d) = self.pb.op.apply_fields(
            [&mut self.t, &mut self.r],
            self.control.uniform(),
            &mut self.work,
            |i, [t, y], input| {
                let row = i * nx..(i + 1) * nx;
                let (prow, urow, zrow) = (&p[row.clone()], &u[row.clone()], &z[row]);
                with_rows(nx, |g, _| {
                    contact_gap(g, prow, urow, zrow, f, c);
                    kernels.direction_pc_row([ybar, beta], prow, y, g, t, input)
                })
            },
            |_| Some(()),
            |_, i, [t, r], q| {
                r.copy_from_slice(q);
                kernels.step_sums(f, &p[i * nx..(i + 1) * nx], t, q)
            },
        )?;
        let mut d = d.unwrap_or_default();
        d.gt = gt;
        Ok(self.pending(d))
    }

    /// A fused iteration: the pending step applied row by row as the rows of the next
    /// preconditioner product are formed (the new gap g′ on the unchanged contact set,
    /// see [`State::update_fill`]); the product stops after the fill if the set changed,
    /// the new state converged, or `go` is false.
    fn fused_pc(
        &mut self,
        p: &mut [f64],
        step: Pending,
        minv: &Operator,
        go: bool,
    ) -> Result<Fused, BemError> {
        let kernels = self.pb.kernels;
        let fill = self.update_fill(step, p.len());
        let (tol, z_rms) = (self.pb.tolerance, self.pb.z_rms);
        let gate = |a: &Sums| (go && !a.changed.any() && a.stats.error(z_rms) > tol).then_some(());
        let (z, nx) = (self.pb.z, self.pb.op.nx());
        let (f2, c2) = (fill.f2, fill.c2);
        let (sums, drained) = minv.apply_fields(
            [&mut *p, &mut self.u, &mut self.t, &mut self.r],
            self.control.uniform(),
            &mut self.work,
            |i, [p, u, t, r], input| {
                with_rows(nx, |g, corr| {
                    let sums = kernels.update_fill_row(&fill, i, [p, u, g, t, r, corr], input);
                    // r is read: Δp (0 where p stayed on the step) goes over it.
                    r.copy_from_slice(corr);
                    sums
                })
            },
            gate,
            // The set is unchanged (else no drain): Δp = 0 in `r`, the next y goes there.
            |_, i, [p, u, _, y], q| {
                with_rows(nx, |g, _| {
                    contact_gap(g, p, u, &z[i * nx..(i + 1) * nx], f2, c2);
                    PcSums::drain(kernels, p, g, y, q)
                })
            },
        )?;
        if drained.is_some() {
            self.products += 1;
        }
        if drained.is_some() || !sums.changed.any() {
            // The state is the new one: its scale, offset and error terms are known.
            self.f = fill.f2;
            self.c = fill.c2;
            self.stats = sums.stats;
            self.sz = sums.sz;
            self.m = sums.m;
        }
        Ok(match drained {
            Some(d) => Fused::Stepped(d.precond(self.control)),
            None => Fused::Stopped(sums),
        })
    }
}
