//! `strata ratio-map`: K_t/K_n of one disc and of rough surfaces against their closed-form
//! limits — Mindlin's 2(1 − ν)/(2 − ν) on a half-space at every a/h₁ and, for the N model
//! on a homogeneous surface, at every step (K_n = Σ 2E*aᵢ, K_t = Σ 8μaᵢ/(2 − ν)); a layer on
//! a rigid base between Mindlin's ratio (a ≪ h₁) and the thin layer's
//! (1 − 2ν)/(2(1 − ν)) (a ≫ h₁).

use crate::support::{fresh_dir, repo};

#[test]
fn ratio_map_meets_its_limits() {
    let d = fresh_dir("ratio_map", "small");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_strata"))
        .args([
            "-q",
            "ratio-map",
            "--stacks",
            "tables/stacks/half-space-steel.toml,tables/stacks/polymer-on-cooled-base.toml",
            "--scenes",
            "scenes/homogeneous-km10-independent.toml",
            "--per-decade",
            "1",
            "--out",
        ])
        .arg(&d)
        .current_dir(repo())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mindlin = |nu: f64| 2.0 * (1.0 - nu) / (2.0 - nu);
    let text = std::fs::read_to_string(d.join("ratio_asperity.csv")).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let num = |s: &str| s.parse::<f64>().unwrap();
    let (mut worst_hs, mut polymer) = (0.0f64, Vec::new());
    for r in &rows {
        match r[0] {
            "half-space-steel" => {
                worst_hs = worst_hs.max((num(r[5]) / mindlin(0.3) - 1.0).abs());
            }
            "polymer-on-cooled-base" => polymer.push((num(r[1]), num(r[5]))),
            s => panic!("stack {s}"),
        }
    }
    // measured 2.2e-16
    assert!(worst_hs < 1e-13, "half-space vs Mindlin {worst_hs:e}");
    assert_eq!(polymer.len(), 5);
    let thin = (1.0 - 2.0 * 0.35) / (2.0 * (1.0 - 0.35));
    let (small, wide) = (polymer[0].1, polymer[4].1);
    eprintln!(
        "half-space vs Mindlin {worst_hs:.1e}; polymer a/h1 = 0.01: {:.2e} off Mindlin, a/h1 = 100: {:.2e} above the thin layer",
        small / mindlin(0.35) - 1.0,
        wide / thin - 1.0
    );
    // a/h1 = 0.01: within 2 % of Mindlin's 0.788 (measured 0.47 % below); a/h1 = 100:
    // above the thin layer's 0.231 by less than 5 % (measured 1.1 %: the excess falls as h/a)
    assert!((small / mindlin(0.35) - 1.0).abs() < 0.02, "{small}");
    assert!(wide > thin && wide / thin - 1.0 < 0.05, "{wide} vs {thin}");
    assert!(polymer.windows(2).all(|w| w[1].1 < w[0].1), "{polymer:?}");
    // rough: the N model on the homogeneous surface is Mindlin's at every step
    let text = std::fs::read_to_string(d.join("ratio_rough.csv")).unwrap();
    let mut n = 0;
    for l in text.lines().skip(1) {
        let r: Vec<&str> = l.split(',').collect();
        if r[1] == "N" {
            let e = (num(r[6]) / mindlin(0.15) - 1.0).abs();
            assert!(e < 1e-13, "{l}: {e:e}");
            n += 1;
        }
    }
    assert_eq!(n, 5, "{text}");
    assert!(
        std::fs::read_to_string(d.join("ratio_rough.svg"))
            .unwrap()
            .contains("<svg")
    );
}
