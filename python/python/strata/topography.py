"""SurfaceTopography interoperability by duck typing (no import of SurfaceTopography).

A topography object with ``heights()`` (a 2-D array, m), ``physical_sizes`` ((Lx, Ly),
m) and ``is_periodic`` goes into strata as it is: :func:`from_topography`, or directly
as the ``surface`` of :class:`strata.Scene`. SurfaceTopography's first array axis is x,
as strata's.
"""

from __future__ import annotations

import numpy as np

from . import _strata


def _is_topography(obj) -> bool:
    return callable(getattr(obj, "heights", None)) and hasattr(obj, "physical_sizes")


def from_topography(topography, periodic=None, repair: str = "none", unit_factor: float = 1.0) -> _strata.Surface:
    """A :class:`strata.Surface` from a SurfaceTopography topography (duck typing).

    Uses ``topography.heights()`` (2-D), ``physical_sizes`` (Lx, Ly) and
    ``is_periodic`` (overridden by ``periodic``). strata works in metres: a topography
    in another unit (``topography.unit`` is ``"um"``, ``"mm"``, ``"nm"``) is converted,
    and ``unit_factor`` multiplies heights and sizes on top (for topographies without
    a unit). Raises strata.SurfaceError for a line scan, non-finite heights
    (``repair="median"`` interpolates them) or missing sizes.
    """
    if not _is_topography(topography):
        raise _strata.SurfaceError(
            "from_topography: expected an object with heights(), physical_sizes and is_periodic "
            f"(a SurfaceTopography topography), got {type(topography).__name__}")
    heights = np.asarray(topography.heights())
    if heights.ndim != 2:
        raise _strata.SurfaceError(
            f"from_topography: a 2-D topography is needed, got {heights.ndim} dimension(s) (a line scan?)")
    sizes = topography.physical_sizes
    if sizes is None or len(sizes) != 2:
        raise _strata.SurfaceError("from_topography: the topography has no physical_sizes (Lx, Ly)")
    factor = float(unit_factor) * _unit_to_metres(getattr(topography, "unit", None))
    lx, ly = (float(s) * factor for s in sizes)
    if periodic is None:
        periodic = bool(getattr(topography, "is_periodic", False))
    z = heights * factor if factor != 1.0 else heights
    if np.ma.isMaskedArray(z):
        z = z.filled(np.nan)
    return _strata.Surface(np.ascontiguousarray(z, dtype=np.float64) if z.dtype.kind == "f" else z,
                           size=(lx, ly), periodic=periodic, repair=repair)


_UNITS = {None: 1.0, "m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "nm": 1e-9, "pm": 1e-12}


def _unit_to_metres(unit) -> float:
    try:
        return _UNITS[unit]
    except KeyError:
        raise _strata.SurfaceError(
            f"from_topography: unknown topography unit {unit!r} (known: m, mm, um, nm, pm)") from None


def as_surface(obj) -> _strata.Surface:
    """``obj`` if it is a :class:`strata.Surface`, else :func:`from_topography` of it."""
    if isinstance(obj, _strata.Surface):
        return obj
    if _is_topography(obj):
        return from_topography(obj)
    raise _strata.SurfaceError(
        f"surface: expected a strata.Surface or a SurfaceTopography topography, got {type(obj).__name__}")
