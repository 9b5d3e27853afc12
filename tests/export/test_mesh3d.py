"""The folded form as GLB, PLY and STL (:mod:`filletfold.export.mesh3d`), read back with trimesh."""

from __future__ import annotations

import io
import json
import struct

import numpy as np
import pytest
import trimesh
from numpy.testing import assert_allclose

from filletfold.errors import ParameterError
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


#: Metres per drawing unit, glTF's length unit being the metre.
METRES = {"mm": 1e-3, "cm": 1e-2, "m": 1.0, "in": 0.0254}


def load_glb(data: bytes):
    return trimesh.load(io.BytesIO(data), file_type="glb")


def load_mesh(data: bytes, file_type: str):
    return trimesh.load(io.BytesIO(data), file_type=file_type, process=False)


def ply_comments(data: bytes) -> list[str]:
    """The comment lines of a PLY header."""
    header = data[: data.index(b"end_header")].decode("ascii")
    return [line[len("comment ") :] for line in header.splitlines() if line.startswith("comment ")]


def mesh_bounds(folder) -> dict[str, np.ndarray]:
    """(2, 3) bounding box of each of folder's folded.glb, folded.ply and folded.stl, in the
    design's axes (the GLB's y-up turned back: ``(x, y, z) -> (x, -z, y)``)."""
    out = {}
    for ext in ("glb", "ply", "stl"):
        loaded = trimesh.load(folder / f"folded.{ext}", process=False)
        points = loaded.bounds if ext != "glb" else loaded.bounds[:, [0, 2, 1]] * [1, -1, 1]
        out[ext] = np.sort(points, axis=0)
    return out


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


@pytest.mark.parametrize(
    ("units", "scale"), [("", 1.0), ("", 3.0), ("mm", 200.0), ("cm", 2.5), ("m", 1.0), ("in", 0.5)]
)
def test_files_are_drawn_at_scale_in_units(pattern, units, scale):
    """PLY and STL coordinates are the design's times ``scale`` (in ``units``, which the PLY
    names); the GLB's are in metres: times ``scale`` and the unit's length in metres."""
    lo, hi = pattern.vertices_3d.min(axis=0), pattern.vertices_3d.max(axis=0)
    to_metres = METRES[units] if units else 1.0
    scene = load_glb(folded_glb(pattern, units=units, scale=scale))
    want = np.array([[lo[0], lo[2], -hi[1]], [hi[0], hi[2], -lo[1]]]) * scale * to_metres
    assert_allclose(scene.bounds, want, rtol=1e-6, atol=1e-6 * np.abs(want).max())
    ply_data = folded_ply(pattern, units=units, scale=scale)
    ply = load_mesh(ply_data, "ply")
    stl = load_mesh(folded_stl(pattern, scale=scale), "stl")
    for mesh in (ply, stl):
        assert_allclose(mesh.bounds, np.array([lo, hi]) * scale, rtol=1e-6, atol=1e-6 * scale)
        assert mesh.area == pytest.approx(folded_area(pattern) * scale**2, rel=1e-6)
    named = [c for c in ply_comments(ply_data) if c.startswith("units")]
    assert named == ([f"units {units}"] if units else [])
    # welding and normals do not depend on the size
    assert len(ply.vertices) == len(load_mesh(folded_ply(pattern), "ply").vertices)
    for kind, mesh in scene.geometry.items():
        normals = load_glb(folded_glb(pattern)).geometry[kind].vertex_normals
        assert_allclose(mesh.vertex_normals, normals, atol=1e-6)


def test_unit_and_scale_errors(cube):
    with pytest.raises(ParameterError, match="units"):
        folded_glb(cube.pattern, units="pt")
    with pytest.raises(ParameterError, match="units"):
        folded_ply(cube.pattern, units="furlong")
    for bad in (0.0, -1.0, float("nan"), True):
        with pytest.raises(ParameterError, match="scale"):
            folded_stl(cube.pattern, scale=bad)


def test_cli_round_and_export_draw_the_mesh_files_at_scale(tmp_path):
    """``round`` and ``export`` pass ``--units`` and ``--scale`` to the GLB, PLY and STL as to
    the 3dm files: PLY and STL times K, the GLB in metres (``--units mm --scale 200``: x 0.2)."""
    from filletfold.cli import main

    plain, scaled = tmp_path / "plain", tmp_path / "scaled"
    formats = ["--format", "fold,glb,ply,stl"]
    assert main(["round", "cube", "-q", "-o", str(plain), *formats, "--size", "none"]) == 0
    args = ["--units", "mm", "--scale", "200"]
    assert main(["round", "cube", "-q", "-o", str(scaled), *formats, *args]) == 0
    base, got = mesh_bounds(plain), mesh_bounds(scaled)
    for ext, factor in (("glb", 0.2), ("ply", 200.0), ("stl", 200.0)):
        assert_allclose(got[ext], base[ext] * factor, rtol=1e-6, err_msg=ext)
    assert "units mm" in ply_comments((scaled / "folded.ply").read_bytes())
    assert "units" not in " ".join(ply_comments((plain / "folded.ply").read_bytes()))
    # export from design.fold (12 digits): the same sizes, to single precision
    assert (
        main(["export", str(plain), "--format", "glb,ply,stl", "--units", "in", "--scale", "3"])
        == 0
    )
    got = mesh_bounds(plain)
    for ext, factor in (("glb", 3 * 0.0254), ("ply", 3.0), ("stl", 3.0)):
        assert_allclose(got[ext], base[ext] * factor, rtol=1e-6, err_msg=ext)
    assert "units in" in ply_comments((plain / "folded.ply").read_bytes())


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
    sized = cut_files(cube.pattern, "glb,ply,stl", units="mm", scale=200.0)
    assert sized["folded.glb"] == folded_glb(cube.pattern, units="mm", scale=200.0)
    assert sized["folded.ply"] == folded_ply(cube.pattern, units="mm", scale=200.0)
    assert sized["folded.stl"] == folded_stl(cube.pattern, scale=200.0)
    assert sized["folded.stl"] != files["folded.stl"]
