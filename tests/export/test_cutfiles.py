"""Cut files and pictures: DXF, PDF, PNG, annotations in SVG, reading FOLD back, the export CLI."""

from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET

import pytest
from numpy.testing import assert_allclose

from filletfold.cli import main
from filletfold.errors import ParameterError
from filletfold.export import (
    cut_files,
    fold_document,
    fold_json,
    parse_formats,
)
from filletfold.export.cutfiles import ALL_FORMATS, fit_page_scale, scaled_pattern

from ..conftest import tiny_square
from .conftest import arc_pattern, check_lengths, pdf_pages, read_dxf

SVG_NS = "{http://www.w3.org/2000/svg}"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


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
        "annotations.json",
        "simulator.fold",
        "simulator.svg",
        "report.json",
        "folded.obj",
        "pattern.svg",
        "pattern.dxf",
        "pattern.pdf",
        "pattern.png",
        "preview.png",
        "pattern.3dm",
        "folded.3dm",
        "folded.glb",
        "folded.ply",
        "folded.stl",
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
        "annotations.json",
        "simulator.fold",
        "simulator.svg",
        "report.json",
        "folded.obj",
        "pattern.svg",
        "pattern.dxf",
        "pattern.pdf",
        "pattern.png",
        "preview.png",
        "pattern.3dm",
        "folded.3dm",
        "folded.glb",
        "folded.ply",
        "folded.stl",
        "assembly.txt",
        "assembly.pdf",
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


def test_cli_export_writes_the_simulator_files(tmp_path, capsys):
    """From a design folder, as Origami Simulator needs them: triangles only, the folded
    form in its frame, and the SVG in the app's colours."""
    folder = tmp_path / "miura"
    assert main(["round", "miura", "--material-loss", "-o", str(folder), "-q"]) == 0
    assert main(["export", str(folder), "--format", "simulator"]) == 0
    assert "wrote 2 files" in capsys.readouterr().out
    doc = json.loads((folder / "simulator.fold").read_text())
    fine = json.loads((folder / "design.fold").read_text())
    assert {len(f) for f in doc["faces_vertices"]} == {3}
    assert len(doc["vertices_coords"]) < len(fine["vertices_coords"]) / 2
    assert len(doc["file_frames"][0]["vertices_coords"]) == len(doc["vertices_coords"])
    svg = (folder / "simulator.svg").read_text()
    assert 'stroke="#ff0000"' in svg and 'stroke="#0000ff"' in svg and 'stroke="#ff00ff"' not in svg


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


@pytest.mark.slow  # every format, written by the command: the fast tier under 3 minutes
def test_cli_round_with_all_formats(tmp_path, capsys):
    out = tmp_path / "cube"
    args = ["round", "cube", "-o", str(out), "-q", "--format", "all", "--units", "cm"]
    assert main([*args, "--sheet", "A3"]) == 0
    assert "wrote 19 files" in capsys.readouterr().out  # assembly.pdf with the pdf
    assert (out / "pattern.pdf").read_bytes().startswith(b"%PDF")
    assert read_dxf((out / "pattern.dxf").read_text()).header["$INSUNITS"] == 5


def test_cli_round_bad_format_fails_before_solving(tmp_path, capsys):
    assert main(["round", "cube", "-o", str(tmp_path / "x"), "--format", "fold,step"]) == 2
    assert "unknown format 'step'" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
