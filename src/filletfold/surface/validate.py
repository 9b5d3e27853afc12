"""Whether a crease pattern is complete and consistent: what every exporter checks before it
writes (faces of valid vertex indices, counter-clockwise in 2D, edges and assignments of the
right shapes, finite coordinates)."""

from __future__ import annotations

import itertools
import operator

import numpy as np

from ..arrays import run_starts
from ..errors import ExportError
from ..tolerances import tol
from .patch import Patch
from .pattern import CreasePattern, FlatFaces, face_arrays

#: The edge assignments a pattern may have: the FOLD ``edges_assignment`` values written.
ASSIGNMENTS = ("M", "V", "B", "F")


def face_signed_area_2d(vertices_2d: np.ndarray, faces: list) -> np.ndarray:
    """Signed area of each face in the flat layout (shoelace formula).

    Parameters
    ----------
    vertices_2d : (n, 2) float
    faces : list of (k,) int

    Returns
    -------
    (n_faces,) float
        Positive for counter-clockwise faces.
    """
    if len(faces) == 0:
        return np.zeros(0)
    a, start = face_arrays(faces)
    return _signed_area(vertices_2d, a.astype(np.int64, copy=False), start)


def _signed_area(vertices_2d: np.ndarray, a: np.ndarray, start: np.ndarray) -> np.ndarray:
    """:func:`face_signed_area_2d` of faces given as :func:`face_arrays`."""
    if len(start) < 2:
        return np.zeros(0)
    nxt = np.arange(len(a)) + 1
    nxt[start[1:] - 1] = start[:-1]
    p, q = vertices_2d[a], vertices_2d[a[nxt]]
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
    return 0.5 * np.add.reduceat(cross, start[:-1])


def _face_arrays_if_valid(faces, n: int) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`face_arrays` when every face is a 1-D list of at least 3 integer indices in
    ``0..n-1``, checked all at once; None otherwise (or when the faces cannot be read that
    way): :func:`validate_pattern` then finds the first bad face."""
    if not isinstance(faces, FlatFaces) and not _integer_faces(faces):  # (integers as made)
        return None
    try:
        flat, start = face_arrays(faces)
    except (TypeError, ValueError):
        return None
    ok = (
        flat.ndim == 1
        and len(flat) == start[-1]
        and np.issubdtype(flat.dtype, np.integer)
        and (len(faces) == 0 or (np.diff(start).min() >= 3 and flat.min() >= 0 and flat.max() < n))
    )
    return (flat, start) if ok else None


def _integer_faces(faces) -> bool:
    """Whether every face is an integer array, or a list or tuple of integers (not booleans),
    so that joining them keeps each face's values (no face of booleans read as 0 and 1)."""
    kinds = set(map(type, faces))
    if not kinds <= {np.ndarray, list, tuple}:
        return False
    if kinds == {np.ndarray}:
        dtypes = set(map(operator.attrgetter("dtype"), faces))
        return all(np.issubdtype(dtype, np.integer) for dtype in dtypes)
    arrays = [f for f in faces if type(f) is np.ndarray]
    if any(not np.issubdtype(f.dtype, np.integer) for f in arrays):
        return False
    items = [f for f in faces if type(f) is not np.ndarray] if arrays else faces
    return all(
        t is not bool and issubclass(t, int | np.integer)
        for t in set(map(type, itertools.chain.from_iterable(items)))
    )


def validate_pattern(pattern: CreasePattern) -> None:
    """Check that a crease pattern is complete and consistent enough to export.

    See :func:`validated_faces`, which this calls.

    Raises
    ------
    ExportError
        Naming the first offending element.
    """
    validated_faces(pattern)


def validated_faces(pattern: CreasePattern) -> tuple[np.ndarray, np.ndarray]:
    """Check a crease pattern (see below) and return its faces as :func:`face_arrays`.

    Checks: matching vertex counts in 2D and 3D, finite coordinates, faces of at least three
    in-range vertex indices, one patch name and one piece per face, edge arrays of one length,
    assignments among ``M V B F`` with fold angles of the matching sign (valley > 0, mountain < 0,
    zero for ``B``/``F``), and faces counter-clockwise in 2D.

    Parameters
    ----------
    pattern : CreasePattern

    Raises
    ------
    ExportError
        Naming the first offending element.
    """
    if not isinstance(pattern, CreasePattern):
        raise ExportError(f"expected a CreasePattern, got {type(pattern).__name__}")
    v2, v3 = pattern.vertices_2d, pattern.vertices_3d
    n = len(v2)
    if v2.ndim != 2 or v2.shape[1] != 2 or v3.ndim != 2 or v3.shape[1] != 3:
        raise ExportError("pattern vertices must be (n, 2) in 2D and (n, 3) in 3D")
    if len(v3) != n:
        raise ExportError(f"pattern has {n} vertices in 2D but {len(v3)} in 3D")
    for name, arr in (("vertices_2d", v2), ("vertices_3d", v3)):
        bad = np.flatnonzero(~np.isfinite(arr).all(axis=1))
        if len(bad):
            raise ExportError(f"pattern {name}[{bad[0]}] is not finite")
    n_faces = len(pattern.faces)
    checked = _face_arrays_if_valid(pattern.faces, n)
    if checked is None:
        for i, f in enumerate(pattern.faces):
            idx = np.asarray(f)
            if idx.ndim != 1 or len(idx) < 3 or not np.issubdtype(idx.dtype, np.integer):
                raise ExportError(f"pattern face {i} must list at least 3 integer vertex indices")
            if idx.min() < 0 or idx.max() >= n:
                raise ExportError(f"pattern face {i} refers to a vertex outside 0..{n - 1}")
        sizes = np.fromiter(map(len, pattern.faces), dtype=np.int64, count=n_faces)
        start = run_starts(sizes)
        flat = np.concatenate([np.asarray(f, dtype=np.int64) for f in pattern.faces] or [[]])
        checked = flat.astype(np.int64), start
    if len(pattern.face_patch) != n_faces:
        raise ExportError(
            f"pattern has {n_faces} faces but {len(pattern.face_patch)} face_patch names"
        )
    if not all(isinstance(p, Patch | str) for p in pattern.face_patch):
        raise ExportError("pattern face_patch entries must be patches (or their names)")
    if pattern.face_piece.shape != (n_faces,):
        raise ExportError(
            f"pattern has {n_faces} faces but face_piece has shape {pattern.face_piece.shape}"
        )
    if pattern.edges is None or pattern.edge_assignment is None or pattern.edge_fold_angle is None:
        raise ExportError("pattern edges, edge_assignment and edge_fold_angle must all be set")
    edges = np.asarray(pattern.edges)
    assign = np.asarray(pattern.edge_assignment)
    angle = np.asarray(pattern.edge_fold_angle, dtype=np.float64)
    m = len(edges)
    if edges.shape != (m, 2) or assign.shape != (m,) or angle.shape != (m,):
        raise ExportError(
            f"pattern edge arrays disagree: edges {edges.shape}, edge_assignment "
            f"{assign.shape}, edge_fold_angle {angle.shape}"
        )
    if m and (edges.min() < 0 or edges.max() >= n):
        raise ExportError(f"pattern edges refer to a vertex outside 0..{n - 1}")
    unknown = np.flatnonzero(~np.isin(assign, ASSIGNMENTS))
    if len(unknown):
        e = int(unknown[0])
        raise ExportError(f"pattern edge {e} has assignment {str(assign[e])!r}, not one of M V B F")
    bad = np.flatnonzero(~np.isfinite(angle))
    if len(bad):
        raise ExportError(f"pattern edge_fold_angle[{bad[0]}] is not finite")
    wrong = ((assign == "V") & (angle < 0)) | ((assign == "M") & (angle > 0))
    wrong |= np.isin(assign, ("B", "F")) & (angle != 0)
    if wrong.any():
        e = int(np.flatnonzero(wrong)[0])
        raise ExportError(
            f"pattern edge {e} is {str(assign[e])!r} but its fold angle is {angle[e]:g} degrees "
            "(valley > 0, mountain < 0, border and flat 0)"
        )
    if n_faces:
        area = _signed_area(v2, *checked)
        scale = float(np.ptp(v2, axis=0).max()) if n else 0.0
        cw = np.flatnonzero(area < -tol.area * max(scale, 1.0) ** 2)
        if len(cw):
            raise ExportError(f"pattern face {cw[0]} is clockwise in the flat layout")
    return checked
