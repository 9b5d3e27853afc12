"""Making the bends in a real sheet (issue 31): reliefs for metal, kerf grooves for plywood,
score layers for card, each re-measured by the certificate, which fails a design broken on
purpose."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
import shapely

import filletfold
from filletfold.check import certify_design, check_folder
from filletfold.layout.making import MakingPath, score_layers
from filletfold.materials import MATERIALS, Kerf


def _checks(design) -> dict:
    return {c.name: c for c in certify_design(design).checks}


def _with_making(design, making):
    """The design with other making paths (the pattern's annotations replaced)."""
    pattern = dataclasses.replace(
        design.pattern,
        annotations=dataclasses.replace(design.pattern.annotations, making=list(making)),
    )
    return dataclasses.replace(design, pattern=pattern)


@pytest.fixture(scope="module")
def metal():
    return filletfold.round_mesh("cube", material="aluminium-1mm", size="100mm")


@pytest.fixture(scope="module")
def ply():
    return filletfold.round_mesh("cube", material="plywood-3mm", size="1500mm")


def test_metal_cones_are_relieved_where_they_bend_too_tight(metal):
    making = metal.pattern.annotations.making
    reliefs = [m for m in making if m.kind == "relief"]
    assert {m.patch for m in reliefs} == {f"cone {u}" for u in range(8)}
    assert all(m.closed and len(m.points) >= 3 for m in reliefs)
    checks = _checks(metal)
    assert checks["relief"].ok and "kerfs" not in checks
    assert metal.certificate.ok
    # every relief is at least the sheet's thickness across (a radius of t, in pattern units)
    t = MATERIALS["aluminium-1mm"].thickness_mm / metal.params.mm_per_unit
    for m in reliefs:
        assert shapely.Polygon(m.points).area >= 0.5 * math.pi * t * t * 0.5


def test_the_relief_check_fails_a_missing_a_small_or_a_stray_relief(metal):
    making = list(metal.pattern.annotations.making)
    assert not _checks(_with_making(metal, making[1:]))["relief"].ok  # one cone not relieved
    first = making[0]
    centre = first.points.mean(axis=0)
    small = dataclasses.replace(first, points=centre + 0.2 * (first.points - centre))
    assert not _checks(_with_making(metal, [small, *making[1:]]))["relief"].ok
    # a relief moved onto another patch: it cuts what it should not
    shift = metal.mesh.mean_edge_length * 0.5
    stray = dataclasses.replace(first, points=first.points + shift)
    check = _checks(_with_making(metal, [*making, stray]))["relief"]
    assert not check.ok and "cutting another patch" in check.detail


def test_plywood_cylinders_are_grooved_as_they_bend(ply):
    """The kerf-bending relation on every cylinder: n = ceil(phi / turn_max) grooves along its
    rulings, evenly spaced s apart with n s = r phi (their turns add up to the bend), s at
    least the groove and its land."""
    kerf = MATERIALS["plywood-3mm"].kerf
    mm = ply.params.mm_per_unit
    grooves = [m for m in ply.pattern.annotations.making if m.kind.startswith("kerf")]
    assert grooves and all(not m.closed for m in grooves)
    checks = _checks(ply)
    assert checks["kerfs"].ok and checks["relief"].ok and ply.certificate.ok
    rd = ply.rounding
    for e in range(ply.mesh.n_edges):
        mine = [m for m in grooves if m.patch == f"cylinder {e}"]
        r, phi = float(rd.radius[e]), 2 * float(rd.half_angle[e])
        n = math.ceil(phi / kerf.turn_max() - 1e-9)
        assert n * kerf.turn_max() >= phi
        # each half of the cylinder (laid out its own way) has its n grooves, r phi / n apart
        halves: list = []  # grooves grouped by direction (parallel within 1e-6)
        for m in mine:
            d = m.points[-1] - m.points[0]
            d = d / np.linalg.norm(d)
            for ref, lines in halves:
                if abs(ref[0] * d[1] - ref[1] * d[0]) < 1e-6:
                    lines.append(m)
                    break
            else:
                halves.append((d, [m]))
        spacing = r * phi / n  # n spacings make the arc: the grooves' turns add up to phi
        runs = 0
        for ref, lines in halves:
            across = np.array([-ref[1], ref[0]])
            pos = np.unique(np.round([m.points.mean(axis=0) @ across for m in lines], 9))
            for run in np.split(pos, np.flatnonzero(np.diff(pos) > 1.5 * spacing) + 1):
                assert len(run) == n  # one half of the cylinder
                np.testing.assert_allclose(np.diff(run), spacing, rtol=1e-6)
                runs += 1
        assert runs in (1, 2)  # the halves apart, or glued into one strip (grooves in line)
        assert spacing * mm >= kerf.width_mm + kerf.land_mm - 1e-9


def test_the_kerf_check_fails_a_missing_or_a_turned_groove(ply):
    making = list(ply.pattern.annotations.making)
    k = next(i for i, m in enumerate(making) if m.kind.startswith("kerf"))
    missing = making[:k] + making[k + 1 :]
    assert not _checks(_with_making(ply, missing))["kerfs"].ok
    g = making[k]
    mid = g.points.mean(axis=0)
    turned = np.array([[0.0, -1.0], [1.0, 0.0]]) @ (g.points - mid).T
    bad = dataclasses.replace(g, points=mid + 0.5 * turned.T)  # across the rulings
    assert not _checks(_with_making(ply, [*missing, bad]))["kerfs"].ok


def test_the_kerf_model():
    k = Kerf(width_mm=3.2, depth_mm=2.0, land_mm=2.0, skin_radius_mm=25.0)
    assert k.turn_max() == pytest.approx(min(2 * math.atan(3.2 / 4.0), 3.2 / 25.0))
    assert k.min_radius() == pytest.approx(2 * 5.2 / k.turn_max())
    # closure alone (a stiff skin): a groove that closes turns by 2 atan(w / 2d), so a bend of
    # radius R takes one every R w / d for small w / d (the woodworking relation)
    wide = Kerf(width_mm=0.2, depth_mm=2.0, land_mm=1.0, skin_radius_mm=1e-6)
    assert wide.turn_max() == pytest.approx(2 * math.atan(0.05))
    assert 100.0 * wide.turn_max() == pytest.approx(100.0 * 0.2 / 2.0, rel=1e-3)
    assert MATERIALS["plywood-3mm"].min_bend_radius_mm == pytest.approx(k.min_radius())


def test_card_is_scored_on_layers_of_its_own(tmp_path):
    assert score_layers("score") == {"mountain": "SCORE_FRONT", "valley": "SCORE_BACK"}
    assert score_layers("relief") is None
    card = filletfold.round_mesh("cube", material="card-300gsm", size="100mm")
    assert card.pattern.annotations.making == []
    card.export(tmp_path / "card", formats="dxf,json")
    dxf = (tmp_path / "card" / "pattern.dxf").read_text()
    assert "SCORE_FRONT" in dxf and "SCORE_BACK" in dxf and "\nMOUNTAIN\n" not in dxf
    report = json.loads((tmp_path / "card" / "report.json").read_text())
    assert report["material"]["making"]["method"] == "score"


def test_the_files_carry_the_making_and_the_check_measures_it_again(ply, tmp_path):
    folder = tmp_path / "ply"
    ply.export(folder, formats="fold,json,svg,dxf")
    svg = (folder / "pattern.svg").read_text()
    assert 'id="kerf-back"' in svg and 'id="relief"' in svg
    dxf = (folder / "pattern.dxf").read_text()
    assert "KERF_BACK" in dxf and "RELIEF" in dxf
    report = json.loads((folder / "report.json").read_text())["material"]["making"]
    n = len(ply.pattern.annotations.making)
    assert report["reliefs"] + report["grooves_front"] + report["grooves_back"] == n
    checks = {c.name: c for c in check_folder(folder).checks}
    assert checks["kerfs"].ok and checks["relief"].ok
    ann = json.loads((folder / "annotations.json").read_text())
    ann["making"] = [m for m in ann["making"] if m["kind"] != "kerf-back"]  # grooves lost
    (folder / "annotations.json").write_text(json.dumps(ann))
    assert not {c.name: c for c in check_folder(folder).checks}["kerfs"].ok


def test_no_making_without_a_material():
    design = filletfold.round_mesh("cube", size="100mm")
    assert design.pattern.annotations.making == []
    assert {"relief", "kerfs"}.isdisjoint(_checks(design))
    assert isinstance(MakingPath("relief", "cone 0", np.zeros((3, 2)), True), MakingPath)


def test_plywood_cones_are_grooved_along_their_rulings(ply):
    """The cube's corner cones in plywood: grooves are rays from each cone's apex, outside its
    relief, as many as its turn needs, at least the land apart; one turned off its ray, or
    one removed, fails the check."""
    from filletfold.layout.making import cone_fans

    kerf = MATERIALS["plywood-3mm"].kerf
    making = list(ply.pattern.annotations.making)
    fans = cone_fans(ply.pattern, ply.vertices.apex)
    assert len(fans) == 8
    for fan in fans:
        rays = [m for m in making if m.patch == f"cone {fan.vertex}" and m.kind != "relief"]
        assert len(rays) >= math.ceil(fan.turn.sum() / kerf.turn_max() - 1e-9) - 1
        for m in rays:
            d, r = m.points[-1] - m.points[0], m.points[0] - fan.apex_2d
            assert abs(d[0] * r[1] - d[1] * r[0]) <= 1e-9 * np.linalg.norm(d) * (
                1 + np.linalg.norm(r)
            )  # on a ray from the apex
    assert _checks(ply)["kerfs"].ok
    k = next(i for i, m in enumerate(making) if m.patch.startswith("cone ") and m.kind != "relief")
    g = making[k]
    off = dataclasses.replace(g, points=g.points + np.array([0.0, 0.05 * np.ptp(g.points)]))
    assert not _checks(_with_making(ply, [*making[:k], off, *making[k + 1 :]]))["kerfs"].ok
    fewer = [m for m in making if not (m.patch == g.patch and m.kind == g.kind)]
    assert not _checks(_with_making(ply, fewer))["kerfs"].ok
