//! The table-backed (second-order) asperity of a stack, as `strata asperity --model
//! approx` and the Python package use it: the law from a table file or the table cache,
//! a paraboloid's contact radius and load, and its pressure and displacement profile
//! (physics.md §4).

use crate::error::{Context, Result, bail_input};
use strata_runtime::Solid;
use strata_runtime::table::Table;
use strata_tablegen::tablebuild::{Bars, BuildOptions};

use crate::progress;

/// Build time for the header: SOURCE_DATE_EPOCH when set, else now.
pub fn build_time() -> Result<u64> {
    match std::env::var("SOURCE_DATE_EPOCH") {
        Ok(v) => v
            .trim()
            .parse()
            .with_context(|| format!("SOURCE_DATE_EPOCH = `{v}` is not a number of seconds")),
        Err(_) => Ok(std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0)),
    }
}

/// The table-backed asperity law of `stack` for `strata asperity --model approx`:
/// from `table` when given (refusing stacks the table does not serve), else from the
/// table cache ([`crate::cache`]), building and caching the table there on first use.
pub fn law_for_stack(
    stack: &(impl Solid + ?Sized),
    table: Option<&std::path::Path>,
    cache_dir: Option<&std::path::Path>,
) -> Result<strata_runtime::table::TableLaw> {
    if let Some(p) = table {
        let t = Table::load(p).with_context(|| format!("--table {}", p.display()))?;
        return t
            .law_for(stack)
            .with_context(|| format!("--table {} cannot serve this stack", p.display()));
    }
    let opts = BuildOptions {
        check_points: 200,
        build_time: build_time()?,
        progress: true,
        bars: Some(Bars(progress::raw_bar)),
        ..BuildOptions::default()
    };
    let (t, _) = crate::setup::cached_table(stack, cache_dir, false, Some(opts))?;
    Ok(t.law_for(stack)?)
}

/// Second-order approximation of a paraboloid (radius R) at approach δ (physics.md
/// §4): the contact radius a of δ = ζ(a) a²/R ([`strata_runtime::law::contact_radius`],
/// the runtime's one root finder) and P = (4/3) E*₁ χ(a) a³/R. δ = 0 gives (0, 0).
pub fn approx_paraboloid(
    law: &strata_runtime::table::TableLaw,
    delta: f64,
    radius: f64,
) -> Result<(f64, f64)> {
    use strata_runtime::law;
    if delta == 0.0 {
        return Ok((0.0, 0.0));
    }
    let Some(a) = law::contact_radius(law, radius, delta) else {
        bail_input!("cannot bracket the contact radius for delta = {delta} m");
    };
    let p = law::force(law, a, radius);
    if !(a.is_finite() && p.is_finite()) {
        bail_input!("approximate solution at delta = {delta} m is not finite");
    }
    Ok((a, p))
}

/// Approximate pressure (Pa, compressive positive) and displacement (m) at r for
/// contact radius a (physics.md §4): p = (2E*₁/(πR)) χ(a) √(a² − r²) inside, and the
/// displacement of `strata_runtime::law::displacement`.
pub fn approx_profile(
    law: &strata_runtime::table::TableLaw,
    a: f64,
    radius: f64,
    r: f64,
) -> (f64, f64) {
    use strata_runtime::law::{self, AsperityLaw};
    let p = if r < a {
        2.0 * law.e_star() / (std::f64::consts::PI * radius) * law.chi(a) * (a * a - r * r).sqrt()
    } else {
        0.0
    };
    (p, law::displacement(law, a, radius, r))
}
