"""Consistent material loss (paper sec. 4): the linear programme, closed developments, one sheet."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

import filletfold
from filletfold.errors import ParameterError, SolverError
from filletfold.mesh import load_mesh
from filletfold.rounding.edges import edge_dihedral, loss_from_radius, round_edges
from filletfold.rounding.material_loss import cycle_equalities, solve_material_loss
from filletfold.vertex.frame import vertex_frame

from ..conftest import CHECKS, folded_degree4_vertex


def cut_edges(pattern) -> int:
    """B edges whose folded segment is also another B edge: a seam cut through the sheet."""
    return int(pattern.cut_mask().sum())


@pytest.mark.parametrize("name", ["icosahedron", "cube", "dimpled-cube"])
def test_closing_conditions_and_radii(name):
    m = load_mesh(name)[0]
    ml = solve_material_loss(m)
    assert ml.ok and ml.bound > 0
    A, rows = cycle_equalities(m, ~m.is_boundary_vertex)
    assert np.abs(A @ ml.halfedge_width).max() < 1e-14
    assert len(rows) == 2 * m.n_edges  # one equality per (vertex, incident edge)
    gamma, _ = edge_dihedral(m)
    assert_allclose(loss_from_radius(ml.edge_radius, gamma), ml.edge_loss, rtol=1e-12)
    assert np.all(ml.halfedge_width >= ml.bound * (1 - 1e-6))
    # the radii are valid roundings
    round_edges(m, ml.edge_radius)


def test_regular_solid_gets_uniform_loss():
    ml = solve_material_loss(load_mesh("icosahedron")[0])
    assert_allclose(ml.edge_loss, ml.edge_loss[0], rtol=1e-9)


def test_max_loss_caps_every_edge():
    m = load_mesh("cube")[0]
    ml = solve_material_loss(m, max_loss=0.05)
    assert ml.ok and ml.edge_loss.max() <= 0.05 * (1 + 1e-9)
    assert any("maximal loss" in t for t in ml.tight)


def test_no_positive_solution_names_what_binds():
    with pytest.raises(SolverError, match=r"no consistent material loss .* binding: vertices"):
        filletfold.round_mesh("random-convex", material_loss=True)


def test_bad_max_loss():
    with pytest.raises(ParameterError, match="max loss must be a positive length"):
        solve_material_loss(load_mesh("cube")[0], max_loss=-1.0)


def test_developable_vertex_closes_and_folds_from_one_sheet():
    v, f = folded_degree4_vertex()
    d = filletfold.round_mesh((v, f), material_loss=True)
    m = d.mesh
    u = int(np.argmin(np.linalg.norm(m.vertices, axis=1)))
    # rho is the identity: the rounded development closes (sec. 2.4, 4)
    fr = vertex_frame(m, d.rounding, u)
    assert_allclose(fr.rho, np.eye(3), atol=1e-12)
    assert d.vertices.kind[u] == "developable" and d.vertices.status[u] == "ok"
    assert d.layout == "sheet" and d.pattern.n_pieces == 1
    assert cut_edges(d.pattern) == 0
    for check in CHECKS:
        check(d)


def test_without_material_loss_the_developable_vertex_is_reported():
    v, f = folded_degree4_vertex()
    d = filletfold.round_mesh((v, f), radius="2%")
    u = int(np.argmin(np.linalg.norm(d.mesh.vertices, axis=1)))
    assert d.vertices.status[u] == "developable"
    assert "--material-loss" in d.vertices.reason[u]
    assert d.layout == "net"  # not one sheet


def rotational_dome(n=8, rings=4, radius=2.0):
    """A conical mesh: planar quads along meridians and parallels of a sphere cap."""
    phis = np.linspace(0.25, 1.2, rings + 1)
    t = 2 * np.pi * np.arange(n) / n
    v = np.array(
        [
            [radius * np.sin(p) * np.cos(a), radius * np.sin(p) * np.sin(a), radius * np.cos(p)]
            for p in phis
            for a in t
        ]
    )
    f = [
        [i * n + k, (i + 1) * n + k, (i + 1) * n + (k + 1) % n, i * n + (k + 1) % n]
        for i in range(rings)
        for k in range(n)
    ]
    return v, f


def test_conical_mesh_is_detected_and_rounded_by_face_offset():
    from filletfold.rounding.conical import is_conical, vertex_cone_axes

    m = load_mesh(rotational_dome())[0]
    assert is_conical(m)
    assert not is_conical(load_mesh("blob")[0])
    d = filletfold.round_mesh(m, material_loss=True)
    assert d.report()["material_loss"]["method"].startswith("conical")
    inner = ~m.is_boundary_vertex
    assert all(s == "ok" for s, i in zip(d.vertices.status, inner, strict=True) if i)
    assert d.material_loss.closure.max() < 1e-14
    # the vertex normal is the cone axis, on the apex side
    axis, _ = vertex_cone_axes(m)
    for u in np.nonzero(inner)[0]:
        assert_allclose(d.vertices.normal[u], d.vertices.sigma[u] * axis[u], atol=1e-12)
    # loss w = 2 delta tan(gamma) on every rounded edge: one offset for all
    gamma, _ = edge_dihedral(m)
    r = d.rounding.radius > 0
    delta = d.material_loss.edge_loss[r] / (2 * np.tan(gamma[r]))
    assert_allclose(delta, delta[0], rtol=1e-12)
    for check in CHECKS:
        check(d)


def test_development_of_a_developable_mesh():
    from filletfold.errors import MeshError

    from ..reference.develop import develop_faces

    m = load_mesh(folded_degree4_vertex())[0]
    flat = develop_faces(m)
    for f, face in enumerate(m.faces):  # every face congruent to its unfolding
        p3 = m.vertices[face]
        d3 = np.linalg.norm(p3[:, None] - p3[None], axis=-1)
        d2 = np.linalg.norm(flat[f][:, None] - flat[f][None], axis=-1)
        assert_allclose(d2, d3, atol=1e-12)
    with pytest.raises(MeshError, match="not developable: vertex"):
        develop_faces(load_mesh("cube")[0])


def check_sheet_is_the_input_shrunk_by_the_losses(d):
    """Across every rounded edge the two face pieces come closer by exactly the edge's loss.

    In the input's flat development the piece centres of the faces f, g beside edge e differ by
    ``c_g - c_f``; in the sheet by ``c_g - c_f - w_e n_e`` (``n_e`` the edge normal from f to g).
    """
    from scipy.spatial import cKDTree

    from filletfold.surface.centres import face_piece_centres

    from ..reference.develop import develop_faces

    m, p = d.mesh, d.pattern
    flat = develop_faces(m)
    centres = face_piece_centres(m, d.rounding)
    where = {}
    tree = cKDTree(p.vertices_3d)
    for f in range(m.n_faces):
        # centre in the input's development: fit the face's rigid map 3D plane -> 2D
        face = m.faces[f]
        p3 = m.vertices[face] - m.vertices[face[0]]
        e1 = p3[1] / np.linalg.norm(p3[1])
        e2 = np.cross(m.face_normal[f], e1)
        local = np.stack([p3 @ e1, p3 @ e2], axis=1)
        q = flat[f] - flat[f][0]
        rot = np.linalg.lstsq(local, q, rcond=None)[0]
        c = centres[f] - m.vertices[face[0]]
        dist, k = tree.query(centres[f])
        assert dist < 1e-9
        where[f] = (np.array([c @ e1, c @ e2]) @ rot + flat[f][0], p.vertices_2d[k])
    worst = 0.0
    for e in np.nonzero(d.rounding.radius > 0)[0]:
        f, g = m.edge_faces[e]
        a, b = m.edges[e]
        ia = int(np.nonzero(m.faces[f] == a)[0][0])
        ib = int(np.nonzero(m.faces[f] == b)[0][0])
        t = flat[f][ib] - flat[f][ia]
        n = np.array([t[1], -t[0]]) / np.linalg.norm(t)  # right of a -> b in f: toward g
        expect = np.linalg.norm(where[g][0] - where[f][0] - d.material_loss.edge_loss[e] * n)
        got = np.linalg.norm(where[g][1] - where[f][1])
        worst = max(worst, abs(got - expect))
    assert worst < 1e-9 * m.mean_edge_length


TESSELLATIONS = ["miura", "chicken-wire", "yoshimura", "resch"]


@pytest.mark.parametrize("name", TESSELLATIONS)
def test_tessellation_folds_from_one_uncut_sheet(name):
    d = filletfold.round_mesh(name, material_loss=True)
    assert d.material_loss.ok and d.material_loss.bound > 0
    assert d.material_loss.closure.max() < 1e-14
    interior = ~d.mesh.is_boundary_vertex
    assert all(d.vertices.status[u] == "ok" for u in np.nonzero(interior)[0])
    assert d.layout == "sheet" and d.pattern.n_pieces == 1
    assert cut_edges(d.pattern) == 0
    # the radii reproduce the losses
    gamma, _ = edge_dihedral(d.mesh)
    assert_allclose(
        loss_from_radius(d.rounding.radius, gamma), d.material_loss.edge_loss, atol=1e-15
    )
    for check in CHECKS:
        check(d)
    check_sheet_is_the_input_shrunk_by_the_losses(d)


def test_miura_from_an_obj_file(tmp_path):
    from filletfold.mesh import example_mesh, write_obj

    v, f = example_mesh("miura:5x4,fold=0.6")
    write_obj(tmp_path / "miura.obj", v, f)
    d = filletfold.round_mesh(str(tmp_path / "miura.obj"), material_loss=True)
    assert d.layout == "sheet" and d.pattern.n_pieces == 1 and cut_edges(d.pattern) == 0
    assert d.status_counts()["ok"] == int((~d.mesh.is_boundary_vertex).sum())
    check_sheet_is_the_input_shrunk_by_the_losses(d)


def test_loss_limit_per_edge_is_reported():
    rep = filletfold.round_mesh("cube").report()
    e = rep["edges"][0]
    assert_allclose(e["material_loss_limit"], loss_from_radius(e["radius_limit"], np.pi / 4))
