"""Stage 1, the mesh: reading (:mod:`.io`), built-in examples and tessellations
(:mod:`.examples`, :mod:`.tessellations`), validation, cleaning and repair (:mod:`.clean`,
:mod:`.repair`, :mod:`.intersect`), half-edge connectivity (:mod:`.polymesh`), the
measures of polygons the stages share (:mod:`.measures`), coarsening by quadric
decimation (:mod:`.coarsen`, the ``faces`` parameter), and which way is up (:mod:`.upright`,
the ``up`` parameter).

:func:`load_mesh` is the one entry point front ends call: it accepts a file, a built-in example
name, a ``(vertices, faces)`` pair or a :class:`PolyMesh`, and returns a cleaned mesh.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import MeshError, MeshReadError
from ..tolerances import tol
from .clean import CleanLog, clean_mesh
from .examples import EXAMPLES, Example, example_mesh, example_names, find_example
from .examples import unknown_example_message as _unknown_example_message
from .io import SUPPORTED_EXTENSIONS, read_mesh, write_obj, write_off
from .polymesh import PolyMesh, VertexRing, too_many_corners
from .repair import Repair

__all__ = [
    "EXAMPLES",
    "SUPPORTED_EXTENSIONS",
    "CleanLog",
    "Example",
    "PolyMesh",
    "Repair",
    "VertexRing",
    "clean_mesh",
    "example_mesh",
    "example_names",
    "load_mesh",
    "read_mesh",
    "write_obj",
    "write_off",
]


def load_mesh(
    source,
    *,
    coplanar_deg: float = tol.coplanar_deg,
    merge_coplanar: bool = True,
    strict: bool = False,
    max_corners: int | None = None,
) -> tuple[PolyMesh, CleanLog]:
    """Load and clean a mesh from a file, a built-in example, arrays, or a PolyMesh.

    Parameters
    ----------
    source : str, os.PathLike, tuple or PolyMesh
        * a path to an existing mesh file (see :func:`read_mesh`);
        * a built-in example name (a str that is not an existing path), see
          :func:`example_names`;
        * a pair ``(vertices, faces)``: vertices ``(n, 3)`` float, faces an ``(m, k)`` int array
          or a list of index lists;
        * a :class:`PolyMesh`, cleaned again.
    coplanar_deg, merge_coplanar, strict
        Passed to :func:`clean_mesh` (``strict``: refuse defects instead of repairing them).
    max_corners : int, optional
        Refuse, before it is cleaned, a face with more distinct corners than this
        (:func:`~filletfold.mesh.polymesh.check_corners` then bounds the cleaned mesh): the
        cleaning's work on a face grows faster than its corners (a 10,000-gon: 35 s).

    Returns
    -------
    mesh : PolyMesh
    log : CleanLog

    Raises
    ------
    MeshReadError
        The file cannot be read, or a str names neither an existing file nor an example.
    MeshError
        The mesh is invalid (see :func:`clean_mesh`).
    """
    path = None  # the file, when the mesh is one: its errors name it
    if isinstance(source, PolyMesh):
        vertices, faces = source.vertices, source.faces
    elif isinstance(source, str):
        if Path(source).exists():
            vertices, faces = read_mesh(source)
            path = source
        elif find_example(source) is not None:
            vertices, faces = example_mesh(source)
        else:
            raise MeshReadError(
                f"{source}: no such file and no built-in example named {source!r}; "
                f"{_unknown_example_message(source)}"
            )
    elif isinstance(source, os.PathLike):
        vertices, faces = read_mesh(source)
        path = os.fspath(source)
    elif isinstance(source, tuple | list) and len(source) == 2:
        vertices, faces = source
        if isinstance(faces, np.ndarray) and faces.ndim == 2:
            faces = list(faces)
    else:
        raise MeshReadError(
            f"cannot load a mesh from a {type(source).__name__}: expected a file path, a "
            f"built-in example name, a (vertices, faces) pair or a PolyMesh"
        )
    if max_corners is not None:
        _check_raw_corners(faces, max_corners, path)
    try:
        return clean_mesh(
            vertices, faces, coplanar_deg=coplanar_deg, merge_coplanar=merge_coplanar, strict=strict
        )
    except MeshError as exc:
        if path is None or str(exc).startswith(f"{path}:"):
            raise
        named = type(exc)(f"{path}: {exc}")
        named.vertex, named.edge, named.face = exc.vertex, exc.edge, exc.face
        raise named from None


def _check_raw_corners(faces, limit: int, path) -> None:
    """A :class:`MeshError` naming the first face of ``faces`` (as read) with more distinct
    corners than ``limit`` (a face that repeats its corners is the cleaning's to repair)."""
    for f, face in enumerate(faces):
        if len(face) <= limit:
            continue
        distinct = len(set(np.asarray(face).tolist()))
        if distinct > limit:
            where = f"{path}: " if path is not None else ""
            raise too_many_corners(f"{where}face {f} has {distinct} corners", limit, face=f)
