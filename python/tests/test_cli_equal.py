"""The Python package gives the CLI's curve.csv on the shipped scenes (same engine).

The CLI runs in the test on the same scene file; every column must agree to 1e-12
relative (contacts exactly). The README's main scene is first.
"""

import numpy as np
import pytest

import strata
from conftest import read_curve_csv

SCENES = [
    "paper-E2E1-5-interacting.toml",  # the README's main scene
    "paper-E2E1-5-independent.toml",
    "paper-E2E1-1-interacting.toml",
    "paper-E2E1-1-independent.toml",
    "paper-E2E1-0.2-interacting.toml",
    "paper-E2E1-0.2-independent.toml",
    "homogeneous-km10-independent.toml",
    "paper-E2E1-1-bem.toml",  # full-field BEM, ~20 s
]


def assert_same(py, cli_cols, header):
    assert header == list(strata._scene.CURVE_COLUMNS)
    for name in header:
        a, b = np.asarray(getattr(py, name)), cli_cols[name]
        assert a.shape == b.shape, name
        if name in ("contacts", "valid"):
            np.testing.assert_array_equal(a, b)
        else:
            # curve.csv holds shortest round-trip decimals: exact f64 values.
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=0.0, err_msg=name)


@pytest.mark.parametrize("name", SCENES)
def test_scene_equals_cli(name, root, cli, tmp_path):
    scene = root / "scenes" / name
    cli("solve", scene, "--out", tmp_path / "out", "--no-plots", "-q")
    header, cols = read_curve_csv(tmp_path / "out" / "curve.csv")
    curve = strata.solve(scene)
    assert len(curve) == len(cols["delta"]) > 0
    assert_same(curve, cols, header)
    assert curve.meta["model"]


def test_in_memory_scene_equals_file_scene(root):
    """Stack, surface and table given as Python objects: the same numbers as the file."""
    path = root / "scenes" / "paper-E2E1-5-interacting.toml"
    from_file = strata.solve(path)
    stack = strata.Stack.from_file(root / "tables" / "stacks" / "paper-two-layer.toml")
    surface = strata.Surface.generate(size=1e-3, grid=512, fractal_dimension=2.4, k_min=2, k_max=10,
                                      rms=3.4e-6, seed=20240611)
    table = strata.Table.load(root / "tables" / "paper-two-layer.strata")
    scene = strata.Scene(stack, surface, model="interacting", images="periodic",
                         load={"approach": {"from": 1.3e-6, "to": 5.3e-6, "steps": 20}}, table=table)
    mem = scene.solve()
    for c in strata._scene.CURVE_COLUMNS:
        np.testing.assert_allclose(getattr(mem, c), getattr(from_file, c), rtol=1e-12, atol=0, err_msg=c)


def test_surface_from_array_equals_generated(root):
    """A generated surface passed back through numpy (heights, size) is the same surface."""
    g = strata.Surface.generate(size=1e-3, grid=128, fractal_dimension=2.4, k_min=2, k_max=10, rms=3.4e-6, seed=7)
    a = strata.Surface(g.heights, size=1e-3, periodic=True)
    np.testing.assert_array_equal(a.heights, g.heights)
    assert a.pixel_size == g.pixel_size and a.periodic
    b = strata.Surface(g.heights, pixel_size=g.pixel_size, periodic=True)
    assert b.extent == pytest.approx(g.extent, rel=1e-15)


def test_python_c_one_liner_equals_cli(root, cli, tmp_path):
    """`python -c "import strata; ..."` on the README's main scene: curve.csv's values."""
    import subprocess
    import sys
    scene = root / "scenes" / "paper-E2E1-5-interacting.toml"
    cli("solve", scene, "--out", tmp_path / "out", "--no-plots", "-q")
    code = "import strata, sys; strata.solve(sys.argv[1]).to_csv(sys.argv[2])"
    subprocess.run([sys.executable, "-c", code, str(scene), str(tmp_path / "py.csv")], check=True)
    h1, cli_cols = read_curve_csv(tmp_path / "out" / "curve.csv")
    h2, py_cols = read_curve_csv(tmp_path / "py.csv")
    assert h1 == h2
    for name in h1:
        np.testing.assert_allclose(py_cols[name], cli_cols[name], rtol=1e-12, atol=0.0, err_msg=name)
