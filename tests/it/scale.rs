//! The I model at the scale of measured surfaces: a generated 1024² surface
//! with k_M = 512 (36 974 summits; before the grid far field it aborted asking for
//! 28.75 GB) solves through `strata solve` under the default memory limit, and the same
//! request under a limit far below its estimate fails with the estimate, exit 1.

use std::path::Path;

use crate::support::{fresh_dir, stderr_of, strata_in};

fn scene(d: &Path, model: &str) -> std::path::PathBuf {
    let p = d.join(format!("{model}.toml"));
    std::fs::write(
        &p,
        format!(
            "[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
             [surface.generate]\nsize = 1e-3\ngrid = 1024\nfractal_dimension = 2.4\n\
             k_min = 2\nk_max = 512\nrms = 3.4e-6\nseed = 1\n\
             [model]\nkind = \"{model}\"\n[load]\nseparations = [3e-6]\n"
        ),
    )
    .unwrap();
    p
}

/// (mean pressure, contacts) of the single step in `out/curve.csv`.
fn step(out: &Path) -> (f64, usize) {
    let text = std::fs::read_to_string(out.join("curve.csv")).unwrap();
    let row: Vec<&str> = text.lines().nth(1).unwrap().split(',').collect();
    (row[2].parse().unwrap(), row[5].parse().unwrap())
}

/// 36 974 summits, I model (5×5 periodic images) at g_n = 3 µm: solved (KKT residual
/// below 1e-8, as every I-model step), with fewer contacts and a lower mean pressure
/// than the N model at the same approach (interactions only add displacement on a
/// half-space). On this fine surface (summits 5 µm apart) the difference is large:
/// measured p_I = 2.79 MPa against p_N = 262 MPa — the N model's pressure would sink
/// the mean plane by p_N L/E* ≈ 65 µm, far more than the 10 µm approach, so the
/// interacting answer is the self-consistent one.
#[test]
fn i_model_solves_37k_summits() {
    let d = fresh_dir("scale", "37k");
    let run = |model: &str| {
        let out = d.join(format!("out-{model}"));
        let o = strata_in(&d)
            .args(["solve", scene(&d, model).to_str().unwrap(), "--out"])
            .arg(&out)
            .output()
            .unwrap();
        let e = stderr_of(&o);
        assert!(o.status.success(), "{e}");
        (e, step(&out))
    };
    let (e, (p_i, c_i)) = run("interacting");
    assert!(e.contains("36974 summits"), "{e}");
    let kkt: f64 = e
        .split("largest KKT residual ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no KKT line in {e}"));
    assert!(kkt < 1e-8, "{kkt}");
    let (_, (p_n, c_n)) = run("independent");
    assert!(p_i < p_n && p_i > 1e6, "I {p_i} N {p_n}");
    assert!(c_i <= c_n && c_i > 100, "I {c_i} N {c_n}");
}

/// The same request under a 64 MiB limit (the surface fits, the I model's estimate,
/// about 0.5 GiB, does not): refused before the pair sums are allocated,
/// naming the grid, the near corrections and the estimate; exit 1, nothing written.
#[test]
fn i_model_37k_refused_below_its_estimate() {
    let d = fresh_dir("scale", "refused");
    let out = d.join("out");
    let o = strata_in(&d)
        .args([
            "solve",
            scene(&d, "interacting").to_str().unwrap(),
            "--memory-limit",
            "64M",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let e = stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    for needle in [
        "grid far field",
        "near corrections",
        "needs about",
        "memory limit",
    ] {
        assert!(e.contains(needle), "`{needle}` missing in {e}");
    }
    assert!(!out.join("curve.csv").exists());
}
