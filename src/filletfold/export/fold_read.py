"""Reading back a design written by :func:`~filletfold.export.fold.fold_document`.

:func:`read_fold` rebuilds the :class:`~filletfold.surface.pattern.CreasePattern` of a
``design.fold``: the key frame's 2D ``vertices_coords``, ``faces_vertices``, ``edges_vertices``,
``edges_assignment`` and ``edges_foldAngle`` (kept as written, not derived again),
``filletfold:faces_patch``, ``filletfold:faces_piece``, ``filletfold:pieces_vertex`` and, from the
folded frame, the 3D ``vertices_coords``. The annotations (tabs, labels, sheets) come from
the ``annotations.json`` beside it (:data:`~filletfold.export.fold.ANNOTATIONS_FILE`), or,
in files written before that file, from their ``filletfold:annotations`` key (the labels as
parallel lists, or as a list of records in older files still).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from ..errors import ExportError, MeshReadError
from ..surface.patch import as_patch
from ..surface.pattern import Annotations, CreasePattern, Label, LabelRows
from ..surface.validate import validate_pattern
from .fold import ANNOTATIONS_FILE, NAMESPACE, design_counts

__all__ = ["pattern_from_fold", "read_annotations", "read_fold"]

_REQUIRED = (
    "vertices_coords",
    "faces_vertices",
    "edges_vertices",
    "edges_assignment",
    "edges_foldAngle",
    NAMESPACE + "faces_patch",
    NAMESPACE + "faces_piece",
)


def read_fold(path) -> CreasePattern:
    """Read a filletfold ``design.fold`` back into a crease pattern
    (:func:`read_fold_document` without the document).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    CreasePattern
        With the file's edges, assignments and fold angles, and its annotations (empty when the
        file has none).

    Raises
    ------
    MeshReadError
        When the file is missing or unreadable, is not JSON, or is not a filletfold FOLD file
        (a required key or the folded frame is missing, or the data is inconsistent); the
        message names the file and the problem.
    """
    return read_fold_document(path)[0]


def read_fold_document(path) -> tuple[CreasePattern, dict]:
    """:func:`read_fold`, and the parsed document (for its other keys, such as the mesh's
    ``filletfold:mesh_*`` that ``filletfold check`` reads)."""
    path = Path(os.fspath(path))
    doc = load_json(path, "a FOLD file")
    try:
        pattern = pattern_from_fold(doc)
    except MeshReadError as exc:
        raise MeshReadError(f"{path}: {exc}") from None
    if NAMESPACE + "annotations" not in doc:
        pattern.annotations = read_annotations(path.with_name(ANNOTATIONS_FILE), pattern)
    return pattern, doc


def read_annotations(path, pattern: CreasePattern) -> Annotations:
    """The annotations in ``path`` (an ``annotations.json``) of ``pattern``, read from the
    ``design.fold`` beside it; none when there is no such file.

    Parameters
    ----------
    path : str or os.PathLike
    pattern : CreasePattern

    Returns
    -------
    Annotations

    Raises
    ------
    MeshReadError
        When the file is unreadable or malformed, or was written for another design (its
        ``"design"`` counts are not those of ``pattern``).
    """
    path = Path(os.fspath(path))
    if not path.exists():
        return Annotations()
    doc = load_json(path, "an annotations file")
    if not isinstance(doc, dict):
        raise MeshReadError(f"{path}: not an annotations file (not a JSON object)")
    expected = design_counts(pattern)
    if doc.get("design") != expected:
        raise MeshReadError(
            f"{path}: written for another design ({doc.get('design')!r}; design.fold has "
            f"{expected['vertices']} vertices, {expected['faces']} faces and "
            f"{expected['pieces']} pieces)"
        )
    return _annotations(doc, str(path))


def load_json(path: Path, what: str):
    """The parsed JSON text of ``path``; a :class:`MeshReadError` naming the file when it is
    missing, a folder, unreadable or not JSON (``what`` it should be: ``"a FOLD file"``)."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MeshReadError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise MeshReadError(f"{path}: is a folder, not {what}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MeshReadError(f"{path}: cannot read: {exc}") from exc
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise MeshReadError(f"{path}: not {what} (invalid JSON: {exc.msg})") from None
    except RecursionError:
        raise MeshReadError(f"{path}: not {what} (JSON nested too deeply)") from None


def pattern_from_fold(doc: dict) -> CreasePattern:
    """The crease pattern of a parsed filletfold FOLD document (see :func:`read_fold`).

    Parameters
    ----------
    doc : dict

    Returns
    -------
    CreasePattern

    Raises
    ------
    MeshReadError
        When the document is not a filletfold FOLD document.
    """
    if not isinstance(doc, dict):
        raise MeshReadError(f"not a FOLD file (top level is a {type(doc).__name__}, not an object)")
    missing = [k for k in _REQUIRED if k not in doc]
    if missing:
        raise MeshReadError(
            f"not a filletfold FOLD file: missing key(s) {', '.join(missing)} "
            "(write it with 'filletfold round')"
        )
    frame = _folded_frame(doc)
    try:
        v2 = np.asarray(doc["vertices_coords"], dtype=np.float64)
        v3 = np.asarray(frame["vertices_coords"], dtype=np.float64)
        faces = [np.asarray(f, dtype=np.int64) for f in doc["faces_vertices"]]
        edges = np.asarray(doc["edges_vertices"], dtype=np.int64).reshape(-1, 2)
        assign = np.asarray([str(a) for a in doc["edges_assignment"]], dtype="<U1")
        angle = np.asarray(doc["edges_foldAngle"], dtype=np.float64).reshape(-1)
        if len(angle) == len(assign):  # borders are null and facets bent in the file: 0 here
            angle = np.where((assign == "B") | (assign == "F"), 0.0, angle)
        face_piece = np.asarray(doc[NAMESPACE + "faces_piece"], dtype=np.int64).reshape(-1)
        names = {str(p) for p in doc[NAMESPACE + "faces_patch"]}
        read = {name: as_patch(name) for name in names}  # each distinct name parsed once
        patches = [read[str(p)] for p in doc[NAMESPACE + "faces_patch"]]
    except (TypeError, ValueError) as exc:
        raise MeshReadError(f"not a filletfold FOLD file: malformed arrays ({exc})") from None
    if v2.ndim != 2 or v2.shape[1] != 2:
        raise MeshReadError(f"key frame vertices_coords must be 2D points, got shape {v2.shape}")
    if v3.ndim != 2 or v3.shape[1] != 3:
        raise MeshReadError(f"folded frame vertices_coords must be 3D points, got shape {v3.shape}")
    n_pieces = int(face_piece.max()) + 1 if len(face_piece) else 0
    pv = doc.get(NAMESPACE + "pieces_vertex")
    piece_vertex = np.full(n_pieces, -1, dtype=np.int64) if pv is None else np.asarray(pv)
    pattern = CreasePattern(
        v2,
        v3,
        faces,
        patches,
        face_piece,
        piece_vertex,
        edges=edges,
        edge_assignment=assign,
        edge_fold_angle=angle,
        edge_faces=None,
        annotations=_annotations(doc.get(NAMESPACE + "annotations")),
    )
    try:
        validate_pattern(pattern)
    except ExportError as exc:
        raise MeshReadError(f"not a valid filletfold design: {exc}") from None
    pattern.edge_faces = pattern.faces_beside_edges()  # found once, from its faces
    return pattern


def _folded_frame(doc: dict) -> dict:
    """The first frame of ``file_frames`` with 3D vertex coordinates (``foldedForm`` first)."""
    frames = doc.get("file_frames")
    if not isinstance(frames, list) or not frames:
        raise MeshReadError("not a filletfold FOLD file: no folded frame (file_frames is missing)")
    frames = [f for f in frames if isinstance(f, dict) and "vertices_coords" in f]
    frames.sort(key=lambda f: "foldedForm" not in (f.get("frame_classes") or []))
    if not frames:
        raise MeshReadError("not a filletfold FOLD file: no frame of file_frames has coordinates")
    return frames[0]


def _annotations(data, where: str = NAMESPACE + "annotations") -> Annotations:
    """Annotations from the ``filletfold:annotations`` value, or an ``annotations.json``
    (``where`` names it in the errors; ``None``: none)."""
    if data is None:
        return Annotations()
    if not isinstance(data, dict):
        raise MeshReadError(f"{where} must be an object")
    try:
        tabs = [np.asarray(t, dtype=np.float64).reshape(-1, 2) for t in data.get("tabs", [])]
        hinges = _hinges(data.get("tab_hinges", []), tabs)
        labels = _labels(data.get("labels", []))
        sheets = np.asarray(data.get("sheets", []), dtype=np.float64).reshape(-1, 4)
        seams = _seams(data.get("seams"))
        making = _making(data.get("making", []))
    except (TypeError, ValueError, KeyError, AttributeError) as exc:
        raise MeshReadError(f"{where} is malformed ({exc!r})") from None
    return Annotations(
        tabs=tabs, tab_hinges=hinges, labels=labels, sheets=sheets, seams=seams, making=making
    )


def _making(items) -> list:
    """The :class:`~filletfold.layout.making.MakingPath` list of an annotations file's
    ``"making"``."""
    from ..layout.making import MAKING_KINDS, MakingPath

    out = []
    for item in items:
        kind, patch = item["kind"], item["patch"]
        if kind not in MAKING_KINDS or not isinstance(patch, str):
            raise ValueError(f"making path of kind {kind!r}, patch {patch!r}")
        points = np.asarray(item["points"], dtype=np.float64).reshape(-1, 2)
        out.append(MakingPath(kind, patch, points, bool(item["closed"])))
    return out


def _seams(data):
    """The :class:`~filletfold.layout.tabs.Seams` of an annotations file's ``"seams"`` (None
    when it has none)."""
    if data is None:
        return None
    from ..layout.tabs import Seams

    names = [str(n) for n in data["pieces"]]
    joins = np.asarray(data["joins"], dtype=np.int64).reshape(-1, 2)
    tab_on = np.asarray(data["tab_on"], dtype=np.int64).reshape(-1)
    if len(tab_on) != len(joins):
        raise ValueError(f"{len(joins)} seams but {len(tab_on)} tab sides")
    if len(joins) and (joins.min() < 0 or joins.max() >= len(names)):
        raise ValueError("a seam joins a piece that is not named")
    if len(tab_on) and (tab_on.min() < -1 or tab_on.max() > 1):
        raise ValueError("a seam's tab side is not -1, 0 or 1")
    return Seams(names, joins, tab_on)


def _hinges(items, tabs: list) -> list[np.ndarray]:
    """The tab hinges of ``tab_hinges``: each item ``[i, j]``, two points of its tab's outline
    (by index), or ``[[x, y], [x, y]]`` (as files written before the indices)."""
    out = []
    for k, h in enumerate(items):
        if isinstance(h, list) and len(h) == 2 and all(type(i) is int for i in h):
            if k >= len(tabs) or not all(0 <= i < len(tabs[k]) for i in h):
                raise ValueError(f"tab hinge {k} names points {h} its tab does not have")
            out.append(tabs[k][h].copy())
        else:
            out.append(np.asarray(h, dtype=np.float64).reshape(2, 2))
    return out


def _labels(data) -> LabelRows | list[Label]:
    """The labels of ``filletfold:annotations``: parallel lists ``{"position": [[x, y], ...],
    "text": [...], "angle": [...], "height": [...], "kind": [...]}`` (``angle``, ``height`` and
    ``kind`` optional), or, as files written before those, a list of records ``{"position",
    "text", "angle", "height", "kind"}``."""
    if isinstance(data, dict):
        position = np.asarray(data["position"], dtype=np.float64)
        if position.size == 0:
            position = position.reshape(0, 2)
        if position.ndim != 2 or position.shape[1] != 2:
            raise ValueError(f"labels' positions must be [x, y] points, got shape {position.shape}")
        n = len(position)
        text = [str(t) for t in data["text"]]
        angle = [float(a) for a in data.get("angle", [0.0] * n)]
        height = [float(h) for h in data.get("height", [0.05] * n)]
        kind = [str(k) for k in data.get("kind", ["part"] * n)]
        sizes = {len(text), len(angle), len(height), len(kind)}
        if sizes != {n}:
            raise ValueError(f"labels' lists have lengths {sorted(sizes | {n})}, not one length")
        return LabelRows(position, text, angle, height, kind)
    return [
        Label(
            position=np.asarray(lb["position"], dtype=np.float64).reshape(2),
            text=str(lb["text"]),
            angle=float(lb.get("angle", 0.0)),
            height=float(lb.get("height", 0.05)),
            kind=str(lb.get("kind", "part")),
        )
        for lb in data
    ]
