"""Reading a design back from its FOLD file (:mod:`filletfold.export.fold_read`): the pattern
the writer wrote, to the file's 12 digits, and one-line errors on what is not such a file."""

from __future__ import annotations

import json

import numpy as np
import pytest

from filletfold.errors import MeshReadError
from filletfold.export import fold_document, fold_json, read_fold
from filletfold.export.fold_read import pattern_from_fold

from ..conftest import design_of


@pytest.mark.parametrize("name", ["cube", "torus", "miura"])
def test_read_fold_gives_back_the_written_pattern(name, tmp_path):
    p = design_of(name).pattern
    path = tmp_path / "design.fold"
    path.write_text(fold_json(fold_document(p)))
    q = read_fold(path)
    size = np.abs(p.vertices_3d).max() + np.abs(p.vertices_2d).max()
    np.testing.assert_allclose(q.vertices_2d, p.vertices_2d, rtol=0, atol=1e-11 * size)
    np.testing.assert_allclose(q.vertices_3d, p.vertices_3d, rtol=0, atol=1e-11 * size)
    assert [f.tolist() for f in q.faces] == [np.asarray(f).tolist() for f in p.faces]
    assert q.face_patch == list(p.face_patch)
    np.testing.assert_array_equal(q.face_piece, p.face_piece)
    np.testing.assert_array_equal(q.piece_vertex, p.piece_vertex)
    np.testing.assert_array_equal(q.edges, p.edges)
    np.testing.assert_array_equal(q.edge_assignment, p.edge_assignment)
    np.testing.assert_allclose(q.edge_fold_angle, p.edge_fold_angle, rtol=1e-11, atol=1e-9)
    np.testing.assert_array_equal(q.edge_faces, p.edge_faces)


def test_what_is_not_a_design_is_refused_in_one_line(tmp_path):
    doc = json.loads(fold_json(fold_document(design_of("cube").pattern)))
    broken = dict(doc)
    del broken["faces_vertices"]
    with pytest.raises(MeshReadError) as e:
        pattern_from_fold(broken)
    assert "\n" not in str(e.value)
    bad = dict(doc, faces_vertices=[[0, 1, 10**9], *doc["faces_vertices"][1:]])
    with pytest.raises(MeshReadError, match="not a valid filletfold design"):
        pattern_from_fold(bad)
    path = tmp_path / "x.fold"
    path.write_text("{ not json")
    with pytest.raises(MeshReadError) as e:
        read_fold(path)
    assert "\n" not in str(e.value)
