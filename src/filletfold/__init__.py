"""filletfold: curved-crease edge rounding of polyhedral meshes.

Turn a polyhedral mesh into a developable curved-crease design: every edge rounded by a
cylinder, every vertex a cone, and the flat pieces (with mountain/valley creases and fold
angles) that fold into it.

>>> import filletfold
>>> design = filletfold.round_mesh("icosahedron", radius="10%", depth="30%")
>>> design.status_counts()["ok"]
12
"""

__version__ = "0.1.0"

from .design import Design, Parameters, round_mesh
from .errors import (
    ExportError,
    FilletfoldError,
    MeshError,
    MeshReadError,
    ParameterError,
    SolverError,
)
from .mesh import PolyMesh, example_names, load_mesh
from .surface.pattern import CreasePattern

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
