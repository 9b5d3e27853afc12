"""The crease of eq. (1) (:mod:`filletfold.vertex.crease`): isometry and derivatives.

Random cylinders: a unit ruling direction ``R``, a circular base curve ``C(s)`` in the plane
through ``M`` normal to ``R`` (``C(s) = O + kappa r N(s)``), a random rigid map from the common
frame into the cylinder's chart, random apices ``V`` and ``v``.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from filletfold.mesh import load_mesh
from filletfold.rounding.edges import round_edges
from filletfold.vertex.apex import crease_length
from filletfold.vertex.crease import (
    chart_apex,
    crease_denominator,
    crease_height,
    crease_numerator,
    denominator_gradients,
    numerator_arc_derivatives,
    numerator_gradients,
)
from filletfold.vertex.frame import vertex_frame

M_ROWS = 16


def random_cylinders(seed: int, scale: float):
    """Rows of random cylinders: (R, M, O, N0, B, kappa, radius, Q, t, s, V, v)."""
    rng = np.random.default_rng(seed)
    m = M_ROWS
    R = rng.normal(size=(m, 3))
    R /= np.linalg.norm(R, axis=1)[:, None]
    N0 = np.cross(R, rng.normal(size=(m, 3)))
    N0 /= np.linalg.norm(N0, axis=1)[:, None]
    B = np.cross(R, N0)  # unit, normal to R and N0
    radius = scale * rng.uniform(0.05, 0.5, m)
    kappa = rng.choice([-1.0, 1.0], m)
    M = scale * rng.normal(size=(m, 3))
    O = M + scale * rng.normal(size=(m, 1)) * np.cross(R, B)  # in the plane through M
    theta = rng.uniform(-np.pi, np.pi, m)
    c, sn = np.cos(theta), np.sin(theta)
    Q = np.stack([np.stack([c, -sn], axis=1), np.stack([sn, c], axis=1)], axis=1)
    t = scale * rng.normal(size=(m, 2))
    s = radius * rng.uniform(0, 2, m)
    V = M + scale * rng.normal(size=(m, 3))
    v = scale * rng.normal(size=(m, 2))
    return R, M, O, N0, B, kappa, radius, Q, t, s, V, v


def base(O, N0, B, kappa, radius, s):
    ang = (s / radius)[:, None]
    return O + (kappa * radius)[:, None] * (np.cos(ang) * N0 + np.sin(ang) * B)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), scale=st.sampled_from([1e-3, 1.0, 1e3]))
def test_crease_rulings_are_isometric(seed, scale):
    """|F - V| = |f - v_i| for F = C + l R, f = c + l r, whatever the apices."""
    R, M, O, N0, B, kappa, radius, Q, t, s, V, v = random_cylinders(seed, scale)
    C = base(O, N0, B, kappa, radius, s)
    vi = chart_apex(Q, t, v)
    dn = crease_denominator(V, vi, M, R)
    keep = np.abs(dn) > 1e-3 * scale  # eq. (1) needs dn != 0
    l = crease_height(crease_numerator(V, vi, s, C), dn)
    F = C + l[:, None] * R
    f = np.stack([s, l], axis=1)
    d3, d2 = np.linalg.norm(F - V, axis=1), np.linalg.norm(f - vi, axis=1)
    assert_allclose(d3[keep], d2[keep], rtol=1e-9)
    # d3^2 - d2^2 = 2 l dn - num: zero to the rounding of the squared distances in num
    c = np.stack([s, np.zeros_like(s)], axis=1)
    size = np.einsum("ij,ij->i", V - C, V - C) + np.einsum("ij,ij->i", vi - c, vi - c) + d3**2
    err = np.abs(d3**2 - d2**2) / size
    assert (err[keep] < 1e-13).all(), err[keep].max()
    # and the denominator is the same with C instead of M: C - M has no R part
    dn_c = vi[:, 1] - np.einsum("ij,ij->i", V - C, R)
    assert_allclose(dn_c, dn, atol=1e-12 * scale)


def _numerator_of(V, v, R, M, Q, t, s, C):
    return crease_numerator(V, chart_apex(Q, t, v), s, C)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_gradients_match_finite_differences(seed):
    R, M, O, N0, B, kappa, radius, Q, t, s, V, v = random_cylinders(seed, 1.0)
    C = base(O, N0, B, kappa, radius, s)
    vi = chart_apex(Q, t, v)
    num_V, num_v = numerator_gradients(V, vi, s, C, Q)
    dn_V, dn_v = denominator_gradients(R, Q)
    h = 1e-6
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        fd = _numerator_of(V + e, v, R, M, Q, t, s, C) - _numerator_of(V - e, v, R, M, Q, t, s, C)
        assert_allclose(fd / (2 * h), num_V[:, k], rtol=1e-7, atol=1e-7)
        fd = crease_denominator(V + e, vi, M, R) - crease_denominator(V - e, vi, M, R)
        assert_allclose(fd / (2 * h), dn_V[:, k], rtol=1e-7, atol=1e-7)
    for k in range(2):
        e = np.zeros(2)
        e[k] = h
        fd = _numerator_of(V, v + e, R, M, Q, t, s, C) - _numerator_of(V, v - e, R, M, Q, t, s, C)
        assert_allclose(fd / (2 * h), num_v[:, k], rtol=1e-7, atol=1e-7)
        fd = crease_denominator(V, chart_apex(Q, t, v + e), M, R)
        fd = fd - crease_denominator(V, chart_apex(Q, t, v - e), M, R)
        assert_allclose(fd / (2 * h), dn_v[:, k], rtol=1e-7, atol=1e-7)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_arc_derivatives_match_finite_differences(seed):
    _R, _M, O, N0, B, kappa, radius, Q, t, s, V, v = random_cylinders(seed, 1.0)
    vi = chart_apex(Q, t, v)
    P, Qb = np.einsum("ij,ij->i", V - O, N0), np.einsum("ij,ij->i", V - O, B)
    d1, d2 = numerator_arc_derivatives(vi[:, 0], s, kappa, radius, P, Qb)
    h = 1e-4 * radius

    def num(x):
        return crease_numerator(V, vi, x, base(O, N0, B, kappa, radius, x))

    assert_allclose((num(s + h) - num(s - h)) / (2 * h), d1, rtol=1e-6, atol=1e-6)
    assert_allclose((num(s + h) - 2 * num(s) + num(s - h)) / h**2, d2, rtol=1e-4, atol=1e-3)


def test_the_frame_crease_is_the_crease_of_the_rows():
    """crease_length of a vertex frame is eq. (1) on that frame's sides, and the cylinders'
    creases meet the isometry on a real vertex (icosahedron, r = 0.15, d = 0.3)."""
    m = load_mesh("icosahedron")[0]
    fr = vertex_frame(m, round_edges(m, 0.15), 0)
    v = fr.developed_apex()
    V = fr.U - 0.3 * fr.U / np.linalg.norm(fr.U)
    sa = fr.arrays
    side = np.repeat(np.arange(fr.n_sides), 9)
    s = np.tile(np.linspace(0, 1, 9), fr.n_sides) * sa.arc[side]
    C = sa.base(side, s)
    l, dn = crease_length(fr, side, V, v, s)
    vi = chart_apex(sa.Q, sa.t, v)[side]
    assert (dn > 0).all() and (l > 0).all()
    F = C + l[:, None] * sa.R[side]
    assert_allclose(np.linalg.norm(F - V, axis=1), np.linalg.norm(np.stack([s, l], 1) - vi, axis=1))
    # the same crease in the common frame: the chart's (s, l) mapped by the cylinder's map
    maps = fr.cyl_maps[side]
    f_common = np.einsum("kij,kj->ki", maps[:, :2, :2], np.stack([s, l], 1)) + maps[:, :2, 2]
    assert_allclose(np.linalg.norm(f_common - v, axis=1), np.linalg.norm(F - V, axis=1))
