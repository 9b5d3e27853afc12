"""Reading and writing polygon meshes.

OBJ and OFF are parsed here, keeping polygon faces as polygons. PLY, STL (ASCII and binary),
glTF and GLB are read through :func:`trimesh.load` and come back as triangles.

Every error names the file first, then what is wrong and, for OBJ and OFF, on which line.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import ExportError, MeshError, MeshReadError

#: File extensions :func:`read_mesh` understands, and who parses them.
SUPPORTED_EXTENSIONS: dict[str, str] = {
    ".obj": "filletfold",
    ".off": "filletfold",
    ".ply": "trimesh",
    ".stl": "trimesh",
    ".glb": "trimesh",
    ".gltf": "trimesh",
}

_TRIMESH_TYPES = {".ply": "ply", ".stl": "stl", ".glb": "glb", ".gltf": "gltf"}


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
        Polygons as stored in the file (0-based indices); PLY, STL and glTF give triangles.

    Raises
    ------
    MeshReadError
        The file is missing, is not a file, has an unsupported extension, cannot be parsed
        (OBJ/OFF errors give the line number), or holds no faces.
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
    if ext in (".obj", ".off"):
        try:
            data = p.read_bytes()
        except OSError as exc:
            raise MeshReadError(f"{name}: cannot read file: {exc.strerror or exc}") from exc
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


def _parse_obj(text: str, name: str) -> tuple[np.ndarray, list[np.ndarray]]:
    vertices: list[tuple[float, float, float]] = []
    faces: list[np.ndarray] = []
    face_lines: list[int] = []
    for number, tokens in _logical_lines(text):
        key = tokens[0]
        if key == "v":
            if len(tokens) < 4:
                raise MeshReadError(
                    f"{name}: line {number}: vertex needs 3 coordinates, got {len(tokens) - 1}"
                )
            try:
                vertices.append((float(tokens[1]), float(tokens[2]), float(tokens[3])))
            except ValueError as exc:
                raise MeshReadError(
                    f"{name}: line {number}: cannot parse vertex coordinates "
                    f"{' '.join(tokens[1:4])!r}"
                ) from exc
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


def _read_trimesh(p: Path, name: str, ext: str) -> tuple[np.ndarray, list[np.ndarray]]:
    import trimesh

    try:
        mesh = trimesh.load(str(p), file_type=_TRIMESH_TYPES[ext], force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types for bad files
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
    if ext == ".ply":
        _check_ply_counts(p, name, len(vertices), len(faces))
    return vertices.reshape(-1, 3), list(faces)


def _check_ply_counts(p: Path, name: str, n_vertices: int, n_faces: int) -> None:
    """Refuse a PLY file that holds fewer vertices or faces than its header declares (a file
    cut short, which trimesh reads without a word): the mesh would be silently incomplete.
    Polygons come back as triangles, so there may be more faces, not fewer."""
    with p.open("rb") as fh:
        head = fh.read(1 << 16)
    end = head.find(b"end_header")
    if end < 0:
        return
    declared = {}
    for line in head[:end].decode("ascii", "replace").splitlines():
        words = line.split()
        if len(words) == 3 and words[0] == "element" and words[2].isdigit():
            declared[words[1]] = int(words[2])
    want_v, want_f = declared.get("vertex"), declared.get("face")
    if (want_v is not None and n_vertices < want_v) or (want_f is not None and n_faces < want_f):
        raise MeshReadError(
            f"{name}: the file ends early: its header declares {want_v} vertices and {want_f} "
            f"faces, {n_vertices} and {n_faces} were read"
        )


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
