"""SurfaceTopography interoperability: a topography goes in as it is (duck typing).

With SurfaceTopography installed (CI installs it from PyPI) the real package is used;
without it the test is skipped, unless STRATA_REQUIRE_TOOLS=1 (CI), where it fails.
A duck-typed stand-in is always tested.
"""

import os

import numpy as np
import pytest

import strata


class StandIn:
    """What strata reads of a SurfaceTopography topography."""

    def __init__(self, h, sizes, periodic, unit=None):
        self._h, self.physical_sizes, self.is_periodic = h, sizes, periodic
        if unit is not None:
            self.unit = unit

    def heights(self):
        return self._h


def surface_topography():
    try:
        import SurfaceTopography
    except ImportError:
        if os.environ.get("STRATA_REQUIRE_TOOLS") == "1":
            pytest.fail("SurfaceTopography is not installed (STRATA_REQUIRE_TOOLS=1)")
        pytest.skip("SurfaceTopography is not installed: *** this test did NOT run")
    return SurfaceTopography


def reference():
    return strata.Surface.generate(size=1e-3, grid=64, fractal_dimension=2.4, k_min=2, k_max=16, rms=2e-6, seed=11)


def test_stand_in_rectangular_and_units():
    ref = reference()
    z = ref.heights[:, :48]
    s = strata.from_topography(StandIn(z, (1e-3, 0.75e-3), False))
    np.testing.assert_array_equal(s.heights, z)
    assert s.extent == pytest.approx((1e-3, 0.75e-3), rel=1e-15)
    assert not s.periodic
    um = strata.from_topography(StandIn(z * 1e6, (1e3, 750.0), False, unit="um"))
    np.testing.assert_allclose(um.heights, z, rtol=1e-15)
    assert um.pixel_size == pytest.approx(s.pixel_size, rel=1e-15)


def test_stand_in_errors():
    with pytest.raises(strata.SurfaceError, match="line scan"):
        strata.from_topography(StandIn(np.zeros(16), (1e-3,), False))
    with pytest.raises(strata.SurfaceError, match="unit"):
        strata.from_topography(StandIn(np.zeros((8, 8)), (1e-3, 1e-3), False, unit="furlong"))
    with pytest.raises(strata.SurfaceError, match="heights"):
        strata.from_topography(object())
    z = reference().heights
    z[3, 4] = np.nan
    with pytest.raises(strata.SurfaceError, match="row 3, column 4"):
        strata.from_topography(StandIn(z, (1e-3, 1e-3), True))


def test_surface_topography_into_a_scene():
    """A SurfaceTopography Topography solves to the same curve as the strata surface."""
    ST = surface_topography()
    ref = reference()
    topo = ST.Topography(ref.heights, physical_sizes=(1e-3, 1e-3), periodic=True)
    s = strata.from_topography(topo)
    np.testing.assert_array_equal(s.heights, ref.heights)
    assert s.periodic and s.pixel_size == ref.pixel_size
    stack = strata.Stack.half_space(210e9, 0.3)
    load = {"approach": {"from": 2e-7, "to": 2e-6, "steps": 5}}
    a = strata.Scene(stack, topo, model="interacting", load=load).solve()
    b = strata.Scene(stack, ref, model="interacting", load=load).solve()
    for c in ("gap", "mean_pressure", "area_fraction", "contacts"):
        np.testing.assert_array_equal(getattr(a, c), getattr(b, c))
    # in micrometres, detrended by SurfaceTopography itself
    topo_um = ST.Topography(ref.heights * 1e6, physical_sizes=(1e3, 1e3), unit="um", periodic=True)
    s_um = strata.from_topography(topo_um.detrend("center"))
    np.testing.assert_allclose(s_um.heights, ref.heights - ref.heights.mean(), atol=1e-18)
    np.testing.assert_allclose(s_um.extent, (1e-3, 1e-3), rtol=1e-15)


def netcdf_scene(tmp_path, surface_lines, model):
    return strata.Scene.from_toml(
        f"""
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
{surface_lines}
[model]
kind = "{model}"
[load]
approach = {{ from = 1e-6, to = 4e-6, steps = 4 }}
""",
        dir=str(tmp_path),
    )


@pytest.mark.parametrize("model", ["bem", "interacting"])
def test_netcdf_topography_solves_as_the_npy_heights(tmp_path, model):
    """A NetCDF topography written by SurfaceTopography (heights in µm, periodic flag,
    physical sizes in its attributes) solves to the same curve as the same heights in
    metres from .npy with the sizes and periodicity given in the scene (1e-12)."""
    st = surface_topography()
    h_um = reference().heights * 1e6
    lx_um, ly_um = 1000.0, 1000.0
    st.Topography(h_um, (lx_um, ly_um), unit="um", periodic=True).to_netcdf(str(tmp_path / "topo.nc"))
    np.save(tmp_path / "heights.npy", h_um * 1e-6)
    from_nc = netcdf_scene(tmp_path, 'file = "topo.nc"', model)
    from_npy = netcdf_scene(
        tmp_path,
        f'file = "heights.npy"\nsize = [{lx_um * 1e-6!r}, {ly_um * 1e-6!r}]\nperiodic = true',
        model,
    )
    s_nc, s_npy = from_nc.surface(), from_npy.surface()
    assert s_nc.periodic and s_nc.shape == s_npy.shape
    assert s_nc.extent == s_npy.extent
    assert np.array_equal(s_nc.heights, s_npy.heights)
    a, b = strata.solve(from_nc), strata.solve(from_npy)
    for col in ("delta", "gap", "mean_pressure", "area_fraction", "stiffness"):
        x, y = getattr(a, col), getattr(b, col)
        assert np.allclose(x, y, rtol=1e-12, atol=0), (col, x, y)
    assert a.contacts.tolist() == b.contacts.tolist()
    assert (a.mean_pressure > 0).all()


def test_netcdf_topography_read_directly(tmp_path):
    """Surface.read of SurfaceTopography's file: unit, sizes and periodic flag honoured;
    a size given beside the file's, or another height unit, is refused."""
    st = surface_topography()
    h = reference().heights
    st.Topography(h * 1e9, (2e6, 1e6), unit="nm", periodic=False).to_netcdf(str(tmp_path / "t.nc"))
    s = strata.Surface.read(tmp_path / "t.nc")
    assert not s.periodic
    assert np.array_equal(s.heights, h * 1e9 * 1e-9)
    assert s.extent == (2e6 * 1e-9, 1e6 * 1e-9)
    with pytest.raises(strata.SurfaceError, match="physical sizes"):
        strata.Surface.read(tmp_path / "t.nc", size=1e-3)
    with pytest.raises(strata.SurfaceError, match="height_unit"):
        strata.Surface.read(tmp_path / "t.nc", height_unit="um")
