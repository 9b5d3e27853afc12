"""Vertex normals of rings padded by valence group (issue 30: one vertex of 10,000 edges padded
every ring of the mesh to 10,000, 2.2 GB)."""

from __future__ import annotations

import numpy as np

import filletfold
from tests.test_limits import _bipyramid


def test_the_vertex_normals_of_rings_of_mixed_valence_do_not_depend_on_the_padding():
    """Rings are padded to the longest of their valence group, not of the mesh: the normals
    are those of each ring on its own."""
    from filletfold.vertex.normal import vertex_normals

    d = filletfold.round_mesh(_bipyramid(40), certify=False, max_corners=64)
    for u in (0, 40, 41):  # a valence-4 vertex and the two tips of 40 edges
        frame = d.stages.frames[u]
        R, faces = frame.arrays.R, frame.ring.faces
        mesh = d.mesh
        alone = vertex_normals(R[None], mesh.face_normal[faces][None])
        np.testing.assert_array_equal(d.vertices.normal[u], alone[0][0])
