"""The PNG pictures (:mod:`filletfold.export.png`): the flat layout and the folded preview."""

from __future__ import annotations

import io

import numpy as np
import pytest
from matplotlib.image import imread

from filletfold.errors import ParameterError
from filletfold.export import pattern_png, preview_png
from filletfold.export.png import DEFAULT_VIEW, VIEWS, parse_view
from filletfold.surface.pattern import CreasePattern

from ..conftest import tiny_square
from .conftest import arc_pattern

SVG_NS = "{http://www.w3.org/2000/svg}"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- PNG


def check_picture(data: bytes, width: int, height: int | None = None) -> None:
    assert data.startswith(PNG_SIGNATURE)
    img = imread(io.BytesIO(data))
    assert img.shape[1] == width
    if height is not None:
        assert img.shape[0] == height
    rgb = img[..., :3]
    non_white = np.any(rgb < 0.97, axis=2).mean()
    assert non_white > 0.10
    colours = np.unique((rgb * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 50


def test_pattern_png(cube):
    check_picture(pattern_png(cube.pattern, width_px=500), 500)
    check_picture(pattern_png(arc_pattern(annotated=True), width_px=300), 300)


def test_preview_png(cube):
    data = preview_png(cube.pattern, width_px=400, elev=30.0, azim=20.0)
    check_picture(data, 400, 300)
    assert data == preview_png(cube.pattern, width_px=400, elev=30.0, azim=20.0)


@pytest.mark.parametrize(
    ("func", "kw", "match"),
    [
        (pattern_png, {"width_px": 5}, "width_px must be an integer"),
        (pattern_png, {"width_px": 300.0}, "width_px must be an integer"),
        (preview_png, {"width_px": 10**6}, "width_px must be an integer"),
        (preview_png, {"elev": float("nan")}, "elev must be a finite number"),
        (preview_png, {"azim": "x"}, "azim must be a finite number"),
    ],
)
def test_png_parameters_rejected(func, kw, match):
    with pytest.raises(ParameterError, match=match):
        func(tiny_square(), **kw)


def covered_fold() -> CreasePattern:
    """Two pieces: the tiny square folded by 90 degrees along its diagonal (a valley, blue),
    and a 3 x 3 square 1.5 above it (z = 1.5, a face) that covers it seen from above."""
    small = tiny_square()
    v2 = np.vstack([small.vertices_2d, [[2, 0], [5, 0], [5, 3], [2, 3]]])
    lid = np.array([[-1, -1, 1.5], [2, -1, 1.5], [2, 2, 1.5], [-1, 2, 1.5]], dtype=float)
    v3 = np.vstack([small.vertices_3d, lid])
    faces = [*small.faces, [4, 5, 6], [4, 6, 7]]
    patches = [*small.face_patch, "face 2", "face 2"]
    return CreasePattern(v2, v3, faces, patches, [0, 0, 1, 1], [0, 1])


def blue_pixels(data: bytes) -> int:
    rgb = (imread(io.BytesIO(data))[..., :3] * 255).astype(int)
    return int(((rgb[..., 2] > 150) & (rgb[..., 0] < 60) & (rgb[..., 1] < 60)).sum())


def test_preview_hides_creases_behind_the_surface():
    pattern = covered_fold()
    assert list(pattern.edge_assignment).count("V") == 1
    below = preview_png(pattern, width_px=300, elev=-90.0, azim=-90.0)
    above = preview_png(pattern, width_px=300, elev=90.0, azim=-90.0)
    assert blue_pixels(below) > 50  # the valley seen from below
    assert blue_pixels(above) == 0  # under the lid
    side = preview_png(pattern, width_px=300, elev=0.0, azim=-90.0)
    assert blue_pixels(side) > 10


def test_parse_view():
    assert parse_view("front") == (*DEFAULT_VIEW, "z") == (*VIEWS["front"], "z")
    assert parse_view(" Back ,Y") == (*VIEWS["back"], "y")
    assert parse_view("30,-10.5") == (30.0, -10.5, "z")
    assert parse_view("30,-10.5,x") == (30.0, -10.5, "x")
    assert parse_view((10, 20)) == (10.0, 20.0, "z")
    assert parse_view((10, 20, "y")) == (10.0, 20.0, "y")
    for bad in ("", "north", "1,2,3", "nan,3", "1,inf", "front,w", "y", (1,), None, 5):
        with pytest.raises(ParameterError, match="view must be front, back, top, side"):
            parse_view(bad)
