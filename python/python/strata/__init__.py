"""strata: normal contact of rough surfaces on multi-layered elastic solids.

Python bindings of the strata workspace (Waddad et al., *A new contact model for
multi-layered solids with rough surfaces*). SI units everywhere: m, Pa, N, N/m.

Concepts (each mirrors the library's):

- :class:`Stack` -- elastic layers on a rigid or elastic base; ``compliance(rho)`` is S(rho).
- :class:`Table` -- surrogate table of the asperity law: ``load``, ``build``, ``save``,
  lookups ``chi``, ``zeta``, ``g``, ``s``; ``law(stack)`` gives an :class:`AsperityLaw`.
- :class:`Surface` -- a height map: from a numpy array (``size`` or ``pixel_size``,
  ``periodic``), ``generate(...)``, ``read(path)`` (.npy, .x3p, text);
  :func:`from_topography` takes a SurfaceTopography topography.
- :class:`Scene` and :func:`solve` -- a rough-contact case solved by the engine of
  ``strata solve``: a :class:`Curve` with the columns of curve.csv.
- :class:`ContactLaw` -- p(g), A(g)/A0, dp/dg of the interface and its Abaqus table
  (``Scene.law``).
- :func:`indent` -- one paraboloid asperity, full Fredholm solution or approximation.

Errors are :class:`StrataError` (a ``ValueError``) subclasses carrying the library's
message; a missing input file is ``FileNotFoundError``.
"""

from ._strata import (
    AsperityLaw,
    ContactLaw,
    LawError,
    SceneError,
    SolveError,
    Stack,
    StackError,
    StrataError,
    Surface,
    SurfaceError,
    Table,
    TableError,
    __version__,
    indent,
)
from . import _progress  # noqa: F401  (the native module's display of a call's progress)
from ._scene import Curve, Scene, solve
from .topography import from_topography

__all__ = [
    "AsperityLaw",
    "ContactLaw",
    "Curve",
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
    "from_topography",
    "indent",
    "solve",
]
