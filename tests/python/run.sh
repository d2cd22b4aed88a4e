#!/usr/bin/env bash
# Checks strata's FFT-BEM against independent public solvers:
#   * Tamaas 2.9 (homogeneous half-space, equal mean gap; and steel on steel, strata's
#     two-body [counterface], against Tamaas with the composite E*),
#   * ContactMechanics 1.8 (one layer bonded to a rigid base, equal approach; and its
#     plastic system on a half-space, loading and unloading, strata's [plasticity]) and
#   * ContactMechanics 1.8 FreeFFTElasticHalfSpace (the surface as an isolated,
#     non-periodic sample on a half-space, equal approach),
# and opens strata's NetCDF maps with xarray (tests/python/netcdf_xarray.py),
# on strata's generated paper-like surface (L = 1 mm, D_f = 2.4, k = 2…10, RMS 3.4 µm),
# written to .npy by `strata surface export` from a scene written here: nothing outside
# the repository is needed. Tolerances (tests/it/bem_reference.rs, docs/validation.md):
# mean pressure within about 10× the measured difference (3e-10 … 5e-9), area within two
# grid points, with loads spanning A/A0 from ≤ 1 % to ≥ 20 %.
#
# Usage: tests/python/run.sh [--ci] [--speed]
#   --ci     CI mode: 256² surface and 4 loads per solver instead of 512² and 7–9
#            (same tolerances, same A/A0 span); 15 s once the venv exists (124 s without
#            --ci), plus ~40 s to make the venv.
#   --speed  also times one load step at n = 512 and 2048 (mean pressure and mean gap)
#            for Tamaas (Python) and strata (criterion bench `bem`, release build), on
#            surfaces the bench writes, and prints the ratios.
# Environment: PYTHON (default python3; CPython 3.11 has wheels for both packages),
#   STRATA_PY_VENV (default target/python-venv), STRATA_PY_REF (default
#   target/python-reference: surface.npy and the CSVs the Rust tests read).
# Fails (non-zero exit, message on stderr) if the venv or PyPI is unavailable: the
# check is never skipped silently.
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$PWD
export STRATA_PY_REF=${STRATA_PY_REF:-$ROOT/target/python-reference}
VENV=${STRATA_PY_VENV:-$ROOT/target/python-venv}
export STRATA_PY_VENV=$VENV
PY=${PYTHON:-python3}
CI_MODE=""
SPEED=""
for a in "$@"; do
    case "$a" in
        --ci) CI_MODE="--ci" ;;
        --speed) SPEED=1 ;;
        *) echo "usage: tests/python/run.sh [--ci] [--speed]" >&2; exit 2 ;;
    esac
done
if [ -n "$CI_MODE" ]; then
    export STRATA_PY_GRID=${STRATA_PY_GRID:-256}
else
    export STRATA_PY_GRID=${STRATA_PY_GRID:-512}
fi
fail() { echo "tests/python/run.sh: ERROR: $*" >&2; exit 1; }

t_start=$(date +%s)
mkdir -p "$STRATA_PY_REF"
rm -f "$STRATA_PY_REF/surface.npy" "$STRATA_PY_REF"/{tamaas,tamaas_pair,cm,cm_plastic,free}.{csv,log}
if [ ! -x "$VENV/bin/python" ]; then
    "$PY" -m venv "$VENV" || fail "cannot create a venv with $PY (install python3-venv)"
fi
"$VENV/bin/python" -m pip install --quiet --disable-pip-version-check \
    -r tests/python/requirements.txt \
    || fail "pip could not install tests/python/requirements.txt (is PyPI reachable?)"
t_pip=$(date +%s)
echo "python: venv ready in $((t_pip - t_start)) s ($("$VENV/bin/python" --version))"

# 1. strata writes the surface; 2. the Python solvers load it; 3. Rust compares.
# `--workspace`: the features of `cargo test --workspace`, so its build is reused (a
# package-only build unifies features differently and recompiles the workspace crates);
# it builds the `strata` binary the integration tests run, used here too.
cargo test --workspace --no-run
STRATA="${CARGO_TARGET_DIR:-$ROOT/target}/debug/strata"
[ -x "$STRATA" ] || fail "no strata binary at $STRATA after cargo test --workspace --no-run"
# A scene of the paper-like surface on a homogeneous half-space (the Python solvers take
# the heights only); the netcdf one is a small BEM run with every map in NetCDF.
paper_scene() { # $1: grid, $2: seed, $3: extra lines
    cat <<EOF2
[stack]
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
grid = $1
fractal_dimension = 2.4
k_min = 2
k_max = 10
rms = 3.4e-6
seed = $2
[model]
kind = "bem"
[load]
approach = { from = 1e-6, to = 5e-6, steps = 3 }
$3
EOF2
}
paper_scene "$STRATA_PY_GRID" 20240611 "" >"$STRATA_PY_REF/surface.toml"
"$STRATA" surface export "$STRATA_PY_REF/surface.toml" --out "$STRATA_PY_REF/surface.npy" \
    --force || fail "strata surface export failed"
t_surf=$(date +%s)
# Each solver single-threaded (a fair per-core comparison on shared CI machines); the
# three run side by side, each into a log of its own printed when all are done (one after
# the other they left a core idle for ~20 s of a CI run).
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
solvers=(tamaas tamaas_pair cm cm_plastic free)
pids=()
for solver in "${solvers[@]}"; do
    "$VENV/bin/python" tests/python/compare.py "$solver" "$STRATA_PY_REF/surface.npy" \
        "$STRATA_PY_REF/$solver.csv" >"$STRATA_PY_REF/$solver.log" 2>&1 &
    pids+=($!)
done
failed=""
for i in "${!solvers[@]}"; do
    solver=${solvers[$i]}
    wait "${pids[$i]}" || failed="$failed $solver"
    cat "$STRATA_PY_REF/$solver.log"
done
[ -z "$failed" ] || fail "tests/python/compare.py failed for:$failed (logs above)"
t_py=$(date +%s)
# and the BEM's coupled partial slip against Tamaas' PolonskyKeerTan (tests/it/tangential_peer.rs)
cargo test --workspace --test it -- --ignored bem_reference::python_ tangential_peer:: --nocapture
# strata's NetCDF maps (contact.engineering's results.nc) opened with xarray.
rm -rf "$STRATA_PY_REF/netcdf"
mkdir -p "$STRATA_PY_REF/netcdf"
paper_scene 64 7 $'[output]\nmaps = "all"\nformat = ["npy", "netcdf"]' >"$STRATA_PY_REF/netcdf/scene.toml"
"$STRATA" solve "$STRATA_PY_REF/netcdf/scene.toml" --out "$STRATA_PY_REF/netcdf/out" --no-plots \
    || fail "strata solve with NetCDF maps failed"
"$VENV/bin/python" tests/python/netcdf_xarray.py "$STRATA_PY_REF/netcdf/out"
t_end=$(date +%s)
echo "python cross-checks passed: venv $((t_pip - t_start)) s, surface (cargo) $((t_surf - t_pip)) s, Python solvers $((t_py - t_surf)) s, strata comparison $((t_end - t_py)) s, total $((t_end - t_start)) s"

if [ -n "$SPEED" ]; then
    # Side by side in one run, on both cores each: strata (criterion bench `bem`, release
    # build) writes the surfaces (n = 512, 2048) and its times; Tamaas solves the same
    # surfaces and loads (mean pressure 0.005 E*, mean gap 0.5 (z_M - z_mean)) at the
    # same tolerance 1e-8; the ratio table is printed.
    SPEED_DIR=$STRATA_PY_REF/speed
    mkdir -p "$SPEED_DIR"
    unset OMP_NUM_THREADS
    STRATA_TAMAAS_DIR=$SPEED_DIR cargo bench -p strata-benches --bench bem -- tamaas
    "$VENV/bin/python" tests/python/compare.py speed "$SPEED_DIR" "$SPEED_DIR/tamaas_speed.csv"
    "$VENV/bin/python" - "$SPEED_DIR/strata_speed.csv" "$SPEED_DIR/tamaas_speed.csv" <<'PY'
import csv, sys
def rows(p):
    return [r for r in csv.DictReader(l for l in open(p) if not l.startswith("#"))]
s = {(r["n"], r["control"]): r for r in rows(sys.argv[1])}
print("| n | control | Tamaas (s) | strata (s) | Tamaas / strata | iterations T / s | p/E* rel. diff |")
print("|---|---|---|---|---|---|---|")
for t in rows(sys.argv[2]):
    k = (t["n"], t["control"])
    if k not in s:
        continue
    o = s[k]
    ts, ss = float(t["seconds"]), float(o["seconds"])
    dp = abs(float(o["pressure_ratio"]) / float(t["pressure_ratio"]) - 1)
    print(f"| {k[0]} | {k[1]} | {ts:.3f} | {ss:.4f} | {ts / ss:.1f} | {t['iterations']} / {o['iterations']} | {dp:.1e} |")
PY
    # The hardness cap side by side: strata's capped step (bench `bem -- plastic`) and
    # ContactMechanics' plastic system on the same 512² surface, approach and hardness.
    STRATA_CM_PLASTIC_DIR=$SPEED_DIR/plastic cargo bench -p strata-benches --bench bem -- plastic
    "$VENV/bin/python" tests/python/compare.py cm_plastic_speed "$SPEED_DIR/plastic" "$SPEED_DIR/plastic/cm_plastic_speed.csv"
fi
