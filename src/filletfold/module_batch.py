"""The vertex modules of many vertices at once (the surface stage).

:func:`build_modules` returns, for every vertex, what :func:`~filletfold.module.build_module`
returns. Its common case -- a closed ring with a cone whose development is one piece free of
overlap -- is computed on flat arrays over all those vertices: arc samples, base and crease
points, their 2D images, the face shares' centres and the cut's end copies, every face with its
area, then the merge and overlap checks of all the pieces together. The points and faces come
in the order :func:`~filletfold.module.build_module` adds them, with the same arithmetic row by
row, so the pieces are the same bit for bit.

A vertex takes the per-vertex :func:`~filletfold.module.build_module` instead when

* its ring is open, it has no cone, a side is not rounded, a face occurs twice in its ring or
  a corner is reflex;
* :meth:`~filletfold.module.Piece.merge_coincident` could change its piece: two points
  coincide in 2D and 3D within the merge distance (with a margin), a point is not finite, a
  face has twice-area ``<= 2 eps**2`` or a point is in no face;
* :func:`~filletfold.module.faces_interior_disjoint_many` does not prove its piece free of
  overlap (the piece may then be split into runs).
"""

from __future__ import annotations

import itertools

import numpy as np

from .module import (
    Piece,
    _arc_parameters,
    apply_rows,
    build_module,
    faces_interior_disjoint_many,
    polygon_area2,
)
from .vertex.apex import _stack
from .vertex.frame import VertexFrame, _dot, _gluing_maps

#: Most vertices built together (bounds the flat arrays' size).
CHUNK = 2048

#: Corners of the largest face of the common case (a face share: crease, base, centre, base,
#: crease).
_WIDTH = 5


def build_modules(
    mesh, frames, centres, n_samples, apices, developed, progress=None
) -> list[list[Piece]]:
    """The modules of many vertices: ``build_module(mesh, frame, centres, n_samples, apex, v)``
    for every ``(frame, apex, v)``.

    Parameters
    ----------
    mesh : PolyMesh
    frames : sequence of VertexFrame
        Any vertices, in any order.
    centres : (n_faces, 3) float
        Face piece centres (:func:`~filletfold.module.face_piece_centres`).
    n_samples : int or (n_edges,) int
        Points per arc, for all arcs or per edge.
    apices : sequence of ((3,) float or None)
        Spatial apex of each frame's vertex (None: a hole border).
    developed : sequence of ((2,) float or None)
        Its developed apex.
    progress : callable, optional
        ``progress("surface", done, total)`` after every :data:`CHUNK` of vertices.

    Returns
    -------
    list of list of Piece
        One module per frame, in the order of ``frames``.
    """
    if not len(frames) == len(apices) == len(developed):
        raise ValueError(
            f"{len(frames)} frames, {len(apices)} apices and {len(developed)} developed apices"
        )
    modules: list = [None] * len(frames)
    common = [
        j
        for j, (frame, apex, v) in enumerate(zip(frames, apices, developed, strict=True))
        if _common_case(frame, apex, v)
    ]
    if np.size(n_samples) == 0 or np.min(n_samples) < 1:
        common = []  # no arc samples: let build_module handle (or refuse) it
    for c in range(0, len(common), CHUNK):
        which = common[c : c + CHUNK]
        pieces = _cone_pieces(
            [frames[j] for j in which],
            centres,
            n_samples,
            np.array([apices[j] for j in which], dtype=float).reshape(-1, 3),
            np.array([developed[j] for j in which], dtype=float).reshape(-1, 2),
        )
        for j, piece in zip(which, pieces, strict=True):
            if piece is not None:
                modules[j] = [piece]
        if progress is not None:
            progress("surface", c + len(which), len(frames))
    for j, module in enumerate(modules):
        if module is None:
            modules[j] = build_module(mesh, frames[j], centres, n_samples, apices[j], developed[j])
    if progress is not None:
        progress("surface", len(frames), len(frames))
    return modules


def _common_case(frame: VertexFrame, apex, v) -> bool:
    """Whether the vertex may take the batched path: a closed ring of rounded sides with a cone,
    every ring face once, no reflex corner (kept out although with a cone its faces are built
    alike)."""
    if apex is None or v is None or not frame.ring.closed:
        return False
    faces = frame.ring.faces
    n = len(faces)
    return (
        n > 0
        and len(frame.sides) == n
        and all(m is not None for m in frame.cyl_map)
        and len(set(np.asarray(faces).tolist())) == n
        and not (np.asarray(frame.corner_angle) > np.pi).any()
    )


def _cone_pieces(frames: list, centres, n_samples, apex: np.ndarray, dev: np.ndarray) -> list:
    """The one piece of each closed ring with a cone, or None where the vertex must go through
    :func:`~filletfold.module.build_module`.

    Point order of a piece (that of ``build_module``): the apex; side 0's base curve and crease;
    then, for each face share ``i``, the start of side ``i + 1`` (base, crease point) and the
    centre of face ``f_i``, followed by the rest of side ``i + 1``'s base curve and crease; the
    last share ends on side 0's start as reached across the cut (base, crease) and the centre of
    ``f_{n-1}``. Faces, side after side: quad and cone triangle of every arc step, the face
    share, its cone triangle.
    """
    n_vert = len(frames)
    sa = _stack([frame.arrays for frame in frames])
    ne = np.array([len(frame.sides) for frame in frames], dtype=np.int64)
    so = np.cumsum(ne) - ne  # first side of each vertex
    sv = np.repeat(np.arange(n_vert), ne)  # vertex of each side (and ring face)
    sp = np.arange(len(sv)) - so[sv]  # ring position
    cyl = np.array(list(itertools.chain.from_iterable(f.cyl_map for f in frames)))
    face_map = np.array(list(itertools.chain.from_iterable(f.face_map for f in frames)))
    face_frame = np.array(list(itertools.chain.from_iterable(f.face_frames for f in frames)))
    ring_face = np.concatenate([np.asarray(f.ring.faces, dtype=np.int64) for f in frames])

    # ---- arc samples, base curves and creases (module._side_curves)
    n = np.full(len(sv), n_samples) if np.ndim(n_samples) == 0 else np.asarray(n_samples)[sa.edge]
    n = np.where(sa.arc > 0, n, 1).astype(np.int64)
    side, k, s = _arc_parameters(sa.arc, n)
    first = np.cumsum(n) - n
    last = first + n - 1
    C = sa.base(side, s)
    # eq. (1), crease_length with each side's own apex
    vi = np.einsum("kij,kj->ki", sa.Q, dev[sv]) + sa.t
    dn = vi[:, 1] - np.einsum("ij,ij->i", apex[sv] - sa.M, sa.R)
    VC = apex[sv[side]] - C
    num = (vi[side, 0] - s) ** 2 + vi[side, 1] ** 2 - np.einsum("ij,ij->i", VC, VC)
    z = 0.5 * num / dn[side]
    F = C + z[:, None] * sa.R[side]
    # ---- their 2D images (module._strips)
    maps = cyl[side]
    b2 = apply_rows(maps, np.stack([s, np.zeros(len(s))], axis=1))
    t2 = apply_rows(maps, np.stack([s, z], axis=1))
    # the cut's end copies of side 0's start, in the chart after face f_{n-1}
    p0 = so
    lastf = so + ne - 1
    s0 = np.zeros(len(p0))  # VertexFrame.gluing_start of side 0, into the chart of f_{n-1}
    start = _gluing_maps(sa.tangent(p0, s0), sa.R[p0], face_frame[lastf], sa.base(p0, s0), s0)
    m = face_map[lastf] @ start
    g0 = first[p0]
    end_b2 = apply_rows(m, np.stack([s[g0], np.zeros(n_vert)], axis=1))
    end_t2 = apply_rows(m, np.stack([s[g0], z[g0]], axis=1))
    # face share centres
    c3 = centres[ring_face]
    rel = c3 - face_frame[:, 0]
    c2 = apply_rows(
        face_map, np.stack([_dot(rel, face_frame[:, 1]), _dot(rel, face_frame[:, 2])], axis=1)
    )

    # ---- point numbering within each piece
    head = sp == 0
    block = 2 * n + ~head  # side 0: its curves; others: start, centre before, rest of curves
    off = np.cumsum(block) - block
    off = 1 + off - off[so][sv]
    n_points = 1 + np.add.reduceat(block, so) + 3
    tail = n_points - 3  # end copies (base, crease) and the last centre
    pbase = np.cumsum(n_points) - n_points
    o, ns, hs = off[side], n[side], head[side]
    base_l = np.where(hs, o + k, np.where(k == 0, o, o + 2 + k))
    top_l = np.where(hs, o + ns + k, np.where(k == 0, o + 1, o + ns + 1 + k))
    wrap = sp == ne[sv] - 1  # the last face share ends across the cut
    nxt = np.where(wrap, 0, np.arange(len(sv)) + 1)
    centre_l = np.where(wrap, tail[sv] + 2, off[nxt] + 2)
    b1_l = np.where(wrap, tail[sv], base_l[first[nxt]])
    t1_l = np.where(wrap, tail[sv] + 1, top_l[first[nxt]])
    b1_2 = np.where(wrap[:, None], end_b2[sv], b2[first[nxt]])
    t1_2 = np.where(wrap[:, None], end_t2[sv], t2[first[nxt]])

    P2 = np.empty((int(n_points.sum()), 2))
    P3 = np.empty((len(P2), 3))
    P2[pbase], P3[pbase] = dev, apex
    at = pbase[sv[side]]
    P2[at + base_l], P3[at + base_l] = b2, C
    P2[at + top_l], P3[at + top_l] = t2, F
    P2[pbase[sv] + centre_l], P3[pbase[sv] + centre_l] = c2, c3
    P2[pbase + tail], P3[pbase + tail] = end_b2, C[g0]
    P2[pbase + tail + 1], P3[pbase + tail + 1] = end_t2, F[g0]

    # ---- faces, in order: per side its quads and cone triangles, the share, its triangle
    n_faces = 2 * n
    fpos = np.cumsum(n_faces) - n_faces
    corners = np.zeros((int(n_faces.sum()), _WIDTH), dtype=np.int64)
    size = np.empty(len(corners), dtype=np.int64)
    area = np.empty(len(corners))
    code = np.empty(len(corners), dtype=np.int64)  # patch: cylinder (side), cone, face
    n_sides = len(sv)
    q = np.flatnonzero(k < ns - 1)  # arc steps: sample q to q + 1
    quad = fpos[side[q]] + 2 * k[q]
    corners[quad, :4] = np.stack([base_l[q], base_l[q + 1], top_l[q + 1], top_l[q]], axis=1)
    size[quad] = 4
    area[quad] = polygon_area2(np.stack([b2[q], b2[q + 1], t2[q + 1], t2[q]], axis=1))
    code[quad] = side[q]
    tri = quad + 1
    corners[tri, 1:3] = np.stack([top_l[q], top_l[q + 1]], axis=1)
    size[tri] = 3
    area[tri] = polygon_area2(np.stack([dev[sv[side[q]]], t2[q], t2[q + 1]], axis=1))
    code[tri] = n_sides + sv[side[q]]
    share = fpos + n_faces - 2
    t0_l, b0_l = top_l[last], base_l[last]
    corners[share] = np.stack([t0_l, b0_l, centre_l, b1_l, t1_l], axis=1)
    size[share] = 5
    area[share] = polygon_area2(np.stack([t2[last], b2[last], c2, b1_2, t1_2], axis=1))
    code[share] = n_sides + n_vert + np.arange(n_sides)
    cone = share + 1
    corners[cone, 1:3] = np.stack([t0_l, t1_l], axis=1)
    size[cone] = 3
    area[cone] = polygon_area2(np.stack([dev[sv], t2[last], t1_2], axis=1))
    code[cone] = n_sides + sv
    # Piece.face: zero area dropped, clockwise reversed
    keep = area != 0
    face_vertex = np.repeat(sv, n_faces)
    for w in (3, 4, 5):
        rows = np.flatnonzero((area < 0) & (size == w))
        corners[rows, :w] = corners[rows, w - 1 :: -1]
        area[rows] = polygon_area2(P2[pbase[face_vertex[rows]][:, None] + corners[rows, :w]])
    face_vertex, corners, size, code = face_vertex[keep], corners[keep], size[keep], code[keep]

    # ---- the checks of build_module, all pieces at once: merge_coincident changes nothing
    # (nothing merges, no face is too small or clockwise, every point is used), and the proof
    # that the piece does not overlap itself
    point_piece = np.repeat(np.arange(n_vert), n_points)
    eps = 1e-9 * np.minimum.reduceat(sa.length, so)
    good = _nothing_merges(P2, P3, point_piece, eps)
    good[face_vertex[~(area[keep] > 2 * (eps * eps)[face_vertex])]] = False
    used = np.arange(_WIDTH) < size[:, None]
    flat = (corners + pbase[face_vertex][:, None])[used]
    unused = np.ones(len(P2), dtype=bool)
    unused[flat] = False
    good[point_piece[unused]] = False
    good &= faces_interior_disjoint_many(P2, flat, size, face_vertex, n_vert)

    # ---- the pieces
    take = good[face_vertex]
    face_vertex, corners, size, code = face_vertex[take], corners[take], size[take], code[take]
    names = [f"cylinder {e}" for e in sa.edge.tolist()]
    names += [f"cone {f.vertex}" for f in frames]
    names += [f"face {f}" for f in ring_face.tolist()]
    patches = list(map(names.__getitem__, code.tolist()))
    faces = _index_lists(corners, size)
    fb = np.concatenate([[0], np.cumsum(np.bincount(face_vertex, minlength=n_vert))]).tolist()
    pb = np.append(pbase, len(P2)).tolist()
    out = []
    for j, frame in enumerate(frames):
        if not good[j]:
            out.append(None)
            continue
        a, b, fa, fz = pb[j], pb[j + 1], fb[j], fb[j + 1]
        out.append(
            Piece(
                vertex=frame.vertex,
                points_2d=P2[a:b].copy(),
                points_3d=P3[a:b].copy(),
                faces=faces[fa:fz],
                patches=patches[fa:fz],
                apex_index=0,
            )
        )
    return out


def _index_lists(corners: np.ndarray, size: np.ndarray) -> list:
    """Rows of ``corners`` (k, w) cut to their ``size`` (k,) as lists of int, in order."""
    order, rows = [], []
    for w in np.unique(size).tolist():
        idx = np.flatnonzero(size == w)
        order.append(idx)
        rows += corners[idx, :w].tolist()
    if not rows:
        return []
    inverse = np.argsort(np.concatenate(order), kind="stable")
    return list(map(rows.__getitem__, inverse.tolist()))


def _nothing_merges(
    p2: np.ndarray, p3: np.ndarray, piece: np.ndarray, eps: np.ndarray, longest: int = 64
) -> np.ndarray:
    """(n_pieces,) bool: no two points of a piece coincide within ``eps`` (per piece) in both
    2D and 3D, with a small margin, and all are finite: then
    :meth:`~filletfold.module.Piece.merge_coincident` merges nothing.

    Candidates are the points of a piece whose ``x`` lie in one chain of gaps ``<= eps`` (a
    piece with a chain longer than ``longest`` points is refused).

    Parameters
    ----------
    p2 : (k, 2) float
    p3 : (k, 3) float
        The points, piece after piece.
    piece : (k,) int
        Piece of each point (non-decreasing).
    eps : (n_pieces,) float
    """
    bad = np.zeros(len(eps), dtype=bool)
    bad[piece[~(np.isfinite(p2).all(axis=1) & np.isfinite(p3).all(axis=1))]] = True
    reach = eps * (1 + 1e-6)
    order = np.lexsort((p2[:, 0], piece))
    x, pc = p2[order, 0], piece[order]
    link = (np.diff(x) <= reach[pc[1:]]) & (pc[1:] == pc[:-1])
    chain = np.concatenate([[0], np.cumsum(~link)])  # chain of each sorted point
    for d in range(1, len(x)):
        same = np.flatnonzero(chain[d:] == chain[:-d])
        if not len(same):
            break
        i, j = order[same], order[same + d]
        if d >= longest:
            bad[piece[i]] = True
            break
        r = reach[piece[i]]
        near = (np.hypot(*(p2[i] - p2[j]).T) <= r) & (np.linalg.norm(p3[i] - p3[j], axis=1) < r)
        bad[piece[i[near]]] = True
    return ~bad
