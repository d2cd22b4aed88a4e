//! The law's effects from Rust (the functions behind `strata_law_new_with_law_options`):
//! h_c(g) between the samples of a coarse law against a law sampled twice as finely
//! (the interpolation error, docs/validation.md), and the hardness's domain. The
//! samples themselves are the engine's (`strata_engine::law_build`), `strata law`'s own
//! code: nothing here compares copies.

use std::path::PathBuf;

use strata_capi::*;
use strata_runtime::rough::{Model, Params};
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
        conductance: Some(ConductanceSpec {
            kind: strata_runtime::conduction::ConductionKind::Thermal,
            counterface: CounterfaceConduction::HalfSpace(50.0),
        }),
        friction: None,
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

/// With `options.friction_coefficient` the law carries the full-stick tangential
/// stiffness: `strata_law_tangential_stiffness` at the law's own samples equals the
/// `tangential_stiffness` column of `strata solve` (the engine's `solve`) of the same
/// scene at those separations, for the N and I models (homogeneous half-space); a law
/// without friction and a negative coefficient are refused, naming `law` and
/// `options.friction_coefficient`.
#[test]
fn tangential_stiffness_equals_solve() {
    let stack = Stack::half_space(4e9, 0.15).unwrap();
    let s = surface(8.0, 7);
    let opts = StrataLawOptions {
        friction_coefficient: 0.3,
        ..StrataLawOptions::default()
    };
    let effects = opts.effects().unwrap();
    let mut worst = 0.0f64;
    for (model, kind) in [
        (Model::Independent, "independent"),
        (
            Model::Interacting(strata_runtime::rough::Images::Isolated),
            "interacting",
        ),
    ] {
        let law =
            build_law_with_effects(None, &stack, &s, model, 2e-6, 8, Params::default(), effects)
                .expect("law");
        let csv = law_csv(&law);
        assert!(
            csv.lines()
                .next()
                .unwrap()
                .ends_with(",tangential_stiffness"),
            "{csv}"
        );
        let gaps: Vec<f64> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap().parse().unwrap())
            .collect();
        let c: Vec<f64> = gaps
            .iter()
            .map(|&g| {
                let mut out = f64::NAN;
                // SAFETY: a live law and a writable double.
                assert_eq!(
                    unsafe { strata_law_tangential_stiffness(&law, g, &mut out) },
                    STRATA_OK
                );
                out
            })
            .collect();
        // the same scene through the engine's solve at the law's separations
        // (all of them, first contact too: the I model's path is warm-started step by step)
        let list: Vec<String> = gaps.iter().map(|g| format!("{g:e}")).collect();
        let text = format!(
            "[stack]\n[[stack.layer]]\nthickness = 1e-3\nyoung = 4e9\npoisson = 0.15\n\
             [stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
             [surface]\nperiodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 128\n\
             fractal_dimension = 2.4\nk_min = 2\nk_max = 8\nrms = 3.4e-6\nseed = 7\n\
             [model]\nkind = \"{kind}\"\nimages = \"isolated\"\n[load]\nseparations = [{}]\n\
             [friction]\ncoefficient = 0.3\n",
            list.join(", ")
        );
        let dir = std::env::temp_dir().join(format!("strata-capi-kt-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(format!("{kind}.toml"));
        std::fs::write(&p, text).unwrap();
        let scene = strata::scene::Scene::from_file(&p).unwrap();
        let sol = strata::engine::solve(
            &scene,
            None,
            &strata::engine::EngineOptions::default(),
            &mut strata::engine::Quiet,
        )
        .unwrap();
        let kt = sol.tangential_stiffnesses().unwrap();
        assert_eq!(c[0], 0.0, "first contact");
        assert_eq!(kt.len(), c.len());
        for (a, b) in c[1..].iter().zip(&kt[1..]) {
            assert!(*b > 0.0 || *a == 0.0);
            worst = worst.max(rel(*a, *b));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    eprintln!("C ABI K_t vs solve: worst {worst:.1e}");
    // the same solve at the same separations: bit for bit (measured 0)
    assert_eq!(worst, 0.0);
    // refusals
    let plain = build_law_with_effects(
        None,
        &stack,
        &s,
        Model::Independent,
        2e-6,
        4,
        Params::default(),
        LawEffects::default(),
    )
    .unwrap();
    let mut out = 0.0;
    // SAFETY: a live law and a writable double.
    assert_eq!(
        unsafe { strata_law_tangential_stiffness(&plain, 1e-6, &mut out) },
        STRATA_ERR_INVALID_ARGUMENT
    );
    let bad = StrataLawOptions {
        friction_coefficient: -0.1,
        ..StrataLawOptions::default()
    };
    let e = bad.effects().unwrap_err().to_string();
    assert!(e.contains("options.friction_coefficient"), "{e}");
}
