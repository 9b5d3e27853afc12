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

from ..arrays import run_owners, split_runs
from ..rounding.tapered import FilletRows, arc_points, cone_rulings, developed_angles
from ..vertex.frame import VertexFrame, to_chart
from .patch import Patch
from .piece import Piece

#: A fan is split into runs that each sweep at most ``2 pi - SEAM_MARGIN`` (radians), so that
#: no run's two cut rays come closer than that angle.
SEAM_MARGIN = 0.05


def _side_points(frames: list, conical, n_samples) -> list[list[tuple]]:
    """Per frame, the half of each side seen from the sharp vertex: 3D points, their
    distances to ``S`` and their developed angles from the side's start (one point, ``M``,
    when not conical). The conical halves of all frames are computed together."""
    out = []
    rows = []  # (frame, side, s) of the conical halves
    for k, frame in enumerate(frames):
        halves = []
        for i, side in enumerate(frame.sides):
            rounded = side.radius > 0 and (conical is None or conical[side.edge])
            if not rounded:
                halves.append((side.M[None], np.array([0.5 * side.length]), np.zeros(1)))
                continue
            n = int(n_samples) if np.ndim(n_samples) == 0 else int(n_samples[side.edge])
            rows.append((k, i, np.linspace(0.0, side.arc, max(n, 2))))
            halves.append(None)
        out.append(halves)
    if not rows:
        return out
    count = np.array([len(s) for _, _, s in rows])
    which = run_owners(count)
    sides = [frames[k].sides[i] for k, i, _ in rows]
    s = np.concatenate([s for _, _, s in rows])
    O, N0, B = (np.array([getattr(x, a) for x in sides])[which] for a in ("O", "N0", "B"))
    kappa = np.array([float(x.kappa) for x in sides])[which]
    radius = np.array([x.radius for x in sides])[which]
    S = np.array([frames[k].U for k, _, _ in rows])[which]
    C = arc_points(O, N0, B, kappa, radius, s)[0]
    rho = cone_rulings(C, S)[1]
    theta = developed_angles(FilletRows(O, N0, B, kappa, radius, S), s, fillet=which)
    bounds = np.cumsum(count)[:-1]
    for (k, i, _), c, r, th in zip(
        rows, split_runs(C, bounds), split_runs(rho, bounds), split_runs(theta, bounds), strict=True
    ):
        out[k][i] = (c, r, th)
    return out


def _fan(frame: VertexFrame, centres: np.ndarray, sides: list):
    """Every face's wedge at ``S`` and its three corners ``P``, centre, ``P'`` in the face's
    chart with the chart angle of ``P``, given the frame's side halves (:func:`_side_points`)."""
    ring = frame.ring
    n_e, n_f = len(ring.edges), len(ring.faces)
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
    return wedge, chart_points


def _polar(angle: np.ndarray, radius: np.ndarray) -> np.ndarray:
    return np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=-1)


def sharp_module(frame: VertexFrame, centres: np.ndarray, conical, n_samples) -> list[Piece]:
    """The flat piece(s) of one sharp vertex (:func:`sharp_modules` of a batch of one)."""
    return sharp_modules([frame], centres, conical, n_samples)[0]


def _module(frame: VertexFrame, centres: np.ndarray, sides: list) -> list[Piece]:
    """The flat piece(s) of one sharp vertex from its side halves (:func:`_side_points`).

    Parameters
    ----------
    frame : VertexFrame
    centres : (n_faces, 3) float
        Face piece centres, by mesh face.
    sides : list
        Its side halves.

    Returns
    -------
    list of Piece
    """
    ring = frame.ring
    n_e, n_f = len(ring.edges), len(ring.faces)
    U = frame.U
    wedge, chart_points = _fan(frame, centres, sides)
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
            flat = _polar(phi + theta, rho)
            idx = [piece.point(("side", i, k), flat[k], C[k]) for k in range(len(C))]
            patch = Patch("fillet", int(ring.edges[i]))
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
            piece.face([apex, p_end, p_c, p_next], Patch("face", int(ring.faces[i])))
            phi += wedge[i]
    return [p.compact() for p in pieces]


def sharp_modules(frames: list, centres: np.ndarray, conical, n_samples) -> list[list[Piece]]:
    """The modules of many sharp vertices.

    Parameters
    ----------
    frames : sequence of VertexFrame
    centres : (n_faces, 3) float
        Face piece centres, by mesh face.
    conical : (n_edges,) bool or None
        Which edges are conical fillets (the other end takes a cone); None: every rounded
        side (radius > 0: an edge between two sharp vertices has radius 0).
    n_samples : int or (n_edges,) int
        Points per fillet arc.

    Returns
    -------
    list of list of Piece
        One module per frame, in order (the fillets of all frames computed together).
    """
    frames = list(frames)
    halves = _side_points(frames, conical, n_samples)
    return [_module(f, centres, h) for f, h in zip(frames, halves, strict=True)]


def fan_angle(frame: VertexFrame, centres: np.ndarray, conical=None) -> float:
    """The angle the sharp vertex's fan sweeps in the development (radians): the faces'
    wedges at ``S`` (each corner angle less ``psi`` beside each conical side) plus the
    fillets' sectors ``theta(a)``."""
    sides = _side_points([frame], conical, 2)[0]
    wedge, _ = _fan(frame, centres, sides)
    return float(wedge.sum() + sum(side[2][-1] for side in sides))
