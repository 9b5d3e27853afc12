"""Cutter presets (:mod:`filletfold.export.presets`) in the SVG and DXF, read back."""

from __future__ import annotations

import itertools
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from filletfold.cli import main
from filletfold.errors import ParameterError
from filletfold.export import pattern_dxf, pattern_svg
from filletfold.export.cutfiles import cut_files, scaled_pattern
from filletfold.export.paths import dash_polylines, polyline_length
from filletfold.export.presets import (
    DEFAULT_PRESET,
    PRESETS,
    RESOLUTION_MM,
    Pen,
    dxf_lineweight,
    get_preset,
    hex_rgb,
)

from .conftest import arc_pattern, read_dxf

SVG_NS = "{http://www.w3.org/2000/svg}"
#: Group of each pen role in the SVG.
GROUP = {"cut": "border", "mountain": "mountain", "valley": "valley", "tab": "tab-hinge"}


def mm_pattern():
    """The annotated half annulus at 40 mm per unit (radii 40-100 mm), drawn in mm."""
    return scaled_pattern(arc_pattern(annotated=True), 40.0)


def svg_groups(text: str) -> tuple[dict, float]:
    """The SVG's groups by id and its user units per mm."""
    root = ET.fromstring(text)
    user = float(root.get("viewBox").split()[2]) / float(root.get("width")[:-2])
    return {g.get("id"): g for g in root.iter(SVG_NS + "g")}, user


def points(el) -> np.ndarray:
    return np.array([list(map(float, p.split(","))) for p in el.get("points").split()])


def test_get_preset_names_and_errors():
    assert get_preset().name == DEFAULT_PRESET == "print"
    assert get_preset(" Laser ") is PRESETS["laser"]
    assert get_preset(PRESETS["card"]) is PRESETS["card"]
    assert {"print", "origami-simulator", "laser", "plotter", "card"} <= set(PRESETS)
    with pytest.raises(ParameterError, match="unknown preset 'x': choose from print, origami"):
        get_preset("x")
    with pytest.raises(ParameterError, match="colour"):
        Pen("red", "CUT", 1, 0.1)
    with pytest.raises(ParameterError, match="not several"):
        Pen("#ff0000", "CUT", 1, 0.1, dash_mm=(1.0, 1.0), perforation_mm=(1.0, 1.0))


def test_lineweights_and_colours():
    assert dxf_lineweight(0.01) == 0  # a hairline
    assert dxf_lineweight(0.25) == 25
    assert dxf_lineweight(0.3) == 30
    assert hex_rgb("#00a0ff") == (0, 160, 255)
    for p in PRESETS.values():
        assert len({pen.layer for pen in p.pens().values()}) == 6
    for pen in PRESETS["laser"].pens().values():
        assert 0.01 <= pen.width_mm <= 0.025  # laser hairlines


@pytest.mark.parametrize("name", list(PRESETS))
def test_svg_follows_preset_colours_and_widths(name):
    preset = PRESETS[name]
    groups, user = svg_groups(pattern_svg(mm_pattern(), units="mm", preset=name))
    for role, gid in GROUP.items():
        pen = getattr(preset, role)
        g = groups[gid]
        assert float(g.get("stroke-width")) == pytest.approx(pen.width_mm * user)
        assert len(g) > 0
        assert {el.get("stroke") for el in g} == {pen.color}, (name, gid)
        if pen.dash_mm is not None:
            dash = list(map(float, g.get("stroke-dasharray").split()))
            assert dash == pytest.approx([x * user for x in pen.dash_mm])
    assert groups["labels"].get("fill") == preset.label.color
    assert ("flat" in groups) == preset.flat_edges
    assert ("legend" in groups) == preset.annotations
    if preset.join_lines:  # cutter presets: whole paths, not one line per edge
        assert not groups["mountain"].findall(SVG_NS + "line")


@pytest.mark.parametrize("name", list(PRESETS))
def test_dxf_follows_preset_layers(name):
    preset = PRESETS[name]
    doc = read_dxf(pattern_dxf(mm_pattern(), units="mm", preset=name))
    names = {layer.dxf.name for layer in doc.layers} - {"0", "Defpoints"}
    pens = {r: p for r, p in preset.pens().items() if r != "flat"}
    assert names == {p.layer for p in pens.values()}
    used = {e.dxf.layer for e in doc.modelspace()}
    assert used == names
    for pen in pens.values():
        layer = doc.layers.get(pen.layer)
        assert layer.dxf.color == pen.aci
        assert layer.dxf.lineweight == dxf_lineweight(pen.width_mm)
        assert layer.rgb == (hex_rgb(pen.color) if preset.true_color else None)
        if pen.dash_mm is not None:
            on, off = pen.dash_mm
            lt = doc.linetypes.get(layer.dxf.linetype)
            assert _pattern(lt) == pytest.approx([on + off, on, -off])  # mm: units="mm"


def _pattern(linetype) -> list[float]:
    """The total length and the dash/gap lengths of a simple linetype."""
    tags = linetype.pattern_tags.tags
    return [t.value for t in tags if t.code in (40, 49)]


def test_default_dxf_layers():
    doc = read_dxf(pattern_dxf(mm_pattern(), units="mm"))
    got = {layer.dxf.name: layer.dxf.color for layer in doc.layers} | {}
    assert {k: got[k] for k in ("CUT", "MOUNTAIN", "VALLEY", "TAB", "LABEL")} == {
        "CUT": 7,
        "MOUNTAIN": 1,
        "VALLEY": 5,
        "TAB": 6,
        "LABEL": 8,
    }
    assert doc.layers.get("TAB").dxf.linetype == "DASHED"


def test_default_dxf_layers_show_the_svg_colours():
    """The default DXF has no true colours, so its layers' ACI colours are what a viewer shows:
    each line the SVG draws (cut, mountain, valley, tab hinge, facet) has the same colour in
    both files -- the tab hinge magenta, not ACI 3 ``#00ff00``, which Origami Simulator reads
    as a cut, and the facets yellow (ACI 2), not grey. ACI 7 is black on a white sheet."""
    from ezdxf.colors import aci2rgb

    groups, _ = svg_groups(pattern_svg(mm_pattern(), units="mm", flat_edges=True))
    doc = read_dxf(pattern_dxf(mm_pattern(), units="mm", flat_edges=True))
    preset = get_preset()
    for role, gid in {**GROUP, "flat": "flat"}.items():
        assert groups[gid], role
        layer = doc.layers.get(getattr(preset, role).layer)
        assert layer.rgb is None  # no true colour: the ACI is the colour
        aci = layer.dxf.color
        shown = (0, 0, 0) if aci == 7 else tuple(aci2rgb(aci))
        assert {hex_rgb(el.get("stroke")) for el in groups[gid]} == {shown}, role


def check_dashes(paths, length: float, dash: float, gap: float) -> None:
    """Dashes of one path, in order: each ``dash`` long along the path, ``gap`` apart (chord,
    so at most ``gap``), as many as fit, with equal leftovers."""
    n = int(np.floor((length + gap) / (dash + gap)))
    assert len(paths) == n
    for d in paths:
        # SVG numbers: to RESOLUTION_MM (a micrometre), at most 8 digits
        assert polyline_length(d) == pytest.approx(dash, rel=1e-5, abs=2 * RESOLUTION_MM)
    for a, b in itertools.pairwise(paths):
        step = float(np.linalg.norm(b[0] - a[-1]))
        assert gap * (1 - 1e-3) - 2 * RESOLUTION_MM <= step <= gap * (1 + 1e-5) + 2 * RESOLUTION_MM


def test_card_perforates_in_the_geometry():
    pattern = mm_pattern()
    card = PRESETS["card"]
    groups, user = svg_groups(pattern_svg(pattern, units="mm", preset="card"))
    doc = read_dxf(pattern_dxf(pattern, units="mm", preset="card"))
    for role, radius in (("mountain", 60.0), ("valley", 80.0)):
        dash, gap = getattr(card, role).perforation_mm
        svg = [points(el) / user for el in groups[GROUP[role]]]
        assert all(el.tag == SVG_NS + "polyline" for el in groups[GROUP[role]])
        check_dashes(svg, np.pi * radius, dash, gap)  # each crease is one half circle
        layer = getattr(card, role).layer
        entities = [e for e in doc.modelspace() if e.dxf.layer == layer]
        assert {e.dxftype() for e in entities} == {"LWPOLYLINE"}
        dxf = [np.array(e.get_points("xy")) for e in entities]
        check_dashes(dxf, np.pi * radius, dash, gap)
    # the tab hinge (60 mm) perforated too
    dash, gap = card.tab.perforation_mm
    hinge = [points(el) / user for el in groups["tab-hinge"]]
    check_dashes(hinge, 60.0, dash, gap)


def test_plotter_dashes_are_a_style_on_whole_paths():
    pattern = mm_pattern()
    groups, user = svg_groups(pattern_svg(pattern, units="mm", preset="plotter"))
    (arc,) = list(groups["mountain"])  # the mountain half circle, one path
    assert polyline_length(points(arc) / user) == pytest.approx(np.pi * 60, rel=1e-2)
    assert groups["mountain"].get("stroke-dasharray") == f"{4 * user:g} {2 * user:g}"


def test_dash_polylines_short_path_and_corner():
    p = np.array([[0.0, 0.0], [5.0, 0.0], [5.0, 5.0]])
    dashes = dash_polylines(p, False, 2.0, 1.0)
    assert [polyline_length(d) for d in dashes] == pytest.approx([2.0, 2.0, 2.0])
    assert dashes[1].tolist() == [[4.0, 0.0], [5.0, 0.0], [5.0, 1.0]]  # through the corner
    (one,) = dash_polylines(p, False, 20.0, 10.0)
    assert polyline_length(one) == pytest.approx(10 * 2 / 3)


@pytest.mark.parametrize("name", list(PRESETS))
def test_presets_reproducible(name):
    a = cut_files(mm_pattern(), "svg,dxf", units="mm", preset=name)
    b = cut_files(mm_pattern(), "svg,dxf", units="mm", preset=name)
    assert a == b


def test_cli_preset(tmp_path, capsys):
    design = tmp_path / "d"
    assert main(["round", "cube", "-q", "-o", str(design), "--format", "fold"]) == 0
    assert main(["export", str(design), "--format", "svg,dxf", "--preset", "laser"]) == 0
    doc = read_dxf((design / "pattern.dxf").read_text())
    assert "SCORE_MOUNTAIN" in {layer.dxf.name for layer in doc.layers}
    groups, _ = svg_groups((design / "pattern.svg").read_text())
    assert {el.get("stroke") for el in groups["border"]} == {"#ff0000"}
    capsys.readouterr()
    out = tmp_path / "r"
    assert main(["round", "cube", "-q", "-o", str(out), "--preset", "lazer"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "unknown preset 'lazer'" in err and "card" in err
    assert not out.exists()
