"""The overlap proof and measure of :mod:`filletfold.surface.overlap`: sound on wound strips,
jittered grids and non-convex faces, the union only where the proof does not clear."""

from __future__ import annotations

import collections

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.rounding.edges import round_edges
from filletfold.surface.centres import face_piece_centres
from filletfold.surface.faces import face_polygons
from filletfold.surface.overlap import faces_interior_disjoint, faces_overlap, measured_overlap
from filletfold.vertex.frame import vertex_frame

from ..conftest import annulus_strip, design_of, jittered_grid
from ..reference.module import build_module


def reference_overlap(points_2d, faces, rel=1e-9) -> bool:
    """The overlap test without the fast proof: invalid faces, or union below the area sum."""
    polys = face_polygons(points_2d, faces)
    if not shapely.is_valid(polys).all():
        return True
    return bool(shapely.union_all(polys).area < shapely.area(polys).sum() * (1 - rel))


# ---------------------------------------------------------------- overlap proof


@pytest.mark.parametrize("fan", [False, True])
@pytest.mark.parametrize(
    ("turn", "overlap"),
    [(1.0, False), (np.pi, False), (1.9 * np.pi, False), (2.1 * np.pi, True), (3.5 * np.pi, True)],
)
def test_overlap_check_on_a_strip_wound_round(turn, overlap, fan):
    pts, faces = annulus_strip(turn, fan=fan)
    assert reference_overlap(pts, faces) is overlap
    assert faces_overlap(pts, faces) is overlap
    if overlap:
        assert not faces_interior_disjoint(pts, faces)
    else:
        assert faces_interior_disjoint(pts, faces)


def test_overlap_check_fires_on_crafted_failures():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    # two separate squares on top of each other (no shared edge: two border loops)
    pts = np.vstack([square, square + 0.5])
    assert faces_overlap(pts, [[0, 1, 2, 3], [4, 5, 6, 7]])
    # a self-intersecting face (bow tie) is invalid
    assert faces_overlap(square, [[0, 2, 1, 3]])
    # one triangle folded back over its neighbour across their shared edge
    pts = np.array([[0, 0], [1, 0], [0, 1], [0.3, 0.3]], dtype=float)
    assert faces_overlap(pts, [[0, 1, 2], [1, 3, 2][::-1]])
    # the same directed edge twice (two faces on one side of it)
    pts = np.array([[0, 0], [2, 0], [1, 1], [1, 2]], dtype=float)
    assert not faces_interior_disjoint(pts, [[0, 1, 2], [0, 1, 3]])
    assert faces_overlap(pts, [[0, 1, 2], [0, 1, 3]])
    # a clockwise face is not proved (the check then measures)
    assert not faces_interior_disjoint(square, [[3, 2, 1, 0]])
    # touching at a corner only is no overlap
    pts = np.vstack([square, square + 1.0])
    assert not faces_overlap(pts, [[0, 1, 2, 3], [4, 5, 6, 7]])


@pytest.mark.parametrize("turn", [1.0, 1.9 * np.pi, 2.0 * np.pi, 2.1 * np.pi, 3.5 * np.pi])
def test_overlap_pairs_only_spare_the_union(turn):
    """Pairs tried first give the measured answer: an overlapping pair answers at once, pairs
    that never overlap leave the answer to the union."""
    pts, faces = annulus_strip(turn)
    want = reference_overlap(pts, faces)
    n = len(faces)
    ends = [[0, n - 1], [1, n - 1], [0, n - 2]]
    for pairs in (None, ends, [[0, 1]], np.zeros((0, 2), dtype=int)):
        assert measured_overlap(pts, faces, pairs=pairs) is want
    # a pair sharing more than rel (1e-9) of the smaller face overlaps; less is round-off
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    pts = np.vstack([square, square + np.array([1 - 1e-8, 0])])
    assert measured_overlap(pts, [[0, 1, 2, 3], [4, 5, 6, 7]], pairs=[[0, 1]])
    pts = np.vstack([square, square + np.array([1 - 1e-12, 0])])
    assert not measured_overlap(pts, [[0, 1, 2, 3], [4, 5, 6, 7]], pairs=[[0, 1]])


def test_overlap_proof_on_non_convex_faces():
    # an L-shaped face and its neighbour: non-convex faces go through shapely's validity
    pts = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2], [3, 0], [3, 1]], dtype=float)
    faces = [[0, 1, 2, 3, 4, 5], [1, 6, 7, 2]]
    assert faces_interior_disjoint(pts, faces)
    assert not faces_overlap(pts, faces)
    pts[6] = [1.5, 0.5]  # the neighbour's corner now lies inside the L
    assert faces_overlap(pts, faces) and reference_overlap(pts, faces)
    assert not faces_interior_disjoint(pts, faces)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 0.9))
def test_overlap_proof_is_sound_on_jittered_grids(seed, jitter):
    """Whenever the fast proof says disjoint, the polygons' union has their total area."""
    rng = np.random.default_rng(seed)
    pts, quads = jittered_grid(rng, 5, jitter)
    faces = []
    for a, b, c, d in quads:
        faces.extend([[a, b, c], [a, c, d]] if rng.random() < 0.5 else [[a, b, c, d]])
    faces = [f if _signed_area(pts[f]) > 0 else f[::-1] for f in faces]
    assert faces_overlap(pts, faces) == reference_overlap(pts, faces)
    if faces_interior_disjoint(pts, faces):
        assert not reference_overlap(pts, faces)


def _signed_area(q) -> float:
    r = np.roll(q, -1, axis=0)
    return 0.5 * float(np.sum(q[:, 0] * r[:, 1] - r[:, 0] * q[:, 1]))


@pytest.mark.parametrize("name", ["torus", "l-prism", "saddle-patch", "icosahedron"])
def test_modules_split_exactly_where_the_union_says(name):
    """Every module piece is free of overlap by the union test; every vertex whose module was
    split overlaps as one piece by the union test too."""
    d = design_of(name, layout="modules")
    for piece in d.pieces:
        p2, _ = piece.arrays()
        assert not reference_overlap(p2, piece.faces)
        assert not piece.overlaps()
    count = collections.Counter(int(v) for v in d.pattern.piece_vertex)
    split = [u for u, k in count.items() if k > 1]
    if name == "icosahedron":
        assert not split
        return
    assert split
    rd = round_edges(d.mesh, d.rounding.radius)
    centres = face_piece_centres(d.mesh, rd)
    for u in split[:6]:
        fr = vertex_frame(d.mesh, rd, u)
        apex = d.vertices.apex[u] if np.isfinite(d.vertices.apex[u]).all() else None
        dev = d.vertices.apex_developed[u] if apex is not None else None
        (whole,) = build_module(d.mesh, fr, centres, 24, apex, dev, runs=[(0, fr.n_sides - 1)])
        p2, _ = whole.arrays()
        assert whole.overlaps() and reference_overlap(p2, whole.faces)
