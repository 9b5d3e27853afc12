"""Faces as flat arrays (:mod:`filletfold.surface.faces`): corner lists and counts, shapely
polygons, twice the signed area of polygons of one size, and :class:`FaceLists`."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.surface.faces import FaceLists, face_polygons, flat_faces, polygon_area2
from filletfold.surface.pattern import FaceRows

from ..conftest import jittered_grid, signed_area

FACES = [[0, 1, 2], [2, 1, 3, 4], [4, 3, 5, 6, 7]]


def star_polygon(rng, k: int, ccw: bool = True) -> np.ndarray:
    """A simple polygon of ``k`` corners, star-shaped about the origin (no two consecutive
    corners half a turn or more apart, as seen from it)."""
    t = (np.arange(k) + rng.uniform(-0.2, 0.2, size=k)) * (2 * np.pi / k)
    r = rng.uniform(0.3, 2.0, size=k)
    p = np.c_[r * np.cos(t), r * np.sin(t)]
    return p if ccw else p[::-1]


@st.composite
def face_lists(draw):
    sizes = draw(st.lists(st.integers(3, 7), max_size=15))
    return [draw(st.lists(st.integers(0, 40), min_size=k, max_size=k)) for k in sizes]


# ---------------------------------------------------------------- flat_faces


@settings(max_examples=100, deadline=None)
@given(face_lists())
def test_flat_faces_of_index_lists(faces):
    flat, size = flat_faces(faces)
    assert flat.dtype == np.int64 and size.dtype == np.int64
    assert size.tolist() == [len(f) for f in faces]
    assert flat.tolist() == [i for f in faces for i in f]


@settings(max_examples=50, deadline=None)
@given(face_lists())
def test_flat_faces_of_flat_faces_are_their_arrays(faces):
    size = np.array([len(f) for f in faces], dtype=np.int64)
    flat = np.array([i for f in faces for i in f], dtype=np.int64)
    for cls in (FaceRows, FaceLists):
        held = cls.of_sizes(flat, size)
        got_flat, got_size = flat_faces(held)
        assert got_flat is held.flat  # handed out as they are
        np.testing.assert_array_equal(got_size, size)
        # the same as the index lists
        ref_flat, ref_size = flat_faces(faces)
        np.testing.assert_array_equal(got_flat, ref_flat)
        np.testing.assert_array_equal(got_size, ref_size)


def test_flat_faces_of_arrays_and_of_nothing():
    flat, size = flat_faces([np.array([3, 1, 2]), (5, 6, 7, 8)])
    assert flat.tolist() == [3, 1, 2, 5, 6, 7, 8] and size.tolist() == [3, 4]
    flat, size = flat_faces([])
    assert flat.shape == size.shape == (0,)


# ---------------------------------------------------------------- face_polygons


@pytest.mark.parametrize("seed", range(5))
def test_face_polygons_have_the_shoelace_area(seed):
    rng = np.random.default_rng(seed)
    pts, quads = jittered_grid(rng, 5, 0.3)
    faces = [q if i % 2 else q[:3] for i, q in enumerate(quads)]  # quads and triangles
    polys = face_polygons(pts, faces)
    assert polys.shape == (len(faces),)
    assert shapely.is_valid(polys).all()
    for poly, f in zip(polys, faces, strict=True):
        assert poly.area == pytest.approx(abs(signed_area(pts[f])), rel=1e-12)
        np.testing.assert_array_equal(np.asarray(poly.exterior.coords)[: len(f)], pts[f])
    # the faces of a grid tile its square, overlapping nowhere
    quad_polys = face_polygons(pts, quads)
    total = shapely.area(quad_polys).sum()
    assert shapely.union_all(quad_polys).area == pytest.approx(total, rel=1e-12)


def test_face_polygons_of_flat_faces_are_those_of_index_lists():
    pts = np.random.default_rng(0).normal(size=(8, 2))
    held = FaceLists.of_sizes(np.concatenate(FACES), [len(f) for f in FACES])
    a, b = face_polygons(pts, FACES), face_polygons(pts, held)
    assert all(p.equals_exact(q, 0.0) for p, q in zip(a, b, strict=True))


# ---------------------------------------------------------------- polygon_area2


@settings(max_examples=100, deadline=None)
@given(st.integers(3, 12), st.integers(1, 6), st.integers(0, 10**6), st.booleans())
def test_polygon_area2_is_twice_the_signed_area(k, n, seed, ccw):
    rng = np.random.default_rng(seed)
    xy = np.stack([star_polygon(rng, k, ccw) + rng.normal(size=2) * 5 for _ in range(n)])
    got = polygon_area2(xy)
    assert got.shape == (n,)
    for a2, p in zip(got, xy, strict=True):
        assert a2 == pytest.approx(2 * signed_area(p), rel=1e-12, abs=1e-12)
        assert abs(a2) == pytest.approx(2 * shapely.Polygon(p).area, rel=1e-9)
        assert (a2 > 0) == ccw  # positive exactly for counter-clockwise polygons


@settings(max_examples=50, deadline=None)
@given(st.integers(3, 9), st.integers(0, 10**6))
def test_polygon_area2_does_not_depend_on_the_first_corner(k, seed):
    rng = np.random.default_rng(seed)
    p = star_polygon(rng, k)
    turned = np.stack([np.roll(p, s, axis=0) for s in range(k)])
    got = polygon_area2(turned)
    np.testing.assert_allclose(got, got[0], rtol=1e-12)
    # reversed corners: the same area, of the other sign
    np.testing.assert_allclose(polygon_area2(p[None, ::-1]), -got[:1], rtol=1e-12)


def test_polygon_area2_of_known_polygons():
    square = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    flat = np.array([[0, 0], [1, 1], [2, 2], [3, 3]], dtype=float)  # all on a line
    np.testing.assert_array_equal(polygon_area2(np.stack([square, square[::-1], flat])), [8, -8, 0])
    assert polygon_area2(np.zeros((0, 3, 2))).shape == (0,)


# ---------------------------------------------------------------- FaceLists


def test_face_lists_read_as_lists_of_int():
    held = FaceLists.of_sizes(np.concatenate(FACES), [len(f) for f in FACES])
    assert len(held) == len(FACES)
    assert held.lists() == FACES
    assert all(type(i) is int for f in held.lists() for i in f)
    assert held.lists() is held.lists()  # made once
    assert [held[i] for i in range(len(held))] == FACES
    assert held[-1] == FACES[-1] and held[0:2] == FACES[0:2]
    assert list(held) == FACES
    assert held == FACES and held == FaceLists.of_sizes(held.flat, [3, 4, 5])
    assert held != [*FACES[:2], [4, 3, 5, 6]]
    assert [4, 3, 5, 6, 7] in held and held.index([2, 1, 3, 4]) == 1
    with pytest.raises(IndexError):
        held[3]


def test_face_lists_from_offsets():
    flat = np.arange(7)
    held = FaceLists(flat, np.array([0, 3, 7]))
    assert held.lists() == [[0, 1, 2], [3, 4, 5, 6]]
    assert held.flat.dtype == np.int64 and held.start.dtype == np.int64
    assert FaceLists(np.zeros(0), np.zeros(1)).lists() == [] and len(FaceLists([], [0])) == 0


@pytest.mark.parametrize(
    ("other", "equal"),
    [
        (lambda: [np.array(f) for f in FACES], True),
        (lambda: FaceRows.of_sizes(np.concatenate(FACES), [3, 4, 5]), True),
        (lambda: None, False),
    ],
    ids=["arrays", "face-rows", "none"],
)
def test_face_lists_compare_without_raising(other, equal):
    held = FaceLists.of_sizes(np.concatenate(FACES), [len(f) for f in FACES])
    assert (held == other()) is equal
