//! The I-model energy U_E (P22), its scaled gradient F and Jacobian ∂F/∂a on a prepared
//! geometry (interacting module docs). [`State`] is the workspace of one solve: it is
//! allocated once and refilled at every evaluation.

use super::far_field::{FarModel, NB, Vb, bracket, dot};
use super::images::Prepared;
use super::pair_sums::Work;
use super::uniform::ZeroMean;
use crate::law::AsperityLaw;
use crate::rough::local::Local;

/// Zero basis (inactive asperity or no far model).
const ZB: (Vb, Vb) = ([0.0; NB], [0.0; NB]);

/// Relative step ε/a of the one-sided differences of g in r at the contact edge
/// ([`inside_bracket`]): small against h₁ for the table's a/h₁ ≤ 1e3, large against the
/// round-off of g.
const EDGE_STEP: f64 = 1e-5;

/// Relative step of the central differences in a of the g part of [`inside_bracket`].
const INSIDE_STEP: f64 = 1e-3;

/// The bracket M(a, r) (m²) of G inside the contact circle, r ≤ a, and ∂M/∂a (m),
/// ∂²M/∂a² (-): G = χ(a) M(a, r)/(πR), the same form as outside (G = χB/(πR)).
///
/// Inside its own contact an asperity's surface is displaced by the second-order
/// displacement of eq. (P18), u(r) = (2a²ζ − r²)/(2R): a parabola in r, so an asperity
/// centre at r < a feels u(r), not the centre value a²ζ/R that eq. (P19) uses (which
/// jumps by ≈ a²/(2R) at r = a, so U_E has no minimum where a contact grows over another
/// centre: the I model then stalls). strata uses the parabola in r that joins the
/// outside displacement with its value and slope at r = a,
///
/// ```text
/// M(a, r) = B(a, a) + (πa − g_r(a)) (a² − r²)/(2a),
/// B(a, a) = πa²/2 + g(a, a),  g_r(a) = ∂g/∂r (a, a⁺),
/// ```
///
/// (−χ(πa − g_r)/(πR) is ∂u/∂r at r = a⁺; the half-space part of B has ∂B₀/∂r = −πa
/// there). Then G is continuous at r = a and so is ∂G/∂a (to the accuracy of g_r: the
/// one-sided difference of the law's g), so U_E is C¹ and its minimum exists. On a
/// homogeneous solid M = π(2a² − r²)/2 and G is eq. (P18) inside exactly; on a layered
/// solid it differs from (P18) by the second-order approximation's own mismatch at the
/// edge. Only overlapping contacts (flagged in the step's validity) reach it.
pub(crate) fn inside_bracket(law: &dyn AsperityLaw, a: f64, r: f64) -> (f64, f64, f64) {
    let pi = std::f64::consts::PI;
    // half-space part π(2a² − r²)/2, exact derivatives
    let (hs, dhs, d2hs) = (0.5 * pi * (2.0 * a * a - r * r), 2.0 * pi * a, 2.0 * pi);
    if law.is_homogeneous() {
        return (hs, dhs, d2hs);
    }
    // g part m(x) = g(x, x) − g_r(x) (x² − r²)/(2x)
    let part = |x: f64| {
        // g_r from forward differences D(ε) = D₀ + c√ε + O(ε) (a table interpolated in
        // w ∝ √(r − a) carries a (r − a)^{3/2} term): D₀ ≈ 2D(ε) − D(4ε)
        let e = EDGE_STEP * x;
        let (g0, g1, g4) = (law.g(x, x), law.g(x, x + e), law.g(x, x + 4.0 * e));
        let gr = 2.0 * (g1 - g0) / e - (g4 - g0) / (4.0 * e);
        g0 - gr * (x * x - r * r) / (2.0 * x)
    };
    let h = INSIDE_STEP * a;
    let (m0, mp, mm) = (part(a), part(a + h), part(a - h));
    (
        hs + m0,
        dhs + (mp - mm) / (2.0 * h),
        d2hs + (mp - 2.0 * m0 + mm) / (h * h),
    )
}

/// [G, ∂G/∂a, c₀, c_χ] of an asperity (contact radius a, radius R, local quantities `l`)
/// at distance r: G = χ(a)B(a, r)/(πR) outside (r > a, eq. P19, [`bracket`]) and
/// χ(a)M(a, r)/(πR) inside ([`inside_bracket`]), with ∂²G/∂a² = c₀ + c_χ χ″ (the law
/// gives no second derivatives of χ): G″ = (χ″B + 2χ′B′ + χB″)/(πR).
/// `h_rel`: relative step of the differences of g outside (see [`bracket`]).
pub(crate) fn g_derivs(
    law: &dyn AsperityLaw,
    l: &Local,
    a: f64,
    radius: f64,
    r: f64,
    h_rel: f64,
) -> [f64; 4] {
    if a <= 0.0 {
        return [0.0; 4];
    }
    let (b, db, d2b) = if r <= a {
        inside_bracket(law, a, r)
    } else {
        bracket(law, a, r, h_rel)
    };
    let k = 1.0 / (std::f64::consts::PI * radius);
    [
        l.chi * k * b,
        k * (l.dchi * b + l.chi * db),
        k * (2.0 * l.dchi * db + l.chi * d2b),
        k * b,
    ]
}

/// Everything the residual needs at one set of contact radii: the workspace of a solve.
#[derive(Default)]
pub(crate) struct State {
    pub a: Vec<f64>,
    pub loc: Vec<Local>,
    /// (ℓ_i(a), dℓ_i/da) per local index (zero where a = 0 or without far model).
    pub basis: Vec<(Vb, Vb)>,
    /// Σ_{l≠k} G_l at k (m).
    pub d_other: Vec<f64>,
    /// Σ_{l≠k} Q_l N_kl (far model).
    pub u_other: Vec<Vb>,
    /// Per near entry the [`g_derivs`] of p and q (None when both are out of contact).
    pub pair_derivs: Vec<Option<([f64; 4], [f64; 4])>>,
    /// Per near entry (G_p, ∂G_p/∂a_p, G_q, ∂G_q/∂a_q) at its distance.
    pub near_vals: Vec<[f64; 4]>,
    /// Σ_near Q_q ∂²G_k/∂a_k² + Q_k Σ_self ∂²G_k/∂a_k² as [c₀, c_χ] (see
    /// [`g_derivs`]): the a_k-derivative of the near part of E_k, for the Jacobian.
    pub near_d2: Vec<[f64; 2]>,
    /// Σ_near Q_q ∂G_k(r)/∂a_k.
    pub e_cross: Vec<f64>,
    /// Σ of the near self images G_k(r) and ∂G_k(r)/∂a_k.
    pub self_g: Vec<f64>,
    pub self_h: Vec<f64>,
    /// Σ_{l≠k} Q_l V(x_l − x_k): the others' share of the zero-mean correction
    /// ([`ZeroMean`]; empty without one).
    pub uni: Vec<f64>,
    /// F (NaN where a = 0).
    pub f: Vec<f64>,
    /// Scratch: active local indices.
    act: Vec<usize>,
    /// Far-field sources of the pair sums: y_l = Q_l ℓ(a_l)/π and Q_l (zero where
    /// a_l = 0), and the workspace of the interaction grid.
    pub src: Vec<Vb>,
    pub sc: Vec<f64>,
    pub work: Work,
}

/// Resizes `v` to `n` copies of `x` without reallocating when it is large enough.
fn refill<T: Clone>(v: &mut Vec<T>, n: usize, x: T) {
    v.clear();
    v.resize(n, x);
}

/// The energy of one approach on a prepared geometry: the law, the geometry, the
/// interferences δ_k of the candidates (m) and the difference steps.
pub(crate) struct Energy<'p> {
    pub law: &'p dyn AsperityLaw,
    pub geo: &'p Prepared,
    /// The zero-mean correction of periodic images on an elastic base.
    pub zero_mean: Option<&'p ZeroMean>,
    pub deltas: &'p [f64],
    /// Relative step of the differences of g in a.
    pub h_g: f64,
    /// Relative step of the differences of the Jacobian diagonal.
    pub h_jac: f64,
    /// Per local index, a factor on Q_l as a source of displacement (the capped I
    /// model's sources carry their actual load, `interacting::capped`); `None`: 1.
    pub source_scale: Option<&'p [f64]>,
}

impl Energy<'_> {
    fn far(&self) -> Option<&FarModel> {
        self.geo.far.as_ref()
    }

    /// Evaluates the state at contact radii `a` (local indices, m) into `st`.
    pub fn eval(&self, a: &[f64], st: &mut State) {
        let (law, geo) = (self.law, self.geo);
        let n = geo.n();
        let pi = std::f64::consts::PI;
        st.a.clear();
        st.a.extend_from_slice(a);
        st.loc.clear();
        st.loc.extend((0..n).map(|p| {
            if a[p] > 0.0 {
                Local::at(law, a[p], geo.radius[p])
            } else {
                Local::default()
            }
        }));
        if let Some(scale) = self.source_scale {
            // G = χB/(πR) and Q = χa³/R: the source scaled through χ
            for (l, f) in st.loc.iter_mut().zip(scale) {
                l.q *= f;
                l.dq *= f;
                l.chi *= f;
                l.dchi *= f;
            }
        }
        st.act.clear();
        st.act.extend((0..n).filter(|&p| a[p] > 0.0));
        refill(&mut st.basis, n, ZB);
        refill(&mut st.d_other, n, 0.0);
        refill(&mut st.u_other, n, [0.0; NB]);
        if let Some(far) = self.far() {
            refill(&mut st.src, n, [0.0; NB]);
            refill(&mut st.sc, n, 0.0);
            for &l in &st.act {
                st.basis[l] = far.basis(a[l]);
                let q = st.loc[l].q;
                st.src[l] = st.basis[l].0.map(|x| x * q / pi);
                st.sc[l] = q;
            }
            // an interaction grid that cannot run (a planning bug) poisons F: the Newton
            // search then fails on the non-finite residual
            if geo
                .interact(
                    &st.src,
                    &st.sc,
                    self.deltas,
                    &mut st.d_other,
                    &mut st.u_other,
                    &mut st.work,
                    false,
                )
                .is_err()
            {
                st.d_other.iter_mut().for_each(|d| *d = f64::NAN);
            }
        }
        refill(&mut st.near_vals, geo.near.len(), [0.0; 4]);
        refill(&mut st.near_d2, n, [0.0; 2]);
        refill(&mut st.e_cross, n, 0.0);
        let h_g = self.h_g;
        let loc = &st.loc;
        let pair = |&(p, q, r): &(usize, usize, f64)| {
            if a[p] <= 0.0 && a[q] <= 0.0 {
                return None;
            }
            Some((
                g_derivs(law, &loc[p], a[p], geo.radius[p], r, h_g),
                g_derivs(law, &loc[q], a[q], geo.radius[q], r, h_g),
            ))
        };
        // the exact pairs' g lookups dominate large evaluations: in parallel there
        #[cfg(feature = "spectral")]
        {
            use rayon::prelude::*;
            geo.near
                .par_iter()
                .with_min_len(512)
                .map(pair)
                .collect_into_vec(&mut st.pair_derivs);
        }
        #[cfg(not(feature = "spectral"))]
        {
            st.pair_derivs.clear();
            st.pair_derivs.extend(geo.near.iter().map(pair));
        }
        for (e, &(p, q, _)) in geo.near.iter().enumerate() {
            let Some((dp, dq)) = st.pair_derivs[e] else {
                continue;
            };
            st.near_vals[e] = [dp[0], dp[1], dq[0], dq[1]];
            st.d_other[q] += dp[0];
            st.d_other[p] += dq[0];
            st.e_cross[p] += st.loc[q].q * dp[1];
            st.e_cross[q] += st.loc[p].q * dq[1];
            for i in 0..2 {
                st.near_d2[p][i] += st.loc[q].q * dp[2 + i];
                st.near_d2[q][i] += st.loc[p].q * dq[2 + i];
            }
        }
        refill(&mut st.self_g, n, 0.0);
        refill(&mut st.self_h, n, 0.0);
        for &p in &st.act {
            for &r in &geo.near_self {
                let d = g_derivs(law, &st.loc[p], a[p], geo.radius[p], r, self.h_g);
                st.self_g[p] += d[0];
                st.self_h[p] += d[1];
                for i in 0..2 {
                    st.near_d2[p][i] += st.loc[p].q * d[2 + i];
                }
            }
        }
        if let Some(zm) = self.zero_mean {
            let w: Vec<f64> = (0..n).map(|l| st.loc[l].q).collect();
            refill(&mut st.uni, n, 0.0);
            zm.apply(&geo.pos, &w, &mut st.uni);
            for (u, wl) in st.uni.iter_mut().zip(&w) {
                *u -= wl * zm.v0;
            }
        }
        refill(&mut st.f, n, f64::NAN);
        for i in 0..st.act.len() {
            let p = st.act[i];
            st.f[p] = self.f_of(
                st,
                p,
                &st.loc[p],
                &st.basis[p],
                (st.self_g[p], st.self_h[p], st.e_cross[p]),
            );
        }
    }

    /// Total displacement D_k at k (m) and E_k = Σ_j Q_j ∂G_k(r_kj)/∂a_k (m²) with
    /// asperity p at the local state `lp`, `b` (basis), and its near sums
    /// `near` = (Σ self G, Σ self ∂G/∂a, Σ_near Q_q ∂G_p/∂a_p); others from `st`.
    fn d_e(
        &self,
        st: &State,
        p: usize,
        lp: &Local,
        b: &(Vb, Vb),
        near: (f64, f64, f64),
    ) -> (f64, f64) {
        let mut d = st.d_other[p] + near.0;
        let mut e = near.2 + lp.q * near.1;
        if let Some(zm) = self.zero_mean {
            // Σ_l Q_l V_pl, p's own images included; symmetric, so E gains Q'_p times it
            let u = st.uni[p] + lp.q * zm.v0;
            d += u;
            e += lp.dq * u;
        }
        if self.far().is_some() {
            let nkk = &self.geo.self_far;
            let mut u = st.u_other[p];
            for i in 0..NB {
                u[i] += lp.q * nkk[i];
            }
            let pi = std::f64::consts::PI;
            d += lp.q * dot(nkk, &b.0) / pi;
            e += (lp.dq * dot(&u, &b.0) + lp.q * dot(&u, &b.1)) / pi;
        }
        (d, e)
    }

    /// The effective displacement D̃_k = (D_k + E_k/Q′_k)/2 (m) at local index `p`: the
    /// others' (and p's own images') displacement at its centre and its reciprocal
    /// average over its contact, so that F_k = 2[δ_I(a_k) − δ_k + D̃_k] with
    /// δ_I(a) = (s + Q s′/Q′)/2 the I model's own interference of one asperity
    /// (module docs of `interacting`); D_k alone where p is out of contact.
    pub fn effective_displacement(&self, st: &State, p: usize) -> f64 {
        let near = (st.self_g[p], st.self_h[p], st.e_cross[p]);
        let lp = &st.loc[p];
        let (d, e) = self.d_e(st, p, lp, &st.basis[p], near);
        if st.a[p] > 0.0 && lp.dq > 0.0 {
            0.5 * (d + e / lp.dq)
        } else {
            d
        }
    }

    /// U_E/c (m³) at the state `st`: Σ_k Q_k (D_k + s_k − 2δ_k) (module docs).
    pub fn energy(&self, st: &State) -> f64 {
        let mut u = 0.0;
        for (k, dk) in self.deltas.iter().enumerate() {
            if st.a[k] > 0.0 {
                let l = &st.loc[k];
                let near = (st.self_g[k], st.self_h[k], st.e_cross[k]);
                let (d, _) = self.d_e(st, k, l, &st.basis[k], near);
                u += l.q * (d + l.s - 2.0 * dk);
            }
        }
        u
    }

    /// F_p (m) with asperity p in the local state `lp` (module docs).
    fn f_of(&self, st: &State, p: usize, lp: &Local, b: &(Vb, Vb), near: (f64, f64, f64)) -> f64 {
        let (d, e) = self.d_e(st, p, lp, b, near);
        d + lp.s - 2.0 * self.deltas[p] + (lp.q * lp.ds + e) / lp.dq
    }

    /// F_p as a function of a_p = `ap` alone, the others fixed at `st`: the Jacobian
    /// diagonal and F_p(0⁺) of inactive asperities.
    pub fn row(&self, st: &State, p: usize, ap: f64) -> f64 {
        let (law, geo) = (self.law, self.geo);
        let rp = geo.radius[p];
        let lp = Local::at(law, ap, rp);
        let b = self.far().map_or(ZB, |f| f.basis(ap));
        let (mut sg, mut sh, mut ec) = (0.0, 0.0, 0.0);
        for &r in &geo.near_self {
            let d = g_derivs(law, &lp, ap, rp, r, self.h_g);
            sg += d[0];
            sh += d[1];
        }
        for &e in &geo.near_of[p] {
            let (i, j, r) = geo.near[e];
            let o = if i == p { j } else { i };
            if st.a[o] > 0.0 {
                ec += st.loc[o].q * g_derivs(law, &lp, ap, rp, r, self.h_g)[1];
            }
        }
        self.f_of(st, p, &lp, &b, (sg, sh, ec))
    }

    /// The Jacobian ∂F_k/∂a_l on the active set `act` (row-major |act|²): off-diagonal
    /// entries analytic, the diagonal by central differences of the local and far parts
    /// (relative step `h_jac`) plus the analytic a-derivative of the near sums.
    pub fn jacobian(&self, st: &State, act: &[usize]) -> Vec<f64> {
        let geo = self.geo;
        let (n, ma) = (geo.n(), act.len());
        let mut jm = vec![0.0; ma * ma];
        let pi = std::f64::consts::PI;
        if let (Some(_), Some(nf)) = (self.far(), geo.sums.dense()) {
            let z: Vec<Vb> = act
                .iter()
                .map(|&l| {
                    let (lq, (b, db)) = (&st.loc[l], &st.basis[l]);
                    let mut v = [0.0; NB];
                    for i in 0..NB {
                        v[i] = (lq.dq * b[i] + lq.q * db[i]) / pi;
                    }
                    v
                })
                .collect();
            for (ii, &k) in act.iter().enumerate() {
                let row = &nf[k * n..(k + 1) * n];
                let dqk = st.loc[k].dq;
                let out = &mut jm[ii * ma..(ii + 1) * ma];
                for (jj, &l) in act.iter().enumerate() {
                    if l != k {
                        let nkl = &row[l];
                        out[jj] = dot(nkl, &z[jj]) + st.loc[l].dq / dqk * dot(nkl, &z[ii]);
                    }
                }
            }
        }
        let mut pos = vec![usize::MAX; n];
        for (ii, &p) in act.iter().enumerate() {
            pos[p] = ii;
        }
        for (e, &(p, q, _)) in geo.near.iter().enumerate() {
            let (ip, iq) = (pos[p], pos[q]);
            if ip == usize::MAX || iq == usize::MAX {
                continue;
            }
            let [_, hp, _, hq] = st.near_vals[e];
            let (dp, dq) = (st.loc[p].dq, st.loc[q].dq);
            jm[iq * ma + ip] += hp + dp * hq / dq;
            jm[ip * ma + iq] += hq + dq * hp / dp;
        }
        if let Some(zm) = self.zero_mean {
            // ∂(2 Σ_l Q_l V_kl)/∂a_l
            for (ii, &k) in act.iter().enumerate() {
                let pk = geo.pos[k];
                for (jj, &l) in act.iter().enumerate() {
                    if l != k {
                        let pl = geo.pos[l];
                        jm[ii * ma + jj] += 2.0 * zm.value(pl.0 - pk.0, pl.1 - pk.1) * st.loc[l].dq;
                    }
                }
            }
        }
        for (ii, &p) in act.iter().enumerate() {
            jm[ii * ma + ii] = self.diagonal(st, p);
        }
        jm
    }

    /// ∂F_p/∂a_p: the local and far parts by central differences with the near sums
    /// frozen, plus their a_p-derivative Σ_self ∂G_p/∂a_p + (∂E_p^near/∂a_p)/Q′_p.
    pub(crate) fn diagonal(&self, st: &State, p: usize) -> f64 {
        let law = self.law;
        let h = self.h_jac * st.a[p];
        let near = (st.self_g[p], st.self_h[p], st.e_cross[p]);
        let frozen = |ap: f64| {
            let lp = Local::at(law, ap, self.geo.radius[p]);
            let b = self.far().map_or(ZB, |f| f.basis(ap));
            self.f_of(st, p, &lp, &b, near)
        };
        let mut d = (frozen(st.a[p] + h) - frozen(st.a[p] - h)) / (2.0 * h);
        let [c0, cc] = st.near_d2[p];
        let mut d2c = 0.0;
        if cc != 0.0 {
            let ha = self.h_g * st.a[p];
            let (_, c1, _, _) = law.chi_zeta_derivs(st.a[p] + ha);
            let (_, c2, _, _) = law.chi_zeta_derivs(st.a[p] - ha);
            d2c = (c1 - c2) / (2.0 * ha);
        }
        d += st.self_h[p] + (c0 + cc * d2c) / st.loc[p].dq;
        d
    }
}
