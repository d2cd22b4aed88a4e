#!/usr/bin/env bash
# Builds the Python package's aarch64 (arm64) Linux wheel on an x86_64 machine, without
# Docker: maturin cross-compiles for aarch64-unknown-linux-gnu and zig links it against
# glibc 2.17's symbol versions (manylinux2014, abi3: one wheel for CPython >= 3.9). Then
# prints the wheel's name, size, auditwheel's platform tag and the newest glibc symbol
# version its extension module binds, and, where qemu-aarch64 is installed
# (qemu-user-static), imports the module under qemu with an aarch64 Python if one is
# given (STRATA_AARCH64_PYTHON) or only runs its ELF check otherwise.
#
# Not part of CI: every library is compiled again for aarch64 (docs/development.md).
#
# Usage: tools/wheel-aarch64.sh [OUT_DIR]      (default $CARGO_TARGET_DIR/wheels)
# Environment: CARGO_TARGET_DIR (default ./target), STRATA_PY_PROFILE (release | dev;
#   default release), STRATA_PY_BUILD_VENV (default $CARGO_TARGET_DIR/python-build-venv:
#   maturin, auditwheel, ziglang; made here if missing).
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$PWD/target}
OUT=${1:-$CARGO_TARGET_DIR/wheels}
PROFILE=${STRATA_PY_PROFILE:-release}
BUILD_VENV=${STRATA_PY_BUILD_VENV:-$CARGO_TARGET_DIR/python-build-venv}
TARGET=aarch64-unknown-linux-gnu
fail() { echo "wheel-aarch64: ERROR: $*" >&2; exit 1; }

if ! "$BUILD_VENV/bin/python" -c "import maturin, auditwheel, ziglang" 2>/dev/null; then
    python3 -m venv "$BUILD_VENV" || fail "cannot create the build venv $BUILD_VENV"
    "$BUILD_VENV/bin/python" -m pip install --quiet --disable-pip-version-check \
        "maturin>=1.16,<2" auditwheel ziglang || fail "pip could not install maturin, auditwheel, ziglang"
fi
rustup target list --installed | grep -qx "$TARGET" || rustup target add "$TARGET"

mkdir -p "$OUT"
rm -f "$OUT"/strata-*aarch64*.whl
# maturin finds zig as `python -m ziglang` of the Python on PATH: the build venv's.
PATH="$BUILD_VENV/bin:$PATH" "$BUILD_VENV/bin/maturin" build --profile "$PROFILE" \
    -m python/Cargo.toml --zig --target "$TARGET" --compatibility manylinux2014 --out "$OUT" \
    || fail "maturin build failed"
WHEEL=$(ls "$OUT"/strata-*aarch64*.whl 2>/dev/null | head -1)
[ -n "$WHEEL" ] || fail "no aarch64 wheel in $OUT"
case "$(basename "$WHEEL")" in
    *-cp39-abi3-*manylinux_2_17_aarch64*) ;;
    *) fail "$(basename "$WHEEL") is not an abi3 manylinux_2_17_aarch64 wheel" ;;
esac
AUDIT=$("$BUILD_VENV/bin/auditwheel" show "$WHEEL" 2>&1) || fail "auditwheel show failed: $AUDIT"
TAG=$(echo "$AUDIT" | tr '\n' ' ' | grep -oE 'platform tag: *"[^"]+"' | head -1 | sed -E 's/.*"(.*)"/\1/')
UNPACK=$(mktemp -d)
trap 'rm -rf "$UNPACK"' EXIT
"$BUILD_VENV/bin/python" -m zipfile -e "$WHEEL" "$UNPACK"
SO=$(ls "$UNPACK"/strata/_strata*.so | head -1)
GLIBC_MAX=$(readelf -V "$SO" | grep -oE 'GLIBC_[0-9]+(\.[0-9]+)+' | sort -u -V | tail -1)
echo "wheel:    $(basename "$WHEEL")"
echo "size:     $(stat -c %s "$WHEEL") bytes"
echo "machine:  $(readelf -h "$SO" | sed -n 's/^ *Machine: *//p')"
echo "auditwheel platform tag: $TAG"
echo "newest glibc symbol version: $GLIBC_MAX"
case "$TAG" in
    manylinux_2_17_aarch64 | manylinux2014_aarch64) ;;
    *) fail "auditwheel: $TAG, not manylinux_2_17_aarch64" ;;
esac

# Under qemu (user mode), with an aarch64 CPython to import the module with.
if command -v qemu-aarch64-static >/dev/null || command -v qemu-aarch64 >/dev/null; then
    QEMU=$(command -v qemu-aarch64-static || command -v qemu-aarch64)
    if [ -n "${STRATA_AARCH64_PYTHON:-}" ]; then
        PYTHONPATH="$UNPACK" "$QEMU" "$STRATA_AARCH64_PYTHON" -c \
            "import strata, strata._strata as m; print('imported under qemu:', m.__file__)" \
            || fail "the module does not import under $QEMU"
    else
        echo "qemu: $QEMU present; set STRATA_AARCH64_PYTHON to an aarch64 python3 to import the module"
    fi
fi
