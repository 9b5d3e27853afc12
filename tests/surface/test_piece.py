"""Pieces (:mod:`filletfold.surface.piece`, :mod:`filletfold.surface.faces`): merging coincident
points, and faces kept as flat arrays read as lists."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.surface.piece import Piece

from ..conftest import design_of

# ---------------------------------------------------------------- merging coincident points


def reference_merge(piece: Piece, eps: float) -> None:
    """The union-find and face-by-face loop :meth:`Piece.merge_coincident` replaces."""
    from scipy.spatial import cKDTree

    p2, p3 = piece.arrays()
    pairs = cKDTree(p2).query_pairs(eps, output_type="ndarray")
    if len(pairs) == 0:
        return
    pairs = pairs[np.linalg.norm(p3[pairs[:, 0]] - p3[pairs[:, 1]], axis=1) < eps]
    root = list(range(len(p2)))

    def find(i):
        while root[i] != i:
            i = root[i]
        return i

    for a, b in sorted(map(tuple, pairs.tolist())):
        ra, rb = find(a), find(b)
        root[max(ra, rb)] = min(ra, rb)
    root = [find(i) for i in range(len(root))]
    faces, patches = piece.faces, piece.patches
    piece.faces, piece.patches = [], []
    for f, patch in zip(faces, patches, strict=True):
        piece.face([root[i] for i in f], patch, min_area=eps * eps)
    used = sorted({i for f in piece.faces for i in f})
    new = {old: k for k, old in enumerate(used)}
    piece.points_2d = [piece.points_2d[i] for i in used]
    piece.points_3d = [piece.points_3d[i] for i in used]
    piece.faces = [[new[i] for i in f] for f in piece.faces]
    piece._keys = {k: new[root[i]] for k, i in piece._keys.items() if root[i] in new}
    if piece.apex_index is not None:
        piece.apex_index = new.get(root[piece.apex_index])


def _copy(piece: Piece) -> Piece:
    out = Piece(vertex=piece.vertex, apex_index=piece.apex_index)
    out.points_2d, out.points_3d = list(piece.points_2d), list(piece.points_3d)
    out.faces, out.patches = [list(f) for f in piece.faces], list(piece.patches)
    out._keys = dict(piece._keys)
    return out


def _same(a: Piece, b: Piece) -> None:
    assert np.array_equal(a.arrays()[0], b.arrays()[0])
    assert np.array_equal(a.arrays()[1], b.arrays()[1])
    assert a.faces == b.faces and a.patches == b.patches
    assert a._keys == b._keys and a.apex_index == b.apex_index


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_merge_coincident_is_the_union_find_loop(seed):
    """Points on a coarse grid (many coincide), faces with repeats, slivers and both turns."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 40))
    p2 = rng.integers(0, 4, size=(n, 2)).astype(float)
    p3 = np.c_[p2, np.where(rng.random(n) < 0.2, 1.0, 0.0)]  # some coincide in 2D only
    piece = Piece(vertex=1)
    for i in range(n):
        piece.point(("p", i), p2[i], p3[i])
    piece.apex_index = int(rng.integers(0, n))
    for j in range(int(rng.integers(1, 25))):
        f = rng.integers(0, n, size=int(rng.integers(3, 7))).tolist()
        piece.faces.append(f)
        piece.patches.append(f"face {j}")
    a, b = _copy(piece), _copy(piece)
    a.merge_coincident(1e-9)
    reference_merge(b, 1e-9)
    _same(a, b)


@pytest.mark.parametrize("name", ["miura", "cube"])
def test_merge_coincident_of_a_doubled_module(name):
    """Two copies of every module on top of each other merge into one, as the loop does."""
    for piece in design_of(name).pieces[:12]:
        twice = _copy(piece)
        base = len(piece.points_2d)
        twice.points_2d += list(piece.points_2d)
        twice.points_3d += list(piece.points_3d)
        twice.faces += [[i + base for i in f] for f in piece.faces]
        twice.patches += list(piece.patches)
        a, b = _copy(twice), _copy(twice)
        a.merge_coincident(1e-9)
        reference_merge(b, 1e-9)
        _same(a, b)
        assert len(a.points_2d) == len(piece.points_2d)


def test_face_lists_read_as_lists_of_int():
    """A batched piece's faces (one flat array) read exactly as the lists build_module makes,
    and a face added afterwards turns them into a plain list."""
    from filletfold.surface.faces import FaceLists
    from filletfold.surface.piece import Piece

    faces = FaceLists.of_sizes(np.array([0, 1, 2, 2, 1, 3, 4]), np.array([3, 4]))
    assert len(faces) == 2 and faces[1] == [2, 1, 3, 4] and faces[-1] == [2, 1, 3, 4]
    assert list(faces) == [[0, 1, 2], [2, 1, 3, 4]] == faces
    assert all(type(i) is int for f in faces for i in f)
    piece = Piece(
        vertex=0,
        points_2d=np.array([[0.0, 0], [1, 0], [0, 1], [1, 1], [2, 2]]),
        points_3d=np.zeros((5, 3)),
        faces=faces,
        patches=["face 0", "face 1"],
    )
    piece.face([1, 4, 3], "face 2")
    assert piece.faces == [[0, 1, 2], [2, 1, 3, 4], [1, 4, 3]]


def test_face_rows_read_as_the_list_of_face_arrays():
    """An assembled pattern's faces (FaceRows: one flat array) index, slice and iterate as the
    list of (k,) int64 arrays they replace; face_arrays gives their arrays back as they are."""
    from filletfold.surface.pattern import FaceRows, face_arrays

    faces = [np.array([0, 1, 2]), np.array([2, 1, 3, 4]), np.array([4, 3, 5])]
    flat, start = face_arrays(faces)
    rows = FaceRows(flat, start)
    assert len(rows) == 3 and bool(rows) and not bool(FaceRows(flat[:0], start[:1]))
    for got in (list(rows), rows[:], [rows[i] for i in range(3)], [rows[-3], rows[-2], rows[-1]]):
        assert [g.tolist() for g in got] == [f.tolist() for f in faces]
        assert all(g.dtype == np.int64 for g in got)
    assert rows[np.int64(1)].tolist() == [2, 1, 3, 4]
    with pytest.raises(IndexError):
        rows[3]
    got_flat, got_start = face_arrays(rows)
    assert got_flat is flat and got_start is start
    assert list(FaceRows(flat[:0], start[:1])) == []


def test_lowest_linked_matches_the_connected_components():
    """Label propagation gives every point its group's lowest index, as the sparse graph's
    connected components do."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from filletfold.surface.piece import lowest_linked

    rng = np.random.default_rng(0)
    for _ in range(300):
        n, m = int(rng.integers(1, 40)), int(rng.integers(0, 60))
        pairs = rng.integers(0, n, size=(m, 2))
        graph = coo_matrix((np.ones(m), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, group = connected_components(graph, directed=False)
        low = np.full(group.max() + 1, n)
        np.minimum.at(low, group, np.arange(n))
        assert np.array_equal(lowest_linked(pairs, n), low[group])


def test_a_faces_area_is_polygon_area2_to_the_bit():
    """``Piece.face`` measures each polygon with Python floats: the same sums in the same
    order as :func:`~filletfold.surface.faces.polygon_area2`, bit for bit."""
    import numpy as np

    from filletfold.surface.faces import polygon_area2
    from filletfold.surface.piece import _area2

    rng = np.random.default_rng(3)
    for k in (3, 4, 5, 9):
        xy = rng.normal(size=(200, k, 2)) * rng.choice([1e-6, 1.0, 1e4], (200, 1, 1))
        want = polygon_area2(xy)
        for j in range(len(xy)):
            pts = list(xy[j])
            assert _area2(pts, list(range(k))) == want[j]
