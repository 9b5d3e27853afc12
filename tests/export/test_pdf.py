"""The PDF writer (:mod:`filletfold.export.pdf`): pages at true scale, tiles and marks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from filletfold.errors import ParameterError
from filletfold.export import pattern_pdf
from filletfold.export.pdf import MAX_PAGES, REGION_PAD_MM, pdf_tiles
from filletfold.units import sheet_size_mm

from ..conftest import tiny_square
from .conftest import arc_pattern, pdf_pages

SVG_NS = "{http://www.w3.org/2000/svg}"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- PDF


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
    # what is drawn on each sheet, tiled (its box, 260 x 290 mm, would take 4 pages)
    per_sheet = [sum(t.region == r for t in tiles) for r in (0, 1)]
    assert [t.region for t in tiles] == [0] * per_sheet[0] + [1] * per_sheet[1]
    whole = math.ceil((260.0 + 4.0) / 190.0) * math.ceil((290.0 + 4.0) / 277.0)
    assert 1 <= min(per_sheet) and max(per_sheet) < whole
    assert pdf_pages(pattern_pdf(pattern, units="mm", scale=100.0)) == len(tiles)


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


def test_a_sheet_prints_what_is_drawn_on_it_on_pages_turned_to_fit():
    """Pieces lie inside their sheet by a gap: the drawing on an A4 sheet fits one A4
    page's printable area, turned for a landscape sheet (the sheet's box with the printer's
    margins took two or four pages)."""
    import filletfold

    design = filletfold.round_mesh("icosahedron", sheet="A4")
    p = design.params
    sheets = np.asarray(design.pattern.annotations.sheets) * p.mm_per_unit
    tiles = pdf_tiles(design.pattern, page="A4", units=p.units, scale=p.scale)
    assert len(tiles) == len(sheets) == 3 and [t.region for t in tiles] == [0, 1, 2]
    assert any(t.landscape for t in tiles)  # a drawing wider than a portrait page
    for tile in tiles:
        x0, y0, x1, y1 = sheets[tile.region]
        bx0, _, _, by1 = tile.box  # tiled from the drawing's top left, on its sheet
        assert x0 - 2.5 <= bx0 < x1 and y0 < by1 <= y1 + 2.5
    data = pattern_pdf(design.pattern, page="A4", units=p.units, scale=p.scale)
    assert pdf_pages(data) == 3
