"""The compact containers of a pattern's annotations (:class:`PointRows`, :class:`LabelRows`)
and of its seams (:class:`~filletfold.layout.tabs.Seams`): sequences that read as the lists of
objects they replace, with one array per field."""

from __future__ import annotations

import numpy as np
import pytest

from filletfold.layout.tabs import Seams, assembly_text
from filletfold.surface.pattern import Label, LabelRows, PointRows


def test_point_rows_read_as_a_list_of_arrays():
    rows = [np.arange(8.0).reshape(4, 2), np.ones((2, 2)), np.zeros((3, 2))]
    start = np.cumsum([0, 4, 2, 3])
    pr = PointRows(np.concatenate(rows), start)
    assert len(pr) == 3
    for got, want in zip(pr, rows, strict=True):
        assert np.array_equal(got, want)
    assert np.array_equal(pr[-1], rows[-1]) and np.array_equal(pr[1], rows[1])
    assert [r.tolist() for r in pr[0:2]] == [r.tolist() for r in rows[:2]]
    with pytest.raises(IndexError, match="row 3 out of range"):
        pr[3]
    blocks = np.random.default_rng(0).normal(size=(5, 4, 2))
    split = PointRows.of_blocks(blocks)
    assert all(np.array_equal(a, b) for a, b in zip(split, blocks, strict=True))
    assert len(PointRows.of_blocks(np.zeros((0, 4, 2)))) == 0


def test_label_rows_read_as_labels_and_join():
    labels = [
        Label(np.array([0.5, 1.0]), "1", 12.5, 0.25, "tab"),
        Label([2.0, -3.0], "P1", 0.0, 0.5, "part"),
    ]
    rows = LabelRows.of(labels)
    assert LabelRows.of(rows) is rows
    assert len(rows) == 2
    for got, want in zip(rows, labels, strict=True):
        assert np.array_equal(got.position, np.asarray(want.position, dtype=float))
        assert (got.text, got.angle, got.height, got.kind) == (
            want.text,
            want.angle,
            want.height,
            want.kind,
        )
    both = rows.__add__([Label([9.0, 9.0], "P2", 0.0, 0.5, "part")])  # rows + a list
    assert [lb.text for lb in both] == ["1", "P1", "P2"]
    assert both[-1].kind == "part" and both.position.shape == (3, 2)
    same = LabelRows(np.zeros((2, 2)), ["a", "b"], 0.0, 1.0, "tab")  # scalars broadcast
    assert same.kind == ["tab", "tab"] and same.height.tolist() == [1.0, 1.0]
    with pytest.raises(ValueError, match="2 positions, 1 texts"):
        LabelRows(np.zeros((2, 2)), ["a"], 0.0, 1.0, "tab")
    with pytest.raises(IndexError, match="label 2 out of range"):
        rows[2]


def test_seams_read_as_dicts_and_write_the_assembly_text():
    seams = Seams(["P1", "P2", "P3"], [[0, 1], [1, 2], [2, 2]], [1, -1, 0])
    want = [
        {"label": 1, "pieces": ["P1", "P2"], "tab_on": "P2"},
        {"label": 2, "pieces": ["P2", "P3"], "tab_on": None},
        {"label": 3, "pieces": ["P3", "P3"], "tab_on": "P3"},
    ]
    assert list(seams) == want and seams == want and seams[-1] == want[-1]
    assert assembly_text(seams) == assembly_text(want)
    assert assembly_text(seams).splitlines()[3] == "2\tP2 - P3\t-"
    assert not Seams([], np.zeros((0, 2)), [])


def test_annotations_of_a_tabbed_design_are_arrays():
    """A design's tabs, hinges and labels are held as arrays, not one object per item: the
    annotations of a design of modules take a few tens of bytes per tab, not hundreds."""
    from filletfold import round_mesh

    design = round_mesh("blob")
    ann = design.pattern.annotations
    assert isinstance(ann.tabs, PointRows) and isinstance(ann.tab_hinges, PointRows)
    assert isinstance(ann.labels, LabelRows)
    assert isinstance(design.fabrication["seams"], Seams)
    n_tabs = len(ann.tabs)
    assert n_tabs > 100
    held = (
        ann.tabs.points.nbytes
        + ann.tab_hinges.points.nbytes
        + ann.labels.position.nbytes
        + ann.labels.angle.nbytes
        + ann.labels.height.nbytes
    )
    assert held / n_tabs < 200  # 4 + 2 points and two labels' numbers per tab
