//! End-to-end tests of `strata sweep` and `strata sweep merge`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let d = crate::support::scratch().join(format!("sweep-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn strata(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .output()
        .expect("run strata")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn ok(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{err}");
    err
}

/// Fails with a clear message (no panic); returns stderr.
fn fails(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!o.status.success(), "should fail: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// A homogeneous half-space (E = 4 GPa, ν = 0.15), a small generated surface.
pub(crate) const BASE: &str = r#"
title = "test sweep"
[scene.stack]
[[scene.stack.layer]]
thickness = 1e-3
young = 4e9
poisson = 0.15
[scene.stack.base]
kind = "elastic"
young = 4e9
poisson = 0.15
[scene.surface]
periodic = true
[scene.surface.generate]
size = 1e-3
grid = 64
fractal_dimension = 2.4
k_min = 2
k_max = 8
rms = 3.4e-6
seed = 1
[scene.model]
kind = "independent"
images = "isolated"
[scene.load]
separations = [6e-6, 4.5e-6, 3e-6]
"#;

const AXES: &str = r#"
[sweep]
surface.k_max = [4, 8]
surface.seed = { from = 1, count = 3 }
model.kind = ["independent", "interacting"]
"#;

fn write_sweep(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write sweep");
    p
}

const HEADER: &str = "case,surface.k_max,surface.seed,model,step,delta,gap,mean_pressure,pressure_ratio,area_fraction,contacts,stiffness,valid";

/// The CSV has one row per case and step with the documented columns and order; every
/// case equals `strata solve` of the same scene (field for field, all 3 steps); the
/// pressure grows with the approach; plots and bands.csv are written.
#[test]
fn small_sweep_rows_columns_and_single_solves() {
    let dir = tmp("rows");
    let sw = write_sweep(&dir, "sweep.toml", &format!("{BASE}{AXES}"));
    let out = dir.join("out");
    let err = ok(&strata(&["sweep", s(&sw), "--out", s(&out)]));
    assert!(err.contains("12 cases, 36 rows"), "{err}");
    let csv = std::fs::read_to_string(out.join("sweep.csv")).expect("sweep.csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], HEADER);
    assert_eq!(lines.len(), 1 + 12 * 3);
    // case order: model.kind slowest, then k_max, then seed (axes sorted by name)
    for (case, (k, seed, model)) in [
        (0, ("4", "1", "independent")),
        (2, ("4", "3", "independent")),
        (3, ("8", "1", "independent")),
        (7, ("4", "2", "interacting")),
        (11, ("8", "3", "interacting")),
    ] {
        for step in 0..3 {
            let f: Vec<&str> = lines[1 + 3 * case + step].split(',').collect();
            assert_eq!(f.len(), 13);
            assert_eq!(
                &f[..5],
                &[&case.to_string(), k, seed, model, &step.to_string()]
            );
        }
    }
    for case in 0..12 {
        let p: Vec<f64> = (0..3)
            .map(|st| {
                lines[1 + 3 * case + st]
                    .split(',')
                    .nth(8)
                    .unwrap()
                    .parse()
                    .unwrap()
            })
            .collect();
        assert!(
            p[0] > 0.0 && p[1] > p[0] && p[2] > p[1],
            "case {case}: {p:?}"
        );
    }
    // Case 10 (interacting, k_max = 8, seed 2) through `strata solve`.
    let scene = BASE
        .replace("title = \"test sweep\"\n", "")
        .replace("[scene.", "[")
        .replace("[[scene.", "[[")
        .replace("seed = 1", "seed = 2")
        .replace("kind = \"independent\"", "kind = \"interacting\"");
    let sc = dir.join("scene.toml");
    std::fs::write(&sc, scene).unwrap();
    let single = dir.join("single");
    ok(&strata(&[
        "solve",
        s(&sc),
        "--out",
        s(&single),
        "--no-plots",
    ]));
    let curve = std::fs::read_to_string(single.join("curve.csv")).unwrap();
    for (step, row) in curve.lines().skip(1).enumerate() {
        let sweep_row = lines[1 + 3 * 10 + step];
        assert!(sweep_row.starts_with(&format!("10,8,2,interacting,{step},")));
        assert!(
            sweep_row.ends_with(&format!(",{row}")),
            "{sweep_row} vs {row}"
        );
    }
    for f in [
        "sweep.json",
        "bands.csv",
        "pressure_gap.svg",
        "area_pressure.svg",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sweep.json")).unwrap()).unwrap();
    assert_eq!(meta["cases"], 12);
    assert_eq!(meta["case_ids"].as_array().unwrap().len(), 12);
    assert!(meta["shard"].is_null());
    // bands: mean between min and max, 4 series × 2 plots × 25 points
    let bands = std::fs::read_to_string(out.join("bands.csv")).unwrap();
    assert_eq!(bands.lines().count(), 1 + 4 * 2 * 25);
    for l in bands.lines().skip(1) {
        let v: Vec<f64> = l.split(',').skip(4).map(|x| x.parse().unwrap()).collect();
        assert!(
            v[2] <= v[1] * (1.0 + 1e-12) && v[1] <= v[3] * (1.0 + 1e-12),
            "{l}"
        );
        assert_eq!(v[4], 3.0);
    }
}

/// Shards 1/2 + 2/2 merged are byte for byte the unsharded CSV; so is a run on one
/// thread (results do not depend on scheduling); a shard holds the cases
/// id % N == I − 1.
#[test]
fn shards_merge_to_the_unsharded_csv() {
    let dir = tmp("shards");
    let sw = write_sweep(&dir, "sweep.toml", &format!("{BASE}{AXES}"));
    let full = dir.join("full");
    ok(&strata(&["sweep", s(&sw), "--out", s(&full), "--no-plots"]));
    let one = dir.join("one");
    ok(&strata(&[
        "sweep",
        s(&sw),
        "--out",
        s(&one),
        "--no-plots",
        "--threads",
        "1",
    ]));
    let reference = std::fs::read(full.join("sweep.csv")).unwrap();
    assert_eq!(std::fs::read(one.join("sweep.csv")).unwrap(), reference);
    let sh = dir.join("shards");
    for i in ["1/2", "2/2"] {
        ok(&strata(&["sweep", s(&sw), "--out", s(&sh), "--shard", i]));
    }
    let part = std::fs::read_to_string(sh.join("shard-2-of-2.csv")).unwrap();
    let ids: Vec<&str> = part
        .lines()
        .skip(1)
        .step_by(3)
        .map(|l| &l[..l.find(',').unwrap()])
        .collect();
    assert_eq!(ids, ["1", "3", "5", "7", "9", "11"]);
    let merged = dir.join("merged.csv");
    let plots = dir.join("plots");
    ok(&strata(&[
        "sweep",
        "merge",
        s(&sh),
        "--out",
        s(&merged),
        "--plots",
        s(&plots),
    ]));
    assert_eq!(std::fs::read(&merged).unwrap(), reference);
    assert!(plots.join("pressure_gap.svg").is_file());
    // the merged file is not overwritten without --force
    let e = fails(&strata(&["sweep", "merge", s(&sh), "--out", s(&merged)]));
    assert!(e.contains("--force"), "{e}");
    // nor, even with --force, a shard it reads (the next merge then failed: 40 rows)
    let first = sh.join("shard-1-of-2.csv");
    let before = std::fs::read(&first).unwrap();
    let e = fails(&strata(&[
        "sweep",
        "merge",
        s(&sh),
        "--out",
        s(&first),
        "--force",
    ]));
    assert!(e.contains("is the shard"), "{e}");
    assert_eq!(std::fs::read(&first).unwrap(), before);
}

/// Merge refuses a missing shard, a duplicate (copied) shard, a shard present twice,
/// shards of another sweep file and a directory mixing shard counts, naming the file.
#[test]
fn merge_refuses_bad_shard_sets() {
    let dir = tmp("merge-bad");
    let sw = write_sweep(&dir, "sweep.toml", &format!("{BASE}{AXES}"));
    let other = write_sweep(
        &dir,
        "other.toml",
        &format!("{BASE}{AXES}").replace("rms = 3.4e-6", "rms = 3.0e-6"),
    );
    let run = |sweep: &Path, out: &Path, shard: &str| {
        ok(&strata(&[
            "sweep",
            s(sweep),
            "--out",
            s(out),
            "--shard",
            shard,
        ]));
    };
    let merge = |d: &Path| strata(&["sweep", "merge", s(d), "--out", s(&d.join("m.csv"))]);
    // missing
    let a = dir.join("missing");
    run(&sw, &a, "1/2");
    let e = fails(&merge(&a));
    assert!(
        e.contains("shard 2/2 is missing") && e.contains("shard-2-of-2.csv"),
        "{e}"
    );
    // duplicate: shard 1 copied over shard 2 (CSV and sidecar)
    for ext in ["csv", "json"] {
        std::fs::copy(
            a.join(format!("shard-1-of-2.{ext}")),
            a.join(format!("shard-2-of-2.{ext}")),
        )
        .unwrap();
    }
    let e = fails(&merge(&a));
    assert!(
        e.contains("duplicate") && e.contains("shard-2-of-2.csv"),
        "{e}"
    );
    // duplicate rows with a correct sidecar
    ok(&strata(&[
        "sweep",
        s(&sw),
        "--out",
        s(&a),
        "--shard",
        "2/2",
        "--force",
    ]));
    std::fs::copy(a.join("shard-1-of-2.csv"), a.join("shard-2-of-2.csv")).unwrap();
    let e = fails(&merge(&a));
    assert!(
        e.contains("shard-2-of-2.csv") && e.contains("differs from what its run wrote"),
        "{e}"
    );
    // duplicated: a second file for shard 1 (a copy under another spelling, sidecar
    // and all) beside a complete set; both would be merged, shard 1's cases twice
    let t = dir.join("twice");
    run(&sw, &t, "1/2");
    run(&sw, &t, "2/2");
    for ext in ["csv", "json"] {
        std::fs::copy(
            t.join(format!("shard-1-of-2.{ext}")),
            t.join(format!("shard-01-of-2.{ext}")),
        )
        .unwrap();
    }
    let e = fails(&merge(&t));
    assert!(
        e.contains("shard 1/2 is duplicated")
            && e.contains("shard-01-of-2.csv")
            && e.contains("shard-1-of-2.csv"),
        "{e}"
    );
    assert!(!t.join("m.csv").exists(), "a merge was written");
    std::fs::remove_file(t.join("shard-01-of-2.csv")).unwrap();
    ok(&merge(&t));
    // another sweep file
    let b = dir.join("foreign");
    run(&sw, &b, "1/2");
    run(&other, &b, "2/2");
    let e = fails(&merge(&b));
    assert!(e.contains("different sweep"), "{e}");
    // mixed counts
    let c = dir.join("mixed");
    run(&sw, &c, "1/2");
    run(&sw, &c, "2/2");
    run(&sw, &c, "1/3");
    let e = fails(&merge(&c));
    assert!(e.contains("different counts"), "{e}");
    // empty directory
    let d = dir.join("empty");
    std::fs::create_dir_all(&d).unwrap();
    let e = fails(&merge(&d));
    assert!(e.contains("no shard files"), "{e}");
}

/// Bad sweep files and shard specs fail with the offending field named, non-zero exit,
/// no panic; an existing non-empty --out (or this shard's own files) is refused
/// without --force.
#[test]
fn bad_input_is_refused_clearly() {
    let dir = tmp("bad");
    let out = dir.join("out");
    let cases = [
        ("[sweep]\nsurface.colour = [1]\n", "sweep.surface.colour"),
        (
            "[sweep]\nsurface.k_max = []\n",
            "sweep.surface.k_max: empty list",
        ),
        ("[sweep]\nsurface.seed = [1.5]\n", "sweep.surface.seed[0]"),
        ("[sweep]\nmodel.kind = [\"magic\"]\n", "sweep.model.kind[0]"),
        (
            "[sweep]\nstack.layer2.young = [1e9]\n",
            "sweep.stack.layer2.young",
        ),
        ("[sweep]\nsurface.k_max = [8, 40]\n", "case 1"),
        (
            "[sweep]\nmode = \"list\"\nsurface.k_max = [4, 8]\nsurface.rms = [1e-6]\n",
            "same length",
        ),
    ];
    for (i, (axes, expect)) in cases.iter().enumerate() {
        let sw = write_sweep(&dir, &format!("bad{i}.toml"), &format!("{BASE}{axes}"));
        let e = fails(&strata(&["sweep", s(&sw), "--out", s(&out)]));
        assert!(e.contains(expect), "{axes}: {e}");
    }
    let e = fails(&strata(&[
        "sweep",
        s(&write_sweep(&dir, "noscene.toml", AXES)),
        "--out",
        s(&out),
    ]));
    assert!(e.contains("scene: missing"), "{e}");
    let sw = write_sweep(&dir, "good.toml", &format!("{BASE}{AXES}"));
    for bad in ["0/2", "3/2", "1/0", "x"] {
        let e = fails(&strata(&[
            "sweep",
            s(&sw),
            "--out",
            s(&out),
            "--shard",
            bad,
        ]));
        assert!(e.contains(&format!("--shard {bad}")), "{e}");
    }
    // existing non-empty --out
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("keep.txt"), "x").unwrap();
    let e = fails(&strata(&["sweep", s(&sw), "--out", s(&out)]));
    assert!(e.contains("not empty") && e.contains("--force"), "{e}");
    ok(&strata(&[
        "sweep",
        s(&sw),
        "--out",
        s(&out),
        "--force",
        "--no-plots",
    ]));
    // a shard may share a directory with others, but not overwrite its own files
    let sh = dir.join("sh");
    ok(&strata(&[
        "sweep",
        s(&sw),
        "--out",
        s(&sh),
        "--shard",
        "1/2",
    ]));
    let e = fails(&strata(&[
        "sweep",
        s(&sw),
        "--out",
        s(&sh),
        "--shard",
        "1/2",
    ]));
    assert!(
        e.contains("shard-1-of-2.csv") && e.contains("--force"),
        "{e}"
    );
    ok(&strata(&[
        "sweep",
        s(&sw),
        "--out",
        s(&sh),
        "--shard",
        "2/2",
    ]));
}

/// A case whose load is out of range fails the sweep naming the case and its values;
/// with --keep-going the other cases are written, the failure is listed in the
/// sidecar, the exit status is non-zero, and merge accepts the listed failure.
#[test]
fn failing_case_is_named_and_keep_going_writes_the_rest() {
    let dir = tmp("fail");
    // z_M − z̄ of an RMS-1 µm surface is a few µm: separation 6 µm is out of range.
    let text = format!("{BASE}[sweep]\nsurface.rms = [3.4e-6, 1e-6]\nsurface.seed = [1, 2]\n")
        .replace(
            "separations = [6e-6, 4.5e-6, 3e-6]",
            "separations = [6e-6, 5e-6]",
        );
    let sw = write_sweep(&dir, "sweep.toml", &text);
    let e = fails(&strata(&["sweep", s(&sw), "--out", s(&dir.join("a"))]));
    assert!(
        e.contains("surface.rms = 0.000001") && e.contains("load.separations[0]"),
        "{e}"
    );
    let b = dir.join("b");
    let e = fails(&strata(&["sweep", s(&sw), "--out", s(&b), "--keep-going"]));
    assert!(e.contains("case(s) failed"), "{e}");
    let csv = std::fs::read_to_string(b.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 2 * 2);
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(b.join("sweep.json")).unwrap()).unwrap();
    let failed: Vec<u64> = meta["failed"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["case"].as_u64().unwrap())
        .collect();
    assert_eq!(failed, [2, 3]); // axes surface.rms (slowest), surface.seed
    let sh = dir.join("sh");
    for i in ["1/2", "2/2"] {
        fails(&strata(&[
            "sweep",
            s(&sw),
            "--out",
            s(&sh),
            "--shard",
            i,
            "--keep-going",
        ]));
    }
    let merged = dir.join("merged.csv");
    let e = ok(&strata(&["sweep", "merge", s(&sh), "--out", s(&merged)]));
    assert!(e.contains("failed"), "{e}");
    assert_eq!(std::fs::read_to_string(&merged).unwrap(), csv);
}

/// The shipped bandwidth study enumerates the paper's 240 cases in the documented
/// order; on the shipped family table, a swept E2/E1 = 5 case equals `strata solve`
/// of the shipped E2/E1 = 5 stack.
#[test]
fn bandwidth_study_and_table_stacks() {
    let bw = root().join("sweeps/bandwidth.toml");
    let o = strata(&["sweep", s(&bw), "--list"]);
    ok(&o);
    let text = String::from_utf8(o.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "case,model.kind,stack.modulus_ratio,surface.k_max,surface.seed"
    );
    assert_eq!(lines.len(), 241);
    assert_eq!(lines[1], "0,independent,1,10,1");
    assert_eq!(lines[240], "239,interacting,5,40,20");
    let o = strata(&["sweep", s(&bw), "--list", "--shard", "3/8"]);
    let text = String::from_utf8(o.stdout).unwrap();
    assert_eq!(text.lines().count(), 1 + 30);
    assert!(
        text.lines()
            .skip(1)
            .all(|l| l.split(',').next().unwrap().parse::<usize>().unwrap() % 8 == 2)
    );

    let dir = tmp("table");
    let stacks = root().join("tables/stacks");
    let table = root().join("tables/paper-two-layer.strata");
    let base = BASE
        .replace(
            "[scene.stack]\n[[scene.stack.layer]]\nthickness = 1e-3\nyoung = 4e9\npoisson = 0.15\n[scene.stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n",
            &format!(
                "[scene.stack]\nfile = \"{}\"\ntable = \"{}\"\n",
                stacks.join("paper-two-layer-E2E1-1.toml").display(),
                table.display()
            ),
        );
    assert!(base.contains("paper-two-layer-E2E1-1.toml"));
    let sw = write_sweep(
        &dir,
        "sweep.toml",
        &format!("{base}[sweep]\nstack.modulus_ratio = [1, 5]\n"),
    );
    let out = dir.join("out");
    ok(&strata(&["sweep", s(&sw), "--out", s(&out), "--no-plots"]));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let scene = BASE
        .replace("title = \"test sweep\"\n", "")
        .replace("[scene.", "[")
        .replace("[[scene.", "[[")
        .replace(
            "[stack]\n[[stack.layer]]\nthickness = 1e-3\nyoung = 4e9\npoisson = 0.15\n[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n",
            &format!(
                "[stack]\nfile = \"{}\"\ntable = \"{}\"\n",
                stacks.join("paper-two-layer.toml").display(),
                table.display()
            ),
        );
    assert!(scene.contains("paper-two-layer.toml"));
    let sc = dir.join("scene.toml");
    std::fs::write(&sc, scene).unwrap();
    let single = dir.join("single");
    ok(&strata(&[
        "solve",
        s(&sc),
        "--out",
        s(&single),
        "--no-plots",
    ]));
    let curve = std::fs::read_to_string(single.join("curve.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().filter(|l| l.starts_with("1,5,")).collect();
    assert_eq!(rows.len(), 3);
    for (row, c) in rows.iter().zip(curve.lines().skip(1)) {
        assert!(row.ends_with(&format!(",{c}")), "{row} vs {c}");
    }
    // and E2/E1 = 1 differs from E2/E1 = 5 (the axis acts)
    let p = |case: &str| -> f64 {
        csv.lines()
            .find(|l| l.starts_with(case))
            .unwrap()
            .split(',')
            .nth(6)
            .unwrap()
            .parse()
            .unwrap()
    };
    assert!(p("1,5,independent,2,") > 1.05 * p("0,1,independent,2,"));
}

/// A shard is merged only as its run wrote it (row count and FNV-1a checksum in the
/// sidecar), and only with shards run against the same physics (the fingerprint hashes
/// the content of the stack file the base scene reads): a last row cut short, two
/// dropped rows and a stack file changed between shards are refused, naming the file.
#[test]
fn merge_refuses_truncated_cut_and_physics_changed_shards() {
    let dir = tmp("merge-damage");
    let stack = dir.join("stack.toml");
    let half_space = |e: &str| {
        std::fs::write(
            &stack,
            format!("[base]\nkind = \"elastic\"\nyoung = {e}\npoisson = 0.15\n"),
        )
        .unwrap()
    };
    half_space("4e9");
    let base = BASE.replace(
        "[scene.stack]\n[[scene.stack.layer]]\nthickness = 1e-3\nyoung = 4e9\npoisson = 0.15\n[scene.stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n",
        "[scene.stack]\nfile = \"stack.toml\"\n",
    );
    assert!(base.contains("file = \"stack.toml\""));
    let sw = write_sweep(&dir, "sweep.toml", &format!("{base}{AXES}"));
    let shards = |out: &Path| {
        for i in ["1/2", "2/2"] {
            ok(&strata(&["sweep", s(&sw), "--out", s(out), "--shard", i]));
        }
    };
    let merge = |d: &Path| strata(&["sweep", "merge", s(d), "--out", s(&d.join("m.csv"))]);
    // Intact shards merge.
    let good = dir.join("good");
    shards(&good);
    ok(&merge(&good));
    // The last row's last number cut to a prefix (`3.102e-3,1` → `3.102,1`, the
    // `valid` column kept: the row still parses).
    let cut = dir.join("cut");
    shards(&cut);
    let f = cut.join("shard-1-of-2.csv");
    let text = std::fs::read_to_string(&f).unwrap();
    let e_pos = text.trim_end().rfind('e').unwrap();
    let comma = e_pos + text[e_pos..].find(',').unwrap();
    std::fs::write(
        &f,
        format!("{}{}", &text[..e_pos], text[comma..].trim_end()),
    )
    .unwrap();
    let e = fails(&merge(&cut));
    assert!(
        e.contains("shard-1-of-2.csv") && e.contains("checksum"),
        "{e}"
    );
    assert!(!cut.join("m.csv").exists());
    // Two rows dropped.
    let dropped = dir.join("dropped");
    shards(&dropped);
    let f = dropped.join("shard-2-of-2.csv");
    let text = std::fs::read_to_string(&f).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let kept: Vec<&str> = lines
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != 3 && *i != 4)
        .map(|(_, l)| *l)
        .collect();
    std::fs::write(&f, kept.join("\n") + "\n").unwrap();
    let e = fails(&merge(&dropped));
    assert!(
        e.contains("shard-2-of-2.csv") && e.contains(&format!("has {} rows", lines.len() - 3)),
        "{e}"
    );
    // The stack file changed between the shards (same sweep and scene files).
    let physics = dir.join("physics");
    ok(&strata(&[
        "sweep",
        s(&sw),
        "--out",
        s(&physics),
        "--shard",
        "1/2",
    ]));
    half_space("5e9");
    ok(&strata(&[
        "sweep",
        s(&sw),
        "--out",
        s(&physics),
        "--shard",
        "2/2",
    ]));
    let e = fails(&merge(&physics));
    assert!(e.contains("different sweep") && e.contains("stack"), "{e}");
    half_space("4e9");
}

/// A sweep of capped N-model cases (`[plasticity]`) builds the capped asperity's response
/// table once, before the parallel part, into the table cache (one `capped-*.strata`,
/// the log says so once); every case equals its own `strata solve` reading the cache.
#[test]
fn capped_cases_share_one_response_table() {
    let dir = tmp("capped");
    let cache = dir.join("cache");
    let text = format!(
        "{BASE}[scene.plasticity]\nhardness = 0.2e9\n[sweep]\nsurface.seed = {{ from = 1, count = 4 }}\n"
    );
    let sw = write_sweep(&dir, "sweep.toml", &text);
    let out = dir.join("out");
    let err = ok(&strata(&[
        "sweep",
        s(&sw),
        "--out",
        s(&out),
        "--no-plots",
        "--threads",
        "2",
        "--cache-dir",
        s(&cache),
    ]));
    assert_eq!(
        err.matches("response table built (ring solves").count(),
        1,
        "{err}"
    );
    let files: Vec<String> = std::fs::read_dir(&cache)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        files.len() == 1 && files[0].starts_with("capped-"),
        "{files:?}"
    );
    // a second sweep reads it
    let err = ok(&strata(&[
        "sweep",
        s(&sw),
        "--out",
        s(&dir.join("out2")),
        "--no-plots",
        "--cache-dir",
        s(&cache),
    ]));
    assert!(
        err.contains("response table read from the table cache"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("sweep.csv")).unwrap(),
        std::fs::read_to_string(dir.join("out2/sweep.csv")).unwrap()
    );
}

/// The effects a scene runs reach sweep.csv as they reach curve.csv: a conducting
/// scene's sweep carries `conductance`, a capped scene's `plastic_area_fraction`, after
/// `valid`, equal to `strata solve`'s columns for the same case (they were dropped).
#[test]
fn sweeps_carry_the_conductance_and_plastic_columns_of_solve() {
    let d = tmp("effects");
    let scene = |extra: &str| {
        format!(
            "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
             thermal_conductivity = 0.5\n\
             [counterface]\nkind = \"rigid\"\nthermal_conductivity = 50\n\
             [surface]\nperiodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 64\n\
             fractal_dimension = 2.4\nk_min = 2\nk_max = 10\nrms = 3.4e-6\nseed = 5\n\
             [model]\nkind = \"independent\"\n\
             [load]\napproach = {{ from = 1e-6, to = 6e-6, steps = 4 }}\n{extra}"
        )
    };
    for (name, extra, column, absent) in [
        (
            "conducting",
            "[conductance]\nkind = \"thermal\"\n",
            "conductance",
            "plastic_area_fraction",
        ),
        (
            "capped",
            "[plasticity]\nhardness = 0.2e9\n",
            "plastic_area_fraction",
            "conductance",
        ),
    ] {
        let sc = d.join(format!("{name}.toml"));
        std::fs::write(&sc, scene(extra)).unwrap();
        let sw = d.join(format!("{name}-sweep.toml"));
        std::fs::write(
            &sw,
            format!("scene = \"{name}.toml\"\n[sweep]\nsurface.seed = [5, 6]\n"),
        )
        .unwrap();
        let out = d.join(format!("{name}-out"));
        let cache = d.join("cache");
        ok(&strata(&[
            "sweep",
            s(&sw),
            "--out",
            s(&out),
            "--no-plots",
            "--cache-dir",
            s(&cache),
        ]));
        let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
        let head: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        assert_eq!(head.last(), Some(&column), "{name}: {head:?}");
        assert!(!head.contains(&absent), "{name}: {head:?}");
        let solved = d.join(format!("{name}-solve"));
        ok(&strata(&[
            "solve",
            s(&sc),
            "--out",
            s(&solved),
            "--no-plots",
            "--cache-dir",
            s(&cache),
        ]));
        let curve = std::fs::read_to_string(solved.join("curve.csv")).unwrap();
        let want: Vec<&str> = curve
            .lines()
            .skip(1)
            .map(|l| l.rsplit(',').next().unwrap())
            .collect();
        let got: Vec<&str> = csv
            .lines()
            .skip(1)
            .filter(|l| l.starts_with("0,"))
            .map(|l| l.rsplit(',').next().unwrap())
            .collect();
        assert_eq!(got.len(), 4, "{name}");
        assert_eq!(got, want, "{name}");
        assert!(
            got.iter().any(|v| v.parse::<f64>().is_ok_and(|x| x > 0.0)),
            "{name}: {got:?}"
        );
    }
}
