"""``--size``: the object's physical size sets the drawing units and scale."""

from __future__ import annotations

import json

import numpy as np
import pytest

import filletfold
from filletfold.cli import main
from filletfold.errors import ParameterError
from filletfold.parameters import Parameters, sized
from filletfold.units import parse_size


@pytest.mark.parametrize(
    ("text", "mm", "unit"),
    [
        ("300mm", 300.0, "mm"),
        ("30 cm", 300.0, "cm"),
        ("0.3m", 300.0, "m"),
        ("12in", 304.8, "in"),
        ("250", 250.0, "mm"),
        (120, 120.0, "mm"),
    ],
)
def test_a_size_is_a_length_with_a_unit(text, mm, unit):
    assert parse_size(text) == (pytest.approx(mm), unit)


@pytest.mark.parametrize("text", ["3ft", "-1mm", "0", "0mm", "", "mm", True, None, "1e400mm"])
def test_a_bad_size_is_refused_naming_it(text):
    with pytest.raises(ParameterError, match="size"):
        parse_size(text)


def test_sized_derives_units_and_scale_from_the_extent():
    assert sized(Parameters(size=None), 2.0) == Parameters(size=None)  # no size: unchanged
    assert sized(Parameters(), 2.0, 0.1) == Parameters()  # the default: the layout settles it
    # the default with units or a scale given is no size (the mesh is in those units), and
    # so it is for a mesh of no extent
    assert sized(Parameters(units="mm"), 2.0, 0.1) == Parameters(units="mm", size=None)
    assert sized(Parameters(scale=3.0), 2.0, 0.1) == Parameters(scale=3.0, size=None)
    assert sized(Parameters(), 0.0, 0.0) == Parameters(size=None)
    p = sized(Parameters(size="300mm"), 2.0)
    assert (p.units, p.scale) == ("mm", pytest.approx(150.0))
    p = sized(Parameters(size="300mm", units="cm"), 2.0)
    assert (p.units, p.scale) == ("cm", pytest.approx(15.0))
    p = sized(Parameters(size="12in"), 3.0)
    assert (p.units, p.scale) == ("in", pytest.approx(4.0))


def test_a_sized_design_has_the_size_and_says_so():
    design = filletfold.round_mesh("icosahedron", size="30cm")
    extent = float(np.ptp(design.mesh.vertices, axis=0).max())
    assert design.params.units == "cm"
    assert design.params.scale * extent == pytest.approx(30.0)
    line = next(x for x in design.summary().splitlines() if x.startswith("size: 30cm"))
    assert "1 unit = 18.54 cm" in line and "the smallest piece spans" in line


def test_round_with_size_writes_the_cut_files_at_that_size(tmp_path):
    out = tmp_path / "ico"
    args = ["round", "icosahedron", "--size", "300mm", "-q", "-f", "svg,json", "-o", str(out)]
    assert main(args) == 0
    report = json.loads((out / "report.json").read_text())
    p = report["parameters"]
    assert (p["size"], p["units"]) == ("300mm", "mm")
    assert p["scale"] == pytest.approx(300.0 / ((1 + 5**0.5) / 2), rel=1e-12)  # extent phi
    svg = (out / "pattern.svg").read_text()
    assert 'mm" height="' in svg  # a drawing in millimetres


def test_size_and_scale_together_are_refused_in_one_line(capsys):
    assert main(["round", "cube", "--size", "300mm", "--scale", "2", "--dry-run"]) != 0
    err = capsys.readouterr().err
    assert "--size or --scale" in err and "Traceback" not in err


def test_pieces_under_the_minimum_are_reported_and_warned_of():
    from filletfold.export.outputs import MIN_PIECE_MM, piece_sizes_mm, piece_spans

    plain = filletfold.round_mesh("icosahedron", size=None)
    assert piece_sizes_mm(plain) is None  # no units: no physical size
    assert not any("warning: " in x and " mm" in x for x in plain.summary().splitlines())
    big = filletfold.round_mesh("icosahedron", units="cm", scale=10.0)
    spans = piece_spans(big.pattern)
    assert len(spans) == big.pattern.n_pieces and np.all(spans > 0)
    sizes = piece_sizes_mm(big)
    assert sizes["smallest_piece_mm"] == pytest.approx(spans.min() * 100.0)
    assert sizes["pieces_under_min"] == 0 and sizes["min_piece_mm"] == MIN_PIECE_MM
    tiny = filletfold.round_mesh("icosahedron", size="4mm", layout="modules")  # ~2.5 mm each
    sizes = piece_sizes_mm(tiny)
    assert sizes["pieces_under_min"] == tiny.pattern.n_pieces == 12
    assert sizes["smallest_piece_mm"] < MIN_PIECE_MM
    assert "warning: 12 of 12 pieces span less than 3 mm" in tiny.summary()


def test_the_report_gives_the_smallest_piece_at_the_drawing_size(tmp_path):
    out = tmp_path / "cube"
    assert main(["round", "cube", "--units", "mm", "--scale", "30", "-q", "-o", str(out)]) == 0
    fab = json.loads((out / "report.json").read_text())["fabrication"]
    assert fab["pieces_under_min"] == 0 and fab["smallest_piece_mm"] > 3.0
    out = tmp_path / "plain"
    assert main(["round", "cube", "-q", "-o", str(out), "--size", "none"]) == 0
    assert "smallest_piece_mm" not in json.loads((out / "report.json").read_text())["fabrication"]


def test_tabs_and_labels_have_a_physical_height_and_low_ones_are_warned_of():
    from filletfold.export.outputs import MIN_LABEL_MM, piece_sizes_mm
    from filletfold.layout.arrange import TAB_MM

    # with units, full tabs are TAB_MM on the sheet and labels 0.45 of them, at any size
    for size in ("40mm", "300mm"):
        design = filletfold.round_mesh("icosahedron", size=size)
        # (label heights are written to 3 digits in pattern units)
        assert piece_sizes_mm(design)["smallest_label_mm"] == pytest.approx(0.45 * TAB_MM, rel=5e-3)
        assert "warning: labels" not in design.summary()
    # a drawing too small for them: tabs at most half an edge, and the labels warned of
    small = filletfold.round_mesh("icosahedron", size="4mm")
    label = piece_sizes_mm(small)["smallest_label_mm"]
    edge_mm = small.mesh.mean_edge_length * small.params.scale
    assert label == pytest.approx(0.45 * 0.5 * edge_mm, rel=5e-3) and label < MIN_LABEL_MM
    assert f"warning: labels {label:.3g} mm high" in small.summary()
    # without units: a share of the mean edge length
    plain = filletfold.round_mesh("icosahedron", size=None)
    heights = np.asarray(plain.pattern.annotations.labels.height)
    assert heights.min() == pytest.approx(0.45 * 0.04 * plain.mesh.mean_edge_length, rel=5e-3)


def test_a_nearly_flat_mesh_is_warned_of_and_nets_join_it():
    from filletfold.export.outputs import FLAT_RATIO, thickness_ratio

    square = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    assert thickness_ratio(square) == 0.0
    assert thickness_ratio(np.vstack([square, [[0.5, 0.5, 0.01]]])) == pytest.approx(0.01)
    flat = filletfold.round_mesh("miura:4x4,fold=0.05", layout="modules")
    assert thickness_ratio(flat.mesh.vertices) < FLAT_RATIO
    assert "warning: the mesh is nearly flat" in flat.summary()
    joined = filletfold.round_mesh("miura:4x4,fold=0.05")  # nets, by default
    assert joined.pattern.n_pieces < flat.pattern.n_pieces
    assert "nearly flat" not in joined.summary()
    assert "nearly flat" not in filletfold.round_mesh("miura").summary()  # folded: 16 %


def test_cut_and_fold_lengths_and_areas():
    from filletfold.export.outputs import cut_and_fold

    bare = filletfold.round_mesh("cube", tabs=False)
    p = bare.pattern
    work = cut_and_fold(p)
    length = np.linalg.norm(p.vertices_2d[p.edges[:, 0]] - p.vertices_2d[p.edges[:, 1]], axis=1)
    assert work["cut_length"] == pytest.approx(length[p.edge_assignment == "B"].sum())
    assert work["fold_length"] == pytest.approx(
        length[np.isin(p.edge_assignment, ["M", "V"])].sum()
    )
    # the pattern is the folded form's development: the same area in 3D, up to what the chords
    # across bent facets lose (a facet's diagonals are shorter folded than flat)
    area3 = sum(
        0.5
        * np.linalg.norm(
            sum(
                np.cross(p.vertices_3d[f[k]], p.vertices_3d[f[(k + 1) % len(f)]])
                for k in range(len(f))
            )
        )
        for f in p.faces
    )
    assert work["piece_area"] == pytest.approx(area3, rel=1e-3)
    assert "sheet_area" not in work
    tabbed = cut_and_fold(filletfold.round_mesh("cube").pattern)
    assert tabbed["cut_length"] > work["cut_length"] and tabbed["fold_length"] == pytest.approx(
        work["fold_length"]
    )
    sheets = filletfold.round_mesh("cube", sheet="A4", units="mm", scale=30.0)
    n = len(sheets.pattern.annotations.sheets)
    assert cut_and_fold(sheets.pattern)["sheet_area"] == pytest.approx(n * 210 * 297 / 30**2)
    assert "to make: " in sheets.summary() and " m² of sheets" in sheets.summary()


@pytest.mark.parametrize(
    ("x", "up"), [(614.2, 620.0), (100.0, 100.0), (100.4, 110.0), (1234.0, 1300.0), (88.9, 89.0)]
)
def test_a_default_size_is_rounded_up_to_two_digits(x, up):
    from filletfold.units import ceil_digits

    assert ceil_digits(x) == pytest.approx(up)


def test_the_default_size_is_the_largest_of_its_three_bounds():
    from filletfold.layout.arrange import TAB_MAX, default_size
    from filletfold.layout.tabs import LABEL_SHARE
    from filletfold.units import LEAST_SIZE_MM, MIN_LABEL_MM, MIN_PIECE_MM

    assert default_size(10.0, 1.0) == (LEAST_SIZE_MM, "least")  # labels need 88.9 mm
    labels = 10.0 * MIN_LABEL_MM / (LABEL_SHARE * TAB_MAX * 0.1)  # 888.9 mm
    assert default_size(10.0, 0.1) == (pytest.approx(890.0), "labels") and labels < 890
    assert default_size(10.0, 0.1, smallest=0.05) == (pytest.approx(890.0), "labels")
    pieces = 10.0 * MIN_PIECE_MM / 0.01  # 3000 mm
    assert default_size(10.0, 0.1, smallest=0.01) == (pytest.approx(pieces), "pieces")


def test_the_default_size_is_set_by_the_smallest_laid_out_piece():
    from filletfold.layout.arrange import settle_size, smallest_span
    from filletfold.surface.piece import Piece

    square = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    big = Piece(0, square * 5.0, np.zeros((4, 3)), [[0, 1, 2, 3]])
    # a piece of two triangles 0.2 across, and a point its faces do not use
    small = Piece(
        1, np.vstack([square * 0.2, [[9.0, 9.0]]]), np.zeros((5, 3)), [[0, 1, 2], [0, 2, 3]]
    )
    assert smallest_span([big, small]) == pytest.approx(0.2)
    assert smallest_span([Piece(2)]) is None
    p, default = settle_size(Parameters(), 10.0, 1.0, [big, small])
    assert default == {"size": "150mm", "binding": "pieces"}  # 0.2 units are 3 mm at 150 mm
    assert (p.size, p.units, p.scale) == ("150mm", "mm", pytest.approx(15.0))
    # on sheets, the pieces were fitted at the labels' size: only the labels and least bound
    assert settle_size(Parameters(), 10.0, 1.0, None)[1] == {"size": "100mm", "binding": "least"}
    # a size given stays as it is
    assert settle_size(Parameters(size="50mm"), 10.0, 1.0, [small]) == (
        Parameters(size="50mm"),
        None,
    )


def test_by_default_every_label_and_piece_can_be_made_and_the_summary_says_the_size():
    """A capsule of 66 vertices: its smallest piece sets the default size, 110 mm; at it every
    label is 2 mm high and every piece spans 3 mm; at less, pieces are too small."""
    import trimesh

    from filletfold.export.outputs import piece_sizes_mm
    from filletfold.units import MIN_LABEL_MM, MIN_PIECE_MM

    capsule = trimesh.creation.capsule(height=6.0, radius=0.5, count=[8, 8])
    mesh = (capsule.vertices, capsule.faces)
    design = filletfold.round_mesh(mesh, layout="modules")
    assert design.fabrication["default_size"] == {"size": "110mm", "binding": "pieces"}
    assert (design.params.size, design.params.units) == ("110mm", "mm")
    extent = float(np.ptp(design.mesh.vertices, axis=0).max())
    assert design.params.scale * extent == pytest.approx(110.0)
    sizes = piece_sizes_mm(design)
    # (label heights are written to 3 digits)
    assert sizes["smallest_label_mm"] >= MIN_LABEL_MM * (1 - 5e-4)
    assert sizes["pieces_under_min"] == 0 and sizes["smallest_piece_mm"] >= MIN_PIECE_MM
    line = next(x for x in design.summary().splitlines() if x.startswith("size: 110mm"))
    assert "the default: the least with every piece 3 mm across; --size to choose" in line
    assert "warning" not in design.summary()
    smaller = filletfold.round_mesh(mesh, layout="modules", size="100mm", reuse=design)
    assert piece_sizes_mm(smaller)["pieces_under_min"] > 0
    assert "pieces span less than 3 mm" in smaller.summary() and "default" not in smaller.summary()


def test_the_default_size_on_the_command_line_and_how_to_go_without(tmp_path):
    out = tmp_path / "cube"
    assert main(["round", "cube", "-q", "-f", "svg,json", "-o", str(out)]) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["fabrication"]["default_size"] == {"size": "100mm", "binding": "least"}
    assert (report["parameters"]["size"], report["parameters"]["units"]) == ("100mm", "mm")
    assert report["parameters"]["scale"] == pytest.approx(100.0)  # the cube's side is 1
    assert 'mm" height="' in (out / "pattern.svg").read_text()
    # --size none: unitless; --units alone: the mesh is in those units (1 unit = 1 mm)
    for args, units, scale in ((["--size", "none"], "", None), (["--units", "mm"], "mm", None)):
        out = tmp_path / (units or "unitless")
        assert main(["round", "cube", "-q", "-f", "json", "-o", str(out), *args]) == 0
        report = json.loads((out / "report.json").read_text())
        p = report["parameters"]
        assert (p["size"], p["units"], p["scale"]) == (None, units, scale)
        assert "default_size" not in report["fabrication"]


def test_a_default_size_on_sheets_fits_the_pieces_again_when_they_ask_more(monkeypatch):
    """On sheets the pieces are fitted at the labels' size first; when they need a larger
    size, they are fitted again at it, unless a module would not fit a sheet there."""
    from filletfold.layout import arrange
    from filletfold.layout.arrange import spacing
    from filletfold.units import sheet_size_mm

    tab, gap, box, room = spacing(Parameters(units="mm", scale=10.0, sheet="A4"), 1.0)
    assert (tab, gap) == (pytest.approx(0.5), pytest.approx(1.35))  # 5 mm tabs, in units
    assert box == pytest.approx((21.0, 29.7)) and room == pytest.approx((17.3, 26.0))
    with pytest.raises(ParameterError, match="too small for any piece"):
        spacing(Parameters(units="mm", scale=1000.0, sheet="A4"), 1.0)
    plain = filletfold.round_mesh("icosahedron", sheet="A4", layout="modules")
    assert plain.fabrication["default_size"] == {"size": "100mm", "binding": "least"}
    monkeypatch.setattr(arrange, "MIN_PIECE_MM", 120.0)  # pieces 120 mm across (63 at 100)
    big = filletfold.round_mesh("icosahedron", sheet="A4", layout="modules")
    assert big.fabrication["default_size"]["binding"] == "pieces"
    from filletfold.export.outputs import piece_spans

    mm = piece_spans(big.pattern) * big.params.mm_per_unit
    assert mm.min() >= 120.0 and big.params.scale > plain.params.scale
    w, h = sheet_size_mm("A4")  # every piece on a sheet of that size
    sheets = np.asarray(big.pattern.annotations.sheets) * big.params.mm_per_unit
    assert np.allclose(np.sort(sheets[:, 2:] - sheets[:, :2], axis=1), [w, h])
    monkeypatch.setattr(arrange, "MIN_PIECE_MM", 2000.0)  # a module would not fit A4
    kept = filletfold.round_mesh("icosahedron", sheet="A4", layout="modules")
    assert kept.fabrication["default_size"] == {"size": "100mm", "binding": "least"}


def test_a_design_on_many_sheets_is_warned_of(monkeypatch):
    from filletfold.export import outputs

    design = filletfold.round_mesh("cube", sheet="A4", layout="modules", size="150mm")
    n = len(design.pattern.annotations.sheets)
    assert n > 1 and "sheets are more than" not in design.summary()
    monkeypatch.setattr(outputs, "MANY_SHEETS", n - 1)
    assert f"warning: {n} sheets are more than a person prints" in design.summary()
