"""The pipeline: mesh + parameters -> :class:`Design` (the one orchestrator).

Stages: clean the mesh, round the edges, classify the vertices and find their normals, find the
developed and spatial apices, build the vertex modules (creases, cones, cylinders, face pieces),
lay them out, and derive the crease pattern.
"""

from __future__ import annotations

import copy
import dataclasses
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .defaults import (
    DEFAULT_DEPTH,
)
from .errors import (
    FilletfoldError,
    InternalError,
    ParameterError,
    SolverError,
    callers_progress,
    is_callers,
    named_stages,
    one_line,
)
from .errors import stage as _stage
from .layout.arrange import arrange
from .mesh import load_mesh
from .mesh.polymesh import PolyMesh, mesh_size
from .parameters import Parameters, resolve_chord_tol
from .rounding.conical import conical_material_loss, is_conical
from .rounding.edges import EdgeRounding, clamp_radii, round_edges
from .rounding.material_loss import MaterialLoss, solve_material_loss
from .surface.assemble import locate_apices
from .surface.centres import face_piece_centres
from .surface.module import build_modules
from .surface.pattern import CreasePattern
from .surface.sampling import cone_sample_counts, unsampled_cones
from .tolerances import tol
from .vertex.rescue import Rescue, rescue_vertices
from .vertex.sharpen import (
    kept_sharp,
    set_treatments,
    sharp_kind,
    sharpen_vertices,
    unround_between,
)
from .vertex.solve import (
    STATUSES,
    VertexResult,
    classify_vertices,
    saddle_reason,
    saddle_vertices,
    solve_apices,
    use_cone_axes,
)


def parse_length(value, reference: float, name: str, *, count: int | None = None) -> np.ndarray:
    """Absolute length(s) from a number, a ``"12%"`` string (of ``reference``) or an array.

    Parameters
    ----------
    value : float, str or array_like
    reference : float
        The length that 100% stands for (the mean edge length).
    name : str
        Parameter name, for error messages.
    count : int, optional
        Expected length of a per-element array.

    Returns
    -------
    float or (count,) float array
    """
    if isinstance(value, str):
        text = value.strip()
        try:
            if text.endswith("%"):
                out = float(text[:-1]) / 100.0 * reference
            else:
                out = float(text)
        except ValueError:
            raise ParameterError(
                f"{name} must be a number or a percentage like '10%', got {value!r}", name=name
            ) from None
    else:
        out = np.asarray(value, dtype=float)
        if out.ndim == 0:
            out = float(out)
        elif count is not None and out.shape != (count,):
            raise ParameterError(
                f"per-element {name} must have shape ({count},), got {out.shape}", name=name
            )
    arr = np.atleast_1d(out)
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"{name} must be finite, got {value!r}", name=name)
    if np.any(arr <= 0):
        raise ParameterError(f"{name} must be positive, got {value!r}", name=name)
    return out


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
        coplanar tolerance) the stages belong to.
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


def _input_key(mesh, coplanar_deg, strict) -> tuple | None:
    """Hashable identity of a :func:`round_mesh` input and the options its cleaning depends
    on, for a :class:`PolyMesh` (its vertices and faces by their bytes); None otherwise."""
    if not isinstance(mesh, PolyMesh):
        return None
    faces = (mesh.face_start.astype(np.int64), mesh.halfedge_from.astype(np.int64))
    return (mesh.vertices.tobytes(), *(f.tobytes() for f in faces), repr(coplanar_deg), strict)


def _stage_key(pm: PolyMesh, *params) -> tuple:
    """Hashable identity of a mesh and parameters (arrays compared by their bytes)."""

    def plain(x):
        if isinstance(x, dict):
            return tuple(sorted((str(k), plain(v)) for k, v in x.items()))
        if isinstance(x, np.ndarray | list | tuple):
            a = np.asarray(x, dtype=float)
            return (a.shape, a.tobytes())
        return repr(x)

    # the faces: each face's first corner and the corners' vertices, in order
    faces = (pm.face_start.astype(np.int64).tobytes(), pm.halfedge_from.astype(np.int64).tobytes())
    return (pm.vertices.tobytes(), faces, *(plain(p) for p in params))


@dataclass
class Design:
    """A curved-crease design: the cleaned mesh, its rounding, vertex results and pattern.

    Attributes
    ----------
    mesh : PolyMesh
    params : Parameters
    rounding : EdgeRounding
    vertices : VertexResult
    pattern : CreasePattern
    pieces : list of Piece
        Every vertex module's pieces, as made before the layout (empty when
        :func:`round_mesh` ran with ``keep_stages=False``: they go once the pattern is laid
        out, which holds their points again).
    timings : dict of str to float
        Seconds per stage (written to ``timings.json``, not to the report).
    source : str
        What the mesh came from (path or example name).
    material_loss : MaterialLoss or None
        The consistent-material-loss solution, when radii came from it.
    layout : str
        ``"modules"`` (one piece per vertex) or ``"sheet"`` (one glued sheet).
    layout_note : str
        Why the sheet could not be made, when it was tried and not made.
    fabrication : dict
        Counts of cut borders, glue tabs placed, tabs at a reduced height, and cut borders
        left without a tab.
    stages : Stages or None
        Intermediate results a later ``round_mesh(..., reuse=design)`` takes over.
    repairs : list of Repair
        The repairs made to the input mesh (:mod:`filletfold.mesh.repair`).
    fitting : dict
        ``radius_requested`` (n_edges,) float, the radii asked for (0 at boundary and flat
        edges); ``fitted_radius`` (n_edges,) float, the radii after fitting to the limits and
        before any rescue; ``reduced`` (k,) int, the edges whose radius was reduced to fit its
        limit; ``sharp`` (k,) int, the edges left sharp (their fillet would be narrower than
        ``tol.fillet_floor`` of the edge); ``rescued`` (dict vertex -> factor), the vertices
        whose edges' radii were scaled by ``factor`` to make their cone feasible (applied when
        ``rescue_applied``, else only reported in their reason); ``sharpened``, the vertices
        no radius rescued whose edges were left sharp instead (sharp vertices).
    """

    mesh: PolyMesh
    params: Parameters
    rounding: EdgeRounding
    vertices: VertexResult
    pattern: CreasePattern
    pieces: list
    timings: dict = field(default_factory=dict)
    source: str = ""
    material_loss: MaterialLoss | None = None
    layout: str = "modules"
    layout_note: str = ""
    fabrication: dict = field(default_factory=dict)
    stages: Stages | None = field(default=None, repr=False, compare=False)
    repairs: list = field(default_factory=list)
    fitting: dict = field(default_factory=dict)
    certificate: object = None

    @property
    def vertex_status(self) -> list:
        """Status of every mesh vertex (see :data:`STATUSES`)."""
        return self.vertices.status

    def status_counts(self) -> dict:
        """Number of vertices per status, in :data:`STATUSES` order."""
        return {s: self.vertices.status.count(s) for s in STATUSES}

    def report(self) -> dict:
        """The content of ``report.json``."""
        from .export.outputs import design_report

        return design_report(self)

    def summary(self) -> str:
        """A short plain-text summary."""
        from .export.outputs import design_summary

        return design_summary(self)

    def export(self, folder, **options) -> list[Path]:
        """Write the design's files into ``folder`` atomically (all of them or none):
        :func:`~filletfold.export.outputs.export_design` of this design.

        Parameters
        ----------
        folder : str or Path
        **options
            ``title``, ``formats``, ``units``, ``scale``, ``page``, ``preset``, ``view``: those of
            :func:`~filletfold.export.outputs.export_design` (the same defaults).

        Returns
        -------
        list of Path
            The files written.
        """
        from .export.outputs import export_design

        return export_design(self, folder, **options)


def _resolve_depth(depth, reference: float, n: int) -> np.ndarray:
    if isinstance(depth, dict):
        base = parse_length(depth.get("default", DEFAULT_DEPTH), reference, "depth")
        out = np.full(n, float(base))
        for k, val in depth.items():
            if k == "default":
                continue
            if not (0 <= int(k) < n):
                raise ParameterError(
                    f"depth given for vertex {k}, which does not exist", name="depth"
                )
            out[int(k)] = float(parse_length(val, reference, "depth"))
        return out
    d = parse_length(depth, reference, "depth", count=n)
    return np.broadcast_to(np.asarray(d, dtype=float), (n,)).copy()


def _round(pm: PolyMesh, radius, clamp, material_loss, max_loss, coplanar_deg, floor, min_width):
    """Radii (given, fitted to their limits, or from the material-loss programme) and the edge
    rounding.

    Returns
    -------
    loss : MaterialLoss or None
    rounding : EdgeRounding
    conical : bool
        True when the radii came from a conical mesh's face offset.
    requested : (n_edges,) float
        The radius asked for on each edge (the cap with ``material_loss``).
    """
    ref = pm.mean_edge_length
    loss, conical = None, False
    requested = np.broadcast_to(
        np.asarray(parse_length(radius, ref, "radius", count=pm.n_edges), dtype=float),
        (pm.n_edges,),
    ).copy()
    if material_loss:
        cap = None if max_loss is None else float(parse_length(max_loss, ref, "max loss"))
        developable = np.all(
            np.abs(pm.vertex_angle_sum[~pm.is_boundary_vertex] - 2 * np.pi) < tol.developable
        )
        conical = not developable and is_conical(pm)
        r_cap = parse_length(radius, ref, "radius", count=pm.n_edges)
        if conical:
            loss, _ = conical_material_loss(
                pm, max_loss=cap, max_radius=r_cap, flat_deg=coplanar_deg
            )
        else:
            loss = solve_material_loss(pm, max_loss=cap, max_radius=r_cap, flat_deg=coplanar_deg)
        if not loss.ok:
            raise SolverError(loss.message)
        r = loss.edge_radius
    else:
        r = parse_length(radius, ref, "radius", count=pm.n_edges)
        if clamp:
            r = clamp_radii(pm, r, flat_deg=coplanar_deg)
    if material_loss:  # consistent losses need every edge rounded
        floor = min_width = 0.0
    rounding = round_edges(pm, r, flat_deg=coplanar_deg, floor=floor, min_width=min_width)
    return loss, rounding, conical, requested


@named_stages("reading the mesh")
def round_mesh(
    mesh,
    params: Parameters | None = None,
    *,
    progress=None,
    reuse: Design | None = None,
    keep_stages: bool = True,
    certify: bool = True,
    **options,
) -> Design:
    """Turn a polyhedral mesh into its curved-crease rounded design.

    Parameters
    ----------
    mesh : PolyMesh, str, Path or (vertices, faces)
        A mesh, a file path (OBJ, OFF, PLY, STL, glTF), a built-in example name, or arrays.
    params : Parameters, optional
        The design's parameters (default: :class:`~filletfold.parameters.Parameters`'s
        defaults).
    **options
        Fields of :class:`~filletfold.parameters.Parameters` that replace those of ``params``
        (``radius="5%"``, ``depth=0.3``, ``samples``, ``arc_step``, ``chord_tol``, ``clamp``,
        ``material_loss``, ``max_loss``, ``layout``, ``coplanar_deg``, ``fit_vertices``,
        ``strict``, ``sharp``, ``sheet``, ``units``, ``scale``, ``tabs``, ``nest``).
    progress : callable, optional
        ``progress(stage, done, total)`` called during long stages.
    reuse : Design, optional
        An earlier design of the same mesh: when the rounding parameters are the same, its
        rounding, frames and normals are taken over and only the vertices whose depth changed
        are re-solved and rebuilt (see :class:`Stages`); when ``mesh`` is a :class:`PolyMesh`
        equal to the earlier one (same coplanar tolerance and ``strict``), its cleaned mesh is
        taken over whatever the other parameters. The result is the same as without.
    certify : bool
        Measure the design's invariants (:func:`filletfold.check.certify_design`) into
        ``design.certificate`` (about 5 % of the time; the browser app skips it).
    keep_stages : bool
        Keep what ``reuse`` needs in ``design.stages`` (the default). False lets the vertex
        frames and modules go as soon as the layout no longer needs them, and the pieces once
        the pattern is laid out (``design.pieces`` is then empty), which lowers the peak
        memory of a large design by about a third (the command line does so: it never reuses).

    Returns
    -------
    Design
        With ``design.params`` the parameters resolved
        (:meth:`~filletfold.parameters.Parameters.resolved`).

    Raises
    ------
    MeshError
        Unreadable or invalid mesh.
    ParameterError
        An unknown or invalid parameter (a radius over an edge's limit names the edge).
    SolverError
        With ``material_loss``: the programme has no solution with positive losses (the
        message names the binding vertices and edges); with ``layout="sheet"``: the modules do
        not fit into one sheet.
    """
    timings = {}
    t0 = time.perf_counter()
    given = (params if params is not None else Parameters()).replace(**options)
    given.check()
    params = given.resolved()
    progress = callers_progress(progress)
    strict, kinds = params.strict, params.sharp_kinds()
    floor = 0.0 if strict else tol.fillet_floor
    radius, depth, coplanar_deg = params.radius, params.depth, params.coplanar_deg
    material_loss, max_loss, layout = params.material_loss, params.max_loss, params.layout
    source = str(mesh) if isinstance(mesh, str | Path) else type(mesh).__name__
    input_key = _input_key(mesh, coplanar_deg, strict)
    cleaned = reuse.stages.cleaned if reuse is not None and reuse.stages is not None else None
    if input_key is not None and cleaned is not None and cleaned[0] == input_key:
        _, pm, clean_log, shift = cleaned  # the same input, cleaned the same way: take it over
    else:
        _stage("reading the mesh")
        pm, clean_log = load_mesh(mesh, coplanar_deg=coplanar_deg, strict=strict)
        shift = far_offset(pm.vertices)
        if shift is not None:  # far from the origin: compute about the centre, shift back later
            pm = PolyMesh(pm.vertices - shift, pm.faces)
    timings["read"] = time.perf_counter() - t0
    ref = pm.mean_edge_length
    size = mesh_size(pm)
    chord = resolve_chord_tol(params.chord_tol, ref)
    min_width = 0.0 if strict else tol.min_fillet * size

    key = _stage_key(pm, radius, params.clamp, material_loss, max_loss, coplanar_deg, params.sharp)
    st = reuse.stages if reuse is not None and reuse.stages is not None else None
    if st is not None and st.key != key:
        st = None
    if (
        st is not None
        and any(f.sharp for f in st.frames)
        and not np.array_equal(st.depths, _resolve_depth(depth, ref, pm.n_vertices))
    ):  # a new depth may give a sharp vertex its cone: the sharp vertices are chosen again
        st = None

    t = time.perf_counter()
    _stage("rounding the edges")
    if st is not None:
        loss, rounding, centres, conical = st.loss, st.rounding, st.centres, st.conical
        requested = st.requested
    else:
        loss, rounding, conical, requested = _round(
            pm, radius, params.clamp, material_loss, max_loss, coplanar_deg, floor, min_width
        )
        centres = face_piece_centres(pm, rounding)
    fitted_radius = rounding.radius.copy()
    timings["rounding"] = time.perf_counter() - t
    depths = _resolve_depth(depth, ref, pm.n_vertices)

    t = time.perf_counter()
    _stage("vertex normals")
    saddles = None  # (n_vertices,) bool, when saddles are made sharp before the frames
    if st is not None:
        # the earlier design's stages stay as they were: the apex stage replaces the frames
        # and classification of the vertices it classifies again in lists of this design's
        frames, classified = list(st.frames), copy.deepcopy(st.classified)
    else:
        rounding, centres, frames, classified, saddles = _classified(
            pm, rounding, centres, "saddle" in kinds, conical, coplanar_deg, floor, min_width
        )
    res = copy.deepcopy(classified)
    if saddles is not None:
        for u in np.flatnonzero(saddles).tolist():
            res.reason[u] = kept_sharp(res.reason[u])
    timings["normals"] = time.perf_counter() - t

    t = time.perf_counter()
    # the shortest chord an arc is sampled at: no pattern edge under the certificate's limit
    min_chord = 0.0 if strict else 2 * tol.ruling * size
    needs: dict = {}  # each cone's sampling needs, measured once (apex stage, then surface)
    cuts: dict = {}  # the samples each vertex's solves added (solve_apices), solve to solve
    frames, classified, rounding, centres, solved, kept, rescue = _apices(
        pm,
        rounding,
        frames,
        classified,
        res,
        centres,
        depths,
        st,
        progress,
        size,
        material_loss=material_loss,
        fit_vertices=params.fit_vertices,
        coplanar_deg=coplanar_deg,
        floor=floor,
        min_width=min_width,
        sharp_kinds=kinds,
        arc_step=params.arc_step,
        min_chord=min_chord,
        needs=needs,
        cuts=cuts,
    )
    timings["apices"] = time.perf_counter() - t

    t = time.perf_counter()
    _stage("vertex modules")
    points = rounding.arc_points(
        params.samples,
        params.arc_step,
        min_chord=min_chord,
        chord_tol=chord,
        radius_scale=np.where(conical_sides(frames, pm.n_edges), 2.0, 1.0),
    )
    # a cone's normal may turn faster than its arc: more points where it does
    points = np.maximum(
        points, cone_sample_counts(solved, centres, pm.n_edges, params.arc_step, needs)
    )
    needs.clear()  # its last use: it holds every cone's frame, which the layout may not need
    same_samples = st is not None and np.array_equal(st.samples, points)
    modules = [st.modules[u] if same_samples and u in kept else None for u in range(len(solved))]
    todo = [u for u, module in enumerate(modules) if module is None]
    built = _build_modules(pm, [solved[u] for u in todo], centres, points, progress)
    for u, module in zip(todo, built, strict=True):
        modules[u] = module
    stages = (
        None
        if not keep_stages
        else Stages(
            key=key,
            loss=loss,
            conical=conical,
            requested=requested,
            rounding=rounding,
            centres=centres,
            frames=frames,
            classified=classified,
            depths=depths,
            vertices=res,
            solved=solved,
            samples=points,
            modules=modules,
            cleaned=None if input_key is None else (input_key, pm, clean_log, shift),
            cuts=cuts,
        )
    )
    pieces = [piece for module in modules for piece in module]
    ring_closed = [f.ring.closed for f in frames]
    if not keep_stages and not (layout == "net" or (layout == "auto" and params.sheet is not None)):
        # the layout needs neither the frames nor the modules (nets do: net_pieces rebuilds)
        del frames, classified
        solved = modules = built = None
    _stage("layout")
    pattern, layout_used, layout_note, fab = arrange(
        pm,
        rounding,
        pieces,
        solved,
        centres,
        points,
        res,
        ring_closed,
        layout=layout,
        material_loss=material_loss,
        sheet=params.sheet,
        units=params.sheet_units,
        scale=params.sheet_scale,
        tabs=params.tabs,
        nest=params.nest,
        stage=_stage,
        timings=timings,
        release_pieces=not keep_stages,
    )
    locate_apices(pattern, res)
    pattern.crease_sharp_rulings(  # a cone is creased along its rulings to sharp edges
        res.apex,
        pm.vertices,
        pm.edges,
        ~(rounding.radius > 0),
        tol.closure * size,  # the apex and the edges' points, to round-off of the size
    )
    timings["surface"] = time.perf_counter() - t
    mesh_out, rounding_out, res_out, pieces = pm, rounding, res, pieces
    if shift is not None:  # back where the mesh was (the stages stay about the centre)
        mesh_out, rounding_out, res_out, pieces = _shifted(pm, rounding, res, pieces, shift)
        pattern.vertices_3d = pattern.vertices_3d + shift
    design = Design(
        mesh=mesh_out,
        params=params,
        rounding=rounding_out,
        vertices=res_out,
        pattern=pattern,
        pieces=pieces,
        timings=timings,
        source=source,
        material_loss=loss,
        layout=layout_used,
        layout_note=layout_note,
        fabrication=fab,
        stages=stages,
        repairs=list(clean_log.repairs),
        fitting=_fitting(rounding_out, requested, fitted_radius, rescue, res),
    )
    if certify:
        from .check import certify_design

        t = time.perf_counter()
        _stage("certificate")
        design.certificate = certify_design(design)
        timings["certificate"] = time.perf_counter() - t
    timings["total"] = time.perf_counter() - t0
    return design


def _classified(pm, rounding, centres, sharp_saddles, conical, coplanar_deg, floor, min_width):
    """The vertex frames and classification of :func:`round_mesh` (every vertex classified
    once). With ``sharp_saddles``, the saddles are known before any frame
    (:func:`~filletfold.vertex.solve.saddle_vertices`) and made sharp from the start, their
    shared edges unrounded, so that each frame is built once with the neighbours' sides
    toward them conical. Returns the rounding, face piece centres, frames, classification and
    the saddles made sharp ((n_vertices,) bool, or None)."""
    classified = VertexResult.empty(pm.n_vertices)
    saddles = saddle_vertices(pm, rounding) if sharp_saddles else None
    if saddles is not None and saddles.any():
        rounding, centres, _ = unround_between(
            pm, rounding, centres, saddles, face_piece_centres, coplanar_deg, floor, min_width
        )
    else:
        saddles = None
    frames = classify_vertices(pm, rounding, classified, sharp=saddles)
    for u in [] if saddles is None else np.flatnonzero(saddles).tolist():
        # a saddle stays one, though its edges may all be unrounded now
        classified.kind[u] = classified.status[u] = "saddle"
        classified.reason[u] = saddle_reason(classified.normal_bound[u])
    if conical:
        use_cone_axes(pm, frames, classified)
    return rounding, centres, frames, classified, saddles


def _apices(
    pm,
    rounding,
    frames,
    classified,
    res,
    centres,
    depths,
    st,
    progress,
    size,
    *,
    material_loss,
    fit_vertices,
    coplanar_deg,
    floor,
    min_width,
    sharp_kinds=frozenset(),
    arc_step=0.0,
    min_chord=0.0,
    needs=None,
    cuts=None,
):
    """The apex stage of :func:`round_mesh`: every pending vertex's apex (those of a reused
    design's vertices whose depth did not change are kept), then the rescue of the infeasible
    ones, then the cone-less vertices of ``sharp_kinds`` made sharp and their neighbours solved
    again (:func:`~filletfold.vertex.sharpen.sharpen_vertices`). With ``infeasible`` among
    ``sharp_kinds`` (and without ``material_loss``), a cone that no sampling of its arcs at
    ``arc_step`` (degrees) with chords of at least ``min_chord`` can follow
    (:func:`~filletfold.surface.sampling.unsampled_cones`) is infeasible too, and made sharp;
    up to :data:`SAMPLING_ROUNDS` times, as its neighbours' new cones may be so in turn.
    ``frames`` and ``classified`` are this design's own and updated in place (the old frame
    of a vertex classified again is freed at once: a scan's frames take hundreds of MB).
    Returns the frames, classification, rounding and face-piece centres afterwards (the
    rescue may change them), ``solved`` (frame, apex, developed apex) per vertex, the vertices
    kept from ``st`` and the :class:`~filletfold.vertex.rescue.Rescue`."""

    def sharpen(kinds, apices, **options):
        """:func:`sharpen_vertices` of ``kinds`` on this stage's state (frames and the
        classification updated in place); the new rounding, centres and Sharpening."""
        _stage("sharp vertices")
        return sharpen_vertices(
            pm,
            rounding,
            frames,
            res,
            depths,
            centres,
            face_piece_centres,
            apices,
            kinds,
            flat_deg=coplanar_deg,
            floor=floor,
            min_width=min_width,
            classified=classified,
            sharp=_sharp_frames(frames),
            cuts=cuts,
            **options,
        )

    pending = [u for u in range(pm.n_vertices) if res.status[u] == ""]
    kept = set()
    if st is not None:
        kept = {u for u in range(pm.n_vertices) if st.depths[u] == depths[u]}
        res.take(st.vertices, sorted(kept))
        pending = [u for u in pending if u not in kept]
        if cuts is not None and st.cuts:  # a kept vertex solved again starts as in a fresh one
            cuts.update({u: st.cuts[u] for u in sorted(kept) if u in st.cuts})
    _stage("apices")
    # thorough even with the rescue to come: a quick solve calls vertices infeasible that are
    # not, and the rescue would shrink their radii for nothing; but without the linear
    # programmes when the rescue follows (they pay for themselves only there)
    rescue_follows = fit_vertices and not material_loss
    apices = _solve_apices(
        frames, depths, res, centres, progress, pending, size, lp=not rescue_follows, cuts=cuts
    )
    rescue = Rescue()
    if not material_loss and any(res.status[u] == "infeasible" for u in pending):
        rounding, centres, rescue = rescue_vertices(
            pm,
            rounding,
            frames,
            res,
            depths,
            centres,
            face_piece_centres,
            apply=fit_vertices,
            flat_deg=coplanar_deg,
            floor=floor,
            min_width=min_width,
            apices=apices,
            classified=classified,
            vertices=pending,
            sharp=_sharp_frames(frames),
            cuts=cuts,
        )
        kept -= rescue.resolved
    check = set(apices)  # the cones solved here (those kept from ``st`` were checked then)
    for _ in range(SAMPLING_ROUNDS):
        if "infeasible" in sharp_kinds and check and not material_loss:
            # a cone no sampling can follow (its facets would fold past the arc step, or
            # its arcs need sliver chords) is infeasible: sharp, its neighbours solved again
            # (not with the material-loss radii, which fold one uncut sheet as they are)
            cones = [(frames[u], *apices[u]) for u in sorted(check) if apices[u][0] is not None]
            for u, why in unsampled_cones(cones, centres, arc_step, min_chord, needs).items():
                res.status[u], res.reason[u], apices[u] = "infeasible", why, (None, None)
                res.apex[u], res.apex_developed[u] = np.nan, np.nan  # no cone: no apex
                res.depth[u], res.margin[u], res.solver[u] = np.nan, np.nan, ""
        already = _sharp_frames(frames)
        if not sharp_kinds or not any(
            sharp_kind(s) in sharp_kinds and not a for s, a in zip(res.status, already, strict=True)
        ):
            break
        rounding, centres, sharpening = sharpen(sharp_kinds, apices, size=size, progress=progress)
        kept -= sharpening.resolved | set(np.flatnonzero(sharpening.sharp).tolist())
        check = {u for u in sharpening.resolved if u in apices}
    solved = [
        st.solved[u] if u in kept else (frame, *apices.get(u, (None, None)))
        for u, frame in enumerate(frames)
    ]
    set_treatments(res, _sharp_frames(frames))
    return frames, classified, rounding, centres, solved, kept, rescue


#: Rounds of :func:`_apices`' last step: cones no sampling can follow made sharp, their
#: neighbours solved again (whose new cones may be such in turn).
SAMPLING_ROUNDS = 3


def _sharp_frames(frames) -> np.ndarray:
    """(n_vertices,) bool: the vertices whose frames are built sharp."""
    return np.array([f.sharp for f in frames], dtype=bool)


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


def _shifted(pm: PolyMesh, rounding: EdgeRounding, res: VertexResult, pieces, shift):
    """The mesh, rounding, vertex results and pieces of a design computed about a centre,
    moved by ``shift`` (copies: the stages keep the centred ones)."""
    mesh = PolyMesh(pm.vertices + shift, pm.faces)
    rounding = dataclasses.replace(
        rounding,
        axis_point=rounding.axis_point + shift,
        tangent_point=rounding.tangent_point + shift,
    )
    res = copy.deepcopy(res)
    res.apex = res.apex + shift
    moved = []
    for piece in pieces:
        piece = copy.copy(piece)
        piece.points_3d = np.asarray(piece.points_3d, dtype=float) + shift
        moved.append(piece)
    return mesh, rounding, res, moved


def _solve_apices(
    frames,
    depths,
    res: VertexResult,
    centres,
    progress,
    pending,
    size,
    thorough=True,
    lp=True,
    cuts=None,
) -> dict:
    """:func:`solve_apices` of the vertices ``pending``; when it fails unforeseen, the
    vertices are solved one by one and a vertex whose solve fails is infeasible, with the
    failure as its reason (a failure is data, not the end of the design)."""
    try:
        return solve_apices(
            frames, depths, res, centres, progress, vertices=pending, size=size,
            thorough=thorough, lp=lp, cuts=cuts,
        )  # fmt: skip
    except FilletfoldError:
        raise
    except Exception as exc:
        if is_callers(exc):
            raise
        out = {}
        for u in pending:
            res.status[u] = ""
            try:
                out.update(
                    solve_apices(
                        frames,
                        depths,
                        res,
                        centres,
                        vertices=[u],
                        size=size,
                        thorough=thorough,
                        lp=lp,
                        cuts=cuts,
                    )
                )
            except FilletfoldError:
                raise
            except Exception as exc:
                res.status[u] = "infeasible"
                res.reason[u] = f"the apex solver failed: {one_line(exc)}"
                out[u] = (None, None)
        return out


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


def _fitting(rounding: EdgeRounding, requested, fitted, rescue: Rescue, res) -> dict:
    """What :attr:`Design.fitting` holds: the radii asked for, the edges reduced to fit their
    limits, the edges left sharp, the vertices rescued (:mod:`filletfold.vertex.rescue`), the
    cones whose apex needed the solver's linear programmes."""
    bent = rounding.half_angle > 0  # rounded or left sharp (not boundary, not flat)
    asked = np.where(bent, requested, 0.0)
    sharp = rounding.sharp if rounding.sharp is not None else np.zeros(len(bent), dtype=bool)
    reduced = np.flatnonzero(bent & ~sharp & (fitted < asked * (1 - tol.roundoff)))
    return {
        "radius_requested": asked,
        "fitted_radius": fitted,
        "reduced": reduced,
        "sharp": np.flatnonzero(sharp),
        "rescued": dict(sorted(rescue.rescued.items())),
        "rescue_applied": rescue.applied,
        "sharpened": sorted(rescue.sharpened),
        "cones_by_lp": sum(
            1 for st, s in zip(res.status, res.solver, strict=True) if st == "ok" and "lp" in s
        ),
    }
