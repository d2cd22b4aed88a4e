#!/usr/bin/env bash
# Tests the Python package as a user meets it: the package built once as an abi3 wheel
# for manylinux2014 (maturin, in a build venv; linked by zig against glibc 2.17's symbol
# versions), checked with `auditwheel show` (manylinux_2_17, abi3), installed
# into a fresh venv on a PATH where neither `cargo` nor `rustc` is found (the README's
# first way: a wheel, no Rust toolchain), then pytest (+ SurfaceTopography for the adapter
# test, matplotlib for the examples, mypy for the stubs' stubtest, pandas and xarray for
# the conversions, nbconvert and ipykernel for the notebook test) on that PATH, then the
# examples and the walkthrough notebook.
#
# Usage: python/ci.sh [--ci] [--venv DIR]
#   --ci        CI mode: SurfaceTopography must be installed and its test must run
#               (STRATA_REQUIRE_TOOLS=1); the examples run headless (MPLBACKEND=Agg).
#   --venv DIR  use DIR, a venv made for this run without strata in it (.ci/run makes it
#               and installs pytest, matplotlib and SurfaceTopography while cargo builds),
#               instead of making one here.
#
# The build venv ($STRATA_PY_BUILD_VENV, default $CARGO_TARGET_DIR/python-build-venv)
# holds maturin, auditwheel and ziglang (zig from PyPI); made here if missing (.ci/run
# makes it in the background).
#
# manylinux2014 (glibc >= 2.17: RHEL/Rocky 8 and 9, Ubuntu 20.04, most clusters) without
# Docker: the extension module is linked by zig's cc for x86_64-linux-gnu.2.17 (maturin's
# zig wrapper; zig carries stubs of every glibc's symbol versions), so every glibc symbol
# it binds is one 2.17 has. Linked on the build machine's own glibc (Debian 12, 2.36) it
# bound the newest versions: GLIBC_2.35 at most (hypot), 2.34 (pthread_*, dlsym, moved
# into libc), 2.33 (stat64, fstat64), 2.29 (exp, log, pow). Only the link changes, so
# only the last crate gets the linker (`-- -C linker=...`: maturin passes it through
# `cargo rustc` to the extension module alone) and every library of `cargo test`'s build
# is reused. `maturin build --zig` builds with `--target x86_64-unknown-linux-gnu` in a
# directory of its own: every library compiled again (see docs/development.md).
#
# Build cost: maturin builds with the dev profile and the same CARGO_TARGET_DIR as
# `cargo test` (`maturin build --profile dev`). `cargo test` builds every library
# with the test profile, which has the dev profile's settings (Cargo.toml), and
# python/Cargo.toml unifies the features with the workspace's (either, bitflags, and
# syn's `fold` on the host), so after `cargo test --workspace` every library is reused
# and only pyo3, numpy and the bindings are compiled: the wheel's build 10 s on a
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
BUILD_VENV=${STRATA_PY_BUILD_VENV:-$CARGO_TARGET_DIR/python-build-venv}
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

echo "== python: wheel (maturin build, manylinux2014, profile $PROFILE, CARGO_TARGET_DIR=$CARGO_TARGET_DIR)"
t1=$(date +%s)
if ! "$BUILD_VENV/bin/python" -c "import maturin, auditwheel, ziglang" 2>/dev/null; then
    "$PY" -m venv "$BUILD_VENV" || fail "cannot create the build venv $BUILD_VENV"
    "$BUILD_VENV/bin/python" -m pip install --quiet --disable-pip-version-check \
        "maturin>=1.16,<2" auditwheel ziglang || fail "pip could not install maturin, auditwheel and ziglang"
fi
# The linker of the extension module: zig's cc for glibc 2.17, through maturin's wrapper
# of it (which adapts rustc's linker arguments to zig).
ZIGCC="$BUILD_VENV/bin/strata-zigcc-x86_64-linux-gnu.2.17"
cat >"$ZIGCC" <<EOF
#!/bin/sh
export CARGO_ZIGBUILD_ZIG_COMMAND="$BUILD_VENV/bin/python" CARGO_ZIGBUILD_ZIG_COMMAND_ARGS="-m ziglang"
exec "$BUILD_VENV/bin/maturin" zig cc -- -g -fno-sanitize=all -target x86_64-linux-gnu.2.17 "\$@"
EOF
chmod +x "$ZIGCC"
mkdir -p "$WORK/wheels"
"$BUILD_VENV/bin/maturin" build --quiet --profile "$PROFILE" -m python/Cargo.toml \
    --compatibility manylinux2014 --interpreter "$VPY" --out "$WORK/wheels" \
    -- -C "linker=$ZIGCC" || fail "maturin build failed"
WHEEL=$(ls "$WORK"/wheels/strata-*.whl 2>/dev/null | head -1)
[ -n "$WHEEL" ] || fail "maturin built no wheel"
case "$(basename "$WHEEL")" in
    *-cp39-abi3-*manylinux_2_17_x86_64*) ;;
    *) fail "$(basename "$WHEEL") is not an abi3 (cp39-abi3) manylinux_2_17_x86_64 wheel" ;;
esac
AUDIT=$("$BUILD_VENV/bin/auditwheel" show "$WHEEL" 2>&1) || fail "auditwheel show failed: $AUDIT"
TAG=$(echo "$AUDIT" | tr '\n' ' ' | grep -oE 'platform tag: *"[^"]+"' | head -1 | sed -E 's/.*"(.*)"/\1/')
# auditwheel names the oldest policy the wheel satisfies: manylinux_2_17 (manylinux2014),
# or an older one if no symbol needs 2.17; anything newer fails on RHEL 7 / CentOS 7.
case "$TAG" in
    manylinux_2_5_x86_64 | manylinux_2_12_x86_64 | manylinux_2_17_x86_64 | manylinux2014_x86_64) ;;
    *) fail "auditwheel: $(basename "$WHEEL") is ${TAG:-not manylinux}, not manylinux_2_17 (manylinux2014): a glibc symbol newer than 2.17 is bound: $AUDIT" ;;
esac
t2=$(date +%s)
echo "   $(basename "$WHEEL"): auditwheel platform tag $TAG, $((t2 - t1)) s"

# The CLI the tests compare with, built now (with the toolchain).
export STRATA_BIN=${STRATA_BIN:-$CARGO_TARGET_DIR/debug/strata}
if [ ! -x "$STRATA_BIN" ]; then
    cargo build --bin strata
fi

# From here on no Rust toolchain: a PATH of the venv's bin and the system directories
# that hold neither cargo nor rustc.
NO_RUST_PATH="$(dirname "$VPY")"
IFS=: read -r -a DIRS <<<"$PATH"
for d in "${DIRS[@]}"; do
    [ -n "$d" ] && [ ! -e "$d/cargo" ] && [ ! -e "$d/rustc" ] && NO_RUST_PATH="$NO_RUST_PATH:$d"
done
norust() { env -u RUSTUP_HOME -u CARGO_HOME PATH="$NO_RUST_PATH" "$@"; }
norust bash -c '! command -v cargo >/dev/null && ! command -v rustc >/dev/null' \
    || fail "cargo or rustc is still on the test PATH $NO_RUST_PATH"
echo "   test PATH without cargo and rustc: $NO_RUST_PATH"
norust "$VPY" -m pip install --quiet --disable-pip-version-check "$WHEEL" \
    || fail "pip install $(basename "$WHEEL") failed without a Rust toolchain"

# mypy: stubtest checks strata/_strata.pyi against the module (python/tests/test_stubs.py).
norust "$VPY" -m pip install --quiet --disable-pip-version-check pytest matplotlib SurfaceTopography mypy \
    pandas xarray nbconvert ipykernel \
    || fail "pip could not install pytest, matplotlib, SurfaceTopography, mypy, pandas, xarray, nbconvert, ipykernel"
t3=$(date +%s)
echo "   install (wheel, test dependencies): $((t3 - t2)) s"

if [ -n "$CI_MODE" ]; then export STRATA_REQUIRE_TOOLS=1 MPLBACKEND=Agg; fi
# Run from outside the source tree: the installed package is imported, not python/python/.
(cd "$WORK" && norust "$VPY" -m pytest -q -p no:cacheprovider "$ROOT/python/tests") || fail "pytest failed"
t4=$(date +%s)
echo "   pytest: $((t4 - t3)) s"

echo "== python: examples"
(cd "$WORK" && norust "$VPY" "$ROOT/python/examples/fig15_curve.py" --out "$WORK/fig15.png" --grid 128) \
    || fail "examples/fig15_curve.py failed"
(cd "$WORK" && norust "$VPY" "$ROOT/python/examples/surfacetopography_example.py" --out "$WORK/st.png") \
    || fail "examples/surfacetopography_example.py failed"
# The walkthrough notebook (docs/guide/walkthrough.md in Python), executed as Jupyter does.
(cd "$WORK" && STRATA_REPO="$ROOT" norust "$VPY" -m nbconvert --to notebook --execute --output-dir "$WORK" \
    --output walkthrough.ipynb "$ROOT/python/examples/walkthrough.ipynb") \
    || fail "examples/walkthrough.ipynb failed"
t5=$(date +%s)
echo "   examples: $((t5 - t4)) s"
echo "== python: passed in $((t5 - t0)) s"
