"""Glue tabs and labels (:mod:`filletfold.layout.tabs`): every cut border gets a tab or keeps
its two labels, tabs lie outside every piece and every other tab, on their own border."""

from __future__ import annotations

import copy
from itertools import pairwise
from types import SimpleNamespace

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import filletfold
from filletfold.layout import arrange, tabs
from filletfold.layout.tabs import add_tabs_and_labels, assembly_text
from filletfold.surface.pattern import LabelRows

from ..reference import tabs as tabs_reference


@pytest.fixture(scope="module", params=["cube", "icosahedron", "l-prism", "house", "torus"])
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
    outlines = [shapely.Polygon(t) for t in p.annotations.tabs]
    scale = np.ptp(p.vertices_2d, axis=0).max() ** 2
    for k, t in enumerate(outlines):
        assert t.is_valid and t.area > 0 and t.exterior.is_ccw
        assert t.intersection(faces).area <= 1e-9 * scale, k
    for a, b in zip(*shapely.STRtree(outlines).query(outlines), strict=True):
        if a < b:
            assert outlines[a].intersection(outlines[b]).area <= 1e-9 * scale


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


# ---------------------------------------------------------------- the arrays and the reference


@pytest.fixture(
    scope="module",
    params=[
        ("cube", {}),
        ("l-prism", {}),
        ("house", {}),
        ("torus", {}),
        ("saddle-patch", {}),
        ("torus", {"layout": "net"}),  # a run's face centre on its "normal": bits decide
        ("dodecahedron", {"layout": "net", "sheet": "A4", "scale": 60}),
    ],
    ids=lambda param: " ".join([param[0], *map(str, param[1].values())]),
)
def untabbed(request):
    """A pattern as :func:`add_tabs_and_labels` gets it (laid out for tabs), and its height."""
    name, options = request.param
    got = {}

    def spy(p, h, **kw):
        got["p"], got["h"] = copy.deepcopy(p), h
        return add_tabs_and_labels(p, h, **kw)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(arrange, "add_tabs_and_labels", spy)
        filletfold.round_mesh(name, tabs=True, certify=False, **options)
    return got["p"], got["h"]


def test_the_tabs_are_those_of_the_reference_to_the_bit(untabbed):
    """The array version places the tabs of the one-geometry-at-a-time version: the same
    tabs, hinges, labels (with the digits of :func:`~filletfold.layout.tabs.label_digits`)
    and seams, bit for bit (so the same files)."""
    p, h = untabbed
    old, new = copy.deepcopy(p), copy.deepcopy(p)
    want, got = tabs_reference.add_tabs_and_labels(old, h), add_tabs_and_labels(new, h)
    assert got == want
    a, b = old.annotations, new.annotations
    a.labels = tabs.label_digits(LabelRows.of(a.labels), old.vertices_2d)
    for name in ("tabs", "tab_hinges"):
        x, y = getattr(a, name), getattr(b, name)
        assert len(x) == len(y) and all(np.array_equal(u, v) for u, v in zip(x, y, strict=True))
    assert len(a.labels) == len(b.labels)
    for u, v in zip(a.labels, b.labels, strict=True):
        assert np.array_equal(u.position, v.position)
        assert (u.text, u.angle, u.height, u.kind) == (v.text, v.angle, v.height, v.kind)


def test_labels_carry_the_digits_of_their_placement_and_no_more():
    """Label positions land on a power-of-ten grid of at most 1e-6 of the pattern's extent,
    angles on 0.01 degree, heights on 3 significant digits: each moves by at most half its
    step, and the JSON of the design's labels has no number longer than its grid needs."""
    rng = np.random.default_rng(5)
    points = rng.uniform(-3.0, 4.0, (50, 2))  # extent 7: a grid of 1e-6
    pos = rng.uniform(-3.0, 4.0, (40, 2))
    angle = rng.uniform(-90.0, 90.0, 40)
    rows = LabelRows(pos, [str(k) for k in range(40)], angle, 0.000661234, "tab")
    got = tabs.label_digits(rows, points)
    step = 10.0 ** np.floor(np.log10(1e-6 * np.ptp(points, axis=0).max()))
    assert step == 1e-6
    assert np.abs(got.position - pos).max() <= step / 2 + 1e-15
    assert np.allclose(got.position / step, np.round(got.position / step), atol=1e-6)
    assert np.abs(got.angle - angle).max() <= 0.005 + 1e-12
    assert np.all(got.height == 0.000661)
    assert got.text == rows.text and got.kind == rows.kind
    assert all(len(repr(x)) <= 10 for x in got.position.ravel().tolist())
    # a pattern without extent keeps its positions
    same = tabs.label_digits(rows, np.zeros((3, 2)))
    assert np.array_equal(same.position, pos)


def test_a_designs_labels_are_written_short(tmp_path):
    """``annotations.json`` of a design with tabs writes each label number with the digits
    of its grid (the 12 significant digits of before made them 2-3x longer)."""
    import json

    design = filletfold.round_mesh("blob")
    design.export(tmp_path)
    labels = json.loads((tmp_path / "annotations.json").read_text())["labels"]
    assert len(labels["angle"]) > 100
    assert max(len(str(a)) for a in labels["angle"]) <= 6
    assert max(len(repr(h)) for h in labels["height"]) <= 8
    assert max(len(repr(x)) for xy in labels["position"] for x in xy) <= 12


def test_the_segments_are_those_of_the_reference(untabbed):
    p, _ = untabbed
    pairs = tabs._seam_pairs(p)
    assert pairs.tolist() == [list(q) for q in tabs_reference._seam_pairs(p)]
    side_a, side_b, start = tabs._runs(p, pairs)
    runs = tabs_reference._runs(p, tabs_reference._seam_pairs(p))
    assert [list(r[0]) for r in runs] == [side_a[i:j].tolist() for i, j in pairwise(start)]
    assert [list(r[1]) for r in runs] == [side_b[i:j].tolist() for i, j in pairwise(start)]
    for side, edges in enumerate((side_a, side_b)):
        ends, normal = tabs._segments(p, edges, start)
        for k, run in enumerate(runs):
            e, n = tabs_reference._segment(p, run[side])
            assert np.array_equal(e, ends[k]) and np.array_equal(n, normal[k]), (side, k)


def test_row_dots_have_the_bits_of_the_scalar_ones():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(2000, 2)) * rng.uniform(1e-3, 1e3, (2000, 1))
    b = rng.normal(size=(2000, 2))
    assert np.array_equal(tabs._rowdot(a, b), [x @ y for x, y in zip(a, b, strict=True)])
    assert np.array_equal(tabs._rownorm(a), [np.linalg.norm(x) for x in a])


def test_the_tab_timing_is_reported():
    assert "tabs" in filletfold.round_mesh("cube", tabs=True, certify=False).timings
    assert "tabs" not in filletfold.round_mesh("cube", tabs=False, certify=False).timings


# ----------------------------------------------------- the array predicates against shapely


def _convex_polygon(rng, centre, size, k):
    """A random convex polygon (counter-clockwise), about ``centre``."""
    pts = centre + size * rng.normal(size=(3 * k, 2))
    hull = shapely.convex_hull(shapely.multipoints(pts))
    return np.asarray(hull.exterior.coords)[:-1][::-1]


def _scene(seed, far=False):
    """Random faces (convex and not) and tabs; some tabs stand on a face's side (touching
    it), some meet other tabs at a corner: the cases where the shrink decides. ``far``: all
    of it far from the origin, where round-off leaves every pair to shapely."""
    rng = np.random.default_rng(seed)
    faces = [_convex_polygon(rng, rng.uniform(0, 4, 2), rng.uniform(0.2, 1), 4) for _ in range(6)]
    star = rng.uniform(0, 4, 2) + np.stack(
        [np.cos(t := np.linspace(0, 2 * np.pi, 7)[:-1]), np.sin(t)], axis=1
    ) * rng.choice([0.3, 0.8], size=(6, 1))
    faces.append(star)
    h = rng.uniform(0.05, 0.5)
    ends, normal = [], []
    for f in faces:  # on a side of a face, pointing out or in
        i = rng.integers(len(f))
        e = np.array([f[i], f[(i + 1) % len(f)]])
        d = e[1] - e[0]
        n = np.array([d[1], -d[0]]) / np.linalg.norm(d)
        ends.append(e)
        normal.append(n if rng.random() < 0.7 else -n)
    for _ in range(8):  # anywhere
        p0 = rng.uniform(0, 4, 2)
        ang = rng.uniform(0, 2 * np.pi)
        e = np.array([p0, p0 + rng.uniform(0.05, 1.5) * np.array([np.cos(ang), np.sin(ang)])])
        ends.append(e)
        d = e[1] - e[0]
        normal.append(np.array([-d[1], d[0]]) / np.linalg.norm(d))
    ends, normal = np.array(ends), np.array(normal)
    quads, ok = tabs.tab_outlines(ends, normal, h * rng.choice([1.0, 0.5, 0.25], len(ends)))
    # and a tab sharing a corner with each of the others
    turn = rng.uniform(-2.5, 2.5, len(ends))
    d = np.stack([np.cos(turn), np.sin(turn)], axis=1) * rng.uniform(0.1, 1, (len(ends), 1))
    d = np.einsum("nij,nj->ni", _rotations(np.arctan2(*(ends[:, 1] - ends[:, 0]).T[::-1])), d)
    ends2 = np.stack([ends[:, 1], ends[:, 1] + d], axis=1)
    n2 = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.linalg.norm(d, axis=1)[:, None]
    quads2, ok2 = tabs.tab_outlines(ends2, n2 * np.sign(rng.random(len(d)) - 0.3)[:, None], h)
    quads = np.concatenate([quads[ok], quads2[ok2]])
    shift = 1e7 if far else 0.0
    return [f + shift for f in faces], quads + shift, h


def _rotations(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_face_tests_agree_with_shapely(seed, far):
    faces, quads, h = _scene(seed, far)
    p = SimpleNamespace(
        vertices_2d=np.concatenate(faces),
        faces=[np.arange(len(f)) + sum(map(len, faces[:i])) for i, f in enumerate(faces)],
    )
    polys = [shapely.Polygon(f) for f in faces]
    shapes = [shapely.Polygon(q) for q in quads]
    keep = [i for i, t in enumerate(shapes) if t.is_valid and t.area > 0]
    quads, shapes = quads[keep], [shapes[i] for i in keep]
    area = np.array([t.area for t in shapes])
    got = tabs._Faces(p, h).clear(quads, area)[0] < 0
    for k, t in enumerate(shapes):
        shrunk = t.buffer(-tabs.SHRINK * h)
        want = not any(
            polys[i].intersection(shrunk).area > tabs.OVERLAP * t.area
            for i in shapely.STRtree(polys).query(shrunk)
        )
        assert got[k] == want, k


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_tab_conflicts_agree_with_shapely(seed, far):
    _, quads, h = _scene(seed, far)
    i, j = np.triu_indices(len(quads), 1)
    s = tabs.SHRINK * h
    got = tabs.conflicts(quads[i], quads[j], s)
    bound = tabs.conflicts(quads[i], quads[j], s, exact=False)
    shapes = [shapely.Polygon(q) for q in quads]
    want = [shapes[a].intersects(shapes[b].buffer(-s)) for a, b in zip(i, j, strict=True)]
    assert got.tolist() == want
    assert (bound | ~got).all()  # without shapely: a bound


@pytest.mark.slow
def test_tabs_found_in_small_blocks_are_the_same(monkeypatch):
    """The tabs' faces are found a few tabs at a time and their neighbours paired a few
    candidates at a time (to bound the memory of tabs half an edge high): the same tabs."""
    tabs_module = tabs
    design = filletfold.round_mesh("blob", tabs=False)
    h = arrange.tab_height(design.params, design.mesh.mean_edge_length)  # 5 mm at 100 mm
    assert h > 0.3 * design.mesh.mean_edge_length  # large tabs: many faces each

    def tabs_of():
        p = copy.deepcopy(design.pattern)
        stats = tabs_module.add_tabs_and_labels(p, h)
        labels = LabelRows.of(p.annotations.labels)
        return stats["tabs"], np.asarray(p.annotations.tabs.points), labels.position, labels.text

    whole = tabs_of()
    monkeypatch.setattr(tabs_module, "QUERY_BLOCK", 7)
    monkeypatch.setattr(tabs_module, "PAIR_CHUNK", 5)
    blocks = tabs_of()
    assert whole[0] == blocks[0] > 0
    assert np.array_equal(whole[1], blocks[1]) and np.array_equal(whole[2], blocks[2])
    assert list(whole[3]) == list(blocks[3])
