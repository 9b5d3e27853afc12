"""The SVG writer (:mod:`filletfold.export.svg`) on small hand-made crease patterns."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from numpy.testing import assert_allclose

from filletfold.errors import ParameterError
from filletfold.export import (
    pattern_svg,
)
from filletfold.export.svg import nice_length

from ..conftest import PATTERNS, signed_area, square_pattern, strip_pattern, two_pieces
from .conftest import arc_pattern

SVG_NS = "{http://www.w3.org/2000/svg}"
ATOL = 1e-9


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


# ---------------------------------------------------------------- SVG annotations


def test_svg_draws_annotations():
    root = ET.fromstring(pattern_svg(arc_pattern(annotated=True), units="cm"))
    groups = {g.get("id"): g for g in root.iter(f"{SVG_NS}g")}
    assert {"tab-cut", "tab-hinge", "sheets", "labels"} <= set(groups)
    (cut,) = list(groups["tab-cut"])
    assert cut.tag == f"{SVG_NS}polyline" and cut.get("stroke") == "#000000"
    assert len(cut.get("points").split()) == 4  # the outline without its hinge
    assert groups["tab-hinge"].get("stroke-dasharray")
    assert [c.get("stroke") for c in groups["tab-hinge"]] == ["#00a000"]
    assert len(list(groups["sheets"])) == 1
    texts = {t.text: t for t in groups["labels"]}
    assert set(texts) == {"P1", "7"}
    assert texts["7"].get("transform").startswith("rotate(-30 ")
    assert texts["P1"].get("transform") is None


def test_svg_without_annotations_has_no_annotation_groups():
    root = ET.fromstring(pattern_svg(arc_pattern()))
    ids = {g.get("id") for g in root.iter(f"{SVG_NS}g")}
    assert not ids & {"tab-cut", "tab-hinge", "sheets", "labels"}
