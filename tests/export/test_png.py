"""The PNG pictures (:mod:`filletfold.export.png`): the flat layout and the folded preview."""

from __future__ import annotations

import io

import numpy as np
import pytest
from matplotlib.image import imread

from filletfold.errors import ParameterError
from filletfold.export import pattern_png, preview_png

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
