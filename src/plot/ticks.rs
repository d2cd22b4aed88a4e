//! Tick positions and labels: readable numbers, enough labelled ticks on log axes
//! (1-2-5 or 1…9 per decade when the range spans few decades), and "nice" steps for
//! map axes and scale bars.

pub use strata_engine::number::{tick, tick_sci};

/// Labelled (bold) and minor (light) tick values of a log axis on [lo, hi] (lo > 0):
/// the coarsest of decades, 1-2-5 and 1…9 per decade that puts at least four labels
/// in the range (at most ~12 decades labelled, every k-th beyond); minor ticks at
/// 1…9 per decade.
pub fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return (vec![lo, hi], Vec::new());
    }
    let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-12) && *v <= hi * (1.0 + 1e-12);
    let with = |mantissas: &[f64]| -> Vec<f64> {
        (d0..=d1)
            .flat_map(|d| mantissas.iter().map(move |m| m * 10f64.powi(d)))
            .filter(inside)
            .collect()
    };
    let minor = with(&[1., 2., 3., 4., 5., 6., 7., 8., 9.]);
    let decades = with(&[1.0]);
    let bold = if decades.len() >= 4 {
        let every = decades.len().div_ceil(12).max(1);
        decades.into_iter().step_by(every).collect()
    } else {
        let candidates: [&[f64]; 3] = [
            &[1., 2., 5.],
            &[1., 2., 3., 4., 5., 6., 7., 8., 9.],
            &[1., 1.2, 1.5, 2., 2.5, 3., 4., 5., 6., 7., 8., 9.],
        ];
        candidates
            .iter()
            .map(|m| with(m))
            .find(|v| v.len() >= 4)
            .unwrap_or_else(|| {
                // Narrower than ~20 %: five evenly spaced values.
                (0..5)
                    .map(|i| lo * (hi / lo).powf(i as f64 / 4.0))
                    .collect()
            })
    };
    (bold, minor)
}

/// A "nice" step (1, 2 or 5 × 10^k) that cuts `span` into about `parts` pieces.
pub fn nice_step(span: f64, parts: f64) -> f64 {
    if !(span > 0.0 && span.is_finite() && parts > 0.0) {
        return 1.0;
    }
    let raw = span / parts;
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    let n = if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    };
    n * p
}

/// A length (m) in a readable unit: `200 µm`, `1.5 mm`, `30 nm`, `2 m`.
pub fn length(m: f64) -> String {
    let (v, unit) = if m >= 1.0 {
        (m, "m")
    } else if m >= 1e-3 {
        (m * 1e3, "mm")
    } else if m >= 1e-6 {
        (m * 1e6, "µm")
    } else {
        (m * 1e9, "nm")
    };
    format!("{} {unit}", tick(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_keep_small_values_readable() {
        assert_eq!(tick(2.5e-6), "2.5e-6");
        assert_eq!(tick(1e-5), "1e-5");
        assert_eq!(tick(0.0012), "0.0012");
        assert_eq!(tick(0.5), "0.5");
        assert_eq!(tick(0.0), "0");
        assert_eq!(tick(2e9), "2e9");
        assert_eq!(tick_sci(0.005), "5e-3");
        assert_eq!(tick_sci(1.5e-4), "1.5e-4");
    }

    /// Every log range gets at least four labels, inside the range.
    #[test]
    fn log_axes_have_enough_labels() {
        for (lo, hi) in [
            (1e-5, 1e-1),
            (2e-4, 3e-3),
            (1.2e-4, 4e-4),
            (1.1, 1.3),
            (1e-30, 1e30),
        ] {
            let (bold, minor) = log_ticks(lo, hi);
            assert!(bold.len() >= 4 && bold.len() <= 13, "{lo} {hi}: {bold:?}");
            assert!(bold.iter().all(|v| *v >= lo * 0.999 && *v <= hi * 1.001));
            assert!(minor.iter().all(|v| *v >= lo * 0.999 && *v <= hi * 1.001));
        }
        let (bold, _) = log_ticks(2e-4, 3e-3);
        let want = [2e-4, 5e-4, 1e-3, 2e-3];
        assert_eq!(bold.len(), want.len(), "{bold:?}");
        for (b, w) in bold.iter().zip(want) {
            assert!((b / w - 1.0).abs() < 1e-12, "{bold:?}");
        }
    }

    #[test]
    fn nice_steps_and_lengths() {
        assert!((nice_step(1e-3, 5.0) / 2e-4 - 1.0).abs() < 1e-12);
        assert!((nice_step(7.0, 4.0) / 2.0 - 1.0).abs() < 1e-12);
        assert_eq!(length(2e-4), "200 µm");
        assert_eq!(length(1.5e-3), "1.5 mm");
    }
}
