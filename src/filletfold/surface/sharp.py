"""Modules of sharp vertices: the polyhedron's corner kept, the fillets tapering into it.

A *sharp* vertex ``S`` takes no cone (see ``docs/method.md``, "Sharp vertices and conical
fillets"). Its module is a fan around ``S``, in ring order: for each incident edge ``e_i`` the
vertex's half of it, then its share of face ``f_i``, and so on around the ring.

- On a **conical** edge (rounded, its other end takes a cone) the half is the conical fillet
  from ``S`` to the edge's base curve: the triangles ``(S, C(s_k), C(s_{k+1}))`` of the cone,
  developed as a sector of angle ``theta(a)`` (:mod:`filletfold.rounding.tapered`).
- On any other edge (a sharp crease between two sharp vertices, an unrounded, flat or
  boundary edge) the half is the segment from ``S`` to the edge's midpoint ``M``: the faces on
  either side meet along it.
- The share of face ``f_i`` is the polygon ``[S, P_i, centre, P'_{i+1}]``: ``P_i`` where edge
  ``e_i``'s half ends on the face (the base curve's end ``C(a)`` on a conical edge, ``M``
  otherwise), the face piece's centre, and ``P'_{i+1}`` where edge ``e_{i+1}``'s half starts
  on it (``C(0)`` or ``M``). These are the corners the neighbours' shares of the face use.

The development lays the fan around ``S`` at the origin, each face share rigidly (its chart
turned about ``S``) and each fillet as its sector, so every join is a ray from ``S``. The
angle swept is the sum of the faces' wedges and the fillets' sectors. A closed ring is cut
along the ray to the first edge's start; a fan that sweeps more than ``2 pi`` less
:data:`SEAM_MARGIN` (a saddle) is split into runs of whole elements that each sweep less. An
open ring (a boundary vertex) starts and ends on its boundary edges' straight halves: the
sheet's edge stays straight there.
"""

from __future__ import annotations

import numpy as np

from ..rounding.tapered import arc_points, cone_rulings, developed_angles
from ..vertex.frame import VertexFrame, to_chart
from .piece import Piece

#: A fan is split into runs that each sweep at most ``2 pi - SEAM_MARGIN`` (radians), so that
#: no run's two cut rays come closer than that angle.
SEAM_MARGIN = 0.05


def _side_points(frame: VertexFrame, i: int, conical, n_samples):
    """The half of side ``i`` seen from the sharp vertex: 3D points, their distances to ``S``
    and their developed angles from the side's start (one point, ``M``, when not conical)."""
    side = frame.sides[i]
    U = frame.U
    if not ((side.radius > 0) if conical is None else (conical[side.edge] and side.radius > 0)):
        return side.M[None], np.array([0.5 * side.length]), np.zeros(1)
    n = int(n_samples) if np.ndim(n_samples) == 0 else int(n_samples[side.edge])
    s = np.linspace(0.0, side.arc, max(n, 2))
    m = len(s)
    rows = (
        np.repeat(side.O[None], m, 0),
        np.repeat(side.N0[None], m, 0),
        np.repeat(side.B[None], m, 0),
        np.full(m, float(side.kappa)),
        np.full(m, side.radius),
    )
    C = arc_points(*rows, s)[0]
    S = np.repeat(U[None], m, 0)
    return C, cone_rulings(C, S)[1], developed_angles(*rows, S, s, fillet=np.zeros(m, int))


def _fan(frame: VertexFrame, centres: np.ndarray, conical, n_samples):
    """Every side's half (:func:`_side_points`), every face's wedge at ``S`` and its three
    corners ``P``, centre, ``P'`` in the face's chart with the chart angle of ``P``."""
    ring = frame.ring
    n_e, n_f = len(ring.edges), len(ring.faces)
    sides = [_side_points(frame, i, conical, n_samples) for i in range(len(ring.edges))]
    chart_points = []
    wedge = np.zeros(n_f)
    for f in range(n_f):
        start = sides[f][0][-1]  # where side f's half ends on face f
        end = sides[(f + 1) % n_e][0][0]  # where side f+1's half starts on it
        ch = to_chart(frame.face_frames[f], np.stack([start, centres[ring.faces[f]], end]))
        a0 = np.arctan2(ch[0, 1], ch[0, 0])
        rel = np.mod(np.arctan2(ch[:, 1], ch[:, 0]) - a0, 2 * np.pi)
        wedge[f] = rel[2]
        chart_points.append((ch, a0))
    return sides, wedge, chart_points


def _polar(angle: np.ndarray, radius: np.ndarray) -> np.ndarray:
    return np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=-1)


def sharp_module(frame: VertexFrame, centres: np.ndarray, conical, n_samples) -> list[Piece]:
    """The flat piece(s) of one sharp vertex (:func:`sharp_modules` of a batch of one).

    Parameters
    ----------
    frame : VertexFrame
    centres : (n_faces, 3) float
        Face piece centres, by mesh face.
    conical : (n_edges,) bool or None
        Which edges are conical fillets (the other end takes a cone); None: every rounded
        side (radius > 0: an edge between two sharp vertices has radius 0).
    n_samples : int or (n_edges,) int
        Points per fillet arc.

    Returns
    -------
    list of Piece
    """
    ring = frame.ring
    n_e, n_f = len(ring.edges), len(ring.faces)
    U = frame.U
    sides, wedge, chart_points = _fan(frame, centres, conical, n_samples)
    # elements in ring order: side 0, face 0, side 1, ..., (closed) face n_f - 1
    elements = []
    for i in range(n_e):
        elements.append(("side", i))
        if i < n_f:
            elements.append(("face", i))
    pieces: list[Piece] = []
    piece = None
    phi = 0.0  # angle of the current ray in the development
    run_start = 0.0
    limit = 2 * np.pi - SEAM_MARGIN
    for kind, i in elements:
        sweep = sides[i][2][-1] if kind == "side" else wedge[i]
        if piece is None or phi + sweep - run_start > limit:
            if piece is not None and kind == "face" and sweep > limit:
                raise ValueError(f"vertex {frame.vertex}: face {ring.faces[i]} spans its corner")
            piece = Piece(vertex=int(frame.vertex))
            pieces.append(piece)
            run_start = phi
        apex = piece.point(("S",), (0.0, 0.0), U)
        if kind == "side":
            C, rho, theta = sides[i]
            idx = [
                piece.point(("side", i, k), _polar(phi + theta[k], rho[k]), C[k])
                for k in range(len(C))
            ]
            patch = f"fillet {ring.edges[i]}"
            for k in range(len(idx) - 1):
                piece.face([apex, idx[k], idx[k + 1]], patch)
            phi += theta[-1]
        else:
            ch, a0 = chart_points[i]
            turn = phi - a0
            c, s_ = np.cos(turn), np.sin(turn)
            rot = ch @ np.array([[c, s_], [-s_, c]])
            j = (i + 1) % n_e
            last_start = ("side", j, 0)
            p_end = piece.point(("side", i, len(sides[i][0]) - 1), rot[0], sides[i][0][-1])
            p_c = piece.point(("centre", i), rot[1], centres[ring.faces[i]])
            if j == 0 and ring.closed:
                last_start = ("seam",)  # the cut: side 0's start again, at the fan's end
            p_next = piece.point(last_start, rot[2], sides[j][0][0])
            piece.face([apex, p_end, p_c, p_next], f"face {ring.faces[i]}")
            phi += wedge[i]
    return [p.compact() for p in pieces]


def sharp_modules(frames: list, centres: np.ndarray, conical, n_samples) -> list[list[Piece]]:
    """The modules of many sharp vertices: :func:`sharp_module` of each frame.

    Parameters
    ----------
    frames : sequence of VertexFrame
    centres : (n_faces, 3) float
    conical : (n_edges,) bool or None
    n_samples : int or (n_edges,) int

    Returns
    -------
    list of list of Piece
        One module per frame, in order.
    """
    return [sharp_module(f, centres, conical, n_samples) for f in frames]


def fan_angle(frame: VertexFrame, centres: np.ndarray, conical=None) -> float:
    """The angle the sharp vertex's fan sweeps in the development (radians): the faces'
    wedges at ``S`` (each corner angle less ``psi`` beside each conical side) plus the
    fillets' sectors ``theta(a)``."""
    sides, wedge, _ = _fan(frame, centres, conical, 2)
    return float(wedge.sum() + sum(side[2][-1] for side in sides))
