//! Form removal (scene key `[surface] detrend`): the least-squares plane or quadric
//! subtracted from the heights.
//!
//! With u = x − x̄, v = y − ȳ about the sample centre (x = i·dx, y = j·dy), the fitted
//! form is
//!
//! ```text
//!   plane:      f = c₀ + a_x u + a_y v
//!   curvature:  f = c₀ + a_x u + a_y v + ½ h_xx (u² − ⟨u²⟩) + h_xy u v + ½ h_yy (v² − ⟨v²⟩)
//! ```
//!
//! minimising Σ (z − f)² over the grid. On a full regular grid the functions 1, u, v,
//! u² − ⟨u²⟩, uv, v² − ⟨v²⟩ are mutually orthogonal (each sum factorises into sums over
//! i and j, and Σu = Σu³ = 0 on a symmetric grid), so every coefficient is a projection
//! ⟨z, φ⟩/⟨φ, φ⟩: no linear system, no conditioning issue for any dx, dy, n. The
//! slopes a_x, a_y are dimensionless, the second derivatives h (1/m). The span is that
//! of {1, x, y, x², xy, y²}, so this is the ordinary least-squares fit.
//!
//! Measured files default to `"plane"` in a scene (a scan's tilt is the stage, not the
//! part); a periodic sample has no tilt or curvature to remove (a plane is not
//! periodic: its edges would no longer meet), so [`Surface::read`](super::Surface::read) refuses form removal
//! on a periodic sample. Two warnings ([`Surface::warnings`](super::Surface::warnings)) catch a form that
//! dominates the heights: with `"none"` on a non-periodic sample, a least-squares plane
//! that would remove more than [`KEPT_FORM_FRACTION`] of the RMS height; with form
//! removal, a removed form whose RMS exceeds [`REMOVED_FORM_RATIO`] × the remaining
//! roughness RMS.

/// With `detrend = "none"`: warn when a least-squares plane would remove more than this
/// fraction of the RMS height (RMS after removal < (1 − fraction) × RMS before).
pub const KEPT_FORM_FRACTION: f64 = 0.5;

/// With form removal: warn when the removed form's RMS exceeds this multiple of the
/// remaining roughness RMS.
pub const REMOVED_FORM_RATIO: f64 = 10.0;

/// Which form is removed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Detrend {
    /// Keep the heights as read (default).
    #[default]
    None,
    /// Remove the least-squares plane (mean and tilt).
    Plane,
    /// Remove the least-squares quadric (mean, tilt and curvature).
    Curvature,
}

impl Detrend {
    /// Parses the scene value `"none" | "plane" | "curvature"`.
    pub fn parse(s: &str) -> Option<Detrend> {
        match s {
            "none" => Some(Detrend::None),
            "plane" => Some(Detrend::Plane),
            "curvature" => Some(Detrend::Curvature),
            _ => None,
        }
    }
    /// The scene value.
    pub fn name(self) -> &'static str {
        match self {
            Detrend::None => "none",
            Detrend::Plane => "plane",
            Detrend::Curvature => "curvature",
        }
    }
}

/// The form removed by [`Surface::detrend`](super::Surface::detrend) (module docs for the symbols).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Form {
    pub kind: Detrend,
    /// c₀: the fitted height at the sample centre (m).
    pub offset: f64,
    /// (a_x, a_y): the fitted slopes (1).
    pub slope: (f64, f64),
    /// (h_xx, h_xy, h_yy): the fitted second derivatives (1/m); zero for a plane.
    pub curvature: (f64, f64, f64),
    /// RMS of the removed form about its mean (m).
    pub rms: f64,
    /// RMS of the heights after removal, the remaining roughness (m).
    pub residual_rms: f64,
}

impl Form {
    /// One log line describing the removed form.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "detrend = \"{}\": removed the least-squares form with slopes z_x = {:.4e}, z_y = {:.4e}",
            self.kind.name(),
            self.slope.0,
            self.slope.1
        );
        if self.kind == Detrend::Curvature {
            let (a, b, c) = self.curvature;
            s.push_str(&format!(
                ", second derivatives z_xx = {a:.4e}, z_xy = {b:.4e}, z_yy = {c:.4e} 1/m"
            ));
        }
        s.push_str(&format!(
            " (RMS of the removed form {:.4e} m, of the remaining roughness {:.4e} m; detrend = \"none\" keeps the form)",
            self.rms, self.residual_rms
        ));
        s
    }

    /// The warning when the removed form's RMS exceeds [`REMOVED_FORM_RATIO`] × the
    /// remaining roughness RMS (a tilted stage, a curved part), else `None`.
    pub fn dominance_warning(&self) -> Option<String> {
        (self.rms > REMOVED_FORM_RATIO * self.residual_rms).then(|| {
            format!(
                "the removed form (detrend = \"{}\", slopes z_x = {:.3e}, z_y = {:.3e}) has an RMS \
                 of {:.3e} m, {:.0} × the remaining roughness ({:.3e} m; warning above {REMOVED_FORM_RATIO} ×): \
                 often a tilted stage or a curved part; the contact is solved on the remaining roughness",
                self.kind.name(),
                self.slope.0,
                self.slope.1,
                self.rms,
                self.rms / self.residual_rms.max(f64::MIN_POSITIVE),
                self.residual_rms
            )
        })
    }
}

/// Centred coordinates u_i = (i − (n − 1)/2)·d and ⟨u²⟩.
pub(super) fn centred(n: usize, d: f64) -> (Vec<f64>, f64) {
    let c = (n as f64 - 1.0) / 2.0;
    let u: Vec<f64> = (0..n).map(|i| (i as f64 - c) * d).collect();
    let m2 = u.iter().map(|x| x * x).sum::<f64>() / n as f64;
    (u, m2)
}

/// The least-squares form `kind` (module docs) fitted to the heights at the points
/// where `keep` is set (a map with invalid points or spikes: the basis is no longer
/// orthogonal, so the normal equations are solved, in coordinates scaled to the grid),
/// evaluated at every point of the n0 × n1 grid. `Detrend::None` gives zeros. The fit
/// is linear in z: adding a plane (quadric, for `"curvature"`) to z adds it to the form.
pub(super) fn fit_form(z: &[f64], keep: &[bool], n0: usize, n1: usize, kind: Detrend) -> Vec<f64> {
    let m = match kind {
        Detrend::None => return vec![0.0; z.len()],
        Detrend::Plane => 3,
        Detrend::Curvature => 6,
    };
    // scaled centred coordinates in [−1, 1]: the fit is the same for any dx, dy
    let (u, _) = centred(n0, 2.0 / (n0 as f64 - 1.0).max(1.0));
    let (v, _) = centred(n1, 2.0 / (n1 as f64 - 1.0).max(1.0));
    let phi = |k: usize| -> [f64; 6] {
        let (a, b) = (u[k / n1], v[k % n1]);
        [1.0, a, b, a * a, a * b, b * b]
    };
    let mut ata = [[0.0f64; 6]; 6];
    let mut atz = [0.0f64; 6];
    for k in (0..z.len()).filter(|&k| keep[k]) {
        let p = phi(k);
        for r in 0..m {
            atz[r] += p[r] * z[k];
            for c in 0..m {
                ata[r][c] += p[r] * p[c];
            }
        }
    }
    // Gaussian elimination with partial pivoting; a singular direction (too few points
    // along an axis) is left out (coefficient 0)
    let scale = ata[0][0].max(1.0);
    let mut coef = [0.0f64; 6];
    let mut piv_ok = [false; 6];
    for col in 0..m {
        let best = (col..m)
            .max_by(|&a, &b| ata[a][col].abs().total_cmp(&ata[b][col].abs()))
            .unwrap_or(col);
        ata.swap(col, best);
        atz.swap(col, best);
        if ata[col][col].abs() <= 1e-12 * scale {
            continue;
        }
        piv_ok[col] = true;
        for r in col + 1..m {
            let f = ata[r][col] / ata[col][col];
            let pivot_row = ata[col];
            for (x, p) in ata[r][col..m].iter_mut().zip(&pivot_row[col..m]) {
                *x -= f * p;
            }
            atz[r] -= f * atz[col];
        }
    }
    for r in (0..m).rev() {
        if !piv_ok[r] {
            continue;
        }
        let s: f64 = (r + 1..m).map(|c| ata[r][c] * coef[c]).sum();
        coef[r] = (atz[r] - s) / ata[r][r];
    }
    (0..z.len())
        .map(|k| {
            let p = phi(k);
            (0..m).map(|r| coef[r] * p[r]).sum()
        })
        .collect()
}
