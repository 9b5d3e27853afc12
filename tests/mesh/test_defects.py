"""Defects of real meshes (issue 26), each made by hand: repaired into a manifold, oriented
surface with the repair listed naming its element, and ``filletfold round`` gives a design
whose certificate holds; with ``strict`` the defect is refused, naming the element.

Non-manifold vertices and edges, an edge used twice in one direction, faces back to back,
reversed pairs of faces (walls, fins), duplicate and zero-area faces, faces visiting a vertex
many times."""

from __future__ import annotations

import json
import time

import numpy as np
import pytest

from filletfold.cli import main
from filletfold.errors import MeshError
from filletfold.mesh import clean_mesh, example_mesh, write_obj
from filletfold.mesh.repair import _simple_loops

from ..conftest import signed_volume
from .test_clean import assert_manifold_oriented


def whats(log) -> list[str]:
    return [r.what for r in log.repairs]


def round_file(tmp_path, v, faces, name="m.obj"):
    """``filletfold round`` on the mesh written as OBJ: exit code 0, the certificate holds
    (in the report and again from the files); the report's repairs."""
    path = tmp_path / name
    write_obj(path, v, faces)
    out = tmp_path / (name + ".out")
    assert main(["round", str(path), "-o", str(out), "-q"]) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["certificate"]["ok"] is True
    assert main(["check", str(out)]) == 0
    return report["repairs"]


# ----------------------------------------------------------------------------- the meshes
def cone(apex, base_z, n=6):
    """A closed cone (apex, ring of n, centre of the base), outward."""
    t = 2 * np.pi * np.arange(n) / n
    ring = np.c_[np.cos(t), np.sin(t), np.full(n, base_z)]
    v = np.vstack([apex, ring, [0, 0, base_z]])
    up = base_z < apex[2]
    faces = []
    for i in range(n):
        j = (i + 1) % n
        side, base = [0, 1 + i, 1 + j], [n + 1, 1 + j, 1 + i]
        faces += [side, base] if up else [side[::-1], base[::-1]]
    return v, faces


def bowtie():
    """Two cones touching at their apexes (vertex 0 and vertex 8, the same point)."""
    v1, f1 = cone([0, 0, 0], -1.0)
    v2, f2 = cone([0, 0, 0], 1.0)
    return np.vstack([v1, v2]), f1 + [[x + len(v1) for x in f] for f in f2]


def cube():
    v, faces = example_mesh("cube")
    return v, [f.tolist() for f in faces]


def cube_with_fin():
    """A third face on edge (a, b) of the cube, sticking out."""
    v, faces = cube()
    a, b = faces[0][0], faces[0][1]
    return np.vstack([v, 3 * v[[a, b]].mean(axis=0)]), [*faces, [a, b, 8]], (a, b)


def spike_quads():
    """Two non-planar quads on the same pair of opposite corners (0, 2), sharing the edges
    (0, 3) and (3, 2) (a mirror plane through vertex 3, as in Suzanne's nose): split along
    their shared diagonal, their inner triangles would be one triangle twice, edge (0, 2)
    used twice in each direction."""
    v = np.array(
        [
            [0.0, -0.656, 0.531],
            [0.781, 0.594, 0.219],
            [0.0, 0.281, -0.562],
            [0.0, -0.813, -0.406],
            [-0.781, 0.594, 0.219],
        ]
    )
    return v, [[0, 1, 2, 3], [0, 3, 2, 4]]


# ------------------------------------------------------------------- 1. non-manifold spots
def test_bowtie_vertex_is_split_into_one_copy_per_fan(tmp_path):
    v, faces = bowtie()
    mesh, log = clean_mesh(v, faces)
    assert whats(log) == ["split-vertex"]
    assert log.repairs[0].where == "vertex 0"
    assert "2 separate fans" in log.repairs[0].why
    assert_manifold_oriented(mesh)
    assert mesh.n_vertices == 14 and mesh.is_closed  # the bases' centres are flat: removed
    assert signed_volume(mesh) > 0
    repairs = round_file(tmp_path, v, faces)
    assert [r["where"] for r in repairs] == ["vertex 0"]
    with pytest.raises(MeshError, match=r"non-manifold vertex 0: its faces form 2") as info:
        clean_mesh(v, faces, strict=True)
    assert info.value.vertex == 0


def test_three_faces_on_an_edge_are_cut_apart(tmp_path):
    v, faces, (a, b) = cube_with_fin()
    mesh, log = clean_mesh(v, faces)
    cut = [r for r in log.repairs if r.what == "cut-edge"]
    assert len(cut) == 1 and cut[0].where == f"edge ({min(a, b)}, {max(a, b)})"
    assert "shared by 3 faces" in cut[0].why
    assert_manifold_oriented(mesh)
    repairs = round_file(tmp_path, v, faces)
    assert any(r["what"] == "cut-edge" for r in repairs)
    with pytest.raises(MeshError, match=r"non-manifold edge \(\d, \d\): shared by 3") as info:
        clean_mesh(v, faces, strict=True)
    assert info.value.edge == (min(a, b), max(a, b))


def test_an_edge_used_twice_in_one_direction_is_reoriented_and_reported(tmp_path):
    v, faces = cube()
    faces = [f[::-1] if i in (1, 4) else f for i, f in enumerate(faces)]
    mesh, log = clean_mesh(v, faces)
    assert whats(log) == ["flip-face"] and log.repairs[0].where == "faces 1, 4"
    assert "in the same direction" in log.repairs[0].why
    assert_manifold_oriented(mesh)
    assert signed_volume(mesh) == pytest.approx(1.0)
    repairs = round_file(tmp_path, v, faces)
    assert [r["what"] for r in repairs] == ["flip-face"]


def test_an_inside_out_closed_piece_is_turned_and_reported():
    v, faces = cube()
    mesh, log = clean_mesh(v, [f[::-1] for f in faces])
    assert whats(log) == ["flip-face"] and "inside out" in log.repairs[0].why
    assert signed_volume(mesh) == pytest.approx(1.0)
    assert clean_mesh(v, [f[::-1] for f in faces], strict=True)[1].repairs == []


def test_quads_sharing_a_diagonal_are_split_along_their_other_ones(tmp_path):
    """Suzanne (common-3d-test-models) stopped with 'edge (70, 136) is used twice in the
    same direction': triangulating her non-planar quads 142 and 143 along the diagonal they
    share made a doubled triangle. The other diagonals are chosen."""
    v, faces = spike_quads()
    mesh, log = clean_mesh(v, faces)
    assert whats(log) == ["split-face", "split-face"]
    assert [r.where for r in log.repairs] == ["face 0", "face 1"]
    assert_manifold_oriented(mesh)
    assert len({frozenset(f.tolist()) for f in mesh.faces}) == 4  # no triangle twice
    assert mesh.face_area.sum() > 0
    round_file(tmp_path, v, faces)


def test_a_polygon_whose_every_diagonal_is_taken_is_split_around_a_new_vertex():
    """A non-planar quad (0, 1, 2, 3) whose diagonals (0, 2) and (1, 3) are both edges of
    other faces already: split around a new vertex at its middle."""
    from filletfold.mesh.repair import RepairLog, edge_keys, split_into_triangles

    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.3], [0, 1, 0], [0.5, 0.5, -1.0]], dtype=float)
    faces = [np.array(f) for f in ([0, 1, 2, 3], [0, 2, 4], [1, 3, 4])]
    log = RepairLog()
    out, origin, v2 = split_into_triangles(
        faces, np.arange(3), v, [0], log, lambda i: "bent", lambda o, i: ""
    )
    assert len(v2) == 6 and len(out) == 6 and origin.tolist() == [0, 0, 0, 0, 1, 2]
    assert all(5 in f for f in out[:4])
    assert "around a new vertex at its middle" in log.repairs[0].why
    np.testing.assert_allclose(v2[5], v[:4].mean(axis=0))
    # and otherwise the diagonals it takes are no edges yet
    assert len(edge_keys(out, 6)) == len(edge_keys(faces, 6)) + 4  # the four spokes


# --------------------------------------------------------- 2. faces back to back, inner pairs
def test_two_solids_sharing_a_face_lose_the_inner_pair(tmp_path):
    """Two cubes side by side, each closed: the shared square is there twice, in opposite
    orders. Both copies go (no hole is left) and the two cubes are one box."""
    v, faces = cube()
    v2 = np.vstack([v, v + np.array([1.0, 0.0, 0.0])])
    faces2 = faces + [[x + 8 for x in f] for f in faces]
    mesh, log = clean_mesh(v2, faces2)
    drops = [r for r in log.repairs if r.what == "drop-face"]
    assert len(drops) == 2 and all("reversed" in r.why for r in drops)
    assert mesh.is_closed and mesh.n_faces == 6
    assert signed_volume(mesh) == pytest.approx(2.0)
    assert_manifold_oriented(mesh)
    repairs = round_file(tmp_path, v2, faces2)
    assert sorted(r["where"] for r in repairs if r["what"] == "drop-face") == ["face 5", "face 6"]


def test_a_zero_volume_fin_is_dropped_as_a_pair(tmp_path):
    v, faces = cube()
    a, b = faces[0][0], faces[0][1]
    v2 = np.vstack([v, 3 * v[[a, b]].mean(axis=0)])
    faces2 = [*faces, [a, b, 8], [b, a, 8]]
    mesh, log = clean_mesh(v2, faces2)
    assert [(r.what, r.where) for r in log.repairs] == [
        ("drop-face", "face 6"),
        ("drop-face", "face 7"),
    ]
    assert "face 7 reversed" in log.repairs[0].why
    assert mesh.is_closed and mesh.n_faces == 6 and mesh.n_vertices == 8
    round_file(tmp_path, v2, faces2)
    with pytest.raises(MeshError, match=r"degenerate face 7: .* same vertices as face 6"):
        clean_mesh(v2, faces2, strict=True)


def test_a_reversed_copy_of_a_face_of_a_closed_surface_is_dropped_alone():
    """Dropping both would open the surface: the copy goes, the first is kept."""
    v, faces = example_mesh("tetrahedron")
    mesh, log = clean_mesh(v, [*faces, faces[0][::-1]])
    assert [(r.what, r.where) for r in log.repairs] == [("drop-face", "face 4")]
    assert "same vertices as face 0 (duplicate face)" in log.repairs[0].why
    assert mesh.is_closed and mesh.n_faces == 4


def test_a_two_sided_sheet_keeps_one_side():
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    mesh, log = clean_mesh(v, [[0, 1, 2], [0, 2, 3], [2, 1, 0], [3, 2, 0]])
    assert mesh.n_faces == 1 and [r.where for r in log.repairs] == ["face 2", "face 3"]


def test_faces_back_to_back_along_an_edge_go_through_round(tmp_path):
    """The beetle (common-3d-test-models) stopped with 'faces 578 and 868 lie back to back
    along edge (343, 344)': such an edge is cut open now, reported."""
    from .test_clean import two_objects

    v, faces = two_objects()
    repairs = round_file(tmp_path, v, [np.asarray(f) for f in faces])
    assert any(r["what"] == "cut-edge" and "back to back" in r["why"] for r in repairs)


# --------------------------------------------------------------- 4. duplicate and degenerate
def test_a_doubled_face_is_dropped_and_reported(tmp_path):
    v, faces = cube()
    faces2 = [*faces, faces[2], np.roll(faces[3], 1).tolist()]
    mesh, log = clean_mesh(v, faces2)
    assert [(r.what, r.where) for r in log.repairs] == [
        ("drop-face", "face 6"),
        ("drop-face", "face 7"),
    ]
    assert "same vertices as face 2" in log.repairs[0].why
    assert_manifold_oriented(mesh)
    assert len(round_file(tmp_path, v, faces2)) == 2


def test_zero_area_faces_are_removed_and_reported(tmp_path):
    """A T-junction filler (a vertex on the edge of its triangle), a triangle on one point
    and a quad on one line: removed, the surface stays closed."""
    v, faces = cube()
    a, b = faces[0][0], faces[0][1]
    x = faces[0][2]
    m = (v[a] + v[b]) / 2
    q = [v[a] + t * (v[b] - v[a]) for t in (0.25, 0.75)]
    v2 = np.vstack([v, m, v[x], v[x], q])  # 8: on edge (a, b); 9, 10: copies of x
    faces2 = [
        [a, 8, x, faces[0][3]],
        [8, b, x],
        *faces[1:],
        [b, a, 8],  # zero area: 8 lies on its edge (a, b)
        [x, 9, 10],  # one point
        [a, 11, 12, b],  # one line
    ]
    mesh, log = clean_mesh(v2, faces2)
    assert [(r.what, r.where) for r in log.repairs] == [
        ("drop-face", "face 8"),
        ("drop-face", "face 7"),
        ("drop-face", "face 9"),
    ]
    assert "1 distinct vertices" in log.repairs[0].why
    assert "vertex 8 lies on its edge" in log.repairs[1].why
    assert "area is (almost) zero" in log.repairs[2].why
    assert_manifold_oriented(mesh)
    assert mesh.is_closed and signed_volume(mesh) == pytest.approx(1.0)
    round_file(tmp_path, v2, faces2)


def test_a_face_visiting_a_vertex_many_times_is_split_fast(tmp_path):
    """A closed fan written as one face that comes back to its apex after each triangle:
    split into its triangles in one pass (linear in its length)."""
    n = 3000
    t = 2 * np.pi * np.arange(n) / n
    v = np.vstack([[0, 0, 0.5], np.c_[np.cos(t), np.sin(t), np.zeros(n)], [0, 0, -0.5]])
    face = [x for i in range(n) for x in (0, 1 + i, 1 + (i + 1) % n)]
    bottom = [[n + 1, 1 + (i + 1) % n, 1 + i] for i in range(n)]
    start = time.perf_counter()
    mesh, log = clean_mesh(v, [face, *bottom], merge_coplanar=False)
    assert time.perf_counter() - start < 30
    assert whats(log) == ["split-face"]
    assert log.repairs[0].why == f"it visits vertex 0 {n} times: split into {n} simple polygon(s)"
    assert mesh.n_faces == 2 * n and mesh.is_closed
    assert_manifold_oriented(mesh)
    with pytest.raises(MeshError, match=r"degenerate face 0: it visits a vertex twice"):
        clean_mesh(v, [face, *bottom], strict=True)


def test_splitting_face_loops_is_linear():
    loop = [x for i in range(100_000) for x in (0, 1 + 2 * i, 2 + 2 * i)]
    start = time.perf_counter()
    parts = _simple_loops(loop)
    assert time.perf_counter() - start < 5  # quadratic, it took minutes
    assert len(parts) == 100_000 and parts[0] == [0, 1, 2] and parts[-1][0] == 0
    assert _simple_loops([0, 1, 2, 1]) == []  # back and forth: no loop of three
    assert _simple_loops([0, 1, 2, 5, 4, 2, 3]) == [[2, 5, 4], [0, 1, 2, 3]]


def folded_over_octahedron():
    """An octahedron whose vertex 5 (below) is moved up into the plane of face 0, inside it:
    face 3 (0, 5, 1) then lies folded over on face 0 along edge (0, 1), whose two ends are
    inside the surface, so no cut can separate the two."""
    v, faces = example_mesh("octahedron")
    v = v.copy()
    v[5] = v[0][0] * np.array([0.4, 0.4, 0.2])
    return v, [f.tolist() for f in faces]


def test_a_triangle_folded_over_inside_the_surface_is_dropped(tmp_path):
    """The beetle's faces 578 and 868 (common-3d-test-models): back to back along an edge
    inside the surface. One of the two goes, reported, leaving a hole."""
    v, faces = folded_over_octahedron()
    mesh, log = clean_mesh(v, faces)
    drops = [r for r in log.repairs if r.what == "drop-face"]
    assert len(drops) == 1 and drops[0].where in ("face 0", "face 3")
    assert "back to back on face" in drops[0].why and "edge (0, 1)" in drops[0].why
    assert mesh.n_faces == 7 and not mesh.is_closed
    assert_manifold_oriented(mesh)
    round_file(tmp_path, v, faces)
    with pytest.raises(MeshError, match=r"faces 0 and 3 lie back to back along edge \(0, 1\)"):
        clean_mesh(v, faces, strict=True)


def test_the_last_guard_repairs_what_a_later_step_might_break():
    """Should a step after orientation ever leave an edge used twice in one direction, or by
    three faces, the last guard re-orients or cuts it, reported (strict: names the edge)."""
    from filletfold.mesh.clean import _ensure_manifold
    from filletfold.mesh.repair import RepairLog

    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1.0]])
    same = [np.array([0, 1, 2]), np.array([0, 1, 3])]
    log = RepairLog()
    faces, _, _, flipped = _ensure_manifold(same, np.arange(2), v, np.arange(5), log, False)
    assert flipped == 1 and [r.what for r in log.repairs] == ["flip-face"]
    assert_manifold_oriented(faces)
    three = [*same, np.array([1, 0, 4])]
    log = RepairLog()
    faces, _, v2, _ = _ensure_manifold(three, np.arange(3), v, np.arange(5), log, False)
    assert len(v2) > len(v)  # the cut gave vertices copies
    assert "cut-edge" in [r.what for r in log.repairs]
    assert_manifold_oriented(faces)
    with pytest.raises(MeshError, match=r"edge \(0, 1\) is used twice in the same direction"):
        _ensure_manifold(same, np.arange(2), v, np.arange(5), RepairLog(strict=True), True)
    tri = [np.array([0, 1, 2]), np.array([1, 0, 3])]  # nothing to do: the same lists back
    assert _ensure_manifold(tri, np.arange(2), v, np.arange(5), RepairLog(), False)[0] is tri
