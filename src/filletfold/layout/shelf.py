"""Lay flat pieces out side by side without overlap (shelf packing of bounding boxes)."""

from __future__ import annotations

import numpy as np

from ..arrays import run_starts


def shelf_layout(boxes: np.ndarray, gap: float, row_width: float | None = None) -> np.ndarray:
    """Translations that place axis-aligned boxes in rows, never overlapping.

    Parameters
    ----------
    boxes : (n, 4) float
        ``(xmin, ymin, xmax, ymax)`` of each piece.
    gap : float
        Clearance between boxes.
    row_width : float, optional
        Target row width; default about the square root of the total box area times 1.4.

    Returns
    -------
    offset : (n, 2) float
        Translation to add to each piece; rows go downward (negative y) in input order.
    """
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    w = boxes[:, 2] - boxes[:, 0]
    h = boxes[:, 3] - boxes[:, 1]
    if row_width is None:
        area = float(np.sum((w + gap) * (h + gap)))
        row_width = max(np.sqrt(area) * 1.4, float(w.max(initial=0)))
    out = np.zeros((len(boxes), 2))
    x = 0.0
    y_top = 0.0
    row_h = 0.0
    for i in range(len(boxes)):
        if x > 0 and x + w[i] > row_width:
            y_top -= row_h + gap
            x = 0.0
            row_h = 0.0
        out[i] = (x - boxes[i, 0], y_top - boxes[i, 3])
        x += w[i] + gap
        row_h = max(row_h, h[i])
    return out


def shelf_offsets(pieces: list, gap: float) -> np.ndarray:
    """(n_pieces, 2) translations laying pieces side by side in rows."""
    points = [np.asarray(piece.points_2d, dtype=float).reshape(-1, 2) for piece in pieces]
    if not points:
        return shelf_layout(np.zeros((0, 4)), gap)
    p2 = np.concatenate(points)
    count = np.array([len(p) for p in points])
    first = run_starts(count)[:-1]
    boxes = np.hstack([np.minimum.reduceat(p2, first), np.maximum.reduceat(p2, first)])
    return shelf_layout(boxes, gap)
