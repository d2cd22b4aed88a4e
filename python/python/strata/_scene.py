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
    h_c per step (W/(m²·K) or S/m²) of a scene with ``[conductance]``, else None.
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

    def __len__(self) -> int:
        return len(self.delta)

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
    H, BEM and N model) and ``conductance`` its ``[conductance]`` table
    (``{"kind": "thermal"}``).
    """

    def __init__(self, stack, surface, model: str = "interacting", load=None, images: Optional[str] = None,
                 image_cells: Optional[int] = None, table=None, solver: Optional[Dict[str, Any]] = None,
                 counterface=None, counterface_surface=None, plasticity: Optional[Dict[str, Any]] = None,
                 conductance: Optional[Dict[str, Any]] = None):
        cs = None if counterface_surface is None else as_surface(counterface_surface)
        self._native = _strata.Scene(stack, as_surface(surface), model, load, images, image_cells, table,
                                     solver, counterface, cs, plasticity, conductance)

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

    def solve(self, progress: bool = False, cache_dir=None, maps: str = "none", table=None) -> Curve:
        """Solves the load curve with the scene's model (the engine of ``strata solve``).

        Releases the GIL. ``progress=True`` prints progress and log lines on stderr;
        ``maps="last"``/``"all"`` (BEM only) adds the pressure (Pa) and gap (m) maps;
        ``table`` (a :class:`Table` or path) overrides the scene's table and the cache.
        """
        cache = None if cache_dir is None else os.fspath(cache_dir)
        d = self._native.solve(progress, cache, maps, table)
        return Curve(**d)

    def law(self, samples: int = 200, min_gap: Optional[float] = None, progress: bool = False, cache_dir=None,
            table=None) -> _strata.ContactLaw:
        """The contact law p(g) of the interface, sampled as ``strata law`` does."""
        cache = None if cache_dir is None else os.fspath(cache_dir)
        return self._native.law(samples, min_gap, progress, cache, table)

    def __repr__(self) -> str:
        return repr(self._native)


def solve(scene, progress: bool = False, cache_dir=None, maps: str = "none", table=None) -> Curve:
    """Solves a scene: a :class:`Scene`, or the path of a scene TOML file.

    ``strata.solve("scenes/paper-E2E1-5-interacting.toml")`` gives the numbers of
    ``strata solve`` on the same file (its curve.csv columns as a :class:`Curve`).
    """
    if not isinstance(scene, Scene):
        scene = Scene.from_file(scene)
    return scene.solve(progress=progress, cache_dir=cache_dir, maps=maps, table=table)
