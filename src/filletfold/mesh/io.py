"""Reading and writing polygon meshes.

OBJ, OFF and PLY are parsed here, keeping polygon faces as polygons; PLY in every layout,
triangle strips too (:func:`read_ply`); ASCII STL too, facet by facet, so that a file cut short
after its last complete facet (no ``endsolid``, as some exporters write) still reads. Binary
STL, glTF and GLB are read through :func:`trimesh.load` and come back as triangles.

Every error names the file first, then what is wrong and, for OBJ and OFF, on which line.
"""

from __future__ import annotations

import os
import re
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ExportError, MeshError, MeshReadError

#: File extensions :func:`read_mesh` understands, and who parses them.
SUPPORTED_EXTENSIONS: dict[str, str] = {
    ".obj": "filletfold",
    ".off": "filletfold",
    ".ply": "filletfold",
    ".stl": "trimesh",
    ".glb": "trimesh",
    ".gltf": "trimesh",
}

_TRIMESH_TYPES = {".stl": "stl", ".glb": "glb", ".gltf": "gltf"}


def read_mesh(path) -> tuple[np.ndarray, list[np.ndarray]]:
    """Read a polygon mesh from a file.

    Parameters
    ----------
    path : str or os.PathLike
        An ``.obj``, ``.off``, ``.ply``, ``.stl``, ``.glb`` or ``.gltf`` file (case-insensitive
        extension).

    Returns
    -------
    vertices : (n_vertices, 3) float64
    faces : list of (k,) int64
        Polygons as stored in the file (0-based indices; a PLY's triangle strips as their
        triangles); STL and glTF give triangles.

    Raises
    ------
    MeshReadError
        The file is missing, is not a file, has an unsupported extension, cannot be parsed
        (OBJ/OFF/ASCII PLY errors give the line number), or holds no faces.
    MeshError
        A vertex coordinate is not finite (the message names the vertex, 0-based).
    """
    p = Path(os.fspath(path))
    name = str(path)
    ext = p.suffix.lower()
    if ext not in SUPPORTED_EXTENSIONS:
        supported = ", ".join(SUPPORTED_EXTENSIONS)
        shown = f"extension '{p.suffix}'" if p.suffix else "no extension"
        raise MeshReadError(f"{name}: unsupported file type ({shown}); supported: {supported}")
    if not p.exists():
        raise MeshReadError(f"{name}: no such file")
    if not p.is_file():
        raise MeshReadError(f"{name}: not a regular file")
    if p.stat().st_size == 0:
        raise MeshReadError(f"{name}: the file is empty")
    if ext in (".obj", ".off", ".ply", ".stl"):
        try:
            data = p.read_bytes()
        except OSError as exc:
            raise MeshReadError(f"{name}: cannot read file: {exc.strerror or exc}") from exc
    if ext == ".ply":
        vertices, faces = read_ply(data, name)
    elif ext in (".obj", ".off"):
        try:
            text = data.decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            raise MeshReadError(
                f"{name}: not a text {ext[1:].upper()} file (byte {exc.start} is not UTF-8)"
            ) from exc
        if ext == ".obj":
            vertices, faces = _parse_obj(text, name)
        else:
            vertices, faces = _parse_off(text, name)
    elif ext == ".stl" and _is_ascii_stl(data):
        vertices, faces = _parse_stl_ascii(data, name)
    else:
        vertices, faces = _read_trimesh(p, name, ext)
    _check_finite(vertices, name)
    return vertices, faces


# ---------------------------------------------------------------------------------- helpers
def _check_finite(vertices: np.ndarray, name: str) -> None:
    bad = np.nonzero(~np.isfinite(vertices).all(axis=1))[0]
    if len(bad):
        i = int(bad[0])
        raise MeshError(
            f"{name}: vertex {i} has a non-finite coordinate {vertices[i].tolist()}", vertex=i
        )


def _logical_lines(text: str):
    """Yield ``(line_number, tokens)`` for non-empty lines, comments stripped (1-based)."""
    pending: list[str] = []
    start = 0
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0]
        stripped = line.rstrip()
        if stripped.endswith("\\"):  # OBJ line continuation
            if not pending:
                start = number
            pending.append(stripped[:-1])
            continue
        if pending:
            pending.append(line)
            line = " ".join(pending)
            pending = []
            number = start
        tokens = line.split()
        if tokens:
            yield number, tokens
    if pending:
        tokens = " ".join(pending).split()
        if tokens:
            yield start, tokens


def _vertex_xyz(tokens: list[str], name: str, number: int, *, exact: bool) -> tuple:
    """``(x, y, z)`` of a vertex line split into ``tokens`` (its keyword first: OBJ's ``v``,
    STL's ``vertex``), or a one-line error naming the file and ``number``, the line.

    ``exact``: exactly three coordinates (STL); else at least three (OBJ: an optional ``w``
    or colour follows).
    """
    if len(tokens) < 4 or (exact and len(tokens) != 4):
        raise MeshReadError(
            f"{name}: line {number}: vertex needs 3 coordinates, got {len(tokens) - 1}"
        )
    try:
        return float(tokens[1]), float(tokens[2]), float(tokens[3])
    except ValueError as exc:
        raise MeshReadError(
            f"{name}: line {number}: cannot parse vertex coordinates {' '.join(tokens[1:4])!r}"
        ) from exc


def _parse_obj(text: str, name: str) -> tuple[np.ndarray, list[np.ndarray]]:
    vertices: list[tuple[float, float, float]] = []
    faces: list[np.ndarray] = []
    face_lines: list[int] = []
    for number, tokens in _logical_lines(text):
        key = tokens[0]
        if key == "v":
            vertices.append(_vertex_xyz(tokens, name, number, exact=False))
        elif key == "f":
            if len(tokens) < 4:
                raise MeshReadError(
                    f"{name}: line {number}: face needs at least 3 vertices, got {len(tokens) - 1}"
                )
            face = np.empty(len(tokens) - 1, dtype=np.int64)
            for j, token in enumerate(tokens[1:]):
                head = token.split("/", 1)[0]
                try:
                    index = int(head)
                except ValueError as exc:
                    raise MeshReadError(
                        f"{name}: line {number}: cannot parse face vertex {token!r}"
                    ) from exc
                if index == 0:
                    raise MeshReadError(
                        f"{name}: line {number}: face vertex index 0 (OBJ indices start at 1)"
                    )
                if index < 0:
                    index = len(vertices) + index
                    if index < 0:
                        raise MeshReadError(
                            f"{name}: line {number}: relative face vertex {token!r} points "
                            f"before the first vertex"
                        )
                else:
                    index -= 1
                face[j] = index
            faces.append(face)
            face_lines.append(number)
        # other records (vt, vn, vp, l, p, o, g, s, usemtl, mtllib, ...) are ignored
    n = len(vertices)
    for face, number in zip(faces, face_lines, strict=True):
        if face.max() >= n:
            raise MeshReadError(
                f"{name}: line {number}: face vertex {int(face.max()) + 1} does not exist "
                f"(the file has {n} vertices)"
            )
    if not faces:
        what = "is empty" if not vertices else f"has {n} vertices but no faces"
        raise MeshReadError(f"{name}: the file {what}")
    return np.array(vertices, dtype=np.float64).reshape(-1, 3), faces


def _parse_off(text: str, name: str) -> tuple[np.ndarray, list[np.ndarray]]:
    lines = iter(_logical_lines(text))
    first = next(lines, None)
    if first is None:
        raise MeshReadError(f"{name}: the file is empty")
    number, tokens = first
    header = tokens[0]
    if not header.endswith("OFF") or header.startswith(("4", "n")):
        raise MeshReadError(f"{name}: line {number}: expected the header 'OFF', got {header!r}")
    if len(tokens) > 1 and tokens[1].upper() == "BINARY":
        raise MeshReadError(f"{name}: line {number}: binary OFF is not supported")
    counts = tokens[1:]
    if not counts:
        nxt = next(lines, None)
        if nxt is None:
            raise MeshReadError(f"{name}: the file ends after the header (no counts line)")
        number, counts = nxt
    try:
        n_vertices, n_faces = int(counts[0]), int(counts[1])
    except (ValueError, IndexError) as exc:
        raise MeshReadError(
            f"{name}: line {number}: expected 'n_vertices n_faces n_edges', "
            f"got {' '.join(counts)!r}"
        ) from exc
    if n_vertices < 0 or n_faces < 0:
        raise MeshReadError(f"{name}: line {number}: negative element counts")
    vertices = np.empty((n_vertices, 3), dtype=np.float64)
    for i in range(n_vertices):
        item = next(lines, None)
        if item is None:
            raise MeshReadError(f"{name}: the file ends after {i} of its {n_vertices} vertices")
        number, tokens = item
        if len(tokens) < 3:
            raise MeshReadError(
                f"{name}: line {number}: vertex {i} needs 3 coordinates, got {len(tokens)}"
            )
        try:
            vertices[i] = [float(t) for t in tokens[:3]]
        except ValueError as exc:
            raise MeshReadError(
                f"{name}: line {number}: cannot parse vertex {i} from {' '.join(tokens)!r}"
            ) from exc
    faces: list[np.ndarray] = []
    for i in range(n_faces):
        item = next(lines, None)
        if item is None:
            raise MeshReadError(f"{name}: the file ends after {i} of its {n_faces} faces")
        number, tokens = item
        try:
            k = int(tokens[0])
            face = np.array([int(t) for t in tokens[1 : k + 1]], dtype=np.int64)
        except ValueError as exc:
            raise MeshReadError(
                f"{name}: line {number}: cannot parse face {i} from {' '.join(tokens)!r}"
            ) from exc
        if k < 3 or len(face) != k:
            raise MeshReadError(
                f"{name}: line {number}: face {i} announces {k} vertices and lists "
                f"{len(face)} (at least 3 needed)"
            )
        if face.min() < 0 or face.max() >= n_vertices:
            raise MeshReadError(
                f"{name}: line {number}: face {i} refers to a vertex outside 0..{n_vertices - 1}"
            )
        faces.append(face)
    if not faces:
        raise MeshReadError(f"{name}: the file has {n_vertices} vertices but no faces")
    return vertices, faces


def _is_ascii_stl(data: bytes) -> bool:
    """True for an ASCII STL: it starts with ``solid`` and is not sized as a binary one.

    A binary STL is 84 bytes of header and count and 50 bytes per triangle; some exporters
    begin its 80-byte header with ``solid`` too, so the size decides.
    """
    if data.lstrip()[:5].lower() != b"solid":
        return False
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + 50 * count:
            return False
    return True


def _parse_stl_ascii(data: bytes, name: str) -> tuple[np.ndarray, list[np.ndarray]]:
    """Facets of an ASCII STL as polygons (triangles in a well-formed file).

    Every ``outer loop ... endloop`` gives one face of its ``vertex`` lines, one vertex per
    line (welded later by :func:`filletfold.mesh.clean.clean_mesh`). Several ``solid`` blocks are
    read one after the other; a file that ends after a complete facet without ``endsolid``
    is read up to there. A loop of fewer than 3 vertices, an unparseable coordinate or a
    loop cut off by the end of the file is an error naming its line.
    """
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError as exc:
        raise MeshReadError(
            f"{name}: not an ASCII STL file (byte {exc.start} is not ASCII)"
        ) from exc
    coords: list[tuple[float, float, float]] = []
    sizes: list[int] = []
    loop_line = 0
    in_loop = False
    for number, raw in enumerate(text.splitlines(), start=1):
        tokens = raw.split()
        if not tokens:
            continue
        key = tokens[0].lower()
        if key == "vertex":
            if not in_loop:
                raise MeshReadError(f"{name}: line {number}: vertex outside an 'outer loop'")
            coords.append(_vertex_xyz(tokens, name, number, exact=True))
            sizes[-1] += 1
        elif key == "outer":
            if in_loop:
                raise MeshReadError(f"{name}: line {number}: 'outer loop' inside another loop")
            in_loop, loop_line = True, number
            sizes.append(0)
        elif key == "endloop":
            if not in_loop:
                raise MeshReadError(f"{name}: line {number}: 'endloop' without 'outer loop'")
            if sizes[-1] < 3:
                raise MeshReadError(
                    f"{name}: line {loop_line}: facet needs at least 3 vertices, got {sizes[-1]}"
                )
            in_loop = False
        elif key not in ("solid", "endsolid", "facet", "endfacet"):
            raise MeshReadError(f"{name}: line {number}: unexpected {tokens[0]!r} in ASCII STL")
    if in_loop:
        raise MeshReadError(
            f"{name}: line {loop_line}: the file ends inside a facet (no 'endloop')"
        )
    if not sizes:
        raise MeshReadError(f"{name}: no vertices or faces found (empty or unreadable STL file)")
    vertices = np.array(coords, dtype=np.float64).reshape(-1, 3)
    ends = np.cumsum(sizes)
    faces = [np.arange(e - k, e, dtype=np.int64) for e, k in zip(ends.tolist(), sizes, strict=True)]
    return vertices, faces


#: The most triangles a glTF/GLB or STL file may place (every instance counted): a 1.1 MB GLB of
#: instances expanded to 400,000 triangles and 3.3 GB; the 99,785-triangle Stanford bunny is
#: read in 1.9 MB.
MAX_READ_TRIANGLES = 2_000_000


def _placed_triangles(scene) -> int:
    """Triangles of every geometry of a trimesh ``scene``, once per node that places it."""
    total = 0
    for node in scene.graph.nodes_geometry:
        geometry = scene.geometry.get(scene.graph[node][1])
        faces = getattr(geometry, "faces", None)
        total += 0 if faces is None else len(faces)
    return total


def _read_trimesh(p: Path, name: str, ext: str) -> tuple[np.ndarray, list[np.ndarray]]:
    import trimesh

    try:
        scene = trimesh.load_scene(str(p), file_type=_TRIMESH_TYPES[ext], process=False)
    except Exception as exc:  # trimesh raises many types for bad files
        raise MeshReadError(
            f"{name}: cannot read {ext[1:].upper()} file: {type(exc).__name__}: {exc}"
        ) from exc
    placed = _placed_triangles(scene)  # before the instances are expanded
    if placed > MAX_READ_TRIANGLES:
        raise MeshReadError(
            f"{name}: its meshes, every instance placed, have {placed:,} triangles, more than "
            f"the {MAX_READ_TRIANGLES:,} filletfold reads (a small glTF file of many "
            "instances can expand past the memory of the machine)"
        )
    try:
        mesh = scene.to_mesh()  # what trimesh.load(force="mesh") gives
    except Exception as exc:
        raise MeshReadError(
            f"{name}: cannot read {ext[1:].upper()} file: {type(exc).__name__}: {exc}"
        ) from exc
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64)
    if faces.ndim != 2 or len(faces) == 0:
        if len(vertices) == 0:
            raise MeshReadError(
                f"{name}: no vertices or faces found (empty or unreadable {ext[1:].upper()} file)"
            )
        raise MeshReadError(f"{name}: the file has {len(vertices)} vertices but no faces")
    return vertices.reshape(-1, 3), list(faces)


# -------------------------------------------------------------------------------------- PLY
#: PLY scalar type names -> (numpy code, struct code).
_TYPES = {
    "char": ("i1", "b"),
    "int8": ("i1", "b"),
    "uchar": ("u1", "B"),
    "uint8": ("u1", "B"),
    "short": ("i2", "h"),
    "int16": ("i2", "h"),
    "ushort": ("u2", "H"),
    "uint16": ("u2", "H"),
    "int": ("i4", "i"),
    "int32": ("i4", "i"),
    "uint": ("u4", "I"),
    "uint32": ("u4", "I"),
    "int64": ("i8", "q"),
    "uint64": ("u8", "Q"),
    "float": ("f4", "f"),
    "float32": ("f4", "f"),
    "double": ("f8", "d"),
    "float64": ("f8", "d"),
}

#: Element and list names that hold the mesh, in order of preference.
_VERTEX_NAMES = ("vertex", "vertices", "vert")
_FACE_NAMES = ("face", "faces", "facet", "polygon")
_STRIP_NAMES = ("tristrips", "tristrip", "triangle_strips")
_INDEX_NAMES = ("vertex_indices", "vertex_index", "vertex_indexes")


@dataclass
class _Property:
    name: str
    type: str  # numpy code of a scalar, or of a list's items
    count_type: str | None = None  # numpy code of a list's count; None for a scalar

    @property
    def is_list(self) -> bool:
        return self.count_type is not None


@dataclass
class _Element:
    name: str
    count: int
    props: list
    line: int  # header line of the element


def read_ply(data: bytes, name: str) -> tuple[np.ndarray, list[np.ndarray]]:
    """Vertices and faces of the PLY file whose bytes are ``data`` (``name`` names it in
    errors).

    Every layout of the format is read: ASCII, binary little- and big-endian; any scalar type
    (``char`` ... ``double`` and their ``int8`` ... ``float64`` spellings); list properties
    with any count and item type; extra properties (normals, colours, texture lists) and
    other elements (``edge``, ``material``), which are skipped. Faces come from the ``face``
    element's ``vertex_indices`` (or ``vertex_index``) list and stay polygons; triangle strips
    from a ``tristrips`` element (the Stanford scanning repository's files), see
    :func:`strip_triangles`. A table of equal rows (triangles) is read at once, rows of
    different lengths one by one.

    Returns
    -------
    vertices : (n_vertices, 3) float64
    faces : list of (k,) int64
        The ``face`` element's polygons as stored, then the triangles of the strips.

    Raises
    ------
    MeshReadError
        Not a PLY file, a header that cannot be parsed, a body shorter than the header
        declares or that cannot be parsed, no vertex coordinates, no faces, or a face index
        outside the vertex list.
    """
    fmt, elements, body = _header(data, name)
    values: dict[str, dict] = {}
    read_counts: dict[str, int] = {}
    wanted = _wanted(elements)
    if fmt == "ascii":
        _read_ascii(body, elements, wanted, values, read_counts, name, _header_lines(data))
    else:
        _read_binary(
            body,
            "<" if fmt == "binary_little_endian" else ">",
            elements,
            wanted,
            values,
            read_counts,
            name,
        )
    return _mesh(elements, values, name)


# ------------------------------------------------------------------------------ header
def _header(data: bytes, name: str) -> tuple[str, list[_Element], bytes]:
    if not re.match(rb"(?i)ply[ \t]*\r?\n", data[:8]):  # "PLY" too, as trimesh reads it
        raise MeshReadError(
            f"{name}: cannot read PLY file: not a PLY file (it does not start with the line 'ply')"
        )
    m = re.search(rb"(^|\n)end_header[ \t]*(\r\n|\n|\r)?", data[: 1 << 20])
    if m is None:
        raise MeshReadError(f"{name}: cannot read PLY file: no 'end_header' line ends its header")
    try:
        text = data[: m.start()].decode("ascii")
    except UnicodeDecodeError as exc:
        raise MeshReadError(
            f"{name}: cannot read PLY file: its header has a non-ASCII byte at {exc.start}"
        ) from exc
    fmt = None
    elements: list[_Element] = []
    for number, line in enumerate(text.splitlines()[1:], start=2):
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        where = f"{name}: line {number}"
        if words[0] == "format":
            if len(words) < 2 or words[1] not in (
                "ascii",
                "binary_little_endian",
                "binary_big_endian",
            ):
                raise MeshReadError(f"{where}: unknown PLY format {' '.join(words[1:])!r}")
            fmt = words[1]
        elif words[0] == "element":
            if len(words) != 3 or not words[2].isdigit():
                raise MeshReadError(f"{where}: expected 'element NAME COUNT', got {line.strip()!r}")
            elements.append(_Element(words[1], int(words[2]), [], number))
        elif words[0] == "property":
            if not elements:
                raise MeshReadError(f"{where}: a property before any element")
            if len(words) == 5 and words[1] == "list":
                ct, it = _type(words[2], where), _type(words[3], where)
                if ct[0] == "f":
                    raise MeshReadError(
                        f"{where}: the count of list {words[4]!r} has the type {words[2]!r} "
                        "(an integer type is needed)"
                    )
                elements[-1].props.append(_Property(words[4], it, ct))
            elif len(words) == 3:
                elements[-1].props.append(_Property(words[2], _type(words[1], where)))
            else:
                raise MeshReadError(
                    f"{where}: expected 'property TYPE NAME' or 'property list COUNT_TYPE "
                    f"TYPE NAME', got {line.strip()!r}"
                )
        else:
            raise MeshReadError(f"{where}: unknown PLY header keyword {words[0]!r}")
    if fmt is None:
        raise MeshReadError(f"{name}: cannot read PLY file: its header has no 'format' line")
    return fmt, elements, data[m.end() :]


def _header_lines(data: bytes) -> int:
    end = re.search(rb"(^|\n)end_header[^\n]*\n?", data[: 1 << 20])
    return data[: end.end()].count(b"\n") + (0 if data[: end.end()].endswith(b"\n") else 1)


def _type(word: str, where: str) -> str:
    if word not in _TYPES:
        raise MeshReadError(f"{where}: unknown PLY property type {word!r}")
    return _TYPES[word][0]


def _index_prop(el: _Element) -> _Property | None:
    """The list of vertex indices of a face or strip element: by its usual names, else its
    only list property."""
    lists = [p for p in el.props if p.is_list]
    for want in _INDEX_NAMES:
        for p in lists:
            if p.name == want:
                return p
    return lists[0] if len(lists) == 1 else None


def _wanted(elements) -> set:
    """(element, property) names to keep."""
    out = set()
    for el in elements:
        if el.name in _VERTEX_NAMES:
            out.update((el.name, a) for a in ("x", "y", "z"))
        elif el.name in _FACE_NAMES or el.name in _STRIP_NAMES:
            p = _index_prop(el)
            if p is not None:
                out.add((el.name, p.name))
    return out


# ------------------------------------------------------------------------------ binary body
def _read_binary(body, endian, elements, wanted, values, read_counts, name) -> None:
    offset = 0
    for el in elements:
        got, n_read, offset = _binary_element(body, offset, endian, el, wanted, name)
        values[el.name] = got
        read_counts[el.name] = n_read
        if n_read < el.count:
            _ends_early(elements, read_counts, name)


def _binary_element(body, offset, endian, el: _Element, wanted, name):
    """Read ``el`` from ``body`` at ``offset``: (kept values by property, rows read, offset
    after it)."""
    lists = [p for p in el.props if p.is_list]
    if not lists:
        dt = np.dtype([(f"p{i}", endian + p.type) for i, p in enumerate(el.props)])
        n = min(el.count, (len(body) - offset) // dt.itemsize) if dt.itemsize else el.count
        rows = np.frombuffer(body, dtype=dt, count=n, offset=offset)
        got = {p.name: rows[f"p{i}"] for i, p in enumerate(el.props) if (el.name, p.name) in wanted}
        return got, n, offset + n * dt.itemsize
    if len(lists) == 1 and el.count:
        fixed = _binary_fixed_lists(body, offset, endian, el, wanted)
        if fixed is not None:
            return fixed
    return _binary_rows(body, offset, endian, el, wanted, name)


def _binary_fixed_lists(body, offset, endian, el: _Element, wanted):
    """The fast way, when every row's list has the length of the first row's (triangles):
    one structured array; None when the lengths differ."""
    fields, at = [], 0
    for i, p in enumerate(el.props):
        if p.is_list:
            if len(body) < offset + at + np.dtype(p.count_type).itemsize:
                return None
            k = int(np.frombuffer(body, endian + p.count_type, 1, offset + at)[0])
            if k < 0 or k * np.dtype(p.type).itemsize > len(body):
                return None
            fields += [(f"c{i}", endian + p.count_type), (f"p{i}", endian + p.type, (k,))]
        else:
            fields.append((f"p{i}", endian + p.type))
        at = np.dtype(fields).itemsize
    dt = np.dtype(fields)
    n = min(el.count, (len(body) - offset) // dt.itemsize)
    rows = np.frombuffer(body, dtype=dt, count=n, offset=offset)
    i = next(i for i, p in enumerate(el.props) if p.is_list)
    k = dt[f"p{i}"].shape[0]
    if (rows[f"c{i}"] != k).any():
        return None
    if n < el.count:  # short: count the whole rows the slow way, for the message
        return None
    got = {}
    for j, p in enumerate(el.props):
        if (el.name, p.name) in wanted:
            col = rows[f"p{j}"]
            got[p.name] = col
    return got, n, offset + n * dt.itemsize


def _binary_rows(body, offset, endian, el: _Element, wanted, name):
    """Row by row (lists of different lengths)."""
    struct_code = {v[0]: v[1] for v in _TYPES.values()}
    steps = []
    for p in el.props:
        keep = (el.name, p.name) in wanted
        if p.is_list:
            count = struct.Struct(endian + struct_code[p.count_type])
            steps.append((p.name, keep, count, np.dtype(endian + p.type)))
        else:
            steps.append((p.name, keep, struct.Struct(endian + struct_code[p.type]), None))
    got = {p.name: [] for p in el.props if (el.name, p.name) in wanted}
    n_read = 0
    end = len(body)
    try:
        for _ in range(el.count):
            for pname, keep, s, item in steps:
                (x,) = s.unpack_from(body, offset)
                offset += s.size
                if item is None:
                    if keep:
                        got[pname].append(x)
                    continue
                if x < 0:
                    raise MeshReadError(
                        f"{name}: row {n_read} of element {el.name!r} has a list {pname!r} of "
                        f"{x} items"
                    )
                if offset + x * item.itemsize > end:
                    raise struct.error("the list runs past the end of the file")
                if keep:
                    got[pname].append(np.frombuffer(body, item, x, offset))
                offset += x * item.itemsize
            n_read += 1
    except struct.error:
        pass
    out = {}
    for p in el.props:
        if p.name in got:
            out[p.name] = got[p.name] if p.is_list else np.asarray(got[p.name], dtype=p.type)
    return out, n_read, offset


# ------------------------------------------------------------------------------ ascii body
def _read_ascii(body, elements, wanted, values, read_counts, name, first_line) -> None:
    try:
        text = body.decode("ascii")
    except UnicodeDecodeError as exc:
        raise MeshReadError(
            f"{name}: not an ASCII PLY body (byte {exc.start} after the header is not ASCII)"
        ) from exc
    raw = text.splitlines()
    lines = [(i + first_line + 1, s) for i, s in enumerate(raw) if s.strip()]
    # a last line without its newline that does not parse: the file was cut there
    cut_line = lines[-1][0] if lines and not text.endswith(("\n", "\r")) else None
    at = 0
    for el in elements:
        rows = lines[at : at + el.count]
        at += len(rows)
        try:
            values[el.name] = _ascii_element(rows, el, wanted, name, cut_line)
        except _Cut:
            read_counts[el.name] = len(rows) - 1
            _ends_early(elements, read_counts, name)
        read_counts[el.name] = len(rows)
        if len(rows) < el.count:
            _ends_early(elements, read_counts, name)


class _Cut(Exception):
    """The last line of an ASCII body, cut short."""


def _ascii_element(rows, el: _Element, wanted, name, cut_line=None) -> dict:
    n_scalar = len(el.props)
    lists = [p for p in el.props if p.is_list]
    if not rows:
        return {p.name: ([] if p.is_list else np.zeros(0)) for p in el.props}
    if not lists:
        flat = " ".join(s for _, s in rows).split()
        if len(flat) == len(rows) * n_scalar:
            try:
                table = np.array(flat, dtype=np.float64).reshape(len(rows), n_scalar)
            except ValueError:
                table = None
            if table is not None:
                return {
                    p.name: table[:, i].astype(p.type if p.type[0] != "f" else np.float64)
                    for i, p in enumerate(el.props)
                    if (el.name, p.name) in wanted
                }
    elif len(lists) == 1:
        fast = _ascii_fixed_lists(rows, el, wanted)
        if fast is not None:
            return fast
    got = {p.name: [] for p in el.props if (el.name, p.name) in wanted}
    for number, line in rows:
        words = line.split()
        k = 0
        try:
            for p in el.props:
                if p.is_list:
                    count = _int(words[k])
                    items = words[k + 1 : k + 1 + count]
                    if count < 0 or len(items) < count:
                        raise IndexError
                    if p.name in got:
                        got[p.name].append(
                            np.array([_int(w) for w in items], dtype=np.int64)
                            if p.type[0] in "iu"
                            else np.array(items, float)
                        )
                    k += 1 + count
                else:
                    x = float(words[k])
                    if p.name in got:
                        got[p.name].append(x)
                    k += 1
        except (IndexError, ValueError) as exc:
            if number == cut_line:
                raise _Cut from exc
            raise MeshReadError(
                f"{name}: line {number}: cannot parse a row of element {el.name!r} "
                f"({_describe(el)}) from {line.strip()[:60]!r}"
            ) from exc
    out = {}
    for p in el.props:
        if p.name in got:
            out[p.name] = got[p.name] if p.is_list else np.asarray(got[p.name], dtype=np.float64)
    return out


def _ascii_fixed_lists(rows, el: _Element, wanted) -> dict | None:
    """The fast way, when every row has as many numbers as the first and its list is as long
    as the first row's (triangles): one table; None otherwise."""
    first = rows[0][1].split()
    width = len(first)
    flat = " ".join(s for _, s in rows).split()
    if len(flat) != width * len(rows):
        return None
    try:
        table = np.array(flat, dtype=np.float64).reshape(len(rows), width)
    except ValueError:
        return None
    got, k = {}, 0
    for p in el.props:
        if p.is_list:
            count = table[:, k]
            n = int(count[0]) if count[0] == int(count[0]) else -1
            if n < 0 or (count != n).any() or k + 1 + n > width:
                return None
            items = table[:, k + 1 : k + 1 + n]
            if (el.name, p.name) in wanted:
                if p.type[0] in "iu" and (items != np.round(items)).any():
                    return None
                got[p.name] = items.astype(np.int64) if p.type[0] in "iu" else items
            k += 1 + n
        else:
            if (el.name, p.name) in wanted:
                got[p.name] = table[:, k]
            k += 1
    return got if k == width else None


def _int(word: str) -> int:
    x = float(word)
    if x != int(x):
        raise ValueError(word)
    return int(x)


def _describe(el: _Element) -> str:
    return ", ".join(("list " if p.is_list else "") + p.name for p in el.props)


def _ends_early(elements, read_counts, name):
    got = {el.name: read_counts.get(el.name, 0) for el in elements}
    declared = {el.name: el.count for el in elements}
    v = next((n for n in _VERTEX_NAMES if n in declared), None)
    f = next((n for n in _FACE_NAMES + _STRIP_NAMES if n in declared), None)
    if v is not None and f is not None:
        what = "faces" if f in _FACE_NAMES else "strips"
        raise MeshReadError(
            f"{name}: the file ends early: its header declares {declared[v]} vertices and "
            f"{declared[f]} {what}, {got[v]} and {got[f]} were read"
        )
    short = next(el for el in elements if got[el.name] < el.count)
    raise MeshReadError(
        f"{name}: the file ends early: its header declares {short.count} {short.name!r} "
        f"elements, {got[short.name]} were read"
    )


# ------------------------------------------------------------------------------ the mesh
def _mesh(elements, values, name) -> tuple[np.ndarray, list[np.ndarray]]:
    by_name = {el.name: el for el in elements}
    vname = next((n for n in _VERTEX_NAMES if n in by_name), None)
    if vname is None:
        raise MeshReadError(f"{name}: no vertices found (the PLY file has no 'vertex' element)")
    missing = [a for a in ("x", "y", "z") if a not in values[vname]]
    if missing:
        raise MeshReadError(
            f"{name}: the PLY 'vertex' element has no {', '.join(missing)} propert"
            + ("y" if len(missing) == 1 else "ies")
        )
    vertices = np.stack([np.asarray(values[vname][a], dtype=np.float64) for a in "xyz"], axis=1)
    n = len(vertices)
    faces: list[np.ndarray] = []
    for fname in _FACE_NAMES:
        if fname in by_name:
            p = _index_prop(by_name[fname])
            if p is None:
                raise MeshReadError(
                    f"{name}: the PLY {fname!r} element has no 'vertex_indices' list"
                )
            faces += _as_index_lists(values[fname][p.name])
    strips = 0
    for sname in _STRIP_NAMES:
        if sname in by_name:
            p = _index_prop(by_name[sname])
            if p is None:
                raise MeshReadError(
                    f"{name}: the PLY {sname!r} element has no 'vertex_indices' list"
                )
            for row in _as_index_lists(values[sname][p.name]):
                tris = strip_triangles(
                    row, end=int(np.iinfo(p.type).max) if p.type[0] == "u" else None
                )
                strips += 1
                faces += list(tris)
    if n == 0:
        raise MeshReadError(f"{name}: no vertices found (the PLY file's vertex element is empty)")
    if not faces:
        raise MeshReadError(f"{name}: the file has {n} vertices but no faces")
    flat = np.concatenate(faces)
    if flat.min() >= 0 and flat.max() < n:
        return vertices, faces
    for i, f in enumerate(faces):
        if len(f) and (f.min() < 0 or f.max() >= n):
            k = int(f[(f < 0) | (f >= n)][0])
            raise MeshReadError(
                f"{name}: face {i} refers to vertex {k}, outside the {n} vertices (0..{n - 1})"
            )
    return vertices, faces


def _as_index_lists(col) -> list[np.ndarray]:
    if isinstance(col, np.ndarray) and col.ndim == 2 and col.dtype.kind in "iu":
        return list(col.astype(np.int64))
    out = []
    for r in col:
        a = np.asarray(r)
        if a.dtype.kind != "f" or (np.isfinite(a).all() and (a == np.round(a)).all()):
            a = a.astype(np.int64)
        out.append(a)  # non-integer indices are left for the cleaning to name
    return out


def strip_triangles(strip, *, end: int | None = None) -> np.ndarray:
    """(n_triangles, 3) int64: the triangles of a PLY ``tristrips`` list.

    ``-1`` (or ``end``: the largest value of an unsigned item type) ends a strip. In a strip
    ``s0, s1, s2, s3, ...`` triangle ``t`` has the corners ``s[t], s[t+1], s[t+2]``, those of
    odd ``t`` reversed (``s[t+1], s[t], s[t+2]``) so that every triangle has the winding of the
    first. Triangles with a repeated corner (how a strip turns, or joins the next one) are
    left out.
    """
    s = np.asarray(strip).astype(np.int64)
    if end is not None:
        s[s == end] = -1
    if len(s) < 3:
        return np.zeros((0, 3), dtype=np.int64)
    sep = s < 0
    # first position of the strip each position belongs to
    pos = np.arange(len(s))
    start = np.maximum.accumulate(np.where(np.r_[True, sep[:-1]], pos, 0))
    t = pos[:-2]
    ok = ~(sep[:-2] | sep[1:-1] | sep[2:])
    t = t[ok]
    a, b, c = s[t], s[t + 1], s[t + 2]
    odd = ((t - start[t]) % 2).astype(bool)
    tri = np.stack([np.where(odd, b, a), np.where(odd, a, b), c], axis=1)
    keep = (a != b) & (b != c) & (a != c)
    return tri[keep]


# ---------------------------------------------------------------------------------- writers
def _format_float(x: float) -> str:
    return repr(float(x))


def write_obj(path, vertices, faces, *, header: str | None = None) -> None:
    """Write a polygon mesh as a plain-text OBJ (``v`` and ``f`` records only).

    Parameters
    ----------
    path : str or os.PathLike
    vertices : (n_vertices, 3) float
    faces : sequence of (k,) int
        0-based polygons; written 1-based.
    header : str, optional
        Written as ``#`` comment lines at the top.

    Raises
    ------
    ExportError
        The file cannot be written.
    """
    lines = [f"# {h}" for h in header.splitlines()] if header else []
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    lines += ["v " + " ".join(map(_format_float, row)) for row in v]
    lines += ["f " + " ".join(str(int(i) + 1) for i in f) for f in faces]
    _write_text(path, "\n".join(lines) + "\n")


def write_off(path, vertices, faces) -> None:
    """Write a polygon mesh as a plain-text OFF.

    Parameters
    ----------
    path : str or os.PathLike
    vertices : (n_vertices, 3) float
    faces : sequence of (k,) int
        0-based polygons.

    Raises
    ------
    ExportError
        The file cannot be written.
    """
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    faces = [np.asarray(f, dtype=np.int64).ravel() for f in faces]
    n_edges = len(
        {(min(a, b), max(a, b)) for f in faces for a, b in zip(f, np.roll(f, -1), strict=True)}
    )
    lines = ["OFF", f"{len(v)} {len(faces)} {n_edges}"]
    lines += [" ".join(map(_format_float, row)) for row in v]
    lines += [f"{len(f)} " + " ".join(str(int(i)) for i in f) for f in faces]
    _write_text(path, "\n".join(lines) + "\n")


def _write_text(path, text: str) -> None:
    try:
        Path(os.fspath(path)).write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ExportError(f"{path}: cannot write file: {exc.strerror or exc}") from exc
