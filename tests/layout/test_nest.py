"""Nesting on sheets: the shelf packer and sparrow (the ``nest`` extra) place pieces apart,
inside their sheets, turned rigidly; a missing or misnamed nester is a one-line error."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest
import shapely

import filletfold
from filletfold.cli import main
from filletfold.errors import ParameterError
from filletfold.export.outputs import edge_mismatch
from filletfold.layout import nest
from filletfold.layout.arrange import TAB_HEIGHT
from filletfold.surface.faces import face_polygons
from filletfold.surface.piece import Piece, piece_area
from filletfold.units import sheet_size_mm

needs_sparrow = pytest.mark.skipif(not nest.have_sparrow(), reason="spyrrow is not installed")

#: dodecahedron nets on A4 at 60 mm per unit: 4 pieces, one of them small
CASE = {"sheet": "A4", "units": "mm", "scale": 60.0}
GAP = 0.1 + 2.5 * TAB_HEIGHT  # arrange's gap for a mean edge length of 1 (with tabs)


@pytest.fixture(scope="module")
def designs():
    out = {"shelf": filletfold.round_mesh("dodecahedron", nest="shelf", **CASE)}
    if nest.have_sparrow():
        out["sparrow"] = filletfold.round_mesh("dodecahedron", nest="sparrow", **CASE)
    return out


def _outlines(pattern) -> list:
    """Each pattern piece's faces' union, from the pattern itself."""
    polys = face_polygons(pattern.vertices_2d, pattern.faces)
    return [
        shapely.union_all(shapely.make_valid(polys[pattern.face_piece == k]))
        for k in range(pattern.n_pieces)
    ]


@pytest.mark.parametrize("nester", ["shelf", "sparrow"])
def test_pieces_are_apart_and_inside_their_sheets(designs, nester):
    if nester not in designs:
        pytest.skip("spyrrow is not installed")
    d = designs[nester]
    p, fab = d.pattern, d.fabrication
    boxes = p.annotations.sheets
    assert fab["nesting"]["nester"] == nester and fab["sheets"] == len(boxes)
    shapes = _outlines(p)
    sheet_of = []
    for k, shape in enumerate(shapes):
        room = [shapely.box(*b).buffer(-GAP * (1 - 1e-6)) for b in boxes]
        inside = [s for s, r in enumerate(room) if r.covers(shape)]
        assert len(inside) == 1, f"piece {k} is within {len(inside)} sheets by the gap"
        sheet_of.append(inside[0])
    for a in range(len(shapes)):
        for b in range(a + 1, len(shapes)):
            assert shapes[a].distance(shapes[b]) >= GAP * (1 - 1e-6)
    assert np.bincount(sheet_of, minlength=len(boxes)).tolist() == fab["pieces_per_sheet"]
    # every glue tab lies on its piece's sheet
    for tab in p.annotations.tabs:
        t = shapely.Polygon(tab)
        assert any(shapely.box(*b).covers(t) for b in boxes)
    # the figures, from the pattern
    w, h = sheet_size_mm("A4") / np.array(CASE["scale"])
    area = sum(s.area for s in shapes)
    assert fab["nesting"]["material_use"] == pytest.approx(area / (len(boxes) * w * h), rel=1e-6)
    assert fab["nesting"]["material_use"] <= fab["nesting"]["strip_use"] <= 1


@needs_sparrow
def test_sparrow_turns_the_pieces_rigidly(designs):
    shelf, sparrow = designs["shelf"].pattern, designs["sparrow"].pattern
    a = sorted(s.area for s in _outlines(shelf))
    b = sorted(s.area for s in _outlines(sparrow))
    np.testing.assert_allclose(a, b, rtol=1e-9)
    assert np.abs(edge_mismatch(sparrow)).max() <= np.abs(edge_mismatch(shelf)).max() + 1e-9
    assert designs["sparrow"].certificate.ok


@needs_sparrow
def test_sparrow_uses_no_more_sheets_here(designs):
    shelf, sparrow = (designs[k].fabrication for k in ("shelf", "sparrow"))
    assert sparrow["sheets"] <= shelf["sheets"]
    assert sparrow["nesting"]["material_use"] >= shelf["nesting"]["material_use"]
    assert sparrow["nesting"]["runs"] >= 1 and sparrow["nesting"]["seconds"] == 0


def _square(size: float, corner=(0.0, 0.0), turn: float = 0.0) -> Piece:
    c = np.array([[0, 0], [size, 0], [size, size / 2], [0, size]], dtype=float)
    c = c @ nest.turn(turn).T + corner
    return Piece(
        vertex=0,
        points_2d=list(c),
        points_3d=[np.array([x, y, 0.0]) for x, y in c],
        faces=[[0, 1, 2, 3]],
        patches=["face 0"],
    )


def test_placement_errors_finds_overlaps_and_pieces_off_their_sheet():
    pieces = [_square(1.0), _square(1.0)]
    boxes = np.array([[0.0, 0.0, 4.0, 3.0]])
    apart = np.array([[0.5, 0.5], [2.0, 0.5]])
    assert nest.placement_errors(pieces, apart, boxes, [0, 0], 0.2) == []
    close = np.array([[0.5, 0.5], [1.6, 0.5]])  # 0.1 apart
    faults = nest.placement_errors(pieces, close, boxes, [0, 0], 0.2)
    assert len(faults) == 1 and "pieces 1 and 2" in faults[0]
    out = np.array([[0.5, 0.5], [3.5, 0.5]])
    faults = nest.placement_errors(pieces, out, boxes, [0, 0], 0.2)
    assert any("piece 2 is not within its sheet 1" in f for f in faults)


@needs_sparrow
@pytest.mark.parametrize("turns", [nest.ORIENTATIONS, None])
def test_nest_on_sheets_is_valid_rigid_and_repeatable(turns):
    pieces = [_square(s, (3 * k, k), 17 * k) for k, s in enumerate([2.0, 1.5, 1.5, 1.0, 0.7, 0.7])]
    area = [piece_area(p) for p in pieces]
    length = [np.linalg.norm(np.diff(p.arrays()[0], axis=0), axis=1) for p in pieces]
    sheet, gap = (5.0, 3.5), 0.1
    first = copy.deepcopy(pieces)
    offsets, boxes, sheet_of, runs = nest.nest_on_sheets(first, sheet, gap, turns=turns)
    assert nest.placement_errors(first, offsets, boxes, sheet_of, gap) == []
    assert len(boxes) < len(pieces) and runs >= 1
    np.testing.assert_allclose([piece_area(p) for p in first], area, rtol=1e-12)
    for p, ref in zip(first, length, strict=True):
        edges = np.linalg.norm(np.diff(p.arrays()[0], axis=0), axis=1)
        np.testing.assert_allclose(edges, ref, rtol=1e-12)
    again = copy.deepcopy(pieces)
    offsets2, _, sheet_of2, _ = nest.nest_on_sheets(again, sheet, gap, turns=turns)
    assert np.array_equal(offsets, offsets2) and np.array_equal(sheet_of, sheet_of2)
    for a, b in zip(first, again, strict=True):
        assert np.array_equal(a.arrays()[0], b.arrays()[0])


@needs_sparrow
def test_a_piece_too_large_for_the_sheet_is_refused():
    with pytest.raises(ParameterError, match=r"piece 1 .* does not fit on the sheet") as err:
        nest.nest_on_sheets([_square(4.0)], (5.0, 3.5), 0.1)
    assert err.value.name == "sheet"


@pytest.mark.parametrize(
    ("spec", "expected"),
    [("shelf", ("shelf", 0)), ("Sparrow", ("sparrow", 0)), ("sparrow:3", ("sparrow", 3))],
)
def test_parse_nest(spec, expected):
    assert nest.parse_nest(spec) == expected


@pytest.mark.parametrize("spec", ["rows", "sparrow:0", "sparrow:x", "shelf:2", ""])
def test_parse_nest_refuses_a_bad_spec(spec):
    with pytest.raises(ParameterError) as err:
        nest.parse_nest(spec)
    assert err.value.name == "nest"


def test_auto_falls_back_to_the_shelves(monkeypatch):
    assert nest.choose_nester("auto", None) == ("shelf", 0)
    monkeypatch.setattr(nest, "have_sparrow", lambda: False)
    assert nest.choose_nester("auto", (5.0, 3.5)) == ("shelf", 0)
    with pytest.raises(ParameterError, match=r"filletfold\[nest\]"):
        nest.choose_nester("sparrow", (5.0, 3.5))
    monkeypatch.setattr(nest, "have_sparrow", lambda: True)
    assert nest.choose_nester("auto:4", (5.0, 3.5)) == ("sparrow", 4)


def test_cli_errors_are_one_line(tmp_path, capsys, monkeypatch):
    out = str(tmp_path / "c")
    assert main(["round", "cube", "--nest", "sparrow", "-o", out]) == 2
    err = capsys.readouterr().err
    assert "give a sheet size (--sheet)" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert main(["round", "cube", "--sheet", "A4", "--nest", "rows", "-o", out]) == 2
    assert "nest must be 'shelf', 'sparrow', 'auto'" in capsys.readouterr().err
    monkeypatch.setattr(nest, "have_sparrow", lambda: False)
    assert main(["round", "cube", "--sheet", "A4", "--nest", "sparrow", "-o", out]) == 2
    err = capsys.readouterr().err
    assert "pip install 'filletfold[nest]'" in err and len(err.strip().splitlines()) == 1


@needs_sparrow
def test_cli_nest_sparrow_reports_the_nester(tmp_path, capsys):
    out = tmp_path / "c"
    args = ["round", "cube", "--sheet", "A4", "--units", "mm", "--scale", "30"]
    assert main([*args, "--nest", "sparrow", "-o", str(out), "--format", "json"]) == 0
    fab = json.loads((out / "report.json").read_text())["fabrication"]
    assert fab["nesting"]["nester"] == "sparrow"
    use = f"{fab['nesting']['material_use']:.0%}"
    assert f"sheets: {fab['sheets']} (sparrow, material use {use})" in capsys.readouterr().out
    assert fab["sheets"] == len(fab["pieces_per_sheet"]) == len(fab["material_use"])
    assert 0 < fab["nesting"]["material_use"] <= fab["nesting"]["strip_use"] <= 1


@pytest.mark.parametrize("fault", ["overlap", "more sheets"])
def test_a_bad_or_worse_nesting_gives_way_to_the_shelves(monkeypatch, fault):
    from filletfold.layout import arrange

    pieces = [_square(1.0), _square(1.0, (5, 0))]
    original = [p.arrays()[0].copy() for p in pieces]
    sheet, gap = (5.0, 3.5), 0.1

    def fake(pieces, sheet, gap, seconds):
        for p in pieces:  # turned, as nest_on_sheets does
            p.points_2d = list(p.arrays()[0] @ nest.turn(90).T)
        if fault == "overlap":
            return np.zeros((2, 2)), np.array([[0.0, 0.0, 5.0, 3.5]]), np.zeros(2, int), 1
        boxes = np.array([[0.0, 0.0, 5.0, 3.5], [6.0, 0.0, 11.0, 3.5]])
        return np.array([[2.0, 1.0], [8.0, -4.0]]), boxes, np.arange(2), 1

    monkeypatch.setattr(nest, "have_sparrow", lambda: True)
    monkeypatch.setattr(arrange, "nest_on_sheets", fake)
    offsets, boxes, sheet_of, nesting = arrange.place_on_sheets(pieces, sheet, gap, "sparrow")
    assert nesting["nester"] == "shelf" and len(boxes) == 1
    assert ("placement refused" if fault == "overlap" else "more sheets") in nesting["note"]
    for p, ref in zip(pieces, original, strict=True):
        assert np.array_equal(p.arrays()[0], ref)
    assert nest.placement_errors(pieces, offsets, boxes, sheet_of, gap) == []
