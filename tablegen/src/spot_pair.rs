//! Two bodies' spot conductances in series (physics.md §6.2): one summit's contact of
//! radius a conducts G(a) with 1/G = 1/G_A(a) + 1/G_B(a), G_X(a) = 4 k₁,X a ψ_X(a) on a
//! layered body (ψ from one [`PsiTable`] covering the radii of a load path, from the
//! table cache when there is one), 4 k a on a
//! homogeneous one and ∞ on a perfect conductor. The one implementation behind the N and
//! I models' conductance of `strata` and of the C ABI.

use std::path::Path;

use strata_runtime::rough::Step;

use crate::psi_table::{CacheUse, PsiError, PsiTable, build, cached};
use crate::spot::Spot;

/// One body's spot conductance.
pub enum SpotSide {
    /// A perfect conductor (1/G = 0).
    Perfect,
    /// 4 k a (a homogeneous conductor of conductivity k, W/(m·K) or S/m).
    Homogeneous(f64),
    /// 4 k₁ a ψ(a) by the Fredholm solver.
    Layered(Box<Spot>),
}

impl SpotSide {
    /// The side of a body's spot solver: homogeneous where its stack is.
    pub fn of(spot: Spot) -> SpotSide {
        let c = spot.compliance();
        if c.is_homogeneous() {
            SpotSide::Homogeneous(c.top_conductivity())
        } else {
            SpotSide::Layered(Box::new(spot))
        }
    }
}

/// G(aᵢ) (W/K or S; 0 out of contact) of every summit of every step, the sides `a` and
/// `b` in series, ψ from one table per layered side covering all the steps' radii: read
/// from (or built into) the table cache `cache` when given ([`cached`]), else built
/// ([`build`]) — the same bits either way. Also what the cache did, per layered side.
pub fn spot_conductances(
    a: &SpotSide,
    b: &SpotSide,
    steps: &[Step],
    cache: Option<&Path>,
) -> Result<(Vec<Vec<f64>>, Vec<CacheUse>), PsiError> {
    let (lo, hi) = steps
        .iter()
        .flat_map(|s| s.radii.iter().copied())
        .filter(|&a| a > 0.0 && a.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), a| {
            (lo.min(a), hi.max(a))
        });
    if hi == 0.0 {
        let g = steps.iter().map(|s| vec![0.0; s.radii.len()]).collect();
        return Ok((g, vec![]));
    }
    let mut uses = vec![];
    let mut table = |s: &SpotSide| -> Result<Option<PsiTable>, PsiError> {
        let SpotSide::Layered(spot) = s else {
            return Ok(None);
        };
        Ok(Some(match cache {
            Some(dir) => {
                let (t, u) = cached(spot, lo, hi, dir)?;
                uses.push(u);
                t
            }
            None => build(spot, lo, hi)?,
        }))
    };
    let (ta, tb) = (table(a)?, table(b)?);
    // 1/G of one side at radius r (0 for a perfect conductor).
    let resistance = |s: &SpotSide, t: &Option<PsiTable>, r: f64| match (s, t) {
        (SpotSide::Perfect, _) => 0.0,
        (SpotSide::Homogeneous(k), _) => 1.0 / (4.0 * k * r),
        (SpotSide::Layered(spot), Some(t)) => {
            1.0 / (4.0 * spot.compliance().top_conductivity() * r * t.at(r))
        }
        (SpotSide::Layered(..), None) => f64::NAN,
    };
    let g = steps
        .iter()
        .map(|s| {
            s.radii
                .iter()
                .map(|&r| {
                    if r > 0.0 && r.is_finite() {
                        1.0 / (resistance(a, &ta, r) + resistance(b, &tb, r))
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    Ok((g, uses))
}
