//! SurfaceTopography's NetCDF topographies: files written here with
//! the `netcdf3` crate in the layout SurfaceTopography's `to_netcdf` writes through
//! scipy (NetCDF-3 64-bit offset; heights(x, y); x(x) and y(y) with float32 `length`,
//! int `periodic`, char `unit`; int `_FillValue` on heights) and in the older layout
//! (`length_unit`); read by `Surface::read`, a scene and the CLI with their units,
//! physical sizes and periodic flags honoured, and bad files refused naming the cause.
//! (python/tests/test_topography.py reads files SurfaceTopography itself wrote.)

use std::path::{Path, PathBuf};

use crate::support::{homogeneous_scene, solve_no_plots, temp_dir};
use netcdf3::{DataSet, FileWriter, Version};
use strata_runtime::surface::{Detrend, HeightUnit, ReadOptions, Repair, Spacing, Surface};

fn tmp(name: &str) -> PathBuf {
    temp_dir(&format!("netcdf-{name}"))
}

/// What a test file holds.
struct Topo<'a> {
    heights: &'a [f64],
    nx: usize,
    ny: usize,
    /// (Lx, Ly) in `unit`, as float32 `length` attributes (as scipy writes 2.0).
    lengths: Option<(f32, f32)>,
    periodic: Option<i32>,
    unit: Option<&'a str>,
    /// The attribute naming the unit on x and y: "unit" (new) or "length_unit" (old).
    unit_key: &'a str,
    fill: Option<i32>,
}

fn write(path: &Path, t: &Topo) {
    let mut d = DataSet::new();
    d.add_fixed_dim("x", t.nx).unwrap();
    d.add_fixed_dim("y", t.ny).unwrap();
    d.add_var_f64("heights", &["x", "y"]).unwrap();
    for (v, n) in [("x", t.nx), ("y", t.ny)] {
        d.add_var_f64(v, &[v]).unwrap();
        if let Some((lx, ly)) = t.lengths {
            d.add_var_attr_f32(v, "length", vec![if v == "x" { lx } else { ly }])
                .unwrap();
        }
        if let Some(p) = t.periodic {
            d.add_var_attr_i32(v, "periodic", vec![p]).unwrap();
        }
        if let Some(u) = t.unit {
            d.add_var_attr_string(v, t.unit_key, u).unwrap();
        }
        let _ = n;
    }
    if let Some(u) = t.unit.filter(|_| t.unit_key == "unit") {
        d.add_var_attr_string("heights", "unit", u).unwrap();
    }
    if let Some(f) = t.fill {
        d.add_var_attr_i32("heights", "_FillValue", vec![f])
            .unwrap();
        d.add_var_attr_i32("heights", "missing_value", vec![f])
            .unwrap();
    }
    let mut w = FileWriter::open(path).unwrap();
    w.set_def(&d, Version::Offset64Bit, 0).unwrap();
    let (lx, ly) = t.lengths.unwrap_or((1.0, 1.0));
    let xs: Vec<f64> = (0..t.nx)
        .map(|i| (i as f64 + 0.5) * f64::from(lx) / t.nx as f64)
        .collect();
    let ys: Vec<f64> = (0..t.ny)
        .map(|i| (i as f64 + 0.5) * f64::from(ly) / t.ny as f64)
        .collect();
    w.write_var_f64("x", &xs).unwrap();
    w.write_var_f64("y", &ys).unwrap();
    w.write_var_f64("heights", t.heights).unwrap();
    w.close().unwrap();
}

/// A smooth, non-symmetric 16×12 height map (µm), x first.
fn heights_um() -> Vec<f64> {
    let (nx, ny) = (16, 12);
    (0..nx * ny)
        .map(|k| {
            let (i, j) = ((k / ny) as f64, (k % ny) as f64);
            (0.7 * i).sin() + 0.4 * (0.9 * j + 0.3).cos() + 0.05 * i
        })
        .collect()
}

fn topo(h: &[f64]) -> Topo<'_> {
    Topo {
        heights: h,
        nx: 16,
        ny: 12,
        lengths: Some((2.0, 1.5)),
        periodic: Some(1),
        unit: Some("um"),
        unit_key: "unit",
        fill: Some(999_999),
    }
}

#[test]
fn surface_topography_layout_is_read_with_units_sizes_and_periodicity() {
    let d = tmp("layout");
    let h = heights_um();
    let p = d.join("topo.nc");
    write(&p, &topo(&h));
    let s = Surface::read(&p, &ReadOptions::default()).unwrap();
    assert_eq!(s.shape(), (16, 12));
    assert!(s.is_periodic(), "the file's periodic flag");
    assert_eq!(s.extent(), (2.0 * 1e-6, 1.5 * 1e-6));
    let want: Vec<f64> = h.iter().map(|v| v * 1e-6).collect();
    assert_eq!(s.heights(), &want[..], "heights in µm → m, x first");
    assert!(s.log().iter().any(|l| l.contains("um")), "{:?}", s.log());

    // The older layout: `length_unit` on x and y only, no periodic flag (non-periodic).
    let old = Topo {
        unit_key: "length_unit",
        periodic: None,
        unit: Some("nm"),
        ..topo(&h)
    };
    let p2 = d.join("old.nc");
    write(&p2, &old);
    let s = Surface::read(&p2, &ReadOptions::default()).unwrap();
    assert!(!s.is_periodic());
    assert_eq!(s.extent(), (2.0 * 1e-9, 1.5 * 1e-9));
    assert_eq!(s.heights()[5], h[5] * 1e-9);

    // No unit and no sizes: the options give them, as for .npy.
    let bare = Topo {
        unit: None,
        lengths: None,
        periodic: Some(0),
        ..topo(&h)
    };
    let p3 = d.join("bare.nc");
    write(&p3, &bare);
    let s = Surface::read(
        &p3,
        &ReadOptions {
            spacing: Some(Spacing::Pixel(1e-7, 2e-7)),
            height_unit: Some(HeightUnit::Um),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(s.pixel_size(), (1e-7, 2e-7));
    assert_eq!(s.heights()[7], h[7] * 1e-6);

    // A periodic file is not detrended, even when a plane is asked (scenes' default for
    // non-periodic files): the log says so.
    let s = Surface::read(
        &p,
        &ReadOptions {
            detrend: Detrend::Plane,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(s.is_periodic());
    assert_eq!(s.heights(), &want[..]);
    assert!(
        s.log().iter().any(|l| l.contains("not detrended")),
        "{:?}",
        s.log()
    );
}

#[test]
fn bad_netcdf_files_are_refused_naming_the_cause() {
    let d = tmp("bad");
    let h = heights_um();
    let p = d.join("topo.nc");
    write(&p, &topo(&h));
    let err = |path: &Path, opts: ReadOptions| Surface::read(path, &opts).unwrap_err().to_string();
    let e = err(
        &p,
        ReadOptions {
            spacing: Some(Spacing::Size(1e-3)),
            ..Default::default()
        },
    );
    assert!(e.contains("physical sizes") && e.contains("topo.nc"), "{e}");
    let e = err(
        &p,
        ReadOptions {
            height_unit: Some(HeightUnit::Nm),
            ..Default::default()
        },
    );
    assert!(e.contains("height_unit") && e.contains("`um`"), "{e}");
    // No sizes in the file and none given.
    let p2 = d.join("nosize.nc");
    write(
        &p2,
        &Topo {
            lengths: None,
            ..topo(&h)
        },
    );
    assert!(err(&p2, ReadOptions::default()).contains("no physical sizes"));
    // A missing value (the fill value) is NaN: refused with its row and column, or repaired.
    let mut holed = h.clone();
    holed[12 + 5] = 999_999.0;
    let p3 = d.join("holed.nc");
    write(&p3, &topo(&holed));
    let e = err(&p3, ReadOptions::default());
    assert!(e.contains("row 1") && e.contains("column 5"), "{e}");
    let s = Surface::read(
        &p3,
        &ReadOptions {
            repair: Repair::Median,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(s.heights().iter().all(|v| v.is_finite()));
    // A unit strata does not know; NetCDF-4 (HDF5); not NetCDF; no `heights`.
    let p4 = d.join("furlong.nc");
    write(
        &p4,
        &Topo {
            unit: Some("furlong"),
            ..topo(&h)
        },
    );
    assert!(err(&p4, ReadOptions::default()).contains("`furlong`"));
    let p5 = d.join("hdf5.nc");
    std::fs::write(&p5, b"\x89HDF\r\n\x1a\n and more").unwrap();
    assert!(err(&p5, ReadOptions::default()).contains("NetCDF-4 (HDF5)"));
    let p6 = d.join("text.nc");
    std::fs::write(&p6, b"1 2 3\n4 5 6\n").unwrap();
    assert!(err(&p6, ReadOptions::default()).contains("not a NetCDF-3 file"));
    let p7 = d.join("noheights.nc");
    let mut ds = DataSet::new();
    ds.add_fixed_dim("x", 4).unwrap();
    ds.add_var_f64("z", &["x"]).unwrap();
    let mut w = FileWriter::open(&p7).unwrap();
    w.set_def(&ds, Version::Classic, 0).unwrap();
    w.write_var_f64("z", &[0.0; 4]).unwrap();
    w.close().unwrap();
    assert!(err(&p7, ReadOptions::default()).contains("no variable `heights`"));
}

/// A scene takes a NetCDF topography without size or periodic keys (the file's), and
/// solves it as the same heights from .npy with the sizes and periodicity in the scene
/// (the BEM, bit for bit: the same heights and sides reach the solver).
#[test]
fn a_scene_solves_the_netcdf_file_as_the_same_npy() {
    let d = tmp("scene");
    let (nx, ny) = (32, 32);
    let h: Vec<f64> = (0..nx * ny)
        .map(|k| {
            let (i, j) = ((k / ny) as f64, (k % ny) as f64);
            let t = std::f64::consts::TAU / 32.0;
            (t * i).cos() + 0.5 * (2.0 * t * j).sin() + 0.3 * (3.0 * t * (i + j)).cos()
        })
        .collect();
    write(
        &d.join("topo.nc"),
        &Topo {
            heights: &h,
            nx,
            ny,
            lengths: Some((1000.0, 1000.0)),
            periodic: Some(1),
            unit: Some("um"),
            unit_key: "unit",
            fill: None,
        },
    );
    let metres: Vec<f64> = h.iter().map(|v| v * 1e-6).collect();
    Surface::new(metres, nx, ny, 1000.0 * 1e-6, true)
        .unwrap()
        .write_npy(&d.join("heights.npy"))
        .unwrap();
    let load = "approach = { from = 2e-7, to = 1.2e-6, steps = 3 }";
    let mut curves = Vec::new();
    for (name, surface) in [
        ("nc", "file = \"topo.nc\"".to_string()),
        (
            "npy",
            format!(
                "file = \"heights.npy\"\nsize = {:?}\nperiodic = true",
                1000.0 * 1e-6
            ),
        ),
    ] {
        let sc = d.join(format!("{name}.toml"));
        std::fs::write(&sc, homogeneous_scene(&surface, "\"bem\"", load)).unwrap();
        let out = d.join(format!("out-{name}"));
        let o = solve_no_plots(&sc, &out);
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        curves.push(std::fs::read_to_string(out.join("curve.csv")).unwrap());
    }
    assert_eq!(curves[0], curves[1]);
    assert!(curves[0].lines().count() == 4, "{}", curves[0]);
}

/// Writes `topo` with its unit attributes replaced by `set` (on `heights` and `x`).
fn write_with_unit(path: &Path, h: &[f64], set: impl Fn(&mut DataSet, &str)) {
    write(
        path,
        &Topo {
            unit: None,
            ..topo(h)
        },
    );
    let mut f = netcdf3::FileReader::open(path).unwrap();
    let vars = f.read_all_vars().unwrap();
    let (mut d, _) = f.close();
    set(&mut d, "heights");
    set(&mut d, "x");
    let mut w = FileWriter::open(path).unwrap();
    w.set_def(&d, Version::Offset64Bit, 0).unwrap();
    for v in ["x", "y", "heights"] {
        w.write_var_f64(v, vars[v].get_f64().unwrap()).unwrap();
    }
    w.close().unwrap();
}

/// Older writers store "µm" in Latin-1 (one byte 0xB5, not UTF-8's 0xC2 0xB5): it reads as
/// micrometres, not as "no unit" (metres, a silent ×1e6). A unit that is a number, or
/// bytes that are neither UTF-8 nor Latin-1 text, is refused naming the file, the variable
/// and the attribute (it too used to read as metres).
#[test]
fn latin1_micrometre_unit_is_read_and_a_numeric_unit_refused() {
    let d = tmp("latin1");
    let h = heights_um();
    let p = d.join("latin1.nc");
    write_with_unit(&p, &h, |d, v| {
        d.add_var_attr_u8(v, "unit", vec![0xb5, b'm']).unwrap()
    });
    let s = Surface::read(&p, &ReadOptions::default()).unwrap();
    assert_eq!(s.extent(), (2.0 * 1e-6, 1.5 * 1e-6));
    let want: Vec<f64> = h.iter().map(|v| v * 1e-6).collect();
    assert_eq!(s.heights(), &want[..], "Latin-1 µm: heights in µm → m");
    assert!(s.log().iter().any(|l| l.contains("µm")), "{:?}", s.log());
    // UTF-8 "µm" (0xC2 0xB5) too.
    let p = d.join("utf8.nc");
    write_with_unit(&p, &h, |d, v| {
        d.add_var_attr_string(v, "unit", "µm").unwrap()
    });
    assert_eq!(
        Surface::read(&p, &ReadOptions::default())
            .unwrap()
            .heights(),
        &want[..]
    );
    // A number where the unit should be.
    let p = d.join("numeric.nc");
    write_with_unit(&p, &h, |d, v| {
        d.add_var_attr_f64(v, "unit", vec![1e-6]).unwrap()
    });
    let e = Surface::read(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("numeric.nc")
            && e.contains("`unit`")
            && e.contains("`heights`")
            && e.contains("not text"),
        "{e}"
    );
    // Control bytes: neither UTF-8 nor Latin-1 text.
    let p = d.join("garbled.nc");
    write_with_unit(&p, &h, |d, v| {
        d.add_var_attr_u8(v, "unit", vec![0x85, 0x01, b'm'])
            .unwrap()
    });
    let e = Surface::read(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("garbled.nc") && e.contains("`unit`") && e.contains("not readable text"),
        "{e}"
    );
}
