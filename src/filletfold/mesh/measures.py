"""Measures of polygons given as flat corner arrays: one definition of each, used by the mesh,
its repair and the certificate.

Polygons are held as ragged arrays (``filletfold.arrays``): the corners of all polygons one
polygon after another, ``start`` (n + 1,) the first corner of each (and the end), ``nxt`` the
next corner of the same polygon.
"""

from __future__ import annotations

import numpy as np

__all__ = ["dihedral_turns", "newell_vectors"]


def newell_vectors(corners: np.ndarray, start: np.ndarray, nxt: np.ndarray) -> np.ndarray:
    """(n, 3) float: each polygon's Newell vector (twice its vector area; its direction the
    front normal), summed about the polygon's centroid.

    About the centroid, not the origin: about the origin the terms ``p x q`` are ``|p|^2`` large
    and cancel down to twice the area, so a sliver far from the origin got a normal off its own
    plane by ``|p|^2 eps / area`` (``2e-11`` rad at ``|p| = 16``, area ``4e-4``).

    Parameters
    ----------
    corners : (h, 3) float
        The polygons' corner points, one polygon after another.
    start : (n + 1,) int
        Polygon ``i`` is ``corners[start[i]:start[i + 1]]`` (each at least one corner).
    nxt : (h,) int
        The next corner of each corner's polygon.
    """
    if len(start) < 2:
        return np.zeros((0, 3))
    size = np.diff(start)
    centroid = np.add.reduceat(corners, start[:-1], axis=0) / size[:, None]
    q = corners - np.repeat(centroid, size, axis=0)
    return np.add.reduceat(np.cross(q, q[nxt]), start[:-1], axis=0)


def dihedral_turns(na: np.ndarray, nb: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """(k,) float: the signed angle (degrees, in (-180, 180]) that turns each unit normal
    ``na`` (k, 3) to ``nb`` about its edge's direction ``axis`` (k, 3; any length): positive
    counter-clockwise seen from the tip of ``axis``. For the faces holding an edge ``a -> b``
    and ``b -> a``, with ``axis = b - a``, it is positive where the surface is convex seen from
    the front (a mountain); FOLD's fold angle is its negative."""
    d = axis / np.linalg.norm(axis, axis=1)[:, None]
    sin = np.einsum("ij,ij->i", np.cross(na, nb), d)
    return np.degrees(np.arctan2(sin, np.einsum("ij,ij->i", na, nb)))
