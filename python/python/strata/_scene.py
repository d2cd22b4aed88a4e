"""Scenes and their solution: :class:`Scene`, :func:`solve` and the :class:`Curve` dataclass."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Union

import numpy as np

from . import _strata
from .topography import as_surface

#: The columns of curve.csv, in its order (``strata solve``; from the library).
CURVE_COLUMNS = tuple(_strata.CURVE_COLUMNS)

#: SI unit of every per-step field of a :class:`Curve` ("1": dimensionless or a count).
UNITS = {
    "delta": "m",
    "gap": "m",
    "mean_pressure": "Pa",
    "pressure_ratio": "1",
    "area_fraction": "1",
    "contacts": "1",
    "stiffness": "N/m",
    "load": "N",
    "kkt_residual": "1",
    "valid": "1",
}

#: What every per-step field of a :class:`Curve` is (xarray's ``long_name``).
LONG_NAMES = {
    "delta": "approach of the flat from first contact",
    "gap": "separation of the mean planes",
    "mean_pressure": "mean (nominal) contact pressure P/A0",
    "pressure_ratio": "mean pressure over E*1",
    "area_fraction": "real contact area fraction A/A0",
    "contacts": "asperities (or BEM patches) in contact",
    "stiffness": "normal stiffness dP/d(delta) of the sample",
    "load": "total load P",
    "kkt_residual": "I-model KKT residual relative to the largest interference",
    "valid": "inside the asperity model's validity",
    "conductance": "interface conductance h_c",
    "tangential_stiffness": "full-stick tangential stiffness K_t of the sample",
}


def _optional(module: str, method: str):
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise ImportError(f"Curve.{method}() needs {module}: pip install {module}") from e


@dataclass
class Curve:
    """A solved load curve: one entry per load step, in the scene's order.

    The columns of ``curve.csv`` (the first seven fields and ``valid``): approach ``delta`` (m),
    separation of the mean planes ``gap`` (m, paper eq. 26), ``mean_pressure`` p = P/A0
    (Pa), ``pressure_ratio`` p/E*1, ``area_fraction`` A/A0, ``contacts`` (asperities in
    contact, or contact patches for the BEM), ``stiffness`` dP/d(delta) of the
    sample (N/m) and ``valid`` (inside the asperity model's validity; 1/0 in the
    file). Then ``load`` P (N), ``kkt_residual`` (I model; NaN otherwise), ``meta`` (curve.json's summary)
    and ``maps`` (BEM pressure/gap maps when asked); ``conductance``: the interface conductance
    h_c per step (W/(m²·K) or S/m²) of a scene with ``[conductance]``, else None;
    ``tangential_stiffness``: the full-stick tangential stiffness K_t of the sample per step
    (N/m) of a scene with ``[friction]``, else None; ``tangential``: the BEM's tangential path
    of a scene with ``[load] tangential`` (the columns of ``tangential.csv`` as arrays:
    ``force_ratio`` Q/(muP), ``tangential_force`` (N), ``tangential_displacement`` (m),
    ``stick_fraction``; and ``dissipation`` (J) per step, ``normal_force`` P (N),
    ``coefficient`` mu), else None.
    """

    delta: np.ndarray
    gap: np.ndarray
    mean_pressure: np.ndarray
    pressure_ratio: np.ndarray
    area_fraction: np.ndarray
    contacts: np.ndarray
    stiffness: np.ndarray
    load: np.ndarray
    kkt_residual: np.ndarray
    valid: np.ndarray
    meta: Dict[str, Any] = field(default_factory=dict)
    maps: List[Dict[str, Any]] = field(default_factory=list)
    conductance: Optional[np.ndarray] = None
    tangential_stiffness: Optional[np.ndarray] = None
    tangential: Optional[Dict[str, Any]] = None

    def __len__(self) -> int:
        return len(self.delta)

    def units(self) -> Dict[str, str]:
        """The SI unit of every per-step field (``conductance``'s from ``meta`` when present)."""
        units = dict(UNITS)
        if self.conductance is not None:
            cond = self.meta.get("conductance", {}) if isinstance(self.meta, dict) else {}
            units["conductance"] = cond.get("units", {}).get("conductance", "W/(m^2 K)")
        if self.tangential_stiffness is not None:
            units["tangential_stiffness"] = "N/m"
        return units

    def _fields(self) -> Dict[str, np.ndarray]:
        names = list(UNITS) + (["conductance"] if self.conductance is not None else [])
        names += ["tangential_stiffness"] if self.tangential_stiffness is not None else []
        return {n: np.asarray(getattr(self, n)) for n in names}

    def to_pandas(self):
        """The per-step fields as a ``pandas.DataFrame``, one row per load step (index
        ``step``); units in ``df.attrs["units"]`` (field -> SI unit) and curve.json's summary
        in ``df.attrs["meta"]``. Needs pandas (an ImportError saying so otherwise)."""
        pd = _optional("pandas", "to_pandas")
        df = pd.DataFrame(self._fields(), index=pd.RangeIndex(len(self), name="step"))
        df.attrs["units"] = self.units()
        df.attrs["meta"] = self.meta
        return df

    def to_xarray(self):
        """The per-step fields as an ``xarray.Dataset`` along dimension ``step``, each variable
        with ``attrs["units"]`` (SI) and ``attrs["long_name"]``; the approach ``delta`` is also a
        coordinate. Dataset attributes: ``model`` and the nominal area when known. Needs xarray
        (an ImportError saying so otherwise)."""
        xr = _optional("xarray", "to_xarray")
        units = self.units()
        data = {
            n: ("step", v, {"units": units[n], "long_name": LONG_NAMES[n]})
            for n, v in self._fields().items()
        }
        ds = xr.Dataset(data, coords={"step": np.arange(len(self))})
        ds = ds.assign_coords(approach=("step", np.asarray(self.delta), {"units": "m"}))
        meta = self.meta if isinstance(self.meta, dict) else {}
        for key in ("model", "scene"):
            if isinstance(meta.get(key), str):
                ds.attrs[key] = meta[key]
        return ds

    def columns(self) -> Dict[str, np.ndarray]:
        """The curve.csv columns as a dict of arrays (for ``pandas.DataFrame``)."""
        return {c: getattr(self, c) for c in CURVE_COLUMNS}

    def to_csv(self, path: Union[str, os.PathLike]) -> None:
        """Writes the curve.csv columns (full precision) to ``path``."""
        cols = self.columns()
        with open(path, "w", encoding="utf-8") as f:
            f.write(",".join(CURVE_COLUMNS) + "\n")
            for i in range(len(self)):
                f.write(",".join(str(int(cols[c][i])) if c in ("contacts", "valid") else repr(float(cols[c][i]))
                                 for c in CURVE_COLUMNS) + "\n")


class Scene:
    """A rough-contact case: stack, surface, model and load (see ``_strata.Scene``).

    ``Scene.from_file(path)`` reads a scene TOML file as ``strata solve`` does;
    ``Scene(stack, surface, model="interacting", load={...})`` builds one from Python
    objects, where ``surface`` may also be a SurfaceTopography topography.
    ``solver`` is the scene's ``[solver]`` table as a dict: the budgets and tolerances
    an error message may ask to raise (``{"max_step_newton_steps": 40000}``, ...).
    ``counterface`` (a :class:`Stack` or stack file) presses the first body against a second
    elastic body instead of a rigid flat (the two compliances add; the pair's E* is in every
    normalisation); ``counterface_surface`` is that body's roughness, heights as seen from the
    first body on the same grid (added to ``surface``). ``plasticity`` is the scene's
    ``[plasticity]`` table as a dict (``{"hardness": 0.4e9}``: the contact pressure capped at
    H, BEM and N model), ``conductance`` its ``[conductance]`` table
    (``{"kind": "thermal"}``) and ``friction`` its ``[friction]`` table (``{"coefficient": 0.3}``:
    the full-stick tangential stiffness of every step, every model); with it a BEM scene's
    ``load`` may hold ``"tangential": {"from": .., "to": .., "steps": ..}`` (ratios Q/(muP) of a
    tangential path at the last step: ``Curve.tangential``).
    """

    def __init__(self, stack, surface, model: str = "interacting", load=None, images: Optional[str] = None,
                 image_cells: Optional[int] = None, table=None, solver: Optional[Dict[str, Any]] = None,
                 counterface=None, counterface_surface=None, plasticity: Optional[Dict[str, Any]] = None,
                 conductance: Optional[Dict[str, Any]] = None, friction: Optional[Dict[str, Any]] = None):
        cs = None if counterface_surface is None else as_surface(counterface_surface)
        self._native = _strata.Scene(stack, as_surface(surface), model, load, images, image_cells, table,
                                     solver, counterface, cs, plasticity, conductance, friction)

    @classmethod
    def _wrap(cls, native) -> "Scene":
        s = cls.__new__(cls)
        s._native = native
        return s

    @classmethod
    def from_file(cls, path: Union[str, os.PathLike]) -> "Scene":
        """Reads a scene TOML file (paths in it are relative to its directory)."""
        return cls._wrap(_strata.Scene.from_file(os.fspath(path)))

    @classmethod
    def from_toml(cls, text: str, dir: Union[str, os.PathLike] = ".") -> "Scene":
        """Parses a scene from TOML text; relative paths resolve against ``dir``."""
        return cls._wrap(_strata.Scene.from_toml(text, os.fspath(dir)))

    @property
    def stack(self) -> _strata.Stack:
        return self._native.stack

    @property
    def model(self) -> str:
        """``"independent"``, ``"interacting"`` or ``"bem"``."""
        return self._native.model

    def surface(self) -> _strata.Surface:
        """The scene's surface (read or generated now, or the one given)."""
        return self._native.surface()

    def solve(self, progress: Optional[bool] = None, cache_dir=None, maps: str = "none", table=None) -> Curve:
        """Solves the load curve with the scene's model (the engine of ``strata solve``).

        Runs off the GIL. ``progress=True`` shows progress and log lines (in a Jupyter notebook
        in the cell's output, else on stderr), ``False`` only warnings; ``None`` (default) shows
        progress in a notebook or on a terminal, not in batch. Ctrl-C (``KeyboardInterrupt``)
        stops the solve within about one iteration and keeps nothing of it;
        ``maps="last"``/``"all"`` (BEM only) adds the pressure (Pa) and gap (m) maps;
        ``table`` (a :class:`Table` or path) overrides the scene's table and the cache.
        """
        cache = None if cache_dir is None else os.fspath(cache_dir)
        d = self._native.solve(progress, cache, maps, table)
        return Curve(**d)

    def law(self, samples: int = 200, min_gap: Optional[float] = None, progress: Optional[bool] = None,
            cache_dir=None, table=None) -> _strata.ContactLaw:
        """The contact law p(g) of the interface, sampled as ``strata law`` does (progress and
        Ctrl-C as in :meth:`solve`)."""
        cache = None if cache_dir is None else os.fspath(cache_dir)
        return self._native.law(samples, min_gap, progress, cache, table)

    def __repr__(self) -> str:
        return repr(self._native)


def solve(scene, progress: Optional[bool] = None, cache_dir=None, maps: str = "none", table=None) -> Curve:
    """Solves a scene: a :class:`Scene`, or the path of a scene TOML file.

    ``strata.solve("scenes/paper-E2E1-5-interacting.toml")`` gives the numbers of
    ``strata solve`` on the same file (its curve.csv columns as a :class:`Curve`).
    """
    if not isinstance(scene, Scene):
        scene = Scene.from_file(scene)
    return scene.solve(progress=progress, cache_dir=cache_dir, maps=maps, table=table)
