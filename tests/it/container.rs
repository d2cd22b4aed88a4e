//! contact.engineering's published containers: the fixture
//! `tests/data/container/container.zip` was written by SurfaceTopography's
//! `SurfaceContainer.to_zip` (`make.py` beside it: a periodic 32×32 topography in µm and a
//! non-periodic 48×32 one in nm, with the same heights as `.npy`); an older-layout container
//! (meta.yml only, an `original` .npy data file, sizes and unit in the metadata) is written
//! here. Read with their units, physical sizes and periodic flags; a scene on a container's
//! topography solves to the same curve.csv as on the same heights from .npy; bad picks and
//! files are refused naming the cause.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::support::{homogeneous_scene, repo, solve_no_plots, temp_dir};
use strata_runtime::surface::container::{Pick, list, read_container};
use strata_runtime::surface::{ReadOptions, Spacing, Surface};

fn fixture() -> PathBuf {
    repo().join("tests/data/container")
}

/// Heights of a fixture `.npy` (in its unit), x first.
fn npy(name: &str, unit: f64) -> (Vec<f64>, usize, usize) {
    let s = Surface::read(
        &fixture().join(name),
        &ReadOptions {
            spacing: Some(Spacing::Pixel(1.0, 1.0)),
            ..Default::default()
        },
    )
    .unwrap();
    let (n0, n1) = s.shape();
    (s.heights().iter().map(|v| v * unit).collect(), n0, n1)
}

#[test]
fn surface_topography_containers_are_read_with_units_sizes_and_periodic_flags() {
    let zip = fixture().join("container.zip");
    let entries = list(&zip, &strata_runtime::resources::MemoryLimit::default()).unwrap();
    let names: Vec<&str> = entries.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["periodic-um", "scan-nm"]);
    assert_eq!(entries[0].unit.as_deref(), Some("µm"));
    assert_eq!(entries[1].size, Some((3000.0, 2000.0)));

    // Topography 0 (Surface::read's default): periodic, 50 µm, heights µm → m.
    let a = Surface::read(&zip, &ReadOptions::default()).unwrap();
    let (want, n0, n1) = npy("periodic-um.npy", 1e-6);
    assert_eq!(a.shape(), (n0, n1));
    assert!(a.is_periodic());
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-15 * y.abs();
    assert!(
        close(a.extent().0, 50e-6) && close(a.extent().1, 50e-6),
        "{:?}",
        a.extent()
    );
    assert_eq!(a.heights(), &want[..]);
    assert!(a.log()[0].contains("periodic-um"), "{:?}", a.log());
    assert!(a.warnings().is_empty(), "{:?}", a.warnings());

    // By name: non-periodic, 3 × 2 µm, heights nm → m.
    let b = read_container(&zip, &Pick::Name("scan-nm".into()), &ReadOptions::default()).unwrap();
    let (want, n0, n1) = npy("scan-nm.npy", 1e-9);
    assert_eq!((b.shape(), b.is_periodic()), ((n0, n1), false));
    assert!(
        close(b.extent().0, 3e-6) && close(b.extent().1, 2e-6),
        "{:?}",
        b.extent()
    );
    assert_eq!(b.heights(), &want[..]);
    assert_eq!(
        read_container(&zip, &Pick::Index(1), &ReadOptions::default())
            .unwrap()
            .heights(),
        b.heights()
    );
}

/// A container in the older layout: only meta.yml, `original` data files (.npy), sizes,
/// unit and periodic flag in the metadata.
fn legacy_container(dir: &Path, meta: &str) -> PathBuf {
    let path = dir.join("legacy.zip");
    let mut z = zip::ZipWriter::new(std::fs::File::create(&path).unwrap());
    let opts =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    z.start_file("meta.yml", opts).unwrap();
    z.write_all(meta.as_bytes()).unwrap();
    z.start_file("data/scan.npy", opts).unwrap();
    z.write_all(&std::fs::read(fixture().join("scan-nm.npy")).unwrap())
        .unwrap();
    z.finish().unwrap();
    path
}

const LEGACY: &str = "\
versions:
  topobank: 1.0.0
surfaces:
- name: Published surface
  category: exp
  topographies:
  - name: Scan 1
    datafile:
      original: data/scan.npy
    size: !!python/tuple
    - 3.0
    - 2.0
    unit: µm
    height_scale: 1.0
    is_periodic: true
";

#[test]
fn older_containers_take_sizes_unit_and_periodic_flag_from_meta_yml() {
    let d = temp_dir("container-legacy");
    let zip = legacy_container(&d, LEGACY);
    let s = read_container(&zip, &Pick::Name("Scan 1".into()), &ReadOptions::default()).unwrap();
    let (want, _, _) = npy("scan-nm.npy", 1e-6);
    assert!(s.is_periodic(), "the metadata's is_periodic");
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-15 * y.abs();
    assert!(
        close(s.extent().0, 3e-6) && close(s.extent().1, 2e-6),
        "{:?}",
        s.extent()
    );
    assert_eq!(s.heights(), &want[..]);
    assert!(
        s.log().iter().any(|l| l.contains("the container's `size`")),
        "{:?}",
        s.log()
    );
    // No member file is left behind in the temporary directory (this test's member,
    // scan.npy; the other tests' run in parallel).
    let left = std::fs::read_dir(std::env::temp_dir())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.starts_with(&format!("strata-container-{}-", std::process::id()))
                && n.ends_with("-scan.npy")
        })
        .count();
    assert_eq!(left, 0);

    // A pipeline on the original without a squeezed copy is refused, naming it.
    let scaled = legacy_container(
        &d,
        &LEGACY.replace("height_scale: 1.0", "height_scale: 2.5"),
    );
    let e = read_container(&scaled, &Pick::Index(0), &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("height_scale = 2.5") && e.contains("legacy.zip"),
        "{e}"
    );
}

#[test]
fn bad_picks_and_files_are_refused_naming_the_cause() {
    let zip = fixture().join("container.zip");
    let e = read_container(&zip, &Pick::Index(5), &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no topography 5") && e.contains("0 `periodic-um`, 1 `scan-nm`"),
        "{e}"
    );
    let e = read_container(&zip, &Pick::Name("nope".into()), &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no topography `nope`") && e.contains("container.zip"),
        "{e}"
    );
    // sizes are the file's: none may be given
    let e = Surface::read(
        &zip,
        &ReadOptions {
            spacing: Some(Spacing::Size(1e-3)),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("physical sizes") && e.contains("member topography0.nc"),
        "{e}"
    );
    // a zip without meta.yml
    let d = temp_dir("container-bad");
    let other = d.join("other.zip");
    let mut z = zip::ZipWriter::new(std::fs::File::create(&other).unwrap());
    z.start_file("a.txt", zip::write::SimpleFileOptions::default())
        .unwrap();
    z.write_all(b"x").unwrap();
    z.finish().unwrap();
    let e = Surface::read(&other, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("no meta.yml") && e.contains("other.zip"), "{e}");
    // topography on a non-container file, and a bad value: scene errors naming the field
    for (surface, want) in [
        (
            format!(
                "file = {:?}\nsize = 1e-3\ntopography = 0",
                fixture().join("scan-nm.npy")
            ),
            "surface.topography",
        ),
        (
            format!("file = {zip:?}\ntopography = 1.5"),
            "surface.topography",
        ),
    ] {
        let text = homogeneous_scene(&surface, "\"bem\"", "approach = [1e-7]");
        let e = strata::scene::Scene::from_str_in(&text, &d)
            .unwrap_err()
            .to_string();
        assert!(e.contains(want), "{e}");
    }
}

#[test]
fn a_container_topography_solves_to_the_curve_of_the_same_heights_from_npy() {
    let d = temp_dir("container-solve");
    let zip = fixture().join("container.zip");
    let cases = [
        (
            "bem",
            format!("file = {zip:?}\ntopography = 0"),
            format!(
                "file = {:?}\nsize = {:?}\nheight_unit = \"um\"\nperiodic = true",
                fixture().join("periodic-um.npy"),
                50.0 * 1e-6
            ),
            "approach = { from = 2e-7, to = 1.2e-6, steps = 3 }",
        ),
        (
            "\"independent\"",
            format!("file = {zip:?}\ntopography = \"scan-nm\""),
            format!(
                "file = {:?}\nsize = [{:?}, {:?}]\nheight_unit = \"nm\"",
                fixture().join("scan-nm.npy"),
                3000.0 * 1e-9,
                2000.0 * 1e-9
            ),
            "approach = { from = 1e-8, to = 4e-7, steps = 4 }",
        ),
    ];
    for (k, (model, from_zip, from_npy, load)) in cases.iter().enumerate() {
        let model = if *model == "bem" { "\"bem\"" } else { model };
        let mut curves = Vec::new();
        for (name, surface) in [("zip", from_zip), ("npy", from_npy)] {
            let sc = d.join(format!("{k}-{name}.toml"));
            std::fs::write(&sc, homogeneous_scene(surface, model, load)).unwrap();
            let out = d.join(format!("out-{k}-{name}"));
            let o = solve_no_plots(&sc, &out);
            assert!(
                o.status.success(),
                "{k} {name}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            curves.push(std::fs::read_to_string(out.join("curve.csv")).unwrap());
        }
        // The same sizes as the container's (its lengths × the unit's metres, here
        // 50 × 1e-6 = 4.9999999999999996e-5): the same curve to the last bit.
        assert_eq!(curves[0], curves[1], "case {k}");
        assert!(curves[0].lines().count() >= 4, "{}", curves[0]);
    }
}

/// A "billion laughs" meta.yml (9 levels of 9 aliases: 9⁹ ≈ 3.9·10⁸ nodes from a few
/// kB; it grew to 6.8 GB) is refused from its alias count, naming the member and the
/// cap, under the default memory limit; a meta.yml that uses an alias sparingly still
/// reads.
#[test]
fn a_yaml_alias_bomb_in_meta_yml_is_refused() {
    let d = temp_dir("container-bomb");
    let mut bomb = String::from(
        "a0: &a0 [\"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\"]\n",
    );
    for l in 1..=9 {
        let p = l - 1;
        bomb.push_str(&format!(
            "a{l}: &a{l} [*a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}]\n"
        ));
    }
    bomb.push_str(LEGACY);
    let zip = legacy_container(&d, &bomb);
    let o = crate::support::strata_in(&d)
        .args(["surface", "info"])
        .arg(&zip)
        .output()
        .unwrap();
    let e = crate::support::stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("legacy.zip") && e.contains("meta.yml") && e.contains("cap of 1000000"),
        "{e}"
    );
    // an anchor used once: read as before
    let zip = legacy_container(&d, &format!("unit0: &u µm\n{LEGACY}"));
    assert_eq!(
        list(&zip, &strata_runtime::resources::MemoryLimit::default())
            .unwrap()
            .len(),
        1
    );
}
