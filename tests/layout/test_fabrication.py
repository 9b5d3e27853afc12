"""Nets, glue tabs, labels and sheets (fabrication layouts)."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
import shapely

import filletfold
from filletfold.errors import ParameterError
from filletfold.units import sheet_size_mm

from ..conftest import CHECKS


@pytest.fixture(scope="module")
def nets():
    return {
        "icosahedron": filletfold.round_mesh("icosahedron", layout="net"),
        "cube": filletfold.round_mesh("cube", layout="net"),
        "torus": filletfold.round_mesh("torus", layout="net"),
        "dodecahedron": filletfold.round_mesh("dodecahedron", layout="net", sheet="A4", scale=60),
    }


def test_nets_have_far_fewer_pieces_than_vertices(nets):
    assert nets["icosahedron"].pattern.n_pieces <= 2
    assert nets["cube"].pattern.n_pieces < 8
    assert nets["torus"].pattern.n_pieces <= 72 // 8
    for d in nets.values():
        assert d.layout == "net"
        assert d.pattern.n_pieces < d.mesh.n_vertices


@pytest.mark.parametrize("check", CHECKS, ids=lambda c: c.__name__[6:])
def test_nets_pass_the_core_invariants(nets, check):
    for d in nets.values():
        check(d)


def test_every_cut_border_has_one_tab_and_two_matching_labels(nets):
    for name, d in nets.items():
        ann, fab = d.pattern.annotations, d.fabrication
        assert fab["tabs"] + fab["untabbed"] == fab["cut_borders"] > 0
        assert len(ann.tabs) == len(ann.tab_hinges) == fab["tabs"]
        seams = Counter(lab.text for lab in ann.labels if lab.kind == "tab")
        assert len(seams) == fab["cut_borders"] and set(seams.values()) == {2}
        parts = [lab.text for lab in ann.labels if lab.kind == "part"]
        assert len(parts) == d.pattern.n_pieces == len(set(parts))
        if name in ("icosahedron", "cube"):
            assert fab["untabbed"] == 0


def test_tabs_overlap_nothing(nets):
    for d in nets.values():
        p = d.pattern
        faces = shapely.union_all([shapely.Polygon(p.vertices_2d[f]) for f in p.faces])
        tabs = [shapely.Polygon(t) for t in p.annotations.tabs]
        for t in tabs:
            assert t.is_valid and t.area > 0
            assert t.intersection(faces).area < 1e-9 * t.area
        assert shapely.union_all(tabs).area == pytest.approx(sum(t.area for t in tabs), rel=1e-9)
        for t, hinge in zip(tabs, p.annotations.tab_hinges, strict=True):
            # each tab hangs on its cut border
            assert t.exterior.distance(shapely.Point(hinge.mean(axis=0))) < 1e-9


def test_pieces_fit_their_sheets(nets):
    d = nets["dodecahedron"]
    p, fab = d.pattern, d.fabrication
    boxes = p.annotations.sheets
    assert fab["sheets"] == len(boxes) >= 1 and sum(fab["pieces_per_sheet"]) == p.n_pieces
    w, h = sheet_size_mm("A4")
    assert sorted(fab["sheet_size"]) == pytest.approx(sorted([w / 60, h / 60]))
    assert all(0 < u <= 1 for u in fab["material_use"])
    for k in range(p.n_pieces):
        pts = p.vertices_2d[np.concatenate([p.faces[i] for i in np.nonzero(p.face_piece == k)[0]])]
        inside = [np.all(pts >= b[:2] - 1e-9) and np.all(pts <= b[2:] + 1e-9) for b in boxes]
        assert sum(inside) == 1
    for tab in p.annotations.tabs:
        assert any(np.all(tab >= b[:2]) and np.all(tab <= b[2:]) for b in boxes)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"sheet": "A9"}, "sheet must be one of"),
        ({"sheet": "0x100"}, "sheet size must be positive"),
        ({"sheet": "A4", "units": "furlong"}, "units must be one of"),
        ({"sheet": "A4", "scale": -2.0}, "scale must be positive"),
        ({"sheet": "40x40", "scale": 100.0}, "too small for any piece"),
        ({"layout": "spiral"}, "layout must be"),
    ],
)
def test_bad_fabrication_parameters(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        filletfold.round_mesh("cube", layout=kwargs.pop("layout", "net"), **kwargs)


def test_tabs_can_be_turned_off():
    d = filletfold.round_mesh("cube", tabs=False)
    assert not d.pattern.annotations.tabs and not d.pattern.annotations.labels
