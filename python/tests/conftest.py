"""Shared fixtures: the repository root, the `strata` CLI binary, CLI runs."""

import csv
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def cli_binary() -> str:
    """The `strata` command: $STRATA_BIN, else `strata` on PATH, else the cargo target
    directory's debug build. A test that needs it and cannot find it fails."""
    env = os.environ.get("STRATA_BIN")
    if env:
        return env
    on_path = shutil.which("strata")
    if on_path:
        return on_path
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for profile in ("debug", "release"):
        exe = target / profile / "strata"
        if exe.exists():
            return str(exe)
    pytest.fail("the strata CLI was not found: set STRATA_BIN, or build it with `cargo build --bin strata`")


@pytest.fixture(scope="session")
def root() -> pathlib.Path:
    return ROOT


@pytest.fixture(scope="session")
def cli():
    """Runs `strata ARGS...` and returns the completed process (checked)."""
    exe = cli_binary()

    def run(*args, check=True):
        p = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"strata {' '.join(map(str, args))} failed:\n{p.stderr}")
        return p

    return run


def read_curve_csv(path):
    """curve.csv as a dict of float arrays (contacts and valid as integers)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    cols = {}
    for j, name in enumerate(header):
        vals = [r[j] for r in body]
        if name in ("contacts", "valid"):
            cols[name] = np.array([int(v) for v in vals])
        else:
            cols[name] = np.array([float(v) if v != "" else np.nan for v in vals])
    return header, cols
