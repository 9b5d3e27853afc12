"""The batched vertex normal (sec. 3.1) against an independent reference.

The reference does not share code with the library: for ``b <= 0`` it reads the facet nearest
the origin off scipy's convex hull; for ``b > 0`` it finds the min-norm point of the hull with
SLSQP on the barycentric weights, polishes it on the active set and checks its optimality
certificate.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.optimize import minimize
from scipy.spatial import ConvexHull, QhullError

from filletfold.errors import ParameterError
from filletfold.mesh import load_mesh
from filletfold.tolerances import tol
from filletfold.vertex.normal import (
    _max_min_enumerate,
    _pack,
    max_min_direction,
    max_min_directions,
    vertex_normal,
    vertex_normals,
)

B_TOL = 1e-9  # agreement of bounds with the reference
EXACT = 1e-12  # rounding-level agreement


def reference_max_min(u: np.ndarray) -> float:
    """``max_{|D|=1} min_k D . u_k`` of one set of vectors (k, 3), k >= 4, in general position."""
    hull = ConvexHull(u)
    offset = hull.equations[:, 3]  # n . x + offset <= 0 inside, |n| = 1
    if np.all(offset < 0):  # origin inside: minus the distance to the nearest facet plane
        return float(offset.max())
    res = minimize(
        lambda lam: (lam @ u) @ (lam @ u),
        np.full(len(u), 1 / len(u)),
        jac=lambda lam: 2 * u @ (lam @ u),
        bounds=[(0, 1)] * len(u),
        constraints=[{"type": "eq", "fun": lambda lam: lam.sum() - 1}],
        method="SLSQP",
        options={"ftol": 1e-16, "maxiter": 500},
    )
    upper = float(np.linalg.norm(res.x @ u))  # a point of the hull: b <= its norm
    if upper < B_TOL:  # the origin on the boundary: 0 <= max(offset) <= b <= upper
        return float(offset.max())
    # polish: project the origin onto the affine hull of the active points
    active = u[res.x > 1e-6 * res.x.max()]
    e = active[1:] - active[0]
    p = active[0] + np.linalg.lstsq(e @ e.T, -e @ active[0], rcond=None)[0] @ e
    b = float(np.min(u @ p) / np.linalg.norm(p))  # the value of a direction: b >= it
    assert b >= upper - 1e-10, "reference not certified"
    return b


def unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_sets(seed: int, n: int, k_max: int, spread: float):
    """n random sets of 4..k_max unit vectors around random axes, padded with garbage."""
    rng = np.random.default_rng(seed)
    count = rng.integers(4, k_max + 1, size=n)
    axis = unit(rng.normal(size=(n, 1, 3)))
    u = unit(axis + spread * rng.uniform(0.2, 1.0, (n, 1, 1)) * rng.normal(size=(n, k_max, 3)))
    pad = np.arange(k_max) >= count[:, None]
    u[pad] = rng.uniform(-50, 50, size=(pad.sum(), 3))  # must never be read
    return u, count


def cone_ring(heights, angles=None, jitter=0.0, seed=0):
    """Edge directions toward a vertex at the origin and the front normals of its faces.

    The neighbours lie at ``(cos a, sin a, h)``; faces are counter-clockwise seen from +z.
    """
    heights = np.asarray(heights, dtype=float)
    n = len(heights)
    if angles is None:
        angles = 2 * np.pi * np.arange(n) / n
    rng = np.random.default_rng(seed)
    nb = np.stack([np.cos(angles), np.sin(angles), heights], axis=1)
    nb += jitter * rng.normal(size=nb.shape)
    face_normal = unit(np.cross(nb, np.roll(nb, -1, axis=0)))
    return unit(-nb), face_normal


def signs_reference(edge_dir, face_normal):
    """Reference bounds (b for sigma = -1, b for sigma = +1) of one vertex."""
    return tuple(
        reference_max_min(np.vstack([-edge_dir, sigma * face_normal])) for sigma in (-1, 1)
    )


# ---------------------------------------------------------------- random sets


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    k_max=st.integers(4, 14),
    spread=st.floats(0.05, 4.0),
)
def test_batched_max_min_matches_reference(seed, k_max, spread):
    u, count = random_sets(seed, 12, k_max, spread)
    d, b = max_min_directions(u, count)
    assert d.shape == (12, 3) and b.shape == (12,)
    assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=EXACT)
    for i in range(12):
        ui = u[i, : count[i]]
        assert_allclose(b[i], reference_max_min(ui), atol=B_TOL)
        assert_allclose(np.min(ui @ d[i]), b[i], atol=EXACT)  # b is D's value


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    degree=st.integers(3, 9),
    lift=st.floats(-1.0, 1.0),
    wobble=st.floats(0.05, 1.5),
)
def test_batched_vertex_normals_match_reference(seed, degree, lift, wobble):
    """Random vertex rings of mixed degree (cones, saddles, flat-ish), padded, in one batch."""
    rng = np.random.default_rng(seed)
    n, k_max = 8, degree + 3
    edge_dir = np.full((n, k_max, 3), np.nan)  # padding, never read
    face_normal = rng.uniform(-9, 9, (n, k_max, 3))
    count = rng.integers(3, k_max + 1, size=n)
    for v in range(n):
        k = count[v]
        angles = np.sort(rng.uniform(0, 2 * np.pi, k))
        if np.max(np.diff(np.r_[angles, angles[0] + 2 * np.pi])) > 0.9 * np.pi:
            angles = 2 * np.pi * np.arange(k) / k + rng.uniform(-0.2, 0.2, k)
        heights = lift + wobble * rng.normal(size=k)
        edge_dir[v, :k], face_normal[v, :k] = cone_ring(heights, angles)
    d, b, sigma = vertex_normals(edge_dir, face_normal, count, count)
    assert d.shape == (n, 3) and b.shape == (n,) and sigma.shape == (n,)
    for v in range(n):
        e, f = edge_dir[v, : count[v]], face_normal[v, : count[v]]
        b_minus, b_plus = signs_reference(e, f)
        assert_allclose(b[v], max(b_minus, b_plus), atol=B_TOL)
        if abs(b_plus - b_minus) > B_TOL:
            assert sigma[v] == (1 if b_plus > b_minus else -1)
        u = np.vstack([-e, sigma[v] * f])
        assert_allclose(np.min(u @ d[v]), b[v], atol=EXACT)
        assert_allclose(np.linalg.norm(d[v]), 1.0, atol=EXACT)


def test_enumeration_fallback_agrees_with_gjk():
    """The candidate enumeration (saddles, and GJK's rare uncertified sets) on every kind of set."""
    u, count = random_sets(11, 60, 9, 1.5)
    _, b = max_min_directions(u, count)
    assert np.any(b > 0.05) and np.any(b < -0.05)
    packed, count = _pack(u, [(u.shape[1], count)])
    d_enum, b_enum = _max_min_enumerate(packed, count)
    assert_allclose(b_enum, b, atol=EXACT)
    assert_allclose(np.einsum("ikx,ix->ik", packed, d_enum).min(axis=1), b, atol=EXACT)


def test_single_vertex_functions_agree_with_the_batch():
    u, count = random_sets(7, 20, 10, 1.0)
    d, b = max_min_directions(u, count)
    for i in range(20):
        di, bi = max_min_direction(u[i, : count[i]])
        assert_allclose(di, d[i], atol=EXACT)
        assert_allclose(bi, b[i], atol=EXACT)
    edge_dir, face_normal = cone_ring([-0.4, -0.2, 0.1, -0.6, -0.3], jitter=0.05)
    D, bound, sigma = vertex_normal(edge_dir, face_normal)
    Db, bb, sb = vertex_normals(edge_dir[None], face_normal[None])
    assert isinstance(bound, float) and isinstance(sigma, int)
    assert_allclose(D, Db[0], atol=EXACT)
    assert (bound, sigma) == (bb[0], sb[0])


# ---------------------------------------------------------------- known answers


@pytest.mark.parametrize("n", [3, 4, 5, 8, 12])
@pytest.mark.parametrize("h", [0.2, 1.0, 3.0])
def test_regular_cone_has_the_axis_as_normal(n, h):
    """A regular n-gonal pyramid with apex U: D = -z, b from the edge or the face (analytic)."""
    edge_dir, face_normal = cone_ring(np.full(n, -h))
    D, b, sigma = vertex_normal(edge_dir, face_normal)
    apothem = np.cos(np.pi / n)
    expected = min(h / np.hypot(1, h), apothem / np.hypot(apothem, h))
    assert sigma == -1
    assert_allclose(D, [0, 0, -1], atol=EXACT)
    assert_allclose(b, expected, atol=EXACT)


@pytest.mark.parametrize("n", [4, 6, 8])
def test_saddle_has_no_positive_bound(n):
    """Neighbours alternately above and below: no plane has all faces on one side."""
    heights = 0.7 * (-1.0) ** np.arange(n)
    edge_dir, face_normal = cone_ring(heights, jitter=0.02, seed=n)
    D, b, sigma = vertex_normal(edge_dir, face_normal)
    assert b <= tol.normal_bound
    assert_allclose(b, max(signs_reference(edge_dir, face_normal)), atol=B_TOL)
    u = np.vstack([-edge_dir, sigma * face_normal])
    assert_allclose(np.min(u @ D), b, atol=EXACT)


def test_duplicated_vectors_change_nothing():
    edge_dir, face_normal = cone_ring([-0.5, -0.1, -0.9, -0.3, -0.4], jitter=0.03)
    D, b, sigma = vertex_normal(edge_dir, face_normal)
    D2, b2, sigma2 = vertex_normal(np.repeat(edge_dir, 3, axis=0), np.vstack([face_normal] * 2))
    assert_allclose(D2, D, atol=EXACT)
    assert_allclose(b2, b, atol=EXACT)
    assert sigma2 == sigma


def test_sets_of_one_and_two_vectors():
    a = unit([0.3, -0.2, 0.9])
    d, b = max_min_directions(np.stack([[a, a], [a, -a], [2 * a, a]]), np.array([1, 2, 2]))
    assert_allclose(d[[0, 2]], [a, a], atol=EXACT)
    assert_allclose(b, [1.0, 0.0, 1.0], atol=EXACT)
    assert_allclose(d[1] @ a, 0.0, atol=EXACT)


def test_degenerate_sets():
    """All vectors equal; two opposite vectors (b = 0, any D normal to them); all zero."""
    a = unit([0.3, -0.2, 0.9])
    d, b = max_min_directions(np.stack([np.tile(a, (3, 1)), [a, -a, a], np.zeros((3, 3))]))
    assert_allclose(d[0], a, atol=EXACT)
    assert_allclose(b[0], 1.0, atol=EXACT)
    assert_allclose(b[1], 0.0, atol=EXACT)
    assert_allclose(d[1] @ a, 0.0, atol=EXACT)
    assert_allclose(b[2], 0.0, atol=EXACT)
    assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=EXACT)


def test_optimum_on_a_hull_edge():
    """Two active vectors: D along the min-norm point of their segment."""
    u = unit([[1, 0, 0.2], [-1, 0, 0.2], [0, 0, 1], [0.3, 0.6, 0.8], [-0.2, -0.5, 0.7]])
    d, b = max_min_direction(u)
    assert_allclose(d, [0, 0, 1], atol=EXACT)
    assert_allclose(b, 0.2 / np.hypot(1, 0.2), atol=EXACT)
    assert np.sum(u @ d - b < 1e-9) == 2


def test_optimum_on_a_hull_vertex():
    """One active vector (not unit): D along it, b its length."""
    u = np.array([[0, 0, 0.5], [0.3, 0, 1.0], [-0.2, 0.4, 0.9], [0.1, -0.6, 0.7]])
    d, b = max_min_direction(u)
    assert_allclose(d, [0, 0, 1], atol=EXACT)
    assert_allclose(b, 0.5, atol=EXACT)
    assert np.sum(u @ d - b < 1e-9) == 1


def test_ties_keep_sigma_minus_one():
    """A flat vertex (all neighbours in the plane): both signs give the same b; -1 is kept."""
    edge_dir, face_normal = cone_ring(np.zeros(6))
    _, b, sigma = vertex_normal(edge_dir, face_normal)
    assert sigma == -1
    assert_allclose(b, 0.0, atol=EXACT)


def sphere_directions(n: int) -> np.ndarray:
    """(n, 3) nearly uniform unit vectors (Fibonacci)."""
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = np.pi * (1 + 5**0.5) * i
    return np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], 1)


@pytest.mark.parametrize("name", ["icosahedron", "dimpled-cube", "l-prism", "torus", "blob"])
def test_mesh_vertices_match_reference(name):
    """Every closed vertex of a mesh, in one padded batch; degenerate rings (a cube corner has
    only 3 distinct vectors per sign) are checked against a dense sampling bound instead."""
    m = load_mesh(name)[0]
    rings = [r for r in map(m.vertex_ring, range(m.n_vertices)) if r.closed]
    count = np.array([len(r.edges) for r in rings])
    edge_dir = np.zeros((len(rings), count.max(), 3))
    face_normal = np.zeros((len(rings), count.max(), 3))
    for i, r in enumerate(rings):
        edge_dir[i, : count[i]] = unit(m.vertices[r.vertex] - m.vertices[r.neighbors])
        face_normal[i, : count[i]] = m.face_normal[r.faces]
    d, b, sigma = vertex_normals(edge_dir, face_normal, count, count)
    grid = sphere_directions(20_000)
    for i in range(len(rings)):
        e, f = edge_dir[i, : count[i]], face_normal[i, : count[i]]
        u = np.vstack([-e, sigma[i] * f])
        assert_allclose(np.min(u @ d[i]), b[i], atol=EXACT)
        try:
            assert_allclose(b[i], max(signs_reference(e, f)), atol=B_TOL)
        except QhullError:
            for s in (-1, 1):
                sampled = (grid @ np.vstack([-e, s * f]).T).min(axis=1).max()
                assert b[i] >= sampled - EXACT
    if name == "torus":
        assert np.sum(b <= tol.normal_bound) == 24
    if name == "l-prism":
        assert np.sum(b <= tol.normal_bound) == 2


# ---------------------------------------------------------------- validation


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((np.zeros((2, 3)), np.zeros((2, 3))), r"edge_dir must have shape \(n, k, 3\)"),
        ((np.zeros((2, 3, 3)), np.zeros((3, 3, 3))), "face_normal has 3 vertices, edge_dir 2"),
        ((np.full((1, 3, 3), np.nan), np.zeros((1, 3, 3))), "edge_dir has non-finite values"),
        ((np.ones((1, 3, 3)), np.full((1, 2, 3), np.inf), [3], [1]), "face_normal has non-fin"),
        (
            (np.ones((2, 3, 3)), np.ones((2, 3, 3)), [3, 4], None),
            r"edge_count must lie in \[0, 3\]",
        ),
        ((np.ones((2, 3, 3)), np.ones((2, 3, 3)), [3.0, 1.0]), "edge_count must be 2 integers"),
        (
            (np.ones((2, 3, 3)), np.ones((2, 3, 3)), [3, 0], [3, 0]),
            "vertex 1 has no edge and no face",
        ),
    ],
)
def test_vertex_normals_validates_its_input(args, match):
    with pytest.raises(ParameterError, match=match):
        vertex_normals(*args)


def test_max_min_directions_validates_its_input():
    with pytest.raises(ParameterError, match="set 1 is empty"):
        max_min_directions(np.ones((2, 3, 3)), np.array([2, 0]))
    with pytest.raises(ParameterError, match="u has non-finite values"):
        max_min_directions(np.full((2, 3, 3), np.nan), np.array([2, 1]))
    with pytest.raises(ParameterError, match=r"u must have shape \(n, k, 3\)"):
        max_min_directions(np.ones((2, 3)))
