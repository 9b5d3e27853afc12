"""Sheet sizes and drawing units: one table each, the same answer from every path."""

from __future__ import annotations

import io
import json
import re

import ezdxf
import pytest
from numpy.testing import assert_allclose

import filletfold
from filletfold.cli import main
from filletfold.errors import ParameterError
from filletfold.export.cutfiles import cut_files, fit_page_scale
from filletfold.export.dxf import DXF_INSUNITS, pattern_dxf
from filletfold.export.pdf import pattern_pdf
from filletfold.export.svg import pattern_svg
from filletfold.units import (
    CUT_FILE_UNITS,
    MM_PER_UNIT,
    SHEET_SIZES_MM,
    check_units,
    sheet_size_mm,
)

from .conftest import tiny_square

PT_PER_MM = 72.0 / 25.4
SHEETS = [*SHEET_SIZES_MM, "600x400"]


def media_boxes(data: bytes) -> list[tuple[float, float]]:
    """(width, height) in points of every page of a PDF."""
    boxes = re.findall(rb"/MediaBox\s*\[\s*0\s+0\s+([\d.]+)\s+([\d.]+)\s*\]", data)
    return [(float(w), float(h)) for w, h in boxes]


def sheet_error(sheet) -> str:
    """The message :func:`sheet_size_mm` refuses ``sheet`` with."""
    with pytest.raises(ParameterError) as info:
        sheet_size_mm(sheet)
    return str(info.value)


def one_error_line(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    return err.strip()


# ---------------------------------------------------------------- the parser


@pytest.mark.parametrize("name", list(SHEET_SIZES_MM))
def test_named_sheets_in_any_case(name):
    size = SHEET_SIZES_MM[name]
    assert sheet_size_mm(name) == size
    assert sheet_size_mm(f" {name.lower()} ") == size
    assert sheet_size_mm(name.upper(), name="page") == size


def test_a1_is_listed():
    assert sheet_size_mm("A1") == (594.0, 841.0)


@pytest.mark.parametrize(
    ("text", "size"),
    [
        ("600x400", (600.0, 400.0)),
        ("600 X 400 mm", (600.0, 400.0)),
        ("600×400", (600.0, 400.0)),
        ("12.5x.5", (12.5, 0.5)),
    ],
)
def test_custom_sheets(text, size):
    assert_allclose(sheet_size_mm(text), size, rtol=0, atol=0)


@pytest.mark.parametrize(
    ("sheet", "match"),
    [
        ("B5", r"sheet must be one of A4, A3, A2, A1, Letter, Legal or 'WxH' .*got 'B5'"),
        ("600x", "sheet must be one of"),
        ("600x400x3", "sheet must be one of"),
        ("-1x100", "sheet must be one of"),
        ("0x100", "sheet size must be positive, got '0x100'"),
        (4, "sheet must be a string, got int"),
    ],
)
def test_bad_sheets_name_the_parameter(sheet, match):
    with pytest.raises(ParameterError, match=match) as info:
        sheet_size_mm(sheet)
    assert info.value.name == "sheet"
    with pytest.raises(ParameterError, match=match.replace("sheet", "page")) as info:
        sheet_size_mm(sheet, name="page")
    assert info.value.name == "page"


def test_units_table():
    assert MM_PER_UNIT["in"] == 25.4
    assert MM_PER_UNIT["pt"] * 72.0 == pytest.approx(25.4, rel=1e-15)
    assert set(CUT_FILE_UNITS) <= set(MM_PER_UNIT)
    # the DXF can write every cut-file unit, and nothing else
    assert set(DXF_INSUNITS) == {"", *CUT_FILE_UNITS}


@pytest.mark.parametrize(
    ("units", "choices", "unitless", "ok"),
    [
        ("mm", CUT_FILE_UNITS, False, True),
        ("", CUT_FILE_UNITS, True, True),
        ("", CUT_FILE_UNITS, False, False),
        ("pt", CUT_FILE_UNITS, True, False),
        ("pt", MM_PER_UNIT, False, True),
        ("ft", MM_PER_UNIT, True, False),
        (None, CUT_FILE_UNITS, True, False),
    ],
)
def test_check_units(units, choices, unitless, ok):
    if ok:
        assert check_units(units, choices, unitless=unitless) == units
        return
    with pytest.raises(ParameterError, match=f"units must be one of .*got {units!r}") as info:
        check_units(units, choices, unitless=unitless)
    assert info.value.name == "units"
    assert ("or '' (unitless)" in str(info.value)) == unitless


def test_every_writer_takes_the_same_units():
    pattern = tiny_square()
    for units in CUT_FILE_UNITS:
        pattern_dxf(pattern, units=units)
        pattern_svg(pattern, units=units)
        pattern_pdf(pattern, units=units, scale=1.0)
        cut_files(pattern, "dxf,svg,pdf", units=units)
    for writer in (pattern_dxf, pattern_svg, pattern_pdf, cut_files):
        with pytest.raises(ParameterError, match="units must be one of mm, cm, m, in"):
            writer(pattern, units="ft")


# ---------------------------------------------------------------- through the CLI


def test_cli_round_a1_pdf(tmp_path):
    out = tmp_path / "a1"
    assert main(["round", "cube", "-q", "-o", str(out), "--sheet", "A1", "--format", "pdf"]) == 0
    boxes = media_boxes((out / "pattern.pdf").read_bytes())
    assert boxes
    for box in boxes:
        assert_allclose(box, [594.0 * PT_PER_MM, 841.0 * PT_PER_MM], atol=0.01)


#: The sheets the fast tier writes every cut format on (an ISO, a US and a custom size); the
#: slow tier runs the others too (1.6 s each).
FAST_SHEETS = ("A4",)  # the others in the slow tier (the fast one under 3 minutes)


@pytest.mark.parametrize(
    "sheet", [s if s in FAST_SHEETS else pytest.param(s, marks=pytest.mark.slow) for s in SHEETS]
)
def test_cli_round_every_sheet_every_cut_format(sheet, tmp_path):
    out = tmp_path / "d"
    args = ["round", "cube", "-q", "-o", str(out), "--sheet", sheet, "--units", "mm"]
    assert main([*args, "--scale", "30", "--format", "json,pdf,svg,dxf,png"]) == 0
    width, height = sheet_size_mm(sheet)
    report = json.loads((out / "report.json").read_text())
    n_sheets = report["fabrication"]["sheets"]
    assert n_sheets >= 1
    side = sorted([width / 30, height / 30])  # a sheet may be laid landscape
    assert_allclose(sorted(report["fabrication"]["sheet_size"]), side, rtol=1e-12)
    # the PDF: pages of the sheet's size
    for box in media_boxes((out / "pattern.pdf").read_bytes()):
        assert_allclose(box, [width * PT_PER_MM, height * PT_PER_MM], atol=0.01)
    # the SVG: one outline per sheet, of the sheet's size in mm (a pattern unit is 30 mm)
    svg = (out / "pattern.svg").read_text()
    group = svg.split('<g id="sheets"', 1)[1].split("</g>", 1)[0]
    rects = re.findall(r'width="([\d.]+)" height="([\d.]+)"', group)
    assert len(rects) == n_sheets
    view_w = float(re.search(r'viewBox="0 0 ([\d.]+)', svg).group(1))
    user = view_w / float(re.search(r'width="([\d.]+)mm"', svg).group(1))  # user units per mm
    sides = [sorted(float(v) / user for v in r) for r in rects]
    assert_allclose(sides, [sorted([width, height])] * n_sheets, atol=2e-3)
    # the DXF read back, in mm; the PNG a picture
    doc = ezdxf.read(io.StringIO((out / "pattern.dxf").read_text()))
    assert doc.header["$INSUNITS"] == 4
    assert (out / "pattern.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


def cli_errors(tmp_path, capsys, sheet: str) -> dict[str, str]:
    """The error line of every CLI path that takes ``--sheet``, each refused before writing."""
    design = tmp_path / "design"
    assert main(["round", "cube", "-q", "-o", str(design), "--format", "fold"]) == 0
    capsys.readouterr()
    before = sorted(p.name for p in design.iterdir())
    paths = {
        "round": ["round", "cube", "-q", "-o", str(tmp_path / "r1")],
        "round pdf": ["round", "cube", "-q", "-o", str(tmp_path / "r2"), "--format", "pdf"],
        "round svg": ["round", "cube", "-q", "-o", str(tmp_path / "r3"), "--format", "svg"],
        "export": ["export", str(design)],
        "export svg": ["export", str(design), "--format", "svg"],
    }
    errors = {}
    for what, args in paths.items():
        assert main([*args, "--sheet", sheet]) == 2, what
        errors[what] = one_error_line(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design"]
    assert sorted(p.name for p in design.iterdir()) == before
    return errors


@pytest.mark.parametrize("sheet", ["B5", "0x100"])
def test_unknown_sheet_same_error_everywhere(sheet, tmp_path, capsys):
    expected = sheet_error(sheet)
    errors = cli_errors(tmp_path, capsys, sheet)
    assert set(errors.values()) == {f"error: {expected}"}, errors


def test_unknown_sheet_same_error_in_the_library():
    pattern = tiny_square()
    expected = sheet_error("B5")
    with pytest.raises(ParameterError) as info:
        filletfold.round_mesh("cube", sheet="B5")
    assert str(info.value) == expected
    for call in (
        lambda: pattern_pdf(pattern, page="B5"),
        lambda: cut_files(pattern, "pdf", page="B5"),
        lambda: fit_page_scale(pattern, page="B5"),
    ):
        with pytest.raises(ParameterError) as info:
            call()
        assert info.value.name == "page"
        assert str(info.value) == expected.replace("sheet must", "page must")
