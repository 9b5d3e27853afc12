"""How many points each arc needs so that no two neighbouring facets of a cone (or of a
conical fillet) fold by more than the arc step.

The arc step bounds the turn of an arc between two samples: the turn of a cylinder's normal
too, since a cylinder's normal turns with its arc. A cone's normal does not: between the
rulings to ``F(s)`` and ``F(s + ds)`` it turns by the angle between the planes
``(V, F(s), F(s + ds))``, which on a narrow cone, or one whose crease runs nearly along its
rulings, is several times the arc's turn. Sampled by the arc alone, the cone's triangle fan
then folds between neighbouring triangles by far more than the step, on an edge the pattern
marks ``F`` (not a crease).
"""

from __future__ import annotations

import math

import numpy as np

#: Points per arc at which a cone's normal is measured (both ends included).
DENSE = 97
#: Most points any arc gets to bound its cones' facet folds (``--samples`` bounds the rest).
MAX_CONE_SAMPLES = 256
#: The share of the step the fastest turn is sampled at: a facet's fold is the turn between
#: two facets' mean normals, which the fastest dense turn slightly underestimates.
SAFETY = 0.8
#: Vertices measured at once (bounds the dense points held).
BATCH = 256


def cone_sample_counts(
    solved: list, centres, n_edges: int, step_deg: float, cache: dict | None = None
) -> np.ndarray:
    """(n_edges,) int: the fewest evenly spaced points on each arc (ends included) at which
    neighbouring triangles of the cones at both its ends fold by at most ``step_deg``
    (:func:`cone_sample_needs`, at most :data:`MAX_CONE_SAMPLES`; 1 on an edge without an arc
    or without a cone at either end)."""
    need = np.ones(n_edges, dtype=np.int64)
    edge, _, count, _ = cone_sample_needs(solved, centres, step_deg, cache)
    np.maximum.at(need, edge, np.minimum(count, MAX_CONE_SAMPLES))
    return need


def unsampled_cones(
    solved: list, centres, step_deg: float, min_chord: float, cache: dict | None = None
) -> dict:
    """The cone vertices whose facet folds no sampling bounds: an arc of theirs would need
    more than :data:`MAX_CONE_SAMPLES` points, or points closer than ``min_chord`` (the
    shortest chord the design's pattern edges may have), for its cone's neighbouring
    triangles to fold by at most ``step_deg`` (at the bare step, without :data:`SAFETY`).
    Such a cone turns its normal by tens of degrees over a sliver of arc: it folds there
    like a crease it has no room for.

    Returns
    -------
    dict of int to str
        Vertex -> why (the arc, the points it needs, the most it may have).
    """
    out = {}
    if step_deg <= 0:
        return out
    edge, vertex, count, arc = cone_sample_needs(solved, centres, step_deg, cache)
    most = np.full(len(arc), MAX_CONE_SAMPLES, dtype=np.int64)
    if min_chord > 0:
        most = np.minimum(most, np.maximum(np.floor(arc / min_chord).astype(np.int64) + 1, 2))
    # the counts carry the SAFETY share of the step: a cone is given up only where even the
    # bare step needs more points than fit
    bare = np.ceil((count - 1) * SAFETY) + 1
    for k in np.flatnonzero(bare > most).tolist():
        u = int(vertex[k])
        if u not in out:
            out[u] = (
                f"its cone folds too sharply along the arc of edge {int(edge[k])} "
                f"({arc[k]:.3g} long): {int(count[k])} points would bound its facets' folds "
                f"by the arc step, {int(most[k])} fit (no chord under {min_chord:.3g})"
            )
    return out


def cone_sample_needs(solved: list, centres, step_deg: float, cache: dict | None = None) -> tuple:
    """Per rounded side of every cone: the points its arc needs (ends included) so that
    neighbouring triangles of the cone fold by at most ``step_deg``.

    Each cone's crease ``F(s)`` (eq. (1)) is evaluated at :data:`DENSE` points per arc; the
    normal of the triangle ``(V, F(s_k), F(s_k+1))`` (on a conical fillet also that of
    ``(S, C(s_k), C(s_k+1))``, the fillet's own cone from its sharp end) turns by
    ``theta_k`` from one dense interval to the next, so the fastest turn per unit arc is
    ``max theta_k / ds``, and the arc needs ``ceil(max theta_k / ds * a / (SAFETY step)) + 1``
    points (not capped).

    Parameters
    ----------
    solved : list of (VertexFrame, apex or None, developed apex or None)
        Per vertex, as the apex stage gives them.
    centres : (n_faces, 3) float
        Face-piece centres.
    step_deg : float
        The arc step (degrees); 0 for no bound (then nothing is measured).
    cache : dict, optional
        Vertex -> its rows and what they were measured for (its frame object, apex and
        developed apex): a cone measured before with the same frame and apex (the apex
        stage's check, then the surface's sampling) is not measured again. Filled here.

    Returns
    -------
    edge, vertex, count : (k,) int
        The mesh edge of each measured side, the cone's vertex, the points its arc needs.
    arc : (k,) float
        The arc's length.
    """
    from .module import _Chunk  # the module builder: only where a design is made

    found = [[np.zeros(0, dtype=np.int64)] * 3 + [np.zeros(0)]]
    if step_deg <= 0:
        return tuple(found[0])
    cones = [x for x in solved if x[1] is not None and not x[0].sharp]
    if cache is not None:
        todo = []
        for x in cones:
            known = cache.get(x[0].vertex)
            if known is not None and known[0] is x[0] and known[1] == _measured_for(x):
                found.append(known[2])
            else:
                todo.append(x)
        cones = todo
    for lo in range(0, len(cones), BATCH):
        part = cones[lo : lo + BATCH]
        chunk = _Chunk.of(
            [x[0] for x in part], centres, DENSE, [x[1] for x in part], [x[2] for x in part]
        )
        sa = chunk.sides
        arc = np.where(chunk.rounded, sa.arc, 0.0)
        sides = np.flatnonzero(arc > 0)
        if not len(sides):
            continue
        side = np.repeat(sides, DENSE)
        s = (np.linspace(0.0, 1.0, DENSE)[None] * arc[sides, None]).ravel()
        C, _, F = chunk.curves(side, s)
        F = F.reshape(len(sides), DENSE, 3)
        fastest = _fastest_turn(F, chunk.apex[chunk.side_vertex[sides]])
        fillet = np.flatnonzero(sa.conical[sides])
        if len(fillet):  # a conical fillet: the cone from its sharp end S over its arc
            C = C.reshape(len(sides), DENSE, 3)[fillet]
            fastest[fillet] = np.maximum(fastest[fillet], _fastest_turn(C, sa.S[sides[fillet]]))
        count = np.ceil(fastest * (DENSE - 1) / (SAFETY * step_deg)) + 1
        rows = [
            sa.edge[sides],
            np.asarray([part[i][0].vertex for i in chunk.side_vertex[sides]], dtype=np.int64),
            np.minimum(count, np.iinfo(np.int32).max).astype(np.int64),
            arc[sides],
        ]
        found.append(rows)
        if cache is not None:
            owner = chunk.side_vertex[sides]
            for i, x in enumerate(part):
                mine = owner == i
                cache[x[0].vertex] = (x[0], _measured_for(x), [col[mine] for col in rows])
    return tuple(np.concatenate(col) for col in zip(*found, strict=True))


def _measured_for(cone: tuple) -> tuple:
    """What a cone's rows depend on besides its frame: its apex and developed apex."""
    _, apex, developed = cone
    return (
        np.asarray(apex, dtype=float).tobytes(),
        None if developed is None else np.asarray(developed, dtype=float).tobytes(),
    )


def _fastest_turn(P: np.ndarray, apex: np.ndarray) -> np.ndarray:
    """(k,) the largest turn (degrees) between the normals of neighbouring triangles
    ``(apex, P_j, P_j+1)`` of each of ``k`` fans, ``P`` (k, m, 3), ``apex`` (k, 3); a triangle
    without area turns by nothing."""
    n = np.cross(P[:, :-1] - apex[:, None], np.diff(P, axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        n = n / np.linalg.norm(n, axis=2, keepdims=True)
        cos = np.einsum("ijk,ijk->ij", n[:, 1:], n[:, :-1])
        sin = np.linalg.norm(np.cross(n[:, 1:], n[:, :-1]), axis=2)
    turn = np.degrees(np.arctan2(sin, cos))
    return np.where(np.isfinite(turn), turn, 0.0).max(axis=1, initial=0.0)


def facet_limit(step_deg: float) -> float:
    """The largest fold between two neighbouring facets of one patch (degrees): the arc step;
    180 (no limit) where the step is 0 (the chord tolerance, or the samples, alone decide)."""
    return float(step_deg) if step_deg > 0 else 180.0


def chord_mismatch_bound(step_deg: float) -> float:
    """The largest relative difference between an arc turning by ``step_deg`` degrees and its
    chord, ``1 - sin(t / 2) / (t / 2)``: how much shorter a facet's side across a bent patch is
    folded than flat (0 for no step: then no bound, ``inf``)."""
    if step_deg <= 0:
        return math.inf
    h = 0.5 * math.radians(min(step_deg, 180.0))
    return 1.0 - math.sin(h) / h
