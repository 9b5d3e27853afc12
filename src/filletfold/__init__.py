"""filletfold: curved-crease edge rounding of polyhedral meshes.

Turn a polyhedral mesh into a developable curved-crease design: every edge rounded by a
cylinder, every vertex a cone, and the flat pieces (with mountain/valley creases and fold
angles) that fold into it.

>>> import filletfold
>>> design = filletfold.round_mesh("icosahedron", radius="10%", depth="30%")
>>> design.status_counts()["ok"]
12
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

__version__ = "0.1.0"

from .errors import (
    ExportError,
    FilletfoldError,
    MeshError,
    MeshReadError,
    ParameterError,
    SolverError,
)

if TYPE_CHECKING:
    from .design import Design, round_mesh
    from .mesh import PolyMesh, example_names, load_mesh
    from .parameters import Parameters
    from .surface.pattern import CreasePattern

# The rest of the API is imported on first use (PEP 562), so that ``import filletfold`` and
# the command line's start stay fast: these modules load numpy, scipy and shapely.
_LAZY = {
    "CreasePattern": ".surface.pattern",
    "Design": ".design",
    "Parameters": ".parameters",
    "PolyMesh": ".mesh",
    "example_names": ".mesh",
    "load_mesh": ".mesh",
    "round_mesh": ".design",
}

__all__ = [
    "CreasePattern",
    "Design",
    "ExportError",
    "FilletfoldError",
    "MeshError",
    "MeshReadError",
    "ParameterError",
    "Parameters",
    "PolyMesh",
    "SolverError",
    "__version__",
    "example_names",
    "load_mesh",
    "round_mesh",
]


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is not None:
        value = getattr(importlib.import_module(module, __name__), name)
    elif not name.startswith("_"):  # a subpackage, as ``filletfold.mesh`` was once imported
        try:
            value = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":
                raise
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
