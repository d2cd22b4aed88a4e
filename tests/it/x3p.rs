//! `.x3p` (ISO 25178-72 / ISO 5436-2) files: hand-made containers written here byte by
//! byte from the standard's layout (a stored zip written by this file, main.xml text,
//! little-endian point data with x fastest, a validity bit map least significant bit
//! first), independent of strata's writer; strata's own round trip; scenes and the CLI.

use std::path::{Path, PathBuf};

use crate::support::{homogeneous_scene, run_strata, solve_no_plots, temp_dir};
use strata_runtime::surface::{ReadOptions, Repair, Surface, SurfaceError};

fn tmp(name: &str) -> PathBuf {
    temp_dir(&format!("x3p-{name}"))
}

/// CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320), bit by bit.
fn crc32(data: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                (c >> 1) ^ 0xEDB8_8320
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// A zip archive of `entries`, all stored (method 0), written from the PKWARE APPNOTE
/// layout: local headers and data, the central directory, the end record.
fn stored_zip(entries: &[(&str, &[u8])]) -> Vec<u8> {
    let (mut out, mut central) = (Vec::new(), Vec::new());
    let u16le = |v: &mut Vec<u8>, x: u16| v.extend_from_slice(&x.to_le_bytes());
    let u32le = |v: &mut Vec<u8>, x: u32| v.extend_from_slice(&x.to_le_bytes());
    for (name, data) in entries {
        let offset = out.len() as u32;
        let crc = crc32(data);
        u32le(&mut out, 0x0403_4b50);
        for x in [20u16, 0, 0, 0, 0x21] {
            u16le(&mut out, x); // version, flags, method, time, date (1980-01-01)
        }
        u32le(&mut out, crc);
        u32le(&mut out, data.len() as u32);
        u32le(&mut out, data.len() as u32);
        u16le(&mut out, name.len() as u16);
        u16le(&mut out, 0);
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(data);
        u32le(&mut central, 0x0201_4b50);
        for x in [20u16, 20, 0, 0, 0, 0x21] {
            u16le(&mut central, x);
        }
        u32le(&mut central, crc);
        u32le(&mut central, data.len() as u32);
        u32le(&mut central, data.len() as u32);
        u16le(&mut central, name.len() as u16);
        for x in [0u16, 0, 0, 0] {
            u16le(&mut central, x); // extra, comment, disk, internal attributes
        }
        u32le(&mut central, 0);
        u32le(&mut central, offset);
        central.extend_from_slice(name.as_bytes());
    }
    let cd_offset = out.len() as u32;
    out.extend_from_slice(&central);
    u32le(&mut out, 0x0605_4b50);
    for x in [0u16, 0, entries.len() as u16, entries.len() as u16] {
        u16le(&mut out, x);
    }
    u32le(&mut out, central.len() as u32);
    u32le(&mut out, cd_offset);
    u16le(&mut out, 0);
    out
}

fn md5hex(b: &[u8]) -> String {
    format!("{:x}", md5::compute(b))
}

/// main.xml of a SUR matrix `nx × ny` with incremental CX/CY (`dx`, `dy`, offsets) and
/// an absolute CZ of `dtype` with optional `Increment`/`Offset`; `data_link` is the
/// inner XML of Record3 after MatrixDimension.
#[allow(clippy::too_many_arguments)]
fn main_xml(
    nx: usize,
    ny: usize,
    dx: &str,
    dy: &str,
    dtype: &str,
    z_inc: Option<&str>,
    z_off: Option<&str>,
    data_link: &str,
) -> String {
    let inc = z_inc.map_or(String::new(), |v| format!("<Increment>{v}</Increment>"));
    let off = z_off.map_or(String::new(), |v| format!("<Offset>{v}</Offset>"));
    format!(
        "\u{feff}<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
<!-- hand-made from the ISO 5436-2 XML schema -->\n\
<p:ISO5436_2 xmlns:p=\"http://www.opengps.eu/2008/ISO5436_2\" xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\">\n\
  <Record1>\n    <Revision>ISO5436 - 2000</Revision>\n    <FeatureType>SUR</FeatureType>\n    <Axes>\n\
      <CX><AxisType>I</AxisType><DataType>D</DataType><Increment>{dx}</Increment><Offset>1.0E-0003</Offset></CX>\n\
      <CY><AxisType>I</AxisType><DataType>D</DataType><Increment>{dy}</Increment><Offset>-2e-3</Offset></CY>\n\
      <CZ><AxisType>A</AxisType><DataType>{dtype}</DataType>{inc}{off}</CZ>\n\
    </Axes>\n  </Record1>\n\
  <Record3>\n    <MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ></MatrixDimension>\n\
    {data_link}\n  </Record3>\n\
  <Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4>\n\
</p:ISO5436_2>\n"
    )
}

/// The archive: main.xml, its checksum file, and the binary entries.
fn container(main: &str, bins: &[(&str, &[u8])]) -> Vec<u8> {
    let sum = format!("{} *main.xml\n", md5hex(main.as_bytes()).to_uppercase());
    let mut entries: Vec<(&str, &[u8])> = vec![("main.xml", main.as_bytes())];
    entries.extend_from_slice(bins);
    entries.push(("md5checksum.hex", sum.as_bytes()));
    stored_zip(&entries)
}

fn read(path: &Path, repair: Repair) -> Result<Surface, SurfaceError> {
    Surface::read(
        path,
        &ReadOptions {
            repair,
            ..Default::default()
        },
    )
}

/// Integer data I (int16) with CZ Increment 1 nm and Offset 5 µm, non-unit and
/// unequal pixel sizes, and two points marked invalid in bindata/valid.bin: the
/// heights are Offset + Increment × value at the right (x, y), the invalid points
/// are refused (naming row = x index and column = y index) or repaired.
#[test]
fn handmade_int16_with_invalid_points() {
    let dir = tmp("i16");
    let (nx, ny) = (6usize, 5usize);
    let v = |i: usize, j: usize| (100 * i as i32 - 37 * j as i32 + 3 * (i * j) as i32 - 300) as i16;
    let invalid = [(2usize, 1usize), (4, 3)];
    let mut data = Vec::new();
    let mut valid = vec![0xFFu8; (nx * ny).div_ceil(8)];
    for j in 0..ny {
        for i in 0..nx {
            let k = j * nx + i; // x fastest
            let raw = if invalid.contains(&(i, j)) {
                valid[k / 8] &= !(1u8 << (k % 8));
                0
            } else {
                v(i, j)
            };
            data.extend_from_slice(&raw.to_le_bytes());
        }
    }
    let link = format!(
        "<DataLink><PointDataLink>bindata/data.bin</PointDataLink>\
         <MD5ChecksumPointData>{}</MD5ChecksumPointData>\
         <ValidPointsLink>bindata/valid.bin</ValidPointsLink>\
         <MD5ChecksumValidPoints>{}</MD5ChecksumValidPoints></DataLink>",
        md5hex(&data),
        md5hex(&valid).to_uppercase()
    );
    let main = main_xml(
        nx,
        ny,
        "2.5e-6",
        "4.0E-0006",
        "I",
        Some("1e-9"),
        Some("5e-6"),
        &link,
    );
    let f = dir.join("scan.x3p");
    // the container with main.xml `main` and point data `bin` (valid.bin as above)
    let write = |main: &str, bin: &[u8]| {
        std::fs::write(
            &f,
            container(
                main,
                &[("bindata/data.bin", bin), ("bindata/valid.bin", &valid)],
            ),
        )
        .expect("write")
    };
    write(&main, &data);
    let e = read(&f, Repair::Refuse).unwrap_err().to_string();
    assert!(
        e.contains("scan.x3p") && e.contains("row 2, column 1"),
        "{e}"
    );
    let s = read(&f, Repair::Median).expect("repaired");
    assert_eq!(s.shape(), (nx, ny));
    assert_eq!(s.pixel_size(), (2.5e-6, 4e-6));
    assert_eq!(s.repaired(), 2);
    // (no checksum warning; these small ramps are mostly tilt, kept with detrend "none")
    assert!(
        s.warnings().iter().all(|w| w.contains("keeps a tilt")),
        "{:?}",
        s.warnings()
    );
    for i in 0..nx {
        for j in 0..ny {
            if !invalid.contains(&(i, j)) {
                assert_eq!(s.z(i, j), 5e-6 + 1e-9 * v(i, j) as f64, "({i}, {j})");
            }
        }
    }
    let log = s.log().join("\n");
    assert!(
        log.contains("I (int16)") && log.contains("2 invalid point(s)"),
        "{log}"
    );
    // A flipped bit in data.bin: the checksum refuses it.
    let mut bad = data.clone();
    bad[3] ^= 1;
    write(&main, &bad);
    let e = read(&f, Repair::Median).unwrap_err().to_string();
    assert!(
        e.contains("corrupt") && e.contains("bindata/data.bin"),
        "{e}"
    );
    // Surplus data (once read with a warning and solved, RMS 1.2e9 m): refused,
    // checksum valid or not.
    let mut long = data.clone();
    long.extend_from_slice(&[7, 0, 9, 0]);
    let long_link = link.replace(&md5hex(&data), &md5hex(&long));
    let long_main = main_xml(
        nx,
        ny,
        "2.5e-6",
        "4.0E-0006",
        "I",
        Some("1e-9"),
        Some("5e-6"),
        &long_link,
    );
    write(&long_main, &long);
    let e = read(&f, Repair::Median).unwrap_err().to_string();
    assert!(
        e.contains("more than the 6×5 values") && e.contains("bindata/data.bin"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Integer data L (int32) without Offset; float data D with NaN as the invalid marker;
/// the points as an XML DataList (an empty Datum = invalid): all read at the right
/// (x, y). An edited main.xml (checksum file no longer matching) is a warning.
#[test]
fn handmade_int32_float64_and_datalist() {
    let dir = tmp("l-d-list");
    let (nx, ny) = (4usize, 7usize);
    let v = |i: usize, j: usize| 1_000_000 * i as i32 - 250_000 * j as i32 + 7 * (i + j) as i32;
    let mut data = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            data.extend_from_slice(&v(i, j).to_le_bytes());
        }
    }
    let link = format!(
        "<DataLink><PointDataLink>bindata/data.bin</PointDataLink>\
         <MD5ChecksumPointData>{}</MD5ChecksumPointData></DataLink>",
        md5hex(&data)
    );
    let main = main_xml(nx, ny, "1.25e-6", "3e-6", "L", Some("1e-12"), None, &link);
    let f = dir.join("l.x3p");
    std::fs::write(&f, container(&main, &[("bindata/data.bin", &data)])).expect("write");
    let s = read(&f, Repair::Refuse).expect("int32");
    assert_eq!((s.shape(), s.pixel_size()), ((nx, ny), (1.25e-6, 3e-6)));
    for i in 0..nx {
        for j in 0..ny {
            assert_eq!(s.z(i, j), 1e-12 * v(i, j) as f64);
        }
    }
    // (no checksum warning; these small ramps are mostly tilt, kept with detrend "none")
    assert!(
        s.warnings().iter().all(|w| w.contains("keeps a tilt")),
        "{:?}",
        s.warnings()
    );
    // D with one NaN (smooth data: no spike), read as an invalid point.
    let w = |i: usize, j: usize| 1e-6 * (0.3 * i as f64).sin() + 2e-7 * j as f64;
    let mut data = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let z = if (i, j) == (1, 5) { f64::NAN } else { w(i, j) };
            data.extend_from_slice(&z.to_le_bytes());
        }
    }
    let link = format!(
        "<DataLink><PointDataLink>bindata/data.bin</PointDataLink>\
         <MD5ChecksumPointData>{}</MD5ChecksumPointData></DataLink>",
        md5hex(&data)
    );
    let main = main_xml(nx, ny, "1e-6", "1e-6", "D", None, None, &link);
    let f = dir.join("d.x3p");
    std::fs::write(&f, container(&main, &[("bindata/data.bin", &data)])).expect("write");
    let e = read(&f, Repair::Refuse).unwrap_err().to_string();
    assert!(e.contains("row 1, column 5"), "{e}");
    let s = read(&f, Repair::Median).expect("repaired");
    assert_eq!(s.z(3, 6), w(3, 6));
    assert_eq!(s.repaired(), 1);
    // DataList, F values in XML text, one empty Datum.
    let mut list = String::from("<DataList>");
    for j in 0..ny {
        for i in 0..nx {
            if (i, j) == (2, 2) {
                list.push_str("<Datum></Datum>");
            } else {
                list.push_str(&format!("<Datum>{:e}</Datum>", w(i, j)));
            }
        }
    }
    list.push_str("</DataList>");
    let main = main_xml(nx, ny, "1e-6", "2e-6", "F", Some("1"), Some("0"), &list);
    let f = dir.join("list.x3p");
    // The checksum file is that of another main.xml: a warning, not an error.
    let edited = main.replace("hand-made", "edited");
    let sum = format!("{} *main.xml\n", md5hex(main.as_bytes()));
    std::fs::write(
        &f,
        stored_zip(&[
            ("main.xml", edited.as_bytes()),
            ("md5checksum.hex", sum.as_bytes()),
        ]),
    )
    .expect("write");
    let s = read(&f, Repair::Median).expect("data list");
    assert_eq!(s.z(3, 4), w(3, 4));
    assert_eq!(s.repaired(), 1);
    // (and the kept tilt of the small ramp, detrend "none")
    assert!(
        s.warnings()[0].contains("main.xml MD5")
            && s.warnings()[1..].iter().all(|w| w.contains("keeps a tilt")),
        "{:?}",
        s.warnings()
    );
    // What is not an areal grid is refused by name.
    for (edit, needle) in [
        ("<FeatureType>SUR", "<FeatureType>PRF"),
        ("<SizeZ>1<", "<SizeZ>2<"),
        ("<DataType>F<", "<DataType>Q<"),
    ] {
        let bad = main.replace(edit, needle);
        std::fs::write(&f, stored_zip(&[("main.xml", bad.as_bytes())])).expect("write");
        let e = read(&f, Repair::Median).unwrap_err().to_string();
        assert!(e.contains("list.x3p"), "{e}");
        let key = ["FeatureType", "SizeZ", "DataType"]
            .into_iter()
            .find(|k| needle.contains(k))
            .unwrap_or_default();
        assert!(e.contains(key), "{needle}: {e}");
    }
    std::fs::write(&f, b"not a zip").expect("write");
    let e = read(&f, Repair::Median).unwrap_err().to_string();
    assert!(e.contains("zip"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

fn strata(args: &[&str]) -> std::process::Output {
    run_strata(args)
}

fn scene_with(surface: &str) -> String {
    homogeneous_scene(
        surface,
        "\"independent\"",
        "approach = { from = 1e-6, to = 6e-6, steps = 4 }",
    )
}

/// `strata surface export` of a generated (periodic) surface to .x3p and .npy; a scene
/// reading the .x3p (sizes from the file) solves to exactly the generated scene's
/// curve; strata writes, strata reads: identical heights and pixel sizes; `surface
/// info` reports the sizes.
#[test]
fn export_round_trip_and_scene() {
    let dir = tmp("export");
    let generated = scene_with(
        "size = 1e-3\n[surface.generate]\ngrid = 64\nfractal_dimension = 2.4\nk_min = 2\nk_max = 10\nrms = 3.4e-6\nseed = 3",
    );
    let sg = dir.join("gen.toml");
    std::fs::write(&sg, &generated).expect("scene");
    let x3p = dir.join("gen.x3p");
    let npy = dir.join("gen.npy");
    for out in [&x3p, &npy] {
        let o = strata(&[
            "surface",
            "export",
            sg.to_str().unwrap_or_default(),
            "--out",
            out.to_str().unwrap_or_default(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let o = strata(&[
        "surface",
        "export",
        sg.to_str().unwrap_or_default(),
        "--out",
        x3p.to_str().unwrap_or_default(),
    ]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("--force"));
    let scene = strata::scene::Scene::from_file(&sg).expect("scene");
    let original = scene
        .load_surface(&strata_runtime::resources::MemoryLimit::default())
        .expect("generated");
    let back = read(&x3p, Repair::Refuse).expect("x3p");
    assert_eq!(back.heights(), original.heights());
    assert_eq!(back.shape(), original.shape());
    assert_eq!(back.pixel_size(), original.pixel_size());
    let back_npy = Surface::read_npy(&npy, 1e-3, true).expect("npy");
    assert_eq!(back_npy.heights(), original.heights());
    // The scene with file = gen.x3p (periodic as the generated one) solves identically.
    let sx = dir.join("x3p.toml");
    std::fs::write(&sx, scene_with("file = \"gen.x3p\"\nperiodic = true")).expect("scene");
    let mut curves = Vec::new();
    for (sc, name) in [(&sg, "a"), (&sx, "b")] {
        let out = dir.join(name);
        let o = solve_no_plots(sc, &out);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        curves.push(std::fs::read_to_string(out.join("curve.csv")).expect("csv"));
        if name == "b" {
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(
                err.contains("x3p: 64×64 grid") && err.contains("D (float64)"),
                "{err}"
            );
            let json: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(out.join("curve.json")).expect("json"),
            )
            .expect("json");
            assert_eq!(json["surface"]["pixel_size"][0], 1e-3 / 64.0);
            assert_eq!(json["surface"]["size"][1], 1e-3);
            assert_eq!(json["surface"]["periodic"], true);
        }
    }
    assert_eq!(curves[0], curves[1]);
    // An .x3p gives its own sizes: a size in the scene is refused by name.
    std::fs::write(&sx, scene_with("file = \"gen.x3p\"\nsize = 1e-3")).expect("scene");
    let o = strata(&[
        "solve",
        sx.to_str().unwrap_or_default(),
        "--out",
        dir.join("c").to_str().unwrap_or_default(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("surface.size") && err.contains(".x3p"),
        "{err}"
    );
    let o = strata(&[
        "surface",
        "info",
        x3p.to_str().unwrap_or_default(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).expect("info json");
    assert_eq!(info["shape"][0], 64);
    assert_eq!(info["size"][0], 1e-3);
    let rms = info["rms_height"].as_f64().unwrap_or_default();
    assert!((rms - 3.4e-6).abs() < 1e-12 * 3.4e-6, "{rms}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A BEM scene on an `.x3p` file (its sizes from the file, none in the scene) writes the
/// PNG pictures of its maps as a generated or `.npy` scene does: they were silently
/// missing (the pictures took the sample's size from the scene's keys alone).
#[test]
fn x3p_scenes_write_png_maps() {
    let dir = tmp("png-maps");
    let sg = dir.join("gen.toml");
    std::fs::write(
        &sg,
        scene_with(
            "size = 1e-3\n[surface.generate]\ngrid = 32\nfractal_dimension = 2.4\nk_min = 2\nk_max = 8\nrms = 3.4e-6\nseed = 3",
        ),
    )
    .expect("scene");
    let x3p = dir.join("gen.x3p");
    let o = strata(&[
        "surface",
        "export",
        sg.to_str().unwrap_or_default(),
        "--out",
        x3p.to_str().unwrap_or_default(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let sx = dir.join("x3p.toml");
    std::fs::write(
        &sx,
        homogeneous_scene(
            "file = \"gen.x3p\"\nperiodic = true",
            "\"bem\"",
            "approach = { from = 1e-6, to = 3e-6, steps = 2 }\n[output]\nmaps = \"all\"",
        ),
    )
    .expect("scene");
    let out = dir.join("out");
    let o = strata(&[
        "solve",
        sx.to_str().unwrap_or_default(),
        "--out",
        out.to_str().unwrap_or_default(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "pressure_step_00.png",
        "gap_step_00.png",
        "pressure_step_01.png",
        "gap_step_01.png",
    ] {
        let bytes = std::fs::read(out.join("maps").join(f)).unwrap_or_default();
        assert!(
            bytes.starts_with(b"\x89PNG"),
            "maps/{f} missing or not a PNG"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
