"""The pattern validator (:mod:`filletfold.surface.validate`): every broken pattern is named."""

from __future__ import annotations

import numpy as np
import pytest

from filletfold.errors import ExportError
from filletfold.export import (
    fold_document,
    folded_obj,
    pattern_svg,
    validate_pattern,
)
from filletfold.surface.pattern import CreasePattern

from ..conftest import square_pattern

SVG_NS = "{http://www.w3.org/2000/svg}"
ATOL = 1e-9


# ---------------------------------------------------------------- validation


def _tampered(**changes) -> CreasePattern:
    p = square_pattern(90.0)
    for k, v in changes.items():
        setattr(p, k, v)
    return p


@pytest.mark.parametrize(
    ("pattern_factory", "match"),
    [
        (lambda: _tampered(face_patch=["face 0"]), "face_patch"),
        (lambda: _tampered(face_piece=np.array([0])), "face_piece"),
        (lambda: _tampered(vertices_3d=np.zeros((3, 3))), "4 vertices in 2D but 3 in 3D"),
        (
            lambda: _tampered(vertices_2d=np.array([[0, 0], [1, 0], [np.nan, 1], [0, 1.0]])),
            r"vertices_2d\[2\] is not finite",
        ),
        (lambda: _tampered(faces=[[0, 1, 2], [0, 2, 9]]), "face 1 refers to a vertex"),
        (lambda: _tampered(faces=[[0, 1, 2], [0, 2]]), "at least 3"),
        (
            lambda: _tampered(edge_fold_angle=np.array([0, -90.0, 0, 0, 0])),
            "edge 1 is 'V' but its fold angle is -90",
        ),
        (
            lambda: _tampered(edge_assignment=np.array(["B", "U", "B", "B", "B"])),
            "edge 1 has assignment 'U'",
        ),
        (lambda: _tampered(edge_fold_angle=np.zeros(4)), "edge arrays disagree"),
        (
            lambda: CreasePattern(
                [[0, 0], [1, 0], [0, 1]],
                [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                [[0, 2, 1]],
                ["face 0"],
                [0],
                [0],
            ),
            "face 0 is clockwise",
        ),
        (lambda: "not a pattern", "expected a CreasePattern"),
    ],
)
def test_validate_pattern_fires(pattern_factory, match):
    p = pattern_factory()
    with pytest.raises(ExportError, match=match):
        validate_pattern(p)
    for export in (fold_document, pattern_svg, folded_obj):
        with pytest.raises(ExportError, match=match):
            export(p)
