"""The COMPAS adapter (:mod:`filletfold.compas`), tested when COMPAS is installed."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from numpy.testing import assert_allclose

from filletfold.compas import (
    compas_meshes,
    compas_polylines,
    mesh_from_compas,
    mesh_to_compas,
    round_compas_mesh,
)
from filletfold.errors import ParameterError

from .conftest import folded_area

datastructures = pytest.importorskip("compas.datastructures")
Mesh = datastructures.Mesh


@pytest.fixture(scope="module")
def dodecahedron():
    return Mesh.from_polyhedron(12)


@pytest.fixture(scope="module")
def design(dodecahedron):
    return round_compas_mesh(dodecahedron, radius="10%", depth="30%")


def test_round_trip_keeps_vertices_and_faces(dodecahedron):
    v, f = mesh_from_compas(dodecahedron)
    assert v.shape == (20, 3) and len(f) == 12 and all(len(face) == 5 for face in f)
    back = mesh_to_compas((v, f))
    v2, f2 = back.to_vertices_and_faces()
    v0, f0 = dodecahedron.to_vertices_and_faces()
    assert_allclose(v2, v0, rtol=0, atol=0)
    assert f2 == f0


def test_round_trip_renumbers_sparse_keys():
    """A mesh whose vertex keys have gaps (a vertex deleted) comes back numbered 0..n-1."""
    mesh = Mesh.from_vertices_and_faces(
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [5, 5, 5]], [[0, 1, 2, 3]]
    )
    mesh.delete_vertex(4)
    mesh.add_vertex(key=9, x=2, y=0, z=0)
    mesh.add_face([1, 9, 2])
    v, f = mesh_from_compas(mesh)
    assert len(v) == 5  # keys 0, 1, 2, 3, 9
    # every face lists the same points as in the COMPAS mesh
    for face, key in zip(f, mesh.faces(), strict=True):
        want = [mesh.vertex_coordinates(k) for k in mesh.face_vertices(key)]
        assert_allclose(v[face], want)


def test_design_of_a_compas_mesh_is_valid(design, dodecahedron):
    assert design.certificate.ok, design.certificate.summary()
    assert len(design.mesh.vertices) == dodecahedron.number_of_vertices()
    assert_allclose(
        np.sort(design.mesh.vertices, axis=0),
        np.sort(mesh_from_compas(dodecahedron)[0], axis=0),
        atol=1e-12,
    )
    # the cleaned mesh goes back to COMPAS whole
    back = mesh_to_compas(design.mesh)
    assert back.number_of_faces() == len(design.mesh.faces)
    assert back.is_closed()


def test_compas_meshes_per_patch_kind(design):
    meshes = compas_meshes(design)
    pattern = design.pattern
    kinds = {p.kind for p in pattern.face_patch}
    assert set(meshes) == kinds
    assert sum(m.number_of_faces() for m in meshes.values()) == len(pattern.faces)
    area = 0.0
    for kind, mesh in meshes.items():
        patches = {mesh.face_attribute(f, "patch") for f in mesh.faces()}
        assert {p.split()[0] for p in patches} == {kind}
        area += sum(mesh.face_area(f) for f in mesh.faces())
    assert area == pytest.approx(folded_area(pattern), rel=1e-9)


@pytest.mark.parametrize("folded", [False, True])
def test_compas_polylines_per_assignment(design, folded):
    pattern = design.pattern
    lines = compas_polylines(design, folded=folded)
    assert set(lines) == {"M", "V", "B"}
    points = pattern.vertices_3d if folded else pattern.vertices_2d
    for code, polylines in lines.items():
        e = pattern.edges[pattern.edge_assignment == code]
        want = np.linalg.norm(np.diff(points[e], axis=1)[:, 0], axis=1).sum()
        assert sum(p.length for p in polylines) == pytest.approx(want, rel=1e-12), code
        if not folded:
            assert all(abs(q.z) == 0 for p in polylines for q in p.points)
    assert lines["M"] or lines["V"]


def test_bad_input_and_missing_compas(monkeypatch):
    with pytest.raises(ParameterError, match=r"compas\.datastructures\.Mesh"):
        mesh_from_compas("cube")
    with pytest.raises(ParameterError, match="Design or a CreasePattern"):
        compas_meshes(42)
    monkeypatch.setitem(sys.modules, "compas.datastructures", None)
    with pytest.raises(ParameterError, match=r"pip install 'filletfold\[compas\]'"):
        mesh_to_compas((np.eye(3), [[0, 1, 2]]))
