"""Vertex modules: the flat piece(s) of one vertex, in 2D and folded in 3D (paper sec. 2).

A vertex module is made of one *sector* per incident face ``f_i``: the half-cylinder of side
``i`` (from its midpoint base curve up to the crease), the vertex's share of face ``f_i`` (bounded
by the two tangent lines, the face piece's centre and, near the vertex, the straight crease), and
the cone fanned from the apex over the crease (curved on the cylinder, straight on the face).

A closed ring is cut along the transition line between face ``f_{n-1}`` and cylinder 0 (and the
cone ruling to its crease point): the development is then the chain ``tau -> ... -> tau'`` with
the angle-defect wedge open at the apex. Vertices without a cone (saddle, infeasible,
developable, boundary) end at a *hole border* instead: on each cylinder the cross-section at
``z = h`` (half of the shorter ``l_max``), joined by straight segments across the faces.

A module whose development overlaps itself (cone angle above 2 pi, or a saddle's ring) is split
into runs of consecutive sectors, each its own piece.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .errors import MeshError
from .mesh.polymesh import PolyMesh
from .pattern import CreasePattern, FaceRows, FlatFaces
from .rounding import EdgeRounding
from .tolerances import tol
from .vertex.apex import crease_length
from .vertex.frame import VertexFrame, apply, stack_sides, to_chart


class FaceLists(FlatFaces):
    """A piece's faces as :class:`~filletfold.pattern.FlatFaces`, read as a list of lists of
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
        return self.lists() == list(other)


def flat_faces(faces) -> tuple[np.ndarray, np.ndarray]:
    """(m,) int64 corners of ``faces`` (:class:`~filletfold.pattern.FlatFaces`, or index
    lists: read in one pass over their values), face after face, and (n_faces,) int64 their
    counts."""
    if isinstance(faces, FlatFaces):
        return faces.flat, np.diff(faces.start)
    size = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
    flat = np.fromiter(itertools.chain.from_iterable(faces), dtype=np.int64, count=int(size.sum()))
    return flat, size


@dataclass
class Piece:
    """One flat piece: points in 2D (piece frame) and 3D, polygon faces, patch names.

    Attributes
    ----------
    vertex : int
        The mesh vertex of the module.
    points_2d : (k, 2) float
    points_3d : (k, 3) float
    faces : list of list of int, or FaceLists
        Counter-clockwise in 2D.
    patches : list of str
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

    def face(self, idx, patch: str, min_area: float = 0.0):
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
        area = 0.0
        for j in range(len(out)):
            x0, y0 = self.points_2d[out[j - 1]]
            x1, y1 = self.points_2d[out[j]]
            area += x0 * y1 - x1 * y0
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
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, group = connected_components(graph, directed=False)
        lowest = np.full(group.max(initial=0) + 1, n)
        np.minimum.at(lowest, group, np.arange(n))
        root = lowest[group]
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

    def overlaps(self, rel: float = 1e-9) -> bool:
        """True when faces of the piece overlap in 2D (or one is not a valid polygon).

        Overlap means: the union of the faces is smaller than the sum of their areas by more
        than ``rel`` of it. A piece that :func:`faces_interior_disjoint` proves free of
        overlap is answered without computing the union.
        """
        return faces_overlap(self.arrays()[0], self.faces, rel)


def faces_overlap(points_2d: np.ndarray, faces, rel: float = 1e-9) -> bool:
    """:meth:`Piece.overlaps` of the polygons ``faces`` (index lists) over ``points_2d`` (k, 2)."""
    if faces_interior_disjoint(points_2d, faces):
        return False
    return measured_overlap(points_2d, faces, rel)


def measured_overlap(points_2d: np.ndarray, faces, rel: float = 1e-9, pairs=None) -> bool:
    """:func:`faces_overlap` without the proof: a face is not a valid polygon, two faces of
    ``pairs`` share more than ``rel`` of the smaller one, or the union of the faces is smaller
    than the sum of their areas by more than ``rel`` of it.

    The pairs are measured first (the union is not computed when one of them overlaps). Their
    test is the finer one: a sliver that two faces share, such as where the two sides of a
    development's cut cross by a hair, is a tiny share of the whole piece but not of the
    smaller face.

    Parameters
    ----------
    points_2d : (k, 2) float
    faces : list of list of int
        Index lists into ``points_2d``.
    rel : float
    pairs : (m, 2) int, optional
        Pairs of distinct faces likely to overlap.

    Returns
    -------
    bool
    """
    polys = face_polygons(points_2d, faces)
    if not shapely.is_valid(polys).all():
        return True
    area = shapely.area(polys)
    if pairs is not None and _pairs_overlap(polys, area, np.asarray(pairs).reshape(-1, 2), rel):
        return True
    union = shapely.union_all(polys).area
    total = area.sum()
    return bool(union < total * (1 - rel))


def _pairs_overlap(polys: np.ndarray, area: np.ndarray, pairs: np.ndarray, rel: float) -> bool:
    """Whether the valid polygons ``polys`` (n,) (areas ``area`` (n,)) of some pair of ``pairs``
    (m, 2) int share more than ``rel`` of the smaller one (only pairs whose bounding boxes
    overlap by that much are intersected)."""
    box = shapely.bounds(polys)  # (n, 4): xmin, ymin, xmax, ymax
    a, b = box[pairs[:, 0]], box[pairs[:, 1]]
    w = np.minimum(a[:, 2], b[:, 2]) - np.maximum(a[:, 0], b[:, 0])
    h = np.minimum(a[:, 3], b[:, 3]) - np.maximum(a[:, 1], b[:, 1])
    limit = rel * np.minimum(area[pairs[:, 0]], area[pairs[:, 1]])
    near = (w > 0) & (h > 0) & (w * h > limit)
    if not near.any():
        return False
    pa, pb = pairs[near].T
    shared = shapely.area(shapely.intersection(polys[pa], polys[pb]))
    return bool((shared > limit[near]).any())


def run_overlaps(points_2d: np.ndarray, faces, sector: np.ndarray) -> bool:
    """:func:`measured_overlap` of a run's piece, its first sector's faces against its last's
    as the pairs (where a ring that turns by a full turn or more, or whose development's cut
    does not close, overlaps itself).

    Parameters
    ----------
    points_2d : (k, 2) float
    faces : list of list of int
    sector : (n_faces,) int
        Sector of each face, from 0.
    """
    sector = np.asarray(sector)
    first, last = np.flatnonzero(sector == 0), np.flatnonzero(sector == sector.max())
    pairs = np.stack(np.meshgrid(first, last, indexing="ij"), axis=-1).reshape(-1, 2)
    return measured_overlap(points_2d, faces, pairs=pairs)


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
    face = np.repeat(np.arange(n_faces), size)
    start = np.concatenate([[0], np.cumsum(size)])
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
    start = np.concatenate([[0], np.cumsum(count)])
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


def face_polygons(points_2d: np.ndarray, faces) -> np.ndarray:
    """(n_faces,) shapely Polygons of faces given as index lists into ``points_2d`` (k, 2)."""
    idx, sizes = flat_faces(faces)
    rings = shapely.linearrings(points_2d[idx], indices=np.repeat(np.arange(len(faces)), sizes))
    return shapely.polygons(rings)


def faces_interior_disjoint(points_2d: np.ndarray, faces) -> bool:
    """Whether the polygons are proved to be valid and to overlap nowhere (a sufficient test).

    The proof: every face is a simple counter-clockwise polygon (strictly convex, checked with
    cross products, or else valid for shapely with a positive area), so its winding number is 0
    or 1 everywhere; every directed edge ``a -> b`` occurs once, and those whose reverse
    ``b -> a`` also occurs cancel in the sum of the face outlines, which therefore equals the
    remaining *border* edges; these form one closed, simple, counter-clockwise polygon, whose
    winding number is 0 or 1. The number of faces covering a point is the sum of the faces'
    winding numbers, i.e. the border's, so no point is covered twice.

    ``False`` means only that the proof did not go through (overlapping faces, a module cut
    into a ring, a border touching itself...); the caller then measures the overlap.

    Parameters
    ----------
    points_2d : (k, 2) float
    faces : list of list of int
        Index lists into ``points_2d``.

    Returns
    -------
    bool
    """
    n_faces = len(faces)
    if n_faces == 0:
        return True
    flat, size = flat_faces(faces)
    piece = np.zeros(n_faces, dtype=np.int64)
    return bool(faces_interior_disjoint_many(points_2d, flat, size, piece, 1)[0])


def faces_interior_disjoint_many(
    points_2d: np.ndarray, flat: np.ndarray, size: np.ndarray, face_piece: np.ndarray, n_pieces
) -> np.ndarray:
    """:func:`faces_interior_disjoint` of many pieces at once.

    The same proof with the same arithmetic per face, edge and border, so the same answers:
    every face strictly convex (or valid with a positive area), every directed edge once, the
    edges without their reverse one simple counter-clockwise loop.

    Parameters
    ----------
    points_2d : (k, 2) float
        The points of all pieces; each piece's points are its own.
    flat : (h,) int
        The faces' point indices (into ``points_2d``), face after face.
    size : (n_faces,) int
        Corners per face.
    face_piece : (n_faces,) int
        Piece of each face (non-decreasing).
    n_pieces : int

    Returns
    -------
    (n_pieces,) bool
        True where the piece is proved free of overlap.
    """
    ok = np.bincount(face_piece, minlength=n_pieces) > 0  # a piece without faces: proved below
    if len(size) == 0:
        return ~ok
    empty = ~ok
    ok[face_piece[size < 3]] = False
    keep = ok[face_piece]
    if not keep.all():
        sel = np.repeat(keep, size)
        flat, size, face_piece = flat[sel], size[keep], face_piece[keep]
        if len(size) == 0:
            return ok | empty
    a = np.asarray(flat, dtype=np.int64)
    start = np.zeros(len(size) + 1, dtype=np.int64)
    np.cumsum(size, out=start[1:])
    nxt = np.arange(1, len(a) + 1)
    nxt[start[1:] - 1] = start[:-1]
    b = a[nxt]
    # faces: strictly convex, turning once
    d = points_2d[b] - points_2d[a]
    dn = d[nxt]
    cross = d[:, 0] * dn[:, 1] - d[:, 1] * dn[:, 0]
    length = np.hypot(d[:, 0], d[:, 1])
    convex = cross > tol.area * length * length[nxt]
    turn = np.arctan2(cross, np.einsum("ij,ij->i", d, dn))
    face_ok = np.logical_and.reduceat(convex, start[:-1]) & (
        np.add.reduceat(turn, start[:-1]) < 3 * np.pi
    )
    if not face_ok.all():
        rest = np.flatnonzero(~face_ok)
        p, q = points_2d[a], points_2d[b]
        term = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
        area2 = np.add.reduceat(term, start[:-1])[rest]
        scale = np.add.reduceat(np.abs(term), start[:-1])[rest]
        ok[face_piece[rest[~(area2 > tol.area * scale)]]] = False
        rest = rest[ok[face_piece[rest]]]
        if len(rest):
            polys = face_polygons(points_2d, [a[start[i] : start[i + 1]] for i in rest.tolist()])
            ok[face_piece[rest[~shapely.is_valid(polys)]]] = False
    # edges: each directed edge once; border = edges without their reverse
    n = len(points_2d)
    edge_piece = np.repeat(face_piece, size)
    point_piece = np.full(n, -1, dtype=np.int64)
    point_piece[a] = edge_piece
    key = a * n + b
    ks = np.sort(key)
    ok[point_piece[ks[1:][ks[1:] == ks[:-1]] // n]] = False
    rev = b * n + a
    pos = np.minimum(np.searchsorted(ks, rev), len(ks) - 1)
    border = (ks[pos] != rev) & ok[edge_piece]
    ba, bb, bp = a[border], b[border], edge_piece[border]
    m = np.bincount(bp, minlength=n_pieces)
    ok &= m >= 3
    for ends in (ba, bb):
        e = np.sort(ends)
        ok[point_piece[e[1:][e[1:] == e[:-1]]]] = False
    # the border is one loop: cut each piece's successor cycle before its first edge and rank
    # the edges by their distance to the cut (pointer jumping, all pieces at once)
    where = np.full(n, -1, dtype=np.int64)
    where[ba] = np.arange(len(ba))
    succ = where[bb]
    ok[bp[succ < 0]] = False
    live = ok[bp]  # these pieces' successors are permutations of their border edges
    renum = np.cumsum(live) - 1
    ba, bp, succ = ba[live], bp[live], renum[succ[live]]
    pieces = np.flatnonzero(ok)
    head = np.searchsorted(bp, pieces)  # first border edge of each piece
    pred = np.empty(len(succ), dtype=np.int64)
    pred[succ] = np.arange(len(succ))
    jump = np.append(succ, len(succ))  # len(succ): the cut, where every path ends
    jump[pred[head]] = len(succ)
    togo = np.ones(len(jump), dtype=np.int64)  # edges from here to the cut
    togo[-1] = 0
    for _ in range(int(m.max(initial=1)).bit_length()):
        togo, jump = togo + togo[jump], jump[jump]
    loop_len = np.zeros(n_pieces, dtype=np.int64)
    loop_len[pieces] = togo[head]
    ok &= loop_len == m
    rank = m[bp] - togo[:-1]  # position along the loop from the first edge
    live = ok[bp]
    ba, bp, rank = ba[live], bp[live], rank[live]
    if not len(ba):
        return ok | empty
    # each loop's points in order, from its first edge
    r_start = np.flatnonzero(np.concatenate([[True], bp[1:] != bp[:-1]]))
    r_size = np.diff(np.append(r_start, len(bp)))
    ring = np.empty((len(ba), 2))
    ring[np.repeat(r_start, r_size) + rank] = points_2d[ba]
    r_next = np.arange(1, len(ring) + 1)
    r_next[r_start + r_size - 1] = r_start
    nr = ring[r_next]
    term = ring[:, 0] * nr[:, 1] - nr[:, 0] * ring[:, 1]
    pieces = bp[r_start]
    oriented = np.add.reduceat(term, r_start) > tol.area * np.add.reduceat(np.abs(term), r_start)
    rings = shapely.linearrings(ring, indices=np.repeat(np.arange(len(r_start)), r_size))
    ok[pieces[~(oriented & shapely.is_valid(shapely.polygons(rings)))]] = False
    return ok | empty


def _arc_parameters(arc: np.ndarray, n: np.ndarray):
    """``np.linspace(0, arc, n)`` of every side, one side after another, as
    :func:`_side_curves` samples them.

    Returns
    -------
    side : (m,) int
    k : (m,) int
        Sample number along its side.
    s : (m,) float
    """
    side = np.repeat(np.arange(len(n)), n)
    first = np.cumsum(n) - n
    k = np.arange(len(side)) - first[side]
    step = np.where(n > 1, arc / np.maximum(n - 1, 1), 0.0)
    s = k * step[side]
    long = n > 1
    s[(first + n - 1)[long]] = arc[long]
    return side, k, s


def face_piece_centres(mesh: PolyMesh, rounding: EdgeRounding) -> np.ndarray:
    """Centre of every flat face piece, from which the whole piece is visible.

    The face piece of a face is bounded by the tangent lines of its edges (the edge itself for a
    boundary or flat edge); its corners are the crossing points T. Each vertex's share of the
    piece is cut off by straight segments from the edge midpoints to this centre, so the centre
    must see the whole piece: it is the centroid of the piece's kernel (the piece itself when
    convex).

    Returns
    -------
    centre : (n_faces, 3) float

    Raises
    ------
    MeshError
        If a face piece is not star-shaped (no point sees all of it).
    """
    half = 0.5 * rounding.strip_width
    start = np.asarray(mesh.face_start)
    face_of = np.repeat(np.arange(mesh.n_faces), np.diff(start))
    nxt = np.arange(len(face_of)) + 1
    nxt[start[1:] - 1] = start[:-1]  # the half-edge after the last one of a face is its first
    p = mesh.vertices[mesh.halfedge_from]
    u = p[nxt] - p
    u /= np.linalg.norm(u, axis=1)[:, None]
    n = mesh.face_normal[face_of]
    base = p + half[mesh.halfedge_edge][:, None] * np.cross(n, u)  # a point of each tangent line
    # corner of half-edge h: the tangent lines of the previous half-edge and of h cross at T
    prev = mesh.halfedge_prev
    delta = base - base[prev]
    cos = np.einsum("ij,ij->i", u[prev], u)
    sin2 = 1 - cos**2
    parallel = sin2 < 1e-24  # a straight corner between unrounded edges: T is the corner
    z = (np.einsum("ij,ij->i", u[prev], delta) - cos * np.einsum("ij,ij->i", u, delta)) / (
        np.where(parallel, 1.0, sin2)
    )
    T = np.where(parallel[:, None], base, base[prev] + z[:, None] * u[prev])
    # face coordinates: origin at the first corner, e1 along the first edge
    origin = p[start[:-1]]
    e1 = u[start[:-1]]
    e2 = np.cross(mesh.face_normal, e1)
    rel = T - origin[face_of]
    xy = np.stack(
        [np.einsum("ij,ij->i", rel, e1[face_of]), np.einsum("ij,ij->i", rel, e2[face_of])], axis=1
    )
    # convex pieces: the polygon centroid (shoelace); the others: the kernel's centroid
    x, y = xy[:, 0], xy[:, 1]
    xn, yn = x[nxt], y[nxt]
    cross = x * yn - xn * y
    area = np.add.reduceat(cross, start[:-1]) / 2
    cx = np.add.reduceat((x + xn) * cross, start[:-1]) / (6 * np.where(area != 0, area, 1))
    cy = np.add.reduceat((y + yn) * cross, start[:-1]) / (6 * np.where(area != 0, area, 1))
    d = xy[nxt] - xy
    turn = d[:, 0] * d[nxt][:, 1] - d[:, 1] * d[nxt][:, 0]
    convex = (np.minimum.reduceat(turn, start[:-1]) >= 0) & (area > 0)
    centre = np.stack([cx, cy], axis=1)
    for fi in np.nonzero(~convex)[0]:
        c = _kernel_centroid(xy[start[fi] : start[fi + 1]])
        if c is None:
            raise MeshError(
                f"face {fi} is not star-shaped after rounding: no point of it sees the whole "
                "face piece; split it into convex polygons or use a smaller radius",
                face=int(fi),
            )
        centre[fi] = c
    return origin + centre[:, :1] * e1 + centre[:, 1:] * e2


def _kernel_centroid(xy: np.ndarray) -> np.ndarray | None:
    """Centroid of the kernel of a counter-clockwise polygon (k, 2), or None if it is empty.

    (Convex pieces do not come here: :func:`face_piece_centres` takes their centroid.)
    """
    poly = shapely.Polygon(xy)
    size = float(np.ptp(xy, axis=0).max()) * 4 + 1.0
    kernel = poly if poly.is_valid else shapely.convex_hull(poly)
    for a, b in zip(xy, np.roll(xy, -1, axis=0), strict=True):
        t = b - a
        nrm = np.array([-t[1], t[0]]) / np.linalg.norm(t) * size  # left of a -> b is inside
        t = t / np.linalg.norm(t) * size
        half = shapely.Polygon([a - t, b + t, b + t + nrm, a - t + nrm])
        kernel = kernel.intersection(half)
    if kernel.is_empty or kernel.area <= 1e-12 * poly.area:
        return None
    c = kernel.centroid
    return np.array([c.x, c.y])


def merge_distance(frame: VertexFrame) -> float:
    """The distance within which two points of the vertex's module are merged
    (:meth:`Piece.merge_coincident`): ``tol.coincide`` times the larger of the shortest
    incident edge and the largest coordinate of the vertex (their round-off)."""
    shortest = min(s.length for s in frame.sides)
    return tol.coincide * max(shortest, float(np.abs(frame.U).max()))


def hole_heights(frame: VertexFrame) -> np.ndarray:
    """(n_sides,) height of the hole border above the midpoint cross-section on each side.

    At a closed ring whose edges are all unrounded (a sharp vertex) the border runs through
    the vertex itself: no hole, the faces meet at it.
    """
    if frame.ring.closed and not (frame.arrays.radius > 0).any():
        return 0.5 * frame.arrays.length
    lm = np.fmin(frame.lmax_start, frame.lmax_end)
    return 0.5 * lm


def hole_corners(frame: VertexFrame, centres: np.ndarray) -> np.ndarray:
    """(n_faces,) bool: the ring faces on whose share the hole border goes through the corner
    T instead of straight across.

    The straight border joins the tops of the two sides on the face (heights
    :func:`hole_heights`); the share ``[top, base, centre, base, top]`` is a simple polygon only
    when the face piece's centre lies beyond that segment, away from T. It does not at a
    reflex corner (the segment would leave the face) nor on a thin face whose centre lies near
    the side's line (the share's side from its base to the centre would cross the border).
    Through T, the share is the vertex's whole wedge of the face piece, which its centre sees.

    Parameters
    ----------
    frame : VertexFrame
    centres : (n_faces, 3) float
        Face piece centres (:func:`face_piece_centres`), by mesh face.
    """
    nf = len(frame.ring.faces)
    sides = frame.sides
    ne = len(sides)
    h = hole_heights(frame)
    i = np.arange(nf)
    j = (i + 1) % ne
    if frame.ring.closed:
        sa = frame.arrays
        end = sa.base(i, sa.arc[i]) + h[i, None] * sa.R[i]
        start = sa.base(j, np.zeros(nf)) + h[j, None] * sa.R[j]
    else:  # the unrounded ends: their lines, up to half their lmax (as line_points has them)
        top = [
            (s.end_point() + hh * s.R, s.start_point() + hh * s.R)
            if s.rounded
            else (s.M + 0.5 * frame.lmax_end[k] * s.R, s.M + 0.5 * frame.lmax_start[k] * s.R)
            for k, (s, hh) in enumerate(zip(sides, h.tolist(), strict=True))
        ]
        end = np.array([top[k][0] for k in i.tolist()]).reshape(nf, 3)
        start = np.array([top[k][1] for k in j.tolist()]).reshape(nf, 3)
    axes = np.asarray(frame.face_frames)
    normal = np.cross(axes[:, 1], axes[:, 2])
    along = start - end
    length = np.linalg.norm(along, axis=1)
    side_c = np.einsum("ij,ij->i", np.cross(along, centres[frame.ring.faces] - end), normal)
    side_t = np.einsum("ij,ij->i", np.cross(along, frame.T_end[:nf] - end), normal)
    beyond = (side_c * np.sign(side_t) < -merge_distance(frame) * length) | (
        length <= merge_distance(frame)  # no border on the face: the sides' tops meet
    )
    return (np.asarray(frame.corner_angle) > np.pi) | ~beyond


def build_module(
    mesh: PolyMesh,
    frame: VertexFrame,
    centres: np.ndarray,
    n_samples,
    apex: np.ndarray | None = None,
    dev_apex: np.ndarray | None = None,
    runs=None,
) -> list[Piece]:
    """The flat piece(s) of one vertex.

    Parameters
    ----------
    mesh : PolyMesh
    frame : VertexFrame
    centres : (n_faces, 3) float
        Face piece centres (:func:`face_piece_centres`).
    n_samples : int or (n_edges,) int
        Points per cylinder arc (both ends included), for all arcs or per edge
        (:meth:`~filletfold.rounding.EdgeRounding.arc_points`).
    apex : (3,) float, optional
        Spatial apex; when given the module has a cone, otherwise a hole border.
    dev_apex : (2,) float, optional
        Developed apex (required with ``apex``).
    runs : list of (int, int), optional
        Sector ranges ``[j0, j1]`` (inclusive), each one piece; default one run over all
        sectors, split in halves while a piece overlaps itself.

    Returns
    -------
    list of Piece
    """
    nf = len(frame.ring.faces)
    if runs is not None:
        return [
            _build_run(mesh, frame, centres, n_samples, apex, dev_apex, j0, j1)[0]
            for j0, j1 in runs
        ]
    pending = [(0, nf - 1)]
    pieces = []
    while pending:
        j0, j1 = pending.pop(0)
        piece, p2, sector = _build_run(mesh, frame, centres, n_samples, apex, dev_apex, j0, j1)
        if (
            j1 > j0
            and not faces_interior_disjoint(p2, piece.faces)
            and run_overlaps(p2, piece.faces, sector)
        ):
            mid = (j0 + j1) // 2
            pending[:0] = [(j0, mid), (mid + 1, j1)]
            continue
        pieces.append(piece.compact())
    return pieces


def _side_curves(frame: VertexFrame, sides: list, n_samples, apex, dev_apex, heights) -> dict:
    """Base points and crease (or hole) points of the rounded sides ``sides``, all at once.

    Parameters
    ----------
    frame : VertexFrame
    sides : list of int
        Rounded side indices.
    n_samples : int or (n_edges,) int
        Points per arc (one on a side without arc).
    apex, dev_apex : (3,) float and (2,) float, or None
        The cone's apices; without, the top is the hole border at ``heights``.
    heights : (n_sides,) float

    Returns
    -------
    dict
        Side -> (s (k,), base_3d (k, 3), top_3d (k, 3), top_z (k,)), with ``top`` the crease
        or the hole border and ``s = linspace(0, arc, k)``.
    """
    if not sides:
        return {}
    which = np.asarray(sides, dtype=np.int64)
    if frame.ring.closed:
        sa, idx = frame.arrays, which
    else:  # an open ring has no SideArrays: stack the sides asked for
        sa, idx = stack_sides([frame.sides[i] for i in sides]), np.arange(len(sides))
    arc = sa.arc[idx]
    n = np.full(len(idx), n_samples) if np.ndim(n_samples) == 0 else n_samples[sa.edge[idx]]
    n = np.where(arc > 0, n, 1).astype(np.int64)
    rep, _, s = _arc_parameters(arc, n)
    first = np.cumsum(n) - n
    side = idx[rep]
    C = sa.base(side, s)
    if apex is not None:
        z, _ = crease_length(frame, side, apex, dev_apex, s, C=C)
    else:
        z = np.asarray(heights, dtype=float)[which][rep]
    F = C + z[:, None] * sa.R[side]
    bounds = np.append(first, len(rep)).tolist()
    return {
        i: (s[a:b], C[a:b], F[a:b], z[a:b])
        for i, a, b in zip(sides, bounds[:-1], bounds[1:], strict=True)
    }


def apply_rows(m: np.ndarray, p: np.ndarray) -> np.ndarray:
    """:func:`~filletfold.vertex.frame.apply` row by row, in one call.

    Each row goes through the same 1-row matrix product as ``apply(m[k], p[k])``, so the
    result is bitwise the one of ``k`` separate calls (one ``(k, 2) @ (2, 2)`` product may
    round differently, and so would the patterns).

    Parameters
    ----------
    m : (3, 3) or (k, 3, 3) float
        Homogeneous 2D map, or one per row.
    p : (k, 2) float

    Returns
    -------
    (k, 2) float
    """
    lin = np.swapaxes(m[..., :2, :2], -1, -2)  # transposed views, as in apply
    return (p[:, None, :] @ lin)[:, 0, :] + m[..., :2, 2]


def polygon_area2(xy: np.ndarray) -> np.ndarray:
    """Twice the signed area of polygons of one size, summed as :meth:`Piece.face` does.

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


@dataclass
class _Strip:
    """One rounded side's half-cylinder in the run's 2D frame (see :func:`_strips`)."""

    base_2d: np.ndarray  # (n, 2) base curve
    base_3d: np.ndarray  # (n, 3)
    top_2d: np.ndarray  # (n, 2) crease or hole border
    top_3d: np.ndarray  # (n, 3)
    quad_area: list  # (n - 1,) twice the area of quad k
    tri_area: list | None  # (n - 1,) twice the area of cone triangle k (cones only)


def _strips(frame: VertexFrame, sides: list, curves: dict, dev_apex) -> dict:
    """The half-cylinders of ``sides`` (rounded side indices), computed together.

    ``curves`` maps each side to :func:`_side_curves`; ``dev_apex`` is the developed apex, or
    None without a cone. Returns a dict side -> :class:`_Strip`.
    """
    if not sides:
        return {}
    count = np.array([len(curves[i][0]) for i in sides])
    s = np.concatenate([curves[i][0] for i in sides])
    z = np.concatenate([curves[i][3] for i in sides])
    maps = np.repeat(np.stack([frame.cyl_map[i] for i in sides]), count, axis=0)
    base_2d = apply_rows(maps, np.stack([s, np.zeros(len(s))], axis=1))
    top_2d = apply_rows(maps, np.stack([s, z], axis=1))
    k = np.arange(len(s) - 1)  # quad k joins samples k and k + 1 of one side
    quad = polygon_area2(np.stack([base_2d[k], base_2d[k + 1], top_2d[k + 1], top_2d[k]], axis=1))
    quad = quad.tolist()
    tri = None
    if dev_apex is not None:
        apex = np.broadcast_to(np.asarray(dev_apex, dtype=float).reshape(1, 2), (len(k), 2))
        tri = polygon_area2(np.stack([apex, top_2d[k], top_2d[k + 1]], axis=1)).tolist()
    out = {}
    start = 0
    for i, n in zip(sides, count.tolist(), strict=True):
        end = start + n
        out[i] = _Strip(
            base_2d[start:end],
            curves[i][1],
            top_2d[start:end],
            curves[i][2],
            quad[start : end - 1],
            None if tri is None else tri[start : end - 1],
        )
        start = end
    return out


def _curve_points(piece: Piece, key: tuple, p2: np.ndarray, p3: np.ndarray) -> list:
    """Indices of the points ``k = 0 .. n-1`` of a sampled curve, added in order.

    Only the two ends are keyed (``(*key, 0)`` and ``(*key, n - 1)``), the points where other
    faces join; the first may exist already (it is then reused, as :meth:`Piece.point` does).
    """
    known = piece._keys
    first = known.get((*key, 0))
    if first is None:
        idx = piece.add_points(p2, p3).tolist()
        known[(*key, 0)] = idx[0]
    else:
        idx = [first, *piece.add_points(p2[1:], p3[1:]).tolist()]
    known.setdefault((*key, len(idx) - 1), idx[-1])
    return idx


def _add_strip(piece: Piece, bs: list, tp: list, strip: _Strip, patch: str, cone: str) -> None:
    """The quads of one half-cylinder and, with a cone, its triangles from the apex.

    The same faces, in the same order, as ``piece.face`` on ``[bs[k], bs[k+1], tp[k+1], tp[k]]``
    then ``[apex, tp[k], tp[k+1]]`` for each ``k``: the corners are distinct points, so a face
    is dropped only when its area is zero and reversed when it is clockwise (NaN: kept as is).
    """
    faces, patches = piece.faces, piece.patches
    a = piece.apex_index
    tri = strip.tri_area
    quad = strip.quad_area
    if quad and min(quad) > 0 and (tri is None or min(tri) > 0):  # all kept as they are
        pairs = zip(itertools.pairwise(bs), itertools.pairwise(tp), strict=True)
        quads = [[b0, b1, t1, t0] for (b0, b1), (t0, t1) in pairs]
        if tri is None:
            faces.extend(quads)
            patches.extend([patch] * len(quads))
        else:
            tris = [[a, t0, t1] for t0, t1 in itertools.pairwise(tp)]
            faces.extend(itertools.chain.from_iterable(zip(quads, tris, strict=True)))
            patches.extend([patch, cone] * len(quads))
        return
    for k, area in enumerate(quad):
        if area != 0:
            if area < 0:
                faces.append([tp[k], tp[k + 1], bs[k + 1], bs[k]])
            else:
                faces.append([bs[k], bs[k + 1], tp[k + 1], tp[k]])
            patches.append(patch)
        if tri is not None and tri[k] != 0:
            faces.append([tp[k + 1], tp[k], a] if tri[k] < 0 else [a, tp[k], tp[k + 1]])
            patches.append(cone)


def _build_run(
    mesh, frame: VertexFrame, centres, n_samples, apex, dev_apex, j0, j1
) -> tuple[Piece, np.ndarray, np.ndarray]:
    """The piece of sectors ``j0 .. j1``, its ``points_2d`` (k, 2) as an array and the sector
    of each of its faces ((n_faces,) int, from 0 at ``j0``)."""
    u = frame.vertex
    ring = frame.ring
    ne = len(frame.sides)
    heights = hole_heights(frame)
    piece = Piece(vertex=u)
    top_name = "cr" if apex is not None else "hole"
    cone = f"cone {u}"
    if apex is not None:
        piece.apex_index = piece.point(("apex",), dev_apex, apex)
    rounded = [i for i in range(j0, j1 + 1) if frame.sides[i].rounded]
    through_t = hole_corners(frame, centres) if apex is None else None
    curves = _side_curves(frame, rounded, n_samples, apex, dev_apex, heights)
    strips = _strips(frame, rounded, curves, dev_apex if apex is not None else None)

    def curves_of(i):
        if i not in curves:
            curves.update(_side_curves(frame, [i], n_samples, apex, dev_apex, heights))
        return curves[i]

    def line_points(i, face_i, start: bool, end_copy: bool = False):
        """(base, top) point indices of side ``i`` where it meets ring face ``face_i``.

        ``end_copy`` asks for the start of side ``i`` as reached from face ``face_i`` at the end
        of the run (across the cut: same 3D points, the 2D chart after ``face_i``).
        """
        side = frame.sides[i]
        if side.rounded:
            s, C, F, z = curves_of(i)
            k = 0 if start else len(s) - 1
            if end_copy:
                m = frame.face_map[face_i] @ frame.gluing_start(i)
                b = piece.point(("end", i, "bs", k), apply(m, [s[k], 0.0]), C[k])
                t = piece.point(("end", i, top_name, k), apply(m, [s[k], z[k]]), F[k])
                return b, t
            b = piece._keys.get(("side", i, "bs", k))
            t = piece._keys.get(("side", i, top_name, k))
            if b is None or t is None:
                strip = strips.get(i)
                m = frame.cyl_map[i]
                b2 = apply(m, [s[k], 0.0]) if strip is None else strip.base_2d[k]
                t2 = apply(m, [s[k], z[k]]) if strip is None else strip.top_2d[k]
                b = piece.point(("side", i, "bs", k), b2, C[k])
                t = piece.point(("side", i, top_name, k), t2, F[k])
            return b, t
        # unrounded boundary side: points on the edge line, in the chart of face_i
        h = 0.5 * (frame.lmax_start[i] if start else frame.lmax_end[i])
        m3 = side.M
        t3 = side.M + h * side.R
        fr = frame.face_frames[face_i]
        mp = frame.face_map[face_i]
        tag = "start" if start else "end"
        b = piece.point(("line", i, tag, "bs"), apply(mp, to_chart(fr, m3)), m3)
        t = piece.point(("line", i, tag, "top"), apply(mp, to_chart(fr, t3)), t3)
        return b, t

    sector = []
    for i in range(j0, j1 + 1):
        n_before = len(piece.faces)
        side = frame.sides[i]
        # the half-cylinder of side i and the cone over its crease
        if side.rounded:
            strip = strips[i]
            bs = _curve_points(piece, ("side", i, "bs"), strip.base_2d, strip.base_3d)
            tp = _curve_points(piece, ("side", i, top_name), strip.top_2d, strip.top_3d)
            _add_strip(piece, bs, tp, strip, f"cylinder {side.edge}", cone)
        # the share of face f_i, between side i (end) and side i + 1 (start)
        face = int(ring.faces[i])
        b0, t0 = line_points(i, i, start=False)
        nxt = (i + 1) % ne
        b1, t1 = line_points(nxt, i, start=True, end_copy=(i == j1))
        fr = frame.face_frames[i]
        c = piece.point(
            ("centre", face), apply(frame.face_map[i], to_chart(fr, centres[face])), centres[face]
        )
        corner = [t0, b0, c, b1, t1]
        if apex is None and through_t[i]:
            # a straight hole border would leave the face or cross the share: go through T
            T3 = frame.T_end[i]
            corner.append(piece.point(("T", i), apply(frame.face_map[i], to_chart(fr, T3)), T3))
        piece.face(corner, f"face {face}")
        if apex is not None:
            piece.face([piece.apex_index, t0, t1], cone)
        sector += [i - j0] * (len(piece.faces) - n_before)
    p2, kept = piece._merge_coincident(merge_distance(frame))
    sector = np.array(sector, dtype=np.int64)
    return piece, p2, sector if kept is None else sector[kept]


def assemble_pattern(pieces: list[Piece], offsets: np.ndarray) -> CreasePattern:
    """Merge translated pieces into one crease pattern, all faces at once.

    Parameters
    ----------
    pieces : list of Piece
    offsets : (n_pieces, 2) float
        Translation of each piece.

    Returns
    -------
    CreasePattern
        Vertices piece after piece (each piece's points in order, translated), faces as
        ``(k,) int64`` arrays piece after piece (:class:`~filletfold.pattern.FaceRows`), with
        their patches and pieces.
    """
    points = [piece.arrays() for piece in pieces]
    n_points = np.array([len(p2) for p2, _ in points], dtype=np.int64)
    n_faces = np.array([len(piece.faces) for piece in pieces], dtype=np.int64)
    v2 = np.vstack([p2 for p2, _ in points]) if pieces else np.zeros((0, 2))
    v3 = np.vstack([p3 for _, p3 in points]) if pieces else np.zeros((0, 3))
    v2 = v2 + np.repeat(np.asarray(offsets, dtype=float).reshape(-1, 2), n_points, axis=0)
    flats, sizes = zip(*(flat_faces(p.faces) for p in pieces), strict=True) if pieces else ((), ())
    size = np.concatenate([np.zeros(0, dtype=np.int64), *sizes])
    flat = np.concatenate([np.zeros(0, dtype=np.int64), *flats])
    base = np.concatenate([[0], np.cumsum(n_points)[:-1]])
    flat += np.repeat(np.repeat(base, n_faces), size)
    start = np.concatenate([[0], np.cumsum(size)])
    faces = FaceRows(flat, start)  # (k,) int64 rows made when asked for
    patches = list(itertools.chain.from_iterable(piece.patches for piece in pieces))
    apex = np.array([-1 if p.apex_index is None else p.apex_index for p in pieces], dtype=np.int64)
    apex = np.where(apex >= 0, apex + base, -1) if pieces else apex
    true_rulings(v2, v3, flat, size, np.repeat(apex, n_faces), patches)
    return CreasePattern(
        vertices_2d=v2,
        vertices_3d=v3,
        faces=faces,
        face_patch=patches,
        face_piece=np.repeat(np.arange(len(pieces)), n_faces),
        piece_vertex=np.array([piece.vertex for piece in pieces], dtype=np.int64),
    )


def true_rulings(v2, v3, flat, size, face_apex, patches) -> None:
    """Put every cone face's corner on its ruling at its folded distance from the apex, in place.

    Eq. (1) gives the crease point's height as a difference of squared distances divided by the
    denominator, so it loses ``(D / l)^2`` digits on a ruling of length ``l`` far (``D``) from
    its chart's origin: on float32 or near-developable inputs a short ruling came out longer
    folded than flat by ``3e-11`` of its length. The construction makes the ruling isometric,
    so the developed point is moved along its ruling ``v -> p`` to the distance ``|P - V|``
    (by round-off: ``1e-13`` of the design at most).

    Parameters
    ----------
    v2 : (n, 2) float
        Pattern points, moved in place.
    v3 : (n, 3) float
        Folded points.
    flat, size : (N,) int, (n_faces,) int
        The faces' corners one after the other, and how many each face has.
    face_apex : (n_faces,) int
        The apex point of each face's piece (-1 without a cone).
    patches : list of str
        Each face's patch; the corners of ``"cone ..."`` faces are moved.
    """
    cone = np.fromiter((p.startswith("cone") for p in patches), dtype=bool, count=len(patches))
    cone &= face_apex >= 0
    if not cone.any():
        return
    corner_face = np.repeat(np.arange(len(size)), size)
    on = cone[corner_face]
    point, apex = flat[on], face_apex[corner_face[on]]
    keep = point != apex
    pairs = np.unique(np.stack([point[keep], apex[keep]], axis=1), axis=0)
    p, a = pairs[:, 0], pairs[:, 1]
    d2 = v2[p] - v2[a]
    l2 = np.linalg.norm(d2, axis=1)
    l3 = np.linalg.norm(v3[p] - v3[a], axis=1)
    ok = l2 > 0
    v2[p[ok]] = v2[a[ok]] + d2[ok] * (l3[ok] / l2[ok])[:, None]
