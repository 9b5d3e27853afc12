"""Faces as flat arrays: corner lists, twice-areas and shapely polygons of a piece's faces."""

from __future__ import annotations

import itertools

import numpy as np
import shapely

from ..arrays import run_owners
from .pattern import FlatFaces


class FaceLists(FlatFaces):
    """A piece's faces as :class:`~filletfold.surface.pattern.FlatFaces`, read as a list of lists of
    int (made on first use, as :func:`build_module` makes them)."""

    __slots__ = ("_lists",)

    def __init__(self, flat: np.ndarray, start: np.ndarray):
        super().__init__(flat, start)
        self._lists = None

    def lists(self) -> list[list[int]]:
        """The faces as lists of int (made once)."""
        if self._lists is None:
            values = self.flat.tolist()
            self._lists = [values[a:b] for a, b in itertools.pairwise(self.start.tolist())]
        return self._lists

    def __getitem__(self, i):
        return self.lists()[i]

    def __iter__(self):
        return iter(self.lists())

    def __eq__(self, other) -> bool:
        """Equal to any sequence of the same faces (lists, arrays, or flat faces), in order."""
        try:
            faces = [[int(i) for i in f] for f in other]
        except (TypeError, ValueError):
            return NotImplemented
        return self.lists() == faces


def flat_faces(faces) -> tuple[np.ndarray, np.ndarray]:
    """(m,) int64 corners of ``faces`` (:class:`~filletfold.surface.pattern.FlatFaces`, or index
    lists: read in one pass over their values), face after face, and (n_faces,) int64 their
    counts."""
    if isinstance(faces, FlatFaces):
        return faces.flat, np.diff(faces.start)
    size = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
    flat = np.fromiter(itertools.chain.from_iterable(faces), dtype=np.int64, count=int(size.sum()))
    return flat, size


def face_polygons(points_2d: np.ndarray, faces) -> np.ndarray:
    """(n_faces,) shapely Polygons of faces given as index lists into ``points_2d`` (k, 2)."""
    idx, sizes = flat_faces(faces)
    rings = shapely.linearrings(points_2d[idx], indices=run_owners(sizes))
    return shapely.polygons(rings)


def polygon_area2(xy: np.ndarray) -> np.ndarray:
    """Twice the signed area of polygons of one size (the shoelace sum, corner by corner).

    Parameters
    ----------
    xy : (n, k, 2) float
        Corners of ``n`` polygons.

    Returns
    -------
    (n,) float
        Positive for counter-clockwise polygons.
    """
    area = np.zeros(len(xy))
    for j in range(xy.shape[1]):
        x0, y0 = xy[:, j - 1, 0], xy[:, j - 1, 1]
        x1, y1 = xy[:, j, 0], xy[:, j, 1]
        area = area + (x0 * y1 - x1 * y0)
    return area
