#!/usr/bin/env bash
# Checks strata's FFT-BEM against independent public solvers (issue 6):
#   * Tamaas 2.9 (homogeneous half-space, equal mean gap) and
#   * ContactMechanics 1.8 (one layer bonded to a rigid base, equal approach),
# on the shared surface ../shared/reference/surface_km10.npy, over A/A0 ≈ 0.2 %…40 %.
# Tolerances (tests/bem_reference.rs): 1e-4 in mean pressure, 0.5 % in area.
#
# Usage: tests/python/run.sh [--speed]
#   --speed  also times one load step at n = 512 for Tamaas (Python) and strata
#            (criterion bench `bem`, release build) in the same run and prints the ratio.
# Environment: PYTHON (default python3, CPython 3.11 has wheels for both packages),
#   STRATA_PY_VENV (default target/python-venv), STRATA_PY_REF (default
#   target/python-reference; the CSVs the Rust tests read).
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$PWD
OUT=${STRATA_PY_REF:-$ROOT/target/python-reference}
VENV=${STRATA_PY_VENV:-$ROOT/target/python-venv}
PY=${PYTHON:-python3}
mkdir -p "$OUT"
if [ ! -x "$VENV/bin/python" ]; then
    "$PY" -m venv "$VENV"
fi
"$VENV/bin/pip" install --quiet --disable-pip-version-check -r tests/python/requirements.txt
# Single-threaded on both sides: a fair per-core comparison on shared CI machines.
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
"$VENV/bin/python" tests/python/compare.py tamaas "$OUT/tamaas.csv"
"$VENV/bin/python" tests/python/compare.py cm "$OUT/cm.csv"
STRATA_PY_REF="$OUT" cargo test --test bem_reference -- --ignored python_ --nocapture

if [ "${1:-}" = "--speed" ]; then
    "$VENV/bin/python" tests/python/compare.py speed "$OUT/tamaas_speed.csv"
    cargo bench -p strata-runtime --bench bem -- halfspace_mean_gap
    "$VENV/bin/python" - "$OUT/tamaas_speed.csv" "$ROOT/target/criterion/bem_512" <<'PY'
import csv, json, sys
from pathlib import Path
rows = [r for r in csv.reader(l for l in open(sys.argv[1]) if not l.startswith("#"))][1:]
crit = Path(sys.argv[2])
for tol, secs, _ in rows:
    mant, exp = f"{float(tol):e}".split("e")
    tag = f"halfspace_mean_gap_tol{float(mant):g}e{int(exp)}"  # Rust's {:e}: 1e-8
    est_file = crit / tag / "new" / "estimates.json"
    if not est_file.is_file():
        print(f"tol {tol}: no criterion result {est_file}")
        continue
    est = json.load(open(est_file))["mean"]["point_estimate"] * 1e-9
    print(f"n=512, one load step, tol {float(tol):g}: Tamaas {float(secs):.3f} s, strata {est:.3f} s, "
          f"Tamaas/strata = {float(secs) / est:.2f}")
PY
fi
