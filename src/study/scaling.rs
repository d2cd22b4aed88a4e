//! Stage 5: the I model at scale — wall time and peak memory of a cold
//! 20-step I-model load curve (5×5 periodic images, the family table's E₂/E₁ = 5 stack)
//! against the number of summits N of generated surfaces (L = 1 mm, D_f = 2.4,
//! k_m = 2, RMS 3.4 µm, growing grid and k_M), with the exponents of least-squares fits
//! t ∝ N^α and (peak − baseline memory) ∝ N^β. Above `Params::dense_pair_limit` loaded
//! asperities the far field runs on the FFT grid with sparse near corrections.
//!
//! Memory: the process's peak resident set (Linux `VmHWM`, reset before each run by
//! writing 5 to `/proc/self/clear_refs`) minus its resident set before the run; None
//! where the kernel does not offer them.

use std::time::Instant;

use anyhow::{Context, Result};
use strata_runtime::rough::{Images, Model, RoughContact};
use strata_runtime::surface::{GenerateParams, Surface};
use strata_runtime::table::Table;

use super::{Inputs, Mode};

/// One measured curve.
#[derive(Debug, Clone)]
pub struct Row {
    pub grid: usize,
    pub k_max: f64,
    pub summits: usize,
    /// Contacts at the last step.
    pub contacts: usize,
    pub seconds: f64,
    /// Peak resident memory of the run above the resident set before it (bytes).
    pub memory: Option<u64>,
}

#[derive(Debug, Clone, Default)]
pub struct Results {
    pub steps: usize,
    pub rows: Vec<Row>,
    /// Fitted exponents of time and memory against N (None with fewer than 2 points).
    pub time_exponent: Option<f64>,
    pub memory_exponent: Option<f64>,
}

/// (grid, k_M) of the surfaces and the load steps per curve of each mode.
fn settings(mode: Mode) -> (Vec<(usize, f64)>, usize) {
    match mode {
        Mode::Tiny => (vec![(128, 32.0), (192, 48.0)], 3),
        Mode::Quick => (vec![(256, 64.0), (512, 128.0), (1024, 200.0)], 20),
        Mode::Full => (
            vec![
                (256, 64.0),
                (512, 128.0),
                (1024, 200.0),
                (1024, 400.0),
                (2048, 840.0),
            ],
            20,
        ),
    }
}

/// A field of /proc/self/status in bytes ("VmHWM", "VmRSS").
fn status_bytes(field: &str) -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with(field))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Least-squares slope of ln y against ln x.
pub fn fit_exponent(points: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

pub fn run(mode: Mode, inputs: &Inputs) -> Result<Results> {
    let (sizes, steps) = settings(mode);
    let table = Table::load(&inputs.table)
        .with_context(|| format!("loading {}", inputs.table.display()))?;
    let stack = strata_runtime::Stack::paper_two_layer(5.0)?;
    let law = table.law_for(&stack)?;
    let mut rows = Vec::new();
    for (grid, k_max) in sizes {
        let s = Surface::generate(&GenerateParams::paper(grid, k_max))?;
        let base = status_bytes("VmRSS");
        let _ = std::fs::write("/proc/self/clear_refs", "5");
        let t0 = Instant::now();
        let rc = RoughContact::from_surface(&law, &s)?;
        let top = rc.top_to_mean();
        let deltas: Vec<f64> = (1..=steps)
            .map(|i| 0.87 * top * i as f64 / steps as f64)
            .collect();
        let curve = rc.curve(Model::Interacting(Images::Periodic(2)), &deltas)?;
        let seconds = t0.elapsed().as_secs_f64();
        let memory = match (status_bytes("VmHWM"), base) {
            (Some(p), Some(b)) => Some(p.saturating_sub(b)),
            _ => None,
        };
        let row = Row {
            grid,
            k_max,
            summits: rc.summits().len(),
            contacts: curve.last().map_or(0, |s| s.contacts),
            seconds,
            memory,
        };
        crate::progress::log(format!(
            "study: I model at scale: {} summits, {:.2} s, {}",
            row.summits,
            row.seconds,
            row.memory
                .map_or("memory n/a".into(), strata_runtime::resources::human_bytes)
        ));
        rows.push(row);
    }
    let time_exponent = fit_exponent(
        &rows
            .iter()
            .map(|r| (r.summits as f64, r.seconds))
            .collect::<Vec<_>>(),
    );
    let memory_exponent = fit_exponent(
        &rows
            .iter()
            .filter_map(|r| r.memory.map(|m| (r.summits as f64, m as f64)))
            .collect::<Vec<_>>(),
    );
    Ok(Results {
        steps,
        rows,
        time_exponent,
        memory_exponent,
    })
}

/// The report's section.
pub fn markdown(r: &Results) -> String {
    use std::fmt::Write;
    let mut w = String::new();
    let _ = writeln!(
        w,
        "## 5. I model at scale\n\nCold {}-step I-model curve (5×5 periodic images, family table \
         E₂/E₁ = 5) on generated surfaces of growing N; memory is the process's peak resident \
         set during the run above its resident set before it.\n\n\
         | grid | k_M | summits N | contacts (last step) | time | peak memory |\n|---|---|---|---|---|---|",
        r.steps
    );
    for row in &r.rows {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} |",
            row.grid,
            row.k_max,
            row.summits,
            row.contacts,
            super::fmt_time(row.seconds),
            row.memory
                .map_or("n/a".into(), strata_runtime::resources::human_bytes)
        );
    }
    let fmt = |e: Option<f64>| e.map_or("n/a".into(), |v| format!("{v:.2}"));
    let _ = writeln!(
        w,
        "\nFitted exponents: time ∝ N^{}, memory ∝ N^{}.\n",
        fmt(r.time_exponent),
        fmt(r.memory_exponent)
    );
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponent_of_a_power_law() {
        let pts: Vec<(f64, f64)> = [1e3, 4e3, 1e4, 1e5]
            .iter()
            .map(|&n: &f64| (n, 3e-4 * n.powf(1.3)))
            .collect();
        assert!((fit_exponent(&pts).unwrap() - 1.3).abs() < 1e-12);
        assert!(fit_exponent(&pts[..1]).is_none());
    }
}
