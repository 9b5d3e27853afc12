"""Conical meshes (:mod:`filletfold.rounding.conical`, paper sec. 4.4): cone axes, the test,
and the material loss of a face offset."""

from __future__ import annotations

import numpy as np
import pytest

import filletfold
from filletfold.rounding.conical import conical_material_loss, is_conical, vertex_cone_axes
from filletfold.rounding.edges import edge_dihedral


def mesh(name):
    return filletfold.load_mesh(name)[0]


def test_the_face_normals_of_a_conical_vertex_make_one_angle_with_its_axis():
    m = mesh("conical-dome")
    axis, residual = vertex_cone_axes(m)
    inner = np.flatnonzero(~m.is_boundary_vertex)
    assert len(inner) and np.nanmax(residual[inner]) <= 1e-9
    assert np.isnan(axis[m.is_boundary_vertex]).all()
    for u in inner.tolist():
        faces = sorted(
            {int(f) for f, v in zip(m.halfedge_face, m.halfedge_from, strict=True) if v == u}
        )
        c = m.face_normal[faces] @ axis[u]
        assert np.ptp(c) <= 1e-9 and c.min() > 0
        assert np.linalg.norm(axis[u]) == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("name", "conical"), [("conical-dome", True), ("random-convex", False), ("blob", False)]
)
def test_is_conical(name, conical):
    assert is_conical(mesh(name)) is conical


def test_the_offset_loss_is_two_delta_tan_gamma_on_every_edge():
    """The offset faces project onto strips of width delta tan(gamma) on both sides of every
    edge, the same at both of its ends: w = 2 delta tan(gamma)."""
    m = mesh("conical-dome")
    loss, delta = conical_material_loss(m)
    assert loss.ok and delta > 0
    gamma, _ = edge_dihedral(m)
    inner = ~m.is_boundary_edge & (loss.edge_loss > 0)
    assert inner.any()
    np.testing.assert_allclose(loss.edge_loss[inner], 2 * delta * np.tan(gamma[inner]), rtol=1e-9)
    assert (loss.edge_radius[inner] > 0).all()


def test_a_design_of_a_conical_mesh_uses_the_cone_axes():
    d = filletfold.round_mesh("conical-dome", material_loss=True, tabs=False)
    axis, _ = vertex_cone_axes(d.mesh)
    cones = np.flatnonzero(np.array(d.vertices.kind) == "cone")
    assert len(cones)
    for u in cones.tolist():
        np.testing.assert_allclose(np.abs(d.vertices.normal[u] @ axis[u]), 1.0, atol=1e-12)
