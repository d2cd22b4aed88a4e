//! `strata law SCENE.toml --out FILE`: the contact law of the scene's rough interface
//! as a monotone, finely sampled table: p(g), A(g)/A₀ and dp/dg from first
//! contact down to a smallest separation, for FE contact definitions.
//!
//! Formats (by `--format`, else by the extension of FILE):
//! - `csv` (`.csv`): header `gap,overclosure,mean_pressure,area_fraction,dp_dg,valid`
//!   (m, m, Pa, -, Pa/m, 1/0), one line per sample in loading order; `valid` = 0 where
//!   the N or I model is outside its validity (BEM laws: always 1);
//! - `json` (`.json`): the same samples (`valid` and the `validity` reason), the
//!   ranges where the model is invalid (`validity_warnings`), the surface as solved
//!   (`surface`, `warnings`), the scene summary and the convention;
//! - `abaqus` (`.inp`): a `*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR` block, data
//!   lines `pressure, overclosure`, overclosure h = g₀ − g ≥ 0 relative to first contact
//!   (g₀ = z_M − z̄), first line `0., 0.`, h strictly increasing, p non-decreasing;
//!   the convention and units are in its `**` comment lines, every number in at most
//!   20 characters (what Abaqus and CalculiX read); `** WARNING:` lines give the
//!   separations where the model is outside its validity;
//! - `all`: FILE's stem with `.csv`, `.json` and `.inp`.
//!
//! With `[conductance]` in the scene (BEM, N or I model) the CSV gains a `conductance`
//! column after `valid`, the JSON each sample's interface conductance h_c (physics.md
//! §6.2) and the `.inp` a `*GAP CONDUCTANCE, PRESSURE` block after the table
//! ([`SampledLaw::gap_conductance_block`]). With `[friction]` (every model) the CSV
//! gains a `tangential_stiffness` column after them and the JSON each sample's
//! `tangential_stiffness`: the full-stick tangential stiffness K_t of the sample (N/m),
//! the JSON a `friction_card` object and the `.inp` the friction card after the table
//! ([`strata_engine::friction_card`]): CalculiX `*FRICTION` (μ, stick slope λ =
//! K_t(p_d)/A₀ at the design pressure p_d, `--design-pressure`, with λ's range over the
//! path) and Abaqus `*FRICTION, ELASTIC SLIP=γ` (γ = μ p_d A₀/K_t(p_d), with its spread
//! over the path), one active (`--friction-card`), the other commented out. A card
//! with λ <= 0 is refused (CalculiX does not run it).
//!
//! Sampling: `--samples` (default 200) separations evenly from g₀ down to `--min-gap`
//! (default: the smallest separation the scene's `[load]` reaches; for
//! `mean_pressures`, the separation of the largest one). The law between samples is the
//! monotone interpolation of `strata_runtime::interface` (cubic Hermite with the
//! solver's own slopes); the file reports how far the piecewise-linear table (what
//! Abaqus does) is from it. The files are one output set ([`crate::output_set`]):
//! staged, then moved into place together under a lock, so `--format all` never
//! leaves new and old files side by side; existing ones are kept unless `--force`.
//! When an Abaqus block is written, the log warns about what CalculiX 2.20 would
//! change in it (more than 200 lines, overclosure steps below 1e-10 m).

use std::path::{Path, PathBuf};
use std::time::Instant;
use strata_runtime::resources::MemoryLimit;

use crate::scene::Scene;
use anyhow::{Context, Result, bail};

use crate::output_set::{OutputSet, refuse_inputs};
use crate::progress;

use crate::engine::{Console, EngineOptions};
pub use crate::sampled_law::{SampledLaw, csv, range_path, sample_law};
use crate::sampled_law::{check_min_gap, check_samples};
use strata_engine::friction_card as card;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    Csv,
    Json,
    Abaqus,
    All,
}

/// The FE code whose friction card is active in the .inp.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FrictionCard {
    /// `*FRICTION` with `μ, λ` (stick slope λ = K_t/A₀ at the design pressure).
    Calculix,
    /// `*FRICTION, ELASTIC SLIP=γ` with `μ` (γ = μ p_d A₀/K_t).
    Abaqus,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output file (.csv, .json or .inp; with `--format all`, the stem of the three).
    #[arg(long)]
    pub out: PathBuf,
    /// Output format (default: from the extension of --out).
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// Number of samples from first contact down to --min-gap (2 to 100000; CalculiX
    /// keeps at most 200 table lines).
    #[arg(long, default_value_t = 200)]
    pub samples: usize,
    /// Smallest separation g (m) (default: the smallest one the scene's load reaches);
    /// negative below the mean plane (`--min-gap -1e-6` or `--min-gap=-1e-6`).
    #[arg(long, allow_hyphen_values = true)]
    pub min_gap: Option<f64>,
    /// With `[friction]`: the design pressure p_d (Pa) of the friction card (in the .inp
    /// and the JSON; a CSV alone has none) — CalculiX's
    /// stick slope λ = K_t(p_d)/A₀, Abaqus' elastic slip γ = μ p_d A₀/K_t(p_d)
    /// (default: the table's largest pressure, that of the deepest sample: the scene's
    /// largest load or --min-gap's).
    #[arg(long, value_name = "PA")]
    pub design_pressure: Option<f64>,
    /// With `[friction]`: which `*FRICTION` card the .inp makes active (the other is
    /// written under it as `**` comment lines).
    #[arg(long, value_enum, default_value_t = FrictionCard::Calculix)]
    pub friction_card: FrictionCard,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    /// Table cache: the tables of layered stacks without `stack.table`, the ψ tables of
    /// conducting ones and the capped response tables (default: STRATA_CACHE_DIR, else
    /// $XDG_CACHE_HOME/strata or ~/.cache/strata).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
}

fn outputs(a: &Args) -> Result<Vec<(Format, PathBuf)>> {
    let ext = a
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let by_ext = match ext.as_deref() {
        Some("csv") => Some(Format::Csv),
        Some("json") => Some(Format::Json),
        Some("inp") => Some(Format::Abaqus),
        _ => None,
    };
    let format = match (a.format, by_ext) {
        (Some(f), _) => f,
        (None, Some(f)) => f,
        (None, None) => bail!(
            "--out {}: cannot tell the format from the extension: use .csv, .json or .inp, or give --format",
            a.out.display()
        ),
    };
    Ok(match format {
        Format::All => vec![
            (Format::Csv, a.out.with_extension("csv")),
            (Format::Json, a.out.with_extension("json")),
            (Format::Abaqus, a.out.with_extension("inp")),
        ],
        f => vec![(f, a.out.clone())],
    })
}

const CONVENTION: &str = "g = separation of the mean planes (P26), g0 = z_M - zbar its value at first contact (z_M: the highest summit in the N and I models, the highest grid point in the BEM; g, the flat's height above the mean plane, means the same in every model); overclosure h = g0 - g (Abaqus convention: positive when closing); mean_pressure p = P/A0 (nominal pressure); area_fraction = A/A0; dp_dg = derivative of the monotone interpolant of p(g) (<= 0), equal to -(dP/d delta)/A0 of the solver at the samples; p = 0 for g >= g0";

fn json(s: &SampledLaw, scene: &Path, card: Option<&card::FrictionCard>) -> Result<String> {
    let g0 = s.law.first_contact_gap();
    let law: Vec<serde_json::Value> = s
        .law
        .samples()
        .zip(s.law.validity())
        .map(|((g, p, d, a), v)| {
            serde_json::json!({"gap": g, "overclosure": g0 - g, "mean_pressure": p,
                               "area_fraction": a, "dp_dg": d, "valid": v.is_valid(),
                               "validity": v.describe()})
        })
        .collect();
    let v = serde_json::json!({
        "scene": scene.display().to_string(),
        "model": s.model,
        "solid": s.solid,
        "e_star_1": s.e_star,
        "nominal_area": s.nominal_area,
        "first_contact_gap": g0,
        "min_gap": s.law.min_gap(),
        "samples": s.law.len(),
        "limited_slopes": s.law.limited_slopes(),
        "linear_table_deviation": {
            "of_max_pressure": s.law.linear_table_deviation().of_max,
            "local_where_p_above_1pc_of_max": s.law.linear_table_deviation().local,
        },
        "validity_warnings": s.law.validity_warnings(),
        "fe_range": {
            "overclosure_max": s.fe_range().0,
            "pressure_max": s.fe_range().1,
            "note": "the FE overclosure/pressure range the table covers: an FE interface driven beyond \
                     overclosure_max leaves the table (CalculiX holds pressure_max with no stiffness)",
        },
        "surface": s.surface,
        "warnings": s.warnings,
        "convention": CONVENTION,
        "units": {"valid": "inside the model's validity (validity: why not)",
                  "gap": "m", "overclosure": "m", "mean_pressure": "Pa",
                  "area_fraction": "1", "dp_dg": "Pa/m", "nominal_area": "m^2", "e_star_1": "Pa"},
        "law": law,
    });
    let mut v = v;
    if let Some((h, back)) = &s.unloading {
        let g0 = s.law.first_contact_gap();
        v["plasticity"] = serde_json::json!({
            "hardness": h,
            "note": if back.is_empty() {
                "the tips capped at the hardness: `law` is the loading curve; the N and I models \
                 follow the loading path only (`unloading` is empty: model.kind = \"bem\" gives it; \
                 Abaqus/CalculiX tabular laws are elastic: they retrace the loading curve)"
            } else {
                "the tips capped at the hardness: `law` is the loading curve; `unloading` runs \
                 from the deepest sample back to first contact on the flattened surface \
                 (Abaqus/CalculiX tabular laws are elastic: they retrace the loading curve)"
            },
        });
        let slopes = crate::sampled_law::unloading_slopes(back);
        v["unloading"] = serde_json::Value::Array(
            back.iter()
                .zip(&slopes)
                .map(|((g, p, a), d)| {
                    serde_json::json!({"gap": g, "overclosure": g0 - g, "mean_pressure": p,
                                       "area_fraction": a, "dp_dg": d})
                })
                .collect(),
        );
    }
    if let Some((kind, h)) = &s.conductance {
        // [conductance]: h_c per sample (null where infinite: full contact)
        for (entry, &hc) in v["law"].as_array_mut().into_iter().flatten().zip(h) {
            entry["conductance"] = serde_json::json!(hc);
        }
        v["units"]["conductance"] = serde_json::json!(kind.interface_conductance_unit());
        v["conductance_kind"] = serde_json::json!(kind.name());
    }
    if let Some(k) = &s.tangential_stiffness {
        // [friction]: the sample's full-stick tangential stiffness per sample
        for (entry, &kt) in v["law"].as_array_mut().into_iter().flatten().zip(k) {
            entry["tangential_stiffness"] = serde_json::json!(kt);
        }
        v["units"]["tangential_stiffness"] = serde_json::json!("N/m (over the sample, full stick)");
    }
    if let Some(c) = card {
        v["friction_card"] = card_json(c);
    }
    Ok(serde_json::to_string_pretty(&v)?)
}

/// The friction card's values (the JSON's `friction_card`).
fn card_json(c: &card::FrictionCard) -> serde_json::Value {
    let ((l_lo, p_lo), (l_hi, p_hi)) = c.stick_slope_range;
    serde_json::json!({
        "coefficient": c.coefficient,
        "design_pressure": c.design_pressure,
        "tangential_stiffness": c.tangential_stiffness,
        "stick_slope": c.stick_slope,
        "stick_slope_range": {"min": l_lo, "at_pressure_min": p_lo,
                              "max": l_hi, "at_pressure_max": p_hi},
        "elastic_slip": c.elastic_slip,
        "elastic_slip_range": {"min": c.elastic_slip_range.0, "max": c.elastic_slip_range.1},
        "elastic_slip_spread": c.elastic_slip_spread,
        "elastic_slip_nearly_constant": c.elastic_slip_nearly_constant(),
        "units": {"coefficient": "1", "design_pressure": "Pa", "tangential_stiffness": "N/m",
                  "stick_slope": "Pa/m (lambda = K_t/A0 at the design pressure)",
                  "elastic_slip": "m (gamma = mu p A0/K_t)",
                  "elastic_slip_spread": "(max - min)/gamma at the design pressure, over p >= 1 % of p_max"},
    })
}

pub fn run(a: Args, memory: MemoryLimit) -> Result<()> {
    let t0 = Instant::now();
    check_samples(a.samples)?;
    check_min_gap(a.min_gap)?;
    let outs = outputs(&a)?;
    let scene = Scene::from_file(&a.scene)?;
    if a.design_pressure.is_some() && scene.friction.is_none() {
        bail!(
            "--design-pressure: scene {} has no [friction] (coefficient = μ): no friction card to write",
            a.scene.display()
        );
    }
    // beside the Abaqus block, its FE range as an amplitude that sizes a deck's load
    let range = outs
        .iter()
        .find(|(f, _)| *f == Format::Abaqus)
        .map(|(_, p)| range_path(p));
    let paths: Vec<PathBuf> = outs
        .iter()
        .map(|(_, p)| p.clone())
        .chain(range.iter().map(|(p, _)| p.clone()))
        .collect();
    let inputs = scene.inputs(&a.scene);
    for p in &paths {
        refuse_inputs("--out", p, &inputs)?;
    }
    let set = OutputSet::files("--out", &paths, a.force)?;
    let opts = EngineOptions {
        cache_dir: a.cache_dir.clone(),
        memory,
        ..Default::default()
    };
    let solved = crate::engine::load_surface(&scene, &memory)
        .and_then(|surface| sample_law(&scene, surface, &opts, &mut Console, a.samples, a.min_gap))
        .with_context(|| format!("scene {}", a.scene.display()))?;
    // [friction]: the friction card at the design pressure for the .inp and the JSON
    // (refused when λ <= 0); the CSV alone needs none
    let card = match &scene.friction {
        Some(f)
            if solved.tangential_stiffness.is_some()
                && outs.iter().any(|(fmt, _)| *fmt != Format::Csv) =>
        {
            Some(
                card::FrictionCard::new(&solved, f.coefficient, a.design_pressure)
                    .with_context(|| format!("scene {}", a.scene.display()))?,
            )
        }
        _ => None,
    };
    if let Some(c) = &card {
        progress::log(c.summary());
    }
    if outs.iter().any(|(f, _)| *f == Format::Abaqus) {
        for w in solved.law.calculix_warnings() {
            crate::stdio::eprint_line(format_args!("warning: {w}"));
        }
        if let Some(w) = solved.gap_conductance_dropped() {
            crate::stdio::eprint_line(format_args!("warning: {w}"));
        }
    }
    for (f, p) in &outs {
        let text = match f {
            Format::Csv => csv(&solved),
            Format::Json => json(&solved, &a.scene, card.as_ref())?,
            Format::Abaqus => {
                let code = match a.friction_card {
                    FrictionCard::Calculix => card::FeCode::Calculix,
                    FrictionCard::Abaqus => card::FeCode::Abaqus,
                };
                solved.abaqus_block(&a.scene.display().to_string())
                    + &card.as_ref().map(|c| c.block(code)).unwrap_or_default()
            }
            Format::All => bail!("internal error: --format all was not expanded"),
        };
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        set.write(&name, text.as_bytes())?;
    }
    if let Some((p, law_file)) = &range {
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        set.write(&name, solved.range_block(law_file).as_bytes())?;
    }
    set.commit()?;
    let l = &solved.law;
    progress::log(format!(
        "wrote {} samples (g from {:e} to {:e} m, p up to {:e} Pa) to {} in {:.3} s; \
         piecewise-linear table within {:.1e} of p_max ({:.1e} locally where p > 1% of p_max){}",
        l.len(),
        l.first_contact_gap(),
        l.min_gap(),
        l.samples().last().map_or(0.0, |s| s.1),
        outs.iter()
            .map(|(_, p)| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
        t0.elapsed().as_secs_f64(),
        l.linear_table_deviation().of_max,
        l.linear_table_deviation().local,
        if l.limited_slopes() > 0 {
            format!(
                "; {} sample slope(s) limited for monotonicity",
                l.limited_slopes()
            )
        } else {
            String::new()
        }
    ));
    let (h_max, p_max) = solved.fe_range();
    progress::log(format!(
        "FE range: the table covers overclosure 0 to {h_max:e} m (pressure 0 to {p_max:e} Pa); \
         an FE interface driven beyond it leaves the table (CalculiX holds {p_max:e} Pa, no stiffness)"
    ));
    Ok(())
}
