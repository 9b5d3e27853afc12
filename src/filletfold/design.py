"""The orchestrator: mesh + parameters -> :class:`Design`.

:func:`round_mesh` runs the stages of :mod:`filletfold.pipeline` in the order of
``docs/method.md`` ("Pipeline"): read and clean the mesh, round the edges (sec. 2.1, 4),
classify the vertices and find their normals (sec. 3.1), solve the apices (sec. 2.4, 3.2), build
the vertex modules (eq. 1), lay them out into the crease pattern; then certify the design.
"""

from __future__ import annotations

import copy
import dataclasses
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import callers_progress, named_stages
from .errors import stage as _stage
from .mesh.coarsen import Coarsening
from .mesh.polymesh import PolyMesh
from .mesh.upright import up_axis
from .parameters import Parameters
from .pipeline import (
    Edges,
    Job,
    Layout,
    Stages,
    VertexSolution,
    apex_stage,
    edge_stage,
    layout_stage,
    module_stage,
    normal_stage,
    read_stage,
    reusable_stages,
    stages_of,
    timed,
)
from .rounding.edges import EdgeRounding
from .rounding.material_loss import MaterialLoss
from .surface.pattern import CreasePattern
from .tolerances import tol
from .vertex.rescue import Rescue
from .vertex.solve import STATUSES, VertexResult, cones_by_fallback


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
    coarsening : Coarsening or None
        With ``faces``: the triangles and vertices before and after the mesh was coarsened
        (:func:`~filletfold.mesh.coarsen.coarsen_mesh`), and how far its surface moved.
    up : str
        The axis up in its pictures and the app's view (``"x"``, ``"y"``, ``"z"``): the
        parameter ``up``, or the one the mesh stands on
        (:func:`~filletfold.mesh.upright.up_axis`).
    up_why : str
        How ``up`` was chosen.
    fitting : dict
        ``radius_requested`` (n_edges,) float, the radii asked for (0 at boundary and flat
        edges); ``fitted_radius`` (n_edges,) float, the radii after fitting to the limits and
        before any rescue; ``reduced`` (k,) int, the edges whose radius was reduced to fit its
        limit; ``sharp`` (k,) int, the edges left sharp (their fillet would be narrower than
        ``tol.fillet_floor`` of the edge); ``rescued`` (dict vertex -> factor), the vertices
        whose edges' radii were scaled by ``factor`` to make their cone feasible (applied when
        ``rescue_applied``, else only reported in their reason); ``sharpened``, the vertices
        no radius rescued whose edges were left sharp instead (sharp vertices);
        ``cones_by_lp`` and ``cones_by_fallback`` (dict fallback -> int), the cones whose
        feasible point a fallback of the apex solver found
        (:data:`~filletfold.vertex.settings.FALLBACKS`); ``apex_work`` (dict: ``problems``,
        ``phase1_runs``, ``programmes``), what the apex solver did in this design, in counts
        (:class:`~filletfold.vertex.batch.ApexWork`).
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
    coarsening: Coarsening | None = None
    up: str = "z"
    up_why: str = ""

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
        """Write the design's files as the design folder ``folder`` (replaced whole):
        :func:`~filletfold.export.outputs.export_design` of this design.

        Parameters
        ----------
        folder : str or Path
        **options
            ``title``, ``formats``, ``units``, ``scale``, ``page``, ``preset``, ``view``,
            ``tables``, ``force``: those of :func:`~filletfold.export.outputs.export_design`
            (the same defaults: a folder holding files filletfold does not write is refused
            unless ``force=True``).

        Returns
        -------
        list of Path
            The files written.
        """
        from .export.outputs import export_design

        return export_design(self, folder, **options)


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
        The design's parameters (default: :class:`~filletfold.parameters.Parameters`()).
    **options
        Fields of :class:`~filletfold.parameters.Parameters` that replace those of ``params``
        (``radius="5%"``, ``depth=0.3``, ``samples=24``, ``material_loss=True``, ...).
    progress : callable, optional
        ``progress(stage, done, total)`` called during long stages.
    reuse : Design, optional
        An earlier design of the same mesh, whose stages are taken over where they hold for
        this one (:func:`~filletfold.pipeline.reusable_stages`: only the vertices whose depth
        changed are solved again). The result is the same as without.
    certify : bool
        Measure the design's invariants into ``design.certificate``
        (:func:`filletfold.check.certify_design`, about 5 % of the time; the app skips it).
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
        No positive losses with ``material_loss`` (naming the binding vertices and edges), or
        no single sheet with ``layout="sheet"``.
    """
    t0 = time.perf_counter()
    timings: dict = {}
    earlier = None if reuse is None else reuse.stages  # the app's cache of an earlier design
    with timed(timings, "read", since=t0):  # 1. the mesh, read and cleaned
        given = (params if params is not None else Parameters()).replace(**options)
        given.check()
        job = read_stage(mesh, given.resolved(), callers_progress(progress), earlier)
    st = reusable_stages(job, earlier)  # what of the earlier design holds for this one
    with timed(timings, "rounding"):  # 2. a cylinder on every edge (sec. 2.1, 4)
        edges = edge_stage(job, st)
    with timed(timings, "normals"):  # 3. classes and vertex normals (sec. 3.1)
        state = normal_stage(job, edges, st)
    with timed(timings, "apices"):  # 3. apices (sec. 2.4, 3.2), rescue, sharp vertices
        sol = apex_stage(job, state, st)
    del state  # the solution holds what is left of it (the layout may release it)
    with timed(timings, "surface"):
        mods = module_stage(job, sol, st)  # 4. creases (eq. 1), cones, cylinders, faces
        stages = stages_of(job, edges, sol, mods) if keep_stages else None
        laid = layout_stage(job, sol, mods, not keep_stages, timings)  # 5. the crease pattern
    design = _design(job, edges, sol, laid, stages, timings)
    if certify:  # 6. the design's invariants measured again
        with timed(timings, "certificate"):
            design.certificate = _certificate(design)
    timings["total"] = time.perf_counter() - t0
    return design


def _certificate(design: Design):
    """The design's certificate (:func:`filletfold.check.certify_design`, imported on the
    first design that is certified: the app's slider designs are not)."""
    from .check import certify_design

    _stage("certificate")
    return certify_design(design)


def _design(job: Job, edges: Edges, sol: VertexSolution, laid: Layout, stages, timings) -> Design:
    """The :class:`Design` of the stages' results, moved back where the mesh was when it was
    computed about its centre (the stages stay about the centre)."""
    mesh, rounding, res, pieces = job.mesh, sol.rounding, sol.res, laid.pieces
    if job.shift is not None:
        mesh, rounding, res, pieces = _shifted(job.mesh, sol.rounding, sol.res, pieces, job.shift)
        laid.pattern.vertices_3d = laid.pattern.vertices_3d + job.shift
    up, why = _up(mesh, job.params.up, job.source)
    return Design(
        mesh=mesh,
        params=laid.params,
        rounding=rounding,
        vertices=res,
        pattern=laid.pattern,
        pieces=pieces,
        timings=timings,
        source=job.source,
        material_loss=edges.loss,
        layout=laid.layout,
        layout_note=laid.note,
        fabrication=laid.fabrication,
        stages=stages,
        repairs=list(job.clean_log.repairs),
        coarsening=job.coarsening,
        up=up,
        up_why=why,
        fitting=_fitting(rounding, edges, sol.rescue, sol.res, sol.work),
    )


def _up(mesh: PolyMesh, up: str, source: str) -> tuple[str, str]:
    """The up axis of a design and why: ``up`` as given, or the one ``mesh`` stands on."""
    if up != "auto":
        return up, "given"
    if not mesh.n_faces:
        return "z", "no faces: the default"
    return up_axis(mesh.vertices, mesh.face_centroid, mesh.face_area, source)


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


def _fitting(rounding: EdgeRounding, edges, rescue: Rescue, res, work) -> dict:
    """What :attr:`Design.fitting` holds: the radii asked for, the edges reduced to fit their
    limits, the edges left sharp, the fillets made creases for the sheet material's bend
    floor, the vertices rescued (:mod:`filletfold.vertex.rescue`), the
    cones whose apex needed the solver's linear programmes, those each fallback of the
    solver found (:func:`~filletfold.vertex.solve.cones_by_fallback`), and the solver's work
    (:class:`~filletfold.vertex.batch.ApexWork`)."""
    requested, fitted = edges.requested, edges.fitted
    bent = rounding.half_angle > 0  # rounded or left sharp (not boundary, not flat)
    asked = np.where(bent, requested, 0.0)
    sharp = rounding.sharp if rounding.sharp is not None else np.zeros(len(bent), dtype=bool)
    creased = np.zeros(len(bent), dtype=bool) if edges.creased is None else edges.creased
    reduced = np.flatnonzero(bent & ~sharp & ~creased & (fitted < asked * (1 - tol.roundoff)))
    by_fallback = cones_by_fallback(res)
    return {
        "radius_requested": asked,
        "fitted_radius": fitted,
        "reduced": reduced,
        "sharp": np.flatnonzero(sharp),
        "creased": np.flatnonzero(creased),
        "bend_floor": float(edges.bend),
        "rescued": dict(sorted(rescue.rescued.items())),
        "rescue_applied": rescue.applied,
        "sharpened": sorted(rescue.sharpened),
        "cones_by_lp": by_fallback.get("lp", 0),
        "cones_by_fallback": by_fallback,
        "apex_work": work.as_dict(),
    }
