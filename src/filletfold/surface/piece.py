"""A flat piece with its folded positions: points in 2D and 3D, faces, patches, apex."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import shapely
from scipy.spatial import cKDTree

from ..arrays import run_owners, run_starts
from ..tolerances import tol
from .faces import FaceLists, face_polygons, flat_faces, polygon_area2
from .overlap import faces_overlap


@dataclass
class Piece:
    """One flat piece: points in 2D (piece frame) and 3D, polygon faces, their patches.

    Attributes
    ----------
    vertex : int
        The mesh vertex of the module.
    points_2d : (k, 2) float
    points_3d : (k, 3) float
    faces : list of list of int, or FaceLists
        Counter-clockwise in 2D.
    patches : list of Patch
    apex_index : int or None
        Index of the apex point (cone modules).
    """

    vertex: int
    points_2d: list = field(default_factory=list)
    points_3d: list = field(default_factory=list)
    faces: list = field(default_factory=list)
    patches: list = field(default_factory=list)
    apex_index: int | None = None
    _keys: dict = field(default_factory=dict)

    def compact(self) -> Piece:
        """Store the points as two arrays and forget the point keys (a built piece); returns
        the piece. Adding points afterwards still works (the arrays become lists again)."""
        self.points_2d, self.points_3d = self.arrays()
        self._keys = {}
        return self

    def _growable(self) -> None:
        if isinstance(self.points_2d, np.ndarray):
            self.points_2d, self.points_3d = list(self.points_2d), list(self.points_3d)

    def point(self, key, p2, p3) -> int:
        """Index of the point with ``key``, adding it on first use."""
        self._growable()
        if key not in self._keys:
            self._keys[key] = len(self.points_2d)
            self.points_2d.append(np.asarray(p2, dtype=float).reshape(2))
            self.points_3d.append(np.asarray(p3, dtype=float).reshape(3))
        return self._keys[key]

    def add_points(self, p2: np.ndarray, p3: np.ndarray) -> np.ndarray:
        """Append points without keys; return their indices.

        Parameters
        ----------
        p2 : (k, 2) float
        p3 : (k, 3) float

        Returns
        -------
        (k,) int
        """
        self._growable()
        start = len(self.points_2d)
        self.points_2d.extend(p2)
        self.points_3d.extend(p3)
        return np.arange(start, start + len(p2))

    def face(self, idx, patch, min_area: float = 0.0):
        """Add a polygon (duplicate consecutive indices dropped), made counter-clockwise.

        A polygon with fewer than 3 distinct corners or twice-area ``<= 2 min_area`` is dropped.
        """
        out = []
        for i in idx:
            if not out or out[-1] != i:
                out.append(i)
        if len(out) > 1 and out[0] == out[-1]:
            out.pop()
        if len(out) < 3:
            return
        area = _area2(self.points_2d, out)
        if abs(area) <= 2 * min_area:
            return
        if area < 0:
            out = out[::-1]
        if isinstance(self.faces, FaceLists):
            self.faces = list(self.faces.lists())
        self.faces.append(out)
        self.patches.append(patch)

    def merge_coincident(self, eps: float) -> None:
        """Merge points that coincide in 2D and 3D (within ``eps``); drop faces that vanish.

        This happens where a crease runs exactly through a tangent-line crossing T
        (``l = l_max``, docs/method.md, 'Corrections to the paper', 11): the straight crease
        on the face has zero length.
        """
        self._merge_coincident(eps)

    def _merge_coincident(self, eps: float) -> tuple[np.ndarray, np.ndarray | None]:
        """:meth:`merge_coincident`; returns ``points_2d`` (k, 2) as an array afterwards, and
        which faces were kept ((n_faces,) bool, None when nothing changed)."""
        p2, p3 = self.arrays()
        x = np.sort(p2[:, 0])
        if not (np.diff(x) <= eps).any() and np.isfinite(x).all():
            return p2, None  # no two points within eps even in x alone
        pairs = cKDTree(p2).query_pairs(eps, output_type="ndarray")
        if len(pairs) == 0:
            return p2, None
        pairs = pairs[np.linalg.norm(p3[pairs[:, 0]] - p3[pairs[:, 1]], axis=1) < eps]
        # each point goes to the lowest point of its group of coincident points
        n = len(p2)
        root = lowest_linked(pairs, n)
        flat, size, kept = _merged_faces(p2, self.faces, root, min_area=eps * eps)
        used = np.unique(flat)
        new = np.full(n, -1)
        new[used] = np.arange(len(used))
        self.points_2d, self.points_3d = p2[used], p3[used]  # arrays, as compact() keeps them
        self.faces = FaceLists.of_sizes(new[flat], size)
        self.patches = [p for p, k in zip(self.patches, kept.tolist(), strict=True) if k]
        self._keys = {k: int(new[root[i]]) for k, i in self._keys.items() if new[root[i]] >= 0}
        if self.apex_index is not None:
            r = new[root[self.apex_index]]
            self.apex_index = int(r) if r >= 0 else None
        return self.arrays()[0], kept

    def arrays(self):
        """(points_2d (k, 2), points_3d (k, 3))."""
        p2 = np.array(self.points_2d, dtype=float).reshape(-1, 2)
        p3 = np.array(self.points_3d, dtype=float).reshape(-1, 3)
        return p2, p3

    def overlaps(self, rel: float = tol.relative) -> bool:
        """True when faces of the piece overlap in 2D (or one is not a valid polygon).

        Overlap means: the union of the faces is smaller than the sum of their areas by more
        than ``rel`` of it. A piece that :func:`faces_interior_disjoint` proves free of
        overlap is answered without computing the union.
        """
        return faces_overlap(self.arrays()[0], self.faces, rel)


def lowest_linked(pairs: np.ndarray, n: int) -> np.ndarray:
    """(n,) int: the lowest index of each point's group, points linked by ``pairs`` (m, 2).

    The connected components by label propagation on the pairs (each round gives both ends
    of every pair the lower of their labels, then follows labels to their own), so a few
    tiny groups cost a few array operations, not a sparse graph.
    """
    root = np.arange(n)
    a, b = pairs[:, 0], pairs[:, 1]
    while True:
        low = np.minimum(root[a], root[b])
        new = root.copy()
        np.minimum.at(new, a, low)
        np.minimum.at(new, b, low)
        new = new[new]  # labels are indices of points of the group: follow them
        if np.array_equal(new, root):
            return root
        root = new


def _merged_faces(points_2d: np.ndarray, faces, root: np.ndarray, min_area: float):
    """:meth:`Piece.face` of every face with its points replaced by ``root`` (k,), at once.

    Consecutive repeats are dropped (and a last point equal to the first), faces of fewer than
    3 points or twice-area ``<= 2 min_area`` vanish, clockwise ones are reversed; the areas are
    summed as :meth:`Piece.face` does.

    Returns
    -------
    flat : (h,) int
        The kept faces' points, one face after the other.
    size : (n_kept,) int
    kept : (n_faces,) bool
    """
    n_faces = len(faces)
    flat, size = flat_faces(faces)
    idx = root[flat]
    face = run_owners(size)
    start = run_starts(size)
    keep = np.ones(len(idx), dtype=bool)
    keep[1:] = idx[1:] != idx[:-1]
    keep[start[:-1][size > 0]] = True  # a face's first point
    count = np.bincount(face, weights=keep, minlength=n_faces).astype(np.int64)
    last = np.full(n_faces, -1)
    np.maximum.at(last, face[keep], np.flatnonzero(keep))
    first = start[:-1]
    pop = (count > 1) & (idx[np.maximum(last, 0)] == idx[np.minimum(first, len(idx) - 1)])
    keep[last[pop]] = False
    count[pop] -= 1
    idx, face = idx[keep], face[keep]
    start = run_starts(count)
    area = np.full(n_faces, np.nan)
    for k in np.unique(count[count >= 3]).tolist():
        which = np.flatnonzero(count == k)
        area[which] = polygon_area2(points_2d[idx[start[which][:, None] + np.arange(k)]])
    kept = (count >= 3) & ~(np.abs(area) <= 2 * min_area)
    pos = np.arange(len(idx)) - start[face]
    pos = np.where((area < 0)[face], count[face] - 1 - pos, pos)  # clockwise: reversed
    sel = kept[face]
    return idx[(start[face] + pos)[sel]], count[kept], kept


def piece_area(piece: Piece) -> float:
    """Area of a flat piece (sum of its faces' areas)."""
    p2, _ = piece.arrays()
    return float(shapely.area(face_polygons(p2, piece.faces)).sum())


def _area2(points, idx: list) -> float:
    """Twice the signed area of the polygon ``points[idx]``: :func:`polygon_area2` of one
    polygon, the same sums in the same order on Python floats (a face at a time, the numpy
    call cost more than the sum: 0.24 s of a 2,904-vertex scan's sharp modules)."""
    area = 0.0
    x0, y0 = (float(c) for c in points[idx[-1]])
    for i in idx:
        x1, y1 = (float(c) for c in points[i])
        area = area + (x0 * y1 - x1 * y0)
        x0, y0 = x1, y1
    return area
