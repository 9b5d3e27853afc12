"""Consistent material loss: the linear programme of paper sec. 4.2-4.3, solved with HiGHS.

Rounding an edge removes a strip of material of width ``w = A - a`` (sec. 4.1). Around every
interior vertex, walking perpendicular to the incident edges by their losses must close up
(sec. 4.2): then the rounded surface of a developable input folds from one uncut sheet.

Variables: one width ``u_h >= b`` per half-edge ``h`` (edge ``e`` seen from face ``f``): the part of
``e``'s loss taken from face ``f``, so ``w_e = u_(e,f) + u_(e,g)``. In the sector of face ``f`` at
vertex U, between edges ``e`` and ``e'`` with angle ``alpha``, the corner of the contracting cycle
lies at distance ``u_(e,f)`` from ``e`` and ``u_(e',f)`` from ``e'``; it projects onto ``e`` at
``x = (u_(e',f) + u_(e,f) cos(alpha)) / sin(alpha)`` from U. The cycle's side across ``e`` is
perpendicular to ``e`` when both sectors beside ``e`` give the same ``x`` -- the paper's equality
``(w_i^+ + w_i^- cos a_i) / sin a_i = (w_j^- + w_j^+ cos a_j) / sin a_j``, which checks out
against the geometry of fig. 15.

Correction to sec. 4.3 (docs/method.md, 'Corrections to the paper', 10): the paper gives each
sector its own ``w_i^{+/-}``, so a half-edge would have independent widths at its two ends and
the region between the two cycles would be a trapezoid, not the rectangle of fig. 13. Here a
half-edge has one width, shared by both of its ends, so every region is a rectangle and
contracting it gives a consistent sheet.

The programme maximises ``b``; among its solutions the one with the smallest total loss is
kept (a second linear programme), so the widths stay near ``b`` instead of at their caps.

The paper leaves the "maximal rounding width" undefined. Here every face corner must keep its
tangent-line crossing T within ``share`` of each edge's half length (the radius limit of
:func:`filletfold.rounding.edges.radius_limits`, with room left for the crease), and optionally
``w_e <= max_loss``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import lsqr

from ..errors import ParameterError
from ..mesh.polymesh import PolyMesh
from ..tolerances import tol
from .edges import edge_dihedral, radius_from_loss, tan_minus_angle

#: Stage 2 keeps every width at least this share below the optimal bound ``b*`` of stage 1
#: (the LP's own round-off would otherwise make stage 2 infeasible).
LP_STAGE_SLACK = 1e-9
#: Tolerances of the least-squares polish that removes the equality residual.
POLISH_TOL = 1e-16
#: An inequality row is tight (named in the report) when its slack is below this share of the
#: mean edge length.
TIGHT = 1e-9
#: The bound ``b`` is positive (a solution) above this share of the mean edge length.
POSITIVE_BOUND = 1e-12
#: With no solution, the equality rows whose dual marginal exceeds this bind (they are named).
BINDING_MARGINAL = 1e-9


@dataclass
class MaterialLoss:
    """Result of the material-loss linear programme.

    Attributes
    ----------
    ok : bool
        True when the programme is feasible with ``b > 0``.
    bound : float
        The optimal ``b`` (smallest half-edge width).
    halfedge_width : (n_halfedges,) float
        ``u_h`` per mesh half-edge (0 at boundary and flat edges).
    edge_loss : (n_edges,) float
        ``w_e``, the material loss per edge.
    edge_radius : (n_edges,) float
        The radius that causes that loss (0 where not rounded).
    closure : (n_vertices,) float
        Largest violation of the cycle equalities at each interior vertex (0 elsewhere).
    tight : list of str
        Inequalities that hold with equality at the optimum.
    binding : list of str
        When not ok: the vertices and edges that keep ``b`` from being positive.
    message : str
    """

    ok: bool
    bound: float
    halfedge_width: np.ndarray
    edge_loss: np.ndarray
    edge_radius: np.ndarray
    closure: np.ndarray
    tight: list
    binding: list
    message: str


def _corner_rows(mesh: PolyMesh):
    """Projection coefficients of every face corner onto its two edges.

    Returns
    -------
    h_out, h_in : (n_halfedges,) int
        At the corner of half-edge ``h_out`` (its tail), the outgoing and incoming half-edge.
    alpha : (n_halfedges,) float
        Corner angle.
    """
    prev = mesh.halfedge_prev
    return np.arange(len(prev)), prev, mesh.corner_angles()


def cycle_equalities(mesh: PolyMesh, interior: np.ndarray):
    """The cycle equalities ``x_(e,f)(U) = x_(e,g)(U)`` as a sparse matrix over half-edges.

    Parameters
    ----------
    mesh : PolyMesh
    interior : (n_vertices,) bool
        Vertices that get an equality per incident edge.

    Returns
    -------
    A : (n_rows, n_halfedges) scipy.sparse.csr_matrix
    rows : list of (int, int)
        ``(vertex, edge)`` of each row.
    """
    h_out, h_in, alpha = _corner_rows(mesh)
    sin, cos = np.sin(alpha), np.cos(alpha)
    n_h = len(h_out)
    # x along the edge of h_out: (u[h_in] + u[h_out] cos) / sin; along h_in's edge: symmetric.
    # Each expression is two entries (own, other); a row is the difference of the two
    # expressions that meet at (vertex, edge).
    keys, entries = [], []
    for h in np.nonzero(interior[mesh.halfedge_from])[0]:
        u = int(mesh.halfedge_from[h])
        for own, other in ((h_out[h], h_in[h]), (h_in[h], h_out[h])):
            keys.append((u, int(mesh.halfedge_edge[own])))
            entries.append((own, cos[h] / sin[h], other, 1.0 / sin[h]))
    order = sorted(range(len(keys)), key=keys.__getitem__)
    rows, r_idx, c_idx, vals = [], [], [], []
    i = 0
    while i < len(order):
        j = i
        while j < len(order) and keys[order[j]] == keys[order[i]]:
            j += 1
        if j - i == 2:
            for k, sign in ((order[i], 1.0), (order[i + 1], -1.0)):
                own, a, other, b = entries[k]
                r_idx += [len(rows), len(rows)]
                c_idx += [own, other]
                vals += [sign * a, sign * b]
            rows.append(keys[order[i]])
        i = j
    A = sparse.csr_matrix((vals, (r_idx, c_idx)), shape=(len(rows), n_h))
    return A, rows


def solve_material_loss(
    mesh: PolyMesh,
    *,
    max_loss: float | None = None,
    max_radius=None,
    share: float = 0.3,
    flat_deg: float = tol.coplanar_deg,
) -> MaterialLoss:
    """Consistent material loss per edge by the sec. 4.3 linear programme (HiGHS).

    Parameters
    ----------
    mesh : PolyMesh
    max_loss : float, optional
        Upper bound on every edge's loss ``w_e`` (absolute length).
    max_radius : float or (n_edges,) float, optional
        Upper bound on every edge's resulting radius (a loss cap
        ``w_e <= 2 r_max (tan(gamma) - gamma)``); keeps edges with a small dihedral angle,
        whose radius grows like ``w / gamma^3``, from rounding too wide.
    share : float
        Every tangent-line crossing T must stay within ``share`` of each edge's half length from
        the corner, in (0, 1).
    flat_deg : float
        Edges flatter than this (degrees) are not rounded.

    Returns
    -------
    MaterialLoss
    """
    from scipy.optimize import linprog  # 0.1-0.3 s to import: only with material loss

    if not 0 < share < 1:
        raise ParameterError(f"share must be in (0, 1), got {share!r}", name="share")
    if max_loss is not None and not (np.isfinite(max_loss) and max_loss > 0):
        raise ParameterError(
            f"max loss must be a positive length, got {max_loss!r}", name="max_loss"
        )
    gamma, _ = edge_dihedral(mesh)
    rounded = ~mesh.is_boundary_edge & (2 * gamma >= np.radians(flat_deg))
    n_h = len(mesh.halfedge_from)
    he_edge = mesh.halfedge_edge
    var = rounded[he_edge]  # half-edges with a free width
    interior = ~mesh.is_boundary_vertex
    A_eq, rows = cycle_equalities(mesh, interior)

    # offsets d_e = A_e / 2 = k_e w_e of the tangent lines, linear in the loss
    k = np.where(rounded, np.tan(gamma) / (2 * np.where(rounded, tan_minus_angle(gamma), 1.0)), 0.0)
    # w_e = sum of its half-edge widths
    loss_of_edge = sparse.csr_matrix(
        (np.ones(n_h), (he_edge, np.arange(n_h))), shape=(mesh.n_edges, n_h)
    )
    edge_halves = [[] for _ in range(mesh.n_edges)]
    for h, e in enumerate(he_edge):
        edge_halves[e].append(h)
    h_out, h_in, alpha = _corner_rows(mesh)
    sin, cos = np.sin(alpha), np.cos(alpha)
    L = mesh.edge_length
    ub_r, ub_c, ub_v, ub_rhs, ub_names = [], [], [], [], []

    def add_row(coef: dict, rhs: float, name) -> None:
        r = len(ub_rhs)
        for col, val in coef.items():
            ub_r.append(r)
            ub_c.append(col)
            ub_v.append(val)
        ub_rhs.append(rhs)
        ub_names.append(name)

    def edge_terms(e, factor, coef) -> None:
        for h in edge_halves[e]:
            coef[h] = coef.get(h, 0.0) + factor

    for h in range(n_h):
        if sin[h] <= 0:
            continue  # reflex corner: the crossing lies behind the corner
        e_o, e_i = he_edge[h_out[h]], he_edge[h_in[h]]
        for own, other in ((e_o, e_i), (e_i, e_o)):
            if not rounded[own]:
                continue
            coef: dict = {}
            edge_terms(other, k[other] / sin[h], coef)
            edge_terms(own, k[own] * cos[h] / sin[h], coef)
            add_row(
                coef,
                share * 0.5 * L[own],
                f"tangent-line crossing at vertex {mesh.halfedge_from[h]} on face "
                f"{mesh.halfedge_face[h]} at {share:g} of edge {own}'s half length",
            )
    if max_loss is not None:
        for e in np.nonzero(rounded)[0]:
            add_row(
                {h: 1.0 for h in edge_halves[e]},
                max_loss,
                f"edge {e} at the maximal loss {max_loss:g}",
            )
    if max_radius is not None:
        r_cap = np.broadcast_to(np.asarray(max_radius, dtype=float), (mesh.n_edges,))
        if not np.all(np.isfinite(r_cap[rounded]) & (r_cap[rounded] > 0)):
            raise ParameterError("max radius must be a positive length", name="max_radius")
        cap = 2 * r_cap * np.where(rounded, tan_minus_angle(np.where(rounded, gamma, 1.0)), 0)
        for e in np.nonzero(rounded)[0]:
            add_row({h: 1.0 for h in edge_halves[e]}, cap[e], ("maximal radius", f"edge {e}"))
    # b <= u_h for free half-edges:  b - u_h <= 0
    n_x = n_h + 1
    n_names = len(ub_rhs)
    for h in np.nonzero(var)[0]:
        r = len(ub_rhs)
        ub_r += [r, r]
        ub_c += [int(h), n_h]
        ub_v += [-1.0, 1.0]
        ub_rhs.append(0.0)
    n_width_rows = int(var.sum())
    A_ub = sparse.csr_matrix((ub_v, (ub_r, ub_c)), shape=(len(ub_rhs), n_x))
    b_ub = np.array(ub_rhs, dtype=float)
    A_eq_x = sparse.hstack([A_eq, sparse.csr_matrix((A_eq.shape[0], 1))]).tocsr()
    c = np.zeros(n_x)
    c[-1] = -1.0
    bounds = [(0.0, None) if v else (0.0, 0.0) for v in var] + [(None, None)]
    has_eq = A_eq.shape[0] > 0
    lp = {
        "A_ub": A_ub if len(b_ub) else None,
        "b_ub": b_ub if len(b_ub) else None,
        "A_eq": A_eq_x if has_eq else None,
        "b_eq": np.zeros(A_eq.shape[0]) if has_eq else None,
        "method": "highs",
    }
    # stage 1 by HiGHS' interior-point method (with crossover to a vertex): on large
    # tessellations about twice as fast as its simplex on this max-min programme
    res = linprog(c, bounds=bounds, **{**lp, "method": "highs-ipm"})
    if res.status == 0 and res.x[-1] > 0:
        # stage 2: among the solutions with every width >= b*, the smallest total loss; the
        # optimum of stage 1 leaves all widths but the smallest free, often at their caps
        b_star = float(res.x[-1])
        cost = np.append(var.astype(float), 0.0)
        keep = b_star * (1 - LP_STAGE_SLACK)
        bounds2 = [*bounds[:-1], (keep, keep)]
        res2 = linprog(cost, bounds=bounds2, **lp)
        if res2.status == 0:
            res2.x[-1] = b_star
            res = res2
    if res.status != 0 or res.x is None:
        return MaterialLoss(
            False,
            0.0,
            np.zeros(n_h),
            np.zeros(mesh.n_edges),
            np.zeros(mesh.n_edges),
            np.zeros(mesh.n_vertices),
            [],
            [],
            f"the material-loss programme failed: {res.message}",
        )
    u = res.x[:n_h].copy()
    b = float(res.x[-1])
    # polish: remove the solver's equality residual (minimal-norm correction on free widths,
    # sparse least squares, twice for the last digits)
    if has_eq:
        sub = A_eq[:, np.nonzero(var)[0]]
        for _ in range(2):
            resid = A_eq @ np.where(var, u, 0.0)
            corr = lsqr(sub, resid, atol=POLISH_TOL, btol=POLISH_TOL, iter_lim=10 * sub.shape[1])[0]
            u[var] -= corr
    u = np.where(var, u, 0.0)
    closure = np.zeros(mesh.n_vertices)
    if has_eq:
        resid = np.abs(A_eq @ u)
        for (vtx, _), r in zip(rows, resid, strict=True):
            closure[vtx] = max(closure[vtx], r)
    w = loss_of_edge @ u
    radius = np.where(rounded & (w > 0), radius_from_loss(w, np.where(rounded, gamma, 1.0)), 0.0)
    slack = b_ub - A_ub @ res.x if len(b_ub) else np.zeros(0)
    scale = float(L.mean())
    tight = [ub_names[i] for i in range(n_names) if slack[i] <= TIGHT * scale]
    n_b_tight = int(np.sum(slack[n_names : n_names + n_width_rows] <= TIGHT * scale))
    if n_b_tight:
        tight.append(f"{n_b_tight} half-edge width(s) at the bound b")
    ok = b > POSITIVE_BOUND * scale
    binding = []
    if not ok:
        marg = getattr(res, "eqlin", None)
        if marg is not None and len(rows):
            strong = np.nonzero(np.abs(marg.marginals) > BINDING_MARGINAL)[0]
            verts = sorted({rows[i][0] for i in strong})
            edges = sorted({rows[i][1] for i in strong})
            binding = [f"vertices {verts}", f"edges {edges}"]
        message = (
            "no consistent material loss with every rounded edge positive (b = "
            f"{b:.3g} <= 0): the cycle equalities force some widths to zero"
            + (f"; binding: {binding[0]}, {binding[1]}" if binding else "")
        )
    else:
        message = f"consistent material loss found: b = {b:.6g}"
    return MaterialLoss(ok, b, u, w, radius, closure, tight, binding, message)
