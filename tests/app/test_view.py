"""What the browser app draws (:mod:`filletfold.app.view`): the legend, the triangulations it
draws (the library's, :mod:`filletfold.surface.triangulate`) that cover each counter-clockwise
polygon exactly (convex or not), and the scene arrays of a design, consistent with its crease
pattern."""

from __future__ import annotations

import collections
import itertools
import re

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from filletfold.app import view
from filletfold.app.view import (
    CREASE_RGB,
    PATCH_RGB,
    SCENE_WIDTH,
    SHARP_RGB,
    STATUS_RGB,
    legend_markdown,
    scene_arrays,
)
from filletfold.surface.triangulate import triangulate_faces, triangulate_polygon_2d

from ..conftest import design_of, signed_area

# ---------------------------------------------------------------- legend


def test_the_legend_shows_every_colour_with_its_name():
    text = legend_markdown()
    rows = re.findall(
        r'<span style="color:(#[0-9a-f]{6})">&#9632;</span> ([^<\n]+?)  $', text, re.M
    )
    shown = dict((name, colour) for colour, name in rows)
    hexed = lambda rgb: "#{:02x}{:02x}{:02x}".format(*rgb)  # noqa: E731
    for kind, rgb in PATCH_RGB.items():
        assert shown[kind] == hexed(rgb)
    for name, a in (("mountain", "M"), ("valley", "V"), ("cut / border", "B")):
        assert shown[name] == hexed(CREASE_RGB[a])
    for status, rgb in STATUS_RGB.items():
        assert shown[status] == hexed(rgb)
    assert shown["kept sharp (its corner, no hole)"] == hexed(SHARP_RGB)
    assert len(rows) == len(PATCH_RGB) + len(CREASE_RGB) + len(STATUS_RGB) + 1
    headings = [line for line in text.splitlines() if line.startswith("**")]
    assert headings == ["**Patches**  ", "**Creases**  ", "**Vertices**  "]


# ---------------------------------------------------------------- triangulation


def star_polygon(rng, k: int, spread: float = 0.9) -> np.ndarray:
    """A simple counter-clockwise polygon of ``k`` corners, star-shaped about the origin (no
    two consecutive corners half a turn apart), radii from ``1 - spread`` to 1 + spread."""
    t = (np.arange(k) + rng.uniform(-0.2, 0.2, size=k)) * (2 * np.pi / k)
    r = rng.uniform(1 - spread, 1 + spread, size=k)
    return np.c_[r * np.cos(t), r * np.sin(t)]


def check_covers(poly: np.ndarray, tris: np.ndarray) -> None:
    """``tris`` (k - 2, 3) cut the polygon into counter-clockwise triangles inside it that
    overlap nowhere and cover it: their areas add up to the polygon's, and so does their
    union's."""
    k = len(poly)
    assert tris.shape == (k - 2, 3) and np.issubdtype(tris.dtype, np.integer)
    assert tris.min() >= 0 and tris.max() < k
    assert all(len(set(t)) == 3 for t in tris.tolist())
    area = signed_area(poly)
    tri_area = np.array([signed_area(poly[t]) for t in tris])
    assert tri_area.min() > 0
    assert_allclose(tri_area.sum(), area, rtol=1e-9)
    shape = shapely.Polygon(poly)
    triangles = [shapely.Polygon(poly[t]) for t in tris]
    assert all(t.difference(shape).area <= 1e-9 * area for t in triangles)  # none outside
    assert shapely.union_all(triangles).area == pytest.approx(area, rel=1e-9)  # no overlap


@pytest.mark.parametrize("k", [3, 4, 5, 8, 17])
def test_a_convex_polygon_becomes_a_fan(k):
    t = 2 * np.pi * np.arange(k) / k
    poly = np.c_[np.cos(t), np.sin(t)] * 3 + [1, -2]
    tris = triangulate_polygon_2d(poly)
    check_covers(poly, tris)
    assert tris.tolist() == [[0, i, i + 1] for i in range(1, k - 1)]


@pytest.mark.parametrize(
    "poly",
    [
        [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]],  # L
        [[0, 0], [4, 0], [4, 1], [1, 1], [1, 2], [4, 2], [4, 3], [0, 3]],  # C
        [[0, 0], [5, 0], [5, 3], [4, 3], [4, 1], [3, 1], [3, 3], [2, 3], [2, 1], [1, 1], [1, 3]],
        [[0, 0], [1, 0.5], [2, 0], [1.5, 1], [2, 2], [1, 1.5], [0, 2], [0.5, 1]],  # a star
        [[0, 0], [1, 0], [2, 0], [2, 2], [1, 1], [0, 2]],  # a straight corner, not an ear
    ],
    ids=["L", "C", "comb", "star", "straight-corner"],
)
def test_a_non_convex_polygon_is_covered_exactly(poly):
    p = np.array(poly, dtype=float)
    check_covers(p, triangulate_polygon_2d(p))


@settings(max_examples=150, deadline=None)
@given(st.integers(4, 30), st.integers(0, 10**6), st.floats(0.1, 0.95))
def test_random_star_shaped_polygons_are_covered_exactly(k, seed, spread):
    rng = np.random.default_rng(seed)
    poly = star_polygon(rng, k, spread)
    tris = triangulate_polygon_2d(poly)
    check_covers(poly, tris)
    # from any first corner, and moved and scaled: still a cover
    s = int(rng.integers(k))
    check_covers(np.roll(poly, s, axis=0), triangulate_polygon_2d(np.roll(poly, s, axis=0)))
    check_covers(poly * 1e3 + 1e4, triangulate_polygon_2d(poly * 1e3 + 1e4))


@settings(max_examples=50, deadline=None)
@given(st.lists(st.integers(3, 12), min_size=1, max_size=12), st.integers(0, 10**6))
def test_triangulate_faces_covers_each_face(sizes, seed):
    """Faces of mixed sizes, convex and not, sharing one point array in shuffled order."""
    rng = np.random.default_rng(seed)
    polys = [
        star_polygon(rng, k, spread=0.0 if rng.random() < 0.3 else 0.8) + 5 * i
        for i, k in enumerate(sizes)
    ]
    points = np.vstack(polys)
    order = rng.permutation(len(points))  # points[order[j]] is the j-th corner
    where = np.argsort(order)
    starts = np.cumsum([0, *sizes])
    faces = [where[a:b] for a, b in itertools.pairwise(starts)]
    pts = points[order]
    tris, owner = triangulate_faces(pts, faces)
    assert tris.shape == (sum(k - 2 for k in sizes), 3) and owner.shape == (len(tris),)
    assert np.all(np.diff(owner) >= 0)
    assert collections.Counter(owner.tolist()) == {i: k - 2 for i, k in enumerate(sizes)}
    for i, f in enumerate(faces):
        mine = tris[owner == i]
        # the face's own corners, as a triangulation of the polygon
        local = np.searchsorted(np.sort(f), mine)
        back = np.argsort(f)
        check_covers(pts[f], back[local])


def test_the_app_draws_the_library_triangulation():
    """The app has no triangulation of its own: it uses the one the writers use."""
    assert view.triangulate_faces is triangulate_faces


def test_triangulate_faces_of_no_faces_and_of_small_ones():
    pts = np.random.default_rng(0).normal(size=(5, 2))
    tris, owner = triangulate_faces(pts, [])
    assert tris.shape == (0, 3) and owner.shape == (0,)
    tris, owner = triangulate_faces(pts, [[0, 1], [2]])  # fewer than 3 corners: nothing
    assert tris.shape == (0, 3) and owner.shape == (0,)


# ---------------------------------------------------------------- the scene


@pytest.fixture(scope="module")
def cube():
    design = design_of("cube")
    return design, scene_arrays(design)


def test_scene_meshes_are_consistent(cube):
    _, s = cube
    assert set(s.folded) == set(s.flat) <= set(PATCH_RGB)
    for kind in s.folded:
        v3, t3 = s.folded[kind]
        v2, t2 = s.flat[kind]
        assert v3.shape == v2.shape and v3.shape[1] == 3
        assert t3.shape[1] == 3 and np.array_equal(t3, t2)
        assert np.issubdtype(t3.dtype, np.integer) and t3.min() >= 0 and t3.max() < len(v3)
        assert np.array_equal(np.unique(t3), np.arange(len(v3)))  # every point used
        assert np.isfinite(v3).all() and np.isfinite(v2).all()


def test_every_pattern_face_is_drawn(cube):
    """Each kind's triangles number the corners less two of that kind's faces, and cover
    their area: the flat pattern at ``scale * pattern_scale``, the folded form at ``scale``."""
    design, s = cube
    p = design.pattern
    kinds = [patch.kind for patch in p.face_patch]
    assert set(kinds) == set(s.folded)
    k2 = (s.scale * s.pattern_scale) ** 2
    for kind in s.folded:
        faces = [f for f, k in zip(p.faces, kinds, strict=True) if k == kind]
        v3, t = s.folded[kind]
        v2, _ = s.flat[kind]
        assert len(t) == sum(len(f) - 2 for f in faces)
        flat_area = np.array([signed_area(q[:, :2]) for q in v2[t]])
        assert flat_area.min() > 0  # counter-clockwise, as the pattern's faces
        want = sum(signed_area(p.vertices_2d[f]) for f in faces)
        assert_allclose(flat_area.sum(), want * k2, rtol=1e-9)
        # folded: the flat faces themselves on the face pieces; on the cones and cylinders
        # chords of the curved surface, which the pattern never stretches (contraction)
        e1, e2 = v3[t[:, 1]] - v3[t[:, 0]], v3[t[:, 2]] - v3[t[:, 0]]
        folded_area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1).sum()
        if kind == "face":
            assert_allclose(folded_area, want * s.scale**2, rtol=1e-9)
        else:
            assert (1 - 1e-3) * want * s.scale**2 < folded_area <= want * s.scale**2


def test_the_pattern_lies_flat_beside_the_model(cube):
    _, s = cube
    folded = np.vstack([v for v, _ in s.folded.values()])
    flat = np.vstack([v for v, _ in s.flat.values()])
    assert_allclose(flat[:, 2], folded[:, 2].min(), atol=1e-12)  # the plane of the lowest point
    assert flat[:, 0].min() > folded[:, 0].max()
    every = np.vstack([folded, flat])
    assert np.ptp(every, axis=0).max() == pytest.approx(SCENE_WIDTH, rel=1e-12)
    assert_allclose(every.min(axis=0) + every.max(axis=0), 0, atol=1e-12)
    assert 0 < s.pattern_scale <= 1
    assert_allclose(s.to_scene(s.centre), 0, atol=0)


def test_creases_and_markers_match_the_design(cube):
    design, s = cube
    p = design.pattern
    assign = np.asarray(p.edge_assignment)
    assert set(s.folded_creases) == {"M", "V"} and set(s.flat_creases) == {"M", "V", "B"}
    for a, segs in s.flat_creases.items():
        assert segs.shape == ((assign == a).sum(), 2, 3)
        assert_allclose(segs[..., 2], s.flat["face"][0][0, 2], atol=1e-12)
    for a, segs in s.folded_creases.items():
        assert_allclose(segs, s.to_scene(p.vertices_3d[p.edges[assign == a]]))
    m = design.mesh
    assert s.vertex_points.shape == (m.n_vertices, 3)
    assert_allclose(s.vertex_points, s.to_scene(m.vertices))
    assert s.vertex_colors.dtype == np.uint8 and s.vertex_colors.shape == (m.n_vertices, 3)
    for rgb, status in zip(s.vertex_colors.tolist(), design.vertices.status, strict=True):
        assert tuple(rgb) == STATUS_RGB[status]
    assert s.point_size > 0


def test_sharp_vertices_have_their_own_colour_and_fillets_their_patch():
    from filletfold.app.view import scene_arrays

    from ..conftest import design_of

    d = design_of("l-prism")
    arrays = scene_arrays(d)
    sharp = [u for u, t in enumerate(d.vertices.treatment) if t == "sharp"]
    assert sharp
    assert (arrays.vertex_colors[sharp] == SHARP_RGB).all()
    assert "fillet" in arrays.folded
