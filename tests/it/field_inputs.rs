//! Inputs found by an adversarial sweep of the command line that gave
//! contradictory results with exit 0, wrote float32 infinities, ignored the memory limit
//! or returned NaN. Each now fails by name (exit 1, nothing written) or gives the right
//! number.

use std::path::{Path, PathBuf};

use crate::support::{fresh_dir, repo, stderr_of, strata_in};

fn dir(name: &str) -> PathBuf {
    fresh_dir("field-inputs", name)
}

/// A smooth 16×16 height map `scale`·(sin + cos) as a text matrix (one grid row per line).
fn write_heights(path: &Path, scale: f64) {
    let rows: Vec<String> = (0..16)
        .map(|i| {
            (0..16)
                .map(|j| {
                    let (x, y) = (i as f64 * 0.39, j as f64 * 0.39);
                    format!("{:e}", scale * (x.sin() + (1.3 * y).cos()))
                })
                .collect::<Vec<_>>()
                .join(" ")
        })
        .collect();
    std::fs::write(path, rows.join("\n") + "\n").unwrap();
}

/// A scene on the shipped E2/E1 = 1 stack and table with the given `[surface]` body,
/// model kind and `[load]` body.
fn scene(d: &Path, surface: &str, model: &str, load: &str) -> PathBuf {
    let tables = repo().join("tables");
    let text = format!(
        "[stack]\nfile = \"{}\"\ntable = \"{}\"\n[surface]\nperiodic = true\n{surface}\n\
         [model]\nkind = \"{model}\"\nimages = \"periodic\"\n[load]\n{load}\n",
        tables.join("stacks/paper-two-layer-E2E1-1.toml").display(),
        tables.join("paper-two-layer.strata").display(),
    );
    let p = d.join(format!("{model}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

/// `strata solve SCENE --out OUT --no-plots` in `d`.
fn solve(d: &Path, scene: &Path, out: &Path) -> (Option<i32>, String) {
    let (s, o) = (scene.to_str().unwrap(), out.to_str().unwrap());
    run(d, &["solve", s, "--out", o, "--no-plots"])
}

const GENERATED_64: &str = "[surface.generate]\nsize = 1e-3\ngrid = 64\nfractal_dimension = 2.4\n\
                            k_min = 2\nk_max = 10\nseed = 20240611\n";

/// Runs strata in `d` (its own table cache); returns (exit code, stderr).
fn run(d: &Path, args: &[&str]) -> (Option<i32>, String) {
    let o = strata_in(&d.join("cache")).args(args).output().unwrap();
    (o.status.code(), stderr_of(&o))
}

/// Heights of 1e299 m are finite but their RMS overflows: refused by name for every
/// command (before: N and I models wrote `mean_pressure` 0 with `area_fraction`
/// 1.4e−309 and `contacts` 1, exit 0), the value in exponent form (not 300 digits);
/// likewise a pixel of 1e−300 m, whose RMS slope overflows.
#[test]
fn heights_and_pixels_whose_statistics_overflow_are_refused_by_name() {
    let d = dir("overflow");
    let huge = d.join("huge.txt");
    write_heights(&huge, 1e299);
    let h = huge.to_str().unwrap();
    let (code, e) = run(&d, &["surface", "info", h, "--size", "1e-3"]);
    assert_eq!(code, Some(1), "{e}");
    assert!(
        e.contains("`heights`") && e.contains("e299") && e.contains("RMS height overflows"),
        "{e}"
    );
    assert!(e.len() < 400, "short line: {e}");
    for model in ["independent", "interacting"] {
        let sc = scene(
            &d,
            &format!("file = \"{h}\"\nsize = 1e-3"),
            model,
            "approach = { from = 1e-8, to = 2e-6, steps = 4 }",
        );
        let out = d.join(format!("out-{model}"));
        let (code, e) = solve(&d, &sc, &out);
        assert_eq!(code, Some(1), "{model}: {e}");
        assert!(e.contains("`heights`"), "{model}: {e}");
        assert!(!out.join("curve.csv").exists(), "{model}: nothing written");
    }
    let fine = d.join("fine.txt");
    write_heights(&fine, 1e-6);
    let f = fine.to_str().unwrap();
    let (code, e) = run(&d, &["surface", "info", f, "--pixel-size", "1e-300"]);
    assert_eq!(code, Some(1), "{e}");
    assert!(
        e.contains("`pixel_size`") && e.contains("RMS slope overflows"),
        "{e}"
    );
    let (code, e) = run(&d, &["surface", "info", f, "--pixel-size", "1e-5"]);
    assert_eq!(code, Some(0), "the same heights on a 10 µm pixel: {e}");
}

/// The I model at inputs where its Newton search broke down numerically returned an
/// all-zero curve (no contact, zero load) with exit 0 although every summit was loaded:
/// a 1e−100 m RMS surface (summit radii ~1e91 m) at approaches of µm, and an approach of
/// 1e50 m. With positive interference no equilibrium without contact exists (the most
/// loaded summit would have F_k(0⁺) = −δ_k < 0): refused by name, nothing written. The
/// same scenes at ordinary scales solve. Through `law` the message appears once.
/// (Both scenes take the N model's contact areas far past the nominal area,
/// so they are now refused by that check, at once, before the I model is started.)
#[test]
fn interacting_model_refuses_a_contactless_equilibrium() {
    let d = dir("contactless");
    for (what, surface, load) in [
        (
            "rms 1e-100",
            format!("{GENERATED_64}rms = 1e-100"),
            "approach = { from = 1.3e-6, to = 9.8e-6, steps = 3 }",
        ),
        (
            "approach 1e50",
            format!("{GENERATED_64}rms = 3.4e-6"),
            "approach = { from = 1e50, to = 1e50, steps = 1 }",
        ),
    ] {
        let sc = scene(&d, &surface, "interacting", load);
        let out = d.join("out");
        let _ = std::fs::remove_dir_all(&out);
        let (code, e) = solve(&d, &sc, &out);
        assert_eq!(code, Some(1), "{what}: {e}");
        assert!(
            e.contains("I model not started") && e.contains("model.kind = \"bem\""),
            "{what}: {e}"
        );
        assert!(!out.join("curve.csv").exists(), "{what}: nothing written");
        // Through `law` the solver's message is printed once (it was printed twice:
        // the wrapper's text and its `source`).
        let law = d.join("law.csv");
        let (code, e) = run(
            &d,
            &["law", sc.to_str().unwrap(), "--out", law.to_str().unwrap()],
        );
        assert_eq!(code, Some(1), "{what}: {e}");
        assert_eq!(e.matches("reaches A/A₀").count(), 1, "{what}: {e}");
        assert!(!law.exists(), "{what}: nothing written");
    }
    let sc = scene(
        &d,
        &format!("{GENERATED_64}rms = 3.4e-6"),
        "interacting",
        "approach = { from = 1.3e-6, to = 9.8e-6, steps = 3 }",
    );
    let out = d.join("ok");
    let (code, e) = solve(&d, &sc, &out);
    assert_eq!(code, Some(0), "{e}");
    let csv = std::fs::read_to_string(out.join("curve.csv")).unwrap();
    let loads: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap().parse().unwrap())
        .collect();
    assert!(loads.len() == 3 && loads.iter().all(|&p| p > 0.0), "{csv}");
}

/// `surface export --dtype F` wrote float32 ±inf for heights beyond 3.4e38 m (exit 0; read
/// back as "NaN"): refused, naming F and D, nothing written; D writes them. The export
/// also creates a missing parent directory (it failed with "cannot read surface file"),
/// and honours `--memory-limit` for a generated surface (it generated 4096² at 531 MB
/// under a 10 MB limit).
#[test]
fn surface_export_refuses_float32_overflow_creates_its_directory_and_honours_the_limit() {
    let d = dir("export");
    let big = d.join("big.txt");
    write_heights(&big, 1e40);
    let sc = scene(
        &d,
        &format!("file = \"{}\"\nsize = 1e-3", big.display()),
        "independent",
        "approach = { from = 1e39, to = 2e39, steps = 2 }",
    );
    let export = |out: &Path, dtype: &str| {
        let o = out.to_str().unwrap();
        run(
            &d,
            &[
                "surface",
                "export",
                sc.to_str().unwrap(),
                "--out",
                o,
                "--dtype",
                dtype,
            ],
        )
    };
    let f = d.join("f.x3p");
    let (code, e) = export(&f, "F");
    assert_eq!(code, Some(1), "{e}");
    assert!(e.contains("float32") && e.contains("as D"), "{e}");
    assert!(!f.exists(), "nothing written");
    let nested = d.join("new/sub/d.x3p");
    let (code, e) = export(&nested, "D");
    assert_eq!(code, Some(0), "{e}");
    assert!(nested.exists());
    let generated = scene(
        &d,
        "[surface.generate]\nsize = 1e-3\ngrid = 4096\nfractal_dimension = 2.4\nk_min = 2\n\
         k_max = 10\nrms = 3.4e-6\nseed = 1",
        "interacting",
        "approach = { from = 1e-6, to = 2e-6, steps = 2 }",
    );
    let npy = d.join("g.npy");
    for args in [
        &[
            "--memory-limit",
            "10M",
            "surface",
            "export",
            generated.to_str().unwrap(),
            "--out",
            npy.to_str().unwrap(),
        ][..],
        &[
            "--memory-limit",
            "10M",
            "surface",
            "info",
            generated.to_str().unwrap(),
        ][..],
    ] {
        let (code, e) = run(&d, args);
        assert_eq!(code, Some(1), "{args:?}: {e}");
        assert!(e.contains("memory limit is 10.00 MiB"), "{args:?}: {e}");
    }
    assert!(!npy.exists());
}

/// `compliance --rho-h` below ~1e−154 gave "k_z is NaN" (the transfer matrices' t² terms
/// underflowed); k_z → −1 on a rigid base (S ~ ρh), checked to the last bit.
#[test]
fn compliance_at_vanishing_rho_h_is_the_limit() {
    let d = dir("compliance");
    let stack = repo().join("tables/stacks/paper-two-layer.toml");
    let o = strata_in(&d.join("cache"))
        .args([
            "compliance",
            stack.to_str().unwrap(),
            "--rho-h",
            "1e-170,1e-300,1e-3",
        ])
        .output()
        .unwrap();
    let (out, e) = (String::from_utf8_lossy(&o.stdout), stderr_of(&o));
    assert!(o.status.success(), "{e}");
    let kz: Vec<f64> = out
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(kz[..2], [-1.0, -1.0], "{out}");
    assert!(kz[2] > -1.0 && kz[2] < -0.99, "{out}");
}

/// A `.npy` file (format 1.0) with the given header dict and payload.
fn write_npy(path: &Path, dict: &str, payload: &[u8]) {
    let mut header = dict.to_string();
    while !(10 + header.len() + 1).is_multiple_of(64) {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    bytes.extend_from_slice(payload);
    std::fs::write(path, bytes).unwrap();
}

/// Bad `.npy` files give one plain line: a 1-D array (the message showed Rust's
/// `Some(2)`), a header that is not a dict (the parser's multi-line excerpt with a caret).
#[test]
fn bad_npy_files_give_one_plain_line() {
    let d = dir("npy");
    let data: Vec<u8> = (0..16).flat_map(|i| (i as f64).to_le_bytes()).collect();
    let one_d = d.join("oned.npy");
    write_npy(
        &one_d,
        "{'descr': '<f8', 'fortran_order': False, 'shape': (16,), }",
        &data,
    );
    let garbage = d.join("garbage.npy");
    write_npy(&garbage, "garbage", &data);
    let good = d.join("good.npy");
    write_npy(
        &good,
        "{'descr': '<f8', 'fortran_order': False, 'shape': (4, 4), }",
        &data,
    );
    for (f, expect) in [
        (&one_d, "expected a 2-D array, found 1 dimension(s)"),
        (&garbage, "not a valid .npy file: error parsing header"),
    ] {
        let (code, e) = run(
            &d,
            &["surface", "info", f.to_str().unwrap(), "--size", "1e-3"],
        );
        assert_eq!(code, Some(1), "{e}");
        assert_eq!(e.trim_end().lines().count(), 1, "{e}");
        assert!(e.contains(expect), "{e}");
        assert!(!e.contains("Some(") && !e.contains("-->"), "{e}");
    }
    let (code, e) = run(
        &d,
        &["surface", "info", good.to_str().unwrap(), "--size", "1e-3"],
    );
    assert_eq!(code, Some(0), "the same writer, a valid file: {e}");
}

/// `law --min-gap` deep enough that the summed contact areas exceed the nominal area
/// (A/A₀ > 1, outside the asperity models' validity): said so, with the separation and
/// what to do (it said `samples: area_fraction[25] = 1.02…: must lie in [0, 1]`); a
/// shallower one writes the law.
#[test]
fn law_past_full_contact_says_why() {
    let d = dir("law-full");
    let sc = scene(
        &d,
        &format!("{GENERATED_64}rms = 3.4e-6"),
        "independent",
        "approach = { from = 1e-6, to = 2e-6, steps = 2 }",
    );
    let out = d.join("law.csv");
    let (s, o) = (sc.to_str().unwrap(), out.to_str().unwrap());
    let (code, e) = run(&d, &["law", s, "--out", o, "--min-gap=-1e-3"]);
    assert_eq!(code, Some(1), "{e}");
    assert!(
        e.contains("reaches A/A₀ = 1.") && e.contains("> 1 at g = -") && e.contains("--min-gap"),
        "{e}"
    );
    assert!(!out.exists());
    // Without `=`: a negative value is a value, not a flag (clap took it for one).
    let (code, e) = run(&d, &["law", s, "--out", o, "--min-gap", "-2e-5"]);
    assert_eq!(code, Some(0), "{e}");
    assert!(out.exists());
}

/// An `x y z` triplet file (3 columns, every grid point once) was once read as an
/// N×3 height grid. It is refused by name, with the matrix shape to write instead; a
/// genuine height matrix three points wide still reads.
#[test]
fn xyz_triplet_files_are_named_not_read_as_heights() {
    use strata_runtime::surface::Surface;
    let d = dir("triplets");
    let mut text = String::from("# x y z\n");
    for i in 0..4 {
        for j in 0..5 {
            let (x, y) = (i as f64 * 1e-5, j as f64 * 1e-5);
            text.push_str(&format!(
                "{x:e} {y:e} {:e}\n",
                1e-6 * ((i * 7 + j * 3) % 5) as f64
            ));
        }
    }
    let f = d.join("scan.xyz.txt");
    std::fs::write(&f, &text).expect("write");
    let e = Surface::read_text(&f, 1e-3, false).unwrap_err().to_string();
    assert!(
        e.contains("triplets") && e.contains("4×5") && e.contains("scan.xyz.txt"),
        "{e}"
    );
    let (code, err) = run(
        &d,
        &["surface", "info", f.to_str().unwrap(), "--size", "1e-3"],
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("triplets"), "{err}");
    // 6 rows of 3 heights: a matrix
    let m: String = (0..6)
        .map(|r| {
            format!(
                "{:e} {:e} {:e}\n",
                1e-6 * r as f64,
                2e-6 + 1e-7 * r as f64,
                -3e-7 * r as f64
            )
        })
        .collect();
    let g = d.join("narrow.txt");
    std::fs::write(&g, m).expect("write");
    let s = Surface::read_text(&g, 1e-3, false).expect("a 6×3 matrix");
    assert_eq!(s.shape(), (6, 3));
}

/// A surface file that is a link to /dev/zero once grew without bound (under a 1 GB
/// memory limit) and a FIFO would block forever: both are refused at once, by name, for
/// each reader (.npy, text, .x3p).
#[test]
fn surface_files_that_are_streams_are_refused() {
    use strata_runtime::surface::{ReadOptions, Spacing, Surface};
    let d = dir("streams");
    let opts = ReadOptions {
        spacing: Some(Spacing::Size(1e-3)),
        ..Default::default()
    };
    for ext in ["npy", "txt", "x3p"] {
        let link = d.join(format!("zero.{ext}"));
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink("/dev/zero", &link).expect("symlink");
        let o = if ext == "x3p" {
            ReadOptions::default()
        } else {
            opts
        };
        let e = Surface::read(&link, &o).unwrap_err().to_string();
        assert!(
            e.contains("not a regular file") && e.contains(&format!("zero.{ext}")),
            "{e}"
        );
    }
    let fifo = d.join("pipe.txt");
    let _ = std::fs::remove_file(&fifo);
    if std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        let e = Surface::read(&fifo, &opts).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
    }
}

/// `STRATA_MEMORY_LIMIT=garbage` was once refused without naming the variable.
#[test]
fn a_bad_memory_limit_variable_is_named() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(["compliance"])
        .arg(repo().join("tables/stacks/paper-two-layer.toml"))
        .args(["--rho-h", "1"])
        .env("STRATA_MEMORY_LIMIT", "garbage")
        .output()
        .expect("run strata");
    let err = stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("STRATA_MEMORY_LIMIT = `garbage` is invalid"),
        "{err}"
    );
}
