"""Exporters on small hand-made crease patterns: FOLD, SVG, OBJ, report JSON."""

from __future__ import annotations

import dataclasses
import json
import math
import re
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
    folded_obj,
    pattern_svg,
    report_json,
    validate_pattern,
)
from filletfold.export.svg import nice_length
from filletfold.surface.pattern import CreasePattern

SVG_NS = "{http://www.w3.org/2000/svg}"
ATOL = 1e-9


# ---------------------------------------------------------------- patterns


def _rotate(p, c, d, theta):
    """Rotate points ``p`` (k, 3) about the axis through ``c`` along unit ``d`` by ``theta``."""
    r = np.asarray(p, dtype=float) - c
    return (
        c
        + r * math.cos(theta)
        + np.cross(d, r) * math.sin(theta)
        + np.outer(r @ d, d) * (1 - math.cos(theta))
    )


def diagonal_square(angle_deg: float, size: float = 1.0, offset=(0.0, 0.0)) -> dict:
    """A square folded along its diagonal 0-2; ``angle_deg > 0`` lifts vertex 3 to +z (valley)."""
    v2 = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float) * size + offset
    v3 = np.c_[v2, np.zeros(4)]
    d = np.array([1.0, 1.0, 0.0]) / math.sqrt(2)
    v3[3] = _rotate(v3[3:4], v3[0], d, math.radians(angle_deg))[0]
    return {"v2": v2, "v3": v3, "faces": [[0, 1, 2], [0, 2, 3]]}


def square_pattern(angle_deg: float) -> CreasePattern:
    s = diagonal_square(angle_deg)
    return CreasePattern(s["v2"], s["v3"], s["faces"], ["cone 7", "face 1"], [0, 0], [7])


def two_pieces() -> CreasePattern:
    """A valley square (piece 0) and a mountain square (piece 1), apart in 2D and 3D."""
    a, b = diagonal_square(60.0), diagonal_square(-45.0, size=2.0, offset=(3.0, 0.5))
    v2 = np.vstack([a["v2"], b["v2"]])
    v3 = np.vstack([a["v3"], b["v3"] + [0.0, 0.0, 5.0]])
    faces = a["faces"] + [[i + 4 for i in f] for f in b["faces"]]
    patches = ["cone 3", "face 2", "cone 9", "face 5"]
    return CreasePattern(v2, v3, faces, patches, [0, 0, 1, 1], [3, 9])


def strip_pattern() -> CreasePattern:
    """Three quads in a row: a flat join (F), then a 30 degree mountain; B border around."""
    v2 = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [3, 1], [2, 1], [1, 1], [0, 1]], dtype=float)
    v3 = np.c_[v2, np.zeros(8)]
    # fold the last quad down (away from the +z front) about x = 2: a mountain
    t = math.radians(30.0)
    for i in (3, 4):
        dx = v2[i, 0] - 2.0
        v3[i] = [2.0 + dx * math.cos(t), v2[i, 1], -dx * math.sin(t)]
    faces = [[0, 1, 6, 7], [1, 2, 5, 6], [2, 3, 4, 5]]
    return CreasePattern(v2, v3, faces, ["face 0", "face 0", "cone 1"], [0, 0, 0], [0])


PATTERNS = {
    "valley": lambda: square_pattern(90.0),
    "mountain": lambda: square_pattern(-90.0),
    "two_pieces": two_pieces,
    "strip": strip_pattern,
}


@pytest.fixture(params=sorted(PATTERNS))
def pattern(request) -> CreasePattern:
    return PATTERNS[request.param]()


def signed_area(p: np.ndarray) -> float:
    q = np.roll(p, -1, axis=0)
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


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
    assert_allclose(doc["edges_foldAngle"], pattern.edge_fold_angle, atol=ATOL)
    assert doc["faces_vertices"] == [list(f) for f in pattern.faces]


def test_fold_faces_ccw(pattern):
    doc = json.loads(fold_json(fold_document(pattern)))
    xy = np.array(doc["vertices_coords"])
    for f in doc["faces_vertices"]:
        assert signed_area(xy[f]) > 0


def test_fold_assignment_matches_angle_sign(pattern):
    doc = json.loads(fold_json(fold_document(pattern)))
    for a, angle in zip(doc["edges_assignment"], doc["edges_foldAngle"], strict=True):
        assert -180.0 <= angle <= 180.0
        if a == "V":
            assert angle > 0
        elif a == "M":
            assert angle < 0
        else:
            assert angle == pytest.approx(0.0, abs=ATOL)


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
    assert all(g.get("id") != "flat" for g in root.iter(SVG_NS + "g"))
    assert len(root.findall(f".//{SVG_NS}line")) == 9


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


# ---------------------------------------------------------------- validation


def _tampered(**changes) -> CreasePattern:
    p = square_pattern(90.0)
    for k, v in changes.items():
        setattr(p, k, v)
    return p


@pytest.mark.parametrize(
    ("pattern_factory", "match"),
    [
        (lambda: _tampered(face_patch=["face 0"]), "face_patch"),
        (lambda: _tampered(face_piece=np.array([0])), "face_piece"),
        (lambda: _tampered(vertices_3d=np.zeros((3, 3))), "4 vertices in 2D but 3 in 3D"),
        (
            lambda: _tampered(vertices_2d=np.array([[0, 0], [1, 0], [np.nan, 1], [0, 1.0]])),
            r"vertices_2d\[2\] is not finite",
        ),
        (lambda: _tampered(faces=[[0, 1, 2], [0, 2, 9]]), "face 1 refers to a vertex"),
        (lambda: _tampered(faces=[[0, 1, 2], [0, 2]]), "at least 3"),
        (
            lambda: _tampered(edge_fold_angle=np.array([0, -90.0, 0, 0, 0])),
            "edge 1 is 'V' but its fold angle is -90",
        ),
        (
            lambda: _tampered(edge_assignment=np.array(["B", "U", "B", "B", "B"])),
            "edge 1 has assignment 'U'",
        ),
        (lambda: _tampered(edge_fold_angle=np.zeros(4)), "edge arrays disagree"),
        (
            lambda: CreasePattern(
                [[0, 0], [1, 0], [0, 1]],
                [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                [[0, 2, 1]],
                ["face 0"],
                [0],
                [0],
            ),
            "face 0 is clockwise",
        ),
        (lambda: "not a pattern", "expected a CreasePattern"),
    ],
)
def test_validate_pattern_fires(pattern_factory, match):
    p = pattern_factory()
    with pytest.raises(ExportError, match=match):
        validate_pattern(p)
    for export in (fold_document, pattern_svg, folded_obj):
        with pytest.raises(ExportError, match=match):
            export(p)


# ---------------------------------------------------------------- SVG


def _svg(pattern, **kw):
    return ET.fromstring(pattern_svg(pattern, **kw))


def _group(root, gid):
    groups = [g for g in root.iter(SVG_NS + "g") if g.get("id") == gid]
    assert len(groups) == 1, gid
    return groups[0]


def _lines(group):
    return group.findall(SVG_NS + "line")


@pytest.mark.parametrize(
    ("name", "counts"),
    [
        ("valley", {"mountain": 0, "valley": 1, "border": 4}),
        ("mountain", {"mountain": 1, "valley": 0, "border": 4}),
        ("two_pieces", {"mountain": 1, "valley": 1, "border": 8}),
        ("strip", {"mountain": 1, "valley": 0, "border": 8}),
    ],
)
def test_svg_groups_and_colours(name, counts):
    root = _svg(PATTERNS[name]())
    colour = {"mountain": "#ff0000", "valley": "#0000ff", "border": "#000000"}
    for gid, n in counts.items():
        lines = _lines(_group(root, gid))
        assert len(lines) == n
        assert all(ln.get("stroke") == colour[gid] for ln in lines)
    assert not [g for g in root.iter(SVG_NS + "g") if g.get("id") == "flat"]


def test_svg_flat_edges_optional():
    root = _svg(strip_pattern(), flat_edges=True)
    flat = _lines(_group(root, "flat"))
    assert len(flat) == 1 and flat[0].get("stroke") == "#dddddd"


def test_svg_not_mirrored_and_inside_viewbox(pattern):
    root = _svg(pattern)
    x0, y0, w, h = map(float, root.get("viewBox").split())
    assert (x0, y0) == (0.0, 0.0)
    pts = {}
    ids = {"mountain", "valley", "border"}
    for g in root.iter(SVG_NS + "g"):
        if g.get("id") not in ids:
            continue
        for ln in _lines(g):
            for k in ("1", "2"):
                x, y = float(ln.get("x" + k)), float(ln.get("y" + k))
                assert 0 < x < w and 0 < y < h
                pts[(x, y)] = True
    # map pattern vertices to drawing coordinates through the border lines: the drawing is a
    # translation plus a y flip, so faces that are CCW in the pattern have negative signed area
    # in SVG's y-down coordinates (they look counter-clockwise on screen, not mirrored)
    v = pattern.vertices_2d
    sx = v[:, 0] - v[:, 0].min()
    sy = v[:, 1].max() - v[:, 1]
    xs = np.array(sorted({p[0] for p in pts}))
    ys = np.array(sorted({p[1] for p in pts}))
    assert_allclose(xs - xs.min(), np.unique(np.round(sx, 9)), atol=1e-6)
    assert_allclose(ys - ys.min(), np.unique(np.round(sy, 9)), atol=1e-6)
    for f in pattern.faces:
        assert signed_area(np.c_[sx, sy][f]) < 0


def test_svg_scale_bar_and_legend():
    root = _svg(two_pieces(), units="cm")
    bar = _group(root, "scale-bar")
    rect = bar.find(SVG_NS + "rect")
    text = bar.find(SVG_NS + "text")
    length = float(rect.get("width"))
    label = text.text
    assert re.fullmatch(r"[0-9.]+ cm", label)
    assert float(label.split()[0]) == pytest.approx(length)
    mantissa = length / 10 ** math.floor(math.log10(length))
    assert min(abs(mantissa - m) for m in (1, 2, 5)) < 1e-9
    width = np.ptp(two_pieces().vertices_2d[:, 0])
    assert width / 5 / 2 <= length <= width / 5 * 2
    # below the drawing
    drawing_bottom = max(
        float(ln.get(k)) for ln in root.iter(SVG_NS + "line") for k in ("y1", "y2")
    )
    assert float(rect.get("y")) > drawing_bottom
    legend = " ".join(t.text for t in _group(root, "legend").iter(SVG_NS + "text"))
    for word in ("mountain", "valley", "border / cut"):
        assert word in legend


def test_svg_physical_size_and_stroke():
    root = _svg(square_pattern(90.0), units="cm", stroke_mm=0.5)
    _, _, w, h = map(float, root.get("viewBox").split())
    assert root.get("width").endswith("mm")
    assert float(root.get("width")[:-2]) == pytest.approx(w * 10, abs=1e-3)
    assert float(root.get("height")[:-2]) == pytest.approx(h * 10, abs=1e-3)
    assert float(_group(root, "border").get("stroke-width")) == pytest.approx(0.05)


def test_svg_unitless_prints_200mm():
    root = _svg(square_pattern(90.0))
    _, _, w, _ = map(float, root.get("viewBox").split())
    # the 1 x 1 pattern is printed 200 mm wide, so 1 user unit = 200 mm
    assert float(root.get("width")[:-2]) == pytest.approx(w * 200, abs=1e-3)


def test_svg_angle_opacity():
    root = _svg(two_pieces(), angle_opacity=True)
    (valley,) = _lines(_group(root, "valley"))
    (mountain,) = _lines(_group(root, "mountain"))
    assert float(valley.get("opacity")) == pytest.approx(60 / 180, abs=1e-4)
    assert float(mountain.get("opacity")) == pytest.approx(45 / 180, abs=1e-4)


def test_svg_deterministic():
    assert pattern_svg(two_pieces(), units="mm") == pattern_svg(two_pieces(), units="mm")


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"units": "furlong"}, "units must be one of"),
        ({"stroke_mm": 0.0}, "stroke_mm must be a positive"),
        ({"stroke_mm": float("nan")}, "stroke_mm must be a positive"),
    ],
)
def test_svg_parameters_rejected(kw, match):
    with pytest.raises(ParameterError, match=match):
        pattern_svg(square_pattern(90.0), **kw)


@pytest.mark.parametrize(
    ("target", "expected"), [(0.2, 0.2), (0.3, 0.2), (0.4, 0.5), (7.5, 10.0), (140.0, 100.0)]
)
def test_nice_length(target, expected):
    assert nice_length(target) == pytest.approx(expected)


def test_nice_length_rejects():
    with pytest.raises(ParameterError, match="positive"):
        nice_length(0.0)


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


# ---------------------------------------------------------------- report JSON


@dataclasses.dataclass
class _Stats:
    count: int
    ratio: float


def test_report_json_numpy_and_nan():
    report = {
        "z": np.float64(1.5),
        "a": np.array([[1.0, np.nan], [np.inf, -2.0]]),
        "n": np.int64(7),
        "flag": np.bool_(True),
        "nan": float("nan"),
        "ids": (np.int32(1), 2),
        "nested": {np.int64(3): "three", "stats": _Stats(2, float("-inf"))},
    }
    text = report_json(report)
    assert text.endswith("\n")
    assert text.startswith('{\n  "z": 1.5,')
    back = json.loads(text)
    assert list(back) == ["z", "a", "n", "flag", "nan", "ids", "nested"]
    assert back["a"] == [[1.0, None], [None, -2.0]]
    assert back["n"] == 7 and back["flag"] is True and back["nan"] is None
    assert back["ids"] == [1, 2]
    assert back["nested"] == {"3": "three", "stats": {"count": 2, "ratio": None}}
    assert "NaN" not in text and "Infinity" not in text
    assert report_json(report) == text


@pytest.mark.parametrize(
    ("report", "match"),
    [
        ({"x": object()}, r"at x has no JSON form \(object\)"),
        ({"x": [1, complex(1, 2)]}, r"x\[1\] has no JSON form"),
        ({"x": np.array([1j])}, "complex128 array"),
        ({(1, 2): 3}, "is not a string or number"),
    ],
)
def test_report_json_rejects(report, match):
    with pytest.raises(ExportError, match=match):
        report_json(report)
