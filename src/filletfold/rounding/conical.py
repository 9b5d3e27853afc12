"""Conical meshes (paper sec. 4.4): material loss from a face offset, apices on the cone axes.

At a vertex of a conical mesh all incident face planes touch one cone of revolution, i.e. the
unit face normals lie on one circle of the sphere: ``n_f . a = c`` for an axis ``a`` and a
constant ``c``. The faces then have offsets at constant distance ``delta`` whose vertices lie on
the axes, ``U' = U - sigma delta a / c``. Projecting the offset faces back onto the faces gives
the contracting regions: along every edge a strip of width ``delta tan(gamma)`` on each side,
the same at both ends of the edge, so the cycle equalities of sec. 4.3 hold by construction and
the material loss is ``w_e = 2 delta tan(gamma_e)`` (radius ``w / (2 (tan(gamma) - gamma))``).
The axis is the vertex normal.
"""

from __future__ import annotations

import numpy as np

from ..mesh.polymesh import PolyMesh
from ..tolerances import tol
from .edges import edge_dihedral, radius_from_loss, tan_minus_angle
from .material_loss import MaterialLoss, cycle_equalities


def vertex_cone_axes(mesh: PolyMesh) -> tuple[np.ndarray, np.ndarray]:
    """Axis of the cone of revolution touching the faces of every interior vertex.

    Parameters
    ----------
    mesh : PolyMesh

    Returns
    -------
    axis : (n_vertices, 3) float
        Unit axis ``a`` with ``n_f . a = c > 0`` for the incident faces (NaN at boundary
        vertices and where the normals are degenerate).
    residual : (n_vertices,) float
        Largest ``|n_f . a - c|`` (radians-like; 0 for a conical vertex, NaN at boundary).
    """
    axis = np.full((mesh.n_vertices, 3), np.nan)
    residual = np.full(mesh.n_vertices, np.nan)
    faces_of = [[] for _ in range(mesh.n_vertices)]
    for h, f in zip(mesh.halfedge_from, mesh.halfedge_face, strict=True):
        faces_of[h].append(f)
    for u in np.nonzero(~mesh.is_boundary_vertex)[0]:
        n = mesh.face_normal[faces_of[u]]
        # the normals' circle lies in the plane  a . x = c : fit through their centroid
        centre = n.mean(axis=0)
        vt = np.linalg.svd(n - centre)[2]
        a = vt[-1]
        if a @ centre < 0:
            a = -a
        c = float(a @ centre)
        if c <= 0:
            continue
        axis[u] = a
        residual[u] = float(np.abs(n @ a - c).max()) if len(n) > 3 else 0.0
    return axis, residual


def is_conical(mesh: PolyMesh, atol: float = tol.relative) -> bool:
    """True when every interior vertex is conical (and there is at least one)."""
    _, res = vertex_cone_axes(mesh)
    inner = ~mesh.is_boundary_vertex
    return bool(inner.any() and np.all(np.nan_to_num(res[inner], nan=np.inf) <= atol))


def conical_material_loss(
    mesh: PolyMesh,
    *,
    max_loss: float | None = None,
    max_radius=None,
    share: float = 0.3,
    flat_deg: float = tol.coplanar_deg,
) -> tuple[MaterialLoss, float]:
    """Material loss of a conical mesh from the largest valid face offset (sec. 4.4).

    Parameters
    ----------
    mesh : PolyMesh
    max_loss : float, optional
        Cap on every edge's loss.
    max_radius : float or (n_edges,) float, optional
        Cap on every edge's radius.
    share : float
        Every tangent-line crossing T stays within ``share`` of each edge's half length.

    Returns
    -------
    loss : MaterialLoss
    delta : float
        The offset distance used.
    """
    gamma, _ = edge_dihedral(mesh)
    rounded = ~mesh.is_boundary_edge & (2 * gamma >= np.radians(flat_deg))
    g = np.where(rounded, gamma, 0.0)
    # per unit offset: loss 2 tan(gamma), tangent-line offset d = r tan(gamma)
    w1 = 2 * np.tan(g)
    tm = np.where(rounded, tan_minus_angle(np.where(rounded, g, 1.0)), 1.0)
    d1 = np.where(rounded, w1 * np.tan(g) / (2 * tm), 0.0)
    he_edge = mesh.halfedge_edge
    prev = mesh.halfedge_prev
    alpha = mesh.corner_angles()
    sin, cos = np.sin(alpha), np.cos(alpha)
    L = mesh.edge_length
    delta = np.inf
    for own, other in ((he_edge, he_edge[prev]), (he_edge[prev], he_edge)):
        k = (d1[other] + d1[own] * cos) / np.where(sin > 0, sin, np.nan)
        ok = rounded[own] & (sin > 0) & (k > 0)
        if ok.any():
            delta = min(delta, float(np.min(share * 0.5 * L[own][ok] / k[ok])))
    if max_loss is not None and w1.max() > 0:
        delta = min(delta, max_loss / float(w1.max()))
    if max_radius is not None:
        r1 = np.where(rounded, w1 / (2 * tm), 0.0)  # radius per unit offset
        cap = np.broadcast_to(np.asarray(max_radius, dtype=float), r1.shape)
        pos = r1 > 0
        if pos.any():
            delta = min(delta, float(np.min(cap[pos] / r1[pos])))
    if not np.isfinite(delta):
        delta = 0.0
    w = np.where(rounded, delta * w1, 0.0)
    # half-edge widths delta tan(gamma) on both sides of every rounded edge
    u = np.where(rounded[he_edge], 0.5 * w[he_edge], 0.0)
    A, rows = cycle_equalities(mesh, ~mesh.is_boundary_vertex)
    closure = np.zeros(mesh.n_vertices)
    if A.shape[0]:
        for (vtx, _), r in zip(rows, np.abs(A @ u), strict=True):
            closure[vtx] = max(closure[vtx], r)
    radius = np.where(rounded & (w > 0), radius_from_loss(w, np.where(rounded, g, 1.0)), 0.0)
    widths = u[rounded[he_edge]]
    b = float(widths.min()) if len(widths) else 0.0
    ok = delta > 0 and b > 0
    return MaterialLoss(
        ok=ok,
        bound=b,
        halfedge_width=u,
        edge_loss=w,
        edge_radius=radius,
        closure=closure,
        tight=[
            f"face offset delta = {delta:.6g} (largest with every tangent-line crossing T "
            f"within {share:g} of the half edge and the caps)"
        ],
        binding=[],
        message=(
            f"conical mesh: material loss from the face offset delta = {delta:.6g} (sec. 4.4)"
            if ok
            else "conical mesh: no positive face offset fits"
        ),
    ), delta
