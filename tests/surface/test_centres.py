"""Face piece centres (:mod:`filletfold.surface.centres`): on the face's plane, inside the face,
and beyond the tangent line of every rounded edge (the straight creases stay short of them)."""

from __future__ import annotations

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
