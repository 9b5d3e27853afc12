"""The crease pattern (:mod:`filletfold.surface.pattern`): edges derived from the faces, their
assignments and fold angles, the cut borders, and the faces read as arrays."""

from __future__ import annotations

import numpy as np
import pytest

from filletfold.surface.pattern import CreasePattern, edge_faces_of, face_arrays

from ..conftest import design_of


@pytest.mark.parametrize("name", ["cube", "torus", "l-prism"])
def test_edges_are_the_faces_sides_once_each(name):
    p = design_of(name).pattern
    sides = set()
    for f in p.faces:
        f = np.asarray(f)
        for a, b in zip(f.tolist(), np.roll(f, -1).tolist(), strict=True):
            sides.add((min(a, b), max(a, b)))
    edges = [tuple(e) for e in p.edges.tolist()]
    assert edges == sorted(sides)
    assert (p.edges[:, 0] < p.edges[:, 1]).all()


@pytest.mark.parametrize("name", ["cube", "torus"])
def test_edge_faces_hold_the_edge(name):
    p = design_of(name).pattern
    for e, (a, b) in enumerate(p.edges.tolist()):
        faces = [f for f in p.edge_faces[e].tolist() if f >= 0]
        assert faces
        for f in faces:
            assert {a, b} <= set(np.asarray(p.faces[f]).tolist())
        border = len(faces) == 1
        assert border == (p.edge_assignment[e] == "B")


@pytest.mark.parametrize("name", ["cube", "torus", "dimpled-cube"])
def test_fold_angle_signs_follow_the_assignment(name):
    p = design_of(name).pattern
    angle, assign = p.edge_fold_angle, p.edge_assignment
    assert (angle[assign == "M"] < 0).all()
    assert (angle[assign == "V"] > 0).all()
    assert (angle[(assign == "B") | (assign == "F")] == 0).all()
    assert (np.abs(angle) < 180).all()


def test_cut_borders_come_in_pairs_on_one_folded_segment():
    p = design_of("cube").pattern
    cut = p.cut_mask()
    border = p.edge_assignment == "B"
    assert cut.any() and (border & ~cut).sum() == 0  # a closed surface: every border is a cut
    ends = np.sort(np.round(p.vertices_3d[p.edges[cut]], 9).reshape(-1, 6), axis=0)
    segments = {}
    for e in np.flatnonzero(cut).tolist():
        a, b = (tuple(np.round(p.vertices_3d[i], 9)) for i in p.edges[e])
        segments.setdefault(tuple(sorted([a, b])), []).append(e)
    assert len(ends) == cut.sum()
    assert all(len(v) == 2 for v in segments.values())


def test_face_arrays_are_the_faces():
    p = design_of("torus").pattern
    flat, start = face_arrays(p.faces)
    assert start[-1] == len(flat) and len(start) == len(p.faces) + 1
    for k in (0, 1, len(p.faces) // 2, len(p.faces) - 1):
        assert flat[start[k] : start[k + 1]].tolist() == np.asarray(p.faces[k]).tolist()


# ---------------------------------------------------------------- cut borders


def reference_cut_mask(p: CreasePattern, decimals: int = 9) -> np.ndarray:
    b = np.nonzero(p.edge_assignment == "B")[0]
    ends = np.round(p.vertices_3d[p.edges[b]], decimals)
    ends = np.sort(ends.view([("", ends.dtype)] * 3).reshape(len(b), 2), axis=1)
    _, inv, counts = np.unique(ends, axis=0, return_inverse=True, return_counts=True)
    mask = np.zeros(len(p.edges), dtype=bool)
    mask[b] = counts[inv.ravel()] > 1
    return mask


@pytest.mark.parametrize("name", ["cube", "torus", "open-box", "tent"])
def test_cut_mask_matches_the_structured_unique(name):
    p = design_of(name).pattern
    assert np.array_equal(p.cut_mask(), reference_cut_mask(p))
    assert np.array_equal(p.cut_mask(3), reference_cut_mask(p, 3))


def test_cut_mask_treats_minus_zero_as_zero():
    """Two border edges whose folded ends differ only by the sign of a zero are one cut."""
    v2 = np.array([[0, 0], [1, 0], [0, 1], [3, 0], [4, 0], [3, 1]], dtype=float)
    v3 = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1e-12, 0, 0], [1, 0, -0.0], [0, -1, 0]])
    p = CreasePattern(v2, v3, [[0, 1, 2], [3, 4, 5]], ["face 0", "face 1"], [0, 1], [0, 1])
    assert np.array_equal(p.cut_mask(), reference_cut_mask(p))
    assert p.cut_mask().sum() == 2


@pytest.mark.parametrize("name", ["cube", "torus"])
def test_edge_faces_of_finds_the_faces_the_pattern_derived(name):
    """edge_faces_of (what a pattern read from a file is given) agrees with the faces a
    pattern found beside its own edges; an edge given the other way round has them swapped,
    an edge no face has gets -1 on both sides."""
    p = design_of(name).pattern
    n = len(p.vertices_2d)
    assert np.array_equal(edge_faces_of(p.edges, p.faces, n), p.edge_faces)
    assert np.array_equal(edge_faces_of(p.edges[:, ::-1], p.faces, n), p.edge_faces[:, ::-1])
    assert edge_faces_of([[0, n - 1]], [], n).tolist() == [[-1, -1]]
    read = CreasePattern(
        p.vertices_2d, p.vertices_3d, p.faces, p.face_patch, p.face_piece, p.piece_vertex,
        edges=p.edges, edge_assignment=p.edge_assignment, edge_fold_angle=p.edge_fold_angle,
    )  # fmt: skip
    assert read.edge_faces is None
    assert np.array_equal(read.faces_beside_edges(), p.edge_faces)
