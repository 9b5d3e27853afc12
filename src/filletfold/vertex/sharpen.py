"""Sharp vertices: the vertices that take no cone keep their corner instead of a hole.

After the apices (and the rescue), every vertex without a cone whose kind is asked for
(:data:`SHARP_KINDS`: ``saddle``, ``infeasible`` (``developable`` counts as infeasible),
``boundary``) becomes *sharp* (``docs/method.md``, "Sharp vertices and conical fillets"):

- an edge between two sharp vertices is left unrounded (radius 0: a straight crease folded by
  the dihedral angle);
- the other rounded edges of a sharp vertex become conical fillets with their apex at it, so
  every neighbour that has a cone is solved again with those sides conical
  (:func:`~filletfold.vertex.frame.vertex_frames` with ``sharp``);
- a neighbour that then finds no apex is infeasible: when ``infeasible`` is asked for it
  becomes sharp in the next round, and so on until no vertex changes.

:func:`sharpen_vertices` runs these rounds on the vertex stage's state.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..mesh.polymesh import PolyMesh
from ..rounding.edges import EdgeRounding
from .rescue import face_vertices
from .solve import VertexResult, classify_vertices, solve_apices
from .state import VertexState

#: The kinds of cone-less vertices that ``--sharp`` can make sharp, in the order they are
#: named.
SHARP_KINDS = ("saddle", "infeasible", "boundary")


def parse_sharp(spec) -> frozenset:
    """The kinds named by ``spec``: ``"none"``, ``"all"``, or a comma-separated subset of
    :data:`SHARP_KINDS` (a sequence of names works too).

    Raises
    ------
    ParameterError
        For a name that is not a kind.
    """
    if spec is None:
        return frozenset(SHARP_KINDS)
    names = spec.split(",") if isinstance(spec, str) else list(spec)
    names = [str(n).strip().lower() for n in names if str(n).strip()]
    if names in (["none"], []):
        return frozenset()
    if names == ["all"]:
        return frozenset(SHARP_KINDS)
    bad = [n for n in names if n not in SHARP_KINDS]
    if bad:
        raise ParameterError(
            f"--sharp: unknown kind {bad[0]!r}; use none, all or a comma-separated list of "
            + ", ".join(SHARP_KINDS)
        )
    return frozenset(names)


def set_treatments(res: VertexResult, sharp: np.ndarray | None) -> None:
    """Fill ``res.treatment``: ``cone`` where ``ok``, ``sharp`` at the ``sharp`` vertices and
    at those whose edges are all unrounded (status ``sharp``), ``hole`` elsewhere."""
    for u, st in enumerate(res.status):
        if st == "ok":
            res.treatment[u] = "cone"
        elif st == "sharp" or (sharp is not None and sharp[u]):
            res.treatment[u] = "sharp"
        else:
            res.treatment[u] = "hole"


def edge_treatments(mesh: PolyMesh, rounding: EdgeRounding, treatment) -> list:
    """Per mesh edge: ``cylinder`` (rounded, no sharp end), ``cone`` (rounded, a conical
    fillet from its sharp end), ``sharp`` (bent but unrounded: a straight crease), ``flat``
    (between coplanar faces) or ``boundary``."""
    sharp = np.array([t == "sharp" for t in treatment], dtype=bool)
    ends = mesh.edges
    tapered = sharp[ends[:, 0]] | sharp[ends[:, 1]]
    boundary = (mesh.edge_faces < 0).any(axis=1)
    rounded = rounding.radius > 0
    bent = rounding.half_angle > 0
    out = np.where(
        boundary,
        "boundary",
        np.where(rounded, np.where(tapered, "cone", "cylinder"), np.where(bent, "sharp", "flat")),
    )
    return out.tolist()


def sharp_kind(status: str) -> str | None:
    """The :data:`SHARP_KINDS` entry of a vertex without a cone, from its status (None for a
    vertex with a cone, ``ok``, or one whose edges are all unrounded, ``sharp``: its faces
    meet at the vertex already)."""
    if status in ("saddle", "boundary", "infeasible"):
        return status
    if status == "developable":
        return "infeasible"
    return None


def unround_between(
    state: VertexState, sharp: np.ndarray
) -> tuple[EdgeRounding, np.ndarray, np.ndarray]:
    """Leave every rounded edge between two ``sharp`` vertices unrounded (a straight crease).

    Returns the rounding and face piece centres afterwards (the state itself is not changed;
    the centres with the edges from ``sharp`` vertices to others conical fillets) and which
    edges changed, (n_edges,) bool: unrounded, or a fillet now conical on a face whose
    centre moved.
    """
    mesh, rounding = state.mesh, state.rounding
    ends = mesh.edges
    both = sharp[ends[:, 0]] & sharp[ends[:, 1]] & (rounding.radius > 0)
    if both.any():
        radius = rounding.radius.copy()
        radius[both] = 0.0
        _, rounding, centres = state.reround(radius, sharp)
    else:
        centres = state.face_centres(mesh, rounding, sharp)
    moved = np.zeros(mesh.n_faces + 1, dtype=bool)  # the last: no face (a boundary side)
    moved[:-1] = (centres != state.centres).any(axis=1)
    one = (sharp[ends[:, 0]] != sharp[ends[:, 1]]) & (rounding.radius > 0)
    return rounding, centres, both | (one & moved[mesh.edge_faces].any(axis=1))


@dataclass
class Sharpening:
    """What :func:`sharpen_vertices` did.

    Attributes
    ----------
    sharp : (n_vertices,) bool
        The sharp vertices.
    resolved : set of int
        The vertices solved again (the neighbours of sharp vertices).
    rounds : int
    """

    sharp: np.ndarray
    resolved: set = field(default_factory=set)
    rounds: int = 0


def sharpen_vertices(state: VertexState, kinds) -> Sharpening:
    """Make the cone-less vertices of ``kinds`` sharp and solve their neighbours again.

    Parameters
    ----------
    state : VertexState
        Updated in place: its rounding and centres (the edges between sharp vertices
        unrounded), the frames of the sharp vertices and of the vertices solved again, their
        results, classification and apices. The vertices whose frames are built sharp
        already stay sharp and keep their reasons.
    kinds : iterable of str
        Of :data:`SHARP_KINDS`.

    Returns
    -------
    Sharpening
    """
    mesh, frames, res, apices = state.mesh, state.frames, state.res, state.apices
    rounding, centres, classified = state.rounding, state.centres, state.classified
    kinds = frozenset(kinds)
    n = mesh.n_vertices
    sharp = state.sharp_frames()
    initial = sharp.copy()
    out = Sharpening(sharp)
    if not kinds:
        return out
    ends = mesh.edges
    # rounds until no vertex of ``kinds`` is left without its corner: each makes the newly
    # infeasible neighbours of the last round's sharp vertices sharp, and every round adds one
    # at least, so there are at most n (fandisk, a CAD part with feature lines, takes 22)
    while True:
        new = np.array(
            [u for u in range(n) if not sharp[u] and sharp_kind(res.status[u]) in kinds],
            dtype=np.int64,
        )
        if not len(new):
            break
        out.rounds += 1
        sharp[new] = True
        rounding, centres, changed = unround_between(state, sharp)
        state.rounding, state.centres = rounding, centres
        # the vertices whose sides changed: neighbours of the new sharp vertices, and every
        # vertex of a face whose piece (and centre) changed with an unrounded or conical edge
        near = np.zeros(n, dtype=bool)
        at_new = np.isin(ends, new).any(axis=1)
        near[ends[at_new].ravel()] = True
        near[face_vertices(mesh, np.flatnonzero(changed))] = True
        again = np.flatnonzero(near & ~sharp)
        rebuilt = np.flatnonzero(near | sharp)
        fresh = VertexResult.empty(n)
        res.take(fresh, again)
        status = {
            int(u): (res.status[u], res.kind[u], res.reason[u]) for u in np.flatnonzero(sharp)
        }
        new_frames = classify_vertices(mesh, rounding, res, rebuilt, sharp=sharp)
        for u, (st, kind, reason) in status.items():  # a sharp vertex keeps why it is sharp
            res.status[u], res.kind[u], res.reason[u] = st, kind, reason
        if classified is not None:
            classified.take(res, rebuilt)
        for u, f in zip(rebuilt.tolist(), new_frames, strict=True):
            frames[u] = f
        todo = [int(u) for u in again if res.status[u] == ""]
        for u in np.flatnonzero(sharp).tolist():
            apices.pop(u, None)
        if todo:
            solved = solve_apices(
                {u: frames[u] for u in todo}, state.depths, res, centres, state.progress, todo,
                size=state.size, cuts=state.cuts, work=state.work,
            )  # fmt: skip
            apices.update(solved)
        out.resolved.update(int(u) for u in again)
    for u in np.flatnonzero(sharp & ~initial).tolist():
        res.reason[u] = kept_sharp(res.reason[u])
    return out


def kept_sharp(reason: str) -> str:
    """The reason of a vertex without a cone, once it is made sharp."""
    return (reason or "no cone") + "; kept sharp (its corner, no hole)"
