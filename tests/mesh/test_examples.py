"""Built-in example meshes: validity, orientation, edge lengths, curvature signs."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from filletfold.errors import MeshReadError
from filletfold.mesh import EXAMPLES, PolyMesh, clean_mesh, example_mesh, example_names, load_mesh

from ..conftest import signed_volume

NAMES = example_names()
CLOSED = [n for n in NAMES if EXAMPLES[n].closed]
OPEN = [n for n in NAMES if not EXAMPLES[n].closed]
PLATONIC = {
    "tetrahedron": (4, 3),
    "cube": (6, 4),
    "octahedron": (8, 3),
    "dodecahedron": (12, 5),
    "icosahedron": (20, 3),
}


def edge_is_convex(mesh: PolyMesh) -> np.ndarray:
    """(n_edges,) bool: True where the dihedral is convex (False on boundary edges)."""
    out = np.zeros(mesh.n_edges, dtype=bool)
    for e, (f, g) in enumerate(mesh.edge_faces):
        if f >= 0 and g >= 0:
            a = mesh.vertices[mesh.edges[e, 0]]
            out[e] = np.dot(mesh.face_centroid[g] - a, mesh.face_normal[f]) < -1e-12
    return out


@pytest.fixture(scope="module")
def cleaned():
    return {n: clean_mesh(*example_mesh(n)) for n in NAMES}


def test_registry_has_required_examples():
    required = {
        "tetrahedron",
        "cube",
        "octahedron",
        "dodecahedron",
        "icosahedron",
        "square-pyramid",
        "triangular-prism",
        "pentagonal-bipyramid",
        "house",
        "random-convex",
        "dimpled-cube",
        "l-prism",
        "torus",
        "open-box",
        "blob",
    }
    assert required <= set(NAMES)
    assert len(OPEN) >= 2
    for name, ex in EXAMPLES.items():
        assert ex.name == name and ex.description and ex.kinds


@pytest.mark.parametrize("name", NAMES)
def test_example_arrays(name):
    v, faces = example_mesh(name)
    assert v.dtype == np.float64 and v.ndim == 2 and v.shape[1] == 3
    assert all(f.dtype == np.int64 and f.ndim == 1 and len(f) >= 3 for f in faces)
    assert np.isfinite(v).all()


@pytest.mark.parametrize("name", NAMES)
def test_example_is_clean_already(name, cleaned):
    v, faces = example_mesh(name)
    mesh, log = cleaned[name]
    if name == "l-prism":  # its L-shaped faces are split into convex parts (reported)
        assert [r.what for r in log.repairs] == ["split-face"] * 2
        mesh, log = clean_mesh(v, faces, strict=True)
    assert log.repairs == []
    assert mesh.n_faces == len(faces)
    assert mesh.n_vertices == len(v)
    changes = [log.merged_vertices, log.flipped_faces, log.merged_faces, log.removed_vertices]
    assert changes == [0, 0, 0, 0]
    # the example's own faces are already a valid oriented manifold
    direct = PolyMesh(v, faces)
    assert direct.n_edges == mesh.n_edges


@pytest.mark.parametrize("name", NAMES)
def test_example_edge_manifold_and_oriented(name, cleaned):
    mesh, _ = cleaned[name]
    # every edge has one or two faces, and an interior edge is used once in each direction
    has = (mesh.edge_faces >= 0).sum(axis=1)
    assert has.min() >= 1
    assert mesh.is_closed == EXAMPLES[name].closed
    for u in range(mesh.n_vertices):  # vertex-manifold: one fan each
        ring = mesh.vertex_ring(u)
        assert ring.closed == (not mesh.is_boundary_vertex[u])


@pytest.mark.parametrize("name", NAMES)
def test_example_edge_length_about_one(name, cleaned):
    mesh, _ = cleaned[name]
    assert 0.85 <= mesh.mean_edge_length <= 1.25
    assert mesh.edge_length.min() > 0.4


@pytest.mark.parametrize("name", CLOSED)
def test_closed_examples_outward_and_euler(name, cleaned):
    mesh, _ = cleaned[name]
    assert signed_volume(mesh) > 0
    chi = mesh.n_vertices - mesh.n_edges + mesh.n_faces
    assert chi == (0 if "genus-1" in EXAMPLES[name].kinds else 2)


@pytest.mark.parametrize("name", OPEN)
def test_open_examples_are_discs(name, cleaned):
    mesh, _ = cleaned[name]
    assert mesh.n_vertices - mesh.n_edges + mesh.n_faces == 1
    assert mesh.is_boundary_edge.any()


@pytest.mark.parametrize("name", sorted(PLATONIC))
def test_platonic_solids_are_regular(name, cleaned):
    mesh, _ = cleaned[name]
    n_faces, k = PLATONIC[name]
    assert mesh.n_faces == n_faces
    assert all(len(f) == k for f in mesh.faces)
    assert_allclose(mesh.edge_length, 1.0, rtol=0, atol=1e-12)
    assert_allclose(mesh.vertices.mean(axis=0), 0.0, atol=1e-12)
    # all vertices on one sphere and all corner angles equal to the regular polygon's
    radius = np.linalg.norm(mesh.vertices, axis=1)
    assert_allclose(radius, radius[0], rtol=1e-12)
    assert_allclose(mesh.corner_angles(), np.pi * (k - 2) / k, atol=1e-12)


@pytest.mark.parametrize("name", [n for n in NAMES if "convex" in EXAMPLES[n].kinds])
def test_convex_examples(name, cleaned):
    mesh, _ = cleaned[name]
    inner = ~mesh.is_boundary_vertex
    assert (mesh.vertex_angle_sum[inner] < 2 * np.pi - 1e-6).all()
    inner_edges = ~mesh.is_boundary_edge
    assert edge_is_convex(mesh)[inner_edges].all()


@pytest.mark.parametrize("name", [n for n in NAMES if "saddle" in EXAMPLES[n].kinds])
def test_saddle_examples_have_saddle_vertices(name, cleaned):
    mesh, _ = cleaned[name]
    inner = ~mesh.is_boundary_vertex
    assert (mesh.vertex_angle_sum[inner] > 2 * np.pi + 1e-6).any()


def test_l_prism_saddles_are_the_reflex_edge_ends():
    mesh, _ = clean_mesh(*example_mesh("l-prism"), strict=True)  # its L faces kept whole
    saddles = np.nonzero(mesh.vertex_angle_sum > 2 * np.pi + 1e-9)[0]
    assert len(saddles) == 2
    assert_allclose(mesh.vertex_angle_sum[saddles], 2.5 * np.pi, atol=1e-12)
    a, b = mesh.vertices[saddles]
    assert_allclose(a[:2], b[:2], atol=1e-12)  # a vertical edge
    assert sorted(len(f) for f in mesh.faces) == [4] * 6 + [6, 6]


def test_torus_inner_vertices_are_saddles(cleaned):
    mesh, _ = cleaned["torus"]
    rho = np.linalg.norm(mesh.vertices[:, :2], axis=1)
    inner = rho < np.median(rho)
    assert (mesh.vertex_angle_sum[inner] > 2 * np.pi).all()
    assert (mesh.vertex_angle_sum[~inner] < 2 * np.pi).any()


@pytest.mark.parametrize("name", ["dimpled-cube", "blob"])
def test_non_convex_examples_have_reflex_edges_and_concave_vertices(name, cleaned):
    mesh, _ = cleaned[name]
    convex = edge_is_convex(mesh)
    assert (~convex).any() and convex.any()
    kinds = set()
    for u in range(mesh.n_vertices):
        c = convex[mesh.vertex_ring(u).edges]
        kinds.add("convex" if c.all() else "concave" if not c.any() else "mixed")
    assert kinds == {"convex", "concave", "mixed"}


def test_dimpled_cube_centre_is_pushed_in(cleaned):
    mesh, _ = cleaned["dimpled-cube"]
    top = mesh.vertices[:, 2].max()
    centre = np.nonzero(np.linalg.norm(mesh.vertices[:, :2], axis=1) < 1e-12)[0]
    assert len(centre) == 1
    assert_allclose(top - mesh.vertices[centre[0], 2], 0.2, atol=1e-12)


def test_blob_size_and_mixed_curvature(cleaned):
    mesh, _ = cleaned["blob"]
    assert mesh.n_faces == 320 and mesh.n_vertices == 162
    s = mesh.vertex_angle_sum
    assert (s > 2 * np.pi + 1e-6).any() and (s < 2 * np.pi - 1e-6).any()


def test_examples_are_deterministic_and_fresh():
    v1, f1 = example_mesh("random-convex")
    v1[:] = 0
    f1[0][:] = 0
    v2, f2 = example_mesh("random-convex")
    v3, f3 = example_mesh("random-convex")
    assert np.abs(v2).max() > 0
    assert np.array_equal(v2, v3)
    assert all(np.array_equal(a, b) for a, b in zip(f2, f3, strict=True))


def test_example_name_is_forgiving():
    v, _ = example_mesh("Open_Box")
    assert len(v) == 8


def test_unknown_example_lists_names_and_suggests():
    with pytest.raises(
        MeshReadError, match=r"no built-in example named 'cubee'.*did you mean 'cube'"
    ):
        example_mesh("cubee")
    with pytest.raises(MeshReadError, match=r"built-in examples: tetrahedron, cube"):
        example_mesh("zzzz")


# ------------------------------------------------------------------ invariance (hypothesis)
def _angle_sums_sorted(mesh):
    return np.sort(mesh.vertex_angle_sum)


@settings(max_examples=25, deadline=None)
@given(
    name=st.sampled_from(["cube", "dodecahedron", "l-prism", "torus", "open-box", "house"]),
    seed=st.integers(0, 2**32 - 1),
    scale=st.floats(0.01, 100.0),
    reverse_all=st.booleans(),
)
def test_clean_is_invariant_under_motion_and_renumbering(name, seed, scale, reverse_all):
    v, faces = example_mesh(name)
    ref, _ = clean_mesh(v, faces)
    rng = np.random.default_rng(seed)
    rot = Rotation.random(random_state=rng).as_matrix()
    moved = scale * v @ rot.T + rng.uniform(-10, 10, size=3)
    perm = rng.permutation(len(v))  # new index of each old vertex
    new_v = np.empty_like(moved)
    new_v[perm] = moved
    new_faces = [np.roll(perm[f], rng.integers(len(f))) for f in faces]
    if reverse_all:
        new_faces = [f[::-1] for f in new_faces]
    new_faces = [new_faces[i] for i in rng.permutation(len(new_faces))]
    # l-prism's L-shaped faces split into convex parts in more than one way: kept whole here
    strict = name == "l-prism"
    ref, _ = clean_mesh(v, faces, strict=strict)
    mesh, log = clean_mesh(new_v, new_faces, strict=strict)
    assert mesh.n_faces == ref.n_faces and mesh.n_vertices == ref.n_vertices
    assert_allclose(_angle_sums_sorted(mesh), _angle_sums_sorted(ref), atol=1e-9)
    assert_allclose(np.sort(mesh.edge_length) / scale, np.sort(ref.edge_length), rtol=1e-9)
    if EXAMPLES[name].closed:
        assert signed_volume(mesh) > 0
        assert log.flipped_faces == (len(faces) if reverse_all else 0)
        assert_allclose(signed_volume(mesh) / scale**3, signed_volume(ref), rtol=1e-9)
    else:
        assert log.flipped_faces == 0  # the majority orientation is kept on open meshes
    # vertex_map follows the renumbering
    assert_allclose(mesh.vertices[log.vertex_map], new_v)


def test_load_mesh_by_example_name():
    mesh, log = load_mesh("icosahedron")
    assert mesh.n_faces == 20
    assert log.merged_faces == 0


@pytest.mark.parametrize("spec", ["shell", "shell:3x1", "shell:8x5,opening=170,sag=0.4"])
def test_shell_is_a_vault_of_planar_quads(spec):
    v, faces = example_mesh(spec)
    a, b = (6, 4) if spec == "shell" else (3, 1) if spec == "shell:3x1" else (8, 5)
    assert len(v) == (a + 1) * (b + 1) and len(faces) == a * b
    assert all(len(f) == 4 for f in faces)
    mesh = PolyMesh(v, faces)
    for f, n in zip(faces, mesh.face_normal, strict=True):
        assert np.abs((v[f] - v[f].mean(axis=0)) @ n).max() < 1e-12  # planar
        assert n[2] > 0  # counter-clockwise seen from above
    assert abs(v[:, 2].min()) < 1e-12
    inner = ~mesh.is_boundary_vertex
    assert inner.sum() == (a - 1) * (b - 1)
    assert (mesh.vertex_angle_sum[inner] < 2 * np.pi - 1e-6).all()  # convex: positive defect


def test_shell_without_sag_is_a_developable_barrel_vault():
    mesh = PolyMesh(*example_mesh("shell:5x3,sag=0"))
    inner = ~mesh.is_boundary_vertex
    assert_allclose(mesh.vertex_angle_sum[inner], 2 * np.pi, atol=1e-12)


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("shell:1x3", "2..24 quads across"),
        ("shell:4x3,opening=10", "opening"),
        ("shell:4x3,sag=1", "sag"),
    ],
)
def test_shell_parameters_checked(spec, match):
    with pytest.raises(MeshReadError, match=match):
        example_mesh(spec)


def test_shell_rounds_with_every_inner_vertex_a_cone():
    import filletfold

    d = filletfold.round_mesh("shell", tabs=False)
    assert d.certificate.ok
    inner = ~d.mesh.is_boundary_vertex
    treatment = np.asarray(d.vertices.treatment)
    assert (treatment[inner] == "cone").all()
