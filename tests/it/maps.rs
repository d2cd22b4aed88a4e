//! `strata solve` with `[output] maps`: the BEM's pressure and gap maps as .npy and
//! PNG pictures. The maps must be the solution curve.csv summarises: the mean
//! of the pressure map is curve.csv's mean pressure (1e-12 relative), the contact
//! fraction of the map is its A/A₀ (exact count), and on a half-space the mean of the gap
//! map is the separation g_n (the elastic-base convention of the bem module, 1e-10).

use std::path::{Path, PathBuf};
use std::process::Command;

use strata_bem::read_heights_npy;

const N: usize = 64;

fn dir(name: &str) -> PathBuf {
    let d = crate::support::scratch().join(format!("maps-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small BEM scene: homogeneous half-space (E = 4 GPa, ν = 0.15), generated paper-like
/// surface on a 64² grid, three approaches.
fn scene(d: &Path, kind: &str, output: &str) -> PathBuf {
    let p = d.join("scene.toml");
    std::fs::write(
        &p,
        format!(
            r#"[stack]
[[stack.layer]]
thickness = 1e-3
young = 4e9
poisson = 0.15
[stack.base]
kind = "elastic"
young = 4e9
poisson = 0.15
[surface.generate]
size = 1e-3
grid = {N}
fractal_dimension = 2.4
k_min = 2
k_max = 10
rms = 3.4e-6
seed = 7
[model]
kind = "{kind}"
[load]
approach = {{ from = 1e-6, to = 5e-6, steps = 3 }}
{output}
"#
        ),
    )
    .unwrap();
    p
}

fn strata(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .output()
        .unwrap()
}

fn solve(scene: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "solve",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    strata(&args)
}

/// curve.csv rows as numbers (delta, gap, mean_pressure, pressure_ratio, area_fraction,
/// contacts, stiffness).
fn curve(out: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(out.join("curve.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

/// PNG signature and the IHDR width and height.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(
        &b[..8],
        b"\x89PNG\r\n\x1a\n",
        "{}: not a PNG",
        path.display()
    );
    assert_eq!(&b[12..16], b"IHDR");
    let be = |o: usize| u32::from_be_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
    (be(16), be(20))
}

#[test]
fn bem_maps_match_the_curve() {
    let d = dir("all");
    let sc = scene(&d, "bem", "[output]\nmaps = \"all\"");
    let out = d.join("out");
    let o = solve(&sc, &out, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = curve(&out);
    assert_eq!(rows.len(), 3);
    let index = std::fs::read_to_string(out.join("maps/maps.csv")).unwrap();
    let index: Vec<Vec<String>> = index
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    assert_eq!(index.len(), 3);
    for (k, r) in rows.iter().enumerate() {
        let p = read_heights_npy(&out.join(format!("maps/pressure_step_{k:02}.npy"))).unwrap();
        let g = read_heights_npy(&out.join(format!("maps/gap_step_{k:02}.npy"))).unwrap();
        assert_eq!(p.dim(), (N, N));
        assert_eq!(g.dim(), (N, N));
        let nn = (N * N) as f64;
        let mean_p = p.iter().sum::<f64>() / nn;
        let rel_p = (mean_p / r[2] - 1.0).abs();
        assert!(
            rel_p <= 1e-12,
            "step {k}: mean of map {mean_p:e} vs {:e}",
            r[2]
        );
        let in_contact = p.iter().filter(|&&x| x > 0.0).count() as f64 / nn;
        assert_eq!(in_contact, r[4], "step {k}: contact fraction of the map");
        // The error as the bem module defines it (tolerance 1e-10, σ_z the RMS height):
        // p ≥ 0, max over p > 0 of |g|/σ_z and max over p = 0 of −g/σ_z ≤ 1e-10.
        let sigma = 3.4e-6;
        assert!(p.iter().all(|&x| x >= 0.0));
        let comp = p
            .iter()
            .zip(g.iter())
            .filter(|(a, _)| **a > 0.0)
            .map(|(_, b)| b.abs() / sigma)
            .fold(0.0_f64, f64::max);
        let pen = p
            .iter()
            .zip(g.iter())
            .filter(|(a, _)| **a == 0.0)
            .map(|(_, b)| -b / sigma)
            .fold(0.0_f64, f64::max);
        assert!(comp <= 1e-10 && pen <= 1e-10, "step {k}: {comp:e}, {pen:e}");
        let mean_g = g.iter().sum::<f64>() / nn;
        assert!(
            (mean_g / r[1] - 1.0).abs() <= 1e-10,
            "step {k}: mean gap {mean_g:e} vs g_n {:e}",
            r[1]
        );
        // maps.csv: the same step, patches = curve.csv contacts.
        assert_eq!(index[k][0], k.to_string());
        assert_eq!(index[k][5].parse::<f64>().unwrap(), r[5]);
        assert!(r[5] >= 1.0, "step {k}: no contact patch");
        for pic in ["pressure", "gap"] {
            let size = png_size(&out.join(format!("maps/{pic}_step_{k:02}.png")));
            // 64² magnified ×8 to 512 px, + title band, axes, colour bar and labels.
            assert_eq!(size, strata::plot::heatmap_size(64, 64));
            assert_eq!(strata::plot::heatmap_map_size(64, 64), (512, 512));
        }
    }
}

#[test]
fn last_only_and_no_pictures() {
    let d = dir("last");
    let sc = scene(&d, "bem", "[output]\nmaps = \"last\"");
    let out = d.join("out");
    let o = solve(&sc, &out, &["--no-plots"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut names: Vec<String> = std::fs::read_dir(out.join("maps"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["gap_step_02.npy", "maps.csv", "pressure_step_02.npy"]
    );
}

#[test]
fn no_maps_by_default_and_refused_for_asperity_models() {
    let d = dir("none");
    let out = d.join("out");
    let o = solve(&scene(&d, "bem", ""), &out, &["--no-plots"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.join("maps").exists());
    for kind in ["independent", "interacting"] {
        let d = dir(kind);
        let o = solve(
            &scene(&d, kind, "[output]\nmaps = \"all\""),
            &d.join("out"),
            &[],
        );
        assert!(!o.status.success());
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains("output.maps") && e.contains("bem"), "{e}");
        assert!(!e.contains("panicked"), "{e}");
    }
    let d = dir("bad");
    let o = solve(
        &scene(&d, "bem", "[output]\nmaps = \"some\""),
        &d.join("out"),
        &[],
    );
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("output.maps"));
}

/// A global attribute of a NetCDF file as f64 (double or int).
fn nc_attr_f64(set: &netcdf3::DataSet, name: &str) -> f64 {
    let a = set
        .get_global_attr(name)
        .unwrap_or_else(|| panic!("no attribute {name}"));
    a.get_f64()
        .map(|v| v[0])
        .or_else(|| a.get_i32().map(|v| f64::from(v[0])))
        .unwrap_or_else(|| panic!("attribute {name}: not a number"))
}

/// A text attribute (global when `var` is None).
fn nc_text(set: &netcdf3::DataSet, var: Option<&str>, name: &str) -> String {
    let a = match var {
        None => set.get_global_attr(name),
        Some(v) => set.get_var_attr(v, name),
    }
    .unwrap_or_else(|| panic!("no attribute {var:?}.{name}"));
    a.get_as_string()
        .unwrap_or_else(|| panic!("{var:?}.{name}: not text"))
}

#[test]
fn netcdf_maps_are_the_npy_maps_in_contact_engineering_layout() {
    let d = dir("netcdf");
    let sc = scene(
        &d,
        "bem",
        "[output]\nmaps = \"all\"\nformat = [\"npy\", \"netcdf\"]",
    );
    let out = d.join("out");
    let o = solve(&sc, &out, &["--no-plots"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = curve(&out);
    let index = std::fs::read_to_string(out.join("maps/maps.csv")).unwrap();
    assert!(
        index
            .lines()
            .next()
            .unwrap()
            .ends_with(",gap_file,netcdf_file"),
        "{index}"
    );
    for (k, r) in rows.iter().enumerate() {
        let name = format!("results_step_{k:02}.nc");
        assert!(index.lines().nth(k + 1).unwrap().ends_with(&name));
        let p = read_heights_npy(&out.join(format!("maps/pressure_step_{k:02}.npy"))).unwrap();
        let g = read_heights_npy(&out.join(format!("maps/gap_step_{k:02}.npy"))).unwrap();
        let path = out.join(format!("maps/{name}"));
        let mut f = netcdf3::FileReader::open(&path).unwrap();
        let vars = f.read_all_vars().unwrap();
        let (set, version) = f.close();
        // contact.engineering writes NETCDF3_64BIT (CDF-2).
        assert_eq!(version, netcdf3::Version::Offset64Bit);
        assert_eq!(set.dim_names(), ["x", "y"]);
        assert_eq!(set.dim_size("x"), Some(N));
        assert_eq!(set.dim_size("y"), Some(N));
        for v in ["pressure", "contacting_points", "gap", "displacement"] {
            let dims: Vec<String> = set.get_var(v).unwrap().dim_names();
            assert_eq!(dims, ["x", "y"], "{v}");
        }
        for (v, unit) in [
            ("pressure", "Pa"),
            ("gap", "m"),
            ("displacement", "m"),
            ("contacting_points", "1"),
            ("x", "m"),
            ("y", "m"),
        ] {
            assert_eq!(nc_text(&set, Some(v), "units"), unit, "{v}");
        }
        assert_eq!(nc_text(&set, Some("contacting_points"), "dtype"), "bool");
        // (x, y) with x the input's first axis: element [i, j] is the .npy map's row i,
        // column j — bit for bit.
        let field = |v: &str| vars[v].get_f64().unwrap().to_vec();
        let same =
            |m: &ndarray::Array2<f64>| -> Vec<u64> { m.iter().map(|v| v.to_bits()).collect() };
        let bits = |v: Vec<f64>| -> Vec<u64> { v.iter().map(|v| v.to_bits()).collect() };
        assert_eq!(bits(field("pressure")), same(&p), "step {k}: pressure");
        assert_eq!(bits(field("gap")), same(&g), "step {k}: gap");
        let mask: Vec<i8> = p.iter().map(|&v| i8::from(v > 0.0)).collect();
        assert_eq!(vars["contacting_points"].get_i8().unwrap(), &mask[..]);
        // The summary: contact.engineering's attributes are curve.csv's step.
        let nn = (N * N) as f64;
        assert!((nc_attr_f64(&set, "mean_pressure") / r[2] - 1.0).abs() <= 1e-15);
        assert_eq!(nc_attr_f64(&set, "total_contact_area"), r[4]);
        assert!((nc_attr_f64(&set, "approach") / r[0] - 1.0).abs() <= 1e-15);
        assert!((nc_attr_f64(&set, "separation") / r[1] - 1.0).abs() <= 1e-15);
        assert_eq!(nc_attr_f64(&set, "contact_patches"), r[5]);
        assert_eq!(nc_attr_f64(&set, "step"), k as f64);
        assert_eq!(nc_text(&set, None, "type"), "periodic");
        assert_eq!(nc_text(&set, None, "mean_pressure_units"), "Pa");
        // The deflection on an elastic base: zero mean (the bem module's convention).
        let w = field("displacement");
        let w_mean = w.iter().sum::<f64>() / nn;
        assert!(
            w_mean.abs() <= 1e-12 * 3.4e-6,
            "step {k}: mean w {w_mean:e}"
        );
        assert_eq!(nc_attr_f64(&set, "mean_deflection"), 0.0);
        let x = field("x");
        assert_eq!(x.len(), N);
        assert_eq!(x[1], 1e-3 / N as f64);
    }
    // The default files are untouched by the NetCDF ones: the same bytes as without.
    let plain = d.join("plain");
    let o = solve(
        &scene(&d, "bem", "[output]\nmaps = \"all\""),
        &plain,
        &["--no-plots"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "curve.csv",
        "maps/pressure_step_01.npy",
        "maps/gap_step_02.npy",
    ] {
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(plain.join(f)).unwrap(),
            "{f}"
        );
    }
    // NetCDF alone: no .npy maps.
    let only = d.join("only");
    let o = solve(
        &scene(&d, "bem", "[output]\nmaps = \"last\"\nformat = \"netcdf\""),
        &only,
        &["--no-plots"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut names: Vec<String> = std::fs::read_dir(only.join("maps"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["maps.csv", "results_step_02.nc"]);
}

/// A rectangular 64 × 128 input (x the first axis, Lx = 1 mm, Ly = 2 mm, as `surface
/// info` says) is written with `x` of 64 points spanning Lx and `y` of 128 spanning Ly,
/// the fields in the input's orientation (contact.engineering's and SurfaceTopography's
/// convention): read back with the netcdf3 crate. The file used to swap them (x of 128
/// points spanning 2 mm).
#[test]
fn netcdf_maps_keep_the_input_axes_on_a_rectangular_grid() {
    let d = dir("netcdf-rect");
    let (n0, n1, lx, ly) = (64usize, 128usize, 1e-3, 2e-3);
    // A smooth non-periodic bump, higher along x than along y, so a swap shows.
    let z: Vec<f64> = (0..n0 * n1)
        .map(|k| {
            let (i, j) = (k / n1, k % n1);
            let (x, y) = (i as f64 / n0 as f64 - 0.4, j as f64 / n1 as f64 - 0.5);
            -1e-6 * (20.0 * x * x + 4.0 * y * y)
        })
        .collect();
    strata_runtime::surface::Surface::with_spacing(
        z,
        n0,
        n1,
        strata_runtime::surface::Spacing::Pixel(lx / n0 as f64, ly / n1 as f64),
        false,
    )
    .unwrap()
    .write_npy(&d.join("z.npy"))
    .unwrap();
    let sc = d.join("scene.toml");
    std::fs::write(
        &sc,
        format!(
            r#"[stack]
[[stack.layer]]
thickness = 1e-3
young = 4e9
poisson = 0.15
[stack.base]
kind = "elastic"
young = 4e9
poisson = 0.15
[surface]
file = "z.npy"
size = [{lx:e}, {ly:e}]
periodic = false
detrend = "none"
[model]
kind = "bem"
[load]
approach = {{ from = 2e-7, to = 4e-7, steps = 2 }}
[output]
maps = "last"
format = ["npy", "netcdf"]
"#
        ),
    )
    .unwrap();
    let info = strata(&["surface", "info", sc.to_str().unwrap()]);
    assert!(
        info.status.success(),
        "{}",
        String::from_utf8_lossy(&info.stderr)
    );
    let out = d.join("out");
    let o = solve(&sc, &out, &["--no-plots"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let p = read_heights_npy(&out.join("maps/pressure_step_01.npy")).unwrap();
    assert_eq!(p.dim(), (n0, n1));
    let mut f = netcdf3::FileReader::open(out.join("maps/results_step_01.nc")).unwrap();
    let vars = f.read_all_vars().unwrap();
    let (set, _) = f.close();
    assert_eq!(set.dim_names(), ["x", "y"]);
    assert_eq!(set.dim_size("x"), Some(n0));
    assert_eq!(set.dim_size("y"), Some(n1));
    let x = vars["x"].get_f64().unwrap();
    let y = vars["y"].get_f64().unwrap();
    assert_eq!((x.len(), y.len()), (n0, n1));
    // Pixel positions i·L/n: the last one is L(n−1)/n, the step L/n.
    assert!((x[1] / (lx / n0 as f64) - 1.0).abs() < 1e-15, "{}", x[1]);
    assert!((x[n0 - 1] / (lx * (n0 - 1) as f64 / n0 as f64) - 1.0).abs() < 1e-15);
    assert!((y[1] / (ly / n1 as f64) - 1.0).abs() < 1e-15, "{}", y[1]);
    assert!((y[n1 - 1] / (ly * (n1 - 1) as f64 / n1 as f64) - 1.0).abs() < 1e-15);
    let sizes = set
        .get_global_attr("physical_sizes")
        .unwrap()
        .get_f64()
        .unwrap()
        .to_vec();
    assert_eq!(sizes, [lx, ly]);
    let field = vars["pressure"].get_f64().unwrap();
    assert_eq!(field.len(), n0 * n1);
    let bits: Vec<u64> = field.iter().map(|v| v.to_bits()).collect();
    let npy: Vec<u64> = p.iter().map(|v| v.to_bits()).collect();
    assert_eq!(bits, npy, "pressure[i, j] is the .npy map's [i, j]");
    // The contact sits at the bump's top (x = 0.4 Lx, y = 0.5 Ly): element [i, j] with
    // i along x.
    let (imax, _) =
        field.iter().enumerate().fold(
            (0, f64::MIN),
            |(k, m), (i, &v)| if v > m { (i, v) } else { (k, m) },
        );
    let (i, j) = (imax / n1, imax % n1);
    assert!(
        (x[i] / lx - 0.4).abs() < 0.05 && (y[j] / ly - 0.5).abs() < 0.05,
        "{i} {j}"
    );
}
