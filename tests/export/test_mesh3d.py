"""The folded form as GLB, PLY and STL (:mod:`filletfold.export.mesh3d`), read back with trimesh."""

from __future__ import annotations

import io
import json
import struct

import numpy as np
import pytest
import trimesh
from numpy.testing import assert_allclose

from filletfold.export.cutfiles import cut_files, parse_formats
from filletfold.export.mesh3d import (
    folded_glb,
    folded_ply,
    folded_stl,
    patch_kind,
    weld_vertices,
)
from filletfold.export.png import PATCH_COLOR

from ..conftest import folded_area
from .conftest import arc_pattern


def triangle_count(pattern, kind: str | None = None) -> int:
    return sum(
        len(f) - 2
        for f, patch in zip(pattern.faces, pattern.face_patch, strict=True)
        if kind is None or patch_kind(patch) == kind
    )


def load_glb(data: bytes):
    return trimesh.load(io.BytesIO(data), file_type="glb")


def glb_json(data: bytes) -> dict:
    """The JSON chunk of a GLB file."""
    magic, version, _ = struct.unpack_from("<4sII", data, 0)
    assert (magic, version) == (b"glTF", 2)
    length, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    return json.loads(data[20 : 20 + length])


@pytest.fixture(scope="module", params=["cube", "arc"])
def pattern(request, cube):
    return cube.pattern if request.param == "cube" else arc_pattern(annotated=True)


def test_glb_one_mesh_and_material_per_kind(pattern):
    data = folded_glb(pattern)
    scene = load_glb(data)
    kinds = {patch_kind(p) for p in pattern.face_patch}
    assert set(scene.geometry) == kinds
    for kind, mesh in scene.geometry.items():
        assert mesh.visual.material.name == kind
        assert len(mesh.faces) == triangle_count(pattern, kind)
        rgba = np.asarray(mesh.visual.material.baseColorFactor, dtype=float)
        assert_allclose(rgba[:3] / 255.0, PATCH_COLOR[kind], atol=1 / 255)
    doc = glb_json(data)
    assert {m["name"] for m in doc["materials"]} == kinds
    assert all(m["doubleSided"] for m in doc["materials"])
    assert all("NORMAL" in p["attributes"] for m in doc["meshes"] for p in m["primitives"])
    # float32 positions: the area is the folded polygons' to single precision
    total = sum(mesh.area for mesh in scene.geometry.values())
    assert total == pytest.approx(folded_area(pattern), rel=1e-6)


def test_glb_normals_point_to_the_front(pattern):
    """Vertex normals are unit and on the front side of every triangle they belong to."""
    for mesh in load_glb(folded_glb(pattern)).geometry.values():
        vn = mesh.vertex_normals
        assert_allclose(np.linalg.norm(vn, axis=1), 1.0, atol=1e-6)
        side = np.einsum("tkj,tj->tk", vn[mesh.faces], mesh.face_normals)
        assert side.min() > 0


def test_glb_is_y_up():
    """The design's z is glTF's y: a pattern flat in z = 0 lies in y = 0, its y along -z."""
    pattern = arc_pattern()
    scene = load_glb(folded_glb(pattern))
    points = np.vstack([m.vertices for m in scene.geometry.values()])
    assert_allclose(points[:, 1], 0.0, atol=1e-7)
    lo, hi = pattern.vertices_3d.min(axis=0), pattern.vertices_3d.max(axis=0)
    assert_allclose(points.min(axis=0)[[0, 2]], [lo[0], -hi[1]], atol=1e-6)
    assert_allclose(points.max(axis=0)[[0, 2]], [hi[0], -lo[1]], atol=1e-6)
    # the triangles face +y (the front of a counter-clockwise flat pattern is +z)
    for mesh in scene.geometry.values():
        assert (mesh.face_normals[:, 1] > 0.999).all()


def test_ply_and_stl_welded(pattern):
    ply = trimesh.load(io.BytesIO(folded_ply(pattern)), file_type="ply", process=False)
    stl = trimesh.load(io.BytesIO(folded_stl(pattern)), file_type="stl", process=False)
    # one vertex per distinct folded point
    distinct = len(np.unique(np.round(pattern.vertices_3d, 9), axis=0))
    assert len(ply.vertices) == distinct
    assert len(ply.faces) == triangle_count(pattern)
    assert len(stl.faces) == triangle_count(pattern)
    for mesh in (ply, stl):
        assert mesh.area == pytest.approx(folded_area(pattern), rel=1e-6)
    # a colour per face: its patch kind's
    colours = ply.visual.face_colors[:, :3]
    for kind in {patch_kind(p) for p in pattern.face_patch}:
        rgb = np.round(255 * np.asarray(PATCH_COLOR[kind]))
        assert (colours == rgb).all(axis=1).sum() == triangle_count(pattern, kind)


def test_stl_of_closed_design_is_watertight(cube):
    """Every cube vertex is a cone and nothing is left open: welded, the surface closes."""
    mesh = trimesh.load(io.BytesIO(folded_stl(cube.pattern)), file_type="stl")
    assert mesh.is_watertight
    assert mesh.volume > 0  # outward-facing


def test_weld_vertices():
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 1e-12], [1, 1e-13, 0], [0, 1, 0]], dtype=float)
    unique, inverse = weld_vertices(p)
    assert_allclose(unique, p[[0, 1, 4]])
    assert inverse.tolist() == [0, 1, 0, 1, 2]
    assert weld_vertices(np.zeros((0, 3)))[0].shape == (0, 3)


def test_mesh_files_reproducible_and_in_cut_files(cube):
    assert parse_formats("gltf,ply,stl") == ("glb", "ply", "stl")
    files = cut_files(cube.pattern, "glb,ply,stl")
    assert list(files) == ["folded.glb", "folded.ply", "folded.stl"]
    again = cut_files(cube.pattern, "gltf,stl,ply")
    for name, data in files.items():
        assert isinstance(data, bytes)
        assert again[name] == data, name
    assert files["folded.glb"] == folded_glb(cube.pattern)
