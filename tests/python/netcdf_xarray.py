#!/usr/bin/env python3
"""Opens strata's NetCDF maps with xarray: contact.engineering's layout.

    python netcdf_xarray.py OUT_DIR

OUT_DIR is a `strata solve` output set of a BEM scene with `[output] maps = "all"` and
`format = ["npy", "netcdf"]` (tests/python/run.sh writes the scene and runs
`strata solve`). For every step, xarray (its scipy backend: no C NetCDF library) must read
`maps/results_step_KK.nc` with the variables `pressure`, `contacting_points`, `gap`,
`displacement` on dimensions (x, y), their units, contact.engineering's attributes
`mean_pressure` and `total_contact_area`, and fields equal bit for bit to the .npy maps
in the same orientation (x, the NetCDF's first dimension, is the maps' first axis).
"""
import csv
import sys
from pathlib import Path

import numpy as np
import xarray as xr


def same_bits(a, b):
    return a.shape == b.shape and np.array_equal(
        np.ascontiguousarray(a).view(np.uint64), np.ascontiguousarray(b).view(np.uint64)
    )


def main(out):
    out = Path(out)
    rows = list(csv.DictReader(open(out / "maps" / "maps.csv")))
    curve = list(csv.DictReader(open(out / "curve.csv")))
    assert rows, "maps.csv lists no step"
    for row, step in zip(rows, curve):
        path = out / "maps" / row["netcdf_file"]
        with xr.open_dataset(path) as ds:
            assert ds.attrs["type"] == "periodic", ds.attrs
            for name, unit in [("pressure", "Pa"), ("gap", "m"), ("displacement", "m")]:
                v = ds[name]
                assert v.dims == ("x", "y"), (name, v.dims)
                assert v.attrs["units"] == unit, (name, v.attrs)
                assert v.dtype == np.float64, (name, v.dtype)
            mask = ds["contacting_points"]
            assert mask.dims == ("x", "y") and mask.dtype == bool, mask
            assert ds["x"].attrs["units"] == "m" and ds["y"].attrs["units"] == "m"
            p = np.load(out / "maps" / row["pressure_file"])
            g = np.load(out / "maps" / row["gap_file"])
            assert same_bits(ds["pressure"].values, p), f"{path}: pressure"
            assert same_bits(ds["gap"].values, g), f"{path}: gap"
            assert np.array_equal(mask.values, p > 0), f"{path}: contacting_points"
            mp, area = float(step["mean_pressure"]), float(step["area_fraction"])
            assert abs(ds.attrs["mean_pressure"] / mp - 1) <= 1e-15, (ds.attrs, mp)
            assert ds.attrs["total_contact_area"] == area, (ds.attrs, area)
            assert ds.attrs["mean_pressure_units"] == "Pa"
            # contact.engineering's own reductions of the fields give the attributes.
            assert abs(float(ds["pressure"].mean()) / mp - 1) <= 1e-12
            assert float(mask.mean()) == area
            print(
                f"xarray {xr.__version__}: {path.name} dims {dict(ds.sizes)}, "
                f"mean_pressure {ds.attrs['mean_pressure']:.6e} Pa, "
                f"total_contact_area {ds.attrs['total_contact_area']:.4f}: equal to the .npy maps"
            )


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
