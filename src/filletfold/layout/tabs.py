"""Glue tabs and labels on the cut borders of a crease pattern, and part numbers.

A *cut border* is a straight run of seam edges: border edges whose folded segment is also the
folded segment of another border edge (the other side of the cut, on the same or another
piece). Every cut border gets one glue tab, on the side where it overlaps nothing, and the
same label on both sides; every piece gets its part number.

The tabs are chosen greedily, border after border: the first of a border's candidate tabs
that overlaps no face and no tab placed before it. The candidates are tested on arrays, a
round at a time (:func:`_choose`): a grid of boxes finds the faces and tabs near each, and
separating axes and overlap areas (:mod:`filletfold.layout.convex`) decide the pairs that are
clearly apart or clearly overlapping, with margins far above round-off; shapely decides the
few others, as it decided every pair one at a time before. The same tabs, to the bit.
"""

from __future__ import annotations

import gc
from collections.abc import Sequence
from contextlib import contextmanager

import numpy as np
import shapely
from scipy.sparse import coo_array
from scipy.sparse.csgraph import connected_components

from ..arrays import run_owners
from ..surface.pattern import (
    Annotations,
    CreasePattern,
    LabelRows,
    PointRows,
    Rows,
    face_arrays,
)
from .convex import (
    BoxGrid,
    abs_max,
    boxes,
    clip_area,
    convex_overlap,
    cross,
    fold,
    inward_lines,
    is_convex,
    next_corners,
    pad_columns,
    polygon_area,
    row_max,
    sat_gap,
    shrink_convex,
    side_normals,
    surely_valid,
    take_rows,
    turns,
)

#: The candidate tabs of a border, in the order they are tried: (share of the full height,
#: which half of the border or None for all of it); each on side A, then on side B.
LEVELS = ((1.0, None), (0.5, None), (0.5, 0), (0.5, 1), (0.25, 0), (0.25, 1))

#: A tab is tested shrunk by this share of the full tab height (touching is not overlapping).
SHRINK = 1e-9

#: New candidate tabs whose neighbours are paired at a time (:func:`_choose`): bounds the
#: pairs of tabs half an edge high, some 200 per candidate.
PAIR_CHUNK = 4096

#: Tabs whose faces are found at a time (:meth:`_Faces.clear_block`): the grid's query of
#: 8,192 tabs half an edge high met 7.7 million faces and took 1.7 GB on a 9,352-vertex design.
QUERY_BLOCK = 512

#: Tabs tested against the faces at a time (:meth:`_Faces.clear`), and pairs of tabs tested
#: at a time (:func:`conflicts`): bounds the temporaries (some 2 KB per tab).
CLEAR_CHUNK = 8192
#: Overlap area (a share of the tab's area) above which a tab overlaps a face.
OVERLAP = 1e-12

#: A border no longer than this share of the tab height gets no tab.
MIN_BORDER = 1e-9

#: Relative round-off allowance of tab geometry: edges shorter than this share of the tab
#: height are slivers, areas this close (relatively) are equal.
SLIVER = 1e-6

#: Labels are placed on a grid of at most this fraction of the pattern's extent (a power of
#: ten), turned to :data:`LABEL_ANGLE_DECIMALS` decimals of a degree and sized to
#: :data:`LABEL_HEIGHT_DIGITS` significant digits (:func:`label_digits`).
LABEL_GRID = 1e-6
LABEL_ANGLE_DECIMALS = 2
LABEL_HEIGHT_DIGITS = 3

#: Height of a seam label, as a share of the full tab height (part numbers are twice as high).
LABEL_SHARE = 0.45

#: Smallest area of a candidate tab, as a share of its height squared: smaller ones are
#: degenerate.
LEAST_TAB = 1e-3

#: A candidate that holds each (the same or a larger tab on the same hinge): 1 in 0, 4 in 2,
#: 5 in 3 (side A, then B).
COVER = (0, 1, 0, 1, 4, 5, 6, 7, 4, 5, 6, 7)

#: The order levels are tested in within a round: a tab held in another first (if it
#: overlaps a face widely, so does the other).
HOLDS_FIRST = (0, 1, 4, 5, 2, 3)

#: The candidates tested together (each round: on the borders still undecided).
ROUNDS = ((0,), (1,), (2, 3), (4, 5, 6, 7, 8, 9, 10, 11))

EPS = np.finfo(np.float64).eps


def _rowdot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot products of two (n, 2) arrays, with the bits of the scalar ``a[i] @ b[i]``.

    ``np.matmul`` on stacks of (1, 2) and (2, 1) runs the BLAS kernel of a dot of two vectors,
    which may fuse the multiply and the add: ``a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]`` would
    round differently.
    """
    a = np.ascontiguousarray(a, dtype=np.float64)
    b = np.ascontiguousarray(b, dtype=np.float64)
    return np.matmul(a[:, None, :], b[:, :, None])[:, 0, 0]


def _rownorm(a: np.ndarray) -> np.ndarray:
    """Row-wise ``np.linalg.norm`` of an (n, 2) array, with the bits of the scalar one."""
    return np.sqrt(_rowdot(a, a))


def _seam_pairs(p: CreasePattern, decimals: int = 9) -> np.ndarray:
    """(k, 2) int: pairs of pattern edges that are the two sides of one cut.

    Border edges are matched by their rounded folded end points (as
    :meth:`CreasePattern.cut_mask` matches them); a pair is the two edges of a segment held
    by exactly two of them, the lower index first, the pairs in the order of their first edge.
    """
    cut = np.flatnonzero(p.edge_assignment == "B")
    vertex, end = np.unique(p.edges[cut], return_inverse=True)
    at = np.round(p.vertices_3d[vertex], decimals) + 0.0  # no -0.0
    nan = fold(np.logical_or, np.isnan(at))  # NaN is equal to nothing: never paired
    keep = ~nan[end.reshape(-1, 2)].any(axis=1)
    cut, end = cut[keep], end.reshape(-1, 2)[keep]
    if len(cut) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    bits = at.view(np.int64)  # equal values, equal bits
    order = np.lexsort(bits.T[::-1])
    step = np.r_[True, (bits[order][1:] != bits[order][:-1]).any(axis=1)]
    same = np.empty(len(bits), dtype=np.int64)  # the rounded point of each vertex
    same[order] = np.cumsum(step) - 1
    point = same[end]
    a, b = point[:, 0], point[:, 1]
    key = np.minimum(a, b) * (len(bits) + 1) + np.maximum(a, b)
    order = np.lexsort((cut, key))  # by segment, then by edge
    key, edge = key[order], cut[order]
    first = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    size = np.diff(np.r_[first, len(key)])
    two = first[size == 2]
    pairs = np.stack([edge[two], edge[two + 1]], axis=1)
    return pairs[np.argsort(pairs[:, 0], kind="stable")]


def _runs(p: CreasePattern, pairs: np.ndarray, angle_tol: float = 1e-6):
    """Group seam pairs into straight runs: consecutive, collinear edges on both sides.

    Two side-A edges join at a vertex that no other side-A edge has when they are collinear
    and so are their twins on side B. A run is grown from its first edge (in the order of
    ``pairs``) towards that edge's first vertex, then towards its second; the runs are in the
    order of their first edges.

    Returns
    -------
    side_a, side_b : (k,) int
        The edges of every run on side A and their twins on side B, run after run.
    start : (n_runs + 1,) int
        Run ``i`` is ``side_a[start[i]:start[i + 1]]``.
    """
    n = len(pairs)
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(1, np.int64)
    ea = p.edges[pairs[:, 0]]  # (n, 2) vertices of side A
    eb = p.edges[pairs[:, 1]]

    def direction(e):
        d = p.vertices_2d[e[:, 1]] - p.vertices_2d[e[:, 0]]
        with np.errstate(invalid="ignore", divide="ignore"):
            return d / _rownorm(d)[:, None]

    da, db = direction(ea), direction(eb)
    # the vertices held by exactly two side-A edges, and those two (the node = index in pairs)
    flat = ea.ravel()
    order = np.argsort(flat, kind="stable")
    sv = flat[order]
    first = np.flatnonzero(np.r_[True, sv[1:] != sv[:-1]])
    size = np.diff(np.r_[first, len(sv)])
    two = first[size == 2]
    vtx, k1, k2 = sv[two], order[two] // 2, order[two + 1] // 2
    with np.errstate(invalid="ignore"):  # a NaN direction fails no test, as in a loop
        join = (k1 != k2) & ~(np.abs(np.abs(_rowdot(da[k1], da[k2])) - 1) > angle_tol)
        join &= ~(np.abs(np.abs(_rowdot(db[k1], db[k2])) - 1) > angle_tol)
    vtx, k1, k2 = vtx[join], k1[join], k2[join]
    # other[v] = k1 + k2 at a joining vertex: the node after `cur` is other[v] - cur
    other = np.full(len(p.vertices_2d), -1, dtype=np.int64)
    other[vtx] = k1 + k2
    graph = coo_array((np.ones(len(k1)), (k1, k2)), shape=(n, n))
    _, comp = connected_components(graph, directed=False)
    head = np.full(comp.max() + 1, n, dtype=np.int64)
    np.minimum.at(head, comp, np.arange(n))
    head = np.sort(head)  # the first edge of every run, runs in its order
    run_of = np.empty(n, dtype=np.int64)
    pos = np.zeros(n, dtype=np.int64)
    run_of[head] = np.arange(len(head))
    seen = np.zeros(n, dtype=bool)
    seen[head] = True
    for end, sign in ((0, -1), (1, 1)):  # grow from the first vertex, then from the second
        cur, v, step = head.copy(), ea[head, end], 1
        while len(cur):
            nxt = np.where(other[v] >= 0, other[v] - cur, -1)
            ok = nxt >= 0
            ok[ok] = ~seen[nxt[ok]]
            cur, v, nxt = cur[ok], v[ok], nxt[ok]
            if not len(nxt):
                break
            seen[nxt] = True
            run_of[nxt] = run_of[cur]
            pos[nxt] = sign * step
            v = np.where(ea[nxt, 0] == v, ea[nxt, 1], ea[nxt, 0])
            cur, step = nxt, step + 1
    nodes = np.lexsort((pos, run_of))
    start = np.searchsorted(run_of[nodes], np.arange(len(head) + 1))
    return pairs[nodes, 0], pairs[nodes, 1], start


def _segments(p: CreasePattern, edges: np.ndarray, start: np.ndarray):
    """End points and outward unit normals of straight runs of edges.

    Parameters
    ----------
    p : CreasePattern
    edges : (k,) int
        The edges of every run, run after run.
    start : (n_runs + 1,) int
        Run ``i`` is ``edges[start[i]:start[i + 1]]`` (none empty).

    Returns
    -------
    ends : (n_runs, 2, 2) float
        The run's extreme points along its direction, the first one first.
    normal : (n_runs, 2) float
        The unit normal pointing away from the face of the run's first edge.
    """
    n = len(start) - 1
    pts = take_rows(p.vertices_2d, take_rows(p.edges, edges).ravel())  # two per edge
    at = 2 * start[:-1]
    d = np.maximum.reduceat(pts, at, axis=0) - np.minimum.reduceat(pts, at, axis=0)
    norm = _rownorm(d)
    with np.errstate(invalid="ignore", divide="ignore"):
        axis = np.where((norm > 0)[:, None], d / norm[:, None], [1.0, 0.0])
    count = 2 * np.diff(start)
    lo, hi = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    for k in np.unique(count).tolist():  # runs of k points together
        runs = np.flatnonzero(count == k)
        at_k = at[runs][:, None] + np.arange(k)
        # the bits of `points @ axis` (a BLAS gemv), and np.argmin's first of the smallest
        t = np.matmul(pts[at_k], axis[runs][:, :, None])[..., 0]
        lo[runs], hi[runs] = at_k[:, 0] + t.argmin(axis=1), at_k[:, 0] + t.argmax(axis=1)
    ends = np.stack([take_rows(pts, lo), take_rows(pts, hi)], axis=1)
    flat, fstart = face_arrays(p.faces)
    face = p.edge_faces[edges[start[:-1]]].max(axis=1)
    size = fstart[face + 1] - fstart[face]
    centre = np.empty((n, 2))
    for k in np.unique(size).tolist():  # the bits of `corners.mean(axis=0)`: a sum in order
        runs = np.flatnonzero(size == k)
        corners = _padded(p.vertices_2d, flat, fstart, face[runs], k)
        total = corners[:, 0].copy()
        for i in range(1, k):
            total += corners[:, i]
        centre[runs] = total / k
    normal = np.stack([-axis[:, 1], axis[:, 0]], axis=1)
    flip = _rowdot(centre - (ends[:, 0] + ends[:, 1]) / 2, normal) > 0
    normal[flip] = -normal[flip]
    return ends, normal


def tab_outlines(ends: np.ndarray, normal: np.ndarray, height) -> tuple[np.ndarray, np.ndarray]:
    """Trapezoidal tabs on segments: the segment, then its far side ``height`` away.

    Parameters
    ----------
    ends : (n, 2, 2) float
        The segments (the tabs' hinges).
    normal : (n, 2) float
        Unit normals: where the tabs stand.
    height : float or (n,) float

    Returns
    -------
    quads : (n, 4, 2) float
        ``p0, p1``, then the far side, inset at both ends by ``min(height, 0.3 * length)``.
    ok : (n,) bool
        False where the segment is too short for a tab (no more than :data:`MIN_BORDER`
        times ``height``).
    """
    height = np.broadcast_to(np.asarray(height, dtype=np.float64), (len(ends),))
    p0, p1 = ends[:, 0], ends[:, 1]
    length = _rownorm(p1 - p0)
    ok = ~(length <= MIN_BORDER * height)
    with np.errstate(invalid="ignore", divide="ignore"):
        d = (p1 - p0) / length[:, None]
    inset = np.where(0.3 * length < height, 0.3 * length, height)[:, None]
    up = height[:, None] * normal
    return np.stack([p0, p1, p1 + up - inset * d, p0 + up + inset * d], axis=1), ok


def _halves(ends: np.ndarray, which: int) -> np.ndarray:
    """The first (0) or second (1) halves of segments (n, 2, 2): tabs clear of a narrow corner."""
    mid = (ends[:, 0] + ends[:, 1]) / 2
    return np.stack([ends[:, 0], mid] if which == 0 else [mid, ends[:, 1]], axis=1)


def label_digits(labels: LabelRows, points: np.ndarray) -> LabelRows:
    """Labels with the digits their placement carries: positions on a grid of at most
    :data:`LABEL_GRID` of the pattern's extent (a power of ten), angles to
    :data:`LABEL_ANGLE_DECIMALS` decimals of a degree, heights to
    :data:`LABEL_HEIGHT_DIGITS` significant digits. A label's text is placed to that much
    (a micrometre on a metre-wide sheet), so the files hold short numbers
    (``annotations.json``: 12-digit label numbers were 5.4 MB of the cow's 8.8), and every
    cut file made from them, now or again from the files, draws the same labels.

    Parameters
    ----------
    labels : LabelRows
    points : (n, 2) float
        The pattern's points (their extent sets the grid).

    Returns
    -------
    LabelRows
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    extent = float(np.ptp(pts, axis=0).max()) if len(pts) else 0.0
    position = labels.position
    if extent > 0 and np.isfinite(extent):
        position = _to_decimals(position, -np.floor(np.log10(LABEL_GRID * extent))) + 0.0
    height = np.asarray(labels.height, dtype=np.float64)
    ok = np.isfinite(height) & (height != 0)  # 0 and non-finite heights as they are
    height = height.copy()
    height[ok] = _to_decimals(
        height[ok], LABEL_HEIGHT_DIGITS - 1 - np.floor(np.log10(np.abs(height[ok])))
    )
    return LabelRows(
        position,
        labels.text,
        np.round(labels.angle, LABEL_ANGLE_DECIMALS) + 0.0,  # + 0.0: no -0.0
        height,
        labels.kind,
    )


def _to_decimals(x: np.ndarray, decimals) -> np.ndarray:
    """``x`` rounded to ``decimals`` (per value or for all; negative: to tens, hundreds...),
    through exact powers of ten: each result is the double nearest its decimal (short to
    print), not a multiple of an inexact ``10**-d``."""
    d = np.asarray(decimals, dtype=np.float64)
    up = 10.0 ** np.abs(d)
    return np.where(d >= 0, np.round(x * up) / up, np.round(x / up) * up)


def _readable(angle: np.ndarray) -> np.ndarray:
    """Text angles in (-90, 90] so that labels are never upside down."""
    a = (angle + 180.0) % 360.0 - 180.0
    return np.where(a <= -90, a + 180, np.where(a > 90, a - 180, a))


def _closed_polygons(rings: np.ndarray) -> np.ndarray:
    """Shapely polygons of rings (n, k, 2) (closed here; faster than ``shapely.polygons`` of
    the bare coordinates)."""
    return shapely.polygons(shapely.linearrings(np.concatenate([rings, rings[:, :1]], axis=1)))


def _bucket(size: np.ndarray) -> np.ndarray:
    """Corner counts up to 8, larger ones rounded up to a power of two: faces padded together."""
    up = (2 ** np.ceil(np.log2(np.maximum(size, 1)))).astype(np.int64)
    return np.where(size <= 8, np.maximum(size, 1), up)


def _padded(coords: np.ndarray, flat: np.ndarray, start: np.ndarray, faces: np.ndarray, k: int):
    """The corners (len(faces), k, 2) of faces of at most ``k`` corners, the last repeated."""
    size = start[faces + 1] - start[faces]
    slot = np.minimum(np.arange(k), size[:, None] - 1)
    at = np.take(flat, (start[faces][:, None] + slot).ravel())
    return np.take(coords, at, axis=0).reshape(len(faces), k, coords.shape[1])


class _Faces:
    """The faces of a pattern, for testing tabs against them (:meth:`clear`).

    Parameters
    ----------
    p : CreasePattern
    tab_height : float

    Notes
    -----
    Faces of ``k`` corners (:func:`_bucket`) are held together: their corners ``x, y`` and,
    for the convex ones, their sides' unit normals ``ux, uy`` and the faces' extents ``lo, hi``
    along them (separating axes), each (n_k, k). Shapely polygons are made only for the
    faces that need them: those whose validity is in doubt, and those of pairs that the
    arrays leave undecided.
    """

    def __init__(self, p, tab_height):
        self.h, self.s = tab_height, SHRINK * tab_height
        self.coords = p.vertices_2d
        self.flat, self.start = face_arrays(p.faces)
        n = len(self.start) - 1
        size = np.diff(self.start)
        self.bucket = _bucket(size)
        self.row = np.zeros(n, dtype=np.int64)
        self.convex = np.zeros(n, dtype=bool)
        valid = np.zeros(n, dtype=bool)
        finite = np.zeros(n, dtype=bool)
        lo, hi = np.full((n, 2), np.nan), np.full((n, 2), np.nan)
        self.sets = {}
        for k in np.unique(self.bucket).tolist():
            faces = np.flatnonzero(self.bucket == k)
            self.row[faces] = np.arange(len(faces))
            corners = _padded(self.coords, self.flat, self.start, faces, k)
            finite[faces] = np.isfinite(corners).all(axis=(1, 2))
            lo[faces], hi[faces] = boxes(corners)
            turn = turns(corners)
            if k <= 8:  # not padded: strictly convex is valid, no need to ask shapely
                valid[faces] = surely_valid(corners, turn)
            self.convex[faces] = is_convex(corners, turn)
            u = side_normals(corners)
            t_lo = t_hi = None  # the corners' extents along each side's normal, one at a time
            for i in range(k):
                t = u[..., 0] * corners[:, i, None, 0] + u[..., 1] * corners[:, i, None, 1]
                t_lo = t if t_lo is None else np.minimum(t_lo, t)
                t_hi = t if t_hi is None else np.maximum(t_hi, t)
            self.sets[k] = (corners[..., 0], corners[..., 1], u[..., 0], u[..., 1], t_lo, t_hi)
        self.polys: dict[int, object] = {}
        doubt = np.flatnonzero(~valid)
        if len(doubt):  # a face that is not a valid polygon is taken as its valid part
            shapes = self.polygons(doubt)
            ok = shapely.is_valid(shapes)
            valid[doubt] = ok
            fixed = shapely.make_valid(shapes[~ok])
            self.polys.update(zip(doubt[~ok].tolist(), fixed, strict=True))
        self.fast = valid & finite  # the faces that the array tests may decide
        self.extent = np.max(hi - lo, axis=1)
        self.grid = BoxGrid(lo, hi)

    def polygons(self, faces: np.ndarray) -> np.ndarray:
        """Shapely geometries of faces (made once; an invalid face as its valid part)."""
        new = [f for f in dict.fromkeys(faces.tolist()) if f not in self.polys]
        if new:
            new = np.asarray(new, dtype=np.int64)
            size = self.start[new + 1] - self.start[new]
            corner = np.repeat(self.start[new] - np.cumsum(size) + size, size) + np.arange(
                size.sum()
            )
            ring = shapely.linearrings(self.coords[self.flat[corner]], indices=run_owners(size))
            self.polys.update(zip(new.tolist(), shapely.polygons(ring), strict=True))
        return np.array([self.polys[f] for f in faces.tolist()], dtype=object)

    def areas(self) -> np.ndarray:
        """(n_faces,) float: the faces' areas, as shapely gives them within round-off."""
        area = np.zeros(len(self.bucket))
        for k, (fx, fy, *_) in self.sets.items():
            faces = np.flatnonzero(self.bucket == k)
            x, y = fx - fx[:, :1], fy - fy[:, :1]
            area[faces] = np.abs(np.sum(x * next_corners(y) - y * next_corners(x), axis=1)) / 2
        fixed = [f for f in self.polys if not self.fast[f]]
        if fixed:
            area[fixed] = shapely.area(self.polygons(np.asarray(fixed, dtype=np.int64)))
        return area

    def clear(self, quads, area, hint=None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`clear_block` of at most :data:`CLEAR_CHUNK` tabs at a time (each tab is
        tested on its own: the same answers, with the pairs of one block in memory)."""
        n = len(quads)
        if n <= CLEAR_CHUNK:
            return self.clear_block(quads, area, hint)
        blocker = np.full(n, -1, dtype=np.int64)
        wide = np.zeros(n, dtype=bool)
        for lo in range(0, n, CLEAR_CHUNK):
            hi = min(n, lo + CLEAR_CHUNK)
            part = None if hint is None else hint[lo:hi]
            blocker[lo:hi], wide[lo:hi] = self.clear_block(quads[lo:hi], area[lo:hi], part)
        return blocker, wide

    def clear_block(self, quads, area, hint=None) -> tuple[np.ndarray, np.ndarray]:
        """Tabs that overlap no face: shapely's verdict on each, had it been asked.

        Parameters
        ----------
        quads : (n, 4, 2) float
            Tabs (valid convex polygons), their hinge first.
        area : (n,) float
            Their areas.
        hint : (n,) int, optional
            A face likely to overlap each tab (-1: none), tested first.

        Returns
        -------
        blocker : (n,) int
            -1 where the tab shrunk by ``SHRINK`` of the tab height overlaps no face by more
            than ``OVERLAP`` of its area, else a face it overlaps.
        wide : (n,) bool
            The tabs that the arrays find overlapping their blocker by far more than that
            (so does any larger tab that holds them).
        """
        n = len(quads)
        blocker = np.full(n, -1, dtype=np.int64)
        if n == 0 or len(self.bucket) == 0:
            return blocker, np.zeros(n, dtype=bool)
        s = self.s
        local = quads - quads[:, :1]
        normal, offset = inward_lines(local)
        side = next_corners(local) - local
        perimeter = fold(np.add, np.sqrt(side[..., 0] ** 2 + side[..., 1] ** 2))
        # the region s / 2 inside the tab: apart from it by s / 4, a face is apart from the
        # shrunk tab whatever round-off shapely and these figures make (checked by `sure`)
        frame = {
            "origin": quads[:, 0],
            "ox": quads[:, 0, 0].copy(),
            "oy": quads[:, 0, 1].copy(),
            "normal": normal,
            "offset": offset + s / 2,
            "nx": np.ascontiguousarray(normal[..., 0].T),  # (4, n): side after side
            "ny": np.ascontiguousarray(normal[..., 1].T),
            "off": np.ascontiguousarray(offset.T + s / 2),
            "inner": shrink_convex(local, s / 2, normal),  # about the origin
            "least": SHRINK * area + 2 * s * perimeter,
            "reach": abs_max(quads) + abs_max(local) + self.h,
            "wide": np.zeros(n, dtype=bool),
        }
        if hint is not None:
            t = np.flatnonzero(hint >= 0)
            self._pairs(frame, t, hint[t], blocker, None)
        rest = np.flatnonzero(blocker < 0)
        pairs = []  # (tab, face) pairs the arrays leave undecided
        for lo in range(0, len(rest), QUERY_BLOCK):  # the grid's query of tabs half an edge
            # high took 1.7 GB for 8,192 of them (7.7 million faces met)
            some = rest[lo : lo + QUERY_BLOCK]
            i, faces = self.grid.query(*boxes(take_rows(quads, some)))
            tabs = np.take(some, i)
            part = []
            self._pairs(frame, tabs, faces, blocker, part)
            at = np.concatenate(part)
            pairs.append((tabs[at], faces[at]))
        tabs = np.concatenate([t for t, _ in pairs]) if pairs else np.zeros(0, dtype=np.int64)
        faces = np.concatenate([f for _, f in pairs]) if pairs else np.zeros(0, dtype=np.int64)
        open_ = blocker[tabs] < 0  # the tabs no face blocked yet
        tabs, faces = tabs[open_], faces[open_]
        if len(tabs):
            hit = self._exact(quads, tabs, faces)
            blocker[tabs[hit]] = faces[hit]
        return blocker, frame["wide"]

    def _pairs(self, frame, tabs, faces, blocker, slow):
        """Test pairs of a tab and a face; set ``blocker`` of the tabs found overlapping.

        With ``slow`` (a list), the pairs are first tested for separating axes, and those the
        arrays leave undecided are appended to it (as indices into ``tabs``); without, the
        pairs are only clipped, and the undecided ones dropped.
        """
        s = self.s
        reach = np.take(self.extent, faces) + np.take(frame["reach"], tabs)
        sure = np.take(self.fast, faces) & (16 * EPS * reach < s / 4)
        if slow is not None:
            slow.append(np.flatnonzero(~sure))
        todo = np.flatnonzero(sure)
        bucket = np.take(self.bucket, np.take(faces, todo))
        nx, ny, off = frame["nx"], frame["ny"], frame["off"]
        kept = []
        for k in self.sets:
            pair = todo[bucket == k]
            if not len(pair):
                continue
            fx, fy, ux, uy, lo, hi = self.sets[k]
            t, f = np.take(tabs, pair), np.take(faces, pair)
            row = np.take(self.row, f)
            x = take_rows(fx, row) - np.take(frame["ox"], t)[:, None]
            y = take_rows(fy, row) - np.take(frame["oy"], t)[:, None]
            live = np.arange(len(pair))
            if slow is not None:
                # apart along a side of the tab (its hinge first: its own piece's faces)
                for j in range(4):
                    tl = np.take(t, live)
                    xl, yl = take_rows(x, live), take_rows(y, live)
                    d = row_max(xl * np.take(nx[j], tl)[:, None] + yl * np.take(ny[j], tl)[:, None])
                    live = live[~(d - np.take(off[j], tl) < -s / 4)]
                # apart along a side of a convex face
                conv = live[np.take(self.convex, np.take(f, live))]
                if len(conv):
                    r, tc = np.take(row, conv), np.take(t, conv)
                    inner = take_rows(frame["inner"], tc) + take_rows(frame["origin"], tc)[:, None]
                    ur, vr = take_rows(ux, r), take_rows(uy, r)
                    proj = [ur * inner[:, i, 0, None] + vr * inner[:, i, 1, None] for i in range(4)]
                    low, high = np.minimum.reduce(proj), np.maximum.reduce(proj)
                    gap = np.maximum(low - take_rows(hi, r), take_rows(lo, r) - high)
                    apart = fold(np.logical_or, gap > s / 4)  # NaN (no length): not apart
                    drop = np.zeros(len(pair), dtype=bool)
                    drop[conv[apart]] = True
                    live = live[~drop[live]]
            kept.append((np.take(pair, live), take_rows(x, live), take_rows(y, live)))
        if not kept:
            return
        # a tab is blocked by its first overlapping face: clip the first pair of every tab,
        # then the others of the tabs still clear (faces padded to as many corners)
        width = max(x.shape[1] for _, x, _ in kept)
        pair = np.concatenate([p for p, _, _ in kept])
        poly = np.concatenate(
            [np.stack([pad_columns(x, width), pad_columns(y, width)], axis=-1) for _, x, y in kept]
        )
        t = np.take(tabs, pair)
        first = np.zeros(len(pair), dtype=bool)
        first[np.unique(t, return_index=True)[1]] = True
        for part in (np.flatnonzero(first), np.flatnonzero(~first)):
            part = part[np.take(blocker, np.take(t, part)) < 0]
            if not len(part):
                continue
            tp, fp = np.take(t, part), np.take(faces, np.take(pair, part))
            pp = take_rows(poly, part)
            got, empty, doubt = convex_overlap(pp, take_rows(frame["inner"], tp))
            doubt |= ~np.take(self.convex, fp)
            if doubt.any():  # Sutherland-Hodgman: faces not convex, touching sides
                d = np.flatnonzero(doubt)
                td = np.take(tp, d)
                got[d], empty[d] = clip_area(
                    take_rows(pp, d), take_rows(frame["normal"], td), take_rows(frame["offset"], td)
                )
            big = ~empty & (got > np.take(frame["least"], tp))
            blocker[tp[big]] = fp[big]
            frame["wide"][tp[big]] = True
            if slow is not None:
                slow.append(np.take(pair, part[~empty & ~big]))

    def _exact(self, quads, tabs, faces):
        """Blocked pairs of a tab and a face, by shapely on the tab shrunk by ``SHRINK``."""
        uniq, inv = np.unique(tabs, return_inverse=True)
        shapes = _closed_polygons(quads[uniq])
        shrunk, area = _shrunk(shapes, self.s), shapely.area(shapes)
        polys = self.polygons(faces)
        blocked = np.zeros(len(tabs), dtype=bool)
        for i in range(len(tabs)):  # few: faces made valid, far coordinates, grazing pairs
            g, face = shrunk[inv[i]], polys[i]
            if g is None:
                blocked[i] = True
                continue
            if not shapely.intersects(shapely.box(*g.bounds), shapely.box(*face.bounds)):
                continue  # not a pair STRtree.query(shrunk) gives
            try:
                blocked[i] = face.intersection(g).area > OVERLAP * area[inv[i]]
            except shapely.errors.GEOSException:
                blocked[i] = True
        return blocked


def conflicts(
    earlier: np.ndarray, later: np.ndarray, shrink: float, *, exact: bool = True
) -> np.ndarray:
    """Whether tabs intersect tabs shrunk by ``shrink``: shapely's verdict, had it been asked.

    Parameters
    ----------
    earlier, later : (n, 4, 2) float
        Convex tabs; each ``later[i]`` is shrunk and tested against ``earlier[i]``.
    shrink : float
    exact : bool
        False: the pairs the arrays leave undecided count as intersecting (a bound).

    Returns
    -------
    (n,) bool
    """
    if len(later) > CLEAR_CHUNK:  # each pair on its own: in blocks, to bound the temporaries
        out = np.zeros(len(later), dtype=bool)
        for lo in range(0, len(later), CLEAR_CHUNK):
            hi = lo + CLEAR_CHUNK
            out[lo:hi] = conflicts(earlier[lo:hi], later[lo:hi], shrink, exact=exact)
        return out
    if not len(later):
        return np.zeros(0, dtype=bool)
    origin = later[:, :1]
    a, b = earlier - origin, shrink_convex(later - origin, shrink)
    (alo, ahi), (blo, bhi) = boxes(a), boxes(b)
    gap = fold(np.maximum, np.maximum(blo - ahi, alo - bhi))  # apart along x or y
    sat = np.flatnonzero(~(gap > shrink / 4))
    gap[sat] = sat_gap(take_rows(a, sat), take_rows(b, sat))
    scale, reach = abs_max(later), abs_max(a)
    sure = 16 * EPS * (reach + scale + shrink / SHRINK) < shrink / 4
    hit = ~(sure & (gap > shrink / 4))
    slow = np.flatnonzero(~sure | ~((gap > shrink / 4) | (gap < -shrink / 4)))
    if exact and len(slow):
        tabs = _closed_polygons(earlier[slow])
        shrunk = _shrunk(_closed_polygons(later[slow]), shrink)
        for i, k in enumerate(slow.tolist()):
            try:
                hit[k] = shrunk[i] is None or bool(tabs[i].intersects(shrunk[i]))
            except shapely.errors.GEOSException:
                hit[k] = True
    return hit


def _shrunk(tabs: np.ndarray, by: float) -> list:
    """Tabs buffered by ``-by``, as shapely buffers one (None where that fails)."""
    out = []
    for g in tabs:
        try:
            out.append(g.buffer(-by))
        except shapely.errors.GEOSException:
            out.append(None)
    return out


def add_tabs_and_labels(p: CreasePattern, tab_height: float, *, part_names=None) -> dict:
    """Fill ``p.annotations`` with glue tabs, matching labels and part numbers.

    Parameters
    ----------
    p : CreasePattern
        Its 2D layout is final (tabs are placed in it).
    tab_height : float
        Height of a full tab (pattern units); a tab that would overlap a piece or another tab
        is tried on the other side of its cut, then at half the height, then at half or a
        quarter of the height along either half of the border (clear of a narrow wedge).
    part_names : list of str, optional
        Names of the pieces (default ``P1``, ``P2``, ...).

    Returns
    -------
    dict
        ``cut_borders``, ``tabs`` (placed), ``tabs_reduced`` (at a smaller height),
        ``untabbed`` (cut borders where no tab fits: they keep their two labels) and ``seams``
        (per label: the two pieces it joins and the piece carrying the tab).
    """
    with _no_gc():
        return _tabs_and_labels(p, tab_height, part_names)


def _tabs_and_labels(p, tab_height, part_names):
    """The work of :func:`add_tabs_and_labels`."""
    faces = _Faces(p, tab_height)
    ann = Annotations(sheets=p.annotations.sheets)
    label_h = LABEL_SHARE * tab_height
    side_a, side_b, start = _runs(p, _seam_pairs(p))
    ends = np.zeros((0, 2, 2, 2))
    normal = np.zeros((0, 2, 2))
    first_a = first_b = np.zeros(0, dtype=np.int64)
    if len(start) > 1:
        ea, na = _segments(p, side_a, start)
        eb, nb = _segments(p, side_b, start)
        long = _rownorm(ea[:, 1] - ea[:, 0]) > SLIVER * tab_height  # shorter: round-off
        ends, normal = np.stack([ea, eb], axis=1)[long], np.stack([na, nb], axis=1)[long]
        first_a, first_b = side_a[start[:-1][long]], side_b[start[:-1][long]]
    n_runs = len(ends)
    names = part_names or [f"P{k + 1}" for k in range(p.n_pieces)]
    stats = {"cut_borders": n_runs, "tabs": 0, "tabs_reduced": 0, "untabbed": n_runs}
    seams = Seams([], np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64))
    if n_runs:
        run, level, side, quads, hinges = _choose(faces, ends, normal, tab_height)
        stats["tabs"] = len(run)
        stats["tabs_reduced"] = int(np.count_nonzero(level > 0))
        stats["untabbed"] = n_runs - len(run)
        ann.tabs = PointRows.of_blocks(quads)
        ann.tab_hinges = PointRows.of_blocks(hinges)
        tab_on = np.full(n_runs, -1)
        tab_on[run] = side
        pieces = np.stack([_piece_of(p, first_a), _piece_of(p, first_b)], axis=1)
        seams = Seams(names, pieces, tab_on)
        d = ends[:, :, 1] - ends[:, :, 0]
        pos = (ends[:, :, 0] + ends[:, :, 1]) / 2 - 0.9 * label_h * normal
        angle = _readable(np.degrees(np.arctan2(d[..., 1], d[..., 0])))
        text = [""] * (2 * n_runs)
        text[::2] = text[1::2] = list(map(str, range(1, n_runs + 1)))
        ann.labels = LabelRows(pos.reshape(-1, 2), text, angle.ravel(), label_h, "tab")
    ann.labels = LabelRows.of(ann.labels) + _part_labels(p, faces, names, label_h)
    ann.labels = label_digits(ann.labels, p.vertices_2d)
    ann.seams = seams
    p.annotations = ann
    stats["seams"] = seams
    return stats


@contextmanager
def _no_gc():
    """No automatic garbage collection inside: the labels and seams made here live on, and
    each of the collections their numbers would set off (some 70 on hull1000, some
    walking every object of the design) finds nothing to free."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _piece_of(p: CreasePattern, edges: np.ndarray) -> np.ndarray:
    """The piece of the face of each (border) edge."""
    return np.take(p.face_piece, fold(np.maximum, take_rows(p.edge_faces, edges)))


def _part_labels(p: CreasePattern, faces: _Faces, names, label_h: float) -> list:
    """Every piece's part number, inside its largest face (the first of the largest, by
    shapely's areas: asked where two are within round-off)."""
    n = len(faces.bucket)
    piece = p.face_piece
    inside = np.flatnonzero((piece >= 0) & (piece < p.n_pieces))
    if not len(inside):
        return LabelRows(np.zeros((0, 2)), [], 0.0, 0.0, "part")
    area = faces.areas()
    best = np.full(p.n_pieces, -np.inf)
    np.maximum.at(best, piece[inside], area[inside])
    close = inside[~(area[inside] < best[piece[inside]] * (1 - SLIVER))]  # NaN kept: ask
    exact = np.full(n, -np.inf)
    exact[close] = area[close]
    tie = close[np.bincount(piece[close], minlength=p.n_pieces)[piece[close]] > 1]
    exact[tie] = shapely.area(faces.polygons(tie))
    exact = np.where(np.isnan(exact), np.inf, exact)  # np.argmax takes a NaN first
    order = close[np.lexsort((close, -exact[close], piece[close]))]
    first = order[np.r_[True, piece[order][1:] != piece[order][:-1]]]
    where = shapely.get_coordinates(shapely.point_on_surface(faces.polygons(first)))
    return LabelRows(where, [names[k] for k in piece[first].tolist()], 0.0, 2 * label_h, "part")


def _candidates(ends, normal, tab_height, cand):
    """Candidate tabs ``cand`` (``border * 12 + 2 * level + side``, :data:`LEVELS`).

    Returns
    -------
    quads : (n, 4, 2) float
    hinges : (n, 2, 2) float
    ok : (n,) bool
        False where the hinge is too short for a tab.
    height : (n,) float
    """
    quads = np.empty((len(cand), 4, 2))
    hinges = np.empty((len(cand), 2, 2))
    ok = np.zeros(len(cand), dtype=bool)
    height = np.zeros(len(cand))
    border, k = cand // (2 * len(LEVELS)), cand % (2 * len(LEVELS))
    for level, (scale, part) in enumerate(LEVELS):
        for side in (0, 1):
            at = np.flatnonzero(k == 2 * level + side)
            if not len(at):
                continue
            sub = take_rows(ends, border[at])[:, side]
            sub = sub if part is None else _halves(sub, part)
            height[at] = scale * tab_height
            quads[at], ok[at] = tab_outlines(
                sub, take_rows(normal, border[at])[:, side], height[at]
            )
            hinges[at] = sub
    return quads, hinges, ok, height


def _untested(cand, side, tested, n_cand):
    """Pairs of a candidate and each candidate not tested yet (beyond the first ``tested``)
    of a border's side (``2 * border + A or B``), for every (``cand``, ``side``)."""
    k = np.arange(tested, n_cand)
    mask = k[None, :] % 2 == side[:, None] % 2
    i, j = np.nonzero(mask)
    return cand[i], (side[i] // 2) * n_cand + k[j]


def _choose(faces: _Faces, ends, normal, tab_height):
    """The greedy choice of a tab for every border (see :func:`add_tabs_and_labels`).

    The candidates are tested in rounds (:data:`ROUNDS`) on the borders still undecided;
    after each round, the greedy choice runs as far as it can: a border is decided when its
    choice no longer depends on a candidate not tested yet, its own or that of an earlier,
    undecided border.

    Parameters
    ----------
    faces : _Faces
    ends : (n, 2, 2, 2) float
        Per border, per side (A, B): the border's end points.
    normal : (n, 2, 2) float
        Per border, per side: the outward unit normal.
    tab_height : float

    Returns
    -------
    run, level, side : (t,) int
        The borders with a tab, and the level (:data:`LEVELS`) and side of their tab.
    quads : (t, 4, 2) float
        The tabs, counter-clockwise.
    hinges : (t, 2, 2) float
    """
    n = len(ends)
    s = SHRINK * tab_height
    n_cand = 2 * len(LEVELS)  # candidate c of border r: r * n_cand + 2 * level + side

    def quads_of(c):
        """The outlines of candidates ``c``, made again where they are needed (the same
        numbers each time: a table of all of them would take 1 KB per border)."""
        return _candidates(ends, normal, tab_height, c)[0]

    def pairs(c, chunk):
        """For the new candidates ``chunk`` (of the round's ``c``): record in ``state`` the
        tested candidates of other borders they intersect, and the untested ones of earlier
        borders they might."""
        # the sides of other borders near the new candidates
        i, j = sides.query(*boxes(quads_of(chunk)))
        pc, ps = chunk[i], j
        other = ps // 2 != pc // n_cand
        pc, ps = pc[other], ps[other]
        # earlier borders still undecided: the candidates not tested yet that each new one
        # might meet (tested a few together: a full tab holds the half-height one, a half
        # border's tab the quarter-height one)
        lo = np.flatnonzero(ps // 2 < pc // n_cand)
        lo = lo[state.undecided[ps[lo] // 2]]
        lo = lo[conflicts(take_rows(envelope, ps[lo]), quads_of(pc[lo]), s, exact=False)]
        a, b = _untested(pc[lo], ps[lo], ks[-1] + 1, n_cand)
        holder = np.asarray(COVER)[b % n_cand]
        cover = np.where(holder > ks[-1], b - b % n_cand + holder, b)  # if untested too
        key, inv = np.unique(a * (n * n_cand) + cover, return_inverse=True)
        held, _, fits, _ = _candidates(ends, normal, tab_height, key % (n * n_cand))
        maybe = conflicts(held, quads_of(key // (n * n_cand)), s, exact=False) | ~fits
        state.might_meet(a[maybe[inv]], b[maybe[inv]])
        # the tested candidates of those sides: which tabs intersect which
        rows, col = np.nonzero(good[(ps // 2)[:, None], ps[:, None] % 2 + np.arange(0, n_cand, 2)])
        a, b = pc[rows], (ps[rows] // 2) * n_cand + ps[rows] % 2 + 2 * col
        new_b = np.isin(b, c)
        a, b = a[~new_b | (b < a)], b[~new_b | (b < a)]
        later = np.where(a // n_cand > b // n_cand, a, b)
        earlier = a + b - later
        hit = conflicts(quads_of(earlier), quads_of(later), s)
        state.meets(later[hit], earlier[hit])

    # where any candidate of a border's side may lie: the rectangle of the full height on
    # the border (per side 2 * border + A or B)
    up = tab_height * normal[..., None, :]
    envelope = np.concatenate([ends, ends[:, :, ::-1] + up], axis=2).reshape(2 * n, 4, 2)
    sides = BoxGrid(*boxes(envelope))
    good = np.zeros((n, n_cand), dtype=bool)
    state = _Greedy(n, n_cand)
    blocker_of = np.full((n, 2), -1, dtype=np.int64)  # a face that blocked a side's last tab
    undecided = np.arange(n)
    for ks in ROUNDS:
        c = tried = (undecided[:, None] * n_cand + np.asarray(ks)).ravel()
        q, _, ok, height = _candidates(ends, normal, tab_height, c)
        c, q, height = c[ok], np.compress(ok, q, axis=0), height[ok]
        area, least = polygon_area(q), LEAST_TAB * height**2
        valid = surely_valid(q)
        doubt = np.flatnonzero(~valid | ~(np.abs(area - least) > SLIVER * least))
        if len(doubt):
            shapes = _closed_polygons(q[doubt])
            valid[doubt], area[doubt] = shapely.is_valid(shapes), shapely.area(shapes)
        keep = np.flatnonzero(valid & (area > least))
        c, q, area = c[keep], take_rows(q, keep), area[keep]
        blocked = np.zeros(len(c), dtype=bool)
        level = c % n_cand // 2
        held = np.zeros(n * n_cand, dtype=bool)  # held by a tab found wide of its blocker
        for lv in sorted(set(level.tolist()), key=HOLDS_FIRST.index):
            at = np.flatnonzero(level == lv)
            sure = held[c[at]]
            blocked[at[sure]] = True  # their blockers stay those of their held tabs
            at = at[~sure]
            found, wide = faces.clear(
                take_rows(q, at), area[at], blocker_of[c[at] // n_cand, c[at] % 2]
            )
            hit = at[found >= 0]
            blocked[hit] = True
            blocker_of[c[hit] // n_cand, c[hit] % 2] = found[found >= 0]
            holder = c[at[wide]] - c[at[wide]] % n_cand + np.asarray(COVER)[c[at[wide]] % n_cand]
            held[holder[holder != c[at[wide]]]] = True
        c = c[~blocked]
        good.flat[c] = True
        state.tested(tried, good.flat[tried])
        for lo_c in range(0, len(c), PAIR_CHUNK):  # in blocks: the pairs of large tabs
            # (half an edge high) took 800 MB at once on a 9,352-vertex design
            pairs(c, c[lo_c : lo_c + PAIR_CHUNK])
        undecided = state.run(undecided, good, tested=ks[-1] + 1)
        if not len(undecided):
            break
    picked = state.picked()
    out, hinges, _, _ = _candidates(ends, normal, tab_height, picked)
    ccw = np.sum(cross(out - out[:, :1], np.roll(out - out[:, :1], -1, axis=1)), axis=1) > 0
    out[~ccw] = out[~ccw, ::-1]  # far above round-off: shapely's orientation, had it been asked
    local = picked % n_cand
    return picked // n_cand, local // 2, local % 2, out, hinges


class _Greedy:
    """The greedy choice of :func:`_choose`, run as far as the candidates tested allow.

    Parameters
    ----------
    n : int
        Borders.
    n_cand : int
        Candidates per border.
    """

    def __init__(self, n, n_cand):
        self.n_cand = n_cand
        self.meet: dict[int, list] = {}  # candidate -> intersecting candidates, earlier borders
        self.near: dict[int, list] = {}  # candidate -> earlier candidates it might meet
        # bytes: read one at a time by the loop of `run`, written as arrays through views
        self.possible = bytearray(b"\x01") * (n * n_cand)  # not tested yet, or good
        self.waits = bytearray(n)
        self.placed = bytearray(n * n_cand)
        self.linked = np.zeros(n * n_cand, dtype=bool)  # candidates with a `meet` or `near`
        self.choice = np.full(n, -2, dtype=np.int64)  # -2 undecided, -1 no tab, else it
        self.undecided = np.ones(n, dtype=bool)

    def meets(self, later: np.ndarray, earlier: np.ndarray) -> None:
        """Record that candidates ``later`` (shrunk) intersect ``earlier``."""
        self.linked[later] = True
        for a, b in zip(later.tolist(), earlier.tolist(), strict=True):
            self.meet.setdefault(a, []).append(b)

    def might_meet(self, cand: np.ndarray, other: np.ndarray) -> None:
        """Record that candidates may intersect candidates of earlier borders not tested."""
        self.linked[cand] = True
        for a, b in zip(cand.tolist(), other.tolist(), strict=True):
            self.near.setdefault(a, []).append(b)

    def tested(self, cand: np.ndarray, good: np.ndarray) -> None:
        """Record that candidates were tested (``good``: those that may be placed)."""
        np.frombuffer(self.possible, dtype=np.uint8)[cand[~good]] = 0

    def run(self, undecided: np.ndarray, good: np.ndarray, tested: int) -> np.ndarray:
        """Decide the borders ``undecided`` (in order) that the first ``tested`` candidates of
        each decide; the others, still undecided."""
        nc, placed, choice = self.n_cand, self.placed, self.choice
        meet, near, possible, waits = self.meet, self.near, self.possible, self.waits
        placed_, waits_ = np.frombuffer(placed, np.uint8), np.frombuffer(waits, np.uint8)
        # first the borders whose first good candidate meets nothing: decided whatever the
        # others do; and those with no good candidate yet: waiting (or without a tab)
        rows = good[undecided, :tested]
        any_good = rows.any(axis=1)
        first = undecided * nc + rows.argmax(axis=1)
        easy = any_good & ~self.linked[first]
        placed_[first[easy]] = 1
        choice[undecided[easy]] = first[easy]
        waits_[undecided[easy]] = 0
        idle = undecided[~any_good]
        waits_[idle] = tested < nc
        if tested == nc:
            choice[idle] = -1
        still = [] if tested == nc else idle.tolist()
        hard = undecided[any_good & ~easy]
        for r, row in zip(hard.tolist(), good[hard, :tested].tolist(), strict=True):
            base, wait = r * nc, True
            for j, ok in enumerate(row):
                if not ok:
                    continue
                c = base + j
                met = meet.get(c, ())
                if any(placed[x] for x in met):
                    continue
                if any(waits[x // nc] and possible[x] for x in (*met, *near.get(c, ()))):
                    break  # an earlier border, undecided, may take this place
                placed[c], choice[r], wait = 1, c, False
                break
            else:
                if tested == nc:
                    choice[r], wait = -1, False
            waits[r] = wait
            if wait:
                still.append(r)
        still = np.sort(np.asarray(still, dtype=np.int64))
        self.undecided[:] = False
        self.undecided[still] = True
        return still

    def picked(self) -> np.ndarray:
        """The placed candidates, in the order of their borders."""
        return self.choice[self.choice >= 0]


class Seams(Rows):
    """The numbered cut borders of a design, as arrays: seam ``k`` (label ``k + 1``) joins
    pieces ``pieces[k]`` and carries its tab on side ``tab_on[k]`` (0, 1; -1: no tab). Read
    one by one, each is ``{"label", "pieces": [name, name], "tab_on": name or None}``.

    Parameters
    ----------
    names : list of str
        Piece names.
    pieces : (n, 2) int
    tab_on : (n,) int
    """

    __slots__ = ("names", "pieces", "tab_on")
    _what = "seam"

    def __init__(self, names, pieces, tab_on):
        self.names = list(names)
        self.pieces = np.asarray(pieces, dtype=np.int64).reshape(-1, 2)
        self.tab_on = np.asarray(tab_on, dtype=np.int64).reshape(-1)

    def __len__(self) -> int:
        return len(self.tab_on)

    def _row(self, k: int):
        pa, pb = (self.names[i] for i in self.pieces[k].tolist())
        on = int(self.tab_on[k])
        return {"label": k + 1, "pieces": [pa, pb], "tab_on": None if on < 0 else (pa, pb)[on]}

    def __iter__(self):
        return map(self._row, range(len(self)))

    def __eq__(self, other) -> bool:
        """Equal to a sequence of the same seams (as dicts)."""
        if not isinstance(other, Sequence) or isinstance(other, str):
            return NotImplemented
        return len(self) == len(other) and all(a == b for a, b in zip(self, other, strict=True))

    __hash__ = None


def assembly_text(seams) -> str:
    """The assembly sheet: which piece each numbered cut border joins, and where the tab is.

    Parameters
    ----------
    seams : Seams, or sequence of ``{"label", "pieces", "tab_on"}``
    """
    lines = [
        "# filletfold assembly: glue each numbered border to the border with the same number",
        "label\tpieces\ttab on",
    ]
    for s in seams:
        lines.append(f"{s['label']}\t{s['pieces'][0]} - {s['pieces'][1]}\t{s['tab_on'] or '-'}")
    return "\n".join(lines) + "\n"
