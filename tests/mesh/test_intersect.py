"""Self-intersection of polygon surfaces (:mod:`filletfold.mesh.intersect`): crossing triangle
pairs counted once, touching ones (a shared vertex or edge) never, segments piercing
triangles; the same answers after moving, turning or scaling the whole."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.mesh import load_mesh
from filletfold.mesh.intersect import crossing_triangle_pairs, segment_hits_triangle

FLAT = np.array([[0.0, 0, 0], [2, 0, 0], [0, 2, 0]])  # in the plane z = 0


def pair(second) -> tuple[np.ndarray, list[list[int]]]:
    """The triangle FLAT (vertices 0-2) and the triangle ``second`` (vertices 3-5)."""
    return np.vstack([FLAT, second]), [[0, 1, 2], [3, 4, 5]]


def test_two_crossing_triangles_count_once():
    v, f = pair([[0.5, 0.5, -1], [0.5, 0.5, 1], [3, 3, 0.5]])  # an edge through FLAT
    assert crossing_triangle_pairs(v, f) == 1
    # each crossing the other's interior (the edges of both go through the other)
    v, f = pair([[0.3, 0.6, -1], [0.6, 0.3, 1], [-2, -2, 0.0]])
    assert crossing_triangle_pairs(v, f) == 1


def test_disjoint_triangles_count_nothing():
    v, f = pair(FLAT + np.array([0, 0, 0.5]))  # parallel, above
    assert crossing_triangle_pairs(v, f) == 0
    v, f = pair([[3, 3, -1], [3, 3, 1], [4, 4, 0]])  # through the plane, beside FLAT
    assert crossing_triangle_pairs(v, f) == 0
    v, f = pair([[0.5, 0.5, 0.1], [0.5, 0.5, 1], [1, 0.2, 2]])  # stops short of the plane
    assert crossing_triangle_pairs(v, f) == 0


def test_triangles_sharing_an_edge_or_a_vertex_count_nothing():
    v = np.vstack([FLAT, [[1.0, 1.0, 1.0], [-1, -1, 1], [0.5, 0.5, -1]]])
    assert crossing_triangle_pairs(v, [[0, 1, 2], [1, 0, 3]]) == 0  # an edge: a fold
    assert crossing_triangle_pairs(v, [[0, 1, 2], [0, 3, 4]]) == 0  # a vertex
    assert crossing_triangle_pairs(v, [[0, 1, 2], [1, 2, 0]]) == 0  # all three
    # a shared vertex skips the pair, even when it crosses elsewhere (documented)
    assert crossing_triangle_pairs(v, [[0, 1, 2], [0, 3, 5]]) == 0
    assert crossing_triangle_pairs(v, [[0, 1, 2], [4, 3, 5]]) == 1  # the same, apart


def test_polygons_are_fanned():
    square = np.array([[0.0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]])
    stick = [[1.5, 0.5, -1], [1.5, 0.5, 1], [4, 4, 0]]  # pierces the fan's first triangle
    v = np.vstack([square, stick])
    assert crossing_triangle_pairs(v, [[0, 1, 2, 3], [4, 5, 6]]) == 1
    v[4:6, :2] = [0.5, 1.5]  # now the second triangle of the fan
    assert crossing_triangle_pairs(v, [[0, 1, 2, 3], [4, 5, 6]]) == 1


@pytest.mark.parametrize("name", ["cube", "icosahedron", "torus", "l-prism"])
def test_closed_examples_do_not_intersect_themselves(name):
    m = load_mesh(name)[0]
    assert crossing_triangle_pairs(m.vertices, m.faces) == 0


def test_two_interpenetrating_cubes_intersect():
    m = load_mesh("cube")[0]
    size = np.ptp(m.vertices, axis=0).max()
    shifted = m.vertices + 0.5 * size * np.array([1.0, 0.7, 0.3])
    faces = list(m.faces) + [np.asarray(f) + m.n_vertices for f in m.faces]
    assert crossing_triangle_pairs(np.vstack([m.vertices, shifted]), faces) > 0
    apart = m.vertices + 2.0 * size
    assert crossing_triangle_pairs(np.vstack([m.vertices, apart]), faces) == 0


def test_a_segment_piercing_a_triangle():
    t = np.repeat(FLAT[None], 6, axis=0)
    s0 = np.array(
        [[0.5, 0.5, -1], [0.5, 0.5, 0.5], [3, 3, -1], [0.5, 0.5, -1], [0, 0, 0], [1, 1, 1]]
    )
    s1 = np.array([[0.5, 0.5, 1], [0.5, 0.5, 2], [3, 3, 1], [1.0, 0.5, 0], [1, 1, 0], [1, 1, -1]])
    hit = segment_hits_triangle(s0, s1, t)
    assert hit.dtype == bool and hit.shape == (6,)
    # through; above it; beside it; ending on it; lying in its plane (parallel: no hit);
    # through its hypotenuse (on its border: a hit)
    assert hit.tolist() == [True, False, False, True, False, True]
    # the segment's direction does not matter
    assert segment_hits_triangle(s1, s0, t).tolist() == hit.tolist()


# ---------------------------------------------------------------- invariance


def random_motion(rng, scale: float):
    """A random rotation (or rotation-reflection), then ``scale``, then a shift."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    shift = rng.uniform(-1e3, 1e3, size=3)
    return lambda p: (np.asarray(p) @ q.T) * scale + shift


def crossing_configuration(rng, cross: bool):
    """Triangle A, and triangle B whose edge passes through A's interior (barycentric
    coordinates at least 0.2) when ``cross``, else stops at least 0.3 short of A's plane."""
    a = rng.normal(size=(3, 3))
    n = np.cross(a[1] - a[0], a[2] - a[0])
    while np.linalg.norm(n) < 0.5:  # not too thin
        a = rng.normal(size=(3, 3))
        n = np.cross(a[1] - a[0], a[2] - a[0])
    n /= np.linalg.norm(n)
    w = rng.dirichlet([4, 4, 4])
    w = 0.2 + 0.4 * w  # at least 0.2 each, summing to 1
    hit = w @ a
    lo = rng.uniform(0.3, 2.0) * (-1 if cross else 1)
    aside = rng.normal(size=3)
    aside -= (aside @ n) * n  # B's third corner 3 above A's plane
    b = np.array([hit + lo * n, hit + rng.uniform(0.3, 2.0) * n, hit + 3 * n + aside])
    return np.vstack([a, b]), [[0, 1, 2], [3, 4, 5]]


@settings(max_examples=60, deadline=None)
@given(
    st.integers(0, 10**6),
    st.booleans(),
    st.sampled_from([1e-3, 0.1, 1.0, 7.0, 1e3]),
)
def test_counts_do_not_depend_on_placement_or_scale(seed, cross, scale):
    rng = np.random.default_rng(seed)
    v, f = crossing_configuration(rng, cross)
    assert crossing_triangle_pairs(v, f) == int(cross)
    move = random_motion(rng, scale)
    assert crossing_triangle_pairs(move(v), f) == int(cross)
    # the piercing edge alone, against the triangle
    got = segment_hits_triangle(move(v[3:4]), move(v[4:5]), move(v[None, :3]))
    assert got.tolist() == [cross]


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10**6), st.sampled_from([1e-3, 1.0, 1e3]))
def test_an_example_stays_free_of_self_intersection_when_moved(seed, scale):
    m = load_mesh("icosahedron")[0]
    move = random_motion(np.random.default_rng(seed), scale)
    assert crossing_triangle_pairs(move(m.vertices), m.faces) == 0
