"""The FOLD writer (:mod:`filletfold.export.fold`) on small hand-made crease patterns."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from filletfold.errors import ExportError, ParameterError
from filletfold.export import (
    fold_document,
    fold_json,
    pattern_svg,
)
from filletfold.surface.pattern import CreasePattern

from ..conftest import signed_area, square_pattern, strip_pattern, two_pieces

SVG_NS = "{http://www.w3.org/2000/svg}"
ATOL = 1e-9


# ---------------------------------------------------------------- FOLD


def test_fold_keys_and_types(pattern):
    doc = json.loads(fold_json(fold_document(pattern, title="t", description="d")))
    assert doc["file_spec"] == pytest.approx(1.2)
    assert doc["file_creator"].startswith("filletfold")
    assert (doc["file_title"], doc["file_description"]) == ("t", "d")
    assert doc["file_classes"] == ["singleModel"]
    assert doc["frame_classes"] == ["creasePattern"]
    assert doc["frame_attributes"] == ["2D"]
    assert doc["frame_unit"] == "unit"
    n, m, nf = len(pattern.vertices_2d), len(pattern.edges), len(pattern.faces)
    assert len(doc["vertices_coords"]) == n
    assert all(len(c) == 2 and all(isinstance(x, float) for x in c) for c in doc["vertices_coords"])
    assert len(doc["edges_vertices"]) == m
    assert all(len(e) == 2 and all(type(i) is int for i in e) for e in doc["edges_vertices"])
    assert len(doc["edges_assignment"]) == len(doc["edges_foldAngle"]) == m
    assert set(doc["edges_assignment"]) <= {"M", "V", "B", "F"}
    assert len(doc["faces_vertices"]) == nf
    assert doc["filletfold:faces_patch"] == list(pattern.face_patch)
    assert doc["filletfold:faces_piece"] == pattern.face_piece.tolist()
    # every key without a namespace is a FOLD key
    for key in doc:
        assert ":" in key or key.split("_")[0] in {"file", "frame", "vertices", "edges", "faces"}
    assert len(doc["file_frames"]) == 1
    frame = doc["file_frames"][0]
    assert list(frame) == [
        "frame_classes",
        "frame_parent",
        "frame_inherit",
        "frame_attributes",
        "vertices_coords",
    ]
    assert frame["frame_classes"] == ["foldedForm"]
    assert frame["frame_parent"] == 0 and frame["frame_inherit"] is True
    assert frame["frame_attributes"] == ["3D"]
    assert len(frame["vertices_coords"]) == n
    assert all(len(c) == 3 for c in frame["vertices_coords"])


def test_fold_round_trip_values(pattern):
    doc = json.loads(fold_json(fold_document(pattern)))
    assert_allclose(doc["vertices_coords"], pattern.vertices_2d, atol=ATOL)
    assert_allclose(doc["file_frames"][0]["vertices_coords"], pattern.vertices_3d, atol=ATOL)
    assert doc["edges_vertices"] == pattern.edges.tolist()
    assert doc["edges_assignment"] == pattern.edge_assignment.tolist()
    crease = np.isin(pattern.edge_assignment, ["M", "V"])
    angle = np.array([np.nan if a is None else a for a in doc["edges_foldAngle"]])
    assert_allclose(angle[crease], pattern.edge_fold_angle[crease], atol=ATOL)
    assert np.isnan(angle[pattern.edge_assignment == "B"]).all()
    assert doc["faces_vertices"] == [list(f) for f in pattern.faces]


def test_fold_faces_ccw(pattern):
    doc = json.loads(fold_json(fold_document(pattern)))
    xy = np.array(doc["vertices_coords"])
    for f in doc["faces_vertices"]:
        assert signed_area(xy[f]) > 0


def test_fold_assignment_matches_angle_sign(pattern):
    doc = json.loads(fold_json(fold_document(pattern)))
    for a, angle in zip(doc["edges_assignment"], doc["edges_foldAngle"], strict=True):
        if a == "B":
            assert angle is None
            continue
        assert -180.0 <= angle <= 180.0
        if a == "V":
            assert angle > 0
        elif a == "M":
            assert angle < 0


def _frame_dihedral(doc: dict, edge: int) -> float:
    """The fold angle (valley positive) of ``edge`` measured in the folded frame of a FOLD
    document: the signed angle between its two faces' normals, from the frame alone."""
    v3 = np.array(doc["file_frames"][0]["vertices_coords"])
    a, b = doc["edges_vertices"][edge]
    sides = []
    for f in doc["faces_vertices"]:
        k = len(f)
        for i in range(k):
            if {f[i], f[(i + 1) % k]} == {a, b}:
                p = v3[f]
                n = np.sum(np.cross(p - p.mean(0), np.roll(p, -1, 0) - p.mean(0)), axis=0)
                sides.append((f[i] == a, n / np.linalg.norm(n)))
    assert len(sides) == 2
    (_, n1), (_, n2) = sorted(sides, key=lambda s: not s[0])
    d = (v3[b] - v3[a]) / np.linalg.norm(v3[b] - v3[a])
    return -np.degrees(np.arctan2(np.cross(n1, n2) @ d, n1 @ n2))


def test_fold_facet_angles_are_the_folded_dihedrals():
    """F edges inside the cylinders and cones carry the folded form's dihedral (not 0), M/V
    edges their crease angle, on a real design."""
    from ..conftest import design_of

    p = design_of("tetrahedron", samples=6).pattern
    doc = json.loads(fold_json(fold_document(p)))
    inner = [e for e, a in enumerate(doc["edges_assignment"]) if a != "B"]
    measured = np.array([_frame_dihedral(doc, e) for e in inner])
    written = np.array([doc["edges_foldAngle"][e] for e in inner])
    assert_allclose(written, measured, atol=1e-7)
    flat = np.array([doc["edges_assignment"][e] == "F" for e in inner])
    assert flat.any() and (np.abs(written[flat]) > 1e-3).any()


@pytest.mark.parametrize(("angle", "assignment"), [(90.0, "V"), (-90.0, "M")])
def test_fold_square_diagonal(angle, assignment):
    doc = fold_document(square_pattern(angle))
    e = doc["edges_vertices"].index([0, 2])
    assert doc["edges_assignment"][e] == assignment
    assert doc["edges_foldAngle"][e] == pytest.approx(angle, abs=1e-9)
    others = [a for i, a in enumerate(doc["edges_assignment"]) if i != e]
    assert others == ["B"] * 4


def test_fold_strip_flat_and_mountain():
    p = strip_pattern()
    doc = fold_document(p)
    by_edge = dict(zip(map(tuple, doc["edges_vertices"]), doc["edges_assignment"], strict=True))
    angle = dict(zip(map(tuple, doc["edges_vertices"]), doc["edges_foldAngle"], strict=True))
    assert by_edge[(1, 6)] == "F"
    assert by_edge[(2, 5)] == "M"
    assert angle[(2, 5)] == pytest.approx(-30.0, abs=1e-9)
    assert sum(a == "B" for a in doc["edges_assignment"]) == 8


def test_fold_cylinder_face_join_is_flat():
    s = strip_pattern()
    p = CreasePattern(
        s.vertices_2d, s.vertices_3d, s.faces, ["cylinder 4", "face 1", "face 2"], [0, 0, 0], [0]
    )
    doc = fold_document(p)
    by_edge = dict(zip(map(tuple, doc["edges_vertices"]), doc["edges_assignment"], strict=True))
    assert (by_edge[(1, 6)], by_edge[(2, 5)]) == ("F", "M")
    root = ET.fromstring(pattern_svg(p))
    groups = {g.get("id"): g.findall(f"{SVG_NS}line") for g in root.iter(SVG_NS + "g")}
    # the join is a facet line (drawn for Origami Simulator), not a crease
    assert len(groups["flat"]) == 1 and len(groups["mountain"]) == 1
    assert not groups["valley"]
    (join,) = groups["flat"]
    assert join.get("x1") == join.get("x2") != groups["mountain"][0].get("x1")
    assert len(root.findall(f".//{SVG_NS}line")) == 10


def test_fold_two_pieces():
    doc = fold_document(two_pieces())
    assert doc["filletfold:faces_piece"] == [0, 0, 1, 1]
    assert sorted(doc["edges_assignment"]).count("B") == 8
    assert {"M", "V"} <= set(doc["edges_assignment"])


@settings(max_examples=40, deadline=None)
@given(st.floats(min_value=1.0, max_value=179.0), st.sampled_from([1.0, -1.0]))
def test_fold_angle_sign_property(magnitude, sign):
    doc = fold_document(square_pattern(sign * magnitude))
    e = doc["edges_vertices"].index([0, 2])
    assert doc["edges_assignment"][e] == ("V" if sign > 0 else "M")
    assert doc["edges_foldAngle"][e] == pytest.approx(sign * magnitude, abs=1e-7)


def test_fold_extra_keys_merged():
    doc = fold_document(square_pattern(90.0), extra={"filletfold:radius": np.float64(0.25)})
    assert list(doc)[-1] == "filletfold:radius"
    assert json.loads(fold_json(doc))["filletfold:radius"] == pytest.approx(0.25)


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        ({"radius": 1.0}, "namespaced"),
        ({"tm:radius": 1.0}, "namespaced"),
        ({"filletfold:": 1.0}, "namespaced"),
        ({"filletfold:faces_patch": []}, "clashes"),
    ],
)
def test_fold_extra_keys_rejected(extra, match):
    with pytest.raises(ParameterError, match=match):
        fold_document(square_pattern(90.0), extra=extra)


def test_fold_title_must_be_string():
    with pytest.raises(ParameterError, match="title must be a string"):
        fold_document(square_pattern(90.0), title=3)


def test_fold_json_rounds_and_is_deterministic():
    doc = {"a": [0.1 + 0.2, -0.0, 1 / 3], "b": np.arange(3), "c": {"d": np.float32(0.5)}}
    text = fold_json(doc)
    assert text.endswith("\n")
    assert json.loads(text) == {"a": [0.3, 0.0, 0.333333333333], "b": [0, 1, 2], "c": {"d": 0.5}}
    assert "-0" not in text
    assert text == fold_json(doc)


def test_fold_json_same_pattern_same_bytes():
    a = fold_json(fold_document(two_pieces(), title="x"))
    b = fold_json(fold_document(two_pieces(), title="x"))
    assert a == b


@pytest.mark.parametrize(
    ("doc", "match"),
    [
        ({"a": [1.0, float("nan")]}, r"a\[1\] is not finite"),
        ({"a": float("inf")}, "not finite"),
        ({"a": object()}, "unsupported type"),
        ({1: 2}, "keys must be strings"),
        ([1, 2], "must be a mapping"),
    ],
)
def test_fold_json_rejects(doc, match):
    with pytest.raises(ExportError, match=match):
        fold_json(doc)
