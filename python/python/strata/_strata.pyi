"""Type stubs of the native module ``strata._strata`` (built from python/src by maturin).

Every public class and function of the native module is declared here with its
signature (python/tests/test_stubs.py checks the names and the signatures' parameters
against the module itself, and runs mypy's stubtest). The classes are final (pyo3
classes cannot be subclassed); `Scene.from_toml`'s `dir` defaults to ".". SI units: m, Pa, N, N/m. Functions of a gap, a contact
radius or a wavenumber take a float (and return a float) or an array-like (and return a
float64 array of its shape).
"""

import os
import pathlib
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union, final, overload

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
_Array = npt.NDArray[np.float64]
_Layer = Union[Tuple[float, float, float], Sequence[float], Dict[str, float]]
_Base = Union[Literal["rigid"], Tuple[float, float], Sequence[float], Dict[str, float]]
_Repair = Literal["none", "median"]

__all__ = [
    "AsperityLaw",
    "CURVE_COLUMNS",
    "ContactLaw",
    "LawError",
    "Scene",
    "SceneError",
    "SolveError",
    "Stack",
    "StackError",
    "StrataError",
    "Surface",
    "SurfaceError",
    "Table",
    "TableError",
    "__version__",
    "indent",
]
__version__: str
#: The columns of curve.csv, in its order.
CURVE_COLUMNS: List[str]

class StrataError(ValueError):
    """Base class of every strata error (the library's message)."""

class StackError(StrataError): ...
class TableError(StrataError): ...
class SurfaceError(StrataError): ...
class SceneError(StrataError): ...
class SolveError(StrataError): ...
class LawError(StrataError): ...

@final
class Stack:
    """Elastic layers (top first) on a rigid base or an elastic half-space."""

    def __new__(
        cls,
        layers: Sequence[_Layer],
        base: Optional[_Base] = None,
        name: Optional[str] = None,
    ) -> "Stack": ...
    @staticmethod
    def from_file(path: _Path) -> "Stack": ...
    @staticmethod
    def from_toml(text: str) -> "Stack": ...
    @staticmethod
    def half_space(young: float, poisson: float) -> "Stack": ...
    def to_toml(self) -> str: ...
    @property
    def layers(self) -> List[Dict[str, float]]: ...
    @property
    def base(self) -> Union[Literal["rigid"], Dict[str, float]]: ...
    @property
    def name(self) -> Optional[str]: ...
    @property
    def e_star1(self) -> float: ...
    @property
    def is_homogeneous(self) -> bool: ...
    @property
    def total_thickness(self) -> float: ...
    @overload
    def compliance(self, rho: float) -> float: ...
    @overload
    def compliance(self, rho: npt.ArrayLike) -> _Array: ...
    def __eq__(self, other: object, /) -> bool: ...

@final
class AsperityLaw:
    """chi, zeta, g and S of one stack, interpolated from a table."""

    @overload
    def chi(self, a: float) -> float: ...
    @overload
    def chi(self, a: npt.ArrayLike) -> _Array: ...
    @overload
    def zeta(self, a: float) -> float: ...
    @overload
    def zeta(self, a: npt.ArrayLike) -> _Array: ...
    @overload
    def g(self, a: float, r: float) -> float: ...
    @overload
    def g(self, a: float, r: npt.ArrayLike) -> _Array: ...
    @overload
    def s(self, rho: float) -> float: ...
    @overload
    def s(self, rho: npt.ArrayLike) -> _Array: ...
    @property
    def a_range(self) -> Tuple[float, float]: ...
    @property
    def e_star1(self) -> float: ...

@final
class Table:
    """A surrogate table of the asperity law for a stack or a family of stacks."""

    @staticmethod
    def load(path: _Path) -> "Table": ...
    @staticmethod
    def build(
        stack: Union[Stack, _Path],
        progress: bool = False,
        nx: Optional[int] = None,
        nw: Optional[int] = None,
        ns: Optional[int] = None,
        check_points: int = 200,
        far_max: Optional[float] = None,
    ) -> "Table": ...
    def save(self, path: _Path) -> None: ...
    @property
    def stack(self) -> Stack: ...
    @property
    def info(self) -> Dict[str, Any]: ...
    def law(self, stack: Union[Stack, _Path, None] = None) -> AsperityLaw: ...
    @overload
    def chi(self, a: float) -> float: ...
    @overload
    def chi(self, a: npt.ArrayLike) -> _Array: ...
    @overload
    def zeta(self, a: float) -> float: ...
    @overload
    def zeta(self, a: npt.ArrayLike) -> _Array: ...
    @overload
    def g(self, a: float, r: float) -> float: ...
    @overload
    def g(self, a: float, r: npt.ArrayLike) -> _Array: ...
    @overload
    def s(self, rho: float) -> float: ...
    @overload
    def s(self, rho: npt.ArrayLike) -> _Array: ...

@final
class Surface:
    """A height map z (m) on an n0 x n1 grid (first axis x)."""

    def __new__(
        cls,
        heights: npt.ArrayLike,
        size: Union[float, Tuple[float, float], None] = None,
        pixel_size: Optional[Tuple[float, float]] = None,
        periodic: bool = False,
        repair: _Repair = "none",
    ) -> "Surface": ...
    @staticmethod
    def generate(
        size: float,
        grid: int,
        fractal_dimension: float,
        k_min: float,
        k_max: float,
        rms: float,
        seed: Optional[int] = None,
    ) -> "Surface": ...
    @staticmethod
    def read(
        path: _Path,
        size: Union[float, Tuple[float, float], None] = None,
        pixel_size: Optional[Tuple[float, float]] = None,
        periodic: bool = False,
        height_unit: Optional[Literal["m", "mm", "um", "nm"]] = None,
        detrend: Literal["none", "plane", "curvature"] = "none",
        repair: _Repair = "none",
        topography: Union[int, str, None] = None,
    ) -> "Surface": ...
    def write_npy(self, path: _Path) -> None: ...
    @property
    def heights(self) -> _Array: ...
    @property
    def shape(self) -> Tuple[int, int]: ...
    @property
    def pixel_size(self) -> Tuple[float, float]: ...
    @property
    def extent(self) -> Tuple[float, float]: ...
    @property
    def periodic(self) -> bool: ...
    @property
    def mean(self) -> float: ...
    @property
    def rms(self) -> float: ...
    @property
    def stats(self) -> Dict[str, Any]: ...
    @property
    def warnings(self) -> List[str]: ...

@final
class ContactLaw:
    """p(g), A(g)/A0 and dp/dg of a rough interface, sampled (Scene.law)."""

    @overload
    def pressure(self, gap: float) -> float: ...
    @overload
    def pressure(self, gap: npt.ArrayLike) -> _Array: ...
    @overload
    def area_fraction(self, gap: float) -> float: ...
    @overload
    def area_fraction(self, gap: npt.ArrayLike) -> _Array: ...
    @overload
    def dp_dg(self, gap: float) -> float: ...
    @overload
    def dp_dg(self, gap: npt.ArrayLike) -> _Array: ...
    @property
    def samples(self) -> Dict[str, npt.NDArray[Any]]: ...
    @property
    def first_contact_gap(self) -> float: ...
    @property
    def min_gap(self) -> float: ...
    @property
    def model(self) -> str: ...
    @property
    def solid(self) -> str: ...
    @property
    def e_star1(self) -> float: ...
    @property
    def nominal_area(self) -> float: ...
    @overload
    def conductance(self, gap: float) -> float: ...
    @overload
    def conductance(self, gap: npt.ArrayLike) -> _Array: ...
    @overload
    def conductance_at_pressure(self, pressure: float) -> float: ...
    @overload
    def conductance_at_pressure(self, pressure: npt.ArrayLike) -> _Array: ...
    @property
    def conductance_kind(self) -> Optional[str]: ...
    @overload
    def tangential_stiffness(self, gap: float) -> float: ...
    @overload
    def tangential_stiffness(self, gap: npt.ArrayLike) -> _Array: ...
    @overload
    def tangential_stiffness_at_pressure(self, pressure: float) -> float: ...
    @overload
    def tangential_stiffness_at_pressure(self, pressure: npt.ArrayLike) -> _Array: ...
    def csv(self) -> str: ...
    def abaqus(self) -> str: ...
    def write_abaqus(self, path: _Path) -> None: ...
    def calculix_warnings(self) -> List[str]: ...
    def __len__(self) -> int: ...

@final
class Scene:
    """A rough-contact case (the native scene; strata.Scene wraps it)."""

    def __new__(
        cls,
        stack: Union[Stack, _Path],
        surface: Surface,
        model: Literal["independent", "interacting", "bem"] = "interacting",
        load: Optional[Dict[str, Any]] = None,
        images: Optional[Literal["periodic", "isolated"]] = None,
        image_cells: Optional[int] = None,
        table: Union[Table, _Path, None] = None,
        solver: Optional[Dict[str, Any]] = None,
        counterface: Union[Stack, _Path, None] = None,
        counterface_surface: Optional[Surface] = None,
        plasticity: Optional[Dict[str, Any]] = None,
        conductance: Optional[Dict[str, Any]] = None,
        friction: Optional[Dict[str, Any]] = None,
    ) -> "Scene": ...
    @staticmethod
    def from_file(path: _Path) -> "Scene": ...
    @staticmethod
    def from_toml(text: str, dir: _Path = ...) -> "Scene": ...
    @property
    def stack(self) -> Stack: ...
    @property
    def model(self) -> Literal["independent", "interacting", "bem"]: ...
    @property
    def path(self) -> pathlib.Path: ...
    def surface(self) -> Surface: ...
    def solve(
        self,
        progress: Optional[bool] = None,
        cache_dir: Optional[_Path] = None,
        maps: Literal["none", "last", "all"] = "none",
        table: Union[Table, _Path, None] = None,
    ) -> Dict[str, Any]: ...
    def law(
        self,
        samples: int = 200,
        min_gap: Optional[float] = None,
        progress: Optional[bool] = None,
        cache_dir: Optional[_Path] = None,
        table: Union[Table, _Path, None] = None,
    ) -> ContactLaw: ...

def indent(
    stack: Union[Stack, _Path],
    radius: float,
    deltas: npt.ArrayLike,
    model: Literal["full", "approx"] = "full",
    table: Union[Table, _Path, None] = None,
    cache_dir: Optional[_Path] = None,
    progress: bool = False,
) -> Dict[str, _Array]: ...
