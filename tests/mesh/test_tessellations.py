"""Folded tessellations and the conical dome: developability, planarity, folds, parameters."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from filletfold.errors import MeshReadError, ParameterError
from filletfold.mesh import EXAMPLES, PolyMesh, example_mesh, example_names, load_mesh
from filletfold.mesh import tessellations as tess
from filletfold.mesh.intersect import crossing_triangle_pairs

DEVELOPABLE = [n for n in example_names() if "developable" in EXAMPLES[n].kinds]
SPECS = [
    "miura",
    "miura:4x3",
    "miura:4x3,angle=65,fold=0.6",
    "miura:3x5,angle=40,fold=0.3",
    "chicken-wire",
    "chicken-wire:3x5,fold=0.3",
    "chicken-wire:5x3,fold=0.8",
    "yoshimura",
    "yoshimura:3x3,fold=0.3",
    "yoshimura:6x2,fold=0.9",
    "resch",
    "resch:2x3,fold=0.7",
    "resch:4x4,fold=0.6",
]
#: Folding ``resch:4x4`` takes about 5 s of least squares: its cases run in the slow tier.
SLOW_SPECS = {"resch:4x4,fold=0.6"}
CASES = [pytest.param(s, marks=pytest.mark.slow) if s in SLOW_SPECS else s for s in SPECS]
DOMES = ["conical-dome", "conical-dome:12x5,opening=80,height=0.6", "conical-dome:5x3"]


class _Loaded(dict):
    """Each spec's ``(example_mesh(spec), load_mesh(spec))``, made when first asked for."""

    def __missing__(self, spec):
        self[spec] = (example_mesh(spec), load_mesh(spec))
        return self[spec]


@pytest.fixture(scope="module")
def loaded():
    return _Loaded()


def interior_dihedral_deg(mesh: PolyMesh) -> np.ndarray:
    """(n_interior_edges,) float: angle between the two face normals at each interior edge."""
    ef = mesh.edge_faces[~mesh.is_boundary_edge]
    cos = np.einsum("ij,ij->i", mesh.face_normal[ef[:, 0]], mesh.face_normal[ef[:, 1]])
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def planarity(mesh: PolyMesh) -> float:
    """Largest distance of a vertex from its face's plane."""
    worst = 0.0
    for f, n in zip(mesh.faces, mesh.face_normal, strict=True):
        p = mesh.vertices[f]
        worst = max(worst, float(np.abs((p - p.mean(axis=0)) @ n).max()))
    return worst


def crossing_pairs(mesh: PolyMesh) -> int:
    return crossing_triangle_pairs(mesh.vertices, mesh.faces)


def face_angle_lists(mesh: PolyMesh) -> list[np.ndarray]:
    a = mesh.halfedge_corner_angle
    return [a[mesh.face_start[i] : mesh.face_start[i + 1]] for i in range(mesh.n_faces)]


# ------------------------------------------------------------------------------- registry
def test_registry_lists_base_names_with_documented_parameters():
    names = example_names()
    for name in ("miura", "chicken-wire", "resch", "yoshimura", "conical-dome"):
        assert name in names
        ex = EXAMPLES[name]
        assert ex.params and ex.params[0] == "cells"
        assert all(p in ex.description for p in ex.params)
    assert not any(":" in n for n in names)
    for name in DEVELOPABLE:
        kinds = EXAMPLES[name].kinds
        assert {"tessellation", "open"} <= set(kinds)
        assert "quads" in kinds or "triangles" in kinds


# ---------------------------------------------------------------------- developable sheets
@pytest.mark.parametrize("spec", CASES)
def test_tessellation_loads_unchanged(spec, loaded):
    (v, faces), (mesh, log) = loaded[spec]
    assert mesh.n_faces == len(faces) and mesh.n_vertices == len(v)
    changes = [log.merged_vertices, log.flipped_faces, log.merged_faces, log.removed_vertices]
    assert changes == [0, 0, 0, 0]
    assert mesh.n_vertices - mesh.n_edges + mesh.n_faces == 1  # a disc
    assert 0.7 <= mesh.mean_edge_length <= 1.4
    assert mesh.edge_length.min() > 0.4
    assert mesh.face_area.min() > 0.05


@pytest.mark.parametrize("spec", CASES)
def test_tessellation_is_developable_planar_and_folded(spec, loaded):
    mesh, _ = loaded[spec][1]
    inner = ~mesh.is_boundary_vertex
    assert inner.sum() >= 1
    assert_allclose(mesh.vertex_angle_sum[inner], 2 * np.pi, rtol=0, atol=1e-9)
    assert planarity(mesh) < 1e-9
    assert interior_dihedral_deg(mesh).min() > 2.0


@pytest.mark.parametrize("spec", CASES)
def test_tessellation_does_not_intersect_itself(spec, loaded):
    mesh, _ = loaded[spec][1]
    assert crossing_pairs(mesh) == 0


@pytest.mark.parametrize("spec", CASES)
def test_front_faces_up(spec, loaded):
    mesh, _ = loaded[spec][1]
    assert (mesh.face_area[:, None] * mesh.face_normal).sum(axis=0)[2] > 0


@pytest.mark.parametrize(
    ("name", "extra"),
    [("miura", ",angle=55"), ("chicken-wire", ""), ("yoshimura", ""), ("resch", "")],
)
def test_faces_do_not_change_with_the_fold(name, extra):
    cells = "3x3" if name != "resch" else "2x2"
    lo = 0.3 if name != "resch" else 0.45
    a, _ = load_mesh(f"{name}:{cells},fold={lo}{extra}")
    b, _ = load_mesh(f"{name}:{cells},fold=0.7{extra}")
    assert a.n_faces == b.n_faces
    for fa, fb in zip(a.faces, b.faces, strict=True):
        assert np.array_equal(fa, fb)
    for x, y in zip(face_angle_lists(a), face_angle_lists(b), strict=True):
        assert_allclose(x, y, rtol=0, atol=1e-9)
    assert_allclose(a.edge_length, b.edge_length, rtol=0, atol=1e-9)
    assert np.abs(a.vertices - b.vertices).max() > 0.1  # the fold changed the shape


def test_miura_faces_are_unit_parallelograms_with_the_sector_angle():
    mesh, _ = load_mesh("miura:3x4,angle=60,fold=0.4")
    assert_allclose(mesh.edge_length, 1.0, rtol=0, atol=1e-12)
    angles = np.degrees(mesh.halfedge_corner_angle)
    assert_allclose(np.sort(np.minimum(angles, 180 - angles)), 60.0, atol=1e-9)


def test_miura_is_a_translational_surface():
    v, _ = tess.miura((3, 2), fold=0.5)
    p = v.reshape(4, 3, 3)
    assert_allclose(p[1:, 1:] - p[:-1, 1:], p[1:, :-1] - p[:-1, :-1], atol=1e-12)


def test_chicken_wire_faces_are_isosceles_trapezoids():
    mesh, _ = load_mesh("chicken-wire:2x3,fold=0.5")
    for f in mesh.faces:
        p = mesh.vertices[f]
        side = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)
        assert_allclose(side[0], side[2], atol=1e-12)  # the two legs (zigzag edges)
        assert_allclose(sorted(side[[1, 3]]), [0.6, 1.4], atol=1e-12)
        u, w = p[1] - p[2], p[0] - p[3]  # the parallel sides
        assert_allclose(np.linalg.norm(np.cross(u, w)), 0.0, atol=1e-12)


def test_resch_mountains_and_valleys():
    """Star spokes to corners are valleys, spokes to edge midpoints and star rims mountains."""
    mesh, _ = load_mesh("resch:2x3,fold=0.6")
    inner = np.nonzero(~mesh.is_boundary_edge)[0]
    ef = mesh.edge_faces[inner]
    a = mesh.vertices[mesh.edges[inner, 0]]
    # mountain (convex seen from the front): the other face lies behind the first face's plane
    behind = np.einsum("ij,ij->i", mesh.face_centroid[ef[:, 1]] - a, mesh.face_normal[ef[:, 0]])
    length = mesh.edge_length[inner] / mesh.edge_length.min()
    assert (behind[np.abs(length - 2.0) < 1e-9] > 0).all()  # valleys
    assert (behind[np.abs(length - 2.0) > 1e-9] < 0).all()  # mountains
    deg = np.bincount(mesh.edges.ravel())
    assert (deg == 12).sum() == 6  # one interior vertex of degree 12 per star


@pytest.mark.slow
def test_resch_4x4_at_the_default_fold_loads_and_is_developable():
    """At fold 0.5 a few rim spokes of a 4x4 patch fold the other way, nearly flat."""
    mesh, log = load_mesh("resch:4x4")
    assert mesh.n_faces == 222 and log.merged_faces == 0
    inner = ~mesh.is_boundary_vertex
    assert_allclose(mesh.vertex_angle_sum[inner], 2 * np.pi, rtol=0, atol=1e-9)
    assert crossing_pairs(mesh) == 0


# ------------------------------------------------------------------------------- the dome
@pytest.mark.parametrize("spec", DOMES)
def test_conical_dome(spec, loaded):
    (_, faces), (mesh, log) = loaded[spec]
    assert mesh.n_faces == len(faces) and log.merged_faces == 0 and log.flipped_faces == 0
    assert planarity(mesh) < 1e-9
    inner = ~mesh.is_boundary_vertex
    assert (mesh.vertex_angle_sum[inner] < 2 * np.pi - 1e-3).all()  # convex, not developable
    n_conical = 0
    for u in np.nonzero(inner)[0]:
        ring = mesh.vertex_ring(int(u))
        if len(ring.faces) != 4:
            continue
        angle = [
            mesh.halfedge_corner_angle[
                next(
                    h
                    for h in range(mesh.face_start[f], mesh.face_start[f + 1])
                    if mesh.halfedge_from[h] == u
                )
            ]
            for f in ring.faces
        ]
        assert_allclose(angle[0] + angle[2], angle[1] + angle[3], rtol=0, atol=1e-9)
        n_conical += 1
    assert n_conical >= 1
    assert 0.85 <= mesh.mean_edge_length <= 1.25
    assert crossing_pairs(mesh) == 0


# ------------------------------------------------------------------------ parameter errors
@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("miura:4x3,foo=1", r"unknown example parameter 'foo'.*accepts: cells, angle, fold"),
        ("miura:4", r"bad value '4' for example parameter 'cells'.*AxB"),
        ("miura:fold=abc", r"bad value 'abc' for example parameter 'fold'.*a number"),
        ("miura:fold=1.5", r"fold must be in \[0.05, 0.95\], got 1.5.*accepts"),
        ("miura:angle=90", r"angle must be in \[30, 85\]"),
        ("miura:0x3", r"cells must be between 1x1"),
        ("miura:4x3,fold=0.5,fold=0.6", r"'fold' given twice"),
        ("miura:4x3,5", r"parameter '5' needs a name"),
        ("chicken-wire:angle=60", r"unknown example parameter 'angle'.*accepts: cells, fold"),
        ("resch:fold=0.2", r"fold must be in \[0.4, 0.8\]"),
        pytest.param(  # the smallest that curls: 7 s of solving, in the slow tier
            "resch:5x5,fold=0.8", r"passes through itself", marks=pytest.mark.slow
        ),
        ("conical-dome:2x3", r"3\.\.64 meridian"),
        ("cube:2x2", r"'cube' takes no parameters"),
    ],
)
def test_bad_parameters_raise_mesh_read_error(spec, match):
    with pytest.raises(MeshReadError, match=match):
        example_mesh(spec)
    with pytest.raises(MeshReadError, match=match):
        load_mesh(spec)


def test_generators_raise_parameter_error():
    with pytest.raises(ParameterError, match="fold must be in"):
        tess.yoshimura(fold=0.0)
    with pytest.raises(ParameterError, match="cells must be two integers"):
        tess.chicken_wire(cells="big")
    with pytest.raises(ParameterError, match="height must be in"):
        tess.conical_dome(height=-1)


def test_unknown_base_name_with_parameters():
    with pytest.raises(MeshReadError, match=r"did you mean 'miura'"):
        load_mesh("miuraa:4x3")


def test_spec_is_forgiving_and_deterministic():
    v1, f1 = example_mesh("Chicken_Wire:3X2, fold = 0.4")
    v2, f2 = example_mesh("chicken-wire:3x2,fold=0.4")
    assert np.array_equal(v1, v2) and all(np.array_equal(a, b) for a, b in zip(f1, f2, strict=True))
    v3, _ = example_mesh("resch:2x2")
    v3[:] = 0
    assert np.abs(example_mesh("resch:2x2")[0]).max() > 0  # the cached solve is not shared


def test_crossing_triangle_pairs_sees_a_crossing():
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [0.5, 0.5, -1], [0.5, 0.5, 1], [3, 3, 0.0]])
    assert crossing_triangle_pairs(v, [[0, 1, 2], [3, 4, 5]]) == 1
    assert crossing_triangle_pairs(v, [[0, 1, 2]]) == 0
    far = v.copy()
    far[3:, 0] += 10
    assert crossing_triangle_pairs(far, [[0, 1, 2], [3, 4, 5]]) == 0
