"""strata's NetCDF maps (contact.engineering's results.nc layout) read back by xarray on a
rectangular grid: `x` is the input's first axis, with its points and its side Lx, as
SurfaceTopography and contact.engineering index a topography. The input is a
SurfaceTopography NetCDF topography (64 x 128, Lx = 1 mm, Ly = 2 mm), so the maps' axes
are compared with SurfaceTopography's own positions of the same grid.

With xarray and SurfaceTopography installed (CI installs them) the test runs; without
them it is skipped, unless STRATA_REQUIRE_TOOLS=1 (CI), where it fails.
"""

import csv
import os

import numpy as np
import pytest

SCENE = """
[stack]
[[stack.layer]]
thickness = 1e-3
young = 4e9
poisson = 0.15
[stack.base]
kind = "elastic"
young = 4e9
poisson = 0.15
[surface]
file = "topo.nc"
detrend = "none"
[model]
kind = "bem"
[load]
approach = { from = 2e-7, to = 4e-7, steps = 2 }
[output]
maps = "last"
format = ["npy", "netcdf"]
"""


def need(module):
    try:
        return __import__(module)
    except ImportError:
        if os.environ.get("STRATA_REQUIRE_TOOLS") == "1":
            pytest.fail(f"{module} is not installed (STRATA_REQUIRE_TOOLS=1)")
        pytest.skip(f"{module} is not installed: *** this test did NOT run")


def test_netcdf_maps_keep_x_as_the_first_axis_on_a_rectangular_grid(tmp_path, cli):
    xr = need("xarray")
    st = need("SurfaceTopography")
    n0, n1, lx, ly = 64, 128, 1e-3, 2e-3
    i, j = np.meshgrid(np.arange(n0), np.arange(n1), indexing="ij")
    x, y = i / n0 - 0.4, j / n1 - 0.5
    # A bump, its top at x = 0.4 Lx, y = 0.5 Ly: a swap of the axes moves it.
    z = -1e-6 * (20 * x**2 + 4 * y**2)
    topo = st.Topography(z, (lx, ly), unit="m", periodic=False)
    topo.to_netcdf(str(tmp_path / "topo.nc"))
    (tmp_path / "scene.toml").write_text(SCENE)
    info = cli("surface", "info", tmp_path / "scene.toml").stdout
    assert "64" in info and "128" in info, info
    out = tmp_path / "out"
    cli("solve", tmp_path / "scene.toml", "--out", out, "--no-plots")
    rows = list(csv.DictReader(open(out / "maps" / "maps.csv")))
    with xr.open_dataset(out / "maps" / rows[-1]["netcdf_file"]) as ds:
        assert ds["pressure"].dims == ("x", "y")
        assert ds.sizes["x"] == n0 and ds.sizes["y"] == n1, dict(ds.sizes)
        # SurfaceTopography's positions of the input grid: x along the first axis. Its
        # file stores the lengths as float32 (scipy): 4.7e-8 relative measured, 5e-7 allowed.
        px, py = topo.positions()
        np.testing.assert_allclose(ds["x"].values, px[:, 0], rtol=5e-7, atol=0)
        np.testing.assert_allclose(ds["y"].values, py[0, :], rtol=5e-7, atol=0)
        assert ds["x"].values[-1] + ds["x"].values[1] == pytest.approx(lx, rel=5e-7)
        assert ds["y"].values[-1] + ds["y"].values[1] == pytest.approx(ly, rel=5e-7)
        np.testing.assert_allclose(ds.attrs["physical_sizes"], [lx, ly], rtol=5e-7)
        # The fields in the input's orientation: the .npy map element for element, the
        # contact at the bump's top.
        p = np.load(out / "maps" / rows[-1]["pressure_file"])
        assert np.array_equal(ds["pressure"].values, p)
        top = ds["pressure"].where(ds["pressure"] == ds["pressure"].max(), drop=True)
        assert abs(float(top["x"][0]) / lx - 0.4) < 0.05, top
        assert abs(float(top["y"][0]) / ly - 0.5) < 0.05, top
