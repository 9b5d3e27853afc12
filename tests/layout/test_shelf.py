"""Shelf packing (:mod:`filletfold.layout.shelf`): boxes in rows, never overlapping."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.layout.shelf import shelf_layout, shelf_offsets

from ..conftest import design_of


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 40), st.integers(0, 2**32 - 1), st.floats(0.0, 0.5))
def test_boxes_never_overlap_and_keep_the_gap(n, seed, gap):
    rng = np.random.default_rng(seed)
    lo = rng.normal(size=(n, 2)) * 5
    boxes = np.hstack([lo, lo + rng.uniform(0.01, 3.0, size=(n, 2))])
    t = shelf_layout(boxes, gap)
    assert t.shape == (n, 2)
    placed = boxes + np.hstack([t, t])
    for i in range(n):
        for j in range(i + 1, n):
            a, b = placed[i], placed[j]
            apart_x = a[2] + gap <= b[0] + 1e-9 or b[2] + gap <= a[0] + 1e-9
            apart_y = a[3] + gap <= b[1] + 1e-9 or b[3] + gap <= a[1] + 1e-9
            assert apart_x or apart_y, (i, j)


def test_shelf_offsets_lay_the_pieces_apart():
    pieces = design_of("cube").pieces
    t = shelf_offsets(pieces, 0.05)
    boxes = []
    for piece, off in zip(pieces, t, strict=True):
        p = np.asarray(piece.points_2d) + off
        boxes.append(np.concatenate([p.min(axis=0), p.max(axis=0)]))
    boxes = np.array(boxes)
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            a, b = boxes[i], boxes[j]
            assert a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]
    assert shelf_offsets([], 0.05).shape == (0, 2)
