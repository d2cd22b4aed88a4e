//! The BEM's grid convergence on the shared reference surface: the paper's two layers
//! (E2/E1 = 1, rigid base) under the band-limited surface of `tests/reference`
//! (k ≤ 10·2π/L, so it is resampled exactly to each grid). The flat is held at the same
//! height on every grid (δ given for the 512² grid's highest point, shifted by the
//! change of the sampled maximum). Prints the Markdown rows of `docs/validation.md`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use strata_bem::{BemLoad, BemOptions, BemSolver, read_heights_npy, resample_spectral};
use strata_runtime::Stack;

/// Side of the reference sample (m).
const L: f64 = 1e-3;

fn reference_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/reference")
}

/// The `delta` column of the reference curve (`#` comment lines, one header line).
fn deltas(path: &Path) -> Result<Vec<f64>> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let Some(id) = header.iter().position(|h| h.trim() == "delta") else {
        bail!("{}: no `delta` column", path.display());
    };
    lines
        .map(|l| {
            let v = l.split(',').nth(id).unwrap_or_default().trim();
            v.parse::<f64>()
                .with_context(|| format!("{}: delta `{v}`", path.display()))
        })
        .collect()
}

pub fn table() -> Result<()> {
    let dir = reference_dir();
    let heights = read_heights_npy(&dir.join("surface_km10.npy"))?;
    let stack = Stack::from_toml_file(&dir.join("stack_h100um_E2E1_1.toml"))?;
    let all = deltas(&dir.join("rough_h100um_E2E1_1.csv"))?;
    let deltas: Vec<f64> = [2, 7, 11, 14].iter().map(|&i| all[i]).collect();
    let grids = [64, 128, 256, 512, 1024];
    let base = BemSolver::new(&heights, L, &stack, BemOptions::default())?.max_separation();
    let mut t = Vec::new();
    for &n in &grids {
        eprintln!("grid {n}² …");
        let z = if n == heights.dim().0 {
            heights.clone()
        } else {
            resample_spectral(&heights, n)?
        };
        let solver = BemSolver::new(&z, L, &stack, BemOptions::default())?;
        let shift = solver.max_separation() - base;
        let loads: Vec<BemLoad> = deltas
            .iter()
            .map(|&d| BemLoad::Approach(d + shift))
            .collect();
        let row: Vec<(f64, f64)> = solver
            .solve_curve(&loads)?
            .iter()
            .map(|s| (s.pressure_ratio, s.area_fraction))
            .collect();
        t.push(row);
    }
    println!("| δ (µm) | n | p̄/E*₁ | A/A₀ | rel. diff p vs 1024² | rel. diff A vs 1024² |");
    println!("|---|---|---|---|---|---|");
    let fine = &t[grids.len() - 1];
    for (k, d) in deltas.iter().enumerate() {
        for (gi, n) in grids.iter().enumerate() {
            let (p, a) = t[gi][k];
            let (pf, af) = fine[k];
            println!(
                "| {:.3} | {n} | {p:.6e} | {a:.5e} | {:.2e} | {:.2e} |",
                d * 1e6,
                (p / pf - 1.0).abs(),
                (a / af - 1.0).abs()
            );
        }
    }
    Ok(())
}
