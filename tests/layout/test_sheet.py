"""One uncut sheet (:mod:`filletfold.layout.sheet`): the modules of a developable input glued
along their shared borders."""

from __future__ import annotations

import numpy as np
import pytest

import filletfold
from filletfold.layout.sheet import glue_pieces
from filletfold.surface.piece import piece_area


@pytest.mark.parametrize("name", ["miura", "chicken-wire"])
def test_the_modules_of_a_developable_input_glue_into_one_sheet(name):
    d = filletfold.round_mesh(name, material_loss=True, tabs=False, layout="modules")
    eps = 1e-9 * d.mesh.mean_edge_length
    sheet, placement, message = glue_pieces(d.pieces, eps)
    assert sheet is not None, message
    assert message == "" and len(placement) == len(d.pieces)
    # the sheet is the pieces moved rigidly: same area, same folded points
    assert piece_area(sheet) == pytest.approx(sum(piece_area(p) for p in d.pieces), rel=1e-9)
    for m in placement:
        q = m[:2, :2]
        np.testing.assert_allclose(q.T @ q, np.eye(2), atol=1e-12)
        assert np.linalg.det(q) == pytest.approx(1.0)
    assert not sheet.overlaps()


def test_the_design_is_one_piece_and_its_creases_fold_it():
    d = filletfold.round_mesh("miura", material_loss=True, tabs=False)
    assert d.layout == "sheet" and d.pattern.n_pieces == 1
    assert (d.pattern.edge_assignment == "B").sum() > 0
    assert not d.pattern.cut_mask().any()  # no border is cut: the sheet's outline only


def test_modules_that_do_not_close_do_not_glue():
    d = filletfold.round_mesh("cube", tabs=False, layout="modules")
    sheet, placement, message = glue_pieces(d.pieces, 1e-9 * d.mesh.mean_edge_length)
    assert sheet is None and placement == [] and message
