//! Polonsky–Keer constrained conjugate gradient (Wear 231, 1999; the form of Rey,
//! Anciaux & Molinari, Comput. Mech. 2017 for displacement control), with one
//! convolution per iteration and the vector operations fused into as few passes over
//! the grid as the algorithm's global reductions allow. This is the plain iteration
//! (`BemOptions::preconditioner = false`) and [`solve`], which runs the preconditioned
//! one ([`crate::pcg`], the default) and falls back on the plain one. The machinery
//! both share is below them: the start, exact refreshes and acceptance in
//! [`crate::iteration`], the update and its correction in [`crate::update`], the row
//! loops in [`crate::kernels`], the sums in [`crate::state`].
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
//! [`crate::state::POINT_SUMS`] points (fewer: K Δ summed in real space, one pass per point), and u is
//! recomputed from p every [`REFRESH`](crate::state::REFRESH) iterations and before the solution is accepted
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

use crate::BemError;
use crate::iteration::{CgOutcome, Head, Problem, Start, State};
use crate::state::{Control, Pending, REFRESH, StepSums, Sums};

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
        s.plain_buffers();
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

impl State<'_> {
    /// The direction t = g + β t (on the contact set) and r = K t, one product, and the
    /// step τ = Σ g t / Σ r̃ t along it (r̃ = r − mean_contact r under pressure control).
    fn direction(&mut self, p: &[f64], beta: f64) -> Result<Pending, BemError> {
        let (z, nx) = (self.pb.z, self.pb.op.nx());
        let (f, c) = (self.f, self.c);
        let uniform = self.control.uniform();
        let u = &self.u;
        let kernels = self.pb.kernels;
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
                kernels.direction_row([f, c, beta], prow, urow, zrow, trow, input)
            },
            |i, trow, rrow, out| {
                out.copy_from_slice(rrow);
                kernels.step_sums(f, &p[i * nx..(i + 1) * nx], trow, rrow)
            },
        )?;
        Ok(self.pending(StepSums { gt, ..d }))
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
        let kernels = self.pb.kernels;
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
            |i, rows, input| kernels.update_fill_row(&fill, i, rows, input),
            gate,
            |&beta, _, [p, _, g, t, r, _], q| {
                // The set is unchanged: t′ = g′ + β t, r′ = K g′ + β r.
                kernels.next_direction(beta, f2, [p, g], [t, r], q)
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
}
