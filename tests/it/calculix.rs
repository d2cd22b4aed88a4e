//! CalculiX end to end: `strata law` writes the pressure-overclosure table,
//! the deck examples/calculix/rough_block.inp includes it, `ccx` (CalculiX 2.20, Debian
//! package `calculix-ccx`) solves a compliant block pressed on a stiff block through the
//! rough interface in 10 displacement increments, and the FE contact pressure must be
//! the law strata wrote (its CSV, linear between samples, as the FE code interpolates):
//!
//! - per slave node and increment, *CONTACT PRINT's pressure (CSTR) against the CSV at
//!   the node's overclosure h = −CDIS;
//! - per increment, the reaction force on the top over the area against the CSV at the
//!   overclosure the mechanics gives, h = u − p (H₁/M₁ + H₂/M₂) (uniform stress in a
//!   rigid die, M = E(1−ν)/((1+ν)(1−2ν)) the constrained modulus): a check that
//!   does not rely on CalculiX's own contact output.
//!
//! A second test checks what docs/embedding.md and the block's comments say CalculiX does:
//! the pressure is held beyond the last line, a table of more than 200 lines is
//! resampled onto 200 evenly spaced overclosures (and `strata law` warns), and
//! `TYPE=SURFACE TO SURFACE` with a TABULAR law does not run.
//!
//! Without `ccx` the tests say so on the terminal and pass; `STRATA_REQUIRE_TOOLS=1`
//! (CI, which installs calculix-ccx) makes that a failure.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::support::repo;
use crate::tools::optional_tool;

/// Nominal area of the blocks' contact faces (m²).
const AREA: f64 = 1e-6;
/// Final displacement of the top face (m), applied in 10 equal increments.
const U: f64 = 1.5e-5;

/// H₁/M₁ + H₂/M₂ (m/Pa): both blocks 1 mm high, ν = 0.3, E = 1 GPa and 200 GPa.
fn die_compliance() -> f64 {
    let m = |e: f64, nu: f64| e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    1e-3 / m(1e9, 0.3) + 1e-3 / m(2e11, 0.3)
}

/// A fresh scratch directory `ccx-NAME`.
pub(crate) fn tmp(name: &str) -> PathBuf {
    let d = crate::support::scratch().join(format!("ccx-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// The `ccx` to run (`STRATA_CCX` or `ccx`), `None` (said on the terminal) when absent.
pub(crate) fn ccx() -> Option<String> {
    optional_tool(
        &std::env::var("STRATA_CCX").unwrap_or_else(|_| "ccx".into()),
        "-v",
        "apt-get install calculix-ccx",
    )
}

/// `strata law SCENE --out DIR/law --format all [extra]`; returns its log.
pub(crate) fn strata_law(scene: &str, dir: &Path, extra: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(["law", scene, "--out"])
        .arg(dir.join("law"))
        .args(["--format", "all"])
        .args(extra)
        .current_dir(repo())
        .output()
        .expect("run strata");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "strata law failed:\n{err}");
    err
}

/// (overclosure, pressure) of the CSV strata wrote, overclosure ascending from 0.
pub(crate) fn read_table(csv: &Path) -> Vec<(f64, f64)> {
    crate::law::read_csv(csv)
        .iter()
        .map(|r| (r[1], r[2]))
        .collect()
}

/// The table interpolated linearly at overclosure `h` (inside the table).
pub(crate) fn linear(t: &[(f64, f64)], h: f64) -> f64 {
    let last = t[t.len() - 1].0;
    assert!((0.0..=last).contains(&h), "h = {h:e} outside [0, {last:e}]");
    let k = t.partition_point(|r| r.0 <= h).clamp(1, t.len() - 1);
    let ((h0, p0), (h1, p1)) = (t[k - 1], t[k]);
    p0 + (p1 - p0) * (h - h0) / (h1 - h0)
}

/// `n` points evenly spaced in overclosure over the table, linear from it: what
/// CalculiX 2.20 makes of a table longer than 200 lines.
fn resampled(t: &[(f64, f64)], n: usize) -> Vec<(f64, f64)> {
    let last = t[t.len() - 1].0;
    (0..n)
        .map(|i| {
            let h = if i + 1 == n {
                last
            } else {
                last * i as f64 / (n - 1) as f64
            };
            (h, linear(t, h))
        })
        .collect()
}

/// One increment of the .dat file.
#[derive(Debug, Default)]
pub(crate) struct Increment {
    pub(crate) time: f64,
    /// Total z force on the top face (N).
    pub(crate) force_z: f64,
    /// (slave node, contact pressure (Pa)).
    pub(crate) pressure: Vec<(usize, f64)>,
    /// (slave node, relative normal displacement (m), −overclosure).
    pub(crate) normal: Vec<(usize, f64)>,
}

/// The print blocks of a CalculiX .dat file, in order: (time, block title — the line
/// that names the set and the time —, the numeric rows under it).
pub(crate) fn dat_blocks(text: &str) -> Vec<(f64, String, Vec<Vec<f64>>)> {
    let mut blocks: Vec<(f64, String, Vec<Vec<f64>>)> = Vec::new();
    for line in text.lines() {
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        if t.contains(" and time ") {
            let time: f64 = t
                .split_whitespace()
                .last()
                .and_then(|v| v.parse().ok())
                .expect("time");
            blocks.push((time, t.to_string(), Vec::new()));
            continue;
        }
        let v: Vec<f64> = t.split_whitespace().map_while(|x| x.parse().ok()).collect();
        if let Some(b) = blocks.last_mut()
            && !v.is_empty()
        {
            b.2.push(v);
        }
    }
    blocks
}

/// Parses the `*NODE PRINT, TOTALS=ONLY` and `*CONTACT PRINT` blocks of a .dat file.
pub(crate) fn parse_dat(text: &str) -> Vec<Increment> {
    let mut incs: Vec<Increment> = Vec::new();
    for (time, title, rows) in dat_blocks(text) {
        if incs.last().is_none_or(|i| i.time != time) {
            incs.push(Increment {
                time,
                ..Default::default()
            });
        }
        let Some(inc) = incs.last_mut() else { continue };
        for v in rows {
            if title.starts_with("total force") && v.len() == 3 {
                inc.force_z = v[2];
            } else if title.starts_with("contact stress") && v.len() == 4 {
                inc.pressure.push((v[0] as usize, v[1]));
            } else if title.starts_with("relative contact displacement") && v.len() == 4 {
                inc.normal.push((v[0] as usize, v[1]));
            }
        }
    }
    incs
}

/// Runs `ccx -i JOB` in `dir` (one thread).
pub(crate) fn run_ccx(ccx: &str, dir: &Path, job: &str) -> Output {
    Command::new(ccx)
        .args(["-i", job])
        .env("OMP_NUM_THREADS", "1")
        .current_dir(dir)
        .output()
        .expect("run ccx")
}

/// The example deck with `from` replaced by `to` (must occur), written as DIR/JOB.inp.
fn deck(dir: &Path, job: &str, edits: &[(&str, &str)]) {
    let mut text =
        std::fs::read_to_string(repo().join("examples/calculix/rough_block.inp")).expect("deck");
    for (from, to) in edits {
        assert!(text.contains(from), "deck lacks `{from}`");
        text = text.replace(from, to);
    }
    std::fs::write(dir.join(format!("{job}.inp")), text).expect("write deck");
}

/// Solves the deck on `scene`'s law; returns the increments and the table.
fn solve(
    ccx: &str,
    scene: &str,
    law_args: &[&str],
    tag: &str,
    u: &str,
) -> (Vec<Increment>, Vec<(f64, f64)>) {
    let dir = tmp(tag);
    let log = strata_law(scene, &dir, law_args);
    // (the samples below the mean plane are outside the N and I models' validity:
    // `warning: law: …`, expected; no CalculiX warning)
    assert!(
        !log.lines()
            .any(|l| l.contains("warning") && !l.starts_with("warning: law: the")),
        "{log}"
    );
    deck(&dir, "rough_block", &[("TOP, 3, 3, -1.5E-5", u)]);
    let out = run_ccx(ccx, &dir, "rough_block");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "ccx failed:\n{stdout}");
    let dat = std::fs::read_to_string(dir.join("rough_block.dat")).expect("rough_block.dat");
    (parse_dat(&dat), read_table(&dir.join("law.csv")))
}

/// The FE pressure at every increment and slave node is the law's, both from CalculiX's
/// contact output and from the reaction force with the mechanics' overclosure.
fn fe_pressure_follows_the_law(scene: &str, law_args: &[&str], tag: &str) {
    let Some(ccx) = ccx() else { return };
    let (incs, table) = solve(&ccx, scene, law_args, tag, "TOP, 3, 3, -1.5E-5");
    assert!(incs.len() >= 8, "{} increments", incs.len());
    let h_last = table[table.len() - 1].0;
    let (mut worst_node, mut worst_rf, mut h_max) = (0.0f64, 0.0f64, 0.0f64);
    for inc in &incs {
        assert_eq!(
            inc.pressure.len(),
            9,
            "9 slave nodes in contact at t = {}",
            inc.time
        );
        assert_eq!(inc.normal.len(), 9);
        for (&(n, p), &(m, c)) in inc.pressure.iter().zip(&inc.normal) {
            assert_eq!(n, m);
            let h = -c;
            let law = linear(&table, h);
            let e = (p - law).abs() / law;
            assert!(
                e <= 1e-3,
                "t = {}, node {n}: FE {p:e} Pa, law {law:e} Pa at h = {h:e} m",
                inc.time
            );
            worst_node = worst_node.max(e);
            h_max = h_max.max(h);
        }
        let p = -inc.force_z / AREA;
        let h = U * inc.time - p * die_compliance();
        let law = linear(&table, h);
        let e = (p - law).abs() / law;
        assert!(
            e <= 1e-3,
            "t = {}: RF/A {p:e} Pa, law {law:e} Pa at h = {h:e} m",
            inc.time
        );
        worst_rf = worst_rf.max(e);
    }
    eprintln!(
        "{tag}: {} increments, h up to {h_max:.3e} m of {h_last:.3e}: contact pressure vs law {worst_node:.1e}, RF/A vs law {worst_rf:.1e}",
        incs.len()
    );
    assert!(
        h_max > 0.5 * h_last,
        "the increments cover too little of the table"
    );
}

/// Homogeneous scene (N model, Hertz asperities), sampled down to g = −1 µm (h up to
/// 11.2 µm; the scene's own load stops at 6.8 µm, which the 15 µm displacement passes).
#[test]
fn calculix_pressure_follows_the_law_homogeneous() {
    fe_pressure_follows_the_law(
        "scenes/homogeneous-km10-independent.toml",
        &["--min-gap=-1e-6"],
        "homogeneous",
    );
}

/// Layered stack (E2/E1 = 1 on a rigid base), I model with periodic images.
#[test]
fn calculix_pressure_follows_the_law_layered_interacting() {
    fe_pressure_follows_the_law("scenes/paper-E2E1-1-interacting.toml", &[], "layered");
}

/// What the block's comments and docs/embedding.md say CalculiX 2.20 does with a table.
#[test]
fn calculix_holds_beyond_the_table_resamples_long_ones_and_needs_node_to_surface() {
    let Some(ccx) = ccx() else { return };
    let scene = "scenes/paper-E2E1-1-interacting.toml";
    // Beyond the last line: the pressure stays at the last line's.
    let (incs, table) = solve(&ccx, scene, &[], "beyond", "TOP, 3, 3, -4.0E-5");
    let (h_last, p_last) = table[table.len() - 1];
    let mut beyond = 0;
    for inc in &incs {
        let (&(_, p), &(_, c)) = (&inc.pressure[0], &inc.normal[0]);
        if -c > h_last * (1.0 + 1e-3) {
            assert!(
                (p - p_last).abs() <= 1e-6 * p_last,
                "t = {}: {p:e} vs {p_last:e}",
                inc.time
            );
            beyond += 1;
        }
    }
    assert!(beyond >= 3, "{beyond} increments beyond the table");

    // 1000 lines: strata warns; CalculiX uses 200 evenly spaced points of the table.
    let dir = tmp("long");
    let log = strata_law(scene, &dir, &["--samples", "1000"]);
    assert!(
        log.contains("warning") && log.contains("CalculiX") && log.contains("200"),
        "{log}"
    );
    let inp = std::fs::read_to_string(dir.join("law.inp")).expect("law.inp");
    assert!(
        inp.contains("** WARNING: 1000 table lines"),
        "the block says so too"
    );
    deck(&dir, "rough_block", &[]);
    let out = run_ccx(&ccx, &dir, "rough_block");
    assert!(out.status.success());
    let dat = std::fs::read_to_string(dir.join("rough_block.dat")).expect("dat");
    let table = read_table(&dir.join("law.csv"));
    let coarse = resampled(&table, 200);
    let (mut vs_coarse, mut vs_given) = (0.0f64, 0.0f64);
    for inc in parse_dat(&dat) {
        let (&(_, p), &(_, c)) = (&inc.pressure[0], &inc.normal[0]);
        vs_coarse = vs_coarse.max((p / linear(&coarse, -c) - 1.0).abs());
        vs_given = vs_given.max((p / linear(&table, -c) - 1.0).abs());
    }
    eprintln!(
        "1000-line table: FE vs 200-point resampling {vs_coarse:.1e}, vs the table {vs_given:.1e}"
    );
    assert!(
        vs_coarse <= 1e-5 && vs_given > 1e-4,
        "{vs_coarse:e} {vs_given:e}"
    );

    // SURFACE TO SURFACE with a TABULAR law: CalculiX 2.20 does not run it.
    let dir = tmp("s2s");
    strata_law(scene, &dir, &[]);
    deck(
        &dir,
        "rough_block",
        &[(
            "TYPE=NODE TO SURFACE\nSLAVE",
            "TYPE=SURFACE TO SURFACE\nSLAVE",
        )],
    );
    let out = run_ccx(&ccx, &dir, "rough_block");
    assert!(
        !out.status.success(),
        "SURFACE TO SURFACE ran: update docs/embedding.md and the block's comments"
    );
}
