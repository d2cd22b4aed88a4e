//! The cluster guide's batch scripts (docs/cluster/), run as SLURM would run them: a
//! stand-in `sbatch` on PATH runs each submitted script at once with the variables of
//! an allocation (each task of an `--array` in turn, `SLURM_ARRAY_TASK_ID`,
//! `SLURM_ARRAY_TASK_COUNT`, `SLURM_NTASKS`, `SLURM_CPUS_PER_TASK`), and a stand-in
//! `srun` starts the command once, or under `mpirun` with `SLURM_NTASKS` ranks when the
//! `strata` under test is linked with MPI (`--features mpi`) and `mpirun` is installed.
//! The docs test (tests/it/docs.rs) checks the scripts' paths and command lines.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::support::{fresh_dir, repo};

/// `sbatch` for the tests: runs the batch script at once, in the caller's directory,
/// its output to `$SHIM_STATE/job-ID.log` as SLURM's `--output`. A job whose
/// `--dependency=afterok:…` names a job that did not succeed is refused.
const SBATCH: &str = r#"#!/bin/bash
set -euo pipefail
parsable=; array=; deps=; ntasks=
while [ $# -gt 0 ]; do
    case "$1" in
        --parsable) parsable=1 ;;
        --array=*) array=${1#--array=} ;;
        --dependency=*) deps=${1#--dependency=} ;;
        --ntasks=*) ntasks=${1#--ntasks=} ;;
        -*) ;;
        *) break ;;
    esac
    shift
done
script=$1
shift
directive() { sed -n "s/^#SBATCH --$1=//p" "$script" | head -1; }
[ -n "$array" ] || array=$(directive array)
if [ -z "$ntasks" ]; then
    ntasks=$(directive ntasks)
    if [ -z "$ntasks" ]; then
        nodes=$(directive nodes)
        per_node=$(directive ntasks-per-node)
        ntasks=$(( ${nodes:-1} * ${per_node:-1} ))
    fi
fi
jid=$(( $(cat "$SHIM_STATE/jobs" 2>/dev/null || echo 100) + 1 ))
echo "$jid" >"$SHIM_STATE/jobs"
if [ -n "$deps" ]; then
    IFS=: read -r -a ids <<<"${deps#afterok:}"
    for d in "${ids[@]}"; do
        grep -qx "$d ok" "$SHIM_STATE/done" || { echo "sbatch: dependency $d not satisfied" >&2; exit 1; }
    done
fi
log="$SHIM_STATE/job-$jid.log"
export SLURM_NTASKS=$ntasks SLURM_CPUS_PER_TASK=1 SLURM_SUBMIT_DIR=$PWD
if [ -n "$array" ]; then
    lo=${array%%-*}; hi=${array#*-}; hi=${hi%%%*}
    for ((i = lo; i <= hi; i++)); do
        echo "== task $i of $lo-$hi" >>"$log"
        SLURM_JOB_ID=$((jid * 1000 + i)) SLURM_ARRAY_JOB_ID=$jid SLURM_ARRAY_TASK_ID=$i \
            SLURM_ARRAY_TASK_COUNT=$((hi - lo + 1)) SLURM_ARRAY_TASK_MIN=$lo SLURM_ARRAY_TASK_MAX=$hi \
            bash "$script" "$@" >>"$log" 2>&1 || { echo "sbatch: job $jid task $i failed (see $log)" >&2; exit 1; }
    done
else
    SLURM_JOB_ID=$jid bash "$script" "$@" >>"$log" 2>&1 || { echo "sbatch: job $jid failed (see $log)" >&2; exit 1; }
fi
echo "$jid ok" >>"$SHIM_STATE/done"
if [ -n "$parsable" ]; then echo "$jid"; else echo "Submitted batch job $jid"; fi
"#;

/// `srun` for the tests: its options dropped, the command started once, or under
/// `mpirun` with SLURM_NTASKS ranks when SHIM_MPIRUN is set.
const SRUN: &str = r#"#!/bin/bash
set -euo pipefail
while [ $# -gt 0 ] && [ "${1#-}" != "$1" ]; do shift; done
if [ -n "${SHIM_MPIRUN:-}" ]; then
    echo "srun: mpirun -np ${SLURM_NTASKS:-1} $*"
    exec mpirun --allow-run-as-root --oversubscribe -np "${SLURM_NTASKS:-1}" "$@"
fi
echo "srun: $*"
exec "$@"
"#;

/// A directory of stand-ins (`sbatch`, `srun`, and `strata`, the binary under test)
/// and the state of the fake scheduler.
struct Cluster {
    bin: PathBuf,
    state: PathBuf,
    mpi: bool,
}

impl Cluster {
    fn new(dir: &Path) -> Self {
        use std::os::unix::fs::PermissionsExt;
        let bin = dir.join("bin");
        let state = dir.join("slurm");
        std::fs::create_dir_all(&bin).unwrap();
        std::fs::create_dir_all(&state).unwrap();
        for (name, text) in [("sbatch", SBATCH), ("srun", SRUN)] {
            let p = bin.join(name);
            std::fs::write(&p, text).unwrap();
            std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
        }
        std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_strata"), bin.join("strata")).unwrap();
        // A strata linked with an MPI library runs its ranks under mpirun.
        let linked_mpi = Command::new("ldd")
            .arg(env!("CARGO_BIN_EXE_strata"))
            .output()
            .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains("libmpi"));
        let mpirun = Command::new("mpirun").arg("--version").output().is_ok();
        Cluster {
            bin,
            state,
            mpi: linked_mpi && mpirun,
        }
    }

    /// Runs `bash SCRIPT ARGS` in `cwd` with the stand-ins first on PATH.
    fn run(&self, cwd: &Path, script: &Path, args: &[&OsStr], env: &[(&str, &str)]) -> Output {
        let path = format!(
            "{}:{}",
            self.bin.display(),
            std::env::var("PATH").unwrap_or_default()
        );
        let mut c = Command::new("bash");
        c.arg(script)
            .args(args)
            .current_dir(cwd)
            .env("PATH", path)
            .env("SHIM_STATE", &self.state)
            .env("STRATA_CACHE_DIR", self.state.join("cache"))
            .env_remove("STRATA_PROGRESS")
            .env_remove("STRATA_MEMORY_LIMIT")
            .env_remove("RAYON_NUM_THREADS");
        for (k, v) in env {
            c.env(k, v);
        }
        if self.mpi {
            c.env("SHIM_MPIRUN", "1");
        }
        let o = c.output().expect("run bash");
        assert!(
            o.status.success(),
            "{} failed: {}\n{}\nlogs:\n{}",
            script.display(),
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr),
            self.logs()
        );
        o
    }

    fn logs(&self) -> String {
        let mut out = String::new();
        let mut logs: Vec<PathBuf> = std::fs::read_dir(&self.state)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "log"))
            .collect();
        logs.sort();
        for p in logs {
            out.push_str(&format!("--- {}\n", p.display()));
            out.push_str(&std::fs::read_to_string(&p).unwrap_or_default());
        }
        out
    }
}

fn script(name: &str) -> PathBuf {
    let p = repo().join("docs/cluster").join(name);
    assert!(p.is_file(), "{} missing", p.display());
    p
}

/// The largest relative difference between two curve.csv texts (same header and shape)
/// of every column but `stiffness`, and of the stiffness (reported apart: it is a
/// linear solve of its own, the tangent on the contact set).
fn distributed_differences(a: &str, b: &str) -> (f64, f64) {
    let (ha, hb) = (a.lines().next(), b.lines().next());
    assert_eq!(ha, hb, "header");
    let stiffness = ha
        .unwrap()
        .split(',')
        .position(|c| c == "stiffness")
        .unwrap();
    let (ra, rb) = (crate::support::csv_rows(a), crate::support::csv_rows(b));
    assert_eq!(ra.len(), rb.len(), "rows");
    let (mut w, mut ws) = (0.0f64, 0.0f64);
    for (x, y) in ra.iter().zip(&rb) {
        assert_eq!(x.len(), y.len());
        for (k, (u, v)) in x.iter().zip(y).enumerate() {
            let d = (u - v).abs() / u.abs().max(1e-300);
            if k == stiffness {
                ws = ws.max(d);
            } else {
                w = w.max(d);
            }
        }
    }
    (w, ws)
}

/// docs/cluster/submit-sweep.sh submits docs/cluster/sweep.sbatch as an array of 3
/// tasks packing 8 cases (3, 3, 2 per task), then docs/cluster/merge.sbatch after it:
/// the merged CSV is byte for byte the sweep.csv of one unsharded run.
#[test]
fn array_sweep_script_merges_to_the_single_run() {
    let dir = fresh_dir("cluster", "sweep");
    let sweep = dir.join("sweep.toml");
    // the sweep tests' small homogeneous case, over 2 × 4 surfaces
    std::fs::write(
        &sweep,
        crate::sweep::BASE.replace("test sweep", "cluster sweep")
            + "[sweep]\nsurface.k_max = [4, 8]\nsurface.seed = { from = 1, count = 4 }\n",
    )
    .unwrap();
    let cluster = Cluster::new(&dir);
    let runs = dir.join("runs");
    let o = cluster.run(
        &dir,
        &script("submit-sweep.sh"),
        &[sweep.as_os_str(), runs.as_os_str()],
        &[("TASKS", "3")],
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("Submitted batch job"), "{stdout}");
    for i in 1..=3 {
        assert!(
            runs.join(format!("shard-{i}-of-3.csv")).is_file(),
            "shard {i}"
        );
    }
    // 8 cases in 3 tasks: 3, 3 and 2 cases (3 load steps each).
    for (i, cases) in [(1, 3), (2, 3), (3, 2)] {
        let text = std::fs::read_to_string(runs.join(format!("shard-{i}-of-3.csv"))).unwrap();
        assert_eq!(text.lines().count() - 1, 3 * cases, "shard {i}/3");
    }
    let merged = std::fs::read_to_string(runs.join("sweep.csv")).expect("merged sweep.csv");
    assert!(runs.join("plots/pressure_gap.svg").is_file());
    let full = dir.join("full");
    let o = Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(["sweep", sweep.to_str().unwrap(), "--out"])
        .arg(&full)
        .arg("--no-plots")
        .env("STRATA_CACHE_DIR", cluster.state.join("cache"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let single = std::fs::read_to_string(full.join("sweep.csv")).unwrap();
    assert_eq!(merged.lines().count(), 1 + 8 * 3);
    assert_eq!(merged, single, "merged shards differ from the single run");
    // A rerun of the merge job after one task's shard was lost is refused, naming it.
    std::fs::remove_file(runs.join("shard-2-of-3.csv")).unwrap();
    let o = Command::new("bash")
        .arg(script("merge.sbatch"))
        .arg(&runs)
        .env(
            "PATH",
            format!(
                "{}:{}",
                cluster.bin.display(),
                std::env::var("PATH").unwrap()
            ),
        )
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("shard 2/3 is missing"),
        "{err}"
    );
    assert!(err.contains("shard-2-of-3.csv"), "{err}");
}

/// docs/cluster/solve.sbatch solves a small BEM scene: under mpirun with 2 ranks when
/// strata is built with MPI (the same curve to 1e-12), else once (the same bytes as
/// `strata solve`).
#[test]
fn distributed_solve_script_writes_the_serial_curve() {
    let dir = fresh_dir("cluster", "solve");
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        r#"
[stack]
[[stack.layer]]
thickness = 1e-4
young = 4e9
poisson = 0.15
[stack.base]
kind = "elastic"
young = 2e10
poisson = 0.3
[surface]
periodic = true
[surface.generate]
size = 1e-3
grid = 32
fractal_dimension = 2.4
k_min = 2
k_max = 8
rms = 3.4e-6
seed = 7
[model]
kind = "bem"
[solver]
bem_tolerance = 1e-13
[load]
separations = [6e-6, 4.5e-6, 3e-6]
"#,
    )
    .unwrap();
    let cluster = Cluster::new(&dir);
    let out = dir.join("out");
    // Two ranks (the script asks for 4 nodes; a command-line option wins, as in sbatch).
    let sbatch = cluster.bin.join("sbatch");
    let o = cluster.run(
        &dir,
        &sbatch,
        &[
            "--ntasks=2".as_ref(),
            script("solve.sbatch").as_os_str(),
            scene.as_os_str(),
            out.as_os_str(),
        ],
        &[],
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("Submitted batch job"));
    let log = cluster.logs();
    let got =
        std::fs::read_to_string(out.join("curve.csv")).unwrap_or_else(|e| panic!("{e}\n{log}"));
    let reference = dir.join("serial");
    let o = Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(["solve", scene.to_str().unwrap(), "--out"])
        .arg(&reference)
        .arg("--no-plots")
        .env("STRATA_CACHE_DIR", cluster.state.join("cache"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let want = std::fs::read_to_string(reference.join("curve.csv")).unwrap();
    assert_eq!(got.lines().count(), 4, "{got}");
    if cluster.mpi {
        assert!(log.contains("srun: mpirun -np 2"), "{log}");
        // The distributed and the serial iterations agree to round-off at this
        // tolerance, and so do the tangents on their contact sets.
        let (d, ds) = distributed_differences(&want, &got);
        assert!(d <= 1e-12 && ds <= 1e-12, "{d:e} {ds:e}\n{got}\n{want}");
    } else {
        assert!(log.contains("srun: strata solve"), "{log}");
        assert_eq!(got, want);
    }
}

/// `strata solve` (the binary under test, without mpirun: one process, the serial
/// solver) and `mpirun -np 2` / `-np 4` of the same binary (the `mpi` build: the BEM
/// distributed in slabs of rows) write the same curve.csv to 1e-12 relative, every
/// number: a 512² periodic cell on the paper's two-layer stack and a 256 × 384 isolated
/// sample on a coated half-space, both under approach control. Both scenes ask
/// `solver.bem_tolerance = 1e-13`: the serial (accelerated) and the distributed
/// (reference) iterations are different iterations of the same problem and agree to
/// about the tolerance they stop at; at 1e-13 their curves agree to round-off
/// (measured 3.2e-14 periodic, 1.9e-14 isolated on 2 ranks; asserted 1e-12). The
/// stiffness is the tangent on each step's contact set, the same linear solve on both
/// (measured 1.0e-14 and 7.2e-16 periodic, 2.6e-15 and 2.4e-14 isolated on 2 and 4
/// ranks; asserted 1e-12; the difference quotient over dδ = 1e-4 δ it
/// replaced magnified the loads' round-off ~1e4 times: 3.3e-10 and 6.3e-11). (Under
/// mean-pressure control the distributed iteration on the isolated sample stalls near
/// ε = 1e-12: 1.04e-12 after 400 iterations.)
#[cfg(feature = "mpi")]
mod distributed {
    use std::path::Path;
    use std::process::Command;

    use strata_runtime::surface::{GenerateParams, Surface};

    use crate::support::{csv_rows, fresh_dir, repo};
    use crate::tools::optional_tool;

    /// `strata solve SCENE` in one process, or under `mpirun -np NP`; its curve.csv.
    fn solve(scene: &Path, out: &Path, np: Option<usize>) -> String {
        solve_logged(scene, out, np).0
    }

    /// [`solve`]'s curve.csv and stderr (the log of rank 0).
    fn solve_logged(scene: &Path, out: &Path, np: Option<usize>) -> (String, String) {
        let strata = env!("CARGO_BIN_EXE_strata");
        let mut c = match np {
            None => Command::new(strata),
            Some(np) => {
                let mut c = Command::new("mpirun");
                c.args(["--allow-run-as-root", "--oversubscribe", "-np"])
                    .arg(np.to_string())
                    .arg(strata);
                c
            }
        };
        let o = c
            .args([
                "solve",
                scene.to_str().unwrap(),
                "--no-plots",
                "--force",
                "--out",
            ])
            .arg(out)
            // One thread per rank: the ranks share the cores.
            .env("RAYON_NUM_THREADS", "1")
            .output()
            .expect("strata runs");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "np {np:?}: {err}");
        if let Some(np) = np {
            assert!(
                err.contains(&format!("distributed over {np} MPI ranks")),
                "{err}"
            );
        }
        let curve = std::fs::read_to_string(out.join("curve.csv")).expect("curve.csv");
        (curve, err.into_owned())
    }

    /// The surface buffers each rank held at the peak of generating its rows (MB), from
    /// rank 0's log line; None if the surface was not generated per rank.
    fn generated_per_rank(log: &str) -> Option<Vec<f64>> {
        let line = log
            .lines()
            .find(|l| l.contains("surface: generated by each rank for its own rows"))?;
        let list = line.split("per rank ").nth(1)?.split(" (").next()?;
        Some(
            list.split(", ")
                .map(|v| v.trim_end_matches(" MB").parse().expect("MB"))
                .collect(),
        )
    }

    fn agree(dir: &Path, scene: &Path, what: &str) -> Vec<String> {
        let serial = solve(scene, &dir.join("serial"), None);
        assert!(
            csv_rows(&serial).iter().all(|r| r[2] > 0.0 && r[5] > 0.0),
            "{serial}"
        );
        let mut logs = Vec::new();
        for np in [2, 4] {
            let (got, log) = solve_logged(scene, &dir.join(format!("np{np}")), Some(np));
            logs.push(log);
            let (d, ds) = super::distributed_differences(&serial, &got);
            println!(
                "{what}: mpirun -np {np} against serial: {d:.2e} relative (stiffness {ds:.2e})"
            );
            assert!(
                d <= 1e-12,
                "{what}: np {np} differs by {d:e}\n{serial}\n{got}"
            );
            assert!(
                ds <= 1e-12,
                "{what}: np {np} stiffness differs by {ds:e}\n{serial}\n{got}"
            );
        }
        logs
    }

    fn mpirun() -> bool {
        optional_tool("mpirun", "--version", "apt-get install openmpi-bin").is_some()
    }

    #[test]
    fn periodic_layered_512_same_curve_serial_and_2_4_ranks() {
        if !mpirun() {
            return;
        }
        let dir = fresh_dir("cluster", "mpi-periodic");
        let stack = repo().join("tables/stacks/paper-two-layer-E2E1-1.toml");
        let scene = dir.join("scene.toml");
        std::fs::write(
            &scene,
            format!(
                r#"
[stack]
file = "{}"
[surface]
periodic = true
[surface.generate]
size = 1e-3
grid = 512
fractal_dimension = 2.4
k_min = 2
k_max = 10
rms = 3.4e-6
seed = 20240611
[model]
kind = "bem"
[solver]
bem_tolerance = 1e-13
[load]
approach = {{ from = 4e-6, to = 6e-6, steps = 3 }}
"#,
                stack.display()
            ),
        )
        .unwrap();
        let logs = agree(&dir, &scene, "512² periodic layered");
        // No rank generates the whole grid: each rank's surface buffers at the peak are
        // the one-rank figure over P (32 B per point of its kx lines: 16 B per grid
        // point over P, counted), 4.2 MB on one rank: 2.1 MB on each of 2, 1.1 MB on
        // each of 4, against the whole height map's 2.1 MB.
        for (log, np) in logs.iter().zip([2usize, 4]) {
            let per = generated_per_rank(log).unwrap_or_else(|| panic!("{log}"));
            assert_eq!(per.len(), np, "{log}");
            let one = 32.0 * 512.0 * 257.0 / 1e6;
            for (q, mb) in per.iter().enumerate() {
                assert!(
                    *mb <= one / np as f64 * 1.02 + 0.05,
                    "np {np} rank {q}: {mb} MB of surface buffers (one rank: {one} MB)\n{log}"
                );
            }
            assert!(
                log.contains(&format!("rank 0 holds rows 0..{} of 512", 512 / np)),
                "{log}"
            );
        }
    }

    #[test]
    fn non_periodic_256_by_384_same_curve_serial_and_2_4_ranks() {
        if !mpirun() {
            return;
        }
        let dir = fresh_dir("cluster", "mpi-free");
        // The corner of a generated periodic surface: not periodic itself.
        let dx = 1e-3 / 512.0;
        let s = Surface::generate(&GenerateParams {
            size: 1e-3,
            grid: 512,
            fractal_dimension: 2.3,
            k_min: 2.0,
            k_max: 16.0,
            rms: 1e-6,
            seed: 5,
        })
        .expect("surface");
        let (n0, n1) = (256usize, 384usize);
        let z: Vec<f64> = (0..n0 * n1).map(|k| s.z(k / n1, k % n1)).collect();
        Surface::with_spacing(
            z,
            n0,
            n1,
            strata_runtime::surface::Spacing::Pixel(dx, dx),
            false,
        )
        .expect("surface")
        .write_npy(&dir.join("z.npy"))
        .expect("npy");
        let stack = repo().join("tables/stacks/coating-on-steel.toml");
        let scene = dir.join("scene.toml");
        std::fs::write(
            &scene,
            format!(
                r#"
[stack]
file = "{}"
[surface]
file = "z.npy"
pixel_size = [{dx:e}, {dx:e}]
detrend = "none"
[model]
kind = "bem"
[solver]
bem_tolerance = 1e-13
[load]
approach = {{ from = 1.6e-6, to = 3.6e-6, steps = 3 }}
"#,
                stack.display()
            ),
        )
        .unwrap();
        let logs = agree(&dir, &scene, "256×384 non-periodic");
        // A file is read whole on every rank (its checks judge the whole map).
        assert!(
            logs.iter()
                .all(|l| l.contains("surface: read whole on every rank")),
            "{logs:?}"
        );
    }

    /// `mpirun -np 2 strata solve`, its status and stderr (out DIR).
    fn mpirun2(scene: &Path, out: &Path) -> (bool, String) {
        let o = Command::new("mpirun")
            .args(["--allow-run-as-root", "--oversubscribe", "-np", "2"])
            .arg(env!("CARGO_BIN_EXE_strata"))
            .args(["solve", scene.to_str().unwrap(), "--no-plots", "--out"])
            .arg(out)
            .env("RAYON_NUM_THREADS", "1")
            .output()
            .expect("mpirun runs");
        (
            o.status.success(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    }

    /// Under mpirun a non-BEM scene runs on rank 0 alone and says so, writing the serial
    /// curve byte for byte; a BEM scene with an effect that is not distributed is refused
    /// naming the scene field, nothing written.
    #[test]
    fn other_models_run_on_rank_0_and_undistributed_effects_are_refused() {
        if !mpirun() {
            return;
        }
        let dir = fresh_dir("cluster", "mpi-others");
        let surface = "periodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 64\n\
                       fractal_dimension = 2.4\nk_min = 2\nk_max = 8\nrms = 3e-6\nseed = 3";
        let scene = dir.join("independent.toml");
        std::fs::write(
            &scene,
            crate::support::homogeneous_scene(
                surface,
                "\"independent\"",
                "separations = [6e-6, 4e-6]",
            ),
        )
        .unwrap();
        let (ok, err) = mpirun2(&scene, &dir.join("np2"));
        assert!(ok, "{err}");
        assert!(
            err.contains("only the BEM is distributed") && err.contains("rank 0 alone"),
            "{err}"
        );
        let serial = solve(&scene, &dir.join("serial"), None);
        let got = std::fs::read_to_string(dir.join("np2/curve.csv")).unwrap();
        assert_eq!(got, serial);
        let scene = dir.join("maps.toml");
        std::fs::write(
            &scene,
            crate::support::homogeneous_scene(surface, "\"bem\"", "separations = [6e-6]")
                + "[output]\nmaps = \"last\"\n",
        )
        .unwrap();
        let (ok, err) = mpirun2(&scene, &dir.join("maps"));
        assert!(!ok, "{err}");
        assert!(
            err.contains("output.maps") && err.contains("maps.toml"),
            "{err}"
        );
        assert!(!dir.join("maps/curve.csv").exists());
    }
}
