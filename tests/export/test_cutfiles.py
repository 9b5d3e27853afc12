"""Cut files and pictures: DXF, PDF, PNG, annotations in SVG, reading FOLD back, the export CLI."""

from __future__ import annotations

import dataclasses
import io
import itertools
import json
import math
import re
import xml.etree.ElementTree as ET
import zlib

import ezdxf
import numpy as np
import pytest
from matplotlib.image import imread
from numpy.testing import assert_allclose

import filletfold
from filletfold.cli import main
from filletfold.errors import ExportError, MeshReadError, ParameterError
from filletfold.export import (
    cut_files,
    fold_document,
    fold_json,
    parse_formats,
    pattern_dxf,
    pattern_pdf,
    pattern_png,
    pattern_svg,
    preview_png,
    read_fold,
)
from filletfold.export.cutfiles import ALL_FORMATS, fit_page_scale, scaled_pattern
from filletfold.export.dxf import LAYER_COLOR
from filletfold.export.palette import ASSIGNMENT_COLOR, LABEL_COLOR, TAB_HINGE_COLOR
from filletfold.export.paths import (
    SPLINE_MIN_POINTS,
    chain_is_smooth,
    chain_runs,
    edge_chains,
    simplify_polyline,
    tab_cut_paths,
)
from filletfold.export.pdf import MAX_PAGES, REGION_PAD_MM, pdf_tiles
from filletfold.surface.pattern import Annotations, CreasePattern, Label
from filletfold.units import sheet_size_mm

from ..conftest import tiny_square

SVG_NS = "{http://www.w3.org/2000/svg}"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- patterns


def arc_pattern(n: int = 40, annotated: bool = False) -> CreasePattern:
    """A half annulus in three rings (radii 1, 1.5, 2, 2.5) of ``n`` quads each.

    The arc at radius 1.5 is a mountain crease (-30 degrees), the arc at 2 a valley (+45);
    radial edges are flat, the outline is a border. Flat in 3D (the exporters do not look).
    """
    t = np.linspace(0.0, math.pi, n + 1)
    radii = (1.0, 1.5, 2.0, 2.5)
    v2 = np.vstack([np.c_[r * np.cos(t), r * np.sin(t)] for r in radii])
    v3 = np.c_[v2, np.zeros(len(v2))]
    faces, patches = [], []
    for ring, kind in enumerate(("cone 0", "cylinder 1", "face 2")):
        a, b = ring * (n + 1), (ring + 1) * (n + 1)
        for i in range(n):
            faces.append([a + i + 1, a + i, b + i, b + i + 1])
            patches.append(kind)
    base = CreasePattern(v2, v3, faces, patches, np.zeros(len(faces), dtype=int), [0])
    edges = base.edges
    lo, hi = edges[:, 0], edges[:, 1]
    ring_of = np.arange(len(v2)) // (n + 1)
    same_ring = ring_of[lo] == ring_of[hi]
    assign = np.full(len(edges), "F", dtype="<U1")
    angle = np.zeros(len(edges))
    assign[same_ring & (ring_of[lo] == 1)] = "M"
    angle[same_ring & (ring_of[lo] == 1)] = -30.0
    assign[same_ring & (ring_of[lo] == 2)] = "V"
    angle[same_ring & (ring_of[lo] == 2)] = 45.0
    assign[(base.edge_faces < 0).any(axis=1)] = "B"
    ann = Annotations()
    if annotated:
        # a trapezoid tab on the inner border segment at the right end (x from 1 to 2.5, y = 0)
        tab = np.array([[1.0, 0.0], [1.2, -0.2], [2.3, -0.2], [2.5, 0.0]])
        ann = Annotations(
            tabs=[tab],
            tab_hinges=[np.array([[1.0, 0.0], [2.5, 0.0]])],
            labels=[
                Label(np.array([0.0, 1.75]), "P1", 0.0, 0.2, "part"),
                Label(np.array([1.75, -0.1]), "7", 30.0, 0.08, "tab"),
            ],
            sheets=np.array([[-2.6, -0.3, 2.6, 2.6]]),
        )
    return CreasePattern(
        v2,
        v3,
        faces,
        patches,
        np.zeros(len(faces), dtype=int),
        [0],
        edges=edges,
        edge_assignment=assign,
        edge_fold_angle=angle,
        edge_faces=base.edge_faces,
        annotations=ann,
    )


@pytest.fixture(scope="module")
def cube():
    """The real cube design (with the tabs, labels and sheets the pipeline adds, if any)."""
    return filletfold.round_mesh("cube")


def edge_length(pattern: CreasePattern, code: str) -> float:
    e = pattern.edges[pattern.edge_assignment == code]
    return float(np.linalg.norm(np.diff(pattern.vertices_2d[e], axis=1)[:, 0], axis=1).sum())


def tab_lengths(ann: Annotations) -> tuple[float, float]:
    """(cut length of all tab outlines without hinges, total hinge length)."""
    cut = 0.0
    for p, closed in tab_cut_paths(ann):
        q = np.vstack([p, p[:1]]) if closed else p
        cut += float(np.linalg.norm(np.diff(q, axis=0), axis=1).sum())
    hinge = sum(float(np.linalg.norm(np.diff(h, axis=0))) for h in ann.tab_hinges)
    return cut, hinge


# ---------------------------------------------------------------- paths


def test_edge_chains_cover_every_edge_once():
    edges = np.array([[0, 1], [1, 2], [2, 3], [1, 4], [5, 6], [6, 7], [5, 7]])
    chains = edge_chains(edges)
    # vertex 1 has degree 3: three open paths end there; 5-6-7 is a loop
    assert sorted((tuple(c), closed) for c, closed in chains) == sorted(
        [((0, 1), False), ((1, 2, 3), False), ((1, 4), False), ((5, 6, 7), True)]
    )
    segs = set()
    for c, closed in chains:
        ring = list(c) + ([c[0]] if closed else [])
        segs |= {tuple(sorted(int(v) for v in s)) for s in itertools.pairwise(ring)}
    assert segs == {tuple(e) for e in edges.tolist()}


def test_edge_chains_mask_and_empty():
    edges = np.array([[0, 1], [1, 2], [2, 3]])
    assert edge_chains(edges, np.zeros(3, dtype=bool)) == []
    ((c, closed),) = edge_chains(edges, np.array([True, True, False]))
    assert c.tolist() == [0, 1, 2] and not closed


def test_simplify_polyline_drops_collinear_points():
    p = np.array([[0, 0], [1, 0], [2, 0], [2, 0], [2, 1], [2, 2]], dtype=float)
    assert simplify_polyline(p).tolist() == [[0, 0], [2, 0], [2, 2]]
    square = np.array([[0, 0], [1, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    assert len(simplify_polyline(square, closed=True)) == 4


def arc(step_deg: float, n: int) -> np.ndarray:
    t = np.radians(step_deg) * np.arange(n)
    return np.c_[np.cos(t), np.sin(t)]


@pytest.mark.parametrize(
    ("points", "smooth"),
    [
        (arc(5.0, 20), True),
        (arc(10.0, 20), False),  # turns more than 8 degrees per point
        (arc(5.0, SPLINE_MIN_POINTS - 1), False),  # too few points
        (np.vstack([arc(5.0, 10), [[-3.0, 5.0]]]), False),  # a corner at the end
    ],
)
def test_chain_is_smooth_rule(points, smooth):
    assert chain_is_smooth(points) is smooth


def test_chain_runs_split_at_corners_and_spacing_jumps():
    # an arc, a long straight segment tangent to it, then a corner
    a = arc(4.0, 15)
    end = a[-1]
    tangent = np.array([-math.sin(math.radians(56.0)), math.cos(math.radians(56.0))])
    p = np.vstack([a, end + 2.0 * tangent, end + 2.0 * tangent + [5.0, 0.0]])
    runs = chain_runs(p)
    assert [(len(r), s) for r, s, _ in runs] == [(15, True), (3, False)]
    assert_allclose(runs[0][0][-1], runs[1][0][0])
    # a full circle is one closed spline whose last point repeats the first
    ((pts, spline, closed),) = chain_runs(arc(6.0, 60), closed=True)
    assert spline and closed and np.array_equal(pts[0], pts[-1])


def test_tab_cut_paths_leave_the_hinge_out():
    tab = np.array([[0, 0], [0.2, -0.2], [0.8, -0.2], [1, 0]], dtype=float)
    ann = Annotations(
        tabs=[tab, tab + np.array([2.0, 0.0])], tab_hinges=[np.array([[1.0, 0.0], [0.0, 0.0]])]
    )
    (p0, c0), (p1, c1) = tab_cut_paths(ann)
    assert not c0 and p0.tolist() == tab.tolist()  # open path 0 -> 3, the hinge 3 -> 0 left out
    assert c1 and len(p1) == 4  # no hinge given for the second tab: all of it is cut


# ---------------------------------------------------------------- DXF


def read_dxf(text: str):
    doc = ezdxf.read(io.StringIO(text))
    auditor = doc.audit()
    assert not auditor.has_errors, [str(e) for e in auditor.errors]
    return doc


def layer_lengths(doc) -> dict:
    """Per layer: (length of polylines + spline fit polylines, list of (spline, fit) lengths)."""
    out: dict = {}
    for e in doc.modelspace():
        splines = out.setdefault(e.dxf.layer, [0.0, []])[1]
        if e.dxftype() == "LWPOLYLINE":
            p = np.array(e.get_points("xy"))
            if e.closed:
                p = np.vstack([p, p[:1]])
            out[e.dxf.layer][0] += float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
        elif e.dxftype() == "SPLINE":
            fit = np.array(e.fit_points)[:, :2]
            fit_len = float(np.linalg.norm(np.diff(fit, axis=0), axis=1).sum())
            flat = np.array(list(e.construction_tool().flattening(1e-6 * fit_len)))
            spline_len = float(np.linalg.norm(np.diff(flat, axis=0), axis=1).sum())
            out[e.dxf.layer][0] += fit_len
            splines.append((spline_len, fit_len))
        elif e.dxftype() == "LINE":
            out[e.dxf.layer][0] += float(np.linalg.norm(np.subtract(e.dxf.end, e.dxf.start)))
    return out


def check_lengths(doc, pattern: CreasePattern, scale: float = 1.0) -> None:
    lengths = layer_lengths(doc)
    tab_cut, hinge = tab_lengths(pattern.annotations)
    expected = {
        "CUT": edge_length(pattern, "B") + tab_cut,
        "MOUNTAIN": edge_length(pattern, "M"),
        "VALLEY": edge_length(pattern, "V"),
        "TAB": hinge,
    }
    for layer, want in expected.items():
        got, splines = lengths.get(layer, (0.0, []))
        assert got == pytest.approx(want * scale, rel=1e-6, abs=1e-9), layer
        for spline_len, fit_len in splines:
            assert spline_len == pytest.approx(fit_len, rel=1e-3), layer


def test_dxf_layers_colours_and_audit():
    doc = read_dxf(pattern_dxf(arc_pattern()))
    # "0" and "Defpoints" are the standard layers every DXF has
    names = {layer.dxf.name for layer in doc.layers} - {"0", "Defpoints"}
    assert names == {"CUT", "MOUNTAIN", "VALLEY", "TAB", "LABEL"}
    for name in names:
        assert doc.layers.get(name).dxf.color == LAYER_COLOR[name]
    assert doc.layers.get("TAB").dxf.linetype == "DASHED"
    assert doc.dxfversion == "AC1024"  # R2010
    assert doc.header["$INSUNITS"] == 0


def test_dxf_flat_layer_optional():
    pattern = arc_pattern()
    doc = read_dxf(pattern_dxf(pattern, flat_edges=True))
    assert doc.layers.get("FLAT").dxf.color == LAYER_COLOR["FLAT"]
    assert layer_lengths(doc)["FLAT"][0] == pytest.approx(edge_length(pattern, "F"), rel=1e-6)


def test_dxf_curves_are_few_splines_of_the_right_length():
    pattern = arc_pattern()
    doc = read_dxf(pattern_dxf(pattern))
    kinds = {}
    for e in doc.modelspace():
        kinds.setdefault(e.dxf.layer, []).append(e.dxftype())
    assert kinds["MOUNTAIN"] == ["SPLINE"] and kinds["VALLEY"] == ["SPLINE"]
    # the outline: two arcs as splines, the two straight ends as polylines
    assert sorted(kinds["CUT"]) == ["LWPOLYLINE", "LWPOLYLINE", "SPLINE", "SPLINE"]
    assert len(kinds["CUT"]) < np.sum(pattern.edge_assignment == "B") / 10
    check_lengths(doc, pattern)


def test_dxf_units_scale_tabs_and_labels():
    pattern = arc_pattern(annotated=True)
    doc = read_dxf(pattern_dxf(pattern, units="mm", scale=10.0))
    assert doc.header["$INSUNITS"] == 4
    check_lengths(doc, pattern, scale=10.0)
    msp = doc.modelspace()
    assert len(msp.query("LINE[layer=='TAB']")) == 1
    texts = sorted(msp.query("TEXT[layer=='LABEL']"), key=lambda t: t.dxf.text)
    assert [t.dxf.text for t in texts] == ["7", "P1"]
    assert [t.dxf.rotation for t in texts] == pytest.approx([30.0, 0.0])
    assert [t.dxf.height for t in texts] == pytest.approx([0.8, 2.0])
    assert_allclose(np.array(texts[1].dxf.align_point)[:2], [0.0, 17.5], atol=1e-9)


def test_dxf_of_the_cube_design(cube):
    pattern = cube.pattern
    text = pattern_dxf(pattern, units="cm", scale=5.0)
    assert text == pattern_dxf(pattern, units="cm", scale=5.0)  # deterministic
    doc = read_dxf(text)
    assert doc.header["$INSUNITS"] == 5
    counts = {}
    for e in doc.modelspace():
        counts[e.dxf.layer] = counts.get(e.dxf.layer, 0) + 1
    n_curved = int(np.sum(np.isin(pattern.edge_assignment, ("B", "M", "V"))))
    n_entities = sum(counts.get(k, 0) for k in ("CUT", "MOUNTAIN", "VALLEY"))
    assert n_entities < n_curved / 10
    assert any(e.dxftype() == "SPLINE" for e in doc.modelspace().query("*[layer=='MOUNTAIN']"))
    assert counts.get("LABEL", 0) == len(pattern.annotations.labels)
    assert counts.get("TAB", 0) == len(pattern.annotations.tab_hinges)
    check_lengths(doc, pattern, scale=5.0)


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"units": "ft"}, "units must be one of"),
        ({"scale": 0.0}, "scale must be a positive number"),
        ({"scale": -2.0}, "scale must be a positive number"),
        ({"scale": float("nan")}, "scale must be a positive number"),
        ({"scale": True}, "scale must be a positive number"),
        ({"scale": "2"}, "scale must be a positive number"),
    ],
)
def test_dxf_parameters_rejected(kw, match):
    with pytest.raises(ParameterError, match=match):
        pattern_dxf(tiny_square(), **kw)


def test_dxf_rejects_an_inconsistent_pattern():
    bad = dataclasses.replace(tiny_square())
    bad.edge_assignment = bad.edge_assignment.copy()
    bad.edge_assignment[0] = "X"
    with pytest.raises(ExportError, match="not one of M V B F"):
        pattern_dxf(bad)


# ---------------------------------------------------------------- PDF


def pdf_pages(data: bytes) -> int:
    return len(re.findall(rb"/Type\s*/Page(?![a-zA-Z])", data))


def test_pdf_tiny_pattern_is_one_page():
    data = pattern_pdf(tiny_square(), units="cm", scale=5.0)
    assert data.startswith(b"%PDF")
    assert pdf_pages(data) == 1
    assert data == pattern_pdf(tiny_square(), units="cm", scale=5.0)  # deterministic


def test_pdf_pages_follow_the_extent():
    pattern = arc_pattern()  # 5 x 2.5 pattern units
    data = pattern_pdf(pattern, units="mm", scale=100.0)
    tw, th = 210.0 - 20.0, 297.0 - 20.0
    cols = math.ceil((500.0 + 2 * REGION_PAD_MM) / tw)
    rows = math.ceil((250.0 + 2 * REGION_PAD_MM) / th)
    assert (rows, cols) == (1, 3)
    assert pdf_pages(data) == rows * cols == len(pdf_tiles(pattern, units="mm", scale=100.0))
    # custom page, inch units: 5 * 4 in = 508 mm wide
    tiles = pdf_tiles(pattern, page="300x200", units="in", scale=4.0, margin_mm=5.0)
    assert len(tiles) == math.ceil(512.0 / 290.0) * math.ceil((254.0 + 4.0) / 190.0)


def test_pdf_tiles_abut_exactly():
    tiles = pdf_tiles(arc_pattern(), page="A3", units="mm", scale=150.0, margin_mm=12.0)
    tw, th = 297.0 - 24.0, 420.0 - 24.0
    assert len(tiles) > 2
    for t in tiles:
        x0, y0, x1, y1 = t.box
        assert (x1 - x0, y1 - y0) == pytest.approx((tw, th), abs=1e-9)
        if t.col > 1:
            left = next(u for u in tiles if (u.row, u.col) == (t.row, t.col - 1))
            assert left.box[2] == x0 and left.box[1] == y0  # shared edge, no overlap
        if t.row > 1:
            up = next(u for u in tiles if (u.row, u.col) == (t.row - 1, t.col))
            assert up.box[1] == y1 and up.box[0] == x0
    xs0 = min(t.box[0] for t in tiles)
    assert xs0 == pytest.approx(-2.5 * 150.0 - REGION_PAD_MM)


def test_pdf_one_page_group_per_sheet():
    pattern = arc_pattern(annotated=True)
    pattern.annotations.sheets = np.array([[-2.6, -0.3, 0.0, 2.6], [0.0, -0.3, 2.6, 2.6]])
    tiles = pdf_tiles(pattern, units="mm", scale=100.0)
    per_sheet = math.ceil((260.0 + 4.0) / 190.0) * math.ceil((290.0 + 4.0) / 277.0)
    assert [t.region for t in tiles] == [0] * per_sheet + [1] * per_sheet
    assert pdf_pages(pattern_pdf(pattern, units="mm", scale=100.0)) == 2 * per_sheet


def test_pdf_of_the_cube_design(cube):
    data = pattern_pdf(cube.pattern, page="Letter", units="mm", scale=120.0)
    assert data.startswith(b"%PDF")
    assert pdf_pages(data) == len(pdf_tiles(cube.pattern, page="Letter", units="mm", scale=120.0))


@pytest.mark.parametrize(
    ("page", "size"),
    [
        ("A4", (210.0, 297.0)),
        ("a3", (297.0, 420.0)),
        ("Legal", (215.9, 355.6)),
        ("600x400", (600.0, 400.0)),
    ],
)
def test_page_sizes(page, size):
    assert sheet_size_mm(page, name="page") == size


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"page": "B5"}, "page must be one of"),
        ({"page": "0x100"}, "page size must be positive"),
        ({"page": 4}, "page must be a string"),
        ({"units": ""}, "units must be one of"),
        ({"scale": 0}, "scale must be a positive number"),
        ({"margin_mm": 150.0}, "margin_mm must be >= 0"),
        ({"margin_mm": -1.0}, "margin_mm must be >= 0"),
        ({"margin_mm": "1"}, "margin_mm must be a number"),
        ({"scale": 1e6}, f"more than {MAX_PAGES}"),
    ],
)
def test_pdf_parameters_rejected(kw, match):
    with pytest.raises(ParameterError, match=match):
        pattern_pdf(tiny_square(), **kw)


# ---------------------------------------------------------------- PNG


def check_picture(data: bytes, width: int, height: int | None = None) -> None:
    assert data.startswith(PNG_SIGNATURE)
    img = imread(io.BytesIO(data))
    assert img.shape[1] == width
    if height is not None:
        assert img.shape[0] == height
    rgb = img[..., :3]
    non_white = np.any(rgb < 0.97, axis=2).mean()
    assert non_white > 0.10
    colours = np.unique((rgb * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 50


def test_pattern_png(cube):
    check_picture(pattern_png(cube.pattern, width_px=500), 500)
    check_picture(pattern_png(arc_pattern(annotated=True), width_px=300), 300)


def test_preview_png(cube):
    data = preview_png(cube.pattern, width_px=400, elev=30.0, azim=20.0)
    check_picture(data, 400, 300)
    assert data == preview_png(cube.pattern, width_px=400, elev=30.0, azim=20.0)


@pytest.mark.parametrize(
    ("func", "kw", "match"),
    [
        (pattern_png, {"width_px": 5}, "width_px must be an integer"),
        (pattern_png, {"width_px": 300.0}, "width_px must be an integer"),
        (preview_png, {"width_px": 10**6}, "width_px must be an integer"),
        (preview_png, {"elev": float("nan")}, "elev must be a finite number"),
        (preview_png, {"azim": "x"}, "azim must be a finite number"),
    ],
)
def test_png_parameters_rejected(func, kw, match):
    with pytest.raises(ParameterError, match=match):
        func(tiny_square(), **kw)


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


# ---------------------------------------------------------------- FOLD read back


def write_fold(tmp_path, doc, name="design.fold"):
    path = tmp_path / name
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    return path


def assert_same_pattern(a: CreasePattern, b: CreasePattern) -> None:
    assert_allclose(a.vertices_2d, b.vertices_2d, atol=1e-9)
    assert_allclose(a.vertices_3d, b.vertices_3d, atol=1e-9)
    assert [list(f) for f in a.faces] == [list(f) for f in b.faces]
    assert list(a.face_patch) == list(b.face_patch)
    assert a.face_piece.tolist() == b.face_piece.tolist()
    assert a.piece_vertex.tolist() == b.piece_vertex.tolist()
    assert a.edges.tolist() == b.edges.tolist()
    assert a.edge_assignment.tolist() == b.edge_assignment.tolist()
    assert_allclose(a.edge_fold_angle, b.edge_fold_angle, atol=1e-9)
    assert a.edge_faces.tolist() == b.edge_faces.tolist()
    aa, ba = a.annotations, b.annotations
    assert len(aa.tabs) == len(ba.tabs) and len(aa.labels) == len(ba.labels)
    for s, t in zip(aa.tabs, ba.tabs, strict=True):
        assert_allclose(s, t, atol=1e-9)
    for s, t in zip(aa.tab_hinges, ba.tab_hinges, strict=True):
        assert_allclose(s, t, atol=1e-9)
    for s, t in zip(aa.labels, ba.labels, strict=True):
        assert (s.text, s.kind) == (t.text, t.kind)
        assert_allclose([*s.position, s.angle, s.height], [*t.position, t.angle, t.height])
    assert_allclose(np.reshape(aa.sheets, (-1, 4)), np.reshape(ba.sheets, (-1, 4)), atol=1e-9)


def test_read_fold_round_trip_cube(cube, tmp_path):
    doc = fold_document(cube.pattern)
    assert doc["filletfold:pieces_vertex"] == cube.pattern.piece_vertex.tolist()
    back = read_fold(write_fold(tmp_path, fold_json(doc)))
    assert_same_pattern(cube.pattern, back)


@pytest.mark.parametrize("annotated", [False, True])
def test_read_fold_round_trip_annotations(annotated, tmp_path):
    pattern = arc_pattern(annotated=annotated)
    doc = fold_document(pattern)
    assert ("filletfold:annotations" in doc) is annotated
    back = read_fold(write_fold(tmp_path, fold_json(doc)))
    assert_same_pattern(pattern, back)
    # the pattern read back exports like the original (up to FOLD's 12 digits)
    a, b = layer_lengths(read_dxf(pattern_dxf(back))), layer_lengths(read_dxf(pattern_dxf(pattern)))
    assert a.keys() == b.keys()
    for layer in a:
        assert a[layer][0] == pytest.approx(b[layer][0], rel=1e-9)
        assert len(a[layer][1]) == len(b[layer][1])


def test_read_fold_without_pieces_vertex(tmp_path):
    doc = fold_document(tiny_square())
    del doc["filletfold:pieces_vertex"]
    back = read_fold(write_fold(tmp_path, doc))
    assert back.piece_vertex.tolist() == [-1]


def _mutated(change):
    doc = json.loads(fold_json(fold_document(tiny_square())))
    change(doc)
    return doc


@pytest.mark.parametrize(
    ("content", "match"),
    [
        ("{not json", "invalid JSON"),
        ("[1, 2]", "top level is a list"),
        ({"file_spec": 1.2, "vertices_coords": [[0, 0]]}, "missing key"),
        (_mutated(lambda d: d.pop("file_frames")), "no folded frame"),
        (_mutated(lambda d: d.update(file_frames=[{"frame_classes": []}])), "no frame of"),
        (_mutated(lambda d: d["file_frames"][0].update(vertices_coords=[[0, 0]] * 4)), "3D"),
        (_mutated(lambda d: d.update(vertices_coords=[[0, 0, 0]] * 4)), "2D points"),
        (_mutated(lambda d: d["edges_assignment"].__setitem__(0, "X")), "not a valid filletfold"),
        (_mutated(lambda d: d.update(edges_foldAngle="x")), "malformed arrays"),
        (_mutated(lambda d: d.update({"filletfold:annotations": [1]})), "must be an object"),
        (
            _mutated(lambda d: d.update({"filletfold:annotations": {"labels": [{"x": 1}]}})),
            "annotations is malformed",
        ),
    ],
)
def test_read_fold_rejects(content, match, tmp_path):
    path = write_fold(tmp_path, content)
    with pytest.raises(MeshReadError, match=match):
        read_fold(path)


def test_read_fold_missing_file_and_folder(tmp_path):
    with pytest.raises(MeshReadError, match="no such file"):
        read_fold(tmp_path / "nothing.fold")
    with pytest.raises(MeshReadError, match="is a folder"):
        read_fold(tmp_path)


# ---------------------------------------------------------------- cut_files and export


@pytest.mark.parametrize(
    ("spec", "expected"),
    [
        ("dxf, PDF", ("dxf", "pdf")),
        ("png,svg,png", ("svg", "png")),
        (["obj", "fold"], ("fold", "obj")),
        ("all", ALL_FORMATS),
        ("svg,all", ALL_FORMATS),
    ],
)
def test_parse_formats(spec, expected):
    assert parse_formats(spec) == expected


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("dxf,dwg", "unknown format 'dwg'"),
        ("", "no output format"),
        ([3], "format names must be strings"),
        (7, "formats must be a string or a list"),
    ],
)
def test_parse_formats_rejects(spec, match):
    with pytest.raises(ParameterError, match=match):
        parse_formats(spec)


def test_cut_files_names_and_types():
    files = cut_files(arc_pattern(annotated=True), "all", units="mm", scale=40.0, report={"a": 1})
    assert list(files) == [
        "design.fold",
        "report.json",
        "folded.obj",
        "pattern.svg",
        "pattern.dxf",
        "pattern.pdf",
        "pattern.png",
        "preview.png",
    ]
    assert isinstance(files["pattern.pdf"], bytes) and isinstance(files["pattern.dxf"], str)
    assert json.loads(files["report.json"]) == {"a": 1}
    # the SVG is drawn at the scale: 5 pattern units * 40 mm
    root = ET.fromstring(files["pattern.svg"])
    assert float(root.get("width").removesuffix("mm")) > 200.0


def test_cut_files_unitless_pdf_fits_one_page():
    pattern = arc_pattern()
    k = fit_page_scale(pattern, "A4")
    assert 0 < k <= (190.0 - 4.0) / 5.0
    assert pdf_pages(cut_files(pattern, "pdf")["pattern.pdf"]) == 1


def test_scaled_pattern():
    pattern = arc_pattern(annotated=True)
    big = scaled_pattern(pattern, 3.0)
    assert_allclose(big.vertices_2d, 3.0 * pattern.vertices_2d)
    assert_allclose(big.vertices_3d, pattern.vertices_3d)
    assert_allclose(big.annotations.tabs[0], 3.0 * pattern.annotations.tabs[0])
    assert big.annotations.labels[0].height == pytest.approx(0.6)
    assert_allclose(big.annotations.sheets, 3.0 * pattern.annotations.sheets)
    assert scaled_pattern(pattern, 1.0) is pattern


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"formats": "json"}, "report.json needs the whole design"),
        ({"formats": "dxf", "units": "ft"}, "units must be one of"),
        ({"formats": "dxf", "scale": -1.0}, "scale must be a positive number"),
        ({"formats": "pdf", "page": "huge"}, "page must be one of"),
    ],
)
def test_cut_files_rejects(kw, match):
    with pytest.raises(ParameterError, match=match):
        cut_files(tiny_square(), **kw)


def test_export_design_all_formats(cube, tmp_path):
    from filletfold.export.outputs import export_design

    written = export_design(cube, tmp_path / "all", formats="all", units="mm", scale=60.0)
    assert [p.name for p in written] == [
        "design.fold",
        "report.json",
        "folded.obj",
        "pattern.svg",
        "pattern.dxf",
        "pattern.pdf",
        "pattern.png",
        "preview.png",
        "assembly.txt",
        "timings.json",
    ]
    written = export_design(cube, tmp_path / "some", formats="dxf,json")
    assert [p.name for p in written] == [
        "report.json",
        "pattern.dxf",
        "assembly.txt",
        "timings.json",
    ]
    written = export_design(cube, tmp_path / "dxf", formats="dxf")
    assert [p.name for p in written] == ["pattern.dxf", "assembly.txt"]


# ---------------------------------------------------------------- CLI


def test_cli_export_writes_the_cut_files(cube, tmp_path, capsys):
    folder = tmp_path / "cube"
    folder.mkdir()
    (folder / "design.fold").write_text(fold_json(fold_document(cube.pattern)))
    args = ["export", str(folder), "--format", "dxf,pdf,svg,png", "--units", "mm", "--scale", "50"]
    assert main(args) == 0
    names = {p.name for p in folder.iterdir()}
    assert names == {
        "design.fold",
        "pattern.dxf",
        "pattern.pdf",
        "pattern.svg",
        "pattern.png",
        "preview.png",
    }
    assert "wrote 5 files" in capsys.readouterr().out
    doc = read_dxf((folder / "pattern.dxf").read_text())
    assert doc.header["$INSUNITS"] == 4
    check_lengths(doc, cube.pattern, scale=50.0)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["--format", "dxf,gif"], "unknown format 'gif'"),
        (["--format", "json"], "cannot be written from design.fold"),
        (["--units", "ft"], "units must be one of"),
        (["--scale", "0"], "scale must be a positive number"),
        (["--sheet", "B5"], "sheet must be one of"),
    ],
)
def test_cli_export_bad_options(args, match, tmp_path, capsys):
    (tmp_path / "design.fold").write_text(fold_json(fold_document(tiny_square())))
    assert main(["export", str(tmp_path), *args]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert re.search(match, err), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design.fold"]


def test_cli_export_missing_inputs(tmp_path, capsys):
    assert main(["export", str(tmp_path / "nope")]) == 2
    assert "no such folder" in " ".join(capsys.readouterr().err.split())
    assert main(["export", str(tmp_path)]) == 2
    assert "no design.fold" in " ".join(capsys.readouterr().err.split())
    (tmp_path / "design.fold").write_text('{"file_spec": 1.2}')
    assert main(["export", str(tmp_path)]) == 2
    assert "not a filletfold FOLD file" in " ".join(capsys.readouterr().err.split())


def test_cli_round_with_all_formats(tmp_path, capsys):
    out = tmp_path / "cube"
    args = ["round", "cube", "-o", str(out), "-q", "--format", "all", "--units", "cm"]
    assert main([*args, "--sheet", "A3"]) == 0
    assert "wrote 10 files" in capsys.readouterr().out
    assert (out / "pattern.pdf").read_bytes().startswith(b"%PDF")
    assert read_dxf((out / "pattern.dxf").read_text()).header["$INSUNITS"] == 5


def test_cli_round_bad_format_fails_before_solving(tmp_path, capsys):
    assert main(["round", "cube", "-o", str(tmp_path / "x"), "--format", "fold,stl"]) == 2
    assert "unknown format 'stl'" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


# ---------------------------------------------------------------- one palette


def pdf_stroke_colors(data: bytes) -> set[str]:
    """Stroke colours (``#rrggbb``) set in the content streams of a PDF."""
    colors = set()
    for raw in re.findall(rb"stream\r?\n(.*?)\r?\nendstream", data, flags=re.S):
        try:
            text = zlib.decompress(raw).decode("latin-1")
        except zlib.error:
            continue
        for rgb in re.findall(r"(?:([\d.]+) ([\d.]+) )?([\d.]+) (?:RG|G)\b", text):
            rgb = rgb if rgb[0] else (rgb[2],) * 3  # "x G" is grey x
            colors.add("#" + "".join(f"{round(float(c) * 255):02x}" for c in rgb))
    return colors


def test_svg_and_pdf_draw_with_one_palette(cube):
    svg = pattern_svg(cube.pattern)
    pdf = pattern_pdf(cube.pattern, scale=20.0)
    present = set(cube.pattern.edge_assignment) - {"F"}
    assert {"M", "B"} <= present
    used = {ASSIGNMENT_COLOR[a] for a in present} | {TAB_HINGE_COLOR}
    assert used <= pdf_stroke_colors(pdf)
    for a in present:
        assert f'stroke="{ASSIGNMENT_COLOR[a]}"' in svg, a
    assert f'stroke="{TAB_HINGE_COLOR}"' in svg
    assert f'fill="{LABEL_COLOR}"' in svg


def test_dxf_classes_are_sorted(cube):
    """ezdxf takes the classes from a set (ordered by the hash seed); the DXF sorts them."""
    text = pattern_dxf(cube.pattern, units="mm")
    section = text.split("\nCLASSES\n", 1)[1].split("\nENDSEC\n", 1)[0]
    names = re.findall(r"\n  0\nCLASS\n  1\n(\S+)\n  2\n(\S+)", "\n" + section)
    assert len(names) > 10
    assert names == sorted(names)
    assert {"LAYOUT", "ACDBPLACEHOLDER"} <= {n for n, _ in names}
