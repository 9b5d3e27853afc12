"""Whether the faces of a piece overlap in 2D: the proof on arrays, and the measure."""

from __future__ import annotations

import numpy as np
import shapely

from ..arrays import run_owners
from ..tolerances import tol
from .faces import face_polygons, flat_faces


def faces_overlap(points_2d: np.ndarray, faces, rel: float = tol.relative) -> bool:
    """:meth:`Piece.overlaps` of the polygons ``faces`` (index lists) over ``points_2d`` (k, 2)."""
    if faces_interior_disjoint(points_2d, faces):
        return False
    return measured_overlap(points_2d, faces, rel)


def measured_overlap(points_2d: np.ndarray, faces, rel: float = tol.relative, pairs=None) -> bool:
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
    rings = shapely.linearrings(ring, indices=run_owners(r_size))
    ok[pieces[~(oriented & shapely.is_valid(shapely.polygons(rings)))]] = False
    return ok | empty
