"""The vertex modules of many vertices at once (the surface stage).

:func:`build_modules` returns, for every vertex, what
:func:`~filletfold.surface.module.build_module`
returns. Cone modules and hole modules (saddle, developable, infeasible and boundary vertices,
closed or open rings) are built on flat arrays over all those vertices, a round of *runs* at a
time as :func:`~filletfold.surface.module.build_module` builds them: first one run over each whole
ring,
then the two halves of every run of more than one sector that overlaps itself. A round computes
for all its runs together the arc samples, base curves and creases (or hole borders), their 2D
images, the face shares' centres, the lines of unrounded boundary sides and the end copies of the
side after each run, every face with its area, then the merge and overlap checks of all the
pieces. Only a run that the overlap proof does not clear has its union measured on its own
(:func:`~filletfold.surface.overlap.run_overlaps`, the measure of ``build_module``). The points and
faces come in the order ``build_module`` adds them, with the same arithmetic row by row, so the
pieces are the same bit for bit.

A vertex takes the per-vertex :func:`~filletfold.surface.module.build_module` instead when

* a face occurs twice in its ring, a corner is reflex, it has a cone on an open ring, or its
  hole border goes through a corner T;
* :meth:`~filletfold.surface.piece.Piece.merge_coincident` could change one of its pieces: two
  points coincide in 2D and 3D within the merge distance (with a margin), a point is not finite, a
  face has twice-area ``<= 2 eps**2`` or a point is in no face.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..parallel import thread_map
from ..tolerances import tol
from ..vertex.apex import _stack
from ..vertex.crease import chart_apex, crease_denominator, crease_height, crease_numerator
from ..vertex.frame import SideArrays, VertexFrame, _dot, _gluing_maps, stack_sides
from .faces import FaceLists, polygon_area2
from .module import _arc_parameters, apply_rows, build_module, hole_corners, hole_heights
from .overlap import faces_interior_disjoint_many, run_overlaps
from .piece import Piece

#: Most vertices built together (bounds the flat arrays' size).
CHUNK = 2048

#: Corners of the largest face of a module (a face share: crease, base, centre, base, crease).
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
        Face piece centres (:func:`~filletfold.surface.centres.face_piece_centres`).
    n_samples : int or (n_edges,) int
        Points per arc, for all arcs or per edge.
    apices : sequence of ((3,) float or None)
        Spatial apex of each frame's vertex (None: a hole border).
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
    modules: list = [None] * len(frames)
    batched = [
        j
        for j, (frame, apex, v) in enumerate(zip(frames, apices, developed, strict=True))
        if _batched_case(frame, apex, v, centres)
    ]
    if np.size(n_samples) == 0 or np.min(n_samples) < 1:
        batched = []  # no arc samples: let build_module handle (or refuse) it
    chunks = [batched[c : c + CHUNK] for c in range(0, len(batched), CHUNK)]

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
    for j, module in enumerate(modules):
        if module is None:
            modules[j] = build_module(mesh, frames[j], centres, n_samples, apices[j], developed[j])
    if progress is not None:
        progress("surface", len(frames), len(frames))
    return modules


def _batched_case(frame: VertexFrame, apex, v, centres) -> bool:
    """Whether the vertex may take the batched path: its ring's faces each once, its sides
    rounded (an open ring: all but the first and the last), no reflex corner (kept out although
    with a cone its faces are built alike), a cone only on a closed ring, and without a cone no
    hole border through a corner T (:func:`~filletfold.surface.module.hole_corners`)."""
    closed = frame.ring.closed
    if apex is not None and (v is None or not closed):
        return False
    faces = np.asarray(frame.ring.faces).tolist()
    n = len(faces)
    rounded = frame.rounded
    return (
        n > 0
        and len(rounded) == n + (not closed)
        and (rounded.all() if closed else rounded.tolist() == [0 < i < n for i in range(n + 1)])
        and len(set(faces)) == n
        and not (np.asarray(frame.corner_angle) > np.pi).any()
        and (apex is not None or not hole_corners(frame, centres).any())
    )


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

    @classmethod
    def of(cls, frames: list, centres, n_samples, apices: list, developed: list) -> _Chunk:
        """The chunk of ``frames`` with their apices (None: a hole border)."""
        sa = _stack([_ring_arrays(f) for f in frames])
        ne = np.array([f.n_sides for f in frames], dtype=np.int64)
        nf = np.array([len(f.ring.faces) for f in frames], dtype=np.int64)
        side_first = np.concatenate([[0], np.cumsum(ne)])
        sv = np.repeat(np.arange(len(frames)), ne)
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
            face_first=np.concatenate([[0], np.cumsum(nf)]),
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
            patch=[f"cylinder {e}" for e in sa.edge.tolist()]
            + [f"cone {f.vertex}" for f in frames]
            + [f"face {f}" for f in ring_face.tolist()],
        )

    def curves(self, side: np.ndarray, s: np.ndarray):
        """Base points ``C`` (m, 3), heights ``z`` (m,) and top points ``F`` (m, 3) at arc
        parameters ``s`` (m,) of ``side`` (m,): the crease (eq. (1)) on a cone's sides, the hole
        border elsewhere."""
        sa = self.sides
        C = sa.base(side, s)
        z = self.height[side]
        on = np.flatnonzero(self.cone[self.side_vertex[side]])
        if len(on):
            i = side[on]
            num = crease_numerator(self.apex[self.side_vertex[i]], self.vi[i], s[on], C[on])
            z[on] = crease_height(num, self.dn[i])
        return C, z, C + z[:, None] * sa.R[side]

    def in_face_chart(self, p: np.ndarray, face: np.ndarray) -> np.ndarray:
        """(m, 2) common-frame images of points ``p`` (m, 3) on ring faces ``face`` (m,)
        (``apply(face_map, to_chart(face_frame, p))`` row by row)."""
        fr = self.face_frame[face]
        rel = p - fr[:, 0]
        return apply_rows(
            self.face_map[face], np.stack([_dot(rel, fr[:, 1]), _dot(rel, fr[:, 2])], axis=1)
        )


def _chunk_modules(chunk: _Chunk) -> list:
    """The module of every vertex of a chunk (list of Piece, in ring order), or None where the
    vertex must go through :func:`~filletfold.surface.module.build_module`.

    Runs ``(vertex, j0, j1)`` of sectors ``j0 .. j1`` are built a round at a time: a run of
    more than one sector whose piece is not proved free of overlap and measured to overlap
    itself is replaced by its halves ``j0 .. mid`` and ``mid + 1 .. j1`` in the next round.
    """
    n_vert = len(chunk.frames)
    last = np.diff(chunk.face_first) - 1
    runs = np.stack([np.arange(n_vert), np.zeros(n_vert, np.int64), last], axis=1)
    done: list = [[] for _ in range(n_vert)]
    failed = np.zeros(n_vert, dtype=bool)
    while len(runs):
        pieces, proved, sectors = _run_pieces(chunk, runs)
        halves = []
        for (j, j0, j1), piece, ok, sector in zip(
            runs.tolist(), pieces, proved.tolist(), sectors, strict=True
        ):
            if piece is None:
                failed[j] = True
            elif j1 > j0 and not ok and run_overlaps(piece.points_2d, piece.faces, sector):
                mid = (j0 + j1) // 2
                halves += [(j, j0, mid), (j, mid + 1, j1)]
            else:
                done[j].append((j0, piece))
        runs = np.array([r for r in halves if not failed[r[0]]], dtype=np.int64).reshape(-1, 3)
    return [
        None if bad else [piece for _, piece in sorted(module, key=lambda x: x[0])]
        for module, bad in zip(done, failed.tolist(), strict=True)
    ]


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
        run = np.repeat(np.arange(len(rv)), count)
        q0 = np.cumsum(count) - count
        i = j0[run] + np.arange(len(run)) - q0[run]
        v = rv[run]
        side = chunk.side_first[v] + i
        rounded = chunk.rounded[side]
        head = i == j0[run]
        n = np.where(rounded, chunk.samples[side], 0)
        lead = np.where(head, np.where(rounded, 2 * n, 2), 2 * (n - 1))
        block = lead + 3
        size = chunk.cone[rv] + np.add.reduceat(block, q0)
        first = np.concatenate([[0], np.cumsum(size)])
        cb = np.cumsum(block) - block
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
            face=chunk.face_first[v] + i,
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
    pieces : list of (Piece or None)
        None where :meth:`~filletfold.surface.piece.Piece.merge_coincident` could change the piece.
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
    point_run = np.repeat(np.arange(n_runs), np.diff(lay.first))
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
    fb = np.concatenate([[0], np.cumsum(np.bincount(face_run, minlength=n_runs))]).tolist()
    cb = np.concatenate([[0], np.cumsum(size)])[fb].tolist()  # each run's first corner
    pb = lay.first.tolist()
    pieces = []
    for r, v in enumerate(lay.vertex.tolist()):
        a, b, fa, fz = pb[r], pb[r + 1], fb[r], fb[r + 1]
        pieces.append(
            Piece(
                vertex=chunk.frames[v].vertex,
                points_2d=P2[a:b].copy(),
                points_3d=P3[a:b].copy(),
                faces=FaceLists.of_sizes(local[cb[r] : cb[r + 1]], size[fa:fz]),
                patches=patches[fa:fz],
                apex_index=0 if chunk.cone[v] else None,
            )
            if good[r]
            else None
        )
    count = runs[:, 2] - runs[:, 1] + 1
    sector = face_share - (np.cumsum(count) - count)[face_run]  # the share within its run
    return pieces, proved, np.split(sector, fb[1:-1])


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
    maps = chunk.cyl[side]
    P2[lay.base] = apply_rows(maps, np.stack([lay.s, np.zeros(len(side))], axis=1))
    P2[lay.top] = apply_rows(maps, np.stack([lay.s, z], axis=1))
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
    glue = _gluing_maps(sa.tangent(side, s0), sa.R[side], chunk.face_frame[face], C, s0)
    m = chunk.face_map[face] @ glue
    P2[at] = apply_rows(m, np.stack([s0, s0], axis=1))
    P2[at + 1] = apply_rows(m, np.stack([s0, z], axis=1))
    P3[at], P3[at + 1] = C, F


def _run_faces(chunk: _Chunk, lay: _Layout):
    """The faces of the runs' pieces before orientation: per share the quad and, with a cone,
    the triangle of every arc step, then the face share and its cone triangle.

    Returns
    -------
    corners : (n_faces, 5) int
        Point indices (into the points of all pieces), ``size`` of them used.
    size : (n_faces,) int
    code : (n_faces,) int
        Index into :attr:`_Chunk.patch`.
    face_share : (n_faces,) int
    """
    cone = chunk.cone[lay.vertex[lay.run]].astype(np.int64)
    count = np.maximum(lay.n - 1, 0) * (1 + cone) + 1 + cone
    fpos = np.cumsum(count) - count
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
    corners[share] = np.stack([t0, b0, b1 + 2, b1, b1 + 1], axis=1)
    size[share] = 5
    code[share] = n_sides + n_vert + lay.face
    c = np.flatnonzero(cone)
    corners[share[c] + 1, :3] = np.stack([apex[c], t0[c], b1[c] + 1], axis=1)
    size[share[c] + 1] = 3
    code[share[c] + 1] = n_sides + vertex[c]
    return corners, size, code, np.repeat(np.arange(len(count)), count)


def _oriented(P2: np.ndarray, corners: np.ndarray, size: np.ndarray):
    """:meth:`~filletfold.surface.piece.Piece.face` of every face: zero-area faces dropped,
    clockwise ones reversed (``corners`` (n, 5) int, in place), NaN kept as is.

    Returns
    -------
    keep : (n,) bool
    area : (n,) float
        Twice the area, after the reversal.
    """
    area = np.empty(len(size))
    for w in (3, 4, 5):
        rows = np.flatnonzero(size == w)
        area[rows] = polygon_area2(P2[corners[rows, :w]])
    keep = area != 0
    for w in (3, 4, 5):
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
