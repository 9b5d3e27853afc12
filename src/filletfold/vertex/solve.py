"""Per-vertex stages: classification, vertex normal, apices (paper sec. 2.4-3.2).

:class:`VertexResult` holds the per-vertex results of a design as arrays; the functions here
fill it one vertex at a time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..arrays import run_owners, run_starts
from ..mesh.polymesh import PolyMesh, mesh_size
from ..parallel import thread_map
from ..rounding.conical import vertex_cone_axes
from ..rounding.edges import EdgeRounding
from ..tolerances import tol
from . import batch, settings
from .apex import (
    KINDS,
    build_constraints,
    build_constraints_many,
    validate_apices,
)
from .batch import ApexWork, solve_apex_batch
from .frame import VertexFrame, closed_ring_sides, developed_apices, vertex_frames
from .normal import is_developable, solid_angles_front, vertex_normals
from .runs import run_means
from .settings import START_PARALLEL

STATUSES = ("ok", "saddle", "infeasible", "boundary", "developable", "sharp")


@dataclass
class VertexResult:
    """Per-vertex results, arrays over all mesh vertices.

    Attributes
    ----------
    kind : list of str
        ``"cone"``, ``"saddle"``, ``"developable"``, ``"boundary"`` or ``"sharp"`` (no edge at
        the vertex is rounded: its faces meet at the vertex itself).
    status : list of str
        ``"ok"``, ``"saddle"``, ``"infeasible"``, ``"boundary"``, ``"developable"`` or
        ``"sharp"``.
    reason : list of str or None
    angle_sum, defect, solid_angle : (n,) float
    normal : (n, 3) float
        Vertex normal ``D`` (NaN at boundary vertices).
    normal_bound : (n,) float
        The max-min value ``b`` of sec. 3.1.
    sigma : (n,) int
    depth_requested, depth : (n,) float
        ``d`` asked for and ``(V - U) . D`` actually used (NaN without apex).
    apex : (n, 3) float
        Spatial apex V (NaN without cone).
    apex_developed : (n, 2) float
        Developed apex in the vertex's own frame (NaN where undefined).
    apex_2d : (n, 2) float
        Apex position in the crease pattern layout.
    margin : (n,) float
        Smallest slack of the dense validation (length units).
    treatment : list of str
        What the surface does at the vertex: ``"cone"`` (status ``ok``), ``"sharp"`` (the
        corner kept: made sharp by :mod:`filletfold.vertex.sharpen`, or every edge unrounded)
        or ``"hole"`` (no cone and not kept sharp: a hole border, or a notch at a boundary
        vertex); ``""`` until the apex stage has run.
    solver : list of str
        What found each cone's apex (:attr:`~filletfold.vertex.apex.ApexSolution.solver`:
        ``"target"``, ``"ipm"``, or ``"<fallback>+ipm"`` when a fallback of the feasibility
        phase found its feasible point (``starts``, ``again``, ``lp``, ``long``: see
        :data:`~filletfold.vertex.settings.FALLBACKS`), with ``"+slsqp"`` when SLSQP finished
        it); ``""`` without a cone.
    """

    kind: list
    status: list
    reason: list
    angle_sum: np.ndarray
    defect: np.ndarray
    solid_angle: np.ndarray
    normal: np.ndarray
    normal_bound: np.ndarray
    sigma: np.ndarray
    depth_requested: np.ndarray
    depth: np.ndarray
    apex: np.ndarray
    apex_developed: np.ndarray
    apex_2d: np.ndarray
    margin: np.ndarray
    treatment: list = None
    solver: list = None

    def __post_init__(self):
        if self.treatment is None:
            self.treatment = [""] * len(self.kind)
        if self.solver is None:
            self.solver = [""] * len(self.kind)

    def take(self, other: VertexResult, vertices) -> None:
        """Copy every per-vertex field of ``other`` at ``vertices`` into this result."""
        idx = np.asarray(list(vertices), dtype=np.int64)
        for name, value in vars(self).items():
            src = getattr(other, name)
            if isinstance(value, list):
                for u in idx:
                    value[u] = src[u]
            else:
                value[idx] = src[idx]

    @classmethod
    def empty(cls, n: int) -> VertexResult:
        nan = np.full(n, np.nan)
        return cls(
            kind=[""] * n,
            status=[""] * n,
            reason=[None] * n,
            angle_sum=nan.copy(),
            defect=nan.copy(),
            solid_angle=nan.copy(),
            normal=np.full((n, 3), np.nan),
            normal_bound=nan.copy(),
            sigma=np.zeros(n, dtype=np.int64),
            depth_requested=nan.copy(),
            depth=nan.copy(),
            apex=np.full((n, 3), np.nan),
            apex_developed=np.full((n, 2), np.nan),
            apex_2d=np.full((n, 2), np.nan),
            margin=nan.copy(),
        )


def cones_by_fallback(res: VertexResult) -> dict:
    """The cones (status ``ok``) whose feasible point a fallback of the solver found, per
    fallback tried (:data:`~filletfold.vertex.settings.FALLBACKS`; 0 for those that found
    none): what each one paid for in this design."""
    out = dict.fromkeys(settings.FALLBACKS, 0)
    for status, solver in zip(res.status, res.solver, strict=True):
        name = solver.split("+", 1)[0]
        if status == "ok" and name in out:
            out[name] += 1
    return out


def classify_vertices(
    mesh: PolyMesh,
    rounding: EdgeRounding,
    res: VertexResult,
    vertices=None,
    start_edge=None,
    sharp=None,
) -> list[VertexFrame]:
    """Build the vertices' frames, classify them and find their normals (sec. 2.5, 3.1).

    Fills ``res`` at each vertex: angle sum, defect, solid angle, normal, bound, sigma, kind,
    and the status of every vertex that cannot get a cone (``status`` stays ``""``
    otherwise). The normals of all vertices are found at once
    (:func:`~filletfold.vertex.normal.vertex_normals`).

    Parameters
    ----------
    mesh : PolyMesh
    rounding : EdgeRounding
    res : VertexResult
    vertices : sequence of int, optional
        Default: every vertex.
    start_edge : sequence of (int or None), optional
        Per listed vertex, the incident edge along which its module is cut (see
        :func:`~filletfold.vertex.frame.vertex_frames`).
    sharp : (n_vertices,) bool, optional
        Sharp vertices: their neighbours' sides toward them are conical fillets
        (:func:`~filletfold.vertex.frame.vertex_frames`).

    Returns
    -------
    list of VertexFrame
        In the order of ``vertices``.
    """
    if vertices is None:
        vertices = range(mesh.n_vertices)
    vertices = [int(u) for u in vertices]
    if start_edge is None:
        start_edge = [None] * len(vertices)
    frames = vertex_frames(mesh, rounding, vertices, start_edge, sharp=sharp)
    closed = [k for k, f in enumerate(frames) if f.ring.closed]
    verts = np.array(vertices, dtype=np.int64)
    res.angle_sum[verts] = mesh.vertex_angle_sum[verts]
    res.defect[verts] = 2 * np.pi - res.angle_sum[verts]
    for k, frame in enumerate(frames):
        if not frame.ring.closed:
            u = vertices[k]
            res.kind[u] = res.status[u] = "boundary"
            res.reason[u] = "boundary vertex: no cone; its module ends at the sheet's edge"
    if not closed:
        return frames
    # the sides of the closed rings, ring after ring (as many ring faces as sides)
    sides = [frames[k].arrays for k in closed]
    count = np.array([len(a.arc) for a in sides], dtype=np.int64)
    edges = np.concatenate([a.edge for a in sides])
    D, bound, sigma = _ring_normals(
        mesh,
        np.concatenate([a.R for a in sides]),
        np.concatenate([frames[k].ring.faces for k in closed]),
        count,
    )
    u_closed = verts[closed]
    res.normal[u_closed], res.normal_bound[u_closed], res.sigma[u_closed] = D, bound, sigma
    res.solid_angle[u_closed] = solid_angles_front(
        rounding.kappa[edges], rounding.half_angle[edges], count
    )
    developable = is_developable(res.angle_sum[u_closed])
    unrounded = (
        np.maximum.reduceat(np.concatenate([a.radius for a in sides]), run_starts(count)[:-1]) == 0
    )
    for j, (k, u, b) in enumerate(zip(closed, u_closed.tolist(), bound.tolist(), strict=True)):
        if unrounded[j]:
            res.kind[u] = res.status[u] = "sharp"
            res.reason[u] = (
                "no edge at this vertex is rounded (each is flat, or left sharp because its "
                "fillet would be a sliver): its faces meet at the vertex itself"
            )
        elif developable[j] and _opens_with_a_near_apex(frames[k]) and b > tol.normal_bound:
            # an angle sum only near 2 pi (float32 coordinates): rho turns a little about a
            # point near the vertex, which is the developed apex of an ordinary cone
            res.kind[u] = "cone"
        elif developable[j]:
            frame = frames[k]
            res.kind[u] = "developable"
            gap = float(np.linalg.norm(frame.rho[:2, 2]))
            scale = float(frame.arrays.length.mean())
            if gap > tol.closure * scale or b <= tol.normal_bound:
                res.status[u] = "developable"
                res.reason[u] = (
                    "developable vertex (angle sum 2 pi) whose rounded development does not "
                    f"close (gap {gap:.3g}): it needs consistent material loss (--material-loss)"
                    if b > tol.normal_bound
                    else "developable vertex (angle sum 2 pi) with no vertex normal"
                )
        elif b <= tol.normal_bound:
            res.kind[u] = res.status[u] = "saddle"
            res.reason[u] = saddle_reason(b)
        else:
            res.kind[u] = "cone"
    return frames


def saddle_reason(bound: float) -> str:
    """Why a saddle vertex has no cone, given its max-min bound."""
    return (
        f"saddle vertex: no plane through it has all its faces on one side "
        f"(max-min bound {bound:.3g} <= 0); no cone possible"
    )


def _ring_normals(mesh: PolyMesh, R: np.ndarray, faces: np.ndarray, count: np.ndarray):
    """:func:`~filletfold.vertex.normal.vertex_normals` of closed rings given flat: their
    sides' directions ``R`` (P, 3) and faces (P,), ``count`` (c,) per ring. Returns the
    normals, max-min bounds and sides (sigma) of the rings."""
    n = len(count)
    D, bound, sigma = np.zeros((n, 3)), np.zeros(n), np.zeros(n, dtype=np.int64)
    start = run_starts(count)[:-1]
    # rings padded to the longest of their group (valences within a factor 2), not of the
    # mesh: one vertex of 10,000 edges would pad every ring to 10,000 (2.2 GB)
    group = np.ceil(np.log2(np.maximum(count, 1))).astype(np.int64)
    for g in np.unique(group).tolist():
        rings = np.flatnonzero(group == g)
        c = count[rings]
        row = run_owners(c)
        col = np.arange(len(row)) - np.repeat(run_starts(c)[:-1], c)
        src = np.repeat(start[rings], c) + col
        edge_dir = np.zeros((len(rings), int(c.max()), 3))
        face_normal = np.zeros_like(edge_dir)
        edge_dir[row, col] = R[src]
        face_normal[row, col] = mesh.face_normal[faces[src]]
        D[rings], bound[rings], sigma[rings] = vertex_normals(edge_dir, face_normal, c, c)
    return D, bound, sigma


def saddle_vertices(mesh: PolyMesh, rounding: EdgeRounding) -> np.ndarray:
    """(n_vertices,) bool: the vertices :func:`classify_vertices` calls saddles (a closed ring
    with a rounded edge, an angle sum away from 2 pi and no plane through the vertex with all
    its faces on one side), found from the mesh and the radii alone, before any frame: the
    saddles are made sharp before the frames are built, so that their neighbours' frames are
    built once (:func:`~filletfold.vertex.sharpen.unround_between`).
    """
    out = np.zeros(mesh.n_vertices, dtype=bool)
    closed, R, edge, face, count = closed_ring_sides(mesh, np.arange(mesh.n_vertices))
    if not len(closed):
        return out
    _, bound, _ = _ring_normals(mesh, R, face, count)
    start = run_starts(count)[:-1]
    rounded = np.logical_or.reduceat(rounding.radius[edge] > 0, start)
    developable = is_developable(mesh.vertex_angle_sum[closed])
    out[closed] = rounded & ~developable & (bound <= tol.normal_bound)
    return out


def _opens_with_a_near_apex(frame: VertexFrame) -> bool:
    """Whether a closed ring whose angle sum is within ``tol.developable`` of 2 pi still does
    not close: ``rho`` moves its points by more than ``tol.closure`` of its sides (the turn
    included, not only the translation), while turning about a point within ten times its
    longest side (a well-placed developed apex). Treating such a vertex as closed would leave
    its rulings unequal by the development's gap."""
    q, t = frame.rho[:2, :2], frame.rho[:2, 2]
    turn = abs(float(np.arctan2(q[1, 0], q[0, 0])))
    length = frame.arrays.length
    reach = float(length.max())
    if float(np.linalg.norm(t)) + turn * reach <= tol.closure * float(length.mean()):
        return False  # closed: a developable vertex
    v = developed_apices(frame.rho[None], min_det=1e-300)[0]  # any fixed point at all
    return bool(np.isfinite(v[0])) and float(np.linalg.norm(v)) <= 10 * reach


def central_rulings_crossing(frame: VertexFrame) -> np.ndarray | None:
    """Where the central rulings of two consecutive developed cylinders cross (sec. 3.2).

    The initial developed apex ``p`` of a closed development. Returns (2,) float in the
    vertex's common frame, or None when every consecutive pair is parallel.
    """
    lines = []
    for i, arc in enumerate(frame.arrays.arc.tolist()):
        if arc > 0:
            m = frame.cyl_map[i]
            lines.append((m[:2, :2] @ [0.5 * arc, 0.0] + m[:2, 2], m[:2, :2] @ [0.0, 1.0]))
    for (p1, d1), (p2, d2) in zip(lines, lines[1:] + lines[:1], strict=True):
        a = np.stack([d1, -d2], axis=1)
        if abs(np.linalg.det(a)) > START_PARALLEL:
            z = np.linalg.solve(a, p2 - p1)
            return p1 + z[0] * d1
    return None


@dataclass
class ApexProblem:
    """The apex problem of one cone vertex and the state of its attempts.

    Attributes
    ----------
    frame : VertexFrame
    closed : bool
        True for a developable vertex: the developed apex is a variable too (sec. 3).
    sigma : int
        Side of the apex (+1 front, -1 back).
    v : (2,) float
        Developed apex (fixed point of rho), or its start for a closed development.
    target : (3,) or (5,) float
        ``P = U + d D`` (and ``v`` when closed).
    starts : (k, 3) or (k, 5) float
        Further starts for the feasibility phase, along ``D`` (:data:`START_DEPTHS`).
    margin : float
        The safety margin ``m`` at scale 1.
    low : float
        The shortest ``l_max``: margins stay under a quarter of it.
    floor : float
        Shortest crease ruling (length): ``tol.ruling`` of the mesh's size, under a quarter of
        ``low`` (0 without a size).
    shrink : (n_sides, 2) float or None
        Factors on ``l_max`` (shortened creases after a face-centre crossing; None: all 1).
    attempts : list of (int, float)
        Remaining (samples per arc, margin scale) to try, in order.
    failing : list of str
        What failed at the last attempt.
    extra : (m, 2) float
        ``(side, s)``: samples added where earlier solutions failed between the samples.
    cut_rounds : int
        Attempts repeated with such samples added (at most :data:`CUT_ROUNDS` per attempt).
    """

    frame: VertexFrame
    closed: bool
    sigma: int
    v: np.ndarray
    target: np.ndarray
    starts: np.ndarray
    margin: float
    low: float
    floor: float
    shrink: np.ndarray | None
    attempts: list
    failing: list
    extra: np.ndarray
    cut_rounds: int

    def constraints(self, n_samples: int, scale: float):
        """The sampled constraints of the next attempt (:func:`build_constraints`)."""
        return build_constraints(*self.constraint_args(n_samples, scale))

    def constraint_args(self, n_samples: int, scale: float) -> tuple:
        """The arguments of :func:`build_constraints` for the next attempt: frame, fixed
        developed apex (None when closed), sigma, samples, margin, crease factors, extra
        samples, shortest ruling."""
        m = min(self.margin * scale, 0.25 * self.low)
        v = None if self.closed else self.v
        return self.frame, v, self.sigma, n_samples, m, self.shrink, self.extra, self.floor


#: Attempts per vertex: (samples per arc, margin scale), the next one after a failed dense
#: validation. After an infeasible attempt :data:`THIN_ATTEMPTS` follow instead (a tenth of
#: the margin, for thin windows); an infeasible thin attempt ends the vertex (more samples
#: only add constraints).
ATTEMPTS = [(9, 1.0), (33, 2.0), (65, 4.0)]
THIN_ATTEMPTS = [(9, 0.1), (33, 0.1), (129, 0.1)]

#: After a failed dense validation where only ``l >= 0`` or the non-intersection condition
#: fails between the samples, the same attempt is repeated with the worst points added as
#: samples (a cutting plane), this many times per attempt, before the next attempt.
CUT_ROUNDS = 2

#: Starts of the feasibility phase: ``U + t L D`` for these ``t`` (``L`` the mean incident
#: edge length).
START_DEPTHS = np.array([0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5])

#: Vertices solved and validated together: bounds the memory of a round's sampled
#: constraints and dense validation (about 100 kB per vertex at 65 validation samples). On a
#: 5,000-vertex scan 512 instead of 2048 took the apex stage's peak from 490 to 306 MB with
#: the same bytes out, and the 2,904-vertex cow's apices from 8.4 to 7.8 s (two slices at
#: once on two cores).
ROUND_SLICE = 512


def apex_problem(
    frame: VertexFrame, depth: float, res: VertexResult, size: float | None = None
) -> ApexProblem | None:
    """Set up the apex problem of a cone vertex, or mark it infeasible and return None.

    Records the requested depth and the developed apex in ``res``. A vertex gets no problem
    (status ``infeasible`` with the reason) when it has no developed apex, a reflex face
    corner, or a tangent-line crossing beyond an edge midpoint. The one-vertex case of
    :func:`_set_up`.
    """
    u = frame.vertex
    return _set_up({u: frame}, {u: depth}, res, [u], size).get(u)


def apex_problems(mesh: PolyMesh, rounding: EdgeRounding, depths: np.ndarray) -> list[ApexProblem]:
    """The apex problems of every vertex that reaches the apex stage, set up as in
    :func:`~filletfold.design.round_mesh` (for tests and benchmarks of the solvers).

    Parameters
    ----------
    mesh : PolyMesh
    rounding : EdgeRounding
    depths : (n_vertices,) float
    """
    res = VertexResult.empty(mesh.n_vertices)
    frames = classify_vertices(mesh, rounding, res)
    vertices = [u for u in range(mesh.n_vertices) if res.status[u] == ""]
    return list(_set_up(frames, depths, res, vertices, mesh_size(mesh)).values())


def _set_up(
    frames, depths, res: VertexResult, vertices, size: float | None = None, cuts=None
) -> dict:
    """The apex problems of ``vertices`` (vertex -> ApexProblem; those without one are
    marked in ``res`` and left out): :func:`apex_problem` of every vertex, computed together
    (each vertex's arithmetic is the one of :func:`apex_problem`); with ``cuts`` (see
    :func:`solve_apices`), a vertex in it starts with those samples added."""
    vertices = [int(u) for u in vertices]
    if not vertices:
        return {}
    fr = [frames[u] for u in vertices]
    idx = np.array(vertices)
    depth = np.array([float(depths[u]) for u in vertices])
    res.depth_requested[idx] = depth
    closed = np.array([res.kind[u] == "developable" for u in vertices])
    # developed apex: the fixed point of rho, or where central rulings cross (closed)
    rho = np.array([f.rho for f in fr])  # (n, 3, 3)
    v = np.full((len(fr), 2), np.nan)
    v[~closed] = developed_apices(rho[~closed])
    turns = ~closed & np.isfinite(v[:, 0])
    for j in np.flatnonzero(closed).tolist():
        crossing = central_rulings_crossing(fr[j])
        if crossing is not None:
            v[j] = crossing
    has_v = turns | (closed & np.isfinite(v[:, 0]))
    # per vertex over its sides and faces: reflex corner, shortest l_max, lengths, arcs
    sa = [f.arrays for f in fr]
    k = np.array([len(x.arc) for x in sa])
    first = run_starts(k)[:-1]
    nf = np.array([len(f.corner_angle) for f in fr])
    corner = np.concatenate([f.corner_angle for f in fr])
    reflex = np.maximum.reduceat(corner, run_starts(nf)[:-1]) > np.pi
    lmax = np.fmin(
        np.concatenate([f.lmax_start for f in fr]), np.concatenate([f.lmax_end for f in fr])
    )
    low = np.minimum.reduceat(lmax, first)
    length = np.concatenate([x.length for x in sa])
    arc = np.concatenate([x.arc for x in sa])
    shortest = np.minimum.reduceat(length, first)
    shortest_arc = np.minimum.reduceat(np.where(arc > 0, arc, np.inf), first)
    margin_length = np.where(
        np.isfinite(shortest_arc), np.minimum(shortest, 4 * shortest_arc), shortest
    )  # or four times the shortest arc, when shorter: nearly flat vertices have thin windows
    mean_length = run_means(length, k)
    U = np.array([f.U for f in fr])
    D = res.normal[idx]
    target = U + depth[:, None] * D
    starts = U[:, None] + (START_DEPTHS[None, :] * mean_length[:, None])[..., None] * D[:, None]
    problems = {}
    for j, u in enumerate(vertices):
        if not has_v[j]:
            res.status[u] = "infeasible"
            res.reason[u] = (
                "no developed apex: the central rulings of the developed cylinders are parallel"
                if closed[j]
                else "the development does not turn (rho is a translation): no developed apex"
            )
            continue
        res.apex_developed[u] = v[j]
        if reflex[j]:
            res.status[u] = "infeasible"
            res.reason[u] = (
                "a face has a reflex corner at this vertex: the straight crease on it "
                "would leave the face"
            )
            continue
        if not low[j] > 0:
            res.status[u] = "infeasible"
            res.reason[u] = "a tangent-line crossing lies beyond an edge midpoint: radius too large"
            continue
        t, st = target[j], starts[j]
        if closed[j]:
            t = np.concatenate([t, v[j]])
            st = np.concatenate([st, np.broadcast_to(v[j], (len(st), 2))], axis=1)
        problems[u] = ApexProblem(
            frame=fr[j],
            closed=bool(closed[j]),
            sigma=int(res.sigma[u]),
            v=v[j].copy(),
            target=t,
            starts=st,
            margin=tol.margin * float(margin_length[j]),
            low=float(low[j]),
            floor=0.0 if size is None else min(tol.ruling * size, 0.25 * float(low[j])),
            shrink=None,
            attempts=list(ATTEMPTS),
            failing=[],
            extra=np.zeros((0, 2)),
            cut_rounds=0,
        )
        if cuts and u in cuts:
            problems[u].extra = cut_samples(fr[j], cuts[u])
    return problems


def cut_fractions(frame: VertexFrame, extra: np.ndarray) -> np.ndarray:
    """(m, 2) float: the added samples ``extra`` ((side, s) rows) of a vertex's problem as
    (mesh edge, fraction of its side's arc): what :func:`cut_samples` reads on the vertex's
    frame after its radii changed (a side keeps its edge; its arc scales with its radius)."""
    extra = np.asarray(extra, dtype=float).reshape(-1, 2)
    if not len(extra):
        return np.zeros((0, 2))
    side = extra[:, 0].astype(np.int64)
    arc = frame.arrays.arc[side]
    frac = np.where(arc > 0, extra[:, 1] / np.where(arc > 0, arc, 1.0), 0.0)
    return np.stack([frame.ring.edges[side].astype(float), frac], axis=1)


def cut_samples(frame: VertexFrame, fractions: np.ndarray) -> np.ndarray:
    """(m, 2) float (side, s): the samples of :func:`cut_fractions` on ``frame``, those on a
    side it no longer has or whose arc is now flat left out."""
    fractions = np.asarray(fractions, dtype=float).reshape(-1, 2)
    edges = np.asarray(frame.ring.edges, dtype=np.int64)
    order = np.argsort(edges, kind="stable")
    at = np.searchsorted(edges[order], fractions[:, 0].astype(np.int64))
    at = np.minimum(at, len(edges) - 1)
    side = order[at]
    arc = frame.arrays.arc[side]
    keep = (edges[side] == fractions[:, 0].astype(np.int64)) & (arc > 0)
    return np.stack([side[keep].astype(float), fractions[keep, 1] * arc[keep]], axis=1)


def solve_apices(
    frames: list[VertexFrame],
    depths: np.ndarray,
    res: VertexResult,
    centres: np.ndarray | None = None,
    progress=None,
    vertices=None,
    thorough: bool = True,
    size: float | None = None,
    lp: bool = True,
    cuts: dict | None = None,
    work: ApexWork | None = None,
) -> dict:
    """Developed and spatial apices of every cone vertex (sec. 2.4, 3.2), validated densely.

    All vertices still without a status are solved together, one attempt per round, by
    :func:`~filletfold.vertex.batch.solve_apex_batch`, and validated together by
    :func:`~filletfold.vertex.apex.validate_apices`, :data:`ROUND_SLICE` vertices at a time
    (slices of a round in threads, :func:`~filletfold.parallel.thread_map`; ``progress`` is
    called after each); a vertex whose attempt fails the dense
    validation goes to its next attempt in the next round (more samples and margin, shorter
    creases when a straight crease passes a face piece's centre, a tenth of the margin when
    the sampled problem is infeasible: see :data:`ATTEMPTS`).
    Sets ``res.status`` to ``ok`` (with apex, depth used and margin) or ``infeasible`` (with
    the constraints that fail).

    Parameters
    ----------
    frames : sequence or mapping of VertexFrame
        Indexed by mesh vertex.
    depths : (n,) float or mapping
        Requested depth, indexed by mesh vertex.
    res : VertexResult
    centres : (n_faces, 3) float, optional
        Face pieces' centres: adds the check that every straight crease stays short of them.
    progress : callable, optional
        ``progress("apices", done, total)`` after every slice of a round.
    vertices : iterable of int, optional
        The vertices to solve (default: every vertex whose status is still empty).
    thorough : bool
        False skips what only decides a hard case (more feasibility starts and the linear
        programmes of the last attempts): faster, and a vertex may be called infeasible that
        the thorough solve would solve (the vertex rescue's trial rounds use it).
    lp : bool
        Whether a thorough solve tries the other starts and linear programmes before it calls a
        vertex infeasible (see :func:`~filletfold.vertex.batch.solve_apex_batch`); off where a
        rescue follows.
    size : float, optional
        The mesh's size (:func:`mesh_size`): every crease stays ``tol.ruling`` of it above its
        base curve (or a quarter of the vertex's shortest ``l_max``), so that no cylinder
        ruling of the pattern is a sliver edge. Default: no such floor.
    cuts : dict, optional
        Vertex -> the samples an earlier solve of it added where its solution dipped between
        the samples (:func:`cut_fractions`: per edge, as fractions of the arc). A vertex in it
        starts with them (after a change of radii its dips are mostly where they were, and
        each would otherwise cost a solve again); every vertex settled here is set to those
        it ended with. The vertex rescue passes one dict from solve to solve.
    work : ApexWork, optional
        Adds the solver's work (problems, phase-1 runs, linear programmes); the design passes
        one from solve to solve (``fitting.apex_work``).

    Returns
    -------
    dict
        Per solved vertex: (apex, dev_apex), the (3,) float spatial apex and the (2,) float
        developed apex in the vertex's common frame, or (None, None) when infeasible.
    """
    if vertices is None:
        vertices = [u for u in range(len(res.status)) if res.status[u] == ""]
    vertices = list(vertices)
    out = dict.fromkeys(vertices, (None, None))
    pending = _set_up(frames, depths, res, vertices, size, cuts)
    total = len(pending)
    # the numba kernel loads on the first batch it solves (none when every vertex is at its
    # target): the first design after installing numba compiles it, its progress says so
    with batch.loading_shown(progress):
        while pending:  # one attempt per vertex and round, ROUND_SLICE vertices at a time
            order = list(pending)
            slices = [order[lo : lo + ROUND_SLICE] for lo in range(0, len(order), ROUND_SLICE)]
            # the slices are independent (each settles its own vertices): in threads
            for _ in thread_map(
                lambda part: _solve_round(
                    part, pending, res, out, centres, thorough, lp, cuts, work
                ),
                slices,
            ):
                if progress is not None:
                    progress("apices", total - len(pending), total)
    return out


def _add_cuts(p: ApexProblem, attempt: tuple[int, float], check) -> bool:
    """After a failed validation: when only ``l >= 0`` and non-intersection fail (between the
    samples), retry ``attempt`` with their worst points as samples; whether it does."""
    between = (KINDS["l_min"], KINDS["nonint"])
    if not len(check.cuts) or not all(f.startswith(between) for f in check.failing):
        return False
    if p.cut_rounds >= CUT_ROUNDS:
        p.cut_rounds = 0  # the next attempt may cut again
        return False
    p.cut_rounds += 1
    p.extra = np.vstack([p.extra, check.cuts])
    p.attempts.insert(0, attempt)
    return True


def _shorten_creases(p: ApexProblem, attempt: tuple[int, float]) -> None:
    """After a failed validation: when only face-centre crossings fail, retry ``attempt``
    with shorter creases on those faces."""
    crossing = [f for f in p.failing if "face piece's centre" in f]
    n_sides = len(p.frame.sides)
    shrink = np.ones((n_sides, 2)) if p.shrink is None else p.shrink
    if crossing and len(crossing) == len(p.failing) and shrink.min() > 0.2:
        faces = {int(f.rsplit(" ", 1)[1]) for f in crossing}
        p.shrink = shrink
        for i, f in enumerate(p.frame.ring.faces):
            if int(f) in faces:
                p.shrink[i, 1] *= 0.7
                p.shrink[(i + 1) % n_sides, 0] *= 0.7
        p.attempts.insert(0, attempt)


def _solve_round(
    order: list,
    pending: dict,
    res: VertexResult,
    out: dict,
    centres,
    thorough: bool = True,
    lp: bool = True,
    cuts: dict | None = None,
    work: ApexWork | None = None,
) -> None:
    """One attempt of the vertices ``order`` (in ``pending``): solve them at once, validate the
    solved ones at once, and settle every vertex that is done (ok, or out of attempts; its
    added samples noted in ``cuts``)."""
    tries = [pending[u].attempts.pop(0) for u in order]
    args = [pending[u].constraint_args(*t) for u, t in zip(order, tries, strict=True)]
    cons = build_constraints_many(*map(list, zip(*args, strict=True)))
    sols = solve_apex_batch(
        cons,
        [pending[u].target for u in order],
        [pending[u].starts for u in order],
        thorough=[thorough and t[1] < 1.0 for t in tries],  # only thin attempts end a vertex
        lp=lp,
        work=work,
    )
    # the dense validation of every solved vertex at once
    solved = [
        (u, sol, sol.developed if pending[u].closed else pending[u].v)
        for u, sol in zip(order, sols, strict=True)
        if sol.ok
    ]
    checks = validate_apices(
        [pending[u].frame for u, _, _ in solved],
        [sol.apex for _, sol, _ in solved],
        [v for _, _, v in solved],
        [pending[u].sigma for u, _, _ in solved],
        centres=centres,
        floors=[pending[u].floor for u, _, _ in solved],
    )
    checked = {u: (v, c) for (u, _, v), c in zip(solved, checks, strict=True)}
    for u, attempt, sol in zip(order, tries, sols, strict=True):
        p = pending[u]
        if not sol.ok:
            p.failing = sol.failing
            p.attempts = [] if attempt[1] < 1.0 else list(THIN_ATTEMPTS)
        else:
            v_sol, check = checked[u]
            if check.ok:
                res.status[u] = "ok"
                res.apex[u] = sol.apex
                res.apex_developed[u] = v_sol
                res.depth[u] = float((sol.apex - p.frame.U) @ res.normal[u])
                res.margin[u] = check.margin
                res.solver[u] = sol.solver
                out[u] = (sol.apex, v_sol)
                if cuts is not None:
                    cuts[u] = cut_fractions(p.frame, p.extra)
                del pending[u]
                continue
            p.failing = check.failing
            if not _add_cuts(p, attempt, check):
                _shorten_creases(p, attempt)
        if not p.attempts:
            res.status[u] = "infeasible"
            res.reason[u] = "no apex meets every constraint: " + "; ".join(p.failing[:6])
            if len(p.failing) > 6:
                res.reason[u] += f"; and {len(p.failing) - 6} more"
            if cuts is not None:
                cuts[u] = cut_fractions(p.frame, p.extra)
            del pending[u]


def use_cone_axes(mesh: PolyMesh, frames: list, res: VertexResult) -> None:
    """Make each cone vertex's normal its cone axis (conical meshes, sec. 4.4)."""
    axis, _ = vertex_cone_axes(mesh)
    for u, frame in enumerate(frames):
        if res.kind[u] != "cone" or not np.all(np.isfinite(axis[u])):
            continue
        D = res.sigma[u] * axis[u]
        dirs = np.vstack(
            [
                -np.array([s.R for s in frame.sides]),
                res.sigma[u] * mesh.face_normal[frame.ring.faces],
            ]
        )
        bound = float((dirs @ D).min())
        if bound > tol.normal_bound:
            res.normal[u], res.normal_bound[u] = D, bound
