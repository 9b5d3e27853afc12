"""The DXF writer (:mod:`filletfold.export.dxf`): layers, units, lengths read back with ezdxf."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose

import filletfold
from filletfold.errors import ExportError, ParameterError
from filletfold.export import pattern_dxf
from filletfold.export.dxf import LAYER_COLOR

from ..conftest import tiny_square
from .conftest import arc_pattern, check_lengths, edge_length, layer_lengths, read_dxf

SVG_NS = "{http://www.w3.org/2000/svg}"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- DXF


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


@pytest.mark.parametrize("layout", ["modules", "net"])
def test_dxf_of_the_cube_design(cube, layout):
    pattern = (cube if layout == "net" else filletfold.round_mesh("cube", layout=layout)).pattern
    text = pattern_dxf(pattern, units="cm", scale=5.0)
    assert text == pattern_dxf(pattern, units="cm", scale=5.0)  # deterministic
    doc = read_dxf(text)
    assert doc.header["$INSUNITS"] == 5
    counts = {}
    for e in doc.modelspace():
        counts[e.dxf.layer] = counts.get(e.dxf.layer, 0) + 1
    n_curved = int(np.sum(np.isin(pattern.edge_assignment, ("B", "M", "V"))))
    n_entities = sum(counts.get(k, 0) for k in ("CUT", "MOUNTAIN", "VALLEY"))
    assert n_entities < n_curved / (10 if layout == "modules" else 9)
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
