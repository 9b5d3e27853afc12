"""The FOLD writer (:mod:`filletfold.export.fold`) on small hand-made crease patterns."""

from __future__ import annotations

import itertools
import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from filletfold.errors import ExportError, ParameterError
from filletfold.export import (
    cut_files,
    fold_document,
    fold_json,
    pattern_svg,
)
from filletfold.surface.pattern import Annotations, CreasePattern, Label

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
    assert doc["filletfold:faces_patch"] == list(map(str, pattern.face_patch))
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


def _frame_dihedrals(doc: dict, edges) -> np.ndarray:
    """The fold angles (valley positive) of ``edges`` measured in the folded frame of a FOLD
    document: the signed angle between each edge's two faces' normals, from the frame alone."""
    v3 = np.array(doc["file_frames"][0]["vertices_coords"])
    sides = {}  # (a, b) with a < b -> [(the face runs a -> b, its unit normal)]
    for f in doc["faces_vertices"]:
        p = v3[f]
        n = np.sum(np.cross(p - p.mean(0), np.roll(p, -1, 0) - p.mean(0)), axis=0)
        for i in range(len(f)):
            a, b = f[i], f[(i + 1) % len(f)]
            sides.setdefault((min(a, b), max(a, b)), []).append((a < b, n / np.linalg.norm(n)))
    out = []
    for edge in edges:
        a, b = doc["edges_vertices"][edge]
        found = sides[(min(a, b), max(a, b))]
        assert len(found) == 2
        # the face that runs a -> b first
        (_, n1), (_, n2) = sorted(found, key=lambda s: s[0] != (a < b))
        d = (v3[b] - v3[a]) / np.linalg.norm(v3[b] - v3[a])
        out.append(-np.degrees(np.arctan2(np.cross(n1, n2) @ d, n1 @ n2)))
    return np.array(out)


def test_fold_facet_angles_are_the_folded_dihedrals():
    """F edges inside the cylinders and cones carry the folded form's dihedral (not 0), M/V
    edges their crease angle, on a real design."""
    from ..conftest import design_of

    p = design_of("tetrahedron", samples=6).pattern
    doc = json.loads(fold_json(fold_document(p)))
    inner = [e for e, a in enumerate(doc["edges_assignment"]) if a != "B"]
    measured = _frame_dihedrals(doc, inner)
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
    root = ET.fromstring(pattern_svg(p, preset="origami-simulator"))
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


def test_fold_json_chunks_are_its_text_a_key_at_a_time():
    """The text (as written before it came in chunks, pinned here) is the chunks joined: the
    opening brace, then one chunk per top-level key, each value converted only when its key's
    turn comes (a bad value raises after the keys before it have been written)."""
    from filletfold.export import fold_json_chunks

    doc = {
        "file_spec": 1.2,
        "a": [0.5, -0.0],
        "frames": [{"k": 1, "v": np.array([[1.0, 2.0]])}, {"k": 2}],
        "m": {"x": {"y": []}},
        "e": {},
        "s": "t",
    }
    expected = (
        '{\n  "file_spec": 1.2,\n  "a": [0.5,0.0],\n  "frames": [\n    {\n      "k": 1,\n'
        '      "v": [[1.0,2.0]]\n    },\n    {\n      "k": 2\n    }\n  ],\n  "m": {\n'
        '    "x": {\n      "y": []\n    }\n  },\n  "e": {},\n  "s": "t"\n}\n'
    )
    chunks = list(fold_json_chunks(doc))
    assert "".join(chunks) == fold_json(doc) == expected
    assert len(chunks) == 1 + len(doc) and chunks[0] == "{\n"
    entries = [c[:-2] if c.endswith(",\n") else c.removesuffix("\n}\n") for c in chunks[1:]]
    assert [json.loads("{" + c + "}") for c in entries] == [
        {k: v} for k, v in json.loads(expected).items()
    ]
    assert fold_json({}) == "".join(fold_json_chunks({})) == "{}\n"
    lazy = fold_json_chunks({"a": 1.0, "b": [float("nan")], "c": 2.0})
    assert next(lazy) == "{\n" and next(lazy) == '  "a": 1.0,\n'
    with pytest.raises(ExportError, match=r"b\[0\] is not finite"):
        next(lazy)


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


def test_fold_facet_angles_are_written_on_a_nanodegree_grid():
    """F edges' dihedrals keep 9 decimals (degrees): within 5e-10 of the folded form's, no more
    digits; M and V angles keep their 12 significant digits."""
    from filletfold.export.fold import _round
    from filletfold.surface.pattern import edge_dihedrals

    from ..conftest import design_of

    p = design_of("tetrahedron", samples=6).pattern
    doc = json.loads(fold_json(fold_document(p)))
    assign = np.array(doc["edges_assignment"])
    written = np.array([np.nan if a is None else a for a in doc["edges_foldAngle"]])
    facet, crease = assign == "F", np.isin(assign, ["M", "V"])
    exact = edge_dihedrals(p)[facet]
    assert np.abs(written[facet] - exact).max() <= 0.5e-9 * (1 + 1e-6)
    nano = written[facet] * 1e9
    assert np.abs(nano - np.rint(nano)).max() < 1e-3
    assert (np.abs(exact * 1e9 - np.rint(exact * 1e9)) > 1e-3).any()  # digits were dropped
    assert written[crease].tolist() == [_round(a) for a in p.edge_fold_angle[crease].tolist()]


# ---------------------------------------------------------------- annotations


def annotated_square(scale: float, n: int = 40, seed: int = 0) -> CreasePattern:
    """The diagonal square with ``n`` random glue tabs (each hinge two of its tab's points),
    ``n`` labels and a sheet, all lengths about ``scale``."""
    rng = np.random.default_rng(seed)
    p = square_pattern(90.0)
    tabs = [scale * rng.normal(size=(4, 2)) for _ in range(n)]
    labels = [
        Label(scale * rng.normal(size=2), str(i), float(rng.uniform(-180, 180)), 0.02 * scale, k)
        for i, k in zip(range(n), itertools.cycle(["tab", "part"]), strict=False)
    ]
    p.annotations = Annotations(
        tabs=tabs,
        tab_hinges=[t[[3, 2]].copy() for t in tabs],
        labels=labels,
        sheets=scale * np.array([[-5.0, -5.0, 5.0, 5.0]]),
    )
    return p


@pytest.mark.parametrize("scale", [1e-4, 0.03, 0.7, 1.0, 93.0, 4e4, 3e8])
def test_annotation_numbers_are_written_to_fold_digits(scale):
    """Tab, hinge, label and sheet numbers as FOLD writes every number (12 significant
    digits), so a tab's base stays on its piece's border; shared points stay equal; both
    writers agree, and annotations.json holds what the FOLD key would."""
    from filletfold.export.fold import _round, annotations_json

    p = annotated_square(scale)
    text = fold_json(fold_document(p))
    assert text == fold_json(fold_document(p))
    ann = json.loads(text)["filletfold:annotations"]

    def as_written(exact):
        exact = np.asarray(exact, dtype=float)
        return np.vectorize(_round)(exact).tolist()

    lab = ann["labels"]
    assert ann["tabs"] == [as_written(t) for t in p.annotations.tabs]
    # each hinge is two points of its tab's outline: written as their indices, once
    assert ann["tab_hinges"] == [[3, 2]] * len(p.annotations.tab_hinges)
    assert lab["position"] == [as_written(lb.position) for lb in p.annotations.labels]
    assert lab["angle"] == [_round(lb.angle) for lb in p.annotations.labels]
    assert lab["height"] == [_round(lb.height) for lb in p.annotations.labels]
    assert ann["sheets"] == as_written(p.annotations.sheets)
    for tab, hinge in zip(ann["tabs"], p.annotations.tab_hinges, strict=True):
        assert [tab[3], tab[2]] == as_written(hinge)  # the very numbers of its tab's points
    assert lab["text"] == [lb.text for lb in p.annotations.labels]
    assert lab["kind"] == [lb.kind for lb in p.annotations.labels]
    side = json.loads(annotations_json(p))
    assert side.pop("design") == {"vertices": 4, "faces": 2, "pieces": 1}
    assert side.pop("file_creator").startswith("filletfold")
    assert side == ann


def test_hinges_off_their_outline_are_written_as_points_and_read_back(tmp_path):
    """A hinge whose ends are two points of its tab's outline is written as their indices; one
    that is not (or has no tab) as its points; reading gives every hinge back bit for bit, and
    an index its tab does not have is a one-line error."""
    from filletfold.errors import MeshReadError
    from filletfold.export.fold import _round, annotations_json, hinge_refs
    from filletfold.export.fold_read import read_annotations

    p = annotated_square(0.7, n=3)
    ann = p.annotations
    off = np.array([[0.1, 0.2], [0.3, 0.4]])
    # tab 0: the usual hinge; tab 1: not on its outline; tab 2: another side; a 4th: no tab
    ann.tab_hinges = [ann.tabs[0][[3, 2]], off, ann.tabs[2][[0, 1]], off]
    refs = hinge_refs(np.concatenate(ann.tabs), np.array([4, 4, 4]), np.array(ann.tab_hinges))
    assert refs.tolist() == [[3, 2], [-1, -1], [0, 1], [-1, -1]]
    text = annotations_json(p)
    items = json.loads(text)["tab_hinges"]
    assert items[0] == [3, 2] and items[-1] == off.tolist()
    path = tmp_path / "annotations.json"
    path.write_text(text)
    back = read_annotations(path, p)
    assert len(back.tab_hinges) == len(ann.tab_hinges)
    for got, exact in zip(back.tab_hinges, ann.tab_hinges, strict=True):
        assert np.array_equal(got, np.vectorize(_round)(exact))  # as FOLD writes numbers
    doc = json.loads(text)
    doc["tab_hinges"][0] = [3, 9]
    path.write_text(json.dumps(doc))
    with pytest.raises(MeshReadError, match="tab hinge 0 names points"):
        read_annotations(path, p)


def test_design_fold_leaves_the_annotations_to_their_own_file():
    """What ``filletfold round`` writes: design.fold without ``filletfold:annotations``,
    annotations.json beside it with them (empty lists without tabs)."""
    p = annotated_square(2.0)
    files = cut_files(p, "fold")
    assert list(files) == ["design.fold", "annotations.json"]
    doc = json.loads(files["design.fold"])
    assert "filletfold:annotations" not in doc
    assert len(doc["vertices_coords"]) == 4
    side = json.loads(files["annotations.json"])
    assert len(side["tabs"]) == len(side["labels"]["text"]) == 40
    bare = cut_files(square_pattern(90.0), "fold")
    empty = json.loads(bare["annotations.json"])
    assert empty["tabs"] == [] and empty["labels"]["text"] == [] and empty["sheets"] == []
    assert "filletfold:annotations" not in json.loads(bare["design.fold"])


def test_annotation_labels_are_parallel_lists_on_a_few_lines():
    """The labels are one list per field (no key repeated per label), and the file has as many
    lines with 400 tabs and labels as with 4: arrays are written on one line each."""
    few, many = annotated_square(1.0, n=4), annotated_square(1.0, n=400)
    texts = [fold_json(fold_document(p)) for p in (few, many)]
    assert texts[0].count("\n") == texts[1].count("\n") < 60
    labels = json.loads(texts[1])["filletfold:annotations"]["labels"]
    assert list(labels) == ["position", "text", "angle", "height", "kind"]
    assert all(len(v) == 400 for v in labels.values())
    assert texts[1].count('"position"') == 1


def test_annotated_fold_is_deterministic():
    a = fold_json(fold_document(annotated_square(93.0, seed=4)))
    b = fold_json(fold_document(annotated_square(93.0, seed=4)))
    assert a == b
