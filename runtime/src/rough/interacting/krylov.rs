//! The linear systems of the I model's Newton steps (J s = −F) and stiffness
//! (J da/dδ = 2·1) on the active set. With dense pair sums the Jacobian is formed and
//! factored (LU); with the grid sums it is never formed: preconditioned conjugate
//! gradients on the symmetric form
//!
//! ```text
//! H = D J,  D = diag(Q'_k),  H_kl = Q'_k J_kl = N_kl·(Q'_k z_l + Q'_l z_k) (k ≠ l)
//! ```
//!
//! (H is the Hessian of U_E/c in a, interacting module docs, positive definite at a
//! minimum), with Jacobian–vector products from the same fast sums as F:
//!
//! ```text
//! (J v)_k = Σ_{l≠k} N_kl·(z_l v_l) + z_k·Σ_{l≠k} N_kl Q'_l v_l / Q'_k
//!           + near exact terms + J_kk v_k,   z_l = (Q'_l ℓ(a_l) + Q_l ℓ'(a_l))/π,
//! ```
//!
//! and a symmetric Gauss–Seidel (SSOR, ω = 1) preconditioner M = (D + L) D⁻¹ (D + Lᵀ)
//! built from the near field of H: its diagonal D and its entries between asperities
//! closer than r_near (exact near pairs from the energy state; the others from the far
//! model's leading three Chebyshev coefficients of the pair, [`PairSums::near_pairs`]).
//! M is symmetric positive definite whenever D > 0, whatever the coupling, and carries
//! the strong short-range couplings the Jacobi preconditioner diag(H) misses.
//! Negative curvature (pᵀHp ≤ 0) ends the iteration with the iterate so far (the Newton
//! line search then checks descent and falls back to its scaled steepest descent).
//!
//! [`PairSums::near_pairs`]: super::pair_sums::PairSums::near_pairs

use super::energy::{Energy, State};
use super::far_field::{NB, Vb, dot};
use super::lu::lu_solve;

/// The solve of J x = b on the active set `act` at the state `st`: dense LU with the
/// dense sums, conjugate gradients to the relative residual `rtol` (max-norm, F units)
/// with the grid sums. None when singular or not finite.
pub(crate) fn solve(
    en: &Energy,
    st: &mut State,
    act: &[usize],
    b: &[f64],
    rtol: f64,
) -> Option<Vec<f64>> {
    if en.geo.sums.grid().is_none() {
        let mut jm = en.jacobian(st, act);
        let mut rhs = b.to_vec();
        return lu_solve(&mut jm, &mut rhs, act.len());
    }
    let mut op = Operator::new(en, st, act);
    let max_it = (4 * act.len()).clamp(50, 2000);
    // where H is indefinite (contacts just activated, overlapping) the SSOR direction
    // can meet negative curvature at once: then Jacobi, as the line search expects
    let pre = Ssor::new(&op, true);
    cg(&mut op, &pre, b, rtol, max_it).or_else(|| {
        let jacobi = Ssor::new(&op, false);
        cg(&mut op, &jacobi, b, rtol, max_it)
    })
}

/// J v on the active set with the fast sums (module docs).
struct Operator<'s, 'e, 'p> {
    en: &'e Energy<'p>,
    st: &'s mut State,
    act: &'s [usize],
    /// J_kk and Q'_k on the active set.
    diag: Vec<f64>,
    dq: Vec<f64>,
    /// z_l per local index (zero off the active set).
    z: Vec<Vb>,
    /// Position of a local index in `act` (usize::MAX when inactive).
    pos: Vec<usize>,
    src: Vec<Vb>,
    sc: Vec<f64>,
    od: Vec<f64>,
    ou: Vec<Vb>,
}

impl<'s, 'e, 'p> Operator<'s, 'e, 'p> {
    fn new(en: &'e Energy<'p>, st: &'s mut State, act: &'s [usize]) -> Self {
        let n = en.geo.n();
        let pi = std::f64::consts::PI;
        let mut z = vec![[0.0; NB]; n];
        let mut pos = vec![usize::MAX; n];
        for (ii, &l) in act.iter().enumerate() {
            pos[l] = ii;
            let (lq, (b, db)) = (&st.loc[l], &st.basis[l]);
            for i in 0..NB {
                z[l][i] = (lq.dq * b[i] + lq.q * db[i]) / pi;
            }
        }
        let diag = act.iter().map(|&p| en.diagonal(st, p)).collect();
        let dq = act.iter().map(|&p| st.loc[p].dq).collect();
        Operator {
            en,
            st,
            act,
            diag,
            dq,
            z,
            pos,
            src: vec![[0.0; NB]; n],
            sc: vec![0.0; n],
            od: vec![0.0; n],
            ou: vec![[0.0; NB]; n],
        }
    }

    /// out = J v (v and out on the active set); false when the sums fail.
    fn apply(&mut self, v: &[f64], out: &mut [f64]) -> bool {
        let geo = self.en.geo;
        for (ii, &l) in self.act.iter().enumerate() {
            self.src[l] = self.z[l].map(|x| x * v[ii]);
            self.sc[l] = self.dq[ii] * v[ii];
        }
        if geo
            .interact(
                &self.src,
                &self.sc,
                self.en.deltas,
                &mut self.od,
                &mut self.ou,
                &mut self.st.work,
                true,
            )
            .is_err()
        {
            return false;
        }
        for (ii, &k) in self.act.iter().enumerate() {
            out[ii] =
                self.od[k] + dot(&self.z[k], &self.ou[k]) / self.dq[ii] + self.diag[ii] * v[ii];
        }
        for (e, &(p, q, _)) in geo.near.iter().enumerate() {
            let (ip, iq) = (self.pos[p], self.pos[q]);
            if ip == usize::MAX || iq == usize::MAX {
                continue;
            }
            let [_, hp, _, hq] = self.st.near_vals[e];
            let (dp, dq) = (self.dq[ip], self.dq[iq]);
            out[iq] += (hp + dp * hq / dq) * v[ip];
            out[ip] += (hq + dq * hp / dp) * v[iq];
        }
        if let Some(zm) = self.en.zero_mean {
            // 2 Σ_{l≠k} V_kl Q'_l v_l (the diagonal's share is in J_kk)
            self.od.iter_mut().for_each(|x| *x = 0.0);
            for (ii, &l) in self.act.iter().enumerate() {
                self.od[l] = self.dq[ii] * v[ii];
            }
            let w = self.od.clone();
            zm.apply(&geo.pos, &w, &mut self.od);
            for (ii, &k) in self.act.iter().enumerate() {
                out[ii] += 2.0 * (self.od[k] - w[k] * zm.v0);
            }
        }
        true
    }
}

/// The SSOR preconditioner of H on the active set (module docs): the diagonal and the
/// strictly lower near-field entries in rows (CSR, columns ascending).
struct Ssor {
    d: Vec<f64>,
    start: Vec<usize>,
    col: Vec<u32>,
    val: Vec<f64>,
}

impl Ssor {
    /// The preconditioner at the operator's state; `coupled` false: Jacobi (D only).
    fn new(op: &Operator, coupled: bool) -> Ssor {
        let m = op.act.len();
        let d: Vec<f64> = op
            .diag
            .iter()
            .zip(&op.dq)
            .map(|(j, q)| {
                let h = (j * q).abs();
                if h > 0.0 && h.is_finite() { h } else { 1.0 }
            })
            .collect();
        let geo = op.en.geo;
        let mut start = vec![0usize; m + 1];
        let (mut col, mut val) = (Vec::new(), Vec::new());
        let Some((pairs, lead)) = geo.sums.near_pairs().filter(|_| coupled) else {
            return Ssor { d, start, col, val };
        };
        // merge-join of the near pairs with the exact near list (one entry per image),
        // both sorted by (q, p): rows of ascending q, columns of ascending p
        let near = &geo.near;
        let key = |e: usize| (near[e].1, near[e].0);
        let mut e = 0;
        let mut row = 0;
        for (&(p, q), c) in pairs.iter().zip(lead) {
            let (p, q) = (p as usize, q as usize);
            let (ip, iq) = (op.pos[p], op.pos[q]);
            let active = ip != usize::MAX && iq != usize::MAX;
            let mut h = 0.0;
            while e < near.len() && key(e) < (q, p) {
                e += 1;
            }
            while e < near.len() && key(e) == (q, p) {
                if active {
                    let [_, hp, _, hq] = op.st.near_vals[e];
                    h += op.dq[iq] * hp + op.dq[ip] * hq;
                }
                e += 1;
            }
            if !active {
                continue;
            }
            for (j, &cj) in c.iter().enumerate() {
                h += f64::from(cj) * (op.dq[ip] * op.z[q][j] + op.dq[iq] * op.z[p][j]);
            }
            if h == 0.0 || !h.is_finite() {
                continue;
            }
            while row < iq {
                row += 1;
                start[row] = col.len();
            }
            col.push(ip as u32);
            val.push(h);
        }
        while row < m {
            row += 1;
            start[row] = col.len();
        }
        Ssor { d, start, col, val }
    }

    /// out = M⁻¹ r: (D + L) y = r forwards by rows, then (D + Lᵀ) x = D y backwards
    /// (Lᵀ applied by the columns of L).
    fn apply(&self, r: &[f64], out: &mut [f64]) {
        let m = self.d.len();
        for i in 0..m {
            let mut s = r[i];
            for e in self.start[i]..self.start[i + 1] {
                s -= self.val[e] * out[self.col[e] as usize];
            }
            out[i] = s / self.d[i];
        }
        for (o, d) in out.iter_mut().zip(&self.d) {
            *o *= d;
        }
        for i in (0..m).rev() {
            let xi = out[i] / self.d[i];
            out[i] = xi;
            for e in self.start[i]..self.start[i + 1] {
                out[self.col[e] as usize] -= self.val[e] * xi;
            }
        }
    }
}

/// Preconditioned conjugate gradients on H = D J for J x = b (module docs): stops when
/// max_k |(b − J x)_k| ≤ rtol·max_k |b_k|, on negative curvature, or after `max_it`
/// iterations (the iterate so far). None when not finite or no progress at all.
fn cg(op: &mut Operator, pre: &Ssor, b: &[f64], rtol: f64, max_it: usize) -> Option<Vec<f64>> {
    let m = b.len();
    let dq = op.dq.clone();
    let bmax = b.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut x = vec![0.0; m];
    if bmax == 0.0 {
        return Some(x);
    }
    // residual of H x = D b
    let mut r: Vec<f64> = b.iter().zip(&dq).map(|(v, q)| v * q).collect();
    let mut z = vec![0.0; m];
    pre.apply(&r, &mut z);
    let mut p = z.clone();
    let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
    let mut hp = vec![0.0; m];
    for it in 0..max_it {
        if !op.apply(&p, &mut hp) {
            return None;
        }
        hp.iter_mut().zip(&dq).for_each(|(v, q)| *v *= q);
        let php: f64 = p.iter().zip(&hp).map(|(a, b)| a * b).sum();
        if !php.is_finite() {
            return None;
        }
        if php <= 0.0 {
            return if it == 0 { None } else { Some(x) };
        }
        let alpha = rz / php;
        for i in 0..m {
            x[i] += alpha * p[i];
            r[i] -= alpha * hp[i];
        }
        let rmax = r
            .iter()
            .zip(&dq)
            .fold(0.0f64, |a, (v, q)| a.max((v / q).abs()));
        if !rmax.is_finite() {
            return None;
        }
        if rmax <= rtol * bmax {
            break;
        }
        pre.apply(&r, &mut z);
        let rz_new: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..m {
            p[i] = z[i] + beta * p[i];
        }
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}
