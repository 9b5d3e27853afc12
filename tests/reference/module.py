"""The per-vertex module builder, kept as an oracle for :mod:`filletfold.surface.module`.

It builds one vertex's module point by point with keyed points (:meth:`Piece.point`), as the
library did before every module was built on arrays; the tests compare the two.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from filletfold.mesh.polymesh import PolyMesh
from filletfold.surface.faces import polygon_area2
from filletfold.surface.module import (
    _arc_parameters,
    apply_rows,
    hole_corners,
    hole_heights,
    merge_distance,
)
from filletfold.surface.overlap import faces_interior_disjoint, run_overlaps
from filletfold.surface.patch import Patch
from filletfold.surface.piece import Piece
from filletfold.vertex.apex import crease_length
from filletfold.vertex.frame import VertexFrame, apply, stack_sides, to_chart


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
        (:meth:`~filletfold.rounding.edges.EdgeRounding.arc_points`).
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
    cone = Patch("cone", int(u))
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
            _add_strip(piece, bs, tp, strip, Patch("cylinder", int(side.edge)), cone)
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
        piece.face(corner, Patch("face", int(face)))
        if apex is not None:
            piece.face([piece.apex_index, t0, t1], cone)
        sector += [i - j0] * (len(piece.faces) - n_before)
    p2, kept = piece._merge_coincident(merge_distance(frame))
    sector = np.array(sector, dtype=np.int64)
    return piece, p2, sector if kept is None else sector[kept]
