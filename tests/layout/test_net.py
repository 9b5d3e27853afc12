"""Nets (:mod:`filletfold.layout.net`): rigid fits, shared borders, the cut tree, and modules
joined into nets that overlap nothing."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import filletfold
from filletfold.layout.net import build_nets, cut_edges_for_nets, rigid_fit, shared_points
from filletfold.surface.piece import piece_area


@settings(max_examples=50, deadline=None)
@given(st.floats(-np.pi, np.pi), st.floats(-10, 10), st.floats(-10, 10), st.integers(0, 10**6))
def test_rigid_fit_recovers_a_rigid_motion(angle, tx, ty, seed):
    src = np.random.default_rng(seed).normal(size=(6, 2))
    c, s = np.cos(angle), np.sin(angle)
    dst = src @ np.array([[c, s], [-s, c]]) + [tx, ty]
    m = rigid_fit(src, dst)
    np.testing.assert_allclose(src @ m[:2, :2].T + m[:2, 2], dst, atol=1e-9)
    assert np.linalg.det(m[:2, :2]) == pytest.approx(1.0)


def test_a_reflection_is_not_fitted():
    src = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    m = rigid_fit(src, src * [1, -1])
    assert np.linalg.det(m[:2, :2]) == pytest.approx(1.0)


@pytest.mark.parametrize("name", ["cube", "icosahedron", "house"])
def test_the_cut_tree_cuts_each_closed_vertex_along_one_of_its_edges(name):
    m = filletfold.load_mesh(name)[0]
    cut = cut_edges_for_nets(m)
    assert cut.shape == (m.n_vertices,)
    for u in range(m.n_vertices):
        assert u in m.edges[cut[u]]


@pytest.mark.parametrize("name", ["cube", "icosahedron"])
def test_nets_hold_every_piece_once_and_overlap_nothing(name):
    d = filletfold.round_mesh(name, tabs=False, layout="modules")
    eps = 1e-9 * d.mesh.mean_edge_length
    shared = shared_points(d.pieces, eps)
    assert shared and all(shared[(b, a)] for (a, b) in shared)
    nets, members = build_nets(d.pieces, eps)
    assert sorted(i for m in members for i in m) == list(range(len(d.pieces)))
    assert 1 <= len(nets) < len(d.pieces)
    for net, m in zip(nets, members, strict=True):
        assert not net.overlaps()
        assert piece_area(net) == pytest.approx(sum(piece_area(d.pieces[i]) for i in m), rel=1e-9)


def test_a_net_design_has_fewer_pieces_than_modules():
    d = filletfold.round_mesh("cube", tabs=False, layout="net")
    assert d.layout == "net" and d.pattern.n_pieces < d.mesh.n_vertices


def _clash(placed, shape, corners, *tolerances) -> bool:
    """Whether one piece (its outline and border points, unmoved) clashes with a net of one
    placed piece ``placed`` (its outline and border points)."""
    import shapely

    from filletfold.layout.net import _Moving, _Placed

    net = _Placed([0], np.array([placed[0]], dtype=object), shapely.bounds([placed[0]]))
    border = [placed[1], corners]
    moving = _Moving(
        np.array([1]), np.array([shape], dtype=object), np.eye(3), np.tile(np.eye(3), (2, 1, 1)),
        border,
    )  # fmt: skip
    return net.clashes(moving, *tolerances)


def _square(x0: float, y0: float):
    import shapely

    return shapely.box(x0, y0, x0 + 1, y0 + 1)


def test_a_piece_touching_a_placed_one_at_two_points_of_the_surface_clashes():
    corner = np.array([[1.0, 1.0]])
    placed = (_square(0, 0), (corner, np.array([[0.0, 0.0, 0.0]])))
    same = (corner, np.array([[0.0, 0.0, 0.0]]))  # one point of the surface: glued there
    other = (corner, np.array([[0.0, 0.0, 1.0]]))  # two points at one place: a pinch
    assert not _clash(placed, _square(1, 1), same, 1e-9, 1e-9, 1e-12)
    assert _clash(placed, _square(1, 1), other, 1e-9, 1e-9, 1e-12)
    far = (np.array([[5.0, 5.0]]), np.array([[0.0, 0.0, 1.0]]))
    assert not _clash(placed, _square(3, 3), far, 1e-9, 1e-9, 1e-12)
    assert _clash(placed, _square(0.5, 0.5), far, 1e-9, 1e-9, 1e-12)  # overlaps a quarter


def test_nets_of_a_real_mesh_are_few_and_touch_only_where_they_are_glued():
    """The corpus sphere (162 vertices): nets joined smallest pair first make it one piece (6
    when grown from one seed at a time); no two sides of the pattern meet, flat, unless they
    share a point (a pinch would be two points of the surface at one place)."""
    import shapely

    from tests.test_corpus import CORPUS

    d = filletfold.round_mesh(str(CORPUS / "geometry-central-sphere_small.ply"), layout="net")
    assert d.certificate.ok
    assert d.pattern.n_pieces <= 2
    v2, edges = d.pattern.vertices_2d, d.pattern.edges
    lines = shapely.linestrings(v2[edges])
    a, b = shapely.STRtree(lines).query(lines, predicate="intersects")
    apart = (edges[a][:, :, None] != edges[b][:, None, :]).all(axis=(1, 2))
    assert not apart.any(), edges[a[apart]][:3]


def test_a_small_overlap_clashes_unless_it_is_a_sliver_along_a_glued_border():
    """A big piece overlapped by a small corner (far less than the tolerance of its area)
    still clashes (pyvista airplane: a small face under a 300-unit face piece); two copies of
    a border apart by round-off do not."""
    import shapely

    nowhere = (np.zeros((0, 2)), np.zeros((0, 3)))
    placed = (shapely.box(0, 0, 100, 100), nowhere)
    corner = shapely.box(99.999, 99.999, 200, 200)  # 1e-6 of the area overlapped, 1e-3 wide
    assert _clash(placed, corner, nowhere, 1e-9 * 1e5, 1e-9, 1e-12)
    beside = shapely.box(100 - 1e-13, 0, 200, 100)  # round-off of the shared border
    assert not _clash(placed, beside, nowhere, 1e-9, 1e-9, 1e-12)


def test_modules_touching_in_space_without_a_face_between_them_share_no_border():
    """Two triangles back to back (the second a copy of the first, reversed, as a split vertex's
    copies leave them): their modules' points coincide in 3D, but no face holds both vertices,
    so without the mesh they share a border and with it they share none."""
    from filletfold.mesh.polymesh import PolyMesh
    from filletfold.surface.piece import Piece

    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    mesh = PolyMesh(np.vstack([v, v]), [[0, 1, 2], [3, 5, 4]])
    edge = np.array([[0.5, 0.0, 0.0], [0.25, 0.25, 0.0]])  # a border segment, both copies

    def piece(u):
        return Piece(vertex=u, points_2d=list(edge[:, :2]), points_3d=list(edge))

    pieces = [piece(0), piece(1), piece(3)]
    assert (0, 2) in shared_points(pieces, 1e-9)  # coincident in space
    shared = shared_points(pieces, 1e-9, mesh)
    assert (0, 1) in shared and (1, 0) in shared  # vertices 0 and 1: one face
    assert (0, 2) not in shared and (1, 2) not in shared  # vertex 3: on the other triangle
