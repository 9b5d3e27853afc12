"""The layout stage (:func:`filletfold.layout.arrange.arrange`, run by ``round_mesh``): for every
layout, with and without sheets, a valid pattern whose faces and tabs overlap nothing, the same
pieces' area whatever the layout, every piece on one sheet, and a sheet too small refused by a
ParameterError naming ``sheet``."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import filletfold
from filletfold.errors import ParameterError, SolverError
from filletfold.surface.faces import face_polygons
from filletfold.surface.overlap import faces_overlap
from filletfold.surface.validate import face_signed_area_2d, validate_pattern
from filletfold.units import sheet_size_mm

#: (mesh, keyword arguments of round_mesh, the layout used)
CASES = {
    "cube-modules": ("cube", {"layout": "modules"}, "modules"),
    "cube-auto": ("cube", {"layout": "auto"}, "net"),
    "cube-auto-A4": ("cube", {"layout": "auto", "sheet": "A4", "scale": 60}, "net"),
    "cube-net-A4-sheets": ("cube", {"layout": "net", "sheet": "A4", "scale": 100}, "net"),
    "cube-modules-A4": ("cube", {"layout": "modules", "sheet": "A4", "scale": 100}, "modules"),
    "icosahedron-modules": ("icosahedron", {"layout": "modules"}, "modules"),
    "icosahedron-net": ("icosahedron", {"layout": "net", "tabs": False}, "net"),
    "miura-modules-loss": ("miura", {"layout": "modules", "material_loss": True}, "modules"),
    "miura-auto-loss": ("miura", {"layout": "auto", "material_loss": True}, "sheet"),
}
#: The modules design each case's pieces are compared with.
SAME_PIECES = {
    "cube": "cube-modules",
    "icosahedron": "icosahedron-modules",
    "miura": "miura-modules-loss",
}


@pytest.fixture(scope="module")
def designs():
    return {key: filletfold.round_mesh(mesh, **kw) for key, (mesh, kw, _) in CASES.items()}


@pytest.fixture(params=sorted(CASES))
def case(request, designs):
    return request.param, designs[request.param]


def piece_points(pattern, k: int) -> np.ndarray:
    faces = [pattern.faces[i] for i in np.flatnonzero(pattern.face_piece == k)]
    return pattern.vertices_2d[np.concatenate(faces)]


def test_the_layout_used(case, designs):
    key, d = case
    assert d.layout == CASES[key][2]
    if d.layout == "modules":
        assert d.pattern.n_pieces == d.mesh.n_vertices  # one module per vertex
    elif d.layout == "sheet":
        assert d.pattern.n_pieces == 1
    else:
        modules = designs[SAME_PIECES[CASES[key][0]]]
        assert 1 <= d.pattern.n_pieces < modules.pattern.n_pieces


def test_the_pattern_is_valid_and_its_faces_overlap_nothing(case):
    _, d = case
    p = d.pattern
    validate_pattern(p)
    assert not faces_overlap(p.vertices_2d, p.faces)
    assert set(p.face_piece.tolist()) == set(range(p.n_pieces))


def test_tabs_overlap_no_face_and_no_other_tab(case):
    key, d = case
    p, fab = d.pattern, d.fabrication
    tabs = [shapely.Polygon(t) for t in p.annotations.tabs]
    assert len(tabs) == fab["tabs"]
    if CASES[key][1].get("tabs", True) is False:
        assert not tabs and fab["cut_borders"] == 0
        return
    if d.pattern.n_pieces > 1 or d.layout == "net":
        assert tabs
    faces = shapely.union_all(face_polygons(p.vertices_2d, p.faces))
    for t in tabs:
        assert t.is_valid and t.area > 0
        assert t.intersection(faces).area <= 1e-9 * t.area
    assert shapely.union_all(tabs).area == pytest.approx(sum(t.area for t in tabs), rel=1e-9)


def test_the_layout_moves_the_pieces_and_keeps_their_area(case, designs):
    key, d = case
    ref = designs[SAME_PIECES[CASES[key][0]]].pattern
    area = face_signed_area_2d(d.pattern.vertices_2d, d.pattern.faces).sum()
    assert area == pytest.approx(face_signed_area_2d(ref.vertices_2d, ref.faces).sum(), rel=1e-9)
    lo, hi = d.pattern.vertices_3d.min(axis=0), d.pattern.vertices_3d.max(axis=0)
    np.testing.assert_allclose(lo, ref.vertices_3d.min(axis=0), atol=1e-9)
    np.testing.assert_allclose(hi, ref.vertices_3d.max(axis=0), atol=1e-9)


def test_every_piece_and_its_tabs_lie_on_one_sheet(case):
    key, d = case
    _, kw, _ = CASES[key]
    p, fab = d.pattern, d.fabrication
    boxes = p.annotations.sheets
    if "sheet" not in kw:
        assert len(boxes) == 0 and "sheets" not in fab
        return
    w, h = sheet_size_mm(kw["sheet"])
    size = np.sort(boxes[:, 2:] - boxes[:, :2], axis=1)
    np.testing.assert_allclose(size, np.tile(np.sort([w, h]) / kw["scale"], (len(boxes), 1)))
    assert fab["sheets"] == len(boxes) and sum(fab["pieces_per_sheet"]) == p.n_pieces
    assert all(0 < u <= 1 for u in fab["material_use"])
    # the sheets are apart
    sheets = [shapely.box(*b) for b in boxes]
    assert shapely.union_all(sheets).area == pytest.approx(sum(s.area for s in sheets))
    eps = 1e-9 * max(w, h) / kw["scale"]
    tabs_of = [shapely.Polygon(t) for t in p.annotations.tabs]
    on = np.zeros(len(boxes), dtype=int)
    for k in range(p.n_pieces):
        pts = piece_points(p, k)
        inside = [bool(np.all(pts >= b[:2] - eps) and np.all(pts <= b[2:] + eps)) for b in boxes]
        assert sum(inside) == 1, f"piece {k} is not on exactly one sheet"
        on[inside.index(True)] += 1
    assert on.tolist() == fab["pieces_per_sheet"]
    for t in tabs_of:
        assert any(shapely.box(*b).buffer(eps).contains(t) for b in boxes)


def test_a_sheet_too_small_for_any_piece():
    with pytest.raises(ParameterError) as info:
        filletfold.round_mesh("cube", sheet="A4", scale=1000)
    assert info.value.name == "sheet" and "sheet" in str(info.value)
    assert "A4" in str(info.value)


@pytest.mark.parametrize("layout", ["modules", "net"])
def test_a_sheet_too_small_for_a_module(layout):
    """Room for a piece, but not for a vertex module, which no cut makes smaller."""
    with pytest.raises(ParameterError) as info:
        filletfold.round_mesh("cube", layout=layout, sheet="A4", scale=250)
    assert info.value.name == "sheet" and "sheet" in str(info.value)
    assert "\n" not in str(info.value)


def test_the_sheet_layout_needs_developments_that_close():
    with pytest.raises(SolverError, match="one sheet"):
        filletfold.round_mesh("cube", layout="sheet")
    # with `auto` the same input is laid out in nets, and says why it is not one sheet
    d = filletfold.round_mesh("cube", layout="auto", material_loss=True)
    assert d.layout == "net" and "not developable" in d.layout_note
