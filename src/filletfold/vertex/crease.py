"""The curved crease of eq. (1): its height over the base curve, and its derivatives.

On the cylinder of side ``i`` of a vertex, the chart ``(s, z) -> C(s) + z R`` develops the
base curve ``C(s)`` (in the edge's midpoint cross-section) onto ``c(s) = (s, 0)`` and the ruling
direction ``R`` (unit, toward the vertex) onto ``r = (0, 1)``. The crease is
``F(s) = C(s) + l(s) R`` in 3D and ``f(s) = c(s) + l(s) r`` in the chart. With the spatial apex
``V`` and the developed apex ``v_i`` (in this cylinder's chart), every cone ruling keeps its
length, ``|F(s) - V|^2 = |f(s) - v_i|^2``; as ``C(s) - c(s)`` has no ``R`` part this is linear in
``l`` and gives (paper eq. (1)) ::

    l(s) = num(s) / (2 dn)
    num(s) = |v_i - c(s)|^2 - |V - C(s)|^2 = (v_x - s)^2 + v_y^2 - |V - C(s)|^2
    dn     = (v_i - c(s)) . r - (V - C(s)) . R = v_y - (V - M) . R

``dn`` (the paper's ``D``; the vertex normal is another ``D``) is the same all along the arc,
since every ``C(s)`` lies in the cross-section through the edge midpoint ``M``: it is computed
with ``M``. A valid patch has ``dn > 0`` (sec. 2.2), and then ``l >= 0`` exactly where
``num >= 0``.

``num`` is evaluated as written: a difference of two squared distances, each a sum of squares
of coordinate differences taken first, so no large coordinates are squared and subtracted.
(It still loses the digits of ``|v_i - c|^2`` against ``l^2`` on a short ruling far from the
chart origin; :func:`filletfold.surface.assemble.true_rulings` restores the pattern's ruling
lengths.)

Every function works on arrays of rows ``(m, ...)``: one row per (side, arc parameter) pair.
The solvers write their constraints as ``sign * num - coef * dn`` and need the derivatives with
respect to the apices: :func:`numerator_gradients` and :func:`denominator_gradients`; the dense
validation minimises ``l`` along an arc with :func:`numerator_arc_derivatives`. The numba
kernel (:mod:`filletfold.vertex.batch_kernel`) has no copy of these: it receives the rows as
``a + A . y + alpha (|v|^2 - |V|^2)`` already evaluated here.

Shapes: ``V`` (m, 3) or (3,); ``v`` (m, 2) or (2,) in the common frame; ``Q`` (m, 2, 2) and
``t`` (m, 2) the rigid map from the common frame into each row's cylinder chart
(``v_i = Q v + t``); ``s`` (m,) arc length; ``C``, ``M``, ``R`` (m, 3). Lengths in the mesh's unit.
"""

from __future__ import annotations

import numpy as np


def chart_apex(Q: np.ndarray, t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(m, 2) float: the developed apex ``v_i = Q v + t`` in each row's cylinder chart.

    Parameters
    ----------
    Q : (m, 2, 2) float
    t : (m, 2) float
    v : (2,) or (m, 2) float
        Developed apex in the vertex's common frame (one for all rows, or one per row).
    """
    v = np.asarray(v, dtype=float)
    if v.ndim == 1:
        return np.einsum("kij,j->ki", Q, v) + t
    return np.einsum("kij,kj->ki", Q, v) + t


def crease_numerator(V: np.ndarray, vi: np.ndarray, s: np.ndarray, C: np.ndarray) -> np.ndarray:
    """(m,) float: ``num = |v_i - c(s)|^2 - |V - C(s)|^2`` of eq. (1) (length squared).

    Parameters
    ----------
    V : (3,) or (m, 3) float
        Spatial apex.
    vi : (m, 2) float
        Developed apex in the row's cylinder chart (:func:`chart_apex`).
    s : (m,) float
        Arc parameter: ``c(s) = (s, 0)``.
    C : (m, 3) float
        Base-curve point ``C(s)``.
    """
    d = V - C
    return (vi[:, 0] - s) ** 2 + vi[:, 1] ** 2 - np.einsum("ij,ij->i", d, d)


def crease_denominator(V: np.ndarray, vi: np.ndarray, M: np.ndarray, R: np.ndarray) -> np.ndarray:
    """(m,) float: ``dn = (v_i)_y - (V - M) . R`` of eq. (1) (length): the developed apex's
    height over the base curve less the spatial one's; > 0 on a valid patch (sec. 2.2).

    Parameters
    ----------
    V : (3,) or (m, 3) float
    vi : (m, 2) float
    M : (m, 3) float
        Edge midpoint (any point of the base curve's plane).
    R : (m, 3) float
        Unit edge direction toward the vertex.
    """
    return vi[:, 1] - np.einsum("ij,ij->i", V - M, R)


def crease_height(num: np.ndarray, dn: np.ndarray) -> np.ndarray:
    """(m,) float: ``l = num / (2 dn)``, the crease's height over the base curve (eq. (1))."""
    return 0.5 * num / dn


def numerator_gradients(V, vi, s, C, Q) -> tuple[np.ndarray, np.ndarray]:
    """Derivatives of :func:`crease_numerator` with respect to the apices.

    Returns
    -------
    d_V : (m, 3) float
        ``d num / d V = -2 (V - C)``.
    d_v : (m, 2) float
        ``d num / d v = 2 Q^T (v_i - c(s))``, with ``v`` in the common frame.
    """
    r = vi - np.stack([s, np.zeros_like(s)], axis=1)
    return -2 * (V - C), 2 * np.einsum("qji,qj->qi", Q, r)


def denominator_gradients(R: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Derivatives of :func:`crease_denominator` with respect to the apices (constants).

    Returns
    -------
    d_V : (m, 3) float
        ``d dn / d V = -R``.
    d_v : (m, 2) float
        ``d dn / d v = Q^T e_y``, the second row of ``Q``.
    """
    return -R, Q[:, 1, :]


def numerator_arc_derivatives(vx, s, kappa, radius, P, Q) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivatives of :func:`crease_numerator` along the arc, ``d/ds`` and
    ``d^2/ds^2`` (for the minimum of ``l`` between samples).

    On a circular base curve ``C(s) = O + kappa r N(s)``, ``N(s) = cos(s/r) N0 + sin(s/r) B``,
    ``num(s) = (v_x - s)^2 + v_y^2 - |V - O|^2 - r^2 + 2 kappa r (P cos(s/r) + Q sin(s/r))``.

    Parameters
    ----------
    vx : (m,) float
        First coordinate of the developed apex in the cylinder chart.
    s : (m,) float
    kappa, radius : (m,) float
        The cylinder's sign and radius (radius > 0).
    P, Q : (m,) float
        ``(V - O) . N0`` and ``(V - O) . B``.
    """
    c, sn = np.cos(s / radius), np.sin(s / radius)
    d1 = -2 * (vx - s) + 2 * kappa * (-P * sn + Q * c)
    d2 = 2 + 2 * kappa / radius * (-P * c - Q * sn)
    return d1, d2
