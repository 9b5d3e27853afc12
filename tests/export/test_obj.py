"""The OBJ writer (:mod:`filletfold.export.obj`) on small hand-made crease patterns."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

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
    v, vn, groups = parse_obj(folded_obj(pattern, vertex_normals=normals))
    assert_allclose(v, pattern.vertices_3d, atol=1e-10)
    expected = {}
    for f, patch in zip(pattern.faces, pattern.face_patch, strict=True):
        expected.setdefault(patch.replace(" ", "_"), []).append(list(f))
    assert groups == expected
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


def test_obj_polygons_kept():
    _, _, groups = parse_obj(folded_obj(strip_pattern()))
    assert all(len(f) == 4 for fs in groups.values() for f in fs)


def test_obj_deterministic():
    assert folded_obj(two_pieces(), vertex_normals=True) == folded_obj(
        two_pieces(), vertex_normals=True
    )
