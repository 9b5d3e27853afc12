"""The half-edge mesh (:mod:`filletfold.mesh.polymesh`): connectivity, orientation, the Euler
characteristic, rings around vertices, and the face and vertex measures."""

from __future__ import annotations

import numpy as np
import pytest

import filletfold
from filletfold.errors import MeshError
from filletfold.mesh import PolyMesh

NAMES = ["cube", "torus", "open-box", "l-prism", "icosahedron", "saddle-patch"]


def mesh(name):
    return filletfold.load_mesh(name)[0]


@pytest.mark.parametrize("name", NAMES)
def test_every_halfedge_has_its_twin_or_is_a_border(name):
    m = mesh(name)
    for h, (a, b) in enumerate(zip(m.halfedge_from, m.halfedge_to, strict=True)):
        assert m.halfedge(int(a), int(b)) == h
        twin = m.halfedge(int(b), int(a))
        e = m.halfedge_edge[h]
        assert (twin < 0) == bool(m.is_boundary_edge[e])
        assert set(m.edges[e].tolist()) == {int(a), int(b)}
        assert m.halfedge_face[h] in m.edge_faces[e]
    assert (m.halfedge_to[m.halfedge_prev] == m.halfedge_from).all()


@pytest.mark.parametrize(("name", "chi"), [("cube", 2), ("icosahedron", 2), ("torus", 0)])
def test_the_euler_characteristic_of_a_closed_surface(name, chi):
    m = mesh(name)
    assert m.is_closed
    assert m.n_vertices - m.n_edges + m.n_faces == chi


@pytest.mark.parametrize("name", NAMES)
def test_a_ring_lists_its_faces_and_edges_in_order(name):
    m = mesh(name)
    for u in range(m.n_vertices):
        ring = m.vertex_ring(u)
        nf, ne = len(ring.faces), len(ring.edges)
        assert ne == nf + (not ring.closed)
        assert ring.closed == (not m.is_boundary_vertex[u])
        for i, f in enumerate(ring.faces.tolist()):
            corners = set(np.asarray(m.faces[f]).tolist())
            assert u in corners
            for e in (ring.edges[i], ring.edges[(i + 1) % ne]):
                assert set(m.edges[e].tolist()) <= corners  # face i lies between edges i, i + 1
        for e, w in zip(ring.edges.tolist(), ring.neighbors.tolist(), strict=True):
            assert set(m.edges[e].tolist()) == {u, w}


@pytest.mark.parametrize("name", ["cube", "icosahedron"])
def test_measures_of_a_closed_convex_solid(name):
    m = mesh(name)
    np.testing.assert_allclose(np.linalg.norm(m.face_normal, axis=1), 1.0, atol=1e-12)
    # outward: the normals point away from the centroid; the areas close the surface
    out = np.einsum("ij,ij->i", m.face_normal, m.face_centroid - m.vertices.mean(axis=0))
    assert (out > 0).all()
    np.testing.assert_allclose((m.face_area[:, None] * m.face_normal).sum(axis=0), 0, atol=1e-12)
    # a convex vertex has an angle sum below 2 pi (its defects sum to 4 pi)
    assert (m.vertex_angle_sum < 2 * np.pi).all()
    assert (2 * np.pi - m.vertex_angle_sum).sum() == pytest.approx(4 * np.pi)


@pytest.mark.parametrize("seed", range(5))
def test_sliver_normals_far_from_the_origin_are_their_planes(seed):
    # Newell's sum about the origin cancels |p|^2 large terms down to twice the area: a sliver
    # of the ant scan (edges 0.18, 0.18, 0.005 at |p| = 16) got a normal 2e-11 rad off its own
    # plane, which made the development's gluing maps shrink lengths (the contraction check)
    rng = np.random.default_rng(seed)
    k = 200
    a = rng.uniform(-20.0, 20.0, (k, 3))
    d = rng.normal(size=(k, 3))
    d *= (0.18 / np.linalg.norm(d, axis=1))[:, None]
    w = np.cross(d, rng.normal(size=(k, 3)))
    w *= (0.005 / np.linalg.norm(w, axis=1))[:, None]
    b, c = a + d, a + 0.5 * d + w
    m = PolyMesh(np.concatenate([a, b, c]), np.arange(3 * k).reshape(3, k).T.copy())
    exact = np.cross(b - a, c - a)
    np.testing.assert_allclose(m.face_area, 0.5 * np.linalg.norm(exact, axis=1), rtol=1e-12)
    for p, q in [(a, b), (b, c), (c, a)]:
        # every edge is in the face's plane to round-off of its own length (was 1e-11)
        assert np.abs(np.einsum("ij,ij->i", m.face_normal, q - p)).max() < 1e-15


def test_faces_used_twice_in_one_direction_are_named():
    v = np.eye(3)
    with pytest.raises(MeshError, match=r"edge \(0, 1\) is used twice"):
        PolyMesh(np.vstack([v, [[1.0, 1.0, 1.0]]]), [[0, 1, 2], [0, 1, 3]])
    with pytest.raises(MeshError, match="fewer than 3 vertices"):
        PolyMesh(v, [[0, 1]])


def test_newell_vectors_are_twice_the_vector_areas_about_the_centroid():
    """newell_vectors (the one definition the mesh, its repair and the certificate share):
    twice a polygon's vector area, the same however far the polygon is moved."""
    from filletfold.mesh.measures import newell_vectors

    square = np.array([[0.0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]])
    tri = np.array([[0.0, 0, 0], [0, 0, 3], [0, 1, 0]])
    corners = np.vstack([square, tri])
    start = np.array([0, 4, 7])
    nxt = np.array([1, 2, 3, 0, 5, 6, 4])
    got = newell_vectors(corners, start, nxt)
    assert np.allclose(got, [[0, 0, 4.0], [-3.0, 0, 0]])
    far = newell_vectors(corners + 1e6, start, nxt)
    assert np.allclose(far, got, atol=1e-9)
    assert newell_vectors(np.zeros((0, 3)), np.array([0]), np.zeros(0, dtype=int)).shape == (0, 3)
