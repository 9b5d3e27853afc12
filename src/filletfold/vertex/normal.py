"""Vertex classification and the vertex normal (paper sec. 2.5, 3.1; METHOD-NOTES 1-2).

The vertex normal ``D`` maximises ``b`` subject to ``D . (-R_i) >= b`` for every incident edge
direction ``R_i`` (toward the vertex), ``D . (sigma N_f) >= b`` for every incident face and
``|D| = 1``. Both signs ``sigma`` are tried; the one with ``b > 0`` wins. When neither has
``b > 0`` no plane through the vertex has all its faces on one side: the vertex is a saddle.

With ``b > 0`` the problem is the convex programme ``max b`` s.t. ``D . u_k >= b``,
``|D| <= 1`` (the optimum has ``|D| = 1``), solved with SLSQP from the normalised mean of the
``u_k`` (the paper's initialisation).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

from ..tolerances import tol


def max_min_direction(u: np.ndarray) -> tuple[np.ndarray, float]:
    """Unit vector ``D`` maximising ``min_k D . u_k``.

    Parameters
    ----------
    u : (k, 3) float
        Unit vectors.

    Returns
    -------
    D : (3,) float
        Unit direction (the best found, also when the bound is not positive).
    b : float
        ``min_k D . u_k``; not positive when no open half-space contains all ``u_k``.
    """
    mean = u.mean(axis=0)
    n = np.linalg.norm(mean)
    d0 = mean / n if n > 1e-12 else u[0]
    d = _max_min_slsqp(u, d0, on_sphere=False)
    nd = np.linalg.norm(d)
    d = d / nd if nd > 1e-12 else d0
    b = float(np.min(u @ d))
    if b > 0:
        return d, b
    # no open half-space holds every u_k: the convex form degenerates (D -> 0); find the
    # (negative) max-min on the sphere from the best of a dense set of directions
    grid = _fibonacci_sphere(2000)
    start = grid[np.argmax((grid @ u.T).min(axis=1))]
    d = _max_min_slsqp(u, start, on_sphere=True)
    cands = [start, d / np.linalg.norm(d)]
    vals = [float(np.min(u @ c)) for c in cands]
    k = int(np.argmax(vals))
    return cands[k], vals[k]


def _max_min_slsqp(u: np.ndarray, d0: np.ndarray, *, on_sphere: bool) -> np.ndarray:
    """SLSQP for ``max b`` s.t. ``u @ D >= b`` and ``|D| <= 1`` (or ``|D| = 1``); returns D."""
    if on_sphere:
        norm = {
            "type": "eq",
            "fun": lambda x: np.array([x[:3] @ x[:3] - 1.0]),
            "jac": lambda x: np.concatenate([2 * x[:3], [0.0]])[None],
        }
    else:
        norm = {
            "type": "ineq",
            "fun": lambda x: 1.0 - x[:3] @ x[:3],
            "jac": lambda x: np.concatenate([-2 * x[:3], [0.0]]),
        }
    res = minimize(
        lambda x: -x[3],
        np.concatenate([d0, [np.min(u @ d0)]]),
        jac=lambda x: np.array([0.0, 0.0, 0.0, -1.0]),
        constraints=[
            {
                "type": "ineq",
                "fun": lambda x: u @ x[:3] - x[3],
                "jac": lambda x: np.hstack([u, -np.ones((len(u), 1))]),
            },
            norm,
        ],
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 200},
    )
    return res.x[:3]


def _fibonacci_sphere(n: int) -> np.ndarray:
    """(n, 3) float: nearly uniform unit vectors."""
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = np.pi * (1 + 5**0.5) * i
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def vertex_normal(edge_dirs: np.ndarray, face_normals: np.ndarray):
    """Vertex normal, its bound and sign ``sigma`` for one vertex.

    Parameters
    ----------
    edge_dirs : (n_e, 3) float
        Unit edge directions ``R_i`` toward the vertex.
    face_normals : (n_f, 3) float
        Front normals of the incident faces.

    Returns
    -------
    D : (3,) float
    b : float
        The max-min bound for the chosen ``sigma`` (``<= tol.normal_bound`` means saddle).
    sigma : int
        +1 (apex on the front side) or -1 (back side).
    """
    best = None
    for sigma in (-1, 1):
        u = np.vstack([-edge_dirs, sigma * face_normals])
        d, b = max_min_direction(u)
        if best is None or b > best[1]:
            best = (d, b, sigma)
    return best


def solid_angle_front(kappa: np.ndarray, half_angle: np.ndarray) -> float:
    """Solid angle on the front side of a closed vertex: ``2 pi + sum(kappa * 2 gamma)``.

    Parameters
    ----------
    kappa : (n,) int
        +1 mountain, -1 valley per incident edge.
    half_angle : (n,) float

    Notes
    -----
    The back side is the geodesic polygon of the edge directions on the unit sphere, with
    interior angles ``pi - kappa 2 gamma``; its area is ``2 pi - sum(kappa 2 gamma)``.
    """
    return float(2 * np.pi + np.sum(kappa * 2 * half_angle))


def is_developable(angle_sum: float) -> bool:
    """True when the face angles around a vertex sum to 2 pi (within tolerance)."""
    return abs(angle_sum - 2 * np.pi) < tol.developable
