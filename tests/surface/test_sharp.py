"""Modules of sharp vertices: the fan of face shares and conical fillets around the corner."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from filletfold.mesh import load_mesh
from filletfold.rounding.edges import round_edges
from filletfold.rounding.tapered import FilletRows, developed_angles
from filletfold.surface.centres import face_piece_centres
from filletfold.surface.overlap import faces_interior_disjoint
from filletfold.surface.sharp import SEAM_MARGIN, fan_angle, sharp_module, sharp_modules
from filletfold.vertex.frame import vertex_frames

CASES = ["cube", "icosahedron", "random-convex", "torus", "saddle-patch", "open-box", "tent"]


@pytest.fixture(scope="module", params=CASES)
def case(request):
    m = load_mesh(request.param)[0]
    rd = round_edges(m, 0.08 * m.mean_edge_length)
    frames = vertex_frames(m, rd, list(range(m.n_vertices)))
    centres = face_piece_centres(m, rd)
    conical = rd.radius > 0  # every rounded edge a fillet: each vertex's module on its own
    return request.param, m, rd, frames, centres, conical


def face_pairs(piece, kind):
    """Every (i, j) pair of corners of the faces of patches of ``kind``, as index arrays;
    for fillet triangles the rulings from ``S`` (index 0 of the piece) and the chords apart."""
    a, b = [], []
    for f, patch in zip(piece.faces, piece.patches, strict=True):
        if patch.kind != kind:
            continue
        for x in range(len(f)):
            for y in range(x + 1, len(f)):
                a.append(f[x])
                b.append(f[y])
    return np.array(a, dtype=int), np.array(b, dtype=int)


def lengths(piece, a, b):
    p2, p3 = np.asarray(piece.points_2d), np.asarray(piece.points_3d)
    return np.linalg.norm(p2[a] - p2[b], axis=1), np.linalg.norm(p3[a] - p3[b], axis=1)


def test_every_face_of_a_sharp_module_is_rigid_and_the_fan_does_not_overlap(case):
    """Face shares are laid down rigidly; a fillet's rulings keep their lengths and its
    chords contract (3D no longer than flat: the sector is the cone's exact development);
    the pieces overlap nowhere."""
    name, m, _rd, frames, centres, conical = case
    size = m.mean_edge_length
    for frame, module in zip(frames, sharp_modules(frames, centres, conical, 9), strict=True):
        where = f"{name} vertex {frame.vertex}"
        for piece in module:
            d2, d3 = lengths(piece, *face_pairs(piece, "face"))
            assert_allclose(d2, d3, atol=1e-12 * size, err_msg=where)
            a, b = face_pairs(piece, "fillet")
            d2, d3 = lengths(piece, a, b)
            ruling = (a == 0) | (b == 0)
            assert_allclose(d2[ruling], d3[ruling], atol=1e-12 * size, err_msg=where)
            assert (d3[~ruling] <= d2[~ruling] + 1e-12 * size).all(), where
            assert faces_interior_disjoint(np.asarray(piece.points_2d), piece.faces), where


def test_fillet_chords_converge_with_order_two():
    m = load_mesh("cube")[0]
    rd = round_edges(m, 0.1 * m.mean_edge_length)
    frame = vertex_frames(m, rd, [0])[0]
    centres = face_piece_centres(m, rd)
    worst = []
    for n in (5, 9, 17, 33):
        (piece,) = sharp_module(frame, centres, rd.radius > 0, n)
        a, b = face_pairs(piece, "fillet")
        keep = (a != 0) & (b != 0)
        d2, d3 = lengths(piece, a[keep], b[keep])
        worst.append(np.max(d2 - d3))
    ratio = np.array(worst[:-1]) / np.array(worst[1:])
    assert_allclose(ratio, 8.0, rtol=0.1)  # chord h: mismatch h^3 per chord


def test_the_fan_is_the_corner_less_the_wedges_the_fillets_replace(case):
    """Sum of the face angles, less 2 psi - theta(a) per conical side (docs/method.md)."""
    _name, _m, _rd, frames, centres, conical = case
    for frame in frames:
        want = float(np.sum(frame.corner_angle))
        for side, e in zip(frame.sides, frame.ring.edges, strict=True):
            if conical[e] and side.radius > 0:
                psi = np.arctan2(side.radius * np.tan(side.gamma), 0.5 * side.length)
                S = frame.U[None]
                rows = (
                    side.O[None],
                    side.N0[None],
                    side.B[None],
                    [float(side.kappa)],
                    [side.radius],
                )
                theta = developed_angles(
                    FilletRows(*(np.asarray(r, dtype=float) for r in rows), S),
                    np.array([side.arc]),
                )[0]
                want -= 2 * psi - theta
        assert_allclose(fan_angle(frame, centres, conical), want, atol=1e-12)


def test_fillet_points_lie_on_their_arcs_and_face_points_on_their_faces(case):
    _name, m, _rd, frames, centres, conical = case
    for frame in frames[:20]:
        for piece in sharp_module(frame, centres, conical, 7):
            p3 = np.asarray(piece.points_3d)
            for f, patch in zip(piece.faces, piece.patches, strict=True):
                kind, idx = patch
                if kind == "face":
                    n = m.face_normal[int(idx)]
                    assert_allclose((p3[f] - frame.U) @ n, 0, atol=1e-12)
                else:
                    assert kind == "fillet"
                    k = list(frame.ring.edges).index(int(idx))
                    side = frame.sides[k]
                    apex = [i for i in f if np.allclose(p3[i], frame.U)]
                    assert len(apex) == 1
                    rim = p3[[i for i in f if i != apex[0]]]
                    # on the base curve: in the midpoint cross-section, at r from the axis
                    assert_allclose((rim - side.M) @ side.R, 0, atol=1e-12)
                    assert_allclose(np.linalg.norm(rim - side.O, axis=1), side.radius, rtol=1e-12)


def test_a_saddle_fan_is_split_into_runs_below_a_full_turn():
    m = load_mesh("saddle-patch")[0]
    rd = round_edges(m, 0.08 * m.mean_edge_length)
    frames = vertex_frames(m, rd, list(range(m.n_vertices)))
    centres = face_piece_centres(m, rd)
    conical = rd.radius > 0
    split = 0
    for frame in frames:
        total = fan_angle(frame, centres, conical)
        module = sharp_module(frame, centres, conical, 5)
        if frame.ring.closed and total > 2 * np.pi - SEAM_MARGIN:
            assert len(module) >= 2
            split += 1
        for piece in module:
            p2 = np.asarray(piece.points_2d)
            ang = np.unwrap(np.arctan2(p2[1:, 1], p2[1:, 0]))
            assert ang.max() - ang.min() <= 2 * np.pi - SEAM_MARGIN + 1e-12
    assert split > 0, "the saddle patch has saddle vertices"


def test_a_boundary_vertex_keeps_the_sheet_edge_straight():
    """At a boundary vertex the fan starts and ends on the boundary edges' halves: the
    module's border runs straight from S to both midpoints (no notch)."""
    m = load_mesh("open-box")[0]
    rd = round_edges(m, 0.08 * m.mean_edge_length)
    frames = [f for f in vertex_frames(m, rd, list(range(m.n_vertices))) if not f.ring.closed]
    assert frames
    centres = face_piece_centres(m, rd)
    for frame in frames:
        (piece,) = sharp_module(frame, centres, rd.radius > 0, 5)
        p3 = np.asarray(piece.points_3d)
        for side in (frame.sides[0], frame.sides[-1]):
            assert np.isclose(np.linalg.norm(p3 - side.M, axis=1), 0, atol=1e-12).any()
