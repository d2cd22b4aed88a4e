"""`[friction]` from Python: the full-stick tangential stiffness of the N and I models'
steps (``Curve.tangential_stiffness``), equal to ``strata solve``'s ``tangential_stiffness``
column on the same scene; the law's ``tangential_stiffness(g)`` at its samples equals the
``samples`` dict's; a law without friction refuses the query."""

import numpy as np
import pytest

import strata

SCENE = """
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
grid = 64
fractal_dimension = 2.4
k_min = 2
k_max = 8
rms = 3.4e-6
seed = 3
[model]
kind = "{model}"
images = "isolated"
[load]
separations = [6e-6, 4.5e-6, 3e-6]
[friction]
coefficient = 0.3
"""


def read_last_column(path):
    lines = path.read_text().splitlines()
    assert lines[0].endswith(",tangential_stiffness"), lines[0]
    return np.array([float(line.split(",")[-1]) for line in lines[1:]])


@pytest.mark.parametrize("model", ["independent", "interacting"])
def test_tangential_stiffness_equals_cli(model, cli, tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(SCENE.format(model=model))
    cache = tmp_path / "cache"
    cli("solve", path, "--out", tmp_path / "out", "--no-plots", "-q", "--cache-dir", cache)
    want = read_last_column(tmp_path / "out" / "curve.csv")
    curve = strata.solve(path, cache_dir=cache)
    assert curve.tangential_stiffness is not None
    np.testing.assert_array_equal(curve.tangential_stiffness, want)
    assert (want > 0).all()
    assert curve.units()["tangential_stiffness"] == "N/m"
    assert curve.meta["friction"]["coefficient"] == 0.3
    law = strata.Scene.from_file(path).law(samples=12, cache_dir=cache)
    s = law.samples
    g, k = s["gap"], s["tangential_stiffness"]
    np.testing.assert_array_equal(law.tangential_stiffness(g[1:]), k[1:])
    plain = strata.Scene.from_toml(SCENE.format(model=model).split("[friction]")[0]).law(
        samples=4, cache_dir=cache)
    with pytest.raises(strata.LawError, match="friction"):
        plain.tangential_stiffness(g[1])


def test_bem_tangential_stiffness_and_path_equal_cli(cli, tmp_path):
    """The BEM's full-stick ``tangential_stiffness`` per step and, with ``[load] tangential``,
    its tangential path equal ``strata solve``'s curve.csv column and tangential.csv, from a
    scene file and from ``Scene(..., model="bem", friction={...})``; its law carries the
    column at its samples."""
    text = SCENE.format(model="bem").replace(
        "separations = [6e-6, 4.5e-6, 3e-6]",
        "separations = [6e-6, 4.5e-6, 3e-6]\ntangential = { from = 0.2, to = 0.6, steps = 3 }",
    )
    path = tmp_path / "scene.toml"
    path.write_text(text)
    cache = tmp_path / "cache"
    cli("solve", path, "--out", tmp_path / "out", "--no-plots", "-q", "--cache-dir", cache)
    want = read_last_column(tmp_path / "out" / "curve.csv")
    assert (want > 0).all()
    lines = (tmp_path / "out" / "tangential.csv").read_text().splitlines()
    assert lines[0] == "force_ratio,tangential_force,tangential_displacement,stick_fraction"
    table = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    from_file = strata.Scene.from_file(path)
    for scene in (
        from_file,
        strata.Scene(
            from_file.stack,
            from_file.surface(),
            model="bem",
            load={"separations": [6e-6, 4.5e-6, 3e-6],
                  "tangential": {"from": 0.2, "to": 0.6, "steps": 3}},
            friction={"coefficient": 0.3},
        ),
    ):
        curve = scene.solve(cache_dir=cache)
        np.testing.assert_array_equal(curve.tangential_stiffness, want)
        t = curve.tangential
        assert t is not None and t["coefficient"] == 0.3
        for k, name in enumerate(
            ["force_ratio", "tangential_force", "tangential_displacement", "stick_fraction"]
        ):
            np.testing.assert_array_equal(t[name], table[:, k])
    law = from_file.law(samples=6, cache_dir=cache)
    k = law.samples["tangential_stiffness"]
    assert k[0] == 0 and (k[1:] > 0).all()
    with pytest.raises(strata.SceneError, match="load.tangential"):
        strata.Scene.from_toml(text.replace("[friction]\ncoefficient = 0.3\n", ""))
