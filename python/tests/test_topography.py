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
