"""The stages of :func:`~filletfold.design.round_mesh`, each a function from one result to the next.

The flow of ``docs/method.md`` ("Pipeline"), one function per stage:

========================  ===============================================  =====================
stage                     computes                                         returns
========================  ===============================================  =====================
:func:`read_stage`        the mesh read and cleaned; the lengths that      :class:`Job`
                          every stage reads
:func:`edge_stage`        a cylinder on every edge (sec. 2.1, 4)           :class:`Edges`
:func:`normal_stage`      the vertex frames, classes and normals           :class:`VertexState`
                          (sec. 3.1)
:func:`apex_stage`        the developed and spatial apices (sec. 2.4,      :class:`VertexSolution`
                          3.2), the rescue, the sharp vertices
:func:`module_stage`      each vertex's module: creases (eq. 1), cone,     :class:`Modules`
                          cylinders, face pieces
:func:`layout_stage`      the pieces laid out into the crease pattern      :class:`Layout`
========================  ===============================================  =====================

The browser app's reuse of an earlier design is a cache around the stages, not code inside
them: :class:`Stages` holds what a design computed, :func:`reusable_stages` says whether it
holds for a new one (the same mesh and rounding parameters), and the stages take its results
over where it does.
"""

from __future__ import annotations

import contextlib
import copy
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .errors import (
    FilletfoldError,
    InternalError,
    ParameterError,
    SolverError,
    is_callers,
    one_line,
)
from .errors import stage as _stage
from .layout.arrange import arrange, default_size
from .layout.fabrication import cut_first, recut_solved
from .layout.making import making_paths
from .layout.net import cut_edges_for_nets
from .mesh import load_mesh
from .mesh.coarsen import Coarsening, coarse_target, coarsen_and_clean
from .mesh.polymesh import PolyMesh, check_corners, check_pattern_size, mesh_size
from .parameters import Parameters, parse_length, resolve_chord_tol, resolve_depth, sized
from .rounding.bend import FLOOR_RTOL, hold_floor, least_size_factor, share_floor_size
from .rounding.conical import conical_material_loss, is_conical
from .rounding.edges import EdgeRounding, clamp_radii, round_edges
from .rounding.material_loss import MaterialLoss, solve_material_loss
from .surface.assemble import locate_apices
from .surface.centres import face_piece_centres
from .surface.module import Modules, build_modules
from .surface.pattern import CreasePattern
from .surface.sampling import cone_sample_counts, unsampled_cones
from .tolerances import tol
from .units import AUTO_SIZE, ceil_digits
from .vertex.rescue import Rescue, rescue_vertices
from .vertex.sharpen import (
    kept_sharp,
    set_treatments,
    sharp_kind,
    sharpen_vertices,
    unround_between,
)
from .vertex.solution import VertexSolution
from .vertex.solve import (
    VertexResult,
    classify_vertices,
    saddle_reason,
    saddle_vertices,
    solve_apices,
    use_cone_axes,
)
from .vertex.state import VertexState

#: Rounds of :meth:`ApexStage.sharpen_cone_less`: cones no sampling can follow made sharp,
#: their neighbours solved again (whose new cones may be such in turn).
SAMPLING_ROUNDS = 3

#: The parameters an earlier design's stages depend on (:attr:`Job.key`): with the same mesh
#: and these, its rounding, frames and normals hold (its apices where the depth is the same).
STAGE_KEY = ("radius", "clamp", "material_loss", "max_loss", "coplanar_deg", "sharp")


@contextlib.contextmanager
def timed(timings: dict, name: str, since: float | None = None):
    """Within the block: ``timings[name]`` gets the seconds it took (from ``since``, a
    :func:`time.perf_counter` reading, when given)."""
    t = time.perf_counter() if since is None else since
    yield
    timings[name] = time.perf_counter() - t


@dataclass
class Job:
    """What every stage reads: the resolved parameters, the cleaned mesh and its lengths.

    Attributes
    ----------
    params : Parameters
        Resolved (:meth:`~filletfold.parameters.Parameters.resolved`).
    mesh : PolyMesh
        The cleaned mesh, about its centre when it lies far from the origin (``shift``).
    source : str
        What the mesh came from (path or type).
    clean_log : CleanLog
        The repairs made to the input (:func:`~filletfold.mesh.load_mesh`).
    shift : (3,) float or None
        Where the mesh's centre was (:func:`far_offset`): the outputs are moved back by it.
    input_key : tuple or None
        The input's identity (:func:`_input_key`), for a later design that takes the cleaned
        mesh over.
    key : tuple
        The mesh and the rounding parameters (:func:`_stage_key`): an earlier design's stages
        hold for this one when their key is the same.
    depths : (n_vertices,) float
        The cone depth at each vertex.
    kinds : frozenset of str
        The kinds of cone-less vertices kept sharp.
    size : float
        The mesh's size (:func:`~filletfold.mesh.polymesh.mesh_size`).
    floor, min_width : float
        The narrowest fillet kept, relative to its edge and absolute (0 with ``strict``).
    min_chord : float
        The shortest chord an arc is sampled at (no pattern edge under the certificate's
        limit; 0 with ``strict``).
    chord : float
        The chord tolerance, absolute.
    progress : callable
        ``progress(stage, done, total)``.
    coarsening : Coarsening or None
        What coarsening the mesh did (``params.faces`` or ``params.edge_length``), else None.
    bend : float
        The sheet material's bend floor in mesh units at the size given
        (:meth:`~filletfold.parameters.Parameters.bend_floor`), or at the default size once
        the edge stage settled it for the fillets (:func:`bend_floor`); 0 without a material.
    """

    params: Parameters
    mesh: PolyMesh
    source: str
    clean_log: Any
    shift: np.ndarray | None
    input_key: tuple | None
    key: tuple
    depths: np.ndarray
    kinds: frozenset
    size: float
    floor: float
    min_width: float
    min_chord: float
    chord: float
    progress: Any
    coarsening: Coarsening | None = None
    bend: float = 0.0


@dataclass
class Edges:
    """The edge stage's result: the edges' cylinders.

    Attributes
    ----------
    loss : MaterialLoss or None
        The consistent-material-loss solution, when the radii came from it.
    rounding : EdgeRounding
    conical : bool
        True when the radii came from a conical mesh's face offset (cone axes as normals).
    requested : (n_edges,) float
        The radius asked for on each edge (the cap with ``material_loss``).
    centres : (n_faces, 3) float
        The face pieces' centres.
    fitted : (n_edges,) float
        The radii after fitting to their limits, before any vertex changed them.
    creased : (n_edges,) bool
        Fillets made creases at the default size: too tight for the sheet material
        (:func:`bend_floor`).
    bend : float
        The bend floor the fillets hold (mesh units; 0: none).
    """

    loss: MaterialLoss | None
    rounding: EdgeRounding
    conical: bool
    requested: np.ndarray
    centres: np.ndarray
    fitted: np.ndarray
    creased: np.ndarray
    bend: float = 0.0


@dataclass
class Layout:
    """The layout stage's result: the crease pattern, the layout used (and why another was
    not), the fabrication figures, the pieces (empty when released) and the parameters with
    the default size settled (:func:`~filletfold.layout.arrange.settle_size`)."""

    pattern: CreasePattern
    layout: str
    note: str
    fabrication: dict
    pieces: list
    params: Parameters


@dataclass
class Stages:
    """What one design computed before its layout, for ``round_mesh(..., reuse=design)``.

    A later call on the same mesh with the same rounding parameters takes over the rounding,
    frames and vertex normals; vertices whose depth did not change keep their apex, and their
    modules are kept when their arcs' sample counts did not change either. Only the changed
    vertices are re-solved and rebuilt; the layout stage always runs.

    Attributes
    ----------
    key : tuple
        The mesh and the rounding parameters (radius, clamp, material loss, max loss,
        coplanar tolerance, sharp kinds) the stages belong to.
    loss : MaterialLoss or None
    conical : bool
        Whether the radii came from the conical-mesh offset (cone axes as normals).
    requested : (n_edges,) float
        The radii asked for.
    rounding : EdgeRounding
        The radii used (fitted to their limits, smaller where vertices were rescued).
    centres : (n_faces, 3) float
    frames : list of VertexFrame
    classified : VertexResult
        Classification and normals, before any apex.
    depths : (n_vertices,) float
    vertices : VertexResult
        The final per-vertex results.
    solved : list of (VertexFrame, apex or None, developed apex or None)
    samples : (n_edges,) int
        Points on each edge's arc (:meth:`~filletfold.rounding.edges.EdgeRounding.arc_points`).
    modules : list of list of Piece
        Each vertex's module pieces, before the layout.
    cleaned : tuple or None
        ``(input key, cleaned mesh, clean log, shift)`` of a :class:`PolyMesh` input (see
        :func:`_input_key`): a later call on the same input takes the cleaned mesh over instead
        of cleaning it again (None for other inputs: a file may change between calls).
    cuts : dict or None
        The samples each vertex's solves added where its solution dipped between the samples
        (:func:`~filletfold.vertex.solve.solve_apices`): a kept vertex solved again later
        starts with them, as it would in a fresh design.
    creased : (n_edges,) bool or None
        The fillets made creases for the sheet material (:attr:`Edges.creased`).
    bend : float
        The bend floor of the rounding (:attr:`Edges.bend`).
    """

    key: tuple
    loss: MaterialLoss | None
    conical: bool
    requested: np.ndarray
    rounding: EdgeRounding
    centres: np.ndarray
    frames: list
    classified: VertexResult
    depths: np.ndarray
    vertices: VertexResult
    solved: list
    samples: np.ndarray
    modules: list
    cleaned: tuple | None = None
    cuts: dict | None = None
    creased: np.ndarray | None = None
    bend: float = 0.0


def read_stage(mesh, params: Parameters, progress, earlier: Stages | None) -> Job:
    """Stage 1: the mesh read and cleaned (:func:`~filletfold.mesh.load_mesh`), or taken over
    from ``earlier`` when it is the same :class:`PolyMesh` cleaned the same way; moved about
    its centre when it lies far from the origin (:func:`far_offset`)."""
    coarse = (params.faces, params.edge_length)
    input_key = _input_key(mesh, params.coplanar_deg, params.strict, coarse)
    cleaned = None if earlier is None else earlier.cleaned
    if input_key is not None and cleaned is not None and cleaned[0] == input_key:
        _, pm, clean_log, shift, coarsening = cleaned  # the same input, cleaned the same way
    else:
        _stage("reading the mesh")
        pm, clean_log = load_mesh(
            mesh, coplanar_deg=params.coplanar_deg, strict=params.strict,
            max_corners=params.max_corners,
        )  # fmt: skip
        coarsening, target = None, coarse_target(pm, params.faces, params.edge_length)
        if target is not None:  # decimated, then cleaned as any input (repairs kept)
            _stage("coarsening the mesh")
            pm, repairs, coarsening = coarsen_and_clean(
                pm, target, coplanar_deg=params.coplanar_deg, strict=params.strict
            )
            clean_log.repairs.extend(repairs)
        check_corners(pm, params.max_corners)  # before anything is solved
        shift = far_offset(pm.vertices)
        if shift is not None:  # far from the origin: compute about the centre, shift back later
            pm = PolyMesh(pm.vertices - shift, pm.faces)
    check_pattern_size(pm, params.samples, params.max_points)  # before anything is solved
    size, strict = mesh_size(pm), params.strict
    params = sized(params, float(np.ptp(pm.vertices, axis=0).max(initial=0.0)), pm.mean_edge_length)
    bend = params.bend_floor()
    return Job(
        params=params,
        mesh=pm,
        source=str(mesh) if isinstance(mesh, str | Path) else type(mesh).__name__,
        clean_log=clean_log,
        shift=shift,
        input_key=input_key,
        coarsening=coarsening,
        key=_stage_key(pm, *(getattr(params, name) for name in STAGE_KEY), bend),
        depths=resolve_depth(params.depth, pm.mean_edge_length, pm.n_vertices),
        kinds=params.sharp_kinds(),
        size=size,
        floor=0.0 if strict else tol.fillet_floor,
        min_width=0.0 if strict else tol.min_fillet * size,
        min_chord=0.0 if strict else 2 * tol.ruling * size,
        chord=resolve_chord_tol(params.chord_tol, pm.mean_edge_length),
        progress=progress,
        bend=bend,
    )


def reusable_stages(job: Job, earlier: Stages | None) -> Stages | None:
    """``earlier`` when its results hold for ``job``: the same mesh and rounding parameters,
    and, if it has sharp vertices, the same depths (a new depth may give a sharp vertex its
    cone, so the sharp vertices are chosen again); else None."""
    if earlier is None or earlier.key != job.key:
        return None
    if any(f.sharp for f in earlier.frames) and not np.array_equal(earlier.depths, job.depths):
        return None
    return earlier


def edge_stage(job: Job, st: Stages | None) -> Edges:
    """Stage 2 (sec. 2.1, 4): the radii -- given, fitted to their limits, or from the
    material-loss programme -- and each edge's cylinder; taken over from ``st`` when given."""
    _stage("rounding the edges")
    if st is not None:
        job.bend = st.bend  # the floor the default size settled, as the stages were made
        return Edges(
            st.loss, st.rounding, st.conical, st.requested, st.centres,
            st.rounding.radius.copy(), st.creased, st.bend,
        )  # fmt: skip
    p, pm = job.params, job.mesh
    ref = pm.mean_edge_length
    loss, conical, floor, min_width = None, False, job.floor, job.min_width
    given = parse_length(p.radius, ref, "radius", count=pm.n_edges)  # a length or (n_edges,)
    requested = np.broadcast_to(np.asarray(given, dtype=float), (pm.n_edges,)).copy()
    if p.material_loss:
        cap = None if p.max_loss is None else float(parse_length(p.max_loss, ref, "max loss"))
        developable = np.all(
            np.abs(pm.vertex_angle_sum[~pm.is_boundary_vertex] - 2 * np.pi) < tol.developable
        )
        conical = not developable and is_conical(pm)
        if conical:
            loss, _ = conical_material_loss(
                pm, max_loss=cap, max_radius=given, flat_deg=p.coplanar_deg
            )
        else:
            loss = solve_material_loss(pm, max_loss=cap, max_radius=given, flat_deg=p.coplanar_deg)
        if not loss.ok:
            raise SolverError(loss.message)
        r = loss.edge_radius
        floor = min_width = 0.0  # consistent losses need every edge rounded
    else:
        r = given
        if p.clamp:
            r = clamp_radii(pm, r, flat_deg=p.coplanar_deg)
    r, creased = bend_floor(job, r)
    rounding = round_edges(pm, r, flat_deg=p.coplanar_deg, floor=floor, min_width=min_width)
    centres = face_piece_centres(pm, rounding)
    return Edges(
        loss, rounding, conical, requested, centres, rounding.radius.copy(), creased, job.bend
    )


def bend_floor(job: Job, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The fitted radii with the sheet material's bend floor held
    (:mod:`~filletfold.rounding.bend`), and the edges made creases for it ((n_edges,) bool).

    At the default size, the size first grows until all but the tightest
    :data:`~filletfold.rounding.bend.CREASE_SHARE` of the fillets' length hold the floor
    (:func:`~filletfold.rounding.bend.share_floor_size`, at least the labels' and the least
    size: :func:`~filletfold.layout.arrange.default_size`), and ``job.bend`` is the floor in
    mesh units at that size. At that size, or at the size given, every fillet below the floor
    is raised to it where its edge's limit allows, and the others become creases (radius 0, a
    straight crease folded by the dihedral). Unchanged without a material.

    With ``strict``, or with the material-loss programme's radii (consistent only as they are:
    never raised or creased), nothing is creased: at the default size the size grows until
    every fillet holds the floor, and at a size given a fillet that cannot is refused, naming
    the edges and the least size at which they can."""
    p, pm, floor = job.params, job.mesh, job.bend
    none = np.zeros(pm.n_edges, dtype=bool)
    material = p.sheet_material()
    auto = material is not None and p.size == AUTO_SIZE
    if floor <= 0 and not auto:
        return radius, none
    radius = np.broadcast_to(np.asarray(radius, dtype=float), (pm.n_edges,)).copy()
    if floor <= 0 and not (p.material_loss or p.strict):
        extent = float(np.ptp(pm.vertices, axis=0).max(initial=0.0))
        need = share_floor_size(extent, material.bend_floor_mm(), radius, pm.edge_length)
        if need is None:
            return radius, none
        mm, _ = default_size(extent, pm.mean_edge_length, None, need)
        job.bend = floor = material.bend_floor_mm() * extent / mm
    if floor <= 0:
        return radius, none
    if not (p.material_loss or p.strict):  # too tight and too narrow to widen: a crease
        held, short = hold_floor(pm, radius, floor)
        return np.where(short, 0.0, held), short
    mm = p.mm_per_unit
    if p.material_loss:
        held, short = radius, (radius > 0) & (radius < floor * (1 - FLOOR_RTOL))
        factor = float(floor / radius[short].min()) if short.any() else 1.0
    else:
        held, short = hold_floor(pm, radius, floor)
        factor = least_size_factor(pm, radius, floor) if short.any() else 1.0
    if short.any():
        size = float(np.ptp(pm.vertices, axis=0).max()) * mm
        edges = np.flatnonzero(short)
        listed = ", ".join(map(str, edges[:6])) + (", ..." if len(edges) > 6 else "")
        least = f"{ceil_digits(size * factor):g}mm" if np.isfinite(factor) else "none"
        raise ParameterError(
            f"{material.name} bends no tighter than {material.bend_floor_mm():g} mm (its least "
            f"inner radius plus half its thickness), but {len(edges)} edge(s) ({listed}) cannot "
            f"hold a fillet that wide at --size {size:.4g}mm; the least size that can: {least}",
            name="size",
        )
    return held, none


def normal_stage(job: Job, edges: Edges, st: Stages | None) -> VertexState:
    """Stage 3a (sec. 3.1): the vertex frames, classification and normals, every vertex
    classified once (taken over from ``st`` when given), as the state the apex stage starts
    from (:class:`~filletfold.vertex.state.VertexState`: ``classified`` the classification
    before any apex, ``res`` its copy the apex stage fills in). With saddles among the sharp
    kinds, the saddles are known before any frame
    (:func:`~filletfold.vertex.solve.saddle_vertices`) and made sharp from the start, their
    shared edges unrounded, so that each frame is built once with the neighbours' sides
    toward them conical."""
    _stage("vertex normals")
    pm, p = job.mesh, job.params
    state = VertexState(
        mesh=pm, rounding=edges.rounding, centres=edges.centres, frames=[],
        res=VertexResult.empty(pm.n_vertices), depths=job.depths, face_centres=face_piece_centres,
        flat_deg=p.coplanar_deg, floor=job.floor, min_width=job.min_width, size=job.size,
        progress=job.progress, bend_floor=job.bend,
    )  # fmt: skip
    if st is not None:
        # the earlier design's stages stay as they were: the apex stage replaces the frames
        # and classification of the vertices it classifies again in lists of this design's
        state.frames, state.classified = list(st.frames), copy.deepcopy(st.classified)
        state.res = copy.deepcopy(state.classified)
        return state
    classified = state.res
    saddles = saddle_vertices(pm, state.rounding) if "saddle" in job.kinds else None
    if saddles is not None and saddles.any():
        state.rounding, state.centres, _ = unround_between(state, saddles)
    else:
        saddles = None
    state.frames = classify_vertices(pm, state.rounding, classified, sharp=saddles)
    made_sharp = [] if saddles is None else np.flatnonzero(saddles).tolist()
    for u in made_sharp:  # a saddle stays one, though its edges may all be unrounded now
        classified.kind[u] = classified.status[u] = "saddle"
        classified.reason[u] = saddle_reason(classified.normal_bound[u])
    if edges.conical:
        use_cone_axes(pm, state.frames, classified)
    state.classified, state.res = classified, copy.deepcopy(classified)
    for u in made_sharp:
        state.res.reason[u] = kept_sharp(state.res.reason[u])
    return state


def apex_stage(job: Job, state: VertexState, st: Stages | None) -> VertexSolution:
    """Stage 3b (sec. 2.4, 3.2): every vertex's apex, the rescue of the infeasible ones, the
    cone-less vertices made sharp (:class:`ApexStage`), from the normal stage's state."""
    return ApexStage(job, state, st).run()


class ApexStage:
    """The apex stage, from the vertex normals to the :class:`VertexSolution`.

    :meth:`run` solves every pending vertex's apex (those of a reused design's vertices whose
    depth did not change are kept), then rescues the infeasible ones, then makes the cone-less
    vertices of the sharp kinds sharp and solves their neighbours again
    (:func:`~filletfold.vertex.sharpen.sharpen_vertices`). With ``infeasible`` among the kinds
    (and without ``material_loss``), a cone that no sampling of its arcs at ``arc_step``
    (degrees) with chords of at least ``min_chord`` can follow
    (:func:`~filletfold.surface.sampling.unsampled_cones`) is infeasible too, and made sharp;
    up to :data:`SAMPLING_ROUNDS` times, as its neighbours' new cones may be so in turn.
    All of it works on one :class:`~filletfold.vertex.state.VertexState`, updated in place.
    """

    def __init__(self, job: Job, state: VertexState, st: Stages | None):
        self.job, self.state, self.st = job, state, st
        self.kept: set = set()  # the vertices whose results are taken over from ``st``
        self.rescue = Rescue()
        self.needs: dict = {}  # each cone's sampling needs, measured once

    def run(self) -> VertexSolution:
        pending = self.take_kept()
        _stage("apices")
        # thorough even with the rescue to come: a quick solve calls vertices infeasible that
        # are not, and the rescue would shrink their radii for nothing; but without the other
        # starts and the linear programmes when the rescue follows (they pay only there)
        p, state = self.job.params, self.state
        state.apices = self.solve(pending, lp=not (p.fit_vertices and not p.material_loss))
        if not p.material_loss and any(state.res.status[u] == "infeasible" for u in pending):
            self.rescue = rescue_vertices(state, apply=p.fit_vertices, vertices=pending)
            self.kept -= self.rescue.resolved
        self.sharpen_cone_less()
        return self.solution()

    def take_kept(self) -> list:
        """The vertices to solve: those not classified cone-less, less those whose depth did
        not change since the reused design (their results are taken over)."""
        state, st = self.state, self.st
        n, res = len(state.frames), state.res
        pending = [u for u in range(n) if res.status[u] == ""]
        if st is None:
            return pending
        self.kept = {u for u in range(n) if st.depths[u] == state.depths[u]}
        res.take(st.vertices, sorted(self.kept))
        if st.cuts:  # a kept vertex solved again starts as in a fresh design
            state.cuts.update({u: st.cuts[u] for u in sorted(self.kept) if u in st.cuts})
        return [u for u in pending if u not in self.kept]

    def solve(self, pending: list, lp: bool = True) -> dict:
        """:func:`~filletfold.vertex.solve.solve_apices` of the vertices ``pending``; when it
        fails unforeseen, the vertices are solved one by one and a vertex whose solve fails is
        infeasible, with the failure as its reason (a failure is data, not the end of the
        design)."""
        state, res = self.state, self.state.res

        def solve(vertices, progress=None):
            return solve_apices(
                state.frames, state.depths, res, state.centres, progress, vertices=vertices,
                size=state.size, thorough=True, lp=lp, cuts=state.cuts, work=state.work,
            )  # fmt: skip

        try:
            return solve(pending, state.progress)
        except FilletfoldError:
            raise
        except Exception as exc:
            if is_callers(exc):
                raise
            out = {}
            for u in pending:
                res.status[u] = ""
                try:
                    out.update(solve([u]))
                except FilletfoldError:
                    raise
                except Exception as exc:
                    res.status[u] = "infeasible"
                    res.reason[u] = f"the apex solver failed: {one_line(exc)}"
                    out[u] = (None, None)
            return out

    def sharpen_cone_less(self) -> None:
        """The cone-less vertices of the sharp kinds made sharp, their neighbours solved again;
        cones no sampling can follow made infeasible first (see the class)."""
        kinds, state = self.job.kinds, self.state
        check = set(state.apices)  # the cones solved here (those kept were checked then)
        for _ in range(SAMPLING_ROUNDS):
            if "infeasible" in kinds and check and not self.job.params.material_loss:
                # a cone no sampling can follow (its facets would fold past the arc step, or
                # its arcs need sliver chords) is infeasible: sharp, its neighbours solved
                # again (not with the material-loss radii, which fold one uncut sheet as they
                # are)
                self.drop_unsampled(check)
            already = state.sharp_frames()
            if not kinds or not any(
                sharp_kind(s) in kinds and not a
                for s, a in zip(state.res.status, already, strict=True)
            ):
                break
            _stage("sharp vertices")
            sharpening = sharpen_vertices(state, kinds)
            self.kept -= sharpening.resolved | set(np.flatnonzero(sharpening.sharp).tolist())
            check = {u for u in sharpening.resolved if u in state.apices}

    def drop_unsampled(self, check: set) -> None:
        """The cones among ``check`` that no sampling of their arcs can follow
        (:func:`~filletfold.surface.sampling.unsampled_cones`) made infeasible."""
        job, state, res = self.job, self.state, self.state.res
        apices = state.apices
        cones = [(state.frames[u], *apices[u]) for u in sorted(check) if apices[u][0] is not None]
        unsampled = unsampled_cones(
            cones, state.centres, job.params.arc_step, job.min_chord, self.needs
        )
        for u, why in unsampled.items():
            res.status[u], res.reason[u], apices[u] = "infeasible", why, (None, None)
            res.apex[u], res.apex_developed[u] = np.nan, np.nan  # no cone: no apex
            res.depth[u], res.margin[u], res.solver[u] = np.nan, np.nan, ""

    def solution(self) -> VertexSolution:
        state, st = self.state, self.st
        solved = [
            st.solved[u] if u in self.kept else (frame, *state.apices.get(u, (None, None)))
            for u, frame in enumerate(state.frames)
        ]
        set_treatments(state.res, state.sharp_frames())
        return VertexSolution(
            rounding=state.rounding,
            centres=state.centres,
            frames=state.frames,
            classified=state.classified,
            res=state.res,
            solved=solved,
            kept=self.kept,
            rescue=self.rescue,
            cuts=state.cuts,
            needs=self.needs,
            ring_closed=[f.ring.closed for f in state.frames],
            work=state.work,
        )


def module_stage(job: Job, sol: VertexSolution, st: Stages | None) -> Modules:
    """Stage 4 (eq. 1): each vertex's module -- the creases, its cone, its halves of the
    cylinders and its shares of the faces -- on arcs sampled finely enough for the cylinders
    and the cones (:func:`~filletfold.surface.module.build_modules`); a vertex of ``st`` whose
    apex and arcs' samples did not change keeps its module."""
    _stage("vertex modules")
    pm, p = job.mesh, job.params
    points = sol.rounding.arc_points(
        p.samples,
        p.arc_step,
        min_chord=job.min_chord,
        chord_tol=job.chord,
        radius_scale=np.where(conical_sides(sol.frames, pm.n_edges), 2.0, 1.0),
    )
    # a cone's normal may turn faster than its arc: more points where it does
    points = np.maximum(
        points, cone_sample_counts(sol.solved, sol.centres, pm.n_edges, p.arc_step, sol.needs)
    )
    sol.needs.clear()  # its last use: it holds every cone's frame, which the layout may not need
    if cut_first(p, pm.n_vertices):  # built where the nets will cut them: not built twice
        sol.solved = list(sol.solved)
        for u, entry in recut_solved(pm, sol.rounding, sol.solved, cut_edges_for_nets(pm)).items():
            sol.solved[u] = entry
    same_samples = st is not None and np.array_equal(st.samples, points)
    modules = [
        st.modules[u] if same_samples and u in sol.kept else None for u in range(len(sol.solved))
    ]
    todo = [u for u, module in enumerate(modules) if module is None]
    built = _build_modules(pm, [sol.solved[u] for u in todo], sol.centres, points, job.progress)
    for u, module in zip(todo, built, strict=True):
        modules[u] = module
    return Modules(points, modules)


def stages_of(job: Job, edges: Edges, sol: VertexSolution, mods: Modules) -> Stages:
    """What a later ``round_mesh(..., reuse=design)`` takes over from this design."""
    return Stages(
        key=job.key,
        loss=edges.loss,
        conical=edges.conical,
        requested=edges.requested,
        rounding=sol.rounding,
        centres=sol.centres,
        frames=sol.frames,
        classified=sol.classified,
        depths=job.depths,
        vertices=sol.res,
        solved=sol.solved,
        samples=mods.points,
        modules=mods.modules,
        cleaned=None
        if job.input_key is None
        else (job.input_key, job.mesh, job.clean_log, job.shift, job.coarsening),
        cuts=sol.cuts,
        creased=edges.creased,
        bend=edges.bend,
    )


def layout_stage(
    job: Job, sol: VertexSolution, mods: Modules, release: bool, timings: dict
) -> Layout:
    """Stage 5: the modules' pieces laid out (:func:`~filletfold.layout.arrange.arrange`) into
    the crease pattern, its cones located and creased along their rulings to sharp edges.

    With ``release``, what the layout does not need goes before it runs: the frames, the
    classification and the solutions of ``sol`` and the modules of ``mods`` (unless a net
    layout rebuilds from them), and the pieces once the pattern holds their points, which
    lowers the peak memory of a large design by about a third."""
    p, pm = job.params, job.mesh
    pieces = [piece for module in mods.modules for piece in module]
    if release and p.layout not in ("net", "auto"):
        # the layout needs neither the frames nor the modules (nets do: net_pieces rebuilds)
        sol.frames = sol.classified = sol.solved = mods.modules = None
    _stage("layout")
    pattern, layout_used, layout_note, fab, params = arrange(
        pm, sol, mods, pieces, p, stage=_stage, timings=timings, release_pieces=release
    )
    locate_apices(pattern, sol.res)
    pattern.crease_sharp_rulings(  # a cone is creased along its rulings to sharp edges
        sol.res.apex,
        pm.vertices,
        pm.edges,
        ~(sol.rounding.radius > 0),
        tol.closure * job.size,  # the apex and the edges' points, to round-off of the size
    )
    material = params.sheet_material()
    if material is not None and params.scale is not None:  # reliefs and kerfs, at its size
        pattern.annotations.making = making_paths(
            pattern, pm, sol.rounding, sol.res.apex, material, params.mm_per_unit
        )
    return Layout(pattern, layout_used, layout_note, fab, pieces, params)


def _build_modules(pm: PolyMesh, solved: list, centres, points, progress) -> list:
    """:func:`build_modules` of ``solved`` (frame, apex, developed apex) per vertex; when it
    fails unforeseen, the modules are built one by one to name the vertex whose module fails."""
    frames, apices, developed = ([x[k] for x in solved] for k in range(3))
    try:
        return build_modules(pm, frames, centres, points, apices, developed, progress)
    except FilletfoldError:
        raise
    except Exception as exc:
        if is_callers(exc):
            raise
        out = []
        for frame, apex, v in solved:
            try:
                out += build_modules(pm, [frame], centres, points, [apex], [v])
            except FilletfoldError:
                raise
            except Exception as exc:
                raise InternalError(
                    f"vertex modules failed at vertex {frame.vertex}: {one_line(exc)} "
                    "(run with --debug for the traceback)",
                    stage="vertex modules",
                    element=f"vertex {frame.vertex}",
                ) from exc
        raise  # every module built alone: the failure was in the batch (re-raise it)


def _input_key(mesh, coplanar_deg, strict, coarse=None) -> tuple | None:
    """Hashable identity of a :func:`round_mesh` input and the options its cleaning (and
    coarsening) depends on, for a :class:`PolyMesh` (its vertices and faces by their bytes);
    None otherwise."""
    if not isinstance(mesh, PolyMesh):
        return None
    return (*_mesh_key(mesh), repr(coplanar_deg), strict, repr(coarse))


def _stage_key(pm: PolyMesh, *params) -> tuple:
    """Hashable identity of a mesh and parameters (arrays compared by their bytes)."""

    def plain(x):
        if isinstance(x, dict):
            return tuple(sorted((str(k), plain(v)) for k, v in x.items()))
        if isinstance(x, np.ndarray | list | tuple):
            a = np.asarray(x, dtype=float)
            return (a.shape, a.tobytes())
        return repr(x)

    return (*_mesh_key(pm), *(plain(p) for p in params))


def _mesh_key(pm: PolyMesh) -> tuple:
    """A mesh's vertices and faces (each face's first corner and the corners' vertices, in
    order) by their bytes."""
    return (
        pm.vertices.tobytes(),
        pm.face_start.astype(np.int64).tobytes(),
        pm.halfedge_from.astype(np.int64).tobytes(),
    )


def conical_sides(frames, n_edges: int) -> np.ndarray:
    """(n_edges,) bool: the edges some vertex frame rounds by a conical fillet."""
    out = np.zeros(n_edges, dtype=bool)
    edges = [side.edge for f in frames for side in f.sides if side.S is not None]
    out[np.asarray(edges, dtype=np.int64)] = True
    return out


def far_offset(vertices: np.ndarray) -> np.ndarray | None:
    """The centre of the bounding box of ``vertices`` (n, 3) when it lies further from the
    origin than the box's diagonal, else None.

    A mesh far from the origin (a model in survey coordinates, a fuzzed copy moved by 1e6)
    loses digits in every difference of two points; its design is computed about this centre
    and moved back (the outputs are where the mesh is).
    """
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    centre = 0.5 * (lo + hi)
    if np.linalg.norm(centre) <= np.linalg.norm(hi - lo):
        return None
    return centre
