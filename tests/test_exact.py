"""Exact designs on ill-conditioned inputs: what the certificate measures holds on vertices whose
developments nearly close, whose apices sit near a face plane, whose creases nearly touch their
base curves, and on the hole borders of thin faces."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import filletfold
from filletfold.mesh.polymesh import PolyMesh
from filletfold.rounding.edges import round_edges
from filletfold.surface.centres import face_piece_centres
from filletfold.surface.module import build_modules
from filletfold.tolerances import tol
from filletfold.vertex.apex import fold_planes
from filletfold.vertex.frame import vertex_frame

from .conftest import design_of
from .reference.module import build_module

DATA = Path(__file__).parent / "data"

#: Round-off allowed on a length: this many units in the last place of the largest coordinate.
ULPS = 16


def _rings() -> list[dict]:
    return json.loads((DATA / "nut-rings.json").read_text())["rings"]


def _edge_lengths(piece) -> tuple[np.ndarray, np.ndarray, float]:
    """(m,) 2D and (m,) 3D lengths of every face side of a piece, and its round-off."""
    p2, p3 = piece.arrays()
    a, b = [], []
    for face in piece.faces:
        face = list(face)
        a += face
        b += face[1:] + face[:1]
    quantum = ULPS * np.finfo(float).eps * max(np.abs(p2).max(), np.abs(p3).max())
    return (
        np.linalg.norm(p2[a] - p2[b], axis=1),
        np.linalg.norm(p3[a] - p3[b], axis=1),
        quantum,
    )


def _largest_shared_area(piece) -> float:
    """The largest area two faces of a piece share in 2D, as a share of the smaller one."""
    p2, _ = piece.arrays()
    polys = np.array([shapely.Polygon(p2[list(f)]) for f in piece.faces])
    i, j = shapely.STRtree(polys).query(polys)
    keep = i < j
    i, j = i[keep], j[keep]
    shared = shapely.area(shapely.intersection(polys[i], polys[j]))
    return float((shared / np.minimum(shapely.area(polys[i]), shapely.area(polys[j]))).max())


def _small_mesh(ring: dict):
    mesh = PolyMesh(np.array(ring["vertices"]), ring["faces"])
    rd = round_edges(mesh, np.array(ring["radius"]))
    return mesh, rd, vertex_frame(mesh, rd, ring["vertex"]), face_piece_centres(mesh, rd)


@pytest.mark.parametrize("ring", _rings(), ids=lambda r: f"nut-{r['nut_vertex']}")
def test_nearly_closed_hole_modules_contract_and_do_not_overlap(ring):
    """A developable vertex whose rounded development misses closing by 6e-13 .. 6e-9 of its
    edges: the two sides of the cut are not merged (a merge moves points by the gap, and the
    edges at them come out longer folded than flat), and where they cross by a hair the module
    is split (a sliver shared by two faces, a tiny share of the piece but not of the face)."""
    mesh, _, frame, centres = _small_mesh(ring)
    gap = np.linalg.norm(frame.rho[:2, 2]) / min(s.length for s in frame.sides)
    assert 1e-13 < gap < 1e-8
    pieces = build_module(mesh, frame, centres, 24)
    for piece in pieces:
        l2, l3, quantum = _edge_lengths(piece)
        assert (l3 - l2 <= 1e-12 * l2 + 6 * quantum).all()
        if len(piece.faces) > 1:
            assert _largest_shared_area(piece) <= 1e-9
    # the batched surface stage builds the same pieces
    (batched,) = build_modules(mesh, [frame], centres, 24, [None], [None])
    assert len(batched) == len(pieces)
    for got, want in zip(batched, pieces, strict=True):
        assert np.array_equal(got.arrays()[0], want.arrays()[0])
        assert list(got.faces) == list(want.faces)


@pytest.mark.parametrize(
    "ring",
    json.loads((DATA / "ant-saddles.json").read_text())["rings"],
    ids=lambda r: f"ant-{r['ant_vertex']}",
)
def test_hole_borders_keep_the_face_shares_simple(ring):
    """At a saddle beside thin faces, a face piece's centre lies near a side's line, on the
    corner's side of the straight hole border: the border then goes through the corner T, and
    every face of the module is a simple counter-clockwise polygon."""
    mesh, _, frame, centres = _small_mesh(ring)
    pieces = build_module(mesh, frame, centres, 24)
    n_faces = 0
    for piece in pieces:
        p2, _ = piece.arrays()
        for face, patch in zip(piece.faces, piece.patches, strict=True):
            poly = shapely.Polygon(p2[list(face)])
            assert poly.is_valid, (patch, shapely.is_valid_reason(poly))
            assert poly.exterior.is_ccw
            n_faces += patch.kind == "face"
        assert _largest_shared_area(piece) <= 1e-9
    assert n_faces == len(frame.ring.faces)
    (batched,) = build_modules(mesh, [frame], centres, 24, [None], [None])
    for got, want in zip(batched, pieces, strict=True):
        assert np.array_equal(got.arrays()[0], want.arrays()[0])
        assert list(got.faces) == list(want.faces)


@settings(max_examples=200, deadline=None)
@given(
    st.floats(np.radians(1.0), np.radians(179.0)),
    st.floats(0.0, 1.0),
    st.floats(0.0, 1.0),
    st.floats(-3.0, 3.0),
    st.floats(-3.0, 3.0),
    st.floats(0.0, 1.0),
    st.sampled_from([-1, 1]),
)
def test_fold_planes_bound_every_straight_crease(corner, s0, s1, x, y, lift, sigma):
    """An apex on or above the three fold planes of a face (through the corner T) sees every
    possible straight crease on the face (from a point of one side's line between T and the
    midpoint to a point of the other's) under the angle ``tol.fold`` or more: the crease
    folds by at most 180 degrees less that."""
    # face in the plane z = 0 (front normal +z), T at the origin, the side lines along a, b
    a = np.array([1.0, 0.0, 0.0])
    b = np.array([np.cos(corner), np.sin(corner), 0.0])
    normal = np.array([0.0, 0.0, 1.0])
    (w,) = fold_planes(normal[None], -a[None], -b[None], np.array([sigma]))
    foot = np.array([x, y, 0.0])
    # the lowest height over the face at this foot that is on or above all three planes
    need = max(0.0, *(-(sigma * wj[:2] @ foot[:2]) / wj[2] for wj in w))
    apex = foot + sigma * (need + lift) * normal
    assert (sigma * w @ apex >= -1e-12).all()
    p0, p1 = s0 * a + 1e-6 * a, s1 * b + 1e-6 * b
    tri = np.cross(p1 - p0, apex - p0)
    # the angle between the face on the far side of the crease (away from T) and the triangle
    along = (p1 - p0) / np.linalg.norm(p1 - p0)
    away = np.cross(normal, along)
    away = away if away @ (-p0) < 0 else -away
    height = sigma * (apex - p0) @ normal
    beyond = (apex - p0) @ away
    assert np.linalg.norm(tri) > 0
    assert np.arctan2(height, beyond) >= tol.fold * (1 - 1e-9)


def test_straight_creases_fold_short_of_flat():
    """resch with consistent material loss: developable vertices whose normal bound is tiny
    had their apices 2e-6 above a face plane, over the face, and straight creases folded to
    -179.999 degrees; every crease now folds by less than 180 degrees less ``tol.fold``, and
    no ruling is shorter than 1e-7 of the design (58 were, down to 2e-8), so the whole
    certificate holds."""
    d = filletfold.round_mesh("resch", material_loss=True)
    cert = d.certificate
    assert cert["fold-angle range"].ok, cert["fold-angle range"].line()
    p = d.pattern
    angle = np.abs(np.asarray(p.edge_fold_angle, dtype=float))
    assert angle.max() <= 180.0 - np.degrees(tol.fold) + 1e-9
    assert cert.ok, "\n".join(cert.summary())


def test_creases_stay_the_floor_away_from_base_curves_and_corners():
    """With a floor on the crease rulings (here a fifth of the shortest l_max, as a mesh of
    that size would ask), every solved crease is at least the floor above its base curve
    along the whole arc, and every straight crease is at least the floor long."""
    from filletfold.vertex.apex import crease_length
    from filletfold.vertex.solve import VertexResult, classify_vertices, solve_apices

    d = design_of("random-convex")
    mesh, rd = d.mesh, d.rounding
    res = VertexResult.empty(mesh.n_vertices)
    frames = classify_vertices(mesh, rd, res)
    low = min(np.fmin(f.lmax_start, f.lmax_end).min() for f in frames)
    floor = 0.2 * low
    out = solve_apices(frames, d.stages.depths, res, d.stages.centres, size=floor / tol.ruling)
    solved = [(u, V, v) for u, (V, v) in out.items() if V is not None]
    assert len(solved) >= 0.9 * len(out)
    for u, V, v in solved:
        fr = frames[u]
        ends = []
        for i, side in enumerate(fr.sides):
            s = np.linspace(0.0, side.arc, 401)
            l, _ = crease_length(fr, i, V, v, s)
            assert l.min() >= floor * (1 - 1e-6)
            C = fr.arrays.base(np.full(2, i), s[[0, -1]])
            ends.append(C + l[[0, -1], None] * side.R)
        for i in range(len(fr.ring.faces)):
            p0, p1 = ends[i][1], ends[(i + 1) % len(ends)][0]
            assert np.linalg.norm(p1 - p0) >= floor * (1 - 1e-6)
