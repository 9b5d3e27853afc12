"""An independent re-check of a design from its ``design.fold`` (and the input mesh) alone.

:func:`recheck_fold` reads the FOLD file's crease pattern (the key frame's 2D
``vertices_coords``) and folded form (the ``foldedForm`` frame's 3D ``vertices_coords``) of
the same vertices, edges and faces, and measures, with plain numpy and nothing of filletfold's
geometry, certificate or export code:

* **edge lengths**: every pattern edge's relative mismatch ``|len3D - len2D| / len2D``, at most
  the share by which the chord of an arc turning by two arc steps is shorter than the arc,
  ``1 - sinc(step)`` (5.07e-3 at 10 degrees), and its stretch ``(len3D - len2D) / len2D``,
  never above round-off (nothing is longer folded than flat);
* **facet folds**: the dihedral between the two faces of every ``F`` (unfolded) edge, at most the
  arc step (the design's ``parameters.arc_step`` in ``report.json`` beside the FOLD, else 10
  degrees; a step of 0 is no limit), and equal to the ``edges_foldAngle`` the file gives it;
* **creases**: on ``M``/``V`` edges the folded dihedral has the sign of the assignment (valley
  positive, as FOLD has it), matches ``edges_foldAngle``, and stays within 179 degrees (or the
  mesh's sharpest dihedral, from the FOLD's ``filletfold:mesh_edges_halfAngle`` or the tables of
  ``report.json``, where that is sharper);
* **faces**: each face's corner-to-corner distances agree in 2D and 3D (the sides, and the
  diagonals of polygons) within the edges' mismatch limit, each face is planar in 3D (its
  corners' distance from the plane through its centroid with its Newell normal, over its
  diameter, at most 1e-9 + round-off), no face is clockwise in 2D, and no pattern edge is
  shorter than 1e-7 of the size; slivers (a 2D corner under 0.25 degrees or an area under
  1e-12 size^2) are counted, a warning only;
* **closure**: the folded form's points welded within ``1e-9`` of its size; the border of the
  welded surface (edges of one face), which must be empty when the input mesh is closed;
* **structure**: every face side is a pattern edge, every edge has one or two faces run in
  opposite directions, M, V and F edges have two.

"Round-off" is the file's rounding of its coordinates to :data:`FILE_DIGITS` significant
digits: ``q = 4 * 10^(1 - digits) * max|coordinate|`` in a length, ``q / len2D`` in a ratio,
``sqrt(3) q (P_a / A_a + P_b / A_b)`` radians in a dihedral (the faces' perimeters and areas),
on top of a slack of 1e-9 (ratios) or 1e-6 degrees (angles); the facet-fold limit gets the
same angle allowance. "Size" is the diagonal of the folded form's bounding box.

The dihedral of an edge is measured as the certificate does it, but from scratch: Newell normals
of the 3D faces in the 2D counter-clockwise order, ``theta = atan2((N_a x N_b) . d, N_a . N_b)``
with ``d`` the edge direction as face ``a`` runs it; the fold angle is ``-theta`` (valley
positive).

Command line: ``python -m filletfold.testing.recheck DIR_OR_FOLD [MESH]`` prints the summary as
JSON and exits 1 when the design fails, 2 when the file cannot be read.
"""

from __future__ import annotations

import itertools
import json
import math
import re
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from ..arrays import run_owners, run_starts

__all__ = [
    "CREASE_LIMIT_DEG",
    "DEFAULT_ARC_STEP_DEG",
    "EDGE_TURNS",
    "FILE_DIGITS",
    "SHORT_EDGE",
    "SLIVER_ANGLE_DEG",
    "SLIVER_AREA",
    "WELD",
    "chord_share",
    "main",
    "recheck_fold",
]

#: Arc step (degrees) used when neither the caller, ``report.json`` nor the FOLD gives one.
DEFAULT_ARC_STEP_DEG = 10.0
#: Significant digits of the FOLD file's floats (``filletfold.export.fold.FOLD_DIGITS``; kept
#: here as a number so that the re-check imports nothing of the exporter).
FILE_DIGITS = 12
#: Largest |fold angle| of a crease (degrees), unless the mesh has a sharper edge.
CREASE_LIMIT_DEG = 179.0
#: A pattern side across a bent patch may be as much shorter folded than flat as the chord of
#: an arc turning by this many arc steps.
EDGE_TURNS = 2.0
#: Relative slack on lengths beyond file rounding.
LENGTH_SLACK = 1e-9
#: Slack on angles beyond file rounding (degrees).
ANGLE_SLACK_DEG = 1e-6
#: A face is a sliver when its smallest 2D corner angle is below this (degrees) ...
SLIVER_ANGLE_DEG = 0.25
#: ... or its 2D area below this times size squared.
SLIVER_AREA = 1e-12
#: A pattern edge shorter than this times size (the shorter of 2D and 3D) is too short.
SHORT_EDGE = 1e-7
#: Folded points closer than this times size are one point.
WELD = 1e-9
#: Failure lines per check (the worst elements first), then one line with the count left.
MAX_LINES = 10


def chord_share(step_deg: float) -> float:
    """``1 - sinc(step / 2)``: the share by which the chord of a circular arc turning by
    ``step_deg`` degrees is shorter than the arc (1.27e-3 at 10 degrees)."""
    half = math.radians(step_deg) / 2
    if half == 0:
        return 0.0
    return 1.0 - math.sin(half) / half


# --------------------------------------------------------------------------------------------
# reading


def _fold_file(path) -> Path:
    p = Path(path)
    return p / "design.fold" if p.is_dir() else p


#: Keys whose values (2D arrays of numbers) :func:`_load_document` parses with numpy.
_NUMERIC_KEYS = ("vertices_coords", "edges_vertices", "faces_vertices")
_NUMERIC_RE = re.compile(r'"({})"\s*:\s*(?=\[\s*\[)'.format("|".join(_NUMERIC_KEYS)))
_ROW_END_RE = re.compile(r"\]\s*\]")
_BLANKS = str.maketrans("[],", "   ")
_SENTINEL = "\x00recheck-array-"


class _Rows:
    """A 2D array of numbers read from the text: ``flat`` values, ``sizes`` per row."""

    __slots__ = ("flat", "sizes")

    def __init__(self, flat: np.ndarray, sizes: np.ndarray):
        self.flat, self.sizes = flat, sizes


def _parse_rows(span: str, integer: bool) -> _Rows:
    """``[[a,b],[c,d,e],...]`` (numbers only) as :class:`_Rows`; ValueError when malformed."""
    b = np.frombuffer(span.encode("ascii"), dtype=np.uint8)
    opens = np.flatnonzero(b == ord("["))[1:]
    closes = np.flatnonzero(b == ord("]"))[:-1]
    if len(opens) != len(closes) or (closes < opens).any():
        raise ValueError("not a 2D array")
    commas = np.flatnonzero(b == ord(","))
    sizes = np.searchsorted(commas, closes) - np.searchsorted(commas, opens) + 1
    with warnings.catch_warnings():  # text it cannot read to its end: a warning, made an error
        warnings.simplefilter("error", DeprecationWarning)
        flat = np.fromstring(span.translate(_BLANKS), sep=" ")
    if flat.size != sizes.sum():
        raise ValueError("a row is empty or a value is not a number")
    if integer:
        ints = flat.astype(np.int64)
        if (ints != flat).any():
            raise ValueError("an index is not an integer")
        flat = ints
    return _Rows(flat, sizes)


def _load_document(text: str) -> dict:
    """The FOLD document of ``text``: ``json.loads``, except that the (large) point, edge and
    face arrays are parsed in bulk with numpy into :class:`_Rows` (the file is about five times
    faster to read); plain ``json.loads`` when that fails."""
    try:
        parts, arrays, pos = [], [], 0
        for match in _NUMERIC_RE.finditer(text):
            begin = match.end()
            if begin < pos:
                raise ValueError("overlapping arrays")
            close = _ROW_END_RE.search(text, begin)
            if close is None:
                raise ValueError("unterminated array")
            span = text[begin : close.end()]
            arrays.append(_parse_rows(span, match.group(1) != "vertices_coords"))
            parts += (text[pos:begin], json.dumps(f"{_SENTINEL}{len(arrays) - 1}"))
            pos = close.end()
        parts.append(text[pos:])
        with np.errstate(all="ignore"):
            doc = json.loads("".join(parts))
        found = 0
        for frame in [doc, *(doc.get("file_frames") or [])]:
            for key in _NUMERIC_KEYS:
                v = frame.get(key) if isinstance(frame, dict) else None
                if isinstance(v, str) and v.startswith(_SENTINEL):
                    frame[key] = arrays[int(v[len(_SENTINEL) :])]
                    found += 1
        if found != len(arrays):
            raise ValueError("an array outside the frames")
        return doc
    except (ValueError, TypeError, UnicodeError, AttributeError, DeprecationWarning):
        return json.loads(text)


def _rows_array(value, width: int, name: str, dtype) -> np.ndarray:
    """(n, width) array of a :class:`_Rows` or a list of lists (longer rows cut)."""
    if isinstance(value, _Rows):
        if len(value.sizes) and (value.sizes == value.sizes[0]).all():
            a = value.flat.reshape(len(value.sizes), int(value.sizes[0]))
        else:
            a = np.array(
                np.split(value.flat, np.cumsum(value.sizes)[:-1]) if len(value.sizes) else [],
                dtype=dtype,
            )
    else:
        a = np.array(value if value is not None else [], dtype=dtype)
    if a.size == 0:
        a = a.reshape(0, width)
    if a.ndim != 2 or a.shape[1] < width:
        raise ValueError(f"{name} must be a list of {width}D rows, got shape {a.shape}")
    return np.ascontiguousarray(a[:, :width], dtype=dtype)


def _read(fold_file: Path) -> dict:
    """The FOLD document's arrays: 2D and 3D points, edges, assignments, angles, faces."""
    doc = _load_document(fold_file.read_text())
    if not isinstance(doc, dict):
        raise ValueError(f"{fold_file}: not a FOLD document (a JSON object)")
    frames = doc.get("file_frames") or []
    folded = None
    for fr in frames:
        if not isinstance(fr, dict):
            continue
        if "foldedForm" in (fr.get("frame_classes") or []) or "3D" in (
            fr.get("frame_attributes") or []
        ):
            folded = fr
            break
    if folded is None or "vertices_coords" not in folded:
        raise ValueError(f"{fold_file}: no folded-form frame (3D vertices_coords) in file_frames")
    v2 = _rows_array(doc.get("vertices_coords"), 2, "vertices_coords", np.float64)
    v3 = _rows_array(folded["vertices_coords"], 3, "file_frames[].vertices_coords", np.float64)
    edges = _rows_array(doc.get("edges_vertices"), 2, "edges_vertices", np.int64)
    m = len(edges)
    assign = np.array(doc.get("edges_assignment") or ["U"] * m, dtype="<U1")
    angle_src = folded.get("edges_foldAngle", doc.get("edges_foldAngle"))
    angle = (
        np.array(angle_src, dtype=np.float64) if angle_src is not None else np.full(m, np.nan)
    )  # None (null) becomes NaN
    fv = doc.get("faces_vertices") or []
    if isinstance(fv, _Rows):
        sizes, flat = fv.sizes.astype(np.int64), fv.flat
    else:
        sizes = np.fromiter(map(len, fv), np.int64, len(fv))
        flat = np.fromiter(itertools.chain.from_iterable(fv), np.int64, int(sizes.sum()))
    patch = doc.get("filletfold:faces_patch")
    arc_step = None
    for key in ("filletfold:arc_step", "filletfold:parameters"):
        v = doc.get(key)
        if isinstance(v, dict):
            v = v.get("arc_step")
        if isinstance(v, int | float) and not isinstance(v, bool):
            arc_step = float(v)
            break
    half = doc.get("filletfold:mesh_edges_halfAngle")
    mesh_faces = doc.get("filletfold:mesh_faces_vertices")
    return {
        "half_angles": half if isinstance(half, list) else None,
        "mesh_faces": mesh_faces if isinstance(mesh_faces, list) else None,
        "v2": v2,
        "v3": v3,
        "edges": edges,
        "assign": assign,
        "angle": angle,
        "sizes": sizes,
        "flat": flat,
        "patch": patch if isinstance(patch, list) and len(patch) == len(sizes) else None,
        "arc_step": arc_step,
    }


def _report_beside(fold_file: Path) -> dict | None:
    p = fold_file.parent / "report.json"
    if not p.is_file():
        return None
    try:
        r = json.loads(p.read_text())
    except (OSError, ValueError, RecursionError):
        return None
    return r if isinstance(r, dict) else None


def _closed_by_edge_count(faces, vertices=None) -> bool:
    """Whether the polygons are a closed surface: every edge used by exactly two faces (no
    border, and no edge of three or more faces, where the surface is not one closed sheet: the
    watertight test of trimesh), counting edges between vertices welded where their coordinates
    are equal (as STL soups store them) when ``vertices`` are given; sides whose ends coincide
    are left out."""
    sizes = np.fromiter(map(len, faces), np.int64, len(faces))
    if len(sizes) == 0:
        return False
    flat = np.fromiter(itertools.chain.from_iterable(faces), np.int64, int(sizes.sum()))
    if vertices is not None:
        _, weld = np.unique(np.asarray(vertices, dtype=np.float64), axis=0, return_inverse=True)
        flat = weld.ravel()[flat]
    start = run_starts(sizes)
    nxt = np.arange(len(flat)) + 1
    nxt[start[1:] - 1] = start[:-1]
    a, b = flat, flat[nxt]
    keep = a != b
    a, b = a[keep], b[keep]
    key = np.minimum(a, b) * (int(flat.max()) + 1) + np.maximum(a, b)
    _, counts = np.unique(key, return_counts=True)
    return bool(len(counts)) and bool((counts == 2).all())


def _crease_limit(report: dict | None, half_angles: list | None = None) -> float:
    """:data:`CREASE_LIMIT_DEG`, or the mesh's sharpest dihedral (twice the largest half
    angle of an edge: ``filletfold:mesh_edges_halfAngle`` of the FOLD, else the ``half_angle``
    of the edges in ``report.json``) where that is sharper."""
    sharpest = 0.0
    if half_angles is None:
        edges = (report or {}).get("edges") or []
        half_angles = [e.get("half_angle") if isinstance(e, dict) else None for e in edges]
    for half in half_angles:
        if isinstance(half, int | float) and math.isfinite(half):
            sharpest = max(sharpest, math.degrees(2.0 * abs(half)))
    return max(CREASE_LIMIT_DEG, sharpest)


def _mesh_closed(
    mesh_path, report: dict | None, mesh_faces: list | None = None
) -> tuple[bool | None, str]:
    """Whether the input mesh is closed, and where that was learnt: a mesh file is read as
    it is (:func:`filletfold.mesh.read_mesh`, edges counted), a built-in example's name loaded
    with :func:`filletfold.mesh.load_mesh`; without a mesh, the cleaned mesh the FOLD
    (``filletfold:mesh_faces_vertices``) or ``report.json`` records."""
    if mesh_path is not None:
        from ..mesh import load_mesh, read_mesh

        if Path(mesh_path).exists():
            vertices, faces = read_mesh(mesh_path)
            return _closed_by_edge_count(faces, vertices), "mesh file (edge count)"
        mesh, _ = load_mesh(str(mesh_path))  # a built-in example (or an error naming it)
        closed = mesh.is_closed  # a property of PolyMesh
        return bool(closed() if callable(closed) else closed), "built-in mesh"
    if mesh_faces:
        return _closed_by_edge_count(mesh_faces), "design.fold mesh (edge count)"
    mesh = (report or {}).get("mesh")
    if isinstance(mesh, dict) and isinstance(mesh.get("faces"), list) and mesh["faces"]:
        return _closed_by_edge_count(mesh["faces"]), "report.json mesh (edge count)"
    return None, "unknown"


# --------------------------------------------------------------------------------------------
# measuring


def _cross2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _norm(x: np.ndarray) -> np.ndarray:
    """Euclidean norms along the last axis (faster than ``np.linalg.norm``)."""
    return np.sqrt(np.einsum("...i,...i->...", x, x))


def _cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (n, 3) arrays (``np.cross`` is several times slower)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    ax, ay, az = a[:, 0], a[:, 1], a[:, 2]
    bx, by, bz = b[:, 0], b[:, 1], b[:, 2]
    out[:, 0] = ay * bz - az * by
    out[:, 1] = az * bx - ax * bz
    out[:, 2] = ax * by - ay * bx
    return out


class _Namer:
    """Names of edges and faces for failure lines: ``edge 12 (F, cone 3|cylinder 7)``."""

    def __init__(self, assign, patch, h1, h2, he_face):
        self.assign, self.patch = assign, patch
        self.h1, self.h2, self.he_face = h1, h2, he_face

    def face_patch(self, f: int) -> str:
        return str(self.patch[f]) if self.patch is not None and f >= 0 else ""

    def edge_patches(self, e: int) -> list[str]:
        out = []
        for h in (self.h1[e], self.h2[e]):
            if h >= 0 and self.patch is not None:
                out.append(str(self.patch[self.he_face[h]]))
        return out

    def edge(self, e: int) -> str:
        e = int(e)
        parts = [str(self.assign[e])]
        names = self.edge_patches(e)
        if names:
            parts.append("|".join(names))
        return f"edge {e} ({', '.join(parts)})"

    def edge_info(self, e: int) -> dict:
        e = int(e)
        return {"edge": e, "assignment": str(self.assign[e]), "patches": self.edge_patches(e)}

    def face(self, f: int) -> str:
        f = int(f)
        p = self.face_patch(f)
        return f"face {f} ({p})" if p else f"face {f}"

    def face_info(self, f: int) -> dict:
        f = int(f)
        return {"face": f, "patch": self.face_patch(f)}


def _worst(values: np.ndarray, mask: np.ndarray | None = None) -> int:
    """Index of the largest finite value (under ``mask``), or -1."""
    v = np.where(np.isfinite(values), values, -np.inf)
    if mask is not None:
        v = np.where(mask, v, -np.inf)
    if v.size == 0 or not np.isfinite(v.max()):
        return -1
    return int(np.argmax(v))


def _lines(failures: list, bad: np.ndarray, score: np.ndarray, line, what: str) -> int:
    """Append a line for each of the worst ``MAX_LINES`` elements of ``bad`` (by ``score``,
    largest first) and a count of the others; return how many are bad."""
    idx = np.nonzero(bad)[0]
    if len(idx) == 0:
        return 0
    s = np.where(np.isfinite(score[idx]), score[idx], np.inf)
    idx = idx[np.argsort(-s, kind="stable")]
    for i in idx[:MAX_LINES].tolist():
        failures.append(line(i))
    if len(idx) > MAX_LINES:
        failures.append(f"... and {len(idx) - MAX_LINES} more {what}")
    return len(idx)


def _first(failures: list, idx: np.ndarray, line, what: str) -> None:
    """A line for each of the first ``MAX_LINES`` elements ``idx``, and a count of the rest."""
    for i in idx[:MAX_LINES].tolist():
        failures.append(line(i))
    if len(idx) > MAX_LINES:
        failures.append(f"... and {len(idx) - MAX_LINES} more {what}")


def _pct(x: float) -> str:
    return f"{100 * x:.3g}%"


def recheck_fold(fold_path, mesh_path=None, *, arc_step_deg: float | None = None) -> dict:
    """Re-check a design from its FOLD file (and the input mesh) alone.

    Parameters
    ----------
    fold_path : str or os.PathLike
        A design folder (its ``design.fold`` is read) or a ``.fold`` file.
    mesh_path : str or os.PathLike, optional
        The input mesh (a file or a built-in example name), read with
        :func:`filletfold.mesh.load_mesh`: when it is closed, the folded form must have no
        border. Without it, the cleaned mesh that ``report.json`` beside the FOLD records is
        used when present (closure by edge counting), else closure is not required.
    arc_step_deg : float, optional
        The largest facet fold (degrees); default: ``parameters.arc_step`` of ``report.json``
        beside the FOLD, else a ``filletfold:arc_step`` key of the FOLD, else
        :data:`DEFAULT_ARC_STEP_DEG` (also when the design's step is 0, "no limit").

    Returns
    -------
    dict
        ``ok``, ``failures`` (one line per bad element, the worst first, at most
        :data:`MAX_LINES` per check and a count of the rest), ``warnings`` (slivers, B edges
        with two faces), ``limits``, ``counts``, the figures ``worst_edge_mismatch``,
        ``worst_stretch``, ``worst_facet_fold_deg``, ``worst_crease_deg``,
        ``worst_angle_match_deg``, ``worst_facet_angle_match_deg``, ``worst_face_isometry``,
        ``worst_planarity``, ``smallest_face_angle_deg``, ``sliver_faces``, ``short_edges``,
        ``mv_sign_errors``, ``boundary_edges``, ``boundary_loops`` (pieces of the border),
        ``boundary_length`` (its length / size), ``open_boundary_length`` (the same when the
        mesh is closed, else 0), ``mesh_closed``, each ``worst_*`` with a ``*_at`` dict naming
        the element (edge index, assignment, patches of its faces, or face index and patch), and
        ``seconds`` (wall time by stage, ``total``, and ``cpu``).

    Raises
    ------
    OSError, ValueError, KeyError
        When the file cannot be read or is not a FOLD document with a folded form.
    filletfold.errors.MeshError
        When ``mesh_path`` cannot be read.
    """
    t0, c0 = time.perf_counter(), time.process_time()
    fold_file = _fold_file(fold_path)
    d = _read(fold_file)
    seconds = {"read": time.perf_counter() - t0}
    t_mark = [time.perf_counter()]

    def tick(name: str) -> None:
        now = time.perf_counter()
        seconds[name] = now - t_mark[0]
        t_mark[0] = now

    report = _report_beside(fold_file)

    # the arc step
    source = "argument"
    step = arc_step_deg
    if step is None:
        rstep = ((report or {}).get("parameters") or {}).get("arc_step")
        if isinstance(rstep, int | float) and not isinstance(rstep, bool) and rstep >= 0:
            step, source = float(rstep), "report.json parameters.arc_step"
        elif d["arc_step"] is not None and d["arc_step"] > 0:
            step, source = d["arc_step"], "design.fold"
        else:
            step, source = DEFAULT_ARC_STEP_DEG, "default"
    step = float(step)
    # a side across a bent facet spans at most two facets' turns; a step of 0 is no limit
    share = chord_share(min(EDGE_TURNS * step, 180.0) if step > 0 else 180.0)
    crease_limit = _crease_limit(report, d["half_angles"])
    tick("report")

    v2, v3, edges, assign, angle = d["v2"], d["v3"], d["edges"], d["assign"], d["angle"]
    sizes, flat, patch = d["sizes"], d["flat"], d["patch"]
    n, m, nf = len(v2), len(edges), len(sizes)
    failures: list[str] = []
    warns: list[str] = []
    out: dict = {"fold": str(fold_file)}

    # ---- structure ---------------------------------------------------------------------------
    if len(v3) != n:
        raise ValueError(f"{fold_file}: {n} pattern vertices but {len(v3)} folded ones")
    if len(assign) != m or len(angle) != m:
        raise ValueError(f"{fold_file}: edges_assignment/edges_foldAngle do not match the edges")
    if (edges < 0).any() or (edges >= n).any() or (flat < 0).any() or (flat >= n).any():
        raise ValueError(f"{fold_file}: a vertex index out of range")
    if (sizes < 3).any():
        f = int(np.nonzero(sizes < 3)[0][0])
        raise ValueError(f"{fold_file}: face {f} has {int(sizes[f])} corners")
    if not (np.isfinite(v2).all() and np.isfinite(v3).all()):
        raise ValueError(f"{fold_file}: a coordinate is not finite")

    size = float(np.linalg.norm(v3.max(axis=0) - v3.min(axis=0))) if n else 0.0
    coord_max = float(max(np.abs(v2).max(initial=0.0), np.abs(v3).max(initial=0.0)))
    q = 4 * 10.0 ** (1 - FILE_DIGITS) * coord_max  # file rounding of one length

    start = run_starts(sizes)
    nh = len(flat)
    he_face = run_owners(sizes)
    pos = np.arange(nh)
    nxt = pos + 1
    nxt[start[1:] - 1] = start[:-1]
    prv = pos - 1
    prv[start[:-1]] = start[1:] - 1
    he_from, he_to = flat, flat[nxt]

    lo, hi = np.minimum(edges[:, 0], edges[:, 1]), np.maximum(edges[:, 0], edges[:, 1])
    ekey = lo * n + hi
    order = np.argsort(ekey, kind="stable")
    sk = ekey[order]
    _first(
        failures,
        np.nonzero(lo == hi)[0],
        lambda e: f"edge {e} joins vertex {int(lo[e])} to itself",
        "edges that are loops",
    )
    _first(
        failures,
        np.nonzero(sk[1:] == sk[:-1])[0],
        lambda i: f"edge {int(order[i + 1])} repeats edge {int(order[i])}",
        "repeated edges",
    )
    hkey = np.minimum(he_from, he_to) * n + np.maximum(he_from, he_to)
    idx = np.searchsorted(sk, hkey)
    idx_c = np.minimum(idx, max(m - 1, 0))
    found = (idx < m) & (sk[idx_c] == hkey) if m else np.zeros(nh, bool)
    he_edge = np.where(found, order[idx_c] if m else -1, -1)
    degenerate_side = he_from == he_to
    missing = ~found & ~degenerate_side
    _first(
        failures,
        np.nonzero(missing)[0],
        lambda h: f"face {int(he_face[h])}: side {int(he_from[h])}-{int(he_to[h])} is no edge",
        "face sides that are no pattern edge",
    )
    _first(
        failures,
        np.nonzero(degenerate_side)[0],
        lambda h: f"face {int(he_face[h])} repeats vertex {int(he_from[h])}",
        "repeated face corners",
    )

    hv = np.nonzero(he_edge >= 0)[0]
    count = np.bincount(he_edge[hv], minlength=m) if m else np.zeros(0, np.int64)
    o = hv[np.argsort(he_edge[hv], kind="stable")]
    off = run_starts(count)[:-1]
    h1 = np.full(m, -1, np.int64)
    h2 = np.full(m, -1, np.int64)
    h1[count >= 1] = o[off[count >= 1]]
    h2[count >= 2] = o[off[count >= 2] + 1]
    namer = _Namer(assign, patch, h1, h2, he_face)
    _first(
        failures,
        np.nonzero(count > 2)[0],
        lambda e: f"{namer.edge(e)} has {int(count[e])} faces",
        "edges of more than two faces",
    )
    _first(
        failures,
        np.nonzero(count == 0)[0],
        lambda e: f"{namer.edge(e)} is a side of no face",
        "edges of no face",
    )
    inner = count == 2
    same_way = inner & (he_from[np.maximum(h1, 0)] == he_from[np.maximum(h2, 0)])
    _lines(
        failures,
        same_way,
        np.zeros(m),
        lambda e: f"{namer.edge(e)}: both faces run it the same way (faces not oriented)",
        "edges run the same way by both faces",
    )
    is_m, is_v, is_f, is_b = (assign == "M"), (assign == "V"), (assign == "F"), (assign == "B")
    bad_assign = ~(is_m | is_v | is_f | is_b)
    _lines(
        failures,
        bad_assign,
        np.zeros(m),
        lambda e: f"{namer.edge(e)}: assignment {assign[e]!r} is none of M V F B",
        "edges with another assignment",
    )
    one_face = (count == 1) & (is_m | is_v | is_f)
    _lines(
        failures,
        one_face,
        np.zeros(m),
        lambda e: f"{namer.edge(e)} has one face (a fold on the border)",
        "folds on the border",
    )
    b_inner = inner & is_b
    if b_inner.any():
        warns.append(f"{int(b_inner.sum())} B edges have two faces")

    tick("structure")
    # ---- faces -------------------------------------------------------------------------------
    p3 = v3[flat]
    c3 = np.add.reduceat(p3, start[:-1], axis=0) / sizes[:, None] if nf else np.zeros((0, 3))
    a3 = p3 - c3[he_face]
    newell = np.add.reduceat(_cross3(a3, a3[nxt]), start[:-1], axis=0) if nf else np.zeros((0, 3))
    nlen = _norm(newell)
    area3 = nlen / 2
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = newell / nlen[:, None]
    p2 = v2[flat]
    c2 = np.add.reduceat(p2, start[:-1], axis=0) / sizes[:, None] if nf else np.zeros((0, 2))
    a2 = p2 - c2[he_face]
    area2 = np.add.reduceat(_cross2(a2, a2[nxt]), start[:-1]) / 2 if nf else np.zeros(0)
    side3 = _norm(v3[he_to] - v3[he_from])
    perim3 = np.add.reduceat(side3, start[:-1]) if nf else np.zeros(0)

    clockwise = area2 < 0
    _lines(
        failures,
        clockwise,
        -area2,
        lambda f: f"{namer.face(f)} is clockwise in 2D (area {area2[f]:.3g})",
        "clockwise faces",
    )

    # corner angles (2D) and slivers
    b2 = v2[flat[nxt]] - p2
    c2v = v2[flat[prv]] - p2
    corner = np.degrees(np.arctan2(_cross2(b2, c2v), np.einsum("ij,ij->i", b2, c2v))) % 360.0
    min_angle = np.minimum.reduceat(corner, start[:-1]) if nf else np.zeros(0)
    sliver = (min_angle < SLIVER_ANGLE_DEG) | (np.abs(area2) < SLIVER_AREA * size**2)
    out["smallest_face_angle_deg"] = float(min_angle.min()) if nf else None
    out["smallest_face_angle_at"] = namer.face_info(int(np.argmin(min_angle))) if nf else None
    out["sliver_faces"] = int(sliver.sum())
    if sliver.any():
        f = int(np.argmin(np.where(sliver, min_angle, np.inf)))
        warns.append(
            f"{int(sliver.sum())} sliver faces (a 2D corner < {SLIVER_ANGLE_DEG} deg or area < "
            f"{SLIVER_AREA:g} size^2); sharpest {namer.face(f)}: {min_angle[f]:.3g} deg, "
            f"area {abs(area2[f]) / size**2:.3g} size^2"
        )

    # isometry (all corner pairs) and planarity, face sizes grouped, in chunks
    iso = np.zeros(nf)
    iso_excess = np.zeros(nf)  # (mismatch - limit) of the face's worst pair, in units of limit
    diam3 = np.zeros(nf)
    for k in np.unique(sizes).tolist():
        fk = np.nonzero(sizes == k)[0]
        iu, ju = np.triu_indices(k, 1)
        chunk = max(1, 2_000_000 // len(iu))
        for s in range(0, len(fk), chunk):
            ff = fk[s : s + chunk]
            corners = flat[start[ff][:, None] + np.arange(k)]
            q2, q3 = v2[corners], v3[corners]
            d2 = _norm(q2[:, iu] - q2[:, ju])
            d3 = _norm(q3[:, iu] - q3[:, ju])
            with np.errstate(invalid="ignore", divide="ignore"):
                rel = np.abs(d3 - d2) / d2
                lim = share + LENGTH_SLACK + q / d2
                ex = rel / lim
            rel = np.where(np.isfinite(rel), rel, np.inf)
            ex = np.where(np.isfinite(ex), ex, np.inf)
            iso[ff] = rel.max(axis=1)
            iso_excess[ff] = ex.max(axis=1)
            diam3[ff] = d3.max(axis=1)
    wf = _worst(iso)
    out["worst_face_isometry"] = float(iso[wf]) if wf >= 0 else 0.0
    out["worst_face_isometry_at"] = namer.face_info(wf) if wf >= 0 else None
    _lines(
        failures,
        iso_excess > 1,
        iso_excess,
        lambda f: (
            f"{namer.face(f)} not isometric: corner distances differ by {_pct(iso[f])} in 3D "
            f"and 2D (> {_pct(share)} + round-off)"
        ),
        "faces not isometric",
    )
    # planarity: the corners' distances from the plane through the centroid with the Newell
    # normal (the least-squares plane of a planar polygon), over the face's diameter
    off_plane = np.abs(np.einsum("ij,ij->i", a3, unit[he_face]))
    with np.errstate(invalid="ignore", divide="ignore"):
        planar = np.maximum.reduceat(off_plane, start[:-1]) / diam3 if nf else np.zeros(0)
        planar_lim = LENGTH_SLACK + q / diam3
    planar = np.where(sizes > 3, np.where(np.isfinite(planar), planar, np.inf), 0.0)
    wp = _worst(planar)
    out["worst_planarity"] = float(planar[wp]) if wp >= 0 else 0.0
    out["worst_planarity_at"] = namer.face_info(wp) if wp >= 0 and planar[wp] > 0 else None
    _lines(
        failures,
        planar > planar_lim,
        planar,
        lambda f: (
            f"{namer.face(f)} not planar in 3D: a corner {planar[f]:.3g} of its diameter "
            f"off its best plane"
        ),
        "faces not planar",
    )

    tick("faces")
    # ---- edge lengths ------------------------------------------------------------------------
    len2 = _norm(v2[edges[:, 1]] - v2[edges[:, 0]])
    len3 = _norm(v3[edges[:, 1]] - v3[edges[:, 0]])
    with np.errstate(invalid="ignore", divide="ignore"):
        stretch = (len3 - len2) / len2
        rnd = LENGTH_SLACK + q / len2
    stretch = np.where(len2 > 0, stretch, np.where(len3 > 0, np.inf, 0.0))
    mismatch = np.abs(stretch)
    mis_lim = share + rnd
    we = _worst(mismatch)
    out["worst_edge_mismatch"] = float(mismatch[we]) if we >= 0 else 0.0
    out["worst_edge_mismatch_at"] = (
        {**namer.edge_info(we), "len2d": float(len2[we]), "len3d": float(len3[we])}
        if we >= 0
        else None
    )
    ws = _worst(stretch)
    out["worst_stretch"] = float(stretch[ws]) if ws >= 0 else 0.0
    out["worst_stretch_at"] = (
        {**namer.edge_info(ws), "len2d": float(len2[ws]), "len3d": float(len3[ws])}
        if ws >= 0
        else None
    )
    _lines(
        failures,
        stretch > rnd,
        stretch,
        lambda e: (
            f"{namer.edge(e)} stretched {_pct(stretch[e])} (3D {len3[e]:.6g} > 2D {len2[e]:.6g})"
        ),
        "stretched edges",
    )
    _lines(
        failures,
        (mismatch > mis_lim) & ~(stretch > rnd),
        mismatch,
        lambda e: (
            f"{namer.edge(e)} length differs by {_pct(mismatch[e])} (3D {len3[e]:.6g}, "
            f"2D {len2[e]:.6g}; limit {_pct(share)} at arc step {step:g} deg)"
        ),
        "edges with a length mismatch",
    )
    shortest = np.minimum(len2, len3)
    short = shortest < SHORT_EDGE * size
    out["short_edges"] = int(short.sum())
    _lines(
        failures,
        short,
        -shortest,
        lambda e: f"{namer.edge(e)} is short: {shortest[e] / size:.3g} of the size",
        "short edges",
    )

    tick("lengths")
    # ---- dihedrals ---------------------------------------------------------------------------
    ei = np.nonzero(inner)[0]
    ha, hb = h1[ei], h2[ei]
    fa, fb = he_face[ha], he_face[hb]
    na, nb = unit[fa], unit[fb]
    dvec = v3[he_to[ha]] - v3[he_from[ha]]
    with np.errstate(invalid="ignore", divide="ignore"):
        dvec = dvec / _norm(dvec)[:, None]
    sin = np.einsum("ij,ij->i", _cross3(na, nb), dvec)
    cos = np.einsum("ij,ij->i", na, nb)
    fold = np.full(m, np.nan)
    fold[ei] = -np.degrees(np.arctan2(sin, cos))
    with np.errstate(invalid="ignore", divide="ignore"):
        rnd_ang = np.full(m, np.inf)
        rnd_ang[ei] = ANGLE_SLACK_DEG + np.degrees(
            math.sqrt(3) * q * (perim3[fa] / area3[fa] + perim3[fb] / area3[fb])
        )
    rnd_ang = np.where(np.isfinite(rnd_ang), rnd_ang, np.inf)
    undefined = inner & ~np.isfinite(fold)
    _lines(
        failures,
        undefined,
        np.zeros(m),
        lambda e: f"{namer.edge(e)}: no fold angle (a face of zero 3D area)",
        "edges without a fold angle",
    )
    absfold = np.abs(fold)

    is_f_inner = inner & is_f
    wff = _worst(absfold, is_f_inner)
    out["worst_facet_fold_deg"] = float(absfold[wff]) if wff >= 0 else 0.0
    out["worst_facet_fold_at"] = namer.edge_info(wff) if wff >= 0 else None
    facet_lim = (step if step > 0 else 180.0) + rnd_ang  # rnd_ang holds the 1e-6 deg slack
    _lines(
        failures,
        is_f_inner & (absfold > facet_lim),
        absfold,
        lambda e: f"{namer.edge(e)} folded {fold[e]:.4g}° > arc step {step:g}°",
        "facet edges folded more than the arc step",
    )
    # written F angles: the folded dihedral (FOLD's edges_foldAngle on F edges)
    f_written = is_f_inner & np.isfinite(angle)
    fdiff = np.where(f_written, np.abs(fold - angle), 0.0)
    wfd = _worst(fdiff, f_written)
    out["worst_facet_angle_match_deg"] = float(fdiff[wfd]) if wfd >= 0 else 0.0
    _lines(
        failures,
        f_written & (fdiff > rnd_ang + 0.5e-9),  # F angles are written to 9 decimals
        fdiff,
        lambda e: f"{namer.edge(e)}: written angle {angle[e]:.9g}° but folded {fold[e]:.9g}°",
        "facet edges whose written angle is not the folded one",
    )

    mv = inner & (is_m | is_v)
    sgn = np.where(assign == "V", 1.0, -1.0)
    wrong = mv & ~((fold * sgn > 0) & (np.nan_to_num(angle) * sgn > 0))
    out["mv_sign_errors"] = int(wrong.sum())
    _lines(
        failures,
        wrong,
        absfold,
        lambda e: (
            f"{namer.edge(e)} folds the wrong way: written {angle[e]:.6g}°, folded "
            f"{fold[e]:.6g}° (valley positive)"
        ),
        "creases folding the wrong way",
    )
    diff = np.where(mv, np.abs(fold - angle), 0.0)
    diff = np.where(np.isfinite(diff), diff, np.inf)
    wm = _worst(diff, mv)
    out["worst_angle_match_deg"] = float(diff[wm]) if wm >= 0 else 0.0
    out["worst_angle_match_at"] = namer.edge_info(wm) if wm >= 0 else None
    _lines(
        failures,
        mv & ~wrong & (diff > rnd_ang),
        diff,
        lambda e: (
            f"{namer.edge(e)}: written angle {angle[e]:.9g}° but folded {fold[e]:.9g}° "
            f"(off by {diff[e]:.3g}°)"
        ),
        "creases whose written angle is not the folded one",
    )
    crease = np.where(mv, np.maximum(absfold, np.abs(np.nan_to_num(angle))), 0.0)
    wc = _worst(crease, mv)
    out["worst_crease_deg"] = float(crease[wc]) if wc >= 0 else 0.0
    out["worst_crease_at"] = namer.edge_info(wc) if wc >= 0 else None
    _lines(
        failures,
        mv & (crease > crease_limit + rnd_ang),  # an edge left sharp folds by its dihedral
        crease,
        lambda e: f"{namer.edge(e)} folds {crease[e]:.4g}° > {crease_limit:.6g}° (flat)",
        "creases folded flat",
    )

    tick("dihedrals")
    # ---- closure -----------------------------------------------------------------------------
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    tol = WELD * size
    pairs = (
        cKDTree(v3).query_pairs(tol, output_type="ndarray") if n and tol > 0 else np.zeros((0, 2))
    )
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    n_welded, label = connected_components(graph, directed=False)
    wa, wb = label[he_from], label[he_to]
    keep = wa != wb
    wkey = np.minimum(wa, wb).astype(np.int64) * n_welded + np.maximum(wa, wb)
    _, inv, wcount = np.unique(wkey[keep], return_inverse=True, return_counts=True)
    hk = np.nonzero(keep)[0]
    border_h = hk[wcount[inv.ravel()] == 1]
    border_len = side3[border_h]
    out["welded_points"] = int(n_welded)
    out["boundary_edges"] = len(border_h)
    # the border's pieces: its edges joined where they share a welded point
    bu, bv = wa[border_h], wb[border_h]
    pts, bi = np.unique(np.concatenate([bu, bv]), return_inverse=True)
    bi = bi.ravel()
    k = len(border_h)
    out["boundary_loops"] = (
        int(
            connected_components(
                coo_matrix((np.ones(k), (bi[:k], bi[k:])), shape=(len(pts), len(pts))),
                directed=False,
            )[0]
        )
        if k
        else 0
    )
    out["boundary_length"] = float(border_len.sum() / size) if size else 0.0
    out["folded_nonmanifold_edges"] = int((wcount > 2).sum())
    closed, closed_src = _mesh_closed(mesh_path, report, d["mesh_faces"])
    out["mesh_closed"] = closed
    out["mesh_closed_source"] = closed_src
    out["open_boundary_length"] = out["boundary_length"] if closed else 0.0
    if closed and len(border_h):
        i = int(np.argmax(border_len))
        h = int(border_h[i])
        e = int(he_edge[h])
        where = namer.edge(e) if e >= 0 else f"side of {namer.face(int(he_face[h]))}"
        failures.append(
            f"folded form open though the mesh is closed: {len(border_h)} border edges in "
            f"{out['boundary_loops']} pieces, "
            f"length {out['boundary_length']:.3g} of the size; longest {where}, "
            f"{border_len[i] / size:.3g} of the size"
        )

    tick("closure")
    # ---- summary -----------------------------------------------------------------------------
    counts = {k: int((assign == k).sum()) for k in ("M", "V", "F", "B")}
    out_head = {
        "ok": not failures,
        "failures": failures,
        "warnings": warns,
        "counts": {"vertices": n, "edges": m, "faces": nf, "assignment": counts},
        "size": size,
        "arc_step_deg": step,
        "arc_step_source": source,
        "limits": {
            "facet_fold_deg": step,
            "facet_fold_slack_deg": "1e-6 + sqrt(3) q (P_a/A_a + P_b/A_b) rad",
            "edge_mismatch": share,
            "edge_mismatch_slack": "1e-9 + q / len2D",
            "stretch": LENGTH_SLACK,
            "stretch_slack": "q / len2D",
            "crease_deg": crease_limit,
            "angle_match_deg": ANGLE_SLACK_DEG,
            "planarity": LENGTH_SLACK,
            "sliver_angle_deg": SLIVER_ANGLE_DEG,
            "sliver_area": SLIVER_AREA,
            "short_edge": SHORT_EDGE,
            "weld": WELD,
            "q": q,
            "q_rule": f"4 * 10^(1 - {FILE_DIGITS}) * max|coordinate|",
        },
    }
    out_head.update(out)
    seconds["total"] = time.perf_counter() - t0
    seconds["cpu"] = time.process_time() - c0
    out_head["seconds"] = seconds
    return out_head


# --------------------------------------------------------------------------------------------
# command line


def main(argv: list[str] | None = None) -> int:
    """``python -m filletfold.testing.recheck DIR_OR_FOLD [MESH] [--arc-step DEG]``: print the
    summary as JSON; exit 0 when the design passes, 1 when it fails, 2 when unreadable."""
    import argparse

    from ..errors import FilletfoldError

    parser = argparse.ArgumentParser(
        prog="python -m filletfold.testing.recheck",
        description="Re-check a filletfold design from design.fold (and the input mesh) alone.",
    )
    parser.add_argument("fold", help="a design folder or a .fold file")
    parser.add_argument("mesh", nargs="?", default=None, help="the input mesh (closure check)")
    parser.add_argument("--arc-step", type=float, default=None, help="facet fold limit (deg)")
    args = parser.parse_args(argv)
    try:
        result = recheck_fold(args.fold, args.mesh, arc_step_deg=args.arc_step)
    except (OSError, ValueError, KeyError, TypeError, FilletfoldError) as exc:
        print(json.dumps({"ok": False, "error": f"{type(exc).__name__}: {exc}"}))
        return 2
    print(json.dumps(result, indent=2, ensure_ascii=False))
    return 0 if result["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
