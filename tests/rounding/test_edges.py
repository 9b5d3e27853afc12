"""Edge rounding: cylinders, half angles, material loss, radius limits (sec. 2.1, 4.1)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from filletfold.errors import ParameterError
from filletfold.mesh import load_mesh
from filletfold.rounding.edges import (
    edge_dihedral,
    loss_from_radius,
    radius_from_loss,
    round_edges,
)
from filletfold.vertex.frame import vertex_frame


def mesh(name):
    return load_mesh(name)[0]


def test_cube_edges_are_right_angle_mountains():
    gamma, kappa = edge_dihedral(mesh("cube"))
    assert_allclose(gamma, np.pi / 4, atol=1e-12)
    assert np.all(kappa == 1)


def test_dimpled_cube_has_valley_edges():
    m = mesh("dimpled-cube")
    _, kappa = edge_dihedral(m)
    assert (kappa == -1).sum() == 4 and (kappa == 1).sum() == m.n_edges - 4


@given(r=st.floats(1e-3, 10), gamma=st.floats(1e-2, 1.5))
def test_loss_radius_round_trip(r, gamma):
    w = loss_from_radius(r, gamma)
    assert w > 0
    assert_allclose(radius_from_loss(w, gamma), r, rtol=1e-9)
    # a = 2 r gamma, A = 2 r tan(gamma), w = A - a (sec. 4.1)
    assert_allclose(w, 2 * r * np.tan(gamma) - 2 * r * gamma, rtol=1e-6)


@pytest.mark.parametrize("name", ["icosahedron", "cube", "dimpled-cube", "random-convex"])
def test_cylinders_are_tangent_to_both_faces(name):
    m = mesh(name)
    rd = round_edges(m, 0.1)
    for u in range(m.n_vertices):
        frame = vertex_frame(m, rd, u)
        ring = frame.ring
        for i, side in enumerate(frame.sides):
            s = np.linspace(0, side.arc, 7)
            C, N, T = side.base(s), side.normal(s), side.tangent(s)
            # orientation: C'(s) x R = N(s) (docs/method.md, 'Conventions')
            assert_allclose(np.cross(T, side.R), N, atol=1e-12)
            # every base point at distance r from the axis, in the midpoint cross-section
            d = C - side.O
            assert_allclose(np.linalg.norm(d - np.outer(d @ side.R, side.R), axis=1), side.radius)
            assert_allclose((C - side.M) @ side.R, 0, atol=1e-12)
            # the ends lie on the two faces, with the faces' normals
            for k, f in ((0, ring.faces[i - 1]), (-1, ring.faces[i])):
                n = m.face_normal[f]
                assert_allclose(N[k], n, atol=1e-12)
                assert abs((C[k] - m.vertices[m.faces[f][0]]) @ n) < 1e-12
            assert_allclose(side.arc, 2 * side.radius * side.gamma)


def test_uniform_limit_is_sharp():
    m = mesh("cube")
    rd = round_edges(m, 0.3)
    assert_allclose(rd.uniform_limit, 0.5, rtol=1e-12)
    # just below the limit the tangent lines cross right at the edge midpoints (l_max -> 0)
    near = round_edges(m, 0.5 * (1 - 1e-6))
    lmax = min(np.nanmin(vertex_frame(m, near, u).lmax_start) for u in range(m.n_vertices))
    assert 0 < lmax < 1e-5
    with pytest.raises(
        ParameterError,
        match=r"radius 0\.51 on edge \d+ \(vertices \d+-\d+\) "
        r"exceeds its limit 0\.5",
    ):
        round_edges(m, 0.51)


def test_limit_per_edge_names_the_edge():
    m = mesh("icosahedron")
    r = np.full(m.n_edges, 0.1)
    r[7] = 2.0
    with pytest.raises(ParameterError, match=r"on edge 7 .*exceeds its limit") as info:
        round_edges(m, r)
    assert info.value.edge == 7


def test_per_edge_radius_is_used():
    m = mesh("random-convex")
    r = np.linspace(0.05, 0.12, m.n_edges)
    rd = round_edges(m, r)
    assert_allclose(rd.radius, r)
    assert_allclose(rd.arc_length, 2 * r * rd.half_angle)
    assert_allclose(rd.strip_width, 2 * r * np.tan(rd.half_angle))


def test_boundary_edges_are_not_rounded():
    m = mesh("open-box")
    rd = round_edges(m, 0.1)
    assert np.all(rd.radius[m.is_boundary_edge] == 0)
    assert np.all(rd.radius[~m.is_boundary_edge] == 0.1)


def test_flat_edges_are_not_rounded():
    m = mesh("torus")  # the top and bottom rings of quads are coplanar around the hole
    rd = round_edges(m, 0.1)
    flat = ~m.is_boundary_edge & (rd.radius == 0)
    assert flat.sum() > 0
    assert np.all(rd.half_angle[flat] == 0) and np.all(rd.loss[flat] == 0)


@pytest.mark.parametrize(
    ("radius", "match"),
    [(np.nan, "finite"), (-0.1, "positive"), (np.ones(3), "shape")],
)
def test_bad_radius(radius, match):
    with pytest.raises(ParameterError, match=match):
        round_edges(mesh("cube"), radius)


def test_zero_radius_and_slivers_leave_edges_sharp():
    """Radius 0 on a bent edge, or a fillet narrower than ``floor`` of its edge, leaves the edge
    sharp: radius 0 but its half angle and mountain/valley sign kept."""
    m = mesh("cube")
    r = np.full(m.n_edges, 0.1)
    r[0] = 0.0
    r[1] = 1e-5
    rd = round_edges(m, r, floor=1e-3)
    assert rd.sharp.tolist() == [True, True] + [False] * (m.n_edges - 2)
    assert np.all(rd.radius[:2] == 0) and np.all(rd.arc_length[:2] == 0)
    assert_allclose(rd.half_angle, np.pi / 4) and np.all(rd.kappa == 1)
    assert round_edges(m, r).sharp.tolist() == [True] + [False] * (m.n_edges - 1)


@pytest.mark.parametrize("name", ["cube", "dimpled-cube", "random-convex"])
def test_tangent_lines_lie_on_both_faces_at_half_the_strip_width(name):
    m = mesh(name)
    rd = round_edges(m, 0.1)
    for e in np.nonzero(~m.is_boundary_edge)[0]:
        mid = m.vertices[m.edges[e]].mean(axis=0)
        for k in (0, 1):
            f = m.edge_faces[e, k]
            t = rd.tangent_point[e, k]
            assert abs((t - m.vertices[m.faces[f][0]]) @ m.face_normal[f]) < 1e-12
            assert_allclose(np.linalg.norm(t - mid), rd.strip_width[e] / 2, rtol=1e-12)
            q = t - rd.axis_point[e]
            assert_allclose(np.linalg.norm(q), rd.radius[e], rtol=1e-12)


def test_unrounded_edges_keep_their_face_pieces():
    """Along an edge left unrounded (sharp, flat or boundary) the rounded neighbours' tangent
    lines must cross before its midpoint too: on the floor of a CAD pocket (a 40-gon of short
    edges at 171 degree corners) with every other rim edge left sharp, the fitted radii leave
    every face piece a simple polygon (the pieces' centres exist)."""
    from filletfold.mesh import clean_mesh
    from filletfold.rounding.edges import shrink_broken
    from filletfold.surface.centres import face_piece_centres

    n = 40
    t = 2 * np.pi * np.arange(n) / n
    ring = np.c_[np.cos(t), np.sin(t)]
    v = np.vstack([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, 0.2)]])
    faces = [np.arange(n)[::-1], np.arange(n, 2 * n)]
    faces += [np.array([i, (i + 1) % n, n + (i + 1) % n, n + i]) for i in range(n)]
    m, _ = clean_mesh(v, faces, strict=True)
    rim = (m.edges >= n).all(axis=1)  # the top 40-gon's edges
    r = np.full(m.n_edges, 0.05)
    r[np.flatnonzero(rim)[::2]] = 0.0  # every other rim edge sharp
    gamma = edge_dihedral(m)[0]
    r = shrink_broken(m, r, gamma)
    rd = round_edges(m, r)
    assert rim.sum() == n and rd.sharp[rim].sum() == n // 2
    assert np.isfinite(face_piece_centres(m, rd)).all()


def test_tiny_fillets_in_a_large_design_are_left_sharp_and_tiny_arcs_sampled_coarsely():
    m = mesh("cube")
    r = np.full(m.n_edges, 0.1)
    r[0] = 1e-7
    rd = round_edges(m, r, min_width=1e-6)
    assert rd.sharp.tolist() == [True] + [False] * (m.n_edges - 1)
    # an arc of length 0.157 sampled no finer than 0.05: 4 points
    assert rd.arc_points(24, 0.0, min_chord=0.05)[1:].tolist() == [4] * (m.n_edges - 1)
    assert rd.arc_points(24, 0.0)[1:].tolist() == [24] * (m.n_edges - 1)
