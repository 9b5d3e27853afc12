"""FOLD 1.2 export of a crease pattern and its folded form.

The key frame (top level) is the flat crease pattern in 2D; ``file_frames[0]`` is the folded
form, inheriting everything from the key frame except its 3D ``vertices_coords``. Spec:
https://github.com/edemaine/fold/blob/main/doc/spec.md

Also home of :func:`validate_pattern`, the entry check every exporter runs on a
:class:`~filletfold.pattern.CreasePattern`.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping

import numpy as np

from ..errors import ExportError, ParameterError
from ..pattern import Annotations, CreasePattern
from ..tolerances import tol

__all__ = [
    "FOLD_SPEC",
    "NAMESPACE",
    "annotations_document",
    "face_signed_area_2d",
    "file_creator",
    "fold_document",
    "fold_json",
    "has_annotations",
    "validate_pattern",
]

#: FOLD specification version written to ``file_spec``.
FOLD_SPEC = 1.2
#: Prefix of filletfold's custom FOLD keys.
NAMESPACE = "filletfold:"
#: Edge assignments the exporters understand.
ASSIGNMENTS = ("M", "V", "B", "F")
#: Significant digits kept for floats in :func:`fold_json`.
FOLD_DIGITS = 12


def file_creator() -> str:
    """``"filletfold <version>"`` or ``"filletfold"`` when the package has no version."""
    import filletfold

    version = getattr(filletfold, "__version__", None)
    return f"filletfold {version}" if version else "filletfold"


def face_signed_area_2d(vertices_2d: np.ndarray, faces: list) -> np.ndarray:
    """Signed area of each face in the flat layout (shoelace formula).

    Parameters
    ----------
    vertices_2d : (n, 2) float
    faces : list of (k,) int

    Returns
    -------
    (n_faces,) float
        Positive for counter-clockwise faces.
    """
    if len(faces) == 0:
        return np.zeros(0)
    sizes = np.array([len(f) for f in faces], dtype=np.int64)
    start = np.concatenate([[0], np.cumsum(sizes)])
    a = np.concatenate([np.asarray(f, dtype=np.int64) for f in faces])
    nxt = np.arange(len(a)) + 1
    nxt[start[1:] - 1] = start[:-1]
    p, q = vertices_2d[a], vertices_2d[a[nxt]]
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
    return 0.5 * np.add.reduceat(cross, start[:-1])


def validate_pattern(pattern: CreasePattern) -> None:
    """Check that a crease pattern is complete and consistent enough to export.

    Checks: matching vertex counts in 2D and 3D, finite coordinates, faces of at least three
    in-range vertex indices, one patch name and one piece per face, edge arrays of one length,
    assignments among ``M V B F`` with fold angles of the matching sign (valley > 0, mountain < 0,
    zero for ``B``/``F``), and faces counter-clockwise in 2D.

    Parameters
    ----------
    pattern : CreasePattern

    Raises
    ------
    ExportError
        Naming the first offending element.
    """
    if not isinstance(pattern, CreasePattern):
        raise ExportError(f"expected a CreasePattern, got {type(pattern).__name__}")
    v2, v3 = pattern.vertices_2d, pattern.vertices_3d
    n = len(v2)
    if v2.ndim != 2 or v2.shape[1] != 2 or v3.ndim != 2 or v3.shape[1] != 3:
        raise ExportError("pattern vertices must be (n, 2) in 2D and (n, 3) in 3D")
    if len(v3) != n:
        raise ExportError(f"pattern has {n} vertices in 2D but {len(v3)} in 3D")
    for name, arr in (("vertices_2d", v2), ("vertices_3d", v3)):
        bad = np.flatnonzero(~np.isfinite(arr).all(axis=1))
        if len(bad):
            raise ExportError(f"pattern {name}[{bad[0]}] is not finite")
    n_faces = len(pattern.faces)
    for i, f in enumerate(pattern.faces):
        idx = np.asarray(f)
        if idx.ndim != 1 or len(idx) < 3 or not np.issubdtype(idx.dtype, np.integer):
            raise ExportError(f"pattern face {i} must list at least 3 integer vertex indices")
        if idx.min() < 0 or idx.max() >= n:
            raise ExportError(f"pattern face {i} refers to a vertex outside 0..{n - 1}")
    if len(pattern.face_patch) != n_faces:
        raise ExportError(
            f"pattern has {n_faces} faces but {len(pattern.face_patch)} face_patch names"
        )
    if not all(isinstance(p, str) for p in pattern.face_patch):
        raise ExportError("pattern face_patch entries must be strings")
    if pattern.face_piece.shape != (n_faces,):
        raise ExportError(
            f"pattern has {n_faces} faces but face_piece has shape {pattern.face_piece.shape}"
        )
    if pattern.edges is None or pattern.edge_assignment is None or pattern.edge_fold_angle is None:
        raise ExportError("pattern edges, edge_assignment and edge_fold_angle must all be set")
    edges = np.asarray(pattern.edges)
    assign = np.asarray(pattern.edge_assignment)
    angle = np.asarray(pattern.edge_fold_angle, dtype=np.float64)
    m = len(edges)
    if edges.shape != (m, 2) or assign.shape != (m,) or angle.shape != (m,):
        raise ExportError(
            f"pattern edge arrays disagree: edges {edges.shape}, edge_assignment "
            f"{assign.shape}, edge_fold_angle {angle.shape}"
        )
    if m and (edges.min() < 0 or edges.max() >= n):
        raise ExportError(f"pattern edges refer to a vertex outside 0..{n - 1}")
    unknown = np.flatnonzero(~np.isin(assign, ASSIGNMENTS))
    if len(unknown):
        e = int(unknown[0])
        raise ExportError(f"pattern edge {e} has assignment {str(assign[e])!r}, not one of M V B F")
    bad = np.flatnonzero(~np.isfinite(angle))
    if len(bad):
        raise ExportError(f"pattern edge_fold_angle[{bad[0]}] is not finite")
    wrong = ((assign == "V") & (angle < 0)) | ((assign == "M") & (angle > 0))
    wrong |= np.isin(assign, ("B", "F")) & (angle != 0)
    if wrong.any():
        e = int(np.flatnonzero(wrong)[0])
        raise ExportError(
            f"pattern edge {e} is {str(assign[e])!r} but its fold angle is {angle[e]:g} degrees "
            "(valley > 0, mountain < 0, border and flat 0)"
        )
    if n_faces:
        area = face_signed_area_2d(v2, pattern.faces)
        scale = float(np.ptp(v2, axis=0).max()) if n else 0.0
        cw = np.flatnonzero(area < -tol.area * max(scale, 1.0) ** 2)
        if len(cw):
            raise ExportError(f"pattern face {cw[0]} is clockwise in the flat layout")


def fold_document(
    pattern: CreasePattern,
    *,
    title: str = "",
    description: str = "",
    extra: Mapping | None = None,
) -> dict:
    """The FOLD 1.2 document of a crease pattern.

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`validate_pattern`.
    title, description : str
        ``file_title`` and ``file_description``.
    extra : mapping, optional
        More top-level keys, each namespaced ``"filletfold:..."``; values must be JSON data
        (numpy arrays and scalars are accepted by :func:`fold_json`).

    Returns
    -------
    dict
        Keys in a fixed order: file metadata, key-frame metadata, ``vertices_coords`` (n, 2),
        ``edges_vertices`` (m, 2), ``edges_assignment`` (m,), ``edges_foldAngle`` (m,) degrees
        (valley positive), ``faces_vertices`` (counter-clockwise), ``filletfold:faces_patch`` and
        ``filletfold:faces_piece`` (n_faces,), ``filletfold:pieces_vertex`` (n_pieces,),
        ``file_frames`` (the folded form: a child of the key frame with 3D ``vertices_coords``
        (n, 3)), ``filletfold:annotations`` when the pattern has any (see
        :func:`annotations_document`), then ``extra``.

    Raises
    ------
    ExportError
        When the pattern is inconsistent (see :func:`validate_pattern`).
    ParameterError
        When ``title``/``description`` are not strings or an ``extra`` key is not namespaced or
        clashes with a key of the document.
    """
    validate_pattern(pattern)
    for name, value in (("title", title), ("description", description)):
        if not isinstance(value, str):
            raise ParameterError(f"{name} must be a string, got {type(value).__name__}", name=name)
    doc = {
        "file_spec": FOLD_SPEC,
        "file_creator": file_creator(),
        "file_title": title,
        "file_description": description,
        "file_classes": ["singleModel"],
        "frame_classes": ["creasePattern"],
        "frame_attributes": ["2D"],
        "frame_unit": "unit",
        "vertices_coords": pattern.vertices_2d.tolist(),
        "edges_vertices": np.asarray(pattern.edges, dtype=np.int64).tolist(),
        "edges_assignment": [str(a) for a in pattern.edge_assignment],
        "edges_foldAngle": np.asarray(pattern.edge_fold_angle, dtype=np.float64).tolist(),
        "faces_vertices": [[int(v) for v in f] for f in pattern.faces],
        NAMESPACE + "faces_patch": [str(p) for p in pattern.face_patch],
        NAMESPACE + "faces_piece": pattern.face_piece.tolist(),
        NAMESPACE + "pieces_vertex": pattern.piece_vertex.tolist(),
        "file_frames": [
            {
                "frame_classes": ["foldedForm"],
                "frame_parent": 0,
                "frame_inherit": True,
                "frame_attributes": ["3D"],
                "vertices_coords": pattern.vertices_3d.tolist(),
            }
        ],
    }
    if has_annotations(pattern.annotations):
        doc[NAMESPACE + "annotations"] = annotations_document(pattern.annotations)
    for key, value in (extra or {}).items():
        if not isinstance(key, str) or not key.startswith(NAMESPACE) or key == NAMESPACE:
            raise ParameterError(
                f"extra FOLD key {key!r} must be namespaced as '{NAMESPACE}<name>'", name="extra"
            )
        if key in doc:
            raise ParameterError(
                f"extra FOLD key {key!r} clashes with a built-in key", name="extra"
            )
        doc[key] = value
    return doc


def has_annotations(annotations: Annotations) -> bool:
    """Whether there is any tab, hinge, label or sheet to write."""
    return bool(
        len(annotations.tabs)
        or len(annotations.tab_hinges)
        or len(annotations.labels)
        or len(np.asarray(annotations.sheets).reshape(-1))
    )


def annotations_document(annotations: Annotations) -> dict:
    """The JSON form of a pattern's annotations (the ``filletfold:annotations`` FOLD key).

    Parameters
    ----------
    annotations : Annotations

    Returns
    -------
    dict
        ``tabs``: list of tab outlines, each a list of ``[x, y]``; ``tab_hinges``: list of
        ``[[x, y], [x, y]]``; ``labels``: list of ``{"position": [x, y], "text", "angle"
        (degrees), "height", "kind"}``; ``sheets``: list of ``[xmin, ymin, xmax, ymax]``. All
        in pattern coordinates.
    """
    return {
        "tabs": [np.asarray(t, dtype=np.float64).reshape(-1, 2).tolist() for t in annotations.tabs],
        "tab_hinges": [
            np.asarray(h, dtype=np.float64).reshape(2, 2).tolist() for h in annotations.tab_hinges
        ],
        "labels": [
            {
                "position": np.asarray(lb.position, dtype=np.float64).reshape(2).tolist(),
                "text": str(lb.text),
                "angle": float(lb.angle),
                "height": float(lb.height),
                "kind": str(lb.kind),
            }
            for lb in annotations.labels
        ],
        "sheets": np.asarray(annotations.sheets, dtype=np.float64).reshape(-1, 4).tolist(),
    }


def _round(x: float) -> float:
    """``x`` rounded to :data:`FOLD_DIGITS` significant digits; ``-0.0`` becomes ``0.0``."""
    if not math.isfinite(x):
        raise ExportError(f"FOLD values must be finite, got {x}")
    r = float(f"{x:.{FOLD_DIGITS}g}")
    return 0.0 if r == 0 else r


def _plain(obj, where: str):
    """JSON-ready copy of ``obj``: numpy to Python, floats rounded, tuples to lists."""
    if isinstance(obj, np.ndarray):
        obj = obj.tolist()
    elif isinstance(obj, np.generic):
        obj = obj.item()
    if obj is None or isinstance(obj, bool | str):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        try:
            return _round(obj)
        except ExportError:
            raise ExportError(f"FOLD value at {where} is not finite ({obj})") from None
    if isinstance(obj, Mapping):
        out = {}
        for k, v in obj.items():
            if not isinstance(k, str):
                raise ExportError(f"FOLD keys must be strings, got {k!r} at {where}")
            out[k] = _plain(v, f"{where}.{k}" if where else k)
        return out
    if isinstance(obj, list | tuple):
        return [_plain(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    raise ExportError(
        f"FOLD value at {where or 'top level'} has unsupported type {type(obj).__name__}"
    )


def _dump(obj, depth: int) -> str:
    """Dicts and lists of dicts one entry per line, everything else compact on one line."""
    pad = "  " * depth
    if isinstance(obj, dict) and obj:
        items = [f"{pad}  {json.dumps(k)}: {_dump(v, depth + 1)}" for k, v in obj.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, list) and any(isinstance(v, dict) for v in obj):
        items = [f"{pad}  {_dump(v, depth + 1)}" for v in obj]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    return json.dumps(obj, separators=(",", ":"), allow_nan=False)


def fold_json(doc: Mapping) -> str:
    """Serialise a FOLD document deterministically.

    Keys keep the document's order (:func:`fold_document` builds them in a fixed order); floats
    are rounded to 12 significant digits (``-0`` written as ``0.0``); numpy arrays and scalars
    become JSON arrays and numbers. Each top-level key (and each key of a frame) is on its own
    line, arrays are compact. Output is ASCII and ends with a newline.

    Parameters
    ----------
    doc : mapping
        A FOLD document, such as the result of :func:`fold_document`.

    Returns
    -------
    str

    Raises
    ------
    ExportError
        When a value is not finite, not JSON data, or a key is not a string.
    """
    if not isinstance(doc, Mapping):
        raise ExportError(f"a FOLD document must be a mapping, got {type(doc).__name__}")
    return _dump(_plain(doc, ""), 0) + "\n"
