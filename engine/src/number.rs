//! Numbers as people read them: plain decimals where they show the value, scientific
//! notation where fixed decimals would print 0.0 or a long row of digits. Used by the
//! engine's descriptions (moduli) and by the plots' tick labels.

/// Tick label: scientific notation for values that fixed decimals would show as 0.0
/// (compliances, tiny pressure ratios), plain decimals otherwise.
pub fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        tick_sci(v)
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// Tick label in scientific notation (`5e-3`, `1.5e-4`), for log axes spanning
/// small or large values, so that all labels of the axis read alike.
pub fn tick_sci(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let s = format!("{v:.2e}");
    match s.split_once('e') {
        Some((m, e)) => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
        None => s,
    }
}
