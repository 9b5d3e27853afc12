"""Convex polygons on arrays (:mod:`filletfold.layout.convex`) against shapely: separating
axes, overlap areas (clipped or by Green's theorem), and the grid that finds overlapping boxes."""

from __future__ import annotations

import numpy as np
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.layout import convex


def _quads(rng, n):
    """Random convex quadrilaterals (n, 4, 2): corners on stretched circles."""
    angle = np.sort(rng.uniform(0, 2 * np.pi, (n, 4)), axis=1)
    ring = np.stack([np.cos(angle), np.sin(angle)], axis=-1)
    stretch = rng.normal(size=(n, 2, 2)) * 0.4
    return rng.uniform(0, 2, (n, 1, 2)) + np.einsum("nij,nkj->nki", stretch, ring)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_separating_axes_and_clipping_agree_with_shapely(seed):
    rng = np.random.default_rng(seed)
    a, b = _quads(rng, 40), _quads(rng, 40)
    pa = [shapely.Polygon(x) for x in a]
    pb = [shapely.Polygon(x) for x in b]
    gap = convex.sat_gap(a, b)
    for k in range(len(a)):
        if gap[k] > 1e-9:
            assert pa[k].distance(pb[k]) >= gap[k] * (1 - 1e-9)
        elif gap[k] < -1e-9:
            assert pa[k].intersects(pb[k])
    normal, offset = convex.inward_lines(b)
    area, empty = convex.clip_area(a, normal, offset)
    want = np.array([x.intersection(y).area for x, y in zip(pa, pb, strict=True)])
    np.testing.assert_allclose(area, want, rtol=1e-9, atol=1e-12)
    assert (want[empty] == 0).all()
    area, empty, doubt = convex.convex_overlap(a, b)
    np.testing.assert_allclose(area[~doubt], want[~doubt], rtol=1e-9, atol=1e-12)
    assert (want[empty] == 0).all()
    # a square on a side of the other: corners on its line, left to clip_area (or no overlap)
    c = np.concatenate([b[:, 1::-1], b[:, :2] + (b[:, 1:2] - b[:, :1]) @ [[0, -1], [1, 0]]], 1)
    area, empty, doubt = convex.convex_overlap(c, b)
    assert (doubt | (np.abs(area) <= 1e-12)).all()


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_grid_finds_every_overlapping_box(seed):
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0, 10, (200, 2))
    hi = lo + rng.exponential(0.5, (200, 2)) * rng.choice([1, 1, 20], (200, 1))
    qlo = rng.uniform(-1, 11, (50, 2))
    qhi = qlo + rng.exponential(0.3, (50, 2))
    a, b = convex.BoxGrid(lo, hi).query(qlo, qhi)
    want = np.argwhere(((qlo[:, None] <= hi[None]) & (lo[None] <= qhi[:, None])).all(axis=2))
    assert sorted(zip(a.tolist(), b.tolist(), strict=True)) == sorted(map(tuple, want.tolist()))
