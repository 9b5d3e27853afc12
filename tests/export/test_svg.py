"""The SVG writer (:mod:`filletfold.export.svg`) on small hand-made crease patterns."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from numpy.testing import assert_allclose

from filletfold.errors import ParameterError
from filletfold.export import pattern_svg
from filletfold.export.paths import pattern_extent
from filletfold.export.presets import PRESETS, RESOLUTION_MM
from filletfold.export.svg import MIN_POINT_SPACING, nice_length

from ..conftest import PATTERNS, signed_area, square_pattern, strip_pattern, two_pieces
from .conftest import arc_pattern

SVG_NS = "{http://www.w3.org/2000/svg}"
ATOL = 1e-9


# ---------------------------------------------------------------- SVG


OS = "origami-simulator"


def _svg(pattern, **kw):
    """The SVG of ``pattern``, parsed; Origami Simulator's preset unless ``preset`` is given."""
    kw.setdefault("preset", OS)
    return ET.fromstring(pattern_svg(pattern, **kw))


def _group(root, gid):
    groups = [g for g in root.iter(SVG_NS + "g") if g.get("id") == gid]
    assert len(groups) == 1, gid
    return groups[0]


def _lines(group):
    return group.findall(SVG_NS + "line")


def _user_per_mm(root) -> float:
    """User units per printed millimetre (viewBox width over ``width``)."""
    _, _, w, _ = map(float, root.get("viewBox").split())
    return w / float(root.get("width")[:-2])


def _endpoints(root, gids) -> np.ndarray:
    """(k, 2) the end points of the ``<line>`` elements of the groups ``gids``."""
    pts = [
        (float(ln.get("x" + k)), float(ln.get("y" + k)))
        for g in root.iter(SVG_NS + "g")
        if g.get("id") in gids
        for ln in _lines(g)
        for k in ("1", "2")
    ]
    return np.array(pts).reshape(-1, 2)


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
    pattern = PATTERNS[name]()
    root = _svg(pattern)
    colour = {"mountain": "#ff0000", "valley": "#0000ff", "border": "#000000", "flat": "#ffff00"}
    counts = {**counts, "flat": int(np.sum(pattern.edge_assignment == "F"))}
    for gid, n in counts.items():
        lines = _lines(_group(root, gid))
        assert len(lines) == n
        assert all(ln.get("stroke") == colour[gid] for ln in lines)


def test_svg_chunks_are_the_document_a_group_at_a_time():
    """pattern.svg is written from chunks (each group drawn when its turn comes): joined they
    are pattern_svg's document, whole lines each, the header first and the legend (which
    names every group drawn) last."""
    from filletfold.export.svg import _pattern_svg_chunks

    from ..conftest import design_of

    pattern = design_of("cube").pattern
    chunks = list(_pattern_svg_chunks(pattern, flat_edges=True))
    assert "".join(chunks) == pattern_svg(pattern, flat_edges=True)
    assert all(c.endswith("\n") for c in chunks) and len(chunks) > 10
    assert chunks[0].startswith("<?xml") and chunks[-1] == "</svg>\n"
    legend = "".join(
        chunks[chunks.index('<g id="legend" font-family="sans-serif" fill="#000000">\n') :]
    )
    for label in ("mountain", "valley", "facet (flat)", "tab hinge"):
        assert f">{label}</text>" in legend


def test_svg_flat_edges_optional():
    root = _svg(strip_pattern(), flat_edges=False)
    assert not [g for g in root.iter(SVG_NS + "g") if g.get("id") == "flat"]
    flat = _lines(_group(_svg(strip_pattern()), "flat"))
    assert len(flat) == 1 and flat[0].get("stroke") == "#ffff00"


def test_svg_not_mirrored_and_inside_viewbox(pattern):
    root = _svg(pattern)
    x0, y0, w, h = map(float, root.get("viewBox").split())
    assert (x0, y0) == (0.0, 0.0)
    pts = _endpoints(root, {"mountain", "valley", "border"})
    assert ((pts > 0) & (pts < [w, h])).all()
    # the drawing is a translation, a scale and a y flip, so faces that are CCW in the pattern
    # have negative signed area in SVG's y-down coordinates (counter-clockwise on screen)
    v = pattern.vertices_2d
    sx = v[:, 0] - v[:, 0].min()
    sy = v[:, 1].max() - v[:, 1]
    xs = np.unique(pts[:, 0])
    ys = np.unique(pts[:, 1])
    k = np.ptp(xs) / np.ptp(sx)
    assert_allclose((xs - xs.min()) / k, np.unique(np.round(sx, 9)), atol=1e-6)
    assert_allclose((ys - ys.min()) / k, np.unique(np.round(sy, 9)), atol=1e-6)
    for f in pattern.faces:
        assert signed_area(np.c_[sx, sy][f]) < 0


def test_svg_scale_bar_and_legend():
    root = _svg(two_pieces(), units="cm")
    user_per_cm = 10 * _user_per_mm(root)
    bar = _group(root, "scale-bar")
    rect = bar.find(SVG_NS + "rect")
    text = bar.find(SVG_NS + "text")
    length = float(rect.get("width")) / user_per_cm
    label = text.text
    assert re.fullmatch(r"[0-9.]+ cm", label)
    assert float(label.split()[0]) == pytest.approx(length)
    mantissa = length / 10 ** math.floor(math.log10(length))
    assert min(abs(mantissa - m) for m in (1, 2, 5)) < 1e-9
    width = np.ptp(two_pieces().vertices_2d[:, 0])
    assert width / 5 / 2 <= length <= width / 5 * 2
    # below the drawing
    drawing_bottom = _endpoints(root, {"mountain", "valley", "border"})[:, 1].max()
    assert float(rect.get("y")) > drawing_bottom
    legend = " ".join(t.text for t in _group(root, "legend").iter(SVG_NS + "text"))
    for word in ("mountain", "valley", "border / cut", "facet"):
        assert word in legend


def test_svg_physical_size_and_stroke():
    root = _svg(square_pattern(90.0), units="cm", stroke_mm=0.5)
    user = _user_per_mm(root)
    assert math.log10(user) == pytest.approx(round(math.log10(user)))  # a power of ten
    assert user >= 1
    h = float(root.get("viewBox").split()[3])
    assert float(root.get("height")[:-2]) == pytest.approx(h / user, abs=1e-3)
    assert float(_group(root, "border").get("stroke-width")) == pytest.approx(0.5 * user)
    # the 1 x 1 cm square, drawn 10 mm wide
    pts = _endpoints(root, {"border"})
    assert np.ptp(pts[:, 0]) / user == pytest.approx(10.0)


def test_svg_unitless_prints_200mm():
    root = _svg(square_pattern(90.0))
    pts = _endpoints(root, {"border"})
    # the 1 x 1 pattern is printed 200 mm wide
    assert np.ptp(pts[:, 0]) / _user_per_mm(root) == pytest.approx(200.0)


@pytest.mark.parametrize("n", [40, 4000])
def test_svg_points_far_apart_for_origami_simulator(n):
    """The two closest distinct drawn points are >= 30 user units apart: ten times Origami
    Simulator's vertex merge tolerance, however fine the curve is sampled."""
    from scipy.spatial import cKDTree

    root = ET.fromstring(pattern_svg(arc_pattern(n), preset=OS))
    pts = np.unique(_endpoints(root, {"flat", "border", "mountain", "valley"}), axis=0)
    d, _ = cKDTree(pts).query(pts, k=2)
    assert d[:, 1].min() >= MIN_POINT_SPACING
    assert d[:, 1].min() < 10 * MIN_POINT_SPACING  # the smallest power of ten that does it


def test_svg_angle_opacity():
    root = _svg(two_pieces())
    (valley,) = _lines(_group(root, "valley"))
    (mountain,) = _lines(_group(root, "mountain"))
    assert float(valley.get("stroke-opacity")) == pytest.approx(60 / 180, abs=1e-6)
    assert float(mountain.get("stroke-opacity")) == pytest.approx(45 / 180, abs=1e-6)
    root = _svg(two_pieces(), angle_opacity=False)
    assert _lines(_group(root, "valley"))[0].get("stroke-opacity") is None


def test_svg_every_crease_opacity_is_its_angle():
    pattern = arc_pattern(annotated=True)
    root = _svg(pattern)
    v = pattern.vertices_2d
    lo, hi = pattern_extent(pattern)
    k = _user_per_mm(root) * 200 / (hi - lo).max()  # unitless: the larger side is 200 mm
    for code, gid in (("M", "mountain"), ("V", "valley")):
        sel = np.flatnonzero(pattern.edge_assignment == code)
        lines = _lines(_group(root, gid))
        assert len(lines) == len(sel)
        for e, ln in zip(sel, lines, strict=True):
            a, b = v[pattern.edges[e]]
            got = float(ln.get("x2")) - float(ln.get("x1"))
            assert got == pytest.approx((b[0] - a[0]) * k, abs=1e-6 * k)
            want = abs(pattern.edge_fold_angle[e]) / 180
            assert float(ln.get("stroke-opacity")) == pytest.approx(want, abs=5e-7)


@pytest.mark.parametrize("preset", ["print", OS])
def test_svg_has_no_unstroked_shape_outside_defs(cube, preset):
    """What Origami Simulator reads: every line, rect, path, polygon and polyline outside
    ``<defs>`` has one of the stroke colours it knows; the legend sits inside ``<defs>``."""
    known = {"#000000", "#ff0000", "#0000ff", "#00ff00", "#ffff00", "#ff00ff"}
    root = ET.fromstring(pattern_svg(cube.pattern, preset=preset))
    shapes = ("line", "rect", "path", "polygon", "polyline")
    (defs,) = root.findall(SVG_NS + "defs")
    hidden = set(map(id, defs.iter()))
    seen = 0
    for el in root.iter():
        if el.tag.removeprefix(SVG_NS) in shapes and id(el) not in hidden:
            assert el.get("stroke") in known, ET.tostring(el)[:80]
            seen += 1
    assert seen > (1000 if preset == OS else 50)
    assert any(el.tag == SVG_NS + "rect" for el in defs.iter())  # legend and scale bar
    (use,) = root.findall(SVG_NS + "use")
    assert use.get("href") == "#annotation"
    assert _group(root, "annotation") in list(defs)


def _polyline_length(group) -> float:
    """Total length (user units) of the ``<polyline>``/``<polygon>`` paths of a group."""
    total = 0.0
    for el in group:
        q = np.array([p.split(",") for p in el.get("points").split()], dtype=float)
        if el.tag == SVG_NS + "polygon":
            q = np.vstack([q, q[:1]])
        total += float(np.linalg.norm(np.diff(q, axis=0), axis=1).sum())
    return total


def test_svg_default_is_the_print_preset(cube):
    """The default draws what is cut and folded, each layer joined into paths, and no facet
    (``F``) lines: every mountain, valley and border edge is drawn once, at its length."""
    pattern = cube.pattern
    text = pattern_svg(pattern)
    assert text == pattern_svg(pattern, preset="print")
    root = ET.fromstring(text)
    ids = {g.get("id") for g in root.iter(SVG_NS + "g")}
    assert "flat" not in ids
    assert "#ffff00" not in text and "stroke-opacity" not in text
    k = _user_per_mm(root) * 200 / np.ptp(pattern_extent(pattern), axis=0).max()
    v = pattern.vertices_2d
    for code, gid in (("M", "mountain"), ("V", "valley"), ("B", "border")):
        e = pattern.edges[pattern.edge_assignment == code]
        want = float(np.linalg.norm(v[e[:, 1]] - v[e[:, 0]], axis=1).sum()) * k
        group = _group(root, gid)
        assert not _lines(group)
        # each segment's ends round to RESOLUTION_MM printed (whole user units here)
        step = RESOLUTION_MM * _user_per_mm(root)
        assert _polyline_length(group) == pytest.approx(want, rel=1e-6, abs=2 * step * len(e))
    assert any(el.tag == SVG_NS + "rect" for el in root.find(SVG_NS + "defs").iter())
    assert len(text) < 0.5 * len(pattern_svg(pattern, preset=OS))


def test_svg_deterministic():
    for name in PRESETS:
        a = pattern_svg(arc_pattern(annotated=True), units="mm", preset=name)
        assert a == pattern_svg(arc_pattern(annotated=True), units="mm", preset=name)


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"units": "furlong"}, "units must be one of"),
        ({"stroke_mm": 0.0}, "stroke_mm must be a positive"),
        ({"stroke_mm": float("nan")}, "stroke_mm must be a positive"),
        (
            {"preset": "lazer"},
            "unknown preset 'lazer': choose from print, origami-simulator, laser",
        ),
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
    assert [c.get("stroke") for c in groups["tab-hinge"]] == ["#ff00ff"]  # the app's hinge
    assert len(list(groups["sheets"])) == 1
    (defs,) = root.findall(SVG_NS + "defs")
    assert groups["sheets"] in list(defs.iter())
    texts = {t.text: t for t in groups["labels"].iter(f"{SVG_NS}text")}
    assert set(texts) == {"P1", "7"}
    runs = list(groups["labels"])  # one group per run of labels of one kind and size
    assert all(r.tag == f"{SVG_NS}g" and r.get("class") and r.get("font-size") for r in runs)
    assert sum(len(r) for r in runs) == 2
    assert texts["7"].get("transform").startswith("rotate(-30 ")
    assert texts["P1"].get("transform") is None


def test_svg_without_annotations_has_no_annotation_groups():
    root = ET.fromstring(pattern_svg(arc_pattern()))
    ids = {g.get("id") for g in root.iter(f"{SVG_NS}g")}
    assert not ids & {"tab-cut", "tab-hinge", "sheets", "labels"}
