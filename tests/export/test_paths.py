"""Cut paths (:mod:`filletfold.export.paths`): borders, creases and tabs as polylines and
splines."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from filletfold.export.paths import (
    SPLINE_MIN_POINTS,
    chain_is_smooth,
    chain_runs,
    edge_chains,
    simplify_polyline,
    simplify_polylines,
    tab_cut_paths,
)
from filletfold.surface.pattern import Annotations

SVG_NS = "{http://www.w3.org/2000/svg}"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- paths


def test_edge_chains_cover_every_edge_once():
    edges = np.array([[0, 1], [1, 2], [2, 3], [1, 4], [5, 6], [6, 7], [5, 7]])
    chains = edge_chains(edges)
    # vertex 1 has degree 3: three open paths end there; 5-6-7 is a loop
    assert sorted((tuple(c), closed) for c, closed in chains) == sorted(
        [((0, 1), False), ((1, 2, 3), False), ((1, 4), False), ((5, 6, 7), True)]
    )
    segs = set()
    for c, closed in chains:
        ring = list(c) + ([c[0]] if closed else [])
        segs |= {tuple(sorted(int(v) for v in s)) for s in itertools.pairwise(ring)}
    assert segs == {tuple(e) for e in edges.tolist()}


def test_edge_chains_mask_and_empty():
    edges = np.array([[0, 1], [1, 2], [2, 3]])
    assert edge_chains(edges, np.zeros(3, dtype=bool)) == []
    ((c, closed),) = edge_chains(edges, np.array([True, True, False]))
    assert c.tolist() == [0, 1, 2] and not closed


def _chains_one_edge_at_a_time(edges, mask=None) -> list:
    """The walk :func:`edge_chains` does, one edge per Python step: the reference for its
    paths and their order (open paths from their lower end vertex, by vertex then edge; then
    loops of degree-two vertices from their lowest-numbered edge)."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    ids = np.arange(len(edges)) if mask is None else np.flatnonzero(mask)
    adjacency: dict[int, list[int]] = {}
    for e in ids.tolist():
        for v in edges[e].tolist():
            adjacency.setdefault(v, []).append(e)
    used: set = set()

    def walk(start, e):
        path, v = [start], start
        while True:
            used.add(e)
            a, b = edges[e].tolist()
            v = b if a == v else a
            if v == start:
                return path, True
            path.append(v)
            nxt = [f for f in adjacency[v] if f not in used]
            if len(adjacency[v]) != 2 or not nxt:
                return path, False
            e = nxt[0]

    out = []
    for v in sorted(adjacency):
        if len(adjacency[v]) != 2:
            out += [walk(v, e) for e in adjacency[v] if e not in used]
    out += [walk(int(edges[e, 0]), e) for e in ids.tolist() if e not in used]
    return [(list(path), closed) for path, closed in out]


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.tuples(st.integers(0, 9), st.integers(0, 9)), min_size=1, max_size=24),
    st.lists(st.booleans(), min_size=24, max_size=24),
)
def test_edge_chains_walk_as_one_edge_at_a_time(pairs, keep):
    """Random multigraphs (parallel edges, branches, loops through a branch vertex, rings):
    the same paths in the same order as the edge-by-edge walk."""
    edges = np.array([(a, b) for a, b in pairs if a != b], dtype=np.int64).reshape(-1, 2)
    mask = np.array(keep[: len(edges)], dtype=bool)
    for m in (None, mask):
        got = [(c.tolist(), closed) for c, closed in edge_chains(edges, m)]
        assert got == _chains_one_edge_at_a_time(edges, m)


@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.lists(st.tuples(st.integers(0, 3), st.integers(0, 3)), min_size=1, max_size=8),
            st.booleans(),
        ),
        min_size=1,
        max_size=6,
    )
)
def test_simplify_polylines_is_simplify_polyline_of_each(paths):
    """On grid points (repeated points, straight runs, closing repeats) the batch gives the
    arrays :func:`simplify_polyline` gives path by path."""
    paths = [(np.array(q, dtype=float), closed) for q, closed in paths]
    got = simplify_polylines(paths)
    assert len(got) == len(paths)
    for g, (q, closed) in zip(got, paths, strict=True):
        assert np.array_equal(g, simplify_polyline(q, closed))


def test_simplify_polyline_drops_collinear_points():
    p = np.array([[0, 0], [1, 0], [2, 0], [2, 0], [2, 1], [2, 2]], dtype=float)
    assert simplify_polyline(p).tolist() == [[0, 0], [2, 0], [2, 2]]
    square = np.array([[0, 0], [1, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    assert len(simplify_polyline(square, closed=True)) == 4


def arc(step_deg: float, n: int) -> np.ndarray:
    t = np.radians(step_deg) * np.arange(n)
    return np.c_[np.cos(t), np.sin(t)]


@pytest.mark.parametrize(
    ("points", "smooth"),
    [
        (arc(5.0, 20), True),
        (arc(10.0, 20), False),  # turns more than 8 degrees per point
        (arc(5.0, SPLINE_MIN_POINTS - 1), False),  # too few points
        (np.vstack([arc(5.0, 10), [[-3.0, 5.0]]]), False),  # a corner at the end
    ],
)
def test_chain_is_smooth_rule(points, smooth):
    assert chain_is_smooth(points) is smooth


def test_chain_runs_split_at_corners_and_spacing_jumps():
    # an arc, a long straight segment tangent to it, then a corner
    a = arc(4.0, 15)
    end = a[-1]
    tangent = np.array([-math.sin(math.radians(56.0)), math.cos(math.radians(56.0))])
    p = np.vstack([a, end + 2.0 * tangent, end + 2.0 * tangent + [5.0, 0.0]])
    runs = chain_runs(p)
    assert [(len(r), s) for r, s, _ in runs] == [(15, True), (3, False)]
    assert_allclose(runs[0][0][-1], runs[1][0][0])
    # a full circle is one closed spline whose last point repeats the first
    ((pts, spline, closed),) = chain_runs(arc(6.0, 60), closed=True)
    assert spline and closed and np.array_equal(pts[0], pts[-1])


def ref_tab_cut_paths(annotations: Annotations) -> list[tuple[np.ndarray, bool]]:
    """tab_cut_paths one tab at a time, as it was written before it took all tabs at once."""
    from filletfold.export.paths import _HINGE_RTOL, _on_segment

    out = []
    hinges = list(annotations.tab_hinges)
    for t, tab in enumerate(annotations.tabs):
        p = np.asarray(tab, dtype=np.float64).reshape(-1, 2)
        if len(p) > 1 and np.array_equal(p[0], p[-1]):
            p = p[:-1]
        hinge = np.asarray(hinges[t], dtype=np.float64).reshape(2, 2) if t < len(hinges) else None
        if hinge is None or len(p) < 2:
            out.append((p, True))
            continue
        size = max(float(np.ptp(p, axis=0).max()), 1.0)
        on_hinge = _on_segment(p, hinge, _HINGE_RTOL * size)
        is_hinge_edge = on_hinge & np.roll(on_hinge, -1)
        if not is_hinge_edge.any() or is_hinge_edge.all():
            out.append((p, True))
            continue
        k = len(p)
        start = (int(np.flatnonzero(is_hinge_edge)[-1]) + 1) % k
        order = [(start + i) % k for i in range(k + 1)]
        pieces, current = [], [p[order[0]]]
        for i in range(k):
            if is_hinge_edge[order[i]]:
                if len(current) > 1:
                    pieces.append(np.array(current))
                current = [p[order[i + 1]]]
            else:
                current.append(p[order[i + 1]])
        if len(current) > 1:
            pieces.append(np.array(current))
        out.extend((piece, False) for piece in pieces)
    return out


@st.composite
def tab_outlines(draw):
    """A tab outline and its hinge: points on a line (the hinge) and off it, some repeated,
    some within a hair of the tolerance, a closing point that repeats the first."""
    k = draw(st.integers(0, 7))
    scale = draw(st.sampled_from([1e-3, 1.0, 250.0]))
    a = np.array(draw(st.tuples(*[st.floats(-5, 5)] * 2))) * scale
    d = np.array(draw(st.sampled_from([(1.0, 0.0), (0.6, 0.8), (0.0, 0.0)]))) * scale
    normal = np.array([-d[1], d[0]]) / max(float(np.hypot(*d)), 1e-300)
    eps = 1e-7 * max(scale, 1.0)
    pts = []
    for _ in range(k):
        t = draw(st.sampled_from([0.0, 1.0, 0.3, 1.5, -0.2]))
        off = draw(st.sampled_from([0.0, 0.0, 0.2 * scale, eps, eps * (1 + 1e-15), 0.5 * eps]))
        pts.append(a + t * d + off * normal)
    if pts and draw(st.booleans()):
        pts.append(pts[0])
    hinge = np.array([a, a + d])
    return np.array(pts).reshape(-1, 2), hinge


@pytest.mark.slow  # fast tier near its budget: in make test-slow (CI runs both)
@settings(max_examples=300, deadline=None)
@given(st.lists(tab_outlines(), max_size=12), st.integers(0, 12))
def test_tab_cut_paths_all_at_once_are_the_tab_by_tab_paths(outlines, n_hinges):
    ann = Annotations(tabs=[p for p, _ in outlines], tab_hinges=[h for _, h in outlines][:n_hinges])
    got, ref = tab_cut_paths(ann), ref_tab_cut_paths(ann)
    assert [c for _, c in got] == [c for _, c in ref]
    assert all(
        np.array_equal(a, b) and a.shape == b.shape for (a, _), (b, _) in zip(got, ref, strict=True)
    )


@pytest.mark.parametrize(
    "rows",
    [
        [],
        [np.ones((3, 2)), np.zeros((0, 2)), np.arange(4).reshape(2, 2)],
        [[[0, 1], [2, 3]], np.array([[True, False]])],
        [np.arange(4.0), np.ones((1, 2))],  # flat and 2-D
        [np.arange(6.0), np.arange(2)],  # all flat
        [np.array([["1.5", "2"]])],
        [np.ones((2, 1, 2))],
    ],
)
def test_point_rows_reads_each_row_as_its_points(rows):
    from filletfold.export.paths import point_rows

    ref = [np.asarray(r, dtype=np.float64).reshape(-1, 2) for r in rows]
    got, sizes = point_rows(rows)
    assert sizes.tolist() == [len(r) for r in ref]
    assert got.dtype == np.float64 and np.array_equal(got, np.concatenate([np.zeros((0, 2)), *ref]))
    with pytest.raises(ValueError):
        point_rows([*rows, np.ones(3)])


def test_tab_cut_paths_leave_the_hinge_out():
    tab = np.array([[0, 0], [0.2, -0.2], [0.8, -0.2], [1, 0]], dtype=float)
    ann = Annotations(
        tabs=[tab, tab + np.array([2.0, 0.0])], tab_hinges=[np.array([[1.0, 0.0], [0.0, 0.0]])]
    )
    (p0, c0), (p1, c1) = tab_cut_paths(ann)
    assert not c0 and p0.tolist() == tab.tolist()  # open path 0 -> 3, the hinge 3 -> 0 left out
    assert c1 and len(p1) == 4  # no hinge given for the second tab: all of it is cut
