//! Solution of the Fredholm equation of the second kind (physics.md §3, paper eq. P9)
//!
//! ```text
//!   φ(s) + ∫₀¹ K_a(s,t) φ(t) dt = G(s),   0 ≤ s ≤ 1,
//! ```
//!
//! for several right-hand sides G at once (the kernel of [`crate::kernel`]).
//!
//! Two discretisations, which must agree where both apply:
//! * [`Discretisation::Nystrom`]: Gauss–Legendre nodes on [0, 1], spectrally accurate while
//!   the kernel is wide (a ≲ a few h₁). φ(1) and φ on a uniform grid come from the
//!   Nyström interpolant φ(s) = G(s) − Σ_j w_j K(s,t_j) φ_j.
//! * [`Discretisation::Product`]: product integration with piecewise-linear φ on the uniform
//!   grid t_j = jΔ, Δ = 1/N, collocated at the grid points. ∫₀¹ K(s_i,t) hat_j(t) dt is
//!   exact in t (see [`crate::kernel::KzQuadrature::product_moments`]):
//!   interior hats ½[Dh(|i−j|) + Dh(i+j)], the half hat at t = 0 ½Dh(i) (K is even in t),
//!   the half hat at t = 1 ½[E(N−i) + E(N+i)]. The kernel's width ~h₁/a is resolved by
//!   the moments, whatever N is; N only has to resolve φ. The scheme is O(Δ²); with
//!   `richardson` the scalar outputs (φ(1), ∫φ) of N and N/2 are extrapolated,
//!   (4·f_N − f_{N/2})/3.
//!
//! The dense systems are solved by LU with partial pivoting (faer).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve as lu};
use faer::{Mat, Par};
use rayon::prelude::*;
use thiserror::Error;

use crate::kernel::{KzQuadrature, gauss_legendre};

/// How the integral operator is discretised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Discretisation {
    /// Gauss–Legendre Nyström with `nodes` nodes.
    Nystrom { nodes: usize },
    /// Product integration on `intervals` uniform intervals (even, ≥ 4), optionally
    /// Richardson-extrapolated against `intervals/2`.
    Product { intervals: usize, richardson: bool },
}

/// Errors of the Fredholm solve.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FredholmError {
    /// The kernel quadrature does not resolve cos(u x) far enough.
    #[error("kernel quadrature resolves |x| ≤ {have} m but the solve needs {need} m")]
    RangeTooShort { have: f64, need: f64 },
    /// Bad discretisation parameters.
    #[error("bad discretisation: {0}")]
    BadDiscretisation(String),
    /// The contact radius must be positive and finite.
    #[error("contact radius a must be positive and finite, got {0} m")]
    BadRadius(f64),
    /// The linear system produced a non-finite solution (singular operator).
    #[error("the discretised Fredholm system is singular or produced a non-finite value")]
    NonFinite,
}

/// The solution for each right-hand side.
#[derive(Debug, Clone, PartialEq)]
pub struct FredholmSolution {
    /// φ_r(1) for each right-hand side r.
    pub at_one: Vec<f64>,
    /// ∫₀¹ φ_r(t) dt for each right-hand side r.
    pub integral: Vec<f64>,
    /// φ_r on the uniform grid s_i = i/(grid.len()−1) (empty when not requested).
    pub grid: Vec<Vec<f64>>,
}

/// Systems up to this size are factored sequentially: for them rayon's thread
/// hand-offs cost more than they save (measured 10× slower at n = 64 on a loaded
/// 2-core machine), and callers may already run solves in parallel.
pub const SEQUENTIAL_LU_MAX: usize = 256;

/// Solves `mat · x = rhs` in place (LU with partial pivoting, faer).
fn lu_solve_in_place(mut mat: Mat<f64>, rhs: &mut Mat<f64>) {
    let n = mat.nrows();
    let par = if n <= SEQUENTIAL_LU_MAX {
        Par::Seq
    } else {
        faer::get_global_parallelism()
    };
    let req = factor::lu_in_place_scratch::<usize, f64>(n, n, par, Default::default()).or(
        lu::solve_in_place_scratch::<usize, f64>(n, rhs.ncols(), par),
    );
    let mut mem = MemBuffer::new(req);
    let stack = MemStack::new(&mut mem);
    let mut perm = vec![0usize; n];
    let mut perm_inv = vec![0usize; n];
    let (_, p) = factor::lu_in_place(
        mat.as_mut(),
        &mut perm,
        &mut perm_inv,
        par,
        stack,
        Default::default(),
    );
    lu::solve_in_place(mat.as_ref(), mat.as_ref(), p, rhs.as_mut(), par, stack);
    if par != Par::Seq {
        // The parallel kernels leave the AVX registers' upper halves dirty on the
        // threads that ran them; see `clear_upper_simd`.
        clear_upper_simd();
        rayon::broadcast(|_| clear_upper_simd());
    }
}

/// `vzeroupper` on the calling thread when the CPU has AVX (a no-op otherwise).
///
/// faer's parallel LU (systems above [`SEQUENTIAL_LU_MAX`]) leaves the upper halves of
/// the AVX registers dirty on the rayon workers, and SSE code that runs there afterwards
/// is then several times slower: a 13×7 table build measured 0.33 s in a fresh process,
/// 1.0–1.4 s after product-integration solves, 0.31 s again after `vzeroupper` on the
/// workers. [`solve`] clears the state on every worker after each parallel LU.
pub fn clear_upper_simd() {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx")]
        fn zeroupper() {
            core::arch::x86_64::_mm256_zeroupper();
        }
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU supports AVX (checked just above).
            unsafe { zeroupper() }
        }
    }
}

/// A right-hand side G(s) on [0, 1].
pub type Rhs<'a> = &'a (dyn Fn(f64) -> f64 + Sync);

fn check_finite(v: &[f64]) -> Result<(), FredholmError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(FredholmError::NonFinite)
    }
}

/// Solves φ + K_a φ = G_r for every r. `grid` > 0 asks for φ on `grid + 1` uniform
/// points (the product method returns its own N + 1 grid points instead).
/// `quad` must resolve |x| ≤ a (Nyström) or 2a (product).
pub fn solve(
    quad: &KzQuadrature,
    a: f64,
    disc: Discretisation,
    rhs: &[Rhs<'_>],
    grid: usize,
) -> Result<FredholmSolution, FredholmError> {
    if !(a.is_finite() && a > 0.0) {
        return Err(FredholmError::BadRadius(a));
    }
    match disc {
        Discretisation::Nystrom { nodes } => {
            if !(2..=4000).contains(&nodes) {
                return Err(FredholmError::BadDiscretisation(format!(
                    "Nyström nodes must be in 2..=4000, got {nodes}"
                )));
            }
            if quad.x_max < a * (1.0 - 1e-12) {
                return Err(FredholmError::RangeTooShort {
                    have: quad.x_max,
                    need: a,
                });
            }
            nystrom(quad, a, nodes, rhs, grid)
        }
        Discretisation::Product {
            intervals,
            richardson,
        } => {
            if intervals < 4 || intervals % 2 != 0 || intervals > 20_000 {
                return Err(FredholmError::BadDiscretisation(format!(
                    "product intervals must be even and in 4..=20000, got {intervals}"
                )));
            }
            if quad.x_max < 2.0 * a * (1.0 - 1e-12) {
                return Err(FredholmError::RangeTooShort {
                    have: quad.x_max,
                    need: 2.0 * a,
                });
            }
            if !richardson {
                return product(quad, a, intervals, rhs);
            }
            let fine = product(quad, a, intervals, rhs)?;
            let coarse = product(quad, a, intervals / 2, rhs)?;
            Ok(self::richardson(&fine, &coarse))
        }
    }
}

/// Product integration with Richardson extrapolation on grids doubled from
/// `intervals` (rounded up to a multiple of 4): while the extrapolations from (N/4, N/2)
/// and (N/2, N) differ (relative, in φ(1) and ∫φ, [`relative_change`]) by more than
/// `tol`, N is doubled, up to `max_intervals`; the last extrapolation is returned. The
/// difference estimates the error of the coarser extrapolation; the accepted one is
/// several times better. Costs one extra N/4 solve when the first N suffices. The
/// caller checks the quadrature range (≥ 2a) as for [`solve`].
pub fn product_adaptive(
    quad: &KzQuadrature,
    a: f64,
    intervals: usize,
    rhs: &[Rhs<'_>],
    tol: f64,
    max_intervals: usize,
) -> Result<FredholmSolution, FredholmError> {
    let mut n_int = intervals.next_multiple_of(4);
    let mut quarter = product(quad, a, n_int / 4, rhs)?;
    let mut half = product(quad, a, n_int / 2, rhs)?;
    loop {
        let full = product(quad, a, n_int, rhs)?;
        let ext = richardson(&full, &half);
        let prev = richardson(&half, &quarter);
        if relative_change(&ext, &prev) <= tol || 2 * n_int > max_intervals {
            return Ok(ext);
        }
        quarter = half;
        half = full;
        n_int *= 2;
    }
}

/// Richardson extrapolation of the O(Δ²) product scheme: f = (4 f_N − f_{N/2})/3 for
/// φ(1) and ∫φ of every right-hand side; the grid is the N solution's.
pub fn richardson(fine: &FredholmSolution, coarse: &FredholmSolution) -> FredholmSolution {
    let ex = |f: &[f64], c: &[f64]| -> Vec<f64> {
        f.iter().zip(c).map(|(f, c)| (4.0 * f - c) / 3.0).collect()
    };
    FredholmSolution {
        at_one: ex(&fine.at_one, &coarse.at_one),
        integral: ex(&fine.integral, &coarse.integral),
        grid: fine.grid.clone(),
    }
}

/// Largest relative difference between two solutions' φ(1) and ∫φ (0 where both are 0):
/// the error estimate of the coarser of two successive Richardson extrapolations.
pub fn relative_change(a: &FredholmSolution, b: &FredholmSolution) -> f64 {
    a.at_one
        .iter()
        .zip(&b.at_one)
        .chain(a.integral.iter().zip(&b.integral))
        .map(|(x, y)| {
            let d = (x - y).abs();
            if d == 0.0 {
                0.0
            } else {
                d / x.abs().max(y.abs())
            }
        })
        .fold(0.0, f64::max)
}

fn nystrom(
    quad: &KzQuadrature,
    a: f64,
    n: usize,
    rhs: &[Rhs<'_>],
    grid: usize,
) -> Result<FredholmSolution, FredholmError> {
    let (x, w) = gauss_legendre(n);
    let t: Vec<f64> = x.iter().map(|x| 0.5 * (x + 1.0)).collect();
    let w: Vec<f64> = w.iter().map(|w| 0.5 * w).collect();
    let k = quad.kernel_matrix(a, &t, &t);
    let mat = Mat::from_fn(n, n, |i, j| {
        k[i * n + j] * w[j] + if i == j { 1.0 } else { 0.0 }
    });
    let mut b = Mat::from_fn(n, rhs.len(), |i, r| rhs[r](t[i]));
    lu_solve_in_place(mat, &mut b);
    let phi: Vec<Vec<f64>> = (0..rhs.len())
        .map(|r| (0..n).map(|i| b[(i, r)]).collect())
        .collect();
    for p in &phi {
        check_finite(p)?;
    }
    // Nyström interpolant at s = 1 and on the grid.
    let mut s_eval = vec![1.0];
    if grid > 0 {
        s_eval.extend((0..=grid).map(|i| i as f64 / grid as f64));
    }
    // Separable kernel: Σ_j w_j K(s,t_j) φ_j = Σ_k c_k cos(a u_k s) F_k with
    // F_k = Σ_j w_j φ_j cos(a u_k t_j), c_k = (2a/π) w_k k_z(u_k): O((N + grid)·M).
    let m = quad.len();
    let ck: Vec<f64> = (0..m)
        .map(|k| 2.0 * a / std::f64::consts::PI * quad.w[k] * quad.kz[k])
        .collect();
    let mut fk = vec![vec![0.0; m]; rhs.len()];
    for j in 0..n {
        for (k, u) in quad.u.iter().enumerate() {
            let c = w[j] * (a * u * t[j]).cos();
            for (f, p) in fk.iter_mut().zip(&phi) {
                f[k] += c * p[j];
            }
        }
    }
    let corr: Vec<Vec<f64>> = s_eval
        .par_iter()
        .map(|&se| {
            let mut acc = vec![0.0; rhs.len()];
            for k in 0..m {
                let c = ck[k] * (a * quad.u[k] * se).cos();
                for r in 0..rhs.len() {
                    acc[r] += c * fk[r][k];
                }
            }
            acc
        })
        .collect();
    let interp = |r: usize, e: usize| -> f64 { rhs[r](s_eval[e]) - corr[e][r] };
    let at_one: Vec<f64> = (0..rhs.len()).map(|r| interp(r, 0)).collect();
    let integral: Vec<f64> = phi
        .iter()
        .map(|p| p.iter().zip(&w).map(|(p, w)| p * w).sum())
        .collect();
    let grid_vals: Vec<Vec<f64>> = if grid > 0 {
        (0..rhs.len())
            .map(|r| (1..s_eval.len()).map(|e| interp(r, e)).collect())
            .collect()
    } else {
        Vec::new()
    };
    check_finite(&at_one)?;
    check_finite(&integral)?;
    Ok(FredholmSolution {
        at_one,
        integral,
        grid: grid_vals,
    })
}

/// Product integration on `n` uniform intervals, without extrapolation (see the module
/// docs). The caller checks `n` (even, ≥ 4) and the quadrature range ([`solve`] does).
pub fn product(
    quad: &KzQuadrature,
    a: f64,
    n: usize,
    rhs: &[Rhs<'_>],
) -> Result<FredholmSolution, FredholmError> {
    let delta = 1.0 / n as f64;
    let (dh, e) = quad.product_moments(a, delta, 2 * n);
    let mat = Mat::from_fn(n + 1, n + 1, |i, j| {
        let kij = if j == 0 {
            0.5 * dh[i]
        } else if j == n {
            0.5 * (e[n - i] + e[n + i])
        } else {
            0.5 * (dh[i.abs_diff(j)] + dh[i + j])
        };
        kij + if i == j { 1.0 } else { 0.0 }
    });
    let mut b = Mat::from_fn(n + 1, rhs.len(), |i, r| rhs[r](i as f64 * delta));
    lu_solve_in_place(mat, &mut b);
    let grid: Vec<Vec<f64>> = (0..rhs.len())
        .map(|r| (0..=n).map(|i| b[(i, r)]).collect())
        .collect();
    for g in &grid {
        check_finite(g)?;
    }
    let at_one = grid.iter().map(|g| g[n]).collect();
    let integral = grid
        .iter()
        .map(|g| delta * (g.iter().sum::<f64>() - 0.5 * (g[0] + g[n])))
        .collect();
    Ok(FredholmSolution {
        at_one,
        integral,
        grid,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_runtime::{Base, Compliance, Layer, Stack};

    fn stack(e2: f64) -> Stack {
        Stack::new(
            vec![
                Layer {
                    thickness: 1e-4,
                    young: 4e9,
                    poisson: 0.15,
                },
                Layer {
                    thickness: 9e-4,
                    young: 4e9 * e2,
                    poisson: 0.15,
                },
            ],
            Base::Rigid,
        )
        .unwrap()
    }

    fn run(st: &Stack, a: f64, disc: Discretisation) -> FredholmSolution {
        let comp = Compliance::new(st);
        let q = KzQuadrature::new(st, &comp, 2.0 * a).unwrap();
        let one = |_s: f64| 1.0;
        let sq = |s: f64| s * s;
        solve(&q, a, disc, &[&one, &sq], 0).unwrap()
    }

    /// The AVX upper state in use on this thread (XINUSE bits 2 and 6, YMM_Hi128 and
    /// ZMM_Hi256, read with XGETBV(1)); `None` where the CPU cannot report it.
    #[cfg(target_arch = "x86_64")]
    fn avx_upper_in_use() -> Option<u64> {
        use core::arch::x86_64::{__cpuid_count, _xgetbv};
        if !std::arch::is_x86_feature_detected!("xsave") {
            return None;
        }
        #[allow(unused_unsafe)]
        // SAFETY: CPUID exists on every x86_64 CPU.
        let leaf = unsafe { __cpuid_count(0xD, 1) };
        if leaf.eax & (1 << 2) == 0 {
            return None;
        }
        #[target_feature(enable = "xsave")]
        fn xinuse() -> u64 {
            // SAFETY: XGETBV with ECX = 1 is supported (CPUID.(0DH, 1):EAX[2]).
            unsafe { _xgetbv(1) }
        }
        // SAFETY: the CPU has XSAVE (checked above).
        Some(unsafe { xinuse() } & ((1 << 2) | (1 << 6)))
    }

    /// After an LU, sequential (n = 96) or parallel (n = 600 > `SEQUENTIAL_LU_MAX`), no
    /// thread of the pool that ran it keeps the AVX upper state in use: SSE code on those
    /// threads then runs at full speed (see `clear_upper_simd`; without the clear after
    /// the parallel LU a worker reports 68 = bits 2 | 6, and a table build on such
    /// workers ran 3–4× slower). The sequential LU needs no clear (measured clean).
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn parallel_lu_leaves_the_avx_upper_state_clean() {
        let Some(_) = avx_upper_in_use() else {
            eprintln!("*** XGETBV(1) is not available on this CPU: the SIMD state is NOT checked");
            return;
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let st = stack(5.0);
        for nodes in [96, 600] {
            let sol = pool.install(|| run(&st, 2e-4, Discretisation::Nystrom { nodes }));
            assert!(sol.at_one.iter().all(|v| v.is_finite()));
            let state = pool.broadcast(|_| avx_upper_in_use());
            assert!(
                state.iter().all(|s| *s == Some(0)),
                "XINUSE bits 2 | 6 per worker after the LU of {nodes} nodes: {state:?}"
            );
        }
    }

    /// Nyström and product integration agree where both apply (a/h = 0.5, 2, 4).
    #[test]
    fn nystrom_and_product_agree() {
        for e2 in [0.2, 5.0] {
            let st = stack(e2);
            for ah in [0.5, 2.0, 4.0] {
                let a = ah * 1e-4;
                let ny = run(&st, a, Discretisation::Nystrom { nodes: 96 });
                let pr = run(
                    &st,
                    a,
                    Discretisation::Product {
                        intervals: 512,
                        richardson: true,
                    },
                );
                for r in 0..2 {
                    let d1 = (ny.integral[r] - pr.integral[r]).abs() / ny.integral[r].abs();
                    let d2 = (ny.at_one[r] - pr.at_one[r]).abs() / ny.at_one[r].abs();
                    assert!(
                        d1 < 1e-8 && d2 < 1e-8,
                        "E2/E1 {e2} a/h {ah} r {r}: {d1:e} {d2:e}"
                    );
                }
            }
        }
    }

    /// Product integration converges at second order without extrapolation.
    #[test]
    fn product_converges_at_second_order() {
        let st = stack(0.2);
        let a = 3e-4;
        let reference = run(&st, a, Discretisation::Nystrom { nodes: 128 }).integral[1];
        let mut errs = Vec::new();
        for n in [32, 64, 128, 256] {
            let p = run(
                &st,
                a,
                Discretisation::Product {
                    intervals: n,
                    richardson: false,
                },
            );
            errs.push((p.integral[1] - reference).abs() / reference.abs());
        }
        for w in errs.windows(2) {
            let ratio = w[0] / w[1];
            assert!((3.5..4.5).contains(&ratio), "errors {errs:?}");
        }
    }

    /// Nyström converges spectrally: the error against 128 nodes falls with 3, 5, 8
    /// nodes and is at round-off by 24 (a/h = 2).
    #[test]
    fn nystrom_converges() {
        let st = stack(5.0);
        let a = 2e-4;
        let r128 = run(&st, a, Discretisation::Nystrom { nodes: 128 });
        let err = |n: usize| {
            let r = run(&st, a, Discretisation::Nystrom { nodes: n });
            ((r.integral[1] - r128.integral[1]) / r128.integral[1]).abs()
        };
        let e: Vec<f64> = [3, 5, 8, 24].iter().map(|&n| err(n)).collect();
        assert!(e[0] > e[1] && e[1] > e[2], "{e:?}");
        assert!(e[3] < 1e-13, "{e:?}");
    }

    #[test]
    fn bad_parameters_are_errors() {
        let st = stack(5.0);
        let comp = Compliance::new(&st);
        let q = KzQuadrature::new(&st, &comp, 1e-4).unwrap();
        let one = |_s: f64| 1.0;
        let r = solve(&q, 1e-3, Discretisation::Nystrom { nodes: 8 }, &[&one], 0);
        assert!(matches!(r, Err(FredholmError::RangeTooShort { .. })));
        let r = solve(&q, -1.0, Discretisation::Nystrom { nodes: 8 }, &[&one], 0);
        assert!(matches!(r, Err(FredholmError::BadRadius(_))));
        let r = solve(
            &q,
            1e-5,
            Discretisation::Product {
                intervals: 7,
                richardson: false,
            },
            &[&one],
            0,
        );
        assert!(matches!(r, Err(FredholmError::BadDiscretisation(_))));
    }
}
