"""Coarsening a mesh before rounding (``--faces``): the decimation and the distance it reports."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import filletfold
from filletfold.cli import main
from filletfold.errors import ParameterError
from filletfold.mesh import load_mesh
from filletfold.mesh.coarsen import (
    coarsen_mesh,
    point_triangle_distance,
    surface_distance,
    triangles_of,
)

coords = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)


def _grid_distance(p, tri, n=120):
    """Distance from ``p`` to a fine barycentric grid of ``tri``: at least the exact distance,
    and at most it plus the grid's spacing."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = i + j <= n
    a, b = i[keep] / n, j[keep] / n
    pts = tri[0] + a[:, None] * (tri[1] - tri[0]) + b[:, None] * (tri[2] - tri[0])
    return np.linalg.norm(pts - p, axis=1).min()


@settings(max_examples=60, deadline=None)
@given(st.lists(coords, min_size=12, max_size=12))
def test_point_triangle_distance_is_the_nearest_point_of_the_triangle(xs):
    x = np.array(xs).reshape(4, 3)
    p, tri = x[0], x[1:]
    d = point_triangle_distance(p[None], tri[None])[0]
    grid = _grid_distance(p, tri)
    spacing = max(np.linalg.norm(tri[1] - tri[0]), np.linalg.norm(tri[2] - tri[0])) / 120
    assert d <= grid + 1e-12
    assert grid <= d + spacing + 1e-12


def test_point_triangle_distance_above_inside_and_beyond_a_corner():
    tri = np.array([[[0.0, 0, 0], [2, 0, 0], [0, 2, 0]]] * 3)
    p = np.array([[0.5, 0.5, 0.3], [-1.0, -1.0, 0.0], [2.0, 2.0, 1.0]])
    d = point_triangle_distance(p, tri)
    # above the hypotenuse's midpoint (1, 1, 0): sqrt(1 + 1 + 1)
    np.testing.assert_allclose(d, [0.3, np.sqrt(2), np.sqrt(3)], rtol=1e-12)


def test_surface_distance_of_points_on_and_off_a_surface():
    v = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    t = np.array([[0, 1, 2], [0, 2, 3]])
    rng = np.random.default_rng(3)
    on = np.column_stack([rng.uniform(0, 1, (200, 2)), np.zeros(200)])
    assert surface_distance(on, v, t) < 1e-12
    off = on + np.array([0.0, 0.0, 0.25])
    assert surface_distance(off, v, t) == pytest.approx(0.25, abs=1e-12)
    far = np.vstack([on, [[3.0, 0.5, 0.0]]])  # 2 beyond the side x = 1
    assert surface_distance(far, v, t) == pytest.approx(2.0, abs=1e-12)


def test_coarsening_a_sphere_keeps_it_close_and_reports_the_distance():
    mesh, _ = load_mesh("geodesic-sphere:level=3")  # 642 vertices, 1280 triangles
    v, t, info = coarsen_mesh(mesh, 200)
    assert info.faces_before == len(triangles_of(mesh)) == 1280
    assert info.faces_after == len(t) <= 200 and info.vertices_after == len(v)
    assert info.vertices_before == mesh.n_vertices
    # the measured distance is the larger of the two one-sided ones, and small on a sphere
    there = surface_distance(mesh.vertices, v, t)
    back = surface_distance(v, mesh.vertices, triangles_of(mesh))
    assert info.distance == max(there, back) > 0
    assert info.distance / info.size < 0.05
    # the same input gives the same mesh
    v2, t2, _ = coarsen_mesh(mesh, 200)
    assert np.array_equal(v, v2) and np.array_equal(t, t2)


def test_a_moved_surface_is_measured():
    """The check that would catch a coarsening that moves the surface: push the coarse
    mesh's vertices out by 1 % of the size and the distance grows by about as much."""
    mesh, _ = load_mesh("geodesic-sphere:level=3")
    v, t, info = coarsen_mesh(mesh, 200)
    pushed = v * (1 + 0.01 * info.size / np.linalg.norm(v, axis=1))[:, None]
    moved = max(
        surface_distance(mesh.vertices, pushed, t),
        surface_distance(pushed, mesh.vertices, triangles_of(mesh)),
    )
    assert moved > info.distance + 0.005 * info.size


def test_a_mesh_with_fewer_faces_is_kept():
    mesh, _ = load_mesh("cube")
    _, _, info = coarsen_mesh(mesh, 100)
    assert info.faces_after == info.faces_before == 12 and info.distance < 1e-12


@pytest.mark.parametrize("faces", [3, 0, -5, 2.5, "many"])
def test_bad_face_counts_are_refused(faces):
    mesh, _ = load_mesh("cube")
    with pytest.raises(ParameterError, match="faces"):
        coarsen_mesh(mesh, faces)


def test_round_with_faces_designs_the_coarse_mesh_and_reports_it(tmp_path):
    out = tmp_path / "blob"
    assert main(["round", "blob", "--faces", "120", "-q", "-o", str(out)]) == 0
    report = json.loads((out / "report.json").read_text())
    c = report["coarsening"]
    assert c["faces_before"] == 320 and c["faces_after"] <= 120
    assert c["vertices_after"] == report["mesh_counts"]["vertices"] < 162
    assert 0 < c["relative_hausdorff"] < 0.1
    assert report["parameters"]["faces"] == 120
    assert report["certificate"]["ok"]
    assert not any("coarsened" in r["where"] for r in report["repairs"])  # a clean result
    design = filletfold.round_mesh("blob")
    assert design.coarsening is None  # not coarsened by default


def test_round_refuses_too_few_faces_in_one_line(capsys):
    assert main(["round", "blob", "--faces", "2", "-o", "/nonexistent/x"]) != 0
    err = capsys.readouterr().err
    assert "--faces" in err and "Traceback" not in err


def test_the_summary_suggests_faces_for_a_design_of_many_pieces(monkeypatch):
    import filletfold.export.outputs as outputs

    monkeypatch.setattr(outputs, "MANY_PIECES", 10)  # blob's modules are 162 pieces
    assert (
        "--faces N coarsens the mesh" in filletfold.round_mesh("blob", layout="modules").summary()
    )
    coarse = filletfold.round_mesh("blob", faces=200)
    assert coarse.coarsening is not None and "--faces N" not in coarse.summary()
    assert coarse.summary().splitlines()[1].startswith("coarsened: 320 -> ")


def test_edge_length_sets_the_triangle_count_from_the_area():
    from filletfold.mesh.coarsen import coarse_target

    mesh, _ = load_mesh("blob")
    assert coarse_target(mesh) is None and coarse_target(mesh, faces=50) == 50
    length = 2 * mesh.mean_edge_length
    want = round(float(mesh.face_area.sum()) / (np.sqrt(3) / 4 * length**2))
    assert coarse_target(mesh, edge_length="200%") == coarse_target(mesh, edge_length=length)
    assert coarse_target(mesh, edge_length=length) == want
    assert coarse_target(mesh, edge_length=1e6) == 4  # at least a tetrahedron's
    with pytest.raises(ParameterError, match="not both"):
        coarse_target(mesh, faces=50, edge_length=length)
    with pytest.raises(ParameterError, match="edge length"):
        coarse_target(mesh, edge_length="-3%")
    design = filletfold.round_mesh("blob", edge_length="200%")
    assert design.coarsening.faces_after <= want


def test_a_concave_polygon_is_triangulated_inside_itself():
    """A merged coplanar region may be concave: a fan from this L's first corner would cover
    4 instead of 3 (a triangle outside it), and the decimation would start from that."""
    from filletfold.mesh.polymesh import PolyMesh

    v = np.array([[2, 0, 0], [2, 1, 0], [1, 1, 0], [1, 2, 0], [0, 2, 0], [0, 0, 0]], float)
    mesh = PolyMesh(v, [np.arange(6)])
    p = v[triangles_of(mesh)]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    assert len(p) == 4 and area.sum() == pytest.approx(3.0) and np.all(area > 0)
