"""Conical fillets (edges with one sharp end): the construction checked numerically.

The claims of ``docs/method.md`` ("Sharp vertices and conical fillets") are tested here on
whole vertices: the fillet is tangent to both faces, its chart is an isometry, eq. (1) with a
ruling per ``s`` puts the crease on the fillet with rulings of ``W``'s cone that keep their
lengths, and the chain of gluing maps around ``W`` (cylinders and conical fillets mixed) has a
fixed point that makes the crease tangent continuous at every face, the cut included.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.integrate import quad

from filletfold.mesh import load_mesh
from filletfold.rounding.edges import round_edges
from filletfold.rounding.tapered import (
    FilletRows,
    arc_points,
    cone_rulings,
    crease_height_ruled,
    developed_angles,
    fillet_chart,
    perpendiculars,
    ruled_gluing_maps,
    sweep_rate,
)
from filletfold.vertex.frame import developed_apices, invert, vertex_frame


def mesh(name):
    return load_mesh(name)[0]


def side_rows(side, s):
    """The side's cylinder parameters repeated for the arc parameters ``s``."""
    m = len(s)
    rep = np.repeat
    return (
        rep(side.O[None], m, 0),
        rep(side.N0[None], m, 0),
        rep(side.B[None], m, 0),
        np.full(m, float(side.kappa)),
        np.full(m, side.radius),
    )


def sharp_end(side):
    """The other end ``S`` of the side's edge."""
    return side.M - 0.5 * side.length * side.R


class Chart:
    """One side of ``W`` as a ruled patch: a cylinder, or a conical fillet from ``S``."""

    def __init__(self, side, conical: bool):
        self.side, self.conical = side, conical

    def at(self, s):
        """C, R, c, r and the perpendiculars E, e at arc parameters ``s``."""
        side = self.side
        s = np.atleast_1d(np.asarray(s, dtype=float))
        rows = side_rows(side, s)
        if self.conical:
            S = np.repeat(sharp_end(side)[None], len(s), 0)
            C, R, c, r, _ = fillet_chart(FilletRows(*rows, S), s)
        else:
            C = arc_points(*rows, s)[0]
            R = np.repeat(side.R[None], len(s), 0)
            c = np.stack([s, np.zeros_like(s)], axis=1)
            r = np.repeat([[0.0, 1.0]], len(s), 0)
        dC = arc_points(*rows, s)[1]
        E, e = perpendiculars(C, dC, R, c, r)
        return C, R, c, r, E, e


def chain(frame, charts):
    """Maps of every side chart into the common frame (the chart of tau = f_{n-1}), and rho."""
    n = len(charts)
    faces = np.array(frame.face_frames)
    face_map = np.eye(3)  # tau
    side_maps = []
    for i, ch in enumerate(charts):
        a = ch.side.arc
        C, R, c, r, E, e = (x for x in ch.at([0.0, a]))
        start = ruled_gluing_maps(faces[[(i - 1) % n]], C[:1], R[:1], E[:1], c[:1], r[:1], e[:1])
        end = ruled_gluing_maps(faces[[i]], C[1:], R[1:], E[1:], c[1:], r[1:], e[1:])
        side_map = face_map @ start[0]
        side_maps.append(side_map)
        face_map = side_map @ invert(end[0])
    return side_maps, face_map


def creases(frame, charts, V, n_s=201):
    """Every side's crease on a dense arc: F, f (in the side chart), l and dn."""
    side_maps, rho = chain(frame, charts)
    v = developed_apices(rho[None])[0]
    out = []
    for ch, m in zip(charts, side_maps, strict=True):
        s = np.linspace(0, ch.side.arc, n_s)
        C, R, c, r, _, _ = ch.at(s)
        vi = (invert(m) @ np.append(v, 1.0))[:2]
        l, _, dn = crease_height_ruled(V, vi, C, R, c, r)
        out.append(dict(s=s, F=C + l[:, None] * R, f=c + l[:, None] * r, l=l, dn=dn, vi=vi))
    return out, side_maps, rho, v


@pytest.fixture(scope="module")
def cube():
    m = mesh("cube")
    return m, round_edges(m, 0.1 * m.mean_edge_length)


def apex_below(m, frame, depth):
    """A spatial apex ``depth`` (times the mean edge) inside the solid, toward its centre."""
    centre = m.vertices.mean(axis=0)
    d = centre - frame.U
    return frame.U + depth * m.mean_edge_length * d / np.linalg.norm(d)


def test_the_chain_of_cylinders_is_the_frames_rho(cube):
    """With no conical side the chain built here is the library's rho (the test's harness)."""
    m, rd = cube
    for u in range(m.n_vertices):
        frame = vertex_frame(m, rd, u)
        _, rho = chain(frame, [Chart(s, False) for s in frame.sides])
        assert_allclose(rho, frame.rho, atol=1e-13)


@pytest.mark.parametrize("name", ["cube", "icosahedron", "random-convex"])
def test_a_conical_fillet_is_tangent_to_both_faces_and_develops_isometrically(name):
    m = mesh(name)
    rd = round_edges(m, 0.1 * m.mean_edge_length)
    frame = vertex_frame(m, rd, 0)
    for i, side in enumerate(frame.sides):
        S = sharp_end(side)
        s = np.linspace(0, side.arc, 401)
        C, R, c, r, q = fillet_chart(
            FilletRows(*side_rows(side, s), np.repeat(S[None], len(s), 0)), s
        )
        dC = arc_points(*side_rows(side, s), s)[1]
        # the rulings run from S through the base curve, toward W
        assert (R @ side.R > 0).all()
        assert_allclose(
            np.linalg.norm(C - S - np.einsum("ij,ij->i", C - S, R)[:, None] * R, axis=1),
            0,
            atol=1e-13,
        )
        # tangent planes along the end rulings are the faces (front normals)
        normal = np.cross(dC, C - S)  # C x R orientation, as on a cylinder
        normal /= np.linalg.norm(normal, axis=1)[:, None]
        assert_allclose(normal[0], m.face_normal[frame.ring.faces[i - 1]], atol=1e-12)
        assert_allclose(normal[-1], m.face_normal[frame.ring.faces[i]], atol=1e-12)
        # the chart is an isometry: distances to S, the base curve's length, and the angle
        # between the curve and the rulings are kept
        assert_allclose(np.linalg.norm(c - q, axis=1), np.linalg.norm(C - S, axis=1), rtol=1e-13)
        dc = np.gradient(c, s, axis=0, edge_order=2)
        assert_allclose(np.linalg.norm(dc, axis=1), 1.0, atol=1e-5)
        assert_allclose(np.einsum("ij,ij->i", dc, r), np.einsum("ij,ij->i", dC, R), atol=1e-5)
        # the chart agrees with a cylinder's at s = 0
        assert_allclose(c[0], [0, 0], atol=1e-15)
        assert_allclose(r[0], [0, 1], atol=1e-15)
        # the sector is narrower than the two tangent strips it replaces would be flat
        assert (
            0
            < np.arctan2(r[-1, 0], r[-1, 1])
            < 2 * np.arctan2(side.radius * np.tan(side.gamma), 0.5 * side.length)
        )


@settings(max_examples=60, deadline=None)
@given(
    radius=st.floats(0.01, 3.0),
    gamma=st.floats(0.02, 1.55),
    half_length=st.floats(0.05, 3.0),
)
def test_the_developed_angle_is_integrated_to_round_off(radius, gamma, half_length):
    """The integrated Chebyshev series against adaptive quadrature, on an edge along z through the
    origin (its midpoint), for fillets from thin to twice as wide at the midpoint as half the
    edge is long."""
    assume(radius * np.tan(gamma) <= 2 * half_length)
    O = np.array([[-radius / np.cos(gamma), 0.0, 0.0]])
    N0 = np.array([[np.cos(gamma), -np.sin(gamma), 0.0]])
    B = np.array([[np.sin(gamma), np.cos(gamma), 0.0]])  # R x N0, R = +z
    S = np.array([[0.0, 0.0, -half_length]])
    kappa, r = np.array([1.0]), np.array([radius])
    a = 2 * radius * gamma

    def rate(t):
        C, dC = arc_points(O, N0, B, kappa, r, np.array([t]))
        return sweep_rate(C, dC, S)[0]

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # quad's own round-off notice at 1e-15
        want = quad(rate, 0, a, epsabs=1e-16, epsrel=1e-15, limit=200)[0]
    got = developed_angles(FilletRows(O, N0, B, kappa, r, S), np.array([a]))[0]
    assert abs(got - want) <= 1e-13 * want
    # inside the arc, with a second fillet (the mirror image) in the same call: each row gets
    # its own fillet's integral from 0 to its s
    s = a * np.array([0.0, 0.1, 0.37, 0.5, 0.93, 1.0, 0.25])
    fill = np.array([0, 0, 0, 1, 1, 1, 0])
    mirror = np.diag([1.0, -1.0, 1.0])
    rows = [np.vstack([x, x @ mirror])[fill] for x in (O, N0, B)]
    both_rows = FilletRows(*rows, np.ones(7), np.full(7, radius), np.vstack([S, S])[fill])
    both = developed_angles(both_rows, s)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        each = [quad(rate, 0, x, epsabs=1e-16, epsrel=1e-15, limit=200)[0] for x in s]
    assert_allclose(both, each, rtol=0, atol=1e-13 * want)
    named = developed_angles(both_rows, s, fillet=fill)
    assert_allclose(named, both, rtol=0, atol=1e-15 * want)
    # the ends of the arc lie on the faces through the edge (the set-up is an edge's)
    C = arc_points(O, N0, B, kappa, r, np.array([0.0, a]))[0]
    assert abs(C[0] @ N0[0]) < 1e-12 * max(1, radius)


def feasible_apex(m, frame, charts):
    """The shallowest apex toward the solid's centre (depths 0.05 to 0.8 mean edges) whose
    creases are valid patches within their halves of the edges (``dn > 0``, ``l >= 0``)."""
    for depth in np.linspace(0.05, 0.8, 31):
        V = apex_below(m, frame, depth)
        out = creases(frame, charts, V, 41)[0]
        if all((o["dn"] > 0).all() and (o["l"] >= 0).all() for o in out):
            return V
    return None


@pytest.mark.parametrize(
    "name, u, sharp",
    [
        ("cube", 0, [0]),
        ("cube", 3, [0, 2]),
        ("cube", 5, [0, 1, 2]),
        ("icosahedron", 0, [1]),
        ("icosahedron", 4, [0, 3]),
        ("random-convex", 2, [1]),
        ("random-convex", 7, [0, 2]),
    ],
)
def test_the_crease_closes_tangent_continuously_around_a_vertex_with_conical_sides(name, u, sharp):
    """Around W with some sharp neighbours: the fixed point of the mixed chain gives creases
    on which eq. (1) holds, that lie on their fillets, keep the cone's ruling lengths and the
    fillet's distances to S, and meet the straight creases on the faces tangentially."""
    m = mesh(name)
    rd = round_edges(m, 0.1 * m.mean_edge_length)
    frame = vertex_frame(m, rd, u)
    n = len(frame.sides)
    charts = [Chart(s, i in sharp) for i, s in enumerate(frame.sides)]
    V = feasible_apex(m, frame, charts)
    assert V is not None, "no apex toward the centre is feasible"
    out, _, rho, v = creases(frame, charts, V)
    assert not np.isnan(v).any()
    # each conical side turns rho by 2 psi - theta(a) more than its cylinder: the faces'
    # wedges at S (half-angle psi, width A/2 at the midpoint) give way to the fillet's sector
    turn = frame.rotation_angle()
    for i in sharp:
        sd = frame.sides[i]
        psi = np.arctan2(sd.radius * np.tan(sd.gamma), 0.5 * sd.length)
        theta = developed_angles(
            FilletRows(*side_rows(sd, [sd.arc]), sharp_end(sd)[None]), [sd.arc]
        )[0]
        turn += 2 * psi - theta
    assert_allclose(np.arctan2(rho[1, 0], rho[0, 0]), turn, atol=1e-13)
    ends = []
    for i, (ch, o) in enumerate(zip(charts, out, strict=True)):
        assert (o["dn"] > 0).all(), f"side {i}: not a valid patch"
        assert (o["l"] >= 0).all(), f"side {i}: the crease leaves its half of the edge"
        # ruling lengths of W's cone kept (eq. (1)), points on the fillet
        assert_allclose(
            np.linalg.norm(o["F"] - V, axis=1),
            np.linalg.norm(o["f"] - o["vi"], axis=1),
            rtol=1e-11,
        )
        if ch.conical:
            S = sharp_end(ch.side)
            q = ch.at(np.zeros(1))[2][0] - np.array([0.0, 1.0]) * np.linalg.norm(
                ch.at(np.zeros(1))[0][0] - S
            )
            assert_allclose(
                np.linalg.norm(o["F"] - S, axis=1),
                np.linalg.norm(o["f"] - q, axis=1),
                rtol=1e-12,
            )
        # crease lengths equal in 3D and in the chart
        L3 = np.linalg.norm(np.diff(o["F"], axis=0), axis=1).sum()
        L2 = np.linalg.norm(np.diff(o["f"], axis=0), axis=1).sum()
        assert_allclose(L2, L3, rtol=1e-4)
        ends.append(
            (o["F"][0], o["F"][-1], end_tangent(ch, o["vi"], V, 0), end_tangent(ch, o["vi"], V, 1))
        )
    # the straight crease on face f_i joins side i's end to side i+1's start tangentially
    for i in range(n):
        seg = ends[(i + 1) % n][0] - ends[i][1]
        seg /= np.linalg.norm(seg)
        for t in (ends[i][3], ends[(i + 1) % n][2]):
            angle = np.arccos(min(abs(seg @ t), 1.0))
            assert angle < 1e-7, f"face {i}: kink of {np.degrees(angle):.2e} deg"


def end_tangent(ch, vi, V, which):
    """Unit tangent of the crease at the start (0) or end (1) of the arc, from a one-sided
    five-point difference (error of order h^4)."""
    a = ch.side.arc
    h = 1e-3 * a
    s = np.arange(5) * h if which == 0 else a - np.arange(5) * h
    C, R, c, r, _, _ = ch.at(s)
    l = crease_height_ruled(V, vi, C, R, c, r)[0]
    F = C + l[:, None] * R
    d = (-25 * F[0] + 48 * F[1] - 36 * F[2] + 16 * F[3] - 3 * F[4]) / 12
    return d / np.linalg.norm(d)


def test_cone_rulings_are_unit():
    C = np.array([[1.0, 2.0, 3.0], [0.0, 0.0, 1.0]])
    S = np.array([[1.0, 2.0, 0.0], [0.0, 0.0, 0.0]])
    R, rho = cone_rulings(C, S)
    assert_allclose(rho, [3.0, 1.0])
    assert_allclose(R, [[0, 0, 1], [0, 0, 1]])


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), m=st.integers(1, 40))
def test_the_sector_apex_is_the_image_of_s_at_the_start_of_the_arc(seed, m):
    """``q = (0, -|C(0) - S|)`` of :func:`fillet_chart` is the distance from ``S`` to the base
    curve's point at ``s = 0`` as :func:`arc_points` gives it, to the bit (it is taken from
    ``O + kappa r N0`` without the sines and cosines of ``s = 0``)."""
    rng = np.random.default_rng(seed)
    N0 = rng.normal(size=(m, 3))
    N0 /= np.linalg.norm(N0, axis=1)[:, None]
    B = np.cross(N0, rng.normal(size=(m, 3)))
    B /= np.linalg.norm(B, axis=1)[:, None]
    B[rng.random(m) < 0.3, 0] = 0.0  # exact zeros and
    N0[rng.random(m) < 0.3, 1] = -0.0  # negative zeros in the frames
    O = rng.normal(size=(m, 3))
    kappa = rng.choice([-1.0, 1.0], m)
    radius = rng.uniform(0.01, 2.0, m)
    S = O + rng.normal(size=(m, 3)) * 3.0
    s = rng.uniform(-1.0, 1.0, m) * radius
    q = fillet_chart(FilletRows(O, N0, B, kappa, radius, S), s, theta=np.zeros(m))[4]
    C0 = arc_points(O, N0, B, kappa, radius, np.zeros(m))[0]
    assert np.array_equal(q[:, 1], -cone_rulings(C0, S)[1]) and not q[:, 0].any()
