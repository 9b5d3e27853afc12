"""Reading PLY files (:func:`filletfold.mesh.io.read_ply`): every layout (ASCII, binary of
either byte order, any count and index type, extra properties and elements, ``vertex_index``
or ``vertex_indices``), polygons kept, triangle strips decoded with their alternating
winding."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
import trimesh

from filletfold.cli import main
from filletfold.errors import MeshReadError
from filletfold.mesh import example_mesh, load_mesh, read_mesh
from filletfold.mesh.io import strip_triangles

from ..conftest import signed_volume

_CODES = {
    "char": "i1",
    "uchar": "u1",
    "short": "i2",
    "ushort": "u2",
    "int": "i4",
    "uint": "u4",
    "float": "f4",
    "double": "f8",
    "int8": "i1",
    "uint8": "u1",
    "int32": "i4",
    "uint32": "u4",
    "float32": "f4",
    "float64": "f8",
}


def ply_bytes(
    vertices,
    faces,
    *,
    fmt="ascii",
    coord="float",
    count="uchar",
    index="int",
    list_name="vertex_indices",
    extra_vertex=(),
    extra_face=False,
    strips=None,
    strip_index="int",
    other_element=False,
) -> bytes:
    """A PLY file of ``vertices`` and ``faces`` (and ``strips``: lists with ``-1`` between
    strips) in the given layout. ``extra_vertex``: scalar properties after x, y, z;
    ``extra_face``: a texture-coordinate list and a flag around the index list;
    ``other_element``: an ``edge`` element between vertices and faces."""
    v = np.asarray(vertices, dtype=float)
    head = ["ply", f"format {fmt} 1.0", "comment made by the tests", "obj_info nothing"]
    head += [f"element vertex {len(v)}"] + [f"property {coord} {a}" for a in "xyz"]
    head += [f"property {t} {n}" for n, t in extra_vertex]
    if other_element:
        head += ["element edge 2", "property int vertex1", "property int vertex2"]
    if faces is not None:
        head.append(f"element face {len(faces)}")
        if extra_face:
            head.append(f"property list {count} float texcoord")
        head.append(f"property list {count} {index} {list_name}")
        if extra_face:
            head.append("property uchar flags")
    if strips is not None:
        head += ["element tristrips 1", f"property list int {strip_index} vertex_indices"]
    head.append("end_header")
    text = ("\n".join(head) + "\n").encode()
    if fmt == "ascii":
        rows = []
        for i, p in enumerate(v):
            rows.append(
                " ".join(map(repr, p.tolist())) + "".join(f" {i % 7}" for _ in extra_vertex)
            )
        if other_element:
            rows += ["0 1", "1 2"]
        for f in faces if faces is not None else []:
            row = ""
            if extra_face:
                row += f"{2 * len(f)} " + " ".join(["0.5"] * 2 * len(f)) + " "
            row += f"{len(f)} " + " ".join(map(str, f))
            if extra_face:
                row += " 3"
            rows.append(row)
        if strips is not None:
            s = [x if x >= 0 or strip_index.startswith("int") else 2**32 - 1 for x in strips]
            rows.append(f"{len(s)} " + " ".join(map(str, s)))
        return text + ("\n".join(rows) + "\n").encode()
    e = "<" if fmt == "binary_little_endian" else ">"
    out = bytearray(text)
    vdt = [(a, e + _CODES[coord]) for a in "xyz"] + [(n, e + _CODES[t]) for n, t in extra_vertex]
    rows = np.zeros(len(v), dtype=vdt)
    for i, a in enumerate("xyz"):
        rows[a] = v[:, i]
    for n, _ in extra_vertex:
        rows[n] = np.arange(len(v)) % 7
    out += rows.tobytes()
    if other_element:
        out += np.array([0, 1, 1, 2], dtype=e + "i4").tobytes()
    for f in faces if faces is not None else []:
        if extra_face:
            out += np.array([2 * len(f)], dtype=e + _CODES[count]).tobytes()
            out += np.full(2 * len(f), 0.5, dtype=e + "f4").tobytes()
        out += np.array([len(f)], dtype=e + _CODES[count]).tobytes()
        out += np.asarray(f, dtype=e + _CODES[index]).tobytes()
        if extra_face:
            out += np.array([3], dtype="u1").tobytes()
    if strips is not None:
        out += np.array([len(strips)], dtype=e + "i4").tobytes()
        out += np.asarray(strips).astype(e + _CODES[strip_index]).tobytes()
    return bytes(out)


def cube_tris():
    v, faces = example_mesh("cube")
    return v, [list(t) for f in faces for t in (f[[0, 1, 2]], f[[0, 2, 3]])]


LAYOUTS = [
    {"fmt": fmt, "count": count, "index": index, "coord": coord}
    for fmt in ("ascii", "binary_little_endian", "binary_big_endian")
    for count, index, coord in (
        ("uchar", "int", "float"),
        ("int", "uint", "double"),
        ("uint8", "int32", "float32"),
        ("ushort", "short", "float64"),
    )
]


@pytest.mark.parametrize("layout", LAYOUTS, ids=lambda d: "-".join(d.values()))
@pytest.mark.parametrize("polygons", [False, True], ids=["triangles", "quads"])
def test_every_layout_reads_the_same_mesh(tmp_path, layout, polygons):
    v, tris = cube_tris()
    faces = [list(f) for f in example_mesh("cube")[1]] if polygons else tris
    path = tmp_path / "m.ply"
    path.write_bytes(ply_bytes(v, faces, **layout))
    v2, f2 = read_mesh(path)
    np.testing.assert_allclose(v2, v, atol=1e-7)
    assert [f.tolist() for f in f2] == faces  # polygons stay polygons
    assert all(f.dtype == np.int64 for f in f2)
    if not polygons:  # what trimesh reads of the same file
        m = trimesh.load(path, force="mesh", process=False)
        np.testing.assert_allclose(m.vertices, v2)
        assert np.array_equal(m.faces, np.array(f2))


@pytest.mark.parametrize("fmt", ["ascii", "binary_little_endian", "binary_big_endian"])
def test_extra_properties_and_elements_and_vertex_index_and_mixed_polygons(tmp_path, fmt):
    """Normals and colours on the vertices, a texture list and a flag around the faces' list,
    an ``edge`` element, the list named ``vertex_index``, triangles and quads mixed."""
    v, faces = example_mesh("house")  # a pentagonal prism-like house: mixed polygon sizes
    faces = [list(f) for f in faces]
    path = tmp_path / "m.ply"
    path.write_bytes(
        ply_bytes(
            v,
            faces,
            fmt=fmt,
            list_name="vertex_index",
            extra_vertex=(("nx", "float"), ("red", "uchar"), ("quality", "double")),
            extra_face=True,
            other_element=True,
        )
    )
    v2, f2 = read_mesh(path)
    np.testing.assert_allclose(v2, v, atol=1e-6)
    assert [f.tolist() for f in f2] == faces
    assert len({len(f) for f in f2}) > 1


def test_trimesh_exports_read_back(tmp_path):
    m = trimesh.creation.icosphere(2)
    for encoding in ("binary", "ascii"):
        path = tmp_path / f"s-{encoding}.ply"
        path.write_bytes(m.export(file_type="ply", encoding=encoding))
        v, f = read_mesh(path)
        np.testing.assert_allclose(v, m.vertices, atol=1e-6)
        assert np.array_equal(np.array(f), m.faces)


def test_an_upper_case_magic_line_with_crlf_reads(tmp_path):
    """COMPAS's tubemesh.ply starts with ``PLY`` and CRLF line ends; trimesh reads it, so
    must filletfold."""
    m = trimesh.creation.icosphere(1)
    text = m.export(file_type="ply", encoding="ascii").decode("ascii")
    path = tmp_path / "upper.ply"
    path.write_bytes(("PLY" + text[3:]).replace("\n", "\r\n").encode("ascii"))
    v, f = read_mesh(path)
    np.testing.assert_allclose(v, m.vertices, atol=1e-6)
    assert np.array_equal(np.array(f), m.faces)


# ------------------------------------------------------------------------- triangle strips
def test_strip_triangles_alternate_their_winding():
    # strip 0 1 2 3 4: (0 1 2), (2 1 3) reversed, (2 3 4); a second strip after -1
    tris = strip_triangles([0, 1, 2, 3, 4, -1, 5, 6, 7, 8])
    assert tris.tolist() == [[0, 1, 2], [2, 1, 3], [2, 3, 4], [5, 6, 7], [7, 6, 8]]
    # the winding restarts with each strip, whatever the parity of its start
    assert strip_triangles([0, 1, 2, -1, 3, 4, 5, 6]).tolist() == [[0, 1, 2], [3, 4, 5], [5, 4, 6]]
    # a repeated index turns the strip (zero-area triangles are not faces) and, as in
    # OpenGL, the parity goes on counting through it
    assert strip_triangles([0, 1, 2, 2, 3, 4]).tolist() == [[0, 1, 2], [3, 2, 4]]
    assert strip_triangles([0, 1, -1]).tolist() == []
    assert strip_triangles([5, 6, 7, 2**32 - 1, 1, 2, 3], end=2**32 - 1).tolist() == [
        [5, 6, 7],
        [1, 2, 3],
    ]


def strip_cube():
    """A unit cube as triangle strips: every triangle wound outward."""
    v, _ = example_mesh("cube")
    # each face (a, b, c, d) counter-clockwise from outside as the strip a b d c
    faces = example_mesh("cube")[1]
    strips = []
    for f in faces:
        strips += [int(f[0]), int(f[1]), int(f[3]), int(f[2]), -1]
    return v, strips[:-1]


@pytest.mark.parametrize("fmt", ["ascii", "binary_little_endian", "binary_big_endian"])
@pytest.mark.parametrize("strip_index", ["int", "uint"])
def test_triangle_strips_read_as_an_outward_closed_surface(tmp_path, fmt, strip_index):
    """The Stanford repository's layout: ``element tristrips 1`` with one ``vertex_indices``
    list, strips ended by -1 (the largest value of an unsigned type)."""
    v, strips = strip_cube()
    path = tmp_path / "strips.ply"
    path.write_bytes(ply_bytes(v, None, fmt=fmt, strips=strips, strip_index=strip_index))
    v2, f2 = read_mesh(path)
    assert len(f2) == 12 and all(len(f) == 3 for f in f2)
    tm = trimesh.Trimesh(v2, np.array(f2), process=False)
    assert tm.is_watertight and tm.is_winding_consistent and tm.volume == pytest.approx(1.0)
    mesh, log = load_mesh(path)
    assert mesh.n_faces == 6 and log.flipped_faces == 0
    assert signed_volume(mesh) == pytest.approx(1.0)


def test_triangle_strips_and_faces_together(tmp_path):
    v, strips = strip_cube()
    faces = [[0, 1, 2]]
    data = ply_bytes(v, faces, strips=strips)
    path = tmp_path / "both.ply"
    path.write_bytes(data)
    _, f2 = read_mesh(path)
    assert len(f2) == 13 and f2[0].tolist() == [0, 1, 2]


def test_a_strip_ply_goes_through_filletfold_round(tmp_path):
    v, strips = strip_cube()
    path = tmp_path / "strips.ply"
    path.write_bytes(ply_bytes(v, None, fmt="binary_little_endian", strips=strips))
    out = tmp_path / "out"
    assert main(["round", str(path), "-o", str(out), "-q"]) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["certificate"]["ok"] is True and report["repairs"] == []
    assert main(["check", str(out)]) == 0


# ------------------------------------------------------------------------------ bad files
@pytest.mark.parametrize(
    "data, pattern",
    [
        (b"\x00\x01garbage" * 20, r"cannot read PLY file: not a PLY file"),
        (b"ply\nformat ascii 1.0\nelement vertex 1\n", r"no 'end_header' line"),
        (b"ply\nelement vertex 0\nend_header\n", r"no 'format' line"),
        (
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n",
            r"line 4: unknown PLY property type 'quad'",
        ),
        (
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            b"property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
            r"has 3 vertices but no faces",
        ),
        (
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
            b"element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0\n3 0 0 0\n",
            r"the PLY 'vertex' element has no z property",
        ),
        (
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            b"property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            b"end_header\n0 0 0\n1 0 zero\n0 1 0\n3 0 1 2\n",
            r"line 11: cannot parse a row of element 'vertex'",
        ),
        (
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            b"property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            b"end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n",
            r"face 0 refers to vertex 5, outside the 3 vertices",
        ),
    ],
)
def test_bad_ply_files_are_refused_in_one_line(tmp_path, data, pattern):
    path = tmp_path / "bad.ply"
    path.write_bytes(data)
    with pytest.raises(MeshReadError, match=rf"^{re.escape(str(path))}: .*{pattern}"):
        read_mesh(path)


@pytest.mark.parametrize("fmt", ["ascii", "binary_little_endian", "binary_big_endian"])
def test_a_ply_cut_short_is_refused_in_every_layout(tmp_path, fmt):
    v, tris = cube_tris()
    whole = ply_bytes(v, tris, fmt=fmt)
    for cut in (len(whole) - 5, len(whole) - 14 * 3, len(whole) - 14 * 12 - 20):
        path = tmp_path / "cut.ply"
        path.write_bytes(whole[:cut])
        with pytest.raises(MeshReadError, match=r"the file ends early: its header declares"):
            read_mesh(path)


def test_odd_binary_lists_are_refused_in_one_line(tmp_path):
    head = (
        b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        b"property float y\nproperty float z\nelement face 1\n"
    )
    verts = np.eye(3, dtype="<f4").tobytes()
    path = tmp_path / "neg.ply"
    path.write_bytes(
        head
        + b"property list int int vertex_indices\nend_header\n"
        + verts
        + np.array([-3, 0, 1, 2], dtype="<i4").tobytes()
    )
    with pytest.raises(MeshReadError, match=r"row 0 of element 'face' has a list .* of -3 items"):
        read_mesh(path)
    path.write_bytes(
        head
        + b"property list uint int vertex_indices\nend_header\n"
        + verts
        + np.array([2**32 - 1, 0, 1, 2], dtype="<u4").tobytes()
    )
    with pytest.raises(MeshReadError, match=r"the file ends early"):
        read_mesh(path)
    path.write_bytes(head + b"property list float int vertex_indices\nend_header\n" + verts)
    with pytest.raises(MeshReadError, match=r"line 8: the count of list 'vertex_indices'"):
        read_mesh(path)
