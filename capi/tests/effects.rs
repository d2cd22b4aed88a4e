//! The law's effects from Rust (the functions behind `strata_law_new_with_law_options`):
//! a capped I-model law on a layered stack (the paper's two-layer table for the
//! interactions, the capped asperity's response on the layers) equals `strata law` on
//! the equivalent scene, and h_c(g) between the samples of a coarse law against a law
//! sampled twice as finely (the interpolation error, docs/validation.md).

use std::path::PathBuf;

use strata_capi::*;
use strata_runtime::rough::{Images, Model, Params};
use strata_runtime::stack::Stack;
use strata_runtime::surface::{GenerateParams, Surface};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("capi/ has a parent")
        .to_path_buf()
}

fn surface(k_max: f64, seed: u64) -> Surface {
    Surface::generate(&GenerateParams {
        size: 1e-3,
        grid: 128,
        fractal_dimension: 2.4,
        k_min: 2.0,
        k_max,
        rms: 3.4e-6,
        seed,
    })
    .expect("surface")
}

fn table() -> StrataTable {
    let p = repo().join("tables/paper-two-layer.strata");
    let mut out = std::ptr::null_mut();
    let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
    // SAFETY: a valid path and out pointer; the handle is leaked for the test's life.
    assert_eq!(
        unsafe { strata_table_load(c.as_ptr(), &mut out) },
        STRATA_OK
    );
    // SAFETY: a handle just created.
    *unsafe { Box::from_raw(out) }
}

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / a.abs().max(b.abs())
    }
}

/// Capped tips on the paper's two-layer stack (E2/E1 = 5, H = 0.2 GPa on the 4 GPa
/// top layer), I model with periodic images: p and A/A₀ per sample equal `strata law`'s
/// (1e-12; measured 0), and the caps lower the pressure at depth.
#[test]
fn capped_law_on_a_layered_stack_matches_strata_law() {
    let root = repo();
    let stack = Stack::from_toml_file(&root.join("tables/stacks/paper-two-layer.toml")).unwrap();
    let s = surface(6.0, 5);
    let t = table();
    let model = Model::Interacting(Images::Periodic(2));
    let effects = LawEffects {
        hardness: Some(0.2e9),
        conductance: None,
    };
    let law = build_law_with_effects(
        Some(&t),
        &stack,
        &s,
        model,
        0.0,
        8,
        Params::default(),
        effects,
    )
    .expect("capped law");
    let c_csv = law_csv(&law);

    let dir = std::env::temp_dir().join(format!("strata-capi-effects-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("capped.toml");
    std::fs::write(
        &scene,
        format!(
            "[stack]\nfile = \"{}\"\ntable = \"{}\"\n[surface]\nperiodic = true\n\
             [surface.generate]\nsize = 1e-3\ngrid = 128\nfractal_dimension = 2.4\nk_min = 2\n\
             k_max = 6\nrms = 3.4e-6\nseed = 5\n[load]\napproach = {{ from = 1e-6, to = 4e-6, steps = 4 }}\n\
             [plasticity]\nhardness = 0.2e9\n[model]\nkind = \"interacting\"\nimages = \"periodic\"\n",
            root.join("tables/stacks/paper-two-layer.toml").display(),
            root.join("tables/paper-two-layer.strata").display()
        ),
    )
    .unwrap();
    let out = dir.join("capped.csv");
    strata::progress::init(true);
    strata::cli::law::run(strata::cli::law::Args {
        scene,
        out: out.clone(),
        format: Some(strata::cli::law::Format::Csv),
        samples: 8,
        min_gap: Some(0.0),
        force: true,
        cache_dir: None,
    })
    .expect("strata law");
    let cli = std::fs::read_to_string(&out).unwrap();
    let rows = |t: &str| -> Vec<Vec<f64>> {
        t.lines()
            .skip(1)
            .map(|l| l.split(',').take(6).map(|v| v.parse().unwrap()).collect())
            .collect()
    };
    let (a, b) = (rows(&cli), rows(&c_csv));
    assert_eq!(a.len(), 8);
    let mut worst: f64 = 0.0;
    for (x, y) in a.iter().zip(&b) {
        for (u, v) in x.iter().zip(y) {
            worst = worst.max(rel(*u, *v));
        }
    }
    eprintln!("layered capped I law vs strata law: worst {worst:e}");
    assert!(worst <= 1e-12, "{worst}");
    assert_eq!(cli.lines().next(), c_csv.lines().next());
    // elastic I law at the deepest sample: the cap bites
    let elastic = build_law(Some(&t), &stack, &s, model, 0.0, 8).unwrap();
    let pe = elastic.samples().last().unwrap().1;
    assert!(a[7][2] < 0.9 * pe, "capped {} vs elastic {pe}", a[7][2]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// h_c(g) of a 40-sample law half-way between its samples against a 79-sample law,
/// whose odd samples lie there (N model, thermal, the paper's conducting stack, a
/// 50 W/(m·K) flat): the interpolation error of the monotone cubic is small where the
/// curve is smooth (one summit in contact: < 4e-3, measured 3.9e-4) and, where a
/// summit touches down between two samples (a ∝ √δ from there), of the order of the
/// law's own A/A₀ interpolation error (< 5×, measured 8.1e-2 against 2.0e-2;
/// docs/validation.md).
#[test]
fn conductance_between_samples_against_a_finer_law() {
    let root = repo();
    let stack =
        Stack::from_toml_file(&root.join("tables/stacks/paper-two-layer-conducting.toml")).unwrap();
    let s = surface(10.0, 20240611);
    let t = table();
    let effects = LawEffects {
        hardness: None,
        conductance: Some((
            strata_runtime::conduction::ConductionKind::Thermal,
            CounterfaceConduction::HalfSpace(50.0),
        )),
    };
    let build = |n| {
        build_law_with_effects(
            Some(&t),
            &stack,
            &s,
            Model::Independent,
            2e-6,
            n,
            Params::default(),
            effects,
        )
        .expect("law")
    };
    let (coarse, fine) = (build(40), build(79));
    let fine_csv = law_csv(&fine);
    let fine_rows: Vec<(f64, f64, f64)> = fine_csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
            (f[0], f[6], f[3])
        })
        .collect();
    let mut worst: f64 = 0.0;
    let mut worst_inner: f64 = 0.0;
    let mut worst_area: f64 = 0.0;
    let mut worst_smooth: f64 = 0.0;
    for (i, (g, h, a)) in fine_rows.iter().enumerate().filter(|(i, _)| i % 2 == 1) {
        let mut out = [0.0];
        conductance_into(&coarse, "gaps", &[*g], false, &mut out).unwrap();
        let e = rel(out[0], *h);
        let ea = rel(coarse_area(&coarse, *g), *a);
        worst_area = worst_area.max(ea);
        if (5..=19).contains(&i) {
            // one summit in contact: a smooth stretch of the curve
            worst_smooth = worst_smooth.max(e);
        }
        worst = worst.max(e);
        if i > 1 {
            worst_inner = worst_inner.max(e);
        }
    }
    eprintln!(
        "h_c between samples: worst {worst:.2e} (beyond the first interval {worst_inner:.2e}); \
         A/A0 there {worst_area:.2e}"
    );
    eprintln!("one summit in contact: worst {worst_smooth:.2e}");
    // measured 3.9e-4 where one summit conducts; 8.1e-2 at a summit's touchdown between
    // two samples (a ∝ √δ there), 4.1× the law's own A/A₀ error at the same gaps
    assert!(worst_smooth < 4e-3, "{worst_smooth}");
    assert!(worst < 5.0 * worst_area, "{worst} vs A/A0 {worst_area}");
}

/// A/A₀ of a law at `g` through the C ABI's evaluation.
fn coarse_area(law: &StrataLaw, g: f64) -> f64 {
    let (mut p, mut a, mut d) = ([0.0], [0.0], [0.0]);
    eval_into(law.law(), &[g], &mut p, &mut a, &mut d).unwrap();
    a[0]
}

/// A hardness outside [1e-3, 1e15] Pa is refused naming `options.hardness` (1e-30 gave
/// A/A₀ = 4294; 1e-100 … 1e-305 empty values or a hang); its ends, 0 and INFINITY
/// (elastic tips) are accepted.
#[test]
fn hardness_outside_its_range_is_refused() {
    for h in [1e-30, 1e-305, 9.9e-4, 1.1e15, 1e300, -1.0, f64::NAN] {
        let o = StrataLawOptions {
            hardness: h,
            ..Default::default()
        };
        let e = o.effects().unwrap_err().to_string();
        assert!(e.contains("options.hardness"), "H = {h}: {e}");
    }
    for (h, want) in [
        (1e-3, Some(1e-3)),
        (1e15, Some(1e15)),
        (0.0, None),
        (f64::INFINITY, None),
    ] {
        let o = StrataLawOptions {
            hardness: h,
            ..Default::default()
        };
        assert_eq!(o.effects().unwrap().hardness, want, "H = {h}");
    }
}
