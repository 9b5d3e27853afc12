"""Face piece centres (:mod:`filletfold.surface.centres`): on the face's plane, inside the face,
and beyond the tangent line of every rounded edge (the straight creases stay short of them)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import filletfold
from filletfold.rounding.edges import round_edges
from filletfold.surface.centres import face_piece_centres


@pytest.mark.parametrize(
    ("name", "radius"), [("cube", 0.1), ("icosahedron", 0.15), ("l-prism", 0.05), ("house", 0.1)]
)
def test_centres_lie_in_their_face_pieces(name, radius):
    m = filletfold.load_mesh(name)[0]
    rounding = round_edges(m, radius * m.mean_edge_length)
    c = face_piece_centres(m, rounding)
    assert c.shape == (m.n_faces, 3) and np.isfinite(c).all()
    offset = 0.5 * rounding.strip_width  # the tangent line's distance from the edge, per face
    for f, face in enumerate(m.faces):
        p = m.vertices[face]
        n = m.face_normal[f]
        assert abs((c[f] - p[0]) @ n) <= 1e-12 * m.mean_edge_length  # on the plane
        for k in range(len(face)):
            a, b = p[k], p[(k + 1) % len(face)]
            inward = np.cross(n, b - a)
            inward /= np.linalg.norm(inward)
            e = m.halfedge_edge[m.halfedge(int(face[k]), int(face[(k + 1) % len(face)]))]
            # inside the face, and beyond the edge's tangent line (strictly: the piece is open)
            assert (c[f] - a) @ inward > offset[e] - 1e-12 * m.mean_edge_length


def test_a_centre_lies_beyond_the_conical_fillets_of_a_sharp_vertex():
    """A thin triangle (a 165 degree corner at vertex 2) beside a sharp vertex 0, as in fuzz
    case hull-33/dup-vertex+bumps#4598: the fillet of edge (0, 2) tapers from vertex 0 and
    reaches twice a cylinder's width into the face at vertex 2. The centre taken for cylinders
    lies beyond that line there (vertex 2's share of the face crossed itself); with the sharp
    vertex given it lies inside the piece the conical lines leave."""
    v = np.array([[0.0, 0.0, 0.0], [2.44, 0.0, 0.0], [1.22, 0.156, 0.0], [1.22, 0.0, -1.0]])
    faces = [[0, 1, 2], [1, 0, 3], [0, 2, 3], [2, 1, 3]]
    m = filletfold.PolyMesh(v, faces)
    rounding = round_edges(m, 1e-3 * np.ones(m.n_edges))
    # the strips of the fuzz case: wide on the short edges, narrow on the long one
    half = np.full(m.n_edges, 0.058)
    half[m.halfedge_edge[m.halfedge(0, 1)]] = 0.012
    rounding = dataclasses.replace(rounding, strip_width=2 * half)
    sharp = np.array([True, False, False, False])

    def inside(c):  # distance inside the conical line of edge (0, 2) on face 0
        e = m.halfedge_edge[m.halfedge(2, 0)]
        inward = np.cross([0.0, 0.0, 1.0], v[0] - v[2])  # face 0 lies left of 2 -> 0
        inward /= np.linalg.norm(inward)
        line = 0.5 * (v[0] + v[2]) + half[e] * inward - v[0]  # from the sharp vertex 0
        normal = np.cross([0.0, 0.0, 1.0], -line)  # left of the line run as 2 -> 0
        return (c - v[0]) @ (normal / np.linalg.norm(normal))

    plain = face_piece_centres(m, rounding)
    coned = face_piece_centres(m, rounding, sharp)
    assert inside(plain[0]) < 0  # the cylinders' centre: beyond the fillet
    assert inside(coned[0]) > 0
    assert np.isfinite(coned).all()


def test_a_face_the_conical_lines_leave_without_a_centre_keeps_the_tangent_lines_one():
    """Where the conical fillets' lines leave no point that sees the whole face piece (here
    the fillet of edge (0, 2) wider than the thin face at its wide end), the centre is the
    tangent lines' one, as before the sharp vertices were known, not an error (suzanne.obj
    of the common 3D test models was refused so: 'face 347 is not star-shaped')."""
    v = np.array([[0.0, 0.0, 0.0], [2.44, 0.0, 0.0], [1.22, 0.156, 0.0], [1.22, 0.0, -1.0]])
    m = filletfold.PolyMesh(v, [[0, 1, 2], [1, 0, 3], [0, 2, 3], [2, 1, 3]])
    rounding = round_edges(m, 1e-3 * np.ones(m.n_edges))
    half = np.full(m.n_edges, 0.058)
    half[m.halfedge_edge[m.halfedge(0, 1)]] = 0.012
    half[m.halfedge_edge[m.halfedge(0, 2)]] = 0.08
    rounding = dataclasses.replace(rounding, strip_width=2 * half)
    plain = face_piece_centres(m, rounding)
    coned = face_piece_centres(m, rounding, np.array([True, False, False, False]))
    np.testing.assert_array_equal(coned[0], plain[0])
