"""How tightly the cones bend: the radius of curvature across each ruling of a faceted cone.

A cone bends across its rulings only: at a point ``s`` from its apex, the surface's radius of
curvature across the ruling is ``s dpsi / dtheta``, where ``psi`` is the developed angle about
the apex and ``theta`` the turn of the surface's normal (a circular cone of half-angle
``alpha``: ``s tan(alpha)``). On the pattern's faceted cones, at a ruling edge between two
faces of one cone: ``dtheta`` is the turn between the two faces' normals, ``dpsi`` the mean of
the two faces' angles at the apex (each face spans two rulings), and ``s`` the distance of the
edge's nearer end from the apex: the tightest the cone bends along that ruling on the sheet.

A cone that reaches its apex (the dimple's tip) bends tighter than any floor near it: within
``floor * s / radius`` of the apex (:func:`cone_tip_zones`), where a sheet must be relieved
(metal) or creased (card). The report gives these tip zones for a sheet material.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..arrays import run_next, run_owners
from ..mesh.measures import newell_vectors
from .patch import kind_indices

__all__ = ["ConeRulings", "cone_bend_radii", "cone_rulings", "cone_tip_zones"]

#: A turn between two faces under this (radians) is no bend (a diagonal of a flat facet).
FLAT_TURN = 1e-9
_NO_ENDS = (np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))


class ConeRulings(NamedTuple):
    """The bent ruling edges inside the cones of a pattern (:func:`cone_rulings`): per edge,
    ``radius`` across it at its nearer end, its ``cone`` (mesh vertex), ``rate`` (the radius
    per unit of distance from the apex) and its ends ``a`` (the nearer to the apex) and
    ``b`` (pattern vertices)."""

    radius: np.ndarray
    cone: np.ndarray
    rate: np.ndarray
    a: np.ndarray
    b: np.ndarray


def cone_bend_radii(
    v3: np.ndarray, flat: np.ndarray, start: np.ndarray, face_cone: np.ndarray, apex: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(radius, cone, rate)`` of :func:`cone_rulings`."""
    r = cone_rulings(v3, flat, start, face_cone, apex)
    return r.radius, r.cone, r.rate


def cone_rulings(
    v3: np.ndarray, flat: np.ndarray, start: np.ndarray, face_cone: np.ndarray, apex: np.ndarray
) -> ConeRulings:
    """The radius of curvature across every ruling edge inside a cone.

    Parameters
    ----------
    v3 : (n, 3) float
        Folded points.
    flat, start : int arrays
        The faces, one after the other (:func:`~filletfold.surface.pattern.face_arrays`).
    face_cone : (n_faces,) int
        The mesh vertex whose cone each face is part of; -1 for a face of no cone.
    apex : (n_vertices, 3) float
        Each mesh vertex's cone apex.

    Returns
    -------
    ConeRulings
        ``radius`` (k,) per edge shared by two faces of one cone and bent (turn over
        :data:`FLAT_TURN`); ``cone`` (k,) the mesh vertex of its cone; ``rate`` (k,)
        ``dpsi / dtheta``: the radius grows by it per unit of distance from the apex, so the
        cone bends tighter than ``floor`` along that ruling within ``floor / rate`` of its
        apex (``radius = s * rate``, ``s`` the edge's nearer end's distance from the apex);
        ``a``, ``b`` (k,) its nearer and farther end.
    """
    v3 = np.asarray(v3, dtype=np.float64)
    flat, start = np.asarray(flat, dtype=np.int64), np.asarray(start, dtype=np.int64)
    face_cone = np.asarray(face_cone, dtype=np.int64)
    none = ConeRulings(*(np.zeros(0), np.zeros(0, dtype=np.int64), np.zeros(0)), *_NO_ENDS)
    if not len(flat) or not (face_cone >= 0).any():
        return none
    owner = run_owners(np.diff(start))
    nxt = run_next(start)
    a, b = flat, flat[nxt]
    cone = face_cone[owner]
    keep = np.flatnonzero(cone >= 0)
    if not len(keep):
        return none
    n = len(v3)
    key = np.minimum(a[keep], b[keep]) * n + np.maximum(a[keep], b[keep])
    order = np.lexsort((cone[keep], key))
    k, c = key[order], cone[keep][order]
    pair = np.flatnonzero((k[1:] == k[:-1]) & (c[1:] == c[:-1]))  # one edge, two faces
    if not len(pair):
        return none
    h1, h2 = keep[order[pair]], keep[order[pair + 1]]
    f1, f2 = owner[h1], owner[h2]
    normal = newell_vectors(v3[flat], start, nxt)
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    n1, n2 = normal[f1], normal[f2]
    turn = np.arctan2(np.linalg.norm(np.cross(n1, n2), axis=1), np.einsum("ij,ij->i", n1, n2))
    # each face's angle at its cone's apex: the widest angle from the ruling of its corner
    # farthest from the apex (a corner at the apex itself has no ruling)
    rays = v3[flat] - apex[np.maximum(cone, 0)]
    dist = np.linalg.norm(rays, axis=1)
    rays /= np.maximum(dist, 1e-300)[:, None]
    order = np.lexsort((-dist, owner))
    ref = order[np.r_[0, np.flatnonzero(np.diff(owner[order])) + 1]]  # per face, in order
    first = rays[ref][owner]
    spread = np.arctan2(np.linalg.norm(np.cross(first, rays), axis=1), (first * rays).sum(axis=1))
    width = np.maximum.reduceat(spread, start[:-1]) if len(start) > 1 else np.zeros(0)
    u = cone[h1]
    sa = np.linalg.norm(v3[a[h1]] - apex[u], axis=1)
    sb = np.linalg.norm(v3[b[h1]] - apex[u], axis=1)
    near = np.where(sa <= sb, a[h1], b[h1])
    far = np.where(sa <= sb, b[h1], a[h1])
    s = np.minimum(sa, sb)
    bent = turn > FLAT_TURN
    with np.errstate(divide="ignore", invalid="ignore"):
        rate = 0.5 * (width[f1] + width[f2]) / turn
    return ConeRulings((s * rate)[bent], u[bent], rate[bent], near[bent], far[bent])


def cone_tip_zones(pattern, apex: np.ndarray, floor: float) -> np.ndarray:
    """Per cone of ``pattern`` (a :class:`~filletfold.surface.pattern.CreasePattern` whose
    faces' patches name its cones; ``apex`` per mesh vertex), the distance from its apex
    within which it bends tighter than ``floor`` (0 where it never does): where the sheet
    must be relieved or creased. Returns ``(n_vertices,)`` float, NaN at vertices without a
    cone in the pattern."""
    from .pattern import face_arrays

    flat, start = face_arrays(pattern.faces)
    cone = kind_indices(pattern.face_patch, "cone")
    apex = np.asarray(apex, dtype=np.float64)
    out = np.full(len(apex), np.nan)
    out[np.unique(cone[cone >= 0])] = 0.0
    radius, u, rate = cone_bend_radii(
        pattern.vertices_3d, flat, start, cone, np.where(np.isfinite(apex), apex, 0.0)
    )
    tight = radius < floor
    np.maximum.at(out, u[tight], floor / rate[tight])
    return out
