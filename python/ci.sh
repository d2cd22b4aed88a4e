#!/usr/bin/env bash
# Tests the Python package as a user meets it: a fresh venv, the README's install
# command (`pip install ./python`), pytest (+ SurfaceTopography for the adapter test,
# matplotlib for the examples, mypy for the stubs' stubtest), then the two examples.
#
# Usage: python/ci.sh [--ci] [--venv DIR]
#   --ci        CI mode: SurfaceTopography must be installed and its test must run
#               (STRATA_REQUIRE_TOOLS=1); the examples run headless (MPLBACKEND=Agg).
#   --venv DIR  use DIR, a venv made for this run without strata in it (.ci/run makes it
#               and installs pytest, matplotlib and SurfaceTopography while cargo builds),
#               instead of making one here.
#
# Build cost: maturin builds with the dev profile and the same CARGO_TARGET_DIR as
# `cargo test` (MATURIN_PEP517_ARGS="--profile dev"). `cargo test` builds every library
# with the test profile, which has the dev profile's settings (Cargo.toml), and
# python/Cargo.toml unifies the features with the workspace's (either, bitflags, and
# syn's `fold` on the host), so after `cargo test --workspace` every library is reused
# and only pyo3, numpy and the bindings are compiled: `pip install ./python` 10 s on a
# target directory that has the test build and pyo3 (was 111 s cold when the workspace
# libraries and faer were compiled again). `--profile test` would build a test harness,
# not the extension module. Without --ci the README's release build is used unless
# STRATA_PY_PROFILE is set. The numbers do not depend on the profile (no fast-math in
# Rust).
# Environment: PYTHON (default python3), CARGO_TARGET_DIR (default ./target),
#   STRATA_BIN (the CLI the tests compare with; default $CARGO_TARGET_DIR/debug/strata,
#   built here if missing), STRATA_PY_PROFILE (dev | release).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
CI_MODE=""
GIVEN_VENV=""
usage() { echo "usage: python/ci.sh [--ci] [--venv DIR]" >&2; exit 2; }
while [ $# -gt 0 ]; do
    case "$1" in
        --ci) CI_MODE=1 ;;
        --venv) [ $# -ge 2 ] || usage; GIVEN_VENV=$2; shift ;;
        *) usage ;;
    esac
    shift
done
fail() { echo "python/ci.sh: ERROR: $*" >&2; exit 1; }
PY=${PYTHON:-python3}
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$ROOT/target}
PROFILE=${STRATA_PY_PROFILE:-$([ -n "$CI_MODE" ] && echo dev || echo release)}
export MATURIN_PEP517_ARGS="--profile $PROFILE"
t0=$(date +%s)

WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
if [ -n "$GIVEN_VENV" ]; then
    VPY="$GIVEN_VENV/bin/python"
    [ -x "$VPY" ] || fail "--venv $GIVEN_VENV: no $VPY (make it with: $PY -m venv $GIVEN_VENV)"
    # The README's install must meet a venv without strata, as a new user's.
    if "$VPY" -m pip show --quiet strata >/dev/null 2>&1; then
        fail "--venv $GIVEN_VENV already has strata installed: give a fresh venv"
    fi
else
    "$PY" -m venv "$WORK/venv" || fail "cannot create a venv with $PY (install python3-venv)"
    VPY="$WORK/venv/bin/python"
    "$VPY" -m pip install --quiet --disable-pip-version-check --upgrade pip \
        || fail "pip cannot reach PyPI"
fi

echo "== python: pip install ./python (maturin, profile $PROFILE, CARGO_TARGET_DIR=$CARGO_TARGET_DIR)"
t1=$(date +%s)
"$VPY" -m pip install --disable-pip-version-check ./python \
    || fail "pip install ./python failed"
t2=$(date +%s)
echo "   pip install ./python: $((t2 - t1)) s"

# mypy: stubtest checks strata/_strata.pyi against the module (python/tests/test_stubs.py).
"$VPY" -m pip install --quiet --disable-pip-version-check pytest matplotlib SurfaceTopography mypy \
    || fail "pip could not install pytest, matplotlib, SurfaceTopography, mypy"
t3=$(date +%s)
echo "   pytest, matplotlib, SurfaceTopography, mypy: $((t3 - t2)) s"

export STRATA_BIN=${STRATA_BIN:-$CARGO_TARGET_DIR/debug/strata}
if [ ! -x "$STRATA_BIN" ]; then
    cargo build --bin strata
fi
if [ -n "$CI_MODE" ]; then export STRATA_REQUIRE_TOOLS=1 MPLBACKEND=Agg; fi
# Run from outside the source tree: the installed package is imported, not python/python/.
(cd "$WORK" && "$VPY" -m pytest -q -p no:cacheprovider "$ROOT/python/tests") || fail "pytest failed"
t4=$(date +%s)
echo "   pytest: $((t4 - t3)) s"

echo "== python: examples"
(cd "$WORK" && "$VPY" "$ROOT/python/examples/fig15_curve.py" --out "$WORK/fig15.png" --grid 128) \
    || fail "examples/fig15_curve.py failed"
(cd "$WORK" && "$VPY" "$ROOT/python/examples/surfacetopography_example.py" --out "$WORK/st.png") \
    || fail "examples/surfacetopography_example.py failed"
t5=$(date +%s)
echo "   examples: $((t5 - t4)) s"
echo "== python: passed in $((t5 - t0)) s"
