"""Reading and writing meshes: OBJ/OFF/PLY by our parsers, STL/GLB via trimesh, load_mesh
(every PLY layout and triangle strips: test_ply.py)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import trimesh
from numpy.testing import assert_allclose

from filletfold.errors import ExportError, MeshError, MeshReadError
from filletfold.mesh import (
    example_mesh,
    load_mesh,
    read_mesh,
    write_obj,
    write_off,
)

from ..conftest import signed_volume

BUNNY = Path(__file__).resolve().parents[2] / "examples" / "bunny-lowres.obj"


def assert_same_faces(a, b):
    assert len(a) == len(b)
    for fa, fb in zip(a, b, strict=True):
        assert np.array_equal(fa, fb)


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


# ------------------------------------------------------------------------- round trips
@pytest.mark.parametrize("name", ["dodecahedron", "house", "l-prism", "torus"])
@pytest.mark.parametrize("writer, ext", [(write_obj, "obj"), (write_off, "off")])
def test_round_trip_keeps_polygons_exactly(tmp_path, name, writer, ext):
    v, faces = example_mesh(name)
    path = tmp_path / f"{name}.{ext}"
    writer(path, v, faces)
    v2, faces2 = read_mesh(path)
    assert v2.dtype == np.float64
    assert np.array_equal(v, v2)  # repr() floats round-trip exactly
    assert_same_faces(faces, faces2)


def test_writers_are_deterministic(tmp_path):
    v, faces = example_mesh("blob")
    for writer in (write_obj, write_off):
        writer(tmp_path / "a", v, faces)
        writer(tmp_path / "b", v, faces)
        assert (tmp_path / "a").read_bytes() == (tmp_path / "b").read_bytes()


def test_write_obj_header(tmp_path):
    v, faces = example_mesh("cube")
    write_obj(tmp_path / "c.obj", v, faces, header="line one\nline two")
    text = (tmp_path / "c.obj").read_text()
    assert text.startswith("# line one\n# line two\nv ")


def test_write_to_missing_directory_raises_export_error(tmp_path):
    v, faces = example_mesh("cube")
    with pytest.raises(ExportError, match=r"nope.*cannot write file"):
        write_obj(tmp_path / "nope" / "c.obj", v, faces)


# ------------------------------------------------------------------------------ OBJ parse
def test_obj_face_index_forms_and_ignored_records(tmp_path):
    text = """# a square pyramid with every face-vertex form
mtllib none.mtl
o pyramid
v -0.5 -0.5 0
v 0.5 -0.5 0
v 0.5 0.5 0 1.0
v -0.5 0.5 0
vt 0 0
vt 1 0
vn 0 0 1
g base
usemtl stuff
s off
f 4/1 3/2 2/1 1/2
v 0 0 0.7   # apex, after the base
f 1//1 2//1 5//1
f 2/1/1 3/1/1 -1/1/1
f -3 -2 -1
l 1 2
f 4 1 \\
  5
"""
    v, faces = read_mesh(write(tmp_path, "p.obj", text))
    assert v.shape == (5, 3)
    assert_same_faces(
        faces, [np.array(f) for f in ([3, 2, 1, 0], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4])]
    )
    mesh, log = load_mesh(tmp_path / "p.obj")
    assert mesh.n_faces == 5 and mesh.is_closed and log.flipped_faces == 0


def test_obj_with_byte_order_mark(tmp_path):
    path = tmp_path / "bom.obj"
    path.write_bytes("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".encode("utf-8-sig"))
    v, faces = read_mesh(path)
    assert v.shape == (3, 3) and len(faces) == 1


def test_obj_uppercase_extension(tmp_path):
    v, faces = example_mesh("cube")
    write_obj(tmp_path / "CUBE.OBJ", v, faces)
    assert len(read_mesh(tmp_path / "CUBE.OBJ")[1]) == 6


@pytest.mark.parametrize(
    "body, pattern",
    [
        ("v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n", r"line 3: cannot parse vertex coordinates"),
        ("v 0 0 0\nv 1 0\n", r"line 2: vertex needs 3 coordinates, got 2"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 x\n", r"line 5: cannot parse face vertex 'x'"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", r"line 4: face needs at least 3 vertices"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", r"line 4: face vertex index 0"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", r"line 4: face vertex 7 does not exist"),
        ("v 0 0 0\nf -1 -2 -3\nv 1 0 0\n", r"line 2: relative face vertex '-2' points before"),
        ("# only a comment\n\n", r"the file is empty"),
        ("v 0 0 0\nv 1 0 0\n", r"the file has 2 vertices but no faces"),
    ],
)
def test_garbled_obj_rejected_with_line_number(tmp_path, body, pattern):
    path = write(tmp_path, "bad.obj", body)
    with pytest.raises(MeshReadError, match=rf"^{re.escape(str(path))}: {pattern}"):
        read_mesh(path)


def test_binary_obj_rejected(tmp_path):
    path = tmp_path / "bin.obj"
    path.write_bytes(b"v 0 0 0\n\xff\xfe\x00\x81")
    with pytest.raises(MeshReadError, match=r"bin\.obj: not a text OBJ file \(byte 8"):
        read_mesh(path)


def test_nan_vertex_in_file_rejected_naming_the_vertex(tmp_path):
    path = write(tmp_path, "nan.obj", "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(MeshError, match=r"nan\.obj: vertex 1 has a non-finite coordinate") as info:
        read_mesh(path)
    assert info.value.vertex == 1
    assert not isinstance(info.value, MeshReadError)


# ------------------------------------------------------------------------------ OFF parse
def test_off_counts_on_header_comments_and_colours(tmp_path):
    text = """OFF 4 4 6   # counts on the header line
# a tetrahedron
0 0 0
1 0 0
0 1 0

0 0 1
3 0 2 1  255 0 0
3 0 1 3 0.5 0.5 0.5 1.0
3 1 2 3
3 0 3 2
"""
    v, faces = read_mesh(write(tmp_path, "t.off", text))
    assert v.shape == (4, 3)
    assert_same_faces(faces, [np.array(f) for f in ([0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2])])
    mesh, _ = load_mesh(str(tmp_path / "t.off"))
    assert signed_volume(mesh) > 0


def test_off_counts_on_next_line_and_coff_header(tmp_path):
    text = "COFF\n3 1 3\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n0 1 0 1 0 0 1\n3 0 1 2\n"
    v, faces = read_mesh(write(tmp_path, "c.off", text))
    assert v.shape == (3, 3) and len(faces) == 1


@pytest.mark.parametrize(
    "body, pattern",
    [
        ("PLY\n3 1 0\n", r"line 1: expected the header 'OFF', got 'PLY'"),
        ("OFF BINARY\n", r"line 1: binary OFF is not supported"),
        ("OFF\n", r"the file ends after the header"),
        ("OFF\nthree 1 0\n", r"line 2: expected 'n_vertices n_faces n_edges'"),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n", r"the file ends after 2 of its 3 vertices"),
        ("OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n", r"line 4: vertex 1 needs 3 coordinates, got 2"),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 a\n3 0 1 2\n", r"line 5: cannot parse vertex 2"),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n",
            r"line 6: face 0 announces 4 vertices and lists 3",
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
            r"line 6: face 0 refers to a vertex outside 0\.\.2",
        ),
        ("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", r"the file ends after 1 of its 2 faces"),
        ("OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", r"the file has 3 vertices but no faces"),
    ],
)
def test_garbled_off_rejected(tmp_path, body, pattern):
    path = write(tmp_path, "bad.off", body)
    with pytest.raises(MeshReadError, match=rf"^{re.escape(str(path))}: {pattern}"):
        read_mesh(path)


# ------------------------------------------------------------------------ trimesh formats
@pytest.mark.parametrize("ext", ["stl", "ply", "glb"])
def test_trimesh_formats_read_as_triangles_and_clean_to_quads(tmp_path, ext):
    v, faces = example_mesh("cube")
    tris = np.array([t for f in faces for t in (f[[0, 1, 2]], f[[0, 2, 3]])])
    path = tmp_path / f"cube.{ext}"
    trimesh.Trimesh(v, tris, process=False).export(path)
    _, faces2 = read_mesh(path)
    assert all(len(f) == 3 for f in faces2) and len(faces2) == 12
    mesh, log = load_mesh(path)
    assert mesh.n_faces == 6 and mesh.n_vertices == 8 and log.merged_faces == 6
    assert_allclose(signed_volume(mesh), 1.0, atol=1e-6)


def test_ascii_stl(tmp_path):
    v, faces = example_mesh("octahedron")
    path = tmp_path / "octa.stl"
    path.write_text(trimesh.exchange.stl.export_stl_ascii(trimesh.Trimesh(v, np.array(faces))))
    mesh, log = load_mesh(path)
    assert mesh.n_faces == 8 and mesh.n_vertices == 6
    assert log.merged_vertices == 24 - 6  # STL repeats every corner


def test_ascii_stl_without_endsolid_and_binary_starting_with_solid(tmp_path):
    """A file cut after its last facet still reads; a binary STL whose header says 'solid' too."""
    v, faces = example_mesh("octahedron")
    mesh = trimesh.Trimesh(v, np.array(faces))
    text = trimesh.exchange.stl.export_stl_ascii(mesh)
    cut = text[: text.rindex("endsolid")]
    path = tmp_path / "cut.stl"
    path.write_text(cut)
    verts, tris = read_mesh(path)
    assert len(tris) == 8 and len(verts) == 24
    assert_allclose(verts[np.concatenate(tris)].reshape(8, 3, 3), v[np.array(faces)], atol=1e-6)
    binary = bytearray(trimesh.exchange.stl.export_stl(mesh))
    binary[:6] = b"solid "
    path = tmp_path / "binary.stl"
    path.write_bytes(bytes(binary))
    verts, tris = read_mesh(path)
    assert len(tris) == 8


@pytest.mark.parametrize(
    "name, data, pattern",
    [
        ("bad.ply", b"\x00\x01garbage" * 20, r"cannot read PLY file: not a PLY file"),
        (
            "bad.stl",
            b"solid x\n facet normal 0 0 1\n garbage\n",
            r"line 3: unexpected 'garbage' in ASCII STL",
        ),
        ("bad.stl", b"solid x\nendsolid x\n", r"no vertices or faces found"),
        (
            "bad.stl",
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n",
            r"line 3: facet needs at least 3 vertices, got 2",
        ),
        (
            "bad.stl",
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n",
            r"line 3: the file ends inside a facet",
        ),
        (
            "bad.stl",
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 x 0\n"
            b"vertex 0 1 0\nendloop\nendfacet\n",
            r"line 5: cannot parse vertex coordinates '1 x 0'",
        ),
        ("bad.stl", b"solid \xff\xfe", r"not an ASCII STL file \(byte 6"),
        ("bad.glb", b"glTF-but-not-really" * 3, r"cannot read GLB file"),
    ],
)
def test_garbled_trimesh_formats_rejected(tmp_path, name, data, pattern):
    path = tmp_path / name
    path.write_bytes(data)
    with pytest.raises(MeshReadError, match=rf"^{re.escape(str(path))}: {pattern}"):
        read_mesh(path)


# ----------------------------------------------------------------------------- file errors
def test_missing_file(tmp_path):
    path = tmp_path / "missing.obj"
    with pytest.raises(MeshReadError, match=rf"^{re.escape(str(path))}: no such file"):
        read_mesh(path)


def test_directory_is_not_a_file(tmp_path):
    d = tmp_path / "dir.obj"
    d.mkdir()
    with pytest.raises(MeshReadError, match=r"dir\.obj: not a regular file"):
        read_mesh(d)


@pytest.mark.parametrize("ext", ["obj", "off", "stl", "ply"])
def test_empty_file(tmp_path, ext):
    path = write(tmp_path, f"empty.{ext}", "")
    with pytest.raises(MeshReadError, match=rf"empty\.{ext}: the file is empty"):
        read_mesh(path)


@pytest.mark.parametrize("name", ["mesh.3ds", "mesh"])
def test_unsupported_extension_lists_supported_ones(tmp_path, name):
    path = write(tmp_path, name, "whatever")
    with pytest.raises(
        MeshReadError,
        match=r"unsupported file type .*supported: \.obj, \.off, "
        r"\.ply, \.stl, \.glb, \.gltf",
    ):
        read_mesh(path)


# ------------------------------------------------------------------------------ load_mesh
def test_load_mesh_sources(tmp_path):
    v, faces = example_mesh("house")
    write_obj(tmp_path / "house.obj", v, faces)
    from_file, _ = load_mesh(str(tmp_path / "house.obj"))
    from_path, _ = load_mesh(tmp_path / "house.obj")
    from_name, _ = load_mesh("house")
    from_pair, _ = load_mesh((v, faces))
    from_lists, _ = load_mesh((v.tolist(), [f.tolist() for f in faces]))
    from_mesh, _ = load_mesh(from_name)
    for m in (from_file, from_path, from_pair, from_lists, from_mesh):
        assert np.array_equal(m.vertices, from_name.vertices)
        assert_same_faces(m.faces, from_name.faces)


def test_load_mesh_array_faces_and_options():
    v, faces = example_mesh("cube")
    tris = np.array([t for f in faces for t in (f[[0, 1, 2]], f[[0, 2, 3]])])
    assert load_mesh((v, tris))[0].n_faces == 6
    assert load_mesh((v, tris), merge_coplanar=False)[0].n_faces == 12
    assert load_mesh((v, tris), coplanar_deg=0.0)[0].n_faces == 12


def test_load_mesh_prefers_an_existing_file_over_an_example(tmp_path, monkeypatch):
    v, faces = example_mesh("tetrahedron")
    monkeypatch.chdir(tmp_path)
    write_obj(tmp_path / "cube", v, faces)  # a file called "cube", without extension
    with pytest.raises(MeshReadError, match=r"cube: unsupported file type \(no extension\)"):
        load_mesh("cube")


def test_load_mesh_unknown_string():
    with pytest.raises(
        MeshReadError,
        match=r"^dodecahedrn: no such file and no built-in example named 'dodecahedrn'; "
        r"did you mean 'dodecahedron'\? built-in examples: tetrahedron, ",
    ):
        load_mesh("dodecahedrn")


def test_load_mesh_missing_path_object(tmp_path):
    with pytest.raises(MeshReadError, match=r"nothing\.off: no such file"):
        load_mesh(tmp_path / "nothing.off")


def test_load_mesh_rejects_other_types():
    with pytest.raises(MeshReadError, match=r"cannot load a mesh from a int"):
        load_mesh(3)


# ------------------------------------------------------------------------------ the bunny
def test_bunny_lowres_loads_and_cleans():
    mesh, log = load_mesh(BUNNY)
    assert mesh.n_faces == 200 and mesh.n_vertices == 102
    assert mesh.is_closed
    assert mesh.n_vertices - mesh.n_edges + mesh.n_faces == 2
    assert signed_volume(mesh) > 0
    assert log.flipped_faces == 0 and log.merged_faces == 0
    s = mesh.vertex_angle_sum
    assert (s > 2 * np.pi).any() and (s < 2 * np.pi).any()


def test_errors_of_a_file_name_the_file(tmp_path):
    """A defect found after reading (here a face index out of range, which trimesh passes
    through from a PLY) is named with the file, like the reader's own errors."""
    bad = tmp_path / "bad.ply"
    bad.write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"
    )
    with pytest.raises(MeshError, match=rf"^{re.escape(str(bad))}: ") as info:
        load_mesh(str(bad))
    assert "vertex 7" in str(info.value) or "face 0" in str(info.value)


def test_a_ply_cut_short_is_refused(tmp_path):
    """trimesh reads a PLY whose face list stops early without complaint: the header's counts
    show it, and the file is refused rather than rounded incomplete."""
    text = (
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n"
    )
    cut = tmp_path / "cut.ply"
    cut.write_text(text)
    with pytest.raises(MeshReadError, match=r"cut\.ply: the file ends early: its header declares"):
        read_mesh(cut)
    whole = tmp_path / "whole.ply"
    whole.write_text(text + "3 1 2 3\n3 0 3 2\n")
    assert len(read_mesh(whole)[1]) == 4
