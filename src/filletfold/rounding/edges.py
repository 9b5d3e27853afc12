"""Edge rounding: one right circular cylinder per interior edge (paper sec. 2.1, 4.1).

For an interior edge with front normals ``N_a`` (face holding ``a -> b``) and ``N_b``:

* ``gamma`` is half the angle between the normals, ``kappa = +1`` for a mountain (convex seen from
  the front) and ``-1`` for a valley;
* the rounded arc has length ``a = 2 r gamma``, it replaces a strip of width ``A = 2 r tan(gamma)``
  (``A / 2`` on each face, from the edge to the tangent line), and the material loss is
  ``w = A - a``;
* the cylinder's axis passes through ``O = M - kappa (r / cos gamma) unit(N_a + N_b)`` (``M`` the
  edge midpoint) along the edge.

Boundary edges and flat edges (between coplanar faces that could not be merged, e.g. a ring of
faces around a hole) are not rounded (radius 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..mesh.polymesh import PolyMesh, mesh_size
from ..tolerances import tol


def edge_dihedral(mesh: PolyMesh) -> tuple[np.ndarray, np.ndarray]:
    """Half angle and mountain/valley sign of every edge.

    Parameters
    ----------
    mesh : PolyMesh

    Returns
    -------
    half_angle : (n_edges,) float
        ``gamma``: half the angle between the two face normals (radians); 0 at boundary edges.
    kappa : (n_edges,) int
        +1 mountain (convex seen from the front), -1 valley, 0 boundary or flat.
    """
    ef = mesh.edge_faces
    inner = (ef >= 0).all(axis=1)
    gamma = np.zeros(mesh.n_edges)
    kappa = np.zeros(mesh.n_edges, dtype=np.int64)
    na = mesh.face_normal[ef[inner, 0]]
    nb = mesh.face_normal[ef[inner, 1]]
    t = mesh.vertices[mesh.edges[inner, 1]] - mesh.vertices[mesh.edges[inner, 0]]
    t /= np.linalg.norm(t, axis=1)[:, None]
    cr = np.cross(na, nb)
    sin = np.linalg.norm(cr, axis=1)
    cos = np.einsum("ij,ij->i", na, nb)
    gamma[inner] = 0.5 * np.arctan2(sin, cos)
    kappa[inner] = np.sign(np.einsum("ij,ij->i", cr, t)).astype(np.int64)
    return gamma, kappa


def tan_minus_angle(half_angle):
    """``tan(gamma) - gamma`` without cancellation for small angles (series below 0.1)."""
    g = np.asarray(half_angle, dtype=float)
    g2 = g * g
    series = g * g2 * (1 / 3 + g2 * (2 / 15 + g2 * (17 / 315 + g2 * 62 / 2835)))
    return np.where(np.abs(g) < 0.1, series, np.tan(g) - g)


def loss_from_radius(radius, half_angle):
    """Material loss ``w = 2 r (tan(gamma) - gamma)`` of a rounded edge (sec. 4.1)."""
    radius = np.asarray(radius, dtype=float)
    half_angle = np.asarray(half_angle, dtype=float)
    return 2.0 * radius * tan_minus_angle(half_angle)


def radius_from_loss(loss, half_angle):
    """Radius ``r = w / (2 (tan(gamma) - gamma))`` that causes material loss ``w`` (sec. 4.1)."""
    loss = np.asarray(loss, dtype=float)
    half_angle = np.asarray(half_angle, dtype=float)
    return loss / (2.0 * tan_minus_angle(half_angle))


def _corner_table(mesh: PolyMesh):
    """Per face corner: the outgoing and incoming edge, the corner angle.

    Returns
    -------
    e_out, e_in : (n_halfedges,) int
        Edge of the half-edge leaving the corner vertex, and of the one entering it.
    alpha : (n_halfedges,) float
        Face angle at the corner (radians).
    """
    he_edge = mesh.halfedge_edge
    return he_edge, he_edge[mesh.halfedge_prev], mesh.corner_angles()


def radius_limits(mesh: PolyMesh, edge_radius: np.ndarray, half_angle: np.ndarray):
    """Largest valid radius of every edge, and the corners that the given radii break.

    A radius is valid when, at every face corner, the two tangent lines cross before the
    midpoint cross-sections of both edges (``l_max > 0`` on both), so that every face keeps a
    flat piece and every cylinder keeps its midpoint base curve; on an unrounded edge they
    cross ``4 tol.ruling`` of the mesh's size before it (a quarter of the edge at most), or its
    line on the face would be a sliver of the pattern. At a corner with angle
    ``alpha`` and tangent-line offsets ``d_e = r_e tan(gamma_e)``, the crossing T lies at
    ``x_e = (d_g + d_e cos(alpha)) / sin(alpha)`` along edge ``e`` from the corner.

    Parameters
    ----------
    mesh : PolyMesh
    edge_radius : (n_edges,) float
        Requested radii (0 at boundary and flat edges).
    half_angle : (n_edges,) float

    Returns
    -------
    limit : (n_edges,) float
        Largest radius of each edge when the edges it shares a corner with are rounded alike
        (``inf`` at edges that are not rounded).
    given : (n_edges,) float
        Largest radius of each edge with the other edges at their requested radii (0 when
        those alone leave no room).
    broken : (n_edges,) bool
        Edges whose tangent-line crossing passes their midpoint with the requested radii.
    uniform_limit : float
        Largest radius that is valid when used on every rounded edge.
    """
    e_out, e_in, alpha = _corner_table(mesh)
    sliver = 4.0 * tol.ruling * mesh_size(mesh)
    tan_g = np.tan(half_angle)
    rounded = edge_radius > 0
    length = mesh.edge_length
    offset = np.where(rounded, edge_radius * tan_g, 0.0)
    sin, cos = np.sin(alpha), np.cos(alpha)
    limit = np.full(mesh.n_edges, np.inf)
    given = np.full(mesh.n_edges, np.inf)
    broken = np.zeros(mesh.n_edges, dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        for e, g in ((e_out, e_in), (e_in, e_out)):
            te = np.where(rounded[e], tan_g[e], 0.0)
            tg = np.where(rounded[g], tan_g[g], 0.0)
            # both crossings: along e (own) and along g (other), each  k * d_e <= m
            for k, m, ku, half in (
                (
                    cos / sin,
                    0.5 * length[e] - offset[g] / sin,
                    (tg + te * cos) / sin,
                    0.5 * length[e],
                ),
                (
                    1.0 / sin,
                    0.5 * length[g] - offset[g] * cos / sin,
                    (te + tg * cos) / sin,
                    0.5 * length[g],
                ),
            ):
                d_max = np.where(k > 0, m / k, np.where(m >= 0, np.inf, 0.0))
                r_given = np.where(rounded[e], np.maximum(d_max, 0.0) / te, np.inf)
                np.minimum.at(given, e, r_given)
                r_uni = np.where(rounded[e] & (ku > 0), half / ku, np.inf)
                np.minimum.at(limit, e, r_uni)
            x_e = (offset[g] + offset[e] * cos) / sin
            # an unrounded edge (boundary, flat, sharp) keeps a face piece only if its rounded
            # neighbours' tangent lines cross it before its midpoint too, and far enough
            # before it that its line there is no sliver edge of the pattern
            room = np.where(
                rounded[e], -tol.roundoff * length[e], np.minimum(sliver, 0.25 * length[e])
            )
            over = (rounded[e] | rounded[g]) & (x_e > 0.5 * length[e] - room)
            broken[e[over & rounded[e]]] = True
            broken[g[over & rounded[g]]] = True
    return limit, given, broken, float(limit.min(initial=np.inf))


def clamp_radii(
    mesh: PolyMesh, edge_radius, *, share: float = 0.9, flat_deg: float = tol.coplanar_deg
) -> np.ndarray:
    """Reduce requested radii to valid ones, edge by edge.

    Each edge keeps its request when valid; otherwise it gets ``share`` of its limit, and
    edges whose tangent-line crossings still pass their midpoints shrink by ``share`` until
    none does.

    Parameters
    ----------
    mesh : PolyMesh
    edge_radius : float or (n_edges,) float
    share : float
        Fraction of the limit to use, in (0, 1).

    Returns
    -------
    (n_edges,) float
        Radii (0 at boundary and flat edges).
    """
    gamma, _ = edge_dihedral(mesh)
    inner = ~mesh.is_boundary_edge & (2 * gamma >= np.radians(flat_deg))
    r = np.where(inner, np.broadcast_to(np.asarray(edge_radius, float), (mesh.n_edges,)), 0.0)
    limit, *_ = radius_limits(mesh, r, gamma)
    r = np.where(r > share * limit, share * limit, r)
    return shrink_broken(mesh, r, gamma, share=share)


def shrink_broken(mesh: PolyMesh, edge_radius, half_angle, *, share: float = 0.9) -> np.ndarray:
    """Shrink the radii whose tangent-line crossings pass an edge midpoint by ``share`` until
    none does (valid radii are kept as they are).

    Parameters
    ----------
    mesh : PolyMesh
    edge_radius : (n_edges,) float
    half_angle : (n_edges,) float
    share : float
        In (0, 1).

    Returns
    -------
    (n_edges,) float
    """
    r = np.array(edge_radius, dtype=float)
    for _ in range(200):
        _, _, broken, _ = radius_limits(mesh, r, half_angle)
        if not broken.any():
            break
        r[broken] *= share
    return r


@dataclass
class EdgeRounding:
    """The cylinders of all edges.

    Attributes
    ----------
    radius : (n_edges,) float
        Rounding radius (0 for boundary and flat edges).
    half_angle : (n_edges,) float
        ``gamma`` (radians).
    kappa : (n_edges,) int
        +1 mountain, -1 valley, 0 boundary.
    arc_length : (n_edges,) float
        ``a = 2 r gamma``.
    strip_width : (n_edges,) float
        ``A = 2 r tan(gamma)``.
    loss : (n_edges,) float
        ``w = A - a``.
    axis_point : (n_edges, 3) float
        ``O``, the axis point in the midpoint cross-section (edge midpoint at boundary edges).
    tangent_point : (n_edges, 2, 3) float
        Where the cylinder touches face ``edge_faces[e, 0]`` and ``edge_faces[e, 1]`` in the
        midpoint cross-section; the tangent lines are these points plus multiples of the edge
        direction (the edge midpoint at boundary and flat edges).
    limit : (n_edges,) float
        Largest valid radius per edge when its neighbours are rounded alike (see
        :func:`radius_limits`).
    uniform_limit : float
        Largest valid uniform radius.
    sharp : (n_edges,) bool
        Interior edges left sharp: bent, but not rounded (radius 0) because their fillet
        would have been a sliver (see ``floor`` in :func:`round_edges`).
    """

    radius: np.ndarray
    half_angle: np.ndarray
    kappa: np.ndarray
    arc_length: np.ndarray
    strip_width: np.ndarray
    loss: np.ndarray
    axis_point: np.ndarray
    tangent_point: np.ndarray
    limit: np.ndarray
    uniform_limit: float
    sharp: np.ndarray | None = None

    def arc_points(
        self,
        samples: int,
        step_deg: float = 0.0,
        min_chord: float = 0.0,
        chord_tol: float = 0.0,
        radius_scale=1.0,
    ) -> np.ndarray:
        """Points to sample on each edge's arc (both ends included).

        With a chord tolerance, an arc of radius ``r`` that turns by ``2 gamma`` gets

            n = ceil(2 gamma / (2 acos(1 - chord_tol / r))) + 1

        points, at least 2: the fewest whose chords stay within ``chord_tol`` of the arc
        (a chord over the turn ``phi`` is ``r (1 - cos(phi / 2))`` from it at its middle), so
        that a small fillet gets fewer points than a large one turning alike. With an arc step,
        it gets at least one point per ``step_deg`` degrees it turns (at least 2). With
        neither, every arc gets ``samples`` points; ``samples`` is the most any arc gets.
        Flat and boundary edges (no arc) get 1.

        Parameters
        ----------
        samples : int
            Most points per arc (>= 2).
        step_deg : float
            Largest turn between two samples (degrees); 0 for no limit.
        min_chord : float
            Shortest step along an arc (length): a tiny arc gets fewer points, at least 2, so
            that its steps are no pattern slivers. 0 for no limit.
        chord_tol : float
            Largest distance between a chord and its arc (a length); 0 for no limit.
        radius_scale : float or (n_edges,) float
            The largest radius of each edge's rounding over its radius in the midpoint
            cross-section (2 on a conical fillet, whose radius grows from its sharp end;
            1 on a cylinder), for the chord tolerance.

        Returns
        -------
        (n_edges,) int
        """
        n_arcs = len(self.arc_length)
        turn = 2 * self.half_angle
        if step_deg <= 0 and chord_tol <= 0:
            n = np.full(n_arcs, int(samples))
        else:
            need = np.full(n_arcs, 2)
            if step_deg > 0:
                steps = np.ceil(  # an exact multiple of the step gains none
                    np.degrees(turn) / step_deg - tol.relative
                )
                need = np.maximum(need, steps + 1).astype(int)
            if chord_tol > 0:
                need = np.maximum(need, chord_counts(turn, self.radius * radius_scale, chord_tol))
            n = np.minimum(int(samples), need)
        if min_chord > 0:
            fit = np.floor(self.arc_length / min_chord) + 1
            n = np.minimum(n, np.maximum(2, fit).astype(int))
        return np.where(self.arc_length > 0, n, 1)


def chord_counts(turn, radius, chord_tol: float) -> np.ndarray:
    """Fewest points, ends included and at least 2, on an arc of ``radius`` turning by
    ``turn`` (radians) whose chords stay within ``chord_tol`` of it:
    ``ceil(turn / (2 acos(1 - chord_tol / r))) + 1`` (2 where ``r`` is 0).

    Parameters
    ----------
    turn, radius : array_like of float
    chord_tol : float
        A length > 0.

    Returns
    -------
    int array, shaped as ``turn`` and ``radius`` broadcast
    """
    turn, radius = np.broadcast_arrays(np.asarray(turn, float), np.asarray(radius, float))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(radius > 0, chord_tol / radius, np.inf)
    # the turn of the longest chord, 2 acos(1 - x) = 4 asin(sqrt(x / 2)) without cancellation
    step = 4.0 * np.arcsin(np.sqrt(np.minimum(0.5 * ratio, 1.0)))
    with np.errstate(divide="ignore", invalid="ignore"):
        steps = np.where(step > 0, np.ceil(turn / step - tol.relative), 1.0)
    return np.maximum(2, steps + 1).astype(int)


def round_edges(
    mesh: PolyMesh,
    radius,
    *,
    flat_deg: float = tol.coplanar_deg,
    floor: float = 0.0,
    min_width: float = 0.0,
) -> EdgeRounding:
    """Round every interior edge with a cylinder tangent to both faces.

    Parameters
    ----------
    mesh : PolyMesh
    radius : float or (n_edges,) float
        Absolute radius, uniform or per edge (values at boundary and flat edges are ignored; 0
        on a bent edge leaves it sharp).
    flat_deg : float
        An interior edge whose faces meet within this angle (degrees) is flat: not rounded
        (radius 0), its two faces join smoothly.
    floor : float
        An edge whose fillet would be narrower than ``floor`` times the edge's length
        (strip width ``A = 2 r tan(gamma)``) is left sharp: radius 0, its faces meet at a
        straight crease folded by the dihedral angle (half angle and kappa kept). 0: none.
    min_width : float
        An edge whose fillet would be narrower than this (a length) is left sharp too: a
        fillet of a short edge in a large design. 0: none.

    Returns
    -------
    EdgeRounding

    Raises
    ------
    ParameterError
        If a radius is not finite or negative, or exceeds its edge's limit (the message
        names the edge, its vertices, the limit and the largest uniform radius).
    """
    gamma, kappa = edge_dihedral(mesh)
    inner = ~mesh.is_boundary_edge
    if np.ndim(radius) and np.shape(radius) != (mesh.n_edges,):
        raise ParameterError(
            f"per-edge radius must have shape ({mesh.n_edges},), got {np.shape(radius)}",
            name="radius",
        )
    r = np.broadcast_to(np.asarray(radius, dtype=float), (mesh.n_edges,)).copy()
    flat = inner & (2 * gamma < np.radians(flat_deg))
    rounded = inner & ~flat
    if not np.all(np.isfinite(r[rounded])):
        raise ParameterError("radius must be finite", name="radius")
    if np.any(r[rounded] < 0):
        e = int(np.nonzero(rounded & (r < 0))[0][0])
        raise ParameterError(
            f"radius must be positive (edge {e} has {r[e]:g})", name="radius", edge=e
        )
    r[~inner | flat] = 0.0
    kappa[flat] = 0
    width = 2 * r * np.tan(gamma)
    sharp = rounded & ((r == 0) | (width < np.maximum(floor * mesh.edge_length, min_width)))
    r[sharp] = 0.0
    rounded &= ~sharp
    limit, given, broken, uniform = radius_limits(mesh, r, gamma)
    if broken.any():
        ratio = np.where(broken, r / limit, 0.0)
        e = int(np.argmax(ratio))
        a, b = mesh.edges[e]
        raise ParameterError(
            f"radius {r[e]:.6g} on edge {e} (vertices {a}-{b}) exceeds its limit "
            f"{limit[e]:.6g} (beyond it the face pieces next to the edge vanish; with its "
            f"neighbours' radii it can be at most {given[e]:.6g}); {int(broken.sum())} edge(s) "
            f"are over their limit, the largest radius valid on every edge is {uniform:.6g} "
            "(or let filletfold reduce each radius to fit: --clamp)",
            name="radius",
            edge=e,
        )
    mid = 0.5 * (mesh.vertices[mesh.edges[:, 0]] + mesh.vertices[mesh.edges[:, 1]])
    axis = mid.copy()
    ef = mesh.edge_faces
    nsum = mesh.face_normal[ef[rounded, 0]] + mesh.face_normal[ef[rounded, 1]]
    nsum /= np.linalg.norm(nsum, axis=1)[:, None]
    shift = kappa[rounded] * r[rounded] / np.cos(gamma[rounded])
    axis[rounded] = mid[rounded] - shift[:, None] * nsum
    tangent = np.repeat(mid[:, None], 2, axis=1)
    for k in (0, 1):
        n = mesh.face_normal[ef[rounded, k]]
        tangent[rounded, k] = axis[rounded] + (kappa[rounded] * r[rounded])[:, None] * n
    gamma = np.where(flat, 0.0, gamma)
    arc = 2 * r * gamma  # 0 at flat and sharp edges
    strip = 2 * r * np.tan(gamma)
    return EdgeRounding(
        radius=r,
        half_angle=gamma,
        kappa=kappa,
        arc_length=arc,
        strip_width=strip,
        loss=loss_from_radius(r, gamma),
        axis_point=axis,
        tangent_point=tangent,
        limit=limit,
        uniform_limit=uniform,
        sharp=sharp,
    )
