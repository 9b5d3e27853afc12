"""Repairs of the input mesh (:mod:`filletfold.mesh.repair`): polygons made planar to
round-off, polygons triangulated, every change recorded (or refused with ``strict``)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.errors import MeshError
from filletfold.mesh.repair import RepairLog, planarize, triangulate_polygon_3d


def quad_torus(na=13, nb=7, big=2.0, small=0.7):
    t = 2 * np.pi * np.arange(na) / na
    s = 2 * np.pi * np.arange(nb) / nb
    T, S = np.meshgrid(t, s, indexing="ij")
    ring = big + small * np.cos(S)
    v = np.stack([ring * np.cos(T), ring * np.sin(T), small * np.sin(S)], axis=-1).reshape(-1, 3)
    faces = [
        np.array(
            [
                i * nb + j,
                i * nb + (j + 1) % nb,
                (i + 1) % na * nb + (j + 1) % nb,
                (i + 1) % na * nb + j,
            ]
        )
        for i in range(na)
        for j in range(nb)
    ]
    return v, faces


def deviation(v, faces):
    out = []
    for f in faces:
        p = v[f] - v[f].mean(axis=0)
        n = np.linalg.svd(p)[2][-1]
        out.append(np.abs(p @ n).max() / np.linalg.norm(np.ptp(v[f], axis=0)))
    return np.array(out)


def test_a_float32_quad_torus_becomes_planar_to_round_off():
    """float32 leaves the torus' trapezoids 5e-8 out of plane; one joint least-norm step per
    round puts every corner on its plane (the old per-vertex steps stalled at 1e-12)."""
    v, faces = quad_torus()
    v32 = v.astype(np.float32).astype(float)
    assert deviation(v32, faces).max() > 1e-9
    log = RepairLog()
    x, residual = planarize(faces, v32, log)
    assert deviation(x, faces).max() < 1e-14
    assert residual.max() <= 1e-14
    moved = np.linalg.norm(x - v32, axis=1).max()
    assert 0 < moved < 1e-6  # a correction of the rounding, no more
    assert [r.what for r in log.repairs] == ["planarize"]


def gentle_cylinder(n=12, step=2e-3):
    """A grid of n x n planar quads bent by ``step`` radians from column to column."""
    a = step * np.arange(n + 1)
    z = np.linspace(0.0, 1.0, n + 1)
    aa, zz = np.meshgrid(a, z, indexing="ij")
    r = 1.0 / (step * n)  # about one unit wide
    v = np.stack([r * np.sin(aa), r * (1 - np.cos(aa)), zz], axis=-1).reshape(-1, 3)
    k = n + 1
    faces = [
        np.array([i * k + j, (i + 1) * k + j, (i + 1) * k + j + 1, i * k + j + 1])
        for i in range(n)
        for j in range(n)
    ]
    return v, faces


@pytest.mark.parametrize("step", [0.2, 2e-3])
def test_noisy_quads_meeting_at_small_angles_become_planar_with_small_moves(step):
    """Holding the normals, the old step needed moves of the noise over the angle between
    neighbours, over the cap: nothing moved and every quad stayed 1e-7 off its plane. With
    the planes free to turn, one or two steps of the size of the noise make them planar."""
    v, faces = gentle_cylinder(step=step)
    noisy = v + np.random.default_rng(1).normal(scale=1e-8, size=v.shape)
    assert deviation(noisy, faces).max() > 1e-8
    x, residual = planarize(faces, noisy, RepairLog())
    assert residual.max() == 0.0
    assert deviation(x, faces).max() < 1e-14
    assert 0 < np.linalg.norm(x - noisy, axis=1).max() < 1e-7


def test_planar_polygons_and_triangles_are_left_alone():
    v, faces = quad_torus()
    log = RepairLog()
    x, residual = planarize(faces, v, log)
    assert x is v or np.array_equal(x, v)
    tri = [np.array([0, 1, 2])]
    x, residual = planarize(tri, v, log)
    assert x is v and residual.tolist() == [0.0]


def test_strict_refuses_instead_of_repairing():
    v, faces = quad_torus()
    with pytest.raises(MeshError):
        planarize(faces, v.astype(np.float32).astype(float), RepairLog(strict=True))


@settings(max_examples=60, deadline=None)
@given(st.integers(4, 12), st.integers(0, 2**32 - 1))
def test_triangulating_a_simple_polygon_covers_it_exactly(n, seed):
    rng = np.random.default_rng(seed)
    angle = np.sort(rng.uniform(0, 2 * np.pi, n))
    radius = rng.uniform(0.3, 1.0, n)  # star-shaped about the origin: simple, maybe not convex
    p = np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=1)
    poly = shapely.Polygon(p)
    if not poly.is_valid or poly.area < 1e-6:
        return
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))  # the polygon in a plane of any direction
    tris = triangulate_polygon_3d(np.c_[p, np.zeros(n)] @ q.T + rng.normal(size=3))
    assert len(tris) == n - 2
    signed = [shapely.Polygon(p[list(t)]).exterior.is_ccw for t in tris]
    if np.linalg.det(q) > 0:  # turning about the plane's normal as the polygon does (its
        # corners sorted by angle run clockwise when the origin is outside it)
        assert all(s == poly.exterior.is_ccw for s in signed)
    areas = [shapely.Polygon(p[list(t)]).area for t in tris]
    assert min(areas) > 0
    assert sum(areas) == pytest.approx(poly.area, rel=1e-9)
    union = shapely.union_all([shapely.Polygon(p[list(t)]) for t in tris])
    assert union.symmetric_difference(poly).area <= 1e-9 * poly.area
