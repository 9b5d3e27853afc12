"""Triangles of a crease pattern's faces, found in the flat layout.

Pattern faces are simple counter-clockwise polygons in 2D (what
:func:`~filletfold.surface.validate.validate_pattern` checks), and the same polygons are
front-facing in 3D, so a triangulation of a face in the flat layout is one of its folded
polygon too, every triangle front-facing as the face is. The folded form's files
(:mod:`filletfold.export.mesh3d`, :mod:`filletfold.export.rhino`), its picture
(:func:`filletfold.export.png.preview_png`) and the browser app all draw these triangles.
"""

from __future__ import annotations

import numpy as np

from ..arrays import run_owners, run_starts
from ..tolerances import tol
from .pattern import face_arrays

__all__ = ["triangulate_faces", "triangulate_polygon_2d"]


def triangulate_polygon_2d(poly_2d: np.ndarray) -> np.ndarray:
    """Triangles of a simple counter-clockwise polygon (ear clipping; a fan when convex).

    Parameters
    ----------
    poly_2d : (k, 2) float

    Returns
    -------
    (k - 2, 3) int
        Indices into the polygon's corners.
    """
    p = np.asarray(poly_2d, dtype=float)
    k = len(p)
    if k == 3:
        return np.array([[0, 1, 2]])
    prev, nxt = np.roll(p, 1, axis=0), np.roll(p, -1, axis=0)
    turn = _cross(p - prev, nxt - p)
    scale = max(float(np.ptp(p, axis=0).max()) ** 2, 1e-300)
    if np.all(turn >= -tol.roundoff * scale):
        return np.array([[0, i, i + 1] for i in range(1, k - 1)])
    idx = list(range(k))
    out = []
    guard = 0
    while len(idx) > 3 and guard < 10 * k:
        guard += 1
        n = len(idx)
        for j in range(n):
            a, b, c = idx[j - 1], idx[j], idx[(j + 1) % n]
            if _cross(p[b] - p[a], p[c] - p[b]) <= 0:
                continue
            tri = p[[a, b, c]]
            others = [i for i in idx if i not in (a, b, c)]
            if others and _inside(p[others], tri).any():
                continue
            out.append([a, b, c])
            idx.pop(j)
            break
        else:  # degenerate: fall back to a fan of what is left
            break
    out += [[idx[0], idx[i], idx[i + 1]] for i in range(1, len(idx) - 1)]
    return np.array(out, dtype=np.int64)


def triangulate_faces(points_2d: np.ndarray, faces) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of many simple counter-clockwise polygons at once.

    Faces of one corner count are handled together: convex ones become fans in one array
    operation, the others go through :func:`triangulate_polygon_2d`. A face of ``k >= 3`` corners
    gives ``k - 2`` triangles, placed face after face.

    Parameters
    ----------
    points_2d : (n, 2) float
    faces : FlatFaces or sequence of (k,) int
        Corner indices into ``points_2d`` (a pattern's
        :class:`~filletfold.surface.pattern.FlatFaces` is read through its flat arrays, with
        no array per face).

    Returns
    -------
    triangles : (t, 3) int
        Indices into ``points_2d``.
    face : (t,) int
        The face each triangle came from (non-decreasing).
    """
    p = np.asarray(points_2d, dtype=float)
    flat, offsets = face_arrays(faces)
    flat = flat.astype(np.int64, copy=False)
    sizes, start = np.diff(offsets), offsets[:-1]
    count = np.maximum(sizes - 2, 0)
    t_start = run_starts(count)[:-1]
    triangles = np.zeros((int(count.sum()), 3), dtype=np.int64)
    for k in np.unique(sizes[sizes >= 3]).tolist():
        which = np.flatnonzero(sizes == k)
        f = flat[start[which][:, None] + np.arange(k)]
        q = p[f]
        turn = _cross(q - np.roll(q, 1, axis=1), np.roll(q, -1, axis=1) - q)
        scale = np.maximum(np.ptp(q, axis=1).max(axis=1) ** 2, 1e-300)
        convex = np.all(turn >= -tol.roundoff * scale[:, None], axis=1)
        fan = np.array([[0, i, i + 1] for i in range(1, k - 1)], dtype=np.int64)
        rows = t_start[which][:, None] + np.arange(k - 2)
        triangles[rows[convex]] = f[convex][:, fan]
        for row, at in zip(f[~convex], rows[~convex], strict=True):
            triangles[at] = row[triangulate_polygon_2d(p[row])]
    return triangles, run_owners(count)


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """z-component of the cross product of 2D vectors (broadcasting)."""
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _inside(q: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(m,) bool: points inside or on a counter-clockwise triangle (which would block it as
    an ear), except points at its corners."""
    a, b, c = tri
    s1 = _cross(b - a, q - a)
    s2 = _cross(c - b, q - b)
    s3 = _cross(a - c, q - c)
    corner = (np.abs(q[:, None, :] - tri[None]).max(axis=2) == 0).any(axis=1)
    return (s1 >= 0) & (s2 >= 0) & (s3 >= 0) & ~corner
