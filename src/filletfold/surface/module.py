"""Vertex modules (paper sec. 2): the flat piece(s) of every vertex, in 2D and folded in 3D,
built for all vertices at once; one vertex is a batch of one (:func:`build_module`).

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

All modules are built on flat arrays over all vertices (:func:`build_modules`), a round of
*runs* at a time: first one run over each whole ring, then the two halves of every run of more
than one sector that overlaps itself. A round computes for all its runs together the arc
samples, base curves and creases (or hole borders), their 2D images, the face shares' centres
(and the corner T where a hole border goes through it, :func:`hole_corners`), the lines of
unrounded boundary sides and the end copies of the side after each run, every face with its
area, then the overlap proof of all the pieces. Only a run that the proof does not clear has
its union measured on its own (:func:`~filletfold.surface.overlap.run_overlaps`), and only a
piece with points that coincide in 2D and 3D (a crease through T, an unrounded side) has them
merged (:meth:`~filletfold.surface.piece.Piece.merge_coincident`). The per-vertex builder this
replaced is kept as the tests' oracle (``tests/reference/module.py``): the pieces agree with it
point for point and face for face.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..arrays import run_owners, run_starts, split_runs
from ..mesh.polymesh import PolyMesh
from ..parallel import thread_map
from ..rounding.tapered import perpendiculars, ruled_gluing_maps
from ..tolerances import tol
from ..vertex.apex import _stack
from ..vertex.crease import chart_apex, crease_denominator, crease_height, crease_numerator
from ..vertex.frame import SideArrays, VertexFrame, dot_rows, gluing_maps, stack_sides
from .faces import FaceLists, polygon_area2
from .overlap import faces_interior_disjoint, faces_interior_disjoint_many, run_overlaps
from .patch import Patch, patches_of
from .piece import Piece
from .sharp import sharp_modules


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
    side = run_owners(n)
    first = run_starts(n)[:-1]
    k = np.arange(len(side)) - first[side]
    step = np.where(n > 1, arc / np.maximum(n - 1, 1), 0.0)
    s = k * step[side]
    long = n > 1
    s[(first + n - 1)[long]] = arc[long]
    return side, k, s


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
            (s.base([s.arc])[0] + hh * s.R, s.base([0.0])[0] + hh * s.R)
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


#: Most vertices built together (bounds the flat arrays' size).
CHUNK = 2048

#: Corners of the largest face of a module (a face share: crease, base, centre, base, crease,
#: and the corner T where a hole border goes through it).
_WIDTH = 6


@dataclass
class Modules:
    """The module stage's result (:func:`build_modules` of every vertex): ``points``
    (n_edges,) int, the samples on each edge's arc, and ``modules``, each vertex's list of
    pieces (None once released for the layout)."""

    points: np.ndarray
    modules: list | None


def build_modules(
    mesh, frames, centres, n_samples, apices, developed, progress=None
) -> list[list[Piece]]:
    """The modules of many vertices: the flat piece(s) of every ``(frame, apex, v)``.

    Parameters
    ----------
    mesh : PolyMesh
    frames : sequence of VertexFrame
        Any vertices, in any order.
    centres : (n_faces, 3) float
        Face piece centres (:func:`~filletfold.surface.centres.face_piece_centres`).
    n_samples : int or (n_edges,) int
        Points per arc, for all arcs or per edge.
    apices : sequence of ((3,) float or None)
        Spatial apex of each frame's vertex (None: a hole border; a sharp vertex's frame,
        :attr:`~filletfold.vertex.frame.VertexFrame.sharp`, gets the fan of
        :func:`~filletfold.surface.sharp.sharp_modules` instead).
    developed : sequence of ((2,) float or None)
        Its developed apex.
    progress : callable, optional
        ``progress("surface", done, total)`` after every :data:`CHUNK` of vertices (chunks are
        built in threads, :func:`~filletfold.parallel.thread_map`).

    Returns
    -------
    list of list of Piece
        One module per frame, in the order of ``frames``.
    """
    if not len(frames) == len(apices) == len(developed):
        raise ValueError(
            f"{len(frames)} frames, {len(apices)} apices and {len(developed)} developed apices"
        )
    if np.size(n_samples) == 0 or np.min(n_samples) < 1:
        raise ValueError(f"every arc needs at least one sample, got {n_samples!r}")
    for frame, apex, v in zip(frames, apices, developed, strict=True):
        if frame.sharp and apex is not None:
            raise ValueError(f"vertex {frame.vertex}: a sharp vertex has no apex")
        if apex is not None and (v is None or not frame.ring.closed):
            why = "no developed apex" if v is None else "an open ring"
            raise ValueError(
                f"vertex {frame.vertex}: a cone needs a closed ring and both apices ({why})"
            )
    modules: list = [None] * len(frames)
    corners = [j for j, f in enumerate(frames) if f.sharp]  # sharp vertices: their fans
    if corners:
        fans = sharp_modules([frames[j] for j in corners], centres, None, n_samples)
        for j, module in zip(corners, fans, strict=True):
            modules[j] = module
    rest = [j for j, f in enumerate(frames) if not f.sharp]
    chunks = [rest[c : c + CHUNK] for c in range(0, len(rest), CHUNK)]

    def chunk_modules(which: list) -> list:
        chunk = _Chunk.of(
            [frames[j] for j in which],
            centres,
            n_samples,
            [apices[j] for j in which],
            [developed[j] for j in which],
        )
        return _chunk_modules(chunk)

    done = 0
    for which, built in zip(chunks, thread_map(chunk_modules, chunks), strict=True):
        for j, module in zip(which, built, strict=True):
            modules[j] = module
        done += len(which)
        if progress is not None:
            progress("surface", done, len(frames))
    if progress is not None:
        progress("surface", len(frames), len(frames))
    return modules


def build_module(
    mesh: PolyMesh,
    frame: VertexFrame,
    centres: np.ndarray,
    n_samples,
    apex: np.ndarray | None = None,
    dev_apex: np.ndarray | None = None,
) -> list[Piece]:
    """The flat piece(s) of one vertex: :func:`build_modules` of a batch of one.

    Parameters
    ----------
    mesh : PolyMesh
    frame : VertexFrame
    centres : (n_faces, 3) float
        Face piece centres (:func:`~filletfold.surface.centres.face_piece_centres`).
    n_samples : int or (n_edges,) int
        Points per cylinder arc (both ends included), for all arcs or per edge
        (:meth:`~filletfold.rounding.edges.EdgeRounding.arc_points`).
    apex : (3,) float, optional
        Spatial apex; when given the module has a cone, otherwise a hole border.
    dev_apex : (2,) float, optional
        Developed apex (required with ``apex``).

    Returns
    -------
    list of Piece
    """
    return build_modules(mesh, [frame], centres, n_samples, [apex], [dev_apex])[0]


def _ring_arrays(frame: VertexFrame) -> SideArrays:
    """The frame's sides as :class:`~filletfold.vertex.frame.SideArrays`: a closed ring's own;
    an open ring's unrounded ends get ``O = M`` and zero ``N0, B`` (their base curve is the
    point ``M``), as in :func:`~filletfold.vertex.frame.vertex_frames`, and NaN charts."""
    if frame.ring.closed:
        return frame.arrays
    zero = np.zeros(3)
    n = len(frame.sides)
    return stack_sides(
        [s if s.rounded else dataclasses.replace(s, O=s.M, N0=zero, B=zero) for s in frame.sides],
        Q=np.full((n, 2, 2), np.nan),
        t=np.full((n, 2), np.nan),
        face_normal=np.full((len(frame.ring.faces), 3), np.nan),
    )


def _or_nan(values, shape) -> np.ndarray:
    """The arrays ``values`` stacked, a NaN array of ``shape`` for each None."""
    return np.array([np.full(shape, np.nan) if x is None else x for x in values], dtype=float)


@dataclass
class _Chunk:
    """The frames of some vertices on flat arrays: their sides, vertex after vertex, and
    likewise their ring faces.

    Attributes
    ----------
    frames : list of VertexFrame
        (n_vert,) frames.
    sides : SideArrays
        Their (n_sides,) sides.
    side_first, face_first : (n_vert + 1,) int
        First side and first ring face of each vertex, then the totals.
    side_vertex : (n_sides,) int
    rounded : (n_sides,) bool
    samples : (n_sides,) int
        Points per arc (1 on a side without arc).
    cyl : (n_sides, 3, 3) float
        Each cylinder chart's map into the common frame (NaN on an unrounded side).
    lmax_start, lmax_end : (n_sides,) float
        As :class:`~filletfold.vertex.frame.VertexFrame` has them.
    height : (n_sides,) float
        Hole border heights (:func:`~filletfold.surface.module.hole_heights`).
    face_map, face_frame : (n_faces, 3, 3) float
        Each ring face's map into the common frame and its chart.
    centre : (n_faces, 3) float
        The centre of each ring face's face piece.
    cone : (n_vert,) bool
    apex : (n_vert, 3) float
    dev : (n_vert, 2) float
        Spatial and developed apex (NaN without a cone).
    vi : (n_sides, 2) float
        The developed apex in each cylinder's chart.
    dn : (n_sides,) float
        The denominator of eq. (1) on each side.
    eps : (n_vert,) float
        The merge distance of :meth:`~filletfold.surface.piece.Piece.merge_coincident`
        (:func:`~filletfold.surface.module.merge_distance`).
    patch : list of str
        Patch names: the cylinder of each side, the cone of each vertex, each ring face.
    """

    frames: list
    sides: SideArrays
    side_first: np.ndarray
    face_first: np.ndarray
    side_vertex: np.ndarray
    rounded: np.ndarray
    samples: np.ndarray
    cyl: np.ndarray
    lmax_start: np.ndarray
    lmax_end: np.ndarray
    height: np.ndarray
    face_map: np.ndarray
    face_frame: np.ndarray
    centre: np.ndarray
    cone: np.ndarray
    apex: np.ndarray
    dev: np.ndarray
    vi: np.ndarray
    dn: np.ndarray
    eps: np.ndarray
    patch: list
    tee: np.ndarray
    T: np.ndarray

    @classmethod
    def of(cls, frames: list, centres, n_samples, apices: list, developed: list) -> _Chunk:
        """The chunk of ``frames`` with their apices (None: a hole border)."""
        sa = _stack([_ring_arrays(f) for f in frames])
        ne = np.array([f.n_sides for f in frames], dtype=np.int64)
        nf = np.array([len(f.ring.faces) for f in frames], dtype=np.int64)
        side_first = run_starts(ne)
        sv = run_owners(ne)
        cone = np.array([a is not None for a in apices], dtype=bool)
        apex = _or_nan(apices, 3).reshape(-1, 3)
        dev = _or_nan(
            [d if a is not None else None for a, d in zip(apices, developed, strict=True)], 2
        )
        dev = dev.reshape(-1, 2)
        n = np.asarray(n_samples)
        n = np.full(len(sv), n) if n.ndim == 0 else n[sa.edge]
        vi = chart_apex(sa.Q, sa.t, dev[sv])
        ring_face = np.concatenate([np.asarray(f.ring.faces, dtype=np.int64) for f in frames])
        return cls(
            frames=frames,
            sides=sa,
            side_first=side_first,
            face_first=run_starts(nf),
            side_vertex=sv,
            rounded=np.concatenate([f.rounded for f in frames]),
            samples=np.where(sa.arc > 0, n, 1).astype(np.int64),
            cyl=np.concatenate([f.cyl_maps for f in frames]),
            lmax_start=np.concatenate([f.lmax_start for f in frames]),
            lmax_end=np.concatenate([f.lmax_end for f in frames]),
            height=np.concatenate([hole_heights(f) for f in frames]),
            face_map=np.concatenate([np.reshape(f.face_map, (-1, 3, 3)) for f in frames]),
            face_frame=np.concatenate([np.reshape(f.face_frames, (-1, 3, 3)) for f in frames]),
            centre=np.asarray(centres)[ring_face],
            cone=cone,
            apex=apex,
            dev=dev,
            vi=vi,
            dn=crease_denominator(apex[sv], vi, sa.M, sa.R),
            eps=tol.coincide
            * np.maximum(
                np.minimum.reduceat(sa.length, side_first[:-1]),
                np.abs(np.array([f.U for f in frames])).max(axis=1),
            ),
            patch=[
                Patch("fillet" if cone_side else "cylinder", e)
                for e, cone_side in zip(sa.edge.tolist(), sa.conical.tolist(), strict=True)
            ]
            + patches_of("cone", [f.vertex for f in frames])
            + patches_of("face", ring_face.tolist()),
            tee=np.concatenate(
                [
                    hole_corners(f, centres) if a is None else np.zeros(len(f.ring.faces), bool)
                    for f, a in zip(frames, apices, strict=True)
                ]
            ),
            T=np.concatenate([np.reshape(f.T_end, (-1, 3))[: len(f.ring.faces)] for f in frames]),
        )

    def curves(self, side: np.ndarray, s: np.ndarray):
        """Base points ``C`` (m, 3), heights ``z`` (m,) and top points ``F`` (m, 3) at arc
        parameters ``s`` (m,) of ``side`` (m,): the crease (eq. (1)) on a cone's sides, the hole
        border elsewhere. On a conical side ``z`` runs along the fillet's ruling at ``s`` and
        eq. (1) is evaluated in that row's chart (:meth:`SideArrays.row_maps`)."""
        sa = self.sides
        C = sa.base(side, s)
        z = self.height[side]
        R = sa.R[side]
        on = self.cone[self.side_vertex[side]]
        conic = sa.conical[side]
        plain = np.flatnonzero(on & ~conic)
        if len(plain):
            i = side[plain]
            num = crease_numerator(self.apex[self.side_vertex[i]], self.vi[i], s[plain], C[plain])
            z[plain] = crease_height(num, self.dn[i])
        k = np.flatnonzero(conic)
        if len(k):
            Q, t, R[k], M = sa.row_maps(side[k], s[k])
            c = np.flatnonzero(on[k])
            if len(c):
                kc = k[c]
                V = self.apex[self.side_vertex[side[kc]]]
                vi = chart_apex(Q[c], t[c], self.dev[self.side_vertex[side[kc]]])
                num = crease_numerator(V, vi, s[kc], C[kc])
                z[kc] = crease_height(num, crease_denominator(V, vi, M[c], R[kc]))
        return C, z, C + z[:, None] * R

    def in_side_chart(self, side: np.ndarray, s: np.ndarray, z: np.ndarray) -> np.ndarray:
        """(m, 2) common-frame images of the points at arc parameters ``s`` and heights ``z``
        (m,) of sides ``side`` (m,): ``(s, z)`` in a cylinder's chart, ``c(s) + z r(s)`` in a
        fillet's."""
        p = np.stack([s, z], axis=1)
        k = np.flatnonzero(self.sides.conical[side])
        if len(k):
            _, _, c, r = self.sides.chart(side[k], s[k])
            p[k] = c + z[k, None] * r
        return apply_rows(self.cyl[side], p)

    def in_face_chart(self, p: np.ndarray, face: np.ndarray) -> np.ndarray:
        """(m, 2) common-frame images of points ``p`` (m, 3) on ring faces ``face`` (m,)
        (``apply(face_map, to_chart(face_frame, p))`` row by row)."""
        fr = self.face_frame[face]
        rel = p - fr[:, 0]
        return apply_rows(
            self.face_map[face],
            np.stack([dot_rows(rel, fr[:, 1]), dot_rows(rel, fr[:, 2])], axis=1),
        )


def _chunk_modules(chunk: _Chunk) -> list:
    """The module of every vertex of a chunk (list of Piece, in ring order).

    Runs ``(vertex, j0, j1)`` of sectors ``j0 .. j1`` are built a round at a time: a run of
    more than one sector whose piece is not proved free of overlap and measured to overlap
    itself is replaced by its halves ``j0 .. mid`` and ``mid + 1 .. j1`` in the next round.
    """
    n_vert = len(chunk.frames)
    last = np.diff(chunk.face_first) - 1
    runs = np.stack([np.arange(n_vert), np.zeros(n_vert, np.int64), last], axis=1)
    done: list = [[] for _ in range(n_vert)]
    while len(runs):
        pieces, proved, sectors = _run_pieces(chunk, runs)
        halves = []
        for (j, j0, j1), piece, ok, sector in zip(
            runs.tolist(), pieces, proved.tolist(), sectors, strict=True
        ):
            if j1 > j0 and not ok and run_overlaps(piece.points_2d, piece.faces, sector):
                mid = (j0 + j1) // 2
                halves += [(j, j0, mid), (j, mid + 1, j1)]
            else:
                done[j].append((j0, piece))
        runs = np.array(halves, dtype=np.int64).reshape(-1, 3)
    return [[piece for _, piece in sorted(module, key=lambda x: x[0])] for module in done]


@dataclass
class _Layout:
    """The face shares of some runs and where their points go in the runs' pieces.

    Share ``q`` is sector ``i`` of a run ``(vertex, j0, j1)``: the half-cylinder of side ``i``
    (when rounded), the share of ring face ``f_i`` and, with a cone, its triangle. A run's
    points, in the order of :func:`~filletfold.surface.module.build_module`: the apex (cones); side
    ``j0``'s base curve and crease (or hole border), or the base and top of its line when it is
    unrounded; then per share the start of the next side (base, top) and the centre of face
    ``f_i``, followed, except after the last share, by the rest of the next side's base curve
    and crease. The last share's next side starts with its end copy (its start as reached across
    ``f_{j1}``), or its line when unrounded.

    Attributes
    ----------
    vertex : (n_runs,) int
        Chunk vertex of each run.
    first : (n_runs + 1,) int
        First point of each run's piece, then the number of points.
    run, side, face, nxt : (n_shares,) int
        Run, side ``i`` and face ``f_i`` (chunk indices) of each share; the next side.
    tee : (n_shares,) bool
        The share's hole border goes through the corner T (a point after the centre).
    head, tail : (n_shares,) bool
        First and last share of its run.
    n : (n_shares,) int
        Samples on side ``i`` (0 when unrounded).
    at : (n_shares,) int
        First point of the share's block (its side's curves, then the next side's start).
    start : (n_shares,) int
        Base point of the next side's start (its top follows, then the face centre).
    end_base, end_top : (n_shares,) int
        Base and top point of side ``i``'s end.
    sample_share, k : (n_samples,) int
        Share and sample number of each arc sample of the shares' sides.
    s : (n_samples,) float
        Their arc parameters.
    base, top : (n_samples,) int
        Their base and top points.
    """

    vertex: np.ndarray
    first: np.ndarray
    run: np.ndarray
    side: np.ndarray
    face: np.ndarray
    tee: np.ndarray
    nxt: np.ndarray
    head: np.ndarray
    tail: np.ndarray
    n: np.ndarray
    at: np.ndarray
    start: np.ndarray
    end_base: np.ndarray
    end_top: np.ndarray
    sample_share: np.ndarray
    k: np.ndarray
    s: np.ndarray
    base: np.ndarray
    top: np.ndarray

    @classmethod
    def of(cls, chunk: _Chunk, runs: np.ndarray) -> _Layout:
        """The layout of ``runs`` (n_runs, 3) int: ``(vertex, j0, j1)`` rows."""
        rv, j0, j1 = runs.T
        count = j1 - j0 + 1
        run = run_owners(count)
        q0 = run_starts(count)[:-1]
        i = j0[run] + np.arange(len(run)) - q0[run]
        v = rv[run]
        side = chunk.side_first[v] + i
        rounded = chunk.rounded[side]
        head = i == j0[run]
        n = np.where(rounded, chunk.samples[side], 0)
        lead = np.where(head, np.where(rounded, 2 * n, 2), 2 * (n - 1))
        face = chunk.face_first[v] + i
        tee = chunk.tee[face]
        block = lead + 3 + tee
        size = chunk.cone[rv] + np.add.reduceat(block, q0)
        first = run_starts(size)
        cb = run_starts(block)[:-1]
        at = first[run] + chunk.cone[v] + cb - cb[q0][run]
        start = at + lead
        sample_share, k, s = _arc_parameters(chunk.sides.arc[side], n)
        hs, ns, g = head[sample_share], n[sample_share], at[sample_share]
        prev = start[np.maximum(sample_share - 1, 0)]  # sample 0 of a later share's side
        base = np.where(hs, g + k, np.where(k == 0, prev, g + k - 1))
        top = np.where(hs, g + ns + k, np.where(k == 0, prev + 1, g + ns + k - 2))
        last = np.maximum(np.cumsum(n) - 1, 0)  # each rounded share's last sample
        has = n > 0  # (a 0 appended: no sample at all)
        return cls(
            vertex=rv,
            first=first,
            run=run,
            side=side,
            face=face,
            tee=tee,
            nxt=chunk.side_first[v] + (i + 1) % np.diff(chunk.side_first)[v],
            head=head,
            tail=i == j1[run],
            n=n,
            at=at,
            start=start,
            end_base=np.where(has, np.append(base, 0)[last], at),
            end_top=np.where(has, np.append(top, 0)[last], at + 1),
            sample_share=sample_share,
            k=k,
            s=s,
            base=base,
            top=top,
        )


def _run_pieces(chunk: _Chunk, runs: np.ndarray):
    """The pieces of runs ``(vertex, j0, j1)`` (n_runs, 3) int, all at once.

    Returns
    -------
    pieces : list of Piece
        Points that coincide in 2D and 3D merged
        (:meth:`~filletfold.surface.piece.Piece.merge_coincident`), on the few pieces that
        have any.
    proved : (n_runs,) bool
        Proved free of overlap (:func:`~filletfold.surface.overlap.faces_interior_disjoint_many`).
    sectors : list of (n_faces,) int
        For each run, the sector (from 0 at ``j0``) of each face of its piece.
    """
    lay = _Layout.of(chunk, runs)
    P2, P3 = _run_points(chunk, lay)
    corners, size, code, face_share = _run_faces(chunk, lay)
    keep, area = _oriented(P2, corners, size)
    corners, size, code, face_share, area = (
        x[keep] for x in (corners, size, code, face_share, area)
    )
    face_run = lay.run[face_share]
    # the checks of build_module: merge_coincident changes nothing (nothing merges, no face is
    # too small, every point is used), and the proof that the piece does not overlap itself
    n_runs = len(runs)
    point_run = run_owners(np.diff(lay.first))
    eps = chunk.eps[lay.vertex]
    good = _nothing_merges(P2, P3, point_run, eps)
    good[face_run[~(area > 2 * (eps * eps)[face_run])]] = False
    flat = corners[np.arange(_WIDTH) < size[:, None]]
    unused = np.ones(len(P2), dtype=bool)
    unused[flat] = False
    good[point_run[unused]] = False
    proved = faces_interior_disjoint_many(P2, flat, size, face_run, n_runs)
    local = (corners - lay.first[face_run][:, None])[np.arange(_WIDTH) < size[:, None]]
    patches = list(map(chunk.patch.__getitem__, code.tolist()))
    fb = run_starts(np.bincount(face_run, minlength=n_runs)).tolist()
    cb = run_starts(size)[fb].tolist()  # each run's first corner
    pb = lay.first.tolist()
    count = runs[:, 2] - runs[:, 1] + 1
    sector = face_share - (run_starts(count)[:-1])[face_run]  # the share within its run
    sectors = split_runs(sector, fb[1:-1])
    pieces = []
    for r, v in enumerate(lay.vertex.tolist()):
        a, b, fa, fz = pb[r], pb[r + 1], fb[r], fb[r + 1]
        piece = Piece(
            vertex=chunk.frames[v].vertex,
            points_2d=P2[a:b].copy(),
            points_3d=P3[a:b].copy(),
            faces=FaceLists.of_sizes(local[cb[r] : cb[r + 1]], size[fa:fz]),
            patches=patches[fa:fz],
            apex_index=0 if chunk.cone[v] else None,
        )
        if not good[r]:  # points that coincide (a crease through T, an unrounded side, ...)
            p2, kept = piece._merge_coincident(float(eps[r]))
            if kept is not None:
                sectors[r] = sectors[r][kept]
                proved[r] = faces_interior_disjoint(p2, piece.faces)
        pieces.append(piece)
    return pieces, proved, sectors


def _run_points(chunk: _Chunk, lay: _Layout) -> tuple[np.ndarray, np.ndarray]:
    """(n_points, 2) and (n_points, 3) float: the points of the runs' pieces, piece after piece
    (see :class:`_Layout`)."""
    P2 = np.empty((int(lay.first[-1]), 2))
    P3 = np.empty((len(P2), 3))
    cones = np.flatnonzero(chunk.cone[lay.vertex])
    P2[lay.first[cones]] = chunk.dev[lay.vertex[cones]]
    P3[lay.first[cones]] = chunk.apex[lay.vertex[cones]]
    # the half-cylinders: base curves and creases (module._side_curves, module._strips)
    side = lay.side[lay.sample_share]
    C, z, F = chunk.curves(side, lay.s)
    P2[lay.base] = chunk.in_side_chart(side, lay.s, np.zeros(len(side)))
    P2[lay.top] = chunk.in_side_chart(side, lay.s, z)
    P3[lay.base], P3[lay.top] = C, F
    # an unrounded first side: its line on the first face, up to half its lmax_end
    q = np.flatnonzero(lay.head & (lay.n == 0))
    _line(chunk, P2, P3, lay.at[q], lay.side[q], lay.face[q], chunk.lmax_end)
    # the side after each run: its start across the run's last face, or its line
    q = np.flatnonzero(lay.tail)
    rounded = chunk.rounded[lay.nxt[q]]
    e, o = q[rounded], q[~rounded]
    _line(chunk, P2, P3, lay.start[o], lay.nxt[o], lay.face[o], chunk.lmax_start)
    _end_copy(chunk, P2, P3, lay.start[e], lay.nxt[e], lay.face[e])
    # the face share centres
    c = lay.start + 2
    P3[c] = chunk.centre[lay.face]
    P2[c] = chunk.in_face_chart(P3[c], lay.face)
    # a hole border through the corner T of the face (hole_corners)
    t = np.flatnonzero(lay.tee)
    P3[c[t] + 1] = chunk.T[lay.face[t]]
    P2[c[t] + 1] = chunk.in_face_chart(P3[c[t] + 1], lay.face[t])
    return P2, P3


def _line(chunk: _Chunk, P2, P3, at: np.ndarray, side: np.ndarray, face: np.ndarray, lmax):
    """Write the base (at ``at``) and top (at ``at + 1``) of unrounded sides (m,) on ring faces
    ``face`` (m,): the midpoint ``M`` and ``M + (lmax / 2) R``."""
    sa = chunk.sides
    M = sa.M[side]
    top = M + (0.5 * lmax[side])[:, None] * sa.R[side]
    P3[at], P3[at + 1] = M, top
    P2[at], P2[at + 1] = chunk.in_face_chart(M, face), chunk.in_face_chart(top, face)


def _end_copy(chunk: _Chunk, P2, P3, at: np.ndarray, side: np.ndarray, face: np.ndarray):
    """Write the start of rounded sides (m,) as reached across the ring faces ``face`` (m,)
    before them (``face_map @ VertexFrame.gluing_start``): base at ``at``, top at ``at + 1``."""
    sa = chunk.sides
    s0 = np.zeros(len(side))
    C, z, F = chunk.curves(side, s0)
    glue = gluing_maps(sa.tangent(side, s0), sa.R[side], chunk.face_frame[face], C, s0)
    k = np.flatnonzero(sa.conical[side])
    if len(k):  # a fillet touches the face along its ruling from S (its chart at s = 0 is a
        # cylinder's: the points below are the same, the map is the fillet's)
        Ck, Rk, c, r = sa.chart(side[k], s0[k])
        E, e = perpendiculars(Ck, sa.tangent(side[k], s0[k]), Rk, c, r)
        glue[k] = ruled_gluing_maps(chunk.face_frame[face[k]], Ck, Rk, E, c, r, e)
    m = chunk.face_map[face] @ glue
    P2[at] = apply_rows(m, np.stack([s0, s0], axis=1))
    P2[at + 1] = apply_rows(m, np.stack([s0, z], axis=1))
    P3[at], P3[at + 1] = C, F


def _run_faces(chunk: _Chunk, lay: _Layout):
    """The faces of the runs' pieces before orientation: per share the quad and, with a cone,
    the triangle of every arc step, then the face share and its cone triangle.

    Returns
    -------
    corners : (n_faces, 6) int
        Point indices (into the points of all pieces), ``size`` of them used.
    size : (n_faces,) int
    code : (n_faces,) int
        Index into :attr:`_Chunk.patch`.
    face_share : (n_faces,) int
    """
    cone = chunk.cone[lay.vertex[lay.run]].astype(np.int64)
    count = np.maximum(lay.n - 1, 0) * (1 + cone) + 1 + cone
    fpos = run_starts(count)[:-1]
    corners = np.zeros((int(count.sum()), _WIDTH), dtype=np.int64)
    size = np.empty(len(corners), dtype=np.int64)
    code = np.empty(len(corners), dtype=np.int64)
    n_sides, n_vert = len(chunk.side_vertex), len(chunk.frames)
    apex = lay.first[lay.run]
    vertex = lay.vertex[lay.run]
    g = np.flatnonzero(lay.k < lay.n[lay.sample_share] - 1)  # arc steps: sample g to g + 1
    q = lay.sample_share[g]
    quad = fpos[q] + (1 + cone[q]) * lay.k[g]
    base, top = lay.base, lay.top
    corners[quad, :4] = np.stack([base[g], base[g + 1], top[g + 1], top[g]], axis=1)
    size[quad] = 4
    code[quad] = lay.side[q]
    c = cone[q] == 1
    g, q = g[c], q[c]
    corners[quad[c] + 1, :3] = np.stack([apex[q], top[g], top[g + 1]], axis=1)
    size[quad[c] + 1] = 3
    code[quad[c] + 1] = n_sides + vertex[q]
    share = fpos + count - 1 - cone
    t0, b0, b1 = lay.end_top, lay.end_base, lay.start
    corners[share, :5] = np.stack([t0, b0, b1 + 2, b1, b1 + 1], axis=1)
    corners[share, 5] = b1 + 3  # T, used where the border goes through it
    size[share] = 5 + lay.tee
    code[share] = n_sides + n_vert + lay.face
    c = np.flatnonzero(cone)
    corners[share[c] + 1, :3] = np.stack([apex[c], t0[c], b1[c] + 1], axis=1)
    size[share[c] + 1] = 3
    code[share[c] + 1] = n_sides + vertex[c]
    return corners, size, code, run_owners(count)


def _oriented(P2: np.ndarray, corners: np.ndarray, size: np.ndarray):
    """:meth:`~filletfold.surface.piece.Piece.face` of every face: zero-area faces dropped,
    clockwise ones reversed (``corners`` (n, 6) int, in place), NaN kept as is.

    Returns
    -------
    keep : (n,) bool
    area : (n,) float
        Twice the area, after the reversal.
    """
    area = np.empty(len(size))
    for w in range(3, _WIDTH + 1):
        rows = np.flatnonzero(size == w)
        area[rows] = polygon_area2(P2[corners[rows, :w]])
    keep = area != 0
    for w in range(3, _WIDTH + 1):
        rows = np.flatnonzero((area < 0) & (size == w))
        corners[rows, :w] = corners[rows, w - 1 :: -1]
        area[rows] = polygon_area2(P2[corners[rows, :w]])
    return keep, area


def _nothing_merges(
    p2: np.ndarray, p3: np.ndarray, piece: np.ndarray, eps: np.ndarray, longest: int = 64
) -> np.ndarray:
    """(n_pieces,) bool: no two points of a piece coincide within ``eps`` (per piece) in both
    2D and 3D, with a small margin, and all are finite: then
    :meth:`~filletfold.surface.piece.Piece.merge_coincident` merges nothing.

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
    chain = run_starts(~link)  # chain of each sorted point
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
