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

from ..mesh.polymesh import PolyMesh
from .solve import VertexResult, classify_vertices, solve_apices
from .state import VertexState

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


def rescue_vertices(state: VertexState, *, apply: bool, vertices=None) -> Rescue:
    """Try smaller radii on the edges of every infeasible cone vertex.

    Parameters
    ----------
    state : VertexState
        With ``apply``: updated in place -- its rounding and centres, the frames, results,
        classification and apices of the vertices classified and solved again. Without: only
        the reasons of the vertices a smaller radius would rescue (``state.res``). Its
        sharp vertices (frames built sharp) keep their neighbours' sides conical, their
        status and their reason; the samples its solves added (``state.cuts``) are where each
        vertex solved again starts, and are updated.
    apply : bool
    vertices : iterable of int, optional
        Try only these vertices (default: every infeasible cone vertex).

    Returns
    -------
    Rescue
    """
    mesh, frames, res, depths = state.mesh, state.frames, state.res, state.depths
    classified, apices, cuts = state.classified, state.apices, state.cuts
    rounding, sharp = state.rounding, state.sharp_frames()
    out = Rescue(applied=apply)
    bad = _infeasible(res)
    if vertices is not None:
        allowed = set(int(u) for u in vertices)
        bad = [u for u in bad if u in allowed]
    if not bad:
        return out
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
            jump = _probe(state, radius, new, sharp)
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
        # (state.reround makes a fillet halved under the sheet's bend floor a crease)
        radius, new_rounding, new_centres = state.reround(radius)
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
            size=state.size,
            cuts=cuts,
            work=state.work,
        )
        if apply:
            out.resolved.update(affected.tolist())
            for u, frame in zip(affected.tolist(), new_frames, strict=True):
                frames[u] = frame
            for u in affected.tolist():  # a vertex now without a cone (sharp) has no apex
                apices[u] = solved.get(u, (None, None))
            state.rounding, state.centres = new_rounding, new_centres
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
    return out


def _probe(state: VertexState, radius: np.ndarray, vertices, sharp: np.ndarray) -> dict:
    """How many halvings of its edges' radii (1 to :data:`ROUNDS`) each of ``vertices`` needs
    for a feasible cone, found on a copy: ``vertices`` alone are classified and solved again
    (quick solves) after each halving, as ``apply=False`` does. A vertex no halving makes
    feasible so gets :data:`ROUNDS` (the last factor, tried thoroughly when applied)."""
    mesh, frames = state.mesh, state.frames
    need = dict.fromkeys(vertices, ROUNDS)
    todo = list(vertices)
    trial = VertexResult.empty(mesh.n_vertices)
    for j in range(1, ROUNDS + 1):
        if not todo:
            break
        scale = np.ones(len(radius))
        for u in todo:
            scale[frames[u].ring.edges] = 0.5**j
        _, rounding, centres = state.reround(radius * scale)
        idx = np.array(todo, dtype=np.int64)
        trial.take(VertexResult.empty(mesh.n_vertices), idx)
        new_frames = classify_vertices(mesh, rounding, trial, idx, sharp=sharp)
        solve_apices(
            dict(zip(todo, new_frames, strict=True)),
            state.depths,
            trial,
            centres,
            vertices=[u for u in todo if trial.status[u] == ""],
            thorough=False,
            size=state.size,
            cuts=state.cuts,
            work=state.work,
        )
        for u in todo:
            if trial.status[u] == "ok":
                need[u] = j
        todo = [u for u in todo if trial.status[u] != "ok"]
    return need


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
