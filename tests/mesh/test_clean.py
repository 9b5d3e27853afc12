"""clean_mesh: repairs (merging, orientation, coplanar faces) and every rejection path."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from filletfold.errors import MeshError
from filletfold.mesh import CleanLog, PolyMesh, clean_mesh, example_mesh
from filletfold.tolerances import tol

from ..conftest import random_convex, signed_volume


def cube():
    return example_mesh("cube")


def triangulated_cube():
    v, faces = cube()
    return v, [t for f in faces for t in (f[[0, 1, 2]], f[[0, 2, 3]])]


def subdivided_cube(triangles: bool = False):
    """Each cube face split into 4 quads (or 8 triangles) through edge midpoints and centre."""
    v, faces = cube()
    pts = [tuple(p) for p in v]
    index = {p: i for i, p in enumerate(pts)}

    def vid(p):
        p = tuple(np.round(p, 12))
        if p not in index:
            index[p] = len(pts)
            pts.append(p)
        return index[p]

    out = []
    for f in faces:
        c = vid(v[f].mean(axis=0))
        corners = [vid(v[i]) for i in f]
        mids = [vid((v[f[i]] + v[f[(i + 1) % 4]]) / 2) for i in range(4)]
        for i in range(4):
            quad = [corners[i], mids[i], c, mids[i - 1]]
            if triangles:
                out += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
            else:
                out.append(quad)
    return np.array(pts, dtype=np.float64), [np.array(f) for f in out]


def assert_is_unit_cube(mesh: PolyMesh):
    assert mesh.n_faces == 6 and mesh.n_vertices == 8
    assert all(len(f) == 4 for f in mesh.faces)
    assert_allclose(mesh.edge_length, 1.0, atol=1e-12)
    assert_allclose(signed_volume(mesh), 1.0, atol=1e-12)


# ------------------------------------------------------------------------------ repairs
def test_clean_returns_polymesh_and_log():
    mesh, log = clean_mesh(*cube())
    assert isinstance(mesh, PolyMesh) and isinstance(log, CleanLog)
    assert_is_unit_cube(mesh)
    assert_allclose(log.vertex_map, np.arange(8))
    assert_allclose(log.face_origin, np.arange(6))


def test_triangulated_cube_merges_back_to_quads():
    mesh, log = clean_mesh(*triangulated_cube())
    assert_is_unit_cube(mesh)
    assert log.merged_faces == 6
    assert sorted(log.face_origin.tolist()) == [0, 2, 4, 6, 8, 10]


def test_merge_coplanar_can_be_disabled():
    mesh, log = clean_mesh(*triangulated_cube(), merge_coplanar=False)
    assert mesh.n_faces == 12 and log.merged_faces == 0


@pytest.mark.parametrize("triangles", [False, True])
def test_subdivided_cube_merges_to_six_quads_and_eight_vertices(triangles):
    v, faces = subdivided_cube(triangles)
    assert len(v) == 26
    mesh, log = clean_mesh(v, faces)
    assert_is_unit_cube(mesh)
    assert log.merged_faces == len(faces) - 6
    assert log.removed_vertices == 18  # 12 edge midpoints + 6 face centres
    kept = log.vertex_map >= 0
    assert kept.sum() == 8
    assert_allclose(mesh.vertices[log.vertex_map[kept]], v[kept])
    assert_allclose(np.abs(v[kept]), 0.5)


def test_subdivided_open_box_drops_straight_boundary_corners():
    v, faces = subdivided_cube()
    keep = [f for f in faces if not np.allclose(v[f, 2], 0.5)]
    mesh, log = clean_mesh(v, keep)
    assert mesh.n_faces == 5 and mesh.n_vertices == 8
    assert log.merged_faces == len(keep) - 5
    assert not mesh.is_closed


def test_duplicate_vertices_are_merged():
    v, faces = cube()
    soup_v = np.concatenate([v[f] for f in faces])  # every face with its own 4 vertices
    soup_f = [np.arange(4 * i, 4 * i + 4) for i in range(6)]
    soup_v += np.random.default_rng(0).normal(scale=1e-13, size=soup_v.shape)
    mesh, log = clean_mesh(soup_v, soup_f)
    assert mesh.n_vertices == 8 and mesh.n_faces == 6
    assert log.merged_vertices == 16
    assert_allclose(mesh.vertices[log.vertex_map], soup_v, atol=1e-12)


def test_inconsistent_orientation_is_fixed():
    v, faces = cube()
    faces = [f[::-1] if i in (1, 4) else f for i, f in enumerate(faces)]
    mesh, log = clean_mesh(v, faces)
    assert log.flipped_faces == 2
    assert_is_unit_cube(mesh)


def test_inside_out_cube_is_turned_outward():
    v, faces = cube()
    mesh, log = clean_mesh(v, [f[::-1] for f in faces])
    assert log.flipped_faces == 6
    assert_is_unit_cube(mesh)
    centre_to_face = mesh.face_centroid - mesh.vertices.mean(axis=0)
    assert (np.einsum("ij,ij->i", mesh.face_normal, centre_to_face) > 0).all()


def test_open_mesh_keeps_majority_orientation():
    v, faces = example_mesh("open-box")
    faces = [f[::-1] if i == 2 else f for i, f in enumerate(faces)]
    mesh, log = clean_mesh(v, faces)
    assert log.flipped_faces == 1
    assert_allclose(mesh.faces[2], faces[2][[0, 3, 2, 1]])


def test_each_component_is_oriented_on_its_own():
    v, faces = cube()
    v2 = np.vstack([v, v + np.array([3.0, 0.0, 0.0])])
    faces2 = list(faces) + [f[::-1] + 8 for f in faces]  # second cube inside out
    mesh, log = clean_mesh(v2, faces2)
    assert log.flipped_faces == 6
    assert_allclose(signed_volume(mesh), 2.0, atol=1e-12)


def test_unreferenced_vertices_are_removed():
    v, faces = cube()
    v = np.vstack([[9.0, 9.0, 9.0], v])
    mesh, log = clean_mesh(v, [f + 1 for f in faces])
    assert mesh.n_vertices == 8 and log.removed_vertices == 1
    assert log.vertex_map[0] == -1
    assert_allclose(log.vertex_map[1:], np.arange(8))


def boundary_loops(mesh: PolyMesh) -> int:
    """Number of boundary loops of a mesh."""
    b = mesh.edges[mesh.is_boundary_edge]
    if not len(b):
        return 0
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix((np.ones(len(b)), (b[:, 0], b[:, 1])), shape=(mesh.n_vertices,) * 2)
    _, label = connected_components(graph, directed=False)
    return len(np.unique(label[b[:, 0]]))


def assert_manifold_oriented(mesh):
    """Every edge of ``mesh`` (a PolyMesh, or a list of faces) is used at most twice, in
    opposite directions, and every vertex has one fan of faces."""
    faces = mesh.faces if isinstance(mesh, PolyMesh) else mesh
    directed = [(int(a), int(b)) for f in faces for a, b in zip(f, np.roll(f, -1), strict=True)]
    assert len(set(directed)) == len(directed), "an edge is used twice in one direction"
    undirected = {}
    for a, b in directed:
        undirected[min(a, b), max(a, b)] = undirected.get((min(a, b), max(a, b)), 0) + 1
    assert max(undirected.values()) <= 2, "an edge is used by three faces or more"
    if isinstance(mesh, PolyMesh):
        for u in range(mesh.n_vertices):
            mesh.vertex_ring(u)  # one fan: raises otherwise


def assert_convex_planar(mesh: PolyMesh):
    assert mesh.corner_angles().max() <= np.pi + tol.angle
    for f, n in zip(mesh.faces, mesh.face_normal, strict=True):
        p = mesh.vertices[f]
        assert np.abs((p - p[0]) @ n).max() <= tol.planar * np.ptp(p, axis=0).max()


@pytest.mark.parametrize("as_triangles", [False, True])
def test_non_convex_polygons_become_convex_parts(as_triangles):
    """An L-shaped face (given as a hexagon, or as a fan of triangles) is split into convex
    parts: a reflex corner would leave its vertex without a cone."""
    v, faces = example_mesh("l-prism")
    if as_triangles:
        tris = []
        for f in faces:
            if len(f) == 6:  # fan from the corner opposite the reflex corner
                j = int(np.argmax([np.abs(v[i, :2] - v[f, :2].min(axis=0)).sum() == 0 for i in f]))
                g = np.roll(f, -j)
                tris += [g[[0, i, i + 1]] for i in range(1, 5)]
            else:
                tris += [f[[0, 1, 2]], f[[0, 2, 3]]]
        faces = tris
    mesh, log = clean_mesh(v, faces)
    assert 10 <= mesh.n_faces <= 12 and mesh.n_vertices == 12  # each L in 2 or 3 parts
    assert_convex_planar(mesh)
    assert_allclose(mesh.face_area.sum(), PolyMesh(v, example_mesh("l-prism")[1]).face_area.sum())
    split = [r for r in log.repairs if r.what == "split-face"]
    assert len(split) == (0 if as_triangles else 2)
    assert all("not convex" in r.why for r in split)
    if not as_triangles:
        with pytest.raises(AssertionError):  # strict keeps the reflex corners (no repair)
            assert_convex_planar(clean_mesh(v, faces, strict=True)[0])


def test_coplanar_region_with_hole_is_merged_into_convex_parts():
    # a flat 3 x 3 grid of unit squares without the centre one: boundary is two loops
    g = np.array([[x, y, 0.0] for y in range(4) for x in range(4)])
    quads = [
        np.array([j * 4 + i, j * 4 + i + 1, (j + 1) * 4 + i + 1, (j + 1) * 4 + i])
        for j in range(3)
        for i in range(3)
        if (i, j) != (1, 1)
    ]
    mesh, log = clean_mesh(g, quads)
    assert mesh.n_faces == 4 and log.merged_faces == 4
    assert_convex_planar(mesh)
    assert_allclose(mesh.face_area.sum(), 8.0, atol=1e-12)
    assert boundary_loops(mesh) == 2


def test_nearly_coplanar_faces_merge_within_tolerance_only():
    def bent_pair(angle_deg):
        t = np.radians(angle_deg)
        v = np.array(
            [
                [0, 0, 0],
                [1, 0, 0],
                [1, 1, 0],
                [0, 1, 0],
                [1 + np.cos(t), 0, np.sin(t)],
                [1 + np.cos(t), 1, np.sin(t)],
            ]
        )
        return v, [np.array([0, 1, 2, 3]), np.array([1, 4, 5, 2])]

    assert clean_mesh(*bent_pair(1e-5))[0].n_faces == 1
    assert clean_mesh(*bent_pair(0.01))[0].n_faces == 2
    # within coplanar_deg but the merged polygon would not be planar: kept apart
    assert clean_mesh(*bent_pair(0.01), coplanar_deg=1.0)[0].n_faces == 2
    assert clean_mesh(*bent_pair(1e-5), coplanar_deg=0)[0].n_faces == 2


def test_faces_as_2d_array_and_float_indices():
    v, faces = cube()
    arr = np.array(faces)
    mesh, _ = clean_mesh(v.tolist(), arr.astype(np.float64))
    assert_is_unit_cube(mesh)


# --------------------------------------------------- refusals (strict=True: repair nothing)
def test_nan_vertex_rejected_naming_the_vertex():
    v, faces = cube()
    v[3, 1] = np.nan
    with pytest.raises(MeshError, match=r"vertex 3 has a non-finite coordinate") as info:
        clean_mesh(v, faces, strict=True)
    assert info.value.vertex == 3


def test_bad_vertex_shape_rejected():
    with pytest.raises(MeshError, match=r"vertices must have shape \(n, 3\), got \(4, 2\)"):
        clean_mesh(np.zeros((4, 2)), [[0, 1, 2]])


def test_index_out_of_range_rejected():
    v, faces = cube()
    faces[1] = np.array([0, 1, 9, 3])
    with pytest.raises(
        MeshError, match=r"face 1 refers to vertex 9, outside the 8 vertices"
    ) as info:
        clean_mesh(v, faces)
    assert info.value.face == 1
    with pytest.raises(MeshError, match=r"face 0 refers to vertex -1"):
        clean_mesh(v, [[-1, 0, 1]])


def test_non_integer_face_rejected():
    with pytest.raises(MeshError, match=r"face 0 has non-integer vertex indices"):
        clean_mesh(np.eye(3), [[0, 1, 1.5]])
    with pytest.raises(MeshError, match=r"face 0 is not a list of vertex indices"):
        clean_mesh(np.eye(3), [["a", "b", "c"]])


def test_empty_mesh_rejected():
    with pytest.raises(MeshError, match=r"empty"):
        clean_mesh(np.zeros((0, 3)), [])
    with pytest.raises(MeshError, match=r"empty"):
        clean_mesh(np.eye(3), [])


def test_face_collapsed_by_merging_is_degenerate():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 1e-14], [1, 1, 0]], dtype=float)
    faces = [[0, 1, 2], [1, 4, 3]]  # vertices 1 and 3 coincide
    with pytest.raises(MeshError, match=r"degenerate face 1: it has 2 distinct vertices") as info:
        clean_mesh(v, faces, strict=True)
    assert info.value.face == 1


def test_short_face_is_degenerate():
    with pytest.raises(MeshError, match=r"degenerate face 0: it has 2 distinct"):
        clean_mesh(np.eye(3), [[0, 1]], strict=True)


def test_zero_area_face_is_degenerate():
    v = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], dtype=float)
    with pytest.raises(MeshError, match=r"degenerate face 1: its area is \(almost\) zero") as info:
        clean_mesh(v, [[0, 1, 3], [0, 1, 2]], strict=True)
    assert info.value.face == 1


def test_face_visiting_a_vertex_twice_is_degenerate():
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 2, 0]], dtype=float)
    with pytest.raises(MeshError, match=r"degenerate face 0: it visits a vertex twice"):
        clean_mesh(v, [[0, 1, 2, 4, 2, 3]], strict=True)


def test_duplicate_face_rejected():
    v, faces = example_mesh("tetrahedron")
    with pytest.raises(
        MeshError, match=r"degenerate face 4: it uses the same vertices as face 0"
    ) as info:
        clean_mesh(v, [*faces, faces[0][::-1]], strict=True)
    assert info.value.face == 4


def test_non_manifold_edge_rejected_naming_the_edge():
    v = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0], [-1, -1, 0]], dtype=float)
    fins = [[0, 1, 2], [0, 1, 3], [0, 1, 4]]  # three triangles on edge (0, 1)
    with pytest.raises(MeshError, match=r"non-manifold edge \(0, 1\): shared by 3 faces") as info:
        clean_mesh(v, fins, strict=True)
    assert info.value.edge == (0, 1)


def test_non_manifold_edge_named_by_input_indices_after_merging():
    v = np.array(
        [[9, 9, 9], [0, 0, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0], [-1, -1, 0], [0, 0, 1]], dtype=float
    )
    fins = [[1, 2, 3], [1, 2, 4], [1, 6, 5]]  # 6 duplicates 2
    with pytest.raises(MeshError, match=r"non-manifold edge \(1, 2\)") as info:
        clean_mesh(v, fins, strict=True)
    assert info.value.edge == (1, 2)


def test_bowtie_rejected_naming_the_vertex():
    v = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0, 2, 0], [1, 2, 0]], dtype=float)
    with pytest.raises(
        MeshError, match=r"non-manifold vertex 2: its faces form 2 separate fans"
    ) as info:
        clean_mesh(v, [[0, 1, 2], [2, 4, 3]], strict=True)
    assert info.value.vertex == 2


def test_two_cubes_touching_at_a_corner_rejected():
    v, faces = cube()
    corner = int(np.argmax(v.sum(axis=1)))  # (0.5, 0.5, 0.5)
    v2 = v + 1.0  # its (-0.5, -0.5, -0.5) corner lands on the first cube's corner
    faces2 = list(faces) + [f + 8 for f in faces]
    with pytest.raises(MeshError, match=rf"non-manifold vertex {corner}:") as info:
        clean_mesh(np.vstack([v, v2]), faces2, strict=True)
    assert info.value.vertex == corner


def moebius_strip(n: int = 8):
    """A triangulated Moebius band: vertices (2n, 3) and 2n triangles."""
    t = 2 * np.pi * np.arange(n) / n
    verts, quads = [], []
    for i, ti in enumerate(t):
        for s in (-0.3, 0.3):
            r = 1 + s * np.cos(ti / 2)
            verts.append([r * np.cos(ti), r * np.sin(ti), s * np.sin(ti / 2)])
        j = (i + 1) % n
        a, b = 2 * i, 2 * i + 1
        c, d = (2 * j, 2 * j + 1) if j else (2 * j + 1, 2 * j)  # the half twist
        quads.append([a, c, d, b])
    tris = [t for q in quads for t in ([q[0], q[1], q[2]], [q[0], q[2], q[3]])]
    return np.array(verts), tris


def test_moebius_strip_rejected():
    with pytest.raises(MeshError, match=r"non-orientable surface: the component containing face"):
        clean_mesh(*moebius_strip(), strict=True)


def test_non_planar_face_rejected():
    v, faces = cube()
    v = v.copy()
    v[int(np.argmax(v.sum(axis=1)))] += [0, 0, 0.01]
    with pytest.raises(MeshError, match=r"face \d+ is not planar: a vertex is") as info:
        clean_mesh(v, faces, strict=True)
    assert info.value.face in range(6)


def test_tolerances_are_used():
    # a duplicate closer than tol.merge * diagonal is the same point (no repair reported); one
    # closer than tol.weld * diagonal is welded (reported); one further away is not
    v, faces = cube()
    diag = np.sqrt(3.0)
    faces2 = [np.where(f == 0, 8, f) if i == 0 else f for i, f in enumerate(faces)]
    extra = np.vstack([v, v[0] + [0.1 * tol.merge * diag, 0, 0]])
    mesh, log = clean_mesh(extra, faces2)
    assert log.merged_vertices == 1 and mesh.n_vertices == 8 and log.repairs == []
    near = np.vstack([v, v[0] + [0.1 * tol.weld * diag, 0, 0]])
    mesh, log = clean_mesh(near, faces2)
    assert log.merged_vertices == 1 and mesh.n_vertices == 8
    assert [r.what for r in log.repairs] == ["weld"] and log.repairs[0].where == "vertices 0, 8"
    mesh, log = clean_mesh(near, faces2, strict=True)  # strict: a crack, as without welding
    assert log.merged_vertices == 0 and mesh.n_vertices == 9 and not mesh.is_closed
    far = np.vstack([v, v[0] + [10 * tol.weld * diag, 0, 0]])
    mesh, log = clean_mesh(far, faces2)  # now a crack: face 0 no longer shares vertex 0
    assert log.merged_vertices == 0 and mesh.n_vertices == 9
    assert not mesh.is_closed


@pytest.mark.parametrize(
    "faces, message",
    [
        # the first repeat in face order, with the face it repeats (sizes mixed)
        ([[0, 1, 2], [0, 2, 3], [3, 0, 1, 4], [2, 0, 1], [4, 1, 0, 3]], r"face 3: .* face 0"),
        ([[0, 1, 2], [1, 2, 3, 4], [0, 2, 3], [4, 3, 2, 1], [2, 1, 0]], r"face 3: .* face 1"),
    ],
)
def test_duplicate_faces_are_named_in_face_order(faces, message):
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.2], [0.5, -1, 0.3]], dtype=float)
    with pytest.raises(MeshError, match=message + r" \(duplicate face\)"):
        clean_mesh(v, [np.array(f) for f in faces], strict=True)


@pytest.mark.parametrize("bad", [[0, 1, 9], [0, -1, 2], [0.0, 1.5, 2.0], [0.0, np.nan, 2.0]])
def test_face_arrays_are_checked_like_face_lists(bad):
    """A rectangular face array (checked all at once) fails with the message of the
    row-by-row check, at the same face."""
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    faces = [[0, 2, 1], [0, 1, 3], bad, [0, 3, 2]]
    with pytest.raises(MeshError) as as_lists:
        clean_mesh(v, [np.asarray(f) for f in faces[:2]] + [np.asarray(bad)] + [np.array(faces[3])])
    with pytest.raises(MeshError) as as_array:
        clean_mesh(v, np.array(faces, dtype=float if isinstance(bad[0], float) else int))
    assert str(as_array.value) == str(as_lists.value) and as_array.value.face == 2


def test_face_array_and_face_lists_give_one_mesh():
    v, f = example_mesh("geodesic-sphere:level=2")
    a, _ = clean_mesh(v, np.asarray(f))
    b, _ = clean_mesh(v, [*[list(map(int, x)) for x in f][:-1], np.asarray(f[-1], dtype=float)])
    np.testing.assert_array_equal(a.vertices, b.vertices)
    assert [x.tolist() for x in a.faces] == [x.tolist() for x in b.faces]


# ------------------------------------------------------------- repairs of defects (default)
def whats(log: CleanLog) -> list[str]:
    return [r.what for r in log.repairs]


def test_faces_on_a_non_finite_vertex_are_dropped_and_reported():
    v, faces = cube()
    v = np.vstack([v, [np.nan, 0, 0], [7.0, np.inf, 0]])
    faces = [*faces, np.array([0, 1, 8]), np.array([2, 3, 9])]
    mesh, log = clean_mesh(v, faces)
    assert_is_unit_cube(mesh)
    assert whats(log) == ["drop-face", "drop-face"]
    assert [r.where for r in log.repairs] == ["face 6", "face 7"]
    assert "vertex 8 has a non-finite coordinate" in log.repairs[0].why
    with pytest.raises(MeshError, match="every face uses a vertex with a non-finite"):
        clean_mesh(np.full((3, 3), np.nan), [[0, 1, 2]])


def test_degenerate_faces_are_dropped_and_reported():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 1e-14], [1, 1, 0]], dtype=float)
    mesh, log = clean_mesh(v, [[0, 1, 2], [1, 4, 3]])  # vertices 1 and 3 coincide
    assert mesh.n_faces == 1 and whats(log) == ["drop-face"] and log.repairs[0].where == "face 1"
    assert "2 distinct vertices" in log.repairs[0].why


def test_zero_area_cap_is_removed_without_opening_the_surface():
    """A triangle whose middle vertex lies on its longest edge (a T-junction filler): it is
    removed and the face across that edge is split at the vertex, so a closed mesh stays
    closed."""
    v, faces = example_mesh("tetrahedron")
    a, b = faces[0][0], faces[0][1]
    m = 0.5 * (v[a] + v[b])
    v = np.vstack([v, m])
    c = len(v) - 1
    # face 0 (a, b, x) becomes (a, c, x), (c, b, x); the cap (a, b, c) has zero area and the
    # other face on (a, b) keeps its edge
    x = faces[0][2]
    faces = [np.array([a, c, x]), np.array([c, b, x]), *faces[1:], np.array([b, a, c])]
    mesh, log = clean_mesh(v, faces)
    assert mesh.is_closed and mesh.n_vertices == 4  # c is a straight corner again: removed
    assert "drop-face" in whats(log)
    assert "inserted into the face beside it" in log.repairs[0].why
    assert_allclose(signed_volume(mesh), signed_volume(PolyMesh(*example_mesh("tetrahedron"))))


def test_face_visiting_a_vertex_twice_is_split_into_simple_loops():
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 2, 0], [2, 1, 0]], dtype=float)
    mesh, log = clean_mesh(v, [[0, 1, 2, 5, 4, 2, 3]], merge_coplanar=False)
    assert sorted(len(f) for f in mesh.faces) == [3, 4]
    assert whats(log) == ["split-face", "split-vertex"]  # the two loops touch at vertex 2
    assert "visits vertex 2 twice" in log.repairs[0].why


def test_duplicate_faces_are_dropped_keeping_the_first():
    v, faces = example_mesh("tetrahedron")
    mesh, log = clean_mesh(v, [*faces, faces[0][::-1], faces[2]])
    assert mesh.n_faces == 4 and mesh.is_closed
    assert [r.where for r in log.repairs] == ["face 4", "face 5"]
    assert "same vertices as face 0" in log.repairs[0].why


def two_cubes(offset):
    v, faces = cube()
    return np.vstack([v, v + offset]), list(faces) + [f + 8 for f in faces]


@pytest.mark.parametrize(
    "offset, what, count",
    [((1.0, 1.0, 1.0), "split-vertex", 1), ((1.0, 1.0, 0.0), "cut-edge", 1)],
)
def test_solids_touching_at_a_vertex_or_an_edge_come_apart(offset, what, count):
    v, faces = two_cubes(np.array(offset))
    mesh, log = clean_mesh(v, faces)
    assert whats(log).count(what) == count
    assert mesh.n_faces == 12 and mesh.is_closed
    assert mesh.n_vertices == 16  # every vertex of each cube its own again
    assert_allclose(signed_volume(mesh), 2.0, atol=1e-12)  # both outward
    for u in range(mesh.n_vertices):
        assert mesh.vertex_ring(u).closed  # manifold everywhere


def test_fin_on_an_edge_is_cut_off_as_a_border():
    v = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0], [-1, -1, 0]], dtype=float)
    mesh, log = clean_mesh(v, [[0, 1, 2], [0, 1, 3], [0, 1, 4]], merge_coplanar=False)
    assert mesh.n_faces == 3 and whats(log).count("cut-edge") == 1
    assert "shared by 3 faces" in log.repairs[0].why
    for u in range(mesh.n_vertices):
        mesh.vertex_ring(u)  # manifold: no error


def test_moebius_strip_is_cut_open_and_oriented():
    verts, tris = moebius_strip()
    mesh, log = clean_mesh(verts, tris)
    assert "cut-edge" in whats(log)
    area = sum(PolyMesh(verts, [t]).face_area[0] for t in tris)
    assert_allclose(mesh.face_area.sum(), area, rtol=1e-12)
    assert "cannot be oriented" in next(r.why for r in log.repairs if r.what == "cut-edge")


def test_non_planar_quad_is_split_into_triangles():
    v, faces = cube()
    v = v.copy()
    v[int(np.argmax(v.sum(axis=1)))] += [0, 0, 0.01]
    mesh, log = clean_mesh(v, faces)
    assert mesh.n_faces == 7 and sorted(map(len, mesh.faces)) == [3] * 2 + [4] * 5
    assert whats(log) == ["split-face"] and "not planar" in log.repairs[0].why
    assert_convex_planar(mesh)


def test_near_straight_corner_next_to_a_rounded_edge_is_split():
    """A pentagon whose corner is 0.5 degrees from straight, on a prism: the tangent lines at
    that corner would cross far away, so the face is split there."""
    t = np.radians(0.5)
    base = np.array([[0, 0], [1, 0], [2, np.tan(t)], [2, 1], [0, 1]], dtype=float)
    v = np.vstack([np.c_[base, np.zeros(5)], np.c_[base, np.ones(5)]])
    top = np.arange(5, 10)
    sides = [np.array([i, (i + 1) % 5, (i + 1) % 5 + 5, i + 5]) for i in range(5)]
    mesh, log = clean_mesh(v, [np.arange(5)[::-1], top, *sides])
    split = [r for r in log.repairs if r.what == "split-face"]
    assert len(split) == 2 and all("from straight" in r.why for r in split)
    assert mesh.n_faces == 9
    angles = mesh.corner_angles()
    assert np.abs(angles - np.pi).min() > tol.straight


def test_triangle_soup_that_welding_cannot_join_is_refused():
    rng = np.random.default_rng(1)
    v = rng.uniform(size=(30, 3))
    with pytest.raises(MeshError, match=r"no two of the 10 faces share an edge"):
        clean_mesh(v, np.arange(30).reshape(10, 3))


def test_triangle_soup_of_a_real_surface_is_welded():
    v, faces = example_mesh("icosahedron")
    soup = np.concatenate([v[f] for f in faces])
    mesh, log = clean_mesh(soup, np.arange(len(soup)).reshape(-1, 3))
    assert mesh.n_vertices == 12 and mesh.is_closed and log.repairs == []


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), kind=st.sampled_from(["flip", "dup", "soup", "nm"]))
def test_repaired_mesh_is_manifold_oriented_planar_convex(seed, kind):
    """Whatever the defect, the repaired mesh is manifold everywhere, consistently oriented,
    and its faces are planar and convex."""
    rng = np.random.default_rng(seed)
    v, faces = random_convex(seed)
    faces = [np.asarray(f) for f in faces]
    if kind == "flip":
        faces = [f[::-1] if rng.random() < 0.4 else f for f in faces]
    elif kind == "dup":
        faces += [faces[i][::-1] for i in rng.choice(len(faces), 3, replace=False)]
    elif kind == "soup":
        v = np.concatenate([v[f] for f in faces])
        faces = list(np.arange(len(v)).reshape(-1, 3))
    else:  # a second copy touching the first at a vertex
        k = len(v)
        shift = v[0] - (v[0] * -1.0)
        v = np.vstack([v, -v + shift])
        faces += [f[::-1] + k for f in faces]
    mesh, _ = clean_mesh(v, faces)
    for u in range(mesh.n_vertices):
        mesh.vertex_ring(u)
    assert_convex_planar(mesh)
    assert signed_volume(mesh) > 0


def two_objects():
    """A tetrahedron lying in a corner of a cube (trimesh's two_objects.obj): once their
    shared vertices are welded, faces meet back to back."""
    v, faces = cube()
    t = np.array([[-0.5, -0.5, -0.5], [0.5, -0.5, -0.5], [-0.5, 0.5, -0.5], [-0.5, -0.5, 0.5]])
    tri = [[0, 2, 1], [0, 3, 2], [1, 3, 0], [1, 2, 3]]
    tris = [f[[0, 1, 2]] for f in faces] + [f[[0, 2, 3]] for f in faces]
    return np.vstack([v, t]), tris + [np.array(x) + 8 for x in tri]


def test_faces_back_to_back_are_cut_open_naming_the_edge():
    """The surface doubles back on itself along the cube's edges at the corner: each such
    edge is cut open (reported with its two faces), leaving a manifold oriented surface; with
    ``strict`` the first is refused, naming it."""
    mesh, log = clean_mesh(*two_objects())
    cuts = [r for r in log.repairs if "back to back" in r.why]
    assert cuts and all(r.what == "cut-edge" for r in cuts)
    assert all(re.fullmatch(r"edge \(\d+, \d+\)", r.where) for r in cuts)
    assert re.match(r"faces \d+ and \d+ lie back to back along it", cuts[0].why)
    assert_manifold_oriented(mesh)
    normal = mesh.face_normal  # no two faces back to back any more
    ef = mesh.edge_faces[(mesh.edge_faces >= 0).all(axis=1)]
    assert (np.einsum("ij,ij->i", normal[ef[:, 0]], normal[ef[:, 1]]) > -0.999).all()
    with pytest.raises(MeshError, match=r"non-manifold edge"):
        clean_mesh(*two_objects(), strict=True)  # its first defect


def folded_sheet():
    """A strip of three triangles whose last one is folded flat back over the middle one
    along edge (2, 3): the two meet back to back there."""
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.45, 0.7, 0]], dtype=float)
    return v, [[0, 1, 2], [1, 3, 2], [2, 3, 4]]


def test_a_sheet_folded_flat_is_cut_along_the_fold_or_refused_with_strict():
    mesh, log = clean_mesh(*folded_sheet(), merge_coplanar=False)
    assert log.repairs[0].what == "cut-edge"
    assert log.repairs[0].where == "edge (2, 3)"
    assert log.repairs[0].why.startswith("faces 1 and 2 lie back to back along it")
    assert_manifold_oriented(mesh)
    assert mesh.n_faces == 3
    with pytest.raises(
        MeshError, match=r"faces 1 and 2 lie back to back along edge \(2, 3\)"
    ) as info:
        clean_mesh(*folded_sheet(), strict=True)
    assert info.value.edge == (2, 3)


def test_a_mesh_too_small_for_where_it_lies_is_refused():
    """Scaled by 1e-6 and moved by 1e6, a cube's coordinates are resolved to 1.2e-10, 1e-4 of
    its size: no tolerance of the pipeline could hold; moved by 1e6 only, it is fine."""
    v, faces = cube()
    with pytest.raises(MeshError, match=r"double precision resolves its coordinates only"):
        clean_mesh(v * 1e-6 + 1e6, faces)
    mesh, _ = clean_mesh(v + 1e6, faces)
    assert mesh.n_faces == 6
