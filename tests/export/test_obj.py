"""The OBJ writer (:mod:`filletfold.export.obj`) on small hand-made crease patterns."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.spatial import cKDTree

from filletfold.export import (
    folded_obj,
)

from ..conftest import strip_pattern, two_pieces

SVG_NS = "{http://www.w3.org/2000/svg}"
ATOL = 1e-9


# ---------------------------------------------------------------- OBJ


def parse_obj(text: str):
    """Tiny OBJ reader: vertices, normals, and faces (0-based) per group."""
    v, vn, groups, current = [], [], {}, None
    for line in text.splitlines():
        parts = line.split()
        if not parts or parts[0].startswith("#"):
            continue
        if parts[0] == "v":
            v.append([float(x) for x in parts[1:]])
        elif parts[0] == "vn":
            vn.append([float(x) for x in parts[1:]])
        elif parts[0] == "g":
            current = parts[1]
            groups.setdefault(current, [])
        elif parts[0] == "f":
            groups[current].append([int(t.split("/")[0]) - 1 for t in parts[1:]])
        else:
            raise AssertionError(f"unexpected OBJ line {line!r}")
    return np.array(v), np.array(vn), groups


@pytest.mark.parametrize("normals", [False, True])
def test_obj_round_trip(pattern, normals):
    """Each pattern face is an OBJ face on the same folded points, in its patch's group; the
    points the pattern's vertices fold onto are written once each (the seams closed)."""
    v, vn, groups = parse_obj(folded_obj(pattern, vertex_normals=normals))
    v3 = pattern.vertices_3d
    size = np.linalg.norm(np.ptp(v3, axis=0))
    expected = {}
    for f, patch in zip(pattern.faces, pattern.face_patch, strict=True):
        expected.setdefault(patch.replace(" ", "_"), []).append(list(f))
    assert {g: len(fs) for g, fs in groups.items()} == {g: len(fs) for g, fs in expected.items()}
    for g, fs in expected.items():
        for got, want in zip(groups[g], fs, strict=True):
            assert_allclose(v[got], v3[want], atol=2e-9 * size)
    # no two OBJ vertices on one point: the pattern's coincident vertices are one
    if len(v) > 1:
        d, _ = cKDTree(v).query(v, k=2)
        assert d[:, 1].min() > 1e-9 * size
    if normals:
        assert vn.shape == v.shape
        assert_allclose(np.linalg.norm(vn, axis=1), 1.0, atol=1e-10)
    else:
        assert len(vn) == 0


def test_obj_groups_and_normals_two_pieces():
    text = folded_obj(two_pieces(), vertex_normals=True)
    assert [ln for ln in text.splitlines() if ln.startswith("g ")] == [
        "g cone_3",
        "g face_2",
        "g cone_9",
        "g face_5",
    ]
    assert "f 1//1 2//2 3//3" in text
    _, vn, _ = parse_obj(text)
    # vertex 1 lies only in the flat face [0, 1, 2] (normal +z)
    assert_allclose(vn[1], [0.0, 0.0, 1.0], atol=1e-12)


def test_obj_welds_the_seams_of_two_pieces():
    """Two pieces glued along a seam: the seam's pattern vertices (two per point) are one OBJ
    vertex each, and the two faces share them."""
    from filletfold.surface.pattern import CreasePattern

    v2 = np.array([[0, 0], [1, 0], [0, 1], [2, 0], [3, 0], [2, 1]], dtype=float)
    v3 = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.5]])
    p = CreasePattern(v2, v3, [[0, 1, 2], [3, 4, 5]], ["face 0", "face 1"], [0, 1], [0, 1])
    text = folded_obj(p)
    v, _, groups = parse_obj(text)
    assert len(v) == 4 and "# 4 vertices, 2 faces, 2 patches" in text
    assert groups == {"face_0": [[0, 1, 2]], "face_1": [[1, 2, 3]]}
    assert "v 1 1 0.5\n" in text  # numbers without trailing zeros


def test_obj_polygons_kept():
    _, _, groups = parse_obj(folded_obj(strip_pattern()))
    assert all(len(f) == 4 for fs in groups.values() for f in fs)


def test_obj_deterministic():
    assert folded_obj(two_pieces(), vertex_normals=True) == folded_obj(
        two_pieces(), vertex_normals=True
    )
