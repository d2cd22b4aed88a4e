//! The row loops of the constrained conjugate gradient, in two forms: the scalar rules
//! (`scalar`, any CPU) and AVX2 (`avx2`, 4 points per instruction, x86-64). Which form
//! runs is decided once, when a solver is built ([`Kernels::detect`]: the one place the
//! CPU is asked), and travels with the problem of each solve; the iterations call the
//! loops through [`Kernels`] and never ask again. Both forms apply the same rules to the
//! same points; their sums are formed in a different order (last bits only).

#[cfg(target_arch = "x86_64")]
mod avx2;
mod scalar;

use crate::state::{StepSums, Sums, UpdateChunk, UpdateFill, UpdateStep};

/// The row loops a solver runs: the scalar rules, or their AVX2 forms where the CPU has
/// AVX2. Only [`Kernels::detect`] can choose AVX2, so holding `Kernels` that say AVX2
/// proves the CPU has it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Kernels(Form);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Form {
    Scalar,
    #[cfg(target_arch = "x86_64")]
    Avx2,
}

impl Kernels {
    /// The fastest loops this CPU runs: AVX2 where `is_x86_feature_detected!` says so,
    /// the scalar rules otherwise.
    pub(crate) fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            return Kernels(Form::Avx2);
        }
        Kernels(Form::Scalar)
    }

    /// The scalar rules, whatever the CPU (tests of the vector forms against them).
    #[cfg(test)]
    pub(crate) fn scalar() -> Self {
        Kernels(Form::Scalar)
    }

    /// Whether these are the vector (AVX2) forms.
    #[cfg(test)]
    pub(crate) fn is_vector(self) -> bool {
        self.0 != Form::Scalar
    }

    /// Σ over the contact set (p > 0) of a step along `t` with product `r` and pressure
    /// f p ([`StepSums`]; Σ g t is left to the caller); all rows of one length.
    #[inline(always)]
    pub(crate) fn step_sums(self, f: f64, p: &[f64], t: &[f64], r: &[f64]) -> StepSums {
        assert!(p.len() == r.len() && t.len() == r.len());
        match self.0 {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `Form::Avx2` is only chosen where the CPU has AVX2 (`detect`); p
            // and t hold r.len() values (asserted).
            Form::Avx2 => unsafe { avx2::step_sums(f, p, t, r) },
            Form::Scalar => scalar::step_sums(f, p, t, r),
        }
    }

    /// The plain direction row: t = g + β t on the contact set (g = f u − z + c, m), 0
    /// off it, written to `input` too; returns Σ g t. All rows hold p.len() values.
    #[inline(always)]
    pub(crate) fn direction_row(
        self,
        fcb: [f64; 3],
        p: &[f64],
        u: &[f64],
        z: &[f64],
        t: &mut [f64],
        input: &mut [f64],
    ) -> f64 {
        match self.0 {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX2 (`detect`); the rows hold p.len() values.
            Form::Avx2 => unsafe { avx2::direction_row(fcb, p, u, z, t, input) },
            Form::Scalar => scalar::direction_row(fcb, p, u, z, t, input),
        }
    }

    /// The preconditioned direction row: t = (y − ȳ) + β t on the contact set, 0 off
    /// it, written to `input` too; returns Σ g t. All rows hold p.len() values.
    #[inline(always)]
    pub(crate) fn direction_pc_row(
        self,
        yb: [f64; 2],
        p: &[f64],
        y: &[f64],
        g: &[f64],
        t: &mut [f64],
        input: &mut [f64],
    ) -> f64 {
        match self.0 {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX2 (`detect`); the rows hold p.len() values.
            Form::Avx2 => unsafe { avx2::direction_pc_row(yb, p, y, g, t, input) },
            Form::Scalar => scalar::direction_pc_row(yb, p, y, g, t, input),
        }
    }

    /// The next direction of a fused iteration (the contact set unchanged): r′ = q + β r,
    /// t′ = g + β t on the set, with the sums of the step along t′ at pressure f′ p.
    /// p, g, t, r hold at least q.len() values.
    #[inline(always)]
    pub(crate) fn next_direction(
        self,
        beta: f64,
        f2: f64,
        pg: [&[f64]; 2],
        tr: [&mut [f64]; 2],
        q: &[f64],
    ) -> StepSums {
        match self.0 {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX2 (`detect`); the rows hold q.len() values.
            Form::Avx2 => unsafe { avx2::next_direction(beta, f2, pg, tr, q) },
            Form::Scalar => scalar::next_direction(beta, f2, pg, tr, q),
        }
    }

    /// The preconditioner's drain: y = q on the contact set (p > 0), 0 off it; returns
    /// [Σ g y, Σ y, Σ g, the count]. p, g, y hold at least q.len() values.
    #[inline(always)]
    pub(crate) fn pc_drain(self, p: &[f64], g: &[f64], y: &mut [f64], q: &[f64]) -> [f64; 4] {
        match self.0 {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX2 (`detect`); the rows hold q.len() values.
            Form::Avx2 => unsafe { avx2::pc_drain(p, g, y, q) },
            Form::Scalar => scalar::pc_drain(p, g, y, q),
        }
    }

    /// Row `i` of a fused iteration's update ([`UpdateFill`]): `rows` = [p, u, g, t, r,
    /// corr], each of the fill's row length.
    #[inline(always)]
    pub(crate) fn update_fill_row(
        self,
        fill: &UpdateFill,
        i: usize,
        rows: [&mut [f64]; 6],
        input: &mut [f64],
    ) -> Sums {
        match self.0 {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX2 (`detect`); the rows hold the fill's nx values.
            Form::Avx2 => unsafe { avx2::update_fill_row(fill, i, rows, input) },
            Form::Scalar => {
                let mut acc = Sums::default();
                fill.points(i, 0..fill.nx, rows, input, &mut acc);
                acc
            }
        }
    }

    /// One chunk of an update pass ([`UpdateStep`]) starting at point `first`; the
    /// chunk's slices of equal lengths.
    #[inline(always)]
    pub(crate) fn update_chunk(self, step: &UpdateStep, first: usize, mut ch: UpdateChunk) -> Sums {
        match self.0 {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX2 (`detect`); equal lengths.
            Form::Avx2 => unsafe { avx2::update_chunk(step, first, ch) },
            Form::Scalar => {
                let mut acc = Sums::default();
                step.points(first, 0..ch.p.len(), &mut ch, &mut acc);
                acc
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::{StepSums, Sums, UpdateChunk, UpdateFill, UpdateStep};

    /// A row of 4k + 3 points mixing the cases: contact points that stay, contact points
    /// projected to p = 0 (one exactly), points off the set that stay off and points that
    /// re-enter, so that blocks take both the vector path and the scalar hand-over.
    fn row(nx: usize) -> [Vec<f64>; 6] {
        let w = |s: f64| (0..nx).map(move |k| (k as f64 * s).sin());
        let mut p: Vec<f64> = w(0.7)
            .enumerate()
            .map(|(k, v)| if k % 3 == 0 { 0.0 } else { 1.0 + v })
            .collect();
        let mut t: Vec<f64> = w(1.3).map(|v| 0.2 * v).collect();
        for k in [16, 17, 19] {
            p[k] = 1.0;
        }
        t[5] = 2.0; // leaves the set past p = 0
        t[10] = 1.0 + (10.0f64 * 0.7).sin(); // reaches p = 0 exactly (τ = 1)
        let mut u: Vec<f64> = w(0.3).map(|v| 0.5 + v).collect();
        let mut r: Vec<f64> = w(2.1).collect();
        // Block 16..20 stays on the vector path, with a point off the set that does not
        // re-enter (old gap > 0) but whose new gap is negative: the interpenetration term.
        u[18] = 1.0;
        r[18] = 30.0;
        [p, u, vec![0.0; nx], t, r, vec![0.0; nx]]
    }

    #[test]
    fn vector_row_loops_equal_the_scalar_rule() {
        let vector = Kernels::detect();
        if !vector.is_vector() {
            eprintln!("no AVX2 on this CPU: the scalar rule runs and is tested elsewhere");
            return;
        }
        let nx = 4 * 9 + 3;
        let z: Vec<f64> = (0..nx).map(|k| 0.9 * (k as f64 * 0.45).cos()).collect();
        let fill = UpdateFill::from_parts(&z, nx, [1.0, 0.1, 1.0, 1.25, -0.05]);
        let (mut a, mut b) = (row(nx), row(nx));
        let (mut ia, mut ib) = (vec![0.0; nx], vec![0.0; nx]);
        let sa = {
            let [p, u, g, t, r, c] = &mut a;
            vector.update_fill_row(&fill, 0, [p, u, g, t, r, c], &mut ia)
        };
        let mut sb = Sums::default();
        {
            let [p, u, g, t, r, c] = &mut b;
            fill.points(0, 0..nx, [p, u, g, t, r, c], &mut ib, &mut sb);
        }
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-13 * (1.0 + x.abs().max(y.abs()));
        for (f, (x, y)) in a.iter().zip(&b).enumerate() {
            assert!(
                x.iter().zip(y).all(|(x, y)| x == y),
                "field {f}: {x:?} vs {y:?}"
            );
        }
        assert_eq!(ia, ib);
        assert!(
            sb.changed.any() && sb.overlap,
            "the row must change the set"
        );
        assert_eq!(sa.changed.points(), sb.changed.points());
        assert_eq!(sa.overlap, sb.overlap);
        for (x, y) in [
            (sa.su, sb.su),
            (sa.sz, sb.sz),
            (sa.m, sb.m),
            (sa.psum, sb.psum),
            (sa.stats.gmax, sb.stats.gmax),
            (sa.stats.psum, sb.stats.psum),
            (sa.stats.gg, sb.stats.gg),
            (sa.stats.pen, sb.stats.pen),
        ] {
            assert!(close(x, y), "{x} vs {y}");
        }

        // The next direction: vector against the scalar loop on the filled row.
        let [p, _, g, t, r, _] = &a;
        let q: Vec<f64> = (0..nx).map(|k| (k as f64 * 0.9).cos()).collect();
        let (mut t1, mut r1, mut t2, mut r2) = (t.clone(), r.clone(), t.clone(), r.clone());
        let (beta, f2) = (0.4, 1.25);
        let d1 = vector.next_direction(beta, f2, [p, g], [&mut t1, &mut r1], &q);
        let mut d2 = StepSums::default();
        for k in 0..nx {
            r2[k] = q[k] + beta * r2[k];
            if p[k] > 0.0 {
                t2[k] = g[k] + beta * t2[k];
                d2.add(f2 * p[k], t2[k], r2[k]);
                d2.gt += g[k] * t2[k];
            }
        }
        assert_eq!(t1, t2);
        assert_eq!(r1, r2);

        // The direction rows and their sums, and the preconditioner's drain.
        let (f, c) = (1.1, 0.05);
        let [p, u, g, t, _, _] = &a;
        let (mut t1, mut t2) = (t.clone(), t.clone());
        let mut i1 = vec![0.0; nx];
        let s1 = vector.direction_row([f, c, beta], p, u, &z, &mut t1, &mut i1);
        let mut s2 = 0.0;
        for k in 0..nx {
            t2[k] = if p[k] > 0.0 {
                let gk = f * u[k] - z[k] + c;
                let v = gk + beta * t2[k];
                s2 += gk * v;
                v
            } else {
                0.0
            };
        }
        assert_eq!(t1, t2);
        assert_eq!(i1, t2);
        assert!(close(s1, s2), "{s1} vs {s2}");
        let (mut t3, mut t4) = (t.clone(), t.clone());
        let ybar = 0.3;
        let s3 = vector.direction_pc_row([ybar, beta], p, &q, g, &mut t3, &mut i1);
        let mut s4 = 0.0;
        for k in 0..nx {
            t4[k] = if p[k] > 0.0 {
                let v = q[k] - ybar + beta * t4[k];
                s4 += g[k] * v;
                v
            } else {
                0.0
            };
        }
        assert_eq!(t3, t4);
        assert!(close(s3, s4), "{s3} vs {s4}");
        let e1 = vector.step_sums(f, p, &t4, &q);
        let mut e2 = StepSums::default();
        for k in 0..nx {
            if p[k] > 0.0 {
                e2.add(f * p[k], t4[k], q[k]);
            }
        }
        for (x, y) in [
            (e1.rt, e2.rt),
            (e1.t, e2.t),
            (e1.r, e2.r),
            (e1.m, e2.m),
            (e1.leave, e2.leave),
        ] {
            assert!(close(x, y), "{x} vs {y}");
        }
        assert!(e2.leave.is_finite());
        let (mut y1, mut y2) = (vec![9.0; nx], vec![9.0; nx]);
        let w1 = vector.pc_drain(p, g, &mut y1, &q);
        let mut w2 = [0.0; 4];
        for k in 0..nx {
            y2[k] = if p[k] > 0.0 { q[k] } else { 0.0 };
            if p[k] > 0.0 {
                w2[0] += g[k] * q[k];
                w2[1] += q[k];
                w2[2] += g[k];
                w2[3] += 1.0;
            }
        }
        assert_eq!(y1, y2);
        for (x, y) in w1.iter().zip(&w2) {
            assert!(close(*x, *y), "{x} vs {y}");
        }

        // The update pass, with and without the error terms of a known offset.
        for known in [None, Some(0.1)] {
            let step = UpdateStep {
                f: 1.0,
                c: 0.1,
                tau: 1.0,
                known,
            };
            let (mut a, mut b) = (row(nx), row(nx));
            let sa = {
                let [p, u, _, t, r, corr] = &mut a;
                let ch = UpdateChunk {
                    p,
                    u,
                    corr,
                    t,
                    r,
                    z: &z,
                };
                vector.update_chunk(&step, 7, ch)
            };
            let mut sb = Sums::default();
            {
                let [p, u, _, t, r, corr] = &mut b;
                let mut ch = UpdateChunk {
                    p,
                    u,
                    corr,
                    t,
                    r,
                    z: &z,
                };
                step.points(7, 0..nx, &mut ch, &mut sb);
            }
            assert_eq!(a, b);
            assert!(sb.changed.any() && sb.overlap);
            assert_eq!(sa.changed.points(), sb.changed.points());
            for (x, y) in [
                (sa.su, sb.su),
                (sa.sz, sb.sz),
                (sa.m, sb.m),
                (sa.psum, sb.psum),
                (sa.stats.gmax, sb.stats.gmax),
                (sa.stats.psum, sb.stats.psum),
                (sa.stats.gg, sb.stats.gg),
                (sa.stats.pen, sb.stats.pen),
            ] {
                assert!(close(x, y), "{known:?}: {x} vs {y}");
            }
            if known.is_some() {
                assert!(
                    sb.stats.pen > 1.0,
                    "the row must interpenetrate: {}",
                    sb.stats.pen
                );
            }
        }
        for (x, y) in [
            (d1.gt, d2.gt),
            (d1.rt, d2.rt),
            (d1.t, d2.t),
            (d1.r, d2.r),
            (d1.m, d2.m),
            (d1.leave, d2.leave),
        ] {
            assert!(close(x, y), "{x} vs {y}");
        }
    }
}
