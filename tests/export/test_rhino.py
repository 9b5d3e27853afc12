"""The Rhino files (:mod:`filletfold.export.rhino`), read back with rhino3dm."""

from __future__ import annotations

import logging
import sys
from collections import Counter

import numpy as np
import pytest
from numpy.testing import assert_allclose

from filletfold.errors import ParameterError
from filletfold.export.cutfiles import cut_files, parse_formats
from filletfold.export.paths import tab_cut_paths
from filletfold.export.rhino import (
    PATTERN_LAYERS,
    RHINO_UNITS,
    folded_3dm,
    pattern_3dm,
    require_rhino3dm,
)
from filletfold.surface.patch import patch_kind

from ..conftest import folded_area
from .conftest import arc_pattern, layer_lengths_of

rhino3dm = pytest.importorskip("rhino3dm")

ASSIGNMENT_LAYER = {"B": "CUT", "M": "MOUNTAIN", "V": "VALLEY"}


def read(data: bytes):
    model = rhino3dm.File3dm.FromByteArray(data)
    assert model is not None
    return model


def by_layer(model) -> dict:
    """Layer name -> list of (geometry, attributes)."""
    names = [layer.Name for layer in model.Layers]
    out: dict = {}
    for obj in model.Objects:
        out.setdefault(names[obj.Attributes.LayerIndex], []).append((obj.Geometry, obj.Attributes))
    return out


def curve_points(curve) -> np.ndarray:
    """The points a curve passes through in order: a line's ends, a polyline's corners, a
    degree-3 interpolating NURBS curve's points at its distinct knots."""
    if isinstance(curve, rhino3dm.LineCurve):
        pts = [curve.PointAtStart, curve.PointAtEnd]
    elif isinstance(curve, rhino3dm.PolylineCurve):
        pts = [curve.Point(i) for i in range(curve.PointCount)]
    else:
        assert isinstance(curve, rhino3dm.NurbsCurve)
        assert curve.Degree == 3 and curve.IsValid
        knots = np.unique([curve.Knots[i] for i in range(len(curve.Knots))])
        pts = [curve.PointAt(float(t)) for t in knots]
    return np.array([[p.X, p.Y, p.Z] for p in pts])


def length(points: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


@pytest.fixture(scope="module", params=["cube", "arc"])
def pattern(request, cube):
    return cube.pattern if request.param == "cube" else arc_pattern(annotated=True)


@pytest.mark.parametrize(("units", "scale"), [("", 1.0), ("mm", 25.0), ("in", 0.5)])
def test_pattern_3dm_layers_units_and_lengths(pattern, units, scale):
    model = read(pattern_3dm(pattern, units=units, scale=scale))
    assert [layer.Name for layer in model.Layers] == list(PATTERN_LAYERS)
    assert model.Settings.ModelUnitSystem == getattr(rhino3dm.UnitSystem, RHINO_UNITS[units])
    layers = by_layer(model)
    expected = layer_lengths_of(pattern)
    v2 = pattern.vertices_2d * scale
    for layer, want in expected.items():
        curves = [g for g, _ in layers.get(layer, [])]
        points = [curve_points(c) for c in curves]
        # a closed curve repeats its first point at its end
        closed = [p for c, p in zip(curves, points, strict=True) if c.IsClosed]
        assert all(np.array_equal(p[0], p[-1]) for p in closed)
        total = sum(map(length, points))
        assert total == pytest.approx(want * scale, rel=1e-9, abs=1e-12), layer
        if layer in ("MOUNTAIN", "VALLEY"):
            # every crease point is a pattern vertex, in the plane z = 0
            for p in points:
                assert_allclose(p[:, 2], 0.0, atol=1e-12)
                gap = np.linalg.norm(p[:, None, :2] - v2[None], axis=2).min(axis=1)
                assert gap.max() <= 1e-9 * scale
    # tab hinges are lines, one per tab; labels are text dots with their texts and places
    assert len(layers.get("TAB", [])) == len(pattern.annotations.tab_hinges)
    dots = [g for g, _ in layers.get("LABEL", [])]
    assert len(dots) == len(pattern.annotations.labels)
    for dot, label in zip(dots, pattern.annotations.labels, strict=True):
        assert isinstance(dot, rhino3dm.TextDot)
        assert dot.Text == label.text
        assert_allclose([dot.Point.X, dot.Point.Y], np.asarray(label.position) * scale)
    assert {a.Name for _, a in layers.get("LABEL", [])} <= {"part", "tab", "angle"}
    assert len(layers.get("CUT", [])) >= len(tab_cut_paths(pattern.annotations))


def test_pattern_3dm_curved_creases_are_nurbs_through_the_samples():
    """The arc pattern's two curved creases: one cubic curve each, through all 41 samples."""
    pattern = arc_pattern(n=40)
    layers = by_layer(read(pattern_3dm(pattern, scale=2.0)))
    for layer, radius in (("MOUNTAIN", 1.5), ("VALLEY", 2.0)):
        (curve,) = [g for g, _ in layers[layer]]
        assert isinstance(curve, rhino3dm.NurbsCurve)
        p = curve_points(curve)
        assert len(p) == 41
        assert_allclose(np.linalg.norm(p[:, :2], axis=1), 2.0 * radius, rtol=1e-12)
        # between the samples the curve stays on the circle to the chord's sag
        t = np.linspace(curve.Domain.T0, curve.Domain.T1, 1001)
        q = np.array([[curve.PointAt(float(s)).X, curve.PointAt(float(s)).Y] for s in t])
        assert np.abs(np.linalg.norm(q, axis=1) - 2.0 * radius).max() < 1e-5 * radius


def test_folded_3dm_meshes_per_patch_and_creases(pattern):
    scale = 10.0
    model = read(folded_3dm(pattern, units="cm", scale=scale))
    assert model.Settings.ModelUnitSystem == rhino3dm.UnitSystem.Centimeters
    kinds = sorted({patch_kind(p) for p in pattern.face_patch})
    names = [layer.Name for layer in model.Layers]
    assert sorted(names[:-2]) == sorted(k.upper() for k in kinds)
    assert names[-2:] == ["MOUNTAIN", "VALLEY"]
    layers = by_layer(model)
    patches = Counter(patch_kind(p).upper() for p in dict.fromkeys(pattern.face_patch))
    area = 0.0
    seen = set()
    for layer, count in patches.items():
        objects = layers[layer]
        assert len(objects) == count
        for mesh, attr in objects:
            assert isinstance(mesh, rhino3dm.Mesh)
            assert attr.Name.split()[0].upper() == layer
            seen.add(attr.Name)
            v = np.array([[p.X, p.Y, p.Z] for p in mesh.Vertices.ToPoint3dArray()])
            faces = [mesh.Faces[i] for i in range(len(mesh.Faces))]
            for f in faces:
                corners = v[list(dict.fromkeys(f))]  # a triangle repeats its last corner
                n = np.cross(corners - corners[0], np.roll(corners, -1, axis=0) - corners[0])
                area += 0.5 * np.linalg.norm(n.sum(axis=0))
            assert len(mesh.Normals) == len(v)
    assert seen == set(map(str, pattern.face_patch))
    assert area == pytest.approx(folded_area(pattern) * scale**2, rel=1e-9)
    v3 = pattern.vertices_3d * scale
    for code in ("M", "V"):
        curves = [g for g, _ in layers.get(ASSIGNMENT_LAYER[code], [])]
        assert bool(curves) == bool((pattern.edge_assignment == code).any())
        for curve in curves:
            p = curve_points(curve)
            gap = np.linalg.norm(p[:, None] - v3[None], axis=2).min(axis=1)
            assert gap.max() <= 1e-9 * scale


def test_crease_counts_match_between_the_files(cube):
    """The folded file draws the pattern's crease runs, through the folded points."""
    flat = by_layer(read(pattern_3dm(cube.pattern)))
    folded = by_layer(read(folded_3dm(cube.pattern)))
    for layer in ("MOUNTAIN", "VALLEY"):
        kinds = [type(g).__name__ for g, _ in flat.get(layer, [])]
        assert kinds == [type(g).__name__ for g, _ in folded.get(layer, [])]


def test_3dm_reproducible_with_fixed_dates(cube):
    files = cut_files(cube.pattern, "3dm", units="mm", scale=100.0)
    assert list(files) == ["pattern.3dm", "folded.3dm"]
    again = cut_files(cube.pattern, "3dm", units="mm", scale=100.0)
    for name, data in files.items():
        assert again[name] == data, name
        model = read(data)
        assert str(model.Created).startswith("2000-01-01")
        assert str(model.LastEdited).startswith("2000-01-01")
        ids = [o.Attributes.Id for o in model.Objects] + [la.Id for la in model.Layers]
        assert len(set(ids)) == len(ids)


def test_3dm_bad_parameters(cube):
    with pytest.raises(ParameterError, match="units"):
        pattern_3dm(cube.pattern, units="pt")
    with pytest.raises(ParameterError, match="scale"):
        folded_3dm(cube.pattern, scale=0.0)


def test_without_rhino3dm(monkeypatch, caplog, cube):
    """No rhino3dm: ``3dm`` is refused in one line, ``all`` leaves it out and says so."""
    monkeypatch.setitem(sys.modules, "rhino3dm", None)
    with pytest.raises(ParameterError, match=r"pip install 'filletfold\[rhino\]'"):
        parse_formats("svg,3dm")
    with pytest.raises(ParameterError, match="rhino3dm"):
        require_rhino3dm()
    with pytest.raises(ParameterError, match="rhino3dm"):
        pattern_3dm(cube.pattern)
    with caplog.at_level(logging.WARNING):
        formats = parse_formats("all")
    assert "3dm" not in formats and "glb" in formats
    assert "format 3dm left out of 'all'" in caplog.text
    monkeypatch.undo()
    assert "3dm" in parse_formats("all")


def test_cli_export_writes_3dm_from_design_fold(tmp_path, cube):
    from filletfold.cli import main

    cube.export(tmp_path, formats="fold")
    code = main(["export", str(tmp_path), "--format", "3dm,glb", "--units", "mm", "--scale", "5"])
    assert code == 0
    model = read((tmp_path / "pattern.3dm").read_bytes())
    assert model.Settings.ModelUnitSystem == rhino3dm.UnitSystem.Millimeters
    folded = by_layer(read((tmp_path / "folded.3dm").read_bytes()))
    meshes = sum(
        len(objs) for layer, objs in folded.items() if layer not in ASSIGNMENT_LAYER.values()
    )
    assert meshes == len(set(cube.pattern.face_patch))
    assert (tmp_path / "folded.glb").read_bytes()[:4] == b"glTF"
