"""Convex polygons on arrays: their sides as half-planes, shrunk, apart or overlapping (by
separating axes and by the overlap's area), and boxes filed on a grid to find which overlap.

Every function takes a batch: polygons (n, k, 2), the i-th of one argument with the i-th of
the other. Used by :mod:`filletfold.layout.tabs` to test candidate glue tabs against faces and
against each other, with margins that leave the doubtful pairs to shapely.
"""

from __future__ import annotations

import numpy as np

from ..arrays import run_owners, run_starts

#: Turns (sines of corner angles) this close to 0 count as straight in :func:`is_convex`.
TURN_ROUNDOFF = 1e-12
#: Turns beyond this are convex far above round-off (:func:`surely_valid`); nearer ones are
#: left to shapely.
SURE_TURN = 1e-6


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z of the cross products of 2D vectors (..., 2)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def side_normals(poly: np.ndarray) -> np.ndarray:
    """Unit normals (n, k, 2) of the sides of polygons (n, k, 2), to the left of each side
    (NaN for a side of no length)."""
    edge = next_corners(poly) - poly
    u = np.empty_like(edge)
    u[..., 0], u[..., 1] = -edge[..., 1], edge[..., 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        u /= np.sqrt(edge[..., 0] ** 2 + edge[..., 1] ** 2)[..., None]
    return u


def next_corners(poly: np.ndarray) -> np.ndarray:
    """``np.roll(poly, -1, axis=1)``, faster: the corner after each corner of polygons."""
    out = np.empty_like(poly)
    out[:, :-1], out[:, -1] = poly[:, 1:], poly[:, 0]
    return out


def inward_lines(quads: np.ndarray):
    """The sides of convex polygons as half-planes.

    Parameters
    ----------
    quads : (n, k, 2) float
        Convex polygons, either orientation.

    Returns
    -------
    normal : (n, k, 2) float
        Unit inward normals of the sides.
    offset : (n, k) float
        A point ``x`` is inside side ``j`` of polygon ``i`` where
        ``normal[i, j] @ x >= offset[i, j]``.
    """
    area2 = cross(quads, next_corners(quads)).sum(axis=1)
    normal = side_normals(quads)
    normal[~(area2 >= 0)] *= -1
    return normal, normal[..., 0] * quads[..., 0] + normal[..., 1] * quads[..., 1]


def shrink_convex(quads: np.ndarray, by, normal: np.ndarray | None = None) -> np.ndarray:
    """Convex polygons (n, k, 2) with every side moved inwards by ``by`` (corners mitred);
    ``normal``: their unit inward normals, if known (:func:`inward_lines`)."""
    if normal is None:
        normal, _ = inward_lines(quads)
    prev = np.roll(normal, 1, axis=1)  # the side before each corner
    dot = prev[..., 0] * normal[..., 0] + prev[..., 1] * normal[..., 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        mitre = (prev + normal) / (1 + dot)[..., None]
    return quads + np.asarray(by, dtype=np.float64).reshape(-1, 1, 1) * mitre


def _project(axes: np.ndarray, poly: np.ndarray):
    """Smallest and largest projections (n, a) of polygons (n, k, 2) on axes (n, a, 2)."""
    t = [
        axes[..., 0] * poly[:, i, None, 0] + axes[..., 1] * poly[:, i, None, 1]
        for i in range(poly.shape[1])
    ]
    return np.minimum.reduce(t), np.maximum.reduce(t)


def sat_gap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Signed gap between convex polygons, by separating axes.

    Parameters
    ----------
    a, b : (n, ka, 2), (n, kb, 2) float
        Convex polygons, either orientation (repeated corners allowed).

    Returns
    -------
    (n,) float
        The widest gap between the projections of ``a[i]`` and ``b[i]`` on the unit normals of
        their sides: > 0, the polygons are that far apart; < 0, they overlap by at least that
        much along every side normal, so they intersect. Sides of no length are skipped.
    """
    axes = np.concatenate([side_normals(a), side_normals(b)], axis=1)
    lo_a, hi_a = _project(axes, a)
    lo_b, hi_b = _project(axes, b)
    gap = np.maximum(lo_b - hi_a, lo_a - hi_b)
    return fold(np.maximum, np.where(np.isnan(gap), -np.inf, gap))


def convex_overlap(a: np.ndarray, b: np.ndarray):
    """Area of the overlap of convex polygons, by Green's theorem on their clipped sides.

    Parameters
    ----------
    a, b : (n, ka, 2), (n, kb, 2) float
        Convex polygons, either orientation (repeated corners allowed).

    Returns
    -------
    area : (n,) float
        Area of ``a[i]`` and ``b[i]`` overlapping.
    empty : (n,) bool
        Whether no side of either has a piece inside the other (they are apart).
    doubt : (n,) bool
        Where a corner lies exactly on the line of a side of the other: sides may overlap
        there, and count twice; ask :func:`clip_area`.
    """
    sign_a, sign_b = np.sign(_signed_area2(a)), np.sign(_signed_area2(b))
    s1, in1, doubt1 = _sides_inside(a, b, sign_b)
    s2, in2, doubt2 = _sides_inside(b, a, sign_a)
    return np.abs(sign_a * s1 + sign_b * s2) / 2, ~in1 & ~in2, doubt1 | doubt2


def _signed_area2(poly: np.ndarray) -> np.ndarray:
    """Twice the signed areas (n,) of polygons (n, k, 2), about their first corners."""
    local = poly - poly[:, :1]
    return cross(local, next_corners(local)).sum(axis=1)


def _sides_inside(p: np.ndarray, q: np.ndarray, sign_q: np.ndarray):
    """The sides of polygons ``p`` clipped to the convex polygons ``q`` (their orientations
    ``sign_q``): the sums (n,) of ``cross(start, end)`` of the pieces inside, whether any
    piece is, and whether a corner of ``p`` lies on the line of a side of ``q``."""
    a = p
    b = next_corners(p)
    px, py = np.ascontiguousarray(p[..., 0]), np.ascontiguousarray(p[..., 1])
    lo = np.zeros(a.shape[:2])
    hi = np.ones(a.shape[:2])
    out = np.zeros(a.shape[:2], dtype=bool)
    doubt = np.zeros(a.shape[:2], dtype=bool)
    q_next = next_corners(q)
    for j in range(q.shape[1]):
        ex, ey = q_next[:, j, 0] - q[:, j, 0], q_next[:, j, 1] - q[:, j, 1]
        nx, ny = (-ey * sign_q)[:, None], (ex * sign_q)[:, None]  # inward
        da = nx * (px - q[:, j, 0, None]) + ny * (py - q[:, j, 1, None])  # at each corner
        db = next_corners(da)  # at the end of each side
        doubt |= ((ex != 0) | (ey != 0))[:, None] & (da == 0)
        below_a, below_b = da < 0, db < 0
        out |= below_a & below_b
        with np.errstate(invalid="ignore", divide="ignore"):
            t = da / (da - db)
        np.maximum(lo, t, out=lo, where=below_a & (db >= 0))  # entering
        np.minimum(hi, t, out=hi, where=below_b & (da >= 0))  # leaving
    keep = ~out & (lo < hi)
    d = b - a
    start, end = a + lo[..., None] * d, a + hi[..., None] * d
    return np.where(keep, cross(start, end), 0.0).sum(axis=1), keep.any(axis=1), doubt.any(1)


def clip_area(poly: np.ndarray, normal: np.ndarray, offset: np.ndarray):
    """Area of polygons clipped by half-planes (Sutherland-Hodgman), in batches.

    Parameters
    ----------
    poly : (n, k, 2) float
        Simple polygons (either orientation, convex or not), padded by repeating a corner.
    normal, offset : (n, h, 2), (n, h) float
        The half-planes ``normal[i, j] @ x >= offset[i, j]`` clipping ``poly[i]`` (together a
        convex region).

    Returns
    -------
    area : (n,) float
        Area of each clipped polygon (0 where empty).
    empty : (n,) bool
        Whether no corner is left at all.
    """
    n = len(poly)
    rows = np.arange(n)[:, None]
    cnt = np.full(n, poly.shape[1])
    for j in range(normal.shape[1]):
        k = poly.shape[1]
        if k == 0:
            break
        dist = (
            poly[..., 0] * normal[:, j, None, 0]
            + poly[..., 1] * normal[:, j, None, 1]
            - offset[:, j, None]
        )
        slot = np.arange(k)
        live = slot < cnt[:, None]
        prev_i = np.where(slot == 0, cnt[:, None] - 1, slot - 1) * live
        prev, dprev = poly[rows, prev_i], dist[rows, prev_i]
        inside, inside_prev = dist >= 0, dprev >= 0
        with np.errstate(invalid="ignore", divide="ignore"):
            t = dprev / (dprev - dist)  # where used, the two ends are on either side
            meet = prev + t[..., None] * (poly - prev)
        out = np.stack([meet, poly], axis=2).reshape(n, 2 * k, 2)
        keep = np.stack([live & (inside != inside_prev), live & inside], axis=2).reshape(n, -1)
        cnt = keep.sum(axis=1)
        dest = np.cumsum(keep, axis=1) - 1
        new = np.zeros((n, int(cnt.max(initial=0)), 2))
        r, c = np.nonzero(keep)
        new[r, dest[r, c]] = out[r, c]
        poly = new
    k = poly.shape[1]
    slot = np.arange(k)
    live = slot < cnt[:, None]
    nxt = poly[rows, np.where(slot + 1 >= cnt[:, None], 0, slot + 1)]
    area = np.abs(np.sum(np.where(live, cross(poly, nxt), 0.0), axis=1)) / 2
    return area, cnt == 0


def fold(op, a: np.ndarray, axis: int = 1) -> np.ndarray:
    """``op.reduce(a, axis)`` over a short axis, a slice at a time (numpy is slow at reducing
    many short rows; ``op`` is ``np.maximum``, ``np.minimum``, ``np.logical_and``, ...)."""
    parts = np.moveaxis(a, axis, 0)
    out = parts[0].copy()
    for x in parts[1:]:
        op(out, x, out=out)
    return out


def row_max(a: np.ndarray) -> np.ndarray:
    """Row maxima of a narrow (n, k) array."""
    return fold(np.maximum, a)


def abs_max(a: np.ndarray) -> np.ndarray:
    """(n,) float: the largest absolute value of every ``a[i]`` (n, k, 2)."""
    return fold(np.maximum, np.abs(a).reshape(len(a), -1))


def take_rows(a: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``a[index]`` for an int array ``index``, much faster for an ``a`` of several
    dimensions (``np.take`` along the first axis)."""
    return np.take(a, index, axis=0)


def pad_columns(a: np.ndarray, width: int) -> np.ndarray:
    """An (n, k) array widened to (n, width) by repeating its last column."""
    if a.shape[1] == width:
        return a
    return np.concatenate([a, np.repeat(a[:, -1:], width - a.shape[1], axis=1)], axis=1)


def turns(corners: np.ndarray) -> np.ndarray:
    """(n, k) float: the sines of the turns at the corners of polygons (n, k, 2) (NaN at a
    side of no length)."""
    edge = next_corners(corners) - corners
    length = np.sqrt(edge[..., 0] ** 2 + edge[..., 1] ** 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        return cross(edge, next_corners(edge)) / (length * next_corners(length))


def is_convex(corners: np.ndarray, turn: np.ndarray | None = None) -> np.ndarray:
    """(n,) bool: padded polygons (n, k, 2) that are convex (every turn one way, up to
    :data:`TURN_ROUNDOFF`); ``turn``: their :func:`turns`, if known."""
    turn = turns(corners) if turn is None else turn
    turn = np.where(np.isnan(turn), 0.0, turn)  # repeated corners turn by nothing
    left = fold(np.logical_and, turn >= -TURN_ROUNDOFF)
    return left | fold(np.logical_and, turn <= TURN_ROUNDOFF)


def surely_valid(quads: np.ndarray, turn: np.ndarray | None = None) -> np.ndarray:
    """(n,) bool: polygons that are strictly convex by a margin far above round-off (so
    valid polygons); False means "ask shapely". ``turn``: their :func:`turns`, if known."""
    turn = turns(quads) if turn is None else turn
    with np.errstate(invalid="ignore"):
        return fold(np.logical_and, turn > SURE_TURN) | fold(np.logical_and, turn < -SURE_TURN)


def polygon_area(quads: np.ndarray) -> np.ndarray:
    """Areas (n,) of polygons (n, k, 2), about their first corners."""
    local = quads - quads[:, :1]
    return np.abs(np.sum(cross(local, next_corners(local)), axis=1)) / 2


class BoxGrid:
    """Boxes filed in the cells of a uniform grid, to find the boxes another box overlaps.

    Parameters
    ----------
    lo, hi : (n, 2) float
        Lower and upper corners of the boxes (a box with a corner not finite is left out).
    """

    def __init__(self, lo: np.ndarray, hi: np.ndarray):
        self.box = np.concatenate([lo, hi], axis=1)  # (n, 4): x0, y0, x1, y1
        self.cols = [np.ascontiguousarray(x) for x in self.box.T]
        kept = np.flatnonzero(np.isfinite(self.box).all(axis=1))
        self.origin, self.cell, self.shape = np.zeros(2), 1.0, np.ones(2, dtype=np.int64)
        self.items = np.zeros(0, dtype=np.int64)
        self.first = np.zeros(0, dtype=np.uint8)  # 1: a box's first column, 2: first row
        self.start = np.zeros(2, dtype=np.int64)
        if not len(kept):
            return
        lo, hi = lo[kept], hi[kept]
        self.origin = lo.min(axis=0)
        span = max(float(np.max(hi.max(axis=0) - self.origin)), 1e-300)
        # about a box per cell; larger cells while the boxes would fill too many of them
        cell = max(float(np.median(np.max(hi - lo, axis=1))), span / 4096, 1e-300)
        while True:
            self.cell = cell
            self.shape = np.floor((hi.max(axis=0) - self.origin) / cell).astype(np.int64) + 1
            c0, c1 = self._cells(lo, hi)
            if np.prod(c1 - c0 + 1, axis=1).sum() <= 8 * len(kept) + 1024:
                break
            cell *= 2
        keys, items, first = self._entries(c0, c1, kept)
        order = _argsort_small(keys, int(np.prod(self.shape)))
        self.items, self.first = items[order], first[order]
        # the entries of cell k: items[start[k]:start[k + 1]]
        self.start = np.zeros(int(np.prod(self.shape)) + 1, dtype=np.int64)
        np.cumsum(np.bincount(keys, minlength=len(self.start) - 1), out=self.start[1:])

    def _cells(self, lo, hi):
        """The first and last cells (n, 2) that boxes cover, clipped to the grid."""
        c0 = np.floor((lo - self.origin) / self.cell)
        c1 = np.floor((hi - self.origin) / self.cell)
        top = self.shape - 1
        return np.clip(c0, 0, top).astype(np.int64), np.clip(c1, -1, top).astype(np.int64)

    def _entries(self, c0, c1, items):
        """(cell key, item, whether the cell is in the box's first column (1) and row (2))
        of every cell of every box."""
        w = np.maximum(c1 - c0 + 1, 0)
        count = w[:, 0] * w[:, 1]
        item = run_owners(count)
        k = np.arange(len(item)) - np.repeat(run_starts(count)[:-1], count)
        wy = np.maximum(w[item, 1], 1)
        dx, dy = k // wy, k % wy
        first = (dx == 0).astype(np.uint8) | ((dy == 0).astype(np.uint8) << 1)
        return (c0[item, 0] + dx) * self.shape[1] + c0[item, 1] + dy, items[item], first

    def query(self, lo: np.ndarray, hi: np.ndarray):
        """The pairs of a box (``lo``, ``hi``: (m, 2)) and a filed box that overlap (closed).

        Returns
        -------
        (k,) int, (k,) int
            The boxes asked and the filed ones.
        """
        if not len(lo) or not len(self.items):
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        box = np.concatenate([lo, hi], axis=1)
        finite = np.isfinite(box).all(axis=1)
        c0, c1 = self._cells(np.where(finite[:, None], lo, 0), np.where(finite[:, None], hi, -1))
        c1[~finite] = -1
        keys, asked, low = self._entries(c0, c1, np.arange(len(lo)))
        first = self.start[keys]
        count = self.start[keys + 1] - first
        which = run_owners(count)
        at = np.arange(len(which)) + np.repeat(first - np.cumsum(count) + count, count)
        # each pair once: in the cell of the low corner of the two boxes' overlap, which is
        # in the first column of one of them and in the first row of one of them
        keep = np.flatnonzero((np.take(low, which) | np.take(self.first, at)) == 3)
        a, b = np.take(asked, np.take(which, keep)), np.take(self.items, np.take(at, keep))
        qa, fb = [np.take(x, a) for x in box.T], [np.take(x, b) for x in self.cols]
        keep = (qa[0] <= fb[2]) & (fb[0] <= qa[2]) & (qa[1] <= fb[3]) & (fb[1] <= qa[3])
        return a[keep], b[keep]


def _argsort_small(keys: np.ndarray, bound: int) -> np.ndarray:
    """Stable ``np.argsort`` of integers in ``[0, bound)``: radix passes on 16 bits."""
    if bound <= 1 << 16:
        return np.argsort(keys.astype(np.uint16), kind="stable")
    if bound <= 1 << 32:
        low = np.argsort((keys & 0xFFFF).astype(np.uint16), kind="stable")
        return low[np.argsort((keys[low] >> 16).astype(np.uint16), kind="stable")]
    return np.argsort(keys, kind="stable")


def boxes(quads: np.ndarray):
    """Lower and upper corners (n, 2) of the boxes of polygons (n, k, 2)."""
    with np.errstate(invalid="ignore"):
        return fold(np.minimum, quads), fold(np.maximum, quads)
