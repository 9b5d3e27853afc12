"""Infeasible vertices: smaller radii on their own edges, found and (optionally) applied.

Every constraint of sec. 3.2 gets easier as the radii shrink (the paper's sec. 2.5 argument:
the rounding's effect vanishes with the radius), so a cone vertex that is infeasible at the
requested radii is tried again with the radii of its own rounded edges halved, up to
:data:`ROUNDS` times. :func:`rescue_vertices` does this for all infeasible vertices at once,
round after round:

* ``apply=True`` (``--fit-vertices``): each infeasible vertex's own factor is found first on
  a copy (:func:`_probe`: only it is solved again after each halving), then applied in one
  round; the halved radii are kept; every vertex of a face that
  has a changed edge is classified and solved again (its frame, or the face piece centres its
  creases must stay short of, changed), so the design stays consistent; a vertex that no
  halving rescues has its edges left sharp at last: a sharp vertex, its faces meeting at it,
  rather than a hole;
* ``apply=False``: only the infeasible vertices are solved again, on a copy; a vertex that
  becomes feasible gets the radius that works in its reason, and the design is unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..mesh.polymesh import PolyMesh, mesh_size
from ..rounding.edges import EdgeRounding, round_edges, shrink_broken
from .solve import VertexResult, classify_vertices, solve_apices

#: Halvings of an infeasible vertex's radii tried before it is left infeasible (1/16 at most).
ROUNDS = 4


@dataclass
class Rescue:
    """What :func:`rescue_vertices` found.

    Attributes
    ----------
    rescued : dict of int to float
        Vertex -> the factor its edges' radii were multiplied by (applied, or only found).
    applied : bool
    edges : (k,) int
        Edges whose radius changed (applied only).
    resolved : set of int
        Vertices classified and solved again on the changed radii (applied only).
    sharpened : list of int
        Vertices no halving rescued whose edges were then left sharp (applied only): they
        are ``"sharp"`` vertices, their faces meeting at the vertex (no hole).
    """

    rescued: dict = field(default_factory=dict)
    applied: bool = False
    edges: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    resolved: set = field(default_factory=set)
    sharpened: list = field(default_factory=list)


def rescue_vertices(
    mesh: PolyMesh,
    rounding: EdgeRounding,
    frames: list,
    res: VertexResult,
    depths: np.ndarray,
    centres: np.ndarray,
    face_centres,
    *,
    apply: bool,
    flat_deg: float,
    floor: float = 0.0,
    min_width: float = 0.0,
    apices: dict,
    classified: VertexResult | None = None,
    vertices=None,
    sharp: np.ndarray | None = None,
    cuts: dict | None = None,
) -> tuple[EdgeRounding, np.ndarray, Rescue]:
    """Try smaller radii on the edges of every infeasible cone vertex.

    Parameters
    ----------
    mesh : PolyMesh
    rounding : EdgeRounding
    frames : list of VertexFrame
        Indexed by vertex; entries of re-solved vertices are replaced (``apply``).
    res : VertexResult
        Updated in place: re-solved vertices (``apply``), or the reasons of the vertices a
        smaller radius would rescue (not ``apply``).
    depths : (n_vertices,) float
    centres : (n_faces, 3) float
        Face piece centres of ``rounding``.
    face_centres : callable
        ``face_centres(mesh, rounding) -> (n_faces, 3)`` (:func:`~filletfold.surface.module.
        face_piece_centres`).
    apply : bool
    flat_deg, floor, min_width : float
        Passed to :func:`~filletfold.rounding.edges.round_edges`.
    apices : dict
        Vertex -> (apex, developed apex) of :func:`solve_apices`; updated in place
        (``apply``).
    classified : VertexResult, optional
        The classification before any apex (what a later design reuses): updated in place at
        the re-classified vertices (``apply``).
    vertices : iterable of int, optional
        Try only these vertices (default: every infeasible cone vertex).
    sharp : (n_vertices,) bool, optional
        Sharp vertices (:mod:`~filletfold.vertex.sharpen`): the frames built again keep their
        neighbours' sides conical, and they keep their status and reason.
    cuts : dict, optional
        The samples earlier solves added (:func:`~filletfold.vertex.solve.solve_apices`):
        each vertex solved again starts with its own, and the dict is updated.

    Returns
    -------
    rounding : EdgeRounding
    centres : (n_faces, 3) float
    rescue : Rescue
    """
    out = Rescue(applied=apply)
    bad = _infeasible(res)
    if vertices is not None:
        allowed = set(int(u) for u in vertices)
        bad = [u for u in bad if u in allowed]
    if not bad:
        return rounding, centres, out
    radius = rounding.radius.copy()
    start = radius.copy()
    factor = {u: 1.0 for u in bad}
    tries = {u: 0 for u in bad}  # each vertex is halved ROUNDS times, then left sharp (apply)
    trial = VertexResult.empty(mesh.n_vertices) if not apply else None
    probed: set = set()
    for _ in range(2 * ROUNDS + 2):  # vertices made infeasible by a change join later rounds
        if not apply:
            bad = [u for u in bad if tries[u] < ROUNDS]
        if not bad:
            break
        jump = {}
        if apply:  # each new vertex's own factor first, found on a copy: one round, not four
            new = [u for u in bad if tries[u] == 0 and u not in probed]
            probed.update(new)
            jump = _probe(
                mesh, radius, rounding.half_angle, frames, depths, face_centres, new,
                flat_deg, floor, min_width, sharp, cuts,
            )  # fmt: skip
        scale = np.ones(len(radius))
        for u in bad:
            halvings = jump.get(u, 1)
            step = 0.5**halvings if tries[u] < ROUNDS else 0.0  # halve; at last leave them sharp
            e = frames[u].ring.edges
            scale[e] = np.minimum(scale[e], step)
            factor[u] *= step
            tries[u] += halvings if tries[u] < ROUNDS else 1
        edges = np.flatnonzero((scale < 1) & (radius > 0))
        if not len(edges):
            break
        radius[edges] *= scale[edges]
        radius, new_rounding, new_centres = reround(
            mesh, radius, rounding.half_angle, face_centres, flat_deg, floor, min_width
        )
        if apply:
            affected = face_vertices(mesh, edges)
            target = res
        else:
            affected = np.array(sorted(bad), dtype=np.int64)
            target = trial
        fresh = VertexResult.empty(mesh.n_vertices)
        kept = [] if sharp is None else [u for u in affected.tolist() if sharp[u]]
        status = {u: (target.status[u], target.kind[u], target.reason[u]) for u in kept}
        target.take(fresh, affected)
        new_frames = classify_vertices(mesh, new_rounding, target, affected, sharp=sharp)
        for u, (st, kind, reason) in status.items():  # a sharp vertex keeps why it is sharp
            target.status[u], target.kind[u], target.reason[u] = st, kind, reason
        if apply and classified is not None:
            classified.take(target, affected)
        todo = [u for u in affected.tolist() if target.status[u] == ""]
        solved = solve_apices(
            dict(zip(affected.tolist(), new_frames, strict=True)),
            depths,
            target,
            new_centres,
            vertices=todo,
            thorough=max(tries[u] for u in bad) >= ROUNDS,  # the fallbacks at the last factor
            size=mesh_size(mesh),
            cuts=cuts,
        )
        if apply:
            out.resolved.update(affected.tolist())
            for u, frame in zip(affected.tolist(), new_frames, strict=True):
                frames[u] = frame
            for u in affected.tolist():  # a vertex now without a cone (sharp) has no apex
                apices[u] = solved.get(u, (None, None))
            rounding, centres = new_rounding, new_centres
        for u in list(bad):
            if target.status[u] == "ok":
                out.rescued[u] = factor[u]
                bad.remove(u)
            elif target.status[u] == "sharp":  # its edges all left sharp: its faces meet at it
                out.sharpened.append(u)
                target.reason[u] = (
                    "no radius on its edges (down to "
                    f"{0.5**ROUNDS:g} of them) made its cone feasible: its edges are left sharp "
                    "and its faces meet at the vertex itself"
                )
                bad.remove(u)
        if apply:  # vertices made infeasible by the change (rescued ones too) join again
            for u in _infeasible(res):
                if u in bad:
                    continue
                if u in out.rescued:
                    del out.rescued[u]
                else:
                    factor.setdefault(u, 1.0)
                    tries.setdefault(u, 0)
                bad.append(u)
    factor_of = {u: f for u, f in factor.items() if u not in out.rescued}
    for u, f in factor_of.items():
        if res.status[u] == "infeasible":
            res.reason[u] += f"; still infeasible with the radii of its edges multiplied by {f:g}"
    if apply:
        out.edges = np.flatnonzero(radius != start)
    else:
        for u, f in out.rescued.items():
            r = rounding.radius[frames[u].ring.edges]
            r = r[r > 0]
            res.reason[u] += (
                f"; its cone is feasible with the radii of its edges multiplied by {f:g} "
                f"(at most {r.max() * f:.4g}): --fit-vertices does so"
            )
    return rounding, centres, out


def _probe(
    mesh,
    radius,
    half_angle,
    frames,
    depths,
    face_centres,
    vertices,
    flat_deg,
    floor,
    min_width,
    sharp,
    cuts=None,
) -> dict:
    """How many halvings of its edges' radii (1 to :data:`ROUNDS`) each of ``vertices`` needs
    for a feasible cone, found on a copy: ``vertices`` alone are classified and solved again
    (quick solves) after each halving, as ``apply=False`` does. A vertex no halving makes
    feasible so gets :data:`ROUNDS` (the last factor, tried thoroughly when applied)."""
    need = dict.fromkeys(vertices, ROUNDS)
    todo = list(vertices)
    trial = VertexResult.empty(mesh.n_vertices)
    for j in range(1, ROUNDS + 1):
        if not todo:
            break
        scale = np.ones(len(radius))
        for u in todo:
            scale[frames[u].ring.edges] = 0.5**j
        _, rounding, centres = reround(
            mesh, radius * scale, half_angle, face_centres, flat_deg, floor, min_width
        )
        idx = np.array(todo, dtype=np.int64)
        trial.take(VertexResult.empty(mesh.n_vertices), idx)
        new_frames = classify_vertices(mesh, rounding, trial, idx, sharp=sharp)
        solve_apices(
            dict(zip(todo, new_frames, strict=True)),
            depths,
            trial,
            centres,
            vertices=[u for u in todo if trial.status[u] == ""],
            thorough=False,
            size=mesh_size(mesh),
            cuts=cuts,
        )
        for u in todo:
            if trial.status[u] == "ok":
                need[u] = j
        todo = [u for u in todo if trial.status[u] != "ok"]
    return need


def reround(
    mesh: PolyMesh,
    radius: np.ndarray,
    half_angle: np.ndarray,
    face_centres,
    flat_deg: float,
    floor: float,
    min_width: float,
) -> tuple[np.ndarray, EdgeRounding, np.ndarray]:
    """The rounding of new radii, and its face piece centres: what the rescue and the sharp
    vertices (:func:`~filletfold.vertex.sharpen.sharpen_vertices`) do after changing radii.

    Parameters
    ----------
    mesh : PolyMesh
    radius : (n_edges,) float
        The new radii.
    half_angle : (n_edges,) float
        The edges' half angles (:attr:`EdgeRounding.half_angle`).
    face_centres : callable
        ``face_centres(mesh, rounding) -> (n_faces, 3)``.
    flat_deg, floor, min_width : float
        Passed to :func:`~filletfold.rounding.edges.round_edges`.

    Returns
    -------
    radius : (n_edges,) float
        ``radius`` with the radii that would break an obtuse corner shrunk
        (:func:`~filletfold.rounding.edges.shrink_broken`).
    rounding : EdgeRounding
    centres : (n_faces, 3) float
    """
    radius = shrink_broken(mesh, radius, half_angle)
    rounding = round_edges(mesh, radius, flat_deg=flat_deg, floor=floor, min_width=min_width)
    return radius, rounding, face_centres(mesh, rounding)


def face_vertices(mesh: PolyMesh, edges) -> np.ndarray:
    """The vertices of every face on one of ``edges`` (sorted, distinct): the vertices whose
    face pieces, and so their creases' limits, change with those edges' radii."""
    faces = np.unique(mesh.edge_faces[np.asarray(edges)])
    faces = faces[faces >= 0]
    if not len(faces):
        return np.zeros(0, dtype=np.int64)
    return np.unique(np.concatenate([mesh.faces[f] for f in faces.tolist()]))


def _infeasible(res: VertexResult) -> list:
    """The cone vertices whose status is infeasible."""
    return [
        u for u, (k, s) in enumerate(zip(res.kind, res.status, strict=True))
        if s == "infeasible" and k in ("cone", "developable")
    ]  # fmt: skip
