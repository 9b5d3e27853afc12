"""Glue tabs and labels (:mod:`filletfold.layout.tabs`): every cut border gets a tab or keeps
its two labels, tabs lie outside every piece and every other tab, on their own border."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import filletfold
from filletfold.layout.tabs import assembly_text


@pytest.fixture(scope="module", params=["cube", "icosahedron", "l-prism"])
def tabbed(request):
    return filletfold.round_mesh(request.param, tabs=True)


def test_every_cut_border_is_tabbed_or_labelled(tabbed):
    fab = tabbed.fabrication
    assert tabbed.pattern.cut_mask().any()
    assert fab["cut_borders"] == len(fab["seams"]) > 0  # a seam: the two sides of one cut
    assert fab["tabs"] + fab["untabbed"] == fab["cut_borders"]
    assert fab["tabs"] == len(tabbed.pattern.annotations.tabs) > 0


def test_tabs_overlap_no_piece_and_no_tab(tabbed):
    p = tabbed.pattern
    faces = shapely.union_all([shapely.Polygon(p.vertices_2d[f]) for f in p.faces])
    tabs = [shapely.Polygon(t) for t in p.annotations.tabs]
    scale = np.ptp(p.vertices_2d, axis=0).max() ** 2
    for k, t in enumerate(tabs):
        assert t.is_valid and t.area > 0
        assert t.intersection(faces).area <= 1e-9 * scale, k
        for other in tabs[k + 1 :]:
            assert t.intersection(other).area <= 1e-9 * scale


def test_each_tab_hinges_on_a_cut_border(tabbed):
    """Both ends of a tab's hinge lie on the cut borders (the tab is folded along its piece's
    border, not in the middle of a piece)."""
    p = tabbed.pattern
    cut = shapely.union_all([shapely.LineString(p.vertices_2d[e]) for e in p.edges[p.cut_mask()]])
    tol = 1e-9 * np.ptp(p.vertices_2d, axis=0).max()
    assert len(p.annotations.tab_hinges) == len(p.annotations.tabs)
    for hinge in p.annotations.tab_hinges:
        for end in np.asarray(hinge):
            assert cut.distance(shapely.Point(end)) <= tol


def test_labels_pair_up_and_the_assembly_text_lists_them(tabbed):
    labels = [label.text for label in tabbed.pattern.annotations.labels if label.kind == "tab"]
    counts = {t: labels.count(t) for t in set(labels)}
    assert counts and all(c == 2 for c in counts.values())  # the two sides of one seam
    seams = tabbed.fabrication["seams"]
    assert {str(s["label"]) for s in seams} == set(counts)
    text = assembly_text(seams).splitlines()
    assert len(text) == 2 + len(seams)
    for line, seam in zip(text[2:], seams, strict=True):
        assert line.split("\t")[0] == str(seam["label"])
