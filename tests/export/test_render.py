"""The z-buffer renderer (:mod:`filletfold.export.render`) behind ``preview.png``."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from filletfold.export.render import MARGIN, png_bytes, render, view_frame

RED, GREEN, BLACK = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 0.0)


def two_squares(near_z: float = 1.0, far_z: float = 0.0, near_half: float = 1.0):
    """A far square (half size 2, z = far_z, green) and a nearer one (half size near_half,
    z = near_z, red) over it, seen from +z: four triangles, faces 0 (near) and 1 (far)."""
    q = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=np.float64)
    points = np.vstack(
        [
            np.column_stack([near_half * q, np.full(4, near_z)]),
            np.column_stack([2 * q, np.full(4, far_z)]),
        ]
    )
    tris = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    colors = np.array([RED, RED, GREEN, GREEN])
    return points, tris, colors, np.array([0, 0, 1, 1])


TOP = {"azim": -90.0, "elev": 90.0}  # right = +x, up = +y


def pixel(img, x: float, y: float) -> np.ndarray:
    """The pixel at (x, y) of the two-squares scene seen from TOP (the far square spans the
    image's usable square)."""
    h, w = img.shape[:2]
    side = min(w, h) * (1 - 2 * MARGIN)
    return img[int(h / 2 - y / 4 * side), int(w / 2 + x / 4 * side)].astype(int)


def test_view_frame_is_orthonormal_and_upright():
    for azim, elev in [(-60, 25), (120, 25), (0, 0), (-90, 90), (33, -40)]:
        f = view_frame(azim, elev)
        assert np.allclose(f @ f.T, np.eye(3), atol=1e-12)
        assert np.allclose(np.cross(f[0], f[1]), f[2], atol=1e-12)  # right-handed
        assert f[1, 2] >= -1e-12 and abs(f[0, 2]) < 1e-12
    assert np.allclose(view_frame(0, 0)[2], [1, 0, 0])
    # another up axis: the same frame with the axes renamed cyclically (a rotation)
    for up, axis, eye0 in (("y", 1, [0, 0, 1]), ("x", 0, [0, 1, 0])):
        for azim, elev in [(-60, 25), (120, 25), (10, -30)]:
            f = view_frame(azim, elev, up)
            assert np.allclose(np.cross(f[0], f[1]), f[2], atol=1e-12)
            assert f[1, axis] > 0 and abs(f[0, axis]) < 1e-12
        assert np.allclose(view_frame(0, 0, up)[2], eye0)
        assert np.allclose(view_frame(0, 0, up)[1, axis], 1)


@pytest.mark.parametrize("order", [(0, 1, 2, 3), (2, 3, 0, 1)])
def test_nearer_square_hides_the_far_one(order):
    points, tris, colors, face = two_squares()
    idx = list(order)
    img = render(
        points, tris[idx], colors[idx], triangle_face=face[idx], width=200, height=200, **TOP
    )
    assert img.shape == (200, 200, 3)
    assert tuple(pixel(img, 0.0, 0.0)) == (255, 0, 0)  # near square over the far one
    assert tuple(pixel(img, 1.5, 1.5)) == (0, 255, 0)  # only the far square
    assert tuple(img[2, 2]) == (255, 255, 255)  # background
    # seen from below the far square is the nearer one
    img = render(points, tris, colors, width=200, height=200, azim=-90.0, elev=-90.0)
    assert tuple(img[100, 100]) == (0, 255, 0)


def test_lines_behind_the_surface_are_hidden():
    points, tris, colors, face = two_squares()
    # a segment on the far square, under the near one, and one on the near square
    behind = np.array([[[-0.5, -0.2, 0.0], [0.5, -0.2, 0.0]]])
    on_top = np.array([[[-0.5, 0.3, 1.0], [0.5, 0.3, 1.0]]])
    outside = np.array([[[1.5, -0.5, 0.0], [1.5, 0.5, 0.0]]])  # on the far square, uncovered
    lines = [
        (behind, None, BLACK, 3.0),
        (on_top, [[0, -1]], BLACK, 3.0),
        (outside, None, BLACK, 3.0),
    ]
    img = render(
        points, tris, colors, triangle_face=face, lines=lines, width=200, height=200, **TOP
    )
    assert tuple(pixel(img, 0.0, -0.2)) == (255, 0, 0)
    assert tuple(pixel(img, 0.0, 0.3)) == (0, 0, 0)
    assert tuple(pixel(img, 1.5, 0.0)) == (0, 0, 0)
    # an edge of the near square itself is drawn along its whole length
    rim = np.array([[[-1.0, 1.0, 1.0], [1.0, 1.0, 1.0]]])
    img = render(
        points,
        tris,
        colors,
        triangle_face=face,
        lines=[(rim, [[0, -1]], BLACK, 3.0)],
        width=200,
        height=200,
        **TOP,
    )
    h = 100 - round(0.25 * 200 * (1 - 2 * MARGIN))
    row = img[h - 1 : h + 1, 60:140].min(axis=0)
    assert (row.max(axis=1) < 100).all()


def test_size_reproducible_and_png():
    points, tris, colors, _ = two_squares()
    img = render(points, tris, colors, width=321, height=123, azim=10.0, elev=30.0)
    assert img.shape == (123, 321, 3) and img.dtype == np.uint8
    data = png_bytes(img)
    assert data == png_bytes(
        render(points, tris, colors, width=321, height=123, azim=10.0, elev=30.0)
    )
    back = np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))
    assert np.array_equal(back, img)


def test_degenerate_and_non_finite_triangles_are_skipped():
    points, tris, colors, _ = two_squares()
    points = np.vstack([points, [[0.0, 0.0, 5.0], [np.nan, 0.0, 0.0], [np.inf, 1.0, 1.0]]])
    extra = np.array([[8, 8, 8], [0, 8, 2], [9, 0, 1], [10, 9, 2], [0, 1, 1]])  # zero area, NaN
    all_tris = np.vstack([tris, extra])
    all_colors = np.vstack([colors, np.full((len(extra), 3), 0.5)])
    with np.errstate(all="raise"):
        img = render(points, all_tris, all_colors, width=200, height=200, **TOP)
    assert np.array_equal(img, render(points[:8], tris, colors, width=200, height=200, **TOP))
    # nothing at all to draw, and only degenerate triangles
    blank = render(np.zeros((3, 3)), np.array([[0, 1, 2]]), np.zeros((1, 3)), width=50, height=40)
    assert blank.shape == (40, 50, 3) and (blank == 255).all()
    empty = render(
        np.zeros((0, 3)), np.zeros((0, 3), dtype=int), np.zeros((0, 3)), width=20, height=20
    )
    assert (empty == 255).all()


def test_big_mesh_chunks_agree():
    """Many triangles over several chunks give the same picture as a small chunk size."""
    import filletfold.export.render as r

    rng = np.random.default_rng(1)
    points = rng.normal(size=(300, 3))
    tris = rng.integers(0, 300, size=(500, 3))
    colors = rng.uniform(size=(500, 3))
    img = render(points, tris, colors, width=120, height=90)
    old = r._CHUNK
    try:
        r._CHUNK = 64
        assert np.array_equal(img, render(points, tris, colors, width=120, height=90))
    finally:
        r._CHUNK = old
