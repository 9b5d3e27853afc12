"""Conical fillets: the rounding of an edge that tapers into a sharp end.

A vertex that takes no cone (a saddle, an infeasible or a boundary vertex) can stay *sharp*:
the surface keeps the polyhedron's corner ``S`` there. An edge from ``S`` to a vertex ``W``
that does take a cone is then rounded by the cone with apex ``S`` over the edge's base curve
``C(s)`` (its circular arc of radius ``r`` in the midpoint cross-section, tangent to both
faces) instead of by a cylinder. Everything here is seen from ``W``, in the conventions of
:class:`~filletfold.vertex.frame.Side`: ``R`` the unit edge direction toward ``W``, ``s`` in
``[0, a]`` from face ``f_{i-1}`` to face ``f_i`` of ``W``'s ring, so that ``S = M - (L/2) R``.

The fillet's rulings are ``R(s) = (C(s) - S) / rho(s)``, ``rho = |C - S|``: unit, from ``S``
through the base curve toward ``W`` (``R(s) . R = (L/2) / rho > 0``). At ``s = 0`` both the
ruling and ``C'(0)`` lie in face ``f_{i-1}``, so that face is the fillet's tangent plane along
the whole ruling; likewise face ``f_i`` at ``s = a``. The fillet is tangent continuous with
both faces, and its width shrinks to zero at ``S``.

Its development is a sector with apex ``q`` (the image of ``S``). In the side's chart
``(s, z) -> C(s) + z R(s)``, developed ``c(s) + z r(s)``, the chart agrees with a cylinder's at
``s = 0``: ``c(0) = (0, 0)`` and ``r(0) = (0, 1)``, so ``q = (0, -rho(0))``, and

    c(s) = q + rho(s) r(s),    r(s) = (sin theta(s), cos theta(s)),

with ``theta`` the developed angle swept from ``s = 0``, the integral of
``|(C - S) x C'| / rho^2 = sqrt(rho^2 - ((C - S) . C')^2) / rho^2`` (``|C'| = 1``). The
integrand is analytic and bounded (``rho >= L / 2``), and its Chebyshev series
(:data:`QUADRATURE_NODES` points), integrated exactly, reaches round-off.

The crease between the fillet and ``W``'s cone keeps the paper's ansatz with the ruling of
each ``s`` (``F = C + l R(s)``, ``f = c + l r(s)``); ``|F - V|^2 = |f - v|^2`` is still linear
in ``l`` because both rulings are unit, which gives eq. (1) with ``r(s)`` and ``R(s)`` in
place of the constants (:func:`crease_height_ruled`).
"""

from __future__ import annotations

from functools import cache
from typing import NamedTuple

import numpy as np

#: Chebyshev points per conical fillet for its developed angle (:func:`developed_angles`):
#: relative error below 1e-13 for fillets up to twice as wide at the midpoint as half the
#: edge is long (``tests/rounding/test_tapered.py``).
QUADRATURE_NODES = 64


def _rows_dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def arc_points(O, N0, B, kappa, radius, s) -> tuple[np.ndarray, np.ndarray]:
    """Base-curve points ``C(s) = O + kappa r N(s)`` and unit tangents ``C'(s)``.

    Parameters
    ----------
    O, N0, B : (..., 3) float
        The cylinder's axis point in the midpoint cross-section and its normal frame
        (``N(s) = cos(s / r) N0 + sin(s / r) B``).
    kappa, radius : (...) float
        Mountain/valley sign and radius (> 0).
    s : (...) float
        Arc parameters.

    Returns
    -------
    C, dC : (..., 3) float
    """
    t = (np.asarray(s, dtype=float) / radius)[..., None]
    k = np.asarray(kappa, dtype=float)[..., None]
    c, sn = np.cos(t), np.sin(t)
    C = O + (k * np.asarray(radius, dtype=float)[..., None]) * (c * N0 + sn * B)
    return C, k * (-sn * N0 + c * B)


def cone_rulings(C: np.ndarray, S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit rulings ``R(s) = (C - S) / rho`` of the cone with apex ``S`` and their lengths.

    Parameters
    ----------
    C : (..., 3) float
        Points of the base curve.
    S : (..., 3) float
        The sharp end of the edge.

    Returns
    -------
    R : (..., 3) float
    rho : (...) float
        ``|C - S|``.
    """
    d = np.asarray(C, dtype=float) - S
    rho = np.sqrt(_rows_dot(d, d))
    return d / rho[..., None], rho


def sweep_rate(C: np.ndarray, dC: np.ndarray, S: np.ndarray) -> np.ndarray:
    """``d theta / ds = |(C - S) x C'| / |C - S|^2``: how fast the developed ruling turns.

    Parameters
    ----------
    C, dC : (..., 3) float
        Base-curve points and their unit tangents.
    S : (..., 3) float

    Returns
    -------
    (...) float
    """
    d = C - S
    rho2 = _rows_dot(d, d)
    along = _rows_dot(d, dC)
    return np.sqrt(np.maximum(rho2 - along * along, 0.0)) / rho2


@cache
def _chebyshev(nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Read-only Chebyshev points of the first kind on ``[-1, 1]`` and the (nodes, nodes)
    matrix taking values there to the coefficients of the interpolating series."""
    k = np.arange(nodes)
    x = np.cos(np.pi * (k + 0.5) / nodes)
    T = np.cos(np.pi * np.outer(k, k + 0.5) / nodes) * (2.0 / nodes)
    T[0] *= 0.5
    x.flags.writeable = T.flags.writeable = False
    return x, T


class FilletRows(NamedTuple):
    """Rows of conical fillets, one per point asked of them: the arc of each row's edge
    (:func:`arc_points`: its centre ``O``, unit ``N0`` and ``B``, ``kappa`` and ``radius``)
    and the apex ``S`` its rulings come from.

    Attributes
    ----------
    O, N0, B, S : (m, 3) float
    kappa, radius : (m,) float
    """

    O: np.ndarray
    N0: np.ndarray
    B: np.ndarray
    kappa: np.ndarray
    radius: np.ndarray
    S: np.ndarray


def developed_angles(rows: FilletRows, s, nodes: int = QUADRATURE_NODES, fillet=None):
    """(m,) float: the developed angle ``theta(s)`` a conical fillet sweeps from ``0`` to ``s``.

    The rows of one fillet (equal ``O``, ``N0``, ``B``, ``kappa``, ``radius``, ``S``) share one
    integral: the sweep rate is interpolated at ``nodes`` Chebyshev points on ``[0, h]`` (``h``
    the largest ``s`` asked of the fillet), the series integrated exactly and evaluated at
    every ``s``. The rate is analytic and bounded, so this reaches round-off like
    Gauss-Legendre quadrature on each ``[0, s]`` with as many nodes, at a cost per fillet
    rather than per row.

    Parameters
    ----------
    rows : FilletRows
    s : (m,) float
    nodes : int
        Chebyshev points per fillet.
    fillet : (m,) int, optional
        Which fillet each row is on, when the caller knows (rows with equal ids must have
        equal parameters); by default rows with equal parameters are found (a sort of the
        rows, slower).
    """
    s = np.asarray(s, dtype=float)
    if not len(s):
        return np.zeros(0)
    O, N0, B, kappa, radius, S = rows
    parts = (O, N0, B, np.asarray(kappa, float)[:, None], np.asarray(radius, float)[:, None], S)
    if fillet is None:
        key, inv = np.unique(np.concatenate(parts, 1), axis=0, return_inverse=True)
    else:
        _, first, inv = np.unique(fillet, return_index=True, return_inverse=True)
        key = np.concatenate([np.asarray(x)[first] for x in parts], 1)
    inv = inv.ravel()
    h = np.zeros(len(key))
    np.maximum.at(h, inv, s)
    series = angle_series(
        FilletRows(key[:, 0:3], key[:, 3:6], key[:, 6:9], key[:, 9], key[:, 10], key[:, 11:14]),
        h,
        nodes,
    )
    return series_angles(series, h, inv, s)


def angle_series(rows: FilletRows, span, nodes: int = QUADRATURE_NODES) -> np.ndarray:
    """(k, L) float: per fillet, the Chebyshev series on ``[0, span]`` of its developed angle
    ``theta(s)`` (0 at ``s = 0``), evaluated by :func:`series_angles`.

    Parameters
    ----------
    rows : FilletRows
        One row per fillet (k rows).
    span : (k,) float
        The largest ``s`` each fillet will be evaluated at (its arc).
    nodes : int
        Chebyshev points per fillet.
    """
    O, N0, B, kappa, radius, S = rows
    x, T = _chebyshev(nodes)
    t = 0.5 * np.asarray(span, dtype=float)[:, None] * (x + 1.0)  # (fillets, nodes)
    C, dC = arc_points(
        O[:, None], N0[:, None], B[:, None], np.asarray(kappa)[:, None],
        np.asarray(radius)[:, None], t,
    )  # fmt: skip
    return _integrated(sweep_rate(C, dC, S[:, None]) @ T.T)


def series_angles(series: np.ndarray, span: np.ndarray, fillet: np.ndarray, s) -> np.ndarray:
    """(m,) float: ``theta(s)`` of rows on fillets ``fillet`` (m,) int, rows of ``series`` and
    ``span`` (:func:`angle_series`), at their ``s`` (m,)."""
    s = np.asarray(s, dtype=float)
    hs = np.asarray(span, dtype=float)[fillet]
    u = np.where(hs > 0, 2.0 * s / np.where(hs > 0, hs, 1.0) - 1.0, -1.0)
    b1 = np.zeros(len(s))
    b2 = np.zeros(len(s))
    for k in range(series.shape[1] - 1, 0, -1):  # Clenshaw, each row its fillet's series
        b1, b2 = 2.0 * u * b1 - b2 + series[fillet, k], b1
    return 0.5 * hs * (u * b1 - b2 + series[fillet, 0])


def _integrated(c: np.ndarray) -> np.ndarray:
    """(k, m) Chebyshev coefficients of the integrals from ``x = -1`` of the series ``c``
    (k, n), without the trailing terms under 1e-16 of the largest in every row (round-off).

    ``int T_0 = T_1``, ``int T_1 = T_2 / 4`` and ``int T_j = T_(j+1) / (2 (j + 1)) -
    T_(j-1) / (2 (j - 1))``; the constant makes each integral 0 at ``x = -1``.
    """
    k, n = c.shape
    pad = np.zeros((k, n + 2))
    pad[:, :n] = c
    out = np.zeros((k, n + 1))
    j = np.arange(1, n + 1)
    out[:, 1:] = (pad[:, :n] - pad[:, 2 : n + 2]) / (2.0 * j)
    out[:, 1] = pad[:, 0] - 0.5 * pad[:, 2]
    out[:, 0] = -(out[:, 1:] * (-1.0) ** j).sum(axis=1)
    size = np.abs(out).max(axis=1, keepdims=True)
    live = np.flatnonzero((np.abs(out) > 1e-16 * size).any(axis=0))
    return out[:, : (live[-1] + 1 if len(live) else 1)]


def fillet_chart(rows: FilletRows, s, nodes: int = QUADRATURE_NODES, fillet=None, theta=None):
    """A conical fillet's base curve and rulings, in 3D and in the side's developed chart.

    The chart is a cylinder's at ``s = 0`` (``c(0) = (0, 0)``, ``r(0) = (0, 1)``); the sector's
    apex ``q = (0, -rho(0))`` is the image of ``S``.

    Parameters
    ----------
    rows : FilletRows
    s : (m,) float
    nodes, fillet
        See :func:`developed_angles`.
    theta : (m,) float, optional
        The developed angles at ``s``, when the caller has them (:func:`series_angles`).

    Returns
    -------
    C, R : (m, 3) float
        Base-curve points and unit rulings (from ``S``, toward ``W``).
    c, r : (m, 2) float
        Their images in the chart.
    q : (m, 2) float
        The image of ``S``.
    """
    O, N0, B, kappa, radius, S = rows
    C, _ = arc_points(O, N0, B, kappa, radius, s)
    R, rho = cone_rulings(C, S)
    # C(0) = O + kappa r N0 (arc_points at s = 0 to the bit, but for the signs of zeros)
    k_r = np.asarray(kappa, dtype=float) * np.asarray(radius, dtype=float)
    rho0 = cone_rulings(O + k_r[..., None] * N0, S)[1]
    if theta is None:
        theta = developed_angles(rows, s, nodes, fillet)
    r = np.stack([np.sin(theta), np.cos(theta)], axis=-1)
    q = np.stack([np.zeros_like(rho0), -rho0], axis=-1)
    return C, R, q + rho[:, None] * r, r, q


def crease_height_ruled(V, v, C, R, c, r) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Eq. (1) on a ruled patch whose ruling changes with ``s``: the crease's height ``l``.

    With ``F = C + l R`` and ``f = c + l r`` (``R``, ``r`` unit), ``|F - V|^2 = |f - v|^2``
    reads ``num = 2 l dn`` with

        num = |v - c|^2 - |V - C|^2,    dn = (v - c) . r - (V - C) . R.

    On a cylinder (``R`` constant, ``c = (s, 0)``, ``r = (0, 1)``) this is the paper's eq. (1)
    (:mod:`filletfold.vertex.crease`); on a conical fillet ``dn`` varies along the arc and a
    valid patch needs ``dn > 0`` at every ``s``.

    Parameters
    ----------
    V : (3,) or (m, 3) float
        Spatial apex.
    v : (2,) or (m, 2) float
        Developed apex in the side's chart.
    C, R : (m, 3) float
    c, r : (m, 2) float

    Returns
    -------
    l, num, dn : (m,) float
    """
    d3 = V - C
    d2 = v - c
    num = _rows_dot(d2, d2) - _rows_dot(d3, d3)
    dn = _rows_dot(d2, r) - _rows_dot(d3, R)
    return 0.5 * num / dn, num, dn


def ruled_gluing_maps(frames, C, R, E, c, r, e) -> np.ndarray:
    """Rigid maps from side charts into face charts along a ruling where side and face touch.

    The chart point ``c + z r`` is ``C + z R``; the chart direction ``e`` (the unit
    perpendicular of ``r`` on the side of increasing ``s``) is the 3D direction ``E`` in the
    face. On a cylinder ``c = (s, 0)``, ``r = (0, 1)``, ``e = (1, 0)`` and ``E = C'(s)``
    (:func:`filletfold.vertex.frame.gluing_maps`).

    Parameters
    ----------
    frames : (k, 3, 3) float
        The faces' charts (rows: origin, e1, e2).
    C, R, E : (k, 3) float
        Contact point, unit ruling and unit in-face perpendicular.
    c, r, e : (k, 2) float
        Their images in the side's chart.

    Returns
    -------
    (k, 3, 3) float
        Homogeneous 2D maps ``side chart -> face chart``.
    """
    axes = frames[:, 1:]  # (k, 2, 3)
    E2 = np.einsum("kij,kj->ki", axes, E)  # E and R in the face chart
    R2 = np.einsum("kij,kj->ki", axes, R)
    p = np.einsum("kij,kj->ki", axes, C - frames[:, 0])
    lin = np.stack([E2, R2], axis=-1) @ np.linalg.inv(np.stack([e, r], axis=-1))
    out = np.zeros((len(C), 3, 3))
    out[:, :2, :2] = lin
    out[:, :2, 2] = p - np.einsum("kij,kj->ki", lin, c)
    out[:, 2, 2] = 1.0
    return out


def perpendiculars(C, dC, R, c, r) -> tuple[np.ndarray, np.ndarray]:
    """The unit perpendiculars of the rulings toward increasing ``s``, in 3D and in the chart:
    ``E = unit(C' - (C' . R) R)`` and ``e = (r_y, -r_x)``.

    Parameters
    ----------
    C, dC, R : (m, 3) float
    c, r : (m, 2) float

    Returns
    -------
    E : (m, 3) float
    e : (m, 2) float
    """
    E = dC - _rows_dot(dC, R)[:, None] * R
    E = E / np.linalg.norm(E, axis=1)[:, None]
    return E, np.stack([r[:, 1], -r[:, 0]], axis=-1)
