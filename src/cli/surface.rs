//! `strata surface`: surfaces on their own.
//!
//! - `strata surface export SCENE.toml --out FILE.x3p|FILE.npy [--dtype D|F|L|I]`: the
//!   scene's surface exactly as a solve sees it (read, converted to metres, repaired,
//!   detrended; or generated) written as ISO 25178-72 `.x3p` (pixel sizes in the file,
//!   metres; `--dtype` the CZ data type, default `D` = lossless float64) or as a 2-D
//!   f64 `.npy` in metres, first axis x. Written atomically; an existing file is
//!   refused unless `--force`.
//! - `strata surface info FILE|SCENE.toml [--size L|LX,LY | --pixel-size DX,DY]
//!   [--height-unit U] [--periodic] [--detrend K] [--repair] [--json]`: grid, pixel
//!   sizes, sample size, periodic flag, RMS height, RMS slope, peak-to-valley, what the
//!   reader did, and the plausibility warnings (also on stderr). An `.x3p` needs no
//!   size; a `.npy`/text file does. A raw file (NaN/inf, spikes) is described, not
//!   refused: the statistics over its valid points, the count and largest cluster of
//!   its invalid points and of its spikes, and what `repair = "median"` would fill;
//!   `--repair` shows the filled surface instead.

use std::path::PathBuf;
use strata_runtime::resources::MemoryLimit;

use anyhow::{Context, Result, bail};
use clap::Subcommand;

use crate::cli::args::parse_list;
use crate::scene::{Scene, SurfaceSource};
use crate::stdio::{self, eprint_line};
use strata_runtime::surface::x3p::{DataType, X3pWriteOptions};
use strata_runtime::surface::{
    Detrend, FileKind, HeightUnit, ReadOptions, Repair, Spacing, Surface,
};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub command: Cmd,
}

#[derive(Debug, Subcommand)]
pub enum Cmd {
    /// Write a scene's surface (as solved: converted, repaired, detrended; or generated) as .x3p (ISO 25178-72) or .npy, by the extension of --out.
    Export(ExportArgs),
    /// Grid, pixel sizes, sample size and statistics (RMS height and slope, peak-to-valley) of a surface file or a scene's surface.
    Info(InfoArgs),
}

#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// Scene file (TOML) whose surface is exported.
    pub scene: PathBuf,
    /// Output file: `.x3p` or `.npy`.
    #[arg(long)]
    pub out: PathBuf,
    /// `.x3p` height data type: D (float64, lossless), F (float32), L (int32) or I (int16).
    #[arg(long, default_value = "D")]
    pub dtype: String,
    /// Overwrite an existing output file.
    #[arg(long)]
    pub force: bool,
}

#[derive(Debug, clap::Args)]
pub struct InfoArgs {
    /// A surface file (.x3p, .npy, text) or a scene (.toml).
    pub file: PathBuf,
    /// .npy/text: length of the first axis L (m), or LX,LY.
    #[arg(long)]
    pub size: Option<String>,
    /// .npy/text: pixel sizes DX,DY (m) (or one value for square pixels).
    #[arg(long)]
    pub pixel_size: Option<String>,
    /// .npy/text: unit of the heights: m (default), mm, um, nm.
    #[arg(long)]
    pub height_unit: Option<String>,
    /// The sample is one cell of a periodic pattern.
    #[arg(long)]
    pub periodic: bool,
    /// Remove a least-squares form first: none, plane, curvature.
    #[arg(long, default_value = "none")]
    pub detrend: String,
    /// Show the surface with its invalid points and spikes filled by harmonic
    /// interpolation (as `repair = "median"` does); without it, the statistics are over
    /// the valid points and what repair would do is listed.
    #[arg(long)]
    pub repair: bool,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also write the radially averaged PSD and the height and slope distributions to
    /// this directory: psd.svg, heights.svg, slopes.svg and psd.csv.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Replace an existing --plot directory's files.
    #[arg(long)]
    pub force: bool,
    /// Format of the --plot pictures: svg (default) or png.
    #[arg(long, default_value = "svg")]
    pub plot_format: String,
}

pub fn run(a: Args, memory: MemoryLimit) -> Result<()> {
    match a.command {
        Cmd::Export(e) => export(e, &memory),
        Cmd::Info(i) => info(i, &memory),
    }
}

fn export(a: ExportArgs, memory: &MemoryLimit) -> Result<()> {
    let scene =
        Scene::from_file(&a.scene).with_context(|| format!("scene {}", a.scene.display()))?;
    crate::output_set::refuse_inputs("--out", &a.out, &scene.inputs(&a.scene))?;
    let kind = a
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if kind != "x3p" && kind != "npy" {
        bail!(
            "--out {}: the extension must be .x3p or .npy",
            a.out.display()
        );
    }
    let data_type = DataType::parse(a.dtype.trim())
        .with_context(|| format!("--dtype `{}`: expected D, F, L or I", a.dtype))?;
    if kind == "npy" && data_type != DataType::D {
        bail!(
            "--dtype {}: applies to .x3p only (.npy is float64)",
            a.dtype
        );
    }
    if a.out.exists() && !a.force {
        bail!(
            "--out {}: exists (use --force to overwrite)",
            a.out.display()
        );
    }
    let surface = crate::engine::load_surface(&scene, memory).context("surface")?;
    crate::engine::surface_report(&surface, &crate::engine::Console);
    let source = match &scene.surface.source {
        SurfaceSource::File(p) => format!("file {}", p.display()),
        SurfaceSource::Generate(g) => format!(
            "generated: L = {:e} m, grid {}, D_f = {}, k = {}…{}, RMS {:e} m, seed {}",
            g.size, g.grid, g.fractal_dimension, g.k_min, g.k_max, g.rms, g.seed
        ),
    };
    if let Some(dir) = a.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| {
            format!("--out {}: cannot create {}", a.out.display(), dir.display())
        })?;
    }
    if kind == "x3p" {
        let comment = format!(
            "exported by strata from scene {} ({source}); periodic = {}",
            a.scene.display(),
            surface.is_periodic()
        );
        surface
            .write_x3p(
                &a.out,
                &X3pWriteOptions {
                    data_type,
                    comment: Some(comment),
                    memory: *memory,
                },
            )
            .with_context(|| format!("--out {}", a.out.display()))?;
    } else {
        surface
            .write_npy(&a.out)
            .with_context(|| format!("--out {}", a.out.display()))?;
    }
    let (n0, n1) = surface.shape();
    eprint_line(format_args!(
        "wrote the {n0}×{n1} surface ({source}) to {}{}",
        a.out.display(),
        if kind == "x3p" {
            format!(" (data type {})", data_type.code())
        } else {
            String::new()
        }
    ));
    if surface.is_periodic() {
        eprint_line(
            "note: .x3p and .npy carry no periodic flag: set surface.periodic = true in a scene that reads it back",
        );
    }
    Ok(())
}

fn info(a: InfoArgs, memory: &MemoryLimit) -> Result<()> {
    let is_scene = a
        .file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    let surface = if is_scene {
        if a.size.is_some() || a.pixel_size.is_some() || a.height_unit.is_some() {
            bail!(
                "--size, --pixel-size, --height-unit: a scene gives its own (its [surface] table)"
            );
        }
        let scene =
            Scene::from_file(&a.file).with_context(|| format!("scene {}", a.file.display()))?;
        crate::engine::load_surface(&scene, memory).context("surface")?
    } else {
        let spacing = match (&a.size, &a.pixel_size) {
            (Some(_), Some(_)) => bail!("give either --size or --pixel-size, not both"),
            (Some(s), None) => match parse_list("--size", s)?[..] {
                [l] => Some(Spacing::Size(l)),
                [lx, ly] => Some(Spacing::Extent(lx, ly)),
                _ => bail!("--size `{s}`: expected L or LX,LY (m)"),
            },
            (None, Some(s)) => match parse_list("--pixel-size", s)?[..] {
                [d] => Some(Spacing::Pixel(d, d)),
                [dx, dy] => Some(Spacing::Pixel(dx, dy)),
                _ => bail!("--pixel-size `{s}`: expected D or DX,DY (m)"),
            },
            (None, None) => None,
        };
        if spacing.is_none()
            && !matches!(
                FileKind::of(&a.file),
                FileKind::X3p | FileKind::NetCdf | FileKind::Container
            )
        {
            bail!(
                "{}: a .npy or text file needs --size L, --size LX,LY or --pixel-size DX,DY (m)",
                a.file.display()
            );
        }
        let height_unit = match &a.height_unit {
            None => None,
            Some(u) => Some(
                HeightUnit::parse(u)
                    .with_context(|| format!("--height-unit `{u}`: expected m, mm, um or nm"))?,
            ),
        };
        let detrend = Detrend::parse(&a.detrend).with_context(|| {
            format!(
                "--detrend `{}`: expected none, plane or curvature",
                a.detrend
            )
        })?;
        Surface::read(
            &a.file,
            &ReadOptions {
                spacing,
                periodic: a.periodic,
                // always checked and filled, so that a raw file is described; without
                // --repair the statistics are over the valid points
                repair: Repair::Median,
                height_unit,
                detrend,
                memory: *memory,
            },
        )?
    };
    if let Some(dir) = &a.plot {
        crate::output_set::refuse_inputs(
            "--plot",
            dir,
            &[("the surface file".into(), a.file.clone())],
        )?;
        let set = crate::output_set::OutputSet::dir("--plot", dir, a.force)?;
        let ext = match a.plot_format.as_str() {
            "svg" | "png" => a.plot_format.as_str(),
            f => bail!("--plot-format `{f}`: expected svg or png"),
        };
        plot_surface(&surface, &set, &a.file.display().to_string(), ext)?;
        set.commit()?;
    }
    // a file read here without --repair: statistics over the points measured
    let over_valid = !is_scene && !a.repair;
    let stats = if over_valid {
        surface.stats_over_valid()
    } else {
        surface.stats()
    };
    let repair_lines = repair_lines(&surface, over_valid);
    let warnings = crate::engine::surface_warnings(&surface);
    for w in &warnings {
        eprint_line(format_args!("WARNING: surface: {w}"));
    }
    if a.json {
        let mut v = serde_json::to_value(crate::solution::SurfaceReport::of(&surface))?;
        if over_valid {
            let st = serde_json::to_value(stats)?;
            if let (Some(obj), Some(st)) = (v.as_object_mut(), st.as_object()) {
                for (k, x) in st {
                    obj.insert(k.clone(), x.clone());
                }
            }
            v["repaired_points"] = serde_json::json!(0);
            v["statistics_over"] = serde_json::json!("valid points (NaN/inf and spikes left out)");
            v["read"] = serde_json::json!(
                surface
                    .log()
                    .iter()
                    .filter(|l| !l.starts_with("repair:"))
                    .collect::<Vec<_>>()
            );
        }
        v["repair_summary"] = serde_json::json!(repair_lines);
        v["file"] = serde_json::json!(a.file.display().to_string());
        v["warnings"] = serde_json::json!(warnings);
        let text = serde_json::to_string_pretty(&v)?;
        return Ok(stdio::print(|o| writeln!(o, "{text}"))?);
    }
    stdio::print(|o| {
        writeln!(o, "file: {}", a.file.display())?;
        writeln!(
            o,
            "grid: {} × {} points (first axis x)",
            stats.shape.0, stats.shape.1
        )?;
        writeln!(
            o,
            "pixel size: dx = {:e} m, dy = {:e} m",
            stats.pixel_size.0, stats.pixel_size.1
        )?;
        writeln!(
            o,
            "size: Lx = {:e} m, Ly = {:e} m",
            stats.size.0, stats.size.1
        )?;
        writeln!(o, "periodic: {}", stats.periodic)?;
        writeln!(o, "mean height: {:e} m", stats.mean_height)?;
        writeln!(o, "RMS height: {:e} m", stats.rms_height)?;
        writeln!(o, "RMS slope: {:e}", stats.rms_slope)?;
        writeln!(o, "peak-to-valley: {:e} m", stats.peak_to_valley)?;
        for l in &repair_lines {
            writeln!(o, "{l}")?;
        }
        for l in surface
            .log()
            .iter()
            .filter(|l| !(over_valid && l.starts_with("repair:")))
        {
            writeln!(o, "read: {l}")?;
        }
        for w in &warnings {
            writeln!(o, "warning: {w}")?;
        }
        Ok(())
    })?;
    Ok(())
}

/// What checking the heights found (invalid points and spikes, their clusters) and what
/// repair does (`over_valid`: the file was filled only to be described) or did.
fn repair_lines(surface: &Surface, over_valid: bool) -> Vec<String> {
    let Some(r) = surface.repair_report() else {
        return Vec::new();
    };
    let mut v = vec![
        format!(
            "invalid points (NaN/inf): {} in {} clusters, the largest {} points",
            r.invalid, r.invalid_clusters, r.invalid_largest
        ),
        format!(
            "spikes (judged after removing the least-squares plane): {} in {} clusters, the largest {} points",
            r.spikes, r.spike_clusters, r.spike_largest
        ),
    ];
    v.push(if r.repaired == 0 {
        "repair: nothing to repair".to_string()
    } else if over_valid {
        format!(
            "repair: [surface] repair = \"median\" would fill {} points ({:.3} % of the map) in {} \
             clusters, the largest {}, by harmonic interpolation; without it a solve refuses \
             this file; the statistics above are over the valid points",
            r.repaired,
            100.0 * r.fraction,
            r.clusters,
            r.largest
        )
    } else {
        format!(
            "repair: filled {} points ({:.3} % of the map) in {} clusters, the largest {}, by \
             harmonic interpolation",
            r.repaired,
            100.0 * r.fraction,
            r.clusters,
            r.largest
        )
    });
    v
}

/// psd (log–log C(q) against q), heights and slopes (densities beside the Gaussian of
/// the same RMS) as `ext` pictures, and psd.csv (`q,C,count`), for `surface info --plot`.
fn plot_surface(
    surface: &Surface,
    set: &crate::output_set::OutputSet,
    name: &str,
    ext: &str,
) -> Result<()> {
    use crate::plot::{PlotSpec, Series, Style};
    let psd = surface.radial_psd()?;
    let text = crate::csv_out::text(
        ["q", "C", "count"],
        psd.iter().map(|b| {
            [
                crate::csv_out::num(b.q),
                crate::csv_out::num(b.c),
                b.count.to_string(),
            ]
        }),
    )?;
    set.write("psd.csv", text.as_bytes())?;
    let short = std::path::Path::new(name)
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| name.to_string());
    crate::plot::lines(
        &set.path(&format!("psd.{ext}"))?,
        &PlotSpec {
            title: format!("Power spectral density: {short}"),
            x_label: "wavenumber q (1/m)".into(),
            y_label: "C(q) (m^4)".into(),
            log_x: true,
            log_y: true,
            series: vec![Series {
                name: "radial average".into(),
                // bins at round-off (a band-limited surface outside its band) left out
                points: psd
                    .iter()
                    .filter(|b| b.c > 1e-14 * psd.iter().fold(0.0_f64, |m, x| m.max(x.c)))
                    .map(|b| (b.q, b.c))
                    .collect(),
                style: Style::Line,
            }],
        },
    )?;
    let (heights, slopes) = surface.distributions(60);
    let stats = surface.stats();
    let gauss =
        |x: f64, s: f64| (-0.5 * (x / s).powi(2)).exp() / (s * (std::f64::consts::TAU).sqrt());
    for (file, d, sigma, unit, density, label, scale) in [
        (
            "heights",
            &heights,
            stats.rms_height,
            "height − mean (µm)",
            "probability density (1/µm)",
            "heights",
            1e6,
        ),
        (
            "slopes",
            &slopes,
            stats.rms_slope / std::f64::consts::SQRT_2,
            "slope ∂h/∂x, ∂h/∂y (-)",
            "probability density (-)",
            "slopes",
            1.0,
        ),
    ] {
        let measured: Vec<(f64, f64)> =
            d.x.iter()
                .zip(&d.p)
                .map(|(x, p)| (x * scale, p / scale))
                .collect();
        let lo = d.x.first().copied().unwrap_or(0.0);
        let hi = d.x.last().copied().unwrap_or(0.0);
        let normal: Vec<(f64, f64)> = (0..=200)
            .map(|k| {
                let x = lo + (hi - lo) * k as f64 / 200.0;
                (x * scale, gauss(x, sigma) / scale)
            })
            .collect();
        crate::plot::lines(
            &set.path(&format!("{file}.{ext}"))?,
            &PlotSpec {
                title: format!("Distribution of the {label}: {short}"),
                x_label: unit.into(),
                y_label: density.into(),
                log_x: false,
                log_y: false,
                series: vec![
                    Series {
                        name: "measured".into(),
                        points: measured,
                        style: Style::Points,
                    },
                    Series {
                        name: "Gaussian, same RMS".into(),
                        points: normal,
                        style: Style::Line,
                    },
                ],
            },
        )?;
    }
    Ok(())
}
