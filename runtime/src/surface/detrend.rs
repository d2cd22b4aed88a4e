//! Form removal on a [`Surface`]: [`Surface::detrend`] subtracts the least-squares form
//! (module `form`: the fit, the form's kinds and the warnings' thresholds) and logs it.

use super::Surface;
use super::form::{Detrend, Form, KEPT_FORM_FRACTION, centred};

impl Surface {
    /// Removes the least-squares form `kind` (module docs) from the heights and logs
    /// it; returns the removed form. `Detrend::None` changes nothing.
    pub fn detrend(&mut self, kind: Detrend) -> Form {
        let (n0, n1) = self.shape();
        let (dx, dy) = self.pixel_size();
        let (u, mu) = centred(n0, dx);
        let (v, mv) = centred(n1, dy);
        let none = Form {
            kind,
            offset: 0.0,
            slope: (0.0, 0.0),
            curvature: (0.0, 0.0, 0.0),
            rms: 0.0,
            residual_rms: self.rms(),
        };
        if kind == Detrend::None {
            return none;
        }
        let quad = kind == Detrend::Curvature;
        // Basis values at (i, j); the six projections and norms in one pass.
        let phi = |i: usize, j: usize| -> [f64; 6] {
            let (a, b) = (u[i], v[j]);
            [1.0, a, b, a * a - mu, a * b, b * b - mv]
        };
        let m = if quad { 6 } else { 3 };
        let (mut num, mut den) = ([0.0f64; 6], [0.0f64; 6]);
        for i in 0..n0 {
            for j in 0..n1 {
                let p = phi(i, j);
                let z = self.z[i * n1 + j];
                for k in 0..m {
                    num[k] += z * p[k];
                    den[k] += p[k] * p[k];
                }
            }
        }
        let mut c = [0.0f64; 6];
        for k in 0..m {
            if den[k] > 0.0 {
                c[k] = num[k] / den[k];
            }
        }
        let mut form_sq = 0.0;
        for i in 0..n0 {
            for j in 0..n1 {
                let p = phi(i, j);
                let f: f64 = (0..m).map(|k| c[k] * p[k]).sum();
                self.z[i * n1 + j] -= f;
                form_sq += (f - c[0]) * (f - c[0]);
            }
        }
        let form = Form {
            kind,
            offset: c[0],
            slope: (c[1], c[2]),
            curvature: if quad {
                (2.0 * c[3], c[4], 2.0 * c[5])
            } else {
                (0.0, 0.0, 0.0)
            },
            rms: (form_sq / (n0 * n1) as f64).sqrt(),
            residual_rms: self.rms(),
        };
        self.note(form.describe());
        self.form = Some(form);
        form
    }

    /// The form removed when the surface was read (`None` when none was).
    pub fn form(&self) -> Option<&Form> {
        self.form.as_ref()
    }

    /// With `detrend = "none"` on a non-periodic sample: the warning when a
    /// least-squares plane would remove more than [`KEPT_FORM_FRACTION`] of the RMS
    /// height, else `None` (the heights are not changed).
    pub fn kept_form_warning(&self) -> Option<String> {
        if self.is_periodic() {
            return None;
        }
        let rms = self.rms();
        let mut plane = self.clone();
        let f = plane.detrend(Detrend::Plane);
        (f.residual_rms < (1.0 - KEPT_FORM_FRACTION) * rms).then(|| {
            format!(
                "detrend = \"none\" keeps a tilt that dominates the heights: the least-squares plane \
                 (slopes z_x = {:.3e}, z_y = {:.3e}) carries {:.0} % of the RMS height ({:.3e} m; \
                 {:.3e} m without it); a tilted scan is mostly form, not roughness: set [surface] \
                 detrend = \"plane\" (the default for measured files) unless the tilt is part of the contact",
                f.slope.0,
                f.slope.1,
                100.0 * (1.0 - f.residual_rms / rms),
                rms,
                f.residual_rms
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::Spacing;
    use super::super::form::*;
    use super::*;

    fn grid(n0: usize, n1: usize, dx: f64, dy: f64, f: impl Fn(f64, f64) -> f64) -> Surface {
        let z = (0..n0 * n1)
            .map(|k| f((k / n1) as f64 * dx, (k % n1) as f64 * dy))
            .collect();
        Surface::with_spacing(z, n0, n1, Spacing::Pixel(dx, dy), false).unwrap()
    }

    /// The two warnings of a dominating form: with form removal, a removed RMS above
    /// 10× the remaining roughness; with "none", a plane carrying more than half of the
    /// RMS height. Neither for a rough sample with a small tilt, nor "none" on a
    /// periodic sample.
    #[test]
    fn dominating_form_warnings() {
        let (n0, n1, d) = (40, 30, 1e-6);
        let rough = |x: f64, y: f64| 1e-8 * ((x * 3e6).sin() * (y * 1.7e6).cos());
        let tilted = |t: f64| grid(n0, n1, d, d, move |x, y| rough(x, y) + t * x);
        // slope 1e-2 over 40 µm: form RMS ~1.2e-7 m against ~5e-9 m of roughness
        let mut s = tilted(1e-2);
        assert!(
            s.kept_form_warning()
                .is_some_and(|w| w.contains("detrend = \"plane\""))
        );
        let f = s.detrend(Detrend::Plane);
        assert!((f.slope.0 - 1e-2).abs() < 1e-6, "{f:?}");
        let w = f.dominance_warning().expect("dominance warning");
        assert!(w.contains("tilted stage"), "{w}");
        assert_eq!(s.form(), Some(&f));
        assert!(s.log()[0].contains("remaining roughness"), "{:?}", s.log());
        let mut s = tilted(1e-5);
        assert!(s.kept_form_warning().is_none());
        assert!(s.detrend(Detrend::Plane).dominance_warning().is_none());
        let z = tilted(1e-2).heights().to_vec();
        let p = Surface::with_spacing(z, n0, n1, Spacing::Pixel(d, d), true).unwrap();
        assert!(p.kept_form_warning().is_none());
    }

    /// An exact plane (quadric) is removed to round-off and its coefficients come
    /// back; the least-squares residual of a rough surface is orthogonal to every
    /// basis monomial 1, x, y, x², xy, y² (the normal equations, checked directly).
    #[test]
    fn exact_forms_and_normal_equations() {
        let (n0, n1, dx, dy) = (37, 24, 1.3e-6, 2.1e-6);
        let (cx, cy) = ((n0 - 1) as f64 * dx / 2.0, (n1 - 1) as f64 * dy / 2.0);
        let mut s = grid(n0, n1, dx, dy, |x, y| 2e-6 + 0.01 * x - 0.03 * y);
        let f = s.detrend(Detrend::Plane);
        assert!(
            s.heights().iter().all(|z| z.abs() < 1e-19),
            "{:?}",
            &s.heights()[..4]
        );
        assert!((f.slope.0 - 0.01).abs() < 1e-14 && (f.slope.1 + 0.03).abs() < 1e-14);
        assert!((f.offset - (2e-6 + 0.01 * cx - 0.03 * cy)).abs() < 1e-18);
        assert!(s.log()[0].contains("detrend = \"plane\""), "{:?}", s.log());
        let (hxx, hxy, hyy) = (50.0, -20.0, 80.0);
        let q =
            |x: f64, y: f64| 1e-6 + 0.02 * x + 0.5 * hxx * x * x + hxy * x * y + 0.5 * hyy * y * y;
        let mut s = grid(n0, n1, dx, dy, q);
        let f = s.detrend(Detrend::Curvature);
        assert!(s.heights().iter().all(|z| z.abs() < 1e-18));
        assert!((f.curvature.0 - hxx).abs() < 1e-9 && (f.curvature.1 - hxy).abs() < 1e-9);
        assert!((f.curvature.2 - hyy).abs() < 1e-9);
        // Rough surface plus form: residual ⟂ monomials.
        let rough = |x: f64, y: f64| {
            1e-6 * ((x * 3e5).sin() * (y * 1.7e5).cos() + (x * 7e5 + y * 2e5).sin())
        };
        for kind in [Detrend::Plane, Detrend::Curvature] {
            let mut s = grid(n0, n1, dx, dy, |x, y| rough(x, y) + q(x, y));
            s.detrend(kind);
            let monomials: Vec<Box<dyn Fn(f64, f64) -> f64>> = vec![
                Box::new(|_, _| 1.0),
                Box::new(|x, _| x),
                Box::new(|_, y| y),
                Box::new(|x, _| x * x),
                Box::new(|x, y| x * y),
                Box::new(|_, y| y * y),
            ];
            let m = if kind == Detrend::Plane { 3 } else { 6 };
            for (k, g) in monomials.iter().take(m).enumerate() {
                let (mut dot, mut scale) = (0.0, 0.0);
                for i in 0..n0 {
                    for j in 0..n1 {
                        let gv = g(i as f64 * dx, j as f64 * dy);
                        dot += s.z(i, j) * gv;
                        scale += (1e-6 * gv).abs();
                    }
                }
                assert!(
                    dot.abs() < 1e-12 * scale,
                    "{kind:?} monomial {k}: {dot:e} {scale:e}"
                );
            }
        }
    }
}
