//! Output sets replaced as a whole: `solve`, `law --format all` and
//! `table build` killed (SIGKILL) at every output file of their write phase and inside
//! their commit, a disk that fills up, and two writers on one directory. After each,
//! the target holds the complete previous set or the complete new one, nothing else,
//! and the next run is not blocked by debris.
//!
//! The kill points come from the test hook `STRATA_TEST_KILL_AT=write:K|commit:K`
//! (`strata::output_set`).

use std::collections::BTreeMap;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::Output;

use crate::support::{fresh_dir, snapshot, stderr_of, strata_in};

type Set = BTreeMap<String, Vec<u8>>;

fn dir(name: &str) -> PathBuf {
    fresh_dir("outputs", name)
}

fn run(cache: &Path, args: &[&str], kill: Option<&str>) -> Output {
    let mut c = strata_in(cache);
    c.args(args);
    if let Some(k) = kill {
        c.env("STRATA_TEST_KILL_AT", k);
    }
    c.output().expect("run strata")
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", stderr_of(o));
}

fn killed(o: &Output, point: &str) {
    assert_eq!(
        o.status.signal(),
        Some(9),
        "{point}: expected SIGKILL, got {:?}: {}",
        o.status,
        stderr_of(o)
    );
}

/// The same set: the same files, byte for byte, except curve.json, whose timing
/// differs between runs: there the steps must agree.
fn same_set(a: &Set, b: &Set) -> bool {
    a.keys().eq(b.keys())
        && a.iter().all(|(k, v)| {
            if k.ends_with("curve.json") {
                let steps = |x: &[u8]| -> serde_json::Value {
                    serde_json::from_slice::<serde_json::Value>(x)
                        .map(|j| j["steps"].clone())
                        .unwrap_or(serde_json::Value::Null)
                };
                steps(v) == steps(&b[k]) && !steps(v).is_null()
            } else {
                *v == b[k]
            }
        })
}

fn names(s: &Set) -> Vec<&String> {
    s.keys().collect()
}

/// No staging or backup directory beside `target` (the lock file may stay).
fn no_debris_beside(target: &Path) {
    let parent = target.parent().expect("parent");
    for e in std::fs::read_dir(parent).unwrap().filter_map(|e| e.ok()) {
        let n = e.file_name().to_string_lossy().into_owned();
        assert!(
            !n.ends_with(".strata-new") && !n.ends_with(".strata-old"),
            "debris beside {}: {n}",
            target.display()
        );
    }
}

/// A 64² generated surface on a homogeneous half-space.
fn scene(d: &Path, name: &str, kind: &str, load: &str, output: &str) -> PathBuf {
    let text = format!(
        "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
         [surface]\nperiodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 64\n\
         fractal_dimension = 2.4\nk_min = 2\nk_max = 8\nrms = 3.4e-6\nseed = 3\n\
         [model]\nkind = \"{kind}\"\n[load]\n{load}\n{output}\n"
    );
    let p = d.join(name);
    std::fs::write(&p, text).expect("scene");
    p
}

/// `solve` (BEM with maps): killed at each of the 9 output files of the new set and at
/// the 3 commit steps, the directory holds the old set (write kills, commit 1–2) or
/// the new one (commit 3: after the swap), never a mix; the new set drops the old
/// set's stale maps; no debris blocks the next run.
#[test]
fn killed_solve_leaves_the_old_or_the_new_set() {
    let d = dir("solve");
    let cache = d.join("cache");
    let old_sc = scene(
        &d,
        "old.toml",
        "bem",
        "separations = [6e-6, 4.5e-6, 3e-6]",
        "[output]\nmaps = \"all\"",
    );
    let new_sc = scene(
        &d,
        "new.toml",
        "bem",
        "separations = [5e-6, 3.5e-6]",
        "[output]\nmaps = \"last\"",
    );
    let out = d.join("out");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let solve = |sc: &Path, target: &Path, kill: Option<&str>| {
        run(
            &cache,
            &["solve", &s(sc), "--out", &s(target), "--force"],
            kill,
        )
    };
    // The reference sets.
    let reference_new = d.join("reference-new");
    ok(&solve(&new_sc, &reference_new, None));
    let new = snapshot(&reference_new);
    ok(&solve(&old_sc, &out, None));
    let old = snapshot(&out);
    assert!(
        old.contains_key("maps/pressure_step_00.npy"),
        "{:?}",
        names(&old)
    );
    assert!(
        !new.contains_key("maps/pressure_step_00.npy"),
        "{:?}",
        names(&new)
    );
    assert!(
        new.contains_key("maps/pressure_step_01.png"),
        "{:?}",
        names(&new)
    );
    // 9 files: 4 maps + maps.csv, curve.csv, curve.json and 2 plots.
    assert_eq!(new.len(), 10, "{:?}", names(&new)); // + the manifest
    let mut points: Vec<String> = (1..=9).map(|k| format!("write:{k}")).collect();
    points.extend((1..=3).map(|k| format!("commit:{k}")));
    for point in &points {
        let o = solve(&new_sc, &out, Some(point));
        killed(&o, point);
        let now = snapshot(&out);
        if point == "commit:3" {
            assert!(same_set(&now, &new), "{point}: {:?}", names(&now));
            ok(&solve(&old_sc, &out, None)); // back to the old set
        } else {
            assert!(same_set(&now, &old), "{point}: {:?}", names(&now));
        }
    }
    // The next run is not blocked and replaces the set as a whole.
    ok(&solve(&new_sc, &out, None));
    assert!(same_set(&snapshot(&out), &new));
    no_debris_beside(&out);
}

/// `law --format all` (three files in a shared directory): killed at each file and
/// before the first rename, the three old files are intact; killed between the
/// renames (commit 2, 3), the next run on the same output completes the commit from
/// its journal before anything else, so the three files are the new set.
#[test]
fn killed_law_all_leaves_the_old_or_the_new_set() {
    let d = dir("law");
    let cache = d.join("cache");
    let sc = scene(
        &d,
        "scene.toml",
        "independent",
        "approach = { from = 1e-6, to = 6e-6, steps = 4 }",
        "",
    );
    let out = d.join("laws");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let stem = out.join("law");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let law = |samples: &str, force: bool, kill: Option<&str>| {
        let mut args = vec![
            "law".to_string(),
            s(&sc),
            "--out".into(),
            s(&stem),
            "--format".into(),
            "all".into(),
            "--samples".into(),
            samples.into(),
        ];
        if force {
            args.push("--force".into());
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        run(&cache, &args, kill)
    };
    let files = |snap: &Set| -> Set {
        snap.iter()
            .filter(|(k, _)| k.starts_with("law."))
            .map(|(k, v)| (k.clone(), v.clone()))
            .collect()
    };
    ok(&law("80", true, None));
    let new = files(&snapshot(&out));
    ok(&law("50", true, None));
    let old = files(&snapshot(&out));
    assert_eq!(old.len(), 3);
    assert_ne!(old, new);
    for point in ["write:1", "write:2", "write:3", "commit:1"] {
        killed(&law("80", true, Some(point)), point);
        assert_eq!(files(&snapshot(&out)), old, "{point}");
    }
    for point in ["commit:2", "commit:3"] {
        killed(&law("80", true, Some(point)), point);
        // Between the renames: the journal is there; the next run (here one that stops
        // at once, the files existing without --force) completes the new set first.
        let o = law("50", false, None);
        assert!(!o.status.success());
        assert!(stderr_of(&o).contains("--force"), "{}", stderr_of(&o));
        assert_eq!(files(&snapshot(&out)), new, "{point}");
        ok(&law("50", true, None));
        assert_eq!(files(&snapshot(&out)), old);
    }
    ok(&law("80", true, None));
    assert_eq!(files(&snapshot(&out)), new);
    assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"mine");
    no_debris_beside(&stem);
}

/// `table build`: refuses an existing file without --force; killed while writing or
/// before the rename, the old table is intact; the next run writes the new one, byte
/// for byte the table of a clean run (SOURCE_DATE_EPOCH fixed).
#[test]
fn killed_table_build_leaves_the_old_or_the_new_table() {
    let d = dir("table");
    let cache = d.join("cache");
    let stack = crate::support::repo().join("tables/stacks/paper-two-layer.toml");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let build = |out: &Path, nx: &str, force: bool, kill: Option<&str>| {
        let mut c = strata_in(&cache);
        c.env("SOURCE_DATE_EPOCH", "1700000000").args([
            "table",
            "build",
            &s(&stack),
            "--out",
            &s(out),
            "--nx",
            nx,
            "--nw",
            "6",
            "--check-points",
            "0",
        ]);
        if force {
            c.arg("--force");
        }
        if let Some(k) = kill {
            c.env("STRATA_TEST_KILL_AT", k);
        }
        c.output().expect("run strata")
    };
    let reference = d.join("reference.strata");
    ok(&build(&reference, "9", false, None));
    let new = std::fs::read(&reference).unwrap();
    let table = d.join("t.strata");
    ok(&build(&table, "7", false, None));
    let old = std::fs::read(&table).unwrap();
    assert_ne!(old, new);
    let o = build(&table, "9", false, None);
    assert!(!o.status.success());
    assert!(stderr_of(&o).contains("--force"), "{}", stderr_of(&o));
    assert_eq!(std::fs::read(&table).unwrap(), old);
    for point in ["write:1", "commit:1"] {
        killed(&build(&table, "9", true, Some(point)), point);
        assert_eq!(std::fs::read(&table).unwrap(), old, "{point}");
    }
    ok(&build(&table, "9", true, None));
    assert_eq!(std::fs::read(&table).unwrap(), new);
    no_debris_beside(&table);
}

/// Two `solve`s started together into one empty directory: one succeeds, the other
/// fails at once naming the directory and the lock; the result is one complete set.
#[test]
fn concurrent_solves_one_wins_one_fails_clearly() {
    let d = dir("concurrent");
    let cache = d.join("cache");
    let surface = crate::support::repo().join("tests/reference/surface_km10.npy");
    let sc = d.join("bem.toml");
    std::fs::write(
        &sc,
        format!(
            "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
             [surface]\nfile = \"{}\"\nsize = 1e-3\nperiodic = true\n[model]\nkind = \"bem\"\n\
             [load]\nseparations = [7e-6, 5e-6]\n",
            surface.display()
        ),
    )
    .unwrap();
    for trial in 0..3 {
        let out = d.join(format!("out-{trial}"));
        let spawn = || {
            strata_in(&cache)
                .args([
                    "solve",
                    sc.to_str().unwrap(),
                    "--out",
                    out.to_str().unwrap(),
                ])
                .stderr(std::process::Stdio::piped())
                .stdout(std::process::Stdio::null())
                .spawn()
                .expect("spawn")
        };
        let (a, b) = (spawn(), spawn());
        let outs = [a.wait_with_output().unwrap(), b.wait_with_output().unwrap()];
        let wins = outs.iter().filter(|o| o.status.success()).count();
        assert_eq!(
            wins,
            1,
            "trial {trial}: {}",
            outs.iter()
                .map(stderr_of)
                .collect::<Vec<_>>()
                .join("\n---\n")
        );
        let loser = outs.iter().find(|o| !o.status.success()).unwrap();
        let e = stderr_of(loser);
        assert!(
            e.contains("another strata process is writing") && e.contains(&format!("out-{trial}")),
            "{e}"
        );
        let set = snapshot(&out);
        assert_eq!(
            names(&set),
            [
                ".strata-set",
                "area_pressure.svg",
                "curve.csv",
                "curve.json",
                "pressure_gap.svg"
            ]
        );
        no_debris_beside(&out);
    }
}

/// A disk that fills up while `solve --force` writes its new set: exit 1 with the
/// system's message, the old set intact, no staging left; once there is room the next
/// run writes the new set. A small tmpfs in a private mount namespace (`unshare -rm`),
/// filled to leave 0 … 32 KiB; where namespaces are not allowed, a file-size limit
/// (RLIMIT_FSIZE, SIGXFSZ ignored) makes the writes fail instead.
#[test]
fn a_full_disk_leaves_the_old_set() {
    let d = dir("full");
    let cache = d.join("cache");
    let old_sc = scene(
        &d,
        "old.toml",
        "independent",
        "approach = { from = 1e-6, to = 6e-6, steps = 4 }",
        "",
    );
    let new_sc = scene(
        &d,
        "new.toml",
        "independent",
        "approach = { from = 1e-6, to = 7e-6, steps = 9 }",
        "",
    );
    let bin = env!("CARGO_BIN_EXE_strata");
    let results = d.join("results");
    std::fs::create_dir_all(&results).unwrap();
    let script = format!(
        r#"set -u
M={d}/mnt; R={r}; mkdir -p $M
mount -t tmpfs -o size=512k tmpfs $M || exit 77
{bin} solve {old} --out $M/out 2>$R/old.err || exit 78
cp -a $M/out $R/old
for x in 0 4096 8192 16384 32768; do
  avail=$(df --output=avail -B1 $M | tail -1)
  head -c $((avail - x)) /dev/zero > $M/fill 2>/dev/null
  {bin} solve {new} --out $M/out --force 2>$R/err-$x; echo $? > $R/rc-$x
  cp -a $M/out $R/after-$x
  ls -a $M > $R/ls-$x
  rm -f $M/fill
done
{bin} solve {new} --out $M/out --force 2>$R/final.err; echo $? > $R/rc-final
cp -a $M/out $R/final
ls -a $M > $R/ls-final
"#,
        d = d.display(),
        r = results.display(),
        old = old_sc.display(),
        new = new_sc.display(),
    );
    let o = std::process::Command::new("unshare")
        .args(["-rm", "sh", "-c", &script])
        .env("STRATA_CACHE_DIR", &cache)
        .env_remove("STRATA_TEST_KILL_AT")
        .output();
    let tmpfs = matches!(&o, Ok(o) if o.status.success());
    if tmpfs {
        eprintln!("full disk: tmpfs of 512 KiB in a private mount namespace");
        let old = snapshot(&results.join("old"));
        assert!(old.contains_key("curve.csv"));
        for x in [0, 4096, 8192, 16384, 32768] {
            let rc = std::fs::read_to_string(results.join(format!("rc-{x}"))).unwrap();
            let err = std::fs::read_to_string(results.join(format!("err-{x}"))).unwrap();
            let after = snapshot(&results.join(format!("after-{x}")));
            let ls = std::fs::read_to_string(results.join(format!("ls-{x}"))).unwrap();
            assert!(!ls.contains("strata-new"), "{x}: staging left: {ls}");
            if rc.trim() == "0" {
                // Enough room after all (the new set fitted): then it is complete.
                assert!(
                    after.contains_key("curve.csv") && !same_set(&after, &old),
                    "{x}"
                );
                continue;
            }
            assert_eq!(rc.trim(), "1", "{x}: {err}");
            assert!(
                err.contains("No space left") && !err.contains("panicked"),
                "{x}: {err}"
            );
            assert!(same_set(&after, &old), "{x}: {:?}", names(&after));
        }
        assert_eq!(
            std::fs::read_to_string(results.join("rc-final"))
                .unwrap()
                .trim(),
            "0"
        );
        let fin = snapshot(&results.join("final"));
        assert!(
            !same_set(&fin, &old) && fin.len() == old.len(),
            "{:?}",
            names(&fin)
        );
        return;
    }
    eprintln!("full disk: no private mount namespace here ({o:?}); using RLIMIT_FSIZE");
    let out = d.join("out");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    ok(&run(
        &cache,
        &["solve", &s(&old_sc), "--out", &s(&out)],
        None,
    ));
    let old = snapshot(&out);
    for limit in [600, 2000, 8000] {
        let o = std::process::Command::new("sh")
            .args([
                "-c",
                &format!(
                    "trap '' XFSZ; exec prlimit --fsize={limit} -- {bin} solve {} --out {} --force",
                    s(&new_sc),
                    s(&out)
                ),
            ])
            .env("STRATA_CACHE_DIR", &cache)
            .output()
            .expect("sh");
        assert_eq!(o.status.code(), Some(1), "{limit}: {}", stderr_of(&o));
        assert!(
            stderr_of(&o).contains("File too large"),
            "{}",
            stderr_of(&o)
        );
        assert!(same_set(&snapshot(&out), &old), "{limit}");
        no_debris_beside(&out);
    }
    ok(&run(
        &cache,
        &["solve", &s(&new_sc), "--out", &s(&out), "--force"],
        None,
    ));
    assert!(!same_set(&snapshot(&out), &old));
}

/// The one-line refusal of an output that is also an input: exit 1,
/// `error: FLAG PATH is also an input of this command (WHAT); choose another path`.
fn refused_as_input(o: &Output, flag: &str, path: &Path, what: &str) {
    let e = stderr_of(o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert_eq!(
        e,
        format!(
            "error: {flag} {} is also an input of this command ({what}); choose another path\n",
            path.display()
        )
    );
}

/// `law`, `surface export`, `solve` and `compare` refuse, even with `--force` and before
/// any work, an output that is one of their inputs: the scene, a file it names (stack
/// file, surface file; `table build` and `asperity`: the stack file), spelled with `./` or reached through a symbolic link; the input
/// is left byte for byte (`law d/s.toml --out d/s.toml --force` once overwrote the
/// scene).
#[test]
fn an_output_that_is_an_input_is_refused() {
    let d = dir("inputs");
    let cache = d.join("cache");
    let stack = d.join("stack.toml");
    std::fs::write(
        &stack,
        "[base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n",
    )
    .unwrap();
    let generated = scene(&d, "gen.toml", "independent", "separations = [3e-6]", "");
    let npy = d.join("surf.npy");
    ok(&run(
        &cache,
        &[
            "surface",
            "export",
            generated.to_str().unwrap(),
            "--out",
            npy.to_str().unwrap(),
        ],
        None,
    ));
    let sc = d.join("s.toml");
    std::fs::write(
        &sc,
        "[stack]\nfile = \"stack.toml\"\n[surface]\nfile = \"surf.npy\"\nsize = 1e-3\n\
         periodic = true\n[model]\nkind = \"independent\"\n[load]\nseparations = [3e-6]\n",
    )
    .unwrap();
    let before = snapshot(&d);
    let s = sc.to_str().unwrap();
    let dotted = d.join(".").join("s.toml");
    let link = d.join("link.csv");
    std::os::unix::fs::symlink(&sc, &link).unwrap();
    let cases: Vec<(Vec<&str>, &Path, &str)> = vec![
        (vec!["law", s, "--format", "csv"], &sc, "the scene"),
        (vec!["law", s, "--format", "csv"], &dotted, "the scene"),
        (vec!["law", s], &link, "the scene"),
        (
            vec!["law", s, "--format", "csv"],
            &stack,
            "the scene's stack file",
        ),
        (
            vec!["surface", "export", s],
            &npy,
            "the scene's surface file",
        ),
        (vec!["solve", s], &sc, "the scene"),
        (vec!["compare", s], &sc, "the scene"),
    ];
    for (args, out, what) in &cases {
        let mut all = args.clone();
        all.extend(["--force", "--out", out.to_str().unwrap()]);
        refused_as_input(&run(&cache, &all, None), "--out", out, what);
    }
    // Commands that read a stack file on the command line.
    let st = stack.to_str().unwrap();
    let o = run(
        &cache,
        &["table", "build", st, "--force", "--out", st],
        None,
    );
    refused_as_input(&o, "--out", &stack, "the stack file");
    let args = ["asperity", st, "--radius", "1e-4", "--delta", "1e-7"];
    let o = run(
        &cache,
        &[&args[..], &["--force", "--profile", st]].concat(),
        None,
    );
    refused_as_input(&o, "--profile", &stack, "the stack file");
    // Nothing written, not even a lock file: every input byte for byte as it was.
    std::fs::remove_file(&link).unwrap();
    let files = |s: Set| -> Set {
        s.into_iter()
            .filter(|(k, _)| !k.starts_with("cache/"))
            .collect()
    };
    assert_eq!(files(snapshot(&d)), files(before));
}

/// An output directory may hold the command's inputs that the user put there (kept by
/// `--force`), not ones the previous set's manifest says strata wrote there (`--force`
/// would replace or remove them).
#[test]
fn inputs_inside_an_output_directory() {
    let d = dir("inputs-dir");
    let cache = d.join("cache");
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let stack = "[base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n";
    std::fs::write(out.join("mine.toml"), stack).unwrap();
    std::fs::write(out.join("theirs.toml"), stack).unwrap();
    std::fs::write(
        out.join(".strata-set"),
        "# strata output set\ntheirs.toml\n",
    )
    .unwrap();
    let scene_with = |name: &str, stack_file: &str| {
        let p = d.join(name);
        std::fs::write(
            &p,
            format!(
                "[stack]\nfile = \"{stack_file}\"\n[surface]\nperiodic = true\n\
                 [surface.generate]\nsize = 1e-3\ngrid = 32\nfractal_dimension = 2.4\n\
                 k_min = 2\nk_max = 8\nrms = 3.4e-6\nseed = 3\n\
                 [model]\nkind = \"independent\"\n[load]\nseparations = [3e-6]\n"
            ),
        )
        .unwrap();
        p
    };
    let theirs = scene_with("theirs.toml", "out/theirs.toml");
    let o = run(
        &cache,
        &[
            "solve",
            theirs.to_str().unwrap(),
            "--no-plots",
            "--force",
            "--out",
            out.to_str().unwrap(),
        ],
        None,
    );
    refused_as_input(&o, "--out", &out, "the scene's stack file");
    assert_eq!(
        std::fs::read_to_string(out.join("theirs.toml")).unwrap(),
        stack
    );
    let mine = scene_with("mine.toml", "out/mine.toml");
    ok(&run(
        &cache,
        &[
            "solve",
            mine.to_str().unwrap(),
            "--no-plots",
            "--force",
            "--out",
            out.to_str().unwrap(),
        ],
        None,
    ));
    assert_eq!(
        std::fs::read_to_string(out.join("mine.toml")).unwrap(),
        stack
    );
    assert!(out.join("curve.csv").is_file());
}

/// A 32² BEM scene on a half-space whose load path `separations` is given; the fifth
/// separation of [`FAILING`] is negative: on an elastic base a periodic cell's approach
/// must stay below z_M − z̄, so the BEM refuses that step and only that step.
fn bem_scene(d: &Path, name: &str, separations: &str) -> PathBuf {
    let p = d.join(name);
    std::fs::write(
        &p,
        format!(
            "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 4e9\npoisson = 0.15\n\
             [surface]\nperiodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 32\n\
             fractal_dimension = 2.4\nk_min = 2\nk_max = 8\nrms = 3.4e-6\nseed = 5\n\
             [model]\nkind = \"bem\"\n[load]\nseparations = {separations}\n"
        ),
    )
    .unwrap();
    p
}

const FIRST_FOUR: &str = "[6e-6, 5e-6, 4e-6, 3e-6]";
const FAILING: &str = "[6e-6, 5e-6, 4e-6, 3e-6, -1e-3, 2e-6]";

/// A BEM run whose fifth step fails leaves the four converged steps as a partial curve
/// (it discarded them all), equal to the rows of a run of those four steps, with the
/// `partial` column in curve.csv and the failed step in curve.json; exit status 1.
#[test]
fn a_bem_run_whose_fifth_step_fails_leaves_the_first_four() {
    let d = dir("bem-partial");
    let four = bem_scene(&d, "four.toml", FIRST_FOUR);
    let failing = bem_scene(&d, "failing.toml", FAILING);
    let (a, b) = (d.join("a"), d.join("b"));
    let go = |s: &Path, o: &Path| {
        run(
            &d,
            &[
                "solve",
                s.to_str().unwrap(),
                "--out",
                o.to_str().unwrap(),
                "--no-plots",
            ],
            None,
        )
    };
    ok(&go(&four, &a));
    let o = go(&failing, &b);
    let e = stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("load step 4") && e.contains("partial curve"),
        "{e}"
    );
    let whole = std::fs::read_to_string(a.join("curve.csv")).unwrap();
    let part = std::fs::read_to_string(b.join("curve.csv")).unwrap();
    let mut lines = part.lines();
    assert_eq!(
        lines.next().unwrap(),
        format!("{},partial", whole.lines().next().unwrap())
    );
    let rows: Vec<String> = lines.map(String::from).collect();
    let want: Vec<String> = whole.lines().skip(1).map(|l| format!("{l},1")).collect();
    assert_eq!(rows, want);
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(b.join("curve.json")).unwrap()).unwrap();
    assert_eq!(j["partial"]["failed_step"], 4, "{j}");
    assert_eq!(j["steps"].as_array().unwrap().len(), 4);
    // a complete curve has no `partial` column
    assert!(!whole.lines().next().unwrap().contains("partial"));
}

/// A failing run with `--force` on a directory holding an earlier complete set leaves
/// that set byte for byte (it was replaced by the partial curve, marked only in
/// curve.json); the error says so. An earlier partial set is replaced as before.
#[test]
fn a_failing_forced_run_leaves_an_earlier_complete_set_as_it_was() {
    let d = dir("force-partial");
    let four = bem_scene(&d, "four.toml", FIRST_FOUR);
    let failing = bem_scene(&d, "failing.toml", FAILING);
    let out = d.join("out");
    let o = out.to_str().unwrap();
    ok(&run(
        &d,
        &["solve", four.to_str().unwrap(), "--out", o, "--no-plots"],
        None,
    ));
    let before = snapshot(&out);
    let r = run(
        &d,
        &[
            "solve",
            failing.to_str().unwrap(),
            "--out",
            o,
            "--no-plots",
            "--force",
        ],
        None,
    );
    let e = stderr_of(&r);
    assert_eq!(r.status.code(), Some(1), "{e}");
    assert!(
        e.contains("complete results of an earlier run, which are kept"),
        "{e}"
    );
    assert_eq!(snapshot(&out), before);
    // over a partial set, a partial set is written (nothing complete is lost)
    let p = d.join("p");
    let ps = p.to_str().unwrap();
    let args = [
        "solve",
        failing.to_str().unwrap(),
        "--out",
        ps,
        "--no-plots",
        "--force",
    ];
    assert_eq!(run(&d, &args, None).status.code(), Some(1));
    let first = std::fs::read(p.join("curve.csv")).unwrap();
    assert_eq!(run(&d, &args, None).status.code(), Some(1));
    assert_eq!(std::fs::read(p.join("curve.csv")).unwrap(), first);
    assert!(String::from_utf8(first).unwrap().starts_with("delta,"));
}
